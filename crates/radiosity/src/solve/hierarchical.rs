//! Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991) with BF refinement.
//!
//! Every input surface is the root of a quadtree: a quadrilateral splits into four at its
//! bilinear midpoints, a triangle into four at its edge midpoints; a polygon of five or more
//! corners is first cut into the fan of triangles from its centroid (as [`crate::mesh`] does),
//! each fan triangle a root of its own. No matrix is stored: energy moves along *links*, each
//! a pair (receiver node p, source node q) with an estimate of the form factor F_pq.
//!
//! # Links and their form factors
//!
//! F_pq is estimated as the mean of Lambert's exact point-to-polygon form factor
//! ([`crate::form_factor::exact::point_to_polygon`]) from four points of p (the centroids of
//! its four children; p's normal) to the polygon q, times the visible fraction of 16 point pairs (4 x 4 stratified points on
//! each, paired by a fixed permutation; only the pairs whose points are each in front of
//! the other's plane count) tested against the occluder BVH (only the occluders
//! whose boxes overlap the pair's box, less the two surfaces themselves; none means fully
//! visible, no ray cast). Each point estimate is bounded by 1 and exact for its point; the
//! mean of four approximates p's area average. (The centroid alone was tried first: in the
//! closed cube it over-estimated links of large receivers near a shared edge so much that
//! the hierarchy's form factors summed to 1.6 at some corner leaves.) The error of the
//! estimate for a receiver that is large relative to its distance is what refinement
//! reduces; links between nodes at the minimum area keep it (as in any hierarchical
//! radiosity without a better kernel).
//!
//! Initial links join every pair of roots that can see each other (some corner of each is
//! strictly in front of the other's plane): O(s^2) in the number of input surfaces. There
//! is no clustering (Smits, Arvo and Greenberg 1994) yet.
//!
//! # Refinement oracle (BF)
//!
//! A link p <- q is refined when
//!
//! ```text
//! rho_p * B_q * max(F_pq, F_qp) > epsilon * B_mean
//! ```
//!
//! where rho_p and B_q are the largest over the three bands, F_qp is the same estimate in the
//! other direction (so that a large receiver that sees a small source from its centroid but
//! not from all of its points, or the reverse, is caught), and B_mean is the area-weighted
//! mean radiosity of the whole scene (largest band) of the current solution (the emission
//! before the first solve). The oracle is therefore scale-free: multiplying all emissions
//! by a constant refines the same links. Of the two nodes the larger by area is split, if its
//! area exceeds `min_area`, else the other one if its area does; a link whose nodes are both
//! at most `min_area` is kept as it is.
//!
//! # Solving
//!
//! Each sweep gathers (every node's irradiance H_p = sum over its links of F_pq B_q), then
//! pushes irradiance down and pulls area-averaged radiosity up (leaves take
//! B = E + rho (H_down + H_p)). Sweeps stop when the largest change of any node's B is below
//! 1e-7 of the largest emission. Then every link is tested again with the new B, refined
//! links are replaced by links from or to the children, and the solve repeats, until no link
//! is refined. The leaves are the elements returned, as a [`Mesh`].
//!
//! # Accuracy (measured on the built-in Cornell box, against Gauss-Seidel on ~1000 elements)
//!
//! Links kept at coarse levels carry form factors averaged over large nodes, and their
//! visibility from 16 point pairs; on the Cornell box these are biased low: the reflected
//! radiosity is about 10 % low at epsilon 0.05 and 2 % (area-weighted RMS over the
//! surfaces) at epsilon 0.01; without the blocks (no occlusion) it agrees within 1 to 3 %
//! already at 0.05. It is not the visibility sampling (all 16 x 16 pairs instead of 16 give
//! the same bias); the likely cause is that a coarse link multiplies a visible fraction by
//! the source's *mean* radiosity, while the hidden part of a source is often its dark part
//! (the floor under a block is both unseen and unlit), so occlusion is counted twice until
//! the link is refined. `--epsilon` trades this error for time.
//!
//! # Energy account
//!
//! emitted = sum over leaves of A E; the power carried by a link is A_p F_pq B_q, of which the
//! fraction rho_p is reflected and 1 - rho_p absorbed; escaped = (power leaving all leaves,
//! sum A B) - (power carried by all links). At convergence emitted = absorbed + escaped
//! holds to the solve tolerance; in a closed scene `escaped` measures how far the link
//! estimates' sums of form factors are from 1 (it can be slightly negative).

