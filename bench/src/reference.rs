//! Exact reference distances that owe nothing to GJK, for judging its answers.
//!
//! The distance between two disjoint convex polytopes is attained between a
//! pair of boundary features: vertex–vertex, vertex–edge, edge–edge or
//! vertex–face. [`Hull::new`] finds (a superset of) those features once per
//! shape in its body frame by brute force: every vertex triple whose plane has
//! all vertices on one side spans a facet plane, and each facet's vertices,
//! ordered round the facet, give its edges and a fan of triangles. Features
//! that lie inside the hull as well do no harm: they are points of the hull, so
//! they cannot beat the true nearest pair, only tie it.
//!
//! Whether the hulls are disjoint at all is decided separately by the
//! separating-axis theorem, on the facet normals of both hulls, the cross
//! products of their edges, and the direction between the nearest feature
//! points (which, when the hulls are apart, gives a gap equal to the distance,
//! a proof that the candidate is exact).
//!
//! Small sets (at most [`SMALL`] points, which covers every degenerate set
//! used here: points, segments, flat polygons, duplicated vertices) skip the
//! facet search and use every vertex pair and triple, plus in-plane axes for
//! flat configurations, so degenerate input needs no special case.

use nalgebra::{Isometry3, Point3, Vector3};

/// The exact closest-point primitives (segment, segment pair, triangle) and
/// the gap along an axis, from gjk's own brute-force test reference: shared
/// rather than copied, since both references must owe nothing to GJK and one
/// implementation of them is enough.
#[path = "../../gjk/tests/common/mod.rs"]
mod common;
use common::gap_along;
pub use common::{closest_on_segment, closest_on_triangle, closest_segment_segment};

type P = Point3<f64>;
type V = Vector3<f64>;

/// Sets of at most this many points use every pair and triple as features.
pub const SMALL: usize = 16;

/// The boundary features of a convex hull in its body frame.
#[derive(Clone, Debug)]
pub struct Hull {
    points: Vec<P>,
    edges: Vec<[usize; 2]>,
    triangles: Vec<[usize; 3]>,
    /// Facet normals (unit, body frame), and for small sets every triple
    /// normal.
    normals: Vec<V>,
    /// Whether in-plane axes are needed (small sets, which may be flat).
    flat_axes: bool,
}

