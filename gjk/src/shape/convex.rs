//! [`Convex`], the stored convex shape: a polytope (the convex hull of a
//! vertex set) or a cylinder, either grown by a rounding radius. It keeps
//! what a query needs whatever the form (centroid, size bound, reach), and
//! hands the support search to its form's strategy by one match, as
//! parry's `TypedShape` hands a query to its shapes: the polytope's
//! searches are in [`super::polytope`], the cylinder's closed form in
//! [`super::cylinder`].

use nalgebra::{Point3, Vector3};

use super::build::{centroid_of, check_input, largest_length, relative_coordinates};
use super::cylinder;
use super::polytope::blocks::Blocks;
use super::polytope::cones::Cones;
use super::polytope::scan::scan_few;
#[cfg(target_arch = "x86_64")]
use super::polytope::scan_avx2::scan_avx2;
use super::polytope::single::F32Copy;
use super::polytope::{SupportKind, SupportSearch};
use super::reach::MAX_REACH;
use crate::Error;
use crate::numeric::robust_norm;
use crate::support_map::{SeedForm, SupportMap};

/// A convex object: the convex hull of a vertex set, grown by a radius `r >= 0`
/// (the paper's r-spherical extension, Section 2).
///
/// A single point with a radius is a sphere, two points a capsule, a box with a
/// radius a rounded box: model only what the scene needs. Vertices need not be
/// hull vertices; duplicates, collinear and coplanar sets are valid.
///
/// ```
/// use gjk::Convex;
/// use nalgebra::{Point3, Vector3};
///
/// let ball = Convex::sphere(0.5)?;
/// let pill = Convex::capsule(Point3::new(0.0, 0.0, -1.0), Point3::new(0.0, 0.0, 1.0), 0.2)?;
/// let crate_ = Convex::cuboid(Vector3::new(1.0, 2.0, 3.0), 0.05)?;
/// let tetra = Convex::new(
///     vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0), Point3::new(0.0, 0.0, 1.0)],
///     0.0,
/// )?;
/// assert_eq!(tetra.vertices().len(), 4);
/// # Ok::<(), gjk::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Convex {
    pub(super) vertices: Vec<Point3<f64>>,
    pub(super) radius: f64,
    pub(super) centroid: Point3<f64>,
    /// `|z̄|`, kept for the per-query precision checks.
    pub(super) centroid_norm: f64,
    /// `D(coZ - z̄)` of (6.4): the largest distance of a vertex from the centroid.
    pub(super) size: f64,
    /// Vertices relative to the centroid, one array per coordinate, so that the
    /// support scan reads memory linearly and vectorises. Kept relative to the
    /// centroid so that a body frame far from its vertices loses no precision.
    pub(super) xs: Vec<f64>,
    pub(super) ys: Vec<f64>,
    pub(super) zs: Vec<f64>,
    /// How the support point is found: a scan in general, a closed form for
    /// the shapes whose support function is one.
    pub(super) kind: SupportKind,
    /// The scanned vertices again in f32, divided by `size` so that every
    /// coordinate lies in [-1, 1] (no overflow, whatever the shape's scale),
    /// for [`Precision::Single`](crate::Precision::Single). None for shapes
    /// that gain nothing from it: closed-form supports, fewer than
    /// [`SINGLE_MIN_VERTICES`] vertices, and [`SINGLE_MAX_VERTICES`] or more.
    pub(super) single: Option<Box<F32Copy>>,
    /// The block search's reordered copy, for [`SupportKind::Blocks`].
    pub(super) blocks: Option<Box<Blocks>>,
    /// The cube map of candidate lists, for [`SupportKind::Cones`].
    pub(super) cones: Option<Box<Cones>>,
}

