//! The exact support search for large vertex sets.
//!
//! The paper's support function is a scan of every vertex, linear in their
//! number. For a set of thousands of vertices most of them cannot be the
//! answer: the search here groups the vertices into blocks of 64 or 128
//! neighbours, bounds each block by a sphere, scans the block of highest bound
//! first and then only the blocks whose bound reaches the best dot product
//! found so far.
//!
//! The answer is the plain scan's own, vertex for vertex: the bounds are
//! inflated to cover every rounding error of both the bound and the scanned
//! dot products, so a skipped block holds no vertex whose computed dot product
//! even ties the best, and ties between blocks go to the lowest original
//! index, as in the scan. Nothing of the algorithm's certificate changes.

use nalgebra::Vector3;

use super::scan::scan_top;
use crate::numeric::robust_norm;

/// Vertices per block: a multiple of the AVX2 scan's eight lanes, near the
/// square root of the set's size, so that bounding every block costs about
/// as much as scanning the few blocks that cannot be skipped. Cold queries
/// on round and box-shaped clouds found 64 best or nearly so up to some
/// 16 000 vertices, and 128 faster on the largest sets.
fn block_size(n: usize) -> usize {
    if n < 32_768 { 64 } else { 128 }
}

/// Sets with fewer vertices keep the plain scan: with a handful of blocks,
/// bounding them costs about what skipping saves: against the scan (cold
/// queries on round and box-shaped clouds) the block search loses below
/// this size, breaks even at it and wins above.
pub(crate) const MIN_VERTICES: usize = 512;

/// Relative growth of each bounding sphere, far above the few units of
/// round-off (about 2^-51 relative) in a dot product and in the bound itself.
const GROW: f64 = 1.0 / (1u64 << 40) as f64;

/// Absolute allowance for dot products that underflow into subnormals, each
/// off by at most 2^-1075: 2^-1060 covers any handful of them.
const TINY: f64 = f64::from_bits(1 << 14);

/// A shape's vertices reordered into spatially compact blocks, with a
/// bounding sphere per block.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Blocks {
    /// Centroid-relative coordinates, block after block; the last block is
    /// padded to a whole block with copies of its first vertex, which
    /// never beat their original (ties go to the lower position).
    xs: Vec<f64>,
    ys: Vec<f64>,
    zs: Vec<f64>,
    /// The caller's index of each position. Within a block positions follow
    /// the caller's order, so the scan's lowest-position tie rule is the
    /// caller's lowest-index rule.
    perm: Vec<u32>,
    /// Each block's sphere: centre and radius, the radius grown by [`GROW`]
    /// relative to the centre's distance from the centroid plus itself.
    /// Padded to a multiple of four (the AVX2 lanes) with spheres of radius
    /// -∞, whose bound is -∞: never the first block, never scanned.
    cx: Vec<f64>,
    cy: Vec<f64>,
    cz: Vec<f64>,
    r: Vec<f64>,
    /// The number of blocks, padding not included.
    count: usize,
    /// Vertices per block.
    block: usize,
}

impl Blocks {
    /// Blocks of the first `n` entries of the centroid-relative coordinate
    /// arrays (which may be longer, padded for the plain scan).
    pub(crate) fn new(xs: &[f64], ys: &[f64], zs: &[f64], n: usize) -> Self {
        let block = block_size(n);
        // The points themselves are partitioned, not indices into them:
        // the splits then read memory in order, which builds large sets
        // several times faster than through indices.
        let mut pts: Vec<([f64; 3], u32)> =
            (0..n).map(|i| ([xs[i], ys[i], zs[i]], i as u32)).collect();
        split(&mut pts, block);
        let count = n.div_ceil(block);
        let mut out = Blocks {
            xs: Vec::with_capacity(count * block),
            ys: Vec::with_capacity(count * block),
            zs: Vec::with_capacity(count * block),
            perm: Vec::with_capacity(count * block),
            cx: Vec::with_capacity(count),
            cy: Vec::with_capacity(count),
            cz: Vec::with_capacity(count),
            r: Vec::with_capacity(count),
            count,
            block,
        };
        for chunk in pts.chunks(block) {
            let padded = chunk
                .iter()
                .chain(std::iter::repeat_n(&chunk[0], block - chunk.len()));
            let (mut lo, mut hi) = (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            );
            for &(p, i) in padded {
                let v = Vector3::from(p);
                lo = lo.inf(&v);
                hi = hi.sup(&v);
                out.xs.push(v.x);
                out.ys.push(v.y);
                out.zs.push(v.z);
                out.perm.push(i);
            }
            // The box's middle: halves first, so that coordinates near
            // f64::MAX cannot overflow in the sum.
            let c = lo * 0.5 + hi * 0.5;
            let mut r: f64 = 0.0;
            for (p, _) in chunk {
                r = r.max(robust_norm(&(Vector3::from(*p) - c)));
            }
            out.cx.push(c.x);
            out.cy.push(c.y);
            out.cz.push(c.z);
            out.r.push(r + (robust_norm(&c) + r) * GROW);
        }
        let padded = count.div_ceil(4) * 4;
        out.cx.resize(padded, 0.0);
        out.cy.resize(padded, 0.0);
        out.cz.resize(padded, 0.0);
        out.r.resize(padded, f64::NEG_INFINITY);
        out
    }

