//! Shapes: convex vertex sets with a rounding radius, and unions of them.
//!
//! A shape is described in its own body frame and placed in the world by an
//! [`Isometry3`] at query time. Everything that does not depend on the pose
//! (centroid, size bound, a layout fit for the support scan) is computed once
//! here, at construction, as Section 6 of the paper suggests.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::Error;
use crate::blocks::Blocks;
use crate::cones::{self, Cones};
use crate::cylinder;

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
    vertices: Vec<Point3<f64>>,
    radius: f64,
    centroid: Point3<f64>,
    /// `|z̄|`, kept for the per-query precision checks.
    centroid_norm: f64,
    /// `D(coZ - z̄)` of (6.4): the largest distance of a vertex from the centroid.
    size: f64,
    /// Vertices relative to the centroid, one array per coordinate, so that the
    /// support scan reads memory linearly and vectorises. Kept relative to the
    /// centroid so that a body frame far from its vertices loses no precision.
    xs: Vec<f64>,
    ys: Vec<f64>,
    zs: Vec<f64>,
    /// How the support point is found: a scan in general, a closed form for
    /// the shapes whose support function is one.
    kind: SupportKind,
    /// The scanned vertices again in f32, divided by `size` so that every
    /// coordinate lies in [-1, 1] (no overflow, whatever the shape's scale),
    /// for [`Precision::Single`](crate::Precision::Single). None for shapes
    /// that gain nothing from it: closed-form supports, fewer than
    /// [`SINGLE_MIN_VERTICES`] vertices, and [`SINGLE_MAX_VERTICES`] or more.
    single: Option<Box<F32Copy>>,
    /// The block search's reordered copy, for [`SupportKind::Blocks`].
    blocks: Option<Box<Blocks>>,
    /// The cube map of candidate lists, for [`SupportKind::Cones`].
    cones: Option<Box<Cones>>,
}

/// How far a shape's vertices (or a compound's pieces) may reach from its
/// body origin: 2^999, about 5.4e300. With the relative translation of a
/// query held to [`MAX_SHIFT`], every sum of coordinates, rotated coordinate
/// and support dot product of a query stays below 2^1006, far from f64's
/// overflow at 2^1024: beyond, a query could overflow and certify bounds
/// that do not hold, so such shapes are refused when built.
pub(crate) const MAX_REACH: f64 = 5.357543035931337e300;

/// How far apart (each coordinate of the relative translation) two shapes
/// may be in a query: 2^1000, about 1.07e301.
pub(crate) const MAX_SHIFT: f64 = 1.0715086071862673e301;

/// Shapes with fewer vertices keep the f64 scan under
/// [`Precision::Single`](crate::Precision::Single): one or two vector steps
/// cost less than the direction's conversion.
pub(crate) const SINGLE_MIN_VERTICES: usize = 16;

/// Shapes with this many vertices or more keep the exact block search under
/// [`Precision::Single`](crate::Precision::Single): around here it catches
/// up with the f32 scan of every vertex on round and box-shaped clouds
/// (cold), and beyond it is faster, by more the larger the set.
pub(crate) const SINGLE_MAX_VERTICES: usize = 1024;

/// The f32 copy of a shape's scan arrays.
#[derive(Clone, Debug, PartialEq)]
struct F32Copy {
    xs: Vec<f32>,
    ys: Vec<f32>,
    zs: Vec<f32>,
}

impl F32Copy {
    /// The copy of centroid-relative arrays of a set of size `size`, each
    /// coordinate divided by it; `None` where that cannot be done exactly
    /// enough or the indices would not fit the scan's i32 lanes.
    fn of(xs: &[f64], ys: &[f64], zs: &[f64], size: f64) -> Option<Box<Self>> {
        if i32::try_from(xs.len()).is_err()
            || size.is_nan()
            || size <= 0.0
            || !(1.0 / size).is_finite()
        {
            return None;
        }
        let inv = 1.0 / size;
        let to32 = |c: &[f64]| c.iter().map(|&x| (x * inv) as f32).collect();
        Some(Box::new(F32Copy {
            xs: to32(xs),
            ys: to32(ys),
            zs: to32(zs),
        }))
    }
}

/// How far the f32 scan's choice can fall short of the true support value,
/// in units of `size · |d|`: each dot product is off by at most 5 units of
/// f32 round-off (coordinates, direction, three fused terms), and the chosen
/// vertex's may be low by that while another's is high by as much, so 10
/// units, rounded up to 16 = 2^-20 for the f64 steps around it.
pub(crate) const SINGLE_SLACK: f64 = 1.0 / (1u64 << 20) as f64;

/// The support function's form, decided once from the vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
enum SupportKind {
    /// One vertex: a sphere's core.
    Point,
    /// Eight vertices `(±h.x, ±h.y, ±h.z)` about the centroid, vertex `i`
    /// taking `+` on axis `k` when bit `k` of `i` is set ([`Convex::cuboid`]'s
    /// order): the support index is the sign bits of the direction.
    Box,
    /// Two to seven vertices (a capsule's segment, a triangle): the scan's
    /// scalar loop, inlined where the support is needed.
    Few,
    /// Eight vertices or more, fewer than
    /// [`blocks::MIN_VERTICES`](crate::blocks::MIN_VERTICES), on a CPU with
    /// AVX2 and FMA (checked once, here): the vector scan, called directly.
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// As [`SupportKind::Avx2`] on a CPU without them: the portable scan.
    Scan,
    /// [`CONES_MIN_VERTICES`] to [`CONES_MAX_VERTICES`] (less one): the cube map's few candidates
    /// for the direction (see [`crate::cones`]), scanned with the arithmetic
    /// of the scan the shape would otherwise use (fused when `fused`, the
    /// [`SupportKind::Avx2`] scan's), so the same vertex; that scan for the
    /// directions the map declines.
    Cones { fused: bool },
    /// Larger sets: the block search, exact and the scan's own choice, which
    /// skips blocks of vertices that cannot hold the support point.
    Blocks,
    /// A cylinder about the body z axis ([`Convex::cylinder`]): no vertices,
    /// the closed form of [`crate::cylinder`], whose support "indices" are
    /// codes of rim points.
    Cylinder { radius: f64, half_height: f64 },
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

