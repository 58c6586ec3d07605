//! Numeric helpers that the shapes and the query share: double-double
//! arithmetic ([`dd`]) and exact power-of-two scaling ([`scale`]).

pub(crate) mod dd;
mod scale;

pub(crate) use scale::{pow2_scale, robust_norm};
