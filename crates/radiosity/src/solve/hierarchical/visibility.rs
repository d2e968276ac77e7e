//! Visibility sampling of a link: the visible fraction between two nodes from up to sixteen
//! point pairs (stratified points of patches, the sample points of clusters) through the
//! occluder BVH.

use glam::DVec3;

use super::solver::Solver;

/// The k-th (0..16) of 16 stratified points of a triangle or a planar convex
/// quadrilateral: one in each cell of a 4 x 4 grid of the quadrilateral's (u, v) square, or
/// in each of the 16 sub-triangles of the triangle split four times along each edge, at a
/// uniformly random spot of its cell drawn from `seed` and the cell's number (jittered
/// sampling, Cook 1986). Cell centres never come nearer the edge than half a cell, and the
/// edge is where a perpendicular occluder hides most (a window at the end of its reveals
/// sees least of the room from its rim): judged from centres, such links were too visible.
/// Jittered points are unbiased. One point at a time, because most links settle after the
/// first four pairs: drawing all 32 points of a link's two nodes up front was 6 % of the
/// million-element building's CPU time (`perf`, December 2026).
fn sample_point(poly: &[DVec3], seed: u64, k: usize) -> DVec3 {
    let (s, t) = crate::splitmix::jitter(seed, k + 1);
    if poly.len() == 4 {
        let (i, j) = (k % 4, k / 4);
        crate::mesh::bilinear(poly, (i as f64 + s) / 4.0, (j as f64 + t) / 4.0)
    } else {
        let (x, y, across) = TRIANGLE_CELLS[k];
        let (u, v) = if s + t > 1.0 {
            (1.0 - s, 1.0 - t)
        } else {
            (s, t)
        };
        let (a, e1, e2) = (poly[0], poly[1] - poly[0], poly[2] - poly[0]);
        if across {
            // The sub-triangle across the diagonal: (x + 1, y + 1) less the same.
            a + e1 * ((x + 1.0 - u) / 4.0) + e2 * ((y + 1.0 - v) / 4.0)
        } else {
            // The sub-triangle (x, y), (x + 1, y), (x, y + 1) of the lattice.
            a + e1 * ((x + u) / 4.0) + e2 * ((y + v) / 4.0)
        }
    }
}

/// The 16 sub-triangles of a triangle split four times along each edge, in the order the
/// points are numbered: the lattice corner (x, y) of each, and whether it is the one across
/// the diagonal. Row by row (y), each upright cell followed by the one across from it.
const TRIANGLE_CELLS: [(f64, f64, bool); 16] = {
    let mut cells = [(0.0, 0.0, false); 16];
    let (mut k, mut y) = (0, 0);
    while y < 4 {
        let mut x = 0;
        while x < 4 - y {
            cells[k] = (x as f64, y as f64, false);
            k += 1;
            if x + y + 1 < 4 {
                cells[k] = (x as f64, y as f64, true);
                k += 1;
            }
            x += 1;
        }
        y += 1;
    }
    cells
};

/// A stride that visits 0..n in a spread-out order: the integer nearest 0.618 n that is
/// coprime with n (1 for n <= 2).
fn spread_stride(n: usize) -> usize {
    fn gcd(a: usize, b: usize) -> usize {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    if n <= 2 {
        return 1;
    }
    let mut s = ((n as f64 * 0.618).round() as usize).max(1);
    while gcd(s, n) != 1 {
        s += 1;
    }
    s
}

/// What one thread keeps between visibility queries: the candidate occluders' list, and
/// the occluder that blocked its last ray traced through the whole hierarchy, tried first
/// by the next (the links a thread takes in turn are mostly between neighbours, hidden
/// from one another by the same wall).
#[derive(Default)]
pub(super) struct VisibilityScratch {
    candidates: Vec<u32>,
    last: Option<u32>,
}

/// The most candidate occluders a patch <- patch link tests its rays against one by one;
/// with more it traverses the whole hierarchy.
const MAX_CANDIDATES: usize = 32;

/// The 16 point pairs of a patch <- patch link: 4 x 4 stratified points on each node,
/// paired by a fixed permutation, each weighed by what it stands for of the exchange.
struct PatchPairs<'a> {
    polygons: (&'a [DVec3], &'a [DVec3]),
    seeds: (u64, u64),
    normals: (DVec3, DVec3),
    /// A sixteenth of the larger node's area: the disc that bounds a pair's kernel.
    disc: f64,
}

