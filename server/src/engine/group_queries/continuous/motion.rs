//! Certified motion bounds along one segment of a continuous path: for
//! each object the path moves, its pose at any `s` and an upper bound on
//! how fast any of its points moves with `s` (Schwarzer, Saha and
//! Latombe's bound), so that `rate * (s1 - s0)` bounds how far any point
//! moves between `s0` and `s1`.
//!
//! - A rigid object whose translation moves linearly and whose rotation
//!   turns about a fixed axis at a constant rate (slerp): a point at
//!   distance `r` from the body origin moves at most
//!   `|Δt| + θ r` over the segment, `θ` the rotation's angle.
//! - With the quaternion's components linear in `s` (renormalised), the
//!   rotation still turns about a fixed axis, at the rate
//!   `2 |q1 - q0| / |q(s)|`, largest where `|q(s)|` is least.
//! - A robot's link, joints linear in `s`: each joint `j` between the root
//!   and the link adds `|Δq_j|` times its lever arm (revolute: the largest
//!   distance from its axis to a point of the link, bounded by the joint
//!   offsets down the chain, prismatic extents included, plus the link's
//!   reach from its own frame; prismatic: 1), and a moving base adds its
//!   own rigid bound with the link's distance from the root frame.
//!
//! A rigid mover's bound splits into its translation (a velocity, known
//! in direction) and its turning, so that a pair's separation along a
//! direction `n` changes no faster than `|Δt·n|` plus the turning: a motion
//! parallel to a separating face is cleared at once, however near.
//!
//! Every pose is computed in floating point: each object also carries a
//! `slack`, how far a computed pose's points may lie from the exact
//! motion's, which every certified interval is widened by.

use gjk::Shape;
use gjkd_model::{JointKind, JointSource, Kinematics, LimitMode};
use gjkd_proto::ErrorCode;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, Unit, UnitQuaternion, Vector3};

use super::super::broadphase::Broadphase;
use super::super::entry::ROUND_OFF;
use super::waypoints::Waypoints;
use crate::engine::objects::ObjectStore;
use crate::engine::robots::{Robots, joint_code};

/// A quaternion path whose norm comes this close to 0 turns through an
/// undefined rotation.
const LEAST_QUATERNION_NORM: f64 = 1e-6;

/// The pose at `s` of a rigid motion from `from` to `to`: translation
/// linear, rotation along the shortest arc, or with `linear`, the
/// quaternion's components linear and renormalised.
pub(crate) fn interpolate(
    from: &Isometry3<f64>,
    to: &Isometry3<f64>,
    s: f64,
    linear: bool,
) -> Isometry3<f64> {
    let t = from.translation.vector + (to.translation.vector - from.translation.vector) * s;
    let rotation = if linear {
        let q = from.rotation.coords * (1.0 - s) + to.rotation.coords * s;
        UnitQuaternion::from_quaternion(Quaternion::from(q))
    } else {
        from.rotation
            .try_slerp(&to.rotation, s, 1e-9)
            .unwrap_or_else(|| aligned_nlerp(&from.rotation, &to.rotation, s))
    };
    Isometry3::from_parts(Translation3::from(t), rotation)
}

/// The normalised linear interpolation along the shorter arc (the same
/// great circle as slerp's, for rotations too near for slerp's formula).
fn aligned_nlerp(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>, s: f64) -> UnitQuaternion<f64> {
    let b = if a.coords.dot(&b.coords) < 0.0 {
        -b.coords
    } else {
        b.coords
    };
    UnitQuaternion::from_quaternion(Quaternion::from(a.coords * (1.0 - s) + b * s))
}

/// The angle of the rotation from `a` to `b` along the shortest arc,
/// rounded up; accurate for small angles too (no `acos`).
fn turn_angle(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
    let relative = b * a.inverse();
    let angle = 2.0 * relative.imag().norm().atan2(relative.w.abs());
    angle * (1.0 + ROUND_OFF) + 4.0 * f64::EPSILON
}

