//! # gjkd-server
//!
//! The gjkd distance server as a library, in layers whose arrows point one
//! way (see `docs/architecture.md`):
//!
//! - [`engine`]: everything the server holds and answers, no IPC and no
//!   file: the [`State`](engine::State) façade over the object store, the
//!   warm-start cache, the robots and the group queries, with its request
//!   handlers;
//! - [`persist`]: the database that keeps objects across crashes, the pose
//!   journal and the migration of the old state file, plugged into the
//!   engine;
//! - [`scene`]: the scene file (`--scene`) of named, read-only objects and
//!   robots;
//! - [`server`]: the iceoryx2 serving loop, with its wait policy in
//!   [`wait`]; [`offline`]: the offline
//!   `gjkd objects` command; [`commands`]: the daemon's commands with their
//!   flags.
//!
//! The `gjkd` binary (package `gjkd`) is a thin command line over these and
//! the tools of `gjkd-bench`.
//!
//! The handlers are pure functions of the [`State`](engine::State) and the
//! request's bytes, so they can be tested and fuzzed without any IPC:
//!
//! ```
//! use gjkd_server::engine::{Limits, State};
//! use gjkd_proto::{AdminOp, AdminRequest, ErrorCode, Item, ItemResult, ObjectId, QueryOptions,
//!     Vertex, WaitMode, shape_kind};
//!
//! let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
//! let mut reg = AdminRequest::new(AdminOp::Register);
//! reg.shape = shape_kind::CONVEX;
//! reg.piece_count = 1;
//! reg.pieces[0].vertex_count = 1;
//! reg.pieces[0].rounding = 0.5;
//! let ball = state.handle_admin(1, &reg, &[Vertex::default().into()]).id;
//! let other = state.handle_admin(1, &reg, &[Vertex { x: 3.0, y: 0.0, z: 0.0 }.into()]).id;
//!
//! let items = [Item::distance(ObjectId::from_raw(ball), ObjectId::from_raw(other), &QueryOptions::default())];
//! let mut results = [ItemResult::default()];
//! state.handle(42, &items, &mut results);
//! assert_eq!(results[0].answer().unwrap().distance, 2.0);
//! ```

#![warn(missing_docs)]

pub mod commands;
pub mod engine;
pub mod offline;
pub mod persist;
pub mod scene;
pub mod server;
pub mod wait;
