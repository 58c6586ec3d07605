//! # gjk
//!
//! The distance between convex objects in three-space by the numerical
//! algorithm of Gilbert, Johnson and Keerthi (1986): Johnson's subalgorithm with
//! cofactors, the Backup Procedure, the relative stopping rule `g <= ε·D²`, the
//! centroid origin shift, warm start from the last simplex, spherical extensions,
//! unions of convex pieces and a lower bound on penetration. Every answer carries
//! a certified lower and upper bound on the distance.
//!
//! Shapes ([`Convex`], [`Compound`], [`Shape`]) are separate from the query
//! ([`distance`]), as in parry. Poses are nalgebra [`Isometry3<f64>`](nalgebra::Isometry3).
//!
//! ```
//! use gjk::{distance, Convex, Options, Shape};
//! use nalgebra::{Isometry3, Vector3};
//!
//! let a: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?.into();
//! let b: Shape = Convex::sphere(0.5)?.into();
//! let pose_a = Isometry3::identity();
//! let pose_b = Isometry3::translation(3.0, 0.0, 0.0);
//! let answer = distance(&a, &pose_a, &b, &pose_b, &Options::default(), None)?;
//! assert!((answer.distance - 1.5).abs() < 1e-12);
//! assert!(answer.lower <= 1.5 && 1.5 <= answer.upper);
//! // Hand `answer.warm_start` back next time for the same pair.
//! let again = distance(&a, &pose_a, &b, &pose_b, &Options::default(), Some(&answer.warm_start))?;
//! assert_eq!(again.distance, answer.distance);
//! # Ok::<(), gjk::Error>(())
//! ```

#![warn(missing_docs)]

#[macro_use]
mod cpu;
mod depth;
mod johnson;
mod numeric;
mod overlap;
pub(crate) mod query;
mod separation;
mod shape;
mod support_map;

pub use depth::{
    DepthOptions, SignedDistance, signed_distance, signed_distance_after, signed_distance_between,
};
pub use overlap::penetration_bound;
#[doc(hidden)]
pub use query::distance_in_baseline;
pub use query::{
    Answer, Options, Precision, Status, WarmStart, Workspace, distance, distance_between,
    distance_between_compounds, distance_between_compounds_in, distance_between_in, distance_in,
};
pub use separation::separation_bound;
pub use shape::{Compound, Convex, Shape};
pub use support_map::{DifferencePoint, SeedForm, SupportMap, SupportPoint, support_of_difference};

#[cfg(target_arch = "x86_64")]
pub(crate) use cpu::has_avx2_fma;

/// What can be wrong with the input. Every query and constructor reports bad
/// input with one of these; none panics and none returns NaN.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Error {
    /// A convex shape needs at least one vertex.
    #[error("empty vertex set")]
    EmptyVertices,
    /// Vertex (or piece) counts must fit in `u32`, the width of warm-start indices.
    #[error("too many vertices or pieces: {0}")]
    TooManyVertices(usize),
    /// A vertex has a NaN or infinite coordinate, or the shape (its
    /// vertices plus its rounding radius) reaches more than 2^999 (about
    /// 5e300) from its body origin, where queries could overflow.
    #[error("vertex {0} is not finite, or the set reaches beyond 5e300")]
    NonFiniteVertex(usize),
    /// The rounding radius is negative, NaN, infinite, or above 2^999
    /// (about 5e300).
    #[error("radius {0} is not a finite number from 0 to 5e300")]
    InvalidRadius(f64),
    /// A compound needs at least one piece.
    #[error("compound with no pieces")]
    EmptyCompound,
    /// A pose (or a piece offset) has a NaN or infinite component; or a
    /// compound's piece reaches more than 2^999 (about 5e300) from its body
    /// origin, or a query's two shapes lie more than 2^1000 (about 1e301)
    /// apart on an axis, where the arithmetic could overflow.
    #[error("pose is not finite, or beyond 1e301")]
    NonFinitePose,
    /// An option is out of its domain (named in the message).
    #[error("invalid option: {0}")]
    InvalidOption(&'static str),
    /// A warm start names a vertex or piece that the shapes do not have.
    #[error("warm start index out of range")]
    WarmStartOutOfRange,
}
