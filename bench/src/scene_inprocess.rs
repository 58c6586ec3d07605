//! The scene engine called in process ([`gjkd_server::engine::state::State::scene`]),
//! without a server process or a round trip: what `gjkd bench
//! scene-robot` sets beside the scene requests, to tell the engine's work
//! from the transport's.

use gjkd_client::{Item, ObjectId};
use gjkd_proto::{SceneReply, SceneRequest, SceneRow, WaitMode};
use gjkd_server::engine::objects::{NewObject, Owner};
use gjkd_server::engine::{Limits, State};
use nalgebra::Isometry3;

use crate::BenchError;
use crate::scene_world::Body;

/// The client id the in-process engine answers as.
const CLIENT: u128 = 1;

/// A server's state holding the scene, asked directly.
pub struct InProcess {
    state: State,
}

impl InProcess {
    /// A state with the server's default limits.
    pub fn new() -> Self {
        InProcess {
            state: State::new(Limits::default(), WaitMode::Spin, 1),
        }
    }

    /// Adds `body` at `pose`, returning its id.
    ///
    /// # Errors
    /// When the body is degenerate or the store refuses it.
    pub fn add(&mut self, body: &Body, pose: &Isometry3<f64>) -> Result<ObjectId, BenchError> {
        self.add_shape(body.gjk()?.into(), pose)
    }

    /// Adds `shape` at `pose`, returning its id.
    ///
    /// # Errors
    /// When the store refuses it.
    pub fn add_shape(
        &mut self,
        shape: gjk::Shape,
        pose: &Isometry3<f64>,
    ) -> Result<ObjectId, BenchError> {
        let new = NewObject {
            shape,
            pose: *pose,
            name: None,
        };
        self.state
            .insert(new, Owner::Client(CLIENT))
            .map(ObjectId::from_raw)
            .map_err(BenchError::from_code)
    }

    /// Answers a scene request as the server would.
    ///
    /// # Errors
    /// The reply's error code.
    pub fn query(
        &mut self,
        request: &SceneRequest,
        items: &[Item],
        rows: &mut [SceneRow],
    ) -> Result<SceneReply, BenchError> {
        let reply = self.state.scene(CLIENT, request, items, rows);
        match reply.error_code() {
            gjkd_client::ErrorCode::Ok => Ok(reply),
            e => Err(BenchError::from_code(e)),
        }
    }
}

impl Default for InProcess {
    fn default() -> Self {
        Self::new()
    }
}
