//! # gjkd-server
//!
//! The gjkd distance server as a library: the server's state ([`state`]),
//! its object store ([`store`]) and request handlers ([`requests`]), the
//! per-pair warm-start cache ([`cache`]), scene files ([`scene`]), the
//! scene service's engine ([`scene_query`]), the
//! database that keeps objects across crashes ([`database`], with the
//! stored form of objects in [`stored`] and the migration of the old state
//! file in [`legacy`]), the pose journal ([`journal`]), the offline
//! `gjkd objects` command ([`offline`]), the iceoryx2 serving loop
//! ([`server`]) with its wait policy ([`wait`]), and the daemon's commands
//! with their flags ([`commands`]).
//! The `gjkd` binary (package `gjkd`) is a thin command line over these and
//! the tools of `gjkd-bench`.
//!
//! The handlers are pure functions of the [`State`](state::State) and the
//! request's bytes, so they can be tested and fuzzed without any IPC:
//!
//! ```
//! use gjkd_server::state::{Limits, State};
//! use gjkd_proto::{AdminOp, AdminRequest, ErrorCode, Item, ItemResult, ObjectId, QueryOptions,
//!     Vertex, WaitMode, shape_kind};
//!
//! let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
//! let mut reg = AdminRequest::new(AdminOp::Register);
//! reg.shape = shape_kind::CONVEX;
//! reg.piece_count = 1;
//! reg.pieces[0].vertex_count = 1;
//! reg.pieces[0].radius = 0.5;
//! let ball = state.handle_admin(1, &reg, &[Vertex::default()]).id;
//! let other = state.handle_admin(1, &reg, &[Vertex { x: 3.0, y: 0.0, z: 0.0 }]).id;
//!
//! let items = [Item::distance(ObjectId::from_raw(ball), ObjectId::from_raw(other), &QueryOptions::default())];
//! let mut results = [ItemResult::default()];
//! state.handle(42, &items, &mut results);
//! assert_eq!(results[0].answer().unwrap().distance, 2.0);
//! ```

#![warn(missing_docs)]

pub mod cache;
pub mod commands;
pub mod database;
pub mod journal;
pub mod legacy;
pub mod offline;
pub mod requests;
pub mod robots;
pub mod scene;
pub mod scene_query;
pub mod scene_robots;
pub mod server;
pub mod state;
pub mod store;
pub mod stored;
pub mod tokens;
pub mod wait;
