//! The paper's Numerical Algorithm (Section 6), steps (1) to (6), on one
//! convex pair.

use nalgebra::Vector3;

use super::pair::ConvexPair;
use super::{Options, Status};
use crate::johnson::{Simplex, Solution, Vertex};

/// Johnson's subalgorithm in the query's compiled form (see
/// [`distance_avx2`](super::distance_avx2)).
#[inline(always)]
pub(super) fn subalgorithm<const AVX2: bool>(simplex: &Simplex) -> Option<Solution> {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: AVX2 is true only below `distance_avx2`, which is entered
        // after the CPU was found to support AVX2 and FMA.
        return unsafe { simplex.solve_avx2() };
    }
    simplex.solve()
}

/// [`Simplex::reset`] in the query's compiled form (see
/// [`distance_avx2`](super::distance_avx2)).
#[inline(always)]
pub(super) fn reset_simplex<const AVX2: bool>(simplex: &mut Simplex, points: &[Vertex]) {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: as in `subalgorithm`.
        unsafe { simplex.reset_avx2(points) };
        return;
    }
    simplex.reset(points);
}

/// [`Simplex::push`] in the query's compiled form (see
/// [`distance_avx2`](super::distance_avx2)).
#[inline(always)]
pub(super) fn push_vertex<const AVX2: bool>(simplex: &mut Simplex, keep: u8, point: Vertex) {
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: as in `subalgorithm`.
        unsafe { simplex.push_avx2(keep, point) };
        return;
    }
    simplex.push(keep, point);
}

/// One convex pair's run of the Numerical Algorithm.
pub(super) struct RunOutcome {
    /// Lower bound on the cores' penetration depth (5.9), 0 unless they touch
    /// or intersect.
    pub(super) core_depth: f64,
    pub(super) solution: Solution,
    /// `|v|`, zero when the cores touch or intersect.
    pub(super) norm: f64,
    /// Best lower bound on the core distance seen, before slack.
    pub(super) lower: f64,
    pub(super) iterations: u32,
    pub(super) exit: Exit,
    pub(super) backup_used: bool,
}

/// What a run carries from one iteration to the next.
pub(super) struct RunProgress {
    pub(super) iterations: u32,
    /// The last iterate that led to a step, with `|v|²`.
    pub(super) previous: Option<(Solution, f64)>,
    /// Best lower bound on the core distance seen, before slack.
    pub(super) lower: f64,
    pub(super) backup_used: bool,
    /// Steps taken without a measurable descent (see step 4) since the
    /// last real progress, and `|v|²` at the last of them.
    pub(super) flat_steps: u32,
    pub(super) level_v2: f64,
}