    /// `|centroid|`.
    pub(crate) fn centroid_norm(&self) -> f64 {
        self.centroid_norm
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

    /// [`support_point`](Self::support_point) for [`SupportKind::Cones`]: the
    /// direction's candidates with the scan's arithmetic, or for a direction
    /// the map declines, the scan itself.
    #[inline(always)]
    fn cones_index(&self, d: &Vector3<f64>, fused: bool) -> usize {
        let Some(cones) = self.cones.as_deref() else {
            return self.scan_portable(d);
        };
        #[cfg(target_arch = "x86_64")]
        if fused {
            // SAFETY: `fused` is only set on a CPU with AVX2 and FMA (it
            // replaces SupportKind::Avx2).
            return unsafe { cones_fused(self, cones, d) };
        }
        let _ = fused;
        match cones.candidates(d) {
            Some(c) => cones::first_max::<false>(&self.xs, &self.ys, &self.zs, c, d),
            None => self.scan_portable(d),
        }
    }

    /// [`scan_top`]'s index for [`SupportKind::Scan`], out of line: the query
    /// inlines only the arms that need no call.
    #[inline(never)]
    fn scan_portable(&self, d: &Vector3<f64>) -> usize {
        scan_top(&self.xs, &self.ys, &self.zs, d).1
    }

    /// [`support_point`](Self::support_point) by the block search when the
    /// shape has one, else (or for a direction it declines) the scan.
    #[inline(never)]
    fn search_index(&self, d: &Vector3<f64>) -> usize {
        if let Some(blocks) = self.blocks.as_deref()
            && let Some(i) = blocks.support(d)
        {
            return i;
        }
        self.scan_index(d)
    }

    /// Whether [`support_point_single`](Self::support_point_single) scans in
    /// f32 (and so may miss the support value by `SINGLE_SLACK · size · |d|`).
    #[inline(always)]
    pub(crate) fn has_single(&self) -> bool {
        self.single.is_some()
    }

    /// The index of [`support_point_single`](Self::support_point_single),
    /// for the tests.
    #[cfg(test)]
    pub(crate) fn support_index_single(&self, d: &Vector3<f64>) -> usize {
        if self.has_single() {
            self.scan_single(d)
        } else {
            self.support_index(d)
        }
    }

    #[inline(never)]
    fn scan_single(&self, d: &Vector3<f64>) -> usize {
        let m = d.x.abs().max(d.y.abs()).max(d.z.abs());
        let inv = 1.0 / m;
        if !inv.is_normal() {
            // A zero direction makes every vertex a support point, and one
            // whose 1/m overflows, is subnormal (a direction near 1e308,
            // scaled with lost bits) or NaN cannot be scaled exactly enough:
            // the f64 scan decides.
            return self.scan_index(d);
        }
        // Largest component 1 (a scaling keeps the support point), so the
        // f32 direction neither overflows nor loses more than its relative
        // round-off, and |u| <= √3 |d| / m keeps the error bound in |d|.
        let u = d * inv;
        let d32 = [u.x as f32, u.y as f32, u.z as f32];
        let Some(s) = self.single.as_deref() else {
            return self.scan_index(d);
        };
        #[cfg(target_arch = "x86_64")]
        {
            if crate::has_avx2_fma() {
                // SAFETY: the CPU supports AVX2 and FMA, checked just above.
                return unsafe { scan_single_avx2(&s.xs, &s.ys, &s.zs, d32) };
            }
        }
        scan_single(&s.xs, &s.ys, &s.zs, d32)
    }

    /// [`support_point`](Self::support_point) by the scan, inlined into its
    /// out-of-line callers: the closed forms are inlined into the query, the
    /// scan is not.
    #[inline(always)]
    fn scan_index(&self, d: &Vector3<f64>) -> usize {
        #[cfg(target_arch = "x86_64")]
        {
            if self.xs.len() >= 8 && crate::has_avx2_fma() {
                // SAFETY: the CPU supports AVX2 and FMA, checked just above.
                return unsafe { scan_avx2_any(&self.xs, &self.ys, &self.zs, d) };
            }
        }
        scan_top(&self.xs, &self.ys, &self.zs, d).1
    }

    /// The block search's data, for shapes that have it.
    #[cfg(test)]
    pub(crate) fn blocks(&self) -> Option<&Blocks> {
        self.blocks.as_deref()
    }

    /// A block index of this shape whatever its kind, so that the block
    /// search is tested on sets the cube map now takes.
    #[cfg(test)]
    pub(crate) fn block_index(&self) -> Blocks {
        Blocks::new(&self.xs, &self.ys, &self.zs, self.len())
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

/// The checks of [`Convex::new`] on its input, before any arithmetic.
fn check_input(vertices: &[Point3<f64>], radius: f64) -> Result<(), Error> {
    if vertices.is_empty() {
        return Err(Error::EmptyVertices);
    }
    if u32::try_from(vertices.len()).is_err() {
        return Err(Error::TooManyVertices(vertices.len()));
    }
    if let Some(index) = vertices
        .iter()
        .position(|v| !v.coords.iter().all(|c| c.is_finite()))
    {
        return Err(Error::NonFiniteVertex(index));
    }
    if !(radius.is_finite() && (0.0..=MAX_REACH).contains(&radius)) {
        return Err(Error::InvalidRadius(radius));
    }
    Ok(())
}

/// The mean of `vertices` (at least one), in two passes around the first
/// vertex: summing raw coordinates of a set far from the origin would lose
/// the digits that matter.
fn centroid_of(vertices: &[Point3<f64>]) -> Result<Point3<f64>, Error> {
    let base = vertices[0];
    let count = vertices.len() as f64;
    let mean_offset = vertices
        .iter()
        .fold(Vector3::zeros(), |acc, v| acc + (v - base))
        / count;
    let centroid = base + mean_offset;
    if !centroid.coords.iter().all(|c| c.is_finite()) {
        // Finite vertices whose spread overflows f64.
        return Err(Error::NonFiniteVertex(0));
    }
    Ok(centroid)
}

/// The scan arrays: each coordinate of every vertex relative to the
/// centroid, one array per axis.
type ScanArrays = (Vec<f64>, Vec<f64>, Vec<f64>);

/// `vertices` relative to `centroid`, as scan arrays, and the largest
/// coordinate among them (absolute).
fn relative_coordinates(
    vertices: &[Point3<f64>],
    centroid: &Point3<f64>,
) -> Result<(ScanArrays, f64), Error> {
    let len = vertices.len();
    let (mut xs, mut ys, mut zs) = (
        Vec::with_capacity(len),
        Vec::with_capacity(len),
        Vec::with_capacity(len),
    );
    let mut widest: f64 = 0.0;
    for v in vertices {
        let d = v - centroid;
        widest = widest.max(d.amax());
        xs.push(d.x);
        ys.push(d.y);
        zs.push(d.z);
    }
    if !widest.is_finite() {
        return Err(Error::NonFiniteVertex(0));
    }
    Ok(((xs, ys, zs), widest))
}

/// The largest length among the scan arrays' points, `D(coZ - z̄)` of
/// (6.4), whose largest coordinate is `widest`. Squared lengths are scaled
/// by a power of two (exact), so that sets near 1e-300 or 1e300 neither
/// underflow to a size of 0 nor overflow.
fn largest_length(xs: &[f64], ys: &[f64], zs: &[f64], widest: f64) -> Result<f64, Error> {
    let (scale, inv_scale) = pow2_scale(widest);
    let mut size2: f64 = 0.0;
    for ((x, y), z) in xs.iter().zip(ys).zip(zs) {
        size2 = size2.max(Vector3::new(x * scale, y * scale, z * scale).norm_squared());
    }
    let size = size2.sqrt() * inv_scale;
    if !size.is_finite() {
        return Err(Error::NonFiniteVertex(0));
    }
    Ok(size)
}

/// How a shape's support point is found, with the copies of its vertices
/// that the search needs.
struct SupportSearch {
    kind: SupportKind,
    single: Option<Box<F32Copy>>,
    blocks: Option<Box<Blocks>>,
    cones: Option<Box<Cones>>,
}

impl SupportSearch {
    /// The search for the `len` vertices of size `size` in the (padded)
    /// scan arrays.
    fn choose(xs: &[f64], ys: &[f64], zs: &[f64], len: usize, size: f64) -> Self {
        let base = if len == 1 {
            SupportKind::Point
        } else if is_box(xs, ys, zs) {
            SupportKind::Box
        } else if len < 8 {
            SupportKind::Few
        } else {
            scan_kind()
        };
        // Sets from CONES_MIN_VERTICES to below CONES_MAX_VERTICES get the
        // cube map, unless their size is outside the range its margins are
        // proved for; larger ones (or those) from blocks::MIN_VERTICES on,
        // the block search.
        let scanned = base == SupportKind::Scan || is_avx2(base);
        let cones = if scanned && (CONES_MIN_VERTICES..CONES_MAX_VERTICES).contains(&len) {
            Cones::new(xs, ys, zs, len, size).map(Box::new)
        } else {
            None
        };
        let kind = match (&cones, base) {
            (Some(_), SupportKind::Scan) => SupportKind::Cones { fused: false },
            (Some(_), _) => SupportKind::Cones { fused: true },
            (None, _) if scanned && len >= crate::blocks::MIN_VERTICES => SupportKind::Blocks,
            (None, other) => other,
        };
        let blocks = (kind == SupportKind::Blocks).then(|| Box::new(Blocks::new(xs, ys, zs, len)));
        // The f32 scan only where the exact search is the portable scan of
        // every vertex: against the AVX2 scan, the cube map and the block
        // search it is slower at every size measured (docs/speed-accuracy.md),
        // and `Single` then takes the
        // exact search. Indices ride in i32 lanes in the f32 scan.
        let single = if kind == SupportKind::Scan
            && (SINGLE_MIN_VERTICES..SINGLE_MAX_VERTICES).contains(&len)
        {
            F32Copy::of(xs, ys, zs, size)
        } else {
            None
        };
        SupportSearch {
            kind,
            single,
            blocks,
            cones,
        }
    }
}

/// A union of convex pieces, each placed in the compound's body frame by its own
/// offset. Its distance to another shape is the minimum over piece pairs, (2.3)
/// and (2.8), and the answer names the pieces that realise it.
///
/// ```
/// use gjk::{Compound, Convex};
/// use nalgebra::{Isometry3, Point3, Vector3};
///
/// // A dumbbell: two balls joined by a bar.
/// let ball = Convex::sphere(0.3)?;
/// let bar = Convex::capsule(Point3::new(-1.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0), 0.05)?;
/// let dumbbell = Compound::new(vec![
///     (Isometry3::translation(-1.0, 0.0, 0.0), ball.clone()),
///     (Isometry3::identity(), bar),
///     (Isometry3::translation(1.0, 0.0, 0.0), ball),
/// ])?;
/// assert_eq!(dumbbell.pieces().len(), 3);
/// # Ok::<(), gjk::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Compound {
    pieces: Vec<(Isometry3<f64>, Convex)>,
    /// Each piece's centroid in the compound's body frame (its offset applied),
    /// for the sphere bounds that order a query's piece pairs: computed once
    /// here instead of on every query.
    centres: Vec<Point3<f64>>,
}

impl Compound {
    /// A union of `pieces`, each with its offset in the compound's body frame.
    ///
    /// # Errors
    /// [`Error::EmptyCompound`] for no pieces, [`Error::TooManyVertices`] past
    /// `u32::MAX` pieces, and [`Error::NonFinitePose`] for an offset with NaN or
    /// infinity, or a piece (its vertices plus its radius) reaching more
    /// than 2^999 (about 5e300) from the
    /// compound's body origin.
    pub fn new(pieces: Vec<(Isometry3<f64>, Convex)>) -> Result<Self, Error> {
        if pieces.is_empty() {
            return Err(Error::EmptyCompound);
        }
        if u32::try_from(pieces.len()).is_err() {
            return Err(Error::TooManyVertices(pieces.len()));
        }
        if pieces.iter().any(|(offset, _)| !pose_is_finite(offset)) {
            return Err(Error::NonFinitePose);
        }
        // Each piece within MAX_REACH of the compound's body origin, so that
        // a query's magnitudes stay far from overflow (see MAX_REACH).
        if pieces
            .iter()
            .any(|(o, c)| robust_norm(&o.translation.vector) + c.reach() + c.radius() > MAX_REACH)
        {
            return Err(Error::NonFinitePose);
        }
        let centres = pieces.iter().map(|(o, c)| o * c.centroid()).collect();
        Ok(Self { pieces, centres })
    }

    /// The pieces with their offsets, in the order given; the answer's piece
    /// indices refer to positions in this slice.
    pub fn pieces(&self) -> &[(Isometry3<f64>, Convex)] {
        &self.pieces
    }
}

/// Anything the query accepts: one convex piece or a union of them.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A single convex object.
    Convex(Convex),
    /// A union of convex objects.
    Compound(Compound),
}

impl Shape {
    /// Number of convex pieces: 1 for a convex shape.
    pub fn piece_count(&self) -> usize {
        match self {
            Shape::Convex(_) => 1,
            Shape::Compound(c) => c.pieces.len(),
        }
    }

