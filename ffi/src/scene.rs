//! Scene queries: a group of objects against the whole scene in one round
//! trip (clearance, pairs within a margin, nearest objects, along a path),
//! into the caller's row array.

#![allow(non_camel_case_types)]

use gjkd_proto::{PathMode, SceneKind, SceneRequest, SceneRow, scene_flags};
use rust_client::{Item, ObjectId, SceneSummary, Steps};

use crate::args::{checked_pose, out, slice, slice_mut};
use crate::gradient::gjkd_gradient;
use crate::handle::{gjkd_client, with_client};
#[cfg(feature = "robots")]
use crate::robots::{gjkd_robot, path_steps};
use crate::status::{Failure, gjkd_status, guard};
use crate::types::{gjkd_answer, gjkd_id, gjkd_pose};

/// The objects a scene question is about: `id` (a robot, whose links are
/// the group, with its allowed pairs; or one object), or, when `id` is 0,
/// the `member_count` ids at `members`. `allowed` holds `allowed_count`
/// pairs (`2 * allowed_count` ids, `a0, b0, a1, b1, ...`) never to report;
/// it may be NULL when `allowed_count` is 0.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct gjkd_group {
    /// A robot or object id, or 0 for the listed members.
    pub id: gjkd_id,
    /// The members when `id` is 0.
    pub members: *const gjkd_id,
    /// Number of members.
    pub member_count: usize,
    /// Pairs never to report, two ids each.
    pub allowed: *const gjkd_id,
    /// Number of allowed pairs.
    pub allowed_count: usize,
}

/// Options of a scene query; start from `gjkd_scene_options_default()`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct gjkd_scene_options {
    /// Relative tolerance of every pair, `>= 0`.
    pub tolerance: f64,
    /// Accept, from motion bounds alone, an interval at most this wide (0:
    /// none).
    pub accept_absolute: f64,
    /// Accept, from motion bounds alone, an interval at most this times
    /// its upper end wide (0: none).
    pub accept_relative: f64,
    /// With `use_cutoff`: ignore objects farther than this (clearance,
    /// nearest); they are never searched for (a member with nothing that near gets `b` 0, or an object found on the way).
    pub cutoff: f64,
    /// Iteration cap of every pair, `>= 1`.
    pub max_iterations: u32,
    /// A `gjkd_precision` value.
    pub precision: u32,
    /// Whether `cutoff` applies.
    pub use_cutoff: bool,
    /// Start each pair from the simplex the server kept for this handle.
    pub warm_start: bool,
    /// Answer pairs from motion bounds when they decide the question (rows
    /// with status `GJKD_QUERY_BOUNDED`).
    pub motion_bounds: bool,
    /// Within: every pair of the scene, not only group against the rest.
    pub all_pairs: bool,
    /// Within and clearance (and their paths): the group's members meet
    /// each other too, but the allowed pairs (a robot's self-collisions).
    /// Refused with nearest.
    pub self_pairs: bool,
    /// Clamp joint positions outside their limits instead of refusing.
    pub clamp: bool,
    /// Exact distances on every reported row: none with status
    /// `GJKD_QUERY_BOUNDED` or `GJKD_QUERY_CLOSER` (motion bounds and early
    /// exits still rule out pairs not reported).
    pub exact: bool,
    /// Every row also carries its distance's gradient (`gjkd_scene_row`'s
    /// `gradient`), with respect to the coordinates that move its `a`.
    pub gradients: bool,
    /// With `gradients`, rows of robot links: the base twist too.
    pub gradient_base: bool,
    /// `GJKD_PATH_CONTINUOUS`: rigid objects turn with their quaternions'
    /// components linear between steps (the GJK paper's Section 8), not
    /// along the shortest arc.
    pub linear_quaternions: bool,
    /// `GJKD_PATH_CONTINUOUS`: the widest bracket of a first contact, in
    /// the segment's `s`, `> 0` (default 1e-6).
    pub bracket: f64,
    /// Every row also carries its pair's signed distance with its
    /// certified interval (`gjkd_result`'s `signed_distance`,
    /// `signed_lower`, `signed_upper`, flagged
    /// `GJKD_RESULT_SIGNED_DISTANCE`): the distance apart, minus the
    /// penetration depth overlapping, with the depth's witnesses. Which
    /// rows are reported does not change: every overlapping pair has
    /// distance 0, so within reports it whatever the margin. Refused
    /// (`GJKD_CODE_MALFORMED`) with `GJKD_PATH_CONTINUOUS`.
    pub signed_distance: bool,
}

