//! Scene queries: questions about the whole scene in one round trip.
//!
//! Instead of naming every pair, ask about a group of objects (a robot's
//! links, one object, or a list) against everything else the server holds:
//!
//! - [`Client::clearance`]: for each member, the nearest object outside the
//!   group;
//! - [`Client::within`]: every pair closer than a margin;
//! - [`Client::nearest`]: the `k` objects nearest to one object;
//! - [`Client::path`], or [`SceneQuery::along`] and
//!   [`SceneQuery::until_hit`]: the same questions at every step of a
//!   candidate motion, without moving anything;
//! - [`SceneQuery::continuous`] and [`Client::edge_contact`]: every pose
//!   of the motion between the steps, certified clear or its first contact
//!   bracketed.
//!
//! Each call returns a [`SceneQuery`] to refine (warm starts, motion
//! bounds, an accepted accuracy, a cut-off, allowed pairs) and then run into
//! a buffer of rows you own: [`SceneQuery::into_rows`] copies the wire rows
//! ([`SceneRow`]), [`SceneQuery::into_pairs`] decodes them ([`ScenePair`]).
//! Nothing is allocated per call. Every row's interval is certified, and an
//! answer with more rows than the buffer holds says so
//! ([`SceneSummary::truncated`]) rather than dropping them silently.
//!
//! ```no_run
//! use gjkd_client::{Client, SceneRow};
//! use nalgebra::{Isometry3, Vector3};
//!
//! # fn main() -> Result<(), gjkd_client::ClientError> {
//! let mut client = Client::connect("gjkd")?;
//! let arm = [
//!     client.register_sphere(0.1)?,
//!     client.register_cuboid(Vector3::new(0.1, 0.1, 0.3), 0.0)?,
//! ];
//! let wall = client.register_cuboid(Vector3::new(0.1, 2.0, 2.0), 0.0)?;
//! client.set_pose(wall, &Isometry3::translation(1.0, 0.0, 0.0))?;
//!
//! let mut rows = [SceneRow::default(); 16];
//! let summary = client.clearance(&arm[..]).into_rows(&mut rows)?;
//! for row in &rows[..summary.written] {
//!     println!("{:#x} is {:.3} from {:#x}", row.a, row.result.distance, row.b);
//! }
//! # Ok(())
//! # }
//! ```
//!
//! The scene service is opened at the first scene call, so clients that
//! never ask one pay nothing for it.

use std::time::Instant;

use gjkd_proto::{
    ErrorCode, Item, JOINTS_PER_ITEM, ObjectId, PathMode, Precision, SceneKind, SceneReply,
    SceneRequest, SceneRow, scene_flags, scene_reply_flags, scene_service_name,
};
use iceoryx2::port::client::Client as IoxClient;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::request_response;
use nalgebra::Isometry3;

#[cfg(feature = "robots")]
use crate::RobotHandle;
use crate::{Answer, Client, ClientError, SceneError, Waited, ipc_err, op_error};

mod continuous;
pub use continuous::Contact;

type ScenePort = IoxClient<ipc::Service, [Item], SceneRequest, [SceneRow], SceneReply>;
type SceneService =
    request_response::PortFactory<ipc::Service, [Item], SceneRequest, [SceneRow], SceneReply>;

/// The scene service's port of one connection, opened at its first use.
pub(crate) struct ScenePorts {
    // The port before its service, so that it is dropped first.
    port: ScenePort,
    service: SceneService,
}

/// The objects a scene question is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group<'a> {
    /// One object.
    Object(ObjectId),
    /// A robot's links (by its id: `RobotHandle::id`, or
    /// [`Client::robot_id`]), with the robot's allowed
    /// pairs (adjacent links, the SRDF's `disable_collisions`).
    Robot(ObjectId),
    /// The objects listed.
    Members(&'a [ObjectId]),
}

impl From<ObjectId> for Group<'_> {
    fn from(id: ObjectId) -> Self {
        Group::Object(id)
    }
}

#[cfg(feature = "robots")]
impl From<&RobotHandle> for Group<'_> {
    fn from(robot: &RobotHandle) -> Self {
        Group::Robot(robot.id)
    }
}

