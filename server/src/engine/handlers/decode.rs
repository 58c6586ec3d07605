//! Registrations in the wire's terms turned into the engine's: every field
//! checked, the first problem found is the answer.

use gjk::{Compound, Convex, Shape};
use gjkd_proto::{AdminRequest, ErrorCode, MAX_PIECES, PieceDesc, Vertex, piece_kind, shape_kind};

use crate::engine::checks::{check_pose, convex, cylinder, map_gjk_error};
use crate::engine::objects::NewObject;
use crate::engine::state::Limits;

/// Checks a registration and builds its shape.
///
/// # Errors
/// The specific [`ErrorCode`] of the first problem found.
pub fn decode_registration(
    limits: &Limits,
    request: &AdminRequest,
    vertices: &[Vertex],
) -> Result<NewObject, ErrorCode> {
    if vertices.len() > limits.max_vertices {
        return Err(ErrorCode::TooManyVertices);
    }
    let name = match request.name_len {
        0 => None,
        _ => Some(request.name().ok_or(ErrorCode::Malformed)?.to_owned()),
    };
    let pose = check_pose(&request.pose)?;
    let count = request.piece_count as usize;
    let shape = match request.shape {
        shape_kind::CONVEX => {
            if count != 1 {
                return Err(ErrorCode::Malformed);
            }
            let piece = &request.pieces[0];
            if piece.vertex_count as usize != vertices.len() {
                return Err(
                    if vertices.is_empty() && piece.reserved == piece_kind::HULL {
                        ErrorCode::EmptyVertices
                    } else {
                        ErrorCode::Malformed
                    },
                );
            }
            Shape::Convex(decode_piece(piece, vertices)?)
        }
        shape_kind::COMPOUND => {
            if count == 0 {
                return Err(ErrorCode::EmptyCompound);
            }
            if count > MAX_PIECES || count > limits.max_pieces {
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
                let offset = check_pose(&p.offset)?;
                pieces.push((offset, decode_piece(p, &vertices[start..end])?));
                start = end;
            }
            Shape::Compound(Compound::new(pieces).map_err(map_gjk_error)?)
        }
        _ => return Err(ErrorCode::Malformed),
    };
    Ok(NewObject { shape, pose, name })
}

/// One piece of a registration, `vertices` its own run of the slice: a
/// hull, or a cylinder whose one vertex holds its dimensions (see
/// [`piece_kind::CYLINDER`]). A kind this version does not know is
/// malformed, as every server before cylinders refused any but 0.
fn decode_piece(desc: &PieceDesc, vertices: &[Vertex]) -> Result<Convex, ErrorCode> {
    match desc.reserved {
        piece_kind::HULL => convex(vertices, desc.radius),
        piece_kind::CYLINDER => match vertices {
            [v] if v.z == 0.0 => cylinder(v.x, v.y, desc.radius),
            _ => Err(ErrorCode::Malformed),
        },
        _ => Err(ErrorCode::Malformed),
    }
}
