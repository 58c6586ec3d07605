//! The shape table: what each shape of the protocol is, written once.
//!
//! Every client (Rust, Python, C) describes what it registers as a
//! [`Geometry`]; [`Geometry::encode`] writes its wire form (the piece table
//! of an [`AdminRequest`] and the vertex slice) and [`decode_shape`] reads
//! that form back into the `gjk` shape the server stores. A new shape is one
//! variant of [`Geometry`] with its arm in [`Geometry::encode`] and in
//! [`decode_piece`], plus one registration call per client.

use std::fmt;

use gjk::{Compound, Convex, Shape};
use nalgebra::{Isometry3, Point3, Vector3};

use crate::{AdminRequest, ErrorCode, MAX_PIECES, PieceDesc, Pose, Vertex, piece_kind, shape_kind};

/// A convex shape, or a union of convex pieces, to register.
///
/// Vertices are in the object's body frame. The radius grows the convex hull
/// of the vertices by a ball ("rounding"); 0 gives the plain polytope.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Geometry<'a> {
    /// A ball of `radius` about the body origin.
    Sphere {
        /// Radius, `>= 0`.
        radius: f64,
    },
    /// The segment from `a` to `b` grown by `radius`.
    Capsule {
        /// One end.
        a: Point3<f64>,
        /// The other end.
        b: Point3<f64>,
        /// Radius, `>= 0`.
        radius: f64,
    },
    /// A box centred on the body origin, its edges rounded by `radius` (the
    /// box grows by `radius` on every side).
    Cuboid {
        /// Half extents, each `>= 0`.
        half_extents: Vector3<f64>,
        /// Rounding radius, `>= 0`.
        radius: f64,
    },
    /// The convex hull of `vertices` grown by `radius`. Vertices need not be
    /// hull vertices.
    Polytope {
        /// At least one vertex.
        vertices: &'a [Point3<f64>],
        /// Rounding radius, `>= 0`.
        radius: f64,
    },
    /// An exact cylinder about the body z axis, centred on the body origin:
    /// the disk of `radius` swept from `z = -half_height` to
    /// `z = +half_height`, its edges rounded by `rounding` (0 for sharp
    /// rims; the cylinder grows by `rounding` on every side). Never a
    /// polytope: the server answers with the cylinder's own support
    /// function.
    Cylinder {
        /// Radius of the disk, `>= 0`.
        radius: f64,
        /// Half the length along z, `>= 0`.
        half_height: f64,
        /// Rounding radius, `>= 0`.
        rounding: f64,
    },
    /// A union of convex pieces (at most [`MAX_PIECES`], none of them itself
    /// a compound). Answers name the pieces that realise the distance, by
    /// position in this slice.
    Compound(&'a [Piece<'a>]),
}

/// A convex piece of a [`Geometry::Compound`], placed in the compound's body
/// frame by `offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece<'a> {
    /// Pose of the piece in the compound's body frame.
    pub offset: Isometry3<f64>,
    /// The piece's shape; not a compound.
    pub geometry: Geometry<'a>,
}

/// Why a [`Geometry`] cannot be put on the wire at all (the server checks
/// everything else, with an [`ErrorCode`] of its own).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShapeError {
    /// A box's half extent is negative: it would give the same corners as
    /// its absolute value, so the server could not tell.
    HalfExtentIsNegative,
    /// A compound was given as a piece of a compound.
    CompoundIsNested,
    /// A compound has more than [`MAX_PIECES`] pieces.
    TooManyPieces,
    /// A piece has more vertices than the wire's `u32` count holds.
    TooManyVertices,
}

impl ShapeError {
    /// A short description.
    pub fn describe(self) -> &'static str {
        match self {
            ShapeError::HalfExtentIsNegative => "a half extent is negative",
            ShapeError::CompoundIsNested => "a compound cannot be a piece of a compound",
            ShapeError::TooManyPieces => "more than MAX_PIECES pieces",
            ShapeError::TooManyVertices => "too many vertices in a piece",
        }
    }
}

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.describe())
    }
}

impl std::error::Error for ShapeError {}

impl<'a> Geometry<'a> {
    /// The geometry that registers `convex` as it is: a cylinder as a
    /// [`Geometry::Cylinder`], anything else as the
    /// [`Geometry::Polytope`] of its vertices and radius (vertex order
    /// kept, so the server builds the very same shape).
    pub fn of_convex(convex: &'a Convex) -> Self {
        match convex.cylinder_dimensions() {
            Some((radius, half_height)) => Geometry::Cylinder {
                radius,
                half_height,
                rounding: convex.radius(),
            },
            None => Geometry::Polytope {
                vertices: convex.vertices(),
                radius: convex.radius(),
            },
        }
    }

