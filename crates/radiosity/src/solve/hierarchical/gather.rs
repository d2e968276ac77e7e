//! The final gather (Lischinski, Tampieri and Greenberg 1993; Smits, Arvo and Greenberg
//! 1994): once the hierarchy has converged (to the rounds' tolerance), every leaf's
//! irradiance is gathered again at the leaf's own resolution instead of being pushed down
//! from its ancestors.
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
//! itself are already at its resolution and are taken as they are. The links of the
//! clusters above L's quadtree are gathered at L too (`gather_cluster_link`), not taken
//! through the clusters' six irradiance bins as the sweeps take them: the bins give the
//! irradiance exactly only on surfaces facing an axis (on a normal n, sum_k |n_k| I_k,
//! up to sqrt 3 times the true value under light from all directions: the facets of a
//! tessellated sphere in a furnace where B = 2 came out between 1.13 and 2.80), and a
//! cluster link's visibility, sampled from sixteen of the cluster's points, may miss the
//! leaf's side of it (the bottom of that sphere saw none of the floor under it). Measured
//! against the path tracer (BENCHMARKS.md): building_small 4.94 -> 3.18 % pixel RMS,
//! room.scene 3.79 -> 2.81 %, the Cornell box unchanged; building_small's solve took
//! about four times as long (3.9 -> 16.9 s under one load).
//! Above [`CLUSTER_WALK_MAX_POINTS`] gather points it costs too much (the million-element
//! building: four times the solve) and the clusters' links come through their bins.
//!
//! Before it, leaves that span several cells of the scene's mesh are split down to single
//! cells (children inheriting their parent's radiosity), so that the solution has at least
//! the mesh's resolution wherever the hierarchy stopped coarser. The gathered radiosity is
//! B = E + rho H. Each leaf's gather is linear in the nodes' radiosity, so it is kept as
//! terms (source and coefficient) and iterated, pulling the leaves' radiosity up the trees
//! between passes, until the changing power is below the solve's tolerance: the fixed
//! point of the leaf-level gather rather than one or two bounces from the hierarchy, whose
//! own excess (a closed cube absorbed 3.2 % more than it emitted without the gather) two
//! passes left at 1.3 % and the iteration at 0.33 %. Where the terms do not fit in the
//! memory left, the hierarchy is first solved to the tolerance and two passes are made,
//! recomputing the terms. The energy account is taken
//! from the gathered H.
//!
//! Where the leaves are more than [`super::HierarchicalSettings::gather_points`], the
//! gather runs at coarser points: the largest patches of area at most A_g, the smallest A_g
//! that keeps them within the budget (leaves along contacts stay points of their own, as
//! their visibility is their own). A leaf's irradiance is then its point's gathered one
//! plus what the links held between the point and the leaf bring, pushed down as a sweep
//! does. Measured on building_small (7,922 leaves) against the path tracer: at every leaf
//! 4.94 % pixel RMS, at 5,849 points 5.68 %, at 3,569 points 6.76 %, without the gather
//! 11.67 %; on the million-element building at 236,916 points 7.35 % against 11.09 %
//! without (BENCHMARKS.md).

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use super::bins::{cluster_emission, irradiance_for};
use super::link::{patch_form_factor, Link};
use super::solver::Solver;
use super::tree::NONE;
use super::visibility::VisibilityScratch;
use crate::form_factor::kernel::mean_cos_over_r2;
use crate::progress::{Progress, Stage};
use crate::solve::SolveError;

/// The gather descends into a patch source's children while the source's radius is more than this
/// fraction of its distance from the receiver. Measured on the Cornell box at 2,046
/// elements and the default settings, against the exact dense solve: 0.5 / 0.25 gives
/// 1.94 / 1.58 % RMS with two passes (2.72 / 2.47 % with one); not descending at all,
/// 3.15 % with one.
const DESCEND_RATIO: f64 = 0.25;

