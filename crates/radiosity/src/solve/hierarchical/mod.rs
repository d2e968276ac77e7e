//! Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991) with BF refinement and
//! clustering (Smits, Arvo and Greenberg 1994; Sillion 1995).
//!
//! # The hierarchy
//!
//! Every input surface is the root of a quadtree of *patches*: a quadrilateral splits into
//! four at its bilinear midpoints, a triangle into four at its edge midpoints; a polygon of
//! five or more corners is first cut into the fan of triangles from its centroid (as
//! [`crate::mesh`] does), each fan triangle a root of its own. Where a patch spans several
//! elements of the mesh [`crate::mesh`] would make at the given `MAX_PATCH_AREA`, it
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
//! each times the visible fraction of point pairs (see [`Solver::visibility`]), and each
//! link that involves a cluster times the ratio of its exchange summed over the two nodes'
//! sample points to the point model's (the `cluster_geometry` module: the point model
//! overstates clusters that meet at an angle, and a closed room of coplanar wall pieces
//! counted 7.3 % of its light twice without it). A link that
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
//! # Final gather
//!
//! With [`HierarchicalSettings::final_gather`] (the default), once the hierarchy has
//! converged (to the rounds' tolerance) every leaf's irradiance is gathered again at the
//! leaf's own resolution (see the `gather` module): each link held by an ancestor is
//! evaluated again with the leaf as
//! the receiver, descending into large near sources, with visibility sampled again from
//! the leaf where the link saw its source partly hidden; the terms are kept and iterated
//! until the changing power is below the tolerance. Leaves that span several cells of the
//! mesh are first split down to cells. It removes the blotches that coarse links pushed
//! down make (a coarse link gives every leaf under it its receiver's mean form factor).
//! Where there are more leaves than [`HierarchicalSettings::gather_points`], the gather
//! runs at the coarsest patches that keep within that many points (leaves along contacts
//! always gather their own), and each leaf takes its point's gathered irradiance plus what
//! the links of the patches between the point and the leaf bring.
//!
//! # Contacts
//!
//! Before any link is made, the quadtrees are refined along contacts as the dense
//! pipeline's mesh is ([`crate::mesh::refine_contacts`], the `contact` module): cells
//! partly buried under or inside other surfaces are split to
//! [`crate::mesh::CONTACT_DEPTH`] levels, wholly buried patches carry no light and are not
//! returned, and the pieces along the outline sample their visibility again in the gather.
//! A patch above buried pieces keeps its *open area* (its area less theirs): the light its
//! links bring is spread over that area when pushed down, and its radiosity is the mean
//! over it (its links, as sources, see only the open part), so the buried share is not
//! lost from the account (room.scene: 5.5 % of the light escaped before, 3.5 % now).
//!
//! # Accuracy
//!
//! Element by element against a dense solve on the same mesh with exact (contour) form
//! factors and 4 x 4 by 4 x 4 visibility pairs, leaves down to a quarter of an element
//! (the Cornell box; tests/hierarchical.rs, BENCHMARKS.md): at 2,046 elements 0.66 % RMS at
//! epsilon 3e-4, 1.3 % at 1e-3, 5 % at 1e-2; at 19,591 elements 0.73 % at 1e-4 and 1.2 %
//! at 3e-4 (a finer mesh has more links per element, each within the BF tolerance, so it
//! needs a smaller epsilon for the same agreement); all these without the final gather and
//! on the plain grid, before contacts were refined. At the defaults (epsilon 0.05, minimum
//! area a sixteenth of an element) the contact-refined Cornell box (2,484 elements) is
//! 1.2 % RMS from the exact dense solve on the same refined mesh, 8.6 % without the final
//! gather. The dense solve with the default area
//! k = 2 form factors is itself 1.2 % RMS from that reference on its own mesh, so it is not
//! accurate enough to judge a 1 % agreement.
//!
//! # Energy account
//!
//! emitted = sum over leaves of A E; each leaf absorbs A (1 - rho) H of the irradiance H that
//! reaches it (its own links and its ancestors', or what the final gather gathered); escaped = (power leaving all leaves, sum
//! A B) - (power arriving, sum A H). emitted = absorbed + escaped holds to the solve
//! tolerance; in a closed scene `escaped` measures how far the link estimates' sums of form
//! factors are from 1 (it can be slightly negative): -0.33 % of the emitted power in a
//! closed cube at the defaults (tests/suite/hierarchical.rs), -3.2 % without the final
//! gather (a coarse source's mean radiosity sent with its mean form factor overshoots
//! where both peak together, near corners).
#![allow(clippy::needless_range_loop)] // bands and bins read best as indices