impl<'a> From<&'a [ObjectId]> for Group<'a> {
    fn from(members: &'a [ObjectId]) -> Self {
        Group::Members(members)
    }
}

impl<'a, const N: usize> From<&'a [ObjectId; N]> for Group<'a> {
    fn from(members: &'a [ObjectId; N]) -> Self {
        Group::Members(members)
    }
}

impl<'a> From<&'a Vec<ObjectId>> for Group<'a> {
    fn from(members: &'a Vec<ObjectId>) -> Self {
        Group::Members(members)
    }
}

/// The steps of a path: the poses (or joint positions) of the moving
/// objects at each step. The server answers at every step and leaves the
/// stored poses as they were.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Steps<'a> {
    /// `poses[s * objects.len() + i]` is object `i`'s pose at step `s`;
    /// `poses.len()` is a multiple of `objects.len()`.
    Poses {
        /// The moving objects.
        objects: &'a [ObjectId],
        /// Their poses, step after step.
        poses: &'a [Isometry3<f64>],
    },
    /// `positions[s * joints..][..joints]` are the robot's joint positions
    /// (in `RobotHandle::joint_names` order) at step `s`.
    Joints {
        /// The robot's id.
        robot: ObjectId,
        /// Its number of moving joints.
        joints: usize,
        /// The positions, step after step.
        positions: &'a [f64],
        /// Clamp positions outside their limits instead of refusing the
        /// request.
        clamp: bool,
    },
}

impl<'a> Steps<'a> {
    /// Steps of `robot`'s joint positions, `robot.positions.len()` per step.
    #[cfg(feature = "robots")]
    pub fn joints(robot: &RobotHandle, positions: &'a [f64]) -> Self {
        Steps::Joints {
            robot: robot.id,
            joints: robot.positions.len(),
            positions,
            clamp: false,
        }
    }

    /// Number of steps, or why the slices do not make whole steps.
    ///
    /// # Errors
    /// [`SceneError::PartialSteps`] when there is no moving object or
    /// joint, or the slices do not make whole steps.
    pub fn count(&self) -> Result<usize, SceneError> {
        let (per, len) = match *self {
            Steps::Poses { objects, poses } => (objects.len(), poses.len()),
            Steps::Joints {
                joints, positions, ..
            } => (joints, positions.len()),
        };
        if per == 0 || !len.is_multiple_of(per) {
            return Err(SceneError::PartialSteps);
        }
        Ok(len / per)
    }

    /// Items of one step (for bindings that lay out a path's items
    /// themselves; see [`Client::scene_with`]): its pose or joint items,
    /// the last of them flagged to end the step ([`Item::ending_step`]).
    pub fn items_per_step(&self) -> usize {
        match *self {
            Steps::Poses { objects, .. } => objects.len(),
            Steps::Joints { joints, .. } => joints.div_ceil(JOINTS_PER_ITEM),
        }
    }

    /// Item `k` (below [`Steps::items_per_step`]) of step `s` (below
    /// [`Steps::count`]).
    pub fn item(&self, s: usize, k: usize) -> Item {
        let item = match *self {
            Steps::Poses { objects, poses } => {
                Item::set_pose(objects[k], &poses[s * objects.len() + k])
            }
            Steps::Joints {
                robot,
                joints,
                positions,
                clamp,
            } => {
                let step = &positions[s * joints..(s + 1) * joints];
                let first = k * JOINTS_PER_ITEM;
                let end = (first + JOINTS_PER_ITEM).min(joints);
                Item::set_joints(robot, first as u32, &step[first..end], None, clamp)
            }
        };
        if k + 1 == self.items_per_step() {
            item.ending_step()
        } else {
            item
        }
    }
}