    /// Piece `i`'s centroid in the shape's body frame: its offset applied,
    /// the same point, bit for bit, as `offset * centroid` (computed once).
    #[inline]
    pub(crate) fn piece_centre(&self, i: usize) -> Option<Point3<f64>> {
        match self {
            Shape::Convex(c) => (i == 0).then(|| c.centroid()),
            Shape::Compound(c) => c.centres.get(i).copied(),
        }
    }

    /// Piece `i` without its offset.
    #[inline]
    pub(crate) fn convex_piece(&self, i: usize) -> Option<&Convex> {
        match self {
            Shape::Convex(c) => (i == 0).then_some(c),
            Shape::Compound(c) => c.pieces.get(i).map(|(_, p)| p),
        }
    }

    /// Piece `i` with its offset in the shape's body frame.
    pub(crate) fn piece(&self, i: usize) -> Option<(Isometry3<f64>, &Convex)> {
        match self {
            Shape::Convex(c) if i == 0 => Some((Isometry3::identity(), c)),
            Shape::Convex(_) => None,
            Shape::Compound(c) => c.pieces.get(i).map(|(o, p)| (*o, p)),
        }
    }
}

impl From<Convex> for Shape {
    fn from(c: Convex) -> Self {
        Shape::Convex(c)
    }
}

impl From<Compound> for Shape {
    fn from(c: Compound) -> Self {
        Shape::Compound(c)
    }
}

/// Whether the centroid-relative vertices are exactly a box in
/// [`Convex::cuboid`]'s order: vertex `i` is `(±h.x, ±h.y, ±h.z)`, with `+` on
/// axis `k` when bit `k` of `i` is set. Exact comparison: a set that is a box
/// only up to round-off keeps the scan, which is never wrong.
fn is_box(xs: &[f64], ys: &[f64], zs: &[f64]) -> bool {
    if xs.len() != 8 {
        return false;
    }
    let h = [xs[7], ys[7], zs[7]];
    if h.iter().any(|&c| c.is_sign_negative()) {
        return false;
    }
    (0..8).all(|i| {
        let want = |bit: usize, c: f64| if i & bit != 0 { c } else { -c };
        xs[i] == want(1, h[0]) && ys[i] == want(2, h[1]) && zs[i] == want(4, h[2])
    })
}

/// A power of two `k` and its inverse such that `m·k` lies in [1, 2) for a
/// normal `m` (and is at least 2^-52 for a subnormal one): scaling by `k` is
/// exact, and brings lengths near 1 where their squares, and the cofactors'
/// products of squares, can neither overflow nor underflow. `(1, 1)` for 0,
/// infinity and NaN.
#[inline]
pub(crate) fn pow2_scale(m: f64) -> (f64, f64) {
    if !(m > 0.0 && m <= f64::MAX) {
        return (1.0, 1.0);
    }
    let biased = ((m.to_bits() >> 52) & 0x7ff) as i32;
    // Subnormals count as 2^-1022; the clamp keeps both factors normal.
    let e = (biased.max(1) - 1023).clamp(-1020, 1020);
    let pow = |x: i32| f64::from_bits(((1023 + x) as u64) << 52);
    (pow(-e), pow(e))
}

/// `|v|` without overflow or underflow of the squares: the plain norm where
/// that is safe, else the norm of `v` scaled by a power of two.
#[inline]
pub(crate) fn robust_norm(v: &Vector3<f64>) -> f64 {
    let n = v.norm();
    if n > 1e-140 && n < 1e140 {
        return n;
    }
    let (k, inv_k) = pow2_scale(v.amax());
    (v * k).norm() * inv_k
}

/// Whether the relative pose of a query is finite and its translation
/// within [`MAX_SHIFT`] on every axis. Comparisons are false for NaN, and
/// `&` keeps them branch-free.
#[inline]
pub(crate) fn shift_is_in_range(p: &Isometry3<f64>) -> bool {
    let t = &p.translation.vector;
    let q = &p.rotation.coords;
    let q0 = (q.x * 0.0 + q.y * 0.0) + (q.z * 0.0 + q.w * 0.0);
    (t.x.abs() <= MAX_SHIFT) & (t.y.abs() <= MAX_SHIFT) & (t.z.abs() <= MAX_SHIFT) & (q0 == 0.0)
}

pub(crate) fn pose_is_finite(p: &Isometry3<f64>) -> bool {
    // x·0 is NaN exactly when x is infinite or NaN; no branch per component.
    let t = &p.translation.vector;
    let q = &p.rotation.coords;
    let poison = t.x * 0.0 + t.y * 0.0 + t.z * 0.0;
    let poison = poison + q.x * 0.0 + q.y * 0.0 + q.z * 0.0 + q.w * 0.0;
    poison == 0.0
}

/// The support scan on 4 independent lanes. Each lane keeps its running maximum
/// and the index (as f64, exact below 2^53) through selects, not branches, so
/// the loop vectorises; lanes are merged lowest index first on ties. Returns
/// the largest dot product and its index.
#[inline(always)]
pub(crate) fn scan_top(xs: &[f64], ys: &[f64], zs: &[f64], d: &Vector3<f64>) -> (f64, usize) {
    const LANES: usize = 4;
    let n = xs.len().min(ys.len()).min(zs.len());
    let (xs, ys, zs) = (&xs[..n], &ys[..n], &zs[..n]);
    let (dx, dy, dz) = (d.x, d.y, d.z);
    if n < 2 * LANES {
        // Spheres, capsules, boxes: lane set-up would cost more than the scan.
        return scan_few(xs, ys, zs, d);
    }
    let mut best = [f64::NEG_INFINITY; LANES];
    let mut best_i = [0.0f64; LANES];
    let mut base = [0.0f64, 1.0, 2.0, 3.0];
    for ((x, y), z) in xs
        .chunks_exact(LANES)
        .zip(ys.chunks_exact(LANES))
        .zip(zs.chunks_exact(LANES))
    {
        for l in 0..LANES {
            let dot = x[l] * dx + y[l] * dy + z[l] * dz;
            let gt = dot > best[l];
            best[l] = if gt { dot } else { best[l] };
            best_i[l] = if gt { base[l] } else { best_i[l] };
            base[l] += LANES as f64;
        }
    }
    let mut top = best[0];
    let mut top_i = best_i[0];
    for l in 1..LANES {
        if best[l] > top || (best[l] == top && best_i[l] < top_i) {
            top = best[l];
            top_i = best_i[l];
        }
    }
    // Through u32: the index is exact and small, and the unsigned 64-bit
    // conversion takes a sequence of instructions without AVX-512.
    let mut idx = top_i as u32 as usize;
    for i in n - n % LANES..n {
        let dot = xs[i] * dx + ys[i] * dy + zs[i] * dz;
        if dot > top {
            top = dot;
            idx = i;
        }
    }
    (top, idx)
}

/// [`scan_top`] one vertex at a time, for the smallest sets: the largest
/// dot product and its first index.
#[inline(always)]
fn scan_few(xs: &[f64], ys: &[f64], zs: &[f64], d: &Vector3<f64>) -> (f64, usize) {
    let n = xs.len().min(ys.len()).min(zs.len());
    let (xs, ys, zs) = (&xs[..n], &ys[..n], &zs[..n]);
    let (dx, dy, dz) = (d.x, d.y, d.z);
    let mut top = f64::NEG_INFINITY;
    let mut idx = 0;
    for i in 0..n {
        let dot = xs[i] * dx + ys[i] * dy + zs[i] * dz;
        if dot > top {
            top = dot;
            idx = i;
        }
    }
    (top, idx)
}

/// Sets with fewer vertices keep the scan. On the paper's family
/// (`paper_compare`), the map from 32 vertices slowed the pairs of its 40- to
/// 60-vertex polytopes (a query's directions cluster at face normals, where
/// a cell lists a whole face) while it sped up the 100-vertex pairs; from
/// 64, only the latter remains.
pub(crate) const CONES_MIN_VERTICES: usize = 64;

/// Sets of this many vertices or more keep the block search: the map's
/// construction grows with the vertices.
pub(crate) const CONES_MAX_VERTICES: usize = 4096;

/// Whether `kind` is the AVX2 scan.
fn is_avx2(kind: SupportKind) -> bool {
    #[cfg(target_arch = "x86_64")]
    if kind == SupportKind::Avx2 {
        return true;
    }
    let _ = kind;
    false
}

/// [`Convex::cones_index`] with fused multiply-adds, as [`scan_avx2`]
/// computes its dot products, so the same vertex; the AVX2 scan for the
/// directions the map declines.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn cones_fused(c: &Convex, cones: &Cones, d: &Vector3<f64>) -> usize {
    match cones.candidates(d) {
        Some(list) => cones::first_max::<true>(&c.xs, &c.ys, &c.zs, list, d),
        // SAFETY: this function's own target features are the callee's.
        None => unsafe { scan_avx2(c, d) },
    }
}

