//! Forward kinematics of a URDF robot: the pose of every link from a base
//! pose and the joint positions.
//!
//! The **joint order** of a position array is the order of the URDF's
//! `<joint>` elements, keeping only the *moving* ones: revolute, continuous
//! and prismatic joints that do not mimic another. Fixed joints take no
//! position; a mimic joint follows its leader (`multiplier * leader +
//! offset`, chains of mimics followed). A mimic joint naming a leader that
//! does not exist is an error in the URDF, but one that real descriptions
//! make: like MoveIt, gjkd logs it (and lists it in
//! [`Kinematics::warnings`]) and moves that joint on its own, so it takes
//! its place in the position array. [`Kinematics::joint_names`] lists the
//! order.
//!
//! A link's pose is its parent's pose, times the joint's origin, times the
//! joint's motion (a rotation about its axis by the position in radians, or
//! a translation along it by the position in metres).

use std::collections::HashMap;

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

pub use crate::kinematics_error::KinematicsError;

/// What can be wrong with a request to move a robot.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointError {
    /// The array is not one position per moving joint.
    #[error("expected {expected} joint positions, got {got}")]
    WrongCount {
        /// Moving joints.
        expected: usize,
        /// Positions given.
        got: usize,
    },
    /// No moving joint has this name (fixed and mimic joints take no
    /// position).
    #[error("no moving joint is named `{0}`")]
    UnknownJoint(String),
    /// A position is NaN or infinite.
    #[error("joint `{0}`: position is not finite")]
    NotFinite(String),
    /// A position is outside the joint's limits (with [`LimitMode::Reject`]).
    #[error("joint `{joint}`: position {value} is outside its limits [{lower}, {upper}]")]
    OutOfLimits {
        /// The joint.
        joint: String,
        /// The position.
        value: f64,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
    /// The base pose is not finite.
    #[error("the base pose is not finite")]
    BadBase,
}

/// What to do with a position outside its joint's limits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LimitMode {
    /// Refuse the whole request ([`JointError::OutOfLimits`]).
    #[default]
    Reject,
    /// Move the joint to the nearest limit.
    Clamp,
}

/// The kind of a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// No motion.
    Fixed,
    /// Rotation about the axis, within limits.
    Revolute,
    /// Rotation about the axis, no limits.
    Continuous,
    /// Translation along the axis, within limits.
    Prismatic,
}

/// Where a joint's position comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointSource {
    /// A fixed joint: none.
    Fixed,
    /// Entry `index` of the position array.
    Moving(usize),
    /// `multiplier * positions[index] + offset` (a mimic joint, chains
    /// resolved).
    Mimic {
        /// The leading entry of the position array.
        index: usize,
        /// Factor.
        multiplier: f64,
        /// Offset.
        offset: f64,
    },
}

/// One joint.
#[derive(Clone, Debug, PartialEq)]
pub struct JointInfo {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: JointKind,
    /// Parent link (index into [`Kinematics::link_names`]).
    pub parent: usize,
    /// Child link.
    pub child: usize,
    /// Child frame in the parent frame at position zero.
    pub origin: Isometry3<f64>,
    /// Unit axis in the joint frame.
    pub axis: Unit<Vector3<f64>>,
    /// Lower limit (`-inf` for continuous and fixed joints).
    pub lower: f64,
    /// Upper limit (`inf` for continuous and fixed joints).
    pub upper: f64,
    /// Where its position comes from.
    pub source: JointSource,
}

/// A robot's kinematic tree.
#[derive(Clone, Debug, PartialEq)]
pub struct Kinematics {
    name: String,
    links: Vec<String>,
    joints: Vec<JointInfo>,
    /// Joints, parents before children.
    order: Vec<usize>,
    /// Per link, the joint whose child it is (`None` for the root).
    parent_joint: Vec<Option<usize>>,
    root: usize,
    /// The moving joints, in position-array order (indices into `joints`).
    moving: Vec<usize>,
    /// What the URDF gets wrong that was accepted.
    warnings: Vec<String>,
}