/// Gather passes where the terms are too many to keep: the second gathers from the
/// radiosity of the first, pulled up the quadtrees, so that the sources' radiosity, not
/// only the receivers', is at the leaves' resolution. Measured as above: one / two / three
/// passes, 2.72 / 1.94 / 1.89 % RMS and 38.8 / 14.3 / 13.8 % largest difference (the
/// coarse hierarchy's own source radiosity made the largest differences).
const GATHER_PASSES: usize = 2;

/// Where the gathered terms fit in memory, the gather is iterated with them (each pass a
/// sum over the terms, no rays) until the power that changes is below the solve's
/// tolerance, or this many passes.
const MAX_GATHER_PASSES: usize = 200;

/// The most gather points at which the links of the clusters above a leaf are gathered at
/// the leaf (see the module documentation); with more, the leaves take them through the
/// clusters' irradiance bins, as the sweeps do. On the million-element building (236,916
/// points, 23,231 clusters) gathering them took the solve from 243 to about 950 s of CPU
/// (1.8 billion rays) for 7.35 -> 6.63 % pixel RMS; on building_small (7,922 points) it
/// takes the solve from 3.9 to 16.9 s (one load) for 4.94 -> 3.18 %.
const CLUSTER_WALK_MAX_POINTS: usize = 50_000;

/// The most leaves whose terms are made at once (the memory check runs between chunks).
const TERM_CHUNK: usize = 1 << 16;

/// The leaves whose terms are made first, to learn the bytes a leaf takes.
const FIRST_TERM_CHUNK: usize = 1 << 12;

