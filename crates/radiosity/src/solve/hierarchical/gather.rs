//! The final gather (Lischinski, Tampieri and Greenberg 1993; Smits, Arvo and Greenberg
//! 1994): once the hierarchy has converged, every leaf's irradiance is gathered again at the
//! leaf's own resolution instead of being pushed down from its ancestors.
//!
//! A link held by an ancestor A of leaf L carries A's area-averaged form factor: pushed
//! down, every leaf under A gets the same irradiance from that source, which is what made
//! blotches where a coarse link covers a patch whose form factor varies over it (a wall
//! near a corner, a ceiling near the light). The gather evaluates each such link again
//! with L as the receiver: for a patch source q, F from L to q by the same kernels as a
//! link (`patch_form_factor`: exact near, Lambert's point-to-polygon at middle distance,
//! point pairs far), with the visibility sampled again from L where the link's own samples
//! saw q partly hidden; for a cluster source, its intensity towards L's centre over L's
//! cos / r^2. Where q is large next to its distance from L and has children, the gather
//! descends into them (their own radiosities and form factors), so that neither end of a
//! coarse link is taken as uniform where the transfer varies over it. The links of L
//! itself are already at its resolution and are taken as they are; the clusters' links
//! reach L through their irradiance bins, as in the sweeps.
//!
//! Before it, leaves that span several cells of the scene's mesh are split down to single
//! cells (children inheriting their parent's radiosity), so that the solution has at least
//! the mesh's resolution wherever the hierarchy stopped coarser. The gathered radiosity is
//! B = E + rho H, one bounce from the converged hierarchy; the energy account is taken
//! from the gathered H.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use super::bins::{cluster_emission, irradiance_for};
use super::link::{patch_form_factor, Link};
use super::solver::Solver;
use super::tree::NONE;
use crate::form_factor::kernel::mean_cos_over_r2;

/// The gather descends into a patch source's children while the source's radius is more than this
/// fraction of its distance from the receiver. Measured on the Cornell box at 2,046
/// elements and the default settings, against the exact dense solve: 0.5 / 0.25 gives
/// 1.94 / 1.58 % RMS with two passes (2.72 / 2.47 % with one); not descending at all,
/// 3.15 % with one.
const DESCEND_RATIO: f64 = 0.25;

/// Gather passes: the second gathers from the radiosity of the first, pulled up the
/// quadtrees, so that the sources' radiosity, not only the receivers', is at the leaves'
/// resolution. Measured as above: one / two / three passes, 2.72 / 1.94 / 1.89 % RMS and
/// 38.8 / 14.3 / 13.8 % largest difference (the coarse hierarchy's own source radiosity
/// made the largest differences).
const GATHER_PASSES: usize = 2;

