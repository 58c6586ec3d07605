//! The exact support search for mid-sized vertex sets: a cube map of
//! directions whose every cell lists the only vertices that can be a support
//! point for a direction in it.
//!
//! The paper's support function scans every vertex. For a polytope of a few
//! dozen vertices most of them are the support point only for directions far
//! from the one asked: each vertex wins on its own cone of directions (its
//! normal cone), and the cones tile the sphere. The directions are cut here
//! into the cells of a cube map (6 faces of `GRID × GRID`), and each cell keeps
//! the vertices that no other vertex beats over the whole cell, by a margin.
//! A query finds its direction's cell and scans that cell's few vertices.
//!
//! The answer is the scan's own, vertex for vertex: a vertex is left out of a
//! cell only when another beats it at every direction of the cell by far more
//! than the rounding of any dot product, so a left-out vertex can neither win
//! nor tie the computed maximum; the candidates are scanned in ascending
//! index with the scan's own arithmetic, so ties go to the lowest index, as in
//! the scan. Directions the margins do not cover (zero, subnormal, huge,
//! NaN) are declined and left to the scan.

use nalgebra::Vector3;

/// Cells along each edge of a cube face: 6·8² = 384 cells, each about 10° on
/// a side, so that a cell meets the normal cones of only a few vertices of a
/// shape of up to a few hundred.
const GRID: usize = 8;

/// Relative margin by which a vertex must beat another over a whole cell for
/// the other to be left out: far above the round-off of a dot product (about
/// 2^-51 relative to `|x|·|d|`) and of the test itself.
const MARGIN: f64 = 1.0 / (1u64 << 40) as f64;

/// Shapes and directions of these sizes only: every product and margin
/// below then stays far from underflow and overflow.
const RANGE: (f64, f64) = (1e-100, 1e100);

/// The cube map of one vertex set.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Cones {
    /// Where each cell's candidates start in `list`, and one past the last.
    start: Vec<u32>,
    /// Candidate indices, ascending within each cell.
    list: Vec<u32>,
}

/// The axes of face `face`: the major axis `a`, its sign, and the two others
/// in cyclic order (`b`, `c`), as a query computes them.
fn face_axes(face: usize) -> (usize, f64, usize, usize) {
    let a = face / 2;
    let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    (a, sign, (a + 1) % 3, (a + 2) % 3)
}

impl Cones {
    /// The map of the first `len` vertices of `xs, ys, zs` (centroid-relative
    /// coordinates), `size` their largest distance from the centroid. `None`
    /// for sizes outside the range the margins are proved for.
    pub(crate) fn new(xs: &[f64], ys: &[f64], zs: &[f64], len: usize, size: f64) -> Option<Self> {
        if !(size >= RANGE.0 && size <= RANGE.1) || len > u32::MAX as usize {
            return None;
        }
        let p = |k: usize| Vector3::new(xs[k], ys[k], zs[k]);
        let norms: Vec<f64> = (0..len).map(|k| p(k).norm()).collect();
        // Any maximiser of x·d: a possible dominator only, so its choice among
        // ties does not matter.
        let argmax = |d: &Vector3<f64>| {
            let mut best = (f64::NEG_INFINITY, 0);
            for k in 0..len {
                let v = p(k).dot(d);
                if v > best.0 {
                    best = (v, k);
                }
            }
            best.1
        };
        // Pairs of vertices both within this of the centroid are never told
        // apart: their margin would be too small to trust.
        let floor = size * (1.0 / (1u64 << 20) as f64);
        let mut start = Vec::with_capacity(6 * GRID * GRID + 1);
        let mut list = Vec::new();
        for face in 0..6 {
            let (a, sign, b, c) = face_axes(face);
            let dir = |u: f64, v: f64| {
                let mut d = Vector3::zeros();
                d[a] = sign;
                d[b] = u;
                d[c] = v;
                d
            };
            let at = |i: usize| -1.0 + 2.0 * i as f64 / GRID as f64;
            for i in 0..GRID {
                for j in 0..GRID {
                    start.push(list.len() as u32);
                    let corners = [
                        dir(at(i), at(j)),
                        dir(at(i + 1), at(j)),
                        dir(at(i), at(j + 1)),
                        dir(at(i + 1), at(j + 1)),
                    ];
                    let centre = dir(
                        -1.0 + (2 * i + 1) as f64 / GRID as f64,
                        -1.0 + (2 * j + 1) as f64 / GRID as f64,
                    );
                    let mut dominators: Vec<usize> = corners.iter().map(argmax).collect();
                    dominators.push(argmax(&centre));
                    dominators.sort_unstable();
                    dominators.dedup();
                    let lengths = corners.map(|d| d.norm());
                    for k in 0..len {
                        let beaten = dominators.iter().any(|&u| {
                            let reach = norms[u] + norms[k];
                            u != k
                                && reach >= floor
                                && corners
                                    .iter()
                                    .zip(&lengths)
                                    .all(|(d, l)| (p(u) - p(k)).dot(d) > 2.0 * MARGIN * reach * l)
                        });
                        if !beaten {
                            list.push(k as u32);
                        }
                    }
                }
            }
        }
        start.push(list.len() as u32);
        Some(Cones { start, list })
    }