/// Points whose terms fit in `bytes_left` at `bytes_per_point` each: from 256 (below
/// which the chunks' own overhead shows) to [`TERM_CHUNK`].
fn chunk_within(bytes_left: u64, bytes_per_point: u64) -> usize {
    (bytes_left / bytes_per_point.max(1)).clamp(256, TERM_CHUNK as u64) as usize
}

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
                sum[k] += cn.open_area * cb[k];
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
                                cn.open_area * cb[band] * m[k].abs();
                        }
                    }
                }
            }
        }
        // Patches: the mean over the open area (see `push_pull`); clusters: over all.
        let area = if is_cluster {
            self.nodes[n as usize].area
        } else {
            self.nodes[n as usize].open_area
        };
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

    /// The terms of the irradiance at leaf `l` from patch source `q` (to `l`'s
    /// resolution), descending into q's children where q is large next to its distance;
    /// `hidden` is whether the link's own samples saw part of q hidden (visibility is then
    /// sampled from `l`).
    fn gather_from_patch(
        &self,
        l: u32,
        q: u32,
        hidden: bool,
        terms: &mut LeafTerms,
        scratch: &mut VisibilityScratch,
    ) {
        let (nl, nq) = (&self.nodes[l as usize], &self.nodes[q as usize]);
        if nq.buried {
            return;
        }
        let r = nl.centre.distance(nq.centre);
        if nq.child_count > 0 && nq.radius > DESCEND_RATIO * r {
            for &c in nq.children() {
                self.gather_from_patch(l, c, hidden, terms, scratch);
            }
            return;
        }
        let (ml, mq) = (
            self.normal[nl.surface as usize],
            self.normal[nq.surface as usize],
        );
        let mut f = patch_form_factor(&self.near_pairs, nl, ml, nq, mq);
        if f <= 0.0 {
            return;
        }
        if hidden {
            let (fraction, cast, _) = self.visibility(l, q, scratch);
            terms.rays += cast;
            f *= fraction;
        }
        if f > 0.0 {
            terms.patches.push((q, f as f32));
        }
    }

    /// The terms of the irradiance at leaf `l` through `link`, held by one of l's
    /// ancestors.
    fn gather_link(
        &self,
        l: u32,
        link: &Link,
        terms: &mut LeafTerms,
        scratch: &mut VisibilityScratch,
    ) {
        let q = link.source;
        let nq = &self.nodes[q as usize];
        let nl = &self.nodes[l as usize];
        // A piece along a contact sees its sources through visibility of its own: the
        // link's, sampled from a coarser receiver, may have seen them wholly.
        let straddles = nl.straddles;
        if nq.is_cluster() {
            let m = self.normal[nl.surface as usize];
            let d = (nl.centre - nq.centre).normalize_or(DVec3::Z);
            let g = mean_cos_over_r2(nl.polygon(), m, nq.centre) / std::f64::consts::PI;
            let g = g * self.cluster_link_factor(nl, nq, d, g) * link.visible as f64;
            if g > 0.0 {
                terms
                    .clusters
                    .push((nq.cluster, g as f32, d.as_vec3().to_array()));
            }
            return;
        }
        if link.visible <= 0.0 && !straddles {
            return;
        }
        self.gather_from_patch(l, q, link.visible < 1.0 || straddles, terms, scratch);
    }

    /// The terms of the irradiance at leaf `l` through `link`, held by one of the clusters
    /// above l's quadtree. The link's
    /// visibility was sampled from the cluster's sample points, which may miss l's side
    /// of it altogether (sixteen points of a sphere of 128 facets, most on its top, see
    /// the floor under it through the sphere), so it is sampled again from l wherever it
    /// is below 1, 0 included.
    fn gather_cluster_link(
        &self,
        l: u32,
        link: &Link,
        terms: &mut LeafTerms,
        scratch: &mut VisibilityScratch,
    ) {
        let q = link.source;
        if self.nodes[q as usize].is_cluster() {
            self.gather_from_cluster(l, q, link.visible < 1.0, terms, scratch);
        } else {
            self.gather_from_patch(l, q, link.visible < 1.0, terms, scratch);
        }
    }

    /// The terms of the irradiance at leaf `l` from cluster `q`: where q is large next to
    /// its distance from l, from its children (patches by their own form factors, with
    /// visibility sampled from l); else by the cluster's intensity towards l over l's
    /// cos / r^2, weighed as a link is (`cluster_link_factor`), the visible fraction
    /// sampled from l where `hidden`. The point model alone gives nothing to a leaf whose
    /// front faces away from a near cluster's centre, though the cluster's members face it.
    fn gather_from_cluster(
        &self,
        l: u32,
        q: u32,
        hidden: bool,
        terms: &mut LeafTerms,
        scratch: &mut VisibilityScratch,
    ) {
        let (nl, nq) = (&self.nodes[l as usize], &self.nodes[q as usize]);
        let r = nl.centre.distance(nq.centre);
        if nq.radius > DESCEND_RATIO * r {
            for &c in nq.children() {
                if self.nodes[c as usize].is_cluster() {
                    self.gather_from_cluster(l, c, hidden, terms, scratch);
                } else {
                    self.gather_from_patch(l, c, true, terms, scratch);
                }
            }
            return;
        }
        let m = self.normal[nl.surface as usize];
        let d = (nl.centre - nq.centre).normalize_or(DVec3::Z);
        let g = mean_cos_over_r2(nl.polygon(), m, nq.centre) / std::f64::consts::PI;
        if g <= 0.0 {
            return;
        }
        let mut g = g * self.cluster_link_factor(nl, nq, d, g);
        if hidden {
            let (fraction, cast, _) = self.visibility(l, q, scratch);
            terms.rays += cast;
            g *= fraction;
        }
        if g > 0.0 {
            terms
                .clusters
                .push((nq.cluster, g as f32, d.as_vec3().to_array()));
        }
    }

    /// Every node's parent (a patch's or a cluster's; `NONE` for the top) and the leaves of
    /// every root.
    fn parents_and_leaves(&self) -> (Vec<u32>, Vec<u32>) {
        let mut parent = vec![NONE; self.nodes.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            for &c in n.children() {
                parent[c as usize] = i as u32;
            }
        }
        let mut leaves = Vec::new();
        for r in 0..self.root_count as u32 {
            self.leaves_of(r, &mut leaves);
        }
        (parent, leaves)
    }

    /// The final gather (see the module documentation): sets every leaf's radiosity to
    /// E + rho H from the irradiance H gathered at the leaf, iterated with the gathered
    /// terms to the solve's tolerance (or [`GATHER_PASSES`] passes where the terms are too
    /// many to keep), and returns each leaf's H.
    ///
    /// It is its own stage, [`Stage::Gather`], whose work units are the gather points: each
    /// is counted when its terms are made (the rays, most of the time); the passes over the
    /// terms that follow are sums.
    ///
    /// The hierarchy comes converged only to the rounds' tolerance: where the terms are
    /// kept, the passes iterate to the solve's tolerance from there (the first pass alone
    /// changes 15 % of the power on the million-element building, so sweeps to 1e-6
    /// before it were wasted: 19 of them, about 3 s); where they are not kept, the
    /// hierarchy is first solved to the tolerance with `emitted` (the solve's emitted
    /// power), as the two passes cannot converge it.
    pub(super) fn final_gather(
        &mut self,
        emitted: [f64; 3],
        progress: &dyn Progress,
    ) -> Result<Gathered, SolveError> {
        let start = std::time::Instant::now();
        self.split_leaves_to_cells();
        let (parent, leaves) = self.parents_and_leaves();
        let points = self.gather_points(&leaves, self.settings.gather_points);
        self.gathered_at = points.len();
        progress.start(Stage::Gather, points.len() as u64);
        let gathered = self.gather_at(&parent, &leaves, &points, emitted, progress)?;
        progress.finish(Stage::Gather, start.elapsed());
        Ok(gathered)
    }

    /// [`Solver::final_gather`] at `points` (of `leaves`, whose parents are `parent`).
    fn gather_at(
        &mut self,
        parent: &[u32],
        leaves: &[u32],
        points: &[u32],
        solve_emitted: [f64; 3],
        progress: &dyn Progress,
    ) -> Result<Gathered, SolveError> {
        let walk = points.len() <= CLUSTER_WALK_MAX_POINTS;
        let mut from_clusters = if walk {
            Vec::new()
        } else {
            self.irradiance_from_clusters()
        };
        let emitted: [f64; 3] = std::array::from_fn(|k| {
            leaves
                .iter()
                .map(|&l| self.nodes[l as usize].area * self.self_exitance(l)[k])
                .sum()
        });
        // The terms, kept while they fit in the memory left, chunk by chunk: each chunk as
        // many points as the memory left holds at the bytes a point has taken so far, so
        // that no chunk overshoots it (65,536 points' terms at once took 250 MiB in the
        // Cornell box at 94,580 leaves, past a 105 MiB limit).
        let budget = self.memory_limit.saturating_sub(self.memory_bytes());
        let mut kept: Vec<LeafTerms> = Vec::new();
        let mut bytes = 0u64;
        let mut chunk = FIRST_TERM_CHUNK;
        while kept.len() < points.len() {
            let next = &points[kept.len()..(kept.len() + chunk).min(points.len())];
            let terms = self.leaf_terms(next, parent, walk, Some(progress));
            bytes += terms.iter().map(LeafTerms::bytes).sum::<u64>();
            kept.extend(terms);
            if bytes > budget {
                break;
            }
            chunk = chunk_within(budget - bytes, bytes / kept.len() as u64);
        }
        // The points a chunk of the passes below makes terms for at once.
        let pass_chunk = chunk_within(budget, bytes / kept.len().max(1) as u64);
        if bytes > budget {
            kept = Vec::new();
        }
        let cached = kept.len() == points.len();
        if !cached {
            progress.message(&format!(
                "final gather: the terms of {} points pass the memory left ({} MiB); each of \
                 {GATHER_PASSES} passes makes them again (the progress counted the points made \
                 before they did not fit)",
                points.len(),
                budget >> 20
            ));
        }
        let (mut sweeps, mut solved) = (0, None);
        let passes = if cached {
            MAX_GATHER_PASSES
        } else {
            let (made, r) = self.solve(solve_emitted, self.settings.tolerance)?;
            (sweeps, solved) = (made, Some(r));
            if !walk {
                // The clusters' bins as that solve left them (review of #11: the first
                // pass took them from before it).
                from_clusters = self.irradiance_from_clusters();
            }
            GATHER_PASSES
        };
        let (mut h, mut made, mut residual) = (Vec::new(), 0, 0.0);
        for pass in 0..passes {
            if pass > 0 {
                // The sources' radiosity and the clusters' bins from the last pass.
                self.pull_up(self.top);
                if !walk {
                    let incident = self.cluster_incident();
                    for (c, inc) in self.clusters.iter_mut().zip(incident) {
                        c.incident = inc;
                    }
                    from_clusters = self.irradiance_from_clusters();
                }
            }
            let at_points = if cached {
                self.evaluate(&kept, &from_clusters)
            } else {
                let mut all = Vec::with_capacity(points.len());
                for chunk in points.chunks(pass_chunk) {
                    let terms = self.leaf_terms(chunk, parent, walk, None);
                    all.extend(self.evaluate(&terms, &from_clusters));
                }
                all
            };
            h = if points.len() == leaves.len() {
                at_points
            } else {
                self.push_below_points(points, &at_points, leaves.len())
            };
            let mut change = [0.0; 3];
            for (&l, hl) in leaves.iter().zip(&h) {
                let n = &self.nodes[l as usize];
                let (s, e) = (n.surface as usize, self.self_exitance(l));
                let new: [f64; 3] = std::array::from_fn(|k| e[k] + self.rho[s][k] * hl[k]);
                for k in 0..3 {
                    change[k] += n.area * (new[k] - self.b[l as usize][k]).abs();
                }
                self.b[l as usize] = new;
            }
            residual = (0..3)
                .filter(|&k| emitted[k] > 0.0)
                .map(|k| change[k] / emitted[k])
                .fold(0.0, f64::max);
            made += 1;
            if cached && residual <= self.settings.tolerance {
                break;
            }
        }
        Ok(Gathered {
            h_of: leaves.iter().copied().zip(h).collect(),
            sweeps,
            passes: made,
            // Where two passes were made from a solved hierarchy, what converged is that
            // solve; their own change is not a convergence measure.
            residual: solved.unwrap_or(residual),
        })
    }

    /// Without the final gather: the leaves along contacts (pieces of partly buried cells)
    /// gathered once from the converged hierarchy, with visibility of their own, as the
    /// final gather does for every leaf; a coarse link's visibility, pushed down, would
    /// light a piece half under a block as if it were in the open. `h_of` (each leaf's
    /// irradiance) is updated for them.
    pub(super) fn gather_contacts(&mut self, h_of: &mut HashMap<u32, [f64; 3]>) {
        let (parent, mut leaves) = self.parents_and_leaves();
        leaves.retain(|&l| self.nodes[l as usize].straddles);
        if leaves.is_empty() {
            return;
        }
        let walk = leaves.len() <= CLUSTER_WALK_MAX_POINTS;
        let from_clusters = if walk {
            Vec::new()
        } else {
            self.irradiance_from_clusters()
        };
        let terms = self.leaf_terms(&leaves, &parent, walk, None);
        let h = self.evaluate(&terms, &from_clusters);
        for (&l, hl) in leaves.iter().zip(h) {
            let (s, e) = (
                self.nodes[l as usize].surface as usize,
                self.self_exitance(l),
            );
            self.b[l as usize] = std::array::from_fn(|k| e[k] + self.rho[s][k] * hl[k]);
            h_of.insert(l, hl);
        }
    }

    /// The patches the final gather gathers at: every leaf where there are at most `max`;
    /// else, in each quadtree, the largest patches of area at most some A_g (the smallest
    /// that keeps their count at most `max`, found by bisection on A_g), except that a
    /// patch with a leaf along a contact under it is not taken whole (such leaves gather
    /// with visibility of their own, as without the coarse points). In the order of
    /// `leaves`: the leaves under each point follow one another.
    fn gather_points(&self, leaves: &[u32], max: usize) -> Vec<u32> {
        let open = leaves
            .iter()
            .filter(|&&l| !self.nodes[l as usize].straddles)
            .count();
        if open <= max {
            return leaves.to_vec();
        }
        // Whether a straddling leaf lies under each node (patches only).
        let mut straddling = vec![false; self.nodes.len()];
        fn mark(s: &Solver, n: u32, out: &mut [bool]) -> bool {
            let node = &s.nodes[n as usize];
            let mut any = node.child_count == 0 && node.straddles && !node.buried;
            for &c in node.children() {
                any |= mark(s, c, out);
            }
            out[n as usize] = any;
            any
        }
        for r in 0..self.root_count as u32 {
            mark(self, r, &mut straddling);
        }
        let pick = |area_max: f64, out: &mut Vec<u32>| {
            let mut stack: Vec<u32> = (0..self.root_count as u32).rev().collect();
            while let Some(n) = stack.pop() {
                let node = &self.nodes[n as usize];
                if node.buried {
                    continue;
                }
                if node.child_count == 0 || (node.area <= area_max && !straddling[n as usize]) {
                    out.push(n);
                } else {
                    stack.extend(node.children().iter().rev());
                }
            }
        };
        let mut hi = 0.0f64;
        for r in 0..self.root_count {
            hi = hi.max(self.nodes[r].area);
        }
        let mut out = Vec::new();
        // Bisection on log area: forty halvings of the ratio reach far below any leaf.
        let mut lo_log = (leaves
            .iter()
            .map(|&l| self.nodes[l as usize].area)
            .fold(f64::INFINITY, f64::min))
        .max(f64::MIN_POSITIVE)
        .ln();
        let mut hi_log = hi.max(f64::MIN_POSITIVE).ln();
        // The coarsest choice (every quadtree whole where it can be) is the fallback.
        let mut best = hi;
        for _ in 0..40 {
            let mid = 0.5 * (lo_log + hi_log);
            out.clear();
            pick(mid.exp(), &mut out);
            let open = out
                .iter()
                .filter(|&&n| !self.nodes[n as usize].straddles)
                .count();
            if open > max {
                lo_log = mid;
            } else {
                hi_log = mid;
                best = mid.exp();
            }
        }
        out.clear();
        pick(best, &mut out);
        out
    }

    /// Each leaf's irradiance from the irradiance gathered at the points above it: the
    /// point's, plus what the links of the patches between the point and the leaf bring,
    /// pushed down as a sweep does (spread over each patch's open area). `count` leaves,
    /// in the order `gather_points` gave.
    fn push_below_points(
        &self,
        points: &[u32],
        at_points: &[[f64; 3]],
        count: usize,
    ) -> Vec<[f64; 3]> {
        let per_point: Vec<Vec<[f64; 3]>> = points
            .par_iter()
            .zip(at_points)
            .map(|(&g, &h_g)| {
                let mut out = Vec::new();
                let mut stack = vec![(g, h_g)];
                while let Some((n, h)) = stack.pop() {
                    let node = &self.nodes[n as usize];
                    if node.buried {
                        continue;
                    }
                    if node.child_count == 0 {
                        out.push(h);
                        continue;
                    }
                    for &c in node.children().iter().rev() {
                        let child = &self.nodes[c as usize];
                        let links = self.links_irradiance(child);
                        let open = if child.open_area > 0.0 && child.open_area < child.area {
                            child.area / child.open_area
                        } else {
                            1.0
                        };
                        stack.push((c, std::array::from_fn(|k| h[k] + links[k] * open)));
                    }
                }
                out
            })
            .collect();
        let mut h = Vec::with_capacity(count);
        for v in per_point {
            h.extend(v);
        }
        h
    }

    /// The gather terms of `leaves`, in parallel; their rays are counted in the report, and
    /// each leaf done in `progress` where given.
    fn leaf_terms(
        &mut self,
        leaves: &[u32],
        parent: &[u32],
        walk: bool,
        progress: Option<&dyn Progress>,
    ) -> Vec<LeafTerms> {
        let this = &*self;
        let terms: Vec<LeafTerms> = leaves
            .par_iter()
            .map_init(VisibilityScratch::default, |scratch, &l| {
                let mut t = LeafTerms::default();
                // The leaf's own links: already at its resolution.
                for link in &this.nodes[l as usize].links {
                    let q = link.source;
                    let c = this.cluster_of[q as usize];
                    if c != NONE {
                        t.clusters.push((c, link.g, link.dir));
                    } else {
                        t.patches.push((q, link.g));
                    }
                }
                // The ancestors' links, evaluated again for the leaf: its quadtree's, and
                // with `walk` the clusters' above it (see `gather_cluster_link`); without,
                // the clusters' links come through their bins to the root.
                let (mut a, mut root) = (parent[l as usize], l);
                while a != NONE && (walk || !this.nodes[a as usize].is_cluster()) {
                    let by_cluster = this.nodes[a as usize].is_cluster();
                    for link in &this.nodes[a as usize].links {
                        if by_cluster {
                            this.gather_cluster_link(l, link, &mut t, scratch);
                        } else {
                            this.gather_link(l, link, &mut t, scratch);
                        }
                    }
                    if !by_cluster {
                        root = a;
                    }
                    a = parent[a as usize];
                }
                t.root = if walk { NONE } else { root };
                if let Some(p) = progress {
                    p.advance(1);
                }
                t
            })
            .collect();
        self.rays += terms.iter().map(|t| t.rays).sum::<u64>();
        terms
    }

    /// Each leaf's irradiance from its terms, the radiosity and power bins the nodes hold
    /// now, and (where the terms leave the clusters' links out) the irradiance each root
    /// takes through the clusters' bins.
    fn evaluate(&self, terms: &[LeafTerms], from_clusters: &[[f64; 3]]) -> Vec<[f64; 3]> {
        terms
            .par_iter()
            .map(|t| {
                let mut h = if t.root == NONE {
                    [0.0; 3]
                } else {
                    from_clusters[t.root as usize]
                };
                for &(q, f) in &t.patches {
                    let b = self.b[q as usize];
                    for k in 0..3 {
                        h[k] += f as f64 * b[k];
                    }
                }
                for &(c, g, d) in &t.clusters {
                    let d = DVec3::new(d[0] as f64, d[1] as f64, d[2] as f64);
                    let x = cluster_emission(&self.clusters[c as usize].power, d);
                    for k in 0..3 {
                        h[k] += g as f64 * x[k];
                    }
                }
                h
            })
            .collect()
    }
}

