//! The fuzz tests' runner: seeded, so that a CI run is reproducible (a
//! failure there is the same failure here); `COSSERAT_FUZZ_SEED=<u64>`
//! explores other inputs, and a seed that finds a bad input becomes a
//! corpus file.

use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// A runner for `cases` inputs from the seed.
pub fn runner(cases: u32) -> TestRunner {
    let seed: u64 = std::env::var("COSSERAT_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0x5eed_c055_e7a7);
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    TestRunner::new_with_rng(
        Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &bytes),
    )
}