    /// The index (in the caller's order) of the vertex of largest dot
    /// product with `d`, the plain scan's choice; `None` for a direction
    /// whose length is too small or too large for the bounds' error analysis
    /// (or not finite), which the caller then scans plainly.
    pub(crate) fn support(&self, d: &Vector3<f64>) -> Option<usize> {
        let len = d.norm();
        if !(len > 1e-150 && len < 1e150) {
            return None;
        }
        #[cfg(target_arch = "x86_64")]
        {
            if crate::has_avx2_fma() {
                // SAFETY: the CPU supports AVX2 and FMA, checked just above.
                return Some(unsafe { self.search_avx2(d, len) }.0);
            }
        }
        Some(self.search(d, len).0)
    }

    /// The search, portable: the first block is the one of highest bound,
    /// then every block whose bound reaches the best dot product found.
    /// Returns the index and the number of blocks scanned.
    fn search(&self, d: &Vector3<f64>, len: f64) -> (usize, usize) {
        let scan = scan_top;
        // Every computed dot product of a vertex of block b is at most
        // bound(b): |v·d - c·d| <= r|d|, and GROW covers the rounding of both
        // sides (a few units of 2^-53 of (|c| + r)|d|), TINY any underflow.
        let bound = |b: usize| {
            // Plain products: `mul_add` outside an FMA-enabled function
            // is a library call.
            (self.cx[b] * d.x + self.cy[b] * d.y + self.cz[b] * d.z) + (self.r[b] * len + TINY)
        };
        let blocks = self.count;
        let mut first = 0;
        let mut first_bound = bound(0);
        for b in 1..blocks {
            let u = bound(b);
            if u > first_bound {
                (first, first_bound) = (b, u);
            }
        }
        let size = self.block;
        let at = |b: usize| b * size..(b + 1) * size;
        let block = |b: usize| {
            let r = at(b);
            let (top, i) = scan(&self.xs[r.clone()], &self.ys[r.clone()], &self.zs[r], d);
            (top, self.perm[b * size + i])
        };
        let (mut best, mut best_i) = block(first);
        let mut scanned = 1;
        for b in 0..blocks {
            // `>=`: a block whose bound ties the best may hold a tie of lower
            // index. A NaN bound is never skipped either.
            if b == first || bound(b) < best {
                continue;
            }
            let (top, i) = block(b);
            scanned += 1;
            if top > best || (top == best && i < best_i) {
                (best, best_i) = (top, i);
            }
        }
        (best_i as usize, scanned)
    }

