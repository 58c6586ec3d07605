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
//! (`cap_seed`), and steps towards the axis are cut to half the angle.
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

use nalgebra::Vector3;

use super::feature_seed::Feature;
use super::pair::{ConvexPair, rotate, rotate_back};
use crate::johnson::{Vertex, triangle_weights};
use crate::shape::Convex;
use crate::shape::cylinder;

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

/// The sine of the angle to a cylinder's axis below which a direction is
/// tried against its cap (see `cap_seed`): Newton's steps close in on a
/// cap's answer without reaching it.
pub(super) const CAP_NEAR: f64 = 0.25;

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

/// One shape's support at a direction, in the pair frame (scaled).
#[derive(Clone, Copy)]
pub(super) struct Touch {
    /// The support point.
    point: Vector3<f64>,
    /// The vertex index, or for a cylinder its cap (0 or 1): a change is a
    /// kink.
    pub(super) key: u32,
    /// The support Hessian `k·t·tᵀ`: zero for a polytope.
    curvature: f64,
    tangent: Vector3<f64>,
    /// A cylinder's axis (the difference of its caps): zero for a polytope,
    /// whose kinks are the differences of its vertices.
    axis: Vector3<f64>,
    /// A cylinder's `|d_xy|` at the unit body direction `d` (the sine of
    /// its angle to the axis): infinite for a polytope.
    pub(super) rho: f64,
}

/// What one shape's kinks have shown: the support keys seen on either side
/// of each (a cylinder's two caps, a polytope's vertices), at most three.
#[derive(Clone, Copy, Default)]
pub(super) struct Kinks {
    pub(super) keys: [u32; 3],
    pub(super) len: usize,
}

impl Kinks {
    pub(super) fn has(&self, key: u32) -> bool {
        self.keys[..self.len].contains(&key)
    }

    fn add(&mut self, key: u32) -> bool {
        if self.has(key) || self.len == 3 {
            return false;
        }
        self.keys[self.len] = key;
        self.len += 1;
        true
    }
}

/// The directions the answer's direction is known to be perpendicular to,
/// orthonormal, at most two.
#[derive(Clone, Copy, Default)]
pub(super) struct Constraints {
    pub(super) axes: [Vector3<f64>; 2],
    pub(super) len: usize,
}

impl Constraints {
    /// Adds the unit `axis`: as [`add`](Self::add), with no normalisation
    /// when it is the first.
    fn add_axis(&mut self, axis: Vector3<f64>) {
        if self.len == 0 {
            self.axes[0] = axis;
            self.len = 1;
        } else {
            self.add(axis);
        }
    }

    /// Adds `c` (any length) unless it is (nearly) in the span of those
    /// already held.
    fn add(&mut self, mut c: Vector3<f64>) {
        let length = c.norm();
        for axis in &self.axes[..self.len] {
            c -= *axis * axis.dot(&c);
        }
        let norm = c.norm();
        if self.len < 2 && norm > 1e-6 * length {
            self.axes[self.len] = c / norm;
            self.len += 1;
        }
    }

    /// `u` moved onto the directions perpendicular to every constraint,
    /// unit; `None` if it has no such part.
    fn project(&self, u: &Vector3<f64>) -> Option<Vector3<f64>> {
        let p = self.project_unscaled(u);
        let norm = p.norm();
        (norm > 1e-12).then(|| p / norm)
    }

    /// [`project`](Self::project) without the normalisation.
    fn project_unscaled(&self, u: &Vector3<f64>) -> Vector3<f64> {
        match self.len {
            0 => *u,
            1 => u - self.axes[0] * self.axes[0].dot(u),
            _ => {
                let n = self.axes[0].cross(&self.axes[1]);
                n * n.dot(u).signum()
            }
        }
    }
}