impl Hull {
    /// The features of the hull of `points` (not empty).
    pub fn new(points: &[P]) -> Hull {
        assert!(!points.is_empty(), "a hull needs a point");
        let n = points.len();
        if n <= SMALL {
            return Hull::brute(points);
        }
        let centre = P::from(points.iter().fold(V::zeros(), |a, p| a + p.coords) / n as f64);
        let scale = points
            .iter()
            .map(|p| (p - centre).norm())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let tol = 1e-11 * scale;
        let mut planes: Vec<(V, f64)> = Vec::new();
        let mut hull = Hull {
            points: points.to_vec(),
            edges: Vec::new(),
            triangles: Vec::new(),
            normals: Vec::new(),
            flat_axes: false,
        };
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    let normal = (points[j] - points[i]).cross(&(points[k] - points[i]));
                    let len = normal.norm();
                    // Also skips NaN: only a clearly non-degenerate triple spans a plane.
                    if len.is_nan() || len <= 1e-18 * scale * scale {
                        continue;
                    }
                    let mut u = normal / len;
                    let mut d = u.dot(&points[i].coords);
                    let on_known = planes.iter().any(|(pu, pd)| {
                        [i, j, k]
                            .iter()
                            .all(|&x| (pu.dot(&points[x].coords) - pd).abs() <= tol)
                    });
                    if on_known {
                        continue;
                    }
                    let (mut lo, mut hi) = (0.0f64, 0.0f64);
                    for p in points {
                        let s = u.dot(&p.coords) - d;
                        lo = lo.min(s);
                        hi = hi.max(s);
                    }
                    if hi > tol && lo < -tol {
                        continue;
                    }
                    if hi > tol {
                        u = -u;
                        d = -d;
                    }
                    planes.push((u, d));
                    let on: Vec<usize> = (0..n)
                        .filter(|&x| (u.dot(&points[x].coords) - d).abs() <= tol)
                        .collect();
                    hull.add_facet(&u, &on);
                }
            }
        }
        if planes.is_empty() {
            // Collinear (or coincident) points: the hull is the segment
            // between the two points farthest apart.
            let (mut best, mut ends) = (-1.0, [0, 0]);
            for i in 0..n {
                for j in i + 1..n {
                    let d = (points[j] - points[i]).norm_squared();
                    if d > best {
                        best = d;
                        ends = [i, j];
                    }
                }
            }
            hull.edges.push(ends);
            hull.flat_axes = true;
        }
        hull
    }

    /// Every pair and triple: exact for any small set, degenerate or not.
    fn brute(points: &[P]) -> Hull {
        let n = points.len();
        let mut hull = Hull {
            points: points.to_vec(),
            edges: Vec::new(),
            triangles: Vec::new(),
            normals: Vec::new(),
            flat_axes: true,
        };
        for i in 0..n {
            for j in i + 1..n {
                hull.edges.push([i, j]);
                for k in j + 1..n {
                    hull.triangles.push([i, j, k]);
                    let normal = (points[j] - points[i]).cross(&(points[k] - points[i]));
                    let len = normal.norm();
                    if len > 0.0 && len.is_finite() {
                        hull.normals.push(normal / len);
                    }
                }
            }
        }
        hull
    }

    /// Adds a facet of outward unit normal `u` through the vertices `on`:
    /// ordered round their mean, consecutive ones are edges, and a fan from
    /// the first covers the facet.
    fn add_facet(&mut self, u: &V, on: &[usize]) {
        let pts = &self.points;
        let mean = on.iter().fold(V::zeros(), |a, &i| a + pts[i].coords) / on.len() as f64;
        let e1 = (pts[on[0]].coords - mean).normalize();
        let e2 = u.cross(&e1);
        let mut ring: Vec<(f64, usize)> = on
            .iter()
            .map(|&i| {
                let r = pts[i].coords - mean;
                (r.dot(&e2).atan2(r.dot(&e1)), i)
            })
            .collect();
        ring.sort_by(|a, b| a.0.total_cmp(&b.0));
        let ring: Vec<usize> = ring.into_iter().map(|(_, i)| i).collect();
        for w in 0..ring.len() {
            let (a, b) = (ring[w], ring[(w + 1) % ring.len()]);
            let e = [a.min(b), a.max(b)];
            if a != b && !self.edges.contains(&e) {
                self.edges.push(e);
            }
        }
        for w in 1..ring.len().saturating_sub(1) {
            self.triangles.push([ring[0], ring[w], ring[w + 1]]);
        }
        self.normals.push(*u);
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are no points (never, by construction).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Number of edges kept as features.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }
}

/// The reference answer for one posed pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Distance between the rounded hulls, 0 when they touch or overlap.
    pub distance: f64,
    /// Whether a separating axis with a positive gap proved the cores apart.
    pub separated: bool,
}

/// Centre and (padded) radius of a ball holding `pts`.
fn ball(pts: &[P]) -> (P, f64) {
    let c = P::from(pts.iter().fold(V::zeros(), |a, p| a + p.coords) / pts.len() as f64);
    let r = pts.iter().map(|p| (p - c).norm()).fold(0.0, f64::max);
    (c, r * (1.0 + 1e-12))
}

