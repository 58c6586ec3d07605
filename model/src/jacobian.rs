//! Point Jacobians: how fast a point fixed on a link moves when each joint
//! moves, from the link poses forward kinematics computed.
//!
//! For a point `p` on a link, column `k` of its Jacobian is `∂p/∂q_k` in
//! world coordinates, summed over the joints between the link and the root
//! that position `k` drives: a revolute or continuous joint with world
//! axis `u` through `o` contributes `u × (p − o)`, a prismatic one `u`, and
//! a mimic joint (`multiplier * q_k + offset`) its column times
//! `multiplier`. Columns are in the order of a position array
//! ([`Kinematics::joint_names`]).
//!
//! A pose's twist (the base pose of a robot, or a free object's pose) is
//! the 6-vector `[v, ω]` in world coordinates, turning about the frame's
//! origin `c`: the pose moves to `Translation(c + v·t) · Rotation(ω·t) ·
//! Translation(−c) · pose`, so a point `p` it carries moves at
//! `v + ω × (p − c)` ([`twist_jacobian`]).
//!
//! ```
//! use gjkd_model::{Kinematics, LimitMode};
//! use nalgebra::{Isometry3, Point3, Vector3};
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
//! let poses = kin.link_poses(&Isometry3::identity(), &[0.0], LimitMode::Reject)?;
//! // A point 1 m along the tip's x axis turns about z through (1, 0, 0).
//! let mut columns = [Vector3::zeros(); 1];
//! kin.point_jacobian_into(&poses, 1, &Point3::new(2.0, 0.0, 0.0), &mut columns);
//! assert_eq!(columns[0], Vector3::new(0.0, 1.0, 0.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use nalgebra::{Isometry3, Point3, Vector3};

use crate::kinematics::{JointKind, JointSource, Kinematics};

impl Kinematics {
    /// Writes the Jacobian of `point` (world coordinates), fixed on link
    /// `link`, into `out` (one column per moving joint; joints that do not
    /// move the link get zero), at the link poses `poses`
    /// ([`Kinematics::link_poses`] at the same configuration).
    ///
    /// # Panics
    /// If `out` is not [`Kinematics::dof`] long, `link` is not a link or
    /// `poses` does not hold every link.
    pub fn point_jacobian_into(
        &self,
        poses: &[Isometry3<f64>],
        link: usize,
        point: &Point3<f64>,
        out: &mut [Vector3<f64>],
    ) {
        assert_eq!(out.len(), self.dof(), "one column per moving joint");
        out.fill(Vector3::zeros());
        self.for_each_column(poses, link, point, |k, column| out[k] += column);
    }

    /// Adds `direction · ∂point/∂q_k` to `out[k]` for every moving joint
    /// `k`: the derivative of a distance measured along `direction` when
    /// `point`, fixed on `link`, moves with the joints. No allocation; the
    /// server's gradients are made of it.
    ///
    /// # Panics
    /// As [`Kinematics::point_jacobian_into`].
    pub fn add_point_derivative(
        &self,
        poses: &[Isometry3<f64>],
        link: usize,
        point: &Point3<f64>,
        direction: &Vector3<f64>,
        out: &mut [f64],
    ) {
        assert_eq!(out.len(), self.dof(), "one entry per moving joint");
        self.for_each_column(poses, link, point, |k, column| {
            out[k] += direction.dot(&column);
        });
    }

    /// Calls `add(k, column)` for every joint between `link` and the root
    /// that moves, with its position-array entry `k` and its column (a
    /// mimic joint's scaled by its multiplier).
    fn for_each_column(
        &self,
        poses: &[Isometry3<f64>],
        link: usize,
        point: &Point3<f64>,
        mut add: impl FnMut(usize, Vector3<f64>),
    ) {
        assert!(poses.len() == self.link_names().len() && link < poses.len());
        let joints = self.joints();
        let mut at = link;
        while let Some(j) = self.parent_joint(at) {
            let joint = &joints[j];
            at = joint.parent;
            let (k, factor) = match joint.source {
                JointSource::Fixed => continue,
                JointSource::Moving(k) => (k, 1.0),
                JointSource::Mimic {
                    index, multiplier, ..
                } => (index, multiplier),
            };
            // The joint's motion leaves its axis fixed, so the child's
            // frame carries it (and, for a rotation, the point it passes
            // through) at any position.
            let child = &poses[joint.child];
            let axis = child.rotation * joint.axis.into_inner();
            let column = match joint.kind {
                JointKind::Fixed => continue,
                JointKind::Prismatic => axis,
                JointKind::Revolute | JointKind::Continuous => {
                    axis.cross(&(point - Point3::from(child.translation.vector)))
                }
            };
            add(k, column * factor);
        }
    }
}

/// The Jacobian of `point` carried by a pose whose origin is at `origin`,
/// with respect to the pose's twist `[v, ω]` (world coordinates, turning
/// about `origin`): columns `e_x, e_y, e_z` for `v` and `e_i × (p − c)` for
/// `ω`.
pub fn twist_jacobian(origin: &Point3<f64>, point: &Point3<f64>) -> [Vector3<f64>; 6] {
    let r = point - origin;
    [
        Vector3::x(),
        Vector3::y(),
        Vector3::z(),
        Vector3::x().cross(&r),
        Vector3::y().cross(&r),
        Vector3::z().cross(&r),
    ]
}

/// Adds `direction · ∂point/∂twist` to `out` (6 entries, `[v, ω]`): the
/// derivative along `direction` of `point`, carried by a pose with origin
/// `origin`, with respect to that pose's twist. `direction · (ω × r) = ω ·
/// (r × direction)`, so the `ω` part is `r × direction`.
pub fn add_twist_derivative(
    origin: &Point3<f64>,
    point: &Point3<f64>,
    direction: &Vector3<f64>,
    out: &mut [f64; 6],
) {
    let turn = (point - origin).cross(direction);
    for i in 0..3 {
        out[i] += direction[i];
        out[3 + i] += turn[i];
    }
}