/// The turning part of the speed bound of a rigid motion for a point
/// `reach` from the body origin (the translation's part is `|Δt|`).
fn rigid_spin(
    from: &Isometry3<f64>,
    to: &Isometry3<f64>,
    reach: f64,
    linear: bool,
) -> Result<f64, ErrorCode> {
    let turning = if linear {
        let (q0, d) = (
            from.rotation.coords,
            to.rotation.coords - from.rotation.coords,
        );
        let dd = d.norm_squared();
        let s = if dd > 0.0 {
            (-q0.dot(&d) / dd).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let least = (q0 + d * s).norm() * (1.0 - ROUND_OFF);
        if least < LEAST_QUATERNION_NORM {
            return Err(ErrorCode::BadQuaternion);
        }
        2.0 * d.norm() / least
    } else {
        turn_angle(&from.rotation, &to.rotation)
    };
    Ok(turning * reach)
}

/// Where the pose of a moving object comes from.
#[derive(Clone, Copy, Debug)]
enum Source {
    /// A rigid motion between two poses.
    Rigid {
        from: Isometry3<f64>,
        to: Isometry3<f64>,
    },
    /// Link `link` of the segment's robot `robot`.
    Link { robot: usize, link: usize },
}

/// One object the path moves (or holds still along this segment).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Mover {
    /// Its broadphase slot.
    pub slot: u32,
    source: Source,
    /// Bound on how fast any of its points moves with `s`; 0 for an object
    /// still along this segment.
    pub rate: f64,
    /// How far a computed pose's points may lie from the exact motion's.
    pub slack: f64,
    /// A rigid mover's translation along the segment (its points'
    /// velocity less their turning), zero for a link.
    pub drift: Vector3<f64>,
    /// `rate` less `|drift|`: the part of a point's speed in no known
    /// direction.
    pub spin: f64,
}

impl Mover {
    /// An object that stays where it is, `slack` its pose's round-off.
    pub(crate) fn still(slot: u32, slack: f64) -> Self {
        Mover {
            slot,
            source: Source::Rigid {
                from: Isometry3::identity(),
                to: Isometry3::identity(),
            },
            rate: 0.0,
            slack,
            drift: Vector3::zeros(),
            spin: 0.0,
        }
    }
}

/// One robot along the segment, and its last forward kinematics.
#[derive(Debug)]
struct RobotMotion<'a> {
    kinematics: &'a Kinematics,
    q0: &'a [f64],
    q1: &'a [f64],
    base0: Isometry3<f64>,
    base1: Isometry3<f64>,
    /// The `s` of `poses` (NaN: none yet).
    at: f64,
    poses: Vec<Isometry3<f64>>,
    q: Vec<f64>,
    /// Per link, the joints from the root down to it: a pair needs one
    /// link's pose at each `s`, and the links below it cost as much again.
    /// Link `l`'s are `chains[starts[l]..starts[l + 1]]` (two allocations
    /// a segment, not one a link).
    chains: Vec<usize>,
    starts: Vec<usize>,
    /// Each position's limits (the order of `q0`).
    limits: Vec<(f64, f64)>,
}

impl<'a> RobotMotion<'a> {
    fn new(
        kinematics: &'a Kinematics,
        (q0, q1): (&'a [f64], &'a [f64]),
        (base0, base1): (Isometry3<f64>, Isometry3<f64>),
        parent_joint: &[Option<usize>],
    ) -> Self {
        let joints = kinematics.joints();
        let mut chains = Vec::new();
        let mut starts = Vec::with_capacity(parent_joint.len() + 1);
        for link in 0..parent_joint.len() {
            let start = chains.len();
            starts.push(start);
            let mut l = link;
            while let Some(j) = parent_joint[l] {
                chains.push(j);
                l = joints[j].parent;
            }
            chains[start..].reverse();
        }
        starts.push(chains.len());
        RobotMotion {
            kinematics,
            q0,
            q1,
            base0,
            base1,
            at: f64::NAN,
            poses: Vec::new(),
            q: Vec::new(),
            chains,
            starts,
            limits: kinematics
                .moving_joints()
                .map(|j| (j.lower, j.upper))
                .collect(),
        }
    }