    /// Writes the wire form of this geometry: `request`'s shape kind and
    /// piece table, and the vertices appended to `vertices`, in the order
    /// the `gjk` crate's constructors use, so that the server's answers
    /// equal in-process ones bit for bit. Nothing is written on an error.
    ///
    /// # Errors
    /// [`ShapeError`]: what no server could be sent.
    pub fn encode(
        &self,
        request: &mut AdminRequest,
        vertices: &mut Vec<Vertex>,
    ) -> Result<(), ShapeError> {
        let before = vertices.len();
        let outcome = self.encode_into(request, vertices);
        if outcome.is_err() {
            vertices.truncate(before);
        }
        outcome
    }

    fn encode_into(
        &self,
        request: &mut AdminRequest,
        vertices: &mut Vec<Vertex>,
    ) -> Result<(), ShapeError> {
        match self {
            Geometry::Compound(pieces) => {
                if pieces.len() > MAX_PIECES {
                    return Err(ShapeError::TooManyPieces);
                }
                let mut table = [PieceDesc::default(); MAX_PIECES];
                for (desc, piece) in table.iter_mut().zip(pieces.iter()) {
                    *desc = piece
                        .geometry
                        .piece(Pose::from_isometry(&piece.offset), vertices)?;
                }
                request.shape = shape_kind::COMPOUND;
                request.piece_count = pieces.len() as u32;
                request.pieces = table;
            }
            convex => {
                let desc = convex.piece(Pose::IDENTITY, vertices)?;
                request.shape = shape_kind::CONVEX;
                request.piece_count = 1;
                request.pieces[0] = desc;
            }
        }
        Ok(())
    }

    /// The piece table entry of a convex geometry at `offset`, its vertices
    /// appended to `out`.
    fn piece(&self, offset: Pose, out: &mut Vec<Vertex>) -> Result<PieceDesc, ShapeError> {
        let before = out.len();
        let hull = |rounding: f64, out: &mut Vec<Vertex>| {
            Ok(PieceDesc {
                offset,
                kind: piece_kind::HULL,
                vertex_count: u32::try_from(out.len() - before)
                    .map_err(|_| ShapeError::TooManyVertices)?,
                rounding,
                ..PieceDesc::default()
            })
        };
        match *self {
            Geometry::Sphere { radius } => {
                out.push(Vertex::default());
                hull(radius, out)
            }
            Geometry::Capsule { a, b, radius } => {
                out.extend([Vertex::from(a), Vertex::from(b)]);
                hull(radius, out)
            }
            Geometry::Cylinder {
                radius,
                half_height,
                rounding,
            } => Ok(PieceDesc {
                offset,
                kind: piece_kind::CYLINDER,
                vertex_count: 0,
                rounding,
                cylinder_radius: radius,
                half_height,
            }),
            Geometry::Cuboid {
                half_extents: h,
                radius,
            } => {
                if h.iter().any(|&c| c < 0.0) {
                    return Err(ShapeError::HalfExtentIsNegative);
                }
                out.extend(cuboid_corners(&h).map(Vertex::from));
                hull(radius, out)
            }
            Geometry::Polytope { vertices, radius } => {
                out.extend(vertices.iter().map(|&p| Vertex::from(p)));
                hull(radius, out)
            }
            Geometry::Compound(_) => Err(ShapeError::CompoundIsNested),
        }
    }
}

/// The eight corners of a box of half extents `h`, in the order of
/// `gjk::Convex::cuboid` (bit 0 of the index picks x, bit 1 y, bit 2 z).
pub fn cuboid_corners(h: &Vector3<f64>) -> [Point3<f64>; 8] {
    std::array::from_fn(|i| {
        Point3::new(
            if i & 1 == 0 { -h.x } else { h.x },
            if i & 2 == 0 { -h.y } else { h.y },
            if i & 4 == 0 { -h.z } else { h.z },
        )
    })
}