/// The kind of a set of 8 vertices or more that the block search leaves to
/// the scan: [`SupportKind::Avx2`] if this CPU has AVX2 and FMA, the vector scan's
/// requirements, else [`SupportKind::Scan`].
fn scan_kind() -> SupportKind {
    #[cfg(target_arch = "x86_64")]
    if crate::has_avx2_fma() {
        return SupportKind::Avx2;
    }
    SupportKind::Scan
}

/// [`scan_top`] in AVX2 and FMA intrinsics, chosen at run time: two sets of four
/// lanes, so the two compare-and-select chains overlap, and the comparison
/// mask used as it is (the compiler's own vectorisation of [`scan_top`] spends
/// instructions on every step converting it to booleans and back). Dot
/// products are fused multiply-adds, so they may differ from [`scan_top`]'s in
/// the last bit; either vertex of such a near-tie is a valid support point.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(crate) unsafe fn scan_avx2_top(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    d: &Vector3<f64>,
) -> (f64, usize) {
    use std::arch::x86_64::*;
    let n = xs.len().min(ys.len()).min(zs.len());
    let full = n - n % 8;
    let (dx, dy, dz) = (
        _mm256_set1_pd(d.x),
        _mm256_set1_pd(d.y),
        _mm256_set1_pd(d.z),
    );
    let mut best = [_mm256_set1_pd(f64::NEG_INFINITY); 2];
    let mut best_i = [_mm256_setzero_pd(); 2];
    let mut base = [
        _mm256_setr_pd(0.0, 1.0, 2.0, 3.0),
        _mm256_setr_pd(4.0, 5.0, 6.0, 7.0),
    ];
    let step = _mm256_set1_pd(8.0);
    let mut i = 0;
    while i < full {
        for h in 0..2 {
            let k = i + 4 * h;
            // SAFETY: k + 4 <= full <= n, the length of all three slices.
            let (x, y, z) = unsafe {
                (
                    _mm256_loadu_pd(xs.as_ptr().add(k)),
                    _mm256_loadu_pd(ys.as_ptr().add(k)),
                    _mm256_loadu_pd(zs.as_ptr().add(k)),
                )
            };
            let dot = _mm256_fmadd_pd(z, dz, _mm256_fmadd_pd(y, dy, _mm256_mul_pd(x, dx)));
            let gt = _mm256_cmp_pd::<_CMP_GT_OQ>(dot, best[h]);
            best[h] = _mm256_blendv_pd(best[h], dot, gt);
            best_i[h] = _mm256_blendv_pd(best_i[h], base[h], gt);
            base[h] = _mm256_add_pd(base[h], step);
        }
        i += 8;
    }
    // Merge the eight lanes without branches: at each step a lane takes its
    // partner's value if larger, or equal with a lower index.
    let pick = |v: __m256d, i: __m256d, w: __m256d, j: __m256d| {
        let take = _mm256_or_pd(
            _mm256_cmp_pd::<_CMP_GT_OQ>(w, v),
            _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_EQ_OQ>(w, v),
                _mm256_cmp_pd::<_CMP_LT_OQ>(j, i),
            ),
        );
        (_mm256_blendv_pd(v, w, take), _mm256_blendv_pd(i, j, take))
    };
    let (v, ix) = pick(best[0], best_i[0], best[1], best_i[1]);
    let (v, ix) = pick(
        v,
        ix,
        _mm256_permute2f128_pd::<1>(v, v),
        _mm256_permute2f128_pd::<1>(ix, ix),
    );
    let (v, ix) = pick(
        v,
        ix,
        _mm256_permute_pd::<0b0101>(v),
        _mm256_permute_pd::<0b0101>(ix),
    );
    let mut top = _mm256_cvtsd_f64(v);
    let top_i = _mm256_cvtsd_f64(ix);
    // Through u32: the index is exact and small, and the unsigned 64-bit
    // conversion takes a sequence of instructions without AVX-512.
    let mut idx = top_i as u32 as usize;
    for i in full..n {
        let dot = zs[i].mul_add(d.z, ys[i].mul_add(d.y, xs[i] * d.x));
        if dot > top {
            top = dot;
            idx = i;
        }
    }
    (top, idx)
}