use std::collections::HashMap;
use std::time::{Duration, Instant};

use glam::DVec3;
use rayon::prelude::*;

use super::{EnergyBalance, Radiosity, SolveError};
use crate::form_factor::exact::point_to_polygon;
use crate::geometry;
use crate::mesh::Mesh;
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::Scene;
use crate::visibility::PolygonBvh;

/// Sweeps stop when the largest change of B is below this fraction of the largest emission.
const SOLVE_TOLERANCE: f64 = 1e-7;
/// Give up after this many sweeps in one solve.
const MAX_SWEEPS: usize = 100_000;
/// Give up refining after this many rounds (each round is a solve and a refinement pass).
const MAX_ROUNDS: usize = 64;

/// How a hierarchical solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HierarchicalReport {
    /// Leaves (the elements returned).
    pub leaves: usize,
    /// Nodes of all quadtrees (leaves and inner nodes).
    pub nodes: usize,
    /// Links at the end.
    pub links: usize,
    /// Links made between the input surfaces before any refinement (O(s^2), no clustering).
    pub initial_links: usize,
    /// Refinement rounds (solve, then refine) made.
    pub rounds: usize,
    /// Gather / push-pull sweeps made in all.
    pub iterations: usize,
    /// Visibility segments tested.
    pub rays: u64,
    /// Where the emitted power went (see the module documentation).
    pub balance: EnergyBalance,
    /// Wall-clock time of the whole solve (linking, refinement and sweeps).
    pub elapsed: Duration,
}

/// The result of [`solve_hierarchical`]: the leaves as a mesh, with their radiosities.
#[derive(Clone, Debug)]
pub struct HierarchicalSolution {
    /// The leaves of every surface's quadtree, surface by surface (T-junctions allowed).
    pub mesh: Mesh,
    /// B per leaf (element of `mesh`), per band.
    pub radiosity: Radiosity,
    /// Counts, sweeps, energy.
    pub report: HierarchicalReport,
}

#[derive(Clone, Copy, Debug)]
struct Link {
    source: u32,
    /// Estimated F_pq (receiver p, the node holding the link; source q), occlusion included.
    ff: f64,
    /// max(F_pq, F_qp), occlusion included: what the oracle uses.
    oracle: f64,
}

#[derive(Clone, Debug)]
struct Node {
    surface: u32,
    corners: [DVec3; 4],
    count: u8,
    area: f64,
    children: Option<[u32; 4]>,
    links: Vec<Link>,
    b: [f64; 3],
    gathered: [f64; 3],
}

impl Node {
    fn polygon(&self) -> &[DVec3] {
        &self.corners[..self.count as usize]
    }
}

struct Solver<'a> {
    nodes: Vec<Node>,
    roots: Vec<Vec<u32>>,
    normal: Vec<DVec3>,
    rho: Vec<[f64; 3]>,
    emission: Vec<[f64; 3]>,
    occluders: &'a PolygonBvh,
    epsilon: f64,
    min_area: f64,
    rays: u64,
    candidates: Vec<u32>,
}

fn max3(v: [f64; 3]) -> f64 {
    v[0].max(v[1]).max(v[2])
}

fn mid(a: DVec3, b: DVec3) -> DVec3 {
    0.5 * (a + b)
}

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

/// The mean of Lambert's point-to-polygon form factor from 4 points of `receiver` (the
/// centres of its four children, equal areas) to `source`: an estimate of the
/// area-averaged F of the receiver.
fn mean_point_to_polygon(receiver: &[DVec3], normal: DVec3, source: &[DVec3]) -> f64 {
    let p = receiver;
    let points: [DVec3; 4] = if p.len() == 4 {
        [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75)]
            .map(|(u, v)| crate::mesh::bilinear(p, u, v))
    } else {
        let c = (p[0] + p[1] + p[2]) / 3.0;
        [
            (4.0 * p[0] + p[1] + p[2]) / 6.0,
            (p[0] + 4.0 * p[1] + p[2]) / 6.0,
            (p[0] + p[1] + 4.0 * p[2]) / 6.0,
            c,
        ]
    };
    points
        .iter()
        .map(|&x| point_to_polygon(x, normal, source))
        .sum::<f64>()
        / 4.0
}