impl PatchPairs<'_> {
    /// The pairs' order: the first four spread over both nodes (a diagonal of the 4 x 4
    /// grid).
    const ORDER: [usize; 16] = [0, 5, 10, 15, 1, 2, 3, 4, 6, 7, 8, 9, 11, 12, 13, 14];

    /// Pairs `range` (in [`Self::ORDER`]) and their weights: the kernel cos cos / (pi d^2),
    /// bounded as the form factor to a disc of a sixteenth of the larger node (Wallace et
    /// al. 1989, eq. 7) so that two points that nearly meet do not outweigh the rest.
    fn draw(
        &self,
        range: std::ops::Range<usize>,
        pairs: &mut [(DVec3, DVec3, DVec3, DVec3); 16],
        weights: &mut [f64; 16],
    ) {
        let (mp, mq) = self.normals;
        for k in range {
            let i = Self::ORDER[k];
            let x = sample_point(self.polygons.0, self.seeds.0, i);
            let y = sample_point(self.polygons.1, self.seeds.1, (i * 5 + 3) % 16);
            pairs[k] = (x, mp, y, mq);
            let d = y - x;
            let d2 = d.length_squared();
            let (cx, cy) = (mp.dot(d), -mq.dot(d));
            weights[k] = if cx > 0.0 && cy > 0.0 {
                cx * cy / (d2 * (std::f64::consts::PI * d2 + self.disc))
            } else {
                0.0
            };
        }
    }
}