/// Smallest feature-pair distance and its witness points.
fn candidate(ha: &Hull, pa: &[P], hb: &Hull, pb: &[P]) -> (f64, P, P) {
    let mut best = (f64::INFINITY, pa[0], pb[0]);
    let consider = |best: &mut (f64, P, P), x: P, y: P| {
        let d = (y - x).norm();
        if d < best.0 {
            *best = (d, x, y);
        }
    };
    // Balls of features: a feature pair whose balls are farther apart than
    // the best so far cannot hold the nearest points.
    let hopeless = |best: &(f64, P, P), c1: &P, r1: f64, c2: &P, r2: f64| {
        (c2 - c1).norm() - r1 - r2 > best.0 * (1.0 + 1e-9)
    };
    let edge_balls = |h: &Hull, p: &[P]| -> Vec<(P, f64)> {
        h.edges.iter().map(|&[i, j]| ball(&[p[i], p[j]])).collect()
    };
    let tri_balls = |h: &Hull, p: &[P]| -> Vec<(P, f64)> {
        h.triangles
            .iter()
            .map(|&[i, j, k]| ball(&[p[i], p[j], p[k]]))
            .collect()
    };
    let (ea, eb) = (edge_balls(ha, pa), edge_balls(hb, pb));
    let (ta, tb) = (tri_balls(ha, pa), tri_balls(hb, pb));
    for x in pa {
        for y in pb {
            consider(&mut best, *x, *y);
        }
    }
    for x in pa {
        for (&[i, j], (c, r)) in hb.edges.iter().zip(&eb) {
            if !hopeless(&best, x, 0.0, c, *r) {
                consider(&mut best, *x, closest_on_segment(x, &pb[i], &pb[j]));
            }
        }
        for (&[i, j, k], (c, r)) in hb.triangles.iter().zip(&tb) {
            if !hopeless(&best, x, 0.0, c, *r) {
                consider(
                    &mut best,
                    *x,
                    closest_on_triangle(x, &pb[i], &pb[j], &pb[k]),
                );
            }
        }
    }
    for y in pb {
        for (&[i, j], (c, r)) in ha.edges.iter().zip(&ea) {
            if !hopeless(&best, y, 0.0, c, *r) {
                consider(&mut best, closest_on_segment(y, &pa[i], &pa[j]), *y);
            }
        }
        for (&[i, j, k], (c, r)) in ha.triangles.iter().zip(&ta) {
            if !hopeless(&best, y, 0.0, c, *r) {
                consider(
                    &mut best,
                    closest_on_triangle(y, &pa[i], &pa[j], &pa[k]),
                    *y,
                );
            }
        }
    }
    for (&[i, j], (c1, r1)) in ha.edges.iter().zip(&ea) {
        for (&[k, l], (c2, r2)) in hb.edges.iter().zip(&eb) {
            if !hopeless(&best, c1, *r1, c2, *r2) {
                let (x, y) = closest_segment_segment(&pa[i], &pa[j], &pb[k], &pb[l]);
                consider(&mut best, x, y);
            }
        }
    }
    best
}

/// The largest gap over the separating axes: facet normals of both hulls,
/// cross products of their edges, in-plane axes for flat sets, and `extra`.
fn best_gap(ha: &Hull, pa: &[P], na: &[V], hb: &Hull, pb: &[P], nb: &[V], extra: Option<V>) -> f64 {
    let origin = pa[0];
    let mut best = f64::NEG_INFINITY;
    let mut try_axis = |axis: V| {
        let n = axis.norm();
        if n == 0.0 || !n.is_finite() {
            return;
        }
        let a = axis / n;
        best = best
            .max(gap_along(pa, pb, &a, &origin))
            .max(gap_along(pa, pb, &-a, &origin));
    };
    if let Some(w) = extra {
        try_axis(w);
    }
    for n in na.iter().chain(nb) {
        try_axis(*n);
    }
    for &[i, j] in &ha.edges {
        for &[k, l] in &hb.edges {
            try_axis((pa[j] - pa[i]).cross(&(pb[l] - pb[k])));
        }
    }
    if ha.flat_axes || hb.flat_axes {
        // Two flat or thin sets in one plane are told apart only by axes in
        // that plane: the plane's normal crossed with each edge.
        for n in na.iter().chain(nb) {
            for (h, p) in [(ha, pa), (hb, pb)] {
                for &[i, j] in &h.edges {
                    try_axis(n.cross(&(p[j] - p[i])));
                }
            }
        }
        // Collinear against collinear: the segment directions and the line
        // between them span the only plane that matters.
        if na.is_empty() && nb.is_empty() {
            for &[i, j] in &ha.edges {
                for &[k, l] in &hb.edges {
                    let plane = (pa[j] - pa[i]).cross(&(pb[k] - pa[i]));
                    try_axis(plane.cross(&(pa[j] - pa[i])));
                    let plane = (pb[l] - pb[k]).cross(&(pa[i] - pb[k]));
                    try_axis(plane.cross(&(pb[l] - pb[k])));
                }
            }
        }
    }
    best
}

