//! The solver's state: the nodes (quadtree patches and clusters) with the links they hold,
//! every node's radiosity, the input surfaces' normals, reflectances and emissions, the
//! counts a report gives, and the memory all of it holds. Its methods live beside the steps
//! they make (tree, link, oracle, visibility, refine, sweep).

use glam::DVec3;

use super::link::Link;
use super::near_pairs::{self, NearPairMemo};
use super::tree::{Cluster, ClusterSample, Node, CLUSTER_SAMPLES};
use super::HierarchicalSettings;
use crate::luminaire::Luminaire;
use crate::visibility::PolygonBvh;

/// The largest of three bands.
pub(super) fn max3(v: [f64; 3]) -> f64 {
    v[0].max(v[1]).max(v[2])
}

/// Everything a hierarchical solve holds.
pub(super) struct Solver<'a> {
    pub(super) nodes: Vec<Node>,
    /// Area-averaged radiosity of every node (apart from the nodes: the sweeps read it at
    /// random).
    pub(super) b: Vec<[f64; 3]>,
    /// Smallest and largest radiosity (largest band) of the leaves under every patch.
    pub(super) b_span: Vec<(f64, f64)>,
    /// Cluster index of every node, NONE for patches.
    pub(super) cluster_of: Vec<u32>,
    pub(super) clusters: Vec<Cluster>,
    /// Quadtree roots of each input surface.
    pub(super) roots: Vec<Vec<u32>>,
    pub(super) top: u32,
    /// Nodes 0..root_count are the roots; cluster c is node root_count + c.
    pub(super) root_count: usize,
    pub(super) normal: Vec<DVec3>,
    pub(super) rho: Vec<[f64; 3]>,
    pub(super) emission: Vec<[f64; 3]>,
    /// The scene's point luminaires.
    pub(super) lights: &'a [Luminaire],
    /// Per node, the light of the point luminaires it reflects at first bounce: rho times
    /// its mean direct illuminance (see [`Solver::point_light_bounce`]); zero for clusters.
    /// Empty when the scene has no point luminaire.
    pub(super) direct: Vec<[f64; 3]>,
    pub(super) occluders: &'a PolygonBvh,
    pub(super) settings: HierarchicalSettings,
    pub(super) rays: u64,
    /// Links held by all nodes.
    pub(super) link_count: usize,
    /// Refinement stops with an error when [`Solver::memory_bytes`] passes this.
    pub(super) memory_limit: u64,
    /// The most [`Solver::memory_bytes`] plus a refinement frontier reached.
    pub(super) peak_memory: u64,
    /// Points the final gather gathered at (0 before it or without it).
    pub(super) gathered_at: usize,
    /// Exact form factors of near patch pairs by shape (see [`NearPairMemo`]).
    pub(super) near_pairs: NearPairMemo,
}

/// Bytes each pair of a refinement frontier takes while it is estimated: the pair in the
/// frontier and in the expanded list, up to four in the next frontier (a patch splits in
/// four), and its estimate. A frontier
/// is transient but can dwarf what is held: the 5,000 coplanar fan triangles of a convex
/// 5,000-gon expand into millions of too-close cluster pairs (612 MB measured where the
/// held nodes and links took 10 MiB).
pub(super) const FRONTIER_PAIR_BYTES: u64 =
    (6 * std::mem::size_of::<(u32, u32)>() + std::mem::size_of::<super::link::Estimate>()) as u64;

/// Bytes per node held beside the node itself: its B ([f64; 3]), its span of leaf B
/// ((f64, f64)) and its cluster index (u32).
const PER_NODE_BYTES: usize = 24 + 16 + 4;

impl Solver<'_> {
    /// What leaf or patch `n` sends of itself, before what it reflects of the scene's
    /// light: its surface's emission plus the point luminaires' first bounce.
    pub(super) fn self_exitance(&self, n: u32) -> [f64; 3] {
        let e = self.emission[self.nodes[n as usize].surface as usize];
        match self.direct.get(n as usize) {
            Some(d) => std::array::from_fn(|k| e[k] + d[k]),
            None => e,
        }
    }

    /// Bytes held by nodes, clusters and links (links with the slack of their vectors).
    /// The refinement adds its frontier's [`FRONTIER_PAIR_BYTES`] per pair while it runs.
    pub(super) fn memory_bytes(&self) -> u64 {
        (self.nodes.len() * (std::mem::size_of::<Node>() + PER_NODE_BYTES)
            + self.direct.len() * 24
            + self.clusters.len()
                * (std::mem::size_of::<Cluster>()
                    + CLUSTER_SAMPLES * std::mem::size_of::<ClusterSample>())
            + self.link_count * std::mem::size_of::<Link>() * 3 / 2) as u64
            + self.near_pairs.len() as u64 * near_pairs::ENTRY_BYTES
    }
}
