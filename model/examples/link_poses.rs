//! Prints a URDF robot's link poses at random joint configurations within
//! its limits, one JSON object per configuration, for comparison with
//! another kinematics library: `joints` holds every moving or mimic
//! joint's position (mimic joints' computed from their leaders'), `links`
//! every link's pose as `[x, y, z, r00, r01, r02, r10, ..., r22]` (the
//! root link at the identity).
//!
//! ```sh
//! cargo run -p gjkd-model --example link_poses -- robot.urdf COUNT [SEED]
//! ```

use std::fmt::Write as _;
use std::path::Path;

use gjkd_model::kinematics::JointSource;
use gjkd_model::{Kinematics, LimitMode};
use nalgebra::Isometry3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [urdf, count, rest @ ..] = args.as_slice() else {
        return Err("usage: link_poses ROBOT.urdf COUNT [SEED]".into());
    };
    let kin = Kinematics::from_urdf_str(&std::fs::read_to_string(Path::new(urdf))?)?;
    let mut state: u64 = rest
        .first()
        .map_or(Ok(0x9e37_79b9_7f4a_7c15), |s| s.parse())?;
    let mut uniform = |lo: f64, hi: f64| {
        // xorshift: reproducible without a dependency.
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..count.parse::<usize>()? {
        let q: Vec<f64> = kin
            .moving_joints()
            .map(|j| {
                let (lo, hi) = if j.lower.is_finite() {
                    (j.lower, j.upper)
                } else {
                    (-std::f64::consts::PI, std::f64::consts::PI)
                };
                uniform(lo, hi)
            })
            .collect();
        let poses = kin.link_poses(&Isometry3::identity(), &q, LimitMode::Reject)?;
        println!("{}", configuration_json(&kin, &q, &poses));
    }
    Ok(())
}

fn configuration_json(kin: &Kinematics, q: &[f64], poses: &[Isometry3<f64>]) -> String {
    let mut joints = Vec::new();
    for joint in kin.joints() {
        let value = match joint.source {
            JointSource::Fixed => continue,
            JointSource::Moving(k) => q[k],
            JointSource::Mimic {
                index,
                multiplier,
                offset,
            } => multiplier * q[index] + offset,
        };
        joints.push(format!("{:?}: {value:?}", joint.name));
    }
    let mut links = Vec::new();
    for (name, pose) in kin.link_names().iter().zip(poses) {
        let t = pose.translation.vector;
        let r = pose.rotation.to_rotation_matrix();
        let mut numbers = format!("{:?}, {:?}, {:?}", t.x, t.y, t.z);
        for a in 0..3 {
            for b in 0..3 {
                let _ = write!(numbers, ", {:?}", r[(a, b)]);
            }
        }
        links.push(format!("{name:?}: [{numbers}]"));
    }
    format!(
        "{{\"joints\": {{{}}}, \"links\": {{{}}}}}",
        joints.join(", "),
        links.join(", ")
    )
}
