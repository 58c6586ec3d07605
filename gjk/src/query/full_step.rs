//! Steps (3) to (6) of the Numerical Algorithm in full: every outcome of an
//! iteration but the plain descent that the main loop takes itself. The
//! ends, repeated support points, level steps, refinement of `v` and the
//! Backup Procedure.

use nalgebra::Vector3;

use super::numerical_algorithm::{Exit, RunOutcome, RunProgress, push_vertex};
use super::pair::ConvexPair;
use super::{Options, Status};
use crate::johnson::{Simplex, Solution, Vertex};
use crate::support_map::SupportMap;

/// What step (3) found for one `v` (the subalgorithm's solution, kept
/// beside it), read by every later decision of the iteration.
#[derive(Clone, Copy)]
struct Iterate {
    /// `|v|²` and `|v|`.
    v2: f64,
    norm: f64,
    /// `s_K(-v)`.
    support_point: Vertex,
    /// The run's best lower bound on the core distance, before slack.
    lower: f64,
    /// `g(v) = |v|² - v·s`, the gap of Theorem 4.1 times `|v|`.
    g: f64,
    /// Whether (6.2), `g(v) <= ε·D²`, holds.
    paper_met: bool,
    /// Whether the support point is a vertex of the simplex already.
    repeat: bool,
}

/// The remedies an iteration has tried, each at most once between two
/// runs of the Backup Procedure (and `by_backup`: whether `v` came from it).
#[derive(Clone, Copy)]
struct Tried {
    refined: bool,
    inside_asked: bool,
    regrown: bool,
    by_backup: bool,
}

