//! # gjkd-c
//!
//! The C ABI of the gjkd client, for C and C++ programs: a `cdylib`
//! (`libgjkd_c.so`) and a `staticlib` (`libgjkd_c.a`) with the header
//! `include/gjkd.h`, generated from this crate by cbindgen, and a
//! header-only C++17 wrapper `include/gjkd.hpp`.
//!
//! Every function returns a [`gjkd_status`]; a failure's words are in
//! [`gjkd_last_error`] (thread-local), a server's refusal code in
//! [`gjkd_last_error_code`]. No panic crosses the boundary: each entry
//! point runs in `catch_unwind`, and a caught panic is `GJKD_ERR_PANIC`.
//! A handle serves one call at a time, from any thread (see `handle.rs`).
//! Batch calls make their items straight into the request's shared memory
//! and copy the answers straight from the response's into the caller's
//! arrays, with no buffer in between (`Client::query_batch_with`);
//! `gjkd_query_pairs` takes rows laid out as the server's requests and
//! gives rows laid out as its answers, so both are copied whole.
//!
//! Robots and meshes need the cargo feature `robots` (off by default,
//! on in what `install.sh` installs): it links `gjkd-model` and through it
//! parry3d-f64, urdf-rs and mesh-loader. The header declares their
//! functions under `GJKD_ROBOTS`, which it defines unless the program
//! defines `GJKD_NO_ROBOTS` (as a lean install's CMake package and
//! pkg-config file do).
//!
//! The semantics are the Rust client's (`gjkd-client`) and the names follow
//! the Python API's (`gjkd.Client`): `register_sphere`, `set_poses`,
//! `distance`, `distances`, ...

#![warn(missing_docs)]
// The C names are the API.
#![allow(non_camel_case_types)]

mod args;
mod connect;
mod gradient;
mod handle;
mod lifetime;
#[cfg(feature = "robots")]
mod meshes;
mod objects;
mod poses;
mod query;
#[cfg(feature = "robots")]
mod robots;
mod rows;
mod scene;
mod signed_batch;
mod status;
mod thread;
mod types;

pub use connect::*;
pub use gradient::*;
pub use handle::gjkd_client;
pub use lifetime::*;
#[cfg(feature = "robots")]
pub use meshes::*;
pub use objects::*;
pub use poses::*;
pub use query::*;
#[cfg(feature = "robots")]
pub use robots::*;
pub use rows::*;
pub use scene::*;
pub use signed_batch::*;
pub use status::gjkd_status;
pub use thread::*;
pub use types::*;

/// The wire protocol version this library speaks; a server of another
/// version is refused with `GJKD_ERR_VERSION_MISMATCH`.
pub const GJKD_PROTOCOL_VERSION: u32 = 4;
const _: () = assert!(GJKD_PROTOCOL_VERSION == gjkd_proto::PROTOCOL_VERSION);

/// Default relative tolerance of a query: 100 × machine epsilon.
pub const GJKD_DEFAULT_TOLERANCE: f64 = 2.220446049250313e-14;
const _: () = assert!(GJKD_DEFAULT_TOLERANCE == gjkd_proto::DEFAULT_TOLERANCE);

/// Default iteration cap of a query.
pub const GJKD_DEFAULT_MAX_ITERATIONS: u32 = 128;
const _: () = assert!(GJKD_DEFAULT_MAX_ITERATIONS == gjkd_proto::DEFAULT_MAX_ITERATIONS);

/// Most pieces of a compound.
pub const GJKD_MAX_PIECES: usize = 64;
const _: () = assert!(GJKD_MAX_PIECES == gjkd_proto::MAX_PIECES);

/// Longest object name, in bytes of UTF-8 (not counting the NUL).
pub const GJKD_MAX_NAME_LEN: usize = 64;
const _: () = assert!(GJKD_MAX_NAME_LEN == gjkd_proto::MAX_NAME_LEN);

/// The largest magnitude of a pose's translation component, 2^998 (about
/// 2.68e300): a pose beyond is refused with `GJKD_CODE_NON_FINITE_POSE`
/// when it is set, so that any two stored poses stay within what a query
/// accepts.
pub const GJKD_MAX_TRANSLATION: f64 = 2.6787715179656683e300;
const _: () = assert!(GJKD_MAX_TRANSLATION == gjkd_proto::MAX_TRANSLATION);
