//! A memo of the exact form factors of near patch pairs, keyed by the pair's shape up to
//! translation.
//!
//! Near pairs (bounding spheres overlapping) take the double contour integral
//! ([`crate::form_factor::exact::polygon_to_polygon`]), about twenty times the cost of
//! Lambert's point formula; in the first refinement of the million-element building it was
//! 60 % of the CPU (`perf`, December 2026). The quadtrees of a meshed room repeat pair
//! shapes (a wall piece beside the floor piece under it, at each level, in every room of
//! the same size), so the memo computes each shape once: on the million-element building
//! 1.77 M shapes were computed and 1.32 M pairs reused them (43 %), and the solve's CPU
//! time fell by 16 % (BENCHMARKS.md, issue #11).
//!
//! The key is the two polygons' corners relative to the lowest corner of their common box,
//! snapped to a grid of 2^-31 of the box's extent rounded up to a power of two (so that the
//! snapped corners are exact in f64), the pair put in a canonical order (the one with the
//! smaller key first) so that p <- q and q <- p share an entry. The value is computed from
//! the *snapped* polygons, so it is a function of the key alone: which pair of a shape comes
//! first (the threads' order) cannot change any result, and the output stays deterministic.
//! Snapping moves a corner by at most 2.4e-10 of the pair's extent: the form factor, whose
//! derivative in a corner is at worst logarithmic (edges meeting), moves by less than 1e-8
//! of itself, far below the link estimates' own error (visibility from sixteen point pairs).
//!
//! Polygons of more than [`MAX_CORNERS`] corners (none in the quadtrees, which hold quads and
//! triangles) are not memoized.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use glam::DVec3;

use crate::form_factor::exact::polygon_to_polygon;
use crate::geometry::area_vector;

/// The most corners a memoized polygon has.
pub(super) const MAX_CORNERS: usize = 4;
/// Grid steps per power-of-two extent: 2^31 (coordinates fit a u32).
const GRID_BITS: i32 = 31;
/// Shards of the memo (the refinement's threads insert concurrently).
const SHARDS: usize = 64;
/// Bytes one entry holds (key, value and the hash table's slack), for the memory account.
pub(super) const ENTRY_BYTES: u64 = 2 * std::mem::size_of::<(PairKey, Value)>() as u64;

/// The snapped corners of both polygons (x, y, z each), the corner counts and the grid's
/// power of two.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub(super) struct PairKey {
    coords: [[u32; 3 * MAX_CORNERS]; 2],
    counts: [u8; 2],
    exponent: i16,
}

/// F from the key's first polygon to its second, and the first's area over the second's
/// (both of the snapped polygons).
#[derive(Clone, Copy)]
pub(super) struct Value {
    f_first: f64,
    area_ratio: f64,
}

/// FNV-1a over the key's bytes, as the `fnv` crate does, but written over whole words: the
/// key is 100 bytes and byte-at-a-time hashing would cost more than the lookups it saves.
#[derive(Default)]
struct WordHasher(u64);

impl Hasher for WordHasher {
    fn finish(&self) -> u64 {
        // A final avalanche (splitmix64's) so that the shard (low bits) and the table's
        // buckets (high bits) both see every input word.
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u32(&mut self, word: u32) {
        self.write_u64(word as u64);
    }
    fn write_u64(&mut self, word: u64) {
        self.0 = (self.0 ^ word).wrapping_mul(0x0000_0100_0000_01b3) ^ 0xcbf2_9ce4_8422_2325;
    }
}

type Shard = HashMap<PairKey, Value, BuildHasherDefault<WordHasher>>;

/// The memo: sharded, bounded, counting its hits.
pub(super) struct NearPairMemo {
    shards: Vec<Mutex<Shard>>,
    /// Entries each shard takes; past that, pairs are computed and not kept.
    shard_capacity: usize,
    hits: AtomicU64,
    misses: AtomicU64,
    /// Misses not kept because their shard was full.
    not_kept: AtomicU64,
}

impl NearPairMemo {
    /// A memo holding at most `max_bytes` (at least one entry per shard).
    pub(super) fn new(max_bytes: u64) -> Self {
        let shard_capacity = ((max_bytes / ENTRY_BYTES) as usize / SHARDS).max(1);
        Self {
            shards: (0..SHARDS).map(|_| Mutex::new(Shard::default())).collect(),
            shard_capacity,
            hits: AtomicU64::new(0),
            misses: AtomicU64::new(0),
            not_kept: AtomicU64::new(0),
        }
    }

