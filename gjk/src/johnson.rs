//! Johnson's distance subalgorithm (Section 5) and the Backup Procedure (6.5).
//!
//! The simplex holds up to four points `y_i` of `K = A - B` in four slots; a bit
//! mask names a subset `Y_s`. Dot products `y_i·y_j` and the cofactors
//! `Δ_i(Y_s)` of (5.6) are kept between iterations: when a point enters a slot,
//! only the subsets that contain that slot are recomputed, because every other
//! subset is a subset of the previous simplex and its cofactors are unchanged.

use nalgebra::Vector3;

/// Slot bit masks of each subset's members, precomputed for speed.
const fn members(mask: usize) -> ([u8; 4], u8) {
    let mut out = [0u8; 4];
    let mut n = 0;
    let mut i = 0;
    while i < 4 {
        if mask & (1 << i) != 0 {
            out[n] = i as u8;
            n += 1;
        }
        i += 1;
    }
    (out, n as u8)
}

/// Every non-empty subset, smallest first, so that a subset's cofactors are
/// computed after those of the subsets they recurse on.
const BY_SIZE: [u8; 15] = [1, 2, 4, 8, 3, 5, 6, 9, 10, 12, 7, 11, 13, 14, 15];

/// For each new slot `n` and set `all` holding it: the subsets of `all` that
/// hold `n`, smallest first, so each cofactor's smaller subsets are ready.
const WITH_NEW: [[([u8; 8], u8); 16]; 4] = {
    let mut t = [[([0u8; 8], 0u8); 16]; 4];
    let mut n = 0;
    while n < 4 {
        let mut all = 0;
        while all < 16 {
            let mut k = 0;
            while k < 15 {
                let m = BY_SIZE[k] as usize;
                if m & (1 << n) != 0 && m & !all == 0 {
                    let (list, len) = &mut t[n][all];
                    list[*len as usize] = m as u8;
                    *len += 1;
                }
                k += 1;
            }
            all += 1;
        }
        n += 1;
    }
    t
};

const MEMBERS: [([u8; 4], u8); 16] = {
    let mut t = [([0u8; 4], 0u8); 16];
    let mut m = 0;
    while m < 16 {
        t[m] = members(m);
        m += 1;
    }
    t
};

/// One vertex of the simplex: the point of `K` and where it came from.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Vertex {
    /// `y = a - b` in the pair frame.
    pub y: Vector3<f64>,
    /// Index of the vertex of A (in its piece) and of B.
    pub ia: u32,
    pub ib: u32,
}

/// Outcome of one run of the subalgorithm on the current point set.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Solution {
    /// Subset `V̂` whose relative interior holds the nearest point.
    pub mask: u8,
    /// `v(co Y)`.
    pub v: Vector3<f64>,
    /// Barycentric weights by slot (zero outside `mask`).
    pub lambda: [f64; 4],
}

/// The point set `Y` with its dot products and cofactors.
#[derive(Clone, Debug)]
pub(crate) struct Simplex {
    pub vertices: [Vertex; 4],
    /// Slots in use: `Y`, the kept subset plus the newest point.
    pub all: u8,
    /// `dot[i][j] = y_i·y_j`.
    dot: [[f64; 4]; 4],
    /// `delta[mask][i] = Δ_i(Y_mask)`, valid for every subset of `all`.
    delta: [[f64; 4]; 16],
    /// The newest slot, or `None` right after initialisation (every subset is
    /// then a candidate).
    newest: Option<u8>,
}

impl Simplex {
    /// `Y = V0`, one to four points, all cofactors computed from scratch.
    #[cfg(test)]
    pub fn new(points: &[Vertex]) -> Self {
        let mut s = Simplex::empty();
        s.reset(points);
        s
    }

    /// A simplex with no points, to be [`reset`](Self::reset) before use. One
    /// per query, reused across a compound's piece pairs.
    pub fn empty() -> Self {
        Simplex {
            vertices: [Vertex::default(); 4],
            all: 0,
            dot: [[0.0; 4]; 4],
            delta: [[0.0; 4]; 16],
            newest: None,
        }
    }

    /// `Y = V0`, one to four points, all cofactors computed from scratch.
    pub fn reset(&mut self, points: &[Vertex]) {
        debug_assert!(!points.is_empty() && points.len() <= 4);
        if let [p] = points {
            // The single-point start of Section 6, the common case.
            self.vertices[0] = *p;
            self.dot[0][0] = p.y.norm_squared();
            self.delta[1][0] = 1.0;
            self.all = 1;
            self.newest = Some(0);
            return;
        }
        self.all = 0;
        let mut slot = 0u8;
        for p in points {
            self.insert(slot, *p);
            // A warm start may name points that have become (nearly) affinely
            // dependent at the new pose. Their cofactors would be round-off,
            // so such a point is left out: it costs an iteration, not accuracy.
            if self.independent() {
                slot += 1;
            } else {
                self.all &= !(1 << slot);
            }
        }
        self.newest = None;
    }

