//! The distance of a union (2.3), (2.8): the nearest of its piece pairs,
//! searched so that pairs that cannot win stop early or do not run. Generic
//! over the shapes' [`Pieces`]: the stored [`Shape`](crate::Shape)s of
//! [`distance`](crate::distance) and the compounds of any support maps of
//! [`distance_between_compounds`](crate::distance_between_compounds) run
//! the same search, monomorphised.

use nalgebra::{Isometry3, Vector3};

use super::numerical_algorithm::{Exit, RunOutcome};
use super::pair::{ConvexPair, PiecePlacement, is_identity};
use super::warm_start::PieceSimplex;
use super::{Answer, Query, Status, WarmStart};
use crate::johnson::Simplex;
use crate::numeric::robust_norm;
use crate::shape::Pieces;
use crate::support_map::SupportMap;

/// A certified lower bound on the distance between piece `convex_a` placed
/// by `offset_a` and piece `convex_b` placed by `placed_b`, both in A's body
/// frame: their gap along the unit `axis` (from A towards B), one support
/// search on each, less what round-off may hide. Any axis gives a lower
/// bound (a separating plane); the best pair's normal is a good one for the
/// pieces beside it, and costs two support searches where running the pair
/// costs a set-up and an iteration at least. NaN (from a NaN axis) passes no
/// cutoff, so it skips nothing.
#[inline(always)]
pub(super) fn axis_gap<A: SupportMap, B: SupportMap>(
    convex_a: &A,
    offset_a: &Isometry3<f64>,
    convex_b: &B,
    placed_b: &Isometry3<f64>,
    axis: &Vector3<f64>,
) -> f64 {
    let axis_in_a = offset_a.rotation.inverse_transform_vector(axis);
    let axis_in_b = placed_b.rotation.inverse_transform_vector(axis);
    let ((_, top_point), (_, bottom_point)) = (
        convex_a.local_support(&axis_in_a),
        convex_b.local_support(&-axis_in_b),
    );
    let top_a = (axis_in_a.dot(&convex_a.centre().coords) + axis_in_a.dot(&top_point))
        + axis.dot(&offset_a.translation.vector);
    let bottom_b = (axis_in_b.dot(&convex_b.centre().coords) + axis_in_b.dot(&bottom_point))
        + axis.dot(&placed_b.translation.vector);
    let gap = (bottom_b - top_a) - (convex_a.rounding() + convex_b.rounding());
    // Each product and sum above errs by a few ε of the magnitudes involved,
    // the rotated axes by a few ε of their length 1, and a support search may
    // miss the maximum by a near-tie's last bit: 64 ε of every magnitude, as
    // a pair's own slack. The axis is unit to a few ε, which scales the gap.
    // (`centre_norm + size` is a convex piece's reach.)
    let magnitude = (convex_a.centre_norm() + convex_a.size())
        + (convex_b.centre_norm() + convex_b.size())
        + robust_norm(&offset_a.translation.vector)
        + robust_norm(&placed_b.translation.vector)
        + convex_a.rounding()
        + convex_b.rounding();
    (gap - 64.0 * f64::EPSILON * magnitude) * (1.0 - 8.0 * f64::EPSILON)
}

/// (2.3), (2.8): the minimum over piece pairs. Pairs are visited warm pair
/// first, then by a bounding-sphere lower bound; each runs with the best upper
/// bound so far as its cutoff, so a pair that cannot win stops early, and a
/// pair proved beyond the cutoff before its run (by its sphere gap, or by its
/// gap along the best pair's normal, [`axis_gap`]) does not run at all.
/// With the answer, the interval width beyond which it counts as stuck (see
/// [`second_opinion`](super::recovery::second_opinion)).
///
/// Run out of line in the query's compiled form (see
/// [`distance_avx2`](super::distance_avx2)): a function of its own is
/// compiled for the baseline CPU unless it carries the target features
/// itself, and the piece pairs' runs, inlined in it, take more instructions
/// in SSE2 code.
#[inline(always)]
pub(super) fn search_compound<const AVX2: bool, A: Pieces, B: Pieces>(
    simplex: &mut Simplex,
    query: &Query<'_, A, B>,
    rel: &Isometry3<f64>,
    warm: Option<&WarmStart>,
) -> (Answer, f64) {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: as in `subalgorithm`.
        return unsafe { search_compound_avx2(simplex, query, rel, warm) };
    }
    search_compound_base(simplex, query, rel, warm)
}