    fn poses_at(&mut self, s: f64) -> Result<&[Isometry3<f64>], ErrorCode> {
        if self.at != s {
            self.q.clear();
            self.q
                .extend(self.q0.iter().zip(self.q1).map(|(a, b)| a + (b - a) * s));
            let base = interpolate(&self.base0, &self.base1, s, false);
            // Positions between two in-limit ends are in limits; clamping
            // only absorbs the last bit of round-off.
            self.kinematics
                .link_poses_into(&base, &mut self.q, LimitMode::Clamp, &mut self.poses)
                .map_err(joint_code)?;
            self.at = s;
        }
        Ok(&self.poses)
    }

    /// Link `link`'s pose at `s`: the arithmetic of [`Self::poses_at`] for
    /// its chain alone, less the products with identities (within the
    /// poses' round-off `slack` of it).
    fn link_pose_at(&self, link: usize, s: f64) -> Isometry3<f64> {
        if self.at == s {
            return self.poses[link];
        }
        let position = |k: usize| {
            let (lo, hi) = self.limits[k];
            (self.q0[k] + (self.q1[k] - self.q0[k]) * s).clamp(lo, hi)
        };
        let joints = self.kinematics.joints();
        // A base that stays needs no slerp (most robots' bases stay).
        let mut pose = if self.base0 == self.base1 {
            self.base0
        } else {
            interpolate(&self.base0, &self.base1, s, false)
        };
        for &j in &self.chains[self.starts[link]..self.starts[link + 1]] {
            let joint = &joints[j];
            // A fixed joint's motion is the identity: its origin alone.
            if joint.kind == JointKind::Fixed {
                pose *= joint.origin;
                continue;
            }
            let q = match joint.source {
                JointSource::Fixed => 0.0,
                JointSource::Moving(k) => position(k),
                JointSource::Mimic {
                    index,
                    multiplier,
                    offset,
                } => multiplier * position(index) + offset,
            };
            pose = pose * joint.origin * joint.motion(q);
        }
        pose
    }
}

/// Everything that moves along one segment, with its bounds.
#[derive(Debug)]
pub(crate) struct Segment<'a> {
    store: &'a ObjectStore,
    bp: &'a Broadphase,
    robots: Vec<RobotMotion<'a>>,
    /// The path's objects, moving along this segment or not.
    pub movers: Vec<Mover>,
    linear: bool,
}

impl<'a> Segment<'a> {
    /// Segment `k` (waypoint `k` to `k + 1`) of `w`; `linear` as
    /// [`interpolate`]'s.
    ///
    /// # Errors
    /// [`ErrorCode::BadQuaternion`] for linear quaternions whose path
    /// passes through 0; [`ErrorCode::UnknownObject`] for a robot gone.
    pub(crate) fn new(
        store: &'a ObjectStore,
        robots: &'a Robots,
        bp: &'a Broadphase,
        w: &'a Waypoints,
        k: usize,
        linear: bool,
    ) -> Result<Self, ErrorCode> {
        let mut movers = Vec::new();
        for r in &w.rigid {
            let (from, to) = (r.poses[k], r.poses[k + 1]);
            let e = bp.entry(r.slot);
            let drift = to.translation.vector - from.translation.vector;
            let spin = if from.rotation == to.rotation {
                0.0
            } else {
                rigid_spin(&from, &to, e.reach, linear)? * (1.0 + 4.0 * ROUND_OFF)
            };
            let rate = (drift.norm() + spin) * (1.0 + 4.0 * ROUND_OFF);
            let t = from.translation.vector.abs().sum() + to.translation.vector.abs().sum();
            movers.push(Mover {
                slot: r.slot,
                source: Source::Rigid { from, to },
                rate,
                slack: ROUND_OFF * (t + e.reach) + f64::MIN_POSITIVE,
                drift,
                spin,
            });
        }
        let mut motions = Vec::with_capacity(w.robots.len());
        for (i, way) in w.robots.iter().enumerate() {
            let robot = robots.get(way.id).ok_or(ErrorCode::UnknownObject)?;
            let parent_joint = parent_joints(&robot.kinematics);
            let mut motion = RobotMotion::new(
                &robot.kinematics,
                (way.at(k), way.at(k + 1)),
                (way.bases[k], way.bases[k + 1]),
                &parent_joint,
            );
            link_movers(&mut motion, bp, &robot.links, &parent_joint, i, &mut movers)?;
            motions.push(motion);
        }
        Ok(Segment {
            store,
            bp,
            robots: motions,
            movers,
            linear,
        })
    }