impl Kinematics {
    /// The kinematic tree of URDF text.
    ///
    /// # Errors
    /// A [`KinematicsError`] naming the problem.
    pub fn from_urdf_str(text: &str) -> Result<Self, KinematicsError> {
        Self::from_urdf(&crate::urdf::parse_urdf(text)?)
    }

    /// The kinematic tree of a parsed URDF.
    ///
    /// # Errors
    /// A [`KinematicsError`] naming the problem.
    pub fn from_urdf(robot: &urdf_rs::Robot) -> Result<Self, KinematicsError> {
        if robot.links.is_empty() {
            return Err(KinematicsError::NoLinks);
        }
        let links: Vec<String> = robot.links.iter().map(|l| l.name.clone()).collect();
        let link_index = unique_index(&links, "links")?;
        let joint_names: Vec<String> = robot.joints.iter().map(|j| j.name.clone()).collect();
        let joint_index = unique_index(&joint_names, "joints")?;
        let mut joints = Vec::with_capacity(robot.joints.len());
        let mut moving = Vec::new();
        let mut warnings = Vec::new();
        for joint in &robot.joints {
            let info = joint_info(joint, &link_index)?;
            if info.source != JointSource::Fixed {
                if let Some(mimic) = &joint.mimic
                    && !joint_index.contains_key(mimic.joint.as_str())
                {
                    let warning = format!(
                        "joint `{}` mimics `{}`, which does not exist: it moves on its own",
                        joint.name, mimic.joint
                    );
                    tracing::warn!(robot = %robot.name, "{warning}");
                    warnings.push(warning);
                }
                if leader(joint, &joint_index).is_none() {
                    moving.push(joints.len());
                }
            }
            joints.push(info);
        }
        resolve_mimics(robot, &joint_index, &mut joints, &moving)?;
        let (root, order, parent_joint) = tree_order(&links, &joints)?;
        Ok(Kinematics {
            name: robot.name.clone(),
            links,
            joints,
            order,
            parent_joint,
            root,
            moving,
            warnings,
        })
    }

    /// What the URDF gets wrong that gjkd accepts all the same, one
    /// sentence each (also logged with `tracing` as warnings when loaded):
    /// so far, mimic joints naming a leader that does not exist, which move
    /// on their own (as MoveIt treats them).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The robot's name in the URDF.
    pub fn robot_name(&self) -> &str {
        &self.name
    }

    /// Link names, in URDF order: the order of [`Kinematics::link_poses`].
    pub fn link_names(&self) -> &[String] {
        &self.links
    }

    /// The root link's index.
    pub fn root(&self) -> usize {
        self.root
    }

    /// The joint whose child `link` is (an index into
    /// [`Kinematics::joints`]); `None` for the root or an index out of
    /// range.
    pub fn parent_joint(&self, link: usize) -> Option<usize> {
        self.parent_joint.get(link).copied().flatten()
    }

    /// All joints, in URDF order.
    pub fn joints(&self) -> &[JointInfo] {
        &self.joints
    }

    /// The moving joints' names: the order of a position array.
    pub fn joint_names(&self) -> Vec<&str> {
        self.moving
            .iter()
            .map(|&j| self.joints[j].name.as_str())
            .collect()
    }

    /// The moving joints, in position-array order.
    pub fn moving_joints(&self) -> impl Iterator<Item = &JointInfo> {
        self.moving.iter().map(|&j| &self.joints[j])
    }

    /// Number of moving joints: the length of a position array.
    pub fn dof(&self) -> usize {
        self.moving.len()
    }

    /// The pairs of links joined by a joint (parent, child), as indices.
    pub fn adjacent_links(&self) -> Vec<(usize, usize)> {
        self.joints.iter().map(|j| (j.parent, j.child)).collect()
    }

