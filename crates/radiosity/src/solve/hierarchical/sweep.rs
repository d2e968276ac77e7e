//! The sweeps: gather (patches from their links, clusters into their irradiance bins), then
//! push irradiance down and pull radiosity and power bins up, until the power that changes
//! is below the tolerance.

use glam::DVec3;
use rayon::prelude::*;

use super::bins::{bin, cluster_emission, irradiance_for};
use super::solver::{max3, Solver};
use super::tree::{Node, NONE};
use crate::solve::SolveError;

/// Give up after this many sweeps in one solve.
const MAX_SWEEPS: usize = 100_000;

/// Sweeps in a row whose changed power rises before the light is said to grow without end:
/// a converging solve's change falls every sweep (after the first few, where the light
/// still spreads), so twenty rises in a row is growth, not a wobble.
const RISING_SWEEPS: usize = 20;

impl Solver<'_> {
    /// Pushes irradiance down and pulls radiosity (and power bins) up from node `n`;
    /// `down` is the irradiance from above as bins (clusters) or reduced to n's normal
    /// (patches, in band 0..3 of bin 0). Returns sum over the leaves below of A |dB| per
    /// band, and records each leaf's total irradiance in `arriving` when asked.
    pub(super) fn push_pull(
        &mut self,
        n: u32,
        down: &[[f64; 6]; 3],
        arriving: &mut Option<&mut Vec<(u32, [f64; 3])>>,
    ) -> [f64; 3] {
        let node = &self.nodes[n as usize];
        if node.is_cluster() {
            let c = node.cluster as usize;
            let mut total = self.clusters[c].incident;
            for band in 0..3 {
                for k in 0..6 {
                    total[band][k] += down[band][k];
                }
            }
            let children = node.children;
            let count = node.child_count as usize;
            let mut change = [0.0; 3];
            let mut power = [[0.0; 6]; 3];
            let mut sum = [0.0; 3];
            let mut b_max: f64 = 0.0;
            for &child in &children[..count] {
                let ch = self.push_pull(child, &total, arriving);
                for k in 0..3 {
                    change[k] += ch[k];
                }
                let cn = &self.nodes[child as usize];
                let cb = self.b[child as usize];
                for k in 0..3 {
                    sum[k] += cn.open_area * cb[k];
                }
                if cn.is_cluster() {
                    b_max = b_max.max(self.clusters[cn.cluster as usize].b_max);
                    let cp = &self.clusters[cn.cluster as usize].power;
                    for band in 0..3 {
                        for k in 0..6 {
                            power[band][k] += cp[band][k];
                        }
                    }
                } else {
                    b_max = b_max.max(max3(cb));
                    let m = self.normal[cn.surface as usize];
                    for band in 0..3 {
                        for k in 0..3 {
                            power[band][bin(k, m[k])] += cn.open_area * cb[band] * m[k].abs();
                        }
                    }
                }
            }
            let area = self.nodes[n as usize].area;
            self.clusters[c].power = power;
            self.clusters[c].b_max = b_max;
            self.b[n as usize] = sum.map(|s| if area > 0.0 { s / area } else { 0.0 });
            return change;
        }
        // A patch: `down` is bins when the parent is a cluster (a root), else the scalar
        // irradiance in down[band][0].
        let h_down: [f64; 3] = if self.is_root(n) {
            irradiance_for(down, self.normal[node.surface as usize])
        } else {
            std::array::from_fn(|band| down[band][0])
        };
        // The light this patch's own links bring is spread over its open area: their form
        // factors are averages over the whole patch, whose buried points see nothing, and
        // spread over the whole area the buried share would leave the account (room.scene
        // lost 5 % of its light where the sofa and the rug touch what they stand on).
        let open = if node.open_area > 0.0 && node.open_area < node.area {
            node.area / node.open_area
        } else {
            1.0
        };
        let h: [f64; 3] = std::array::from_fn(|k| h_down[k] + node.gathered[k] * open);
        let old = self.b[n as usize];
        if node.buried {
            // Nothing reaches a buried patch and it sends nothing; its leaves' spread is
            // left out of its parent's (they are not among the leaves shown).
            self.b[n as usize] = [0.0; 3];
            self.b_span[n as usize] = (f64::INFINITY, f64::NEG_INFINITY);
            return [0.0; 3];
        }
        if node.child_count == 0 {
            let (s, e) = (node.surface as usize, self.self_exitance(n));
            let new: [f64; 3] = std::array::from_fn(|k| e[k] + self.rho[s][k] * h[k]);
            let area = node.area;
            if let Some(out) = arriving {
                out.push((n, h));
            }
            self.b[n as usize] = new;
            self.b_span[n as usize] = (max3(new), max3(new));
            return std::array::from_fn(|k| area * (new[k] - old[k]).abs());
        }
        let (children, count) = (node.children, node.child_count as usize);
        let mut pass = [[0.0; 6]; 3];
        for band in 0..3 {
            pass[band][0] = h[band];
        }
        let mut change = [0.0; 3];
        let mut sum = [0.0; 3];
        let mut span = (f64::INFINITY, f64::NEG_INFINITY);
        for &child in &children[..count] {
            let ch = self.push_pull(child, &pass, arriving);
            let (area, cb) = (self.nodes[child as usize].open_area, self.b[child as usize]);
            for k in 0..3 {
                change[k] += ch[k];
                sum[k] += area * cb[k];
            }
            let (lo, hi) = self.b_span[child as usize];
            span = (span.0.min(lo), span.1.max(hi));
        }
        // The mean over the open area: a patch's links, as sources, see only its open
        // part (the rays to its buried points are blocked), so its radiosity is that
        // part's; over the whole area the buried share would be left out twice.
        let area = self.nodes[n as usize].open_area;
        self.b[n as usize] = sum.map(|s| if area > 0.0 { s / area } else { 0.0 });
        self.b_span[n as usize] = span;
        change
    }

    /// Every cluster's irradiance bins gathered through its links from the radiosity and
    /// power bins the nodes hold now.
    pub(super) fn cluster_incident(&self) -> Vec<[[f64; 6]; 3]> {
        let (nodes, clusters, root_count) = (&self.nodes, &self.clusters, self.root_count);
        let (b, cluster_of) = (&self.b, &self.cluster_of);
        clusters
            .par_iter()
            .enumerate()
            .map(|(c, _)| {
                let mut inc = [[0.0; 6]; 3];
                // The cluster's node: clusters are made in order after the roots.
                let n = &nodes[root_count + c];
                for l in &n.links {
                    let c = cluster_of[l.source as usize];
                    let d = DVec3::new(l.dir[0] as f64, l.dir[1] as f64, l.dir[2] as f64);
                    let x = if c != NONE {
                        cluster_emission(&clusters[c as usize].power, d)
                    } else {
                        b[l.source as usize]
                    };
                    for k in 0..3 {
                        // Light travelling along d lands on surfaces facing -d.
                        let w = l.g as f64 * d[k].abs();
                        let slot = bin(k, -d[k]);
                        for band in 0..3 {
                            inc[band][slot] += w * x[band];
                        }
                    }
                }
                inc
            })
            .collect()
    }

    /// The irradiance node `n`'s own links bring from the radiosity and bins the nodes
    /// hold now (what a sweep gathers at `n`).
    pub(super) fn links_irradiance(&self, n: &Node) -> [f64; 3] {
        let mut g = [0.0; 3];
        for l in &n.links {
            let c = self.cluster_of[l.source as usize];
            let x = if c != NONE {
                let d = DVec3::new(l.dir[0] as f64, l.dir[1] as f64, l.dir[2] as f64);
                cluster_emission(&self.clusters[c as usize].power, d)
            } else {
                self.b[l.source as usize]
            };
            for k in 0..3 {
                g[k] += l.g as f64 * x[k];
            }
        }
        g
    }

    /// Gather / push-pull sweeps until the power that changes is below `tolerance` (a
    /// fraction of the emitted power); returns the sweeps made and the last residual.
    pub(super) fn solve(
        &mut self,
        emitted: [f64; 3],
        tolerance: f64,
    ) -> Result<(usize, f64), SolveError> {
        let rho_max = self.rho.iter().flatten().fold(0.0, |m: f64, &r| m.max(r));
        let (mut previous, mut rising) = (f64::INFINITY, 0);
        for sweep in 1..=MAX_SWEEPS {
            let this = &*self;
            let gathered: Vec<[f64; 3]> = this
                .nodes
                .par_iter()
                .map(|n| {
                    if n.is_cluster() {
                        [0.0; 3]
                    } else {
                        this.links_irradiance(n)
                    }
                })
                .collect();
            let incident = self.cluster_incident();
            for (n, g) in self.nodes.iter_mut().zip(gathered) {
                n.gathered = g;
            }
            for (c, inc) in self.clusters.iter_mut().zip(incident) {
                c.incident = inc;
            }
            let change = self.push_pull(self.top, &[[0.0; 6]; 3], &mut None);
            let residual = (0..3)
                .filter(|&k| emitted[k] > 0.0)
                .map(|k| change[k] / emitted[k])
                .fold(0.0, f64::max);
            // NaN is dropped by f64::max above and would read as converged: look for it.
            if let Some((node, value)) = self
                .b
                .iter()
                .enumerate()
                .find_map(|(i, b)| b.iter().find(|x| !x.is_finite()).map(|&x| (i, x)))
                .or_else(|| {
                    change
                        .iter()
                        .find(|x| !x.is_finite())
                        .map(|&x| (self.top as usize, x))
                })
            {
                return Err(SolveError::NotFinite {
                    solver: "hierarchical radiosity",
                    element: node,
                    value,
                    after: format!("sweep {sweep}"),
                });
            }
            // A converging sweep changes less than the one before it (by rho times the
            // form factors' sum, below 1); a change that rises sweep after sweep is light
            // growing, whatever bound it has yet to reach.
            rising = if residual > previous { rising + 1 } else { 0 };
            previous = residual;
            if rising >= RISING_SWEEPS {
                return Err(SolveError::HierarchicalGrowing {
                    rising,
                    change: residual,
                    sweep,
                    rho_max,
                    kept: 1.0 / (1.0 - rho_max).max(1e-12),
                });
            }
            // The power a sweep changes is at most the power in the scene, which valid
            // links keep below emitted / (1 - rho_max); twice that leaves room for the
            // links' own error.
            let limit = 2.0 / (1.0 - rho_max).max(1e-12);
            if residual > limit {
                return Err(SolveError::Diverged {
                    solver: "hierarchical radiosity",
                    what: "the power changed by one sweep (fraction of the emitted)",
                    value: residual,
                    bound: limit,
                    reason: format!(
                        "twice the most a scene with rho <= {rho_max} holds, 1 / (1 - rho_max)"
                    ),
                    after: format!("sweep {sweep}"),
                });
            }
            if residual <= tolerance {
                return Ok((sweep, residual));
            }
        }
        Err(SolveError::HierarchicalNotConverged { sweeps: MAX_SWEEPS })
    }
}
