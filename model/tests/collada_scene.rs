//! COLLADA scenes placed as the format says: nested nodes composed parent
//! first, the unit applied to the nodes' translations as to the vertices,
//! `<instance_node>` followed, a geometry placed twice read twice, one that
//! no node places left out. Each against coordinates computed by hand.

mod files;

use gjkd_model::Mesh;

/// A document with one triangle geometry (`tri`: the unit points on the
/// axes) and, when `second`, another (`far`: the same triangle 100 along
/// z), in units of `meter`, with `nodes` as its visual scene and
/// `library_nodes` beside it.
fn document(meter: f64, nodes: &str, library_nodes: &str, second: bool) -> String {
    let geometry = |id: &str, z: f64| {
        format!(
            r##"<geometry id="{id}" name="{id}"><mesh>
  <source id="{id}-p"><float_array id="{id}-pa" count="9">1 0 {z} 0 1 {z} 0 0 {z1}</float_array>
    <technique_common><accessor source="#{id}-pa" count="3" stride="3">
      <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
    </accessor></technique_common></source>
  <vertices id="{id}-v"><input semantic="POSITION" source="#{id}-p"/></vertices>
  <triangles count="1"><input semantic="VERTEX" source="#{id}-v" offset="0"/><p>0 1 2</p></triangles>
</mesh></geometry>"##,
            z1 = z + 1.0
        )
    };
    let far = if second {
        geometry("far", 100.0)
    } else {
        String::new()
    };
    format!(
        r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="u" meter="{meter}"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>{tri}{far}</library_geometries>
  <library_nodes>{library_nodes}</library_nodes>
  <library_visual_scenes><visual_scene id="S">{nodes}</visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#S"/></scene>
</COLLADA>"##,
        tri = geometry("tri", 0.0),
    )
}

/// The vertices `Mesh::load` reads from `text`, sorted.
fn load(tag: &str, text: &str) -> Vec<[f64; 3]> {
    load_named(tag, "scene.dae", text)
}

/// [`load`] from a file named `name`.
fn load_named(tag: &str, name: &str, text: &str) -> Vec<[f64; 3]> {
    let dir = files::scratch(tag);
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let mut out: Vec<[f64; 3]> = Mesh::load(&path, [1.0; 3])
        .unwrap()
        .vertices
        .iter()
        .map(|p| [p.x, p.y, p.z])
        .collect();
    out.sort_by(|a, b| a.partial_cmp(b).unwrap());
    out
}

/// `got` equals `want` (sorted the same way) to single precision's
/// round-off of coordinates of size `size`.
fn assert_points(got: &[[f64; 3]], want: &[[f64; 3]], size: f64) {
    let mut want = want.to_vec();
    want.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
    for (g, w) in got.iter().zip(&want) {
        for k in 0..3 {
            assert!((g[k] - w[k]).abs() <= 1e-6 * size, "{got:?} vs {want:?}");
        }
    }
}

#[test]
fn nested_nodes_compose_parent_first() {
    // The outer node turns a quarter about z; the inner one moves 10 along
    // x and scales by 2. A vertex p goes to Rz(90°)·(10 x̂ + 2p).
    let nodes = r##"<node id="outer"><rotate>0 0 1 90</rotate>
        <node id="inner"><translate>10 0 0</translate><scale>2 2 2</scale>
          <instance_geometry url="#tri"/></node></node>"##;
    let got = load("nested", &document(1.0, nodes, "", false));
    // (x, y, z) -> (-y, x, z) after the inner transform.
    assert_points(
        &got,
        &[[0.0, 12.0, 0.0], [-2.0, 10.0, 0.0], [0.0, 10.0, 2.0]],
        12.0,
    );
}

#[test]
fn a_collada_file_without_the_extension_is_placed_the_same() {
    // Told apart by its content, as mesh-loader does.
    let nodes = r##"<node id="outer"><rotate>0 0 1 90</rotate>
        <node id="inner"><translate>10 0 0</translate><instance_geometry url="#tri"/></node></node>"##;
    let text = document(1.0, nodes, "", false);
    for name in ["scene.mesh", "scene"] {
        let got = load_named("no-extension", name, &text);
        assert_points(
            &got,
            &[[0.0, 11.0, 0.0], [-1.0, 10.0, 0.0], [0.0, 10.0, 1.0]],
            11.0,
        );
    }
}