/// The shape of a registration: `request`'s shape kind and piece table
/// with the request's `vertices`, each piece checked, at most `max_pieces`
/// pieces (and never more than [`MAX_PIECES`]).
///
/// # Errors
/// The specific [`ErrorCode`] of the first problem found.
pub fn decode_shape(
    request: &AdminRequest,
    vertices: &[Vertex],
    max_pieces: usize,
) -> Result<Shape, ErrorCode> {
    let count = request.piece_count as usize;
    match request.shape {
        shape_kind::CONVEX => {
            if count != 1 {
                return Err(ErrorCode::Malformed);
            }
            let piece = &request.pieces[0];
            if piece.vertex_count as usize != vertices.len() {
                return Err(if vertices.is_empty() && piece.kind == piece_kind::HULL {
                    ErrorCode::EmptyVertices
                } else {
                    ErrorCode::Malformed
                });
            }
            Ok(Shape::Convex(decode_piece(piece, vertices)?))
        }
        shape_kind::COMPOUND => {
            if count == 0 {
                return Err(ErrorCode::EmptyCompound);
            }
            if count > MAX_PIECES || count > max_pieces {
                return Err(ErrorCode::TooManyPieces);
            }
            let table = &request.pieces[..count];
            let total: u64 = table.iter().map(|p| u64::from(p.vertex_count)).sum();
            if total != vertices.len() as u64 {
                return Err(ErrorCode::Malformed);
            }
            let mut pieces = Vec::with_capacity(count);
            let mut start = 0usize;
            for p in table {
                let end = start + p.vertex_count as usize;
                let offset = p.offset.checked()?;
                pieces.push((offset, decode_piece(p, &vertices[start..end])?));
                start = end;
            }
            Ok(Shape::Compound(
                Compound::new(pieces).map_err(ErrorCode::from)?,
            ))
        }
        _ => Err(ErrorCode::Malformed),
    }
}

/// One piece of a registration, `vertices` its own run of the slice
/// (empty for a cylinder). A kind this version does not know is malformed.
///
/// # Errors
/// The specific [`ErrorCode`] of the first problem found.
pub fn decode_piece(desc: &PieceDesc, vertices: &[Vertex]) -> Result<Convex, ErrorCode> {
    match desc.kind {
        piece_kind::HULL => hull(vertices, desc.rounding),
        piece_kind::CYLINDER if vertices.is_empty() => {
            cylinder(desc.cylinder_radius, desc.half_height, desc.rounding)
        }
        _ => Err(ErrorCode::Malformed),
    }
}

/// The farthest a shape may reach from its body origin, 2^999 (gjk's own
/// limit, about 5e300), so that no query's arithmetic can overflow.
const MAX_REACH: f64 = 5.357543035931337e300;

/// An exact cylinder of `radius` and `half_height` rounded by `rounding`:
/// each a number from 0 to 2^999, and the whole within 2^999 of its
/// origin.
///
/// # Errors
/// [`ErrorCode::InvalidRadius`] otherwise (gjk would call a bad dimension a
/// bad vertex, which a cylinder sent none of).
pub fn cylinder(radius: f64, half_height: f64, rounding: f64) -> Result<Convex, ErrorCode> {
    let dimensions = [radius, half_height, rounding];
    if !dimensions.iter().all(|x| (0.0..=MAX_REACH).contains(x)) {
        return Err(ErrorCode::InvalidRadius);
    }
    if radius.hypot(half_height) + rounding > MAX_REACH {
        return Err(ErrorCode::InvalidRadius);
    }
    Convex::cylinder(radius, half_height, rounding).map_err(ErrorCode::from)
}

