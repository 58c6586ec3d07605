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

/// A triangle is thin when `Δ(Y_s)` is below this times its longest squared
/// edge squared (its smallest angle below about 1e-3 rad): (5.6) then loses
/// more than 1e-10 of its cofactors to round-off.
const THIN: f64 = 1e-6;

/// The slot a triangle's mask leaves out. A triangle's cofactors use three
/// of its row's four entries; the fourth marks it thin (1) or not (0).
#[inline(always)]
const fn missing(mask: usize) -> usize {
    (!mask & 15).trailing_zeros() as usize & 3
}

/// `a × b`, each component `p·q - r·s` with one rounding (Kahan's fused
/// difference of products): exact to a unit in the last place of the
/// component, however much the two products cancel.
#[inline(always)]
fn fused_cross(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector3<f64> {
    let dop = |p: f64, q: f64, r: f64, t: f64| {
        let w = r * t;
        let err = (-r).mul_add(t, w);
        p.mul_add(q, -w) + err
    };
    Vector3::new(
        dop(a.y, b.z, a.z, b.y),
        dop(a.z, b.x, a.x, b.z),
        dop(a.x, b.y, a.y, b.x),
    )
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

/// Runs `$body` with `$m` bound to `$mask` as a constant, one arm per
/// non-empty subset: inside an arm every table lookup on `$m` is a constant,
/// so the loops over its members unroll into straight-line code.
macro_rules! by_mask {
    ($mask:expr, $m:ident => $body:expr) => {
        match $mask & 15 {
            1 => {
                const $m: usize = 1;
                $body
            }
            2 => {
                const $m: usize = 2;
                $body
            }
            3 => {
                const $m: usize = 3;
                $body
            }
            4 => {
                const $m: usize = 4;
                $body
            }
            5 => {
                const $m: usize = 5;
                $body
            }
            6 => {
                const $m: usize = 6;
                $body
            }
            7 => {
                const $m: usize = 7;
                $body
            }
            8 => {
                const $m: usize = 8;
                $body
            }
            9 => {
                const $m: usize = 9;
                $body
            }
            10 => {
                const $m: usize = 10;
                $body
            }
            11 => {
                const $m: usize = 11;
                $body
            }
            12 => {
                const $m: usize = 12;
                $body
            }
            13 => {
                const $m: usize = 13;
                $body
            }
            14 => {
                const $m: usize = 14;
                $body
            }
            _ => {
                const $m: usize = 15;
                $body
            }
        }
    };
}

/// Runs `$body` with `$n` and `$all` bound as constants to the newest slot
/// and the set holding it: the 32 shapes a simplex can have after a push.
/// `$other` handles anything else (only reachable through a logic error).
macro_rules! by_shape {
    ($slot:expr, $set:expr, $n:ident, $all:ident => $body:expr, $other:expr) => {
        by_shape!(@arms ($slot, $set), $n, $all, $body, $other;
            0: 1 3 5 7 9 11 13 15;
            1: 2 3 6 7 10 11 14 15;
            2: 4 5 6 7 12 13 14 15;
            3: 8 9 10 11 12 13 14 15)
    };
    (@arms $key:expr, $n:ident, $all:ident, $body:expr, $other:expr;
        $($nv:literal: $($av:literal)*);*) => {
        match $key {
            $($(($nv, $av) => {
                const $n: usize = $nv;
                const $all: usize = $av;
                $body
            })*)*
            _ => $other,
        }
    };
}

/// For each newest slot `n` and set `all` holding it, the candidates of the
/// subalgorithm after the "first face" of Section 6: the subsets holding `n`,
/// smallest first (but a full tetrahedron first of all), then the rest
/// (rejected last iteration; tried again for round-off's sake only).
const ORDER: [[([u8; 15], u8); 16]; 4] = {
    let mut t = [[([0u8; 15], 0u8); 16]; 4];
    let mut n = 0;
    while n < 4 {
        let mut all = 0;
        while all < 16 {
            let (list, len) = &mut t[n][all];
            // A full tetrahedron is tried right after the first face: when the
            // origin is inside (the objects intersect) it is the answer, and
            // when not, its first negative cofactor rejects it at once.
            if all == 15 {
                list[0] = 15;
                *len = 1;
            }
            let (with, with_len) = WITH_NEW[n][all];
            let mut k = 0;
            while k < with_len as usize {
                if !(all == 15 && with[k] == 15) {
                    list[*len as usize] = with[k];
                    *len += 1;
                }
                k += 1;
            }
            let mut m = 1;
            while m < 16 {
                if m & (1 << n) == 0 && m & !all == 0 {
                    list[*len as usize] = m as u8;
                    *len += 1;
                }
                m += 1;
            }
            all += 1;
        }
        n += 1;
    }
    t
};

/// For each set `all`, its non-empty subsets, largest first: the candidates
/// for a fresh `V0`, where the whole set is the likeliest answer.
const DOWN: [([u8; 15], u8); 16] = {
    let mut t = [([0u8; 15], 0u8); 16];
    let mut all = 0;
    while all < 16 {
        let (list, len) = &mut t[all];
        let mut k = 15;
        while k > 0 {
            k -= 1;
            let m = BY_SIZE[k] as usize;
            if m & !all == 0 {
                list[*len as usize] = m as u8;
                *len += 1;
            }
        }
        all += 1;
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
    pub const fn empty() -> Self {
        const ORIGIN: Vertex = Vertex {
            y: Vector3::new(0.0, 0.0, 0.0),
            ia: 0,
            ib: 0,
        };
        Simplex {
            vertices: [ORIGIN; 4],
            all: 0,
            dot: [[0.0; 4]; 4],
            delta: [[0.0; 4]; 16],
            newest: None,
        }
    }

    /// `Y = {p}`: the single-point start of Section 6, the common case,
    /// inlined where it is asked for.
    #[inline(always)]
    pub fn start(&mut self, p: Vertex) {
        self.vertices[0] = p;
        self.dot[0][0] = p.y.norm_squared();
        self.delta[1][0] = 1.0;
        self.all = 1;
        self.newest = Some(0);
    }

    /// `Y = V0`, one to four points, all cofactors computed from scratch.
    pub fn reset(&mut self, points: &[Vertex]) {
        self.reset_inline(points);
    }

    /// [`reset`](Self::reset) compiled for AVX2 and FMA: the same cofactors
    /// bit for bit (see `query::distance_avx2`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub fn reset_avx2(&mut self, points: &[Vertex]) {
        self.reset_inline(points);
    }

    /// The body of [`reset`](Self::reset), inlined into each compiled form.
    #[inline(always)]
    fn reset_inline(&mut self, points: &[Vertex]) {
        debug_assert!(!points.is_empty() && points.len() <= 4);
        if let [p] = points {
            self.start(*p);
            return;
        }
        if (2..=4).contains(&points.len()) {
            // All points at once: the usual warm start, whose points are still
            // independent. If the whole set passes the test below, so does
            // every prefix (Fischer's inequality bounds a Gram determinant by
            // its leading minor times the last squared edge), and the
            // incremental pass below would have kept every point.
            let independent = match points.len() {
                2 => self.load_cofactors::<2, 0b11>(points),
                3 => self.load_cofactors::<3, 0b111>(points),
                _ => self.load_cofactors::<4, 0b1111>(points),
            };
            if independent {
                self.newest = None;
                return;
            }
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

    /// `Y` = the `K` points, `ALL` their slots: every dot product and
    /// cofactor, unrolled for the size (a warm start's usual path), and
    /// whether the set is independent.
    #[inline(always)]
    fn load_cofactors<const K: usize, const ALL: usize>(&mut self, points: &[Vertex]) -> bool {
        self.vertices[..K].copy_from_slice(&points[..K]);
        for i in 0..K {
            for j in 0..=i {
                let d = self.vertices[i].y.dot(&self.vertices[j].y);
                self.dot[i][j] = d;
                self.dot[j][i] = d;
            }
        }
        self.all = ALL as u8;
        self.fill_cofactors::<ALL>();
        self.independent_in(ALL)
    }

    /// The cofactors of every subset of `ALL`, smallest first, unrolled.
    #[inline(always)]
    fn fill_cofactors<const ALL: usize>(&mut self) {
        macro_rules! step {
            ($($k:literal)*) => {$(
                if const { BY_SIZE[$k] as usize & !ALL == 0 } {
                    by_mask!(const { BY_SIZE[$k] } as usize, M => self.cofactors_of::<M>());
                }
            )*};
        }
        step!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14);
    }

    /// `Y = V̂ ∪ {p}`: keep `keep`, put `p` in a free slot, and compute the dot
    /// products and cofactors that involve it.
    #[inline(always)]
    pub fn push(&mut self, keep: u8, p: Vertex) {
        let slot = self.slot_after_keeping(keep);
        self.insert(slot, p);
        self.newest = Some(slot);
    }

    /// `Y = V̂` ahead of a push: the slot the new point goes to.
    #[inline(always)]
    fn slot_after_keeping(&mut self, keep: u8) -> u8 {
        debug_assert!(keep.count_ones() <= 3);
        self.all = keep;
        (!keep).trailing_zeros() as u8
    }

    /// [`push`](Self::push) with the update compiled for AVX2 and FMA: the
    /// same cofactors bit for bit (see `query::distance_avx2`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub fn push_avx2(&mut self, keep: u8, p: Vertex) {
        let slot = self.slot_after_keeping(keep);
        self.insert_avx2(slot, p);
        self.newest = Some(slot);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline(never)]
    fn insert_avx2(&mut self, n: u8, p: Vertex) {
        self.insert_inline(n, p);
    }

    #[inline(never)]
    fn insert(&mut self, n: u8, p: Vertex) {
        self.insert_inline(n, p);
    }

    /// The body of [`insert`](Self::insert), inlined into each compiled form.
    #[inline(always)]
    fn insert_inline(&mut self, n: u8, p: Vertex) {
        let n_us = n as usize & 3;
        self.vertices[n_us] = p;
        // All four products, used slots or not: branch-free, and a stale slot's
        // product is never read, since every read goes through a subset of
        // `all`.
        for i in 0..4 {
            let d = self.vertices[i].y.dot(&p.y);
            self.dot[i][n_us] = d;
            self.dot[n_us][i] = d;
        }
        self.all |= 1 << n;
        // Subsets of the old set keep their cofactors; those holding n are new.
        // One monomorphised update per (slot, set): the subset lists and the
        // members of each subset are then constants, and the recursion (5.6)
        // compiles to straight-line arithmetic.
        macro_rules! dispatch {
            ($($n:literal => [$($all:literal),*]),*) => {
                match (n_us, self.all as usize) {
                    $($(($n, $all) => self.update_cofactors::<$n, $all>(),)*)*
                    _ => {
                        let (list, len) = WITH_NEW[n_us][self.all as usize & 15];
                        for &mask in list.iter().take(len as usize) {
                            self.cofactors(mask as usize);
                        }
                    }
                }
            };
        }
        dispatch!(
            0 => [1, 3, 5, 7, 9, 11, 13, 15],
            1 => [2, 3, 6, 7, 10, 11, 14, 15],
            2 => [4, 5, 6, 7, 12, 13, 14, 15],
            3 => [8, 9, 10, 11, 12, 13, 14, 15]
        );
    }

    /// The cofactors of every subset of `ALL` that holds slot `N`, smallest
    /// first, unrolled: each step's subset is a constant.
    #[inline(always)]
    fn update_cofactors<const N: usize, const ALL: usize>(&mut self) {
        macro_rules! step {
            ($($k:literal)*) => {$(
                if const { WITH_NEW[N][ALL].1 > $k } {
                    by_mask!(const { WITH_NEW[N][ALL].0[$k] } as usize, M => self.cofactors_of::<M>());
                }
            )*};
        }
        step!(0 1 2 3 4 5 6 7);
    }

    /// [`cofactors`](Self::cofactors) for a subset known at compile time.
    #[inline(always)]
    fn cofactors_of<const MASK: usize>(&mut self) {
        let (mem, len) = const { MEMBERS[MASK] };
        if len == 1 {
            self.delta[MASK][mem[0] as usize & 3] = 1.0;
            return;
        }
        for &j in &mem[..len as usize] {
            let j = j as usize & 3;
            let sub = MASK & !(1 << j);
            let (smem, slen) = MEMBERS[sub];
            let k = smem[0] as usize & 3;
            let mut acc = 0.0;
            for &i in &smem[..slen as usize] {
                let i = i as usize & 3;
                acc += self.delta[sub][i] * (self.dot[i][k] - self.dot[i][j]);
            }
            self.delta[MASK][j] = acc;
        }
        if len == 3 {
            self.check_thin(MASK);
        }
        if len == 4 {
            self.check_sliver();
        }
    }

    /// After (5.6) for a triangle: if it is thin, its cofactors again, by
    /// [`thin_triangle`](Self::thin_triangle). `Δ(Y_s)` is `|e1 × e2|²`, so
    /// its ratio to the largest squared edge squared is at most the squared
    /// sine of the triangle's smallest angle, times a constant.
    #[inline(always)]
    fn check_thin(&mut self, mask: usize) {
        let mask = mask & 15;
        let (mem, _) = MEMBERS[mask];
        let [i, j, k] = [mem[0], mem[1], mem[2]].map(|x| x as usize & 3);
        // A pair's cofactors sum to its squared edge length.
        let edge = |a: usize, b: usize| {
            let m = (1 << a) | (1 << b);
            self.delta[m][a] + self.delta[m][b]
        };
        let longest = edge(i, j).max(edge(i, k)).max(edge(j, k));
        let total = self.delta[mask][i] + self.delta[mask][j] + self.delta[mask][k];
        // NaN counts as thin.
        match total.partial_cmp(&(THIN * longest * longest)) {
            Some(std::cmp::Ordering::Greater) => self.delta[mask][missing(mask)] = 0.0,
            _ => self.thin_triangle(mask),
        }
    }

    /// After (5.6) for the tetrahedron: if it is a sliver, its cofactors
    /// again, from signed volumes. Near nearly parallel edges of A and B the
    /// four points of `Y` can lie within 1e-9 of a plane; the recursion then
    /// leaves `Δ_l(Y)`, whose signs decide which face holds the nearest point
    /// (condition (3) of Theorem 5.2), as round-off, and the run settles on a
    /// face whose plane passes 1e-9 of the size from the origin while the
    /// true distance is 0.
    #[inline(always)]
    fn check_sliver(&mut self) {
        let edge = |b: usize| {
            let m = 1 | (1 << b);
            self.delta[m][0] + self.delta[m][b]
        };
        // Hadamard: V² is at most the product of the squared edges from y0,
        // with equality for orthogonal edges.
        let bound = edge(1) * edge(2) * edge(3);
        let total = self.total(15);
        // NaN counts as a sliver.
        if total.partial_cmp(&(THIN * bound)) != Some(std::cmp::Ordering::Greater) {
            self.sliver();
        }
    }

    /// A sliver tetrahedron's cofactors, `Δ_l(Y) = V_l·V`: `Δ(Y)` is `V²`, `V`
    /// the signed volume `det(y1 - y0, y2 - y0, y3 - y0)`, and `Δ_l/Δ` is the
    /// origin's barycentric weight `V_l/V`, `V_l` the volume with the origin
    /// in place of `y_l`. Each volume is a triple product through fused cross
    /// products, whose error is relative to the volume, not to `|y|³`. Out of
    /// line: slivers are rare.
    #[cold]
    #[inline(never)]
    fn sliver(&mut self) {
        #[cfg(target_arch = "x86_64")]
        if crate::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            unsafe { self.sliver_fma() };
            return;
        }
        self.sliver_inline();
    }

    /// [`sliver`](Self::sliver) with its fused products as FMA
    /// instructions, not calls to the software `fma`: the same values bit
    /// for bit (`mul_add` rounds once either way).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn sliver_fma(&mut self) {
        self.sliver_inline();
    }

    /// The body of [`sliver`](Self::sliver), inlined into each compiled form.
    #[inline(always)]
    fn sliver_inline(&mut self) {
        let y = self.vertices.map(|v| v.y);
        let volume = |p: Vector3<f64>, q: Vector3<f64>, r: Vector3<f64>, s: Vector3<f64>| {
            (q - p).dot(&fused_cross(&(r - p), &(s - p)))
        };
        let z = Vector3::zeros();
        let v = volume(y[0], y[1], y[2], y[3]);
        self.delta[15] = [
            volume(z, y[1], y[2], y[3]) * v,
            volume(y[0], z, y[2], y[3]) * v,
            volume(y[0], y[1], z, y[3]) * v,
            volume(y[0], y[1], y[2], z) * v,
        ];
    }

    /// The cofactors of a thin triangle (nearly parallel edges of A and B
    /// make one: two long edges of K a small angle θ apart), from cross
    /// products instead of (5.6). The recursion takes them from differences
    /// of dot products of size `|y|²` whose result is of size `θ²|y|⁴`:
    /// relative error `ε/θ²`, all of it at `θ = 1e-8`. Here `Δ_i = n·(y_j ×
    /// y_k)` with `n = (y_j - y_i) × (y_k - y_i)`, each component of each cross
    /// product a difference of products fused to one rounding: relative error
    /// `ε/θ`. Out of line: thin triangles are rare.
    #[cold]
    #[inline(never)]
    fn thin_triangle(&mut self, mask: usize) {
        #[cfg(target_arch = "x86_64")]
        if crate::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            unsafe { self.thin_triangle_fma(mask) };
            return;
        }
        self.thin_triangle_inline(mask);
    }

    /// [`thin_triangle`](Self::thin_triangle) with its fused products as
    /// FMA instructions (see [`sliver_fma`](Self::sliver_fma)).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn thin_triangle_fma(&mut self, mask: usize) {
        self.thin_triangle_inline(mask);
    }

    /// The body of [`thin_triangle`](Self::thin_triangle), inlined into
    /// each compiled form.
    #[inline(always)]
    fn thin_triangle_inline(&mut self, mask: usize) {
        let mask = mask & 15;
        let (mem, _) = MEMBERS[mask];
        let [i, j, k] = [mem[0], mem[1], mem[2]].map(|x| x as usize & 3);
        let [yi, yj, yk] = [i, j, k].map(|x| self.vertices[x].y);
        let n = fused_cross(&(yj - yi), &(yk - yi));
        self.delta[mask][i] = n.dot(&fused_cross(&yj, &yk));
        self.delta[mask][j] = n.dot(&fused_cross(&yk, &yi));
        self.delta[mask][k] = n.dot(&fused_cross(&yi, &yj));
        self.delta[mask][missing(mask)] = 1.0;
    }

    /// Whether the triangle `mask` is thin (see [`check_thin`](Self::check_thin)).
    #[inline(always)]
    fn is_thin(&self, mask: usize) -> bool {
        self.delta[mask & 15][missing(mask)] != 0.0
    }

    /// `v(aff Y_s)` of a thin triangle, `None` when it has no plane: the
    /// origin's projection on its plane, `n (n·y_i) / |n|²`. `Σ λ_i y_i`
    /// would carry the weights' error `ε/θ`
    /// times the triangle's length, along its length, which is more than the
    /// whole distance near contact. The plane's normal, from two long edges
    /// by fused products, is tilted by round-off only about the triangle's
    /// long axis, where the triangle is narrow, so `|v|` is right to
    /// `ε·|y|` and `v`'s direction separates K from the origin to within
    /// that: the lower bound of Theorem 4.1 stays tight.
    #[cold]
    #[inline(never)]
    fn thin_simplex_v(&self, mask: usize) -> Option<Vector3<f64>> {
        #[cfg(target_arch = "x86_64")]
        if crate::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA.
            return unsafe { self.thin_simplex_v_fma(mask) };
        }
        self.thin_simplex_v_inline(mask)
    }

    /// [`thin_simplex_v`](Self::thin_simplex_v) with its fused products as
    /// FMA instructions (see [`sliver_fma`](Self::sliver_fma)).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn thin_simplex_v_fma(&self, mask: usize) -> Option<Vector3<f64>> {
        self.thin_simplex_v_inline(mask)
    }

    /// The body of [`thin_simplex_v`](Self::thin_simplex_v), inlined into
    /// each compiled form.
    #[inline(always)]
    fn thin_simplex_v_inline(&self, mask: usize) -> Option<Vector3<f64>> {
        let (mem, _) = MEMBERS[mask & 15];
        let [i, j, k] = [mem[0], mem[1], mem[2]].map(|x| x as usize & 3);
        let [yi, yj, yk] = [i, j, k].map(|x| self.vertices[x].y);
        let n = fused_cross(&(yj - yi), &(yk - yi));
        let nn = n.norm_squared();
        // A triangle flat to the last bit has no plane: the weights decide.
        (nn > 0.0).then(|| n * (n.dot(&yi) / nn))
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
        if len == 3 {
            self.check_thin(mask);
        }
        if len == 4 {
            self.check_sliver();
        }
    }

    /// Whether `Y` is affinely independent by a clear margin: `Δ(Y)` is the
    /// Gram determinant of the edges from the first point (proof of Theorem
    /// 5.1), so its ratio to the product of the squared edge lengths is a
    /// product of squared sines, 1 for orthogonal edges and 0 for flat sets.
    #[inline(always)]
    fn independent(&self) -> bool {
        by_mask!(self.all as usize, ALL => self.independent_in(ALL))
    }

    #[inline(always)]
    fn independent_in(&self, all: usize) -> bool {
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
    #[inline(always)]
    fn total(&self, mask: usize) -> f64 {
        let (mem, len) = MEMBERS[mask];
        let mut sum = 0.0;
        for &i in &mem[..len as usize] {
            sum += self.delta[mask][i as usize & 3];
        }
        sum
    }

    /// Conditions (1) and (2) of Theorem 5.2.
    #[inline(always)]
    fn interior(&self, mask: usize) -> bool {
        let (mem, len) = MEMBERS[mask];
        // A loop, not `Iterator::all`, which the compiler may leave as a call
        // and so lose the constant `mask` of a specialised caller.
        for &i in &mem[..len as usize] {
            let d = self.delta[mask][i as usize & 3];
            if d <= 0.0 || d.is_nan() {
                return false;
            }
        }
        true
    }

    /// All three conditions of Theorem 5.2 for `mask` within `Y = all`.
    #[inline(always)]
    fn passes_in(&self, mask: usize, all: usize) -> bool {
        if !self.interior(mask) {
            return false;
        }
        if mask == 0b1111 {
            return self.holds_origin();
        }
        let rest = all & !mask;
        let (rmem, rlen) = MEMBERS[rest];
        for &j in &rmem[..rlen as usize] {
            let j = j as usize & 3;
            let d = self.delta[(mask | (1 << j)) & 15][j];
            if d > 0.0 || d.is_nan() {
                return false;
            }
        }
        true
    }

    /// Whether the origin is certainly inside the tetrahedron `Y`. Round-off
    /// can make every cofactor of a flat tetrahedron positive, so the full set
    /// passing Theorem 5.2 is confirmed here by the signs of the four signed
    /// volumes with the origin in place of one vertex, each compared with a
    /// forward bound on its own rounding error. A tetrahedron that fails is
    /// left to its faces, which then give a `v` within round-off of the origin.
    fn holds_origin(&self) -> bool {
        let [a, b, c, d] = [0, 1, 2, 3].map(|i| self.vertices[i].y);
        let (ba, ca, da) = (b - a, c - a, d - a);
        // Each volume p·(q×r) against its error bound 16ε|p||q||r|, both
        // squared, so no square root is taken: v² > (16ε)²|p|²|q|²|r|². One
        // bound serves all four: with M the largest |y_i| (from the kept
        // y_i·y_i), every factor is a point (at most M) or an edge from `a`
        // (at most 2M), so |p||q||r| <= 4M³, and 16ε of room covers the
        // rounding of the edges, of M² and of its powers. A looser bound only
        // sends more volumes to the exact test, which gives the same signs;
        // it saves the seven norms. A bound that underflows needs every
        // vertex within about 1e-50 of the origin in the run's frame (whose
        // sizes are near 1), where calling the distance 0 is within the
        // round-off allowance anyway.
        let m2 = self.largest_y2();
        let e2 = (16.0 * f64::EPSILON) * (16.0 * f64::EPSILON) * (1.0 + 16.0 * f64::EPSILON);
        let bound = e2 * (16.0 * (m2 * m2) * m2);
        let vols = [
            b.dot(&c.cross(&d)),
            (-a).dot(&ca.cross(&da)),
            ba.dot(&(-a).cross(&da)),
            ba.dot(&ca.cross(&(-a))),
        ];
        let total = ba.dot(&ca.cross(&da));
        if vols.iter().all(|&v| v * v > bound) {
            return vols.iter().all(|&v| (v > 0.0) == (total > 0.0));
        }
        // Each volume's test again, for the rare exact path: carrying the
        // four flags through the common path costs every intersecting query
        // more than the rare recomputation does.
        self.holds_origin_exactly(&vols.map(|v| (v, v * v > bound)))
    }

    /// `M²`, the largest `|y_i|²` of a full simplex, from the kept dot
    /// products: the scale of the error bounds of its volumes and faces.
    #[inline(always)]
    fn largest_y2(&self) -> f64 {
        (self.dot[0][0].max(self.dot[1][1])).max(self.dot[2][2].max(self.dot[3][3]))
    }

    /// The four points for the exact orientation predicate, or `None` when a
    /// coordinate is outside 2^±300, where its products could underflow or
    /// overflow.
    fn predicate_points(&self) -> Option<[Vector3<f64>; 4]> {
        let y = self.vertices.map(|v| v.y);
        let safe = |x: f64| x == 0.0 || (x.abs() >= 4.9e-91 && x.abs() <= 2.0e90);
        y.iter().all(|p| p.iter().all(|&x| safe(x))).then_some(y)
    }

    /// [`holds_origin`](Self::holds_origin) when round-off leaves the sign
    /// of some of the volumes in doubt (`vols` holds each volume and whether
    /// its sign is certain): those signs
    /// computed exactly (Shewchuk's adaptive orientation predicate), the
    /// origin strictly inside when all four agree. A certain volume's sign
    /// is already its exact sign, so two certain volumes of opposite signs
    /// settle it without exact arithmetic; near a touching contact this is
    /// the usual case (the origin near one face, the other three volumes
    /// clear), and only the volumes in doubt are recomputed.
    ///
    /// This is what a tetrahedron needs whose points lie within 1e-8
    /// of a plane through the origin (a flat shape touching a needle-thin
    /// one): the weights of two of its vertices are then below the error
    /// bound of the floating-point volumes, and the run would otherwise end
    /// on a face 1e-9 of the size from the origin while the origin is inside
    /// (found by a hunt over sets of 64 to 511 vertices; the case is
    /// `needle_touching_a_flat_polygon`). Coordinates outside 2^±300 leave
    /// the predicate's products in danger of underflow or overflow: `false`
    /// then, as before, and the faces decide. Out of line: it is rare.
    #[cold]
    #[inline(never)]
    fn holds_origin_exactly(&self, vols: &[(f64, bool); 4]) -> bool {
        let (mut pos, mut neg) = (false, false);
        for &(v, c) in vols {
            if c {
                pos |= v > 0.0;
                neg |= v < 0.0;
            }
        }
        if pos && neg {
            return false;
        }
        let Some(y) = self.predicate_points() else {
            return false;
        };
        for (l, _) in vols.iter().enumerate().filter(|(_, (_, c))| !*c) {
            let s = exact_volume_without(&y, l);
            pos |= s > 0.0;
            neg |= s < 0.0;
            if s == 0.0 || (pos && neg) {
                return false;
            }
        }
        true
    }

    #[inline(always)]
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
        if len == 3
            && self.is_thin(mask)
            && let Some(p) = self.thin_simplex_v(mask)
        {
            v = p;
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
        self.solve_inline()
    }

    /// [`solve`](Self::solve) compiled for AVX2 and FMA: the same answer bit
    /// for bit (see `query::distance_avx2`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    pub fn solve_avx2(&self) -> Option<Solution> {
        self.solve_inline()
    }

    /// The body of [`solve`](Self::solve), inlined into each compiled form.
    #[inline(always)]
    fn solve_inline(&self) -> Option<Solution> {
        let all = self.all as usize;
        match self.newest {
            Some(n) => by_shape!(n as usize, all, N, ALL => self.solve_after_push::<N, ALL>(), {
                self.solve_warm()
            }),
            None => self.solve_warm(),
        }
    }

    /// [`solve`](Self::solve) after a push of slot `N` into the set `ALL`.
    #[inline(always)]
    fn solve_after_push<const N: usize, const ALL: usize>(&self) -> Option<Solution> {
        let old = ALL & !(1 << N);
        if old == 0 {
            return Some(self.solution(ALL));
        }
        // First the face that drops the old vertex most aligned with the
        // newest point: it most often holds the answer.
        let (mem, len) = const { MEMBERS[ALL & !(1 << N)] };
        let mut drop = mem[0] as usize & 3;
        for &i in &mem[1..len as usize] {
            let i = i as usize & 3;
            if self.dot[i][N] > self.dot[drop][N] {
                drop = i;
            }
        }
        let first = ALL & !(1 << drop);
        if by_mask!(first, M => self.passes_in(M, ALL)) {
            return Some(self.solution_specialised(first));
        }
        let (list, len) = const { ORDER[N][ALL] };
        for &m in &list[..len as usize] {
            let m = m as usize;
            if m != first && by_mask!(m, M => self.passes_in(M, ALL)) {
                return Some(self.solution_specialised(m));
            }
        }
        None
    }

    /// [`solve`](Self::solve) for a fresh `V0` (a warm start), where the whole
    /// set is the likeliest answer.
    fn solve_warm(&self) -> Option<Solution> {
        if self.all == 0 {
            return None;
        }
        by_mask!(self.all as usize, ALL => self.solve_warm_set::<ALL>())
    }

    /// [`solve_warm`](Self::solve_warm) for the set `ALL`, unrolled.
    #[inline(always)]
    fn solve_warm_set<const ALL: usize>(&self) -> Option<Solution> {
        macro_rules! step {
            ($($k:literal)*) => {$(
                if const { DOWN[ALL].1 > $k } {
                    let m = const { DOWN[ALL].0[$k] as usize };
                    if by_mask!(m, M => self.passes_in(M, ALL)) {
                        return Some(by_mask!(m, M => self.solution(M)));
                    }
                }
            )*};
        }
        step!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14);
        None
    }

    /// [`solution`](Self::solution), one specialised body per subset.
    #[inline(always)]
    fn solution_specialised(&self, mask: usize) -> Solution {
        by_mask!(mask, M => self.solution(M))
    }

    /// The Backup Procedure (6.5): among the subsets with `Δ > 0` and every
    /// `Δ_i > 0`, the one whose affine hull is nearest the origin (measured
    /// on the `v` it gives, see `backup_distance2`).
    /// Always succeeds: a single point qualifies.
    pub fn backup(&self) -> Solution {
        let all = self.all as usize;
        let mut best = 0;
        let mut best_d2 = f64::INFINITY;
        for mask in 1..16usize {
            if mask & !all != 0 {
                continue;
            }
            let d2 = by_mask!(mask, M => self.backup_distance2(M));
            if d2 < best_d2 {
                best_d2 = d2;
                best = mask;
            }
        }
        // A singleton always qualifies (Δ = 1); the fallback only guards
        // against a NaN having crept into a dot product.
        if best == 0 {
            best = all & all.wrapping_neg();
        }
        self.solution_specialised(best)
    }

    /// `|v(aff Y_s)|²` for a candidate of the Backup Procedure, infinity for a
    /// subset that is not one.
    #[inline(always)]
    fn backup_distance2(&self, mask: usize) -> f64 {
        if !self.interior(mask) || (mask == 0b1111 && !self.holds_origin()) {
            return f64::INFINITY;
        }
        let total = self.total(mask);
        if total <= 0.0 || total.is_nan() {
            return f64::INFINITY;
        }
        // |v(aff Y_s)|² is taken from v itself, not from (5.10): that
        // formula's absolute error, about ε·|y|², is larger than |v|² near
        // contact: it ranked a sliver triangle whose v was 2e-9 off level
        // with its edge whose v was exact (found by long property runs),
        // and at other contacts a worse subset above a better one. The v
        // each candidate gives is the one the run would keep.
        let v = self.solution(mask).v;
        v.norm_squared()
    }

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
    fn refine_by_edges(
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
    fn face_weights_of_origin(&self) -> Option<([f64; 4], f64)> {
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

    /// Whether the vertex pair `(ia, ib)` is already in the subset `mask`.
    #[inline(always)]
    pub fn has_pair(&self, mask: u8, ia: u32, ib: u32) -> bool {
        self.pair_slots(ia, ib) & mask != 0
    }

    /// The slots whose vertex pair is `(ia, ib)`, as a bit mask.
    #[inline(always)]
    fn pair_slots(&self, ia: u32, ib: u32) -> u8 {
        // Each pair as one 64-bit key (the two adjacent indices of a
        // vertex load as one word), compared without short-circuit: which
        // slot matches is unpredictable, so a bit mask of matches costs
        // less than the branches of `any`.
        let key = |a: u32, b: u32| u64::from(a) | u64::from(b) << 32;
        let want = key(ia, ib);
        let mut hit = 0u8;
        for (i, v) in self.vertices.iter().enumerate() {
            hit |= u8::from(key(v.ia, v.ib) == want) << i;
        }
        hit
    }
}

/// The barycentric weights of `q` in the triangle `y` (`q` in its plane,
/// or its projection otherwise: the 2×2 normal equations of the first
/// corner's edges), `None` for a triangle too thin for them.
#[inline]
pub(crate) fn triangle_weights(y: [Vector3<f64>; 3], q: &Vector3<f64>) -> Option<[f64; 3]> {
    let (e1, e2, w) = (y[1] - y[0], y[2] - y[0], q - y[0]);
    let (g11, g12, g22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
    let det = g11 * g22 - g12 * g12;
    // Also refuses a NaN, which fails every comparison.
    if det.is_nan() || det <= 1e-24 * g11 * g22 {
        return None;
    }
    let (r1, r2) = (w.dot(&e1), w.dot(&e2));
    let (s, t) = ((r1 * g22 - r2 * g12) / det, (g11 * r2 - g12 * r1) / det);
    Some([1.0 - s - t, s, t])
}

/// The signed volume of the tetrahedron `y` with the origin in place of
/// vertex `l`, det(q1 - q0, q2 - q0, q3 - q0), with its sign exact (Shewchuk's
/// adaptive predicate): the float volumes' own orientation, since
/// orient3d(pa, pb, pc, pd) is det(pa - pd, pb - pd, pc - pd).
fn exact_volume_without(y: &[Vector3<f64>; 4], l: usize) -> f64 {
    let point = |p: Vector3<f64>| robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    };
    let mut q = *y;
    q[l] = Vector3::zeros();
    robust::orient3d(point(q[1]), point(q[2]), point(q[3]), point(q[0]))
}

/// What round-off `delta` in each point of a face (`m2` the largest squared
/// norm of the points) may do to its plane's distance `|n·p| / |n|` from
/// the origin: `(shrink, widen)`, the most `|n·p|` may move and a bound on
/// how far `|n|²` may grow (see [`Simplex::inner_radius`]), so that
/// `(|n·p| - shrink)² / (|n|² + widen)` never exceeds the true squared
/// distance.
#[inline]
pub(crate) fn face_round_off(delta: f64, m2: f64) -> (f64, f64) {
    let m = m2.sqrt();
    let shrink = delta * (3.0 * m2 + delta * (3.0 * m + delta));
    let widen = 64.0 * delta * m2 * (m + delta);
    (shrink, widen)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex_at(x: f64, y: f64, z: f64) -> Vertex {
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
            vertex_at(1.0, 0.2, 0.3),
            vertex_at(-0.5, 1.0, 0.1),
            vertex_at(0.3, -0.7, 1.2),
            vertex_at(0.9, 0.4, -1.1),
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

    /// The needle's triangle of `regrow`'s documentation: an edge
    /// of K 5.55e-5 from the origin and a vertex 1.3e5 away whose weight in
    /// the nearest point is about 1e-16.
    #[test]
    fn regrow_restores_a_far_vertex_lost_to_round_off() {
        let mut pts = [
            vertex_at(
                9.166550882371626e-12,
                5.365944365714793e-5,
                -61997.68103873958,
            ),
            vertex_at(
                -22760.413943159896,
                8.154773311155362e-12,
                131071.99999999999,
            ),
            vertex_at(
                -5.385364345995226e-12,
                6.0975361175549454e-5,
                181151.45797131996,
            ),
        ];
        pts[1].ia = 57;
        pts[1].ib = 10;
        let s = Simplex::new(&pts);
        let edge = s.solve().unwrap();
        // The subalgorithm drops the far vertex, although it lies 2.3e-3
        // beyond the plane through the edge's v normal to v.
        assert_eq!(edge.mask, 0b101);
        let beyond = |v: &Vector3<f64>| v.norm_squared() - v.dot(&pts[1].y);
        assert!(beyond(&edge.v) > 1e-7, "{:e}", beyond(&edge.v));
        assert!(s.regrow(edge, 1, 1).is_none(), "not a vertex of Y");
        let tri = s.regrow(edge, 57, 10).unwrap();
        assert_eq!(tri.mask, 0b111);
        assert!(tri.lambda.iter().all(|l| (0.0..=1.0).contains(l)));
        assert!(tri.lambda[1] > 0.0);
        // Optimality in the triangle's plane: v normal to both edges, to
        // within the round-off of a dot product of 1e5-long vectors; the
        // edge's v misses the first by 1.3e-7.
        for j in [1, 2] {
            let e = pts[j].y - pts[0].y;
            let off = tri.v.dot(&e);
            assert!(off.abs() < 1e-15 * e.norm() * 1e-4, "{off:e}");
        }
        assert!(tri.v.norm_squared() <= edge.v.norm_squared() * (1.0 + 8.0 * f64::EPSILON));
        // The sideways component that steered the support search changes
        // sign: the support point then is the vertex next to the needle.
        assert!(edge.v.x > 0.0 && tri.v.x < 0.0, "{:?} {:?}", edge.v, tri.v);
        assert!(s.regrow(tri, 57, 10).is_none(), "not dropped");
    }

    #[test]
    fn segment_nearest_point_is_projection() {
        let s = Simplex::new(&[vertex_at(-1.0, 1.0, 0.0), vertex_at(3.0, 1.0, 0.0)]);
        let sol = s.solve().unwrap();
        assert_eq!(sol.mask, 0b11);
        assert!((sol.v - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-15);
        assert!((sol.lambda[0] - 0.75).abs() < 1e-15);
    }

    #[test]
    fn tetrahedron_with_origin_inside_and_its_inner_radius() {
        let mut s = Simplex::empty();
        s.reset(&[
            vertex_at(1.0, 1.0, 1.0),
            vertex_at(1.0, -1.0, -1.0),
            vertex_at(-1.0, 1.0, -1.0),
            vertex_at(-1.0, -1.0, 1.0),
        ]);
        let sol = s.solve().unwrap();
        assert_eq!(sol.mask, 0b1111);
        assert!(sol.v.norm() < 1e-15);
        // Regular tetrahedron with circumradius √3: inradius √3/3.
        assert!((s.inner_radius(0.0) - 3f64.sqrt() / 3.0).abs() < 1e-14);
    }

    /// The origin a hair from one face (far below the float volumes' error
    /// bound): that face's sign is in doubt and decided exactly, the other
    /// three are clear. Inside, on and outside the face must all come out
    /// as the exact geometry says; so must a tetrahedron whose clear
    /// volumes already disagree.
    #[test]
    fn origin_next_to_a_face_is_decided_exactly() {
        let at = |h: f64| {
            let mut s = Simplex::empty();
            s.reset(&[
                vertex_at(0.3, 0.2, 1.0),
                vertex_at(-1.0, -1.0, -h),
                vertex_at(2.0, -1.0, -h),
                vertex_at(-1.0, 2.0, -h),
            ]);
            s
        };
        for (h, inside) in [(1e-60, true), (1e-17, true), (0.0, false), (-1e-60, false)] {
            let s = at(h);
            // The face b, c, d: its volume is in doubt, the rest are not.
            let b = s.vertices[1].y;
            let vol = b.dot(&s.vertices[2].y.cross(&s.vertices[3].y));
            assert!(vol.abs() < 1e-12, "h = {h}: the face is not in doubt");
            assert_eq!(s.holds_origin(), inside, "h = {h}");
        }
        // Clear volumes of both signs: the origin beyond an edge, far out.
        let mut s = Simplex::empty();
        s.reset(&[
            vertex_at(5.0, 5.0, 1.0),
            vertex_at(4.0, 4.0, 0.0),
            vertex_at(7.0, 4.0, 0.0),
            vertex_at(4.0, 7.0, 0.0),
        ]);
        assert!(!s.holds_origin());
    }

    #[test]
    fn origin_weights_come_from_exact_volumes() {
        // A tetrahedron 1e-12 thick around the origin, whose weights are
        // known: the origin is 0.1, 0.2, 0.3 and 0.4 of its vertices.
        let h = 1e-12;
        let corners = [
            Vector3::new(4.0, -1.0, 3.0 * h),
            Vector3::new(-2.0, 3.0, -h),
            Vector3::new(-1.0, -2.0, -h),
            Vector3::zeros(),
        ];
        let want = [0.1, 0.2, 0.3, 0.4];
        // The last corner is placed so that Σ w_i y_i = 0.
        let rest = corners[..3]
            .iter()
            .zip(want)
            .fold(Vector3::zeros(), |s, (c, w)| s + c * w);
        let last = -rest / want[3];
        let pts = [corners[0], corners[1], corners[2], last].map(|c| vertex_at(c.x, c.y, c.z));
        // As a run builds it, by a push: `new` would keep a flat set to
        // its independent points.
        let four = |p: &[Vertex; 4]| {
            let mut s = Simplex::new(&p[..3]);
            s.push(0b111, p[3]);
            s
        };
        let s = four(&pts);
        let got = s.origin_weights().expect("the origin is inside");
        let sum: f64 = got.iter().sum();
        assert!((sum - 1.0).abs() < 1e-15, "{got:?}");
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{got:?}");
        }
        let v = (0..4).fold(Vector3::zeros(), |a, i| a + s.vertices[i].y * got[i]);
        // Round-off of the points' size (about 4), not of a flat cofactor.
        assert!(v.amax() < 32.0 * f64::EPSILON, "{v:?}");
        // Lifted by ten times its thickness: the origin is just below it.
        let off = pts.map(|p| vertex_at(p.y.x, p.y.y, p.y.z + 10.0 * h));
        assert_eq!(four(&off).origin_weights(), None);
        // Flat through the origin (all four volumes exactly 0): undecided.
        let flat = [
            vertex_at(1.0, 0.0, 0.0),
            vertex_at(0.0, 1.0, 0.0),
            vertex_at(-1.0, -1.0, 0.0),
            vertex_at(2.0, 2.0, 0.0),
        ];
        assert_eq!(four(&flat).origin_weights(), None);
        // Fewer than four points: not asked.
        assert_eq!(Simplex::new(&pts[..3]).origin_weights(), None);
    }

    #[test]
    fn backup_picks_nearest_affine_hull() {
        let s = Simplex::new(&[
            vertex_at(1.0, 1.0, 0.0),
            vertex_at(1.0, -1.0, 0.0),
            vertex_at(2.0, 0.0, 0.0),
        ]);
        let sol = s.backup();
        assert!((sol.v - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-15);
    }
}
