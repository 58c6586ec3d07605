//! The simplex's rarely taken refinements: the origin's weights in a
//! tetrahedron decided by exact orientation tests, the inner radius of
//! (5.9), one step of iterative refinement, and regrowing a vertex the
//! subalgorithm dropped to round-off. All cold, kept out of the loop.

use nalgebra::Vector3;

use super::weights::{exact_volume_without, face_round_off, triangle_weights};
use super::{MEMBERS, Simplex, Solution};

impl Simplex {
    /// The origin as a point of the tetrahedron `Y`, decided and weighed by
    /// exact orientation tests alone, for when round-off in the cofactors
    /// has sent the subalgorithm to a face. A nearly flat tetrahedron (a
    /// collinear set touching a face) can have cofactors of the wrong sign
    /// while the origin is inside it: the run then stops on a face 1e-10 of
    /// the size from the origin, the support point repeating the vertex the
    /// subalgorithm dropped. The weights are the four signed volumes with
    /// the origin in place of each vertex, over their sum; their signs are
    /// exact and, being of one sign, the weights are in `[0, 1]`. Closed:
    /// the origin on a face counts, since the distance is then 0 as well.
    /// `None` when the origin is outside, when the tetrahedron is flat
    /// through it (all four volumes 0), or when a coordinate is outside the
    /// predicate's safe range.
    #[cold]
    #[inline(never)]
    pub fn origin_weights(&self) -> Option<[f64; 4]> {
        if self.all != 0b1111 {
            return None;
        }
        let y = self.predicate_points()?;
        let vols = [0, 1, 2, 3].map(|l| exact_volume_without(&y, l));
        let pos = vols.iter().any(|&v| v > 0.0);
        let neg = vols.iter().any(|&v| v < 0.0);
        if pos == neg {
            return None;
        }
        let sum: f64 = vols.iter().map(|v| v.abs()).sum();
        if !(sum > 0.0 && sum.is_finite()) {
            return None;
        }
        Some(vols.map(|v| v.abs() / sum))
    }