/// What the final gather found.
pub(super) struct Gathered {
    /// Each leaf's irradiance.
    pub h_of: HashMap<u32, [f64; 3]>,
    /// Sweeps of the hierarchy made first (where the terms were not kept).
    pub sweeps: usize,
    /// Passes over the terms.
    pub passes: usize,
    /// The power that changed in the last pass, a fraction of the emitted (largest band);
    /// where the terms were not kept, in the last sweep of the solve made first.
    pub residual: f64,
}

/// What a leaf gathers, as terms linear in the nodes' radiosity: H = H_root + sum f B_q
/// over patch sources + sum g I_c(d) over cluster sources.
#[derive(Default)]
struct LeafTerms {
    /// (patch source, form factor times visible fraction).
    patches: Vec<(u32, f32)>,
    /// (cluster index, cos / (pi r^2) times visible fraction, direction from the cluster).
    clusters: Vec<(u32, f32, [f32; 3])>,
    /// The leaf's quadtree root, which takes the irradiance through the clusters' bins
    /// above it; `NONE` where the clusters' links are among the terms instead.
    root: u32,
    /// Rays cast to find the terms.
    rays: u64,
}

impl LeafTerms {
    /// Bytes held.
    fn bytes(&self) -> u64 {
        (std::mem::size_of::<LeafTerms>()
            + self.patches.capacity() * 8
            + self.clusters.capacity() * 20) as u64
    }
}