    /// A position array from `(name, position)` pairs, starting from
    /// `current` (joints not named keep their position there).
    ///
    /// # Errors
    /// [`JointError::UnknownJoint`], [`JointError::WrongCount`] when
    /// `current` has the wrong length.
    pub fn positions_by_name(
        &self,
        named: &[(&str, f64)],
        current: &[f64],
    ) -> Result<Vec<f64>, JointError> {
        if current.len() != self.moving.len() {
            return Err(JointError::WrongCount {
                expected: self.moving.len(),
                got: current.len(),
            });
        }
        let mut out = current.to_vec();
        for &(name, value) in named {
            let k = self
                .moving
                .iter()
                .position(|&j| self.joints[j].name == name)
                .ok_or_else(|| JointError::UnknownJoint(name.to_owned()))?;
            out[k] = value;
        }
        Ok(out)
    }

    /// Checks `positions` (NaN, limits) and clamps them in place with
    /// [`LimitMode::Clamp`]. Nothing is changed on error.
    ///
    /// # Errors
    /// [`JointError::WrongCount`], [`JointError::NotFinite`],
    /// [`JointError::OutOfLimits`] (with [`LimitMode::Reject`]).
    pub fn check_positions(
        &self,
        positions: &mut [f64],
        mode: LimitMode,
    ) -> Result<(), JointError> {
        if positions.len() != self.moving.len() {
            return Err(JointError::WrongCount {
                expected: self.moving.len(),
                got: positions.len(),
            });
        }
        for (q, j) in positions.iter().zip(self.moving_joints()) {
            if !q.is_finite() {
                return Err(JointError::NotFinite(j.name.clone()));
            }
            if mode == LimitMode::Reject && !(j.lower <= *q && *q <= j.upper) {
                return Err(JointError::OutOfLimits {
                    joint: j.name.clone(),
                    value: *q,
                    lower: j.lower,
                    upper: j.upper,
                });
            }
        }
        if mode == LimitMode::Clamp {
            for (q, &j) in positions.iter_mut().zip(&self.moving) {
                let j = &self.joints[j];
                *q = q.clamp(j.lower, j.upper);
            }
        }
        Ok(())
    }

    /// Every link's pose (in [`Kinematics::link_names`] order) for the base
    /// (root link) pose `base` and the positions of the moving joints.
    ///
    /// # Errors
    /// As [`Kinematics::check_positions`], and [`JointError::BadBase`].
    pub fn link_poses(
        &self,
        base: &Isometry3<f64>,
        positions: &[f64],
        mode: LimitMode,
    ) -> Result<Vec<Isometry3<f64>>, JointError> {
        let mut out = Vec::new();
        let mut q = positions.to_vec();
        self.link_poses_into(base, &mut q, mode, &mut out)?;
        Ok(out)
    }

    /// [`Kinematics::link_poses`] into a reused buffer; `positions` are
    /// clamped in place with [`LimitMode::Clamp`]. `out` is left alone on
    /// error.
    ///
    /// # Errors
    /// As [`Kinematics::link_poses`].
    pub fn link_poses_into(
        &self,
        base: &Isometry3<f64>,
        positions: &mut [f64],
        mode: LimitMode,
        out: &mut Vec<Isometry3<f64>>,
    ) -> Result<(), JointError> {
        let finite = base.translation.vector.iter().all(|c| c.is_finite())
            && base.rotation.coords.iter().all(|c| c.is_finite());
        if !finite {
            return Err(JointError::BadBase);
        }
        self.check_positions(positions, mode)?;
        out.clear();
        out.resize(self.links.len(), Isometry3::identity());
        out[self.root] = *base;
        for &j in &self.order {
            let joint = &self.joints[j];
            let q = match joint.source {
                JointSource::Fixed => 0.0,
                JointSource::Moving(k) => positions[k],
                JointSource::Mimic {
                    index,
                    multiplier,
                    offset,
                } => multiplier * positions[index] + offset,
            };
            out[joint.child] = out[joint.parent] * joint.origin * joint.motion(q);
        }
        Ok(())
    }
}

