//! The request handlers: pure functions of the [`State`](super::State) and
//! the bytes a client sent, with no iceoryx2 in sight, so that they can be
//! tested and fuzzed in-process. Each service has its file; the decoding of
//! a registration is [`decode`]'s.
//!
//! Nothing here trusts the request: every field is checked, every failure is
//! an [`ErrorCode`](gjkd_proto::ErrorCode) in the result, and nothing panics
//! on any input.

pub mod admin;
pub mod decode;
pub mod poses;
pub mod query;