impl Default for gjkd_scene_options {
    fn default() -> Self {
        gjkd_scene_options {
            tolerance: gjkd_proto::DEFAULT_TOLERANCE,
            accept_absolute: 0.0,
            accept_relative: 0.0,
            cutoff: 0.0,
            max_iterations: gjkd_proto::DEFAULT_MAX_ITERATIONS,
            precision: 0,
            use_cutoff: false,
            warm_start: true,
            motion_bounds: true,
            all_pairs: false,
            self_pairs: false,
            clamp: false,
            exact: false,
            gradients: false,
            gradient_base: false,
            linear_quaternions: false,
            bracket: gjkd_proto::DEFAULT_BRACKET,
            signed_distance: false,
        }
    }
}

/// The default scene options: default tolerance and iteration cap, warm
/// starts and motion bounds on, no accepted accuracy, no cut-off.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_scene_options_default() -> gjkd_scene_options {
    gjkd_scene_options::default()
}

/// One row of a scene answer: the pair and its answer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct gjkd_scene_row {
    /// The group's object (the object asked about, for `gjkd_nearest()`).
    pub a: gjkd_id,
    /// The other object; 0 when none qualifies.
    pub b: gjkd_id,
    /// The path step (0 when not a path).
    pub step: u32,
    /// The pair's `gjkd_error_code`, 0 when answered.
    pub error: u32,
    /// The pair's answer, `point_a` on `a`. `lower` and `upper` always
    /// bound the true distance. With status `GJKD_QUERY_CONVERGED` (and
    /// `ITERATION_CAP`, `TOLERANCE_NOT_MET` within their bounds) `distance`
    /// and the points are the answer; with `GJKD_QUERY_CLOSER` (a within
    /// pair proved inside the margin by an early exit) or
    /// `GJKD_QUERY_BOUNDED` (from motion bounds, without GJK) they are an
    /// estimate inside `[lower, upper]`, which may be wide. Set
    /// `gjkd_scene_options.exact` for exact distances on every row.
    pub answer: gjkd_answer,
    /// The distance's gradient, with `gjkd_scene_options::gradients`
    /// (`columns` 0 otherwise).
    pub gradient: gjkd_gradient,
    /// `GJKD_PATH_CONTINUOUS`: every pose of the segment (`step`) before
    /// this `s` is certified clear (0 otherwise).
    pub s_lo: f64,
    /// `GJKD_PATH_CONTINUOUS`: the `s` of the pose `answer` is at, within
    /// the margin: the first contact's bracket is `[s_lo, s_hi]`.
    pub s_hi: f64,
}

/// What a scene answer held besides its rows.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct gjkd_scene_summary {
    /// Rows written, from the start of the caller's array.
    pub written: usize,
    /// Rows that qualified, also those that did not fit.
    pub total: u64,
    /// Pair queries that ran GJK.
    pub gjk_runs: u64,
    /// Pairs answered from motion bounds alone.
    pub bounded: u64,
    /// Pairs the broadphase could not rule out.
    pub candidates: u64,
    /// Steps answered (1 when not a path).
    pub steps: u32,
    /// First-hit paths: the first step with a pair within the margin,
    /// `UINT32_MAX` when none.
    pub first_hit: u32,
    /// More rows qualified than the array holds: the rows written are a
    /// prefix of the answer.
    pub truncated: bool,
}

