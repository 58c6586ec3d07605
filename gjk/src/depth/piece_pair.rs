//! The signed distance of one convex piece pair: the distance query's
//! answer when the cores are apart (the paper's rule for rounded shapes,
//! `d = d(cores) - r_A - r_B`, negative when only the shells overlap), the
//! expansion on the cores otherwise, with the radii subtracted (a radius
//! adds itself to the support function along every unit direction, so to
//! the depth).

use nalgebra::{Point3, Vector3};

use super::expand::expand;
use super::frame::PairFrame;
use super::{DepthOptions, SignedDistance};
use crate::query::core_run::{Placed, core_run};
use crate::support_map::SupportMap;
use crate::{Status, WarmStart, Workspace};

/// `x - y` rounded down: less a bound on the subtraction's round-off, so
/// that a certified lower bound stays one.
fn sub_down(x: f64, y: f64) -> f64 {
    let d = x - y;
    d - 2.0 * f64::EPSILON * (x.abs() + y.abs())
}

/// `x - y` rounded up, as [`sub_down`].
fn sub_up(x: f64, y: f64) -> f64 {
    let d = x - y;
    d + 2.0 * f64::EPSILON * (x.abs() + y.abs())
}

/// The signed distance of pieces `a` and `b` (see the module).
pub(super) fn piece_signed_distance<A: SupportMap, B: SupportMap>(
    workspace: &mut Workspace,
    a: Placed<'_, A>,
    b: Placed<'_, B>,
    pieces: [u32; 2],
    options: &DepthOptions,
    warm: Option<&WarmStart>,
) -> SignedDistance {
    let run = core_run(workspace, a, b, pieces, &options.distance, warm);
    let (ra, rb) = (a.convex.rounding(), b.convex.rounding());
    let radii = ra + rb;
    let answer = &run.answer;
    if run.core_lower > 0.0 {
        return SignedDistance {
            value: run.core_distance - radii,
            lower: sub_down(run.core_lower, radii),
            upper: sub_up(run.core_upper, radii),
            point_a: answer.point_a,
            point_b: answer.point_b,
            normal: answer.normal,
            pieces,
            expansions: 0,
            converged: answer.status == Status::Converged,
            tied: false,
        };
    }
    let frame = PairFrame::new(&a, &b);
    let start: Vec<_> = answer
        .warm_start
        .pairs()
        .iter()
        .map(|&[ia, ib]| frame.point(ia, ib))
        .collect();
    let found = expand(
        &frame,
        &start,
        options.tolerance,
        options.max_points as usize,
    );
    let inv = frame.inv_scale;
    // The cores' signed distance is minus their depth.
    let core_lower = -(found.upper * inv);
    let core_upper = if found.lower > 0.0 {
        (-(found.lower * inv)).min(run.core_upper)
    } else {
        run.core_upper
    };
    let core_value = (-(found.depth * inv)).max(core_lower).min(core_upper);
    let mut normal = frame.world_vector(&found.normal);
    let len = normal.norm();
    normal = if len > 0.0 {
        normal / len
    } else {
        Vector3::zeros()
    };
    // B's witness is A's moved by the signed distance along the normal,
    // so that the two agree with the value exactly.
    let (core_a, core_b): (Point3<f64>, Point3<f64>) = match found.witness_a {
        Some(wa) => {
            let core_a = frame.world_point(&wa);
            (core_a, core_a + normal * core_value)
        }
        None => (
            answer.point_a - answer.normal * ra,
            answer.point_b + answer.normal * rb,
        ),
    };
    SignedDistance {
        value: core_value - radii,
        lower: sub_down(core_lower, radii),
        upper: sub_up(core_upper, radii),
        point_a: core_a + normal * ra,
        point_b: core_b - normal * rb,
        normal,
        pieces,
        expansions: found.expansions,
        converged: found.converged,
        tied: found.tied,
    }
}
