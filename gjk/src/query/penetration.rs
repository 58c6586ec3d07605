//! A deeper certified penetration bound, on request
//! ([`Options::penetration_expansions`]): GJK's final tetrahedron around
//! the origin grown EPA-style by support points of `K = A - B`.
//!
//! Why it holds: the polytope is kept as a closed, oriented surface of
//! triangles on points of `K` (each step removes the faces that see the new
//! point and closes the hole with a cone from it over the removed faces'
//! boundary, which leaves a closed surface whatever round-off decided was
//! visible). When every face has the origin strictly on its inner side,
//! each face subtends a positive solid angle at the origin, so the surface
//! winds around the origin at least once; a ball about the origin that
//! meets no face's plane then lies where the winding number is that same
//! non-zero value, hence in the convex hull of the points, hence in `K`: its
//! radius, the smallest distance to a face's plane, is a lower bound on the
//! penetration depth. Each face's distance counts only what survives the
//! round-off of its points, as [`Simplex::inner_radius`] does; a surface
//! that fails the check proves nothing, and the run keeps its own bound.

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use super::Options;
use super::numerical_algorithm::RunOutcome;
use super::pair::ConvexPair;
use crate::johnson::{Simplex, face_round_off};
use crate::support_map::SupportMap;

/// At most this many points are added, whatever the options ask.
pub(super) const MAX_EXPANSIONS: u32 = 12;
const MAX_POINTS: usize = 4 + MAX_EXPANSIONS as usize;
/// Room for the faces of a closed surface on `MAX_POINTS` points, `2V - 4`,
/// and for a few more should round-off make the surface fold.
const MAX_FACES: usize = 2 * MAX_POINTS + 8;
const _: () = assert!(MAX_FACES <= 64, "the faces seen are a u64's bits");
/// A face whose plane a support point passes by less than this fraction of
/// its distance is taken as a face of `K`: expanding it gains nothing.
const CONVERGED: f64 = 1e-3;

/// One oriented face: its points, `n = (q - p) × (r - p)` (outward), `n·p`,
/// `|n|²` and the squared distance from the origin to its plane (`+∞` when
/// the origin is not on its inner side: never the nearest).
#[derive(Clone, Copy)]
struct Face {
    points: [u8; 3],
    normal: Vector3<f64>,
    offset: f64,
    len2: f64,
    distance2: f64,
}

impl Face {
    fn new(points: [u8; 3], at: &[Vector3<f64>]) -> Self {
        let [p, q, r] = points.map(|i| at[i as usize]);
        let normal = (q - p).cross(&(r - p));
        let offset = normal.dot(&p);
        let len2 = normal.norm_squared();
        Face {
            points,
            normal,
            offset,
            len2,
            distance2: if offset > 0.0 && len2 > 0.0 {
                offset * offset / len2
            } else {
                f64::INFINITY
            },
        }
    }
}

/// The growing polytope: its points (in the run's scaled frame) and faces.
struct Polytope {
    points: ArrayVec<Vector3<f64>, MAX_POINTS>,
    faces: ArrayVec<Face, MAX_FACES>,
    /// The largest `|y|²` of the points.
    largest2: f64,
}

impl Polytope {
    /// An empty polytope (built where it is used: moving one copies all
    /// its room).
    fn new() -> Self {
        Polytope {
            points: ArrayVec::new(),
            faces: ArrayVec::new(),
            largest2: 0.0,
        }
    }

    /// Makes `self` (empty) the tetrahedron `y0..y3`, faces outward;
    /// `false` if it is flat.
    fn start(&mut self, y: [Vector3<f64>; 4]) -> bool {
        let volume = (y[1] - y[0]).cross(&(y[2] - y[0])).dot(&(y[3] - y[0]));
        if !(volume != 0.0) {
            return false;
        }
        self.largest2 = y.iter().map(|p| p.norm_squared()).fold(0.0, f64::max);
        let order = if volume > 0.0 {
            [0, 1, 2, 3]
        } else {
            [0, 2, 1, 3]
        };
        self.points.extend(order.map(|i| y[i]));
        for face in [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
            self.faces.push(Face::new(face, &self.points));
        }
        true
    }

    /// The face nearest the origin, with its squared distance.
    fn nearest(&self) -> Option<(usize, f64)> {
        let mut best = None;
        let mut best_d2 = f64::INFINITY;
        for (i, face) in self.faces.iter().enumerate() {
            let d2 = face.distance2;
            if d2 < best_d2 {
                best_d2 = d2;
                best = Some(i);
            }
        }
        best.map(|i| (i, best_d2))
    }

