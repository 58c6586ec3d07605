//! What a query returns, and how a convex pair's run becomes one: its
//! certified bounds, nearest points and penetration bound.

use nalgebra::{Point3, Vector3};

use super::Status;
use super::numerical_algorithm::{Exit, RunOutcome};
use super::pair::{ConvexPair, PiecePlacement, is_identity};
use super::warm_start::{PieceSimplex, WarmStart};
use crate::johnson::{Simplex, Solution};
use crate::support_map::SupportMap;

/// Everything a query returns. Distances are after radii; points are in world
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Answer {
    /// The distance between the (rounded) shapes, `>= 0`.
    pub distance: f64,
    /// Certified lower bound on the true distance (Theorem 4.1, widened by a
    /// bound on floating-point error).
    pub lower: f64,
    /// Certified upper bound on the true distance.
    pub upper: f64,
    /// Nearest point on A. When the shapes overlap, the deepest point of A's
    /// surface along `normal` (so `point_b - point_a = -penetration·normal`).
    /// When the cores touch or cross (`normal` zero), a point of A's core
    /// where they meet; `point_b` is B's, equal to it up to the round-off
    /// of the final simplex's weights.
    pub point_a: Point3<f64>,
    /// Nearest point on B, as `point_a`.
    pub point_b: Point3<f64>,
    /// Unit vector from A's nearest point towards B's; zero when the cores
    /// touch or intersect and no direction is defined.
    pub normal: Vector3<f64>,
    /// Lower bound on the penetration depth (the smallest translation that
    /// separates the shapes): 0 when separated, exact when only the rounded
    /// shells overlap, the inner radius of the final simplex (5.9) plus the
    /// radii when the cores intersect. For a compound, the largest of its
    /// piece pairs' bounds.
    pub penetration: f64,
    /// Subalgorithm iterations, summed over piece pairs for compounds.
    pub iterations: u32,
    /// How the query ended.
    pub status: Status,
    /// Whether the Backup Procedure (6.5) was needed.
    pub backup_used: bool,
    /// `[piece of A, piece of B]` that realise the distance (`[0, 0]` for two
    /// convex shapes). After an early exit on a margin, the pair nearest so
    /// far, which need not be the nearest of all.
    pub pieces: [u32; 2],
    /// The final simplex, for the next query of this pair.
    pub warm_start: WarmStart,
}

