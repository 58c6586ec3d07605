//! What the property tests of this crate share.

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
