//! Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991) with BF refinement and
//! clustering (Smits, Arvo and Greenberg 1994; Sillion 1995).
//!
//! # The hierarchy
//!
//! Every input surface is the root of a quadtree of *patches*: a quadrilateral splits into
//! four at its bilinear midpoints, a triangle into four at its edge midpoints; a polygon of
//! five or more corners is first cut into the fan of triangles from its centroid (as
//! [`crate::mesh`] does), each fan triangle a root of its own. Where a patch spans several
//! elements of the mesh [`crate::mesh`] would make at the scene's `MAX_PATCH_AREA`, it
//! splits along the grid lines nearest its middle instead (four children, or two across a
//! patch twice as long as wide), so that the leaves nest with the mesh's elements: a leaf
//! is a piece of one element or a union of whole ones, and a solution can be compared with
//! a dense solve on that mesh element by element without mixing two grids (two dense
//! solutions on grids 4x apart differ by 1.7 % RMS on the Cornell box at 2,000 elements).
//! Triangles nest while their m is even. Above the roots sits a binary tree of *clusters*
//! (median split of the roots' centres along the longest axis, down to single roots), so
//! that the whole scene is one node. No matrix is stored: energy moves along *links*, each
//! held by its receiver p and naming its source q.
//!
//! # Clusters: light by direction
//!
//! A cluster is treated as a point at its box centre whose surfaces face the six axis
//! directions: it keeps, per band, six *power bins* P[k±] = sum over its patches of
//! A B max(0, ±n_k) (n the patch's normal), so that its radiant intensity towards a unit
//! direction d is I(d) = (1/pi) sum_k |d_k| P[k, sign d_k]; and a receiving cluster keeps
//! six *irradiance bins* (the irradiance on a surface facing ±e_k), which its patches take
//! as E(n) = sum_k |n_k| E[k, sign n_k]. Both are exact for axis-aligned surfaces (rooms,
//! buildings, the Cornell box's walls) and approximate for tilted ones; neither sees
//! occlusion inside the cluster (as in every clustering method). Links:
//!
//! * patch <- patch: F_pq, exact (double contour integral,
//!   [`crate::form_factor::exact::polygon_to_polygon`]) for pairs whose bounding spheres
//!   overlap, the mean of Lambert's point-to-polygon form factor from four points of p for
//!   pairs up to three times the sum of the radii apart, and beyond, the point-to-point
//!   kernel between four points of each (the midpoint rule on both);
//! * patch <- cluster: irradiance I_q(d) cos+(theta_p) / r^2 (averaged over four points of
//!   p);
//! * cluster <- patch: the patch's intensity B_q A_q cos+(theta_q) / pi into p's bins;
//! * cluster <- cluster: I_q(d) into p's bins;
//!
//! each times the visible fraction of point pairs (see [`Solver::visibility`]). A link that
//! involves a cluster is only made between a cluster and a node that its bounding sphere
//! does not reach (a patch's box, another cluster's sphere); closer pairs are always
//! refined. Initial linking is the root cluster's link to itself, refined: it costs about
//! the number of near pairs, not the square of the number of surfaces (measured in
//! tests/hierarchical.rs: links grow with the surfaces to the power 1.1).
//!
//! # Refinement oracle (BF)
//!
//! A link p <- q is refined when rho_p B_q F_hat > epsilon B_ref, where rho_p is the
//! largest reflectance of p (of any patch, for a cluster), B_q the largest band of q's
//! radiosity (for a patch: the larger of its mean and twice the spread of its leaves, as a
//! link misses the covariance of F and B where both peak together; for a cluster: the
//! largest of its patches, as its mean would hide a small light among dark walls), F_hat =
//! max(F_pq, F_qp) (F_qp by reciprocity) for patch links and the coupling of the two
//! projected areas, Ap(p) Ap(q) / (pi r^2), over the smaller area otherwise (capped at 1; a
//! cluster's projected area is raised by R / r times its area, for the directions its
//! members see the other node from). F_hat includes the visible fraction only when the
//! pair is fully visible, or is two patches hidden by at least eight facing point pairs (a
//! cluster's few sample points were seen to call visible pairs hidden): a partly hidden
//! link keeps its unoccluded F_hat, because the hidden part of a source is often its
//! darkest (the floor behind a block is both unseen and in shadow), so the visible fraction
//! times the mean B underestimates the transfer until the link is refined. A pair that the
//! oracle refines is refined whatever its visibility, even when all its sample pairs are
//! blocked: a sliver that pokes out from under an object is easily missed by sixteen
//! point pairs, and only the finished links (which the oracle accepts) are dropped when
//! wholly hidden. B_ref is the area-weighted mean radiosity of the scene; before the first
//! solve, the mean emission over one minus the mean reflectance (the ambient term of Cohen
//! et al. 1988). The oracle is scale-free. Of the two nodes the larger (bounding radius) is
//! split: a patch only while its area exceeds `min_area`, a cluster always.
//!
//! # Solving
//!
//! Each sweep gathers (patches: their links' irradiance; clusters: their irradiance bins),
//! then pushes irradiance down (bins are turned into a root's irradiance by its normal) and
//! pulls area-averaged radiosity and power bins up (leaves take B = E + rho H). Sweeps stop
//! when the power that changed, sum over leaves of A |dB|, is at most `tolerance` of the
//! emitted power in every band: the analogue of progressive refinement's unshot energy.
//! Then every link is tested again with the new B, refined links are replaced, and the
//! solve repeats until a round refines fewer than one link in 10,000. The leaves are the
//! elements returned, as a [`Mesh`].
//!
//! # Accuracy
//!
//! Element by element against a dense solve on the same mesh with exact (contour) form
//! factors and 4 x 4 by 4 x 4 visibility pairs, leaves down to a quarter of an element
//! (the Cornell box; tests/hierarchical.rs, BENCHMARKS.md): at 2,046 elements 0.66 % RMS at
//! epsilon 3e-4, 1.3 % at 1e-3, 5 % at 1e-2; at 19,591 elements 0.73 % at 1e-4 and 1.2 %
//! at 3e-4 (a finer mesh has more links per element, each within the BF tolerance, so it
//! needs a smaller epsilon for the same agreement). The dense solve with the default area
//! k = 2 form factors is itself 1.2 % RMS from that reference on its own mesh, so it is not
//! accurate enough to judge a 1 % agreement.
//!
//! # Energy account
//!
//! emitted = sum over leaves of A E; each leaf absorbs A (1 - rho) H of the irradiance H that
//! reaches it (its own links and its ancestors'); escaped = (power leaving all leaves, sum
//! A B) - (power arriving, sum A H). emitted = absorbed + escaped holds to the solve
//! tolerance; in a closed scene `escaped` measures how far the link estimates' sums of form
//! factors are from 1 (it can be slightly negative).
#![allow(clippy::needless_range_loop)] // bands and bins read best as indices

