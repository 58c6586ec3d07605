//! An independent, brute-force reference for the distance between convex hulls
//! of small point sets. Nothing here calls into `gjk`'s algorithm: it only uses
//! the crate's shape types to read back vertices, radii and piece offsets.
//!
//! The distance between two disjoint convex polytopes is attained by a pair of
//! boundary simplices, and the distance between two simplices of dimension at
//! most 2 is attained by a vertex–triangle or an edge–edge pair. Every vertex
//! triple of a set spans a triangle inside its hull, and the hull's boundary is
//! covered by such triangles, so the minimum over all
//! (point, triangle), (triangle, point), (segment, segment) candidates (plus
//! (point, point) and (point, segment) for sets too small to have triangles) is
//! the exact distance when the hulls are disjoint, and an upper bound always.
//!
//! A separate separating-axis test decides whether the hulls are disjoint: the
//! candidate axes are the normals of all vertex triples of each set, the cross
//! products of all edge pairs, and the direction between the nearest candidate
//! witness points (which separates whenever the hulls are disjoint, including
//! for collinear and coplanar sets). No separating axis means the hulls touch
//! or intersect, distance 0.
#![allow(dead_code)]

use gjk::{Convex, Shape};
use nalgebra::{Isometry3, Point3, Vector3};

pub type P = Point3<f64>;
pub type V = Vector3<f64>;

/// Nearest point of segment `[a, b]` to `p` (a point when `a == b`).
pub fn closest_on_segment(p: &P, a: &P, b: &P) -> P {
    let d = b - a;
    let dd = d.norm_squared();
    if dd == 0.0 {
        return *a;
    }
    let t = ((p - a).dot(&d) / dd).clamp(0.0, 1.0);
    a + d * t
}

