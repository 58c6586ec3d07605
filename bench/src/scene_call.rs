//! The one place the benchmarks send a scene request
//! ([`gjkd_proto::SceneRequest`]) through the client, with the request's
//! items as a slice, so that the benchmarks are written against the wire
//! types alone.

use gjkd_client::{Client, Item};
use gjkd_proto::{SceneReply, SceneRequest, SceneRow, scene_reply_flags};

use crate::BenchError;

/// Whether this build's client can send scene requests; the benchmarks
/// leave their scene columns out when it cannot.
pub fn available() -> bool {
    true
}

/// Sends `request` with `items` and writes the rows into `rows`
/// (`request.max_rows` of them at most), returning the reply header.
///
/// # Errors
/// The client's, or the reply's error code.
pub fn query(
    client: &mut Client,
    request: &SceneRequest,
    items: &[Item],
    rows: &mut [SceneRow],
) -> Result<SceneReply, BenchError> {
    let summary = client.scene_with(
        request,
        items.len(),
        |i| items[i],
        |got| rows[..got.len()].copy_from_slice(got),
    )?;
    Ok(SceneReply {
        error: 0,
        flags: if summary.truncated {
            scene_reply_flags::TRUNCATED
        } else {
            0
        },
        total: summary.total,
        steps: summary.steps,
        first_hit: summary.first_hit.unwrap_or(u32::MAX),
        gjk_runs: summary.gjk_runs,
        bounded: summary.bounded,
        candidates: summary.candidates,
    })
}
