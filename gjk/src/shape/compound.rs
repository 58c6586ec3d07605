//! [`Compound`]: a union of convex pieces, each placed by its own offset;
//! its pieces are stored [`Convex`] shapes, or any one [`SupportMap`] type.

use nalgebra::{Isometry3, Point3};

use super::Convex;
use super::reach::{MAX_REACH, pose_is_finite};
use crate::Error;
use crate::numeric::robust_norm;
use crate::support_map::SupportMap;

/// A union of convex pieces, each placed in the compound's body frame by its own
/// offset. Its distance to another shape is the minimum over piece pairs, (2.3)
/// and (2.8), and the answer names the pieces that realise it.
///
/// The pieces are [`Convex`] shapes by default, what a [`Shape`](crate::Shape)
/// holds and [`distance`](crate::distance) takes; a compound of any other
/// [`SupportMap`] type (a shape of one's own among them) is queried by
/// [`distance_between_compounds`](crate::distance_between_compounds), with
/// the same search over its piece pairs.
///
/// ```
/// use gjk::{Compound, Convex};
/// use nalgebra::{Isometry3, Point3, Vector3};
///
/// // A dumbbell: two balls joined by a bar.
/// let ball = Convex::sphere(0.3)?;
/// let bar = Convex::capsule(Point3::new(-1.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0), 0.05)?;
/// let dumbbell = Compound::new(vec![
///     (Isometry3::translation(-1.0, 0.0, 0.0), ball.clone()),
///     (Isometry3::identity(), bar),
///     (Isometry3::translation(1.0, 0.0, 0.0), ball),
/// ])?;
/// assert_eq!(dumbbell.pieces().len(), 3);
/// # Ok::<(), gjk::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Compound<S = Convex> {
    pub(super) pieces: Vec<(Isometry3<f64>, S)>,
    /// Each piece's centroid in the compound's body frame (its offset applied),
    /// for the sphere bounds that order a query's piece pairs: computed once
    /// here instead of on every query.
    pub(super) centres: Vec<Point3<f64>>,
}

impl<S: SupportMap> Compound<S> {
    /// A union of `pieces`, each with its offset in the compound's body frame.
    ///
    /// # Errors
    /// [`Error::EmptyCompound`] for no pieces, [`Error::TooManyVertices`] past
    /// `u32::MAX` pieces, and [`Error::NonFinitePose`] for an offset with NaN or
    /// infinity, or a piece (its vertices plus its radius) reaching more
    /// than 2^999 (about 5e300) from the
    /// compound's body origin.
    pub fn new(pieces: Vec<(Isometry3<f64>, S)>) -> Result<Self, Error> {
        if pieces.is_empty() {
            return Err(Error::EmptyCompound);
        }
        if u32::try_from(pieces.len()).is_err() {
            return Err(Error::TooManyVertices(pieces.len()));
        }
        if pieces.iter().any(|(offset, _)| !pose_is_finite(offset)) {
            return Err(Error::NonFinitePose);
        }
        // Each piece within MAX_REACH of the compound's body origin, so that
        // a query's magnitudes stay far from overflow (see MAX_REACH).
        // (`centre_norm + size` is a convex piece's reach.)
        if pieces.iter().any(|(o, c)| {
            robust_norm(&o.translation.vector) + (c.centre_norm() + c.size()) + c.rounding()
                > MAX_REACH
        }) {
            return Err(Error::NonFinitePose);
        }
        let centres = pieces.iter().map(|(o, c)| o * c.centre()).collect();
        Ok(Self { pieces, centres })
    }

    /// The pieces with their offsets, in the order given; the answer's piece
    /// indices refer to positions in this slice.
    pub fn pieces(&self) -> &[(Isometry3<f64>, S)] {
        &self.pieces
    }
}