impl Solver<'_> {
    /// Area-averaged radiosity of every patch from its leaves, and the clusters' power
    /// bins, after the leaves' radiosity has changed.
    fn pull_up(&mut self, n: u32) {
        let node = &self.nodes[n as usize];
        if node.child_count == 0 {
            return;
        }
        let (children, count, is_cluster) =
            (node.children, node.child_count as usize, node.is_cluster());
        let mut sum = [0.0; 3];
        let mut power = [[0.0; 6]; 3];
        for &c in &children[..count] {
            self.pull_up(c);
            let cn = &self.nodes[c as usize];
            let cb = self.b[c as usize];
            for k in 0..3 {
                sum[k] += cn.area * cb[k];
            }
            if is_cluster {
                if cn.is_cluster() {
                    let cp = &self.clusters[cn.cluster as usize].power;
                    for band in 0..3 {
                        for k in 0..6 {
                            power[band][k] += cp[band][k];
                        }
                    }
                } else {
                    let m = self.normal[cn.surface as usize];
                    for band in 0..3 {
                        for k in 0..3 {
                            power[band][super::bins::bin(k, m[k])] +=
                                cn.area * cb[band] * m[k].abs();
                        }
                    }
                }
            }
        }
        let area = self.nodes[n as usize].area;
        self.b[n as usize] = sum.map(|s| if area > 0.0 { s / area } else { 0.0 });
        if is_cluster {
            let c = self.nodes[n as usize].cluster as usize;
            self.clusters[c].power = power;
        }
    }

    /// Splits every leaf that spans more than one cell of the scene's mesh down to cells.
    pub(super) fn split_leaves_to_cells(&mut self) {
        let mut stack: Vec<u32> = (0..self.root_count as u32).collect();
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if node.child_count > 0 {
                stack.extend_from_slice(node.children());
                continue;
            }
            let [cu, cv] = node.grid;
            let spans = if node.count == 4 {
                cu * cv > 1
            } else {
                cu >= 2
            };
            if spans {
                let children = self.split_patch(n);
                stack.extend(children);
            }
        }
    }

    /// The irradiance each quadtree root receives through the irradiance bins of the
    /// clusters above it (their links, accumulated downwards).
    fn irradiance_from_clusters(&self) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; self.root_count];
        let mut stack = vec![(self.top, [[0.0; 6]; 3])];
        while let Some((n, down)) = stack.pop() {
            let node = &self.nodes[n as usize];
            if node.is_cluster() {
                let mut total = self.clusters[node.cluster as usize].incident;
                for band in 0..3 {
                    for k in 0..6 {
                        total[band][k] += down[band][k];
                    }
                }
                for &c in node.children() {
                    stack.push((c, total));
                }
            } else {
                out[n as usize] = irradiance_for(&down, self.normal[node.surface as usize]);
            }
        }
        out
    }

    /// The irradiance at leaf `l` from patch source `q` (to `l`'s resolution), descending
    /// into q's children where q is large next to its distance; `hidden` is whether the
    /// link's own samples saw part of q hidden (visibility is then sampled from `l`).
    fn gather_from_patch(
        &self,
        l: u32,
        q: u32,
        hidden: bool,
        scratch: &mut Vec<u32>,
        rays: &mut u64,
    ) -> [f64; 3] {
        let (nl, nq) = (&self.nodes[l as usize], &self.nodes[q as usize]);
        let r = nl.centre.distance(nq.centre);
        if nq.child_count > 0 && nq.radius > DESCEND_RATIO * r {
            let mut h = [0.0; 3];
            for &c in nq.children() {
                let x = self.gather_from_patch(l, c, hidden, scratch, rays);
                for k in 0..3 {
                    h[k] += x[k];
                }
            }
            return h;
        }
        let (ml, mq) = (
            self.normal[nl.surface as usize],
            self.normal[nq.surface as usize],
        );
        let mut f = patch_form_factor(nl, ml, nq, mq);
        if f <= 0.0 {
            return [0.0; 3];
        }
        if hidden {
            let (fraction, cast, _) = self.visibility(l, q, scratch);
            *rays += cast;
            f *= fraction;
        }
        self.b[q as usize].map(|b| f * b)
    }

    /// The irradiance at leaf `l` through `link`, held by one of l's ancestors.
    fn gather_link(&self, l: u32, link: &Link, scratch: &mut Vec<u32>, rays: &mut u64) -> [f64; 3] {
        let q = link.source;
        let nq = &self.nodes[q as usize];
        if nq.is_cluster() {
            let nl = &self.nodes[l as usize];
            let m = self.normal[nl.surface as usize];
            let d = (nl.centre - nq.centre).normalize_or(DVec3::Z);
            let g = mean_cos_over_r2(nl.polygon(), m, nq.centre) / std::f64::consts::PI
                * link.visible as f64;
            let x = cluster_emission(&self.clusters[nq.cluster as usize].power, d);
            return x.map(|x| g * x);
        }
        if link.visible <= 0.0 {
            return [0.0; 3];
        }
        self.gather_from_patch(l, q, link.visible < 1.0, scratch, rays)
    }

    /// The final gather (see the module documentation): sets every leaf's radiosity to
    /// E + rho H from the irradiance H gathered at the leaf, and returns each leaf's H.
    pub(super) fn final_gather(&mut self) -> HashMap<u32, [f64; 3]> {
        self.split_leaves_to_cells();
        let mut out = HashMap::new();
        for pass in 0..GATHER_PASSES {
            if pass > 0 {
                self.pull_up(self.top);
            }
            out = self.gather_pass();
        }
        out
    }

    /// One gather pass over all leaves, from the radiosity the nodes hold now.
    fn gather_pass(&mut self) -> HashMap<u32, [f64; 3]> {
        let mut parent = vec![NONE; self.nodes.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            if !n.is_cluster() {
                for &c in n.children() {
                    parent[c as usize] = i as u32;
                }
            }
        }
        let from_clusters = self.irradiance_from_clusters();
        let mut leaves = Vec::new();
        for r in 0..self.root_count as u32 {
            self.leaves_of(r, &mut leaves);
        }
        let this = &*self;
        let gathered: Vec<([f64; 3], u64)> = leaves
            .par_iter()
            .map_init(Vec::new, |scratch, &l| {
                let mut h = [0.0; 3];
                let mut rays = 0;
                let mut add = |x: [f64; 3]| {
                    for k in 0..3 {
                        h[k] += x[k];
                    }
                };
                // The leaf's own links: already at its resolution.
                for link in &this.nodes[l as usize].links {
                    let q = link.source;
                    let c = this.cluster_of[q as usize];
                    let x = if c != NONE {
                        let d =
                            DVec3::new(link.dir[0] as f64, link.dir[1] as f64, link.dir[2] as f64);
                        cluster_emission(&this.clusters[c as usize].power, d)
                    } else {
                        this.b[q as usize]
                    };
                    add(x.map(|x| link.g as f64 * x));
                }
                // The ancestors' links, evaluated again for the leaf.
                let (mut a, mut root) = (parent[l as usize], l);
                while a != NONE {
                    for link in &this.nodes[a as usize].links {
                        add(this.gather_link(l, link, scratch, &mut rays));
                    }
                    root = a;
                    a = parent[a as usize];
                }
                // The clusters' links, through their bins.
                add(from_clusters[root as usize]);
                (h, rays)
            })
            .collect();
        let mut out = HashMap::with_capacity(leaves.len());
        for (&l, (h, rays)) in leaves.iter().zip(gathered) {
            let s = self.nodes[l as usize].surface as usize;
            self.b[l as usize] =
                std::array::from_fn(|k| self.emission[s][k] + self.rho[s][k] * h[k]);
            self.rays += rays;
            out.insert(l, h);
        }
        out
    }
}