/// True when some corner of `other` lies strictly in front of `poly`'s plane.
fn some_corner_in_front(poly: &[DVec3], normal: DVec3, other: &[DVec3]) -> bool {
    let centre = geometry::vertex_mean(poly);
    let size = geometry::diameter(poly).max(geometry::diameter(other));
    other.iter().any(|&v| normal.dot(v - centre) > 1e-9 * size)
}

impl Solver<'_> {
    fn new_node(&mut self, surface: u32, poly: &[DVec3], b: [f64; 3]) -> u32 {
        let mut corners = [DVec3::ZERO; 4];
        corners[..poly.len()].copy_from_slice(poly);
        self.nodes.push(Node {
            surface,
            corners,
            count: poly.len() as u8,
            area: geometry::polygon_area(poly),
            children: None,
            links: Vec::new(),
            b,
            gathered: [0.0; 3],
        });
        self.nodes.len() as u32 - 1
    }

    /// The children of node `n`, made on first use (they start with the parent's B).
    fn children(&mut self, n: u32) -> [u32; 4] {
        if let Some(c) = self.nodes[n as usize].children {
            return c;
        }
        let node = &self.nodes[n as usize];
        let (surface, b) = (node.surface, node.b);
        let p = node.corners;
        let polys: Vec<Vec<DVec3>> = if node.count == 4 {
            let (m01, m12, m23, m30) = (
                mid(p[0], p[1]),
                mid(p[1], p[2]),
                mid(p[2], p[3]),
                mid(p[3], p[0]),
            );
            let c = 0.25 * (p[0] + p[1] + p[2] + p[3]);
            vec![
                vec![p[0], m01, c, m30],
                vec![m01, p[1], m12, c],
                vec![c, m12, p[2], m23],
                vec![m30, c, m23, p[3]],
            ]
        } else {
            let (m01, m12, m20) = (mid(p[0], p[1]), mid(p[1], p[2]), mid(p[2], p[0]));
            vec![
                vec![p[0], m01, m20],
                vec![m01, p[1], m12],
                vec![m20, m12, p[2]],
                vec![m01, m12, m20],
            ]
        };
        let children = [0, 1, 2, 3].map(|i| self.new_node(surface, &polys[i], b));
        self.nodes[n as usize].children = Some(children);
        children
    }

    /// The link p <- q with its form-factor estimates.
    fn estimate(&mut self, p: u32, q: u32) -> Link {
        let (np, nq) = (&self.nodes[p as usize], &self.nodes[q as usize]);
        let (normal_p, normal_q) = (
            self.normal[np.surface as usize],
            self.normal[nq.surface as usize],
        );
        let f_pq = mean_point_to_polygon(np.polygon(), normal_p, nq.polygon());
        let f_qp = mean_point_to_polygon(nq.polygon(), normal_q, np.polygon());
        let mut link = Link {
            source: q,
            ff: f_pq,
            oracle: f_pq.max(f_qp),
        };
        if link.oracle == 0.0 {
            return link;
        }
        // Occluders whose boxes overlap the pair's box, less the two surfaces themselves.
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &v in np.polygon().iter().chain(nq.polygon()) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        let (sp, sq) = (np.surface, nq.surface);
        self.candidates.clear();
        self.occluders.overlapping(lo, hi, &mut self.candidates);
        let occ = self.occluders;
        self.candidates
            .retain(|&k| occ.id_of(k) != sp && occ.id_of(k) != sq);
        if self.candidates.is_empty() {
            return link;
        }
        let (a, b) = (sample_points(np.polygon()), sample_points(nq.polygon()));
        // Only pairs that face each other count: a pair with a point behind the other's
        // plane carries no energy, and counting it as blocked would bias the fraction low
        // for nodes that straddle each other's planes (a floor node round a block's side).
        let (mut facing, mut visible) = (0u32, 0u32);
        for i in 0..16 {
            let (x, y) = (a[i], b[(i * 5 + 3) % 16]);
            if normal_p.dot(y - x) <= 0.0 || normal_q.dot(x - y) <= 0.0 {
                continue;
            }
            facing += 1;
            if !occ.segment_blocked_by(&self.candidates, x, y) {
                visible += 1;
            }
        }
        self.rays += facing as u64;
        let fraction = if facing == 0 {
            1.0
        } else {
            visible as f64 / facing as f64
        };
        link.ff *= fraction;
        link.oracle *= fraction;
        link
    }

    /// Refines the link p <- q (estimating it first) until the oracle is satisfied, storing
    /// the resulting links; returns whether anything was split.
    fn refine(&mut self, p: u32, q: u32, b_ref: f64) -> bool {
        let mut stack = vec![(p, q)];
        let mut split = false;
        while let Some((p, q)) = stack.pop() {
            let link = self.estimate(p, q);
            let (np, nq) = (&self.nodes[p as usize], &self.nodes[q as usize]);
            let value = max3(self.rho[np.surface as usize]) * max3(nq.b) * link.oracle;
            if value > self.epsilon * b_ref {
                let (ap, aq) = (np.area, nq.area);
                let split_p = if ap >= aq {
                    ap > self.min_area
                } else {
                    aq <= self.min_area && ap > self.min_area
                };
                let split_q = !split_p && aq > self.min_area;
                if split_p {
                    split = true;
                    for c in self.children(p) {
                        stack.push((c, q));
                    }
                    continue;
                }
                if split_q {
                    split = true;
                    for c in self.children(q) {
                        stack.push((p, c));
                    }
                    continue;
                }
            }
            self.nodes[p as usize].links.push(link);
        }
        split
    }

    /// One refinement pass over all links with the current B; returns the links split.
    fn refine_all(&mut self, b_ref: f64) -> usize {
        let mut refined = 0;
        for p in 0..self.nodes.len() {
            let links = std::mem::take(&mut self.nodes[p].links);
            let mut kept = Vec::with_capacity(links.len());
            for link in links {
                let (np, nq) = (&self.nodes[p], &self.nodes[link.source as usize]);
                let value = max3(self.rho[np.surface as usize]) * max3(nq.b) * link.oracle;
                let splittable = np.area > self.min_area || nq.area > self.min_area;
                if value > self.epsilon * b_ref && splittable {
                    refined += 1;
                    self.refine(p as u32, link.source, b_ref);
                } else {
                    kept.push(link);
                }
            }
            // `refine` may have pushed links to p itself (when it split the source).
            let mut added = std::mem::take(&mut self.nodes[p].links);
            kept.append(&mut added);
            self.nodes[p].links = kept;
        }
        refined
    }

    /// Area-weighted mean over the roots of the largest band of B.
    fn mean_b(&self) -> f64 {
        let (mut sum, mut area) = (0.0, 0.0);
        for &r in self.roots.iter().flatten() {
            let n = &self.nodes[r as usize];
            sum += n.area * max3(n.b);
            area += n.area;
        }
        if area > 0.0 {
            sum / area
        } else {
            0.0
        }
    }

    /// Push irradiance `down` into node n, pull its area-averaged B up; returns the largest
    /// change of B in the subtree.
    fn push_pull(&mut self, n: u32, down: [f64; 3]) -> f64 {
        let node = &self.nodes[n as usize];
        let h: [f64; 3] = std::array::from_fn(|b| down[b] + node.gathered[b]);
        let old = node.b;
        let (new, mut change) = match node.children {
            None => {
                let s = node.surface as usize;
                let b: [f64; 3] =
                    std::array::from_fn(|k| self.emission[s][k] + self.rho[s][k] * h[k]);
                (b, 0.0)
            }
            Some(children) => {
                let area = node.area;
                let mut sum = [0.0; 3];
                let mut change: f64 = 0.0;
                for c in children {
                    change = change.max(self.push_pull(c, h));
                    let cn = &self.nodes[c as usize];
                    for (s, b) in sum.iter_mut().zip(cn.b) {
                        *s += cn.area * b;
                    }
                }
                (std::array::from_fn(|k| sum[k] / area), change)
            }
        };
        for k in 0..3 {
            change = change.max((new[k] - old[k]).abs());
        }
        self.nodes[n as usize].b = new;
        change
    }

    /// Gather / push-pull sweeps until B changes by less than the tolerance.
    fn solve(&mut self, e_max: f64) -> Result<usize, SolveError> {
        for sweep in 1..=MAX_SWEEPS {
            let gathered: Vec<[f64; 3]> = self
                .nodes
                .par_iter()
                .map(|n| {
                    let mut g = [0.0; 3];
                    for l in &n.links {
                        let b = self.nodes[l.source as usize].b;
                        for k in 0..3 {
                            g[k] += l.ff * b[k];
                        }
                    }
                    g
                })
                .collect();
            for (n, g) in self.nodes.iter_mut().zip(gathered) {
                n.gathered = g;
            }
            let mut change: f64 = 0.0;
            for s in 0..self.roots.len() {
                for i in 0..self.roots[s].len() {
                    let r = self.roots[s][i];
                    change = change.max(self.push_pull(r, [0.0; 3]));
                }
            }
            if change <= SOLVE_TOLERANCE * e_max {
                return Ok(sweep);
            }
        }
        Err(SolveError::BadSettings(format!(
            "hierarchical radiosity did not converge in {MAX_SWEEPS} sweeps"
        )))
    }

    fn leaves_of(&self, n: u32, out: &mut Vec<u32>) {
        match self.nodes[n as usize].children {
            None => out.push(n),
            Some(c) => {
                for k in c {
                    self.leaves_of(k, out);
                }
            }
        }
    }
}

