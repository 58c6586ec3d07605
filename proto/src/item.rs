//! One item of a query request (a pose update, a pair query, a joint
//! update, or a part of a scene request) and the query options it carries.

use iceoryx2::prelude::ZeroCopySend;
use nalgebra::Isometry3;

use crate::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_TOLERANCE, ItemBody, JOINTS_PER_ITEM, JointsBody, ObjectId,
    PairBody, Pose,
};

/// What an [`Item`] asks for; the wire values of [`Item::kind`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum ItemKind {
    /// Store a new pose for an object (used by every later query that does not
    /// give its own pose).
    SetPose = 1,
    /// Distance between two objects.
    Distance = 2,
    /// Set a robot's joint positions (and optionally its base pose): the
    /// server computes every link's pose by forward kinematics and stores
    /// them. See [`Item::set_joints`] for the layout.
    SetJoints = 3,
    /// Scene requests only: object `a` is a member of the request's group
    /// (when [`SceneRequest::group`](crate::SceneRequest::group) is 0).
    Member = 4,
    /// Scene requests only: the pair `a`, `b` is never reported (an allowed
    /// pair, on top of a robot's own).
    Allow = 5,
    /// Scene requests only: ends one step of a path.
    Step = 6,
}

impl ItemKind {
    /// The kind with wire value `raw`, if any.
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(ItemKind::SetPose),
            2 => Some(ItemKind::Distance),
            3 => Some(ItemKind::SetJoints),
            4 => Some(ItemKind::Member),
            5 => Some(ItemKind::Allow),
            6 => Some(ItemKind::Step),
            _ => None,
        }
    }
}

/// Bits of [`Item::flags`].
pub mod item_flags {
    /// The item's own `pose_a` replaces the stored pose of object A for this
    /// query only.
    pub const POSE_A: u32 = 1;
    /// The item's own `pose_b` replaces the stored pose of object B for this
    /// query only.
    pub const POSE_B: u32 = 1 << 1;
    /// `margin` is set: stop early once the distance is proved above or below
    /// it.
    pub const MARGIN: u32 = 1 << 2;
    /// Start from the server's cached simplex of this pair (for this client).
    pub const WARM_START: u32 = 1 << 3;
    /// Search support points in f32 ([`Precision::Single`](crate::Precision::Single)).
    pub const SINGLE_PRECISION: u32 = 1 << 4;
    /// For [`super::ItemKind::SetJoints`]: clamp positions outside their
    /// limits instead of refusing the item.
    pub const CLAMP: u32 = 1 << 5;
    /// Scene paths only: a [`super::ItemKind::SetPose`] or
    /// [`super::ItemKind::SetJoints`] item with this bit also ends its path
    /// step, as a [`super::ItemKind::Step`] item after it would. A path's
    /// steps then take one item fewer each, which is what a long path's
    /// round trip is made of. Refused as malformed on any other item and
    /// outside a path.
    pub const END_STEP: u32 = 1 << 6;
    /// For [`super::ItemKind::Distance`]: also answer the signed distance
    /// (negative inside, the penetration depth by an expanding polytope)
    /// with its certified interval, in
    /// [`ItemResult::signed_distance`](crate::ItemResult::signed_distance)
    /// and the two fields after it. Costs nothing for a pair the distance
    /// query proves apart.
    pub const SIGNED_DISTANCE: u32 = 1 << 7;
    /// [`super::ItemKind::Distance`]: also the distance's gradient with
    /// respect to the coordinates that move object A (see
    /// [`Gradient`](crate::Gradient)).
    pub const GRADIENT: u32 = 1 << 8;
    /// With [`GRADIENT`], when A is a robot link: the base pose's twist
    /// too, in the gradient's last 6 columns.
    pub const GRADIENT_BASE: u32 = 1 << 9;
    /// Every bit this version knows; others are rejected as malformed.
    pub const ALL: u32 = POSE_A
        | POSE_B
        | MARGIN
        | WARM_START
        | SINGLE_PRECISION
        | CLAMP
        | END_STEP
        | SIGNED_DISTANCE
        | GRADIENT
        | GRADIENT_BASE;
}

/// Per-query options, the client-side view of [`Item`]'s option fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryOptions {
    /// Relative tolerance `ε` of the stopping rule, `>= 0` (default
    /// [`DEFAULT_TOLERANCE`]). Larger is faster and looser; the answer's bounds
    /// say by how much.
    pub tolerance: f64,
    /// Iteration cap, at least 1 (default [`DEFAULT_MAX_ITERATIONS`]).
    pub max_iterations: u32,
    /// Early exit: stop as soon as the distance is proved greater than this
    /// margin ([`Status::Farther`](crate::Status::Farther)) or at most it ([`Status::Closer`](crate::Status::Closer)).
    pub margin: Option<f64>,
    /// Start from the simplex the server kept for this pair after this
    /// client's previous query of it (default on). Changes only the time,
    /// never the answer beyond the tolerance.
    pub warm_start: bool,
    /// Arithmetic of the support search (default [`Precision::Double`]).
    pub precision: Precision,
    /// Also answer the signed distance with its certified interval
    /// ([`Answer::signed`](crate::Answer::signed)); default off. With a
    /// margin, a pair proved farther keeps the margin's interval (its
    /// signed distance is its distance); the others are answered in full.
    pub signed_distance: bool,
}