    /// The squared certified inner radius: the smallest squared distance
    /// to a face's plane, each cut by what the round-off `delta` of the
    /// points may move it (as [`Simplex::inner_radius`]); 0 unless every
    /// face has the origin on its inner side by more than that.
    fn certified2(&self, delta: f64) -> f64 {
        let (shrink, widen) = face_round_off(delta, self.largest2);
        let mut best = f64::INFINITY;
        for face in &self.faces {
            let h = face.offset - shrink;
            if h <= 0.0 || h.is_nan() {
                return 0.0;
            }
            best = best.min(h * h / (face.len2 + widen));
        }
        if best.is_finite() { best } else { 0.0 }
    }

    /// Adds point `w`: removes the faces that see it and closes the hole
    /// with a cone from `w` over their boundary. `false` (and nothing
    /// changed) when no face sees it or there is no room.
    fn add(&mut self, w: Vector3<f64>) -> bool {
        if self.points.is_full() {
            return false;
        }
        // The directed edges of the faces that see `w`; an edge and its
        // reverse cancel, which leaves the boundary.
        let mut seen = 0u64;
        let mut edges = ArrayVec::<[u8; 2], { 3 * MAX_FACES }>::new();
        for (i, face) in self.faces.iter().enumerate() {
            let p = self.points[face.points[0] as usize];
            let ahead = face.normal.dot(&(w - p));
            if ahead <= 0.0 || ahead.is_nan() {
                continue;
            }
            seen |= 1 << i;
            let [a, b, c] = face.points;
            for edge in [[a, b], [b, c], [c, a]] {
                let reverse = [edge[1], edge[0]];
                match edges.iter().position(|e| *e == reverse) {
                    Some(j) => {
                        edges.swap_remove(j);
                    }
                    None => edges.push(edge),
                }
            }
        }
        let removed = seen.count_ones() as usize;
        if removed == 0 || self.faces.len() - removed + edges.len() > MAX_FACES {
            return false;
        }
        let new = self.points.len() as u8;
        self.points.push(w);
        self.largest2 = self.largest2.max(w.norm_squared());
        let mut slot = 0;
        self.faces.retain(|_| {
            slot += 1;
            seen & (1 << (slot - 1)) == 0
        });
        for &[a, b] in &edges {
            self.faces.push(Face::new([a, b, new], &self.points));
        }
        true
    }
}

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
    /// Raises `run`'s core penetration bound by growing its final
    /// tetrahedron (see the module), when the options ask for expansions,
    /// the cores intersect and neither piece is a cylinder (whose support
    /// points are not kept to this bound's standard).
    pub(super) fn deepen(&self, run: &mut RunOutcome, simplex: &Simplex, options: &Options) {
        let expansions = options.penetration_expansions.min(MAX_EXPANSIONS);
        if expansions == 0
            || run.solution.mask != 0b1111
            || run.norm * self.scale > self.slack
            || run.norm.is_nan()
            || self.seed_after != u32::MAX
        {
            return;
        }
        let grown = self.grown_inner_radius(simplex, expansions);
        let depth = (grown - self.slack).max(0.0) * self.inv_scale;
        if depth > run.core_depth {
            run.core_depth = depth;
        }
    }

    /// The certified inner radius of the final tetrahedron grown by up to
    /// `expansions` support points, in the run's scaled frame, before the
    /// caller's slack.
    #[cold]
    #[inline(never)]
    fn grown_inner_radius(&self, simplex: &Simplex, expansions: u32) -> f64 {
        let mut polytope = Polytope::new();
        if !polytope.start(simplex.vertices.map(|v| v.y)) {
            return 0.0;
        }
        for _ in 0..expansions {
            let Some((i, d2)) = polytope.nearest() else {
                break;
            };
            let face = polytope.faces[i];
            let w = self.support(&face.normal).y;
            // How far past the face's plane the support point lies, against
            // the plane's distance: both times |n|.
            let past = face.normal.dot(&w) - face.offset;
            let needed = CONVERGED * (d2 * face.len2).sqrt();
            if past <= needed || past.is_nan() || !polytope.add(w) {
                break;
            }
        }
        // Only the last surface is checked: the tetrahedron's bound is the
        // run's own, and each step only pushes faces outwards.
        let best = polytope.certified2(self.slack);
        best.sqrt()
    }
}
