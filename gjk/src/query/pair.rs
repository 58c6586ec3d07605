//! A convex pair set up for one query: the pieces in the frame of A's
//! piece, scaled, with the round-off allowance of their bounds.

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

use super::Precision;
use crate::johnson::Vertex;
use crate::shape::Convex;
use crate::support_map::SupportMap;

/// Two convex pieces in the frame of A's piece, origin at A's centroid: the
/// quantities that do not change during one query. Generic over the two
/// shapes' [`SupportMap`]s and monomorphised, so that each pair of types
/// gets its own loop with the support searches inlined; the stored
/// [`Convex`] pair is the default, what unions and the server run.
pub(super) struct ConvexPair<'s, A = Convex, B = Convex> {
    pub(super) a: &'s A,
    pub(super) b: &'s B,
    /// Rotation of B's piece into A's piece frame.
    pub(super) rotation: Matrix3<f64>,
    /// B's centroid minus A's centroid, in A's piece frame: `z̄2 - z̄1`,
    /// times `scale`.
    pub(super) centroid_gap: Vector3<f64>,
    /// `D(K)` bounded by (6.4), times `scale`.
    pub(super) size_bound: f64,
    /// Allowance for floating-point error in the bounds, times `scale`.
    pub(super) slack: f64,
    /// `slack` in the world's units.
    pub(super) slack_world: f64,
    /// The sum of the two pieces' radii.
    pub(super) radii: f64,
    /// The power of two by which the run's frame is scaled, and its inverse.
    pub(super) scale: f64,
    pub(super) inv_scale: f64,
    /// Support search in f32 ([`Precision::Single`]).
    pub(super) single_precision: bool,
    /// How far below the true support value the f32 search may land, as a
    /// distance times `scale`: 0 in f64.
    pub(super) single_slack: f64,
    /// The iteration after which the run is seeded by Newton's method on
    /// the nearest points' direction (see `seed`): never (`u32::MAX`)
    /// unless a piece is a cylinder.
    pub(super) seed_after: u32,
}

/// The plain iterations a cold run of a cylinder against a polytope takes
/// before it is seeded: from the single start point, Newton's vertex
/// changes would name wrong edges. Two cylinders are seeded after one.
pub(super) const COLD_SEED_AFTER: u32 = 2;

/// Whether `iso` is the identity, exactly.
#[inline(always)]
pub(crate) fn is_identity(iso: &Isometry3<f64>) -> bool {
    let q = iso.rotation.coords;
    let shift = iso.translation.vector;
    (q.w == 1.0 && q.x == 0.0 && q.y == 0.0 && q.z == 0.0) && shift == Vector3::zeros()
}

/// B's centroid minus A's in A's piece frame, the centroids placed in the
/// world in double-double (see `crate::dd`): for a frame far from its
/// vertices, where the f64 offset would cancel.
#[inline(always)]
pub(super) fn exact_centroid_gap(
    (place_a, place_b): (PiecePlacement<'_>, PiecePlacement<'_>),
    centroid_a: &Point3<f64>,
    centroid_b: &Point3<f64>,
) -> Vector3<f64> {
    let gap = crate::numeric::dd::centroid_gap(
        (place_a.pose, place_a.offset),
        centroid_a,
        (place_b.pose, place_b.offset),
        centroid_b,
    );
    // Into A's piece frame: the gap is small, so the rotation's rounding
    // costs only ε of it.
    let rotation = match place_a.offset {
        Some(offset) => place_a.pose.rotation * offset.rotation,
        None => place_a.pose.rotation,
    };
    rotation.inverse_transform_vector(&gap)
}

/// `R·z`, each component `(r_i0·z_0 + r_i1·z_1) + r_i2·z_2`: nalgebra's
/// product term for term and in its order, so bit for bit the same, written
/// out so that the hot loop keeps it in scalar registers.
#[inline(always)]
pub(super) fn rotate(r: &Matrix3<f64>, z: &Vector3<f64>) -> Vector3<f64> {
    let row = |i: usize| (r[(i, 0)] * z.x + r[(i, 1)] * z.y) + r[(i, 2)] * z.z;
    Vector3::new(row(0), row(1), row(2))
}

/// `Rᵀ·e`, as nalgebra's `tr_mul` (column dot products, in its order).
#[inline(always)]
pub(super) fn rotate_back(r: &Matrix3<f64>, e: &Vector3<f64>) -> Vector3<f64> {
    let col = |j: usize| (r[(0, j)] * e.x + r[(1, j)] * e.y) + r[(2, j)] * e.z;
    Vector3::new(col(0), col(1), col(2))
}

/// Where a piece sits: its shape's pose and, for a compound's piece, its offset
/// in the shape's body frame.
#[derive(Clone, Copy)]
pub(super) struct PiecePlacement<'p> {
    pub(super) pose: &'p Isometry3<f64>,
    pub(super) offset: Option<&'p Isometry3<f64>>,
}

