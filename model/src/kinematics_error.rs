//! What can be wrong with a URDF's kinematic tree: the error of both the
//! URDF reader ([`crate::urdf`]) and the tree built from it
//! ([`crate::kinematics`]).

/// What can be wrong with a URDF's kinematic tree.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// The text is not a URDF (XML errors, missing required elements).
    #[error("malformed URDF: {0}")]
    Malformed(String),
    /// Two links or two joints share a name.
    #[error("the URDF has two {what} named `{name}`")]
    DuplicateName {
        /// "links" or "joints".
        what: &'static str,
        /// The name.
        name: String,
    },
    /// A joint names a link the URDF does not have.
    #[error("joint `{joint}` names link `{link}`, which the URDF does not have")]
    UnknownLink {
        /// The joint.
        joint: String,
        /// The link.
        link: String,
    },
    /// The robot has no link at all.
    #[error("the robot has no link")]
    NoLinks,
    /// The links do not make one tree: no root, several roots, a link with
    /// two parents, or a cycle.
    #[error("the links do not form one tree: {0}")]
    NotATree(String),
    /// A joint type gjkd does not move (floating, planar, spherical).
    #[error(
        "joint `{joint}` is of type {kind}, which is not supported (fixed, revolute, continuous and prismatic are)"
    )]
    UnsupportedJoint {
        /// The joint.
        joint: String,
        /// Its type.
        kind: String,
    },
    /// A joint's axis is zero or not finite.
    #[error("joint `{0}` has a zero or non-finite axis")]
    BadAxis(String),
    /// A joint's origin is not finite.
    #[error("joint `{0}` has a non-finite origin")]
    BadOrigin(String),
    /// A joint's lower limit is above its upper one, or a limit is NaN.
    #[error("joint `{joint}` has limits [{lower}, {upper}]")]
    BadLimits {
        /// The joint.
        joint: String,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
    /// A mimic joint follows a fixed joint or (through a chain) itself; or
    /// its multiplier or offset is not finite. (One naming a joint that does
    /// not exist moves on its own, see [`Kinematics::warnings`](crate::Kinematics::warnings).)
    #[error("joint `{joint}` cannot mimic `{leader}`: {reason}")]
    BadMimic {
        /// The mimic joint.
        joint: String,
        /// The joint it names.
        leader: String,
        /// Why.
        reason: &'static str,
    },
}