/// What a scene answer held besides its rows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneSummary {
    /// Rows written into the caller's buffer, from its start.
    pub written: usize,
    /// Rows that qualified, also those that did not fit.
    pub total: u64,
    /// More rows qualified than the buffer holds: the rows written are a
    /// prefix of the answer.
    pub truncated: bool,
    /// Steps answered (1 when not a path).
    pub steps: u32,
    /// [`SceneQuery::until_hit`]: the first step with a pair within the
    /// margin, `None` when the whole path is clear.
    pub first_hit: Option<u32>,
    /// Pair queries that ran GJK.
    pub gjk_runs: u64,
    /// Pairs answered from motion bounds alone, without GJK.
    pub bounded: u64,
    /// Pairs the broadphase could not rule out.
    pub candidates: u64,
}

impl SceneSummary {
    /// The summary of a reply of which `written` rows were read: for
    /// bindings that answer a [`SceneRequest`] without a server (Python's
    /// `gjkd.Local` runs the server's engine in process).
    pub fn new(reply: &SceneReply, written: usize) -> Self {
        SceneSummary {
            written,
            total: reply.total,
            truncated: reply.flags & scene_reply_flags::TRUNCATED != 0
                || reply.total > written as u64,
            steps: reply.steps,
            first_hit: (reply.first_hit != u32::MAX).then_some(reply.first_hit),
            gjk_runs: reply.gjk_runs,
            bounded: reply.bounded,
            candidates: reply.candidates,
        }
    }
}

/// A decoded row of a scene answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScenePair {
    /// The group's object (the object asked about, for
    /// [`Client::nearest`]).
    pub a: ObjectId,
    /// The other object; `None` when none qualifies (a clearance with a
    /// [`SceneQuery::cutoff`] and nothing that near, or nothing outside the
    /// group at all).
    pub b: Option<ObjectId>,
    /// The path step (0 when not a path).
    pub step: u32,
    /// The pair's answer, `point_a` on `a`, or the pair's own error.
    pub answer: Result<Answer, ErrorCode>,
}

impl From<&SceneRow> for ScenePair {
    fn from(row: &SceneRow) -> Self {
        ScenePair {
            a: ObjectId::from_raw(row.a),
            b: (row.b != 0).then(|| ObjectId::from_raw(row.b)),
            step: row.step,
            answer: row.result.answer_with(Some(&row.gradient)),
        }
    }
}

impl Default for ScenePair {
    fn default() -> Self {
        ScenePair::from(&SceneRow::default())
    }
}

/// A scene question being set up; run it with [`SceneQuery::into_rows`] or
/// [`SceneQuery::into_pairs`]. Made by [`Client::clearance`],
/// [`Client::within`], [`Client::nearest`] and [`Client::path`].
#[must_use = "a scene query does nothing until it is run with into_rows or into_pairs"]
pub struct SceneQuery<'c, 'a> {
    client: &'c mut Client,
    request: SceneRequest,
    members: &'a [ObjectId],
    allowed: &'a [(ObjectId, ObjectId)],
    poses: &'a [(ObjectId, Isometry3<f64>)],
    steps: Option<Steps<'a>>,
}

impl std::fmt::Debug for SceneQuery<'_, '_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneQuery")
            .field("request", &self.request)
            .field("members", &self.members)
            .field("allowed", &self.allowed)
            .field("poses", &self.poses.len())
            .field("steps", &self.steps)
            .finish()
    }
}

impl<'c, 'a> SceneQuery<'c, 'a> {
    fn new(client: &'c mut Client, kind: SceneKind, group: Group<'a>) -> Self {
        let (id, members) = match group {
            Group::Object(id) | Group::Robot(id) => (id.raw(), &[][..]),
            Group::Members(members) => (0, members),
        };
        SceneQuery {
            client,
            request: SceneRequest::new(kind, id),
            members,
            allowed: &[],
            poses: &[],
            steps: None,
        }
    }

    fn flag(mut self, bit: u32, on: bool) -> Self {
        if on {
            self.request.flags |= bit;
        } else {
            self.request.flags &= !bit;
        }
        self
    }

    /// Start each pair from the simplex the server kept for it after this
    /// client's last scene query (default on).
    pub fn warm(self, on: bool) -> Self {
        self.flag(scene_flags::WARM_START, on)
    }

