//! The polytope form of [`Convex`]: how its support point is found. The
//! search is chosen once, at construction, from the vertex count and the
//! CPU ([`SupportSearch::choose`]); each strategy is a file: the portable
//! scan ([`scan`]), its AVX2 form ([`scan_avx2`]), the f32 scan ([`single`]),
//! the cube map of candidates ([`cones`]) and the block search ([`blocks`]);
//! a box and a single point take closed forms in [`Convex`]'s dispatch.

pub(crate) mod blocks;
pub(crate) mod cones;
pub(crate) mod scan;
#[cfg(target_arch = "x86_64")]
pub(crate) mod scan_avx2;
pub(crate) mod single;
#[cfg(test)]
mod tests;

use nalgebra::Vector3;

use super::Convex;
use blocks::Blocks;
use cones::Cones;
use scan::scan_top;
#[cfg(target_arch = "x86_64")]
use scan_avx2::{scan_avx2, scan_avx2_any};
#[cfg(target_arch = "x86_64")]
use single::scan_single_avx2;
use single::{F32Copy, SINGLE_MAX_VERTICES, SINGLE_MIN_VERTICES, scan_single};

/// The support function's form, decided once from the vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum SupportKind {
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
    /// [`blocks::MIN_VERTICES`](blocks::MIN_VERTICES), on a CPU with
    /// AVX2 and FMA (checked once, here): the vector scan, called directly.
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// As [`SupportKind::Avx2`] on a CPU without them: the portable scan.
    Scan,
    /// [`CONES_MIN_VERTICES`] to [`CONES_MAX_VERTICES`] (less one): the cube map's few candidates
    /// for the direction (see [`cones`]), scanned with the arithmetic
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
    /// [`support_point`](Self::support_point) for [`SupportKind::Cones`]: the
    /// direction's candidates with the scan's arithmetic, or for a direction
    /// the map declines, the scan itself.
    #[inline(always)]
    pub(super) fn cones_index(&self, d: &Vector3<f64>, fused: bool) -> usize {
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
    pub(super) fn scan_portable(&self, d: &Vector3<f64>) -> usize {
        scan_top(&self.xs, &self.ys, &self.zs, d).1
    }

    /// [`support_point`](Self::support_point) by the block search when the
    /// shape has one, else (or for a direction it declines) the scan.
    #[inline(never)]
    pub(super) fn search_index(&self, d: &Vector3<f64>) -> usize {
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
    pub(super) fn scan_single(&self, d: &Vector3<f64>) -> usize {
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
    pub(super) fn scan_index(&self, d: &Vector3<f64>) -> usize {
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
}

/// How a shape's support point is found, with the copies of its vertices
/// that the search needs.
pub(super) struct SupportSearch {
    pub(super) kind: SupportKind,
    pub(super) single: Option<Box<F32Copy>>,
    pub(super) blocks: Option<Box<Blocks>>,
    pub(super) cones: Option<Box<Cones>>,
}

impl SupportSearch {
    /// The search for the `len` vertices of size `size` in the (padded)
    /// scan arrays.
    pub(super) fn choose(xs: &[f64], ys: &[f64], zs: &[f64], len: usize, size: f64) -> Self {
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
            (None, _) if scanned && len >= blocks::MIN_VERTICES => SupportKind::Blocks,
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
