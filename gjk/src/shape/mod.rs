//! Shapes: convex vertex sets with a rounding radius, cylinders, and unions
//! of them, apart from the queries (as in parry).
//!
//! A shape is described in its own body frame and placed in the world by an
//! [`Isometry3`] at query time. Everything that does not depend on the pose
//! (centroid, size bound, a layout fit for the support scan) is computed once,
//! at construction, as Section 6 of the paper suggests.
//!
//! One form a file: [`polytope`] (the vertex sets, with one file per support
//! search strategy), [`cylinder`] (a closed form), [`compound`] (unions);
//! [`convex`] holds the stored convex type that dispatches to the first two,
//! and this file the [`Shape`] a query takes; [`pieces`] what a union's
//! search reads of either.

mod build;
pub(crate) mod compound;
pub(crate) mod convex;
pub(crate) mod cylinder;
pub(crate) mod pieces;
pub(crate) mod polytope;
pub(crate) mod reach;
#[cfg(test)]
pub(crate) mod test_rng;

use nalgebra::{Isometry3, Point3};

pub use compound::Compound;
pub use convex::Convex;
pub(crate) use pieces::Pieces;
pub(crate) use reach::shift_is_in_range;

/// Anything the query accepts: one convex piece or a union of them.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A single convex object.
    Convex(Convex),
    /// A union of convex objects.
    Compound(Compound),
}

impl Shape {
    /// Number of convex pieces: 1 for a convex shape.
    pub fn piece_count(&self) -> usize {
        match self {
            Shape::Convex(_) => 1,
            Shape::Compound(c) => c.pieces.len(),
        }
    }

    /// Piece `i`'s centroid in the shape's body frame: its offset applied,
    /// the same point, bit for bit, as `offset * centroid` (computed once).
    #[inline]
    pub(crate) fn piece_centre(&self, i: usize) -> Option<Point3<f64>> {
        match self {
            Shape::Convex(c) => (i == 0).then(|| c.centroid()),
            Shape::Compound(c) => c.centres.get(i).copied(),
        }
    }

    /// Piece `i` without its offset.
    #[inline]
    pub(crate) fn convex_piece(&self, i: usize) -> Option<&Convex> {
        match self {
            Shape::Convex(c) => (i == 0).then_some(c),
            Shape::Compound(c) => c.pieces.get(i).map(|(_, p)| p),
        }
    }

    /// Piece `i` with its offset in the shape's body frame.
    pub(crate) fn piece(&self, i: usize) -> Option<(Isometry3<f64>, &Convex)> {
        match self {
            Shape::Convex(c) if i == 0 => Some((Isometry3::identity(), c)),
            Shape::Convex(_) => None,
            Shape::Compound(c) => c.pieces.get(i).map(|(o, p)| (*o, p)),
        }
    }
}

impl From<Convex> for Shape {
    fn from(c: Convex) -> Self {
        Shape::Convex(c)
    }
}

impl From<Compound> for Shape {
    fn from(c: Compound) -> Self {
        Shape::Compound(c)
    }
}
