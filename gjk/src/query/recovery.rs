//! The recovery paths for runs that end badly: a warm run rerun cold, a
//! stuck query asked again with A and B swapped, bounds that contradict
//! each other and numbers that overflowed.

use super::numerical_algorithm::{Exit, RunOutcome};
use super::pair::ConvexPair;
use super::{Answer, Options, Query, Status, Workspace, all_finite, distance_body, distance_in};
use crate::Error;
use crate::johnson::Simplex;
use crate::support_map::SupportMap;

/// A query that ended with an interval wider than the tolerance (stuck,
/// its support point tied between far points by `v`'s round-off), asked
/// once more with the shapes swapped (`second`): B's frame rounds
/// differently, and a needle along a prism's edge (vertex lists repeated)
/// that stopped far short of its distance reaches it that way. Unions too:
/// their piece pairs run the same way, and the needle as a union's piece
/// stopped where it did alone. Both answers are certified, so the nearer
/// upper bound wins and the lower bounds combine. Cold, as a warm start
/// names the pairs the other way round; rare, so out of line.
#[cold]
#[inline(never)]
pub(super) fn second_opinion(first: Answer, second: Result<Answer, Error>) -> Answer {
    let Ok(second) = second else {
        return first;
    };
    let lower = first.lower.max(second.lower);
    if lower > first.upper.min(second.upper) {
        // The two contradict each other (round-off beyond the slack):
        // neither is trusted over the other, and the first stands.
        return first;
    }
    let mut best = if second.upper < first.upper {
        Answer {
            point_a: second.point_b,
            point_b: second.point_a,
            normal: -second.normal,
            pieces: [second.pieces[1], second.pieces[0]],
            warm_start: second.warm_start.swapped(),
            ..second
        }
    } else {
        first
    };
    best.lower = lower;
    best.distance = best.distance.max(lower).min(best.upper);
    best.penetration = first.penetration.max(second.penetration);
    best.iterations = first.iterations.saturating_add(second.iterations);
    best.backup_used = first.backup_used || second.backup_used;
    best
}

/// The rare ends of [`distance_body`]: bounds that contradict each other, a
/// number that overflowed ([`mend_bounds_or_reject_overflow`]), or a run
/// stuck with an interval wider than `stuck_width` ([`second_opinion`]).
#[cold]
#[inline(never)]
pub(super) fn recover_suspect_answer<const AVX2: bool>(
    answer: Answer,
    workspace: &mut Workspace,
    query: &Query<'_>,
    stuck_width: f64,
) -> Result<Answer, Error> {
    recover_with(
        answer,
        workspace,
        query,
        stuck_width,
        |workspace| {
            let Query {
                a,
                pose_a,
                b,
                pose_b,
                options,
                ..
            } = *query;
            distance_in(workspace, a, pose_a, b, pose_b, options, None)
        },
        |workspace| distance_body::<AVX2>(workspace, &query.swapped()),
    )
}

/// The rare ends of any query, whatever its shapes' types: `cold` asks the
/// query again with no warm start, `swapped` with A and B swapped.
#[inline(always)]
pub(super) fn recover_with<A, B>(
    answer: Answer,
    workspace: &mut Workspace,
    query: &Query<'_, A, B>,
    stuck_width: f64,
    cold: impl FnOnce(&mut Workspace) -> Result<Answer, Error>,
    swapped: impl FnOnce(&mut Workspace) -> Result<Answer, Error>,
) -> Result<Answer, Error> {
    let answer = mend_bounds_or_reject_overflow(answer, workspace, query.warm.is_some(), cold)?;
    let converging = matches!(answer.status, Status::Converged | Status::ToleranceNotMet);
    if converging && answer.upper - answer.lower > stuck_width {
        let second = swapped(workspace);
        return Ok(second_opinion(answer, second));
    }
    Ok(answer)
}