/// [`scan_avx2_top`]'s index alone, for any length, out of line.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn scan_avx2_any(xs: &[f64], ys: &[f64], zs: &[f64], d: &Vector3<f64>) -> usize {
    // SAFETY: this function's own target features are the callee's.
    unsafe { scan_avx2_top(xs, ys, zs, d).1 }
}

/// The support index of a whole padded set (8 or more vertices, a multiple
/// of 8 in the arrays) by the vector scan: [`scan_avx2_top`]'s arithmetic and
/// choice, with less around the loop, since this is most of a family query's
/// support cost. The lengths are the shape's own, so nothing is checked; the
/// first step takes its eight dot products as they are; the lanes are merged
/// by a maximum, then the lowest index among the lanes that hold it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn scan_avx2(c: &Convex, d: &Vector3<f64>) -> usize {
    use std::arch::x86_64::*;
    // The arrays are built together, padded to the same multiple of 8
    // (at least 8 here), and never changed after construction.
    let n = c.xs.len();
    debug_assert!(n >= 8 && n.is_multiple_of(8) && c.ys.len() == n && c.zs.len() == n);
    let (xs, ys, zs) = (c.xs.as_ptr(), c.ys.as_ptr(), c.zs.as_ptr());
    let (dx, dy, dz) = (
        _mm256_set1_pd(d.x),
        _mm256_set1_pd(d.y),
        _mm256_set1_pd(d.z),
    );
    // SAFETY: callers pass k + 4 <= n, the length of all three arrays.
    let dot = |k: usize| unsafe {
        let (x, y, z) = (
            _mm256_loadu_pd(xs.add(k)),
            _mm256_loadu_pd(ys.add(k)),
            _mm256_loadu_pd(zs.add(k)),
        );
        _mm256_fmadd_pd(z, dz, _mm256_fmadd_pd(y, dy, _mm256_mul_pd(x, dx)))
    };
    // Step 0 without comparisons: a lane's first dot product is its best
    // unless it is NaN, which `max` (second operand on NaN) turns into the
    // -inf that the scan would have kept. Such a lane, or one at -inf,
    // records its own index where the scan keeps 0; that matters only when
    // every lane ends at -inf, and then lane 0 (index 0) is among the
    // lowest-index candidates below, as in the scan.
    let ninf = _mm256_set1_pd(f64::NEG_INFINITY);
    let mut best = [_mm256_max_pd(dot(0), ninf), _mm256_max_pd(dot(4), ninf)];
    // Each lane's index is its step's first index plus the lane's offset,
    // added once after the loop: one step counter for both halves. Indices
    // are integers in 64-bit lanes, below 2^32 (the sets here are small).
    let mut at = [_mm256_setzero_si256(); 2];
    // One step: vertices i to i + 7, `k` holding i.
    let mut take = |i: usize, k: __m256i| {
        for h in 0..2 {
            let v = dot(i + 4 * h);
            let gt = _mm256_cmp_pd::<_CMP_GT_OQ>(v, best[h]);
            // The blend of `v` into `best` by `gt`, bit for bit: `max` returns
            // its second operand unless the first is larger (for NaN and for
            // zeros of either sign too), and its result does not wait for
            // the comparison.
            best[h] = _mm256_max_pd(v, best[h]);
            at[h] = _mm256_castpd_si256(_mm256_blendv_pd(
                _mm256_castsi256_pd(at[h]),
                _mm256_castsi256_pd(k),
                gt,
            ));
        }
    };
    // The other steps two at a time, an odd one out first: one loop test and
    // two counter updates for 16 vertices, a share of a small query that
    // shows.
    let mut i = 8;
    if n.is_multiple_of(16) {
        take(i, _mm256_set1_epi64x(8));
        i += 8;
    }
    let (mut k, mut k2) = (
        _mm256_set1_epi64x(i as i64),
        _mm256_set1_epi64x(i as i64 + 8),
    );
    let step = _mm256_set1_epi64x(16);
    while i < n {
        take(i, k);
        take(i + 8, k2);
        k = _mm256_add_epi64(k, step);
        k2 = _mm256_add_epi64(k2, step);
        i += 16;
    }
    // Each lane holds its first index of its largest value (strict `>`
    // above), so the set's first index of the largest value is the lowest
    // index among the lanes equal to the maximum. No lane holds NaN.
    let top = _mm256_max_pd(best[0], best[1]);
    let top = _mm256_max_pd(top, _mm256_permute2f128_pd::<1>(top, top));
    let top = _mm256_max_pd(top, _mm256_permute_pd::<0b0101>(top));
    let lanes = [
        _mm256_setr_epi64x(0, 1, 2, 3),
        _mm256_setr_epi64x(4, 5, 6, 7),
    ];
    // A lane off the maximum offers u32::MAX (all ones); the minimum is
    // taken on the low 32 bits of each lane, where the indices are.
    let first = |h: usize| {
        let tie = _mm256_cmp_pd::<_CMP_EQ_OQ>(best[h], top);
        let index = _mm256_castsi256_pd(_mm256_or_si256(at[h], lanes[h]));
        _mm256_castpd_si256(_mm256_blendv_pd(
            _mm256_castsi256_pd(_mm256_set1_epi32(-1)),
            index,
            tie,
        ))
    };
    let low = _mm256_min_epu32(first(0), first(1));
    let low = _mm256_min_epu32(low, _mm256_permute2x128_si256::<1>(low, low));
    let low = _mm256_min_epu32(low, _mm256_shuffle_epi32::<0b0100_1110>(low));
    _mm256_cvtsi256_si32(low) as u32 as usize
}

