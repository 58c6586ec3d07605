//! What the property tests of this crate share.

use gjkd_testkit::reference::V;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// Cases per property unless `PROPTEST_CASES` says otherwise.
const CASES: u32 = 512;

/// A property test's configuration with a fixed `seed`, so that runs are
/// reproducible; `PROPTEST_RNG_SEED` and `PROPTEST_CASES` in the
/// environment override seed and case count. Nothing is written to disk.
pub fn config(seed: u64) -> Config {
    let mut c = Config {
        failure_persistence: None,
        ..Config::default()
    };
    if std::env::var_os("PROPTEST_CASES").is_none() {
        c.cases = CASES;
    }
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        c.rng_seed = RngSeed::Fixed(seed);
    }
    c
}

/// A vector with coordinates in `[-1, 1)`.
pub fn vec3() -> impl Strategy<Value = V> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y, z)| V::new(x, y, z))
}

/// A pose: a translation of up to `spread` along each axis and any
/// rotation (a rotation vector of up to π along each axis).
pub fn pose(spread: f64) -> impl Strategy<Value = Isometry3<f64>> {
    (vec3(), vec3()).prop_map(move |(t, w)| {
        Isometry3::from_parts(
            Translation3::from(t * spread),
            UnitQuaternion::from_scaled_axis(w * std::f64::consts::PI),
        )
    })
}