/// The support of `shape` (a body frame's centroid-relative coordinates)
/// at the body direction `d` (unit), by the cylinder's closed form with its
/// curvature, or the polytope's support search. `None` at a cylinder's
/// axis, where the curvature is unbounded.
#[inline(always)]
fn body_touch(shape: &Convex, d: &Vector3<f64>) -> Option<Touch> {
    let Some((r, h)) = shape.cylinder_dimensions() else {
        let (index, point) = shape.support_point(d);
        return Some(Touch {
            point,
            key: index as u32,
            curvature: 0.0,
            tangent: Vector3::zeros(),
            axis: Vector3::zeros(),
            rho: f64::INFINITY,
        });
    };
    // |d| = 1: the squares neither overflow nor lose the direction.
    let rho = (d.x * d.x + d.y * d.y).sqrt();
    if rho.is_nan() || rho <= 1e-9 {
        return None;
    }
    let inv = 1.0 / rho;
    let (cx, sy) = (d.x * inv, d.y * inv);
    let top = d.z > 0.0;
    Some(Touch {
        point: Vector3::new(r * cx, r * sy, cylinder::negate_if(h, !top)),
        key: u32::from(top),
        curvature: r * inv,
        tangent: Vector3::new(-sy, cx, 0.0),
        axis: Vector3::z(),
        rho,
    })
}

/// A running Newton solve: the direction, each shape's kinks (a
/// cylinder's side, a polytope's vertices) and the edges they give.
#[derive(Default)]
pub(super) struct Solve {
    pub(super) u: Vector3<f64>,
    /// Whether the direction is held on each cylinder's side kink, and
    /// whether that kink was found not to hold the answer.
    side: [bool; 2],
    off_side: [bool; 2],
    /// Whether each polytope's held face was found not to hold the
    /// answer (see `let_go_of_face`): its vertex changes then add no edge.
    off_face: [bool; 2],
    pub(super) kinks: [Kinks; 2],
    /// Edges of the polytopes' kinks (differences of their vertices).
    edges: [Vector3<f64>; 2],
    edge_count: usize,
    /// Where the answer met two held sides' face: each side's weight from
    /// the cap it was found at (`this_top`) towards the other.
    face_weights: Option<[f64; 2]>,
    this_top: [bool; 2],
    /// The constraints of the held kinks, kept from one step to the next.
    pub(super) held: Constraints,
    /// Where a warm start names two rims, each one's radial direction at
    /// its warm point (pair frame, any length): where the closed form
    /// starts on the rims' angles (see `feature_seed`).
    pub(super) rim_radials: [Vector3<f64>; 2],
}

impl Solve {
    /// The constraints: each held side's axis (`axes`, the cylinders'
    /// in the pair frame), then the polytope edges.
    fn constraints(&self, axes: &[Vector3<f64>; 2]) -> Constraints {
        let mut out = Constraints::default();
        for (held, axis) in self.side.iter().zip(axes) {
            if *held {
                out.add_axis(*axis);
            }
        }
        for edge in &self.edges[..self.edge_count] {
            out.add(*edge);
        }
        out
    }
}