    /// `Y = V̂ ∪ {p}`: keep `keep`, put `p` in a free slot, and compute the dot
    /// products and cofactors that involve it.
    pub fn push(&mut self, keep: u8, p: Vertex) {
        debug_assert!(keep.count_ones() <= 3);
        self.all = keep;
        let slot = (!keep).trailing_zeros() as u8;
        self.insert(slot, p);
        self.newest = Some(slot);
    }

    fn insert(&mut self, n: u8, p: Vertex) {
        let n_us = n as usize;
        self.vertices[n_us] = p;
        let old = self.all;
        for i in 0..4 {
            if old & (1 << i) != 0 {
                let d = self.vertices[i].y.dot(&p.y);
                self.dot[i][n_us] = d;
                self.dot[n_us][i] = d;
            }
        }
        self.dot[n_us][n_us] = p.y.norm_squared();
        self.all = old | (1 << n);
        // Subsets of `old` keep their cofactors; those holding n are new.
        let (list, len) = WITH_NEW[n_us & 3][self.all as usize & 15];
        for &mask in list.iter().take(len as usize) {
            self.cofactors(mask as usize);
        }
    }

    /// (5.6): `Δ_j(Y_s ∪ {y_j}) = Σ_{i∈I_s} Δ_i(Y_s)(y_i·y_k - y_i·y_j)`,
    /// `k = min I_s`.
    #[inline]
    fn cofactors(&mut self, mask: usize) {
        // The `& 15` and `& 3` cost nothing and let the compiler drop every
        // bounds check in this, the subalgorithm's innermost loop.
        let mask = mask & 15;
        let (mem, len) = MEMBERS[mask];
        if len == 1 {
            self.delta[mask][mem[0] as usize & 3] = 1.0;
            return;
        }
        for &j in &mem[..len as usize] {
            let j = j as usize & 3;
            let sub = mask & !(1 << j);
            let (smem, slen) = MEMBERS[sub];
            let k = smem[0] as usize & 3;
            let mut acc = 0.0;
            for &i in &smem[..slen as usize] {
                let i = i as usize & 3;
                acc += self.delta[sub][i] * (self.dot[i][k] - self.dot[i][j]);
            }
            self.delta[mask][j] = acc;
        }
    }

    /// Whether `Y` is affinely independent by a clear margin: `Δ(Y)` is the
    /// Gram determinant of the edges from the first point (proof of Theorem
    /// 5.1), so its ratio to the product of the squared edge lengths is a
    /// product of squared sines, 1 for orthogonal edges and 0 for flat sets.
    fn independent(&self) -> bool {
        let all = self.all as usize;
        let (mem, len) = MEMBERS[all];
        if len < 2 {
            return true;
        }
        let k = mem[0] as usize;
        let mut scale = 1.0;
        for &i in &mem[1..len as usize] {
            let i = i as usize;
            scale *= self.dot[i][i] - 2.0 * self.dot[i][k] + self.dot[k][k];
        }
        let total = self.total(all);
        total > 1e-10 * scale && scale > 0.0
    }

    /// `Δ(Y_s)` of (5.4).
    #[inline]
    fn total(&self, mask: usize) -> f64 {
        let (mem, len) = MEMBERS[mask];
        mem[..len as usize]
            .iter()
            .map(|&i| self.delta[mask][i as usize])
            .sum()
    }

    /// Conditions (1) and (2) of Theorem 5.2.
    #[inline]
    fn interior(&self, mask: usize) -> bool {
        let (mem, len) = MEMBERS[mask];
        mem[..len as usize]
            .iter()
            .all(|&i| self.delta[mask][i as usize] > 0.0)
    }

    /// All three conditions of Theorem 5.2 for `mask` within `Y`.
    #[inline]
    fn passes(&self, mask: usize) -> bool {
        if !self.interior(mask) {
            return false;
        }
        if mask == 0b1111 {
            return self.holds_origin();
        }
        let rest = self.all as usize & !mask;
        let (rmem, rlen) = MEMBERS[rest];
        rmem[..rlen as usize].iter().all(|&j| {
            let j = j as usize;
            self.delta[mask | (1 << j)][j] <= 0.0
        })
    }