/// Nearest points of segments `[p1, q1]` and `[p2, q2]` (Ericson, Real-Time
/// Collision Detection 5.1.9), made robust for degenerate and parallel segments
/// by also trying the four endpoint-to-segment candidates: every candidate is a
/// pair of real points on the segments, so taking the nearest is never worse.
pub fn closest_segment_segment(p1: &P, q1: &P, p2: &P, q2: &P) -> (P, P) {
    let mut best = (*p1, *p2);
    let mut best_d2 = f64::INFINITY;
    let mut consider = |x: P, y: P| {
        let d2 = (y - x).norm_squared();
        if d2 < best_d2 {
            best_d2 = d2;
            best = (x, y);
        }
    };
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    if a > 0.0 && e > 0.0 {
        let b = d1.dot(&d2);
        let c = d1.dot(&r);
        let f = d2.dot(&r);
        let denom = a * e - b * b;
        let mut s = if denom > 1e-14 * a * e {
            ((b * f - c * e) / denom).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let mut t = (b * s + f) / e;
        if t < 0.0 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else if t > 1.0 {
            t = 1.0;
            s = ((b - c) / a).clamp(0.0, 1.0);
        }
        consider(p1 + d1 * s, p2 + d2 * t);
    }
    consider(*p1, closest_on_segment(p1, p2, q2));
    consider(*q1, closest_on_segment(q1, p2, q2));
    consider(closest_on_segment(p2, p1, q1), *p2);
    consider(closest_on_segment(q2, p1, q1), *q2);
    best
}

/// Nearest point of triangle `abc` to `p`, as a convex combination of the
/// vertices, so that it lies in the triangle up to the rounding of its own
/// sum whatever the error of its weights. A plane projection does not: a thin
/// triangle's plane is tilted by round-off (relative error ε/θ at an angle
/// θ), and its projection can land nearer `p` than any point of the triangle.
/// Seed 8204 of `mid_sets` found a reference 0.8 % below the certified lower
/// bound of a 4e-14 gap, and seed 8401 one 5 % below the truth (exact
/// rational arithmetic: 7.7527e-12) on a sliver of sine 2.6e-6 whose far
/// vertex was 0.54 from the origin. The weights come from the 2 × 2 normal
/// equations with the vertex nearest `p` as the base, which keeps the sum's
/// cancellation small; the edges are candidates too (a degenerate triangle
/// is the union of its edges), and the nearest candidate is returned.
pub fn closest_on_triangle(p: &P, a: &P, b: &P, c: &P) -> P {
    let d2 = |q: &P| (q - p).norm_squared();
    let mut best = [
        closest_on_segment(p, a, b),
        closest_on_segment(p, b, c),
        closest_on_segment(p, c, a),
    ]
    .into_iter()
    .fold(*a, |best, q| if d2(&q) < d2(&best) { q } else { best });
    let mut v = [*a, *b, *c];
    v.sort_by(|x, y| d2(x).total_cmp(&d2(y)));
    let (base, e1, e2) = (v[0], v[1] - v[0], v[2] - v[0]);
    let (g11, g12, g22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
    let to_p = p - base;
    let (r1, r2) = (to_p.dot(&e1), to_p.dot(&e2));
    let det = g11 * g22 - g12 * g12;
    if det > 0.0 {
        let solve = |r1: f64, r2: f64| ((g22 * r1 - g12 * r2) / det, (g11 * r2 - g12 * r1) / det);
        let (mut s, mut t) = solve(r1, r2);
        // One step of refinement on the residual: on a thin triangle the
        // Gram system's conditioning multiplies the weights' round-off, which
        // left a point 6e-20 above a triangle of size 1e-3 at 1.3e-16
        // (property seed 8712); the residual's own solve removes it.
        let residual = to_p - (e1 * s + e2 * t);
        let (ds, dt) = solve(residual.dot(&e1), residual.dot(&e2));
        s += ds;
        t += dt;
        if s >= 0.0 && t >= 0.0 && s + t <= 1.0 {
            let q = base + e1 * s + e2 * t;
            if d2(&q) < d2(&best) {
                best = q;
            }
        }
    }
    best
}

/// The result of the brute force.
#[derive(Clone, Copy, Debug)]
pub struct HullDistance {
    /// Distance between the hulls (0 when they touch or intersect).
    pub distance: f64,
    /// Nearest candidate points on each hull (meaningful when separated).
    pub point_p: P,
    pub point_q: P,
    /// Whether a separating axis with a positive gap was found (proof of
    /// disjointness).
    pub separated: bool,
    /// The largest gap found along any candidate axis: a lower bound on the
    /// distance (when positive).
    pub best_gap: f64,
    /// The smallest candidate distance: an upper bound on the distance.
    pub candidate: f64,
}

fn triples(n: usize) -> impl Iterator<Item = (usize, usize, usize)> {
    (0..n).flat_map(move |i| (i + 1..n).flat_map(move |j| (j + 1..n).map(move |k| (i, j, k))))
}

fn pairs(n: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..n).flat_map(move |i| (i + 1..n).map(move |j| (i, j)))
}

/// A bounding ball of some points: centre and radius (slightly padded).
fn ball(points: &[&P]) -> (P, f64) {
    let n = points.len() as f64;
    let c = P::from(points.iter().fold(V::zeros(), |acc, x| acc + x.coords) / n);
    let r = points.iter().map(|x| (*x - c).norm()).fold(0.0, f64::max);
    (c, r * (1.0 + 1e-12))
}

/// Smallest distance over all feature candidates, with its witness points.
/// Candidates whose bounding balls are already farther apart than the best
/// distance so far are skipped: they cannot be nearer.
fn candidate_distance(p: &[P], q: &[P]) -> (f64, P, P) {
    let mut best = (f64::INFINITY, p[0], q[0]);
    fn consider(best: &mut (f64, P, P), x: P, y: P) {
        let d = (y - x).norm();
        if d < best.0 {
            *best = (d, x, y);
        }
    }
    let hopeless = |best: &(f64, P, P), c1: &P, r1: f64, c2: &P, r2: f64| {
        (c2 - c1).norm() - r1 - r2 > best.0 * (1.0 + 1e-9)
    };
    let segs = |s: &[P]| -> Vec<(usize, usize, P, f64)> {
        pairs(s.len())
            .map(|(i, j)| {
                let (c, r) = ball(&[&s[i], &s[j]]);
                (i, j, c, r)
            })
            .collect()
    };
    let tris = |s: &[P]| -> Vec<(usize, usize, usize, P, f64)> {
        triples(s.len())
            .map(|(i, j, k)| {
                let (c, r) = ball(&[&s[i], &s[j], &s[k]]);
                (i, j, k, c, r)
            })
            .collect()
    };
    let (segs_p, segs_q, tris_p, tris_q) = (segs(p), segs(q), tris(p), tris(q));
    // point-point
    for x in p {
        for y in q {
            consider(&mut best, *x, *y);
        }
    }
    // point-segment, both ways (needed when a set has exactly two points)
    for x in p {
        for &(i, j, ref c, r) in &segs_q {
            if !hopeless(&best, x, 0.0, c, r) {
                consider(&mut best, *x, closest_on_segment(x, &q[i], &q[j]));
            }
        }
    }
    for y in q {
        for &(i, j, ref c, r) in &segs_p {
            if !hopeless(&best, y, 0.0, c, r) {
                consider(&mut best, closest_on_segment(y, &p[i], &p[j]), *y);
            }
        }
    }
    // segment-segment
    for &(i, j, ref c1, r1) in &segs_p {
        for &(k, l, ref c2, r2) in &segs_q {
            if !hopeless(&best, c1, r1, c2, r2) {
                let (x, y) = closest_segment_segment(&p[i], &p[j], &q[k], &q[l]);
                consider(&mut best, x, y);
            }
        }
    }
    // point-triangle, both ways
    for x in p {
        for &(i, j, k, ref c, r) in &tris_q {
            if !hopeless(&best, x, 0.0, c, r) {
                consider(&mut best, *x, closest_on_triangle(x, &q[i], &q[j], &q[k]));
            }
        }
    }
    for y in q {
        for &(i, j, k, ref c, r) in &tris_p {
            if !hopeless(&best, y, 0.0, c, r) {
                consider(&mut best, closest_on_triangle(y, &p[i], &p[j], &p[k]), *y);
            }
        }
    }
    best
}

/// Gap between the sets along the unit axis `a`: `min_q a·q - max_p a·p`,
/// measured from `origin` to keep the products small.
pub fn gap_along(p: &[P], q: &[P], a: &V, origin: &P) -> f64 {
    let max_p = p
        .iter()
        .map(|x| a.dot(&(x - origin)))
        .fold(f64::NEG_INFINITY, f64::max);
    let min_q = q
        .iter()
        .map(|y| a.dot(&(y - origin)))
        .fold(f64::INFINITY, f64::min);
    min_q - max_p
}

/// The largest gap over the separating-axis candidates (either orientation):
/// triple normals of each set, cross products of edge pairs and vertex-edge
/// normals, plus an optional extra axis.
fn best_separation(p: &[P], q: &[P], witness_axis: Option<V>) -> f64 {
    let origin = p[0];
    let mut best = f64::NEG_INFINITY;
    let mut try_axis = |axis: V| {
        let n = axis.norm();
        if n == 0.0 || !n.is_finite() {
            return;
        }
        let a = axis / n;
        best = best.max(gap_along(p, q, &a, &origin));
        best = best.max(gap_along(p, q, &-a, &origin));
    };
    if let Some(w) = witness_axis {
        try_axis(w);
    }
    for set in [p, q] {
        for (i, j, k) in triples(set.len()) {
            try_axis((set[j] - set[i]).cross(&(set[k] - set[i])));
        }
    }
    for (i, j) in pairs(p.len()) {
        for (k, l) in pairs(q.len()) {
            try_axis((p[j] - p[i]).cross(&(q[l] - q[k])));
        }
    }
    // Vertex against edge: the part of (vertex - edge start) across the
    // edge, built by cross products so that it stays square to the edge to
    // round-off. The witness axis of a vertex 1e-11 from an edge of length 1
    // is off by about ε/1e-11 radians, which tilts the edge's projection by
    // 1e-5: only an axis square to the edge by construction shows the gap.
    for (a, b) in [(p, q), (q, p)] {
        for x in a {
            for (k, l) in pairs(b.len()) {
                let e = b[l] - b[k];
                try_axis(e.cross(&(x - b[k]).cross(&e)));
            }
        }
    }
    best
}

/// Largest coordinate magnitude in the sets: the scale for round-off.
pub fn extent(sets: &[&[P]]) -> f64 {
    sets.iter()
        .flat_map(|s| s.iter())
        .map(|x| x.coords.amax())
        .fold(0.0, f64::max)
}

/// Distance between the convex hulls of two non-empty point sets.
pub fn hull_distance(p: &[P], q: &[P]) -> HullDistance {
    assert!(!p.is_empty() && !q.is_empty());
    let (candidate, x, y) = candidate_distance(p, q);
    // Span of the sets (not their position): round-off of differences.
    let span = {
        let all: Vec<P> = p.iter().chain(q.iter()).copied().collect();
        let mut lo = all[0].coords;
        let mut hi = all[0].coords;
        for v in &all {
            lo = lo.inf(&v.coords);
            hi = hi.sup(&v.coords);
        }
        (hi - lo).amax()
    };
    // The direction between the nearest candidates separates whenever the hulls
    // are disjoint; only when it does not is the full axis search needed.
    let witness_gap = if candidate > 0.0 {
        gap_along(p, q, &((y - x) / candidate), &x)
    } else {
        f64::NEG_INFINITY
    };
    let best_gap = if witness_gap > 1e-13 * span {
        witness_gap
    } else {
        best_separation(p, q, (candidate > 0.0).then(|| y - x))
    };
    // Any axis gap is a lower bound on the distance (up to round-off of the
    // projections, ~1e-16·span, whatever the axis), the candidate an upper
    // bound. A positive gap proves the hulls disjoint. A clearly negative best
    // gap proves them overlapping: had they been disjoint at distance d, the
    // witness axis (direction error ~ε·span/d) would show a gap of at least
    // d - ε·span²/d, so only d < ~2e-10·span can be misjudged. In between
    // (near contact) the candidate distance, itself near zero, is the answer.
    //
    // Disjoint hulls are `candidate` apart (their nearest points lie on a
    // vertex, edge or triangle pair), and the witness axis would show that
    // gap but for its direction's error, ~ε·mag/candidate: a witness gap
    // clearly short of the candidate proves overlap too. This decides the
    // shallow overlaps (an edge piercing a face near its border) that no
    // axis shows clearly negative.
    let mag = p
        .iter()
        .chain(q.iter())
        .map(|v| v.coords.amax())
        .fold(0.0, f64::max);
    let pierced = candidate > 0.0
        && witness_gap < candidate - 1e-13 * (mag * span / candidate + mag)
        && best_gap <= 1e-13 * span;
    let distance = if best_gap > 1e-13 * span {
        assert!(
            best_gap <= candidate + 1e-9 * span + 64.0 * f64::EPSILON * mag,
            "reference inconsistent: gap {best_gap} > candidate {candidate}\nP = {p:?}\nQ = {q:?}"
        );
        candidate
    } else if best_gap < -1e-6 * span || pierced || pierces_exactly(p, q) {
        0.0
    } else {
        assert!(
            candidate <= 1e-5 * span,
            "reference undecided: best gap {best_gap}, candidate {candidate}\nP = {p:?}\nQ = {q:?}"
        );
        candidate
    };
    HullDistance {
        distance,
        point_p: x,
        point_q: y,
        separated: best_gap > 1e-13 * span,
        best_gap,
        candidate,
    }
}

/// Whether a segment between two points of one set meets a triangle of
/// three points of the other, decided by exact orientation predicates: near
/// contact, where no axis gap decides (a segment piercing a triangle within
/// 1e-15 of its border, whose nearest vertex, edge and triangle pairs are
/// 1.3e-15 apart in f64: property seed 8712), the hulls meet exactly when
/// such a pair meets, unless one hull holds the other whole, which the axis
/// gaps show clearly.
fn pierces_exactly(p: &[P], q: &[P]) -> bool {
    let c = |x: &P| robust::Coord3D {
        x: x.x,
        y: x.y,
        z: x.z,
    };
    let orient = |a: &P, b: &P, d: &P, e: &P| robust::orient3d(c(a), c(b), c(d), c(e));
    // Both signs allowed to be zero: touching counts as meeting.
    let same = |x: f64, y: f64, z: f64| {
        (x >= 0.0 && y >= 0.0 && z >= 0.0) || (x <= 0.0 && y <= 0.0 && z <= 0.0)
    };
    let meets = |s0: &P, s1: &P, a: &P, b: &P, d: &P| {
        let (o0, o1) = (orient(a, b, d, s0), orient(a, b, d, s1));
        // A segment in the triangle's plane is left to the distances.
        if (o0 > 0.0 && o1 > 0.0) || (o0 < 0.0 && o1 < 0.0) || (o0 == 0.0 && o1 == 0.0) {
            return false;
        }
        same(
            orient(s0, s1, a, b),
            orient(s0, s1, b, d),
            orient(s0, s1, d, a),
        )
    };
    [(p, q), (q, p)].iter().any(|(s, t)| {
        pairs(s.len()).any(|(i, j)| {
            triples(t.len()).any(|(k, l, m)| meets(&s[i], &s[j], &t[k], &t[l], &t[m]))
        })
    })
}

/// `d(K_A^rA, K_B^rB) = max(d(K_A, K_B) - rA - rB, 0)` (2.6).
pub fn rounded_distance(p: &[P], rp: f64, q: &[P], rq: f64) -> f64 {
    (hull_distance(p, q).distance - rp - rq).max(0.0)
}

/// Distance from a point to a rounded hull (0 inside).
pub fn point_to_rounded(x: &P, q: &[P], r: f64) -> f64 {
    (hull_distance(std::slice::from_ref(x), q).distance - r).max(0.0)
}

/// Distance from a point to the core hull (no radius).
pub fn point_to_hull(x: &P, q: &[P]) -> f64 {
    hull_distance(std::slice::from_ref(x), q).distance
}

/// A convex piece in world coordinates: posed vertices and radius.
#[derive(Clone, Debug)]
pub struct WorldPiece {
    pub points: Vec<P>,
    pub radius: f64,
}

pub fn world_convex(c: &Convex, pose: &Isometry3<f64>) -> WorldPiece {
    WorldPiece {
        points: c.vertices().iter().map(|v| pose * v).collect(),
        radius: c.radius(),
    }
}

/// The pieces of a shape in world coordinates.
pub fn world_pieces(s: &Shape, pose: &Isometry3<f64>) -> Vec<WorldPiece> {
    match s {
        Shape::Convex(c) => vec![world_convex(c, pose)],
        Shape::Compound(c) => c
            .pieces()
            .iter()
            .map(|(offset, piece)| world_convex(piece, &(pose * offset)))
            .collect(),
    }
}

/// Reference distance between two posed shapes: min over piece pairs (2.3),
/// (2.8), and the piece pair(s) that realise it (the per-pair distances).
pub fn shape_distance(a: &Shape, pa: &Isometry3<f64>, b: &Shape, pb: &Isometry3<f64>) -> RefShape {
    let wa = world_pieces(a, pa);
    let wb = world_pieces(b, pb);
    let mut per_pair = Vec::new();
    let mut best = f64::INFINITY;
    for (i, x) in wa.iter().enumerate() {
        for (j, y) in wb.iter().enumerate() {
            let d = rounded_distance(&x.points, x.radius, &y.points, y.radius);
            per_pair.push(([i as u32, j as u32], d));
            best = best.min(d);
        }
    }
    let all: Vec<&[P]> = wa
        .iter()
        .chain(wb.iter())
        .map(|w| w.points.as_slice())
        .collect();
    let radii = wa
        .iter()
        .chain(wb.iter())
        .map(|w| w.radius)
        .fold(0.0, f64::max);
    // The world points are sums of a translation and a rotated body point:
    // their round-off follows those terms' sizes, which can exceed the sums'
    // (a pose that brings a body point far from its origin near the world
    // origin), so the scale covers them too.
    let terms = |s: &Shape, pose: &Isometry3<f64>| {
        let body = world_pieces(s, &Isometry3::identity());
        let body: Vec<&[P]> = body.iter().map(|w| w.points.as_slice()).collect();
        pose.translation.vector.amax() + extent(&body)
    };
    let scale = extent(&all).max(terms(a, pa)).max(terms(b, pb)) + radii;
    RefShape {
        distance: best,
        per_pair,
        pieces_a: wa,
        pieces_b: wb,
        scale,
    }
}

#[derive(Clone, Debug)]
pub struct RefShape {
    pub distance: f64,
    pub per_pair: Vec<([u32; 2], f64)>,
    pub pieces_a: Vec<WorldPiece>,
    pub pieces_b: Vec<WorldPiece>,
    /// Largest world coordinate magnitude plus the largest radius.
    pub scale: f64,
}

impl RefShape {
    /// Distance from a world point to the union of a shape's rounded pieces.
    pub fn to_a(&self, x: &P) -> f64 {
        self.pieces_a
            .iter()
            .map(|w| point_to_rounded(x, &w.points, w.radius))
            .fold(f64::INFINITY, f64::min)
    }

    pub fn to_b(&self, x: &P) -> f64 {
        self.pieces_b
            .iter()
            .map(|w| point_to_rounded(x, &w.points, w.radius))
            .fold(f64::INFINITY, f64::min)
    }
}

/// A pose from nalgebra's printed form: quaternion `[i, j, k, w]`, then the
/// translation, for inputs copied from a failing run.
pub fn printed_pose(q: [f64; 4], t: [f64; 3]) -> Isometry3<f64> {
    // As printed: already unit, to the last bit; normalising again would move
    // the pose off the case that failed.
    let q =
        nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
    Isometry3::from_parts(nalgebra::Translation3::new(t[0], t[1], t[2]), q)
}

/// A convex point set with radius 0, from plain coordinates.
pub fn points(p: &[[f64; 3]]) -> Shape {
    let p: Vec<P> = p.iter().map(|&c| Point3::from(c)).collect();
    Convex::new(p, 0.0).unwrap().into()
}

/// Exact-input helpers.
pub fn p(x: f64, y: f64, z: f64) -> P {
    P::new(x, y, z)
}

pub fn v(x: f64, y: f64, z: f64) -> V {
    V::new(x, y, z)
}

/// Distance between two axis-aligned boxes given by centres and half extents.
pub fn aabb_distance(ca: &V, ha: &V, cb: &V, hb: &V) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        let g = (cb[i] - ca[i]).abs() - ha[i] - hb[i];
        if g > 0.0 {
            s += g * g;
        }
    }
    s.sqrt()
}