    /// Answer pairs from their last certified interval widened by how far
    /// the objects moved since, when that decides the question, without
    /// running GJK (default on). Such rows have
    /// [`Status::Bounded`](crate::Status::Bounded).
    pub fn motion_bounds(self, on: bool) -> Self {
        self.flag(scene_flags::MOTION_BOUNDS, on)
    }

    /// Exact distances on every reported row: no row answered from motion
    /// bounds ([`Status::Bounded`](crate::Status::Bounded)) or left at a
    /// margin's early exit ([`Status::Closer`](crate::Status::Closer)), so
    /// `distance` and the points are exact to the tolerance on all of them.
    /// Bounds and early exits still rule out pairs not reported, so it
    /// costs a GJK run only per reported row (default off).
    pub fn exact(self, on: bool) -> Self {
        self.flag(scene_flags::EXACT, on)
    }

    /// Accept, from motion bounds alone, an interval at most `absolute`
    /// wide, or at most `relative` times its upper end wide (0 for none,
    /// the default: motion bounds then only answer what they decide).
    pub fn accept(mut self, absolute: f64, relative: f64) -> Self {
        self.request.accept_absolute = absolute;
        self.request.accept_relative = relative;
        self
    }

    /// Ignore objects farther than `distance` ([`Client::clearance`],
    /// [`Client::nearest`]): they are never searched for, so a member with
    /// nothing that near gets a row with no `b`, or with an object found on
    /// the way (with its own certified answer).
    pub fn cutoff(mut self, distance: f64) -> Self {
        self.request.margin = distance;
        self.flag(scene_flags::CUTOFF, true)
    }

    /// Every row also carries its distance's gradient
    /// ([`SceneRow::gradient`], [`Answer::gradient`]) with respect
    /// to the coordinates that move its `a` (see [`crate::gradient_matrix`]);
    /// `base` adds a robot base's twist. Rows the server would answer
    /// from a motion bound or an early exit are asked to convergence.
    pub fn gradients(self, base: bool) -> Self {
        self.flag(scene_flags::GRADIENTS, true)
            .flag(scene_flags::GRADIENT_BASE, base)
    }

    /// Every row also carries its pair's signed distance with its
    /// certified interval ([`Answer::signed`]): the distance when apart
    /// (the same interval), minus the penetration depth when overlapping,
    /// with the depth's witnesses and normal (see
    /// [`scene_flags::SIGNED_DISTANCE`]). Which rows are reported does not
    /// change: every overlapping pair has distance 0, so [`Client::within`]
    /// reports it whatever the margin and however deep. Refused with
    /// [`SceneQuery::continuous`] (default off).
    pub fn signed_distance(self) -> Self {
        self.flag(scene_flags::SIGNED_DISTANCE, true)
    }

    /// [`Client::within`]: every pair of the scene, not only the group
    /// against the rest.
    pub fn all_pairs(self) -> Self {
        self.flag(scene_flags::ALL_PAIRS, true)
    }

    /// [`Client::within`] and [`Client::clearance`] (and their paths): the
    /// group's members meet each other too, but the allowed pairs (a
    /// robot's self-collisions, without its adjacent links and the SRDF's
    /// disabled pairs). [`Client::nearest`] is refused with it.
    pub fn self_pairs(self) -> Self {
        self.flag(scene_flags::SELF_PAIRS, true)
    }

    /// Relative tolerance of every pair (default
    /// [`DEFAULT_TOLERANCE`](crate::DEFAULT_TOLERANCE)).
    pub fn tolerance(mut self, tolerance: f64) -> Self {
        self.request.tolerance = tolerance;
        self
    }

    /// Iteration cap of every pair (default
    /// [`DEFAULT_MAX_ITERATIONS`](crate::DEFAULT_MAX_ITERATIONS)).
    pub fn max_iterations(mut self, cap: u32) -> Self {
        self.request.max_iterations = cap;
        self
    }

    /// Arithmetic of the support search (default [`Precision::Double`]).
    pub fn precision(self, precision: Precision) -> Self {
        self.flag(
            scene_flags::SINGLE_PRECISION,
            precision == Precision::Single,
        )
    }

