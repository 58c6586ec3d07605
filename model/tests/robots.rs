//! The test arm loaded from its URDF and mesh files; SRDF pairs; every bad
//! input.

mod files;

use gjk::Shape;
use gjkd_model::{
    KinematicsError, MeshError, PackagePath, RobotError, RobotModel, SrdfError, disabled_pairs,
};

fn load(tag: &str) -> (std::path::PathBuf, RobotModel) {
    let dir = files::scratch(tag);
    let (urdf, pkg) = files::write_arm(&dir);
    let model = RobotModel::load(&urdf, &PackagePath::new([pkg])).unwrap();
    (dir, model)
}

fn vertex_count(shape: &Shape) -> Vec<usize> {
    match shape {
        Shape::Convex(c) => vec![c.vertices().len()],
        Shape::Compound(c) => c.pieces().iter().map(|(_, p)| p.vertices().len()).collect(),
    }
}

#[test]
fn the_arm_loads_with_one_shape_per_link() {
    let (dir, model) = load("arm");
    assert_eq!(model.name(), "arm");
    let counts: Vec<(String, Vec<usize>)> = model
        .links
        .iter()
        .map(|l| (l.name.clone(), vertex_count(l.shape.as_ref().unwrap())))
        .collect();
    let want = [
        ("base", vec![8]),
        // A sphere at an offset: a compound of one point grown by a radius.
        ("shoulder", vec![1]),
        ("upper", vec![8]),
        ("slider", vec![6]),
        ("wrist", vec![8]),
        ("hand", vec![8, 1]),
        ("finger_l", vec![8]),
        ("finger_r", vec![8]),
    ];
    let want: Vec<(String, Vec<usize>)> = want
        .iter()
        .map(|(n, c)| (n.to_string(), c.clone()))
        .collect();
    assert_eq!(counts, want);
    // The slider's mesh is scaled by 2 along x; the hand's COLLADA is in mm.
    let Some(Shape::Convex(slider)) = &model.links[3].shape else {
        panic!("slider is one convex piece")
    };
    let max_x = slider
        .vertices()
        .iter()
        .map(|p| p.x)
        .fold(f64::MIN, f64::max);
    assert!((max_x - 0.1).abs() < 1e-7, "{max_x}");
    let Some(Shape::Compound(hand)) = &model.links[5].shape else {
        panic!("hand is a compound")
    };
    let max_x = hand.pieces()[0]
        .1
        .vertices()
        .iter()
        .map(|p| p.x)
        .fold(f64::MIN, f64::max);
    assert!((max_x - 0.03).abs() < 1e-7, "{max_x}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn srdf_pairs_and_adjacent_links_are_allowed_pairs() {
    let (dir, model) = load("srdf");
    let srdf = r#"<robot name="arm">
        <disable_collisions link1="finger_l" link2="finger_r" reason="Never"/>
        <disable_collisions link1="hand" link2="base" reason="Never"/>
    </robot>"#;
    let k = &model.kinematics;
    let only = disabled_pairs(Some(srdf), k, false).unwrap();
    assert_eq!(only, [(0, 5), (6, 7)]);
    let all = disabled_pairs(Some(srdf), k, true).unwrap();
    assert_eq!(
        all,
        [
            (0, 1),
            (0, 5),
            (1, 2),
            (2, 3),
            (3, 4),
            (4, 5),
            (5, 6),
            (5, 7),
            (6, 7)
        ]
    );
    assert_eq!(
        disabled_pairs(
            Some(r#"<robot><disable_collisions link1="hand" link2="tail"/></robot>"#),
            k,
            true
        ),
        Err(SrdfError::UnknownLink("tail".into()))
    );
    assert_eq!(
        disabled_pairs(
            Some(r#"<robot><disable_collisions link1="hand"/></robot>"#),
            k,
            true
        ),
        Err(SrdfError::MissingLink)
    );
    assert!(matches!(
        disabled_pairs(Some("<robot"), k, true),
        Err(SrdfError::Malformed(_))
    ));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_robots_get_their_errors() {
    let dir = files::scratch("bad-robots");
    let (urdf, pkg) = files::write_arm(&dir);
    let packages = PackagePath::new([pkg]);
    let text = std::fs::read_to_string(&urdf).unwrap();
    let base = Some(dir.as_path());
    let try_text = |t: &str| RobotModel::from_urdf_str(t, base, &packages).unwrap_err();

    assert!(matches!(
        RobotModel::load(&dir.join("nope.urdf"), &packages),
        Err(RobotError::Io { .. })
    ));
    assert!(matches!(
        try_text("<robot name='x'><link"),
        RobotError::Kinematics(KinematicsError::Malformed(_))
    ));
    let missing = try_text(&text.replace("meshes/wrist.obj", "meshes/gone.obj"));
    assert!(
        matches!(&missing, RobotError::Mesh { link, source: MeshError::Io { .. } } if link == "wrist"),
        "{missing}"
    );
    let no_package = RobotModel::from_urdf_str(&text, base, &PackagePath::default()).unwrap_err();
    assert!(matches!(&no_package, RobotError::MeshPath { link, .. } if link == "slider"));
    let cylinder = try_text(&text.replace(
        r#"<sphere radius="0.05"/>"#,
        r#"<cylinder radius="0.05" length="0.2"/>"#,
    ));
    assert!(matches!(&cylinder, RobotError::Cylinder { link } if link == "shoulder"));
    assert!(cylinder.to_string().contains("not supported"), "{cylinder}");
    let negative =
        try_text(&text.replace(r#"<sphere radius="0.05"/>"#, r#"<sphere radius="-1"/>"#));
    assert!(matches!(&negative, RobotError::Geometry { link, .. } if link == "shoulder"));
    let nan_box = try_text(&text.replace(r#"size="0.4 0.4 0.2""#, r#"size="0.4 NaN 0.2""#));
    assert!(
        matches!(&nan_box, RobotError::Geometry { link, .. } if link == "base"),
        "{nan_box}"
    );
    let unknown = try_text(&text.replace(r#"<child link="wrist"/>"#, r#"<child link="wrist2"/>"#));
    assert!(matches!(
        unknown,
        RobotError::Kinematics(KinematicsError::UnknownLink { link, .. }) if link == "wrist2"
    ));
    std::fs::remove_dir_all(dir).unwrap();
}
