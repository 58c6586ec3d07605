//! The shapes of a registration: the piece table and the vertices.

use iceoryx2::prelude::ZeroCopySend;
use nalgebra::Point3;

use crate::Pose;

/// A vertex on the wire.
#[derive(Clone, Copy, Debug, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.Vertex")]
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

/// Values of [`AdminRequest::shape`](crate::AdminRequest::shape).
pub mod shape_kind {
    /// One convex piece: `pieces[0]` describes it (its offset is ignored).
    pub const CONVEX: u32 = 1;
    /// A union of `piece_count` convex pieces, each with its offset.
    pub const COMPOUND: u32 = 2;
}

/// Values of [`PieceDesc::kind`]: what a piece is. A kind a server does not
/// know is [`ErrorCode::Malformed`](crate::ErrorCode::Malformed).
pub mod piece_kind {
    /// The convex hull of the piece's `vertex_count` vertices (its run of
    /// the slice) grown by its rounding radius. Spheres, capsules and boxes
    /// travel as hulls, with the vertices the shape table
    /// ([`Geometry`](crate::Geometry)) gives them.
    pub const HULL: u32 = 1;
    /// An exact cylinder about the piece's z axis, centred at the piece's
    /// origin, of [`PieceDesc::cylinder_radius`](crate::PieceDesc::cylinder_radius)
    /// and [`PieceDesc::half_height`](crate::PieceDesc::half_height) (each
    /// finite, `>= 0`, at most 2^999, else
    /// [`InvalidRadius`](crate::ErrorCode::InvalidRadius)), its edges
    /// rounded by the rounding radius. It has no vertices.
    pub const CYLINDER: u32 = 2;
}

/// One convex piece of a registration: its kind, its offset in the object's
/// body frame, its rounding radius, and its dimensions (how many of the
/// slice's vertices are its own, for a hull: pieces take consecutive runs
/// of the slice, in order; radius and half-height, for a cylinder). Fields
/// a kind does not use are zero.
///
/// ```
/// use gjkd_proto::{piece_kind, PieceDesc, Pose};
///
/// // Radius 0.05, length 0.4 (half-height 0.2), sharp rims.
/// let can = PieceDesc {
///     kind: piece_kind::CYLINDER,
///     cylinder_radius: 0.05,
///     half_height: 0.2,
///     ..PieceDesc::default()
/// };
/// assert_eq!(can.vertex_count, 0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.PieceDesc")]
pub struct PieceDesc {
    /// Offset of the piece in the object's body frame.
    pub offset: Pose,
    /// The piece's kind, a [`piece_kind`] value.
    pub kind: u32,
    /// [`piece_kind::HULL`]: number of vertices of this piece.
    pub vertex_count: u32,
    /// Rounding radius, `>= 0`: the piece grows by it on every side.
    pub rounding: f64,
    /// [`piece_kind::CYLINDER`]: radius of the disk.
    pub cylinder_radius: f64,
    /// [`piece_kind::CYLINDER`]: half the length along z.
    pub half_height: f64,
}

impl Default for PieceDesc {
    /// An empty hull at the identity: no server accepts it as a shape.
    fn default() -> Self {
        PieceDesc {
            offset: Pose::IDENTITY,
            kind: piece_kind::HULL,
            vertex_count: 0,
            rounding: 0.0,
            cylinder_radius: 0.0,
            half_height: 0.0,
        }
    }
}
