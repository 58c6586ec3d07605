//! The expanding polytope: a closed, oriented surface of triangles on
//! points of `K = A - B`, grown by support points.
//!
//! Why its bound holds: each step removes the faces that see the new point
//! and closes the hole with a cone from it over the removed faces'
//! boundary (the edges that only one removed face has), which leaves a
//! closed surface whatever round-off decided was visible. When every face
//! has the origin strictly on its inner side, each face subtends a
//! positive solid angle at the origin, so the surface winds around the
//! origin at least once; a ball about the origin that meets no face's
//! plane lies where the winding number is that same non-zero value, hence
//! in the convex hull of the points, hence in `K`. Its radius, the least
//! distance to a face's plane, less what round-off may have moved the
//! planes, is a lower bound on the penetration depth, however the surface
//! has folded.

use nalgebra::Vector3;

use super::frame::Vertex;

/// One oriented face: its points, `n = (q - p) × (r - p)` (outward), `n·p`,
/// `|n|²` and the signed distance from the origin to its plane (negative
/// when the origin is outside; NaN for a face without area).
#[derive(Clone, Copy, Debug)]
pub(super) struct Face {
    pub(super) points: [u32; 3],
    pub(super) normal: Vector3<f64>,
    offset: f64,
    len2: f64,
    pub(super) distance: f64,
}

impl Face {
    fn new(points: [u32; 3], at: &[Vertex]) -> Self {
        let [p, q, r] = points.map(|i| at[i as usize].y);
        let normal = (q - p).cross(&(r - p));
        let offset = normal.dot(&p);
        let len2 = normal.norm_squared();
        let distance = if len2 > 0.0 {
            offset / len2.sqrt()
        } else {
            f64::NAN
        };
        Face {
            points,
            normal,
            offset,
            len2,
            distance,
        }
    }

    /// The unit outward normal; `None` for a face without area.
    pub(super) fn unit_normal(&self) -> Option<Vector3<f64>> {
        (self.len2 > 0.0 && self.len2.is_finite()).then(|| self.normal / self.len2.sqrt())
    }
}

/// The polytope: its points and faces.
pub(super) struct Polytope {
    pub(super) points: Vec<Vertex>,
    faces: Vec<Face>,
}

impl Polytope {
    /// The tetrahedron on `v`, faces outward; `None` if it is flat.
    pub(super) fn tetrahedron(v: [Vertex; 4]) -> Option<Self> {
        let y = v.map(|p| p.y);
        let volume = (y[1] - y[0]).cross(&(y[2] - y[0])).dot(&(y[3] - y[0]));
        if !(volume != 0.0) {
            return None;
        }
        let order = if volume > 0.0 {
            [0, 1, 2, 3]
        } else {
            [0, 2, 1, 3]
        };
        let points: Vec<Vertex> = order.iter().map(|&i| v[i]).collect();
        let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
            .iter()
            .map(|&f| Face::new(f, &points))
            .collect();
        Some(Polytope { points, faces })
    }

    /// The faces.
    pub(super) fn faces(&self) -> &[Face] {
        &self.faces
    }

    /// The face whose plane passes nearest the origin (signed: a face with
    /// the origin outside comes first).
    pub(super) fn nearest(&self) -> Option<Face> {
        let mut best: Option<Face> = None;
        for face in &self.faces {
            if face.distance < best.map_or(f64::INFINITY, |b| b.distance) {
                best = Some(*face);
            }
        }
        best
    }

    /// The certified inner radius (see the module): the least distance to a
    /// face's plane, each cut by what the round-off `delta` of the points
    /// (and of the face's own arithmetic) may move it; 0 unless every face
    /// has the origin on its inner side by more than that.
    pub(super) fn certified_depth(&self, delta: f64) -> f64 {
        let mut best = f64::INFINITY;
        for face in &self.faces {
            let h = certified_distance(face, &self.points, delta);
            if h.is_nan() || h <= 0.0 {
                return 0.0;
            }
            best = best.min(h);
        }
        if best.is_finite() { best } else { 0.0 }
    }

