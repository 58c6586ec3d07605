//! Loads a URDF with its meshes and prints its links (vertex counts of their
//! shapes), its joint order and every link's pose at zero.
//!
//! ```sh
//! cargo run -p gjkd-model --example inspect_urdf -- robot.urdf [PACKAGE_DIR ...]
//! ```

use std::path::PathBuf;

use gjk::Shape;
use gjkd_model::{LimitMode, PackagePath, RobotModel};
use nalgebra::Isometry3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args_os().skip(1);
    let urdf = PathBuf::from(
        args.next()
            .ok_or("usage: inspect_urdf ROBOT.urdf [PACKAGE_DIR ...]")?,
    );
    let packages = PackagePath::with_env(args.map(PathBuf::from));
    let model = RobotModel::load(&urdf, &packages)?;
    let k = &model.kinematics;
    println!(
        "robot `{}`: {} links, joint order {:?}",
        model.name(),
        k.link_names().len(),
        k.joint_names()
    );
    for warning in k.warnings() {
        println!("warning: {warning}");
    }
    let mut q = vec![0.0; k.dof()];
    k.check_positions(&mut q, LimitMode::Clamp)?;
    let poses = k.link_poses(&Isometry3::identity(), &q, LimitMode::Reject)?;
    for (link, pose) in model.links.iter().zip(&poses) {
        let shape = match &link.shape {
            None => "no collision geometry".to_string(),
            Some(Shape::Convex(c)) => format!("convex, {} vertices", c.vertices().len()),
            Some(Shape::Compound(c)) => format!("compound of {} pieces", c.pieces().len()),
        };
        let t = pose.translation.vector;
        println!(
            "{:<32} {:<28} at [{:.4}, {:.4}, {:.4}]",
            link.name, shape, t.x, t.y, t.z
        );
    }
    Ok(())
}