impl From<&SceneSummary> for gjkd_scene_summary {
    fn from(s: &SceneSummary) -> Self {
        gjkd_scene_summary {
            written: s.written,
            total: s.total,
            gjk_runs: s.gjk_runs,
            bounded: s.bounded,
            candidates: s.candidates,
            steps: s.steps,
            first_hit: s.first_hit.unwrap_or(u32::MAX),
            truncated: s.truncated,
        }
    }
}

/// What a path reports at each step (`gjkd_path()`).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum gjkd_path_question {
    /// Each member's clearance at every step.
    GJKD_PATH_CLEARANCE = 0,
    /// The pairs within the margin at every step.
    GJKD_PATH_WITHIN = 1,
    /// Only the first step with a pair within the margin: its pairs, and
    /// its index in `gjkd_scene_summary::first_hit`.
    GJKD_PATH_FIRST_HIT = 2,
    /// Every pose of the motion between consecutive steps, not samples
    /// (joints linear between steps; translations linear and rotations
    /// along the shortest arc): a row per segment that comes within the
    /// margin, its first contact bracketed in `[s_lo, s_hi]`
    /// (`options->bracket` wide at most, everything before `s_lo`
    /// certified clear), `step` the segment; no row for a segment
    /// certified clear. `first_hit` is the first segment that touches.
    GJKD_PATH_CONTINUOUS = 3,
}

/// The caller's arguments of a scene call, checked.
struct Call<'a> {
    request: SceneRequest,
    members: &'a [gjkd_id],
    allowed: &'a [[gjkd_id; 2]],
    moving: &'a [gjkd_id],
    poses: &'a [gjkd_pose],
    /// A path of joint positions, instead of `moving` and `poses`.
    joints: Option<Steps<'a>>,
}

impl<'a> Call<'a> {
    /// The request of `kind` about `group` with `options` (NULL: the
    /// defaults).
    ///
    /// # Safety
    /// `group` and `options` NULL or readable, their arrays as they say.
    unsafe fn new(
        kind: SceneKind,
        group: *const gjkd_group,
        options: *const gjkd_scene_options,
    ) -> Result<Self, Failure> {
        // SAFETY: the caller's promises.
        let group = unsafe { group.as_ref() }.ok_or_else(|| Failure::null("group"))?;
        // SAFETY: as above.
        let options = unsafe { options.as_ref() }.copied().unwrap_or_default();
        // SAFETY: as above.
        let members = unsafe { slice(group.members, group.member_count, "group->members") }?;
        // SAFETY: as above.
        let allowed = unsafe {
            slice(
                group.allowed.cast::<[gjkd_id; 2]>(),
                group.allowed_count,
                "group->allowed",
            )
        }?;
        let mut request = SceneRequest::new(kind, group.id);
        request.tolerance = options.tolerance;
        request.max_iterations = options.max_iterations;
        request.accept_absolute = options.accept_absolute;
        request.accept_relative = options.accept_relative;
        if options.precision > 1 {
            return Err(Failure::invalid("options->precision is no gjkd_precision"));
        }
        let bits = [
            (options.warm_start, scene_flags::WARM_START),
            (options.motion_bounds, scene_flags::MOTION_BOUNDS),
            (options.exact, scene_flags::EXACT),
            (options.all_pairs, scene_flags::ALL_PAIRS),
            (options.self_pairs, scene_flags::SELF_PAIRS),
            (options.precision == 1, scene_flags::SINGLE_PRECISION),
            (options.use_cutoff, scene_flags::CUTOFF),
            (options.clamp, scene_flags::CLAMP),
            (options.gradients, scene_flags::GRADIENTS),
            (
                options.gradients && options.gradient_base,
                scene_flags::GRADIENT_BASE,
            ),
            (options.linear_quaternions, scene_flags::LINEAR_QUATERNION),
            (options.signed_distance, scene_flags::SIGNED_DISTANCE),
        ];
        request.flags = bits.iter().filter(|b| b.0).fold(0, |f, b| f | b.1);
        if options.use_cutoff {
            request.margin = options.cutoff;
        }
        request.bracket = options.bracket;
        Ok(Call {
            request,
            members: if group.id == 0 { members } else { &[] },
            allowed,
            moving: &[],
            poses: &[],
            joints: None,
        })
    }

