//! One convex piece pair's run, for the penetration depth: the answer with
//! the certified bounds on the distance between the cores (the radii left
//! out), which the signed distance needs where the answer's own bounds,
//! after radii and clamped at 0, have lost them.

use nalgebra::Isometry3;

use super::pair::{ConvexPair, PiecePlacement, is_identity};
use super::{Answer, Options, WarmStart, Workspace};
use crate::shape::Convex;
use crate::support_map::SupportMap;

/// A piece pair's answer and the certified interval of its cores' distance.
pub(crate) struct CoreRun {
    /// The pair's answer, as a query of the two pieces alone gives it.
    pub(crate) answer: Answer,
    /// Certified lower bound on the distance between the cores.
    pub(crate) core_lower: f64,
    /// Certified upper bound on the distance between the cores.
    pub(crate) core_upper: f64,
    /// The cores' distance, between the two bounds.
    pub(crate) core_distance: f64,
}

/// Where one piece sits: its shape's pose and its offset in the shape's
/// body frame (the identity for a convex shape).
pub(crate) struct Placed<'p, S = Convex> {
    /// The piece.
    pub(crate) convex: &'p S,
    /// Its shape's pose.
    pub(crate) pose: &'p Isometry3<f64>,
    /// Its offset in the shape's body frame.
    pub(crate) offset: &'p Isometry3<f64>,
}

// By hand: derived, they would ask `S` to be `Copy` too.
impl<S> Clone for Placed<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S> Copy for Placed<'_, S> {}

impl<S> Placed<'_, S> {
    /// The pose of the piece's own frame relative to `other`'s, `other⁻¹ ·
    /// self`, the shapes' poses composed first so that translations far
    /// from the world's origin cancel before anything is rotated.
    pub(crate) fn relative_to<T>(&self, other: &Placed<'_, T>) -> Isometry3<f64> {
        let rel = other.pose.inv_mul(self.pose);
        let placed = if is_identity(self.offset) {
            rel
        } else {
            rel * self.offset
        };
        if is_identity(other.offset) {
            placed
        } else {
            other.offset.inv_mul(&placed)
        }
    }
}

/// The distance query of one piece pair, run to convergence (no margin),
/// in the portable compiled form: the depth's caller runs it only for
/// pairs that may overlap, a path whose time is the expansion's.
pub(crate) fn core_run<A: SupportMap, B: SupportMap>(
    workspace: &mut Workspace,
    a: Placed<'_, A>,
    b: Placed<'_, B>,
    pieces: [u32; 2],
    options: &Options,
    warm: Option<&WarmStart>,
) -> CoreRun {
    let options = Options {
        margin: None,
        ..*options
    };
    let rel = b.relative_to(&a);
    let place_a = PiecePlacement {
        pose: a.pose,
        offset: Some(a.offset),
    };
    let place_b = PiecePlacement {
        pose: b.pose,
        offset: Some(b.offset),
    };
    let pair = ConvexPair::new(
        a.convex,
        b.convex,
        &rel,
        (place_a, place_b),
        options.precision,
    );
    let simplex = &mut workspace.simplex;
    let warm_pairs = warm.and_then(|w| w.for_pieces(pieces));
    let run = pair.solve_or_rerun_cold::<false>(simplex, &options, warm_pairs, f64::INFINITY);
    let answer = pair.to_answer(&run, simplex, place_a, pieces);
    let core_upper = run.norm + pair.slack_world;
    let core_lower = (run.lower - pair.slack_world).min(core_upper);
    CoreRun {
        answer,
        core_lower,
        core_upper,
        core_distance: run.norm.max(core_lower).min(core_upper),
    }
}
