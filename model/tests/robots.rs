//! The test arm loaded from its URDF and mesh files; SRDF pairs; every bad
//! input.

mod files;

use gjk::Shape;
use gjkd_model::{
    KinematicsError, LimitMode, MeshError, PackagePath, RobotError, RobotModel, SrdfError,
    disabled_pairs,
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
    for bad in [
        r#"radius="-0.05" length="0.2""#,
        r#"radius="0.05" length="NaN""#,
    ] {
        let cylinder =
            try_text(&text.replace(r#"<sphere radius="0.05"/>"#, &format!("<cylinder {bad}/>")));
        assert!(
            matches!(&cylinder, RobotError::Geometry { link, .. } if link == "shoulder"),
            "{cylinder}"
        );
    }
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

/// `<cylinder>` elements are exact cylinders along their element's z axis:
/// laid along the link's y axis by their origin's roll, the distance from a
/// ball past the end cap is `|y - y0| - length/2 - r_ball`, beside the
/// curved face `|(x, z) - (x0, z0)| - radius - r_ball`, to round-off.
#[test]
fn cylinder_elements_are_exact_along_their_z_axis() {
    use nalgebra::{Isometry3, Vector3};
    let urdf = r#"<robot name="can">
  <link name="rod">
    <collision>
      <origin xyz="0.5 0 0.2" rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.1" length="0.6"/></geometry>
    </collision>
    <collision>
      <geometry><box size="0.2 0.2 0.2"/></geometry>
    </collision>
  </link>
  <link name="can">
    <collision><geometry><cylinder radius="0.25" length="1.0"/></geometry></collision>
  </link>
  <joint name="fix" type="fixed"><parent link="rod"/><child link="can"/></joint>
</robot>"#;
    let model = RobotModel::from_urdf_str(urdf, None, &PackagePath::default()).unwrap();
    let Some(Shape::Compound(rod)) = &model.links[0].shape else {
        panic!("two elements make a compound");
    };
    assert_eq!(rod.pieces()[0].1.cylinder_dimensions(), Some((0.1, 0.3)));
    assert_eq!(rod.pieces()[1].1.cylinder_dimensions(), None);
    let Some(Shape::Convex(can)) = &model.links[1].shape else {
        panic!("one element at the origin is convex");
    };
    assert_eq!(can.cylinder_dimensions(), Some((0.25, 0.5)));

    let ball: Shape = gjk::Convex::sphere(0.05).unwrap().into();
    let rod = model.links[0].shape.as_ref().unwrap();
    let options = gjk::Options::default();
    // (ball centre in the link frame, exact distance)
    let cases = [
        (Vector3::new(0.5, 1.0, 0.2), 1.0 - 0.3 - 0.05),
        (Vector3::new(0.5, -0.45, 0.2), 0.45 - 0.3 - 0.05),
        (Vector3::new(0.5, 0.1, 0.9), 0.7 - 0.1 - 0.05),
        (Vector3::new(0.8, -0.2, 0.6), 0.5 - 0.1 - 0.05),
    ];
    for (at, want) in cases {
        let a = gjk::distance(
            rod,
            &Isometry3::identity(),
            &ball,
            &Isometry3::translation(at.x, at.y, at.z),
            &options,
            None,
        )
        .unwrap();
        assert!(
            (a.distance - want).abs() < 1e-12,
            "{at:?}: {} vs {want}",
            a.distance
        );
        assert!(a.lower <= want && want <= a.upper, "{at:?}");
    }
}

#[test]
fn undeclared_namespace_prefixes_load_as_ros_reads_them() {
    // Fetch's URDF names its Gazebo sensors `<sensor:camera>` with no
    // `xmlns:sensor`: ROS's parser takes the colon as part of the name,
    // and the robot must load here too, the same as without them.
    let plain = r#"<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="base"><collision><geometry><box size="0.2 0.4 0.6"/></geometry></collision></link>
  <link name="arm"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="arm"/>
    <origin xyz="0.5 0 0.25" rpy="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
GAZEBO</robot>"#;
    let gazebo = r#"<gazebo reference="arm">
    <sensor:camera name="rgb" cam:fov="50"><imageSize>192 128</imageSize></sensor:camera>
    <controller:gazebo_ros_camera name="c" plugin="libgazebo_ros_camera.so"/>
  </gazebo>
"#;
    let with = plain.replace("GAZEBO", gazebo);
    let without = plain.replace("GAZEBO", "");
    let packages = PackagePath::default();
    let a = RobotModel::from_urdf_str(&with, None, &packages).unwrap();
    let b = RobotModel::from_urdf_str(&without, None, &packages).unwrap();
    assert_eq!(a.kinematics.joint_names(), ["j"]);
    let base = nalgebra::Isometry3::translation(1.0, 2.0, 3.0);
    for q in [-0.7, 0.0, 0.9] {
        let (pa, pb) = (
            a.kinematics
                .link_poses(&base, &[q], LimitMode::Reject)
                .unwrap(),
            b.kinematics
                .link_poses(&base, &[q], LimitMode::Reject)
                .unwrap(),
        );
        assert_eq!(pa, pb);
    }
    let counts = |m: &RobotModel| -> Vec<Vec<usize>> {
        m.links
            .iter()
            .map(|l| vertex_count(l.shape.as_ref().unwrap()))
            .collect()
    };
    assert_eq!(counts(&a), counts(&b));
    // An SRDF may carry the same: its pairs are read all the same.
    let srdf =
        r#"<robot name="r"><group:x/><disable_collisions link1="base" link2="arm"/></robot>"#;
    assert_eq!(
        disabled_pairs(Some(srdf), &a.kinematics, false).unwrap(),
        [(0, 1)]
    );
}