    /// Sends the request with room for `capacity` rows at `rows`, and
    /// writes the summary.
    ///
    /// # Safety
    /// `rows` NULL or room for `capacity` rows; `summary` NULL or writable.
    unsafe fn run(
        mut self,
        c: &mut gjkd_client,
        rows: *mut gjkd_scene_row,
        capacity: usize,
        summary: *mut gjkd_scene_summary,
    ) -> Result<(), Failure> {
        // SAFETY: the caller's promise.
        let summary = unsafe { out(summary, "summary") }?;
        *summary = gjkd_scene_summary::default();
        // SAFETY: the caller's promise.
        let rows = match unsafe { slice_mut(rows, capacity, "rows") }? {
            Some(rows) => rows,
            None if capacity == 0 => &mut [],
            None => return Err(Failure::null("rows")),
        };
        for (i, p) in self.poses.iter().enumerate() {
            checked_pose(p, &format!("poses[{i}]"))?;
        }
        let (per_step, steps) = match self.joints {
            Some(j) => (j.items_per_step(), j.count()?),
            None if self.moving.is_empty() => (1, 0),
            None => (self.moving.len(), self.poses.len() / self.moving.len()),
        };
        let (members, allowed, moving, poses, joints) = (
            self.members,
            self.allowed,
            self.moving,
            self.poses,
            self.joints,
        );
        let count = members.len() + allowed.len() + steps * per_step;
        self.request.max_rows = u32::try_from(capacity).unwrap_or(u32::MAX);
        let item = |i: usize| {
            if i < members.len() {
                return Item::member(ObjectId::from_raw(members[i]));
            }
            let i = i - members.len();
            if let Some([a, b]) = allowed.get(i) {
                return Item::allow(ObjectId::from_raw(*a), ObjectId::from_raw(*b));
            }
            let i = i - allowed.len();
            let (s, k) = (i / per_step, i % per_step);
            if let Some(j) = joints {
                return j.item(s, k);
            }
            match moving.get(k) {
                Some(&id) => {
                    let item = Item {
                        a: id,
                        pose_a: poses[s * moving.len() + k].wire(),
                        ..Item::set_pose(ObjectId::from_raw(id), &Default::default())
                    };
                    // The step's last pose ends it: one item fewer a step.
                    if k + 1 == moving.len() {
                        item.ending_step()
                    } else {
                        item
                    }
                }
                None => Item::step(),
            }
        };
        let got = c.client.scene_with(&self.request, count, item, |got| {
            for (out, row) in rows.iter_mut().zip(got) {
                *out = scene_row(row);
            }
        })?;
        *summary = gjkd_scene_summary::from(&got);
        Ok(())
    }
}

fn scene_row(row: &SceneRow) -> gjkd_scene_row {
    gjkd_scene_row {
        a: row.a,
        b: row.b,
        step: row.step,
        error: row.result.error,
        answer: gjkd_answer::from(&row.result),
        gradient: gjkd_gradient::from(&row.gradient),
        s_lo: row.s_lo,
        s_hi: row.s_hi,
    }
}

/// For each member of `group`, the nearest object outside the group: one
/// row per member into `rows` (room for `capacity`), the counts into
/// `*summary`. `options` NULL means `gjkd_scene_options_default()`. An
/// empty group (`id` 0 and no members) has no member to answer for:
/// `GJKD_OK` with no rows (`written` and `total` 0), here and in
/// `gjkd_within()`.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `group`, `summary`, `rows`
/// with a non-zero `capacity`, the group's arrays with non-zero counts),
/// `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT` (a precision that
/// is no `gjkd_precision`), `GJKD_ERR_REJECTED` with
/// `GJKD_CODE_UNKNOWN_OBJECT` (the group or a member),
/// `GJKD_CODE_INVALID_OPTIONS` (tolerance, iteration cap, accepted
/// accuracy, cut-off out of their domain), `GJKD_CODE_BATCH_TOO_LARGE`
/// (more members and allowed pairs than the server's `max_batch`, see
/// `gjkd_server_info()`); `GJKD_ERR_SERVER_GONE`,
/// `GJKD_ERR_TIMEOUT`, `GJKD_ERR_PROTOCOL` (a server without scene
/// queries). On failure nothing changed on the server and `*summary` is
/// zeroed.
///
/// # Safety
/// `client` is NULL or a live handle; every other non-NULL pointer points
/// to what its parameter says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_clearance(
    client: *mut gjkd_client,
    group: *const gjkd_group,
    options: *const gjkd_scene_options,
    rows: *mut gjkd_scene_row,
    capacity: usize,
    summary: *mut gjkd_scene_summary,
) -> gjkd_status {
    guard("gjkd_clearance", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                Call::new(SceneKind::Clearance, group, options)?.run(c, rows, capacity, summary)
            })
        }
    })
}

