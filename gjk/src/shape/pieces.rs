//! [`Pieces`]: what the union search (2.3), (2.8) reads of a shape made of
//! convex pieces, so that one search serves the stored [`Shape`] and a
//! [`Compound`] of any [`SupportMap`] type.

use nalgebra::{Isometry3, Point3};

use super::{Compound, Convex, Shape};
use crate::support_map::SupportMap;

/// A shape as a list of convex pieces, each placed in the shape's body
/// frame: a convex shape is one piece at the identity.
pub(crate) trait Pieces {
    /// The pieces' type.
    type Piece: SupportMap;

    /// Number of pieces: 1 for a convex shape.
    fn piece_count(&self) -> usize;

    /// Piece `i`'s centre in the shape's body frame (its offset applied,
    /// computed once).
    fn piece_centre(&self, i: usize) -> Option<Point3<f64>>;

    /// Piece `i` without its offset.
    fn convex_piece(&self, i: usize) -> Option<&Self::Piece>;

    /// Piece `i` with its offset in the shape's body frame.
    fn piece(&self, i: usize) -> Option<(Isometry3<f64>, &Self::Piece)>;
}

impl Pieces for Shape {
    type Piece = Convex;

    #[inline(always)]
    fn piece_count(&self) -> usize {
        Shape::piece_count(self)
    }

    #[inline(always)]
    fn piece_centre(&self, i: usize) -> Option<Point3<f64>> {
        Shape::piece_centre(self, i)
    }

    #[inline(always)]
    fn convex_piece(&self, i: usize) -> Option<&Convex> {
        Shape::convex_piece(self, i)
    }

    #[inline(always)]
    fn piece(&self, i: usize) -> Option<(Isometry3<f64>, &Convex)> {
        Shape::piece(self, i)
    }
}

impl<S: SupportMap> Pieces for Compound<S> {
    type Piece = S;

    #[inline(always)]
    fn piece_count(&self) -> usize {
        self.pieces.len()
    }

    #[inline(always)]
    fn piece_centre(&self, i: usize) -> Option<Point3<f64>> {
        self.centres.get(i).copied()
    }

    #[inline(always)]
    fn convex_piece(&self, i: usize) -> Option<&S> {
        self.pieces.get(i).map(|(_, p)| p)
    }

    #[inline(always)]
    fn piece(&self, i: usize) -> Option<(Isometry3<f64>, &S)> {
        self.pieces.get(i).map(|(o, p)| (*o, p))
    }
}
