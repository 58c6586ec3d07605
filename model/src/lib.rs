//! # gjkd-model
//!
//! Robots and meshes as gjkd's users already have them, turned into what
//! gjkd needs: convex vertex sets, compounds of them, and link poses.
//!
//! - [`mesh`]: triangle meshes from binary or ASCII STL, OBJ and COLLADA
//!   (`.dae`) files or from arrays, scaled; their convex hull (a mesh's hull
//!   never reports more distance than the mesh itself), or a convex
//!   decomposition into pieces with its largest deviation from the mesh.
//! - [`robot`]: a robot from URDF: one shape per link (its collision
//!   elements: boxes, spheres, capsules, meshes, each with its origin; several
//!   make a compound), mesh paths resolved through a [`PackagePath`].
//! - [`kinematics`]: forward kinematics (fixed, revolute, continuous and
//!   prismatic joints, limits checked or clamped, mimic joints followed).
//! - [`jacobian`]: point Jacobians of links (joint columns in the order
//!   of a position array, mimic joints folded into their leader) and of a
//!   pose's twist.
//! - [`srdf`]: an SRDF's `disable_collisions` pairs.
//!
//! Pure Rust, no IPC: the server and the client both use it, so that the
//! joint order a client sends is the one the server reads.
//!
//! ```
//! use gjkd_model::{Kinematics, LimitMode};
//! use nalgebra::{Isometry3, Vector3};
//!
//! let urdf = r#"<robot name="r">
//!   <link name="base"/><link name="tip"/>
//!   <joint name="j" type="revolute">
//!     <parent link="base"/><child link="tip"/>
//!     <origin xyz="1 0 0"/><axis xyz="0 0 1"/>
//!     <limit lower="-1" upper="1" effort="1" velocity="1"/>
//!   </joint>
//! </robot>"#;
//! let kin = Kinematics::from_urdf_str(urdf)?;
//! assert_eq!(kin.joint_names(), ["j"]);
//! let poses = kin.link_poses(&Isometry3::identity(), &[0.5], LimitMode::Reject)?;
//! assert!((poses[1].translation.vector - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-15);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod collada;
pub mod jacobian;
pub mod kinematics;
mod kinematics_error;
pub mod mesh;
pub mod paths;
pub mod robot;
pub mod srdf;
mod urdf;
mod xml_prefixes;

pub use jacobian::{add_twist_derivative, twist_jacobian};
pub use kinematics::{
    JointError, JointInfo, JointKind, JointSource, Kinematics, KinematicsError, LimitMode,
};
pub use mesh::{Decomposition, Mesh, MeshError};
pub use paths::{PACKAGE_PATH_ENV, PackagePath};
pub use robot::{CylinderError, LinkModel, RobotError, RobotModel, cylinder};
pub use srdf::{SrdfError, disabled_pairs};
