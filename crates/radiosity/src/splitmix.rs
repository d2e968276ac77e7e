//! SplitMix64's output function (Steele, Lea and Flood, "Fast splittable pseudorandom number
//! generators", OOPSLA 2014) as a hash: deterministic jitter for stratified samples, seeded
//! by what they belong to (a pixel, a link) rather than by a generator's history, so the
//! result does not depend on which thread draws them. Hand-written: five lines, and the
//! `rand` generators need a state where these need a hash.

/// A bijection of u64 that scatters nearby inputs.
pub(crate) fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A point in [0, 1)^2 that depends on `salt` and `stratum` only: the jitter of one stratum.
pub(crate) fn jitter(salt: u64, stratum: usize) -> (f64, f64) {
    let a = splitmix64(salt ^ splitmix64(stratum as u64));
    let b = splitmix64(a);
    let unit = |h: u64| (h >> 11) as f64 / (1u64 << 53) as f64;
    (unit(a), unit(b))
}