#[test]
fn the_unit_scales_the_nodes_translations_too() {
    // Millimetres: the node's matrix moves the triangle 100 mm along x and
    // 20 mm along y; all of it is in metres afterwards.
    let nodes = r##"<node id="n"><matrix>1 0 0 100 0 1 0 20 0 0 1 0 0 0 0 1</matrix>
        <instance_geometry url="#tri"/></node>"##;
    let got = load("unit", &document(0.001, nodes, "", false));
    assert_points(
        &got,
        &[[0.101, 0.02, 0.0], [0.1, 0.021, 0.0], [0.1, 0.02, 0.001]],
        0.1,
    );
}

#[test]
fn instance_nodes_are_followed_and_geometries_placed_twice_read_twice() {
    // The library node moves its geometry 5 along y; the scene places it
    // once directly and once under a node that moves 3 along z, and places
    // the triangle itself once more, unmoved.
    let library = r##"<node id="lib"><translate>0 5 0</translate>
        <instance_geometry url="#tri"/></node>"##;
    let nodes = r##"<instance_node url="#lib"/>
        <node id="up"><translate>0 0 3</translate><instance_node url="#lib"/></node>
        <node id="plain"><instance_geometry url="#tri"/></node>"##;
    let got = load("instances", &document(1.0, nodes, library, false));
    let tri = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut want = Vec::new();
    for shift in [[0.0, 5.0, 0.0], [0.0, 5.0, 3.0], [0.0, 0.0, 0.0]] {
        want.extend(tri.map(|p| [p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]]));
    }
    assert_points(&got, &want, 10.0);
}

#[test]
fn a_geometry_no_node_places_is_left_out() {
    // `far` (100 along z) is in the library but not in the scene.
    let nodes = r##"<node id="n"><instance_geometry url="#tri"/></node>"##;
    let got = load("unplaced", &document(1.0, nodes, "", true));
    assert_points(
        &got,
        &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        1.0,
    );
}

#[test]
fn a_cycle_of_instance_nodes_is_refused_not_followed_forever() {
    // `a` holds `b`, which holds `a`: the scene is left to mesh-loader,
    // which reads the geometry without the cycle's transforms, or refuses.
    let library = r##"<node id="a"><translate>1 0 0</translate><instance_node url="#b"/></node>
        <node id="b"><instance_node url="#a"/><instance_geometry url="#tri"/></node>"##;
    let nodes = r##"<instance_node url="#a"/>"##;
    let dir = files::scratch("cycle");
    let path = dir.join("scene.dae");
    std::fs::write(&path, document(1.0, nodes, library, false)).unwrap();
    // Returns, whatever it reads: no stack overflow, no hang.
    let _ = Mesh::load(&path, [1.0; 3]);
}

#[test]
fn transforms_near_the_identity_are_applied_in_full() {
    // mesh-loader takes any transform within 0.01 of the identity in each
    // entry for the identity and drops it: a part moved 3 mm (Franka's
    // visual link4, UR5's base) or turned a third of a degree.
    let nodes = r##"<node id="n"><translate>0.003 -0.002 0.001</translate>
        <instance_geometry url="#tri"/></node>"##;
    let got = load("near-identity", &document(1.0, nodes, "", false));
    assert_points(
        &got,
        &[
            [1.003, -0.002, 0.001],
            [0.003, 0.998, 0.001],
            [0.003, -0.002, 1.001],
        ],
        1.0,
    );
    let nodes = r##"<node id="n"><rotate>0 0 1 0.3</rotate><scale>1.005 1.005 1.005</scale>
        <instance_geometry url="#tri"/></node>"##;
    let got = load("near-identity-turn", &document(1.0, nodes, "", false));
    let (s, c) = 0.3_f64.to_radians().sin_cos();
    let k = 1.005;
    assert_points(
        &got,
        &[[k * c, k * s, 0.0], [-k * s, k * c, 0.0], [0.0, 0.0, k]],
        1.0,
    );
}
