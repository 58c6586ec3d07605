//! Real robot descriptions no one on the project wrote (example-robot-data's
//! panda and UR5, vendored under `tests/data` with their collision meshes
//! and `package://` URLs): they load through the package search path, and
//! the distances from their links to obstacles at random joint
//! configurations agree with the brute-force exact reference on the
//! meshes' hulls. (Their forward kinematics is checked against the `k`
//! crate in `against_k.rs`.)

mod files;

use std::path::Path;

use files::Rng;
use gjk::{Convex, Options, Shape};
use gjkd_model::{LimitMode, Mesh, PackagePath, RobotError, RobotModel};
use gjkd_testkit::reference::{Hull, distance};
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

fn load(urdf: &Path) -> RobotModel {
    RobotModel::load(urdf, &PackagePath::new([files::real_robots()])).unwrap()
}

/// The corners of the axis-aligned box around points.
fn bounding_box(points: &[Point3<f64>]) -> [[f64; 3]; 2] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    [lo, hi]
}

#[test]
fn real_robots_load_with_their_meshes_through_the_package_path() {
    let meshes = files::real_robots().join("example-robot-data/robots");
    let cases = [
        (
            files::panda_urdf(),
            "panda",
            "panda_link3",
            meshes.join("panda_description/meshes/collision/link3.stl"),
        ),
        (
            files::ur5_urdf(),
            "ur5",
            "forearm_link",
            meshes.join("ur_description/meshes/ur5/collision/forearm.stl"),
        ),
    ];
    for (urdf, name, link, stl) in cases {
        let robot = load(&urdf);
        assert_eq!(robot.name(), name);
        let shape = &robot.links.iter().find(|l| l.name == link).unwrap().shape;
        let Some(Shape::Convex(hull)) = shape else {
            panic!("{link}: {shape:?}");
        };
        // The link's shape is the mesh file's hull: the same box around it
        // as around all the file's vertices, and fewer vertices.
        let mesh = Mesh::load(&stl, [1.0; 3]).unwrap();
        assert_eq!(
            bounding_box(hull.vertices()),
            bounding_box(&mesh.vertices),
            "{link}"
        );
        assert!(hull.vertices().len() < mesh.vertices.len());
        assert!(hull.vertices().len() > 50, "{link}");
        // Without the search path the meshes are not found, and say so.
        let lost = RobotModel::load(&urdf, &PackagePath::default()).unwrap_err();
        assert!(
            matches!(&lost, RobotError::MeshPath { message, .. } if message.contains("package://example-robot-data/")),
            "{lost}"
        );
    }
    // The panda's fingers are four boxes each; its flange and tool frame
    // have no collision elements.
    let panda = load(&files::panda_urdf());
    let shapes: Vec<(&str, usize)> = panda
        .links
        .iter()
        .map(|l| {
            let pieces = match &l.shape {
                None => 0,
                Some(Shape::Convex(_)) => 1,
                Some(Shape::Compound(c)) => c.pieces().len(),
            };
            (l.name.as_str(), pieces)
        })
        .collect();
    assert_eq!(
        shapes,
        [
            ("panda_link0", 1),
            ("panda_link1", 1),
            ("panda_link2", 1),
            ("panda_link3", 1),
            ("panda_link4", 1),
            ("panda_link5", 1),
            ("panda_link6", 1),
            ("panda_link7", 1),
            ("panda_link8", 0),
            ("panda_hand", 1),
            ("panda_hand_tcp", 0),
            ("panda_leftfinger", 4),
            ("panda_rightfinger", 4),
        ]
    );
}

/// A shape's convex pieces with their offsets, each piece's hull features
/// found once.
fn reference_pieces(shape: &Shape) -> Vec<(Isometry3<f64>, Hull, f64)> {
    let pieces: Vec<(Isometry3<f64>, &Convex)> = match shape {
        Shape::Convex(c) => vec![(Isometry3::identity(), c)],
        Shape::Compound(c) => c.pieces().iter().map(|(o, p)| (*o, p)).collect(),
    };
    pieces
        .into_iter()
        .map(|(offset, c)| (offset, Hull::new(c.vertices()), c.radius()))
        .collect()
}