/// Penetration depth of two intersecting convex hulls (the smallest
/// translation that separates them) is the minimum over all directions of the
/// overlap of the projections. This takes the minimum over the face normals of
/// the Minkowski difference (triple normals of each set, cross products of
/// edge pairs) and, for flat differences, in-plane normals: exact for
/// full-dimensional and flat differences, and an upper bound on the depth
/// always (a minimum over a subset of directions).
pub fn penetration_depth(p: &[P], q: &[P]) -> f64 {
    let origin = p[0];
    let mut best = f64::INFINITY;
    let mut try_axis = |axis: V| {
        let n = axis.norm();
        if n == 0.0 || !n.is_finite() {
            return;
        }
        let a = axis / n;
        // Overlap when moving Q along +a: max_p a·p - min_q a·q.
        let o1 = -gap_along(p, q, &a, &origin);
        let o2 = -gap_along(p, q, &-a, &origin);
        best = best.min(o1.max(0.0)).min(o2.max(0.0));
    };
    let mut normals = Vec::new();
    for set in [p, q] {
        for (i, j, k) in triples(set.len()) {
            normals.push((set[j] - set[i]).cross(&(set[k] - set[i])));
        }
    }
    for (i, j) in pairs(p.len()) {
        for (k, l) in pairs(q.len()) {
            try_axis((p[j] - p[i]).cross(&(q[l] - q[k])));
        }
    }
    // In-plane normals, for flat Minkowski differences (coplanar sets).
    for n in &normals {
        try_axis(*n);
        for set in [p, q] {
            for (i, j) in pairs(set.len()) {
                try_axis(n.cross(&(set[j] - set[i])));
            }
        }
    }
    best
}

