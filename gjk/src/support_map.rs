//! [`SupportMap`]: a convex shape known by its support function, as in
//! parry; and the support of the difference of two placed shapes, with its
//! witness points, which GJK iterates on and a penetration depth (EPA)
//! expands.
//!
//! Every support point is taken relative to the shape's [`centre`]
//! (a polytope's centroid), as the query works in the centroid-origin frame
//! of the paper's (6.1): small vectors for shapes far from their body
//! origin. Support points carry an index (a vertex's position, or a
//! cylinder's point code, see [`Convex::cylinder`](crate::Convex::cylinder))
//! that names the point again in a warm start.
//!
//! [`centre`]: SupportMap::centre

use nalgebra::{Isometry3, Point3, Vector3};

/// A convex shape's support function, in its body frame.
///
/// The distance query is generic over it ([`distance_between`](crate::distance_between)
/// takes any two), monomorphised, so a support search is inlined where it
/// is cheap; the stored [`Convex`](crate::Convex) dispatches to its form by
/// one match, as parry's `TypedShape` does. A shape defined outside the
/// crate implements the six required methods and is queried as the
/// crate's own are, with the same bounds.
pub trait SupportMap {
    /// The point of the core (the rounding radius left out) farthest along
    /// `dir`, relative to [`centre`](Self::centre), with its index. Exact
    /// ties go to the lowest index. `dir` need not be unit.
    fn local_support(&self, dir: &Vector3<f64>) -> (usize, Vector3<f64>);

    /// The core's point of index `index`, relative to
    /// [`centre`](Self::centre): for an index that
    /// [`local_support`](Self::local_support) returned, the same point,
    /// bit for bit, as the answer's nearest points and a warm start are
    /// rebuilt from the indices alone. Any index below
    /// [`index_count`](Self::index_count) must name a point of the core.
    fn local_point(&self, index: usize) -> Vector3<f64>;

    /// The point every support point is relative to, in the body frame.
    fn centre(&self) -> Point3<f64>;

    /// The rounding radius grown around the core.
    fn rounding(&self) -> f64;

    /// An upper bound on the distance of every point of the core from
    /// [`centre`](Self::centre): the `D(coZ - z̄)` of the paper's (6.4),
    /// which scales the stopping rule and the round-off allowance.
    fn size(&self) -> f64;

    /// How many indices name a point: [`local_point`](Self::local_point)
    /// takes every index below this. A warm start naming another is
    /// refused ([`Error::WarmStartOutOfRange`](crate::Error::WarmStartOutOfRange)).
    fn index_count(&self) -> usize;

    /// `|centre|`, for the precision checks of a query; computed from
    /// [`centre`](Self::centre) by default, kept by a shape that stores it.
    fn centre_norm(&self) -> f64 {
        crate::numeric::robust_norm(&self.centre().coords)
    }

    /// The size that [`local_support_single`](Self::local_support_single)'s
    /// shortfall is relative to: a shape whose f32 search may land below
    /// the support value by up to `2^-20 · single_size · |dir|` returns
    /// its [`size`](Self::size); one whose search is exact, 0 (the default).
    fn single_size(&self) -> f64 {
        0.0
    }

    /// [`local_support`](Self::local_support) in f32 arithmetic where the
    /// shape has such a search ([`Precision::Single`](crate::Precision::Single)):
    /// the support value may then fall short by a slack the query allows
    /// for. The exact search by default.
    fn local_support_single(&self, dir: &Vector3<f64>) -> (usize, Vector3<f64>) {
        self.local_support(dir)
    }

    /// The seed hook: the curved core that the run's Newton seed solves
    /// for (see [`SeedForm`]), or `None` (the default, "no seed") for a
    /// shape whose plain run ends in a few iterations, as a polytope's
    /// does. A pair with a seed form is seeded, the others run the
    /// paper's plain loop; the query decides once, at the pair's setup.
    fn seed_form(&self) -> Option<SeedForm> {
        None
    }

    /// The support point of the shape, its radius included, at `pose`
    /// along the world direction `dir`, in world coordinates.
    fn support(&self, pose: &Isometry3<f64>, dir: &Vector3<f64>) -> SupportPoint {
        let local_dir = pose.rotation.inverse_transform_vector(dir);
        let (index, core) = self.local_support(&local_dir);
        let norm = local_dir.norm();
        let grown = if norm > 0.0 && self.rounding() > 0.0 {
            core + local_dir * (self.rounding() / norm)
        } else {
            core
        };
        SupportPoint {
            point: pose * (self.centre() + grown),
            index: index as u32,
        }
    }
}

/// A curved core with a closed form that the run seeds by Newton's method
/// on the direction between the nearest points, where a plain run would
/// converge one digit an iteration (see the query's `seed` module).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum SeedForm {
    /// A cylinder about the body z axis, centred at the body origin.
    Cylinder {
        /// The disk's radius.
        radius: f64,
        /// Half the length along the axis.
        half_height: f64,
    },
}

/// A support point in world coordinates with its index on its shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SupportPoint {
    /// The point, in world coordinates.
    pub point: Point3<f64>,
    /// The vertex index, or a cylinder's point code.
    pub index: u32,
}

/// A support point of the difference `A - B` with the two witness points
/// it is the difference of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DifferencePoint {
    /// `witness_a - witness_b`.
    pub point: Vector3<f64>,
    /// A's support point along the direction.
    pub witness_a: SupportPoint,
    /// B's support point against it.
    pub witness_b: SupportPoint,
}

/// The support point of `A - B` (each shape at its pose, radii included)
/// along the world direction `dir`: `s_A(dir) - s_B(-dir)`, (3.8) of the
/// paper, with the witnesses. What an expanding-polytope penetration depth
/// grows its polytope by.
///
/// ```
/// use gjk::{Convex, SupportMap, support_of_difference};
/// use nalgebra::{Isometry3, Vector3};
///
/// let a = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;
/// let b = Convex::sphere(0.5)?;
/// let s = support_of_difference(
///     &a, &Isometry3::identity(), &b, &Isometry3::translation(3.0, 0.0, 0.0), &Vector3::x(),
/// );
/// // A's corner (ties go to the lower faces) less B's nearest point.
/// assert_eq!(s.witness_a.point.coords, Vector3::new(1.0, -1.0, -1.0));
/// assert_eq!(s.witness_b.point.coords, Vector3::new(2.5, 0.0, 0.0));
/// assert_eq!(s.point, Vector3::new(-1.5, -1.0, -1.0));
/// # Ok::<(), gjk::Error>(())
/// ```
pub fn support_of_difference<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    pose_a: &Isometry3<f64>,
    b: &B,
    pose_b: &Isometry3<f64>,
    dir: &Vector3<f64>,
) -> DifferencePoint {
    let witness_a = a.support(pose_a, dir);
    let witness_b = b.support(pose_b, &-dir);
    DifferencePoint {
        point: witness_a.point - witness_b.point,
        witness_a,
        witness_b,
    }
}
