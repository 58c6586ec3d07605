//! The distance of a union (2.3), (2.8): the nearest of its piece pairs,
//! searched so that pairs that cannot win stop early or do not run.

use nalgebra::{Isometry3, Vector3};

use super::numerical_algorithm::Exit;
use super::pair::{ConvexPair, PiecePlacement, is_identity};
use super::warm_start::PieceSimplex;
use super::{Answer, Query, Status, WarmStart};
use crate::johnson::Simplex;
use crate::shape::{Convex, robust_norm};

/// A certified lower bound on the distance between piece `ca` placed by `oa`
/// and piece `cb` placed by `ob`, both in A's body frame: their gap along the
/// unit axis `n` (from A towards B), one support search on each, less what
/// round-off may hide. Any axis gives a lower bound (a separating plane); the
/// best pair's normal is a good one for the pieces beside it, and costs two
/// support searches where running the pair costs a set-up and an iteration
/// at least. NaN (from a NaN axis) passes no cutoff, so it skips nothing.
#[inline(always)]
pub(super) fn axis_gap(
    ca: &Convex,
    oa: &Isometry3<f64>,
    cb: &Convex,
    ob: &Isometry3<f64>,
    n: &Vector3<f64>,
) -> f64 {
    let da = oa.rotation.inverse_transform_vector(n);
    let db = ob.rotation.inverse_transform_vector(n);
    let (ia, ib) = (ca.support_index(&da), cb.support_index(&-db));
    let top_a =
        (da.dot(&ca.centroid().coords) + da.dot(&ca.local(ia))) + n.dot(&oa.translation.vector);
    let bottom_b =
        (db.dot(&cb.centroid().coords) + db.dot(&cb.local(ib))) + n.dot(&ob.translation.vector);
    let gap = (bottom_b - top_a) - (ca.radius() + cb.radius());
    // Each product and sum above errs by a few ε of the magnitudes involved,
    // the rotated axes by a few ε of their length 1, and a support search may
    // miss the maximum by a near-tie's last bit: 64 ε of every magnitude, as
    // a pair's own slack. `n` is unit to a few ε, which scales the gap.
    let scale = ca.reach()
        + cb.reach()
        + robust_norm(&oa.translation.vector)
        + robust_norm(&ob.translation.vector)
        + ca.radius()
        + cb.radius();
    (gap - 64.0 * f64::EPSILON * scale) * (1.0 - 8.0 * f64::EPSILON)
}