/// Solves `scene` by hierarchical radiosity with BF refinement (see the module
/// documentation): `occluders` is the scene's occluder BVH
/// ([`crate::form_factor::occluder_bvh`]), `epsilon` the refinement threshold (relative to
/// the mean radiosity; smaller is finer and slower), `min_area` the area (scene units
/// squared) below which nodes are not split.
pub fn solve_hierarchical(
    scene: &Scene,
    occluders: &PolygonBvh,
    epsilon: f64,
    min_area: f64,
    progress: &dyn Progress,
) -> Result<HierarchicalSolution, SolveError> {
    if !(epsilon.is_finite() && epsilon > 0.0) {
        return Err(SolveError::BadSettings(format!(
            "epsilon must be a positive number, got {epsilon}"
        )));
    }
    if !(min_area.is_finite() && min_area > 0.0) {
        return Err(SolveError::BadSettings(format!(
            "the minimum element area must be a positive number, got {min_area}"
        )));
    }
    for (s, surface) in scene.surfaces.iter().enumerate() {
        for b in 0..3 {
            let (r, e) = (surface.reflectance.0[b], surface.emission.0[b]);
            if !(0.0..1.0).contains(&r) {
                return Err(SolveError::BadValue {
                    element: s,
                    what: "reflectance",
                    band: b,
                    value: r,
                    why: "outside [0, 1)",
                });
            }
            if !(e.is_finite() && e >= 0.0) {
                return Err(SolveError::BadValue {
                    element: s,
                    what: "emission",
                    band: b,
                    value: e,
                    why: "not a finite non-negative number",
                });
            }
        }
    }
    let start = Instant::now();
    let mut solver = Solver {
        nodes: Vec::new(),
        roots: Vec::new(),
        normal: Vec::new(),
        rho: Vec::new(),
        emission: Vec::new(),
        occluders,
        epsilon,
        min_area,
        rays: 0,
        candidates: Vec::new(),
    };
    for (s, surface) in scene.surfaces.iter().enumerate() {
        let v = &surface.vertices;
        solver
            .normal
            .push(geometry::polygon_normal(v).unwrap_or(DVec3::Z));
        solver.rho.push(surface.reflectance.0);
        solver.emission.push(surface.emission.0);
        let polys: Vec<Vec<DVec3>> = if v.len() <= 4 {
            vec![v.clone()]
        } else {
            let c = geometry::polygon_centroid(v);
            (0..v.len())
                .map(|i| vec![c, v[i], v[(i + 1) % v.len()]])
                .collect()
        };
        let roots = polys
            .iter()
            .map(|p| solver.new_node(s as u32, p, surface.emission.0))
            .collect();
        solver.roots.push(roots);
    }
    let e_max = scene
        .surfaces
        .iter()
        .map(|s| s.emission.max_band())
        .fold(0.0, f64::max);

    let (rounds, iterations, initial_links) =
        run_stage(progress, Stage::Solve, 0, || -> Result<_, SolveError> {
            // Initial links: every pair of roots of different surfaces that face each other.
            let all_roots: Vec<u32> = solver.roots.iter().flatten().copied().collect();
            let mut pairs = Vec::new();
            for &p in &all_roots {
                for &q in &all_roots {
                    let (np, nq) = (&solver.nodes[p as usize], &solver.nodes[q as usize]);
                    if np.surface == nq.surface {
                        continue;
                    }
                    let (mp, mq) = (
                        solver.normal[np.surface as usize],
                        solver.normal[nq.surface as usize],
                    );
                    if some_corner_in_front(np.polygon(), mp, nq.polygon())
                        && some_corner_in_front(nq.polygon(), mq, np.polygon())
                    {
                        pairs.push((p, q));
                    }
                }
            }
            let initial_links = pairs.len();
            let b_ref = solver.mean_b();
            for (p, q) in pairs {
                solver.refine(p, q, b_ref);
            }
            let mut iterations = 0;
            let mut rounds = 0;
            if e_max == 0.0 {
                return Ok((rounds, iterations, initial_links));
            }
            loop {
                rounds += 1;
                iterations += solver.solve(e_max)?;
                let b_ref = solver.mean_b();
                let refined = solver.refine_all(b_ref);
                progress.advance(1);
                if refined == 0 || rounds >= MAX_ROUNDS {
                    if refined > 0 {
                        iterations += solver.solve(e_max)?;
                    }
                    break;
                }
            }
            Ok((rounds, iterations, initial_links))
        })?;

    // The leaves, surface by surface, as a mesh; corners shared where they coincide exactly.
    let mut parts = Vec::with_capacity(scene.surfaces.len());
    let mut leaf_ids = Vec::new();
    for s in 0..scene.surfaces.len() {
        let mut leaves = Vec::new();
        for &r in &solver.roots[s] {
            solver.leaves_of(r, &mut leaves);
        }
        let mut index: HashMap<[u64; 3], u32> = HashMap::new();
        let mut vertices = Vec::new();
        let mut elements = Vec::with_capacity(leaves.len());
        for &l in &leaves {
            let corners = solver.nodes[l as usize]
                .polygon()
                .iter()
                .map(|&p| {
                    *index
                        .entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                        .or_insert_with(|| {
                            vertices.push(p);
                            vertices.len() as u32 - 1
                        })
                })
                .collect();
            elements.push(corners);
        }
        parts.push((vertices, elements, solver.normal[s]));
        leaf_ids.extend(leaves);
    }
    let mesh = Mesh::from_surfaces(parts);
    let radiosity = Radiosity {
        bands: std::array::from_fn(|k| {
            leaf_ids
                .iter()
                .map(|&l| solver.nodes[l as usize].b[k])
                .collect()
        }),
    };

    // Energy account.
    let mut emitted = [0.0; 3];
    let mut leaving = [0.0; 3];
    for &l in &leaf_ids {
        let n = &solver.nodes[l as usize];
        for k in 0..3 {
            emitted[k] += n.area * solver.emission[n.surface as usize][k];
            leaving[k] += n.area * n.b[k];
        }
    }
    let mut carried = [0.0; 3];
    let mut absorbed = [0.0; 3];
    let mut links = 0;
    for n in &solver.nodes {
        links += n.links.len();
        let rho = solver.rho[n.surface as usize];
        for l in &n.links {
            let b = solver.nodes[l.source as usize].b;
            for k in 0..3 {
                let power = n.area * l.ff * b[k];
                carried[k] += power;
                absorbed[k] += (1.0 - rho[k]) * power;
            }
        }
    }
    let balance = EnergyBalance {
        emitted,
        absorbed,
        escaped: std::array::from_fn(|k| leaving[k] - carried[k]),
    };
    let report = HierarchicalReport {
        leaves: leaf_ids.len(),
        nodes: solver.nodes.len(),
        links,
        initial_links,
        rounds,
        iterations,
        rays: solver.rays,
        balance,
        elapsed: start.elapsed(),
    };
    progress.message(&format!(
        "hierarchical radiosity: {} leaves, {} links ({} initial), {} rounds, {} sweeps, {} rays",
        report.leaves, report.links, report.initial_links, rounds, iterations, report.rays
    ));
    Ok(HierarchicalSolution {
        mesh,
        radiosity,
        report,
    })
}