use std::collections::HashMap;
use std::time::{Duration, Instant};

use glam::DVec3;
use rayon::prelude::*;

use super::{EnergyBalance, Radiosity, SolveError};
use crate::form_factor::exact::point_to_polygon;
use crate::form_factor::kernel::{
    mean_cos_over_r2, mean_point_pairs, mean_point_to_polygon, quarter_points,
};
use crate::geometry;
use crate::mesh::Mesh;
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::Scene;
use crate::visibility::PolygonBvh;

/// The default of [`HierarchicalSettings::tolerance`]: sweeps stop when the power still
/// changing is below this fraction of the emitted power.
pub const DEFAULT_HIERARCHICAL_TOLERANCE: f64 = 1e-6;
/// Give up after this many sweeps in one solve.
const MAX_SWEEPS: usize = 100_000;
/// Give up refining after this many rounds (each round is a solve and a refinement pass).
const MAX_ROUNDS: usize = 64;
/// The oracle takes a patch source's radiosity as the larger of its mean and this many
/// times the spread (largest - smallest) of its leaves. Measured on the Cornell box at 2,046
/// elements, epsilon 0.01: weight 0 / 1 / 2 / 4 gives 6.4 / 6.2 / 5.6 / 5.0 % RMS against
/// the dense solve and -1.2 / -0.9 / -0.5 / -0.4 % mean difference; on the default building
/// (217k leaves) 2 costs 14 % more time and 4 costs 29 %.
const SPAN_WEIGHT: f64 = 2.0;
/// No node index.
const NONE: u32 = u32::MAX;
/// Sample points kept per cluster for visibility.
const CLUSTER_SAMPLES: usize = 8;

/// How a hierarchical solve is driven.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HierarchicalSettings {
    /// BF refinement threshold, relative to the mean radiosity (smaller: finer and slower).
    pub epsilon: f64,
    /// Patches of at most this area (scene units squared) are not split.
    pub min_area: f64,
    /// Sweeps stop when sum A |dB| over the leaves is at most this fraction of the emitted
    /// power, in every band.
    pub tolerance: f64,
    /// Refinement stops with [`SolveError::HierarchicalTooBig`] when nodes and links would
    /// take more than this; `None`: 80 % of the memory available.
    pub max_memory_bytes: Option<u64>,
}