/// Every pair, `group` against the rest (or all against all with
/// `options->all_pairs`), whose distance is at most `margin`, into `rows`.
///
/// Errors: as `gjkd_clearance()`, plus `GJKD_CODE_INVALID_OPTIONS` for a
/// NaN margin.
///
/// # Safety
/// As `gjkd_clearance()`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_within(
    client: *mut gjkd_client,
    group: *const gjkd_group,
    margin: f64,
    options: *const gjkd_scene_options,
    rows: *mut gjkd_scene_row,
    capacity: usize,
    summary: *mut gjkd_scene_summary,
) -> gjkd_status {
    guard("gjkd_within", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let mut call = Call::new(SceneKind::Within, group, options)?;
                call.request.margin = margin;
                call.run(c, rows, capacity, summary)
            })
        }
    })
}

/// The `k` objects nearest to `object`, nearest first, into `rows`.
///
/// Errors: as `gjkd_clearance()`, with `GJKD_CODE_INVALID_OPTIONS` for a
/// `k` of 0.
///
/// # Safety
/// As `gjkd_clearance()`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_nearest(
    client: *mut gjkd_client,
    object: gjkd_id,
    k: u32,
    options: *const gjkd_scene_options,
    rows: *mut gjkd_scene_row,
    capacity: usize,
    summary: *mut gjkd_scene_summary,
) -> gjkd_status {
    guard("gjkd_nearest", || {
        let group = gjkd_group {
            id: object,
            members: std::ptr::null(),
            member_count: 0,
            allowed: std::ptr::null(),
            allowed_count: 0,
        };
        // SAFETY: the caller's promises; `group` is ours.
        unsafe {
            with_client(client, |c| {
                let mut call = Call::new(SceneKind::Nearest, &group, options)?;
                call.request.k = k;
                call.run(c, rows, capacity, summary)
            })
        }
    })
}

/// A question asked at every step of a candidate motion, without moving
/// anything on the server: `poses` holds `step_count * moving_count` poses,
/// `poses[s * moving_count + i]` the pose of `moving[i]` at step `s`.
/// `question` is a `gjkd_path_question`; `margin` applies to
/// `GJKD_PATH_WITHIN` and `GJKD_PATH_FIRST_HIT`. Rows carry their step.
///
/// Errors: as `gjkd_within()`, plus `GJKD_ERR_NULL_POINTER` (`moving`,
/// `poses` with non-zero counts), `GJKD_ERR_INVALID_ARGUMENT` (a
/// `question` that is no `gjkd_path_question`, no moving object or no
/// step, a pose that is not finite or not a unit quaternion: nothing is
/// sent), `GJKD_CODE_BATCH_TOO_LARGE` (the group's members and allowed
/// pairs plus one step's poses exceed the server's `max_batch`; a longer
/// path is split into several requests by this library and answered
/// whole).
///
/// # Safety
/// As `gjkd_clearance()`; `moving` and `poses` NULL or pointing to their
/// counts.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gjkd_path(
    client: *mut gjkd_client,
    group: *const gjkd_group,
    question: u32,
    margin: f64,
    moving: *const gjkd_id,
    moving_count: usize,
    poses: *const gjkd_pose,
    step_count: usize,
    options: *const gjkd_scene_options,
    rows: *mut gjkd_scene_row,
    capacity: usize,
    summary: *mut gjkd_scene_summary,
) -> gjkd_status {
    guard("gjkd_path", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let (kind, mode) = path_question(question)?;
                if moving_count == 0 || step_count == 0 {
                    return Err(Failure::invalid("a path needs a moving object and a step"));
                }
                let total = moving_count
                    .checked_mul(step_count)
                    .ok_or_else(|| Failure::invalid("step_count * moving_count overflows"))?;
                let mut call = Call::new(kind, group, options)?;
                call.request.path = mode as u32;
                call.request.margin = if kind == SceneKind::Within {
                    margin
                } else {
                    call.request.margin
                };
                call.moving = slice(moving, moving_count, "moving")?;
                call.poses = slice(poses, total, "poses")?;
                call.run(c, rows, capacity, summary)
            })
        }
    })
}