/// Arithmetic of the support search, the step whose cost grows with the
/// number of vertices; the rest of a query is f64 whatever is chosen. The
/// wire form of `gjk::Precision`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// f64: the distance is exact to the tolerance.
    #[default]
    Double,
    /// f32 for objects of 16 to 1 023 vertices: faster on a few hundred
    /// (about 1.17× at 256 vertices, up to 1.26× at 512), the distance exact
    /// to the tolerance plus about 1e-6 of the two objects' sizes, bounds
    /// still certified. Larger objects use the exact block search either way.
    Single,
}

impl Default for QueryOptions {
    fn default() -> Self {
        QueryOptions {
            tolerance: DEFAULT_TOLERANCE,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            margin: None,
            warm_start: true,
            precision: Precision::Double,
            signed_distance: false,
        }
    }
}

impl QueryOptions {
    /// Defaults with warm start off: every query starts cold.
    pub fn cold() -> Self {
        QueryOptions {
            warm_start: false,
            ..Self::default()
        }
    }
}

/// One item of a query request: a pose update, a pair query or a joint
/// update. A request is a slice of items, answered by a slice of
/// [`ItemResult`](crate::ItemResult)s of the same length, in the same
/// order; items are applied in order, so a pose update affects the queries
/// after it in the same batch.
///
/// The header (`kind`, `flags`, `a`, `b`, `pose_a`) is common to every
/// kind; the [`body`](Item::body) is a pair query's pose of B and options
/// ([`Item::pair`]) or a joint update's positions ([`Item::joints`]), two
/// views of the same bytes. Build items with [`Item::set_pose`],
/// [`Item::distance`] and [`Item::set_joints`].
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.Item")]
pub struct Item {
    /// [`ItemKind`] wire value.
    pub kind: u32,
    /// [`item_flags`] bits.
    pub flags: u32,
    /// Object A: the object whose pose is set ([`ItemKind::SetPose`]), the
    /// first of a pair, the robot ([`ItemKind::SetJoints`]).
    pub a: u64,
    /// Object B of a pair; zero for the other kinds.
    pub b: u64,
    /// Pose of A: the new stored pose for [`ItemKind::SetPose`]; this
    /// query's pose of A with [`item_flags::POSE_A`]; the robot's new base
    /// pose for [`ItemKind::SetJoints`] with [`item_flags::POSE_A`].
    pub pose_a: Pose,
    /// The kind's own fields: [`PairBody`] for every kind but
    /// [`ItemKind::SetJoints`], whose body is a [`JointsBody`].
    pub body: ItemBody,
}

impl Item {
    /// Store `pose` as the pose of object `id`.
    pub fn set_pose(id: ObjectId, pose: &Isometry3<f64>) -> Self {
        Item {
            kind: ItemKind::SetPose as u32,
            flags: 0,
            a: id.raw(),
            b: 0,
            pose_a: Pose::from_isometry(pose),
            body: ItemBody {
                pair: PairBody {
                    pose_b: Pose::IDENTITY,
                    tolerance: DEFAULT_TOLERANCE,
                    margin: 0.0,
                    max_iterations: DEFAULT_MAX_ITERATIONS,
                    reserved: 0,
                },
            },
        }
    }

    /// Distance between `a` and `b` at their stored poses.
    pub fn distance(a: ObjectId, b: ObjectId, options: &QueryOptions) -> Self {
        let mut flags = 0;
        if options.warm_start {
            flags |= item_flags::WARM_START;
        }
        if options.margin.is_some() {
            flags |= item_flags::MARGIN;
        }
        if options.precision == Precision::Single {
            flags |= item_flags::SINGLE_PRECISION;
        }
        if options.signed_distance {
            flags |= item_flags::SIGNED_DISTANCE;
        }
        Item {
            kind: ItemKind::Distance as u32,
            flags,
            a: a.raw(),
            b: b.raw(),
            pose_a: Pose::IDENTITY,
            body: ItemBody {
                pair: PairBody {
                    pose_b: Pose::IDENTITY,
                    tolerance: options.tolerance,
                    margin: options.margin.unwrap_or(0.0),
                    max_iterations: options.max_iterations,
                    reserved: 0,
                },
            },
        }
    }

    /// Distance between `a` at `pose_a` and `b` at `pose_b`, leaving the
    /// stored poses alone.
    pub fn distance_at(
        a: ObjectId,
        pose_a: &Isometry3<f64>,
        b: ObjectId,
        pose_b: &Isometry3<f64>,
        options: &QueryOptions,
    ) -> Self {
        Self::distance(a, b, options)
            .with_pose_a(pose_a)
            .with_pose_b(pose_b)
    }

    /// This query with its own pose for A.
    pub fn with_pose_a(mut self, pose: &Isometry3<f64>) -> Self {
        self.flags |= item_flags::POSE_A;
        self.pose_a = Pose::from_isometry(pose);
        self
    }

