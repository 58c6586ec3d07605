//! The frame a piece pair's expansion runs in: A's piece frame with its
//! origin at A's centroid, scaled by a power of two that brings the pair's
//! size near 1, where the support points of `K = A - B` (cores only) are
//! small vectors whatever the poses, and their round-off is bounded.

use nalgebra::{Isometry3, Matrix3, Point3, UnitQuaternion, Vector3};

use crate::numeric::dd::centroid_gap;
use crate::query::core_run::Placed;
use crate::shape::Convex;
use crate::support_map::SupportMap;

/// How many units of round-off, relative to the frame's size, a computed
/// support point of `K` may be from the exact one: B's rotation into A's
/// frame, the centroid gap's rotation, the difference, a cylinder's rim
/// point (within 2 ε of the rim) and a support search's near-tie in the
/// last bit, with room to spare.
const POINT_UNITS: f64 = 64.0;

/// A point of the cores' difference with the two points it is the
/// difference of, in the frame (scaled).
#[derive(Clone, Copy, Debug)]
pub(super) struct Vertex {
    /// `a - b`.
    pub(super) y: Vector3<f64>,
    /// A's point.
    pub(super) a: Vector3<f64>,
}

/// A piece pair placed in the frame (see the module).
pub(super) struct PairFrame<'s, A = Convex, B = Convex> {
    a: &'s A,
    b: &'s B,
    /// B's piece frame into A's.
    rotation: Matrix3<f64>,
    /// B's centroid less A's, in A's piece frame (unscaled).
    shift: Vector3<f64>,
    /// A's piece frame in the world.
    rotation_a: UnitQuaternion<f64>,
    /// A's centroid in the world's frame, as `world_point` places it.
    place_a: Isometry3<f64>,
    centre_a: Point3<f64>,
    /// The power of two the frame is scaled by, and its inverse.
    pub(super) scale: f64,
    pub(super) inv_scale: f64,
    /// A bound on the round-off of each computed point (scaled).
    pub(super) delta: f64,
}

impl<'s, A: SupportMap, B: SupportMap> PairFrame<'s, A, B> {
    /// The frame of pieces `a` and `b` as they sit.
    pub(super) fn new(a: &Placed<'s, A>, b: &Placed<'s, B>) -> Self {
        let rel = b.relative_to(a);
        let rotation = *rel.rotation.to_rotation_matrix().matrix();
        // The centroids' gap in double-double in the world, rotated once:
        // exact for shapes far from the world's origin or from their own
        // body origins, where the relative pose's translation would cancel.
        let gap = centroid_gap(
            (a.pose, Some(a.offset)),
            &a.convex.centre(),
            (b.pose, Some(b.offset)),
            &b.convex.centre(),
        );
        let rotation_a = a.pose.rotation * a.offset.rotation;
        let shift = rotation_a.inverse_transform_vector(&gap);
        let size = shift.norm() + a.convex.size() + b.convex.size();
        let (scale, inv_scale) = power_of_two_near_inverse(size);
        PairFrame {
            a: a.convex,
            b: b.convex,
            rotation,
            shift,
            rotation_a,
            place_a: a.pose * a.offset,
            centre_a: a.convex.centre(),
            scale,
            inv_scale,
            delta: POINT_UNITS * f64::EPSILON * size * scale,
        }
    }

    /// The support point of the cores' difference along `dir` (frame).
    #[inline]
    pub(super) fn support(&self, dir: &Vector3<f64>) -> Vertex {
        let (_, a) = self.a.local_support(dir);
        let (_, b) = self.b.local_support(&self.rotation.tr_mul(&-dir));
        self.vertex(a, b)
    }

    /// The difference of the points of index `ia` on A and `ib` on B
    /// (a warm start's pair).
    #[inline]
    pub(super) fn point(&self, ia: u32, ib: u32) -> Vertex {
        let a = self.a.local_point(ia as usize);
        let b = self.b.local_point(ib as usize);
        self.vertex(a, b)
    }

    #[inline]
    fn vertex(&self, a: Vector3<f64>, b: Vector3<f64>) -> Vertex {
        let a = a * self.scale;
        let b = (self.rotation * b + self.shift) * self.scale;
        Vertex { y: a - b, a }
    }

    /// A frame point (scaled, relative to A's centroid) in the world.
    pub(super) fn world_point(&self, p: &Vector3<f64>) -> Point3<f64> {
        self.place_a * (self.centre_a + p * self.inv_scale)
    }

    /// A frame direction in the world.
    pub(super) fn world_vector(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.rotation_a * v
    }
}

/// `(2^-e, 2^e)` with `2^e` within a factor 2 of `size`: scaling by it is
/// exact, and keeps cross products of cross products (sizes to the sixth)
/// from underflow or overflow. `(1, 1)` for a size of 0.
fn power_of_two_near_inverse(size: f64) -> (f64, f64) {
    if !(size > 0.0 && size.is_finite()) {
        return (1.0, 1.0);
    }
    let e = size.log2().floor().clamp(-1000.0, 1000.0) as i32;
    (2f64.powi(-e), 2f64.powi(e))
}