/// The f32 support scan, portable: 8 lanes, any vertex of the largest dot
/// product (ties need no order: the f32 result is within the slack anyway).
fn scan_single(xs: &[f32], ys: &[f32], zs: &[f32], d: [f32; 3]) -> usize {
    const LANES: usize = 8;
    let n = xs.len().min(ys.len()).min(zs.len());
    let [dx, dy, dz] = d;
    let mut best = [f32::NEG_INFINITY; LANES];
    let mut best_i = [0u32; LANES];
    let mut base = [0u32, 1, 2, 3, 4, 5, 6, 7];
    let full = n - n % LANES;
    for ((x, y), z) in xs[..full]
        .chunks_exact(LANES)
        .zip(ys[..full].chunks_exact(LANES))
        .zip(zs[..full].chunks_exact(LANES))
    {
        for l in 0..LANES {
            let dot = x[l] * dx + y[l] * dy + z[l] * dz;
            let gt = dot > best[l];
            best[l] = if gt { dot } else { best[l] };
            best_i[l] = if gt { base[l] } else { best_i[l] };
            base[l] += LANES as u32;
        }
    }
    let (mut top, mut idx) = (best[0], best_i[0] as usize);
    for l in 1..LANES {
        if best[l] > top {
            (top, idx) = (best[l], best_i[l] as usize);
        }
    }
    for i in full..n {
        let dot = xs[i] * dx + ys[i] * dy + zs[i] * dz;
        if dot > top {
            (top, idx) = (dot, i);
        }
    }
    idx
}