    /// The candidates of `d`'s cell, ascending, or `None` for a direction
    /// outside the range the margins cover (the caller then scans).
    #[inline(always)]
    pub(crate) fn candidates(&self, d: &Vector3<f64>) -> Option<&[u32]> {
        let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
        // The major axis, ties to the lower one; the other two in cyclic
        // order, as `face_axes` has them.
        let (face, m, db, dc) = if ax >= ay && ax >= az {
            (usize::from(d.x < 0.0), ax, d.y, d.z)
        } else if ay >= az {
            (2 + usize::from(d.y < 0.0), ay, d.z, d.x)
        } else {
            (4 + usize::from(d.z < 0.0), az, d.x, d.y)
        };
        // NaN fails both comparisons.
        if !(m >= RANGE.0 && m <= RANGE.1) {
            return None;
        }
        let inv = 1.0 / m;
        // |db|, |dc| <= m, so each ratio is within a rounding of [-1, 1] and
        // each cell coordinate below within a rounding of [0, GRID]: the
        // conversion is exact and the clamps take the two ends. A direction a
        // rounding outside its cell is still covered by the margins.
        let half = GRID as f64 / 2.0;
        let cell = |x: f64| {
            let f = (x * inv + 1.0) * half;
            // SAFETY: f is finite and within [-1, GRID + 1] (see above).
            let i: i32 = unsafe { f.to_int_unchecked() };
            i.clamp(0, GRID as i32 - 1) as usize
        };
        let k = (face * GRID + cell(db)) * GRID + cell(dc);
        debug_assert!(k + 1 < self.start.len());
        // SAFETY: k < 6·GRID² and `start` has 6·GRID² + 1 entries, each at
        // most `list.len()`, in ascending order (built so in `new`).
        unsafe {
            let lo = *self.start.get_unchecked(k) as usize;
            let hi = *self.start.get_unchecked(k + 1) as usize;
            Some(self.list.get_unchecked(lo..hi))
        }
    }

    /// Candidates kept, all cells together (for tests and measurements).
    #[cfg(test)]
    pub(crate) fn total(&self) -> usize {
        self.list.len()
    }
}