    /// The pose at `s` of mover `i`.
    ///
    /// # Errors
    /// [`ErrorCode::NonFinitePose`] if forward kinematics fails (never
    /// expected: both ends were checked).
    pub(crate) fn pose(&mut self, i: usize, s: f64) -> Result<Isometry3<f64>, ErrorCode> {
        match self.movers[i].source {
            Source::Rigid { from, to } => Ok(interpolate(&from, &to, s, self.linear)),
            Source::Link { robot, link } => Ok(self.robots[robot].link_pose_at(link, s)),
        }
    }

    /// Computes every robot's links at `s` at once, for the many pairs
    /// about to ask their poses there.
    ///
    /// # Errors
    /// As [`Self::pose`].
    pub(crate) fn prepare(&mut self, s: f64) -> Result<(), ErrorCode> {
        for robot in &mut self.robots {
            robot.poses_at(s)?;
        }
        Ok(())
    }

    /// The shape of the object in `slot`.
    pub(crate) fn shape(&self, slot: u32) -> Option<&'a Shape> {
        self.store
            .object(self.bp.entry(slot).id)
            .map(|object| &object.shape)
    }
}

/// The distance from `p` to the axis of a joint whose child frame is
/// `frame` (the axis `axis` in that frame, through its origin).
fn axis_distance(frame: &Isometry3<f64>, axis: &Unit<Vector3<f64>>, p: &Point3<f64>) -> f64 {
    (p - Point3::from(frame.translation.vector))
        .cross(&(frame.rotation * axis.into_inner()))
        .norm()
}

/// A joint's position change over the segment and the largest absolute
/// position at either end (a prismatic joint's offset).
fn joint_motion(source: &JointSource, q0: &[f64], q1: &[f64]) -> (f64, f64) {
    match *source {
        JointSource::Fixed => (0.0, 0.0),
        JointSource::Moving(k) => ((q1[k] - q0[k]).abs(), q0[k].abs().max(q1[k].abs())),
        JointSource::Mimic {
            index,
            multiplier,
            offset,
        } => (
            (multiplier * (q1[index] - q0[index])).abs(),
            (multiplier * q0[index] + offset)
                .abs()
                .max((multiplier * q1[index] + offset).abs()),
        ),
    }
}

/// The forward kinematics of a segment's robot at both ends.
pub(crate) struct EndPoses<'p> {
    /// Every link's frame at `s = 0`.
    pub start: &'p [Isometry3<f64>],
    /// Every link's frame at `s = 1`.
    pub end: &'p [Isometry3<f64>],
}

/// One robot link's bounding sphere: its centre in the link's frame and
/// the largest distance of a point from it, and its largest distance from
/// the link's frame origin.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LinkBall {
    /// The sphere's centre in the link frame.
    pub centre: Point3<f64>,
    /// Its radius.
    pub extent: f64,
    /// The largest distance of a point from the link frame's origin.
    pub reach: f64,
}