cpu_forms! { entry
    /// [`search_compound_body`] for any CPU; the AVX2 form out of line too,
    /// so that the convex pair's path around its call stays as it was.
    #[inline(never)]
    pub(super) fn search_compound_base / search_compound_avx2 <A: Pieces, B: Pieces> (
        simplex: &mut Simplex,
        query: &Query<'_, A, B>,
        rel: &Isometry3<f64>,
        warm: Option<&WarmStart>
    ) -> (Answer, f64) => search_compound_body
}

/// A piece pair to visit: its sphere gap (a rough lower bound on its
/// distance, without slack), then the piece of A and the piece of B.
type Candidate = (f64, u32, u32);

/// Piece pairs up to this many are ordered on the stack, so that a query
/// of unions of a few pieces allocates nothing.
const ON_STACK: usize = 16;

/// The body of [`search_compound`], inlined into each of its compiled forms.
#[inline(always)]
pub(super) fn search_compound_body<const AVX2: bool, A: Pieces, B: Pieces>(
    simplex: &mut Simplex,
    query: &Query<'_, A, B>,
    rel: &Isometry3<f64>,
    warm: Option<&WarmStart>,
) -> (Answer, f64) {
    let &Query {
        a,
        pose_a,
        b,
        pose_b,
        options,
        ..
    } = query;
    let pair_count = a.piece_count() * b.piece_count();
    let mut small = [(0.0f64, 0u32, 0u32); ON_STACK];
    let mut large = Vec::new();
    let order: &mut [Candidate] = if pair_count <= ON_STACK {
        &mut small[..pair_count]
    } else {
        large.resize(pair_count, (0.0, 0, 0));
        &mut large
    };
    order_by_sphere_gap(query, rel, order);
    put_warm_pairs_first(order, warm);
    let mut best: Option<Answer> = None;
    let mut tally = PairTally::new();
    // The two piece pairs with the smallest upper bounds, for the warm start.
    let mut two_nearest = [(f64::INFINITY, PieceSimplex::default()); 2];
    // The best pair's normal in A's body frame, once the best pair is
    // separated: a separating axis that may prove the next pairs farther.
    let mut axis: Option<Vector3<f64>> = None;
    for (rank, &(sphere_gap, piece_a, piece_b)) in order.iter().enumerate() {
        let cutoff = best.as_ref().map_or(f64::INFINITY, |best| best.upper);
        // The sphere bound is rough (no slack): only skip on a clear margin.
        if sphere_gap > cutoff * (1.0 + 1e-9) + f64::MIN_POSITIVE {
            continue;
        }
        let pieces = [piece_a, piece_b];
        let (offset_a, convex_a) = a.piece(piece_a as usize).expect("index below piece_count");
        let (offset_b, convex_b) = b.piece(piece_b as usize).expect("index below piece_count");
        // An identity offset (a convex shape's, or a piece placed at its
        // compound's origin) changes nothing, to the bit: skip its products.
        let placed_b = if is_identity(&offset_b) {
            *rel
        } else {
            rel * offset_b
        };
        if let Some(axis) = &axis
            && axis_gap(convex_a, &offset_a, convex_b, &placed_b, axis) > cutoff * (1.0 + 1e-9)
        {
            continue;
        }
        let piece_rel = if is_identity(&offset_a) {
            placed_b
        } else {
            offset_a.inv_mul(&placed_b)
        };
        // Each piece's place in the world, for a piece far from its own
        // frame's origin (see `ConvexPair::new`); a convex shape's identity
        // offset places its centroid exactly.
        let place_a = PiecePlacement {
            pose: pose_a,
            offset: Some(&offset_a),
        };
        let place_b = PiecePlacement {
            pose: pose_b,
            offset: Some(&offset_b),
        };
        let precision = options.precision;
        let pair = ConvexPair::new(
            convex_a,
            convex_b,
            &piece_rel,
            (place_a, place_b),
            precision,
        );
        let warm_pairs = warm.and_then(|w| w.for_pieces(pieces));
        let mut run = pair.solve_or_rerun_cold::<AVX2>(simplex, options, warm_pairs, cutoff);
        pair.deepen(&mut run, simplex, options);
        let (pair_lower, pair_upper, pair_distance) = pair.certified_bounds(&run);
        if pair_upper < two_nearest[1].0 {
            let kept = PieceSimplex::from_simplex(simplex, run.solution.mask, pieces);
            keep_two_nearest(&mut two_nearest, (pair_upper, kept));
        }
        let Some(status) = tally.add(&pair, &run, pair_lower, options.tolerance) else {
            continue;
        };
        // Only a pair that becomes the best is turned into an answer.
        let better = best
            .as_ref()
            .is_none_or(|best| (pair_upper, pair_distance) < (best.upper, best.distance));
        if better || status == Status::Closer {
            let answer = pair.to_answer(&run, simplex, place_a, pieces);
            axis = (answer.normal != Vector3::zeros())
                .then(|| pose_a.rotation.inverse_transform_vector(&answer.normal));
            best = Some(answer);
        }
        if status == Status::Closer {
            tally.lower = tally.lower.min(bound_by_unvisited(&order[rank + 1..]));
            break;
        }
    }
    let mut out = best.expect("the first pair is never skipped or pruned");
    out.warm_start.second = two_nearest
        .iter()
        .map(|nearest| nearest.1)
        .find(|kept| kept.len > 0 && kept.pieces != out.pieces)
        .unwrap_or_default();
    out.lower = tally.lower.min(out.upper);
    out.iterations = tally.iterations;
    out.backup_used = tally.backup_used;
    out.penetration = out.penetration.max(tally.penetration);
    out.status = union_status(&out, options.margin, tally.early, tally.trouble);
    (out, tally.stuck_width)
}

