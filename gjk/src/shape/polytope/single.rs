//! The f32 support scan of [`Precision::Single`](crate::Precision::Single):
//! a copy of the vertices in f32, scanned with twice the lanes.

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
pub(crate) struct F32Copy {
    pub(super) xs: Vec<f32>,
    pub(super) ys: Vec<f32>,
    pub(super) zs: Vec<f32>,
}

impl F32Copy {
    /// The copy of centroid-relative arrays of a set of size `size`, each
    /// coordinate divided by it; `None` where that cannot be done exactly
    /// enough or the indices would not fit the scan's i32 lanes.
    pub(crate) fn of(xs: &[f64], ys: &[f64], zs: &[f64], size: f64) -> Option<Box<Self>> {
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

/// The f32 support scan, portable: 8 lanes, any vertex of the largest dot
/// product (ties need no order: the f32 result is within the slack anyway).
pub(super) fn scan_single(xs: &[f32], ys: &[f32], zs: &[f32], d: [f32; 3]) -> usize {
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
pub(super) unsafe fn scan_single_avx2(xs: &[f32], ys: &[f32], zs: &[f32], d: [f32; 3]) -> usize {
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
