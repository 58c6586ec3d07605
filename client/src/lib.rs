//! # gjkd-client
//!
//! Client of the gjkd distance server. A [`Client`] talks to a `gjkd serve`
//! process on the same host through iceoryx2 shared memory: register convex
//! objects once, then ask for distances between them at changing poses, one
//! pair at a time or in batches. The server keeps each pair's last simplex
//! per client, so a sequence of queries along a motion starts warm.
//!
//! Start a server first (`gjkd serve`, or `gjkd serve --service NAME` to run
//! several side by side), then:
//!
//! ```no_run
//! use gjkd_client::{Client, QueryOptions};
//! use nalgebra::{Isometry3, Point3, Vector3};
//!
//! # fn main() -> Result<(), gjkd_client::ClientError> {
//! let mut client = Client::connect("gjkd")?;
//! let ball = client.register_sphere(0.5)?;
//! let crate_ = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;
//!
//! // Poses are stored by the server until changed...
//! client.set_pose(ball, &Isometry3::translation(3.0, 0.0, 0.0))?;
//! let answer = client.distance(crate_, ball, &QueryOptions::default())?;
//! assert!((answer.distance - 1.5).abs() < 1e-9);
//! println!("nearest points {} and {}", answer.point_a, answer.point_b);
//!
//! // ...or given per query, leaving the stored ones alone.
//! let answer = client.distance_at(
//!     crate_, &Isometry3::identity(),
//!     ball, &Isometry3::translation(0.0, 4.0, 0.0),
//!     &QueryOptions::default(),
//! )?;
//! assert!((answer.distance - 2.5).abs() < 1e-9);
//! # Ok(())
//! # }
//! ```
//!
//! ## Batches
//!
//! [`Client::query_batch`] sends any mix of pose updates and pair queries as
//! one request and writes the results, in order, into a buffer you own: no
//! buffers are allocated per call. Each result carries its own error code.
//!
//! ```no_run
//! use gjkd_client::{Client, ErrorCode, Item, ItemResult, QueryOptions};
//! use nalgebra::{Isometry3, Vector3};
//!
//! # fn main() -> Result<(), gjkd_client::ClientError> {
//! let mut client = Client::connect("gjkd")?;
//! let robot = client.register_cuboid(Vector3::new(0.5, 0.5, 1.0), 0.05)?;
//! let obstacles: Vec<_> = (0..8)
//!     .map(|_| client.register_sphere(0.3))
//!     .collect::<Result<_, _>>()?;
//! for (i, &o) in obstacles.iter().enumerate() {
//!     client.set_pose(o, &Isometry3::translation(2.0 + i as f64, 0.0, 0.0))?;
//! }
//!
//! let mut items = Vec::new();
//! let mut results = vec![ItemResult::default(); obstacles.len() + 1];
//! for step in 0..100 {
//!     items.clear();
//!     let pose = Isometry3::translation(0.05 * step as f64, 0.0, 0.0);
//!     items.push(Item::set_pose(robot, &pose));
//!     for &o in &obstacles {
//!         items.push(Item::distance(robot, o, &QueryOptions::default()));
//!     }
//!     client.query_batch(&items, &mut results)?;
//!     for r in &results[1..] {
//!         match r.answer() {
//!             Ok(a) => println!("{:.3}", a.distance),
//!             Err(ErrorCode::UnknownObject) => println!("removed meanwhile"),
//!             Err(e) => println!("error: {e}"),
//!         }
//!     }
//! }
//! # Ok(())
//! # }
//! ```
//!
//! ## Scene queries
//!
//! [`Client::clearance`], [`Client::within`], [`Client::nearest`] and
//! [`Client::path`] ask about a group of objects against the whole scene in
//! one round trip (the nearest obstacle of each robot link, every pair
//! within a margin, the k nearest objects, all of it along a candidate
//! motion), into a buffer of rows you own; see [`SceneQuery`].
//!
//! ## Features
//!
//! - `robots` (off by default): robots from URDF (`Client::register_robot`,
//!   `RobotHandle`, joint paths, `Client::edge_contact`) and meshes from
//!   files or arrays (`Client::register_mesh_file`). It links `gjkd-model`
//!   and through it parry3d-f64, urdf-rs and mesh-loader, which a client of
//!   spheres, boxes, capsules, cylinders and hulls does without. Without it
//!   a client still reaches robots others registered (or the scene file
//!   loaded) by name: [`Client::robot_id`] for scene questions,
//!   [`Item::set_joints`] to move them, [`Client::remove_robot`].
//!   `cargo add gjkd-client --features robots`.
//! - `shared-access`: shared-memory files every user may open (see the
//!   README's "Access" section).
//!
//! ## Errors, timeouts and a server that goes away
//!
//! Each call returns the error of its operation, as iceoryx2 does:
//! [`RegisterError`], [`RemoveError`], [`LookupError`], [`PoseError`],
//! [`QueryError`], [`PoseReadError`], [`StatsError`], [`SceneError`],
//! [`RobotError`] (and [`ConnectError`] for connecting). Each holds the
//! server's refusals that call can meet as variants of their own, the
//! faults found before sending, and the connection faults as its
//! `Connection(`[`ConnectError`]`)` variant; each converts into
//! [`ClientError`], so `?` into one type works on every call, and each
//! variant's `code()` is the [`ErrorCode`] Python and C report for the same
//! fault (`docs/errors.md` has the table per operation).
//!
//! ```no_run
//! use gjkd_client::{Client, Geometry, QueryError, QueryOptions, RegisterError};
//! use nalgebra::Isometry3;
//!
//! # fn main() -> Result<(), gjkd_client::ClientError> {
//! let mut client = Client::connect("gjkd")?;
//! let ball = Geometry::Sphere { radius: 0.5 };
//! let id = match client.register_named("ball", &ball, &Isometry3::identity()) {
//!     Err(RegisterError::NameTaken) => client.lookup("ball")?,
//!     other => other?,
//! };
//! match client.distance(id, id, &QueryOptions::default()) {
//!     Err(QueryError::UnknownObject) => println!("removed meanwhile"),
//!     other => println!("{:?}", other?.distance),
//! }
//! # Ok(())
//! # }
//! ```
//!
//! Every call returns within the client's timeout (default one second, see
//! [`ClientBuilder::timeout`]). If the server has died or stopped, the call
//! fails with [`ConnectError::ServerGone`] (in its `Connection` variant;
//! [`ClientError::ServerGone`] in the umbrella); later calls reconnect by themselves
//! once a server serves the name again. A server started with persistence
//! (the default of `gjkd serve`) reloads every object whose registration it
//! acknowledged, with the same id, geometry, name, owner and latest stored
//! pose, so after a restart the same ids go on working and this `Client`
//! can still remove what it registered. A server started with
//! `--no-persist` starts empty: old ids then get
//! [`ErrorCode::UnknownObject`], never some other object. A registration
//! is the one call that retries by itself, safely (see [`Client::register`]):
//! a server restarted within its timeout answers it with the object it
//! stored, never a second one. Warm starts are
//! not kept across a restart (the first query of each pair is cold).
//!
//! ## Bad input
//!
//! Every field of every request is checked by the server; each bad value has
//! its own [`ErrorCode`] (the full table is in `docs/errors.md`), a bad item
//! fails alone while the rest of its batch is answered, and nothing a client
//! sends can make the server panic or lose an object.
//!
//! A `Client` is not `Send` (iceoryx2 ports are bound to their thread): create
//! one per thread. Each holds one iceoryx2 node and two client ports (three
//! after its first scene query).
//!
//! iceoryx2 runs with its built-in defaults when no config file exists, as
//! gjkd expects, and says so on stderr in every process. The first connect
//! sets iceoryx2's log level to errors only, unless `IOX2_LOG_LEVEL` is set
//! (`IOX2_LOG_LEVEL=warn` brings its warnings back) or the program set
//! another level through iceoryx2 before.

