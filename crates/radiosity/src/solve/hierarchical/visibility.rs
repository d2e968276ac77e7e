//! Visibility sampling of a link: the visible fraction between two nodes from up to sixteen
//! point pairs (stratified points of patches, the sample points of clusters) through the
//! occluder BVH.

use glam::DVec3;

use super::solver::Solver;

/// 16 stratified points of a triangle or a planar convex quadrilateral: one in each cell
/// of a 4 x 4 grid of the quadrilateral's (u, v) square, or in each of the 16 sub-triangles
/// of the triangle split four times along each edge, at a uniformly random spot of its
/// cell drawn from `seed` (jittered sampling, Cook 1986). Cell centres never come nearer
/// the edge than half a cell, and the edge is where a perpendicular occluder hides most (a
/// window at the end of its reveals sees least of the room from its rim): judged from
/// centres, such links were too visible. Jittered points are unbiased.
fn sample_points(poly: &[DVec3], seed: u64) -> [DVec3; 16] {
    let mut stratum = 0;
    let mut next = || {
        stratum += 1;
        crate::splitmix::jitter(seed, stratum)
    };
    let mut out = [DVec3::ZERO; 16];
    if poly.len() == 4 {
        for j in 0..4 {
            for i in 0..4 {
                let (s, t) = next();
                let (u, v) = ((i as f64 + s) / 4.0, (j as f64 + t) / 4.0);
                out[j * 4 + i] = crate::mesh::bilinear(poly, u, v);
            }
        }
    } else {
        let (a, e1, e2) = (poly[0], poly[1] - poly[0], poly[2] - poly[0]);
        let mut k = 0;
        for b in 0..4 {
            for s in 0..4 - b {
                let (x, y) = (s as f64, b as f64);
                // The sub-triangle (x, y), (x + 1, y), (x, y + 1) of the lattice ...
                let (u, v) = next();
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                out[k] = a + e1 * ((x + u) / 4.0) + e2 * ((y + v) / 4.0);
                k += 1;
                if s + b + 1 < 4 {
                    // ... and the one across its diagonal, (x + 1, y + 1) less the same.
                    let (u, v) = next();
                    let (u, v) = if u + v > 1.0 {
                        (1.0 - u, 1.0 - v)
                    } else {
                        (u, v)
                    };
                    out[k] = a + e1 * ((x + 1.0 - u) / 4.0) + e2 * ((y + 1.0 - v) / 4.0);
                    k += 1;
                }
            }
        }
    }
    out
}

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

impl Solver<'_> {
    /// The visible fraction between p and q from a few point pairs, and the rays cast. Only
    /// pairs whose points face each other count (a pair with a point behind the other's
    /// plane carries no energy); when no pair faces, all pairs count. Patch <- patch links
    /// use 16 pairs (4 x 4 stratified points on each, paired by a fixed permutation) and
    /// only the occluders whose boxes overlap the pair's box (none: visible, no ray);
    /// cluster links use up to eight facing pairs of sample points (a cluster keeps up to
    /// sixteen points drawn from its children's in proportion to area, see
    /// [`super::tree::ClusterSample`]) and the whole BVH, and weigh each facing pair by what
    /// it stands for of the exchange, A_x cos_x A_y cos_y / d^2 (the point-to-point kernel
    /// of Cohen & Wallace 1993, eq. 4.16, times the areas), so that the legs hidden under a
    /// table top do not count as much as the top.
    pub(super) fn visibility(&self, p: u32, q: u32, scratch: &mut Vec<u32>) -> (f64, u64, u32) {
        let (np, nq) = (&self.nodes[p as usize], &self.nodes[q as usize]);
        let occ = self.occluders;
        let mut pairs = [(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO); 16];
        let count;
        let mut use_candidates = false;
        // Cluster links weigh their facing pairs by what each stands for.
        let mut weights = [1.0f64; 16];
        let mut weighted = false;
        if !np.is_cluster() && !nq.is_cluster() {
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for &v in np.polygon().iter().chain(nq.polygon()) {
                lo = lo.min(v);
                hi = hi.max(v);
            }
            let (sp, sq) = (np.surface, nq.surface);
            scratch.clear();
            occ.overlapping(lo, hi, scratch);
            scratch.retain(|&k| occ.id_of(k) != sp && occ.id_of(k) != sq);
            if scratch.is_empty() {
                return (1.0, 0, 16);
            }
            use_candidates = scratch.len() <= 32;
            // The same points for the link p <- q as for q <- p.
            let seed = crate::splitmix::splitmix64((p.min(q) as u64) << 32 | p.max(q) as u64);
            let (seed_p, seed_q) = if p < q { (seed, !seed) } else { (!seed, seed) };
            let (a, b) = (
                sample_points(np.polygon(), seed_p),
                sample_points(nq.polygon(), seed_q),
            );
            let (mp, mq) = (self.normal[sp as usize], self.normal[sq as usize]);
            // What a point pair stands for of the exchange: the kernel cos cos / (pi d^2),
            // bounded as the form factor to a disc of a sixteenth of the larger node
            // (Wallace et al. 1989, eq. 7) so that two points that nearly meet do not
            // outweigh the rest.
            let w = np.area.max(nq.area) / 16.0;
            // The first four pairs spread over both nodes (a diagonal of the 4 x 4 grid).
            for (k, i) in [0, 5, 10, 15, 1, 2, 3, 4, 6, 7, 8, 9, 11, 12, 13, 14]
                .into_iter()
                .enumerate()
            {
                let (x, y) = (a[i], b[(i * 5 + 3) % 16]);
                pairs[k] = (x, mp, y, mq);
                let d = y - x;
                let d2 = d.length_squared();
                let (cx, cy) = (mp.dot(d), -mq.dot(d));
                weights[k] = if cx > 0.0 && cy > 0.0 {
                    cx * cy / (d2 * (std::f64::consts::PI * d2 + w))
                } else {
                    0.0
                };
            }
            weighted = weights.iter().all(|w| w.is_finite()) && weights.iter().sum::<f64>() > 0.0;
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
        let blocked = |x: DVec3, y: DVec3| {
            if use_candidates {
                occ.segment_blocked_by(scratch, x, y)
            } else {
                occ.segment_blocked(x, y)
            }
        };
        let (mut facing, mut visible, mut all_visible) = (0u32, 0u32, 0u32);
        let (mut facing_weight, mut visible_weight) = (0.0, 0.0);
        let mut rays = 0;
        for (i, &(x, mx, y, my)) in pairs[..count].iter().enumerate() {
            // Four facing pairs all open settle it; anything else (some blocked: partial
            // visibility, where the fraction matters, or none visible, which ends the
            // link's refinement) casts all sixteen.
            if i == 4 && facing == 4 && visible == 4 {
                break;
            }
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