/// (2.3), (2.8): the minimum over piece pairs. Pairs are visited warm pair
/// first, then by a bounding-sphere lower bound; each runs with the best upper
/// bound so far as its cutoff, so a pair that cannot win stops early, and a
/// pair proved beyond the cutoff before its run (by its sphere gap, or by its
/// gap along the best pair's normal, [`axis_gap`]) does not run at all.
/// With the answer, the interval width beyond which it counts as stuck (see
/// [`second_opinion`](super::recovery::second_opinion)).
///
/// Run out of line in the query's compiled form (see [`distance_avx2`](super::distance_avx2)): a
/// function of its own is compiled for the baseline CPU unless it carries
/// the target features itself, and the piece pairs' runs, inlined in it,
/// took 12 % more instructions in SSE2 code (the Section 8 union, warm).
#[inline(always)]
pub(super) fn search_compound<const AVX2: bool>(
    simplex: &mut Simplex,
    query: &Query<'_>,
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

/// [`search_compound_body`] for any CPU.
#[inline(never)]
pub(super) fn search_compound_base(
    simplex: &mut Simplex,
    query: &Query<'_>,
    rel: &Isometry3<f64>,
    warm: Option<&WarmStart>,
) -> (Answer, f64) {
    search_compound_body::<false>(simplex, query, rel, warm)
}

/// [`search_compound_body`] compiled for AVX2 and FMA (see
/// [`distance_avx2`](super::distance_avx2)); out of line, so that the convex
/// pair's path around its call stays as it was.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
pub(super) fn search_compound_avx2(
    simplex: &mut Simplex,
    query: &Query<'_>,
    rel: &Isometry3<f64>,
    warm: Option<&WarmStart>,
) -> (Answer, f64) {
    search_compound_body::<true>(simplex, query, rel, warm)
}

/// The body of [`search_compound`], inlined into each of its compiled forms.
#[inline(always)]
pub(super) fn search_compound_body<const AVX2: bool>(
    simplex: &mut Simplex,
    query: &Query<'_>,
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
    let (na, nb) = (a.piece_count(), b.piece_count());
    // Piece pairs with their sphere gaps: on the stack for the usual few
    // pieces, so a query allocates nothing.
    const ON_STACK: usize = 16;
    let mut small = [(0.0f64, 0u32, 0u32); ON_STACK];
    let mut large = Vec::new();
    let order: &mut [(f64, u32, u32)] = if na * nb <= ON_STACK {
        &mut small[..na * nb]
    } else {
        large.resize(na * nb, (0.0, 0, 0));
        &mut large
    };
    // B's pieces outside, so that each centre is placed in A's frame once;
    // the sort below orders the pairs the same whichever way they come.
    let mut slot = order.iter_mut();
    for j in 0..nb {
        let cb = b.convex_piece(j).expect("index below piece_count");
        let centre_b = rel * b.piece_centre(j).expect("index below piece_count");
        for i in 0..na {
            let ca = a.convex_piece(i).expect("index below piece_count");
            let centre_a = a.piece_centre(i).expect("index below piece_count");
            let gap = crate::shape::robust_norm(&(centre_b - centre_a))
                - (ca.size() + ca.radius())
                - (cb.size() + cb.radius());
            if let Some(o) = slot.next() {
                *o = (gap, i as u32, j as u32);
            }
        }
    }
    order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    // Warm piece pairs first, the nearest one in front: its upper bound then
    // prunes the others from their first iterations.
    if let Some(w) = warm {
        for e in [w.second, w.first] {
            if e.len > 0
                && let Some(pos) = order.iter().position(|&(_, i, j)| [i, j] == e.pieces)
            {
                order[..=pos].rotate_right(1);
            }
        }
    }

    let mut best: Option<Answer> = None;
    let mut lower = f64::INFINITY;
    let mut iterations = 0u32;
    let mut backup_used = false;
    let mut penetration = 0.0f64;
    let mut trouble: Option<Status> = None;
    // Whether a pair stopped on the margin before converging: only then is
    // the union's answer an early exit rather than a converged one.
    let mut early = false;
    // The widest interval a pair run to its end may have before the union's
    // answer is called stuck: the largest `stuck_width` among those pairs,
    // since every one of them may bound the union from below.
    let mut stuck = 0.0f64;
    // The two piece pairs with the smallest upper bounds, for the warm start.
    let mut kept: [(f64, PieceSimplex); 2] = [(f64::INFINITY, PieceSimplex::default()); 2];
    // The best pair's normal in A's body frame, once the best pair is
    // separated: a separating axis that may prove the next pairs farther.
    let mut axis: Option<Vector3<f64>> = None;
    for (k, &(gap, i, j)) in order.iter().enumerate() {
        let cutoff = best.as_ref().map_or(f64::INFINITY, |b| b.upper);
        // The sphere bound is rough (no slack): only skip on a clear margin.
        if gap > cutoff * (1.0 + 1e-9) + f64::MIN_POSITIVE {
            continue;
        }
        let (oa, ca) = a.piece(i as usize).expect("index below piece_count");
        let (offset_b, cb) = b.piece(j as usize).expect("index below piece_count");
        // An identity offset (a convex shape's, or a piece placed at its
        // compound's origin) changes nothing, to the bit: skip its products.
        let ob = if is_identity(&offset_b) {
            *rel
        } else {
            rel * offset_b
        };
        if let Some(n) = &axis
            && axis_gap(ca, &oa, cb, &ob, n) > cutoff * (1.0 + 1e-9)
        {
            continue;
        }
        let piece_rel = if is_identity(&oa) {
            ob
        } else {
            oa.inv_mul(&ob)
        };
        // Each piece's place in the world, for a piece far from its own
        // frame's origin (see `ConvexPair::new`); a convex shape's identity
        // offset places its centroid exactly.
        let world = (
            PiecePlacement {
                pose: pose_a,
                offset: Some(&oa),
            },
            PiecePlacement {
                pose: pose_b,
                offset: Some(&offset_b),
            },
        );
        let pair = ConvexPair::new(ca, cb, &piece_rel, world, options.precision);
        let warm_pairs = warm.and_then(|w| w.for_pieces([i, j]));
        let run = pair.solve_or_rerun_cold::<AVX2>(simplex, options, warm_pairs, cutoff);
        let (pair_lower, pair_upper, pair_distance) = pair.certified_bounds(&run);
        if pair_upper < kept[1].0 {
            let entry = (
                pair_upper,
                PieceSimplex::from_simplex(simplex, run.solution.mask, [i, j]),
            );
            if pair_upper < kept[0].0 {
                kept = [entry, kept[0]];
            } else {
                kept[1] = entry;
            }
        }
        iterations = iterations.saturating_add(run.iterations);
        backup_used |= run.backup_used;
        lower = lower.min(pair_lower);
        // Separating the union means separating every piece pair: the
        // deepest pair's bound, whichever pair ends up named, bounds the
        // union's depth (a pair whose rounded shells alone overlap counts too).
        let pair_depth = if run.norm == 0.0 {
            run.core_depth + pair.radii
        } else {
            pair.radii - run.norm
        };
        penetration = penetration.max(pair_depth);
        let status = match run.exit {
            Exit::Pruned => continue,
            Exit::Status(s) => s,
        };
        stuck = stuck.max(pair.stuck_width(options.tolerance));
        early |= status == Status::Farther;
        if matches!(status, Status::IterationCap | Status::ToleranceNotMet)
            && trouble != Some(Status::ToleranceNotMet)
        {
            // ToleranceNotMet outranks IterationCap: it is the worse news.
            trouble = Some(status);
        }
        // Only a pair that becomes the best is turned into an answer.
        let better = best
            .as_ref()
            .is_none_or(|b| (pair_upper, pair_distance) < (b.upper, b.distance));
        if better || status == Status::Closer {
            let answer = pair.to_answer(
                &run,
                simplex,
                PiecePlacement {
                    pose: pose_a,
                    offset: Some(&oa),
                },
                [i, j],
            );
            axis = (answer.normal != Vector3::zeros())
                .then(|| pose_a.rotation.inverse_transform_vector(&answer.normal));
            best = Some(answer);
        }
        if status == Status::Closer {
            // The pairs not visited still bound the union's distance from
            // below by their sphere gaps (shaded for round-off).
            let rest = order[k + 1..]
                .iter()
                .map(|o| o.0 - 1e-9 * o.0.abs())
                .fold(f64::INFINITY, f64::min);
            lower = lower.min(rest.max(0.0));
            break;
        }
    }
    let mut out = best.expect("the first pair is never skipped or pruned");
    out.warm_start.second = kept
        .iter()
        .map(|k| k.1)
        .find(|e| e.len > 0 && e.pieces != out.pieces)
        .unwrap_or_default();
    out.lower = lower.min(out.upper);
    out.iterations = iterations;
    out.backup_used = backup_used;
    out.penetration = out.penetration.max(penetration);
    // The margin is decided on the union's bounds, not on one pair's. A
    // union whose pairs all converged says so, as a convex pair that
    // converges before its margin decides does.
    out.status = match options.margin {
        _ if out.status == Status::Closer => Status::Closer,
        Some(m) if early && out.lower > m => Status::Farther,
        _ => match trouble {
            Some(t) => t,
            None if out.status == Status::Farther => Status::Converged,
            None => out.status,
        },
    };
    (out, stuck)
}
