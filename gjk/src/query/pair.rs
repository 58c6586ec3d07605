//! A convex pair set up for one query: the pieces in the frame of A's
//! piece, scaled, with the round-off allowance of their bounds.

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

use super::Precision;
use crate::johnson::Vertex;
use crate::shape::Convex;

/// Two convex pieces in the frame of A's piece, origin at A's centroid: the
/// quantities that do not change during one query.
pub(super) struct Pair<'s> {
    pub(super) a: &'s Convex,
    pub(super) b: &'s Convex,
    /// Rotation of B's piece into A's piece frame.
    pub(super) r: Matrix3<f64>,
    /// B's centroid minus A's centroid, in A's piece frame: `z̄2 - z̄1`,
    /// times `k`.
    pub(super) t: Vector3<f64>,
    /// `D(K)` bounded by (6.4), times `k`.
    pub(super) d: f64,
    /// Allowance for floating-point error in the bounds, times `k`.
    pub(super) slack: f64,
    /// `slack` in the world's units.
    pub(super) slack_world: f64,
    pub(super) radii: f64,
    /// The power of two by which the run's frame is scaled, and its inverse.
    pub(super) k: f64,
    pub(super) inv_k: f64,
    /// Support search in f32 ([`Precision::Single`]).
    pub(super) single: bool,
    /// How far below the true support value the f32 search may land, as a
    /// distance times `k`: 0 in f64.
    pub(super) single_slack: f64,
}

/// Whether `iso` is the identity, exactly.
#[inline(always)]
pub(super) fn is_identity(iso: &Isometry3<f64>) -> bool {
    let q = iso.rotation.coords;
    let t = iso.translation.vector;
    (q.w == 1.0 && q.x == 0.0 && q.y == 0.0 && q.z == 0.0) && t == Vector3::zeros()
}

/// B's centroid minus A's in A's piece frame, the centroids placed in the
/// world in double-double (see `crate::dd`): for a frame far from its
/// vertices, where the f64 offset would cancel.
#[inline(always)]
pub(super) fn exact_centroid_gap(
    (pa, pb): (Place<'_>, Place<'_>),
    ca: &Point3<f64>,
    cb: &Point3<f64>,
) -> Vector3<f64> {
    let gap = crate::dd::centroid_gap((pa.pose, pa.offset), ca, (pb.pose, pb.offset), cb);
    // Into A's piece frame: the gap is small, so the rotation's rounding
    // costs only ε of it.
    let rotation = match pa.offset {
        Some(o) => pa.pose.rotation * o.rotation,
        None => pa.pose.rotation,
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
pub(super) struct Place<'p> {
    pub(super) pose: &'p Isometry3<f64>,
    pub(super) offset: Option<&'p Isometry3<f64>>,
}

impl<'s> Pair<'s> {
    /// The pair at relative pose `rel = A⁻¹·B`. `world` holds where each
    /// piece sits (its shape's pose and a compound piece's offset), for the
    /// exact centroid offset of a frame far from its vertices.
    #[inline(always)]
    pub(super) fn new(
        a: &'s Convex,
        b: &'s Convex,
        rel: &Isometry3<f64>,
        world: (Place<'_>, Place<'_>),
        precision: Precision,
    ) -> Self {
        let r = *rel.rotation.to_rotation_matrix().matrix();
        let rb = r * b.centroid().coords;
        let (ca, cb) = (a.centroid(), b.centroid());
        // Centroids far from their body origins (relative to the shapes'
        // sizes) make rb and the translation cancel: then the offset is
        // taken in world coordinates in double-double and rotated once.
        let (na, nb) = (a.centroid_norm(), b.centroid_norm());
        let far = na + nb > 16.0 * (a.size() + b.size());
        let (t, exact) = if far {
            (exact_centroid_gap(world, &ca, &cb), true)
        } else {
            (rb + rel.translation.vector - ca.coords, false)
        };
        // The run works in a frame scaled by a power of two that brings the
        // pair's sizes near 1: exact (every result is the unscaled one times
        // k, bit for bit), and the cofactors, products of up to three
        // squared lengths, then neither overflow nor underflow for shapes
        // anywhere from 1e-300 to 1e300 in size. Sizes within 2^±64 need no
        // scaling (k = 1): their cofactors stay within 2^±400.
        let m = a.size().max(b.size()).max(t.amax());
        let (k, inv_k) = if m > 5.4e-20 && m < 1.8e19 {
            (1.0, 1.0)
        } else {
            crate::shape::pow2_scale(m)
        };
        let t = t * k;
        let d = (a.size() + b.size()) * k + t.norm();
        let single = precision == Precision::Single;
        // The f32 search lands within SINGLE_SLACK·size·|η| of each shape's
        // support value; every direction it is given has |η| = |v|, so the
        // support value of K = A - B may be missed by this times |v|.
        let single_slack = if single {
            let of = |c: &Convex| if c.has_single() { c.size() } else { 0.0 };
            crate::shape::SINGLE_SLACK * (of(a) + of(b)) * k
        } else {
            0.0
        };
        // Every input to a dot product is at most `scale` in size; the sums of a
        // few products each carry a relative error of a few ε. 64 ε covers the
        // rotation, the centroid shift and the subalgorithm's weights with room.
        let scale = if exact {
            d
        } else {
            // |rb| = |z̄2|: a rotation keeps lengths.
            d + na * k + nb * k + crate::shape::robust_norm(&rel.translation.vector) * k
        };
        let slack = 64.0 * f64::EPSILON * scale;
        Pair {
            a,
            b,
            r,
            t,
            d,
            slack,
            slack_world: slack * inv_k,
            radii: a.radius() + b.radius(),
            k,
            inv_k,
            single,
            single_slack,
        }
    }

    /// `y = z1 - z2` for vertex `ia` of A and `ib` of B. The centroid-midpoint
    /// origin of (6.1) cancels in the difference; what matters is that both
    /// terms are small vectors relative to their centroids.
    #[inline(always)]
    pub(super) fn vertex(&self, ia: usize, ib: usize) -> Vertex {
        let (za, zb) = (self.a.local(ia), rotate(&self.r, &self.b.local(ib)));
        // k is 1 but for shapes beyond 2^±64 in size: skip the products
        // then. Each point is scaled after the rotation, not through a
        // scaled matrix, whose entries could be subnormal.
        let y = if self.k != 1.0 {
            za * self.k - (zb * self.k + self.t)
        } else {
            za - (zb + self.t)
        };
        Vertex {
            y,
            ia: ia as u32,
            ib: ib as u32,
        }
    }

    /// `s_K(η) = s_A(η) - s_B(-η)` (3.8): one scan of each vertex set.
    #[inline(always)]
    pub(super) fn support(&self, eta: &Vector3<f64>) -> Vertex {
        let eta_b = -rotate_back(&self.r, eta);
        let (ia, ib) = if self.single {
            (
                self.a.support_index_single(eta),
                self.b.support_index_single(&eta_b),
            )
        } else {
            (self.a.support_index(eta), self.b.support_index(&eta_b))
        };
        self.vertex(ia, ib)
    }
}