/// Absolute tolerances of a check: on the distance, and on the bounds
/// (round-off of the brute force itself).
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    pub distance: f64,
    pub bounds: f64,
}

/// Everything a property test asserts about one answer, against the brute
/// force. `tol` is absolute (callers scale it by the size of the scene).
/// Returns a description of the first violated property.
pub fn verify(
    a: &Shape,
    pa: &Isometry3<f64>,
    b: &Shape,
    pb: &Isometry3<f64>,
    ans: &gjk::Answer,
    reference: &RefShape,
    tolerance: Tolerance,
) -> Result<(), String> {
    let Tolerance {
        distance: tol,
        bounds: bound_eps,
    } = tolerance;
    let truth = reference.distance;
    let ctx = || format!("truth {truth}\nanswer {ans:?}\nA = {a:?} at {pa:?}\nB = {b:?} at {pb:?}");
    if !(ans.lower <= truth + bound_eps && truth <= ans.upper + bound_eps) {
        return Err(format!(
            "bounds [{}, {}] miss the truth\n{}",
            ans.lower,
            ans.upper,
            ctx()
        ));
    }
    if !(ans.lower <= ans.distance && ans.distance <= ans.upper) {
        return Err(format!("distance outside its own bounds\n{}", ctx()));
    }
    // Round-off may stop the Backup Procedure short of ε·D (a thin simplex
    // at contact): then the status must say so, and the certified interval
    // must still be within the accuracy asked of a converged answer.
    let round_off_floor = ans.status == gjk::Status::ToleranceNotMet
        && ans.backup_used
        && ans.upper - ans.lower <= tol;
    if ans.status != gjk::Status::Converged && !round_off_floor {
        return Err(format!("status {:?}\n{}", ans.status, ctx()));
    }
    if (ans.distance - truth).abs() > tol {
        return Err(format!(
            "distance error {:e} > tol {tol:e}\n{}",
            ans.distance - truth,
            ctx()
        ));
    }
    // The pieces named realise the distance.
    let named = reference
        .per_pair
        .iter()
        .find(|(pp, _)| *pp == ans.pieces)
        .map(|(_, d)| *d);
    match named {
        Some(d) if (d - truth).abs() <= tol => {}
        _ => {
            return Err(format!(
                "pieces {:?} do not realise the distance ({named:?})\n{}",
                ans.pieces,
                ctx()
            ));
        }
    }
    let (ia, ib) = (ans.pieces[0] as usize, ans.pieces[1] as usize);
    let (wa, wb) = (&reference.pieces_a[ia], &reference.pieces_b[ib]);
    // Nearest points lie on (or, when overlapping, in) their rounded pieces.
    let da = point_to_rounded(&ans.point_a, &wa.points, wa.radius);
    let db = point_to_rounded(&ans.point_b, &wb.points, wb.radius);
    if da > tol || db > tol {
        return Err(format!("point off its shape: {da:e}, {db:e}\n{}", ctx()));
    }
    let separated = ans.normal != V::zeros();
    let core = hull_distance(&wa.points, &wb.points);
    // The surface checks need a well-conditioned normal: cores apart by more
    // than round-off amplified by the scene size.
    if separated && core.distance > 1e-8 * reference.scale {
        if (ans.normal.norm() - 1.0).abs() > 1e-12 {
            return Err(format!("normal not unit\n{}", ctx()));
        }
        // On the surface: at distance r from the core.
        let ca = point_to_hull(&ans.point_a, &wa.points);
        let cb = point_to_hull(&ans.point_b, &wb.points);
        if (ca - wa.radius).abs() > tol || (cb - wb.radius).abs() > tol {
            return Err(format!(
                "point not on the surface: {ca} vs r {}, {cb} vs r {}\n{}",
                wa.radius,
                wb.radius,
                ctx()
            ));
        }
        if ans.distance > 0.0 {
            let err = (ans.point_b - ans.point_a - ans.normal * ans.distance).norm();
            if err > tol {
                return Err(format!(
                    "point_b - point_a != distance·normal by {err:e}\n{}",
                    ctx()
                ));
            }
        } else if reference.per_pair.len() == 1 {
            // Shells overlap: b - a = -penetration·normal (for a union the
            // penetration aggregates pairs and the relation is per pair).
            let err = (ans.point_b - ans.point_a + ans.normal * ans.penetration).norm();
            if err > tol {
                return Err(format!(
                    "point_b - point_a != -penetration·normal by {err:e}\n{}",
                    ctx()
                ));
            }
        }
    }
    Ok(())
}

