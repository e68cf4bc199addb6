//! Seeded random numbers: every random choice of a run flows from its seed.

/// A generator for draw number `stream` of a run seeded with `seed`: every random choice is a
/// pure function of (seed, stream), so a resumed run makes the same choices.
pub fn rng_for(seed: u64, stream: u64) -> rand_chacha::ChaCha8Rng {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    rng
}
