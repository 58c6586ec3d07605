//! A seed for the run of a pair with a cylinder: Newton's method on the
//! direction between the nearest points.
//!
//! On a cylinder's curved rim the plain run converges linearly (about one
//! iteration a decimal digit), where a polytope's ends at exact vertices in
//! three or four. The distance is the largest separation of the two
//! shapes' projections on a unit direction `u`,
//! `F(u) = -h_K(u) = -u·s_K(u)`, whose gradient is `-s_K(u)` and whose
//! Hessian is minus the sum of the shapes' support Hessians: a rim's is
//! `k·t·tᵀ` (`t` the rim's tangent, `k = r / |u_xy|`), a vertex's zero.
//! Newton's method on the unit sphere converges quadratically where `F` is
//! smooth. Where the answer lies on a flat feature (a cylinder's side, a
//! polytope's edge or face) `F` has a kink: a step that would cross a
//! cylinder's (where its support changes cap) stops on it, and a step that
//! changes a polytope's support vertex has crossed one. The difference of
//! the two support points is then perpendicular to the answer's direction,
//! and the steps go on in the directions perpendicular to it; a side whose
//! segment's nearest point turns out to be an end is let go again. The
//! support points at the final direction, with the partners of each kink,
//! are the seed. A warm start names its features exactly, so its seed
//! starts on them, from the direction of its points at the new pose.
//! Near a cylinder's axis, where the rim's curvature grows without bound
//! and a cap may hold the answer, the cap is tried in closed form
//! ([`cap`]), and steps towards the axis are cut to half the angle.
//!
//! The seed only chooses where the ordinary run starts: the run certifies
//! the bounds (Theorem 4.1) as for any start, so a seed on the wrong
//! feature, or none when the steps do not converge, costs time, never
//! exactness. Two shortcuts use the same bounds: where the supports at the
//! solved direction are themselves the nearest points (both on curved
//! features), their distance and the direction's separation certify the
//! answer with no run; otherwise the seed carries that separation, a lower
//! bound from which the run's first iteration certifies without a support
//! search of its own.
//!
//! Files: this one runs the steps ([`ConvexPair::newton_seed`],
//! [`ConvexPair::warm_seed`]); [`kinks`] holds the kinks a step keeps and
//! the small systems it solves, [`steps`] the step's arithmetic,
//! [`feature`] the features a support point lies on, [`cap`] the cap's
//! closed form.

pub(super) mod cap;
mod feature;
mod kinks;
mod steps;
#[cfg(test)]
mod tests;

use nalgebra::Vector3;

use super::pair::{ConvexPair, rotate, rotate_back};
use crate::johnson::Vertex;
use crate::shape::cylinder;
use crate::support_map::SupportMap;
use feature::Feature;
use kinks::{Constraints, Kinks, Solve, Touch, body_touch, cylinder_of};
use steps::{
    CAP_NEAR, cap_pair, certifies, newton_step, point_sum, seed_features, span_weights,
    stop_at_side, turn_triangle,
};

/// A seed: the simplex the run starts from (up to three points of `K`,
/// and how many), and a lower bound on the core distance (scaled; 0 when
/// the seed has none) that lets the run's first iteration certify without
/// a support search.
#[derive(Clone, Copy)]
pub(super) struct Seed {
    pub(super) points: [Vertex; 3],
    pub(super) len: usize,
    pub(super) lower: f64,
}

/// What Newton's steps end with.
pub(super) enum Seeding {
    /// The seed the run starts from.
    Start(Seed),
    /// One pair of supports is the answer: no run is needed.
    Certified(Certificate),
}

/// An answer certified by one pair of supports (see
/// [`ConvexPair::certify`]): their difference, a point of `K` whose length
/// is the upper bound, and the lower bound of the direction they were
/// taken in (scaled).
#[derive(Clone, Copy)]
pub(super) struct Certificate {
    pub(super) vertex: Vertex,
    pub(super) lower: f64,
}

/// Newton steps before the seed is given up.
const MAX_STEPS: u32 = 12;

/// How often a step that overshot the directions separating the shapes is
/// halved before the seed is given up.
const MAX_HALVINGS: u32 = 3;