    /// Clamp joint positions outside their limits (of the poses and
    /// steps) instead of refusing the request.
    pub fn clamp(self, on: bool) -> Self {
        self.flag(scene_flags::CLAMP, on)
    }

    /// Pairs never to report, on top of a robot's own allowed pairs.
    pub fn allow(mut self, pairs: &'a [(ObjectId, ObjectId)]) -> Self {
        self.allowed = pairs;
        self
    }

    /// The group is these objects (replacing the group given before).
    pub fn members(mut self, members: &'a [ObjectId]) -> Self {
        self.request.group = 0;
        self.members = members;
        self
    }

    /// Store these poses first, as [`Client::set_pose`] would, then answer.
    /// In a path they are the first step's.
    ///
    /// Storing and answering are one request, which the server handles
    /// whole before any other client's: no other client's update comes in
    /// between, and the answer is at exactly these poses. The poses stay
    /// stored for every client afterwards; to ask at poses without storing
    /// them, use [`SceneQuery::at_poses`].
    pub fn with_poses(mut self, poses: &'a [(ObjectId, Isometry3<f64>)]) -> Self {
        self.poses = poses;
        self
    }

    /// Answer with these objects at these poses for this question only:
    /// the stored poses are neither used for them nor changed (a path of
    /// one step; rows have step 0). Replaces [`SceneQuery::with_poses`].
    pub fn at_poses(mut self, poses: &'a [(ObjectId, Isometry3<f64>)]) -> Self {
        self.poses = poses;
        if self.steps.is_none() && self.request.path == PathMode::Single as u32 {
            self.request.path = PathMode::EveryStep as u32;
        }
        self
    }

    /// Answer at every step of `steps`, the stored poses unchanged
    /// ([`Client::clearance`] or [`Client::within`]).
    ///
    /// A path of any length comes back whole when the buffer holds its
    /// rows: one longer than a request takes (more items than the
    /// server's [`ServerInfo::max_batch`](crate::ServerInfo::max_batch), or
    /// more rows than its [`ServerInfo::max_rows`](crate::ServerInfo::max_rows))
    /// is sent as several requests of consecutive steps, each repeating the
    /// first step's poses for the objects later steps leave alone, and the
    /// rows are numbered from the path's start as in one answer.
    pub fn along(mut self, steps: Steps<'a>) -> Self {
        self.request.path = PathMode::EveryStep as u32;
        self.steps = Some(steps);
        self
    }

    /// [`Client::within`] along `steps`, stopping at the first step with a
    /// pair within the margin: its rows, and its index in
    /// [`SceneSummary::first_hit`].
    pub fn until_hit(mut self, steps: Steps<'a>) -> Self {
        self.request.path = PathMode::FirstHit as u32;
        self.steps = Some(steps);
        self
    }

    /// The request header as it will be sent.
    pub fn request(&self) -> &SceneRequest {
        &self.request
    }

    /// Runs the question and copies the answer's rows into `rows` (at most
    /// `rows.len()` of them, from its start).
    ///
    /// # Errors
    /// [`SceneError::PartialSteps`] for a path whose slices do not make
    /// whole steps, before anything is sent; a refusal of the whole
    /// request by the server (nothing changes then):
    /// [`SceneError::UnknownObject`] (the group, a member, an object of an
    /// allowed pair, a moving object), [`SceneError::InvalidOptions`] (a
    /// tolerance, iteration cap, margin, cut-off, accepted accuracy or `k`
    /// out of its domain: negative, NaN, infinite, zero iterations, `k` 0),
    /// [`SceneError::Malformed`] ([`Client::nearest`] of a group of more
    /// than one, [`SceneQuery::until_hit`] of another question than
    /// [`Client::within`]), [`SceneError::BatchTooLarge`] (more poses,
    /// members, allowed pairs and steps together than the server's
    /// [`ServerInfo::max_batch`](crate::ServerInfo::max_batch) in one step),
    /// [`SceneError::NonFinitePose`], [`SceneError::BadQuaternion`],
    /// [`SceneError::OutOfLimits`]; and the connection faults of every call.
    pub fn into_rows(self, rows: &mut [SceneRow]) -> Result<SceneSummary, SceneError> {
        let max_rows = rows.len();
        self.run(max_rows, |got| {
            rows[..got.len()].copy_from_slice(got);
        })
    }