/// Whether every number of `answer` is finite. x·0 is NaN exactly when x is
/// infinite or NaN, and NaN survives the sums, whatever their order: a
/// balanced tree of sums, whose four-wide halves the compiler can vectorise.
#[inline(always)]
pub(super) fn all_finite(answer: &Answer) -> bool {
    let zeroed = |x: f64| x * 0.0;
    let (pa, pb, n) = (&answer.point_a, &answer.point_b, &answer.normal);
    let bounds = (zeroed(answer.distance) + zeroed(answer.lower))
        + (zeroed(answer.upper) + zeroed(answer.penetration));
    let points = (zeroed(pa.x) + zeroed(pa.y)) + (zeroed(pa.z) + zeroed(pb.x));
    let rest = (zeroed(pb.y) + zeroed(pb.z)) + (zeroed(n.x) + zeroed(n.y));
    ((bounds + points) + (rest + zeroed(n.z))) == 0.0
}

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
    /// A lower bound on the cores' penetration depth once `v` is the origin.
    /// (5.9) needs a tetrahedron around the origin. When the run stopped on a
    /// smaller simplex with `v` exactly zero (the first support point was the
    /// origin, as for identical shapes), one is built from the supports in
    /// tetrahedral directions; when `v` is merely within round-off of zero the
    /// origin lies on a face of the simplex, usually a touching contact, and
    /// the bound is 0. Either way it is cut by the round-off allowance, since
    /// it must never exceed the truth.
    #[cold]
    pub(super) fn penetration_bound(&self, simplex: &Simplex, solution: &Solution) -> f64 {
        let inner = if solution.mask == 0b1111 {
            simplex.inner_radius(self.slack)
        } else if solution.v != Vector3::zeros() {
            0.0
        } else {
            // The two tetrahedra inscribed in a cube between them use all its
            // corners, so one holds any point near a corner of a box-like K.
            let directions = [
                Vector3::new(1.0, 1.0, 1.0),
                Vector3::new(1.0, -1.0, -1.0),
                Vector3::new(-1.0, 1.0, -1.0),
                Vector3::new(-1.0, -1.0, 1.0),
            ];
            let mut tetra = Simplex::empty();
            let mut best = 0.0f64;
            for sign in [1.0, -1.0] {
                tetra.reset(&directions.map(|d| self.support(&(d * sign))));
                if let Some(solved) = tetra.solve()
                    && solved.mask == 0b1111
                {
                    best = best.max(tetra.inner_radius(self.slack));
                }
            }
            best
        };
        (inner - self.slack).max(0.0)
    }

    /// The certified `(lower, upper)` bounds of a run, after radii, and the
    /// distance reported between them.
    #[inline]
    pub(super) fn certified_bounds(&self, run: &RunOutcome) -> (f64, f64, f64) {
        let upper = (run.norm + self.slack_world - self.radii).max(0.0);
        let lower = (run.lower - self.slack_world - self.radii).max(0.0);
        // Not `clamp`: it panics when round-off beyond the slack has put
        // `lower` above `upper`; `distance` repairs that case.
        let distance = (run.norm - self.radii).max(0.0).max(lower).min(upper);
        (lower, upper, distance)
    }

    /// Turn a run into an answer in world coordinates. `place_a` places A's
    /// piece (its shape's pose and, for a compound, the piece's offset); B's
    /// nearest point is placed with it, as A's point minus `v`.
    #[inline(always)]
    pub(super) fn to_answer(
        &self,
        run: &RunOutcome,
        simplex: &Simplex,
        place_a: PiecePlacement<'_>,
        pieces: [u32; 2],
    ) -> Answer {
        let (pose_a, offset_a) = (place_a.pose, place_a.offset);
        let mut lambda = run.solution.lambda;
        if run.solution.mask == 0b1111
            && let Some(refined) = simplex.refine_origin(lambda, self.slack)
        {
            lambda = refined;
        }
        // A's nearest point relative to its centroid, and the vertex pairs
        // of the simplex's kept points.
        let mut nearest_a = Vector3::zeros();
        let mut pairs = [[0u32; 2]; 4];
        let mut len = 0;
        for (slot, (vertex, weight)) in simplex.vertices.iter().zip(lambda).enumerate() {
            if run.solution.mask & (1 << slot) != 0 {
                nearest_a += self.a.local_point(vertex.ia as usize) * weight;
                pairs[len & 3] = [vertex.ia, vertex.ib];
                len += 1;
            }
        }
        // Both nearest points in A's piece frame: B's is A's minus v, since
        // v = Σλ(a_i - b_i) with the same weights. One placement serves both,
        // and their gap is v itself, not the difference of two placements.
        let (rotation, shift) = match offset_a {
            Some(offset) if !is_identity(offset) => (
                pose_a.rotation * offset.rotation,
                pose_a.rotation * offset.translation.vector + pose_a.translation.vector,
            ),
            _ => (pose_a.rotation, pose_a.translation.vector),
        };
        let core_a = Point3::from(rotation * (self.a.centre().coords + nearest_a) + shift);
        let separated = run.norm > self.slack_world;
        // b - a = -v, in world coordinates. Where the cores touch or cross,
        // `v` is the origin by definition, and the weights' own sum
        // `Σλ_i y_i` stands in for it: B's point is then B's weighted sum
        // `Σλ_i b_i`, in B, however flat the final simplex (a needle
        // through a segment can leave that sum far from the origin, a
        // gap that `-v` would have put between B's point and B).
        let v = if separated {
            run.solution.v
        } else {
            let mut sum = Vector3::zeros();
            for (slot, (vertex, weight)) in simplex.vertices.iter().zip(lambda).enumerate() {
                if run.solution.mask & (1 << slot) != 0 {
                    sum += vertex.y * weight;
                }
            }
            sum * self.inv_scale
        };
        let gap = rotation * -v;
        let core_b = core_a + gap;
        let normal = if separated {
            gap * (1.0 / run.norm)
        } else {
            Vector3::zeros()
        };
        let penetration = if !separated {
            run.core_depth + self.radii
        } else {
            (self.radii - run.norm).max(0.0)
        };
        let (lower, upper, distance) = self.certified_bounds(run);
        Answer {
            distance,
            lower,
            upper,
            point_a: core_a + normal * self.a.rounding(),
            point_b: core_b - normal * self.b.rounding(),
            normal,
            penetration,
            iterations: run.iterations,
            status: match run.exit {
                Exit::Status(status) => status,
                Exit::Pruned => Status::Converged,
            },
            backup_used: run.backup_used,
            pieces,
            warm_start: WarmStart {
                first: PieceSimplex {
                    pieces,
                    len: len as u8,
                    pairs,
                },
                second: PieceSimplex::default(),
            },
        }
    }
}