/// `gjkd_path()` along a motion given as joint positions of `robot`:
/// `positions` holds `step_count` steps of the robot's moving joints
/// (`dof` doubles each, in `gjkd_robot_joint()` order), `positions[s * dof
/// + j]` joint `j` at step `s`. The server places the links by forward
/// kinematics at each step and answers there; nothing moves on the server
/// (the robot's stored joints and link poses stay as they were). A position
/// outside its limits is refused, or moved to the nearest limit when
/// `options->clamp` is true. The group is usually the robot itself
/// (`group->id` its id, so that its allowed pairs apply).
///
/// Errors: as `gjkd_path()` (`GJKD_ERR_NULL_POINTER` for `positions` and
/// `robot`), plus `GJKD_ERR_INVALID_ARGUMENT` for a robot without moving
/// joints, no step, or a position NaN or infinite (last error code
/// `GJKD_CODE_NON_FINITE_POSE`) or outside its limits without clamp
/// (`GJKD_CODE_OUT_OF_LIMITS`), the message naming the step and joint:
/// nothing is sent; `GJKD_ERR_REJECTED` with `GJKD_CODE_UNKNOWN_OBJECT`
/// when the robot is gone from the server.
///
/// # Safety
/// As `gjkd_clearance()`; `robot` NULL or live; `positions` NULL or
/// `step_count * dof` doubles.
#[cfg(feature = "robots")]
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gjkd_path_joints(
    client: *mut gjkd_client,
    group: *const gjkd_group,
    question: u32,
    margin: f64,
    robot: *const gjkd_robot,
    positions: *const f64,
    step_count: usize,
    options: *const gjkd_scene_options,
    rows: *mut gjkd_scene_row,
    capacity: usize,
    summary: *mut gjkd_scene_summary,
) -> gjkd_status {
    guard("gjkd_path_joints", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let (kind, mode) = path_question(question)?;
                let r = robot.as_ref().ok_or_else(|| Failure::null("robot"))?;
                if step_count == 0 {
                    return Err(Failure::invalid("a path needs a step"));
                }
                let total = r
                    .dof()
                    .checked_mul(step_count)
                    .ok_or_else(|| Failure::invalid("step_count * dof overflows"))?;
                let positions = slice(positions, total, "positions")?;
                let mut call = Call::new(kind, group, options)?;
                call.request.path = mode as u32;
                if kind == SceneKind::Within {
                    call.request.margin = margin;
                }
                let clamp = call.request.flags & scene_flags::CLAMP != 0;
                call.joints = Some(path_steps(r, positions, clamp)?);
                call.run(c, rows, capacity, summary)
            })
        }
    })
}

/// The scene question and path mode of a `gjkd_path_question` value.
fn path_question(question: u32) -> Result<(SceneKind, PathMode), Failure> {
    match question {
        0 => Ok((SceneKind::Clearance, PathMode::EveryStep)),
        1 => Ok((SceneKind::Within, PathMode::EveryStep)),
        2 => Ok((SceneKind::Within, PathMode::FirstHit)),
        3 => Ok((SceneKind::Within, PathMode::Continuous)),
        _ => Err(Failure::invalid("question is no gjkd_path_question")),
    }
}