/// [`scan_single`] in AVX2 and FMA intrinsics: eight f32 lanes per step where
/// the f64 scan has four, indices in i32 lanes.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn scan_single_avx2(xs: &[f32], ys: &[f32], zs: &[f32], d: [f32; 3]) -> usize {
    use std::arch::x86_64::*;
    let n = xs.len().min(ys.len()).min(zs.len());
    let full = n - n % 8;
    let (dx, dy, dz) = (
        _mm256_set1_ps(d[0]),
        _mm256_set1_ps(d[1]),
        _mm256_set1_ps(d[2]),
    );
    let mut best = _mm256_set1_ps(f32::NEG_INFINITY);
    let mut best_i = _mm256_setzero_si256();
    let mut base = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let step = _mm256_set1_epi32(8);
    let mut i = 0;
    while i < full {
        // SAFETY: i + 8 <= full <= n, the length of all three slices.
        let (x, y, z) = unsafe {
            (
                _mm256_loadu_ps(xs.as_ptr().add(i)),
                _mm256_loadu_ps(ys.as_ptr().add(i)),
                _mm256_loadu_ps(zs.as_ptr().add(i)),
            )
        };
        let dot = _mm256_fmadd_ps(z, dz, _mm256_fmadd_ps(y, dy, _mm256_mul_ps(x, dx)));
        let gt = _mm256_cmp_ps::<_CMP_GT_OQ>(dot, best);
        best = _mm256_blendv_ps(best, dot, gt);
        best_i = _mm256_castps_si256(_mm256_blendv_ps(
            _mm256_castsi256_ps(best_i),
            _mm256_castsi256_ps(base),
            gt,
        ));
        base = _mm256_add_epi32(base, step);
        i += 8;
    }
    // Fold the eight lanes in three swaps of halves, pairs and neighbours,
    // each lane keeping the larger of itself and its partner.
    let fold = |v: __m256, i: __m256i, w: __m256, j: __m256i| {
        let take = _mm256_cmp_ps::<_CMP_GT_OQ>(w, v);
        (
            _mm256_blendv_ps(v, w, take),
            _mm256_castps_si256(_mm256_blendv_ps(
                _mm256_castsi256_ps(i),
                _mm256_castsi256_ps(j),
                take,
            )),
        )
    };
    let (v, ix) = fold(
        best,
        best_i,
        _mm256_permute2f128_ps::<1>(best, best),
        _mm256_permute2f128_si256::<1>(best_i, best_i),
    );
    let swap_pairs = |x: __m256| _mm256_permute_ps::<0b0100_1110>(x);
    let (v, ix) = fold(
        v,
        ix,
        swap_pairs(v),
        _mm256_castps_si256(swap_pairs(_mm256_castsi256_ps(ix))),
    );
    let swap_next = |x: __m256| _mm256_permute_ps::<0b1011_0001>(x);
    let (v, ix) = fold(
        v,
        ix,
        swap_next(v),
        _mm256_castps_si256(swap_next(_mm256_castsi256_ps(ix))),
    );
    let mut top = _mm256_cvtss_f32(v);
    let mut idx = _mm256_cvtsi256_si32(ix) as u32 as usize;
    for i in full..n {
        let dot = zs[i].mul_add(d[2], ys[i].mul_add(d[1], xs[i] * d[0]));
        if dot > top {
            (top, idx) = (dot, i);
        }
    }
    idx
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The support index by brute force: the first vertex of largest `v·d`.
    fn brute_force_support(c: &Convex, d: &Vector3<f64>) -> usize {
        let mut best = 0;
        for i in 1..c.len() {
            if c.local(i).dot(d) > c.local(best).dot(d) {
                best = i;
            }
        }
        best
    }

    #[test]
    fn box_support_is_the_scan_including_ties() {
        let comps = [-1.5, -1e-300, -0.0, 0.0, 1e-300, 0.7];
        for half in [
            Vector3::new(0.5, 2.0, 0.25),
            Vector3::new(0.5, 2.0, 1e-200),
            Vector3::new(0.5, 2.0, 0.0),
        ] {
            let b = Convex::cuboid(half, 0.1).unwrap();
            assert_eq!(b.kind, SupportKind::Box);
            for &x in &comps {
                for &y in &comps {
                    for &z in &comps {
                        let d = Vector3::new(x, y, z);
                        let (i, j) = (b.support_index(&d), brute_force_support(&b, &d));
                        assert_eq!(b.local(i).dot(&d), b.local(j).dot(&d), "{d:?}");
                        // A flat axis, or a component lost in the sum,
                        // ties the two faces: either is a support point.
                        let lost = [x, y, z].iter().any(|c| c.abs() == 1e-300);
                        if half.z > 1e-100 && !lost {
                            assert_eq!(i, j, "direction {d:?}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn only_exact_boxes_in_cuboid_order_take_the_closed_form() {
        let b = Convex::cuboid(Vector3::new(1.0, 2.0, 3.0), 0.0).unwrap();
        let mut swapped = b.vertices().to_vec();
        swapped.swap(0, 7);
        let shifted: Vec<_> = b
            .vertices()
            .iter()
            .map(|v| v + Vector3::new(1e3, 0.0, 0.0))
            .collect();
        let mut skew = b.vertices().to_vec();
        skew[3].x += 1e-9;
        for (verts, kind) in [
            (swapped, scan_kind()),
            (skew, scan_kind()),
            (shifted, SupportKind::Box),
            (b.vertices()[..1].to_vec(), SupportKind::Point),
            (b.vertices()[..2].to_vec(), SupportKind::Few),
        ] {
            let c = Convex::new(verts, 0.0).unwrap();
            assert_eq!(c.kind, kind);
            for d in [
                Vector3::new(0.3, -0.2, 0.9),
                Vector3::new(-1.0, 0.0, 0.0),
                Vector3::new(0.0, 0.0, 0.0),
            ] {
                assert_eq!(
                    c.support_index(&d),
                    brute_force_support(&c, &d),
                    "{kind:?} {d:?}"
                );
            }
        }
    }

    /// A small xorshift generator, uniform in [-1, 1): the tests need no
    /// more. Shared with the block search's tests.
    pub(crate) struct Rng(pub(crate) u64);
    impl Rng {
        pub(crate) fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// `n` points of a cloud of size `scale` at `offset` on x. Flat sets put
    /// every other vertex within 3e-7 of the plane x = scale, far from the
    /// centroid: with directions near +x, near-ties that f32 cannot
    /// resolve, which is what the slack is for.
    fn cloud(rng: &mut Rng, n: usize, scale: f64, offset: f64, flat: bool) -> Vec<Point3<f64>> {
        (0..n)
            .map(|i| {
                let x = if flat && i % 2 == 0 {
                    1.0 + 3e-7 * rng.next()
                } else if flat {
                    rng.next().min(0.0)
                } else {
                    rng.next()
                };
                Point3::new(
                    offset + x * scale,
                    rng.next() * scale,
                    rng.next() * scale * 1e-3,
                )
            })
            .collect()
    }

    /// The `k`-th direction of a test on a cloud of size `scale`: near +x
    /// for a flat cloud, and by turns with a tiny component, signed zeros,
    /// huge and subnormal.
    fn direction(rng: &mut Rng, k: usize, flat: bool, scale: f64) -> Vector3<f64> {
        let mut d = Vector3::new(rng.next(), rng.next(), rng.next());
        if flat {
            d = Vector3::new(1.0, d.y * 1e-9, d.z * 1e-9);
        }
        match k % 5 {
            1 => d.y *= 1e-300,
            2 => d = Vector3::new(0.0, -0.0, d.z),
            // Subnormal: 1/max overflows, the f64 scan takes over.
            4 => d *= 1e-310,
            // Large, but not so large that the reference overflows.
            3 => d *= 1e120 / scale.max(1.0),
            _ => {}
        }
        d
    }

    /// The f32 scan's picks for `d` on `c` (which has its f32 copy): through
    /// the support search, and straight from the portable and, where the
    /// CPU has them, the AVX2 f32 scans.
    fn single_picks(c: &Convex, d: &Vector3<f64>) -> Vec<usize> {
        let s = c.single.as_deref().expect("an f32 copy");
        let d32 = {
            let m = d.x.abs().max(d.y.abs()).max(d.z.abs());
            let u = d * (1.0 / m);
            [u.x as f32, u.y as f32, u.z as f32]
        };
        let mut picks = vec![c.support_index_single(d)];
        let scalable = d32.iter().all(|x| x.is_finite());
        if scalable {
            picks.push(scan_single(&s.xs, &s.ys, &s.zs, d32));
        }
        #[cfg(target_arch = "x86_64")]
        if scalable
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
        {
            // SAFETY: the features were checked just above.
            picks.push(unsafe { scan_single_avx2(&s.xs, &s.ys, &s.zs, d32) });
        }
        picks
    }

    /// The f32 scan's choice is within `SINGLE_SLACK · size · |d|` of the
    /// true support value, on both code paths, at every scale f64 allows,
    /// far from the origin, for directions with components of wildly
    /// different sizes (and ±0).
    #[test]
    fn single_precision_support_is_within_its_slack() {
        let mut rng = Rng(0x5eed_1234_abcd_0001);
        let mut checked = 0;
        let mut worst = 0.0f64;
        for n in [16, 17, 40, 1000] {
            // Sizes are found through squared lengths, so 1e±150 is the range.
            for scale in [1e-140, 1e-9, 1.0, 1e9, 1e140] {
                for (offset, flat) in [(0.0, false), (1e9, false), (0.0, true), (1e9, true)] {
                    let mut c = Convex::new(cloud(&mut rng, n, scale, offset, flat), 0.0).unwrap();
                    if offset * 1e-6 > scale {
                        // The vertices collapsed onto a few values.
                        continue;
                    }
                    // The f32 copy is only built where the exact search is
                    // the portable scan; built here on any CPU, so that the
                    // f32 path is tested everywhere.
                    if c.single.is_none() {
                        c.single = F32Copy::of(&c.xs, &c.ys, &c.zs, c.size);
                    }
                    assert!(c.has_single(), "n {n} scale {scale:e}");
                    for k in 0..64 {
                        let d = direction(&mut rng, k, flat, scale);
                        let best = c.local(brute_force_support(&c, &d)).dot(&d);
                        let slack = SINGLE_SLACK * c.size() * d.norm();
                        for i in single_picks(&c, &d) {
                            assert!(i < c.len());
                            let got = c.local(i).dot(&d);
                            worst = worst.max((best - got) / (c.size() * d.norm()));
                            assert!(
                                got >= best - slack,
                                "n {n} scale {scale:e} d {d:?}: {got:e} < {best:e} - {slack:e}"
                            );
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 3000, "{checked}");
        // The flat sets did produce misses, so the bound was tested, not
        // just the easy picks.
        assert!(worst > 0.0);
    }

    /// Directions whose largest component is near f64::MAX (1/m would be
    /// subnormal), or that are subnormal themselves, go to the exact scan.
    #[test]
    fn single_precision_leaves_extreme_directions_to_the_exact_scan() {
        let mut ring = Convex::new(
            (0..40)
                .map(|i| {
                    let a = f64::from(i) * 0.157;
                    Point3::new(a.cos(), a.sin(), 0.1 * a)
                })
                .collect::<Vec<_>>(),
            0.0,
        )
        .unwrap();
        ring.single = F32Copy::of(&ring.xs, &ring.ys, &ring.zs, ring.size);
        assert!(ring.has_single());
        for d in [
            Vector3::new(1.7e308, 3e307, -2e307),
            Vector3::new(-1e-320, 5e-321, 0.0),
        ] {
            assert_eq!(ring.support_index_single(&d), ring.scan_index(&d), "{d:?}");
        }
    }

    /// Small and closed-form shapes keep the exact support under
    /// `Precision::Single`; so do sets large enough for the cube map or the
    /// block search, which are faster.
    #[test]
    fn shapes_without_an_f32_copy_keep_the_exact_support() {
        let small = Convex::new(
            (0..15)
                .map(|i| Point3::new(i as f64, (i * i) as f64, 1.0))
                .collect::<Vec<_>>(),
            0.0,
        )
        .unwrap();
        let cube = Convex::cuboid(Vector3::new(1.0, 2.0, 3.0), 0.0).unwrap();
        let large = Convex::new(
            (0..SINGLE_MAX_VERTICES)
                .map(|i| {
                    let a = i as f64 * 0.37;
                    Point3::new(a.cos(), a.sin(), (i % 17) as f64 * 0.1)
                })
                .collect::<Vec<_>>(),
            0.0,
        )
        .unwrap();
        assert!(matches!(
            large.kind,
            SupportKind::Blocks | SupportKind::Cones { .. }
        ));
        for c in [small, cube, large] {
            assert!(!c.has_single());
            let d = Vector3::new(0.3, -0.8, 0.1);
            assert_eq!(c.support_index_single(&d), brute_force_support(&c, &d));
        }
    }

    /// The scan's rule written out plainly, one vertex at a time: the first
    /// vertex of largest dot product, computed as the support search computes
    /// it on this machine (fused multiply-adds on the AVX2 path, which sets
    /// of 8 or more vertices take when the CPU has AVX2 and FMA; plain
    /// products and sums otherwise).
    fn reference(c: &Convex, d: &Vector3<f64>) -> usize {
        #[cfg(target_arch = "x86_64")]
        let fused = c.len() >= 8
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        #[cfg(not(target_arch = "x86_64"))]
        let fused = false;
        reference_with(c, d, fused)
    }

    /// [`reference`] with the arithmetic chosen: fused or plain.
    fn reference_with(c: &Convex, d: &Vector3<f64>, fused: bool) -> usize {
        let (mut top, mut best) = (f64::NEG_INFINITY, 0);
        for i in 0..c.len() {
            let (x, y, z) = (c.xs[i], c.ys[i], c.zs[i]);
            let dot = if fused {
                z.mul_add(d.z, y.mul_add(d.y, x * d.x))
            } else {
                x * d.x + y * d.y + z * d.z
            };
            if dot > top {
                (top, best) = (dot, i);
            }
        }
        best
    }

    /// The support index is the reference's, vertex for vertex (and the
    /// portable scan's is the plain reference's), for every
    /// set size from 2 to 200 and past the vector steps' boundaries: sets
    /// full of exact ties (grid points, duplicates, a repeated maximum in
    /// every lane), near-ties that fused and plain arithmetic round apart,
    /// and directions that are zero, signed zeros, tiny, huge enough to
    /// overflow the dot products to infinity, or that make them NaN.
    #[test]
    fn support_index_is_the_plain_scans_first_maximum() {
        let mut rng = Rng(0x5eed_0000_5ca1_0001);
        let mut checked = 0;
        for n in (2..=200).chain([255, 256, 257, 511]) {
            for style in 0..4 {
                let pts: Vec<Point3<f64>> = (0..n)
                    .map(|i| match style {
                        // A coarse grid: many exact ties, duplicates.
                        0 => Point3::new(
                            (rng.next() * 3.0).round(),
                            (rng.next() * 3.0).round(),
                            (rng.next() * 2.0).round(),
                        ),
                        // The same point again and again but for a few.
                        1 if i % 7 != 3 => Point3::new(1.0, 2.0, 3.0),
                        // Near-ties: a sphere of radius 1 + a few ulps.
                        2 => {
                            let v = Vector3::new(rng.next(), rng.next(), rng.next());
                            Point3::from(v.normalize() * (1.0 + rng.next() * 1e-15))
                        }
                        _ => Point3::new(rng.next(), rng.next(), rng.next()),
                    })
                    .collect();
                let c = Convex::new(pts, 0.0).unwrap();
                if matches!(c.kind, SupportKind::Box | SupportKind::Point) {
                    continue;
                }
                for k in 0..40 {
                    let mut d = Vector3::new(rng.next(), rng.next(), rng.next());
                    match k % 10 {
                        0 => d = d.map(|x| (x * 2.0).round()),
                        1 => d = Vector3::new(0.0, -0.0, 0.0),
                        2 => d = Vector3::new(-0.0, d.y, 0.0),
                        3 => d *= 1e-310,
                        4 => d *= 1e308,
                        5 => d = Vector3::new(f64::INFINITY, d.y, d.z),
                        6 => d = Vector3::new(f64::NAN, d.y, d.z),
                        _ => {}
                    }
                    assert_eq!(
                        c.support_index(&d),
                        reference(&c, &d),
                        "n {n} style {style} d {d:?}"
                    );
                    // The portable path, whatever this CPU has.
                    assert_eq!(
                        scan_top(&c.xs, &c.ys, &c.zs, &d).1,
                        reference_with(&c, &d, false),
                        "portable: n {n} style {style} d {d:?}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 30_000, "{checked}");
    }
}

/// The documented bound on a shape's reach holds with its radius counted.
#[cfg(test)]
mod reach_tests {
    use super::*;
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