    /// [`search`](Self::search) in AVX2 and FMA: four bounds per step in
    /// both passes, and the AVX2 scan in the blocks, the one the plain scan
    /// uses on such a CPU, so both compute the same dot products.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn search_avx2(&self, d: &Vector3<f64>, len: f64) -> (usize, usize) {
        use std::arch::x86_64::*;
        let (dx, dy, dz) = (
            _mm256_set1_pd(d.x),
            _mm256_set1_pd(d.y),
            _mm256_set1_pd(d.z),
        );
        let (l, tiny) = (_mm256_set1_pd(len), _mm256_set1_pd(TINY));
        let padded = self
            .r
            .len()
            .min(self.cx.len())
            .min(self.cy.len())
            .min(self.cz.len());
        let bound4 = |k: usize| {
            // SAFETY: k + 4 <= padded, the length of all four arrays.
            let (x, y, z, r) = unsafe {
                (
                    _mm256_loadu_pd(self.cx.as_ptr().add(k)),
                    _mm256_loadu_pd(self.cy.as_ptr().add(k)),
                    _mm256_loadu_pd(self.cz.as_ptr().add(k)),
                    _mm256_loadu_pd(self.r.as_ptr().add(k)),
                )
            };
            let cd = _mm256_fmadd_pd(z, dz, _mm256_fmadd_pd(y, dy, _mm256_mul_pd(x, dx)));
            _mm256_add_pd(cd, _mm256_fmadd_pd(r, l, tiny))
        };
        // Pass 1: the block of highest bound (any of them on a tie).
        let mut top = _mm256_set1_pd(f64::NEG_INFINITY);
        let mut top_i = _mm256_setzero_pd();
        let mut base = _mm256_setr_pd(0.0, 1.0, 2.0, 3.0);
        let step = _mm256_set1_pd(4.0);
        let mut k = 0;
        while k + 4 <= padded {
            let u = bound4(k);
            let gt = _mm256_cmp_pd::<_CMP_GT_OQ>(u, top);
            top = _mm256_blendv_pd(top, u, gt);
            top_i = _mm256_blendv_pd(top_i, base, gt);
            base = _mm256_add_pd(base, step);
            k += 4;
        }
        let (mut tops, mut tops_i) = ([0.0f64; 4], [0.0f64; 4]);
        // SAFETY: both arrays hold four f64.
        unsafe {
            _mm256_storeu_pd(tops.as_mut_ptr(), top);
            _mm256_storeu_pd(tops_i.as_mut_ptr(), top_i);
        }
        let mut first = tops_i[0] as usize;
        let mut first_bound = tops[0];
        for j in 1..4 {
            if tops[j] > first_bound {
                (first, first_bound) = (tops_i[j] as usize, tops[j]);
            }
        }
        let first = first.min(self.count - 1);
        let block = |b: usize| {
            let r = b * self.block..(b + 1) * self.block;
            // SAFETY: the caller's CPU has AVX2 and FMA (this function's
            // own requirement).
            let (top, i) = unsafe {
                crate::shape::polytope::scan_avx2::scan_avx2_top(
                    &self.xs[r.clone()],
                    &self.ys[r.clone()],
                    &self.zs[r],
                    d,
                )
            };
            (top, self.perm[b * self.block + i])
        };
        let (mut best, mut best_i) = block(first);
        let mut scanned = 1;
        // Pass 2: every other block whose bound is not below the best (a
        // NaN bound is not skipped either).
        let mut floor = _mm256_set1_pd(best);
        let mut k = 0;
        while k + 4 <= padded {
            let mut hits =
                _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_NLT_UQ>(bound4(k), floor)) as u32;
            while hits != 0 {
                let b = k + hits.trailing_zeros() as usize;
                hits &= hits - 1;
                if b == first || b >= self.count {
                    continue;
                }
                let (top, i) = block(b);
                scanned += 1;
                if top > best || (top == best && i < best_i) {
                    (best, best_i) = (top, i);
                    floor = _mm256_set1_pd(best);
                }
            }
            k += 4;
        }
        (best_i as usize, scanned)
    }
}