impl ConvexPair<'_> {
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
        for (k, shape) in [self.a, self.b].into_iter().enumerate() {
            let index = |pair: &[u32; 2]| pair[k];
            let first = index(&pairs[0]);
            if shape.cylinder_dimensions().is_some() {
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
                    let edge = shape.point(key as usize) - shape.point(first as usize);
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

    /// The cap seed (see `cap_seed`) of each cylinder whose `rho` is below
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
        for (k, shape) in [self.a, self.b].into_iter().enumerate() {
            if shape.cylinder_dimensions().is_none() {
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
    /// `feature_seed`).
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
        let (a, b) = (self.a.support_point(&u), self.b.support_point(&d_b));
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
        for (k, shape) in [self.a, self.b].into_iter().enumerate() {
            if let (true, Some((_, h))) = (solve.side[k], shape.cylinder_dimensions())
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
                self.difference_of(self.a.support_point(&(u + tilt)), other)
            } else {
                let d_b = -rotate_back(&self.rotation, &(u + tilt));
                self.difference_of(other, self.b.support_point(&d_b))
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
        let shape = if face == 0 { self.a } else { self.b };
        let edge = self.in_pair_frame(
            face,
            shape.point(keys[1] as usize) - shape.point(keys[0] as usize),
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

/// The sum of `shape`'s points named by the pairs (`k`: 0 for A's
/// index, 1 for B's), a point repeated from the pair before, or its other
/// cap's, not decoded again; and the first of them.
#[inline(always)]
fn point_sum(shape: &Convex, pairs: &[[u32; 2]], k: usize) -> (Vector3<f64>, Vector3<f64>) {
    let cylinder = shape.cylinder_dimensions().is_some();
    let mut sum = Vector3::zeros();
    let mut first = None;
    let mut last: Option<(u32, Vector3<f64>)> = None;
    for pair in pairs {
        let index = pair[k];
        let point = match last {
            Some((seen, point)) if seen == index => point,
            Some((seen, point)) if cylinder && seen == cylinder::other_cap(index) => {
                Vector3::new(point.x, point.y, -point.z)
            }
            _ => shape.point(index as usize),
        };
        last = Some((index, point));
        first.get_or_insert(point);
        sum += point;
    }
    (sum, first.unwrap_or_default())
}

/// Whether the point `y` of `K`, with `F = -u·y` at the unit `u`, is within
/// `stop_d` of the distance (see [`ConvexPair::certify`]), the shapes apart
/// by more than `slack`.
#[inline(always)]
fn certifies(u: &Vector3<f64>, y: &Vector3<f64>, f: f64, slack: f64, stop_d: f64) -> bool {
    let across = y + u * f;
    f > slack && across.norm_squared() <= 2.0 * f * stop_d
}

/// The seed triangle `points` (normal `u`, unit) turned to hold the
/// origin's projection on its plane: when the projection lies past one of
/// its edges, the corner opposite that edge is replaced by
/// `corner(opposite, away)` (`away` the unit direction across the edge,
/// in the plane), if the new triangle holds the projection. When `corner`
/// gives none, the edge's corners and `away`: nothing lies past that edge.
/// When the new triangle lies past another of its own edges, that edge's
/// corners and the direction across it: the projection is past both
/// halves of a face, off the face. Otherwise the seed stays as it is (the
/// run certifies from any start).
fn turn_triangle(
    points: &mut [Vertex; 3],
    u: &Vector3<f64>,
    corner: impl FnOnce(usize, Vector3<f64>) -> Option<Vertex>,
) -> Option<(Vertex, Vertex, Vector3<f64>)> {
    let projection = u * u.dot(&points[0].y);
    let weights = triangle_weights(points.map(|p| p.y), &projection)?;
    let (k, least) = least_weight(&weights);
    if least >= -HOLDS_SLACK {
        return None;
    }
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let away = away_across(points, u, k)?;
    let Some(corner) = corner(k, away) else {
        return Some((points[i], points[j], away));
    };
    let mut turned = *points;
    turned[k] = corner;
    let weights = triangle_weights(turned.map(|p| p.y), &projection)?;
    let (m, least) = least_weight(&weights);
    if least >= -HOLDS_SLACK {
        *points = turned;
        return None;
    }
    // Past the new corner's weight is back across the edge the turn
    // crossed: not a face's outer edge.
    if m == k {
        return None;
    }
    let away = away_across(&turned, u, m)?;
    Some((turned[(m + 1) % 3], turned[(m + 2) % 3], away))
}

/// The least of a triangle's three weights, and its corner.
fn least_weight(weights: &[f64; 3]) -> (usize, f64) {
    let (k, &least) = weights
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .expect("three weights");
    (k, least)
}

/// The unit direction in the plane across `u` (unit) from triangle
/// `points`' corner `k` across the edge opposite it, outwards; `None` for
/// a degenerate edge.
fn away_across(points: &[Vertex; 3], u: &Vector3<f64>, k: usize) -> Option<Vector3<f64>> {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let edge = points[j].y - points[i].y;
    let out = points[i].y - points[k].y;
    let away = out - edge * (edge.dot(&out) / edge.norm_squared());
    let away = away - u * u.dot(&away);
    let norm = away.norm();
    (norm > 0.0 && norm.is_finite()).then(|| away / norm)
}

/// How far outside a seed face's triangle its point's projection may lie,
/// in weights, and still count as held: round-off, not a wrong half.
const HOLDS_SLACK: f64 = 1e-9;

/// A shape's support point `support` (index and body point) and the
/// partners of its held kinks: a cylinder's other cap at the same angle,
/// a polytope's other kink vertices. At most three.
#[inline(always)]
fn seed_features(
    shape: &Convex,
    support: (usize, Vector3<f64>),
    kinks: &Kinks,
    side: bool,
) -> ([(usize, Vector3<f64>); 3], usize) {
    let mut out = ([support; 3], 1);
    if shape.cylinder_dimensions().is_some() {
        if side {
            let (code, point) = support;
            let other = cylinder::other_cap(code as u32) as usize;
            out.0[1] = (other, Vector3::new(point.x, point.y, -point.z));
            out.1 = 2;
        }
        return out;
    }
    for &key in &kinks.keys[..kinks.len] {
        if key as usize != support.0 && out.1 < 3 {
            out.0[out.1] = (key as usize, shape.point(key as usize));
            out.1 += 1;
        }
    }
    out
}

/// The Newton step at `solve.u` for the supports `touches`: the tangent
/// vector `ξ` with `(P·H·P + F)·ξ = -P·y`, `y = a - b`, `F = -u·y > 0`, `P`
/// the projection on the directions perpendicular to `u` and to the
/// constraints. `None` where the projections overlap (`F <= 0`).
#[inline(always)]
fn newton_step(
    u: &Vector3<f64>,
    constraints: &Constraints,
    touches: &[Touch; 2],
) -> Option<Vector3<f64>> {
    let u = *u;
    let y = touches[0].point - touches[1].point;
    let f = -u.dot(&y);
    if !(f > 0.0 && f.is_finite()) {
        return None;
    }
    let hessian = |e: &Vector3<f64>, g: &Vector3<f64>| {
        touches
            .iter()
            .map(|t| t.curvature * t.tangent.dot(e) * t.tangent.dot(g))
            .sum::<f64>()
    };
    match constraints.len {
        0 => Some(free_step(&u, &y, f, touches)),
        1 => {
            let e = u.cross(&constraints.axes[0]);
            Some(e * (-e.dot(&y) / (hessian(&e, &e) + f)))
        }
        _ => Some(Vector3::zeros()),
    }
    .map(|step: Vector3<f64>| {
        let step = toward_axes_by_half(step, touches);
        // Far from the answer the quadratic model is poor: no step turns
        // the direction by more than about half a radian.
        let squared = step.norm_squared();
        if squared > 0.25 {
            step * (0.5 / squared.sqrt())
        } else {
            step
        }
    })
}

/// `step` with its part towards each cylinder's axis cut to half the
/// direction's angle to it: near an axis the rim's curvature (`r / rho`)
/// changes faster than the quadratic model knows, and a full step would
/// cross the axis; the part along the rim is kept, so the rim point still
/// turns to the answer's.
#[inline(always)]
fn toward_axes_by_half(mut step: Vector3<f64>, touches: &[Touch; 2]) -> Vector3<f64> {
    for (k, touch) in touches.iter().enumerate() {
        if touch.rho >= CAP_NEAR {
            continue;
        }
        // The direction in which the angle to the axis grows: A's support
        // direction is `u`, B's `-u`.
        let outward = touch.tangent.cross(&touch.axis);
        let outward = if k == 0 { outward } else { -outward };
        let along = step.dot(&outward);
        let floor = -0.5 * touch.rho;
        if along < floor {
            step += outward * (floor - along);
        }
    }
    step
}

/// The unconstrained step: `(F + Σ k_i·p_i·p_iᵀ)·ξ = g`, `g = -P·y`,
/// `p_i = P·t_i`, by the Woodbury identity: a 2×2 solve for `α_i = p_i·ξ`,
/// then `ξ = (g - Σ k_i·α_i·p_i) / F`. No basis of the tangent plane, so
/// no square root.
#[inline(always)]
fn free_step(u: &Vector3<f64>, y: &Vector3<f64>, f: f64, touches: &[Touch; 2]) -> Vector3<f64> {
    let flat = |x: &Vector3<f64>| x - u * u.dot(x);
    let g = -flat(y);
    let (p1, p2) = (flat(&touches[0].tangent), flat(&touches[1].tangent));
    let (k1, k2) = (touches[0].curvature, touches[1].curvature);
    let (p11, p12, p22) = (p1.dot(&p1), p1.dot(&p2), p2.dot(&p2));
    let (m11, m12, m21, m22) = (f + k1 * p11, k2 * p12, k1 * p12, f + k2 * p22);
    let (r1, r2) = (p1.dot(&g), p2.dot(&g));
    let det = m11 * m22 - m12 * m21;
    let (a1, a2) = ((r1 * m22 - m12 * r2) / det, (m11 * r2 - m21 * r1) / det);
    (g - p1 * (k1 * a1) - p2 * (k2 * a2)) / f
}

/// Cuts `step` where it would first cross a cylinder's side kink (the
/// direction perpendicular to its axis, where its support changes cap) and
/// holds the direction there: Newton's quadratic model knows nothing of the
/// kink and would overshoot it. Whether it did.
fn stop_at_side(solve: &mut Solve, touches: &[Touch; 2], step: &mut Vector3<f64>) -> bool {
    let mut first: Option<(f64, usize)> = None;
    for (k, touch) in touches.iter().enumerate() {
        if touch.axis == Vector3::zeros() || solve.side[k] || solve.off_side[k] {
            continue;
        }
        let (now, change) = (touch.axis.dot(&solve.u), touch.axis.dot(step));
        if now * (now + change) >= 0.0 {
            continue;
        }
        let at = -now / change;
        if at > 0.0 && at < 1.0 && first.is_none_or(|(best, _)| at < best) {
            first = Some((at, k));
        }
    }
    let Some((at, k)) = first else {
        return false;
    };
    *step *= at;
    solve.side[k] = true;
    true
}

/// A cylinder's support point and its other cap's (`seed_features`), the
/// one on the cap named by `top` first.
fn cap_pair(features: &[(usize, Vector3<f64>); 3], top: bool) -> [(usize, Vector3<f64>); 2] {
    let [this, other, _] = *features;
    if cylinder::is_top(this.0 as u32) == top {
        [this, other]
    } else {
        [other, this]
    }
}

/// The weights `α` with `y + Σ α_j·span_j = 0` (least squares), for one
/// or two spans; `None` when they are degenerate.
fn span_weights(y: &Vector3<f64>, spans: &[(usize, Vector3<f64>)]) -> Option<[f64; 2]> {
    match spans {
        [(_, d)] => {
            let dd = d.norm_squared();
            (dd > 0.0).then(|| [-y.dot(d) / dd, 0.0])
        }
        [(_, d1), (_, d2)] => {
            let (m11, m12, m22) = (d1.norm_squared(), d1.dot(d2), d2.norm_squared());
            let det = m11 * m22 - m12 * m12;
            let (r1, r2) = (-y.dot(d1), -y.dot(d2));
            (det > 1e-12 * m11 * m22)
                .then(|| [(r1 * m22 - r2 * m12) / det, (m11 * r2 - m12 * r1) / det])
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

    use super::super::numerical_algorithm::RunOutcome;
    use super::super::pair::{ConvexPair, PiecePlacement};
    use super::{Seeding, turn_triangle};
    use crate::johnson::{Simplex, Vertex};
    use crate::shape::test_rng::Rng;
    use crate::{Convex, Options, Precision};

    /// The run of `a` at the identity against `b` at `pose`, seeded or
    /// plain, cold or from `warm`.
    fn run(
        a: &Convex,
        b: &Convex,
        pose: &Isometry3<f64>,
        seeded: bool,
        warm: Option<&[[u32; 2]]>,
    ) -> RunOutcome {
        run_at(&Isometry3::identity(), a, b, pose, seeded, warm)
    }

    /// [`run`] with both shapes moved by `base`.
    fn run_at(
        base: &Isometry3<f64>,
        a: &Convex,
        b: &Convex,
        pose: &Isometry3<f64>,
        seeded: bool,
        warm: Option<&[[u32; 2]]>,
    ) -> RunOutcome {
        let pose_b = base * pose;
        let rel = base.inv_mul(&pose_b);
        let place = |pose| PiecePlacement { pose, offset: None };
        let mut pair =
            ConvexPair::new(a, b, &rel, (place(base), place(&pose_b)), Precision::Double);
        if !seeded {
            pair.seed_after = u32::MAX;
        }
        let mut simplex = Simplex::empty();
        pair.solve::<false>(&mut simplex, &Options::default(), warm, f64::INFINITY)
    }

    /// A random pose of B about A, `reach` from it (times `scale`), at
    /// `offset` from the origin; `parallel` keeps B's axis along A's.
    fn pose(rng: &mut Rng, reach: f64, scale: f64, parallel: bool) -> Isometry3<f64> {
        let dir = Vector3::new(rng.next(), rng.next(), rng.next()).normalize();
        let rotation = if parallel {
            UnitQuaternion::from_euler_angles(0.0, 0.0, rng.next() * 3.0)
        } else {
            UnitQuaternion::from_euler_angles(rng.next() * 3.0, rng.next() * 3.0, rng.next() * 3.0)
        };
        Isometry3::from_parts(Translation3::from(dir * reach * scale), rotation)
    }

    /// The feature of a shape the unit normal `n` (body frame) meets: a
    /// cylinder's rim, side or cap, a box's vertex, edge or face.
    fn feature(shape: &Convex, n: &Vector3<f64>) -> &'static str {
        let flat = |x: f64| x.abs() < 1e-7;
        match shape.cylinder_dimensions() {
            Some(_) if flat(n.z) => "side",
            Some(_) if flat(n.x) && flat(n.y) => "cap",
            Some(_) => "rim",
            None => ["vertex", "edge", "face", "face"][n.iter().filter(|x| flat(**x)).count()],
        }
    }

    /// Seeded and plain runs agree within the tolerance on every pose (their
    /// certified intervals overlap), and the seed brings the runs on the
    /// rim, the side and the polytope's edges and vertices (the features
    /// Newton's steps switch between) to a few iterations, where the plain
    /// run's are many: cylinder against cylinder and against a box, crossing
    /// and parallel axes, from 1e-9 to 1e6 in size, near the origin and 1e6
    /// from it.
    #[test]
    fn seeded_runs_agree_with_plain_runs_in_few_iterations() {
        let mut rng = Rng(0x5eed_0e70_5eed_0001);
        let mut by_feature = std::collections::BTreeMap::<String, (u32, u32, u32)>::new();
        for scale in [1e-9, 1.0, 1e6] {
            let a = Convex::cylinder(0.5 * scale, 0.8 * scale, 0.0).unwrap();
            let cylinder = Convex::cylinder(0.3 * scale, 0.6 * scale, 0.0).unwrap();
            let cuboid = Convex::cuboid(Vector3::new(0.4, 0.3, 0.5) * scale, 0.0).unwrap();
            for k in 0..600 {
                let b = if k % 2 == 0 { &cylinder } else { &cuboid };
                let p = pose(&mut rng, [1.6, 2.2, 4.0][k % 3], scale, k % 5 == 0);
                // Every seventh pair 1e6 of its size from the origin.
                let shift = if k % 7 == 0 { 1e6 * scale } else { 0.0 };
                let base = Isometry3::translation(shift, -shift, shift);
                let (seeded, plain) = (
                    run_at(&base, &a, b, &p, true, None),
                    run_at(&base, &a, b, &p, false, None),
                );
                let tol = 1e-12 * scale;
                assert!(
                    seeded.lower <= plain.norm + tol && plain.lower <= seeded.norm + tol,
                    "scale {scale:e} pose {k}: seeded [{:e}, {:e}] plain [{:e}, {:e}]",
                    seeded.lower,
                    seeded.norm,
                    plain.lower,
                    plain.norm
                );
                assert!((seeded.norm - plain.norm).abs() <= 1e-9 * scale);
                if plain.norm <= 1e-6 * scale {
                    continue;
                }
                let n = plain.solution.v / -plain.norm;
                let nb = p.rotation.inverse() * -n;
                let key = format!("{}-{}", feature(&a, &n), feature(b, &nb));
                let entry = by_feature.entry(key).or_default();
                entry.0 += 1;
                entry.1 += seeded.iterations;
                entry.2 += plain.iterations;
            }
        }
        for key in [
            "rim-rim",
            "rim-side",
            "side-rim",
            "side-side",
            "rim-vertex",
            "rim-edge",
            "side-vertex",
        ] {
            let (count, seeded, plain) = by_feature[key];
            let (seeded, plain) = (
                f64::from(seeded) / f64::from(count),
                f64::from(plain) / f64::from(count),
            );
            assert!(count >= 10, "{key}: {count} poses");
            // A box edge against the rim is found by the support vertex
            // changing between steps, which far from the answer can name
            // the wrong edge: the seed helps there, but less.
            let (most, share) = if key == "rim-edge" {
                (15.0, 0.75)
            } else {
                (6.0, 0.5)
            };
            assert!(
                seeded <= most && seeded < share * plain,
                "{key}: {seeded} against {plain}"
            );
        }
    }

    /// The warm seed reads a converged simplex's features (a side where both
    /// caps appear at one angle, a box edge between two vertices) and,
    /// from the answer's own simplex, the run certifies in one iteration.
    #[test]
    fn warm_seeds_from_converged_simplexes_certify_at_once() {
        let a = Convex::cylinder(0.5, 0.8, 0.0).unwrap();
        let b = Convex::cylinder(0.3, 0.6, 0.0).unwrap();
        let cuboid = Convex::cuboid(Vector3::new(0.4, 0.3, 0.5), 0.0).unwrap();
        let mut rng = Rng(0x5eed_0e70_5eed_0002);
        let (mut checked, mut box_iterations) = (0, 0);
        for k in 0..300 {
            let other = if k % 2 == 0 { &b } else { &cuboid };
            let p = pose(&mut rng, [2.2, 4.0][k % 2], 1.0, k % 5 == 0);
            let cold = run(&a, other, &p, true, None);
            if cold.norm <= 1e-6 {
                continue;
            }
            let id = Isometry3::identity();
            let place = |pose| PiecePlacement { pose, offset: None };
            let pair = ConvexPair::new(&a, other, &p, (place(&id), place(&p)), Precision::Double);
            let mut simplex = Simplex::empty();
            let answer =
                pair.solve::<false>(&mut simplex, &Options::default(), None, f64::INFINITY);
            let kept = super::super::warm_start::PieceSimplex::from_simplex(
                &simplex,
                answer.solution.mask,
                [0, 0],
            );
            let warm = run(&a, other, &p, true, Some(kept.pairs()));
            assert!((warm.norm - cold.norm).abs() <= 1e-12, "pose {k}");
            // Cylinder pairs certify at once; a box's face can take the
            // plain run a few more.
            if k % 2 == 0 {
                assert!(
                    warm.iterations <= 2,
                    "pose {k}: {} iterations",
                    warm.iterations
                );
            }
            box_iterations += if k % 2 == 1 { warm.iterations } else { 0 };
            checked += 1;
        }
        assert!(checked > 150, "{checked}");
        assert!(
            f64::from(box_iterations) / f64::from(checked) < 1.5,
            "{box_iterations}"
        );
    }

    /// Where Newton's method cannot start it gives no seed, and the plain
    /// run answers: overlapping cylinders (no direction separates them).
    /// A direction along a cylinder's axis, whose rim curvature is
    /// unbounded, is seeded from the cap instead: coaxial caps 0.5 apart.
    #[test]
    fn no_seed_where_newton_cannot_start_and_the_plain_run_answers() {
        let a = Convex::cylinder(0.5, 0.8, 0.0).unwrap();
        let b = Convex::cylinder(0.3, 0.6, 0.0).unwrap();
        let id = Isometry3::identity();
        let place = |pose| PiecePlacement { pose, offset: None };
        let above = Isometry3::translation(0.0, 0.0, 1.9);
        let pair = ConvexPair::new(
            &a,
            &b,
            &above,
            (place(&id), place(&above)),
            Precision::Double,
        );
        let stop_d = Options::default().tolerance * pair.size_bound;
        let Some(Seeding::Start(seed)) = pair.newton_seed(&Vector3::new(0.0, 0.0, -1.0), stop_d)
        else {
            panic!("the cap seeds the coaxial pair");
        };
        let pairs: Vec<[u32; 2]> = seed.points[..seed.len]
            .iter()
            .map(|p| [p.ia, p.ib])
            .collect();
        let coaxial = run(&a, &b, &above, true, Some(&pairs));
        assert!((coaxial.norm - 0.5).abs() < 1e-12, "{}", coaxial.norm);
        assert!((coaxial.lower - 0.5).abs() < 1e-12, "{}", coaxial.lower);
        assert_eq!(coaxial.iterations, 1);
        let coaxial = run(&a, &b, &above, false, None);
        assert!((coaxial.norm - 0.5).abs() < 1e-12, "{}", coaxial.norm);
        let inside = Isometry3::translation(0.2, 0.1, 0.3);
        let pair = ConvexPair::new(
            &a,
            &b,
            &inside,
            (place(&id), place(&inside)),
            Precision::Double,
        );
        for v in [Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.3, -0.7, 0.2)] {
            assert!(pair.newton_seed(&v, 0.0).is_none(), "{v:?}");
        }
        assert_eq!(run(&a, &b, &inside, true, None).norm, 0.0);
        // A seed that the run cannot use (codes far from the answer) costs
        // iterations, never the answer.
        let beside = Isometry3::from_parts(
            Translation3::new(1.3, 0.4, 0.2),
            UnitQuaternion::from_euler_angles(0.3, 1.2, 0.1),
        );
        let plain = run(&a, &b, &beside, false, None);
        let far = run(
            &a,
            &b,
            &beside,
            true,
            Some(&[[7, 1 << 31], [1 << 30, 12345]]),
        );
        assert!((far.norm - plain.norm).abs() <= 1e-12);
    }

    /// A seed triangle of a unit square face (in the plane `z = 1`, `u`
    /// along `z`), the origin's projection at `(x, y)`: inside the first
    /// half, the seed stays; in the other half, it turns to the fourth
    /// corner; past an outer edge of the other half, off the face, the
    /// edge's corners and the outward direction come back; past an outer
    /// edge of the first half, where the support across the edge finds no
    /// new corner, the same.
    #[test]
    fn seed_triangles_turn_to_the_half_or_off_the_face() {
        // The face's corners less the projection: the origin projects
        // onto the face at `p`.
        let corner = |x: f64, y: f64, key: u32| Vertex {
            y: Vector3::new(x, y, 1.0),
            ia: 0,
            ib: key,
        };
        let u = Vector3::new(0.0, 0.0, -1.0);
        // Keys 0 to 3 at (0, 0), (1, 0), (1, 1), (0, 1); the seed is the
        // half (0, 1, 3), the fourth corner 2.
        let square = |p: (f64, f64)| {
            [(0.0, 0.0, 0), (1.0, 0.0, 1), (0.0, 1.0, 3)]
                .map(|(x, y, k)| corner(x - p.0, y - p.1, k))
        };
        let fourth = |p: (f64, f64), from: &[Vertex; 3]| {
            let mut known = from.map(|v| v.ib);
            known.sort_unstable();
            (known == [0, 1, 3]).then(|| corner(1.0 - p.0, 1.0 - p.1, 2))
        };
        let keys = |v: &[Vertex; 3]| {
            let mut k = v.map(|v| v.ib);
            k.sort_unstable();
            k
        };
        // Inside the seed's half.
        let p = (0.2, 0.3);
        let mut points = square(p);
        let seed = points;
        assert!(turn_triangle(&mut points, &u, |_, _| fourth(p, &seed)).is_none());
        assert_eq!(keys(&points), [0, 1, 3]);
        // In the other half: turned to it.
        let p = (0.8, 0.7);
        let mut points = square(p);
        let seed = points;
        assert!(turn_triangle(&mut points, &u, |_, _| fourth(p, &seed)).is_none());
        assert_eq!(keys(&points), [1, 2, 3]);
        // Past the other half's edge from (1, 0) to (1, 1): off the face,
        // outwards along x.
        let p = (1.3, 0.6);
        let mut points = square(p);
        let seed = points;
        let (i, j, away) =
            turn_triangle(&mut points, &u, |_, _| fourth(p, &seed)).expect("off the face");
        let mut edge = [i.ib, j.ib];
        edge.sort_unstable();
        assert_eq!(edge, [1, 2]);
        assert!((away - Vector3::x()).norm() < 1e-12, "{away:?}");
        assert_eq!(keys(&points), [0, 1, 3], "the seed stays");
        // Past the seed's own outer edge from (0, 0) to (1, 0), where the
        // support across it finds no new corner.
        let p = (0.4, -0.5);
        let mut points = square(p);
        let (i, j, away) = turn_triangle(&mut points, &u, |_, _| None).expect("off the face");
        let mut edge = [i.ib, j.ib];
        edge.sort_unstable();
        assert_eq!(edge, [0, 1]);
        assert!((away + Vector3::y()).norm() < 1e-12, "{away:?}");
    }
}