/// The penetration field against the brute force: 0 when separated; exactly
/// `rA + rB - d(cores)` when only the shells overlap; between `rA + rB` and
/// the true depth when the cores touch or intersect. For a union (which
/// aggregates piece pairs) only the sign is checked.
pub fn verify_penetration(ans: &gjk::Answer, reference: &RefShape, tol: f64) -> Result<(), String> {
    let truth = reference.distance;
    let ctx = || {
        format!(
            "truth {truth}\nanswer {ans:?}\nA = {:?}\nB = {:?}",
            reference.pieces_a, reference.pieces_b
        )
    };
    let (ia, ib) = (ans.pieces[0] as usize, ans.pieces[1] as usize);
    let (wa, wb) = (&reference.pieces_a[ia], &reference.pieces_b[ib]);
    let core = hull_distance(&wa.points, &wb.points);
    let radii = wa.radius + wb.radius;
    let single = reference.per_pair.len() == 1;
    if truth > tol {
        if ans.penetration != 0.0 {
            return Err(format!(
                "separated but penetration {}\n{}",
                ans.penetration,
                ctx()
            ));
        }
    } else if !single {
        // A union's penetration aggregates piece pairs: only its sign is checked.
        if ans.penetration.is_nan() || ans.penetration < 0.0 {
            return Err(format!("penetration {}\n{}", ans.penetration, ctx()));
        }
    } else if core.distance > tol {
        // Only the shells overlap: exact.
        let want = radii - core.distance;
        if (ans.penetration - want).abs() > tol {
            return Err(format!(
                "shell penetration {} != {want}\n{}",
                ans.penetration,
                ctx()
            ));
        }
    } else if truth == 0.0 {
        // Cores touch or intersect: radii <= penetration <= true depth. Cores
        // apart by at most `tol` may also be answered as apart, with the
        // shells' exact overlap: `radii - core.distance`, within `tol`.
        let depth = penetration_depth(&wa.points, &wb.points) + radii;
        let least = radii - core.distance;
        if ans.penetration < least - tol || ans.penetration > depth + tol {
            return Err(format!(
                "penetration {} not in [{least}, {depth}]\n{}",
                ans.penetration,
                ctx()
            ));
        }
    }
    Ok(())
}
