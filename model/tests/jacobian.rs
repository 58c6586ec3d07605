//! Point Jacobians against central finite differences of forward
//! kinematics, on random configurations of the test arm (prismatic,
//! continuous, fixed and mimic joints) and the vendored Panda (a mimic
//! finger) and UR5, and the base twist's Jacobian against finite
//! differences of a turned and shifted base.

mod files;

use files::Rng;
use gjkd_model::{Kinematics, LimitMode, twist_jacobian};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// Central-difference step: its truncation error (h² · |p'''|) and its
/// round-off (1e-16 / h) are both far below the 1e-6 judged.
const H: f64 = 1e-6;

fn kinematics(path: &std::path::Path) -> Kinematics {
    Kinematics::from_urdf_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A random configuration inside the limits (continuous joints in
/// [-π, π]), kept `H` away from them so that the differences stay inside.
fn random_positions(kin: &Kinematics, rng: &mut Rng) -> Vec<f64> {
    kin.moving_joints()
        .map(|j| {
            let lo = j.lower.max(-std::f64::consts::PI) + H;
            let hi = j.upper.min(std::f64::consts::PI) - H;
            rng.uniform(lo, hi)
        })
        .collect()
}

fn random_base(rng: &mut Rng) -> Isometry3<f64> {
    let axis = Vector3::new(
        rng.uniform(-1.0, 1.0),
        rng.uniform(-1.0, 1.0),
        rng.uniform(-1.0, 1.0),
    );
    Isometry3::from_parts(
        Translation3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        ),
        UnitQuaternion::from_scaled_axis(axis),
    )
}

fn assert_close(got: &Vector3<f64>, want: &Vector3<f64>, what: &str) {
    let error = (got - want).norm();
    assert!(
        error <= 1e-6 * want.norm().max(1e-3),
        "{what}: {got:?} against {want:?} (error {error:e})"
    );
}

/// Every link's Jacobian at a few points on it against finite differences
/// of the points' world positions, for several random configurations.
fn check_robot(kin: &Kinematics, seed: u64) {
    let mut rng = Rng(seed);
    let mut columns = vec![Vector3::zeros(); kin.dof()];
    let mut along = vec![0.0; kin.dof()];
    for _ in 0..8 {
        let base = random_base(&mut rng);
        let q = random_positions(kin, &mut rng);
        let poses = kin.link_poses(&base, &q, LimitMode::Reject).unwrap();
        for link in 0..kin.link_names().len() {
            let local = Point3::new(
                rng.uniform(-0.2, 0.2),
                rng.uniform(-0.2, 0.2),
                rng.uniform(-0.2, 0.2),
            );
            let point = poses[link] * local;
            kin.point_jacobian_into(&poses, link, &point, &mut columns);
            let direction = Vector3::new(0.3, -0.5, 0.8);
            along.fill(0.0);
            kin.add_point_derivative(&poses, link, &point, &direction, &mut along);
            for k in 0..kin.dof() {
                let at = |dq: f64| {
                    let mut moved = q.clone();
                    moved[k] += dq;
                    kin.link_poses(&base, &moved, LimitMode::Reject).unwrap()[link] * local
                };
                let want = (at(H) - at(-H)) / (2.0 * H);
                let what = format!(
                    "{} link {} joint {k}",
                    kin.robot_name(),
                    kin.link_names()[link]
                );
                assert_close(&columns[k], &want, &what);
                assert!(
                    (along[k] - direction.dot(&want)).abs() <= 1e-6 * want.norm().max(1e-3),
                    "{what}"
                );
            }
        }
    }
}

#[test]
fn point_jacobians_of_the_test_arm_match_finite_differences() {
    let kin = Kinematics::from_urdf_str(files::ARM_URDF).unwrap();
    // The mimic finger follows j6 with multiplier -1: its column lands on j6.
    assert_eq!(kin.dof(), 5);
    check_robot(&kin, 0x5eeda1);
}

#[test]
fn point_jacobians_of_the_panda_and_ur5_match_finite_differences() {
    check_robot(&kinematics(&files::panda_urdf()), 0x9a4da);
    check_robot(&kinematics(&files::ur5_urdf()), 0x05u64 + 7);
}

#[test]
fn a_link_no_joint_moves_has_a_zero_jacobian() {
    let kin = Kinematics::from_urdf_str(files::ARM_URDF).unwrap();
    let poses = kin
        .link_poses(
            &Isometry3::identity(),
            &[0.0, 0.0, 0.1, 0.0, 0.0],
            LimitMode::Reject,
        )
        .unwrap();
    let mut columns = vec![Vector3::new(1.0, 1.0, 1.0); kin.dof()];
    kin.point_jacobian_into(
        &poses,
        kin.root(),
        &Point3::new(1.0, 2.0, 3.0),
        &mut columns,
    );
    assert!(columns.iter().all(|c| *c == Vector3::zeros()));
    // The shoulder moves with j1 alone: u × (p − o) with u = z, o = (0, 0, 0.1).
    kin.point_jacobian_into(&poses, 1, &Point3::new(1.0, 0.0, 0.1), &mut columns);
    assert_eq!(columns[0], Vector3::new(0.0, 1.0, 0.0));
    assert!(columns[1..].iter().all(|c| *c == Vector3::zeros()));
}

#[test]
fn the_twist_jacobian_matches_a_turned_and_shifted_pose() {
    let mut rng = Rng(77);
    for _ in 0..20 {
        let pose = random_base(&mut rng);
        let local = Point3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        let origin = Point3::from(pose.translation.vector);
        let columns = twist_jacobian(&origin, &(pose * local));
        for (i, column) in columns.iter().enumerate() {
            // The twist convention: Translation(c + v t) · Rotation(ω t) · Translation(−c) · pose.
            let moved = |t: f64| {
                let mut twist = [0.0; 6];
                twist[i] = t;
                let v = Vector3::new(twist[0], twist[1], twist[2]);
                let w = Vector3::new(twist[3], twist[4], twist[5]);
                let turned = Translation3::from(origin.coords + v)
                    * UnitQuaternion::from_scaled_axis(w)
                    * Translation3::from(-origin.coords)
                    * pose;
                turned * local
            };
            let want = (moved(H) - moved(-H)) / (2.0 * H);
            assert_close(column, &want, &format!("twist column {i}"));
        }
    }
}
