//! Refinement: which node of a refined pair to split, breadth-first refinement of candidate
//! pairs into links (estimates in parallel, splits in order), and a pass over all links
//! with the current radiosity.

use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::link::Estimate;
use super::solver::Solver;
use super::visibility::VisibilityScratch;
use crate::progress::Progress;
use crate::solve::SolveError;

/// How often a long refinement says how far it has got (QA of issue #16: a tiny `--epsilon`
/// refined for minutes with nothing but a spinner).
const HEARTBEAT: Duration = Duration::from_secs(10);

impl Solver<'_> {
    /// Which of p and q to split for a refined link: Some(true) for p, Some(false) for q,
    /// None when neither can be.
    pub(super) fn split_choice(&self, p: u32, q: u32) -> Option<bool> {
        let (np, nq) = (&self.nodes[p as usize], &self.nodes[q as usize]);
        let min = self.settings.min_area;
        let can_p = np.is_cluster() || np.area > min;
        let can_q = nq.is_cluster() || nq.area > min;
        if can_p && (!can_q || np.radius >= nq.radius) {
            Some(true)
        } else if can_q {
            Some(false)
        } else {
            None
        }
    }

    /// Refines the candidate pairs (p, q) breadth first until the oracle is satisfied,
    /// storing the resulting links (estimates in parallel, splits in order); returns whether
    /// anything was split. Between breadth-first levels, at most once every [`HEARTBEAT`]
    /// (a level itself can take longer), it tells `progress` the nodes, links and memory so
    /// far: how long refinement takes is not known before it ends, but the memory limit
    /// bounds it.
    pub(super) fn refine(
        &mut self,
        mut frontier: Vec<(u32, u32)>,
        b_ref: f64,
        progress: &dyn Progress,
    ) -> Result<bool, SolveError> {
        let mut split = false;
        let mut last_said = Instant::now();
        while !frontier.is_empty() {
            if last_said.elapsed() >= HEARTBEAT {
                last_said = Instant::now();
                progress.message(&format!(
                    "hierarchical refinement: {} nodes, {} links, {} pairs to judge next; \
                     {} MiB of the {} MiB limit",
                    self.nodes.len(),
                    self.link_count,
                    frontier.len(),
                    self.memory_bytes() >> 20,
                    self.memory_limit >> 20
                ));
            }
            // What is held, and the frontier about to be expanded and estimated (checked
            // before it is allocated).
            let expanded: u64 = frontier
                .iter()
                .map(|&(p, q)| match &self.nodes[p as usize] {
                    node if p == q && node.is_cluster() => (node.children().len() as u64).pow(2),
                    _ => 1,
                })
                .sum();
            let used = self.memory_bytes() + expanded * super::solver::FRONTIER_PAIR_BYTES;
            self.peak_memory = self.peak_memory.max(used);
            if used > self.memory_limit {
                return Err(SolveError::HierarchicalTooBig {
                    used_mib: used >> 20,
                    limit_mib: self.memory_limit >> 20,
                    nodes: self.nodes.len(),
                    links: self.link_count,
                });
            }
            // A cluster's link to itself becomes the links between its children.
            let mut pairs = Vec::with_capacity(frontier.len());
            for &(p, q) in &frontier {
                if p == q {
                    let node = &self.nodes[p as usize];
                    if node.is_cluster() {
                        for &a in node.children() {
                            for &b in node.children() {
                                pairs.push((a, b));
                            }
                        }
                    }
                } else {
                    pairs.push((p, q));
                }
            }
            let this = &*self;
            let estimates: Vec<Estimate> = pairs
                .par_iter()
                .map_init(VisibilityScratch::default, |scratch, &(p, q)| {
                    if p == q {
                        // Expanded again next time round (a child cluster's self-link).
                        Estimate::TooClose
                    } else {
                        this.estimate(p, q, b_ref, scratch)
                    }
                })
                .collect();
            let mut next = Vec::new();
            for (&(p, q), estimate) in pairs.iter().zip(estimates) {
                let link = match estimate {
                    Estimate::Nothing => continue,
                    Estimate::TooClose => {
                        if p == q {
                            next.push((p, q));
                            continue;
                        }
                        None
                    }
                    Estimate::Link(link, rays) => {
                        self.rays += rays;
                        Some(link)
                    }
                    Estimate::Refine => None,
                };
                let refine = match &link {
                    None => true,
                    Some(link) => self.wants_refining(p, link, b_ref),
                };
                let choice = if refine {
                    self.split_choice(p, q)
                } else {
                    None
                };
                match (choice, link) {
                    (Some(split_p), _) => {
                        split = true;
                        let (node, other) = if split_p { (p, q) } else { (q, p) };
                        let children: Vec<u32> = if self.nodes[node as usize].is_cluster() {
                            self.nodes[node as usize].children().to_vec()
                        } else {
                            self.split_patch(node)
                        };
                        for c in children {
                            next.push(if split_p { (c, other) } else { (other, c) });
                        }
                    }
                    (None, Some(link)) => {
                        self.link_count += 1;
                        self.nodes[p as usize].links.push(link);
                    }
                    (None, None) => {
                        unreachable!("a pair without a link is one that can be split")
                    }
                }
            }
            frontier = next;
        }
        Ok(split)
    }

    /// One refinement pass over all links with the current B; returns the links refined.
    pub(super) fn refine_all(
        &mut self,
        b_ref: f64,
        progress: &dyn Progress,
    ) -> Result<usize, SolveError> {
        let mut pairs = Vec::new();
        for p in 0..self.nodes.len() {
            let links = std::mem::take(&mut self.nodes[p].links);
            let mut kept = Vec::with_capacity(links.len());
            for link in links {
                if self.wants_refining(p as u32, &link, b_ref)
                    && self.split_choice(p as u32, link.source).is_some()
                {
                    pairs.push((p as u32, link.source));
                } else {
                    kept.push(link);
                }
            }
            self.nodes[p].links = kept;
        }
        let refined = pairs.len();
        self.link_count -= refined;
        if refined > 0 {
            // The pairs are estimated again (cheap next to their children) so that `refine`
            // handles them like any candidate.
            self.refine(pairs, b_ref, progress)?;
        }
        Ok(refined)
    }
}
