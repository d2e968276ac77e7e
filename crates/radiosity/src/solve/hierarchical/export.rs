//! What a finished solve hands back: each leaf's total irradiance, the leaves as a [`Mesh`]
//! with their radiosity, and the energy account from the leaves (see the module
//! documentation of [`super`], "Energy account").

use std::collections::HashMap;

use super::solver::Solver;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solve::{EnergyBalance, Radiosity};

/// Each leaf's total irradiance (from its own links and its ancestors'), by one more
/// push-pull pass that records it.
pub(super) fn arriving_irradiance(solver: &mut Solver) -> HashMap<u32, [f64; 3]> {
    // Each leaf's total irradiance, for the energy account.
    let mut arriving = Vec::new();
    solver.push_pull(solver.top, &[[0.0; 6]; 3], &mut Some(&mut arriving));
    arriving.into_iter().collect()
}

/// The leaves of every surface's quadtree, surface by surface, as a mesh, with their
/// radiosity; and the leaves' nodes in the mesh's element order.
pub(super) fn leaves_to_mesh(solver: &Solver, scene: &Scene) -> (Mesh, Radiosity, Vec<u32>) {
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
    let radiosity = Radiosity(
        leaf_ids
            .iter()
            .map(|&l| crate::light::Rgb(solver.b[l as usize]))
            .collect(),
    );
    (mesh, radiosity, leaf_ids)
}

/// Where the emitted power went, from the leaves `leaf_ids` and their total irradiance
/// `h_of` (see the module documentation of [`super`]).
pub(super) fn energy_account(
    solver: &Solver,
    leaf_ids: &[u32],
    h_of: &HashMap<u32, [f64; 3]>,
) -> EnergyBalance {
    // Energy account from the leaves.
    let (mut emitted_leaves, mut leaving, mut carried, mut absorbed) =
        ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
    for &l in leaf_ids {
        let n = &solver.nodes[l as usize];
        let (s, e) = (n.surface as usize, solver.self_exitance(l));
        let h = h_of.get(&l).copied().unwrap_or([0.0; 3]);
        for k in 0..3 {
            // The point luminaires' first bounce counts as emitted, as in the dense
            // solvers' account (`crate::solve::energy_balance`).
            emitted_leaves[k] += n.area * e[k];
            leaving[k] += n.area * solver.b[l as usize][k];
            carried[k] += n.area * h[k];
            absorbed[k] += n.area * (1.0 - solver.rho[s][k]) * h[k];
        }
    }
    EnergyBalance {
        emitted: emitted_leaves,
        absorbed,
        escaped: std::array::from_fn(|k| leaving[k] - carried[k]),
    }
}