impl JointInfo {
    /// The motion of the joint at position `q`: child frame in the joint
    /// frame.
    pub fn motion(&self, q: f64) -> Isometry3<f64> {
        match self.kind {
            JointKind::Fixed => Isometry3::identity(),
            JointKind::Revolute | JointKind::Continuous => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&self.axis, q),
            ),
            JointKind::Prismatic => Isometry3::from_parts(
                Translation3::from(self.axis.into_inner() * q),
                UnitQuaternion::identity(),
            ),
        }
    }
}

/// The isometry of a URDF origin (`xyz`, then `rpy`: roll about x, pitch
/// about y, yaw about z, in fixed axes, so R = Rz(yaw) Ry(pitch) Rx(roll)).
pub fn urdf_pose(pose: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = pose.xyz.0;
    let [r, p, yaw] = pose.rpy.0;
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(r, p, yaw),
    )
}

fn unique_index<'a>(
    names: &'a [String],
    what: &'static str,
) -> Result<HashMap<&'a str, usize>, KinematicsError> {
    let mut index = HashMap::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        if index.insert(name.as_str(), i).is_some() {
            return Err(KinematicsError::DuplicateName {
                what,
                name: name.clone(),
            });
        }
    }
    Ok(index)
}

fn joint_info(
    joint: &urdf_rs::Joint,
    link_index: &HashMap<&str, usize>,
) -> Result<JointInfo, KinematicsError> {
    use urdf_rs::JointType as T;
    let name = joint.name.clone();
    let link = |l: &str| {
        link_index
            .get(l)
            .copied()
            .ok_or_else(|| KinematicsError::UnknownLink {
                joint: name.clone(),
                link: l.to_owned(),
            })
    };
    let parent = link(&joint.parent.link)?;
    let child = link(&joint.child.link)?;
    let kind = match joint.joint_type {
        T::Fixed => JointKind::Fixed,
        T::Revolute => JointKind::Revolute,
        T::Continuous => JointKind::Continuous,
        T::Prismatic => JointKind::Prismatic,
        ref other => {
            return Err(KinematicsError::UnsupportedJoint {
                joint: name,
                kind: format!("{other:?}").to_lowercase(),
            });
        }
    };
    let origin = urdf_pose(&joint.origin);
    let origin_ok = joint
        .origin
        .xyz
        .0
        .iter()
        .chain(&joint.origin.rpy.0)
        .all(|c| c.is_finite());
    if !origin_ok {
        return Err(KinematicsError::BadOrigin(name));
    }
    let axis = Vector3::from(joint.axis.xyz.0);
    let axis = match kind {
        JointKind::Fixed => Vector3::x_axis(),
        _ if axis.iter().all(|c| c.is_finite()) && axis.norm() > 0.0 => Unit::new_normalize(axis),
        _ => return Err(KinematicsError::BadAxis(name)),
    };
    let (lower, upper) = match kind {
        JointKind::Revolute | JointKind::Prismatic => (joint.limit.lower, joint.limit.upper),
        _ => (f64::NEG_INFINITY, f64::INFINITY),
    };
    if lower.is_nan() || upper.is_nan() || lower > upper {
        return Err(KinematicsError::BadLimits {
            joint: name,
            lower,
            upper,
        });
    }
    let source = match kind {
        JointKind::Fixed => JointSource::Fixed,
        // Filled in once every joint is known.
        _ => JointSource::Moving(usize::MAX),
    };
    Ok(JointInfo {
        name,
        kind,
        parent,
        child,
        origin,
        axis,
        lower,
        upper,
        source,
    })
}

