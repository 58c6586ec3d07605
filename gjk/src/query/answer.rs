//! What a query returns, and how a convex pair's run becomes one: its
//! certified bounds, nearest points and penetration bound.

use nalgebra::{Point3, Vector3};

use super::Status;
use super::numerical_algorithm::{Exit, Run};
use super::pair::{Pair, Place, is_identity};
use super::warm_start::{PieceSimplex, WarmStart};
use crate::johnson::{Simplex, Solution};

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
pub(super) fn is_finite(answer: &Answer) -> bool {
    let z = |x: f64| x * 0.0;
    let (pa, pb, n) = (&answer.point_a, &answer.point_b, &answer.normal);
    let s1 = (z(answer.distance) + z(answer.lower)) + (z(answer.upper) + z(answer.penetration));
    let s2 = (z(pa.x) + z(pa.y)) + (z(pa.z) + z(pb.x));
    let s3 = (z(pb.y) + z(pb.z)) + (z(n.x) + z(n.y));
    ((s1 + s2) + (s3 + z(n.z))) == 0.0
}

impl Pair<'_> {
    /// A lower bound on the cores' penetration depth once `v` is the origin.
    /// (5.9) needs a tetrahedron around the origin. When the run stopped on a
    /// smaller simplex with `v` exactly zero (the first support point was the
    /// origin, as for identical shapes), one is built from the supports in
    /// tetrahedral directions; when `v` is merely within round-off of zero the
    /// origin lies on a face of the simplex, usually a touching contact, and
    /// the bound is 0. Either way it is cut by the round-off allowance, since
    /// it must never exceed the truth.
    #[cold]
    pub(super) fn penetration(&self, simplex: &Simplex, sol: &Solution) -> f64 {
        let inner = if sol.mask == 0b1111 {
            simplex.inner_radius(self.slack)
        } else if sol.v != Vector3::zeros() {
            0.0
        } else {
            // The two tetrahedra inscribed in a cube between them use all its
            // corners, so one holds any point near a corner of a box-like K.
            let dirs = [
                Vector3::new(1.0, 1.0, 1.0),
                Vector3::new(1.0, -1.0, -1.0),
                Vector3::new(-1.0, 1.0, -1.0),
                Vector3::new(-1.0, -1.0, 1.0),
            ];
            let mut tetra = Simplex::empty();
            let mut best = 0.0f64;
            for sign in [1.0, -1.0] {
                tetra.reset(&dirs.map(|d| self.support(&(d * sign))));
                if let Some(s) = tetra.solve()
                    && s.mask == 0b1111
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
    pub(super) fn bounds(&self, run: &Run) -> (f64, f64, f64) {
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
    pub(super) fn answer(
        &self,
        run: &Run,
        simplex: &Simplex,
        place_a: Place<'_>,
        pieces: [u32; 2],
    ) -> Answer {
        let (pose_a, off_a) = (place_a.pose, place_a.offset);
        let mut lambda = run.sol.lambda;
        if run.sol.mask == 0b1111
            && let Some(l) = simplex.refine_origin(lambda, self.slack)
        {
            lambda = l;
        }
        let mut wa = Vector3::zeros();
        let mut pairs = [[0u32; 2]; 4];
        let mut len = 0;
        for (i, (vx, l)) in simplex.vertices.iter().zip(lambda).enumerate() {
            if run.sol.mask & (1 << i) != 0 {
                wa += self.a.local(vx.ia as usize) * l;
                pairs[len & 3] = [vx.ia, vx.ib];
                len += 1;
            }
        }
        // Both nearest points in A's piece frame: B's is A's minus v, since
        // v = Σλ(a_i - b_i) with the same weights. One placement serves both,
        // and their gap is v itself, not the difference of two placements.
        let (rot, shift) = match off_a {
            Some(o) if !is_identity(o) => (
                pose_a.rotation * o.rotation,
                pose_a.rotation * o.translation.vector + pose_a.translation.vector,
            ),
            _ => (pose_a.rotation, pose_a.translation.vector),
        };
        let core_a = Point3::from(rot * (self.a.centroid().coords + wa) + shift);
        // b - a = -v, in world coordinates.
        let gap = rot * -run.sol.v;
        let core_b = core_a + gap;
        let separated = run.norm > self.slack_world;
        let normal = if separated {
            gap * (1.0 / run.norm)
        } else {
            Vector3::zeros()
        };
        let (ra, rb) = (self.a.radius(), self.b.radius());
        let penetration = if !separated {
            run.inner + self.radii
        } else {
            (self.radii - run.norm).max(0.0)
        };
        let (lower, upper, distance) = self.bounds(run);
        Answer {
            distance,
            lower,
            upper,
            point_a: core_a + normal * ra,
            point_b: core_b - normal * rb,
            normal,
            penetration,
            iterations: run.iterations,
            status: match run.exit {
                Exit::Status(s) => s,
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
