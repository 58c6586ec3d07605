//! The subalgorithm against Gram determinants, exact volumes and direct
//! constructions.

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