/// The first index of the largest `x·d` among `cands` (ascending), with the
/// arithmetic of the scan it stands in for: with `FUSED` the AVX2 scan's,
/// `fma(z, dz, fma(y, dy, x·dx))` each rounded once as `_mm256_fmadd_pd`
/// does lane by lane; without, the portable scan's `x·dx + y·dy + z·dz`,
/// left to right.
#[inline(always)]
pub(crate) fn first_max<const FUSED: bool>(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    cands: &[u32],
    d: &Vector3<f64>,
) -> usize {
    let (mut top, mut idx) = (f64::NEG_INFINITY, 0);
    debug_assert!(ys.len() == xs.len() && zs.len() == xs.len());
    for &k in cands {
        let k = k as usize;
        debug_assert!(k < xs.len());
        // SAFETY: candidates are vertex indices of the set the map was
        // built from, below the length of its three coordinate arrays.
        let (x, y, z) = unsafe {
            (
                *xs.get_unchecked(k),
                *ys.get_unchecked(k),
                *zs.get_unchecked(k),
            )
        };
        let value = if FUSED {
            z.mul_add(d.z, y.mul_add(d.y, x * d.x))
        } else {
            x * d.x + y * d.y + z * d.z
        };
        if value > top {
            (top, idx) = (value, k);
        }
    }
    idx
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::test_rng::Rng;

    /// The full scan's choice: the first index of the largest dot product.
    fn full(xs: &[f64], ys: &[f64], zs: &[f64], d: &Vector3<f64>, fused: bool) -> usize {
        let all: Vec<u32> = (0..xs.len() as u32).collect();
        if fused {
            first_max::<true>(xs, ys, zs, &all, d)
        } else {
            first_max::<false>(xs, ys, zs, &all, d)
        }
    }

    fn centred(points: &[Vector3<f64>]) -> (Vec<f64>, Vec<f64>, Vec<f64>, f64) {
        let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
        let rel: Vec<_> = points.iter().map(|p| p - mean).collect();
        let size = rel.iter().map(|p| p.norm()).fold(0.0, f64::max);
        (
            rel.iter().map(|p| p.x).collect(),
            rel.iter().map(|p| p.y).collect(),
            rel.iter().map(|p| p.z).collect(),
            size,
        )
    }

    /// Point sets with the ties and near-ties a support search can meet:
    /// round and flat clouds, lattices hit square on, coplanar and
    /// collinear sets, duplicates, a point far off a tiny cluster.
    fn sets(rng: &mut Rng) -> Vec<Vec<Vector3<f64>>> {
        let mut out = Vec::new();
        for n in [16, 20, 40, 100, 300, 511, 1500, 4000] {
            out.push(
                (0..n)
                    .map(|_| Vector3::new(rng.next(), rng.next(), rng.next()))
                    .collect(),
            );
            // On a sphere: every point a hull vertex.
            out.push(
                (0..n)
                    .map(|_| {
                        let v = Vector3::new(rng.next(), rng.next(), rng.next());
                        v / v.norm().max(1e-9)
                    })
                    .collect(),
            );
        }
        // A 4 x 4 x 4 lattice: exact ties along every axis direction.
        out.push(
            (0..64)
                .map(|i| Vector3::new((i % 4) as f64, ((i / 4) % 4) as f64, (i / 16) as f64))
                .collect(),
        );
        // Coplanar (z = 0) and collinear sets, with duplicates.
        out.push(
            (0..30)
                .map(|_| Vector3::new(rng.next(), rng.next(), 0.0))
                .chain((0..5).map(|_| Vector3::zeros()))
                .collect(),
        );
        out.push(
            (0..24)
                .map(|i| Vector3::new(i as f64 * 0.1, 2.0 * i as f64 * 0.1, 0.0))
                .collect(),
        );
        let dup: Vec<Vector3<f64>> = (0..20)
            .map(|_| Vector3::new(rng.next(), rng.next(), rng.next()))
            .collect();
        out.push(dup.iter().chain(dup.iter()).copied().collect());
        // A two-plane polytope like the paper's, and a prism.
        out.push(
            (0..40)
                .map(|i| {
                    let t = i as f64 * 0.31;
                    Vector3::new(t.cos(), 0.7 * t.sin(), if i % 2 == 0 { 0.4 } else { -0.4 })
                })
                .collect(),
        );
        out.push(
            (0..20)
                .map(|i| {
                    let t = std::f64::consts::TAU * (i % 10) as f64 / 10.0;
                    Vector3::new(t.cos(), t.sin(), if i < 10 { -1.0 } else { 1.0 })
                })
                .collect(),
        );
        out
    }

    #[test]
    fn candidates_give_the_scans_own_vertex() {
        let mut rng = Rng(0x00c0_0e5e_ed00_0001);
        let mut checked = 0;
        let mut kept = 0;
        let mut cells = 0;
        for base in sets(&mut rng) {
            for scale in [1e-90, 1e-6, 1.0, 1e7, 1e90] {
                for offset in [0.0, 1e3] {
                    let pts: Vec<_> = base
                        .iter()
                        .map(|p| p * scale + Vector3::repeat(offset * scale))
                        .collect();
                    let (xs, ys, zs, size) = centred(&pts);
                    let cones = Cones::new(&xs, &ys, &zs, xs.len(), size).expect("in range");
                    kept += cones.total();
                    cells += 6 * GRID * GRID;
                    for k in 0..400 {
                        let mut d = Vector3::new(rng.next(), rng.next(), rng.next());
                        match k % 8 {
                            // On cell borders and face edges, and axis-aligned.
                            1 => d = Vector3::new(1.0, 0.25 * (k % 9) as f64 - 1.0, -0.5),
                            2 => d = Vector3::new(-0.75, 0.75, 0.125 * (k % 17) as f64 - 1.0),
                            3 => d = Vector3::new(0.0, 0.0, -1.0),
                            4 => d = Vector3::new(0.0, -0.0, 1.0) + Vector3::new(0.0, 1e-300, 0.0),
                            5 => d *= 1e-90,
                            6 => d *= 1e90,
                            _ => {}
                        }
                        for fused in [false, true] {
                            let want = full(&xs, &ys, &zs, &d, fused);
                            let got = match cones.candidates(&d) {
                                Some(c) if fused => first_max::<true>(&xs, &ys, &zs, c, &d),
                                Some(c) => first_max::<false>(&xs, &ys, &zs, c, &d),
                                None => want,
                            };
                            assert_eq!(
                                got,
                                want,
                                "n {} scale {scale:e} d {d:?} fused {fused}",
                                xs.len()
                            );
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 100_000, "{checked}");
        // The lists are short: a few vertices a cell on average.
        let mean = kept as f64 / cells as f64;
        assert!(mean < 12.0, "{mean}");
    }

    #[test]
    fn directions_out_of_range_and_sizes_out_of_range_are_declined() {
        let pts: Vec<_> = (0..20)
            .map(|i| Vector3::new(i as f64, (i * i) as f64 * 0.1, 1.0 - i as f64))
            .collect();
        let (xs, ys, zs, size) = centred(&pts);
        let cones = Cones::new(&xs, &ys, &zs, xs.len(), size).unwrap();
        for d in [
            Vector3::zeros(),
            Vector3::new(1e-200, 0.0, 0.0),
            Vector3::new(0.0, 1e200, 1.0),
            Vector3::new(1.0, f64::INFINITY, 0.0),
        ] {
            assert!(cones.candidates(&d).is_none(), "{d:?}");
        }
        for s in [1e-120, 1e120] {
            let (xs, ys, zs, size) = centred(&pts.iter().map(|p| p * s).collect::<Vec<_>>());
            assert!(Cones::new(&xs, &ys, &zs, xs.len(), size).is_none());
        }
    }
}
