//! Gradients of pair distances with respect to the coordinates that move
//! the pair's first object (a robot's joints and base, or a free object's
//! pose), from the witness points, the normal and the point Jacobians of
//! the forward kinematics the server already runs (GJK paper, equations
//! 2.9–2.10; the wire form and conventions are `gjkd_proto::Gradient`'s).
//! The query service's pair items and the scene service's rows share it.

mod poses;
mod witness;

use gjk::Shape;
use gjkd_model::twist_jacobian;
use gjkd_proto::{ErrorCode, GRADIENT_COLUMNS, Gradient, ItemResult, gradient_flags};
use nalgebra::{Isometry3, Point3, Vector3};

pub(crate) use poses::{LinkPoses, StepConfigurations};
pub(crate) use witness::{depth_witness, not_unique, overlap_witness, witness};

use super::robots::Robots;

/// One object of a pair, as its gradient sees it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Side<'a> {
    /// Its id.
    pub id: u64,
    /// Its shape.
    pub shape: &'a Shape,
    /// Its pose where the pair was answered.
    pub pose: &'a Isometry3<f64>,
}

/// Where a gradient's robots stand: the stored joint positions, or those a
/// path's step gives them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stance<'a> {
    /// The path's recorded steps, `None` outside a path.
    pub steps: Option<&'a StepConfigurations>,
    /// The step (0 outside a path).
    pub step: u32,
    /// The base twist's 6 columns too.
    pub base: bool,
}

/// Writes into `out` the gradient of `result`'s distance with respect to
/// the coordinates that move `a` (see `gjkd_proto::Gradient`); an
/// overlapping pair's `result.penetration` may rise to the depth's lower
/// bound found on the way. `depth` is the
/// pair's signed distance when the caller computed it (a pair that asked
/// for it and may overlap): its direction is then the gradient's, and
/// `result`'s normal (already the depth's) is not read as a distance's.
///
/// # Errors
/// [`ErrorCode::InvalidOptions`] when `a`'s robot has more coordinates
/// than [`GRADIENT_COLUMNS`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn fill(
    result: &mut ItemResult,
    out: &mut Gradient,
    a: Side<'_>,
    b: Side<'_>,
    robots: &Robots,
    cache: &mut LinkPoses,
    stance: Stance<'_>,
    depth: Option<&gjk::SignedDistance>,
) -> Result<(), ErrorCode> {
    let w = match depth {
        Some(sd) => depth_witness(result, sd),
        None => witness(result).or_else(|| overlap_witness(result, &a, &b)),
    };
    let (point_a, point_b) = match &w {
        Some(w) => (w.point_a, w.point_b),
        None => (Point3::from(result.point_a), Point3::from(result.point_b)),
    };
    // Columns of J_b(p_b) − J_a(p_a).
    let mut columns = [Vector3::zeros(); GRADIENT_COLUMNS];
    let mut flags = gradient_flags::PRESENT;
    let count = match robots.link_of(a.id) {
        Some((robot_id, link_a)) => {
            let robot = robots.get(robot_id).ok_or(ErrorCode::Internal)?;
            let kin = &robot.kinematics;
            let dof = kin.dof();
            let count = dof + if stance.base { 6 } else { 0 };
            if count > GRADIENT_COLUMNS {
                return Err(ErrorCode::InvalidOptions);
            }
            let at = stance
                .steps
                .and_then(|s| s.at(robot_id, stance.step))
                .unwrap_or((&robot.base, &robot.positions));
            let base_origin = Point3::from(at.0.translation.vector);
            let poses = cache
                .get(robot_id, stance.step, kin, at)
                .ok_or(ErrorCode::Internal)?;
            let sides = moved_points(link_a, &point_a, robots.link_of(b.id), robot_id, &point_b);
            let mut scratch = [Vector3::zeros(); GRADIENT_COLUMNS];
            for (link, point, sign) in sides.into_iter().flatten() {
                kin.point_jacobian_into(poses, link, &point, &mut scratch[..dof]);
                for (c, s) in columns.iter_mut().zip(&scratch[..dof]) {
                    *c += s * sign;
                }
                if stance.base {
                    add_twist_columns(&base_origin, &point, sign, &mut columns[dof..dof + 6]);
                }
            }
            if stance.base {
                flags |= gradient_flags::BASE;
            }
            count
        }
        None => {
            let origin = Point3::from(a.pose.translation.vector);
            add_twist_columns(&origin, &point_a, -1.0, &mut columns[..6]);
            6
        }
    };
    let mut gradient = Gradient {
        columns: count as u32,
        ..Gradient::NONE
    };
    match w {
        Some(w) => {
            let mut widest: f64 = 0.0;
            for (value, column) in gradient.values.iter_mut().zip(&columns[..count]) {
                *value = w.normal.dot(column);
                widest = widest.max(column.norm());
            }
            gradient.error = w.normal_error * widest;
            // Two kinds of non-unique witness: a tied depth direction
            // (overlapping), or parallel supporting features (either).
            if w.tied
                || not_unique(
                    (a.shape, a.pose),
                    (b.shape, b.pose),
                    result.pieces,
                    &w.normal,
                )
            {
                flags |= gradient_flags::NOT_UNIQUE;
            }
        }
        None => flags |= gradient_flags::NO_DIRECTION,
    }
    gradient.flags = flags;
    *out = gradient;
    Ok(())
}

/// The points whose motion a robot's gradient takes: `a`'s on its link
/// (moving `a` away lowers the distance: sign −1) and, when `b` is a link
/// of the same robot, `b`'s (sign +1).
fn moved_points(
    link_a: usize,
    point_a: &Point3<f64>,
    b: Option<(u64, usize)>,
    robot: u64,
    point_b: &Point3<f64>,
) -> [Option<(usize, Point3<f64>, f64)>; 2] {
    let same = b
        .filter(|(r, _)| *r == robot)
        .map(|(_, link)| (link, *point_b, 1.0));
    [Some((link_a, *point_a, -1.0)), same]
}

/// Adds `sign` times the twist Jacobian's columns of `point` (carried by a
/// pose with origin `origin`) to `out` (6 columns).
fn add_twist_columns(
    origin: &Point3<f64>,
    point: &Point3<f64>,
    sign: f64,
    out: &mut [Vector3<f64>],
) {
    for (column, twist) in out.iter_mut().zip(twist_jacobian(origin, point)) {
        *column += twist * sign;
    }
}
