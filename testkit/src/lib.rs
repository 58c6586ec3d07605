//! # gjkd-testkit
//!
//! What the tests, benches and measurements of gjk and gjkd share, and what
//! none of them may own alone: it is not published, and nothing it holds is
//! part of gjk's API.
//!
//! - [`reference`](mod@reference): the brute-force distance between convex hulls, owing
//!   nothing to GJK, against which gjk's answers are judged.
//! - [`minkowski_depth`]: the brute-force penetration depth, from the
//!   Minkowski difference's facets, for the signed distance's tests.
//! - [`check`]: one answer against that reference, every property at once.
//! - [`dense`]: dense sampling of a motion for its first pose within a
//!   distance, skipping only samples a motion bound decides.
//! - [`paper`]: the polytopes and pairs of the paper's Section 7 and the
//!   collision sweep of its Section 8, rebuilt deterministically.
//! - [`sweep`]: randomised extreme cases whose distance is known by
//!   construction.
//! - [`input`]: inputs written by hand or copied from a failing run.
//! - `parry` (feature `parry`): the same geometry handed to parry3d-f64, for
//!   the comparisons.
//!
//! gjk's integration tests that need any of these live in this crate's
//! `tests/`: gjk cannot depend on its own test kit, even for its tests,
//! since the kit depends on gjk.

#![warn(missing_docs)]

pub mod check;
pub mod dense;
pub mod input;
pub mod minkowski_depth;
/// The paper's test data (crate `gjkd-paper`, apart so that `gjkd demo`
/// does not link the test kit).
pub use gjkd_paper as paper;
#[cfg(feature = "parry")]
pub mod parry;
pub mod reference;
pub mod sweep;
