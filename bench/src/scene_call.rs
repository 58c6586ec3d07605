//! The one place the benchmarks send a scene request
//! ([`gjkd_proto::SceneRequest`]) through the client, so that the
//! benchmarks are written against the wire types alone.

use gjkd_client::{Client, Item};
use gjkd_proto::{SceneReply, SceneRequest, SceneRow};

use crate::BenchError;

/// Whether this build's client can send scene requests; the benchmarks
/// leave their scene columns out when it cannot.
pub fn available() -> bool {
    false
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
    let _ = (client, request, items, rows);
    Err(BenchError::Other(
        "this build's client has no scene requests".into(),
    ))
}