    /// Adds `w`: removes the faces that see it and closes the hole with a
    /// cone from `w` over their boundary. `false` (nothing changed) when
    /// `face`, the face it was found for, does not see it.
    pub(super) fn add(&mut self, w: Vertex, face: &Face) -> bool {
        let sees = |f: &Face, points: &[Vertex]| {
            let ahead = f.normal.dot(&(w.y - points[f.points[0] as usize].y));
            ahead > 0.0
        };
        if !sees(face, &self.points) {
            return false;
        }
        // The directed edges of the faces that see `w`; an edge and its
        // reverse cancel, which leaves the boundary.
        let mut edges: Vec<[u32; 2]> = Vec::new();
        let points = &self.points;
        self.faces.retain(|f| {
            if !sees(f, points) {
                return true;
            }
            let [a, b, c] = f.points;
            for edge in [[a, b], [b, c], [c, a]] {
                match edges.iter().position(|e| *e == [edge[1], edge[0]]) {
                    Some(j) => {
                        edges.swap_remove(j);
                    }
                    None => edges.push(edge),
                }
            }
            false
        });
        let new = self.points.len() as u32;
        self.points.push(w);
        for [a, b] in edges {
            self.faces.push(Face::new([a, b, new], &self.points));
        }
        true
    }

    /// A's point of the convex combination of `face`'s points nearest the
    /// origin (the origin's projection on the face when it falls inside,
    /// as it does on a converged face): by barycentric regions, which
    /// stay defined on a sliver of a face.
    pub(super) fn witness_a(&self, face: &Face) -> Vector3<f64> {
        let v = face.points.map(|i| self.points[i as usize]);
        let weights = nearest_weights(v.map(|p| p.y));
        v.iter().zip(weights).map(|(p, w)| p.a * w).sum()
    }
}

/// A lower bound on the distance of the origin inside `face`'s plane, for
/// the exact points each within `delta` of the computed ones: the face's
/// own bound, from its edges' lengths, so that a small or thin face near
/// the origin's projection (where the expansion crowds them) is judged by
/// what round-off can do to it, not to the polytope's largest face.
fn certified_distance(face: &Face, points: &[Vertex], delta: f64) -> f64 {
    const U: f64 = f64::EPSILON;
    let [p, q, r] = face.points.map(|i| points[i as usize].y);
    let (e1, e2) = ((q - p).norm(), (r - p).norm());
    // Each edge errs by the two points' `delta` and its subtraction.
    let (d1, d2) = (2.0 * delta + U * e1, 2.0 * delta + U * e2);
    // The cross product: the edges' errors, and its own products and
    // differences.
    let dn = e1 * d2 + e2 * d1 + d1 * d2 + 4.0 * U * e1 * e2;
    let n = face.len2.sqrt() * (1.0 + 4.0 * U);
    let m = p.norm();
    // The offset `n·p`: the normal's error, the point's, its own sum.
    let doff = dn * (m + delta) + n * delta + 4.0 * U * n * m;
    (face.offset - doff) / (n + dn) * (1.0 - 4.0 * U)
}

/// The barycentric weights of the point of triangle `y` nearest the
/// origin (Ericson, Real-Time Collision Detection 5.1.5), by its Voronoi
/// regions: a vertex, an edge or the inside, each with weights that sum
/// to 1 whatever the triangle's shape.
fn nearest_weights(y: [Vector3<f64>; 3]) -> [f64; 3] {
    let [a, b, c] = y;
    let (ab, ac, ap) = (b - a, c - a, -a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = -b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = -c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = va + vb + vc;
    if !(denom.is_finite() && denom != 0.0) {
        return [1.0 / 3.0; 3];
    }
    let (v, w) = (vb / denom, vc / denom);
    [1.0 - v - w, v, w]
}