    /// (5.9): for a tetrahedron holding the origin, the distance from the
    /// origin to the nearest face plane, a lower bound on penetration depth.
    /// Computed from each face's normal rather than through (5.10): that
    /// formula gives the squared distance, whose square root carries an error
    /// of `√ε` relative, too much for a bound that must stay below the truth.
    pub fn inner_radius(&self, delta: f64) -> f64 {
        debug_assert_eq!(self.all, 0b1111);
        // The distance to a face's plane is |V|/|n|, V = det(p, q, r) = n·p
        // and n = (q - p) × (r - p). Each point may be off the true geometry
        // by up to `delta` (the pair's slack: rotation and centroid shift),
        // which moves V by up to δ(3M² + 3δM + δ²) (det is trilinear, M the
        // largest |y|) and |n| by up to 8δM. On a face of normal shape that
        // is about δ of distance; on a sliver face (nearly parallel edges of
        // A and B, |n| far below M²) it is far more. So each face counts only
        // what survives its own error, (|V| - δ(3M² + …))⁺ / (|n| + 8δM),
        // squared, with |n| ≤ 4M² putting the denominator under
        // len2 + 64δM³ + 64δ²M². The exact orientation test can certify the
        // origin inside such a tetrahedron by a hair; without this, a hunt
        // found a bound of 1.8e-18 on objects of size 1.7e-9 touching (depth
        // 0) edge to nearly parallel edge. M² from the kept |y|² products.
        let (shrink, widen) = face_round_off(delta, self.largest_y2());
        // The smallest squared distance over the faces, then one square
        // root: the four quotients are independent, and the one root rounds
        // as the four would have (the caller's slack covers both).
        let mut best = f64::INFINITY;
        for face in [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]] {
            let [p, q, r] = face.map(|i| self.vertices[i].y);
            let n = (q - p).cross(&(r - p));
            let len2 = n.norm_squared();
            if len2.is_nan() || len2 == 0.0 {
                // A flat face: the tetrahedron is degenerate and proves nothing.
                return 0.0;
            }
            let h = (n.dot(&p).abs() - shrink).max(0.0);
            best = best.min(h * h / (len2 + widen));
        }
        if best.is_finite() { best.sqrt() } else { 0.0 }
    }

    /// One step of iterative refinement of `sol` within the affine hull of
    /// its subset: `v' = v - E (EᵀE)⁻¹ Eᵀ v`, with `E` the edges from the
    /// subset's first point, taken as differences of the points themselves.
    /// In exact arithmetic `v'` is `v(aff Y_s)` whatever error `v` had, so one
    /// step removes the error that cofactors of a thin simplex (nearly
    /// parallel edges, or nearly collinear points of `K`) put into `v`: up to
    /// √ε of the simplex's size in its direction, where only the correction's
    /// own round-off, a small multiple of ε·|v|, remains. `None` when the
    /// subset has one point or four, when its edges are dependent, or when a
    /// refined weight leaves `[0, 1]`: `v'` would then not be a point of `K`
    /// and `|v'|` no longer an upper bound. Out of line: it is rare.
    #[cold]
    #[inline(never)]
    pub fn refine(&self, sol: Solution) -> Option<Solution> {
        let (mem, len) = MEMBERS[sol.mask as usize & 15];
        let base = mem[0] as usize & 3;
        let y0 = self.vertices[base].y;
        let mut lambda = sol.lambda;
        let v = match len {
            2 => {
                let j = mem[1] as usize & 3;
                let e = self.vertices[j].y - y0;
                let ee = e.norm_squared();
                if ee.is_nan() || ee <= 0.0 {
                    return None;
                }
                let mu = e.dot(&sol.v) / ee;
                lambda[j] -= mu;
                lambda[base] += mu;
                sol.v - e * mu
            }
            // A thin triangle's v is already its plane's (`thin_simplex_v`); the
            // normal equations below would square its condition.
            3 if self.is_thin(sol.mask as usize) => return None,
            3 => {
                let (j, k) = (mem[1] as usize & 3, mem[2] as usize & 3);
                let (e1, e2) = (self.vertices[j].y - y0, self.vertices[k].y - y0);
                let (g11, g12, g22) = (e1.norm_squared(), e1.dot(&e2), e2.norm_squared());
                let det = g11 * g22 - g12 * g12;
                if det.is_nan() || det <= 0.0 {
                    return None;
                }
                let (r1, r2) = (e1.dot(&sol.v), e2.dot(&sol.v));
                let mu1 = (g22 * r1 - g12 * r2) / det;
                let mu2 = (g11 * r2 - g12 * r1) / det;
                lambda[j] -= mu1;
                lambda[k] -= mu2;
                lambda[base] += mu1 + mu2;
                sol.v - e1 * mu1 - e2 * mu2
            }
            _ => return None,
        };
        let inside = lambda.iter().all(|l| (0.0..=1.0).contains(l));
        let finite = (v.x * 0.0 + v.y * 0.0 + v.z * 0.0) == 0.0;
        (inside && finite).then_some(Solution {
            mask: sol.mask,
            v,
            lambda,
        })
    }

    /// When the support point `(ia, ib)` repeats a vertex `y_j` of `Y` that
    /// the subalgorithm dropped from `sol`, the nearest point of
    /// `aff(V̂ ∪ {y_j})` by one refinement step from `sol`, if it lies in
    /// their hull. In exact arithmetic that cannot happen with `g > 0`: a
    /// dropped vertex satisfies `v·y_j >= |v|²`. When it does, the
    /// cofactors lost `y_j`'s weight in round-off: a far vertex (1e5 away)
    /// whose weight (1e-16) moves `v` across the set by more than `v`'s own
    /// round-off while `|v|` changes by less. A needle lying along a prism's
    /// edge, the support search then tied between the edge's two faces by
    /// the sign of that sideways error, stopped far short of its distance
    /// (the `mid_sets` sweep found it). `None` when `y_j` is not a
    /// dropped vertex, when the grown subset would be the whole tetrahedron
    /// (see [`origin_weights`](Self::origin_weights)), or when
    /// [`refine`](Self::refine) declines.
    #[cold]
    #[inline(never)]
    pub fn regrow(&self, sol: Solution, ia: u32, ib: u32) -> Option<Solution> {
        let dropped = self.pair_slots(ia, ib) & self.all & !sol.mask;
        if dropped == 0 {
            return None;
        }
        let mask = sol.mask | (dropped & dropped.wrapping_neg());
        if mask.count_ones() > 3 {
            return None;
        }
        self.refine(Solution { mask, ..sol })
    }

    /// For a tetrahedron holding the origin, its weights refined by one step
    /// so that `Σ λ_i y_i` is the origin to round-off of the points, not to
    /// that of the cofactors: `λ' = λ - δ`, `E δ = Σ λ_i y_i` with `E` the
    /// edges from the first point. Cofactors of a flat tetrahedron (cores
    /// that touch) can leave the sum 1e-9 of the size from the origin, and
    /// the nearest points, `Σ λ_i a_i` and `Σ λ_i b_i`, that far apart. `None`
    /// when the sum is already within `floor` of the origin on every axis
    /// (the usual case, which then costs one weighted sum), when a weight
    /// would leave `[0, 1]` and no face does better (see
    /// [`face_weights_of_origin`](Self::face_weights_of_origin)), or when
    /// `E` is singular.
    #[inline(never)]
    pub fn refine_origin(&self, lambda: [f64; 4], floor: f64) -> Option<[f64; 4]> {
        let y = self.vertices.map(|v| v.y);
        let (e1, e2, e3) = (y[1] - y[0], y[2] - y[0], y[3] - y[0]);
        // Σ λ_i y_i = y0 + Σ λ_i e_i when the weights sum to 1.
        let r = y[0] + e1 * lambda[1] + e2 * lambda[2] + e3 * lambda[3];
        if r.amax() <= floor {
            return None;
        }
        let miss = |w: &[f64; 4]| (y[0] + e1 * w[1] + e2 * w[2] + e3 * w[3]).norm_squared();
        let (mut best, mut least) = (None, r.norm_squared());
        if let Some(refined) = Self::refine_by_edges(lambda, r, (e1, e2, e3)) {
            let m = miss(&refined);
            if m <= floor * floor {
                return Some(refined);
            }
            (best, least) = (Some(refined), least.min(m));
        }
        // The step did not reach the origin: the tetrahedron is too flat
        // for its edges' system. A face's weights may.
        if let Some((weights, m)) = self.face_weights_of_origin()
            && m < least
        {
            best = Some(weights);
        }
        best
    }

    /// The one step of [`refine_origin`](Self::refine_origin): `λ - δ`
    /// with `E δ = r`, `None` when a weight would leave `[0, 1]` or `E` is
    /// singular.
    #[inline(always)]
    pub(super) fn refine_by_edges(
        lambda: [f64; 4],
        r: Vector3<f64>,
        (e1, e2, e3): (Vector3<f64>, Vector3<f64>, Vector3<f64>),
    ) -> Option<[f64; 4]> {
        // Cramer's rule for E δ = r, the three cofactor vectors shared.
        let (c23, c31, c12) = (e2.cross(&e3), e3.cross(&e1), e1.cross(&e2));
        let det = e1.dot(&c23);
        if det.is_nan() || det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let (d1, d2, d3) = (r.dot(&c23) * inv, r.dot(&c31) * inv, r.dot(&c12) * inv);
        let out = [
            lambda[0] + d1 + d2 + d3,
            lambda[1] - d1,
            lambda[2] - d2,
            lambda[3] - d3,
        ];
        out.iter().all(|l| (0.0..=1.0).contains(l)).then_some(out)
    }

    /// Weights for the origin from one face of a tetrahedron too flat for
    /// its own (cores that cross, a needle through a segment): there the
    /// 3×3 system of the whole is near singular, and its weights, though
    /// they sum to 1, can put `Σ λ_i a_i` and `Σ λ_i b_i` far apart, off
    /// the shape that the other is reported on. In the plane of a flat
    /// tetrahedron its four faces cover its outline, so the origin's
    /// projection lies in one of them, whose 2×2 system is well
    /// conditioned. The face's weights (in their slots, 0 in the fourth)
    /// whose point is nearest the origin, with that point's squared
    /// distance; `None` if no face holds the projection.
    #[cold]
    pub(super) fn face_weights_of_origin(&self) -> Option<([f64; 4], f64)> {
        let y = self.vertices.map(|v| v.y);
        let mut best: Option<([f64; 4], f64)> = None;
        for skip in 0..4 {
            let [i, j, k] = match skip {
                0 => [1, 2, 3],
                1 => [0, 2, 3],
                2 => [0, 1, 3],
                _ => [0, 1, 2],
            };
            let (p, e1, e2) = (y[i], y[j] - y[i], y[k] - y[i]);
            let Some([_, s, t]) = triangle_weights([p, y[j], y[k]], &Vector3::zeros()) else {
                continue;
            };
            if !(s >= 0.0 && t >= 0.0 && s + t <= 1.0) {
                continue;
            }
            let miss = (p + e1 * s + e2 * t).norm_squared();
            if best.is_none_or(|(_, least)| miss < least) {
                let mut weights = [0.0; 4];
                (weights[i], weights[j], weights[k]) = (1.0 - s - t, s, t);
                best = Some((weights, miss));
            }
        }
        best
    }
}