/// The hull of `vertices` rounded by `radius`.
///
/// # Errors
/// [`ErrorCode::EmptyVertices`], [`ErrorCode::InvalidRadius`] and the
/// codes of gjk's own checks.
pub fn hull(vertices: &[Vertex], radius: f64) -> Result<Convex, ErrorCode> {
    if vertices.is_empty() {
        return Err(ErrorCode::EmptyVertices);
    }
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(ErrorCode::InvalidRadius);
    }
    let points: Vec<Point3<f64>> = vertices.iter().map(|&v| v.into()).collect();
    Convex::new(points, radius).map_err(ErrorCode::from)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::AdminOp;

    fn register(g: &Geometry<'_>) -> (AdminRequest, Vec<Vertex>) {
        let mut req = AdminRequest::new(AdminOp::Register);
        let mut v = Vec::new();
        g.encode(&mut req, &mut v).expect("encodable");
        (req, v)
    }

    #[test]
    fn every_convex_kind_decodes_to_its_gjk_constructor() {
        let pts = [Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 2.0)];
        let h = Vector3::new(1.0, 2.0, 3.0);
        let cases: [(Geometry<'_>, Convex); 5] = [
            (
                Geometry::Sphere { radius: 0.5 },
                Convex::sphere(0.5).unwrap(),
            ),
            (
                Geometry::Capsule {
                    a: pts[0],
                    b: pts[1],
                    radius: 0.25,
                },
                Convex::capsule(pts[0], pts[1], 0.25).unwrap(),
            ),
            (
                Geometry::Cuboid {
                    half_extents: h,
                    radius: 0.125,
                },
                Convex::cuboid(h, 0.125).unwrap(),
            ),
            (
                Geometry::Polytope {
                    vertices: &pts,
                    radius: 0.0,
                },
                Convex::new(pts.to_vec(), 0.0).unwrap(),
            ),
            (
                Geometry::Cylinder {
                    radius: 0.5,
                    half_height: 2.0,
                    rounding: 0.125,
                },
                Convex::cylinder(0.5, 2.0, 0.125).unwrap(),
            ),
        ];
        for (g, expected) in cases {
            let (req, v) = register(&g);
            let Ok(Shape::Convex(got)) = decode_shape(&req, &v, MAX_PIECES) else {
                panic!("{g:?} did not decode to a convex shape");
            };
            assert_eq!(got.vertices(), expected.vertices(), "{g:?}");
            assert_eq!(got.radius(), expected.radius(), "{g:?}");
            assert_eq!(
                got.cylinder_dimensions(),
                expected.cylinder_dimensions(),
                "{g:?}"
            );
            assert_eq!(Geometry::of_convex(&got).kind_of(), g.kind_of(), "{g:?}");
        }
    }

    impl Geometry<'_> {
        /// Cylinder or not: what `of_convex` can tell back.
        fn kind_of(&self) -> bool {
            matches!(self, Geometry::Cylinder { .. })
        }
    }

    #[test]
    fn shapes_no_server_could_take_are_refused_before_sending() {
        let pieces = [Piece {
            offset: Isometry3::identity(),
            geometry: Geometry::Sphere { radius: 1.0 },
        }];
        let nested = [Piece {
            offset: Isometry3::identity(),
            geometry: Geometry::Compound(&pieces),
        }];
        let many = [pieces[0]; MAX_PIECES + 1];
        let cases = [
            (
                Geometry::Cuboid {
                    half_extents: Vector3::new(1.0, -1e-300, 1.0),
                    radius: 0.0,
                },
                ShapeError::HalfExtentIsNegative,
            ),
            (Geometry::Compound(&nested), ShapeError::CompoundIsNested),
            (Geometry::Compound(&many), ShapeError::TooManyPieces),
        ];
        for (g, expected) in cases {
            let mut req = AdminRequest::new(AdminOp::Register);
            let mut v = vec![Vertex::default()];
            assert_eq!(g.encode(&mut req, &mut v), Err(expected));
            assert_eq!(v, [Vertex::default()], "nothing appended for {expected}");
            assert_eq!(req, AdminRequest::new(AdminOp::Register));
        }
    }

    #[test]
    fn malformed_piece_tables_are_refused_not_panicked_on() {
        let (req, v) = register(&Geometry::Sphere { radius: 1.0 });
        // A count that promises more vertices than were sent.
        let mut more = req;
        more.pieces[0].vertex_count = 2;
        assert_eq!(
            decode_shape(&more, &v, MAX_PIECES).err(),
            Some(ErrorCode::Malformed)
        );
        // No vertices at all for a hull.
        let mut empty = req;
        empty.pieces[0].vertex_count = 0;
        assert_eq!(
            decode_shape(&empty, &[], MAX_PIECES).err(),
            Some(ErrorCode::EmptyVertices)
        );
        // An unknown piece kind, an unknown shape kind, a compound of
        // more pieces than the table holds.
        let mut kind = req;
        kind.pieces[0].kind = 99;
        assert_eq!(
            decode_shape(&kind, &v, MAX_PIECES).err(),
            Some(ErrorCode::Malformed)
        );
        let mut shape = req;
        shape.shape = 99;
        assert_eq!(
            decode_shape(&shape, &v, MAX_PIECES).err(),
            Some(ErrorCode::Malformed)
        );
        let mut huge = req;
        huge.shape = shape_kind::COMPOUND;
        huge.piece_count = u32::MAX;
        assert_eq!(
            decode_shape(&huge, &v, MAX_PIECES).err(),
            Some(ErrorCode::TooManyPieces)
        );
        // A cylinder sent with vertices, or with a NaN radius.
        let (mut can, none) = register(&Geometry::Cylinder {
            radius: 1.0,
            half_height: 1.0,
            rounding: 0.0,
        });
        assert!(none.is_empty(), "a cylinder travels without vertices");
        can.pieces[0].vertex_count = 1;
        assert_eq!(
            decode_shape(&can, &v, MAX_PIECES).err(),
            Some(ErrorCode::Malformed)
        );
        can.pieces[0].vertex_count = 0;
        can.pieces[0].cylinder_radius = f64::NAN;
        assert_eq!(
            decode_shape(&can, &[], MAX_PIECES).err(),
            Some(ErrorCode::InvalidRadius)
        );
    }
}