    /// Whether the origin is certainly inside the tetrahedron `Y`. Round-off
    /// can make every cofactor of a flat tetrahedron positive, so the full set
    /// passing Theorem 5.2 is confirmed here by the signs of the four signed
    /// volumes with the origin in place of one vertex, each compared with a
    /// forward bound on its own rounding error. A tetrahedron that fails is
    /// left to its faces, which then give a `v` within round-off of the origin.
    fn holds_origin(&self) -> bool {
        let [a, b, c, d] = [0, 1, 2, 3].map(|i| self.vertices[i].y);
        // (p, q, r) -> p·(q×r) with its error bound.
        let triple = |p: Vector3<f64>, q: Vector3<f64>, r: Vector3<f64>| {
            let cr = q.cross(&r);
            (
                p.dot(&cr),
                16.0 * f64::EPSILON * p.norm() * q.norm() * r.norm(),
            )
        };
        let (ba, ca, da) = (b - a, c - a, d - a);
        let vols = [
            triple(b, c, d),
            triple(-a, ca, da),
            triple(ba, -a, da),
            triple(ba, ca, -a),
        ];
        let (total, _) = triple(ba, ca, da);
        vols.iter()
            .all(|&(v, err)| v.abs() > err && (v > 0.0) == (total > 0.0))
    }

    fn solution(&self, mask: usize) -> Solution {
        let total = self.total(mask);
        let (mem, len) = MEMBERS[mask];
        let mut v = Vector3::zeros();
        let mut lambda = [0.0; 4];
        let inv = 1.0 / total;
        if mask == 0b1111 {
            // Certified by `holds_origin`: the origin is inside the tetrahedron.
            for (i, l) in lambda.iter_mut().enumerate() {
                *l = self.delta[mask][i] * inv;
            }
            return Solution {
                mask: mask as u8,
                v,
                lambda,
            };
        }
        for &i in &mem[..len as usize] {
            let i = i as usize;
            let l = self.delta[mask][i] * inv;
            lambda[i] = l;
            v += self.vertices[i].y * l;
        }
        Solution {
            mask: mask as u8,
            v,
            lambda,
        }
    }

    /// The Distance Subalgorithm: the first subset, in the order of Section 6,
    /// that passes Theorem 5.2, or `None` when round-off left none passing.
    pub fn solve(&self) -> Option<Solution> {
        let all = self.all as usize;
        match self.newest {
            Some(n) => {
                let nbit = 1usize << n;
                // First the face that drops the old vertex most aligned with the
                // newest point: it holds the answer about 80% of the time.
                let old = all & !nbit;
                if old == 0 {
                    return Some(self.solution(nbit));
                }
                let first;
                {
                    let (mem, len) = MEMBERS[old];
                    let mut drop = mem[0] as usize;
                    for &i in &mem[1..len as usize] {
                        let i = i as usize;
                        if self.dot[i][n as usize] > self.dot[drop][n as usize] {
                            drop = i;
                        }
                    }
                    first = all & !(1 << drop);
                    if self.passes(first) {
                        return Some(self.solution(first));
                    }
                }
                // Then every other subset holding the newest point, smallest
                // first; subsets without it were rejected last iteration and
                // come last, for round-off's sake only.
                for &mask in &BY_SIZE {
                    let mask = mask as usize;
                    if mask != first && mask & !all == 0 && mask & nbit != 0 && self.passes(mask) {
                        return Some(self.solution(mask));
                    }
                }
                (1..16usize)
                    .filter(|m| m & !all == 0 && m & nbit == 0)
                    .find(|&m| self.passes(m))
                    .map(|m| self.solution(m))
            }
            None => {
                // A fresh V0 (warm start): the whole set is the likeliest answer.
                BY_SIZE
                    .iter()
                    .rev()
                    .map(|&m| m as usize)
                    .filter(|&m| m & !all == 0)
                    .find(|&m| self.passes(m))
                    .map(|m| self.solution(m))
            }
        }
    }

    /// The Backup Procedure (6.5): among the subsets with `Δ > 0` and every
    /// `Δ_i > 0`, the one whose affine hull is nearest the origin, by (5.10).
    /// Always succeeds: a single point qualifies.
    pub fn backup(&self) -> Solution {
        let all = self.all as usize;
        let mut best = None;
        let mut best_d2 = f64::INFINITY;
        for mask in 1..16usize {
            if mask & !all != 0 || !self.interior(mask) {
                continue;
            }
            if mask == 0b1111 && !self.holds_origin() {
                continue;
            }
            let total = self.total(mask);
            if total <= 0.0 {
                continue;
            }
            let d2 = self.aff_dist2(mask, total);
            if d2 < best_d2 {
                best_d2 = d2;
                best = Some(mask);
            }
        }
        // A singleton always qualifies (Δ = 1); the fallback only guards
        // against a NaN having crept into a dot product.
        self.solution(best.unwrap_or(all & all.wrapping_neg()))
    }