/// Order `pts` so that each run of `block` is a cell of a k-d split: halve
/// along the widest extent, at a multiple of `block` so that every block but
/// the last is full, until a part fits one block; within a block, the
/// caller's order.
fn split(pts: &mut [([f64; 3], u32)], block: usize) {
    if pts.len() <= block {
        pts.sort_unstable_by_key(|p| p.1);
        return;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (p, _) in pts.iter() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    // Halves first, so that the extent of coordinates near f64::MAX does
    // not overflow.
    let extent = |k: usize| hi[k] * 0.5 - lo[k] * 0.5;
    let axis = (1..3).fold(0, |best, k| if extent(k) > extent(best) { k } else { best });
    // len > block, so block <= mid < len.
    let mid = (pts.len() / 2).div_ceil(block) * block;
    pts.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
    let (left, right) = pts.split_at_mut(mid);
    split(left, block);
    split(right, block);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Convex;
    use crate::shape::test_rng::Rng;
    use nalgebra::Point3;

    /// The shape's vertices in the plain scan's layout, unpadded.
    fn arrays(c: &Convex) -> [Vec<f64>; 3] {
        let v: Vec<Vector3<f64>> = (0..c.len()).map(|i| c.local(i)).collect();
        [0, 1, 2].map(|k| v.iter().map(|p| p[k]).collect())
    }

    /// The plain scan over the whole set, portable or AVX2: the reference.
    fn plain([xs, ys, zs]: &[Vec<f64>; 3], d: &Vector3<f64>, avx2: bool) -> usize {
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            // SAFETY: callers pass avx2 only when the CPU has AVX2 and FMA.
            return unsafe { crate::shape::polytope::scan_avx2::scan_avx2_top(xs, ys, zs, d).1 };
        }
        let _ = avx2;
        scan_top(xs, ys, zs, d).1
    }

    fn sets(rng: &mut Rng) -> Vec<(&'static str, Vec<Point3<f64>>)> {
        let mut out = vec![];
        for n in [512, 700, 5000, 40_000] {
            out.push((
                "sphere",
                (0..n)
                    .map(|_| {
                        let v = Vector3::new(rng.next(), rng.next(), rng.next());
                        Point3::from(v.normalize())
                    })
                    .collect(),
            ));
            out.push((
                "cloud",
                (0..n)
                    .map(|_| Point3::new(rng.next(), rng.next() * 2.0, rng.next() * 0.5))
                    .collect(),
            ));
        }
        // Exact ties everywhere: an integer lattice, its faces hit square on.
        out.push((
            "lattice",
            (0..1000)
                .map(|i| Point3::new((i % 10) as f64, (i / 10 % 10) as f64, (i / 100) as f64))
                .collect(),
        ));
        out.push((
            "flat",
            (0..700)
                .map(|_| Point3::new(rng.next(), rng.next(), 0.0))
                .collect(),
        ));
        out.push((
            "collinear",
            (0..520)
                .map(|_| {
                    let t = rng.next();
                    Point3::new(t, 2.0 * t, -t)
                })
                .collect(),
        ));
        out.push(("one point", vec![Point3::new(0.5, 0.25, 1.0); 600]));
        // Duplicates of the extreme points, scattered over the order.
        let mut dup: Vec<Point3<f64>> = (0..600)
            .map(|_| Point3::new(rng.next(), rng.next(), rng.next()))
            .collect();
        for i in 0..60 {
            dup[i * 10] = Point3::new(1.0, 1.0, 1.0);
        }
        out.push(("duplicates", dup));
        out
    }

    /// The block search returns the plain scan's own vertex, on both code
    /// paths, for sets with exact ties, flat, collinear and coincident sets,
    /// at scales from 1e-300 to 1e290 and 1e9 from the origin, for
    /// directions of any length (those outside its range go to the scan).
    #[test]
    fn block_search_is_the_plain_scan() {
        let mut rng = Rng(0x0b10_c4ed_5eed_0001);
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        let mut checked = 0;
        for (name, pts) in sets(&mut rng) {
            for (scale, offset) in [
                (1.0, 0.0),
                (1e-300, 0.0),
                (1e290, 0.0),
                (1e-6, 1e9),
                (1.0, 1e9),
            ] {
                let p: Vec<Point3<f64>> = pts
                    .iter()
                    .map(|v| Point3::from(v.coords * scale + Vector3::repeat(offset)))
                    .collect();
                let c = Convex::new(p, 0.0).unwrap_or_else(|e| panic!("{name} {scale:e}: {e}"));
                // The cube map now takes sets below 4 096 vertices: their
                // block index is built here to test the search itself.
                let owned;
                let blocks = match c.blocks() {
                    Some(b) => b,
                    None => {
                        owned = c.block_index();
                        &owned
                    }
                };
                let flat = arrays(&c);
                for k in 0..100 {
                    let mut d = Vector3::new(rng.next(), rng.next(), rng.next());
                    match k % 10 {
                        // Square on a lattice face or edge: ties.
                        1 => d = Vector3::new(1.0, 0.0, 0.0),
                        2 => d = Vector3::new(-1.0, 1.0, -0.0),
                        3 => d = Vector3::new(1.0, 1.0, 1.0),
                        4 => d.y *= 1e-300,
                        // Outside the search's range: the scan decides.
                        5 => d *= 1e-200,
                        6 => d *= 1e200,
                        7 => d *= 1e-310,
                        8 => d *= 1e-140,
                        _ => {}
                    }
                    let want = plain(&flat, &d, avx2);
                    assert_eq!(
                        c.support_index(&d),
                        want,
                        "{name} {scale:e} {offset:e} {d:?}"
                    );
                    let len = d.norm();
                    if len > 1e-150 && len < 1e150 {
                        assert_eq!(
                            blocks.search(&d, len).0,
                            plain(&flat, &d, false),
                            "{name} portable {d:?}"
                        );
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked == 6_500, "{checked}");
    }

    /// The search skips most blocks of a large, round set: about the few
    /// around the support point are scanned.
    #[test]
    fn most_blocks_are_skipped_on_a_large_set() {
        let mut rng = Rng(7);
        let pts: Vec<Point3<f64>> = (0..16_384)
            .map(|_| Point3::from(Vector3::new(rng.next(), rng.next(), rng.next()).normalize()))
            .collect();
        let c = Convex::new(pts, 0.0).unwrap();
        let blocks = c.blocks().unwrap();
        let mut total = 0;
        for _ in 0..100 {
            let d = Vector3::new(rng.next(), rng.next(), rng.next());
            total += blocks.search(&d, d.norm()).1;
        }
        let per_query = total as f64 / 100.0;
        // 256 blocks of 64; a cap on the sphere of the blocks' own width.
        assert!(per_query < 40.0, "{per_query} blocks scanned per search");
        assert!(per_query >= 1.0);
    }
}
