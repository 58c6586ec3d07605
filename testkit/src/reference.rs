//! The brute-force reference: exact distances between convex hulls of point
//! sets, owing nothing to GJK, against which gjk's answers are judged (by its
//! tests, by `gjkd bench tradeoff`).
//!
//! The distance between two disjoint convex polytopes is attained between a
//! pair of boundary features: vertex–vertex, vertex–edge, edge–edge or
//! vertex–triangle. A [`Hull`] holds (a superset of) those features of one
//! set: for small sets (at most [`SMALL`] points, which covers every
//! degenerate set: points, segments, flat polygons, duplicated vertices)
//! every vertex pair and triple, since every triple spans a triangle inside
//! the hull and the hull's boundary is covered by such triangles; for larger
//! sets the facets found by a search over vertex triples whose plane has all
//! vertices on one side, each facet's vertices ordered round it giving its
//! edges and a fan of triangles. Features that lie inside the hull do no
//! harm: they are points of the hull, so they can tie the nearest pair but
//! never beat it. The nearest feature pair is the exact distance when the
//! hulls are disjoint, and an upper bound always.
//!
//! Whether the hulls are disjoint is decided separately, by separating axes:
//! the direction between the nearest feature points (which separates
//! whenever the hulls are disjoint, collinear and coplanar sets included),
//! else the triangle or facet normals of each hull, the cross products of
//! edge pairs and the vertex–edge normals. Near contact, where no axis
//! decides, exact orientation predicates (`robust`) ask whether an edge of
//! one hull meets a triangle of the other.

use nalgebra::{Isometry3, Point3, Vector3};

/// A point in three-space.
pub type P = Point3<f64>;
/// A vector in three-space.
pub type V = Vector3<f64>;

/// Sets of at most this many points use every pair and triple as features;
/// larger ones search their facets, since all triples would cost `n³`.
pub const SMALL: usize = 16;

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
/// The weights come from the 2 × 2 normal equations with the vertex nearest
/// `p` as the base, which keeps the sum's cancellation small; the edges are
/// candidates too (a degenerate triangle is the union of its edges), and the
/// nearest candidate is returned.
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
        // Gram system's conditioning multiplies the weights' round-off, and
        // the residual's own solve removes what it adds.
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

fn triples(n: usize) -> impl Iterator<Item = (usize, usize, usize)> {
    (0..n).flat_map(move |i| (i + 1..n).flat_map(move |j| (j + 1..n).map(move |k| (i, j, k))))
}

fn pairs(n: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..n).flat_map(move |i| (i + 1..n).map(move |j| (i, j)))
}

/// The boundary features of the convex hull of a point set.
#[derive(Clone, Debug)]
pub struct Hull {
    points: Vec<P>,
    edges: Vec<[usize; 2]>,
    triangles: Vec<[usize; 3]>,
    /// Candidate separating axes, not necessarily unit: every triple's
    /// normal for small sets, the outward facet normals for larger ones.
    normals: Vec<V>,
}

impl Hull {
    /// The features of the hull of `points` (not empty).
    ///
    /// # Panics
    /// When `points` is empty.
    pub fn new(points: &[P]) -> Hull {
        assert!(!points.is_empty(), "a hull needs a point");
        if points.len() <= SMALL {
            Hull::brute(points)
        } else {
            Hull::facets(points)
        }
    }

    /// Every pair and triple: exact for any small set, degenerate or not.
    fn brute(points: &[P]) -> Hull {
        let n = points.len();
        Hull {
            points: points.to_vec(),
            edges: pairs(n).map(|(i, j)| [i, j]).collect(),
            triangles: triples(n).map(|(i, j, k)| [i, j, k]).collect(),
            normals: triples(n)
                .map(|(i, j, k)| (points[j] - points[i]).cross(&(points[k] - points[i])))
                .collect(),
        }
    }

