//! Forward kinematics against an established library's (the `k` crate, from
//! openrr) at random configurations, to 1e-12: the test arm, and two real
//! robots no one on the project wrote (example-robot-data's panda, whose
//! finger joints mimic, and UR5).

mod files;

use std::path::Path;

use files::Rng;
use gjkd_model::{JointInfo, Kinematics, LimitMode};
use nalgebra::Isometry3;

/// The largest difference, over `samples` random configurations, between
/// our link poses and k's (every rotation matrix entry and translation
/// coordinate of every joint's child link). `position` draws a joint's
/// position; k's root is the robot's root link at the identity, and so is
/// ours here.
fn worst_difference_from_k(
    urdf: &Path,
    samples: usize,
    mut position: impl FnMut(&JointInfo) -> f64,
) -> f64 {
    let chain = k::Chain::<f64>::from_urdf_file(urdf).unwrap();
    let ours = Kinematics::from_urdf_str(&std::fs::read_to_string(urdf).unwrap()).unwrap();
    let mut worst: f64 = 0.0;
    for _ in 0..samples {
        let q: Vec<f64> = ours.moving_joints().map(&mut position).collect();
        let poses = ours
            .link_poses(&Isometry3::identity(), &q, LimitMode::Reject)
            .unwrap();
        for (j, &qj) in ours.moving_joints().zip(&q) {
            chain.find(&j.name).unwrap().set_joint_position(qj).unwrap();
        }
        chain.update_transforms();
        for joint in ours.joints() {
            let theirs = chain.find(&joint.name).unwrap().world_transform().unwrap();
            let t = theirs.translation.vector;
            let r = theirs.rotation.to_rotation_matrix();
            let mine = &poses[joint.child];
            let mr = mine.rotation.to_rotation_matrix();
            for a in 0..3 {
                worst = worst.max((mine.translation.vector[a] - t[a]).abs());
                for b in 0..3 {
                    worst = worst.max((mr[(a, b)] - r[(a, b)]).abs());
                }
            }
        }
    }
    worst
}

/// A position anywhere within the joint's limits (a continuous joint's
/// within ten radians either way).
fn within_limits(rng: &mut Rng, j: &JointInfo) -> f64 {
    let (lo, hi) = if j.lower.is_finite() {
        (j.lower, j.upper)
    } else {
        (-10.0, 10.0)
    };
    rng.uniform(lo, hi)
}

#[test]
fn link_poses_agree_with_the_k_crate_at_random_configurations() {
    let dir = files::scratch("against-k");
    let path = dir.join("arm.urdf");
    std::fs::write(&path, files::ARM_URDF).unwrap();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let worst = worst_difference_from_k(&path, 200, |j| {
        // k also holds a mimic joint to its own limits: j7 = 0.1 - j6
        // must stay in [-1, 1], so j6 in [-0.9, 1].
        if j.name == "j6" {
            return rng.uniform(-0.9, 1.0);
        }
        within_limits(&mut rng, j)
    });
    assert!(worst <= 1e-12, "largest difference {worst:e}");
    // Not vacuous: the configurations moved the links.
    let ours = Kinematics::from_urdf_str(files::ARM_URDF).unwrap();
    let moved = ours
        .link_poses(
            &Isometry3::identity(),
            &[1.0, 1.0, 0.1, 1.0, 0.5],
            LimitMode::Reject,
        )
        .unwrap();
    let zero = ours
        .link_poses(&Isometry3::identity(), &[0.0; 5], LimitMode::Reject)
        .unwrap();
    assert!((moved[7].translation.vector - zero[7].translation.vector).norm() > 0.1);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn real_robots_link_poses_agree_with_the_k_crate() {
    // The panda's second finger mimics the first with multiplier 1: any
    // position within the first's limits is within its own.
    for (urdf, dof, seed) in [
        (files::panda_urdf(), 8, 0x2545_f491_4f6c_dd1d),
        (files::ur5_urdf(), 6, 0x5851_f42d_4c95_7f2d),
    ] {
        let mut rng = Rng(seed);
        let ours = Kinematics::from_urdf_str(&std::fs::read_to_string(&urdf).unwrap()).unwrap();
        assert_eq!(ours.dof(), dof, "{}", urdf.display());
        let worst = worst_difference_from_k(&urdf, 300, |j| within_limits(&mut rng, j));
        assert!(
            worst <= 1e-12,
            "{}: largest difference {worst:e}",
            urdf.display()
        );
        eprintln!("{}: largest difference from k {worst:e}", urdf.display());
    }
}