/// Distance between hull `ha` at `pose_a` grown by `ra` and hull `hb` at
/// `pose_b` grown by `rb`.
pub fn distance(
    ha: &Hull,
    pose_a: &Isometry3<f64>,
    ra: f64,
    hb: &Hull,
    pose_b: &Isometry3<f64>,
    rb: f64,
) -> Reference {
    let pa: Vec<P> = ha.points.iter().map(|p| pose_a * p).collect();
    let pb: Vec<P> = hb.points.iter().map(|p| pose_b * p).collect();
    let (cand, x, y) = candidate(ha, &pa, hb, &pb);
    let span = {
        let mut lo = pa[0].coords;
        let mut hi = pa[0].coords;
        for v in pa.iter().chain(&pb) {
            lo = lo.inf(&v.coords);
            hi = hi.sup(&v.coords);
        }
        (hi - lo).amax()
    };
    // The direction between the nearest candidates separates whenever the
    // hulls are apart; only when it does not is the full axis search needed.
    let witness = (cand > 0.0).then(|| y - x);
    let quick = witness.map_or(f64::NEG_INFINITY, |w| gap_along(&pa, &pb, &(w / cand), &x));
    let gap = if quick > 1e-13 * span {
        quick
    } else {
        let na: Vec<V> = ha.normals.iter().map(|n| pose_a.rotation * n).collect();
        let nb: Vec<V> = hb.normals.iter().map(|n| pose_b.rotation * n).collect();
        best_gap(ha, &pa, &na, hb, &pb, &nb, witness)
    };
    let separated = gap > 1e-13 * span;
    // Apart: the candidate is exact (its gap proves it up to round-off).
    // Otherwise the cores touch or overlap, or are within round-off of it.
    let core = if separated { cand } else { 0.0 };
    Reference {
        distance: (core - ra - rb).max(0.0),
        separated,
    }
}

