//! The samples of the global stage: an Owen-scrambled Sobol' sequence
//! (Burley 2020, "Practical hash-based Owen scrambling", with the Joe–Kuo
//! direction numbers; the `sobol_burley` crate) with a fixed seed, so that
//! every run, thread count and resumption sees the same points.
//!
//! It replaces a Halton sequence whose 12 prime bases repeated from the
//! 13th coordinate on: coordinates d and d + 12 were identical, so for
//! M > 13 the samples lay on a diagonal of the box.
//!
//! Properties the search relies on (and
//! crates/cosserat-cli/tests/optimizer_trust.rs checks): the first 2^m
//! points are a (t, m, s)-net in base 2 — in particular every
//! coordinate alone is stratified, one point in each interval of width
//! 2^−m — and the scrambling preserves that while removing the lattice
//! structure of the unscrambled sequence.
//!
//! The crate's limits are handled here, never passed on as unspecified
//! values: it has 256 dimensions and 2^16 points per seed. Coordinates
//! beyond 256 and points beyond 2^16 use further seeds (Burley's
//! "padding": each block of 256 coordinates and each block of 2^16 points
//! is its own scrambled net, the blocks randomly associated).

/// The seed of the sequence (any fixed value; fixed so runs repeat).
const SEED: u32 = 0x0c05_5e7a;

/// Points per seed (the crate's limit).
const BLOCK: usize = 1 << 16;

/// Coordinates per seed (the crate's limit).
const DIMENSIONS: usize = sobol_burley::NUM_DIMENSIONS as usize;

/// The seed of the block of points `block` and coordinates `pad`.
fn seed(block: usize, pad: usize) -> u32 {
    // Distinct small integers give distinct seeds; the crate hashes them.
    let mix = (block as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (pad as u64);
    SEED ^ (mix as u32) ^ ((mix >> 32) as u32)
}

/// Point `index` (from 0) of the sequence in [0, 1)^`dimensions`.
pub fn unit_point(index: usize, dimensions: usize) -> Vec<f64> {
    let (block, i) = (index / BLOCK, index % BLOCK);
    (0..dimensions)
        .map(|d| {
            let (pad, dim) = (d / DIMENSIONS, d % DIMENSIONS);
            f64::from(sobol_burley::sample(i as u32, dim as u32, seed(block, pad)))
        })
        .collect()
}