    /// Entries held.
    pub(super) fn len(&self) -> usize {
        self.shards
            .iter()
            .map(|s| s.lock().map(|s| s.len()).unwrap_or(0))
            .sum()
    }

    /// (shapes computed, pairs that reused a computed shape) so far. Counted from the
    /// distinct keys held, not from the misses: two threads meeting a new shape at once both
    /// compute it, and which thread wins changes between runs, while the distinct shapes and
    /// the lookups do not (until a shard is full), so the printed figures stay the same.
    pub(super) fn counts(&self) -> (u64, u64) {
        let lookups = self.hits.load(Ordering::Relaxed) + self.misses.load(Ordering::Relaxed);
        let computed = (self.len() as u64 + self.not_kept.load(Ordering::Relaxed)).min(lookups);
        (computed, lookups - computed)
    }

    /// F from `p1` to `p2` (see [`polygon_to_polygon`]) of the pair snapped to the key's
    /// grid, from the memo when the shape was seen before.
    pub(super) fn form_factor(&self, p1: &[DVec3], p2: &[DVec3]) -> f64 {
        let Some((key, swapped, step)) = pair_key(p1, p2) else {
            return polygon_to_polygon(p1, p2);
        };
        let mut hasher = WordHasher::default();
        key.hash(&mut hasher);
        let shard = &self.shards[(hasher.finish() as usize) % SHARDS];
        let found = shard.lock().ok().and_then(|s| s.get(&key).copied());
        let value = match found {
            Some(v) => {
                self.hits.fetch_add(1, Ordering::Relaxed);
                v
            }
            None => {
                self.misses.fetch_add(1, Ordering::Relaxed);
                let v = evaluate(&key, step);
                if let Ok(mut s) = shard.lock() {
                    if s.len() < self.shard_capacity {
                        s.insert(key, v);
                    } else if !s.contains_key(&key) {
                        self.not_kept.fetch_add(1, Ordering::Relaxed);
                    }
                }
                v
            }
        };
        if swapped {
            // F_21 = F_12 A_1 / A_2 (reciprocity), with 1 the key's first polygon.
            value.f_first * value.area_ratio
        } else {
            value.f_first
        }
    }
}

/// The key of the pair, whether the key's first polygon is `p2`, and the grid step.
fn pair_key(p1: &[DVec3], p2: &[DVec3]) -> Option<(PairKey, bool, f64)> {
    if !(3..=MAX_CORNERS).contains(&p1.len()) || !(3..=MAX_CORNERS).contains(&p2.len()) {
        return None;
    }
    let (mut lo, mut hi) = (p1[0], p1[0]);
    for &v in p1.iter().chain(p2) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    let extent = (hi - lo).max_element();
    if !(extent > 0.0 && extent.is_finite()) {
        return None;
    }
    // extent <= 2^exponent; the step is 2^(exponent - 31), a power of two.
    let exponent = extent.log2().ceil() as i32;
    let step = 2f64.powi(exponent - GRID_BITS);
    let snap = |poly: &[DVec3]| {
        let mut out = [0u32; 3 * MAX_CORNERS];
        for (k, &v) in poly.iter().enumerate() {
            let g = ((v - lo) / step).round();
            // 0 <= g <= 2^31 by construction; the clamp only guards rounding at the top.
            out[3 * k] = g.x.clamp(0.0, u32::MAX as f64) as u32;
            out[3 * k + 1] = g.y.clamp(0.0, u32::MAX as f64) as u32;
            out[3 * k + 2] = g.z.clamp(0.0, u32::MAX as f64) as u32;
        }
        out
    };
    let (a, b) = ((snap(p1), p1.len() as u8), (snap(p2), p2.len() as u8));
    let swapped = (b.1, b.0) < (a.1, a.0);
    let (first, second) = if swapped { (b, a) } else { (a, b) };
    let key = PairKey {
        coords: [first.0, second.0],
        counts: [first.1, second.1],
        exponent: exponent as i16,
    };
    Some((key, swapped, step))
}

/// The memo's value for `key`: computed from the snapped polygons alone.
fn evaluate(key: &PairKey, step: f64) -> Value {
    let corners = |which: usize| -> Vec<DVec3> {
        let c = &key.coords[which];
        (0..key.counts[which] as usize)
            .map(|k| DVec3::new(c[3 * k] as f64, c[3 * k + 1] as f64, c[3 * k + 2] as f64) * step)
            .collect()
    };
    let (first, second) = (corners(0), corners(1));
    let (a1, a2) = (area_vector(&first).length(), area_vector(&second).length());
    Value {
        f_first: polygon_to_polygon(&first, &second),
        area_ratio: if a2 > 0.0 { a1 / a2 } else { 0.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::form_factor::reference;

    fn square(origin: DVec3, u: DVec3, v: DVec3) -> Vec<DVec3> {
        vec![origin, origin + u, origin + u + v, origin + v]
    }

    /// A unit floor square and the wall square standing on its far edge, facing it: the
    /// perpendicular plates with a common edge (Howell's catalogue, C-14: 0.2000438).
    fn floor_and_wall(at: DVec3) -> (Vec<DVec3>, Vec<DVec3>) {
        let floor = square(at, DVec3::X, DVec3::Y);
        let wall = square(at + DVec3::Y, DVec3::X, DVec3::Z);
        (floor, wall)
    }

    #[test]
    fn memoized_form_factors_agree_with_the_closed_form_in_both_directions() {
        let memo = NearPairMemo::new(1 << 20);
        let want = reference::perpendicular_rectangles(1.0, 1.0, 1.0);
        for at in [
            DVec3::ZERO,
            DVec3::new(3.7, -2.1, 0.3),
            DVec3::new(1e3, 1e3, 1e3),
        ] {
            let (floor, wall) = floor_and_wall(at);
            let f = memo.form_factor(&floor, &wall);
            let back = memo.form_factor(&wall, &floor);
            // The snapped corners move by at most 2.4e-10 of the extent (at 1e3 away the
            // corners' own rounding is 1e-13): 1e-8 bounds the form factor's change.
            assert!((f - want).abs() < 1e-8 * want, "{f} vs {want} at {at}");
            assert!(
                (back - want).abs() < 1e-8 * want,
                "{back} vs {want} at {at}"
            );
        }
        // One shape, six lookups: the first computes, the five others (the reverse
        // direction and the translated copies) hit.
        assert_eq!(memo.counts(), (1, 5));
        assert_eq!(memo.len(), 1);
    }

    #[test]
    fn different_shapes_get_different_entries_and_their_own_values() {
        let memo = NearPairMemo::new(1 << 20);
        let (floor, wall) = floor_and_wall(DVec3::ZERO);
        let narrow = square(DVec3::Y, DVec3::X, 0.5 * DVec3::Z);
        let f_square = memo.form_factor(&floor, &wall);
        let f_narrow = memo.form_factor(&floor, &narrow);
        assert_eq!(memo.counts(), (2, 0));
        assert!((f_square - polygon_to_polygon(&floor, &wall)).abs() < 1e-8 * f_square);
        assert!((f_narrow - polygon_to_polygon(&floor, &narrow)).abs() < 1e-8 * f_narrow);
        assert!(f_narrow < f_square);
    }

    #[test]
    fn a_full_memo_computes_without_keeping() {
        // Room for one entry per shard; many shapes still come out right.
        let memo = NearPairMemo::new(0);
        for k in 1..200 {
            let h = 0.5 + 0.01 * k as f64;
            let (floor, _) = floor_and_wall(DVec3::ZERO);
            let wall = square(DVec3::Y, DVec3::X, h * DVec3::Z);
            let got = memo.form_factor(&floor, &wall);
            let want = polygon_to_polygon(&floor, &wall);
            assert!((got - want).abs() < 1e-8 * want, "{h}: {got} vs {want}");
        }
        assert!(memo.len() <= SHARDS);
        // 199 different shapes, each computed once, whether kept or not.
        assert_eq!(memo.counts(), (199, 0));
    }
}
