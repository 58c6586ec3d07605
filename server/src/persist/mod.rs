//! Persistence: the objects kept across a crash or a restart. The
//! [`database`] holds every registered object, the [`journal`] the latest
//! pose of each, [`legacy`] migrates the state file of the format before;
//! [`attach`] plugs them into the engine (as its
//! [`Durability`](crate::engine::durability::Durability)) and
//! [`open_state`] opens the store of a persisting server.

mod backends;
pub mod database;
mod disk;
pub mod journal;
pub mod legacy;

#[cfg(test)]
mod tests;

pub use disk::{attach, default_path, open_state};
