//! Links and their estimation: the link a receiver holds from a source, and the estimate of
//! a candidate pair (the form factor or coupling g by the pair's kinds, the oracle's F_hat
//! and the visible fraction), with the tests that rule a pair out (back to back, or too
//! close for a cluster link).

use glam::DVec3;

use super::near_pairs::NearPairMemo;
use super::solver::Solver;
use super::tree::Node;
use super::visibility::VisibilityScratch;
use crate::form_factor::exact::point_to_polygon;
use crate::form_factor::kernel::{mean_cos_over_r2, mean_point_pairs, mean_point_to_polygon};
use crate::geometry;

/// A link held by receiver p from source q (see the module documentation of [`super`] for `g`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Link {
    pub(super) source: u32,
    /// patch <- patch: F_pq; patch <- cluster: cos+ / (pi r^2); cluster <- patch:
    /// A_q cos+ / (pi r^2); cluster <- cluster: 1 / (pi r^2). Visibility included.
    pub(super) g: f32,
    /// F_hat of the oracle, visibility included.
    pub(super) oracle: f32,
    /// Unit direction of travel, from q's centre to p's.
    pub(super) dir: [f32; 3],
    /// The visible fraction included in `g` (1: no sample pair blocked): the final gather
    /// samples visibility again, from each leaf, only where it is below 1.
    pub(super) visible: f32,
}

/// True when some corner of `other` lies strictly in front of `poly`'s plane.
fn some_corner_in_front(poly: &[DVec3], normal: DVec3, other: &[DVec3]) -> bool {
    let centre = geometry::vertex_mean(poly);
    let size = geometry::diameter(poly).max(geometry::diameter(other));
    other.iter().any(|&v| normal.dot(v - centre) > 1e-9 * size)
}

/// True when some corner of the box [lo, hi] lies strictly in front of the plane through
/// `point` with normal `normal`.
fn box_in_front(lo: DVec3, hi: DVec3, point: DVec3, normal: DVec3) -> bool {
    let far = DVec3::new(
        if normal.x > 0.0 { hi.x } else { lo.x },
        if normal.y > 0.0 { hi.y } else { lo.y },
        if normal.z > 0.0 { hi.z } else { lo.z },
    );
    normal.dot(far - point) > 1e-9 * (hi - lo).length().max(f64::MIN_POSITIVE)
}

/// F from patch p (normal `mp`) to patch q (normal `mq`), unoccluded, by their distance:
/// where the centres are closer than the sum of the radii, the exact area-averaged F (double
/// contour integral, through the memo of pair shapes): the mean over four points misses the peak of F near a shared edge and
/// is biased low there (5 % on the Cornell box's walls at epsilon 0.01); up to three times
/// that, the mean of Lambert's exact point value at four points of p, accurate to
/// O((R / r)^2); beyond, the point-to-point kernel between four points of each.
pub(super) fn patch_form_factor(
    memo: &NearPairMemo,
    np: &Node,
    mp: DVec3,
    nq: &Node,
    mq: DVec3,
) -> f64 {
    let r = np.centre.distance(nq.centre);
    if r < np.radius + nq.radius {
        memo.form_factor(np.polygon(), nq.polygon())
    } else if r > 3.0 * (np.radius + nq.radius) {
        mean_point_pairs(np.polygon(), mp, nq.polygon(), mq, nq.area)
    } else {
        mean_point_to_polygon(np.polygon(), mp, nq.polygon())
    }
}

/// What the estimate of a candidate pair says.
pub(super) enum Estimate {
    /// The pair involves a cluster and the nodes are too close for a cluster link.
    TooClose,
    /// Nothing can pass (back to back, or the same surface).
    Nothing,
    /// A link, and the rays cast for it.
    Link(Link, u64),
    /// The pair must be refined (decided without rays).
    Refine,
}