impl Solver<'_> {
    /// The visible fraction between p and q from a few point pairs, and the rays cast. Only
    /// pairs whose points face each other count (a pair with a point behind the other's
    /// plane carries no energy); when no pair faces, all pairs count. Patch <- patch links
    /// use 16 pairs (4 x 4 stratified points on each, paired by a fixed permutation) and
    /// only the occluders whose boxes overlap the pair's box and that reach in front of
    /// both nodes' planes (none: visible, no ray; more than [`MAX_CANDIDATES`]: the whole
    /// BVH);
    /// cluster links use up to eight facing pairs of sample points (a cluster keeps up to
    /// sixteen points drawn from its children's in proportion to area, see
    /// [`super::tree::ClusterSample`]) and the whole BVH, and weigh each facing pair by what
    /// it stands for of the exchange, A_x cos_x A_y cos_y / d^2 (the point-to-point kernel
    /// of Cohen & Wallace 1993, eq. 4.16, times the areas), so that the legs hidden under a
    /// table top do not count as much as the top.
    pub(super) fn visibility(
        &self,
        p: u32,
        q: u32,
        scratch: &mut VisibilityScratch,
    ) -> (f64, u64, u32) {
        let (np, nq) = (&self.nodes[p as usize], &self.nodes[q as usize]);
        let occ = self.occluders;
        let mut pairs = [(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO); 16];
        let count;
        let mut use_candidates = false;
        // Cluster links weigh their facing pairs by what each stands for.
        let mut weights = [1.0f64; 16];
        let mut weighted = false;
        // A patch link's pairs past the first four, drawn only when those do not settle it.
        let mut deferred = None;
        if !np.is_cluster() && !nq.is_cluster() {
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for &v in np.polygon().iter().chain(nq.polygon()) {
                lo = lo.min(v);
                hi = hi.max(v);
            }
            let (sp, sq) = (np.surface, nq.surface);
            let (mp, mq) = (self.normal[sp as usize], self.normal[sq as usize]);
            let (op, oq) = (np.polygon()[0], nq.polygon()[0]);
            let tol = 1e-9 * occ.scale();
            scratch.candidates.clear();
            // Occluders of the two surfaces themselves, or wholly behind either plane, cannot
            // cross a segment between facing points (it runs in front of both planes); a
            // pair that does not face counts only where none faces.
            let short = occ.overlapping_where(
                lo,
                hi,
                MAX_CANDIDATES,
                |k| {
                    let id = occ.id_of(k);
                    let corners = occ.corners_of(k);
                    id != sp
                        && id != sq
                        && corners.iter().any(|c| mp.dot(*c - op) > tol)
                        && corners.iter().any(|c| mq.dot(*c - oq) > tol)
                },
                &mut scratch.candidates,
            );
            if scratch.candidates.is_empty() {
                return (1.0, 0, 16);
            }
            use_candidates = short;
            // The same points for the link p <- q as for q <- p.
            let seed = crate::splitmix::splitmix64((p.min(q) as u64) << 32 | p.max(q) as u64);
            let (seed_p, seed_q) = if p < q { (seed, !seed) } else { (!seed, seed) };
            let patch_pairs = PatchPairs {
                polygons: (np.polygon(), nq.polygon()),
                seeds: (seed_p, seed_q),
                normals: (self.normal[sp as usize], self.normal[sq as usize]),
                disc: np.area.max(nq.area) / 16.0,
            };
            patch_pairs.draw(0..4, &mut pairs, &mut weights);
            deferred = Some(patch_pairs);
            count = 16;
        } else {
            // Up to eight pairs that face each other (from all pairs of sample points, in
            // a fixed spread-out order), kept in pairs[..8] with their weights; up to eight
            // non-facing ones in pairs[8..], used when none faces.
            let ((a, na), (b, nb)) = (self.samples_of(np), self.samples_of(nq));
            let (a, b) = (&a[..na], &b[..nb]);
            let (mut m, mut spare) = (0, 8);
            // The samples in a spread-out order (a stride near the golden section, coprime
            // with the count): the first eight pairs then cover the whole of each cluster,
            // not the first samples drawn, which lie together (drawn in order of area).
            let (sa, sb) = (spread_stride(a.len()), spread_stride(b.len()));
            'outer: for shift in 0..b.len() {
                for k in 0..a.len() {
                    let i = k * sa % a.len();
                    let (x, y) = (a[i], b[(k + shift) * sb % b.len()]);
                    let d = y.point - x.point;
                    let (cx, cy) = (x.normal.dot(d), -y.normal.dot(d));
                    if cx > 0.0 && cy > 0.0 {
                        pairs[m] = (x.point, x.normal, y.point, y.normal);
                        // What the pair stands for of the light exchanged: both ends'
                        // projected areas (A cos), the distance common to all pairs.
                        weights[m] = x.area * y.area * cx * cy / d.length_squared();
                        m += 1;
                        if m == 8 {
                            break 'outer;
                        }
                    } else if spare < 16 {
                        pairs[spare] = (x.point, x.normal, y.point, y.normal);
                        spare += 1;
                    }
                }
            }
            if m == 0 {
                pairs.copy_within(8..spare, 0);
                m = spare - 8;
            } else {
                weighted = weights[..m].iter().all(|w| w.is_finite())
                    && weights[..m].iter().sum::<f64>() > 0.0;
            }
            count = m;
        }
        // The occluder that blocked the last pair is tested first by the next (most of a
        // link's blocked pairs are blocked by one occluder): moved to the front of the
        // candidates, or kept in the scratch (any occluder of the hierarchy).
        let VisibilityScratch { candidates, last } = scratch;
        let mut blocked = |x: DVec3, y: DVec3| {
            if use_candidates {
                occ.segment_blocked_by_first(candidates, x, y)
            } else {
                occ.segment_blocked_cached(x, y, last)
            }
        };
        let (mut facing, mut visible, mut all_visible) = (0u32, 0u32, 0u32);
        let (mut facing_weight, mut visible_weight) = (0.0, 0.0);
        let mut rays = 0;
        for i in 0..count {
            // Four facing pairs all open settle it; anything else (some blocked: partial
            // visibility, where the fraction matters, or none visible, which ends the
            // link's refinement) casts all sixteen.
            if i == 4 {
                if facing == 4 && visible == 4 {
                    break;
                }
                if let Some(patch_pairs) = &deferred {
                    patch_pairs.draw(4..16, &mut pairs, &mut weights);
                    weighted =
                        weights.iter().all(|w| w.is_finite()) && weights.iter().sum::<f64>() > 0.0;
                }
            }
            let (x, mx, y, my) = pairs[i];
            let faces = mx.dot(y - x) > 0.0 && my.dot(x - y) > 0.0;
            let open = !blocked(x, y);
            rays += 1;
            if faces {
                facing += 1;
                visible += u32::from(open);
                facing_weight += weights[i];
                if open {
                    visible_weight += weights[i];
                }
            }
            all_visible += u32::from(open);
        }
        let fraction = if weighted && facing_weight > 0.0 {
            visible_weight / facing_weight
        } else if facing > 0 {
            visible as f64 / facing as f64
        } else {
            all_visible as f64 / rays as f64
        };
        (fraction, rays, facing)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_points_lie_one_in_each_cell_of_the_4_by_4_grid() {
        let square = [
            DVec3::ZERO,
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(4.0, 4.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
        ];
        for seed in [1, 2, 0xdead_beef] {
            for k in 0..16 {
                let x = sample_point(&square, seed, k);
                // The square's (u, v) is (x, y) / 4: point k in cell (k % 4, k / 4).
                assert_eq!(
                    (x.x.floor() as usize, x.y.floor() as usize),
                    (k % 4, k / 4),
                    "seed {seed}, point {k} at {x}"
                );
            }
        }
    }

    #[test]
    fn triangle_points_lie_one_in_each_of_the_16_sub_triangles() {
        // The right triangle (0,0) (4,0) (0,4): lattice cells are unit squares cut by their
        // diagonal, the lower-left half upright, the upper-right half across.
        let tri = [
            DVec3::ZERO,
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
        ];
        for seed in [1, 7, 0xdead_beef] {
            let mut cells: Vec<(i64, i64, bool)> = (0..16)
                .map(|k| {
                    let p = sample_point(&tri, seed, k);
                    assert!(p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 4.0, "{p}");
                    let (cx, cy) = (p.x.floor(), p.y.floor());
                    (cx as i64, cy as i64, (p.x - cx) + (p.y - cy) > 1.0)
                })
                .collect();
            cells.sort();
            cells.dedup();
            assert_eq!(cells.len(), 16, "seed {seed}: {cells:?}");
        }
    }
}