/// The step (in radians) below which the direction has converged: the next
/// step would be of its square's order, and the run's stopping rule needs
/// the direction to about 1e-7.
pub(super) const CONVERGED_STEP: f64 = 3e-5;

/// The step (in radians) below which the supports at the next direction
/// may certify the answer (see `certify`): after a larger one the next
/// direction is too far off, and the test would only cost time.
const NEAR_STEP: f64 = 1e-3;

/// The tilt (in radians) towards a seed face's projection at which its
/// missing corner is sought (see `turn_face_triangle`): far above the
/// round-off of the face's support values, far below the angle to a
/// neighbouring face of any hull.
const FACE_TILT: f64 = 1e-6;

/// How far (in radians) a direction is turned off a face that does not
/// hold the answer, towards the edge that does (see `let_go_of_face`), as
/// `leave_false_sides` turns off a side.
const FACE_LEAVE: f64 = 1e-3;

/// How the steps close: with a seed (or the answer), or by finding that
/// a held polytope face does not hold the answer (see `let_go_of_face`).
enum Closing {
    Seeded(Seeding),
    OffFace {
        face: usize,
        keys: [u32; 2],
        away: Vector3<f64>,
    },
}

/// What [`ConvexPair::close_at`] ends with.
enum Close {
    Done(Seeding),
    /// A held kink was let go: the steps go on.
    Reopened,
    /// The direction has no part off the held kinks: no seed.
    Failed,
    /// The supports do not name the features a closed form assumed.
    Mismatch,
}

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
    /// Shape `k`'s cylinder (0 for A, 1 for B), as [`cylinder_of`]: each
    /// side through its own type, so that the loops treating both shapes
    /// alike inline each seed hook rather than call through a trait
    /// object (which cost seeded pairs about 1 % of their instructions).
    #[inline(always)]
    pub(super) fn cylinder_at(&self, k: usize) -> Option<(f64, f64)> {
        if k == 0 {
            cylinder_of(self.a)
        } else {
            cylinder_of(self.b)
        }
    }

    /// Shape `k`'s core point of index `index` (body frame, relative to
    /// its centre), through its own type as [`cylinder_at`](Self::cylinder_at).
    #[inline(always)]
    pub(super) fn point_at(&self, k: usize, index: usize) -> Vector3<f64> {
        if k == 0 {
            self.a.local_point(index)
        } else {
            self.b.local_point(index)
        }
    }

    /// Both shapes' supports at `u` (pair frame, unit): A's at `u`, B's at
    /// `-u`, B's moved into the pair frame.
    #[inline(always)]
    fn touches(&self, u: &Vector3<f64>) -> Option<[Touch; 2]> {
        let mut a = body_touch(self.a, u)?;
        let mut b = body_touch(self.b, &-rotate_back(&self.rotation, u))?;
        a.point *= self.scale;
        a.curvature *= self.scale;
        b.point = rotate(&self.rotation, &b.point) * self.scale + self.centroid_gap;
        b.curvature *= self.scale;
        b.tangent = rotate(&self.rotation, &b.tangent);
        b.axis = rotate(&self.rotation, &b.axis);
        Some([a, b])
    }

    /// The seed of a pair with a cylinder, from the direction `-v` of an
    /// iterate: at most three index pairs, or `None` when the solve fails
    /// (the shapes overlap, a direction along a cylinder's axis, no
    /// convergence).
    pub(super) fn newton_seed(&self, v: &Vector3<f64>, stop_d: f64) -> Option<Seeding> {
        let norm = v.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        self.solve_from(
            &mut Solve {
                u: -v / norm,
                ..Solve::default()
            },
            stop_d,
            None,
        )
    }

    /// The seed from a warm start's index pairs at the new pose: from the
    /// direction of their points' mean, on the features they name (a
    /// cylinder's side where both caps appear at one angle, a polytope's
    /// edges between its distinct vertices), which a converged simplex
    /// names exactly.
    pub(super) fn warm_seed(&self, pairs: &[[u32; 2]], stop_d: f64) -> Option<Seeding> {
        if pairs.is_empty() {
            return None;
        }
        if let Some(seed) = self.warm_cap_seed(pairs) {
            return Some(Seeding::Start(seed));
        }
        // The mean of the pairs' points at the new pose, each shape's
        // averaged first: one rotation, and each distinct point decoded
        // once.
        let share = 1.0 / pairs.len() as f64;
        let (sum_a, first_a) = point_sum(self.a, pairs, 0);
        let (sum_b, first_b) = point_sum(self.b, pairs, 1);
        let mean = self.difference_of((0, sum_a * share), (0, sum_b * share)).y;
        let mut solve = Solve::default();
        let mut features = [Feature::Other; 2];
        for k in 0..2 {
            let index = |pair: &[u32; 2]| pair[k];
            let first = index(&pairs[0]);
            if self.cylinder_at(k).is_some() {
                solve.side[k] = pairs.iter().any(|p| index(p) == cylinder::other_cap(first));
                let top = cylinder::is_top(first);
                // Several points of one cap that `warm_cap_seed` found not
                // to hold the answer are a rim's too: a run that crept
                // along the rim, its points a sliver apart, ended there.
                let one_cap = |p: &[u32; 2]| cylinder::is_top(index(p)) == top;
                features[k] = if solve.side[k] {
                    Feature::Side
                } else if pairs.iter().all(|p| index(p) == first)
                    || (cylinder::on_rim(first) && pairs.iter().all(one_cap))
                {
                    Feature::Rim(top)
                } else {
                    Feature::Other
                };
                continue;
            }
            for p in pairs {
                let key = index(p);
                if key != first && !solve.kinks[k].has(key) && solve.edge_count < 2 {
                    solve.kinks[k].add(first);
                    solve.kinks[k].add(key);
                    let edge = self.point_at(k, key as usize) - self.point_at(k, first as usize);
                    solve.edges[solve.edge_count] = self.in_pair_frame(k, edge);
                    solve.edge_count += 1;
                }
            }
            features[k] = match solve.kinks[k].len {
                0 => Feature::Vertex(first),
                2 if pairs.iter().all(|p| solve.kinks[k].has(index(p))) => Feature::Edge,
                3 if pairs.iter().all(|p| solve.kinks[k].has(index(p))) => Feature::Face,
                _ => Feature::Other,
            };
        }
        if !mean.iter().all(|x| x.is_finite()) {
            return None;
        }
        // What `Solve::constraints` gives, built in place: the call, out of
        // line there, measurably slowed every warm query.
        let mut held = Constraints::default();
        for (side, axis) in solve.side.iter().zip(self.axes()) {
            if *side {
                held.add_axis(axis);
            }
        }
        for edge in &solve.edges[..solve.edge_count] {
            held.add(*edge);
        }
        if let [Feature::Rim(_), Feature::Rim(_)] = features {
            let radial =
                |k: usize, x: Vector3<f64>| self.in_pair_frame(k, Vector3::new(x.x, x.y, 0.0));
            solve.rim_radials = [radial(0, first_a), radial(1, first_b)];
        }
        let guess = self.last_direction(&solve, features, [first_a, first_b], &mean);
        // Projected first and normalised once: the guess's length is not
        // needed.
        solve.u = held.project(&guess)?;
        solve.held = held;
        self.solve_from(&mut solve, stop_d, Some(features))
    }

    /// Where the answer's direction (unnormalised) was at the pose the warm
    /// start's `features` come from, as far as they tell, in the pair frame:
    /// a held side's rim direction is that direction (A's support
    /// direction is `u`, B's `-u`); a rim's lies in the plane of its axis
    /// and rim direction, which a held edge cuts to a line, and into which
    /// two rims move the direction of the mean of the warm start's points
    /// (`mean`) at the new pose. Otherwise the mean's direction. Along a
    /// motion the nearest points slide: the mean's direction turns by
    /// their slide over their distance, the features' by the slide over
    /// the curvatures' radii, far less where the shapes are near. `first`
    /// holds each shape's first warm point (body frame); two rims' radial
    /// directions are already in `solve.rim_radials`.
    fn last_direction(
        &self,
        solve: &Solve,
        features: [Feature; 2],
        first: [Vector3<f64>; 2],
        mean: &Vector3<f64>,
    ) -> Vector3<f64> {
        let radial = |k: usize| self.in_pair_frame(k, Vector3::new(first[k].x, first[k].y, 0.0));
        let rim_plane = |k: usize| self.axes()[k].cross(&radial(k));
        match features {
            [Feature::Side, _] => radial(0),
            [_, Feature::Side] => -radial(1),
            [Feature::Rim(_), Feature::Edge] | [Feature::Edge, Feature::Rim(_)] => {
                let k = usize::from(features[1] != Feature::Edge);
                let line = rim_plane(k).cross(&solve.edges[0]);
                if line.dot(mean) > 0.0 { -line } else { line }
            }
            // Each rim's plane holds it: the mean's direction moved into
            // one, then the other.
            [Feature::Rim(_), Feature::Rim(_)] => {
                let onto =
                    |x: Vector3<f64>, n: Vector3<f64>| x - n * (n.dot(&x) / n.norm_squared());
                let plane = |k: usize| self.axes()[k].cross(&solve.rim_radials[k]);
                onto(onto(-mean, plane(0)), plane(1))
            }
            _ => -mean,
        }
    }

    /// The cap seed (see `cap`) of each cylinder whose `rho` is below
    /// [`CAP_NEAR`] at `u`, each tried once.
    fn try_caps(&self, u: &Vector3<f64>, tried: &mut [bool; 2], rho: [f64; 2]) -> Option<Seeding> {
        for k in 0..2 {
            if !tried[k] && rho[k] < CAP_NEAR {
                tried[k] = true;
                if let Some(pairs) = self.cap_seed(k, u) {
                    return Some(Seeding::Start(self.seed_of_pairs(&pairs)));
                }
            }
        }
        None
    }

    /// The cap seed of a warm start whose pairs name a cap: two or more
    /// points of a cylinder, all on one cap (a cap's answer keeps a
    /// triangle of it).
    fn warm_cap_seed(&self, pairs: &[[u32; 2]]) -> Option<Seed> {
        for k in 0..2 {
            if self.cylinder_at(k).is_none() {
                continue;
            }
            let first = pairs[0][k];
            let (mut distinct, mut one_cap) = (false, true);
            for p in &pairs[1..] {
                distinct |= p[k] != first;
                one_cap &= cylinder::is_top(p[k]) == cylinder::is_top(first);
            }
            if !(distinct && one_cap) {
                continue;
            }
            // A's support direction towards the cap's side.
            let side = if cylinder::is_top(first) { 1.0 } else { -1.0 };
            let u = if k == 0 {
                Vector3::new(0.0, 0.0, side)
            } else {
                -rotate(&self.rotation, &Vector3::new(0.0, 0.0, side))
            };
            return self.cap_seed(k, &u).map(|pairs| self.seed_of_pairs(&pairs));
        }
        None
    }

    /// Shape `k`'s body vector `x` (0 for A, 1 for B) in the pair frame:
    /// A's as it is, B's turned by the rotation.
    #[inline(always)]
    pub(super) fn in_pair_frame(&self, k: usize, x: Vector3<f64>) -> Vector3<f64> {
        if k == 0 {
            x
        } else {
            rotate(&self.rotation, &x)
        }
    }

    /// The cylinders' axes in the pair frame (A's is its body's z axis, B's
    /// turned by the rotation); a polytope's is never read.
    #[inline(always)]
    pub(super) fn axes(&self) -> [Vector3<f64>; 2] {
        let r = &self.rotation;
        [Vector3::z(), Vector3::new(r[(0, 2)], r[(1, 2)], r[(2, 2)])]
    }

    /// Newton's steps from `solve` to the seed, or to the answer itself
    /// where the supports at the solved direction certify it within
    /// `stop_d` (the run's stopping rule, scaled). A warm start's
    /// `features` are first solved for in closed form (see
    /// `feature`).
    fn solve_from(
        &self,
        solve: &mut Solve,
        stop_d: f64,
        features: Option<[Feature; 2]>,
    ) -> Option<Seeding> {
        if let Some(features) = features
            && let Some(u) = self.feature_optimum(solve, features)
        {
            let start = solve.u;
            solve.u = u;
            match self.close_at(solve, stop_d, Some(features)) {
                Close::Done(seeding) => return Some(seeding),
                Close::Reopened => {}
                Close::Failed => return None,
                // Not the features the closed form assumed.
                Close::Mismatch => solve.u = start,
            }
        }
        let mut last: Option<[Touch; 2]> = None;
        let mut cap_tried = [false; 2];
        // Whether the supports may be the answer: at the start (a warm
        // start at the same pose) and after a step below `NEAR_STEP`.
        let mut near = true;
        // The last step taken (the direction before it, and the step) and
        // how often it was halved.
        let mut taken: Option<(Vector3<f64>, Vector3<f64>)> = None;
        let mut halvings = 0;
        for _ in 0..MAX_STEPS {
            let Some(touches) = self.touches(&solve.u) else {
                // Along an axis: only its cap can hold the answer.
                return self.try_caps(&solve.u, &mut cap_tried, [0.0; 2]);
            };
            // The supports here may already be the answer: a warm start at
            // the same pose, or a step that landed on it. Checked on the
            // closed forms' points; the certificate is taken from the
            // support search, whose codes name the points the answer
            // reports.
            let y = touches[0].point - touches[1].point;
            if near
                && certifies(&solve.u, &y, -solve.u.dot(&y), self.slack, stop_d)
                && let Some(done) = self.certify(&solve.u, self.support(&solve.u), stop_d)
            {
                return Some(Seeding::Certified(done));
            }
            let rho = [touches[0].rho, touches[1].rho];
            if rho.iter().any(|&rho| rho < CAP_NEAR)
                && let Some(seed) = self.try_caps(&solve.u, &mut cap_tried, rho)
            {
                return Some(seed);
            }
            if let Some(previous) = last
                && self.note_vertex_kinks(solve, &previous, &touches)
            {
                solve.held = solve.constraints(&self.axes());
                solve.u = solve.held.project(&solve.u)?;
                last = None;
                continue;
            }
            last = Some(touches);
            let Some(mut step) = newton_step(&solve.u, &solve.held, &touches) else {
                // The step overshot into directions along which the
                // shapes' projections overlap (near contact the directions
                // that separate them are a narrow cone): half of it, from
                // where it was taken.
                let (from, overshot) = taken?;
                if halvings == MAX_HALVINGS {
                    return None;
                }
                halvings += 1;
                let half = overshot * 0.5;
                solve.u = solve.held.project(&(from + half))?;
                taken = Some((from, half));
                last = None;
                continue;
            };
            let landed = stop_at_side(solve, &touches, &mut step);
            if landed {
                solve.held = solve.constraints(&self.axes());
            }
            // Near a cylinder's axis a turn of the direction turns its rim
            // point by that over `rho`: there the test is on the rim
            // point's turn.
            let converged_step = CONVERGED_STEP * (rho[0].min(rho[1]) / CAP_NEAR).min(1.0);
            let small = step.norm_squared() < converged_step * converged_step;
            near = step.norm_squared() < NEAR_STEP * NEAR_STEP;
            let converged = !landed && (small || solve.held.len == 2);
            taken = Some((solve.u, step));
            solve.u = solve.held.project(&(solve.u + step))?;
            if !converged {
                continue;
            }
            match self.close_at(solve, stop_d, None) {
                Close::Done(seeding) => return Some(seeding),
                Close::Reopened | Close::Mismatch => last = None,
                Close::Failed => return None,
            }
        }
        None
    }

    /// The close of the steps at the converged direction `solve.u`: the
    /// seed from the supports there, unless a held side or face turns out
    /// not to hold the answer (then it is let go and the steps go on from
    /// the direction turned off it, moved onto the kinks still held: a
    /// step from off them is moved back by as much, after the test that
    /// judged it converged), or the supports do not name the `features` a
    /// closed form assumed.
    fn close_at(&self, solve: &mut Solve, stop_d: f64, features: Option<[Feature; 2]>) -> Close {
        let u = solve.u;
        let d_b = -rotate_back(&self.rotation, &u);
        let (a, b) = (self.a.local_support(&u), self.b.local_support(&d_b));
        if let Some(features) = features
            && !self.features_hold(&solve.kinks, [(a.0, u), (b.0, d_b)], features)
        {
            return Close::Mismatch;
        }
        let support = self.difference_of(a, b);
        let tops = [a.0, b.0].map(|code| cylinder::is_top(code as u32));
        if solve.side != [false; 2] && self.leave_false_sides(solve, &support.y, tops) {
            solve.held = solve.constraints(&self.axes());
            return match solve.held.project(&solve.u) {
                Some(u) => {
                    solve.u = u;
                    Close::Reopened
                }
                None => Close::Failed,
            };
        }
        match self.seed_of_supports(solve, a, b, support, stop_d) {
            Closing::Seeded(seeding) => Close::Done(seeding),
            Closing::OffFace { face, keys, away } => {
                self.let_go_of_face(solve, face, keys, away);
                match solve.held.project(&solve.u) {
                    Some(u) => {
                        solve.u = u;
                        Close::Reopened
                    }
                    None => Close::Failed,
                }
            }
        }
    }

    /// The support point `support` of `K` at the unit direction `u`
    /// (A's at `u`, B's at `-u`) as the answer, when it is within `stop_d`
    /// of it: `y` is a point of `K`, so `|y|` bounds the distance from
    /// above, and `F = -u·y`, the separation of the shapes' projections on
    /// `u`, from below (Theorem 4.1's bounds, from one support each). Their
    /// gap `|y| - F` is `|y_⊥|² / (|y| + F)`, with `y_⊥` the part of `y`
    /// across `u`, so `|y_⊥|² <= 2·F·stop_d` certifies it without a square
    /// root. It holds where both supports lie on curved features (rims, a
    /// polytope's vertex); on a flat one they are its corners, far across
    /// `u`, and the test fails.
    #[inline(always)]
    fn certify(&self, u: &Vector3<f64>, support: Vertex, stop_d: f64) -> Option<Certificate> {
        let f = -u.dot(&support.y);
        // `u` is unit to a few ε: the error in `F` is within the slack.
        certifies(u, &support.y, f, self.slack, stop_d).then_some(Certificate {
            vertex: support,
            lower: f,
        })
    }

    /// Whether a held side kink does not hold the answer: the answer's
    /// direction must meet the face of `K` that the held kinks span (each
    /// side's segment, each polytope edge) within each side's segment; a
    /// side whose coefficient falls outside it is a rim point's, so the
    /// kink is let go and the direction moved off it towards that rim.
    /// `y` is the supports' difference at `solve.u`, `tops` whether each
    /// cylinder's support is on its top cap.
    fn leave_false_sides(&self, solve: &mut Solve, y: &Vector3<f64>, tops: [bool; 2]) -> bool {
        let u = solve.u;
        let flat = |x: Vector3<f64>| x - u * u.dot(&x);
        let y = flat(*y);
        let axes = self.axes();
        // Each span: the shape whose side it is (2 for an edge), its
        // vector in the tangent plane.
        let mut spans = [(2usize, Vector3::zeros()); 2];
        let mut count = 0;
        for k in 0..2 {
            if let (true, Some((_, h))) = (solve.side[k], self.cylinder_at(k))
                && count < 2
            {
                // y at the other cap minus y here: A's point moves down
                // from the top, B's move is subtracted.
                let down = if tops[k] { -1.0 } else { 1.0 };
                let sign = if k == 0 { down } else { -down };
                spans[count] = (k, flat(axes[k] * (2.0 * h * self.scale * sign)));
                count += 1;
            }
        }
        for edge in &solve.edges[..solve.edge_count] {
            if count < 2 {
                spans[count] = (2, flat(*edge));
                count += 1;
            }
        }
        let Some(alpha) = span_weights(&y, &spans[..count]) else {
            return false;
        };
        solve.this_top = tops;
        solve.face_weights = (count == 2 && spans[1].0 == 1).then_some(alpha);
        for (j, &(k, _)) in spans[..count].iter().enumerate() {
            if k == 2 || (-1e-9..=1.0 + 1e-9).contains(&alpha[j]) {
                continue;
            }
            // Below 0 the nearest end is this cap, above 1 the other: turn
            // towards the one (A's top faces +axis, B's top faces -axis).
            let toward_top = (alpha[j] < 0.0) == tops[k];
            let facing = if (k == 0) == toward_top { 1.0 } else { -1.0 };
            solve.side[k] = false;
            solve.off_side[k] = true;
            solve.u = (u + axes[k] * (1e-3 * facing)).normalize();
            return true;
        }
        false
    }

    /// Records the vertex kinks crossed between `previous` and `now`: a
    /// polytope's support vertex changed, so the answer's direction is
    /// perpendicular to the two vertices' difference. Whether a new
    /// constraint was added.
    fn note_vertex_kinks(
        &self,
        solve: &mut Solve,
        previous: &[Touch; 2],
        now: &[Touch; 2],
    ) -> bool {
        let mut added = false;
        for k in 0..2 {
            let (was, is) = (&previous[k], &now[k]);
            if was.key == is.key || is.axis != Vector3::zeros() || solve.off_face[k] {
                continue;
            }
            let kinks = &mut solve.kinks[k];
            if kinks.has(is.key) && kinks.has(was.key) {
                continue;
            }
            kinks.add(was.key);
            kinks.add(is.key);
            if solve.edge_count < 2 {
                solve.edges[solve.edge_count] = is.point - was.point;
                solve.edge_count += 1;
                added = true;
            }
        }
        added
    }

    /// The seed at the solved direction `solve.u` (unit), from the
    /// supports there (`a` of A, `b` of B, their difference `support`):
    /// the support points, each kink's partners included (at most three
    /// pairs), with the direction's lower bound, so that the run's first
    /// iteration certifies without a support search of its own; or the
    /// answer itself when the supports alone certify it (see
    /// [`certify`](Self::certify)).
    fn seed_of_supports(
        &self,
        solve: &Solve,
        a: (usize, Vector3<f64>),
        b: (usize, Vector3<f64>),
        support: Vertex,
        stop_d: f64,
    ) -> Closing {
        let u = solve.u;
        let lower = -u.dot(&support.y);
        // Kinks are flat features: there the supports never certify.
        if solve.held.len == 0
            && let Some(done) = self.certify(&u, support, stop_d)
        {
            return Closing::Seeded(Seeding::Certified(done));
        }
        let a = seed_features(self.a, a, &solve.kinks[0], solve.side[0]);
        let b = seed_features(self.b, b, &solve.kinks[1], solve.side[1]);
        let mut points = [Vertex::default(); 3];
        let len = if let Some([wa, wb]) = solve.face_weights {
            // Two sides: the triangle of their parallelogram that holds the
            // answer (four coplanar points would leave the subalgorithm a
            // flat tetrahedron).
            let [a_this, a_other] = cap_pair(&a.0, solve.this_top[0]);
            let [b_this, b_other] = cap_pair(&b.0, solve.this_top[1]);
            let corners = if wa + wb <= 1.0 {
                [(a_this, b_this), (a_other, b_this), (a_this, b_other)]
            } else {
                [(a_other, b_other), (a_other, b_this), (a_this, b_other)]
            };
            for (point, (fa, fb)) in points.iter_mut().zip(corners) {
                *point = self.difference_of(fa, fb);
            }
            3
        } else {
            // The first pair is the support's own.
            points[0] = support;
            let mut len = 1;
            for (j, &fb) in b.0[..b.1].iter().enumerate() {
                for &fa in &a.0[usize::from(j == 0)..a.1] {
                    if len < 3 {
                        points[len] = self.difference_of(fa, fb);
                        len += 1;
                    }
                }
            }
            // A polytope's face (its support and two kink vertices)
            // against one point of the other shape.
            let face = if len == 3 && a.1 == 1 && b.1 == 3 && !solve.side[0] {
                Some((1, a.0[0]))
            } else if len == 3 && a.1 == 3 && b.1 == 1 && !solve.side[1] {
                Some((0, b.0[0]))
            } else {
                None
            };
            if let Some((face, other)) = face {
                if let Some((keys, away)) = self.turn_face_triangle(&mut points, &u, face, other) {
                    return Closing::OffFace { face, keys, away };
                }
            } else if len == 3 && a.1 == 2 && b.1 == 2 {
                // A segment of each (a side, an edge): the points are three
                // corners of their parallelogram, the first opposite the
                // fourth.
                let fourth = self.difference_of(a.0[1], b.0[1]);
                // Past another edge the answer is off the parallelogram:
                // the run finds it.
                let _ = turn_triangle(&mut points, &u, |k, _| (k == 0).then_some(fourth));
            }
            len
        };
        Closing::Seeded(Seeding::Start(Seed { points, len, lower }))
    }

    /// Where a seed is a polytope's face against one point, the triangle
    /// of the face that holds the point's projection: the face's known
    /// vertices (the support and the kinks' partners) are three of its
    /// corners, and when the projection lies beyond them the run would
    /// start on the wrong half of the face and close in on a rim's point
    /// linearly, an iteration a digit. The missing corner is the support
    /// at the face's direction tilted across the edge that the projection
    /// lies past. Where the projection lies off the face (past an edge
    /// with no corner beyond it, or past an outer edge of the face's other
    /// half), the keys of that edge and the direction across it: the face
    /// does not hold the answer (see `let_go_of_face`).
    /// Shape `face` (0 for A) holds the face; `other` is the other
    /// shape's point; `u` the face's unit direction (A's support at `u`).
    #[cold]
    fn turn_face_triangle(
        &self,
        points: &mut [Vertex; 3],
        u: &Vector3<f64>,
        face: usize,
        other: (usize, Vector3<f64>),
    ) -> Option<([u32; 2], Vector3<f64>)> {
        let index = |v: &Vertex| if face == 0 { v.ia } else { v.ib };
        let known = points.map(|p| index(&p));
        let (i, j, away) = turn_triangle(points, u, |_, away| {
            // y = a - b: A's corner moves y with it, B's against it.
            let tilt = away * FACE_TILT;
            let corner = if face == 0 {
                self.difference_of(self.a.local_support(&(u + tilt)), other)
            } else {
                let d_b = -rotate_back(&self.rotation, &(u + tilt));
                self.difference_of(other, self.b.local_support(&d_b))
            };
            (!known.contains(&index(&corner))).then_some(corner)
        })?;
        Some(([index(&i), index(&j)], away))
    }

    /// Lets go of a held face of shape `face` that does not hold the
    /// answer (the other shape's point projects beyond its edge between
    /// vertices `keys`, past which it has no corner): Newton overshot the
    /// face's normal from an answer on that edge, and took the vertex
    /// change for a second kink. The edge alone is held again, the
    /// direction turned off the face towards it (`away`, in the plane),
    /// and the face's vertex changes are no longer kinks.
    fn let_go_of_face(&self, solve: &mut Solve, face: usize, keys: [u32; 2], away: Vector3<f64>) {
        let edge = self.in_pair_frame(
            face,
            self.point_at(face, keys[1] as usize) - self.point_at(face, keys[0] as usize),
        );
        solve.off_face[face] = true;
        solve.kinks[face] = Kinks {
            keys: [keys[0], keys[1], 0],
            len: 2,
        };
        solve.edges = [edge, Vector3::zeros()];
        solve.edge_count = 1;
        solve.held = Constraints::default();
        solve.held.add(edge);
        solve.u += away * FACE_LEAVE;
    }

    /// The seed of index pairs that another rule chose (a cap's), with no
    /// lower bound of its own.
    fn seed_of_pairs(&self, pairs: &[[u32; 2]; 3]) -> Seed {
        let mut points = [Vertex::default(); 3];
        for (point, &[ia, ib]) in points.iter_mut().zip(pairs) {
            *point = self.difference_vertex(ia as usize, ib as usize);
        }
        Seed {
            points,
            len: 3,
            lower: 0.0,
        }
    }
}