mod bins;
mod cluster_geometry;
mod contact;
mod export;
mod gather;
mod link;
mod min_area;
mod near_pairs;
mod oracle;
mod refine;
mod solver;
mod sweep;
mod tree;
mod visibility;

use std::time::{Duration, Instant};

use glam::DVec3;

pub use min_area::check_min_area;

use super::{EnergyBalance, Radiosity, SolveError};
use crate::geometry;
use crate::mesh::Mesh;
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::Scene;
use crate::visibility::PolygonBvh;
use link::Link;
use solver::{max3, Solver};
use tree::{Node, NONE};

/// The default of [`HierarchicalSettings::tolerance`]: sweeps stop when the power still
/// changing is below this fraction of the emitted power.
pub const DEFAULT_HIERARCHICAL_TOLERANCE: f64 = 1e-6;
/// The changing power (fraction of the emitted) at which the solves between refinement
/// rounds stop: the oracle that follows tests links against epsilon = 0.05 of B, so a
/// thousandth of the power is plenty, and the sweeps to 1e-6 are made once, at the end (on
/// the million-element building: 134 sweeps over 6 solves before); with the final gather
/// its passes over the gathered terms iterate to 1e-6 instead (its first pass changes far
/// more than 1e-3 of the power anyway).
const ROUND_TOLERANCE: f64 = 1e-3;
/// The most the memo of near pairs' exact form factors holds (see the `near_pairs` module):
/// the million-element building's shapes take a few MiB.
const NEAR_PAIR_MEMO_BYTES: u64 = 256 << 20;
/// Give up refining after this many rounds (each round is a solve and a refinement pass).
const MAX_ROUNDS: usize = 64;

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
    /// Gather every leaf's irradiance again at its own resolution once the hierarchy has
    /// converged (see "Final gather" in the module documentation); without it each leaf
    /// takes the irradiance of its ancestors' links pushed down.
    pub final_gather: bool,
    /// The most points the final gather gathers at, besides the leaves along contacts
    /// (which always gather their own): where there are more leaves, it gathers at the
    /// coarsest patches that keep within this, and the leaves under each take its
    /// irradiance plus what the links below it bring ([`GATHER_POINTS_DEFAULT`] by
    /// default; the gather's time is about proportional to its points).
    pub gather_points: usize,
}

/// The default of [`HierarchicalSettings::gather_points`]. On the million-element building
/// (1.87 million leaves after the split to cells) gathering at every leaf ran past six
/// minutes of CPU; at 236,916 points it brought the pixel RMS against the path tracer from
/// 11.1 % to 7.4 % (BENCHMARKS.md). Scenes of up to this many leaves gather at every leaf.
pub const GATHER_POINTS_DEFAULT: usize = 250_000;

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
    /// Gather / push-pull sweeps made in all, the final gather's passes over its terms
    /// included.
    pub iterations: usize,
    /// Of [`HierarchicalReport::iterations`], the final gather's sweeps and passes (0
    /// without a final gather).
    pub gather_passes: usize,
    /// Power that still changed in the last sweep (or the final gather's last pass), as a
    /// fraction of the emitted power (the largest band): the analogue of the unshot
    /// fraction.
    pub residual: f64,
    /// Visibility segments tested.
    pub rays: u64,
    /// Bytes held by nodes and links at the end, or the most held with a refinement
    /// frontier if more (an estimate from their sizes, checked against the limit).
    pub memory_bytes: u64,
    /// Patches marked buried by contact refinement (whole cells and pieces; not among the
    /// leaves).
    pub buried_patches: usize,
    /// Their area (scene units squared).
    pub buried_area: f64,
    /// True when the scene had more cells than [`crate::mesh::CONTACT_MAX_ELEMENTS`] and
    /// contacts were not refined.
    pub contacts_skipped: bool,
    /// Where the emitted power went (see the module documentation).
    pub balance: EnergyBalance,
    /// Points the final gather gathered at (0 without it): the leaves, or coarser patches
    /// where the leaves were more than [`HierarchicalSettings::gather_points`].
    pub gather_points: usize,
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