impl RunProgress {
    /// The nearer of `solution` (with `|v|² = v2`) and the last iterate that led
    /// to a step, whose vertices the step kept in their slots.
    #[inline(always)]
    pub(super) fn nearer_iterate(&self, solution: Solution, v2: f64) -> Solution {
        match self.previous {
            Some((previous, previous_v2)) if previous_v2 < v2 => previous,
            _ => solution,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Exit {
    Status(Status),
    /// The lower bound passed the caller's cutoff: this pair cannot be the
    /// nearest of a compound.
    Pruned,
}

impl ConvexPair<'_> {
    /// The Numerical Algorithm, steps (1) to (6): one run, its lengths in the
    /// world's units (the simplex's points stay in the scaled frame).
    #[inline(always)]
    pub(super) fn solve<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        warm: Option<&[[u32; 2]]>,
        cutoff: f64,
    ) -> RunOutcome {
        let mut run = self.solve_scaled::<AVX2>(simplex, options, warm, cutoff);
        if self.inv_scale != 1.0 {
            run.norm *= self.inv_scale;
            run.lower *= self.inv_scale;
            run.core_depth *= self.inv_scale;
            run.solution.v *= self.inv_scale;
        }
        run
    }

    /// [`solve`](Self::solve) in the scaled frame: every length in the
    /// returned run is `k` times the world's.
    ///
    /// The common iteration (the subalgorithm succeeds, the support point is
    /// new, `|v|` descends and no end is reached) is taken in this loop, which
    /// keeps few values live; any other outcome goes to [`step_in_full`](Self::step_in_full),
    /// out of line, which takes steps (3) to (6) in full from the same state.
    /// Both take the same decisions on the same values, so the split changes
    /// the time of a query, never its answer.
    #[inline(always)]
    pub(super) fn solve_scaled<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        warm: Option<&[[u32; 2]]>,
        cutoff: f64,
    ) -> RunOutcome {
        // Step (1): V0 from the warm start, else the single point s_K(z̄2 - z̄1).
        match warm {
            Some(pairs) => {
                let mut points = [Vertex::default(); 4];
                for (point, &[index_a, index_b]) in points.iter_mut().zip(pairs) {
                    *point = self.difference_vertex(index_a as usize, index_b as usize);
                }
                reset_simplex::<AVX2>(simplex, &points[..pairs.len()]);
            }
            None => simplex.start(self.support(&self.centroid_gap)),
        }
        let eps_d = options.tolerance * self.size_bound;
        // What the support search may miss is added to every test of g, so
        // that an f32 search stops where it can prove no more (0 in f64).
        let stop_d = eps_d + self.single_slack;
        let mut state = RunProgress {
            iterations: 0,
            previous: None,
            lower: 0.0,
            backup_used: false,
            flat_steps: 0,
            level_v2: f64::INFINITY,
        };
        loop {
            state.iterations += 1;
            // Step (2).
            let Some(solution) = subalgorithm::<AVX2>(simplex) else {
                state.backup_used = true;
                let solution = simplex.backup();
                match self.step_in_full::<AVX2>(
                    simplex, options, cutoff, &mut state, solution, true, None,
                ) {
                    Some(run) => return run,
                    None => continue,
                }
            };
            let v2 = solution.v.norm_squared();
            let norm = v2.sqrt();
            // Overflow (NaN fails the first test) and touching cores. The
            // cores' meeting, the end of every intersecting query, is taken
            // here as `step` would take it, without its call.
            if !(norm > self.slack && norm.is_finite()) {
                if norm <= self.slack {
                    return self.end_run(simplex, &state, Status::Converged, solution, 0.0);
                }
                match self.step_in_full::<AVX2>(
                    simplex, options, cutoff, &mut state, solution, false, None,
                ) {
                    Some(run) => return run,
                    None => continue,
                }
            }
            // Step (3).
            let support_point = self.support(&-solution.v);
            let v_dot_support = solution.v.dot(&support_point.y);
            let lower = state.lower.max(v_dot_support / norm - self.single_slack);
            let g = v2 - v_dot_support;
            if g <= stop_d * norm || norm <= eps_d {
                return self.end_run(simplex, &state, Status::Converged, solution, lower);
            }
            // Anything but a plain descent by a new point, and every other
            // way to end, is decided by `step`, from the start of step (3).
            let repeat = simplex.has_pair(simplex.all, support_point.ia, support_point.ib);
            let descends = match state.previous {
                None => true,
                Some((_, previous_v2)) => v2 < previous_v2,
            };
            if repeat
                || !descends
                || solution.mask == 0b1111
                || self
                    .exit_decided_by_bounds(lower, norm, cutoff, options.margin)
                    .is_some()
                || state.iterations >= options.max_iterations
            {
                match self.step_in_full::<AVX2>(
                    simplex,
                    options,
                    cutoff,
                    &mut state,
                    solution,
                    false,
                    Some(support_point),
                ) {
                    Some(run) => return run,
                    None => continue,
                }
            }
            // Step (4).
            state.lower = lower;
            state.previous = Some((solution, v2));
            push_vertex::<AVX2>(simplex, solution.mask, support_point);
        }
    }

    /// The early ends decided on the bounds alone, compared in the world's
    /// units: [`Exit::Pruned`] once the certified lower bound passes the
    /// caller's `cutoff` (this pair cannot be a compound's nearest), then,
    /// with a margin, [`Status::Farther`] or [`Status::Closer`] once the
    /// bounds decide it. `lower` is the run's lower bound, `norm` its `|v|`,
    /// both before slack and in the scaled frame.
    #[inline(always)]
    pub(super) fn exit_decided_by_bounds(
        &self,
        lower: f64,
        norm: f64,
        cutoff: f64,
        margin: Option<f64>,
    ) -> Option<Exit> {
        let lower_cert = (lower - self.slack) * self.inv_scale - self.radii;
        if lower_cert > cutoff {
            return Some(Exit::Pruned);
        }
        let m = margin?;
        if lower_cert.max(0.0) > m {
            return Some(Exit::Status(Status::Farther));
        }
        if ((norm + self.slack) * self.inv_scale - self.radii).max(0.0) <= m {
            return Some(Exit::Status(Status::Closer));
        }
        None
    }

    /// A run's end: its bounds and, when the cores touch or intersect, the
    /// penetration bound.
    #[inline(always)]
    pub(super) fn end_run(
        &self,
        simplex: &Simplex,
        state: &RunProgress,
        exit: Status,
        solution: Solution,
        lower: f64,
    ) -> RunOutcome {
        let norm = solution.v.norm();
        RunOutcome {
            core_depth: if norm <= self.slack {
                self.penetration_bound(simplex, &solution)
            } else {
                0.0
            },
            solution,
            norm,
            lower,
            iterations: state.iterations,
            exit: Exit::Status(exit),
            backup_used: state.backup_used,
        }
    }