/// Bounds on how fast any point of `link`'s ball moves with `s` when the
/// joints go linearly from `q0` to `q1` (the base still), and the
/// round-off of its computed pose.
///
/// A revolute joint moves a point at `|Δq|` times the point's distance
/// from its axis. That distance is known at both ends from `ends`; in
/// between it changes no faster than the link moves relative to the
/// joint's frame, which is what the joints nearer the link contribute
/// (summed first, walking from the link up), so over the segment it is at
/// most the mean of the two ends plus half that rate. The chain's lengths
/// (every configuration's bound) cap it where they are smaller.
pub(crate) fn link_rate(
    kinematics: &Kinematics,
    parent_joint: &[Option<usize>],
    (q0, q1): (&[f64], &[f64]),
    ends: &EndPoses<'_>,
    link: usize,
    ball: &LinkBall,
) -> LinkRate {
    let joints = kinematics.joints();
    // First pass: the chain's length and depth, which bound the computed
    // poses' round-off.
    let (mut chain, mut depth) = (ball.reach, 1.0);
    let mut l = link;
    while let Some(j) = parent_joint[l] {
        let joint = &joints[j];
        if joint.kind == JointKind::Prismatic {
            chain += joint_motion(&joint.source, q0, q1).1;
        }
        chain += joint.origin.translation.vector.norm();
        depth += 1.0;
        l = joint.parent;
    }
    // How far a computed distance to an axis may be from the exact one:
    // both frames' round-off, with room to spare.
    let base_t = ends.start[kinematics.root()].translation.vector.abs().sum()
        + ends.end[kinematics.root()].translation.vector.abs().sum();
    let slack = ROUND_OFF * depth * (base_t + chain) + f64::MIN_POSITIVE;
    let (c0, c1) = (ends.start[link] * ball.centre, ends.end[link] * ball.centre);
    // `arm` bounds the distance of the link's points from the frame of the
    // joint reached so far, whatever the configuration.
    let mut arm = ball.reach;
    let mut rate = 0.0;
    let mut l = link;
    while let Some(j) = parent_joint[l] {
        let joint = &joints[j];
        let (dq, most) = joint_motion(&joint.source, q0, q1);
        match joint.kind {
            JointKind::Revolute | JointKind::Continuous => {
                let d0 = axis_distance(&ends.start[joint.child], &joint.axis, &c0);
                let d1 = axis_distance(&ends.end[joint.child], &joint.axis, &c1);
                let lever =
                    (0.5 * (d0 + d1 + rate) + ball.extent) * (1.0 + 8.0 * ROUND_OFF) + 8.0 * slack;
                rate += dq * lever.min(arm);
            }
            JointKind::Prismatic => {
                rate += dq;
                arm += most;
            }
            JointKind::Fixed => {}
        }
        arm += joint.origin.translation.vector.norm();
        l = joint.parent;
    }
    LinkRate {
        rate: rate * (1.0 + 4.0 * depth * ROUND_OFF),
        arm,
        slack,
    }
}

/// A link's bounds from [`link_rate`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct LinkRate {
    /// Bound on how fast any point of the link moves with `s`, the base
    /// still.
    pub rate: f64,
    /// Bound on the distance of any point of the link from the root frame.
    pub arm: f64,
    /// How far its computed pose's points may lie from the exact ones.
    pub slack: f64,
}

/// Every link's parent joint.
fn parent_joints(kinematics: &Kinematics) -> Vec<Option<usize>> {
    let mut parent_joint = vec![None; kinematics.link_names().len()];
    for (j, joint) in kinematics.joints().iter().enumerate() {
        parent_joint[joint.child] = Some(j);
    }
    parent_joint
}

/// Adds the movers of `robot`'s links (segment robot `index`), with their
/// lever-arm bounds.
///
/// # Errors
/// As [`RobotMotion::poses_at`].
fn link_movers(
    motion: &mut RobotMotion<'_>,
    bp: &Broadphase,
    links: &[Option<u64>],
    parent_joint: &[Option<usize>],
    index: usize,
    movers: &mut Vec<Mover>,
) -> Result<(), ErrorCode> {
    let kinematics = motion.kinematics;
    let base_moved = (motion.base1.translation.vector - motion.base0.translation.vector).norm();
    let base_turn = if motion.base0.rotation == motion.base1.rotation {
        0.0
    } else {
        turn_angle(&motion.base0.rotation, &motion.base1.rotation)
    };
    let still = motion.q0 == motion.q1 && motion.base0 == motion.base1;
    let (q0, q1) = (motion.q0, motion.q1);
    let end = motion.poses_at(1.0)?.to_vec();
    let start = motion.poses_at(0.0)?;
    let ends = EndPoses { start, end: &end };
    for (link, id) in links.iter().enumerate() {
        let Some(slot) = id.and_then(|id| bp.slot(id)) else {
            continue;
        };
        let e = bp.entry(slot);
        let ball = LinkBall {
            centre: e.centre,
            extent: e.extent,
            reach: e.reach,
        };
        let bound = link_rate(kinematics, parent_joint, (q0, q1), &ends, link, &ball);
        let rate = bound.rate + (base_moved + base_turn * bound.arm) * (1.0 + 4.0 * ROUND_OFF);
        movers.push(Mover {
            slot,
            source: Source::Link { robot: index, link },
            rate: if still { 0.0 } else { rate },
            slack: bound.slack,
            drift: Vector3::zeros(),
            spin: if still { 0.0 } else { rate },
        });
    }
    Ok(())
}