/// `ε·D`, the tolerance of the stopping rule as a distance, and `stop_d`,
/// that plus what an f32 support search may miss.
#[derive(Clone, Copy)]
struct Tolerance {
    eps_d: f64,
    stop_d: f64,
}

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
    /// Steps (3) to (6) of the Numerical Algorithm for the subalgorithm's
    /// `solution` (from the Backup Procedure when `by_backup`), in full: the
    /// ends, repeats, flat steps, refinement and the Backup Procedure.
    /// `support`, when given, is `s_K(-v)` already found for this
    /// `solution`. `None` once a point has been added to the simplex (the
    /// next iteration begins), `Some` when the run ends.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step_in_full<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        cutoff: f64,
        state: &mut RunProgress,
        mut solution: Solution,
        by_backup: bool,
        mut support: Option<Vertex>,
    ) -> Option<RunOutcome> {
        let eps_d = options.tolerance * self.size_bound;
        let tolerance = Tolerance {
            eps_d,
            stop_d: eps_d + self.single_slack,
        };
        let mut tried = Tried {
            refined: false,
            inside_asked: false,
            regrown: false,
            by_backup,
        };
        loop {
            let v2 = solution.v.norm_squared();
            let norm = v2.sqrt();
            if !norm.is_finite() {
                return Some(self.end_on_overflow(simplex, state));
            }
            if norm <= self.slack {
                // v is the origin up to round-off: the cores touch or
                // intersect, and nothing finer can be certified.
                return Some(self.end_run(simplex, state, Status::Converged, solution, 0.0));
            }
            let mut it = self.step_three(state, (&solution, v2, norm), support.take(), tolerance);
            let end = self.end_at_step_three(
                simplex, options, cutoff, state, &solution, &mut it, tolerance,
            );
            if end.is_some() {
                return end;
            }
            // A step that does not descend refines v before it is taken or
            // given up (as a repeat does, below). Along a long thin edge of
            // K, v's error along the edge (ε times its length) can outweigh
            // v itself in the support search, and on a face of K normal to
            // v, whose points all tie, it alone picks the support point: a
            // needle touching a lattice's face cycled between two such
            // points, each step level, and ended far above its distance.
            // The refined v picks the point a step in exact arithmetic
            // would.
            if !tried.refined
                && !it.repeat
                && matches!(state.previous, Some((_, previous_v2)) if v2 >= previous_v2)
                && let Some(refined_solution) = simplex.refine(solution)
            {
                tried.refined = true;
                solution = refined_solution;
                continue;
            }
            if self.take_descent_step::<AVX2>(simplex, state, &solution, &it) {
                return None;
            }
            if let Some(run) = self.end_if_origin_inside(simplex, state, &solution, &it, &mut tried)
            {
                return Some(run);
            }
            if let Some(regrown) = regrow_dropped_vertex(simplex, &solution, &it, &mut tried) {
                solution = regrown;
                continue;
            }
            let end =
                self.refine_or_back_up(simplex, state, &it, &mut tried, tolerance, &mut solution);
            if end.is_some() {
                return end;
            }
        }
    }

    /// The end of a run whose subalgorithm overflowed. Fuzzing found points
    /// ~1e108 apart whose cofactors exceeded f64 (before the run was scaled
    /// to sizes near 1; kept as a guard, see testkit/tests/fuzz_regressions.rs),
    /// and NaN weights would make every bound below meaningless. Keep the
    /// last finite iterate, or else a single vertex: each is a point of the
    /// hull, so |v| stays an upper bound.
    #[inline(always)]
    fn end_on_overflow(&self, simplex: &Simplex, state: &mut RunProgress) -> RunOutcome {
        state.backup_used = true;
        let best = match state.previous {
            Some((previous, _)) => previous,
            None => {
                let first = simplex.all.trailing_zeros().min(3) as usize;
                let mut lambda = [0.0; 4];
                lambda[first] = 1.0;
                Solution {
                    mask: 1 << first,
                    v: simplex.vertices[first].y,
                    lambda,
                }
            }
        };
        RunOutcome {
            core_depth: 0.0,
            solution: best,
            norm: best.v.norm(),
            lower: state.lower,
            iterations: state.iterations,
            exit: Exit::Status(Status::ToleranceNotMet),
            backup_used: state.backup_used,
        }
    }

    /// Step (3) for `solution` (with `|v|²` and `|v|`): the support point
    /// (`support` when already found) and the bounds of Theorem 4.1.
    #[inline(always)]
    fn step_three(
        &self,
        state: &mut RunProgress,
        (solution, v2, norm): (&Solution, f64, f64),
        support: Option<Vertex>,
        tolerance: Tolerance,
    ) -> Iterate {
        let support_point = match support {
            Some(support_point) => support_point,
            None => self.support(&-solution.v),
        };
        let v_dot_support = solution.v.dot(&support_point.y);
        state.lower = state.lower.max(v_dot_support / norm - self.single_slack);
        let g = v2 - v_dot_support;
        // (6.2): g <= ε·D². Near contact that rule alone lets |v|
        // exceed the distance by up to √ε·D (nearly parallel edges do
        // this), so once it holds the run goes on while |v| still
        // descends, and stops early only when the certified interval,
        // of width g/|v|, is within ε·D. A support point already in V̂
        // leaves nothing to add: g is then the error of v itself.
        let paper_met = g <= tolerance.eps_d * self.size_bound + self.single_slack * norm;
        Iterate {
            v2,
            norm,
            support_point,
            lower: state.lower,
            g,
            paper_met,
            repeat: false,
        }
    }

    /// The ends of step (3): the stopping rule, the ends decided on the
    /// bounds (cutoff, margin) and the iteration cap. Records in `it`
    /// whether the support point repeats a vertex of the simplex, once the
    /// stopping rule has not ended the run.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn end_at_step_three(
        &self,
        simplex: &Simplex,
        options: &Options,
        cutoff: f64,
        state: &RunProgress,
        solution: &Solution,
        it: &mut Iterate,
        tolerance: Tolerance,
    ) -> Option<RunOutcome> {
        let Tolerance { eps_d, stop_d } = tolerance;
        let (solution, norm, lower, g) = (*solution, it.norm, it.lower, it.g);
        // The error of |v| is at most min(|v|, g/|v|): stop once that
        // is within ε·D, or within the round-off allowance when the
        // support point repeats a vertex of V̂. Beyond that, a repeat
        // means the subalgorithm's v is off by more than round-off
        // (a thin simplex: nearly parallel edges, or nearly collinear
        // points of K at contact): refinement, then steps (4) to (6).
        if g <= stop_d * norm || norm <= eps_d {
            return Some(self.end_run(simplex, state, Status::Converged, solution, lower));
        }
        it.repeat = simplex.has_pair(simplex.all, it.support_point.ia, it.support_point.ib);
        if it.repeat && g <= self.slack * norm {
            return Some(self.end_run(simplex, state, Status::Converged, solution, lower));
        }
        // Cutoff and margin are the world's: compared there.
        match self.exit_decided_by_bounds(lower, norm, cutoff, options.margin) {
            Some(Exit::Pruned) => {
                let mut run = self.end_run(simplex, state, Status::Converged, solution, lower);
                run.exit = Exit::Pruned;
                return Some(run);
            }
            Some(Exit::Status(status)) => {
                return Some(self.end_run(simplex, state, status, solution, lower));
            }
            None => {}
        }
        if state.iterations >= options.max_iterations {
            // Converged only where step (5) below would end the run
            // too: (6.2) alone holds for a |v| up to √ε·D off, which
            // a run without the cap goes on to remove (nearly parallel
            // edges capped at two iterations were called converged short
            // of their distance).
            let tight = norm - lower <= 4.0 * stop_d;
            let status = if it.paper_met && tight {
                Status::Converged
            } else {
                Status::IterationCap
            };
            // The nearer of the last two iterates (see step 5).
            let best = state.nearer_iterate(solution, it.v2);
            return Some(self.end_run(simplex, state, status, best, lower));
        }
        None
    }

    /// Step (4): descend while |v| decreases and V̂ is not full. A
    /// step that only grows V̂ by a dimension, with |v| unchanged at
    /// round-off level, is also progress (nearly parallel edges give
    /// such steps); a few are allowed before step (5) takes over.
    /// The budget counts level steps since |v|² last fell by more
    /// than 2⁻²⁰ (far above round-off) from one level step to the
    /// next. On a curved set far larger than |v| (an ellipsoid of 451
    /// points, size 5e5, 1.5e-3 from a disk), v's round-off, times
    /// the points' distance, picks a support point that the next
    /// subalgorithm drops: the step is level, its refined v leads
    /// on, and the next step descends. Counted over the whole run,
    /// four such pairs of steps ended it short of its distance.
    /// Whether the step was taken (the support point pushed).
    #[inline(always)]
    fn take_descent_step<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        state: &mut RunProgress,
        solution: &Solution,
        it: &Iterate,
    ) -> bool {
        let (solution, v2) = (*solution, it.v2);
        let budget = if v2 < state.level_v2 * (1.0 - 1.0 / 1_048_576.0) {
            0
        } else {
            state.flat_steps
        };
        let mut not_down = false;
        let descended = match state.previous {
            None => true,
            Some((_, previous_v2)) if v2 < previous_v2 => true,
            Some((previous, previous_v2)) => {
                let grew = solution.mask.count_ones() > previous.mask.count_ones();
                let flat = grew && v2 <= previous_v2 * (1.0 + 8.0 * f64::EPSILON);
                // |v| up by no more than its round-off while the new
                // support point, not yet in Y, lies beyond v's plane
                // by more than the tolerance: near contact, Johnson's
                // v of a new face can be εD worse than the refined v
                // of the last, and stopping there leaves |v| at
                // (6.2)'s √ε·D (nearly parallel edges touching).
                let level = it.norm <= previous_v2.sqrt() + self.slack;
                not_down = true;
                (flat || level) && budget < 4
            }
        };
        if descended && solution.mask.count_ones() <= 3 && !it.repeat {
            // Only a step taken counts against the budget: a repeat
            // refined within the iteration is the same step.
            if not_down {
                state.flat_steps = budget + 1;
                state.level_v2 = v2;
            }
            state.previous = Some((solution, v2));
            push_vertex::<AVX2>(simplex, solution.mask, it.support_point);
            return true;
        }
        false
    }

    /// Stuck with four points and a face chosen: a nearly flat
    /// tetrahedron's cofactors can reject it while it holds the
    /// origin (a collinear set touching a face ended at 3.5e-10 on
    /// objects of size 2, the support point repeating the dropped
    /// vertex). Refinement and the Backup Procedure work from the same
    /// cofactors; the exact orientation tests do not. Asked once: the
    /// run's end when the tetrahedron holds the origin.
    #[inline(always)]
    fn end_if_origin_inside(
        &self,
        simplex: &Simplex,
        state: &RunProgress,
        solution: &Solution,
        it: &Iterate,
        tried: &mut Tried,
    ) -> Option<RunOutcome> {
        if simplex.all == 0b1111 && solution.mask != 0b1111 && !tried.inside_asked {
            tried.inside_asked = true;
            if let Some(lambda) = simplex.origin_weights() {
                let origin = Solution {
                    mask: 0b1111,
                    v: Vector3::zeros(),
                    lambda,
                };
                return Some(self.end_run(simplex, state, Status::Converged, origin, it.lower));
            }
        }
        None
    }

    /// Steps (5) and (6) for an iterate that could not descend: the run's
    /// end, or else `solution` replaced by the `v` to take back to step (3),
    /// a repeat's refined `v` or the Backup Procedure's.
    #[inline(always)]
    fn refine_or_back_up(
        &self,
        simplex: &Simplex,
        state: &mut RunProgress,
        it: &Iterate,
        tried: &mut Tried,
        tolerance: Tolerance,
        solution: &mut Solution,
    ) -> Option<RunOutcome> {
        // A repeat with g above round-off: v carries the error of a
        // thin simplex's cofactors, or of the Backup Procedure's
        // (which redoes them). One refinement step in V̂'s affine hull
        // removes it, and the refined v goes back to step (3); the
        // Backup Procedure comes after, if needed.
        let refined_solution = if it.repeat && !tried.refined {
            tried.refined = true;
            simplex.refine(*solution)
        } else {
            None
        };
        // Step (5): round-off has the last word. The previous iterate,
        // if nearer, is still valid: its vertices kept their slots.
        // When (6.2) holds the paper would have stopped at step (3):
        // no Backup Procedure is needed to confirm that, unless the
        // support point repeats a point of Y (then (6.2) may hold
        // for a v that is off by up to √ε·D) and refinement is left,
        // or unless the interval is still wider than the tolerance:
        // near contact (6.2) holds for a v up to √ε·D off, and a
        // descent too small to show through v's round-off (|v| far
        // below |y|) stops the steps there. A cluster touching a
        // lattice surface ended so with an interval far wider than the
        // tolerance; the Backup Procedure's subset leads on to the
        // distance.
        let tight = it.norm - it.lower <= 4.0 * tolerance.stop_d;
        if refined_solution.is_none() && (tried.by_backup || (it.paper_met && !it.repeat && tight))
        {
            let status = if it.paper_met {
                Status::Converged
            } else {
                Status::ToleranceNotMet
            };
            // A step that failed to descend (round-off in a
            // degenerate simplex) leaves the previous iterate, whose
            // slots the push kept, as the better upper bound.
            let best = state.nearer_iterate(*solution, it.v2);
            return Some(self.end_run(simplex, state, status, best, it.lower));
        }
        match refined_solution {
            Some(refined) => *solution = refined,
            None => {
                // Step (6): redo v_k with the Backup Procedure. Its v
                // comes from the same kind of cofactors, so it may be
                // refined once too: a cluster against a box surface
                // ended far from its distance on the Backup Procedure's
                // thin triangle, the support point repeating one of its
                // vertices, while the refined v leads on to it.
                *solution = simplex.backup();
                tried.by_backup = true;
                tried.refined = false;
                state.backup_used = true;
            }
        }
        None
    }
}

/// The support point repeats a vertex the subalgorithm dropped,
/// which exact arithmetic rules out while g > 0: its weight was
/// lost to round-off (see `Simplex::regrow`). The grown subset's
/// v goes back to step (3) if it is no farther than round-off
/// allows; its support point then leads on. Asked once.
#[inline(always)]
fn regrow_dropped_vertex(
    simplex: &Simplex,
    solution: &Solution,
    it: &Iterate,
    tried: &mut Tried,
) -> Option<Solution> {
    if it.repeat && !tried.regrown {
        tried.regrown = true;
        if let Some(regrown_solution) =
            simplex.regrow(*solution, it.support_point.ia, it.support_point.ib)
        {
            let regrown_v2 = regrown_solution.v.norm_squared();
            if regrown_v2 <= it.v2 * (1.0 + 8.0 * f64::EPSILON) {
                return Some(regrown_solution);
            }
        }
    }
    None
}