    /// (5.10): `|v(aff Y_s)|² = (1/Δ) Σ_i Δ_i (y_i·y_k)`, `k = min I_s`.
    #[inline]
    fn aff_dist2(&self, mask: usize, total: f64) -> f64 {
        let (mem, len) = MEMBERS[mask];
        let k = mem[0] as usize;
        let s: f64 = mem[..len as usize]
            .iter()
            .map(|&i| self.delta[mask][i as usize] * self.dot[i as usize][k])
            .sum();
        (s / total).max(0.0)
    }

    /// (5.9): for a tetrahedron holding the origin, the distance from the
    /// origin to the nearest face plane, a lower bound on penetration depth.
    /// Computed from each face's normal rather than through (5.10): that
    /// formula gives the squared distance, whose square root carries an error
    /// of `√ε` relative, too much for a bound that must stay below the truth.
    pub fn inner_radius(&self) -> f64 {
        debug_assert_eq!(self.all, 0b1111);
        let mut best = f64::INFINITY;
        for face in [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]] {
            let [p, q, r] = face.map(|i| self.vertices[i].y);
            let n = (q - p).cross(&(r - p));
            let len = n.norm();
            if len.is_nan() || len == 0.0 {
                // A flat face: the tetrahedron is degenerate and proves nothing.
                return 0.0;
            }
            best = best.min(n.dot(&p).abs() / len);
        }
        if best.is_finite() { best } else { 0.0 }
    }

    /// Whether the vertex pair `(ia, ib)` is already in the subset `mask`.
    pub fn has_pair(&self, mask: u8, ia: u32, ib: u32) -> bool {
        (0..4)
            .any(|i| mask & (1 << i) != 0 && self.vertices[i].ia == ia && self.vertices[i].ib == ib)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vtx(x: f64, y: f64, z: f64) -> Vertex {
        Vertex {
            y: Vector3::new(x, y, z),
            ia: 0,
            ib: 0,
        }
    }

    #[test]
    fn cofactors_match_gram_determinant() {
        // Δ(Y_s) is the Gram determinant of the edge vectors (Theorem 5.1 proof).
        let pts = [
            vtx(1.0, 0.2, 0.3),
            vtx(-0.5, 1.0, 0.1),
            vtx(0.3, -0.7, 1.2),
            vtx(0.9, 0.4, -1.1),
        ];
        let s = Simplex::new(&pts);
        let e1 = pts[1].y - pts[0].y;
        let e2 = pts[2].y - pts[0].y;
        let e3 = pts[3].y - pts[0].y;
        let vol = e1.dot(&e2.cross(&e3));
        assert!((s.total(0b1111) - vol * vol).abs() < 1e-12 * vol * vol);
        let a = e1.cross(&e2).norm_squared();
        assert!((s.total(0b0111) - a).abs() < 1e-12 * a);
    }

    #[test]
    fn segment_nearest_point_is_projection() {
        let s = Simplex::new(&[vtx(-1.0, 1.0, 0.0), vtx(3.0, 1.0, 0.0)]);
        let sol = s.solve().unwrap();
        assert_eq!(sol.mask, 0b11);
        assert!((sol.v - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-15);
        assert!((sol.lambda[0] - 0.75).abs() < 1e-15);
    }

    #[test]
    fn tetrahedron_with_origin_inside_and_its_inner_radius() {
        let mut s = Simplex::empty();
        s.reset(&[
            vtx(1.0, 1.0, 1.0),
            vtx(1.0, -1.0, -1.0),
            vtx(-1.0, 1.0, -1.0),
            vtx(-1.0, -1.0, 1.0),
        ]);
        let sol = s.solve().unwrap();
        assert_eq!(sol.mask, 0b1111);
        assert!(sol.v.norm() < 1e-15);
        // Regular tetrahedron with circumradius √3: inradius √3/3.
        assert!((s.inner_radius() - 3f64.sqrt() / 3.0).abs() < 1e-14);
    }

    #[test]
    fn backup_picks_nearest_affine_hull() {
        let s = Simplex::new(&[vtx(1.0, 1.0, 0.0), vtx(1.0, -1.0, 0.0), vtx(2.0, 0.0, 0.0)]);
        let sol = s.backup();
        assert!((sol.v - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-15);
    }
}