/// The reference distance between two posed shapes: the least over their
/// piece pairs.
fn reference_distance(
    a: &[(Isometry3<f64>, Hull, f64)],
    pose_a: &Isometry3<f64>,
    b: &[(Isometry3<f64>, Hull, f64)],
    pose_b: &Isometry3<f64>,
) -> f64 {
    let mut best = f64::INFINITY;
    for (oa, ha, ra) in a {
        for (ob, hb, rb) in b {
            let d = distance(ha, &(pose_a * oa), *ra, hb, &(pose_b * ob), *rb);
            best = best.min(d.distance);
        }
    }
    best
}

#[test]
fn link_obstacle_distances_agree_with_the_exact_reference_on_the_hulls() {
    let obstacles: Vec<(Shape, Isometry3<f64>)> = vec![
        (
            Convex::cuboid(Vector3::new(0.15, 0.1, 0.05), 0.0)
                .unwrap()
                .into(),
            Isometry3::from_parts(
                Vector3::new(0.45, 0.1, 0.4).into(),
                UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7),
            ),
        ),
        (
            Convex::sphere(0.08).unwrap().into(),
            Isometry3::translation(-0.2, -0.35, 0.6),
        ),
        (
            Convex::cuboid(Vector3::new(1.0, 1.0, 0.02), 0.0)
                .unwrap()
                .into(),
            Isometry3::translation(0.0, 0.0, 0.0),
        ),
    ];
    let obstacle_refs: Vec<_> = obstacles.iter().map(|(s, _)| reference_pieces(s)).collect();
    let options = Options::default();
    for (urdf, seed) in [
        (files::panda_urdf(), 0x1234_5678_9abc_def1_u64),
        (files::ur5_urdf(), 0x0fed_cba9_8765_4321),
    ] {
        let robot = load(&urdf);
        let links: Vec<(usize, &Shape, Vec<_>)> = robot
            .links
            .iter()
            .enumerate()
            .filter_map(|(i, l)| l.shape.as_ref().map(|s| (i, s, reference_pieces(s))))
            .collect();
        let kin = &robot.kinematics;
        let mut rng = Rng(seed);
        let (mut apart, mut touching) = (0, 0);
        let mut worst: f64 = 0.0;
        for _ in 0..12 {
            let q: Vec<f64> = kin
                .moving_joints()
                .map(|j| rng.uniform(j.lower, j.upper))
                .collect();
            let poses = kin
                .link_poses(&Isometry3::identity(), &q, LimitMode::Reject)
                .unwrap();
            for (i, shape, pieces) in &links {
                for ((obstacle, pose), obstacle_ref) in obstacles.iter().zip(&obstacle_refs) {
                    let answer =
                        gjk::distance(shape, &poses[*i], obstacle, pose, &options, None).unwrap();
                    let want = reference_distance(pieces, &poses[*i], obstacle_ref, pose);
                    let at = format!("{}: link {} at {q:?}", urdf.display(), robot.links[*i].name);
                    assert!(
                        (answer.distance - want).abs() <= 1e-9,
                        "{at}: {} vs {want}",
                        answer.distance
                    );
                    assert!(
                        answer.lower <= want + 1e-12 && want <= answer.upper + 1e-12,
                        "{at}: [{}, {}] vs {want}",
                        answer.lower,
                        answer.upper
                    );
                    worst = worst.max((answer.distance - want).abs());
                    if want > 0.0 {
                        apart += 1
                    } else {
                        touching += 1
                    }
                }
            }
        }
        // Not vacuous: both separated and touching links were met (the
        // base stands in the floor slab).
        assert!(
            apart > 50 && touching > 0,
            "{apart} apart, {touching} touching"
        );
        eprintln!(
            "{}: worst difference {worst:e}, {apart} apart, {touching} touching",
            urdf.display()
        );
    }
}
