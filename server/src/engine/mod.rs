//! The engine: everything the server holds and every answer it gives, with
//! no iceoryx2 and no file in sight, so that it runs in-process (tests, the
//! fuzzer, Python's `gjkd.Local`) exactly as behind the services.
//!
//! [`State`] is the façade: it owns the object store ([`objects`]), the
//! warm-start cache ([`warm_cache`]), the robots ([`robots`]) and the group
//! queries' engine ([`group_queries`]), and its request handlers
//! ([`handlers`]) are the entry points the serving loop calls. Below them,
//! [`checks`] holds what every shape and pose is held to and
//! [`pair_query`] the one pair query both services run, and `gradient`
//! the distance gradients both services answer with. Persistence is
//! plugged in through the [`durability::Durability`] trait, which the
//! persistence layer ([`crate::persist`]) implements.

pub mod checks;
pub mod durability;
pub(crate) mod gradient;
pub mod group_queries;
pub mod handlers;
pub mod objects;
pub mod pair_query;
pub mod records;
pub mod robots;
mod signed_pair;
pub mod state;
pub mod tokens;
pub mod warm_cache;

pub use state::{Limits, State};