    /// As [`SceneQuery::into_rows`], decoding each row.
    ///
    /// # Errors
    /// As [`SceneQuery::into_rows`].
    pub fn into_pairs(self, pairs: &mut [ScenePair]) -> Result<SceneSummary, SceneError> {
        let max_rows = pairs.len();
        self.run(max_rows, |got| {
            for (out, row) in pairs.iter_mut().zip(got) {
                *out = ScenePair::from(row);
            }
        })
    }

    /// Runs the question with room for `max_rows` rows and hands the rows
    /// received to `read`, straight from the response's shared memory (for
    /// bindings with row layouts of their own).
    ///
    /// # Errors
    /// As [`SceneQuery::into_rows`].
    pub fn run(
        mut self,
        max_rows: usize,
        read: impl FnOnce(&[SceneRow]),
    ) -> Result<SceneSummary, SceneError> {
        self.request.max_rows = u32::try_from(max_rows).unwrap_or(u32::MAX);
        let (members, allowed, poses) = (self.members, self.allowed, self.poses);
        let (steps, per_step, step_count) = match self.steps {
            Some(s) => (Some(s), s.items_per_step(), s.count()?),
            None => (None, 0, 0),
        };
        let heads = [members.len(), allowed.len(), poses.len()];
        // A one-step path of its own poses (`at_poses`) ends with a step.
        let own_step = usize::from(steps.is_none() && self.request.path != PathMode::Single as u32);
        let count = heads.iter().sum::<usize>() + per_step * step_count + own_step;
        let item = move |mut i: usize| {
            if i < members.len() {
                return Item::member(members[i]);
            }
            i -= members.len();
            if i < allowed.len() {
                let (a, b) = allowed[i];
                return Item::allow(a, b);
            }
            i -= allowed.len();
            if i < poses.len() {
                let (id, pose) = &poses[i];
                return Item::set_pose(*id, pose);
            }
            i -= poses.len();
            match steps {
                Some(s) => s.item(i / per_step, i % per_step),
                None => Item::step(),
            }
        };
        self.client.scene_with(&self.request, count, item, read)
    }
}

