//! Registrations in the wire's terms turned into the engine's: every field
//! checked, the first problem found is the answer.

use gjkd_proto::{AdminRequest, ErrorCode, Vertex};

use crate::engine::checks::check_pose;
use crate::engine::objects::NewObject;
use crate::engine::state::Limits;

/// Checks a registration and builds its shape (by the protocol's shape
/// table, [`gjkd_proto::decode_shape`]).
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
    let shape = gjkd_proto::decode_shape(request, vertices, limits.max_pieces)?;
    Ok(NewObject { shape, pose, name })
}