/// What the union's answer gathers from every piece pair run, whichever
/// pair ends up the nearest.
#[derive(Clone, Copy)]
struct PairTally {
    /// The smallest lower bound of the pairs run.
    lower: f64,
    iterations: u32,
    backup_used: bool,
    /// The deepest pair's penetration bound.
    penetration: f64,
    /// The worse of the pairs' IterationCap and ToleranceNotMet ends.
    trouble: Option<Status>,
    /// Whether a pair stopped on the margin before converging: only then is
    /// the union's answer an early exit rather than a converged one.
    early: bool,
    /// The widest interval a pair run to its end may have before the
    /// union's answer is called stuck: the largest `stuck_width` among those
    /// pairs, since every one of them may bound the union from below.
    stuck_width: f64,
}

impl PairTally {
    #[inline(always)]
    fn new() -> Self {
        PairTally {
            lower: f64::INFINITY,
            iterations: 0,
            backup_used: false,
            penetration: 0.0,
            trouble: None,
            early: false,
            stuck_width: 0.0,
        }
    }

    /// Counts a pair's `run` (with its certified lower bound `pair_lower`):
    /// its status, or `None` when it was pruned.
    #[inline(always)]
    fn add<A: SupportMap, B: SupportMap>(
        &mut self,
        pair: &ConvexPair<'_, A, B>,
        run: &RunOutcome,
        pair_lower: f64,
        tolerance: f64,
    ) -> Option<Status> {
        self.iterations = self.iterations.saturating_add(run.iterations);
        self.backup_used |= run.backup_used;
        self.lower = self.lower.min(pair_lower);
        // Separating the union means separating every piece pair: the
        // deepest pair's bound, whichever pair ends up named, bounds the
        // union's depth (a pair whose rounded shells alone overlap counts too).
        let pair_depth = if run.norm == 0.0 {
            run.core_depth + pair.radii
        } else {
            pair.radii - run.norm
        };
        self.penetration = self.penetration.max(pair_depth);
        let status = match run.exit {
            Exit::Pruned => return None,
            Exit::Status(status) => status,
        };
        self.stuck_width = self.stuck_width.max(pair.stuck_width(tolerance));
        self.early |= status == Status::Farther;
        if matches!(status, Status::IterationCap | Status::ToleranceNotMet)
            && self.trouble != Some(Status::ToleranceNotMet)
        {
            // ToleranceNotMet outranks IterationCap: it is the worse news.
            self.trouble = Some(status);
        }
        Some(status)
    }
}

