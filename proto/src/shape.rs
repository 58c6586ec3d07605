//! The shapes of a registration: the piece table and the vertices.

use iceoryx2::prelude::ZeroCopySend;
use nalgebra::Point3;

use crate::Pose;

/// A vertex on the wire.
#[derive(Clone, Copy, Debug, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.Vertex")]
pub struct Vertex {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl From<Point3<f64>> for Vertex {
    fn from(p: Point3<f64>) -> Self {
        Vertex {
            x: p.x,
            y: p.y,
            z: p.z,
        }
    }
}

impl From<Vertex> for Point3<f64> {
    fn from(v: Vertex) -> Self {
        Point3::new(v.x, v.y, v.z)
    }
}

/// Values of [`AdminRequest::shape`].
pub mod shape_kind {
    /// One convex piece: `pieces[0]` describes it (its offset is ignored);
    /// a hull or a cylinder ([`piece_kind`](crate::piece_kind)).
    pub const CONVEX: u32 = 1;
    /// A union of `piece_count` convex pieces, each with its offset, each a
    /// hull or a cylinder ([`piece_kind`](crate::piece_kind)).
    pub const COMPOUND: u32 = 2;
}

/// Values of [`PieceDesc::reserved`]: what a piece's vertices describe.
///
/// Added within v1 (the layout is unchanged): a server older than
/// [`CYLINDER`](piece_kind::CYLINDER) refuses any non-zero value as [`ErrorCode::Malformed`], so
/// a cylinder is never misread there as a one-point hull.
pub mod piece_kind {
    /// The convex hull of the piece's vertices grown by its radius (0, the
    /// only kind before cylinders).
    pub const HULL: u32 = 0;
    /// An exact cylinder about the piece's z axis, centred at the piece's
    /// origin: the piece has exactly one vertex, `(r, h, 0)`, the
    /// cylinder's radius `r` and half-height `h` (each finite, `>= 0`, at
    /// most 2^999; a `z` other than 0 is [`Malformed`](crate::ErrorCode::Malformed),
    /// a bad `r` or `h` [`InvalidRadius`](crate::ErrorCode::InvalidRadius)),
    /// and [`PieceDesc::radius`](crate::PieceDesc::radius) rounds its edges.
    pub const CYLINDER: u32 = 1;
}

/// One convex piece of a registration: its offset in the object's body frame,
/// radius, and how many of the slice's vertices are its own (pieces take
/// consecutive runs of the slice, in order).
///
/// A cylinder piece ([`piece_kind::CYLINDER`] in `reserved`) carries its
/// dimensions as its one vertex:
///
/// ```
/// use gjkd_proto::{piece_kind, PieceDesc, Pose, Vertex};
///
/// // Radius 0.05, length 0.4 (half-height 0.2), sharp rims.
/// let desc = PieceDesc {
///     offset: Pose::IDENTITY,
///     radius: 0.0,
///     vertex_count: 1,
///     reserved: piece_kind::CYLINDER,
/// };
/// let dimensions = Vertex { x: 0.05, y: 0.2, z: 0.0 };
/// # let _ = (desc, dimensions);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.PieceDesc")]
pub struct PieceDesc {
    /// Offset of the piece in the object's body frame.
    pub offset: Pose,
    /// Rounding radius, `>= 0`.
    pub radius: f64,
    /// Number of vertices of this piece (1 for a cylinder).
    pub vertex_count: u32,
    /// The piece's kind, a [`piece_kind`] value: 0 (a hull) unless the
    /// piece is a cylinder. The name is the field's from before
    /// cylinders, kept so that code building pieces still compiles.
    pub reserved: u32,
}