impl Convex {
    /// The convex hull of `vertices` grown by `radius`.
    ///
    /// Sets of 512 vertices or more also get an index for the support
    /// search: the vertices sorted into blocks of nearby points (a copy,
    /// 28 bytes a vertex), built in O(n log n), which makes building a large
    /// shape several times slower than without it.
    ///
    /// # Errors
    /// [`Error::EmptyVertices`] for no vertices, [`Error::TooManyVertices`] past
    /// `u32::MAX`, [`Error::NonFiniteVertex`] for NaN or infinity or a shape
    /// (vertices plus radius) reaching more than 2^999 (about 5e300) from
    /// the body origin, and [`Error::InvalidRadius`] for a radius that is
    /// negative, not finite, or itself above 2^999.
    pub fn new(vertices: impl Into<Vec<Point3<f64>>>, radius: f64) -> Result<Self, Error> {
        let vertices = vertices.into();
        check_input(&vertices, radius)?;
        let centroid = centroid_of(&vertices)?;
        let ((mut xs, mut ys, mut zs), widest) = relative_coordinates(&vertices, &centroid)?;
        let len = vertices.len();
        let size = largest_length(&xs, &ys, &zs, widest)?;
        let centroid_norm = robust_norm(&centroid.coords);
        // The radius counts too: a query's distances and points are the
        // core's grown by it, and must stay as far from overflow.
        if centroid_norm + size + radius > MAX_REACH {
            return Err(Error::NonFiniteVertex(0));
        }
        // Pad the scan arrays to whole vector steps with copies of vertex 0:
        // a copy never beats the original (ties go to the lowest index), and
        // the vector scan then needs no scalar tail with its unpredictable exit.
        if len >= 8 {
            let padded = len.div_ceil(8) * 8;
            for coord in [&mut xs, &mut ys, &mut zs] {
                coord.resize(padded, coord[0]);
            }
        }
        let search = SupportSearch::choose(&xs, &ys, &zs, len, size);
        Ok(Self {
            vertices,
            radius,
            centroid,
            centroid_norm,
            size,
            xs,
            ys,
            zs,
            kind: search.kind,
            single: search.single,
            blocks: search.blocks,
            cones: search.cones,
        })
    }

    /// A sphere: one point at the body origin with a radius.
    ///
    /// # Errors
    /// [`Error::InvalidRadius`] for a radius that is negative, not finite, or
    /// above 2^999 (about 5e300).
    pub fn sphere(radius: f64) -> Result<Self, Error> {
        Self::new(vec![Point3::origin()], radius)
    }

    /// A capsule: the segment from `a` to `b` grown by `radius`.
    ///
    /// # Errors
    /// As [`Convex::new`].
    pub fn capsule(a: Point3<f64>, b: Point3<f64>, radius: f64) -> Result<Self, Error> {
        Self::new(vec![a, b], radius)
    }

