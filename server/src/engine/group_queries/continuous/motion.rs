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
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

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
}

impl RobotMotion<'_> {
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
            let motion = RobotMotion {
                kinematics: &robot.kinematics,
                q0: way.at(k),
                q1: way.at(k + 1),
                base0: way.bases[k],
                base1: way.bases[k + 1],
                at: f64::NAN,
                poses: Vec::new(),
                q: Vec::new(),
            };
            link_movers(&motion, bp, &robot.links, i, &mut movers);
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
            Source::Link { robot, link } => Ok(self.robots[robot].poses_at(s)?[link]),
        }
    }

    /// The shape of the object in `slot`.
    pub(crate) fn shape(&self, slot: u32) -> Option<&'a Shape> {
        self.store
            .object(self.bp.entry(slot).id)
            .map(|object| &object.shape)
    }
}

/// Adds the movers of `robot`'s links (segment robot `index`), with their
/// lever-arm bounds.
fn link_movers(
    motion: &RobotMotion<'_>,
    bp: &Broadphase,
    links: &[Option<u64>],
    index: usize,
    movers: &mut Vec<Mover>,
) {
    let kinematics = motion.kinematics;
    let joints = kinematics.joints();
    let mut parent_joint = vec![None; kinematics.link_names().len()];
    for (j, joint) in joints.iter().enumerate() {
        parent_joint[joint.child] = Some(j);
    }
    let base_moved = (motion.base1.translation.vector - motion.base0.translation.vector).norm();
    let base_turn = if motion.base0.rotation == motion.base1.rotation {
        0.0
    } else {
        turn_angle(&motion.base0.rotation, &motion.base1.rotation)
    };
    let still = motion.q0 == motion.q1 && motion.base0 == motion.base1;
    let base_t =
        motion.base0.translation.vector.abs().sum() + motion.base1.translation.vector.abs().sum();
    for (link, id) in links.iter().enumerate() {
        let Some(slot) = id.and_then(|id| bp.slot(id)) else {
            continue;
        };
        // `arm` bounds the distance of the link's points from the frame
        // of the joint reached so far.
        let mut arm = bp.entry(slot).reach;
        let mut rate = 0.0;
        let mut depth = 1.0;
        let mut l = link;
        while let Some(j) = parent_joint[l] {
            let joint = &joints[j];
            let (dq, most) = match joint.source {
                JointSource::Fixed => (0.0, 0.0),
                JointSource::Moving(k) => (
                    (motion.q1[k] - motion.q0[k]).abs(),
                    motion.q0[k].abs().max(motion.q1[k].abs()),
                ),
                JointSource::Mimic {
                    index,
                    multiplier,
                    offset,
                } => (
                    (multiplier * (motion.q1[index] - motion.q0[index])).abs(),
                    (multiplier * motion.q0[index] + offset)
                        .abs()
                        .max((multiplier * motion.q1[index] + offset).abs()),
                ),
            };
            match joint.kind {
                JointKind::Revolute | JointKind::Continuous => rate += dq * arm,
                JointKind::Prismatic => {
                    rate += dq;
                    arm += most;
                }
                JointKind::Fixed => {}
            }
            arm += joint.origin.translation.vector.norm();
            depth += 1.0;
            l = joint.parent;
        }
        rate += base_moved + base_turn * arm;
        let rate = if still {
            0.0
        } else {
            rate * (1.0 + 4.0 * depth * ROUND_OFF)
        };
        movers.push(Mover {
            slot,
            source: Source::Link { robot: index, link },
            rate,
            slack: ROUND_OFF * depth * (base_t + arm) + f64::MIN_POSITIVE,
            drift: Vector3::zeros(),
            spin: rate,
        });
    }
}
