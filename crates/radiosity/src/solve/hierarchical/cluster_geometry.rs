//! The geometry of a link that involves a cluster, taken from where its members are: the
//! factor by which the point model of a cluster (its centre, its six area bins) misjudges
//! the light the link carries, estimated from the nodes' sample points.
//!
//! A cluster link carries light as if every member of a cluster sat at the cluster's
//! centre and saw the other node along the line between the centres. Near each other that
//! overstates the exchange wherever members meet at an angle: two perpendicular squares
//! sharing an edge exchange A F = 0.20 A (the closed form), and the point model at their
//! centres' distance r = s / sqrt 2 and cosines 1 / sqrt 2 gives A^2 / (2 pi r^2) = 0.32 A,
//! 59 % too much. Clusters are linked once their bounding spheres are apart, where the
//! excess is smaller but not small; a room of walls split into coplanar pieces counted
//! 5.6 % of its light twice at the defaults (bench/scenes/room_split_walls.scene).
//!
//! The correction: the same exchange summed over the two nodes' sample points (a
//! cluster's area-weighted [`ClusterSample`]s, a patch's quarter points), each pair by the
//! point-to-disc kernel A_x A_y cos_x cos_y / (pi d^2 + A) (Wallace, Elmquist and Haines
//! 1989, eq. 7, bounded so that two points that nearly meet do not dominate), over the
//! point model's exchange for the same unit radiosity. The link's coupling is multiplied
//! by the ratio; the bins still share the light among a cluster's members by their normals.

use glam::DVec3;

use super::solver::Solver;
use super::tree::{ClusterSample, Node, CLUSTER_SAMPLES};
use crate::form_factor::kernel::quarter_points;

impl Solver<'_> {
    /// The sample points standing for node `n`: a cluster's own samples, a patch's four
    /// quarter points (each a quarter of its area).
    pub(super) fn samples_of(&self, n: &Node) -> ([ClusterSample; CLUSTER_SAMPLES], usize) {
        let mut out = [ClusterSample {
            point: DVec3::ZERO,
            normal: DVec3::ZERO,
            area: 0.0,
        }; CLUSTER_SAMPLES];
        if n.is_cluster() {
            let samples = &self.clusters[n.cluster as usize].samples;
            out[..samples.len()].copy_from_slice(samples);
            (out, samples.len())
        } else {
            let normal = self.normal[n.surface as usize];
            for (o, point) in out.iter_mut().zip(quarter_points(n.polygon())) {
                *o = ClusterSample {
                    point,
                    normal,
                    area: 0.25 * n.area,
                };
            }
            (out, 4)
        }
    }

    /// The factor for the coupling `g` of the link p <- q (at least one a cluster; `d`
    /// the unit direction of travel from q's centre to p's): the exchange summed over the
    /// sample pairs over the exchange the point model gives with `g` (see the module
    /// documentation). 1 where either is zero or not finite: the point model is kept where
    /// the samples cannot judge it.
    pub(super) fn cluster_link_factor(&self, np: &Node, nq: &Node, d: DVec3, g: f64) -> f64 {
        // The point model's exchange for unit radiosity: what q sends along d (a patch's is
        // already in g) times what p takes from it (a patch takes g per unit area).
        let sent = if nq.is_cluster() {
            self.projected_area(nq, d)
        } else {
            1.0
        };
        let taken = if np.is_cluster() {
            self.projected_area(np, -d)
        } else {
            np.area
        };
        let model = g * sent * taken;
        let ((a, na), (b, nb)) = (self.samples_of(np), self.samples_of(nq));
        let mut sampled = 0.0;
        for x in &a[..na] {
            for y in &b[..nb] {
                let v = y.point - x.point;
                let d2 = v.length_squared();
                let (cx, cy) = (x.normal.dot(v), -y.normal.dot(v));
                if cx > 0.0 && cy > 0.0 {
                    sampled += x.area * y.area * cx * cy
                        / (d2 * (std::f64::consts::PI * d2 + x.area.max(y.area)));
                }
            }
        }
        let factor = sampled / model;
        if model > 0.0 && sampled > 0.0 && factor.is_finite() {
            // Not clamped: the point model errs both ways (clamped to at most 1, the
            // building_small view came out 4.9 % too dark), and clamping to [0.5, 2]
            // changed the pixels by less than 0.1 % (BENCHMARKS.md).
            factor
        } else {
            1.0
        }
    }
}