    /// This query with its own pose for B.
    pub fn with_pose_b(mut self, pose: &Isometry3<f64>) -> Self {
        self.flags |= item_flags::POSE_B;
        self.pair_mut().pose_b = Pose::from_isometry(pose);
        self
    }

    /// Set joint positions `first .. first + positions.len()` of `robot`
    /// (in the robot's joint order: its URDF's moving joints, see
    /// `gjkd_model::kinematics`), and its base pose if `base` is given; the
    /// server then stores every link's pose, computed by forward kinematics.
    /// With `clamp`, positions outside their limits are clamped, otherwise
    /// the item fails with [`ErrorCode::OutOfLimits`](crate::ErrorCode::OutOfLimits) and changes nothing.
    ///
    /// Layout: `a` is the robot, `b` zero, the body a [`JointsBody`];
    /// flag [`item_flags::POSE_A`] sends a base pose in `pose_a`. A robot
    /// with more joints takes several items in one request (each computes
    /// the poses; only the last one's matter).
    ///
    /// # Panics
    /// If `positions` is longer than [`JOINTS_PER_ITEM`].
    pub fn set_joints(
        robot: ObjectId,
        first: u32,
        positions: &[f64],
        base: Option<&Isometry3<f64>>,
        clamp: bool,
    ) -> Self {
        assert!(
            positions.len() <= JOINTS_PER_ITEM,
            "one item carries 0 to {JOINTS_PER_ITEM} joint positions"
        );
        let mut values = [0.0; JOINTS_PER_ITEM];
        values[..positions.len()].copy_from_slice(positions);
        let mut item = Item {
            kind: ItemKind::SetJoints as u32,
            flags: if clamp { item_flags::CLAMP } else { 0 },
            a: robot.raw(),
            b: 0,
            pose_a: Pose::IDENTITY,
            body: ItemBody {
                joints: JointsBody {
                    positions: values,
                    count: positions.len() as u32,
                    first,
                },
            },
        };
        if let Some(base) = base {
            item.flags |= item_flags::POSE_A;
            item.pose_a = Pose::from_isometry(base);
        }
        item
    }

    /// The joint positions in use of a [`ItemKind::SetJoints`] item, `None`
    /// if its count is out of range.
    pub fn joint_positions(&self) -> Option<&[f64]> {
        let joints = self.joints();
        joints.positions.get(..joints.count as usize)
    }

    /// The body's pair view: a pair query's pose of B and options (see
    /// [`ItemBody`] for why reading it from any item is sound).
    #[inline(always)]
    pub fn pair(&self) -> &PairBody {
        self.body.pair()
    }

    /// The body's pair view, to change.
    #[inline(always)]
    pub fn pair_mut(&mut self) -> &mut PairBody {
        self.body.pair_mut()
    }

    /// The body's joints view: a joint update's positions.
    #[inline(always)]
    pub fn joints(&self) -> &JointsBody {
        self.body.joints()
    }

    /// The body's joints view, to change.
    #[inline(always)]
    pub fn joints_mut(&mut self) -> &mut JointsBody {
        self.body.joints_mut()
    }

    /// A scene request's group member (see [`ItemKind::Member`]).
    pub fn member(id: ObjectId) -> Self {
        Item {
            kind: ItemKind::Member as u32,
            a: id.raw(),
            ..Item::set_pose(id, &Isometry3::identity())
        }
    }

    /// A scene request's allowed pair (see [`ItemKind::Allow`]).
    pub fn allow(a: ObjectId, b: ObjectId) -> Self {
        Item {
            kind: ItemKind::Allow as u32,
            b: b.raw(),
            ..Item::member(a)
        }
    }

    /// This pose or joint item, also ending its path step (see
    /// [`item_flags::END_STEP`]).
    #[must_use]
    pub fn ending_step(mut self) -> Self {
        self.flags |= item_flags::END_STEP;
        self
    }

    /// The end of a path step in a scene request (see [`ItemKind::Step`]).
    pub fn step() -> Self {
        Item {
            kind: ItemKind::Step as u32,
            a: 0,
            ..Item::member(ObjectId(0))
        }
    }

    /// The kind, if it is one this version knows.
    pub fn item_kind(&self) -> Option<ItemKind> {
        ItemKind::from_raw(self.kind)
    }

    /// Object A.
    pub fn object_a(&self) -> ObjectId {
        ObjectId(self.a)
    }

    /// Object B.
    pub fn object_b(&self) -> ObjectId {
        ObjectId(self.b)
    }

    /// The options encoded in this item.
    pub fn options(&self) -> QueryOptions {
        let pair = self.pair();
        QueryOptions {
            tolerance: pair.tolerance,
            max_iterations: pair.max_iterations,
            margin: (self.flags & item_flags::MARGIN != 0).then_some(pair.margin),
            warm_start: self.flags & item_flags::WARM_START != 0,
            precision: if self.flags & item_flags::SINGLE_PRECISION != 0 {
                Precision::Single
            } else {
                Precision::Double
            },
            signed_distance: self.flags & item_flags::SIGNED_DISTANCE != 0,
        }
    }
}