impl<'s, A: SupportMap, B: SupportMap> ConvexPair<'s, A, B> {
    /// The pair at relative pose `rel = A⁻¹·B`. `world` holds where each
    /// piece sits (its shape's pose and a compound piece's offset), for the
    /// exact centroid offset of a frame far from its vertices.
    #[inline(always)]
    pub(super) fn new(
        a: &'s A,
        b: &'s B,
        rel: &Isometry3<f64>,
        world: (PiecePlacement<'_>, PiecePlacement<'_>),
        precision: Precision,
    ) -> Self {
        let rotation = *rel.rotation.to_rotation_matrix().matrix();
        let rotated_centroid_b = rotation * b.centre().coords;
        let (centroid_a, centroid_b) = (a.centre(), b.centre());
        // Centroids far from their body origins (relative to the shapes'
        // sizes) make the rotated centroid and the translation cancel: then
        // the offset is taken in world coordinates in double-double and
        // rotated once.
        let (norm_a, norm_b) = (a.centre_norm(), b.centre_norm());
        let far = norm_a + norm_b > 16.0 * (a.size() + b.size());
        let (centroid_gap, exact) = if far {
            (exact_centroid_gap(world, &centroid_a, &centroid_b), true)
        } else {
            (
                rotated_centroid_b + rel.translation.vector - centroid_a.coords,
                false,
            )
        };
        // The run works in a frame scaled by a power of two that brings the
        // pair's sizes near 1: exact (every result is the unscaled one times
        // `scale`, bit for bit), and the cofactors, products of up to three
        // squared lengths, then neither overflow nor underflow for shapes
        // anywhere from 1e-300 to 1e300 in size. Sizes within 2^±64 need no
        // scaling (`scale` = 1): their cofactors stay within 2^±400.
        let largest = a.size().max(b.size()).max(centroid_gap.amax());
        let (scale, inv_scale) = if largest > 5.4e-20 && largest < 1.8e19 {
            (1.0, 1.0)
        } else {
            crate::numeric::pow2_scale(largest)
        };
        let centroid_gap = centroid_gap * scale;
        let size_bound = (a.size() + b.size()) * scale + centroid_gap.norm();
        let single_precision = precision == Precision::Single;
        // The f32 search lands within SINGLE_SLACK·size·|η| of each shape's
        // support value; every direction it is given has |η| = |v|, so the
        // support value of K = A - B may be missed by this times |v|.
        let single_slack = if single_precision {
            crate::shape::polytope::single::SINGLE_SLACK
                * (a.single_size() + b.single_size())
                * scale
        } else {
            0.0
        };
        // Every input to a dot product is at most `magnitude` in size; the
        // sums of a few products each carry a relative error of a few ε.
        // 64 ε covers the rotation, the centroid shift and the
        // subalgorithm's weights with room.
        let magnitude = if exact {
            size_bound
        } else {
            // |rotated_centroid_b| = |z̄2|: a rotation keeps lengths.
            size_bound
                + norm_a * scale
                + norm_b * scale
                + crate::numeric::robust_norm(&rel.translation.vector) * scale
        };
        let slack = 64.0 * f64::EPSILON * magnitude;
        ConvexPair {
            a,
            b,
            rotation,
            centroid_gap,
            size_bound,
            slack,
            slack_world: slack * inv_scale,
            radii: a.rounding() + b.rounding(),
            scale,
            inv_scale,
            single_precision,
            single_slack,
            seed_after: match (a.seed_form(), b.seed_form()) {
                (Some(_), Some(_)) => 1,
                (Some(_), None) | (None, Some(_)) => COLD_SEED_AFTER,
                (None, None) => u32::MAX,
            },
        }
    }

    /// `y = z1 - z2` for point `ia` of A and `ib` of B (vertex indices, or
    /// a cylinder's codes). The centroid-midpoint
    /// origin of (6.1) cancels in the difference; what matters is that both
    /// terms are small vectors relative to their centroids.
    #[inline(always)]
    pub(super) fn difference_vertex(&self, ia: usize, ib: usize) -> Vertex {
        self.difference_of((ia, self.a.local_point(ia)), (ib, self.b.local_point(ib)))
    }

    /// `y = z1 - z2` for A's point `za` (index `ia`) and B's point `zb`
    /// (index `ib`), both relative to their centroids in their own frames.
    #[inline(always)]
    pub(super) fn difference_of(
        &self,
        (ia, za): (usize, Vector3<f64>),
        (ib, zb): (usize, Vector3<f64>),
    ) -> Vertex {
        let zb = rotate(&self.rotation, &zb);
        // k is 1 but for shapes beyond 2^±64 in size: skip the products
        // then. Each point is scaled after the rotation, not through a
        // scaled matrix, whose entries could be subnormal.
        let y = if self.scale != 1.0 {
            za * self.scale - (zb * self.scale + self.centroid_gap)
        } else {
            za - (zb + self.centroid_gap)
        };
        Vertex {
            y,
            ia: ia as u32,
            ib: ib as u32,
        }
    }

    /// `s_K(η) = s_A(η) - s_B(-η)` (3.8): one support search on each shape.
    #[inline(always)]
    pub(super) fn support(&self, eta: &Vector3<f64>) -> Vertex {
        let eta_b = -rotate_back(&self.rotation, eta);
        let (a, b) = if self.single_precision {
            (
                self.a.local_support_single(eta),
                self.b.local_support_single(&eta_b),
            )
        } else {
            (self.a.local_support(eta), self.b.local_support(&eta_b))
        };
        self.difference_of(a, b)
    }
}