    /// Steps (3) to (6) of the Numerical Algorithm for the subalgorithm's
    /// `solution` (from the Backup Procedure when `by_backup`), in full: the ends,
    /// repeats, flat steps, refinement and the Backup Procedure. `support`,
    /// when given, is `s_K(-v)` already found for this `solution`. `None` once a
    /// point has been added to the simplex (the next iteration begins),
    /// `Some` when the run ends.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step_in_full<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        cutoff: f64,
        state: &mut RunProgress,
        mut solution: Solution,
        mut by_backup: bool,
        mut support: Option<Vertex>,
    ) -> Option<RunOutcome> {
        let eps_d = options.tolerance * self.size_bound;
        let stop_d = eps_d + self.single_slack;
        let mut refined = false;
        let mut inside_asked = false;
        let mut regrown = false;
        loop {
            let v2 = solution.v.norm_squared();
            let norm = v2.sqrt();
            if !norm.is_finite() {
                // The subalgorithm overflowed. Fuzzing found points
                // ~1e108 apart whose cofactors exceeded f64 (before the
                // run was scaled to sizes near 1; kept as a guard, see
                // gjk/tests/fuzz_regressions.rs), and NaN weights would
                // make every bound below meaningless. Keep the last
                // finite iterate, or else a single vertex: each is a
                // point of the hull, so |v| stays an upper bound.
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
                return Some(RunOutcome {
                    core_depth: 0.0,
                    solution: best,
                    norm: best.v.norm(),
                    lower: state.lower,
                    iterations: state.iterations,
                    exit: Exit::Status(Status::ToleranceNotMet),
                    backup_used: state.backup_used,
                });
            }
            if norm <= self.slack {
                // v is the origin up to round-off: the cores touch or
                // intersect, and nothing finer can be certified.
                return Some(self.end_run(simplex, state, Status::Converged, solution, 0.0));
            }
            // Step (3): the stopping rule, and the bounds of Theorem 4.1.
            let support_point = match support.take() {
                Some(support_point) => support_point,
                None => self.support(&-solution.v),
            };
            let v_dot_support = solution.v.dot(&support_point.y);
            state.lower = state.lower.max(v_dot_support / norm - self.single_slack);
            let lower = state.lower;
            let g = v2 - v_dot_support;
            // (6.2): g <= ε·D². Near contact that rule alone lets |v|
            // exceed the distance by up to √ε·D (nearly parallel edges do
            // this), so once it holds the run goes on while |v| still
            // descends, and stops early only when the certified interval,
            // of width g/|v|, is within ε·D. A support point already in V̂
            // leaves nothing to add: g is then the error of v itself.
            let paper_met = g <= eps_d * self.size_bound + self.single_slack * norm;
            // The error of |v| is at most min(|v|, g/|v|): stop once that
            // is within ε·D, or within the round-off allowance when the
            // support point repeats a vertex of V̂. Beyond that, a repeat
            // means the subalgorithm's v is off by more than round-off
            // (a thin simplex: nearly parallel edges, or nearly collinear
            // points of K at contact): refinement, then steps (4) to (6).
            if g <= stop_d * norm || norm <= eps_d {
                return Some(self.end_run(simplex, state, Status::Converged, solution, lower));
            }
            let repeat = simplex.has_pair(simplex.all, support_point.ia, support_point.ib);
            if repeat && g <= self.slack * norm {
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
                // edges 6.19e-6 apart, capped at 2 iterations, stopped at
                // 6.23e-6 called converged).
                let tight = norm - lower <= 4.0 * stop_d;
                let status = if paper_met && tight {
                    Status::Converged
                } else {
                    Status::IterationCap
                };
                // The nearer of the last two iterates (see step 5).
                let best = state.nearer_iterate(solution, v2);
                return Some(self.end_run(simplex, state, status, best, lower));
            }
            // A step that does not descend refines v before it is taken or
            // given up (as a repeat does, below). Along a long thin edge of
            // K, v's error along the edge (ε times its length) can outweigh
            // v itself in the support search, and on a face of K normal to
            // v, whose points all tie, it alone picks the support point: a
            // needle of length 1.7 touching a lattice's face cycled between
            // two such points, each step level, and ended at 4.2e-10 against
            // a truth below 1.6e-17 (mid_sets seed 8593, pair 1844). The
            // refined v picks the point a step in exact arithmetic would.
            if !refined
                && !repeat
                && matches!(state.previous, Some((_, previous_v2)) if v2 >= previous_v2)
                && let Some(refined_solution) = simplex.refine(solution)
            {
                refined = true;
                solution = refined_solution;
                continue;
            }
            // Step (4): descend while |v| decreases and V̂ is not full. A
            // step that only grows V̂ by a dimension, with |v| unchanged at
            // round-off level, is also progress (nearly parallel edges give
            // such steps); a few are allowed before step (5) takes over.
            // The budget counts level steps since |v|² last fell by more
            // than 2⁻²⁰ (far above round-off) from one level step to the
            // next. On a curved set far larger than |v| (an ellipsoid of 451
            // points, size 5e5, 1.5e-3 from a disk), v's round-off, times
            // the points' distance, picks a support point that the next
            // subalgorithm drops: the step is level, its refined v leads
            // on, and the next step descends by a few per cent. Counted
            // over the whole run, four such pairs of steps ended it at
            // 1.548e-3, the truth 1.5335e-3 (mid_sets seed 8574, pair 7841).
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
                    let level = norm <= previous_v2.sqrt() + self.slack;
                    not_down = true;
                    (flat || level) && budget < 4
                }
            };
            if descended && solution.mask.count_ones() <= 3 && !repeat {
                // Only a step taken counts against the budget: a repeat
                // refined within the iteration is the same step.
                if not_down {
                    state.flat_steps = budget + 1;
                    state.level_v2 = v2;
                }
                state.previous = Some((solution, v2));
                push_vertex::<AVX2>(simplex, solution.mask, support_point);
                return None;
            }
            // Stuck with four points and a face chosen: a nearly flat
            // tetrahedron's cofactors can reject it while it holds the
            // origin (a collinear set touching a face ended at 3.5e-10 on
            // objects of size 2, the support point repeating the dropped
            // vertex). Refinement and the Backup Procedure work from the same
            // cofactors; the exact orientation tests do not. Asked once.
            if simplex.all == 0b1111 && solution.mask != 0b1111 && !inside_asked {
                inside_asked = true;
                if let Some(lambda) = simplex.origin_weights() {
                    let origin = Solution {
                        mask: 0b1111,
                        v: Vector3::zeros(),
                        lambda,
                    };
                    return Some(self.end_run(simplex, state, Status::Converged, origin, lower));
                }
            }
            // The support point repeats a vertex the subalgorithm dropped,
            // which exact arithmetic rules out while g > 0: its weight was
            // lost to round-off (see `Simplex::regrow`). The grown subset's
            // v goes back to step (3) if it is no farther than round-off
            // allows; its support point then leads on. Asked once.
            if repeat && !regrown {
                regrown = true;
                if let Some(regrown_solution) =
                    simplex.regrow(solution, support_point.ia, support_point.ib)
                {
                    let regrown_v2 = regrown_solution.v.norm_squared();
                    if regrown_v2 <= v2 * (1.0 + 8.0 * f64::EPSILON) {
                        solution = regrown_solution;
                        continue;
                    }
                }
            }
            // A repeat with g above round-off: v carries the error of a
            // thin simplex's cofactors, or of the Backup Procedure's
            // (which redoes them). One refinement step in V̂'s affine hull
            // removes it, and the refined v goes back to step (3); the
            // Backup Procedure comes after, if needed.
            let refined_sol = if repeat && !refined {
                refined = true;
                simplex.refine(solution)
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
            // descent too small to show through v's round-off (|v| 1e9
            // times below |y|) stops the steps there. A cluster touching
            // a lattice surface ended so at 1.6e-13 in [0, 1.6e-13], the
            // truth 2e-17 (mid_sets seed 8526, pair 2624); the Backup
            // Procedure's subset leads on to it.
            let tight = norm - lower <= 4.0 * stop_d;
            if refined_sol.is_none() && (by_backup || (paper_met && !repeat && tight)) {
                let status = if paper_met {
                    Status::Converged
                } else {
                    Status::ToleranceNotMet
                };
                // A step that failed to descend (round-off in a
                // degenerate simplex) leaves the previous iterate, whose
                // slots the push kept, as the better upper bound.
                let best = state.nearer_iterate(solution, v2);
                return Some(self.end_run(simplex, state, status, best, lower));
            }
            match refined_sol {
                Some(refined) => solution = refined,
                None => {
                    // Step (6): redo v_k with the Backup Procedure. Its v
                    // comes from the same kind of cofactors, so it may be
                    // refined once too: a cluster against a box surface
                    // (mid_sets seed 8531, pair 5372) ended at 4.7e-9 in
                    // [0, 4.7e-9] on the Backup Procedure's thin triangle,
                    // the support point repeating one of its vertices, while
                    // the refined v leads on to the truth, 4.8e-11.
                    solution = simplex.backup();
                    by_backup = true;
                    refined = false;
                    state.backup_used = true;
                }
            }
        }
    }
}