impl Solver<'_> {
    /// True when a link between `a` and `b` cannot treat a cluster as a point: two clusters
    /// whose bounding spheres overlap, or a cluster whose sphere reaches a patch's box.
    /// (The patch side of a patch-cluster link needs no such test: its cosines and
    /// distances are averaged over its points, and the oracle refines it when it is large.)
    fn too_close(&self, a: &Node, b: &Node) -> bool {
        match (a.is_cluster(), b.is_cluster()) {
            (false, false) => false,
            (true, true) => a.centre.distance(b.centre) < a.radius + b.radius,
            (true, false) | (false, true) => {
                let (cluster, patch) = if a.is_cluster() { (a, b) } else { (b, a) };
                let (mut lo, mut hi) = (patch.corners[0], patch.corners[0]);
                for &v in &patch.polygon()[1..] {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                let nearest = cluster.centre.clamp(lo, hi);
                nearest.distance(cluster.centre) < cluster.radius
            }
        }
    }

    /// Estimates the link p <- q.
    pub(super) fn estimate(
        &self,
        p: u32,
        q: u32,
        b_ref: f64,
        scratch: &mut VisibilityScratch,
    ) -> Estimate {
        let (np, nq) = (&self.nodes[p as usize], &self.nodes[q as usize]);
        if np.buried || nq.buried {
            return Estimate::Nothing;
        }
        let v = np.centre - nq.centre;
        let r = v.length();
        if self.too_close(np, nq) {
            return Estimate::TooClose;
        }
        let d = if r > 0.0 { v / r } else { DVec3::Z };
        let (g, oracle) = match (np.is_cluster(), nq.is_cluster()) {
            (false, false) => {
                if np.surface == nq.surface {
                    return Estimate::Nothing;
                }
                let (mp, mq) = (
                    self.normal[np.surface as usize],
                    self.normal[nq.surface as usize],
                );
                if !some_corner_in_front(np.polygon(), mp, nq.polygon())
                    || !some_corner_in_front(nq.polygon(), mq, np.polygon())
                {
                    return Estimate::Nothing;
                }
                // Near pairs (centres closer than the sum of the radii) get the exact F
                // (see `patch_form_factor`).
                let near = r < np.radius + nq.radius;
                if near && self.split_choice(p, q).is_some() {
                    // The exact F costs about twenty times Lambert's formula at p's centre
                    // and most near pairs are refined: when half of the centre's value
                    // already asks for refinement, the exact value is not needed (45 % of
                    // the building's solve time went to exact near pairs before).
                    let f_centre = point_to_polygon(np.centre, mp, nq.polygon());
                    let probe = Link {
                        source: q,
                        g: 0.0,
                        oracle: (0.5 * f_centre * (np.area / nq.area).max(1.0)) as f32,
                        dir: [0.0; 3],
                        visible: 1.0,
                    };
                    if self.wants_refining(p, &probe, b_ref) {
                        return Estimate::Refine;
                    }
                }
                let f_pq = patch_form_factor(&self.near_pairs, np, mp, nq, mq);
                // F_qp for the oracle by reciprocity (A_p F_pq = A_q F_qp).
                (f_pq, f_pq * (np.area / nq.area).max(1.0))
            }
            (false, true) => {
                let mp = self.normal[np.surface as usize];
                let cl = &self.clusters[nq.cluster as usize];
                if !box_in_front(cl.lo, cl.hi, np.centre, mp) {
                    return Estimate::Nothing;
                }
                let g = mean_cos_over_r2(np.polygon(), mp, nq.centre) / std::f64::consts::PI;
                (g, self.cluster_oracle(np, nq, d, r))
            }
            (true, false) => {
                let mq = self.normal[nq.surface as usize];
                let cl = &self.clusters[np.cluster as usize];
                if !box_in_front(cl.lo, cl.hi, nq.centre, mq) {
                    return Estimate::Nothing;
                }
                let g =
                    nq.area * mean_cos_over_r2(nq.polygon(), mq, np.centre) / std::f64::consts::PI;
                (g, self.cluster_oracle(np, nq, d, r))
            }
            (true, true) => (
                1.0 / (std::f64::consts::PI * r * r),
                self.cluster_oracle(np, nq, d, r),
            ),
        };
        if g <= 0.0 && oracle <= 0.0 {
            return Estimate::Nothing;
        }
        let link = Link {
            source: q,
            g: g as f32,
            oracle: oracle as f32,
            dir: [d.x as f32, d.y as f32, d.z as f32],
            visible: 1.0,
        };
        let cluster_link = np.is_cluster() || nq.is_cluster();
        if self.wants_refining(p, &link, b_ref) && self.split_choice(p, q).is_some() {
            // Refined whatever its visibility (see the oracle below), even when the pair
            // looks wholly hidden: sixteen point pairs miss a sliver of a patch that pokes
            // out from under an object (a floor patch partly under a block, whose uncovered
            // part sees the light, came out 80 % dark in the Cornell box when such pairs
            // were dropped). The children's links decide, with their own rays.
            return Estimate::Refine;
        }
        // A cluster link that is kept: its coupling weighed by where the clusters' members
        // are (the `cluster_geometry` module; the oracle does not use it, so it is not
        // computed for the pairs refined above). The factor is positive: the tests above
        // decide as they would with it.
        let g = if cluster_link {
            g * self.cluster_link_factor(np, nq, d, g)
        } else {
            g
        };
        let (fraction, rays, facing) = self.visibility(p, q, scratch);
        if fraction == 0.0 && facing >= 8 && !cluster_link {
            return Estimate::Nothing;
        }
        Estimate::Link(
            Link {
                source: q,
                g: (g * fraction) as f32,
                // A partly hidden link keeps its unoccluded F_hat for the oracle: the
                // hidden part of a source is often its darkest (the floor behind a block is
                // both unseen and in shadow), so the visible fraction times the mean B
                // underestimates the transfer until the link is refined (Hanrahan et al.
                // refine partial visibility for the same reason).
                // So does a link judged hidden from fewer than eight facing pairs (a cluster
                // link whose sample points hardly face each other), which would otherwise
                // never be refined.
                oracle: if fraction < 1.0
                    && (fraction > 0.0 || facing < 8 || np.is_cluster() || nq.is_cluster())
                {
                    oracle as f32
                } else {
                    (oracle * fraction) as f32
                },
                dir: [d.x as f32, d.y as f32, d.z as f32],
                visible: fraction as f32,
            },
            rays,
        )
    }
}
