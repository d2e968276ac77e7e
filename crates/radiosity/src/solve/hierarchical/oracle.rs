//! The BF refinement oracle: whether a link's estimated transfer rho_p B_q F_hat passes
//! epsilon B_ref, the F_hat of links that involve a cluster (the coupling of projected
//! areas), and the bounds on reflectance and source radiosity it multiplies.

use glam::DVec3;

use super::bins::bin;
use super::link::Link;
use super::solver::{max3, Solver};
use super::tree::{Node, NONE};

/// The oracle takes a patch source's radiosity as the larger of its mean and this many
/// times the spread (largest - smallest) of its leaves. Measured on the Cornell box at 2,046
/// elements, epsilon 0.01: weight 0 / 1 / 2 / 4 gives 6.4 / 6.2 / 5.6 / 5.0 % RMS against
/// the dense solve and -1.2 / -0.9 / -0.5 / -0.4 % mean difference; on the default building
/// (217k leaves) 2 costs 14 % more time and 4 costs 29 %.
const SPAN_WEIGHT: f64 = 2.0;

impl Solver<'_> {
    /// The area of node `n` projected on the plane normal to unit `d`, seen from the side
    /// `d` points to (clusters: from their area bins).
    pub(super) fn projected_area(&self, n: &Node, d: DVec3) -> f64 {
        if n.is_cluster() {
            let bins = &self.clusters[n.cluster as usize].area_bins;
            (0..3).map(|k| d[k].abs() * bins[bin(k, d[k])]).sum()
        } else {
            n.area * self.normal[n.surface as usize].dot(d).max(0.0)
        }
    }

    /// F_hat of a link that involves a cluster: max(F_pq, F_qp) from the coupling
    /// A_p F_pq = Ap(p, -d) Ap(q, d) / (pi r^2) of the projected areas at the centres'
    /// distance r (d: unit, from q to p), capped at 1. A cluster's projected area is taken
    /// in the direction from its centre, but its members see the other node from
    /// directions up to R / r away: each cluster's is raised by (R / r) A, its area times
    /// that angle. Without it a cluster of the Cornell box's light and the short block's
    /// top, whose centre lies level with part of the red wall, sent the light no light
    /// towards it by the oracle (the light faces down) and kept the coarse link: a
    /// triangle of the red wall at 15 % of its radiosity at epsilon 0.1 (12.8 -> 8.8 %
    /// RMS at epsilon 0.05, largest 177 -> 89 %; the building +12 % time).
    pub(super) fn cluster_oracle(&self, np: &Node, nq: &Node, d: DVec3, r: f64) -> f64 {
        let spread = |n: &Node| {
            if n.is_cluster() {
                (n.radius / r).min(1.0) * n.area
            } else {
                0.0
            }
        };
        let coupling = (self.projected_area(np, -d) + spread(np))
            * (self.projected_area(nq, d) + spread(nq))
            / (std::f64::consts::PI * r * r);
        (coupling / np.area.min(nq.area)).min(1.0)
    }

    /// Reflectance that bounds what node `n` reflects (largest band; clusters: of any patch).
    fn rho_of(&self, n: u32) -> f64 {
        let node = &self.nodes[n as usize];
        if node.is_cluster() {
            self.clusters[node.cluster as usize].rho
        } else {
            max3(self.rho[node.surface as usize])
        }
    }

    /// True when the BF oracle asks to refine `link` held by p.
    pub(super) fn wants_refining(&self, p: u32, link: &Link, b_ref: f64) -> bool {
        let q = link.source;
        let c = self.cluster_of[q as usize];
        let b_q = if c == NONE {
            // The mean, or the spread of the source's leaves where that is larger: a link
            // multiplies the mean F by the mean B, and where both peak together (the floor
            // under a light, seen from the light) the product misses their covariance.
            let (lo, hi) = self.b_span[q as usize];
            max3(self.b[q as usize]).max(SPAN_WEIGHT * (hi - lo))
        } else {
            self.clusters[c as usize].b_max
        };
        self.rho_of(p) * b_q * link.oracle as f64 > self.settings.epsilon * b_ref
    }
}