/// After an early exit: the pairs not visited still bound the union's
/// distance from below by their sphere gaps (shaded for round-off).
#[inline(always)]
fn bound_by_unvisited(unvisited: &[Candidate]) -> f64 {
    let rest = unvisited
        .iter()
        .map(|candidate| candidate.0 - 1e-9 * candidate.0.abs())
        .fold(f64::INFINITY, f64::min);
    rest.max(0.0)
}

/// The union's status, from its best pair's answer `out` (with the union's
/// bounds), whether a pair stopped `early` on the margin and the worst
/// `trouble` of its pairs. The margin is decided on the union's bounds, not
/// on one pair's. A union whose pairs all converged says so, as a convex
/// pair that converges before its margin decides does.
#[inline(always)]
fn union_status(out: &Answer, margin: Option<f64>, early: bool, trouble: Option<Status>) -> Status {
    match margin {
        _ if out.status == Status::Closer => Status::Closer,
        Some(margin) if early && out.lower > margin => Status::Farther,
        _ => match trouble {
            Some(trouble) => trouble,
            None if out.status == Status::Farther => Status::Converged,
            None => out.status,
        },
    }
}

/// Fills `order` with every piece pair and its sphere gap, nearest first
/// (ties by piece indices, so that the order is the same whichever way the
/// pairs come).
#[inline(always)]
fn order_by_sphere_gap<A: Pieces, B: Pieces>(
    query: &Query<'_, A, B>,
    rel: &Isometry3<f64>,
    order: &mut [Candidate],
) {
    let (a, b) = (query.a, query.b);
    // B's pieces outside, so that each centre is placed in A's frame once.
    let mut slot = order.iter_mut();
    for piece_b in 0..b.piece_count() {
        let convex_b = b.convex_piece(piece_b).expect("index below piece_count");
        let centre_b = rel * b.piece_centre(piece_b).expect("index below piece_count");
        for piece_a in 0..a.piece_count() {
            let convex_a = a.convex_piece(piece_a).expect("index below piece_count");
            let centre_a = a.piece_centre(piece_a).expect("index below piece_count");
            let gap = crate::numeric::robust_norm(&(centre_b - centre_a))
                - (convex_a.size() + convex_a.rounding())
                - (convex_b.size() + convex_b.rounding());
            if let Some(entry) = slot.next() {
                *entry = (gap, piece_a as u32, piece_b as u32);
            }
        }
    }
    order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
}

/// Warm piece pairs first, the nearest one in front: its upper bound then
/// prunes the others from their first iterations.
#[inline(always)]
fn put_warm_pairs_first(order: &mut [Candidate], warm: Option<&WarmStart>) {
    if let Some(warm) = warm {
        for kept in [warm.second, warm.first] {
            if kept.len > 0
                && let Some(position) = order.iter().position(|&(_, i, j)| [i, j] == kept.pieces)
            {
                order[..=position].rotate_right(1);
            }
        }
    }
}

/// Keeps `entry` among the two piece pairs of smallest upper bound, whose
/// upper bound it beats at least the second of.
#[inline(always)]
fn keep_two_nearest(two_nearest: &mut [(f64, PieceSimplex); 2], entry: (f64, PieceSimplex)) {
    if entry.0 < two_nearest[0].0 {
        *two_nearest = [entry, two_nearest[0]];
    } else {
        two_nearest[1] = entry;
    }
}
