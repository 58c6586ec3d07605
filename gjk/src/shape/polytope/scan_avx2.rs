//! The support scan in AVX2 and FMA intrinsics, chosen at run time.

use nalgebra::Vector3;

use crate::shape::Convex;

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
pub(crate) unsafe fn scan_avx2_any(xs: &[f64], ys: &[f64], zs: &[f64], d: &Vector3<f64>) -> usize {
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
pub(crate) unsafe fn scan_avx2(c: &Convex, d: &Vector3<f64>) -> usize {
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
