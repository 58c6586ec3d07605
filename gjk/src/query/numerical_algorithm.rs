//! The paper's Numerical Algorithm (Section 6), steps (1) to (6), on one
//! convex pair.

use super::pair::ConvexPair;
use super::seed::{Certificate, Seeding};
use super::{Options, Status};
use crate::johnson::{Simplex, Solution, Vertex};
use crate::support_map::SupportMap;

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

/// Seeds a run may take (see `newton_seed`), besides a warm start's: a
/// warm seed that names features the answer has left (a rim that moved
/// from an edge to the next) leaves the run as far from the answer as a
/// cold start, and it needs as many.
const MAX_SEEDS: u32 = 2;

/// Plain iterations after a seed before the next.
const RESEED_AFTER: u32 = 2;

/// The share of `|v|` an iterate's lower bound must reach for a seed
/// after the first, and the multiple of the round-off allowance.
const RESEED_SHARE: f64 = 0.5;
const RESEED_SLACKS: f64 = 1e6;

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

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
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
        // Two copies of the loop, by the seed hook's answer at the pair's
        // setup (`SupportMap::seed_form`): in this one the compiler knows
        // that `seed_after` is `u32::MAX` and drops every trace of the seed,
        // which keeps the time of the pairs without one.
        let mut run = if self.seed_after == u32::MAX {
            self.solve_scaled::<AVX2>(simplex, options, warm, cutoff)
        } else {
            self.solve_seeded::<AVX2>(simplex, options, warm, cutoff)
        };
        if self.inv_scale != 1.0 {
            run.norm *= self.inv_scale;
            run.lower *= self.inv_scale;
            run.core_depth *= self.inv_scale;
            run.solution.v *= self.inv_scale;
        }
        run
    }

    /// [`solve_scaled`](Self::solve_scaled) with the seed, out of line:
    /// inlined, its copy of the loop slowed the polytope pairs' beside it.
    #[inline(never)]
    fn solve_seeded<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        options: &Options,
        warm: Option<&[[u32; 2]]>,
        cutoff: f64,
    ) -> RunOutcome {
        self.solve_scaled::<AVX2>(simplex, options, warm, cutoff)
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
        // Step (1): V0 from the warm start (for a pair with a cylinder,
        // the seed solved from it), else the single point s_K(z̄2 - z̄1).
        // Whether the pair is seeded at all (see `seed`), from the hook.
        let seeded = self.seed_after != u32::MAX;
        let seed_after = self.seed_after;
        // The iteration from which the run is next seeded, how many seeds
        // it has left, and the share of `|v|` and the length its lower
        // bound must reach.
        let (mut next_seed, mut seeds_left) = (seed_after, MAX_SEEDS);
        // The first seed needs only a separating direction, but not one
        // whose lower bound is lost in round-off: on a touching contact
        // (a rim on a perpendicular cap) that direction comes late in the
        // run, and the seed's restart then spent what was left of the
        // iteration cap, ending far outside the tolerance.
        let (mut seed_share, mut seed_floor) = (0.0, RESEED_SLACKS * self.slack);
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
        match warm {
            Some(pairs) => match if seeded {
                self.warm_seed(pairs, stop_d)
            } else {
                None
            } {
                Some(Seeding::Certified(done)) => {
                    state.iterations = 1;
                    return self.certified_run::<AVX2>(simplex, &state, done);
                }
                Some(Seeding::Start(seed)) => {
                    (next_seed, seeds_left) = (1 + RESEED_AFTER, MAX_SEEDS);
                    (seed_share, seed_floor) = (RESEED_SHARE, RESEED_SLACKS * self.slack);
                    state.lower = seed.lower;
                    reset_simplex::<AVX2>(simplex, &seed.points[..seed.len]);
                }
                None => {
                    let mut points = [Vertex::default(); 4];
                    for (point, &[index_a, index_b]) in points.iter_mut().zip(pairs) {
                        *point = self.difference_vertex(index_a as usize, index_b as usize);
                    }
                    reset_simplex::<AVX2>(simplex, &points[..pairs.len()]);
                }
            },
            None => simplex.start(self.support(&self.centroid_gap)),
        }
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
            // A seed's own lower bound, from the direction it was solved
            // at, may already meet the stopping rule: then no support
            // search is needed.
            if seeded && norm - state.lower <= stop_d {
                return self.end_run(simplex, &state, Status::Converged, solution, state.lower);
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
            // Step (4), or the seed in its place.
            state.lower = lower;
            // Seeded from the first iterate (past `seed_after`) whose
            // direction separates the projections: from there Newton's
            // steps converge. A seed that named the wrong features (a box
            // edge guessed far from the answer) is followed by another,
            // from the nearer iterate the run has reached since, unless the
            // shapes nearly touch, relative to their distance or to the
            // round-off allowance: there Newton's steps divide by a
            // distance lost in round-off, and a fresh start would lose a
            // slow run's progress (a touching contact 1e9 from the origin
            // hit the iteration cap).
            if seeded
                && state.iterations >= next_seed
                && seeds_left > 0
                && v_dot_support > seed_share * v2
                && v_dot_support > seed_floor * norm
            {
                seeds_left -= 1;
                next_seed = state.iterations + RESEED_AFTER;
                (seed_share, seed_floor) = (RESEED_SHARE, RESEED_SLACKS * self.slack);
                match self.newton_seed(&solution.v, stop_d) {
                    Some(Seeding::Start(seed)) => {
                        state.lower = state.lower.max(seed.lower);
                        reset_simplex::<AVX2>(simplex, &seed.points[..seed.len]);
                        state.previous = None;
                        continue;
                    }
                    Some(Seeding::Certified(done)) => {
                        return self.certified_run::<AVX2>(simplex, &state, done);
                    }
                    None => {}
                }
            }
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

    /// A run ended by Newton's certificate (see `newton_seed`): its point
    /// is the simplex and the solution, its bound the larger of the run's
    /// and its own.
    #[inline(always)]
    fn certified_run<const AVX2: bool>(
        &self,
        simplex: &mut Simplex,
        state: &RunProgress,
        done: Certificate,
    ) -> RunOutcome {
        reset_simplex::<AVX2>(simplex, &[done.vertex]);
        let solution = Solution {
            mask: 1,
            v: done.vertex.y,
            lambda: [1.0, 0.0, 0.0, 0.0],
        };
        let lower = state.lower.max(done.lower);
        self.end_run(simplex, state, Status::Converged, solution, lower)
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
}
