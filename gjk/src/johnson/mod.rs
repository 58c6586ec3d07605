//! Johnson's distance subalgorithm (Section 5) and the Backup Procedure (6.5).
//!
//! The simplex holds up to four points `y_i` of `K = A - B` in four slots; a bit
//! mask names a subset `Y_s`. Dot products `y_i·y_j` and the cofactors
//! `Δ_i(Y_s)` of (5.6) are kept between iterations: when a point enters a slot,
//! only the subsets that contain that slot are recomputed, because every other
//! subset is a subset of the previous simplex and its cofactors are unchanged.

//!
//! The rarely taken refinements (the origin's exact weights, iterative
//! refinement, regrowing a dropped vertex) are in [`refine`]; the exact
//! volume and face helpers they and the penetration bound share, in
//! [`weights`].

#[macro_use]
mod subsets;
mod refine;
#[cfg(test)]
mod tests;
mod weights;

use nalgebra::Vector3;

use subsets::{BY_SIZE, DOWN, MEMBERS, ORDER, THIN, WITH_NEW, fused_cross, missing};
use weights::exact_volume_without;
pub(crate) use weights::{face_round_off, triangle_weights};

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

    cpu_forms! { pair
        /// `Y = V0`, one to four points, all cofactors computed from scratch.
        pub fn reset / reset_avx2 (&mut self, points: &[Vertex]) => reset_inline
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

    cpu_forms! { pair
        /// Point `p` into slot `n`, with the cofactors of the subsets that
        /// hold it.
        #[inline(never)]
        fn insert / insert_avx2 (&mut self, n: u8, p: Vertex) => insert_inline
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
                            by_mask!(mask as usize, M => self.cofactors_of::<M>());
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

    /// (5.6): `Δ_j(Y_s ∪ {y_j}) = Σ_{i∈I_s} Δ_i(Y_s)(y_i·y_k - y_i·y_j)`,
    /// `k = min I_s`, for the subset `MASK`. Its one form takes the subset
    /// at compile time: the unrolled updates name constant subsets, and a
    /// subset known only at run time goes through `by_mask!`. (A run-time
    /// `mask` argument, inlined with a constant, left the subset tables'
    /// lookups unfolded: measurably more instructions a query.)
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

    cpu_forms! { dispatch
        /// A sliver tetrahedron's cofactors, `Δ_l(Y) = V_l·V`: `Δ(Y)` is `V²`, `V`
        /// the signed volume `det(y1 - y0, y2 - y0, y3 - y0)`, and `Δ_l/Δ` is the
        /// origin's barycentric weight `V_l/V`, `V_l` the volume with the origin
        /// in place of `y_l`. Each volume is a triple product through fused cross
        /// products, whose error is relative to the volume, not to `|y|³`. Out of
        /// line: slivers are rare.
        #[cold]
        #[inline(never)]
        fn sliver / sliver_fma (&mut self) => sliver_inline
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

    cpu_forms! { dispatch
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
        fn thin_triangle / thin_triangle_fma (&mut self, mask: usize) => thin_triangle_inline
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

    cpu_forms! { dispatch
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
        fn thin_simplex_v / thin_simplex_v_fma (&self, mask: usize) -> Option<Vector3<f64>> => thin_simplex_v_inline
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

    cpu_forms! { pair
        /// The Distance Subalgorithm: the first subset, in the order of Section 6,
        /// that passes Theorem 5.2, or `None` when round-off left none passing.
        pub fn solve / solve_avx2 (&self) -> Option<Solution> => solve_inline
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
