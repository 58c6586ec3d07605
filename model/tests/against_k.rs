//! Forward kinematics against an established library's (the `k` crate, from
//! openrr) at random configurations of the test arm, to 1e-12.

mod files;

use gjkd_model::{Kinematics, LimitMode};
use nalgebra::Isometry3;

/// A small deterministic generator (xorshift), so that failures reproduce.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn link_poses_agree_with_the_k_crate_at_random_configurations() {
    let dir = files::scratch("against-k");
    let path = dir.join("arm.urdf");
    std::fs::write(&path, files::ARM_URDF).unwrap();
    let chain = k::Chain::<f64>::from_urdf_file(&path).unwrap();
    let ours = Kinematics::from_urdf_str(files::ARM_URDF).unwrap();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let q: Vec<f64> = ours
            .moving_joints()
            .map(|j| {
                // k also holds a mimic joint to its own limits: j7 = 0.1 - j6
                // must stay in [-1, 1], so j6 in [-0.9, 1].
                if j.name == "j6" {
                    return rng.uniform(-0.9, 1.0);
                }
                let (lo, hi) = if j.lower.is_finite() {
                    (j.lower, j.upper)
                } else {
                    (-10.0, 10.0)
                };
                rng.uniform(lo, hi)
            })
            .collect();
        // k's root is the robot's root link at the identity; ours takes
        // any base, so compare at the identity.
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
    assert!(worst <= 1e-12, "largest difference {worst:e}");
    // Not vacuous: the configurations moved the links.
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
