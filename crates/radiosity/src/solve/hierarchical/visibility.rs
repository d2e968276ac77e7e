//! Visibility sampling of a link: the visible fraction between two nodes from up to sixteen
//! point pairs (stratified points of patches, the sample points of clusters) through the
//! occluder BVH.

use glam::DVec3;

use super::solver::Solver;
use super::tree::{Node, CLUSTER_SAMPLES};
use crate::form_factor::kernel::quarter_points;

/// 16 stratified points of a triangle or a planar convex quadrilateral.
fn sample_points(poly: &[DVec3]) -> [DVec3; 16] {
    let mut out = [DVec3::ZERO; 16];
    if poly.len() == 4 {
        for j in 0..4 {
            for i in 0..4 {
                let (u, v) = ((i as f64 + 0.5) / 4.0, (j as f64 + 0.5) / 4.0);
                out[j * 4 + i] = crate::mesh::bilinear(poly, u, v);
            }
        }
    } else {
        let (a, e1, e2) = (poly[0], poly[1] - poly[0], poly[2] - poly[0]);
        let mut k = 0;
        for b in 0..4 {
            for s in 0..4 - b {
                let (x, y) = (s as f64, b as f64);
                out[k] = a + e1 * ((x + 1.0 / 3.0) / 4.0) + e2 * ((y + 1.0 / 3.0) / 4.0);
                k += 1;
                if s + b + 1 < 4 {
                    out[k] = a + e1 * ((x + 2.0 / 3.0) / 4.0) + e2 * ((y + 2.0 / 3.0) / 4.0);
                    k += 1;
                }
            }
        }
    }
    out
}

impl Solver<'_> {
    /// The visible fraction between p and q from a few point pairs, and the rays cast. Only
    /// pairs whose points face each other count (a pair with a point behind the other's
    /// plane carries no energy); when no pair faces, all pairs count. Patch <- patch links
    /// use 16 pairs (4 x 4 stratified points on each, paired by a fixed permutation) and
    /// only the occluders whose boxes overlap the pair's box (none: visible, no ray);
    /// cluster links use up to eight facing pairs of sample points (a cluster keeps up to
    /// eight quarter points of its roots, taken alternately from its two children) and the
    /// whole BVH.
    pub(super) fn visibility(&self, p: u32, q: u32, scratch: &mut Vec<u32>) -> (f64, u64, u32) {
        let (np, nq) = (&self.nodes[p as usize], &self.nodes[q as usize]);
        let occ = self.occluders;
        let mut pairs = [(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO); 16];
        let count;
        let mut use_candidates = false;
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
            let (a, b) = (sample_points(np.polygon()), sample_points(nq.polygon()));
            let (mp, mq) = (self.normal[sp as usize], self.normal[sq as usize]);
            // The first four pairs spread over both nodes (a diagonal of the 4 x 4 grid).
            for (k, i) in [0, 5, 10, 15, 1, 2, 3, 4, 6, 7, 8, 9, 11, 12, 13, 14]
                .into_iter()
                .enumerate()
            {
                pairs[k] = (a[i], mp, b[(i * 5 + 3) % 16], mq);
            }
            count = 16;
        } else {
            // Sample points on the stack: this runs for every cluster link estimated.
            let samples_of = |n: &Node| -> ([(DVec3, DVec3); CLUSTER_SAMPLES], usize) {
                let mut out = [(DVec3::ZERO, DVec3::ZERO); CLUSTER_SAMPLES];
                if n.is_cluster() {
                    let samples = &self.clusters[n.cluster as usize].samples;
                    out[..samples.len()].copy_from_slice(samples);
                    (out, samples.len())
                } else {
                    let m = self.normal[n.surface as usize];
                    for (o, x) in out.iter_mut().zip(quarter_points(n.polygon())) {
                        *o = (x, m);
                    }
                    (out, 4)
                }
            };
            // Up to eight pairs that face each other (from all pairs of sample points, in
            // a fixed spread-out order), kept in pairs[..8]; up to eight non-facing ones in
            // pairs[8..], used when none faces.
            let ((a, na), (b, nb)) = (samples_of(np), samples_of(nq));
            let (a, b) = (&a[..na], &b[..nb]);
            let (mut m, mut spare) = (0, 8);
            'outer: for shift in 0..b.len() {
                for i in 0..a.len() {
                    let (x, y) = (a[i], b[(i + shift) % b.len()]);
                    let faces = x.1.dot(y.0 - x.0) > 0.0 && y.1.dot(x.0 - y.0) > 0.0;
                    if faces {
                        pairs[m] = (x.0, x.1, y.0, y.1);
                        m += 1;
                        if m == 8 {
                            break 'outer;
                        }
                    } else if spare < 16 {
                        pairs[spare] = (x.0, x.1, y.0, y.1);
                        spare += 1;
                    }
                }
            }
            if m == 0 {
                pairs.copy_within(8..spare, 0);
                m = spare - 8;
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
            }
            all_visible += u32::from(open);
        }
        let fraction = if facing > 0 {
            visible as f64 / facing as f64
        } else {
            all_visible as f64 / rays as f64
        };
        (fraction, rays, facing)
    }
}