#![warn(missing_docs)]

mod builder;
mod connection;
mod ending;
mod error;
mod gradient;
mod objects;
mod op_error;
mod open_failure;
mod pairs;
mod path_split;
mod poses;
mod refusals;
mod reuse;
#[cfg(feature = "robots")]
mod robots;
mod scene;

pub use builder::{ClientBuilder, DEFAULT_TIMEOUT};
pub use connection::Client;
pub use error::{ClientError, ConnectError};
pub use gradient::{gradient_matrix, row_gradient};
pub use op_error::{
    LookupError, PoseError, PoseReadError, QueryError, RegisterError, RemoveError, RobotError,
    SceneError, StatsError,
};
#[cfg(feature = "robots")]
pub use robots::{
    JointError, Kinematics, LimitMode, Mesh, MeshError, MeshMode, PackagePath, RegisteredMesh,
    RobotHandle, RobotModel, with_geometry,
};
pub use scene::{Contact, Group, ScenePair, SceneQuery, SceneSummary, Steps};

/// Where and how urgently the calling thread runs: pin the thread that
/// sends queries to a CPU of its own (`rt::pin_current_thread`) and, where
/// permitted, give it a real-time priority (`rt::set_realtime_priority`),
/// as `gjkd serve --cpu N --priority P` does for the server. Which to use
/// when, with measured figures: `docs/deployment.md`.
pub use gjkd_rt as rt;

pub use gjkd_proto::{
    Answer, DEFAULT_MAX_ITERATIONS, DEFAULT_SERVICE, DEFAULT_TOLERANCE, ErrorCode,
    GRADIENT_COLUMNS, Geometry, Gradient, Item, ItemKind, ItemResult, MAX_NAME_LEN, MAX_PIECES,
    ObjectId, PROTOCOL_VERSION, Piece, Pose, Precision, QueryOptions, SceneReply, SceneRequest,
    SceneRow, ServerInfo, ServerStats, ShapeError, Status, WaitMode, gradient_flags, item_flags,
    result_flags, scene_flags, scene_reply_flags,
};

/// The signed distance of a pair query asked with
/// [`QueryOptions::signed_distance`].
pub use gjkd_proto::SignedDistance;

/// A pair item's gradient as the query reply carries it, for
/// [`Client::query_batch_read_gradients`].
pub use gjkd_proto::GradientRow;

// The crate's own plumbing, shared by the files that make up `Client`.
pub(crate) use connection::Waited;
pub(crate) use error::{ipc_err, reply_accepted};
pub(crate) use refusals::op_error;