impl Client {
    /// For each member of `group`, the nearest object outside the group
    /// (one row per member, in the group's order for a listed group).
    ///
    /// ```no_run
    /// # use gjkd_client::{Client, ScenePair};
    /// # fn main() -> Result<(), gjkd_client::ClientError> {
    /// # let mut client = Client::connect("gjkd")?;
    /// let hand = client.register_sphere(0.1)?;
    /// let mut pairs = [ScenePair::default(); 1];
    /// let summary = client.clearance(hand).cutoff(0.5).into_pairs(&mut pairs)?;
    /// match pairs[0].b {
    ///     Some(b) => println!("{b} at {:?}", pairs[0].answer.map(|a| a.distance)),
    ///     None => println!("nothing within 0.5"),
    /// }
    /// # Ok(())
    /// # }
    /// ```
    pub fn clearance<'a>(&mut self, group: impl Into<Group<'a>>) -> SceneQuery<'_, 'a> {
        SceneQuery::new(self, SceneKind::Clearance, group.into())
    }

    /// Every pair, `group` against the rest (or all against all with
    /// [`SceneQuery::all_pairs`]), whose distance is at most `margin`.
    pub fn within<'a>(&mut self, group: impl Into<Group<'a>>, margin: f64) -> SceneQuery<'_, 'a> {
        let mut query = SceneQuery::new(self, SceneKind::Within, group.into());
        query.request.margin = margin;
        query
    }

    /// The `k` objects nearest to `object`, nearest first.
    pub fn nearest<'a>(&mut self, object: ObjectId, k: u32) -> SceneQuery<'_, 'a> {
        let mut query = SceneQuery::new(self, SceneKind::Nearest, Group::Object(object));
        query.request.k = k;
        query
    }

    /// The clearance of `group` at every step of `steps` (a candidate
    /// motion: nothing moves on the server); rows carry their step. For
    /// the pairs within a margin along a path, or the first step that
    /// comes within it, see [`SceneQuery::along`] and
    /// [`SceneQuery::until_hit`] after [`Client::within`].
    pub fn path<'a>(
        &mut self,
        group: impl Into<Group<'a>>,
        steps: Steps<'a>,
    ) -> SceneQuery<'_, 'a> {
        self.clearance(group).along(steps)
    }

    /// Sends `request` with the `count` items made by `item(i)` (written
    /// straight into the request's shared memory) and hands the rows
    /// received to `read`, straight from the response's: the layer under
    /// [`SceneQuery`], for bindings that keep their inputs and rows in
    /// layouts of their own. `request.max_rows` is the room for rows; the
    /// items follow the layout of [`SceneRequest`]'s documentation.
    ///
    /// A path longer than one request takes (more items than the server's
    /// [`ServerInfo::max_batch`](crate::ServerInfo::max_batch), or room for
    /// more rows than its [`ServerInfo::max_rows`](crate::ServerInfo::max_rows))
    /// is sent as several requests, and `read` gets all the rows at once:
    /// see [`SceneQuery::along`].
    ///
    /// # Errors
    /// As [`SceneQuery::into_rows`].
    pub fn scene_with(
        &mut self,
        request: &SceneRequest,
        count: usize,
        item: impl FnMut(usize) -> Item,
        read: impl FnOnce(&[SceneRow]),
    ) -> Result<SceneSummary, SceneError> {
        self.ensure_connected(Instant::now() + self.timeout)
            .map_err(op_error::<SceneError>)?;
        let outcome = match self.request_limits() {
            Some(limits) if limits.must_split(request, count) => {
                self.scene_split(request, count, item, read, limits)
            }
            _ => self.scene_once(request, count, item, read),
        };
        outcome.map_err(op_error)
    }

    /// One scene request: [`Client::scene_with`] for what one request takes.
    pub(crate) fn scene_once(
        &mut self,
        request: &SceneRequest,
        count: usize,
        item: impl FnMut(usize) -> Item,
        read: impl FnOnce(&[SceneRow]),
    ) -> Result<SceneSummary, ClientError> {
        let deadline = Instant::now() + self.timeout;
        self.ensure_connected(deadline)?;
        self.ensure_scene_ports()?;
        let conn = self.conn.as_ref().ok_or_else(|| self.gone())?;
        let Some(scene) = conn.scene.as_ref() else {
            return Err(self.gone());
        };
        let mut read = Some(read);
        let outcome = (|| {
            if scene.service.dynamic_config().number_of_servers() == 0 {
                return Err(Waited::Gone);
            }
            let mut loan = scene
                .port
                .loan_slice_uninit(count)
                .map_err(|e| Waited::Failed(ipc_err("scene loan")(e)))?;
            *loan.user_header_mut() = *request;
            let pending = loan
                .write_from_fn(item)
                .send()
                .map_err(|e| conn.send_failed(&self.node, "scene send", e))?;
            if conn.notify_queries {
                let _ = conn.wake.notify();
            }
            Self::await_reply(&self.node, conn, deadline, self.timeout, || {
                let Some(response) = pending.receive().map_err(ipc_err("scene receive"))? else {
                    return Ok(None);
                };
                let reply = *response.user_header();
                crate::reply_accepted(reply.error)?;
                let payload = response.payload();
                let written = usize::try_from(reply.total)
                    .unwrap_or(usize::MAX)
                    .min(payload.len())
                    .min(request.max_rows as usize);
                if let Some(read) = read.take() {
                    read(&payload[..written]);
                }
                Ok(Some(SceneSummary::new(&reply, written)))
            })
        })();
        self.settle(outcome)
    }

    /// Opens the scene service and its client port on the current
    /// connection, if not yet done.
    fn ensure_scene_ports(&mut self) -> Result<(), ClientError> {
        if self.conn.as_ref().is_none_or(|c| c.scene.is_some()) {
            return Ok(());
        }
        let name = scene_service_name(&self.service);
        let service_name = ServiceName::new(&name).map_err(ipc_err("service name"))?;
        let service = self
            .node
            .service_builder(&service_name)
            .request_response::<[Item], [SceneRow]>()
            .request_user_header::<SceneRequest>()
            .response_user_header::<SceneReply>()
            .open()
            .map_err(|e| self.later_service_failed(&name, "scene", "scene queries", e))?;
        let port = service
            .client_builder()
            .initial_max_slice_len(64)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(ipc_err("scene client port"))?;
        if let Some(conn) = self.conn.as_mut() {
            conn.scene = Some(ScenePorts { port, service });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ItemResult;

    #[test]
    fn steps_count_whole_steps_only() {
        let ids = [ObjectId::from_raw(1), ObjectId::from_raw(2)];
        let poses = [Isometry3::identity(); 6];
        let steps = Steps::Poses {
            objects: &ids,
            poses: &poses,
        };
        assert_eq!(steps.count(), Ok(3));
        // Two poses a step, the second ending it.
        assert_eq!(steps.items_per_step(), 2);
        assert_eq!(steps.item(2, 0).flags & crate::item_flags::END_STEP, 0);
        assert_ne!(steps.item(2, 1).flags & crate::item_flags::END_STEP, 0);
        assert_eq!(steps.item(2, 1).a, ids[1].raw());
        let odd = Steps::Poses {
            objects: &ids,
            poses: &poses[..5],
        };
        assert_eq!(odd.count(), Err(SceneError::PartialSteps));
        let none = Steps::Poses {
            objects: &[],
            poses: &[],
        };
        assert_eq!(none.count(), Err(SceneError::PartialSteps));
    }

    #[test]
    fn joint_steps_split_into_items_of_joints_per_item() {
        let joints = JOINTS_PER_ITEM + 2;
        let positions: Vec<f64> = (0..2 * joints).map(|i| i as f64 * 0.01).collect();
        let steps = Steps::Joints {
            robot: ObjectId::from_raw(7),
            joints,
            positions: &positions,
            clamp: true,
        };
        assert_eq!(steps.count(), Ok(2));
        assert_eq!(steps.items_per_step(), 2);
        let first = steps.item(1, 0);
        assert_eq!(first.flags & crate::item_flags::END_STEP, 0);
        let second = steps.item(1, 1);
        let values = second.joint_positions().expect("a joint item");
        assert_eq!(values.len(), 2);
        assert_eq!(second.joints().first, JOINTS_PER_ITEM as u32);
        assert_eq!(values[0], positions[joints + JOINTS_PER_ITEM]);
        assert_ne!(second.flags & crate::item_flags::CLAMP, 0);
        // The last item of a step ends it.
        assert_ne!(second.flags & crate::item_flags::END_STEP, 0);
    }

    #[test]
    fn a_summary_reads_the_reply() {
        let reply = SceneReply {
            total: 5,
            flags: scene_reply_flags::TRUNCATED,
            steps: 3,
            first_hit: 2,
            ..SceneReply::error(ErrorCode::Ok)
        };
        let s = SceneSummary::new(&reply, 4);
        assert!(s.truncated);
        assert_eq!((s.written, s.total, s.first_hit), (4, 5, Some(2)));
        let clear = SceneSummary::new(&SceneReply::error(ErrorCode::Ok), 0);
        assert_eq!(clear.first_hit, None);
        assert!(!clear.truncated);
    }

    #[test]
    fn rows_decode_ids_and_missing_partners() {
        let row = SceneRow {
            a: 3,
            b: 0,
            step: 4,
            reserved: 0,
            result: ItemResult::default(),
            gradient: gjkd_proto::Gradient::NONE,
            s_lo: 0.0,
            s_hi: 0.0,
        };
        let pair = ScenePair::from(&row);
        assert_eq!(pair.a, ObjectId::from_raw(3));
        assert_eq!(pair.b, None);
        assert_eq!(pair.step, 4);
        let err = SceneRow {
            b: 9,
            result: ItemResult::error(ErrorCode::UnknownObject),
            ..row
        };
        assert_eq!(ScenePair::from(&err).answer, Err(ErrorCode::UnknownObject));
    }
}