/// The mimic element of a joint that follows another, `None` for a joint
/// that moves on its own: no mimic element, or one naming a joint that does
/// not exist (MoveIt, too, logs those and moves such a joint on its own).
fn leader<'a>(
    joint: &'a urdf_rs::Joint,
    joint_index: &HashMap<&str, usize>,
) -> Option<&'a urdf_rs::Mimic> {
    joint
        .mimic
        .as_ref()
        .filter(|m| joint_index.contains_key(m.joint.as_str()))
}

/// Gives each moving joint its array entry and each mimic joint its leader's
/// entry, chains of mimics composed.
fn resolve_mimics(
    robot: &urdf_rs::Robot,
    joint_index: &HashMap<&str, usize>,
    joints: &mut [JointInfo],
    moving: &[usize],
) -> Result<(), KinematicsError> {
    for (k, &j) in moving.iter().enumerate() {
        joints[j].source = JointSource::Moving(k);
    }
    for (i, joint) in robot.joints.iter().enumerate() {
        let Some(first) = leader(joint, joint_index) else {
            continue;
        };
        if joints[i].source == JointSource::Fixed {
            continue;
        }
        let fail = |reason| KinematicsError::BadMimic {
            joint: joint.name.clone(),
            leader: first.joint.clone(),
            reason,
        };
        let (mut multiplier, mut offset) = (1.0, 0.0);
        let mut at = i;
        let mut steps = 0;
        while let Some(mimic) = leader(&robot.joints[at], joint_index) {
            let m = mimic.multiplier.unwrap_or(1.0);
            let o = mimic.offset.unwrap_or(0.0);
            if !(m.is_finite() && o.is_finite()) {
                return Err(fail("its multiplier or offset is not finite"));
            }
            // q_at = m * q_leader + o, and q_i = multiplier * q_at + offset.
            offset += multiplier * o;
            multiplier *= m;
            at = joint_index[mimic.joint.as_str()];
            steps += 1;
            if steps > robot.joints.len() {
                return Err(fail("the mimic chain is a cycle"));
            }
        }
        let JointSource::Moving(index) = joints[at].source else {
            return Err(fail("the leader is a fixed joint"));
        };
        joints[i].source = JointSource::Mimic {
            index,
            multiplier,
            offset,
        };
    }
    Ok(())
}

/// What [`tree_order`] finds.
type TreeOrder = (usize, Vec<usize>, Vec<Option<usize>>);

/// The root link, the joints in parents-first order and each link's
/// parent joint.
fn tree_order(links: &[String], joints: &[JointInfo]) -> Result<TreeOrder, KinematicsError> {
    let mut parent_joint: Vec<Option<usize>> = vec![None; links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); links.len()];
    for (j, joint) in joints.iter().enumerate() {
        if parent_joint[joint.child].replace(j).is_some() {
            return Err(KinematicsError::NotATree(format!(
                "link `{}` is the child of two joints",
                links[joint.child]
            )));
        }
        children[joint.parent].push(j);
    }
    let roots: Vec<usize> = (0..links.len())
        .filter(|&l| parent_joint[l].is_none())
        .collect();
    let root = match roots.as_slice() {
        [root] => *root,
        [] => return Err(KinematicsError::NotATree("no root link (a cycle)".into())),
        many => {
            let names: Vec<&str> = many.iter().map(|&l| links[l].as_str()).collect();
            return Err(KinematicsError::NotATree(format!(
                "several root links: {}",
                names.join(", ")
            )));
        }
    };
    let mut order = Vec::with_capacity(joints.len());
    let mut stack = vec![root];
    while let Some(link) = stack.pop() {
        for &j in &children[link] {
            order.push(j);
            stack.push(joints[j].child);
        }
    }
    if order.len() != joints.len() {
        return Err(KinematicsError::NotATree(
            "some links are not reached from the root (a cycle)".into(),
        ));
    }
    Ok((root, order, parent_joint))
}