/// How a hierarchical solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HierarchicalReport {
    /// Leaves (the elements returned).
    pub leaves: usize,
    /// Nodes: clusters, and patches of all quadtrees (leaves and inner nodes).
    pub nodes: usize,
    /// Clusters (inner nodes above the input surfaces).
    pub clusters: usize,
    /// Links at the end.
    pub links: usize,
    /// Links made from the emission alone, before the first solve.
    pub initial_links: usize,
    /// Refinement rounds (solve, then refine) made.
    pub rounds: usize,
    /// Gather / push-pull sweeps made in all.
    pub iterations: usize,
    /// Power that still changed in the last sweep, as a fraction of the emitted power (the
    /// largest band): the analogue of the unshot fraction.
    pub residual: f64,
    /// Visibility segments tested.
    pub rays: u64,
    /// Bytes held by nodes and links at the end (an estimate from their sizes).
    pub memory_bytes: u64,
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

/// A link held by receiver p from source q (see the module documentation for `g`).
#[derive(Clone, Copy, Debug)]
struct Link {
    source: u32,
    /// patch <- patch: F_pq; patch <- cluster: cos+ / (pi r^2); cluster <- patch:
    /// A_q cos+ / (pi r^2); cluster <- cluster: 1 / (pi r^2). Visibility included.
    g: f32,
    /// F_hat of the oracle, visibility included.
    oracle: f32,
    /// Unit direction of travel, from q's centre to p's.
    dir: [f32; 3],
}

#[derive(Clone, Debug)]
struct Node {
    /// Input surface of a patch; NONE for a cluster.
    surface: u32,
    /// Index into `Solver::clusters`; NONE for a patch.
    cluster: u32,
    /// Corners of a patch (3 or 4).
    count: u8,
    children: [u32; 4],
    child_count: u8,
    /// The cells of the scene's mesh across a patch (see [`crate::mesh::grid_of`]): [cu, cv]
    /// for a quadrilateral, [m, 0] for a triangle cut into m^2; [0, 0] for a patch smaller
    /// than one cell or off the mesh's lattice.
    grid: [u32; 2],
    corners: [DVec3; 4],
    centre: DVec3,
    radius: f64,
    area: f64,
    links: Vec<Link>,
    /// A patch's gathered irradiance.
    gathered: [f64; 3],
}

impl Node {
    fn polygon(&self) -> &[DVec3] {
        &self.corners[..self.count as usize]
    }
    fn is_cluster(&self) -> bool {
        self.cluster != NONE
    }
    fn children(&self) -> &[u32] {
        &self.children[..self.child_count as usize]
    }
}

#[derive(Clone, Debug)]
struct Cluster {
    lo: DVec3,
    hi: DVec3,
    /// Largest reflectance of any band of any patch inside.
    rho: f64,
    /// Area bins: sum over its patches of A max(0, ±n_k).
    area_bins: [f64; 6],
    /// Power bins per band (see the module documentation).
    power: [[f64; 6]; 3],
    /// Largest radiosity (largest band) of its patches (root level): what the oracle uses,
    /// as a cluster's mean hides a small bright light among dark surfaces.
    b_max: f64,
    /// Gathered irradiance bins per band.
    incident: [[f64; 6]; 3],
    /// Points on surfaces inside, with their normals, for visibility.
    samples: Vec<(DVec3, DVec3)>,
}

/// Bin of axis `k` for the sign of `x`.
fn bin(k: usize, x: f64) -> usize {
    2 * k + usize::from(x < 0.0)
}

/// (pi times) the intensity of a cluster with power bins `power` along unit `d`.
fn cluster_emission(power: &[[f64; 6]; 3], d: DVec3) -> [f64; 3] {
    std::array::from_fn(|band| (0..3).map(|k| d[k].abs() * power[band][bin(k, d[k])]).sum())
}

/// The irradiance bins `incident` as seen by a surface of unit normal `n`.
fn irradiance_for(incident: &[[f64; 6]; 3], n: DVec3) -> [f64; 3] {
    std::array::from_fn(|band| {
        (0..3)
            .map(|k| n[k].abs() * incident[band][bin(k, n[k])])
            .sum()
    })
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

/// What the estimate of a candidate pair says.
enum Estimate {
    /// The pair involves a cluster and the nodes are too close for a cluster link.
    TooClose,
    /// Nothing can pass (back to back, or the same surface).
    Nothing,
    /// A link, and the rays cast for it.
    Link(Link, u64),
    /// The pair must be refined (decided without rays).
    Refine,
}

struct Solver<'a> {
    nodes: Vec<Node>,
    /// Area-averaged radiosity of every node (apart from the nodes: the sweeps read it at
    /// random).
    b: Vec<[f64; 3]>,
    /// Smallest and largest radiosity (largest band) of the leaves under every patch.
    b_span: Vec<(f64, f64)>,
    /// Cluster index of every node, NONE for patches.
    cluster_of: Vec<u32>,
    clusters: Vec<Cluster>,
    /// Quadtree roots of each input surface.
    roots: Vec<Vec<u32>>,
    top: u32,
    /// Nodes 0..root_count are the roots; cluster c is node root_count + c.
    root_count: usize,
    normal: Vec<DVec3>,
    rho: Vec<[f64; 3]>,
    emission: Vec<[f64; 3]>,
    occluders: &'a PolygonBvh,
    settings: HierarchicalSettings,
    rays: u64,
    /// Links held by all nodes.
    link_count: usize,
    /// Refinement stops with an error when [`Solver::memory_bytes`] passes this.
    memory_limit: u64,
}