    /// The facets of a larger set, found among its vertex triples.
    fn facets(points: &[P]) -> Hull {
        let n = points.len();
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
        };
        for (i, j, k) in triples(n) {
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
        if planes.is_empty() {
            // Collinear (or coincident) points: the hull is the segment
            // between the two points farthest apart.
            let ends = pairs(n)
                .fold((-1.0, [0, 0]), |(best, ends), (i, j)| {
                    let d = (points[j] - points[i]).norm_squared();
                    if d > best { (d, [i, j]) } else { (best, ends) }
                })
                .1;
            hull.edges.push(ends);
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

    /// The same hull moved by `pose`: its points and normals, with the
    /// features found in the body frame.
    pub fn posed(&self, pose: &Isometry3<f64>) -> Hull {
        Hull {
            points: self.points.iter().map(|p| pose * p).collect(),
            edges: self.edges.clone(),
            triangles: self.triangles.clone(),
            normals: self.normals.iter().map(|n| pose.rotation * n).collect(),
        }
    }

    /// The points of the set.
    pub fn points(&self) -> &[P] {
        &self.points
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

/// The result of the brute force.
#[derive(Clone, Copy, Debug)]
pub struct HullDistance {
    /// Distance between the hulls (0 when they touch or intersect).
    pub distance: f64,
    /// Nearest candidate point on the first hull (meaningful when separated).
    pub point_p: P,
    /// Nearest candidate point on the second hull (meaningful when separated).
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

/// A bounding ball of some points: centre and radius (slightly padded).
fn ball(points: &[&P]) -> (P, f64) {
    let n = points.len() as f64;
    let c = P::from(points.iter().fold(V::zeros(), |acc, x| acc + x.coords) / n);
    let r = points.iter().map(|x| (*x - c).norm()).fold(0.0, f64::max);
    (c, r * (1.0 + 1e-12))
}

/// The features of a hull with their bounding balls.
struct Balls {
    edges: Vec<(usize, usize, P, f64)>,
    triangles: Vec<(usize, usize, usize, P, f64)>,
}

impl Balls {
    fn of(h: &Hull) -> Balls {
        let s = &h.points;
        Balls {
            edges: h
                .edges
                .iter()
                .map(|&[i, j]| {
                    let (c, r) = ball(&[&s[i], &s[j]]);
                    (i, j, c, r)
                })
                .collect(),
            triangles: h
                .triangles
                .iter()
                .map(|&[i, j, k]| {
                    let (c, r) = ball(&[&s[i], &s[j], &s[k]]);
                    (i, j, k, c, r)
                })
                .collect(),
        }
    }
}

/// Smallest distance over all feature candidates, with its witness points.
/// Candidates whose bounding balls are already farther apart than the best
/// distance so far are skipped: they cannot be nearer.
fn candidate_distance(hp: &Hull, hq: &Hull) -> (f64, P, P) {
    let (p, q) = (&hp.points[..], &hq.points[..]);
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
    let (bp, bq) = (Balls::of(hp), Balls::of(hq));
    for x in p {
        for y in q {
            consider(&mut best, *x, *y);
        }
    }
    // Point-segment both ways: needed when a set has exactly two points.
    for x in p {
        for &(i, j, ref c, r) in &bq.edges {
            if !hopeless(&best, x, 0.0, c, r) {
                consider(&mut best, *x, closest_on_segment(x, &q[i], &q[j]));
            }
        }
    }
    for y in q {
        for &(i, j, ref c, r) in &bp.edges {
            if !hopeless(&best, y, 0.0, c, r) {
                consider(&mut best, closest_on_segment(y, &p[i], &p[j]), *y);
            }
        }
    }
    for &(i, j, ref c1, r1) in &bp.edges {
        for &(k, l, ref c2, r2) in &bq.edges {
            if !hopeless(&best, c1, r1, c2, r2) {
                let (x, y) = closest_segment_segment(&p[i], &p[j], &q[k], &q[l]);
                consider(&mut best, x, y);
            }
        }
    }
    for x in p {
        for &(i, j, k, ref c, r) in &bq.triangles {
            if !hopeless(&best, x, 0.0, c, r) {
                consider(&mut best, *x, closest_on_triangle(x, &q[i], &q[j], &q[k]));
            }
        }
    }
    for y in q {
        for &(i, j, k, ref c, r) in &bp.triangles {
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
/// the normals of each hull, cross products of edge pairs and vertex-edge
/// normals, plus an optional extra axis.
fn best_separation(hp: &Hull, hq: &Hull, witness_axis: Option<V>) -> f64 {
    let (p, q) = (&hp.points[..], &hq.points[..]);
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
    for n in hp.normals.iter().chain(&hq.normals) {
        try_axis(*n);
    }
    for &[i, j] in &hp.edges {
        for &[k, l] in &hq.edges {
            try_axis((p[j] - p[i]).cross(&(q[l] - q[k])));
        }
    }
    // Vertex against edge: the part of (vertex - edge start) across the
    // edge, built by cross products so that it stays square to the edge to
    // round-off. The witness axis of a vertex very near an edge is off by
    // about ε over their distance, which tilts the edge's projection by as
    // much: only an axis square to the edge by construction shows the gap.
    // In one plane, these are the in-plane edge normals too.
    for (a, hb) in [(p, hq), (q, hp)] {
        let b = &hb.points;
        for x in a {
            for &[k, l] in &hb.edges {
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
///
/// # Panics
/// When a set is empty, or when the reference cannot decide (an axis gap
/// beyond the nearest features, or hulls neither apart nor overlapping by
/// more than round-off): a bug of the reference, never a property of gjk.
pub fn hull_distance(p: &[P], q: &[P]) -> HullDistance {
    assert!(!p.is_empty() && !q.is_empty());
    hulls_distance(&Hull::new(p), &Hull::new(q))
}

/// Distance between two hulls given in one frame, as [`hull_distance`].
///
/// # Panics
/// As [`hull_distance`].
pub fn hulls_distance(hp: &Hull, hq: &Hull) -> HullDistance {
    let (p, q) = (&hp.points[..], &hq.points[..]);
    let (candidate, x, y) = candidate_distance(hp, hq);
    // Span of the sets (not their position): round-off of differences.
    let span = {
        let mut lo = p[0].coords;
        let mut hi = p[0].coords;
        for v in p.iter().chain(q) {
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
        best_separation(hp, hq, (candidate > 0.0).then(|| y - x))
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
    let mag = extent(&[p, q]);
    let pierced = candidate > 0.0
        && witness_gap < candidate - 1e-13 * (mag * span / candidate + mag)
        && best_gap <= 1e-13 * span;
    let distance = if best_gap > 1e-13 * span {
        assert!(
            best_gap <= candidate + 1e-9 * span + 64.0 * f64::EPSILON * mag,
            "reference inconsistent: gap {best_gap} > candidate {candidate}\nP = {p:?}\nQ = {q:?}"
        );
        candidate
    } else if best_gap < -1e-6 * span || pierced || pierces_exactly(hp, hq) {
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

/// Whether an edge of one hull meets a triangle of the other, decided by
/// exact orientation predicates. Near contact, where no axis gap decides
/// and the nearest features lie a few ulps apart in f64, the hulls meet
/// exactly when such a pair meets, unless one hull holds the other whole,
/// which the axis gaps show clearly.
fn pierces_exactly(hp: &Hull, hq: &Hull) -> bool {
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
    [(hp, hq), (hq, hp)].iter().any(|(hs, ht)| {
        let (s, t) = (&hs.points, &ht.points);
        hs.edges.iter().any(|&[i, j]| {
            ht.triangles
                .iter()
                .any(|&[k, l, m]| meets(&s[i], &s[j], &t[k], &t[l], &t[m]))
        })
    })
}

/// The reference answer for one posed pair of rounded hulls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Distance between the rounded hulls, 0 when they touch or overlap.
    pub distance: f64,
    /// Whether a separating axis with a positive gap proved the cores apart.
    pub separated: bool,
}

/// Distance between hull `ha` at `pose_a` grown by `ra` and hull `hb` at
/// `pose_b` grown by `rb`; the hulls' features are found once, in their
/// body frames, and reused at every pose.
///
/// # Panics
/// As [`hull_distance`].
pub fn distance(
    ha: &Hull,
    pose_a: &Isometry3<f64>,
    ra: f64,
    hb: &Hull,
    pose_b: &Isometry3<f64>,
    rb: f64,
) -> Reference {
    let core = hulls_distance(&ha.posed(pose_a), &hb.posed(pose_b));
    Reference {
        distance: (core.distance - ra - rb).max(0.0),
        separated: core.separated,
    }
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

/// Distance between two axis-aligned boxes given by their centres and half
/// extents (a half extent may be 0: flat boxes, segments and points).
pub fn aabb_distance(ca: &V, ha: &V, cb: &V, hb: &V) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        // The difference of nearby centres is exact (Sterbenz), and so is the
        // sum of equal or nicely scaled half extents: then the gap is formed
        // with one rounding, where subtracting the extents one by one would
        // round at the centres' scale first.
        let g = (cb[i] - ca[i]).abs() - (ha[i] + hb[i]);
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