/// Solves `scene` by hierarchical radiosity with clustering and BF refinement (see the
/// module documentation): patches split along the lines that [`crate::mesh::mesh_scene`]
/// cuts at `max_patch_area`, so that the leaves nest with that mesh's elements;
/// `occluders` is the scene's occluder BVH ([`crate::form_factor::occluder_bvh`]).
pub fn solve_hierarchical(
    scene: &Scene,
    max_patch_area: f64,
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
        return Err(SolveError::BadSettings {
            setting: "epsilon",
            expected: "a positive number",
            value: epsilon,
        });
    }
    if !(min_area.is_finite() && min_area > 0.0) {
        return Err(SolveError::BadSettings {
            setting: "the minimum element area",
            expected: "a positive number",
            value: min_area,
        });
    }
    if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
        return Err(SolveError::BadSettings {
            setting: "the tolerance",
            expected: "a number in (0, 1)",
            value: tolerance,
        });
    }
    // Before any node is made (QA pass 16 of #16: a minimum area of 1e-9 refined for
    // minutes); the command line checks it sooner, before the scene's other work.
    check_min_area(scene, max_patch_area, min_area)?;
    for (s, surface) in scene.surfaces.iter().enumerate() {
        crate::light::check_surface(s, surface.reflectance, surface.emission)
            .map_err(crate::light::LightError::from)?;
    }
    if scene.surfaces.is_empty() {
        return Err(SolveError::NoSurfaces);
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
        lights: &scene.lights,
        direct: Vec::new(),
        occluders,
        settings: *settings,
        rays: 0,
        link_count: 0,
        memory_limit: settings
            .max_memory_bytes
            .unwrap_or_else(|| crate::form_factor::available_memory_bytes() / 10 * 8),
        peak_memory: 0,
        gathered_at: 0,
        near_pairs: near_pairs::NearPairMemo::new(0),
    };
    solver.near_pairs =
        near_pairs::NearPairMemo::new(NEAR_PAIR_MEMO_BYTES.min(solver.memory_limit / 8));
    progress.message(&format!(
        "hierarchical radiosity: memory grows with the refinement, about {} bytes per node \
         and {} per link; refinement stops with an error past {} MiB",
        std::mem::size_of::<Node>() + 44,
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
        let grid = crate::mesh::grid_of(v, max_patch_area).unwrap_or([0, 0]);
        let roots = polys
            .iter()
            .map(|p| solver.new_patch(s as u32, p, grid, surface.emission.0))
            .collect();
        solver.roots.push(roots);
    }
    solver.root_count = solver.nodes.len();
    let mut all_roots: Vec<u32> = (0..solver.nodes.len() as u32).collect();
    solver.top = solver.build_clusters(&mut all_roots);
    // Leaves along contacts split as the dense pipeline's mesh, buried pieces marked.
    let contacts = solver.refine_contacts(scene, max_patch_area);
    solver.set_open_areas();
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
    // The surfaces' emission and the point luminaires' first bounce (on the roots).
    let emitted: [f64; 3] = std::array::from_fn(|k| {
        scene
            .surfaces
            .iter()
            .map(|s| geometry::polygon_area(&s.vertices) * s.emission.0[k])
            .sum::<f64>()
            + (0..solver.root_count)
                .filter_map(|r| Some(solver.nodes[r].area * solver.direct.get(r)?[k]))
                .sum::<f64>()
    });

    let (rounds, iterations, initial_links, residual, lit) =
        run_stage(progress, Stage::Solve, 0, || -> Result<_, SolveError> {
            // Power bins and mean B from the emission.
            solver.push_pull(solver.top, &[[0.0; 6]; 3], &mut None);
            // Before any solve the mean radiosity is only the emitters'; the oracle uses
            // what it will be, estimated by the ambient term of Cohen et al. (1988): the
            // mean emission over 1 - the mean reflectance (area weighted, largest band).
            let b_ref = max3(solver.b[solver.top as usize]) / (1.0 - mean_rho).max(1e-3);
            let top = solver.top;
            solver.refine(vec![(top, top)], b_ref, progress)?;
            let initial_links = solver.nodes.iter().map(|n| n.links.len()).sum();
            let (mut iterations, mut rounds, mut residual) = (0, 0, 0.0);
            if max3(emitted) == 0.0 {
                return Ok((rounds, iterations, initial_links, residual, false));
            }
            // The rounds before the last only feed the oracle, which compares B to 5 % or
            // so: they solve to ROUND_TOLERANCE, the last to the settings' tolerance.
            let round_tolerance = ROUND_TOLERANCE.max(settings.tolerance);
            loop {
                rounds += 1;
                let (sweeps, r) = solver.solve(emitted, round_tolerance)?;
                iterations += sweeps;
                residual = r;
                let b_ref = max3(solver.b[solver.top as usize]);
                let refined = solver.refine_all(b_ref, progress)?;
                progress.advance(1);
                progress.message(&format!(
                    "hierarchical round {rounds}: {} nodes, {} links, {refined} refined",
                    solver.nodes.len(),
                    solver.nodes.iter().map(|n| n.links.len()).sum::<usize>()
                ));
                // A round that refines fewer than 1 in 10,000 links changes the solution
                // by far less than the oracle's own tolerance: the last one.
                let links: usize = solver.nodes.iter().map(|n| n.links.len()).sum();
                // What the progress lines say of how far it is from its end (QA of issue
                // #16: the heartbeat only counted rounds).
                progress.status(&format!(
                    "round {rounds} refined {refined} of {links} links (the rounds end when \
                     one refines at most 1 in 10,000, or after {MAX_ROUNDS})"
                ));
                if refined * 10_000 <= links || rounds >= MAX_ROUNDS {
                    // The final gather iterates to the tolerance itself (see
                    // `Solver::final_gather`).
                    let last = if settings.final_gather {
                        round_tolerance
                    } else {
                        settings.tolerance
                    };
                    if refined > 0 || residual > last {
                        let (sweeps, r) = solver.solve(emitted, last)?;
                        iterations += sweeps;
                        residual = r;
                    }
                    break;
                }
            }
            Ok((rounds, iterations, initial_links, residual, true))
        })?;
    // The final gather, at each leaf's own resolution: a stage of its own, with the gather
    // points as its progress (QA of issue #16: on large scenes it ran for a minute inside
    // the solve stage, whose lines counted refinement rounds that no longer changed).
    let (mut iterations, mut residual) = (iterations, residual);
    // The sweeps of the refinement rounds, reported apart from the gather's passes (QA of
    // issue #16: "sweeps" counted both).
    let (round_sweeps, mut gather_passes) = (iterations, 0);
    let gathered = if settings.final_gather && lit {
        let g = solver.final_gather(emitted, progress)?;
        gather_passes = g.sweeps + g.passes;
        iterations += gather_passes;
        residual = g.residual;
        Some(g.h_of)
    } else {
        None
    };

    // Each leaf's total irradiance, for the energy account (gathered again at each leaf, or
    // pushed down); the leaves as a mesh; where the emitted power went.
    let h_of = match gathered {
        Some(h_of) => h_of,
        None => {
            let mut h_of = export::arriving_irradiance(&mut solver);
            solver.gather_contacts(&mut h_of);
            h_of
        }
    };
    let (mesh, radiosity, leaf_ids) = export::leaves_to_mesh(&solver, scene);
    let balance = export::energy_account(&solver, &leaf_ids, &h_of);
    let links: usize = solver.nodes.iter().map(|n| n.links.len()).sum();
    let memory_bytes = solver.memory_bytes().max(solver.peak_memory);
    let report = HierarchicalReport {
        leaves: leaf_ids.len(),
        nodes: solver.nodes.len(),
        clusters: solver.clusters.len(),
        links,
        initial_links,
        rounds,
        iterations,
        gather_passes,
        residual,
        rays: solver.rays,
        memory_bytes,
        buried_patches: contacts.buried,
        buried_area: contacts.buried_area,
        contacts_skipped: contacts.skipped,
        balance,
        gather_points: solver.gathered_at,
        elapsed: start.elapsed(),
    };
    let passes = match gather_passes {
        1 => String::from(" (1 pass)"),
        n => format!(" ({n} passes)"),
    };
    let gather = match report.gather_points {
        0 => String::from("no final gather"),
        p if p == report.leaves => format!("final gather at every leaf{passes}"),
        p => format!("final gather at {p} points (patches of several leaves){passes}"),
    };
    let (shapes_computed, shapes_reused) = solver.near_pairs.counts();
    progress.message(&format!(
        "hierarchical radiosity: {} leaves (the elements of its solution: patches of at most MAX_PATCH_AREA, subdivided where the light varies), {} clusters, {} links ({} initial), {} rounds, {} sweeps, {} rays, {gather}; \
         exact near-pair form factors: {shapes_computed} pair shapes computed, {shapes_reused} pairs of the same shapes reused",
        report.leaves, report.clusters, report.links, report.initial_links, rounds, round_sweeps, report.rays
    ));
    Ok(HierarchicalSolution {
        mesh,
        radiosity,
        report,
    })
}