    /// A box centred on the body origin with the given half extents, its edges
    /// rounded by `radius` (0 for a sharp box).
    ///
    /// # Errors
    /// [`Error::NonFiniteVertex`] for a non-finite or negative half extent, and
    /// as [`Convex::new`] for the radius.
    pub fn cuboid(half_extents: Vector3<f64>, radius: f64) -> Result<Self, Error> {
        if !half_extents.iter().all(|h| h.is_finite() && *h >= 0.0) {
            return Err(Error::NonFiniteVertex(0));
        }
        let h = half_extents;
        let vertices: Vec<Point3<f64>> = (0..8)
            .map(|i| {
                Point3::new(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect();
        Self::new(vertices, radius)
    }

    /// A cylinder about the body z axis, centred at the body origin: the disk
    /// of radius `radius` swept from `z = -half_height` to `z = +half_height`,
    /// its edges rounded by `rounding` (0 for sharp rims). Its support
    /// function is the disk's closed form, exact to f64 precision, not a
    /// polytope's; warm-start indices of a cylinder are codes of its support
    /// points (any `u32` names a point of it), not vertex positions.
    ///
    /// ```
    /// use gjk::{distance, Convex, Options, Shape};
    /// use nalgebra::Isometry3;
    ///
    /// let can: Shape = Convex::cylinder(0.5, 1.0, 0.0)?.into();
    /// let ball: Shape = Convex::sphere(0.25)?.into();
    /// let beside = Isometry3::translation(2.0, 0.0, 0.3);
    /// let answer = distance(&can, &Isometry3::identity(), &ball, &beside, &Options::default(), None)?;
    /// assert!((answer.distance - 1.25).abs() < 1e-12);
    /// # Ok::<(), gjk::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::NonFiniteVertex`] for a negative, NaN or infinite radius or
    /// half-height, or a cylinder reaching more than 2^999 (about 5e300)
    /// from its body origin; [`Error::InvalidRadius`] for a negative or
    /// non-finite rounding radius.
    pub fn cylinder(radius: f64, half_height: f64, rounding: f64) -> Result<Self, Error> {
        if ![radius, half_height]
            .iter()
            .all(|x| x.is_finite() && *x >= 0.0)
        {
            return Err(Error::NonFiniteVertex(0));
        }
        if !(rounding.is_finite() && rounding >= 0.0) {
            return Err(Error::InvalidRadius(rounding));
        }
        let size = radius.hypot(half_height);
        if size > MAX_REACH {
            return Err(Error::NonFiniteVertex(0));
        }
        Ok(Self {
            vertices: Vec::new(),
            radius: rounding,
            centroid: Point3::origin(),
            centroid_norm: 0.0,
            size,
            xs: Vec::new(),
            ys: Vec::new(),
            zs: Vec::new(),
            kind: SupportKind::Cylinder {
                radius,
                half_height,
            },
            single: None,
            blocks: None,
            cones: None,
        })
    }

    /// The vertices as given, in the body frame. Warm-start indices refer to
    /// positions in this slice. Empty for a cylinder, whose warm-start
    /// indices are codes of its support points (see [`Convex::cylinder`]).
    pub fn vertices(&self) -> &[Point3<f64>] {
        &self.vertices
    }

    /// The rounding radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The mean of the vertices, in the body frame.
    pub fn centroid(&self) -> Point3<f64> {
        self.centroid
    }

    /// How far the shape's core reaches from its body origin: `|centroid| +
    /// size`, an upper bound on every vertex's distance from it.
    #[inline]
    pub(crate) fn reach(&self) -> f64 {
        self.centroid_norm + self.size
    }

    /// The largest distance from the centroid to a vertex: `D(coZ - z̄)` of (6.4),
    /// the radius not included.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Number of vertices: 0 for a cylinder.
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Whether the shape has no vertices: false but for a cylinder, whose
    /// support function is a closed form.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// The support point (3.7) for `d`, relative to the centroid, with its
    /// index: the vertex that maximises `(v - centroid)·d`, or for a
    /// cylinder its closed form and code. For vertex sets a linear scan, as
    /// the paper prescribes, over a layout made for vector lanes, or for
    /// large sets the block search, which finds the scan's own vertex. Exact
    /// ties go to the lowest index; a near-tie within the last bit may go
    /// either way between the AVX2 and portable paths (each is a valid
    /// support point), but always the same way on one machine. Index and
    /// point come from one match, so that polytopes pay no test for the
    /// cylinder's points.
    #[inline(always)]
    pub(crate) fn support_point(&self, d: &Vector3<f64>) -> (usize, Vector3<f64>) {
        let i = match self.kind {
            // A sphere's core: nothing to scan.
            SupportKind::Point => 0,
            // A box's support is its direction's sign pattern. A zero
            // component is a tie between the two faces, given to the lower
            // index as the scan would.
            SupportKind::Box => {
                usize::from(d.x > 0.0) | usize::from(d.y > 0.0) << 1 | usize::from(d.z > 0.0) << 2
            }
            // A handful of products: cheaper here than a call.
            SupportKind::Few => scan_few(&self.xs, &self.ys, &self.zs, d).1,
            #[cfg(target_arch = "x86_64")]
            // SAFETY: SupportKind::Avx2 is only chosen on a CPU with AVX2 and FMA.
            SupportKind::Avx2 => unsafe { scan_avx2(self, d) },
            SupportKind::Scan => self.scan_portable(d),
            SupportKind::Cones { fused } => self.cones_index(d, fused),
            SupportKind::Blocks => self.search_index(d),
            SupportKind::Cylinder {
                radius,
                half_height,
            } => {
                let code = cylinder::support_code(d);
                return (code as usize, cylinder::point(code, radius, half_height));
            }
        };
        (i, self.local(i))
    }

    /// The index of [`support_point`](Self::support_point), for the tests.
    #[cfg(test)]
    pub(crate) fn support_index(&self, d: &Vector3<f64>) -> usize {
        self.support_point(d).0
    }

    /// [`support_point`](Self::support_point) for
    /// [`Precision::Single`](crate::Precision::Single): an f32 scan, twice the
    /// lanes per instruction, on shapes that have the f32 copy (see
    /// [`has_single`](Self::has_single)); the exact support elsewhere,
    /// cylinders included. The vertex found is within `SINGLE_SLACK · size ·
    /// |d|` of the support value, not always the exact maximiser.
    #[inline(always)]
    pub(crate) fn support_point_single(&self, d: &Vector3<f64>) -> (usize, Vector3<f64>) {
        if self.has_single() {
            let i = self.scan_single(d);
            (i, self.local(i))
        } else {
            self.support_point(d)
        }
    }

    /// Point `i` relative to the centroid: vertex `i`, or for a cylinder the
    /// rim or cap point of code `i`.
    /// A polytope's index is below its scan arrays' length, the test that
    /// [`local`](Self::local)'s bounds check makes anyway; a cylinder has
    /// none, so its codes all go past it.
    #[inline(always)]
    pub(crate) fn point(&self, i: usize) -> Vector3<f64> {
        if i < self.xs.len() {
            return self.local(i);
        }
        match self.kind {
            SupportKind::Cylinder {
                radius,
                half_height,
            } => cylinder::point(i as u32, radius, half_height),
            // Out of range: `local`'s bounds check reports it.
            _ => self.local(i),
        }
    }

    /// How many indices a warm start may name: the vertex count, or for a
    /// cylinder every `u32` (each code is a point of it).
    #[inline]
    pub(crate) fn index_count(&self) -> usize {
        match self.kind {
            SupportKind::Cylinder { .. } => usize::MAX,
            _ => self.len(),
        }
    }

    /// `(radius, half_height)` of a cylinder's core, `None` for a polytope.
    pub fn cylinder_dimensions(&self) -> Option<(f64, f64)> {
        match self.kind {
            SupportKind::Cylinder {
                radius,
                half_height,
            } => Some((radius, half_height)),
            _ => None,
        }
    }

    /// Vertex `i` relative to the centroid, as stored for the scan.
    #[inline]
    pub(crate) fn local(&self, i: usize) -> Vector3<f64> {
        // One bounds check for three loads: `new` builds and pads the three
        // coordinate arrays together, to one length, and nothing changes
        // them after.
        let x = self.xs[i];
        debug_assert!(self.ys.len() == self.xs.len() && self.zs.len() == self.xs.len());
        // SAFETY: i < xs.len() (checked just above) == ys.len() == zs.len().
        let (y, z) = unsafe { (*self.ys.get_unchecked(i), *self.zs.get_unchecked(i)) };
        Vector3::new(x, y, z)
    }
}

/// The documented bound on a shape's reach holds with its radius counted.
impl SupportMap for Convex {
    #[inline(always)]
    fn local_support(&self, dir: &Vector3<f64>) -> (usize, Vector3<f64>) {
        self.support_point(dir)
    }

    #[inline(always)]
    fn local_point(&self, index: usize) -> Vector3<f64> {
        self.point(index)
    }

    #[inline(always)]
    fn centre(&self) -> Point3<f64> {
        self.centroid
    }

    #[inline(always)]
    fn rounding(&self) -> f64 {
        self.radius
    }

    #[inline(always)]
    fn size(&self) -> f64 {
        self.size
    }

    #[inline(always)]
    fn index_count(&self) -> usize {
        Convex::index_count(self)
    }

    #[inline(always)]
    fn centre_norm(&self) -> f64 {
        self.centroid_norm
    }

    #[inline(always)]
    fn single_size(&self) -> f64 {
        if self.has_single() { self.size } else { 0.0 }
    }

    #[inline(always)]
    fn local_support_single(&self, dir: &Vector3<f64>) -> (usize, Vector3<f64>) {
        self.support_point_single(dir)
    }

    #[inline(always)]
    fn seed_form(&self) -> Option<SeedForm> {
        match self.kind {
            SupportKind::Cylinder {
                radius,
                half_height,
            } => Some(SeedForm::Cylinder {
                radius,
                half_height,
            }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Isometry3;

    use super::*;
    use crate::shape::{Compound, Shape};
    use crate::{Options, distance};

    #[test]
    fn the_radius_counts_towards_the_reach() {
        assert_eq!(MAX_REACH, 2f64.powi(999));
        // A radius alone beyond 2^999 is an invalid radius.
        for r in [1e305, MAX_REACH * 1.000_001] {
            assert_eq!(Convex::sphere(r), Err(Error::InvalidRadius(r)));
        }
        // Within the bound alone, but vertices plus radius beyond it.
        let half = MAX_REACH * 0.6;
        assert_eq!(
            Convex::new(vec![Point3::new(half, 0.0, 0.0)], half),
            Err(Error::NonFiniteVertex(0))
        );
        assert_eq!(
            Convex::cuboid(Vector3::new(half, 0.0, 0.0), half),
            Err(Error::NonFiniteVertex(0))
        );
        let piece = Convex::sphere(half).expect("within the bound");
        assert_eq!(
            Compound::new(vec![(Isometry3::translation(half, 0.0, 0.0), piece)]),
            Err(Error::NonFinitePose)
        );
        // Negative and non-finite half extents.
        for h in [-1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(
                Convex::cuboid(Vector3::new(1.0, h, 1.0), 0.0),
                Err(Error::NonFiniteVertex(0))
            );
        }
        // The largest accepted sphere is queried without an error, and
        // answers of ordinary shapes are what they were: two unit boxes 3
        // apart along x, 1 apart between their faces.
        let big = Convex::sphere(MAX_REACH).expect("at the bound");
        let unit: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
            .expect("box")
            .into();
        let o = Options::default();
        let id = Isometry3::identity();
        let a = distance(&big.into(), &id, &unit, &id, &o, None).expect("queried");
        assert_eq!(a.distance, 0.0);
        let b = distance(
            &unit,
            &id,
            &unit,
            &Isometry3::translation(3.0, 0.0, 0.0),
            &o,
            None,
        )
        .expect("queried");
        assert_eq!(b.distance, 1.0);
    }
}