impl Solver<'_> {
    fn new_patch(&mut self, surface: u32, poly: &[DVec3], grid: [u32; 2], b: [f64; 3]) -> u32 {
        let mut corners = [DVec3::ZERO; 4];
        corners[..poly.len()].copy_from_slice(poly);
        let centre = geometry::vertex_mean(poly);
        let radius = poly.iter().map(|v| v.distance(centre)).fold(0.0, f64::max);
        self.nodes.push(Node {
            surface,
            cluster: NONE,
            count: poly.len() as u8,
            children: [NONE; 4],
            child_count: 0,
            grid,
            corners,
            centre,
            radius,
            area: geometry::polygon_area(poly),
            links: Vec::new(),
            gathered: [0.0; 3],
        });
        self.b.push(b);
        self.b_span.push((max3(b), max3(b)));
        self.cluster_of.push(NONE);
        self.nodes.len() as u32 - 1
    }

    /// Builds the cluster tree over `items` (patch roots); returns its top node.
    fn build_clusters(&mut self, items: &mut [u32]) -> u32 {
        if items.len() == 1 {
            return items[0];
        }
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &i in items.iter() {
            let c = self.nodes[i as usize].centre;
            lo = lo.min(c);
            hi = hi.max(c);
        }
        let axis = (hi - lo).max_position();
        let half = items.len() / 2;
        items.select_nth_unstable_by(half, |&a, &b| {
            let (ca, cb) = (
                self.nodes[a as usize].centre[axis],
                self.nodes[b as usize].centre[axis],
            );
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
        let (left, right) = items.split_at_mut(half);
        let a = self.build_clusters(left);
        let b = self.build_clusters(right);
        // The cluster's box, area, reflectance and sample points from its two children.
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let mut rho: f64 = 0.0;
        let mut area = 0.0;
        let mut samples = Vec::new();
        let mut per_child = Vec::new();
        let mut area_bins = [0.0; 6];
        for c in [a, b] {
            let n = &self.nodes[c as usize];
            area += n.area;
            if n.is_cluster() {
                let cl = &self.clusters[n.cluster as usize];
                for k in 0..6 {
                    area_bins[k] += cl.area_bins[k];
                }
                lo = lo.min(cl.lo);
                hi = hi.max(cl.hi);
                rho = rho.max(cl.rho);
                per_child.push(cl.samples.clone());
            } else {
                for &v in n.polygon() {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                rho = rho.max(max3(self.rho[n.surface as usize]));
                let m = self.normal[n.surface as usize];
                for k in 0..3 {
                    area_bins[bin(k, m[k])] += n.area * m[k].abs();
                }
                // The quarter points, not the centre: the centre of a large patch may lie
                // under something standing on it (the Cornell box's floor centre is under
                // the tall block), which would hide the whole cluster.
                let m = self.normal[n.surface as usize];
                per_child.push(quarter_points(n.polygon()).map(|x| (x, m)).to_vec());
            }
        }
        for k in 0..CLUSTER_SAMPLES {
            if let Some(&s) = per_child[k % 2].get(k / 2) {
                samples.push(s);
            }
        }
        let centre = 0.5 * (lo + hi);
        self.clusters.push(Cluster {
            lo,
            hi,
            rho,
            area_bins,
            b_max: 0.0,
            power: [[0.0; 6]; 3],
            incident: [[0.0; 6]; 3],
            samples,
        });
        self.nodes.push(Node {
            surface: NONE,
            cluster: self.clusters.len() as u32 - 1,
            count: 0,
            children: [a, b, NONE, NONE],
            child_count: 2,
            grid: [0, 0],
            corners: [DVec3::ZERO; 4],
            centre,
            radius: 0.5 * (hi - lo).length(),
            area,
            links: Vec::new(),
            gathered: [0.0; 3],
        });
        self.b.push([0.0; 3]);
        self.b_span.push((0.0, 0.0));
        self.cluster_of.push(self.clusters.len() as u32 - 1);
        self.nodes.len() as u32 - 1
    }

    /// The children of patch `n`, made on first use (they start with the parent's B).
    ///
    /// A patch that spans several cells of the scene's mesh splits along the grid lines
    /// nearest its middle (four children; two, across its length, when it is twice as
    /// many cells long as wide), so that every element of the mesh is a node of the
    /// quadtree and the leaves nest with the mesh's elements (a leaf is a union of elements
    /// or a piece of one); a triangle of m^2 cells with m even splits at its edge midpoints
    /// into four of (m/2)^2. Below one cell, or off the lattice (a triangle of odd m), a
    /// quadrilateral splits at its bilinear midpoints and a triangle at its edge midpoints.
    fn split_patch(&mut self, n: u32) -> Vec<u32> {
        let node = &self.nodes[n as usize];
        if node.child_count > 0 {
            return node.children().to_vec();
        }
        let (surface, b) = (node.surface, self.b[n as usize]);
        let p = node.corners;
        let [cu, cv] = node.grid;
        // (corners, grid) of each child.
        let mut made: Vec<([DVec3; 4], [u32; 2])> = Vec::with_capacity(4);
        if node.count == 4 {
            let aligned = cu > 1 || cv > 1;
            // Cuts in u and v: (parameter, cells before it) for each piece boundary. The
            // mesh's cells are near square, so a patch twice as many cells long as wide is
            // cut across its length only: children stay near square (an elongated patch
            // has a large bounding sphere for its area, which the oracle and the near-pair
            // test pay for).
            let (split_u, split_v) = if cu >= 2 * cv {
                (true, false)
            } else if cv >= 2 * cu {
                (false, true)
            } else {
                (cu > 1, cv > 1)
            };
            let cuts = |c: u32, split: bool| -> Vec<(f64, u32)> {
                if !aligned {
                    vec![(0.0, 0), (0.5, 0), (1.0, 0)]
                } else if split {
                    let h = c / 2;
                    vec![(0.0, 0), (h as f64 / c as f64, h), (1.0, c)]
                } else {
                    vec![(0.0, 0), (1.0, c)]
                }
            };
            let (us, vs) = (cuts(cu, split_u), cuts(cv, split_v));
            for j in 0..vs.len() - 1 {
                for i in 0..us.len() - 1 {
                    let (u0, u1, v0, v1) = (us[i].0, us[i + 1].0, vs[j].0, vs[j + 1].0);
                    let q = |u: f64, v: f64| crate::mesh::bilinear(&p, u, v);
                    let grid = if aligned {
                        [us[i + 1].1 - us[i].1, vs[j + 1].1 - vs[j].1]
                    } else {
                        [0, 0]
                    };
                    made.push(([q(u0, v0), q(u1, v0), q(u1, v1), q(u0, v1)], grid));
                }
            }
        } else {
            let (m01, m12, m20) = (mid(p[0], p[1]), mid(p[1], p[2]), mid(p[2], p[0]));
            let z = DVec3::ZERO;
            let grid = if cu >= 2 && cu % 2 == 0 {
                [cu / 2, 0]
            } else {
                [0, 0]
            };
            for t in [
                [p[0], m01, m20, z],
                [m01, p[1], m12, z],
                [m20, m12, p[2], z],
                [m01, m12, m20, z],
            ] {
                made.push((t, grid));
            }
        }
        let count = node.count as usize;
        let children: Vec<u32> = made
            .iter()
            .map(|(poly, grid)| self.new_patch(surface, &poly[..count], *grid, b))
            .collect();
        let node = &mut self.nodes[n as usize];
        node.children[..children.len()].copy_from_slice(&children);
        node.child_count = children.len() as u8;
        children
    }

    /// Which of p and q to split for a refined link: Some(true) for p, Some(false) for q,
    /// None when neither can be.
    fn split_choice(&self, p: u32, q: u32) -> Option<bool> {
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

    /// The visible fraction between p and q from a few point pairs, and the rays cast. Only
    /// pairs whose points face each other count (a pair with a point behind the other's
    /// plane carries no energy); when no pair faces, all pairs count. Patch <- patch links
    /// use 16 pairs (4 x 4 stratified points on each, paired by a fixed permutation) and
    /// only the occluders whose boxes overlap the pair's box (none: visible, no ray);
    /// cluster links use up to eight facing pairs of sample points (a cluster keeps up to
    /// eight quarter points of its roots, taken alternately from its two children) and the
    /// whole BVH.
    fn visibility(&self, p: u32, q: u32, scratch: &mut Vec<u32>) -> (f64, u64, u32) {
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

    /// The area of node `n` projected on the plane normal to unit `d`, seen from the side
    /// `d` points to (clusters: from their area bins).
    fn projected_area(&self, n: &Node, d: DVec3) -> f64 {
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
    fn cluster_oracle(&self, np: &Node, nq: &Node, d: DVec3, r: f64) -> f64 {
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

    /// Estimates the link p <- q.
    fn estimate(&self, p: u32, q: u32, b_ref: f64, scratch: &mut Vec<u32>) -> Estimate {
        let (np, nq) = (&self.nodes[p as usize], &self.nodes[q as usize]);
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
                // Near pairs (centres closer than twice the sum of the radii) get the exact
                // area-averaged F (double contour integral): the mean over four points
                // misses the peak of F near a shared edge and is biased low there (5 % on
                // the Cornell box's walls at epsilon 0.01). Distant pairs get the mean of four
                // exact point values, accurate to O((R / r)^2).
                let near = r < np.radius + nq.radius;
                let far = r > 3.0 * (np.radius + nq.radius);
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
                    };
                    if self.wants_refining(p, &probe, b_ref) {
                        return Estimate::Refine;
                    }
                }
                let f_pq = if near {
                    crate::form_factor::exact::polygon_to_polygon(np.polygon(), nq.polygon())
                } else if far {
                    mean_point_pairs(np.polygon(), mp, nq.polygon(), mq, nq.area)
                } else {
                    mean_point_to_polygon(np.polygon(), mp, nq.polygon())
                };
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
            },
            rays,
        )
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
    fn wants_refining(&self, p: u32, link: &Link, b_ref: f64) -> bool {
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

    /// Refines the candidate pairs (p, q) breadth first until the oracle is satisfied,
    /// storing the resulting links (estimates in parallel, splits in order); returns whether
    /// anything was split.
    fn refine(&mut self, mut frontier: Vec<(u32, u32)>, b_ref: f64) -> Result<bool, SolveError> {
        let mut split = false;
        while !frontier.is_empty() {
            let used = self.memory_bytes();
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
                .map_init(Vec::new, |scratch, &(p, q)| {
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

    /// Bytes held by nodes, clusters and links (links with the slack of their vectors).
    fn memory_bytes(&self) -> u64 {
        (self.nodes.len() * (std::mem::size_of::<Node>() + 28)
            + self.clusters.len() * (std::mem::size_of::<Cluster>() + CLUSTER_SAMPLES * 48)
            + self.link_count * std::mem::size_of::<Link>() * 3 / 2) as u64
    }

    /// One refinement pass over all links with the current B; returns the links refined.
    fn refine_all(&mut self, b_ref: f64) -> Result<usize, SolveError> {
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
            self.refine(pairs, b_ref)?;
        }
        Ok(refined)
    }

    /// Pushes irradiance down and pulls radiosity (and power bins) up from node `n`;
    /// `down` is the irradiance from above as bins (clusters) or reduced to n's normal
    /// (patches, in band 0..3 of bin 0). Returns sum over the leaves below of A |dB| per
    /// band, and records each leaf's total irradiance in `arriving` when asked.
    fn push_pull(
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
                    sum[k] += cn.area * cb[k];
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
                            power[band][bin(k, m[k])] += cn.area * cb[band] * m[k].abs();
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
        let h: [f64; 3] = std::array::from_fn(|k| h_down[k] + node.gathered[k]);
        let old = self.b[n as usize];
        if node.child_count == 0 {
            let s = node.surface as usize;
            let new: [f64; 3] =
                std::array::from_fn(|k| self.emission[s][k] + self.rho[s][k] * h[k]);
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
            let (area, cb) = (self.nodes[child as usize].area, self.b[child as usize]);
            for k in 0..3 {
                change[k] += ch[k];
                sum[k] += area * cb[k];
            }
            let (lo, hi) = self.b_span[child as usize];
            span = (span.0.min(lo), span.1.max(hi));
        }
        let area = self.nodes[n as usize].area;
        self.b[n as usize] = sum.map(|s| s / area);
        self.b_span[n as usize] = span;
        change
    }

    /// Roots are made first, surface by surface, before any cluster or child.
    fn is_root(&self, n: u32) -> bool {
        (n as usize) < self.root_count
    }

    /// Gather / push-pull sweeps until the power that changes is below the tolerance;
    /// returns the sweeps made and the last residual (fraction of emitted power).
    fn solve(&mut self, emitted: [f64; 3]) -> Result<(usize, f64), SolveError> {
        for sweep in 1..=MAX_SWEEPS {
            let nodes = &self.nodes;
            let clusters = &self.clusters;
            let root_count = self.root_count;
            let (b, cluster_of) = (&self.b, &self.cluster_of);
            let gathered: Vec<[f64; 3]> = nodes
                .par_iter()
                .map(|n| {
                    let mut g = [0.0; 3];
                    if n.is_cluster() {
                        return g;
                    }
                    for l in &n.links {
                        let c = cluster_of[l.source as usize];
                        let x = if c != NONE {
                            let d = DVec3::new(l.dir[0] as f64, l.dir[1] as f64, l.dir[2] as f64);
                            cluster_emission(&clusters[c as usize].power, d)
                        } else {
                            b[l.source as usize]
                        };
                        for k in 0..3 {
                            g[k] += l.g as f64 * x[k];
                        }
                    }
                    g
                })
                .collect();
            let incident: Vec<[[f64; 6]; 3]> = clusters
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
                .collect();
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
            if residual <= self.settings.tolerance {
                return Ok((sweep, residual));
            }
        }
        Err(SolveError::BadSettings(format!(
            "hierarchical radiosity did not converge in {MAX_SWEEPS} sweeps"
        )))
    }

    fn leaves_of(&self, n: u32, out: &mut Vec<u32>) {
        let node = &self.nodes[n as usize];
        if node.child_count == 0 {
            out.push(n);
        } else {
            for &k in node.children() {
                self.leaves_of(k, out);
            }
        }
    }
}

/// Solves `scene` by hierarchical radiosity with clustering and BF refinement (see the
/// module documentation): `occluders` is the scene's occluder BVH
/// ([`crate::form_factor::occluder_bvh`]).
pub fn solve_hierarchical(
    scene: &Scene,
    occluders: &PolygonBvh,
    settings: &HierarchicalSettings,
    progress: &dyn Progress,
) -> Result<HierarchicalSolution, SolveError> {
    let HierarchicalSettings {
        epsilon,
        min_area,
        tolerance,
        ..
    } = *settings;
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
    if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
        return Err(SolveError::BadSettings(format!(
            "the tolerance must be a number in (0, 1), got {tolerance}"
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
    if scene.surfaces.is_empty() {
        return Err(SolveError::BadSettings("the scene has no surfaces".into()));
    }
    let start = Instant::now();
    let mut solver = Solver {
        nodes: Vec::new(),
        b: Vec::new(),
        b_span: Vec::new(),
        cluster_of: Vec::new(),
        clusters: Vec::new(),
        roots: Vec::new(),
        top: NONE,
        root_count: 0,
        normal: Vec::new(),
        rho: Vec::new(),
        emission: Vec::new(),
        occluders,
        settings: *settings,
        rays: 0,
        link_count: 0,
        memory_limit: settings
            .max_memory_bytes
            .unwrap_or_else(|| crate::form_factor::available_memory_bytes() / 10 * 8),
    };
    progress.message(&format!(
        "hierarchical radiosity: memory grows with the refinement, about {} bytes per node \
         and {} per link; refinement stops with an error past {} MiB",
        std::mem::size_of::<Node>() + 28,
        std::mem::size_of::<Link>() * 3 / 2,
        solver.memory_limit >> 20
    ));
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
        // The mesh's grid of each root (fan triangles share the polygon's m).
        let grid = crate::mesh::grid_of(v, scene.settings.max_patch_area).unwrap_or([0, 0]);
        let roots = polys
            .iter()
            .map(|p| solver.new_patch(s as u32, p, grid, surface.emission.0))
            .collect();
        solver.roots.push(roots);
    }
    solver.root_count = solver.nodes.len();
    let mut all_roots: Vec<u32> = (0..solver.nodes.len() as u32).collect();
    solver.top = solver.build_clusters(&mut all_roots);
    let total_area: f64 = scene
        .surfaces
        .iter()
        .map(|s| geometry::polygon_area(&s.vertices))
        .sum();
    let mean_rho = scene
        .surfaces
        .iter()
        .map(|s| geometry::polygon_area(&s.vertices) * s.reflectance.max_band())
        .sum::<f64>()
        / total_area;
    let emitted: [f64; 3] = std::array::from_fn(|k| {
        scene
            .surfaces
            .iter()
            .map(|s| geometry::polygon_area(&s.vertices) * s.emission.0[k])
            .sum()
    });

    let (rounds, iterations, initial_links, residual) =
        run_stage(progress, Stage::Solve, 0, || -> Result<_, SolveError> {
            // Power bins and mean B from the emission.
            solver.push_pull(solver.top, &[[0.0; 6]; 3], &mut None);
            // Before any solve the mean radiosity is only the emitters'; the oracle uses
            // what it will be, estimated by the ambient term of Cohen et al. (1988): the
            // mean emission over 1 - the mean reflectance (area weighted, largest band).
            let b_ref = max3(solver.b[solver.top as usize]) / (1.0 - mean_rho).max(1e-3);
            let top = solver.top;
            solver.refine(vec![(top, top)], b_ref)?;
            let initial_links = solver.nodes.iter().map(|n| n.links.len()).sum();
            let (mut iterations, mut rounds, mut residual) = (0, 0, 0.0);
            if max3(emitted) == 0.0 {
                return Ok((rounds, iterations, initial_links, residual));
            }
            loop {
                rounds += 1;
                let (sweeps, r) = solver.solve(emitted)?;
                iterations += sweeps;
                residual = r;
                let b_ref = max3(solver.b[solver.top as usize]);
                let refined = solver.refine_all(b_ref)?;
                progress.advance(1);
                progress.message(&format!(
                    "hierarchical round {rounds}: {} nodes, {} links, {refined} refined",
                    solver.nodes.len(),
                    solver.nodes.iter().map(|n| n.links.len()).sum::<usize>()
                ));
                // A round that refines fewer than 1 in 10,000 links changes the solution
                // by far less than the oracle's own tolerance: the last one.
                let links: usize = solver.nodes.iter().map(|n| n.links.len()).sum();
                if refined * 10_000 <= links || rounds >= MAX_ROUNDS {
                    if refined > 0 {
                        let (sweeps, r) = solver.solve(emitted)?;
                        iterations += sweeps;
                        residual = r;
                    }
                    break;
                }
            }
            Ok((rounds, iterations, initial_links, residual))
        })?;

    // Each leaf's total irradiance, for the energy account.
    let mut arriving = Vec::new();
    solver.push_pull(solver.top, &[[0.0; 6]; 3], &mut Some(&mut arriving));
    let h_of: HashMap<u32, [f64; 3]> = arriving.into_iter().collect();

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
        bands: std::array::from_fn(|k| leaf_ids.iter().map(|&l| solver.b[l as usize][k]).collect()),
    };

    // Energy account from the leaves.
    let (mut emitted_leaves, mut leaving, mut carried, mut absorbed) =
        ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
    for &l in &leaf_ids {
        let n = &solver.nodes[l as usize];
        let s = n.surface as usize;
        let h = h_of.get(&l).copied().unwrap_or([0.0; 3]);
        for k in 0..3 {
            emitted_leaves[k] += n.area * solver.emission[s][k];
            leaving[k] += n.area * solver.b[l as usize][k];
            carried[k] += n.area * h[k];
            absorbed[k] += n.area * (1.0 - solver.rho[s][k]) * h[k];
        }
    }
    let balance = EnergyBalance {
        emitted: emitted_leaves,
        absorbed,
        escaped: std::array::from_fn(|k| leaving[k] - carried[k]),
    };
    let links: usize = solver.nodes.iter().map(|n| n.links.len()).sum();
    let memory_bytes = solver.memory_bytes();
    let report = HierarchicalReport {
        leaves: leaf_ids.len(),
        nodes: solver.nodes.len(),
        clusters: solver.clusters.len(),
        links,
        initial_links,
        rounds,
        iterations,
        residual,
        rays: solver.rays,
        memory_bytes,
        balance,
        elapsed: start.elapsed(),
    };
    progress.message(&format!(
        "hierarchical radiosity: {} leaves, {} clusters, {} links ({} initial), {} rounds, {} sweeps, {} rays",
        report.leaves, report.clusters, report.links, report.initial_links, rounds, iterations, report.rays
    ));
    Ok(HierarchicalSolution {
        mesh,
        radiosity,
        report,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The six axis directions.
    const AXES: [DVec3; 6] = [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];

    #[test]
    fn bins_are_exact_for_axis_aligned_surfaces() {
        // Patches (A, B, normal) facing the six axes: the cluster's intensity towards any d
        // is the sum of the patches' A B max(0, n . d) / pi, to rounding.
        let patches: Vec<(f64, f64, DVec3)> = AXES
            .iter()
            .enumerate()
            .map(|(i, &n)| (1.0 + i as f64, 0.5 + 0.25 * i as f64, n))
            .collect();
        let mut power = [[0.0; 6]; 3];
        for &(a, b, n) in &patches {
            for band in 0..3 {
                for k in 0..3 {
                    power[band][bin(k, n[k])] += a * b * n[k].abs();
                }
            }
        }
        for d in [
            DVec3::new(1.0, 2.0, -3.0),
            DVec3::new(-0.3, 0.1, 0.9),
            DVec3::Y,
        ] {
            let d = d.normalize();
            let want: f64 = patches
                .iter()
                .map(|&(a, b, n)| a * b * n.dot(d).max(0.0))
                .sum();
            let got = cluster_emission(&power, d);
            assert!((got[0] - want).abs() < 1e-12 * want, "{got:?} vs {want}");
        }
        // Light arriving along directions d_j with irradiance I_j (on a surface facing it):
        // a surface of axis normal n receives sum I_j max(0, n . -d_j).
        let arrivals = [
            (DVec3::new(0.2, -1.0, 0.3).normalize(), 2.0),
            (DVec3::new(-1.0, 0.1, 0.0).normalize(), 0.5),
        ];
        let mut incident = [[0.0; 6]; 3];
        for &(d, i) in &arrivals {
            for k in 0..3 {
                for band in 0..3 {
                    incident[band][bin(k, -d[k])] += i * d[k].abs();
                }
            }
        }
        for n in AXES {
            let want: f64 = arrivals.iter().map(|&(d, i)| i * n.dot(-d).max(0.0)).sum();
            let got = irradiance_for(&incident, n);
            assert!((got[1] - want).abs() < 1e-12, "{n}: {got:?} vs {want}");
        }
    }
}