/// Bounds that contradict each other, or a number that overflowed.
pub(super) fn mend_bounds_or_reject_overflow(
    mut answer: Answer,
    workspace: &mut Workspace,
    warm: bool,
    cold: impl FnOnce(&mut Workspace) -> Result<Answer, Error>,
) -> Result<Answer, Error> {
    if answer.lower > answer.upper {
        // The bounds contradict each other: round-off beyond the slack. The
        // one case fuzzing found (NaN weights from overflowing cofactors)
        // is handled in `solve`; this is the last line of defence. A cold
        // start is tried first; if that too is inconsistent, the lower
        // bound is given up (0) rather than returning an interval that
        // cannot hold.
        if warm {
            return cold(workspace);
        }
        answer.lower = 0.0;
        answer.distance = answer.distance.min(answer.upper);
        answer.status = Status::ToleranceNotMet;
    }
    if !all_finite(&answer) {
        // Finite inputs whose combination overflows f64 (coordinates near 1e308).
        return Err(Error::NonFinitePose);
    }
    Ok(answer)
}

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
    /// [`solve`](Self::solve), then, when a warm start ended with a loose
    /// interval, once more cold ([`rerun_cold`](Self::rerun_cold)): single
    /// pairs and a compound's piece pairs alike. Only a run that meant to
    /// converge is asked again. A pruned run only had to prove that its pair
    /// cannot win; an early exit on the margin and the iteration cap end
    /// with a wide interval by the caller's own choice, and a cold run would
    /// spend a second budget to end as loose (warm queries with a margin took
    /// longer than without one, and came back with the cold run's coarser
    /// distance).
    #[inline(always)]
    pub(super) fn solve_or_rerun_cold<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        warm: Option<&[[u32; 2]]>,
        cutoff: f64,
    ) -> RunOutcome {
        let run = self.solve::<AVX2>(simplex, options, warm, cutoff);
        let meant_to_converge = matches!(
            run.exit,
            Exit::Status(Status::Converged | Status::ToleranceNotMet)
        );
        if warm.is_some() && meant_to_converge && self.interval_is_loose(&run, options.tolerance) {
            return self.rerun_cold::<AVX2>(run, simplex, options, cutoff);
        }
        run
    }

    /// Whether the run's certified interval is wider than the tolerance
    /// allows: (6.2) alone ended it, near contact.
    #[inline(always)]
    pub(super) fn interval_is_loose(&self, run: &RunOutcome, tolerance: f64) -> bool {
        let (lower, upper, _) = self.certified_bounds(run);
        upper - lower > self.tight_width(tolerance)
    }

    /// The widest interval, in the world's units, that the tolerance allows
    /// a converged run: the slack at both ends and the 4 ε·D of step (5).
    #[inline(always)]
    pub(super) fn tight_width(&self, tolerance: f64) -> f64 {
        2.0 * self.slack_world + 4.0 * tolerance * self.size_bound * self.inv_scale
    }

    /// The interval width so much beyond what the tolerance allows (100
    /// times [`tight_width`](Self::tight_width)) that a second opinion is worth a
    /// second run: a stuck run, not one that (6.2) ended a few round-offs
    /// short. At that width itself, a few per cent of the runs of the
    /// randomised sweep and of the paper's family would be asked again;
    /// from ten times on, none of the family's.
    #[inline(always)]
    pub(super) fn stuck_width(&self, tolerance: f64) -> f64 {
        100.0 * self.tight_width(tolerance)
    }

    /// A warm run that ended with a loose interval (the warm simplex can sit
    /// on an edge of a flat K whose line passes 1e-9 of the size from the
    /// origin, coplanar sets touching, where no support point leads off it):
    /// the run once more from the single-point start. The cold run is kept
    /// whole, since the simplex now holds its points; the warm run's lower
    /// bound, certified too, still counts.
    #[cold]
    #[inline(never)]
    pub(super) fn rerun_cold<const AVX2: bool>(
        &self,
        warm: RunOutcome,
        simplex: &mut Simplex,
        options: &Options,
        cutoff: f64,
    ) -> RunOutcome {
        let mut run = self.solve::<AVX2>(simplex, options, None, cutoff);
        run.lower = run.lower.max(warm.lower);
        run.iterations = run.iterations.saturating_add(warm.iterations);
        run.backup_used |= warm.backup_used;
        run
    }
}
