//! The portable support scan: every vertex's dot product with the
//! direction, the first largest kept.

use nalgebra::Vector3;

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
pub(crate) fn scan_few(xs: &[f64], ys: &[f64], zs: &[f64], d: &Vector3<f64>) -> (f64, usize) {
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
