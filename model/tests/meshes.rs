//! Mesh files of every format, written by the test, against the vertices
//! written; hull distances against closed forms and a brute force over the
//! triangles; decomposition; every bad input.

mod files;

use gjk::{Convex, Options, Shape};
use gjkd_model::{Mesh, MeshError};
use nalgebra::{Isometry3, Point3, Vector3};

fn sorted(mut v: Vec<[f64; 3]>) -> Vec<[f64; 3]> {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v
}

fn as_arrays(points: &[Point3<f64>]) -> Vec<[f64; 3]> {
    points.iter().map(|p| [p.x, p.y, p.z]).collect()
}

fn assert_same_points(got: &[Point3<f64>], want: &[[f64; 3]], tol: f64) {
    let (g, w) = (sorted(as_arrays(got)), sorted(want.to_vec()));
    assert_eq!(g.len(), w.len(), "{g:?} vs {w:?}");
    for (a, b) in g.iter().zip(&w) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() <= tol, "{g:?} vs {w:?}");
        }
    }
}

#[test]
fn every_format_loads_the_vertices_written() {
    let dir = files::scratch("formats");
    let (v, t) = files::cuboid([0.5, 0.25, 0.125]);
    files::write_stl_binary(&dir.join("a.stl"), &v, &t);
    files::write_stl_ascii(&dir.join("b.stl"), &v, &t);
    files::write_obj(&dir.join("c.obj"), &v, &t);
    files::write_dae(&dir.join("d.dae"), &v, &t, 1.0);
    files::write_dae(&dir.join("mm.dae"), &v, &t, 0.001);
    for name in ["a.stl", "b.stl", "c.obj", "d.dae"] {
        let mesh = Mesh::load(&dir.join(name), [1.0; 3]).unwrap();
        // STL repeats each corner once per triangle: compare the hull.
        assert_same_points(&mesh.hull(), &v, 0.0);
        assert_eq!(mesh.triangles.len(), 12, "{name}");
    }
    let scaled = Mesh::load(&dir.join("c.obj"), [2.0, 1.0, -1.0]).unwrap();
    let want: Vec<[f64; 3]> = v.iter().map(|p| [2.0 * p[0], p[1], -p[2]]).collect();
    assert_same_points(&scaled.hull(), &want, 0.0);
    let mm = Mesh::load(&dir.join("mm.dae"), [1.0; 3]).unwrap();
    let want: Vec<[f64; 3]> = v.iter().map(|p| p.map(|c| c * 0.001)).collect();
    assert_same_points(&mm.hull(), &want, 1e-9);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn binary_stl_with_a_header_saying_solid_loads_as_binary() {
    // Some exporters (those of example-robot-data's bolt and solo feet,
    // for one) begin binary STL's free-text header with `solid NAME` and a
    // line break, which mesh-loader alone takes for ASCII STL and refuses.
    let dir = files::scratch("solid-header");
    let (v, t) = files::cuboid([0.5, 0.25, 0.125]);
    let plain = dir.join("plain.stl");
    files::write_stl_binary(&plain, &v, &t);
    let mut bytes = std::fs::read(&plain).unwrap();
    let mut header = format!("solid foot{}", " ".repeat(69)).into_bytes();
    header.push(b'\n');
    bytes[..80].copy_from_slice(&header);
    let named = dir.join("named.stl");
    std::fs::write(&named, &bytes).unwrap();
    let mesh = Mesh::load(&named, [1.0; 3]).unwrap();
    assert_same_points(&mesh.hull(), &v, 0.0);
    assert_eq!(mesh.triangles.len(), 12);
    // One byte more and the size no longer says binary: the ASCII error
    // stands.
    bytes.push(0);
    std::fs::write(&named, &bytes).unwrap();
    assert!(matches!(
        Mesh::load(&named, [1.0; 3]),
        Err(MeshError::Parse { .. })
    ));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn the_hull_drops_interior_vertices() {
    let (mut v, t) = files::cuboid([1.0, 1.0, 1.0]);
    v.push([0.1, -0.2, 0.3]);
    let mesh = Mesh::from_arrays(v.iter().map(|&p| p.into()).collect(), t).unwrap();
    assert_same_points(&mesh.hull(), &v[..8], 0.0);
    // A flat mesh has no hull volume: its vertices are kept as they are.
    let flat = Mesh::from_arrays(
        vec![
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    assert_eq!(flat.hull().len(), 3);
}

fn distance_to(shape: &Shape, p: Point3<f64>) -> f64 {
    let point: Shape = Convex::new(vec![Point3::origin()], 0.0).unwrap().into();
    gjk::distance(
        shape,
        &Isometry3::identity(),
        &point,
        &Isometry3::translation(p.x, p.y, p.z),
        &Options::default(),
        None,
    )
    .unwrap()
    .distance
}

/// Closest point of triangle abc to p (Ericson, Real-Time Collision
/// Detection, 5.1.5), by Voronoi regions.
fn closest_on_triangle(
    p: Vector3<f64>,
    a: Vector3<f64>,
    b: Vector3<f64>,
    c: Vector3<f64>,
) -> Vector3<f64> {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Points around the origin at distances up to `reach`, from a fixed
/// low-discrepancy sequence (no randomness to reproduce).
fn probes(reach: f64) -> Vec<Point3<f64>> {
    (1..200)
        .map(|i| {
            let f = f64::from(i);
            let u = (f * 0.618_033_988_749_895).fract() * 2.0 - 1.0;
            let phi = f * 2.399_963_229_728_653;
            let r = reach * (0.2 + (f * 0.414_213_562_373_095).fract());
            let s = (1.0 - u * u).sqrt();
            Point3::new(r * s * phi.cos(), r * s * phi.sin(), r * u)
        })
        .collect()
}

#[test]
fn hull_distances_match_the_box_closed_form() {
    let dir = files::scratch("closed-form");
    let h = [0.5, 0.25, 0.125];
    let (v, t) = files::cuboid(h);
    files::write_stl_binary(&dir.join("box.stl"), &v, &t);
    let shape: Shape = Mesh::load(&dir.join("box.stl"), [1.0; 3])
        .unwrap()
        .to_convex()
        .unwrap()
        .into();
    for p in probes(2.0) {
        let outside = Vector3::new(
            (p.x.abs() - h[0]).max(0.0),
            (p.y.abs() - h[1]).max(0.0),
            (p.z.abs() - h[2]).max(0.0),
        );
        let want = outside.norm();
        let got = distance_to(&shape, p);
        assert!(
            (got - want).abs() <= 1e-9 * (1.0 + want),
            "{p}: {got} vs {want}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn hull_distances_match_a_brute_force_over_the_triangles() {
    let dir = files::scratch("brute");
    let (v, t) = files::octahedron([1.0, 2.0, 0.5]);
    files::write_obj(&dir.join("octa.obj"), &v, &t);
    files::write_dae(&dir.join("octa.dae"), &v, &t, 1.0);
    for name in ["octa.obj", "octa.dae"] {
        let mesh = Mesh::load(&dir.join(name), [1.0; 3]).unwrap();
        let shape: Shape = mesh.to_convex().unwrap().into();
        let corners: Vec<Vector3<f64>> = v.iter().map(|&p| p.into()).collect();
        for p in probes(4.0) {
            // Outside the octahedron iff |x|/1 + |y|/2 + |z|/0.5 > 1.
            if p.x.abs() + p.y.abs() / 2.0 + p.z.abs() / 0.5 <= 1.0 {
                continue;
            }
            let want = t
                .iter()
                .map(|&[a, b, c]| {
                    let q = closest_on_triangle(
                        p.coords,
                        corners[a as usize],
                        corners[b as usize],
                        corners[c as usize],
                    );
                    (p.coords - q).norm()
                })
                .fold(f64::INFINITY, f64::min);
            let got = distance_to(&shape, p);
            assert!(
                (got - want).abs() <= 1e-9 * (1.0 + want),
                "{name} {p}: {got} vs {want}"
            );
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_decomposition_follows_a_non_convex_mesh() {
    // Two unit cubes 3 apart, as one mesh: the hull fills the gap, a
    // decomposition does not.
    let (a, ta) = files::cuboid([0.5, 0.5, 0.5]);
    let mut v: Vec<Point3<f64>> = a
        .iter()
        .map(|p| Point3::new(p[0] - 1.5, p[1], p[2]))
        .collect();
    v.extend(a.iter().map(|p| Point3::new(p[0] + 1.5, p[1], p[2])));
    let mut t = ta.clone();
    t.extend(ta.iter().map(|f| f.map(|i| i + 8)));
    let mesh = Mesh::from_arrays(v, t).unwrap();
    let hull: Shape = mesh.to_convex().unwrap().into();
    let parts = mesh.decompose(32).unwrap();
    assert_eq!(parts.pieces.len(), 2, "{parts:?}");
    assert!(
        parts.deviation.is_finite() && parts.deviation < 0.1,
        "{}",
        parts.deviation
    );
    let compound: Shape = parts.to_compound().unwrap().into();
    let gap = Point3::origin();
    assert_eq!(distance_to(&hull, gap), 0.0);
    let d = distance_to(&compound, gap);
    assert!((d - 1.0).abs() <= 1e-9 + parts.deviation, "{d}");
}

#[test]
fn bad_meshes_get_their_errors() {
    let dir = files::scratch("bad");
    assert!(matches!(
        Mesh::load(&dir.join("missing.stl"), [1.0; 3]),
        Err(MeshError::Io { .. })
    ));
    std::fs::write(dir.join("junk.dae"), "<COLLADA><oops").unwrap();
    assert!(matches!(
        Mesh::load(&dir.join("junk.dae"), [1.0; 3]),
        Err(MeshError::Parse { .. })
    ));
    std::fs::write(
        dir.join("junk.stl"),
        "solid x\nfacet normal 0 0 1\n  oops\n",
    )
    .unwrap();
    assert!(matches!(
        Mesh::load(&dir.join("junk.stl"), [1.0; 3]),
        Err(MeshError::Parse { .. })
    ));
    std::fs::write(dir.join("junk.xyz"), "1 2 3").unwrap();
    assert!(matches!(
        Mesh::load(&dir.join("junk.xyz"), [1.0; 3]),
        Err(MeshError::Parse { .. })
    ));
    let (v, t) = files::cuboid([1.0; 3]);
    files::write_obj(&dir.join("ok.obj"), &v, &t);
    assert!(matches!(
        Mesh::load(&dir.join("ok.obj"), [1.0, f64::NAN, 1.0]),
        Err(MeshError::NotFinite { .. })
    ));
    assert!(matches!(
        Mesh::load(&dir.join("ok.obj"), [1.0, 0.0, 1.0]),
        Err(MeshError::NotFinite { .. })
    ));
    files::write_obj(&dir.join("empty.obj"), &[], &[]);
    assert!(matches!(
        Mesh::load(&dir.join("empty.obj"), [1.0; 3]),
        Err(MeshError::Empty(_))
    ));
    let p = Point3::origin();
    assert!(matches!(
        Mesh::from_arrays(vec![p, p], vec![[0, 1, 2]]),
        Err(MeshError::BadIndex {
            triangle: 0,
            index: 2,
            count: 2
        })
    ));
    assert!(matches!(
        Mesh::from_arrays(vec![Point3::new(f64::INFINITY, 0.0, 0.0)], vec![]),
        Err(MeshError::NotFinite { .. })
    ));
    assert!(matches!(
        Mesh::from_arrays(vec![], vec![]),
        Err(MeshError::Empty(_))
    ));
    assert!(matches!(
        Mesh::from_arrays(vec![p], vec![]).unwrap().decompose(32),
        Err(MeshError::NoPieces)
    ));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn extensions_in_any_case_name_their_format() {
    // Exporters write `.STL`, `.Stl` or `.Obj`; the format is the
    // extension's, whatever its case (binary STL and OBJ have no marker
    // the content could be told by).
    let dir = files::scratch("extension-case");
    let (v, t) = files::cuboid([0.5, 0.25, 0.125]);
    for name in ["a.Stl", "b.sTL", "c.STL"] {
        files::write_stl_binary(&dir.join(name), &v, &t);
    }
    files::write_obj(&dir.join("d.Obj"), &v, &t);
    files::write_dae(&dir.join("e.Dae"), &v, &t, 1.0);
    for name in ["a.Stl", "b.sTL", "c.STL", "d.Obj", "e.Dae"] {
        let mesh = Mesh::load(&dir.join(name), [1.0; 3]).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_same_points(&mesh.hull(), &v, 1e-7);
        assert_eq!(mesh.triangles.len(), 12, "{name}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}