/// Distance between two axis-aligned boxes given by their centres and half
/// extents (a half extent may be 0: flat boxes, segments and points). Each
/// per-axis gap is formed from the inputs with one rounding at most.
pub fn aabb_distance(ca: &V, ha: &V, cb: &V, hb: &V) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        // Sterbenz: the difference of nearby centres is exact.
        let g = (cb[i] - ca[i]).abs() - (ha[i] + hb[i]);
        if g > 0.0 {
            s += g * g;
        }
    }
    s.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(h: f64) -> Vec<P> {
        (0..8)
            .map(|i| {
                P::new(
                    if i & 1 == 0 { -h } else { h },
                    if i & 2 == 0 { -h } else { h },
                    if i & 4 == 0 { -h } else { h },
                )
            })
            .collect()
    }

    /// An icosahedron-like cloud of 20+ points so that the facet search, not
    /// the small-set path, is used.
    fn prism(n: usize, r: f64, h: f64) -> Vec<P> {
        let mut v = Vec::new();
        for z in [-h, h] {
            for k in 0..n {
                let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                v.push(P::new(r * a.cos(), r * a.sin(), z));
            }
        }
        v
    }

    #[test]
    fn boxes_match_the_analytic_distance() {
        let h = Hull::new(&cube(1.0));
        for (t, want) in [
            (V::new(3.5, 0.0, 0.0), 1.5),
            (V::new(3.0, 3.0, 0.0), 2.0f64.sqrt()),
            (V::new(2.0, 0.5, 0.0), 0.0),
            (V::new(0.5, 0.2, 0.1), 0.0),
        ] {
            let r = distance(
                &h,
                &Isometry3::identity(),
                0.0,
                &h,
                &Isometry3::translation(t.x, t.y, t.z),
                0.0,
            );
            assert!((r.distance - want).abs() < 1e-14, "{t:?}: {r:?}");
            let analytic = aabb_distance(&V::zeros(), &V::repeat(1.0), &t, &V::repeat(1.0));
            assert!((analytic - want).abs() < 1e-15);
        }
    }

    #[test]
    fn facet_search_finds_a_rotated_prism_distance() {
        // A 12-gon prism (24 points, facet path) above a cube: the nearest
        // feature is the prism's bottom face, 0.5 above the cube's top.
        let prism = Hull::new(&prism(12, 0.5, 0.25));
        assert!(prism.edge_count() >= 36, "{} edges", prism.edge_count());
        let cube = Hull::new(&cube(1.0));
        let pose = Isometry3::new(V::new(0.1, -0.2, 1.75), V::new(0.0, 0.0, 0.3));
        let r = distance(&cube, &Isometry3::identity(), 0.0, &prism, &pose, 0.0);
        assert!(r.separated);
        assert!((r.distance - 0.5).abs() < 1e-14, "{r:?}");
        // Rounded: the radii come off, and overlap reads 0.
        let r = distance(&cube, &Isometry3::identity(), 0.2, &prism, &pose, 0.1);
        assert!((r.distance - 0.2).abs() < 1e-14);
        let deep = Isometry3::translation(0.0, 0.0, 1.0);
        let r = distance(&cube, &Isometry3::identity(), 0.0, &prism, &deep, 0.0);
        assert!(!r.separated && r.distance == 0.0);
    }

    #[test]
    fn a_small_box_inside_a_big_one_overlaps() {
        // No boundary features meet, so only the axis test can tell.
        let big = Hull::new(&prism(10, 5.0, 5.0));
        let small = Hull::new(&cube(0.1));
        let r = distance(
            &big,
            &Isometry3::identity(),
            0.0,
            &small,
            &Isometry3::translation(0.3, 0.2, 0.1),
            0.0,
        );
        assert!(!r.separated);
        assert_eq!(r.distance, 0.0);
    }

    #[test]
    fn degenerate_sets_are_exact() {
        let seg = Hull::new(&[P::new(0.0, 0.0, -1.0), P::new(0.0, 0.0, 1.0)]);
        let other = Hull::new(&[P::new(-1.0, 0.0, 0.0), P::new(1.0, 0.0, 0.0)]);
        // Skew segments 2 apart.
        let r = distance(
            &seg,
            &Isometry3::identity(),
            0.0,
            &other,
            &Isometry3::translation(0.0, 2.0, 0.5),
            0.0,
        );
        assert!((r.distance - 2.0).abs() < 1e-15, "{r:?}");
        // Crossing segments in one plane touch.
        let r = distance(
            &seg,
            &Isometry3::identity(),
            0.0,
            &other,
            &Isometry3::identity(),
            0.0,
        );
        assert_eq!(r.distance, 0.0);
        // Two points.
        let pt = Hull::new(&[P::origin()]);
        let r = distance(
            &pt,
            &Isometry3::identity(),
            0.5,
            &pt,
            &Isometry3::translation(3.0, 4.0, 0.0),
            0.5,
        );
        assert!((r.distance - 4.0).abs() < 1e-15);
    }

    #[test]
    fn paper_family_matches_its_construction() {
        // The paper's cases are built by sliding along near-point lines, so
        // a separated case's gap is known; touching and intersecting cases
        // are at distance 0. (Five pairs, small sets and the facet search
        // both: the brute force is slow unoptimised.)
        use gjk::paper::{self, Case};
        let family = paper::family();
        let hulls: Vec<Option<Hull>> = family
            .iter()
            .enumerate()
            .map(|(i, c)| {
                [0, 1, 2, 3, 6, 8]
                    .contains(&i)
                    .then(|| Hull::new(c.vertices()))
            })
            .collect();
        for case in Case::ALL {
            for c in paper::cases(case, 1, 5) {
                let (Some(ha), Some(hb)) = (&hulls[c.a], &hulls[c.b]) else {
                    continue;
                };
                let r = distance(ha, &c.pose_a, 0.0, hb, &c.pose_b, 0.0);
                match case {
                    Case::Separated => {
                        assert!(r.separated, "pair {}", c.pair);
                        assert!(
                            (r.distance - c.expected).abs() < 1e-9,
                            "pair {}: {r:?} vs {}",
                            c.pair,
                            c.expected
                        );
                    }
                    Case::Touching => assert!(r.distance < 1e-9, "pair {}: {r:?}", c.pair),
                    Case::Intersecting => {
                        assert!(!r.separated && r.distance == 0.0, "pair {}: {r:?}", c.pair);
                    }
                }
            }
        }
    }
}
