//! Contact refinement of the quadtrees: the hierarchy's leaves follow the outlines of the
//! objects standing on a surface as the dense pipeline's mesh does
//! ([`crate::mesh::refine_contacts`], with the same probe, [`crate::mesh::Probe`]).
//!
//! Before any link is made, every patch that spans several cells of the scene's mesh and
//! has another surface nearby in front of it is split (along the mesh's grid lines, as
//! [`Solver::split_patch`] does), down to single cells; a cell with cover nearby is judged
//! at its 4 x 4 probe points: open, it stays; wholly buried, it is marked *buried*; partly
//! buried, it is split in four, and its children judged again, down to
//! [`CONTACT_DEPTH`] levels below the cell (pieces 1/8 of a cell across), where a piece
//! still partly buried is kept. The pieces are those of the dense pipeline's refined mesh,
//! so the two solutions can be compared element by element along the contacts.
//!
//! A buried patch carries no light: it holds and is the source of no link, its radiosity is
//! zero, it absorbs nothing in the energy account and it is not among the leaves returned.
//! Its ancestors keep their *open area* (area less the buried pieces', `set_open_areas`):
//! the light their links bring is spread over it, and their radiosity is the mean over it.

use rayon::prelude::*;

use super::solver::Solver;
use crate::mesh::{Cover, Probe, CONTACT_DEPTH, CONTACT_MAX_ELEMENTS};
use crate::scene::Scene;

/// What the contact refinement of the quadtrees did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct ContactCount {
    /// Patches marked buried (whole cells and pieces).
    pub(super) buried: usize,
    /// Their area (scene units squared).
    pub(super) buried_area: f64,
    /// True when the scene has more cells than [`CONTACT_MAX_ELEMENTS`] and was left as it
    /// is (as the dense pipeline leaves such a mesh).
    pub(super) skipped: bool,
}

/// What to do with one patch.
enum Verdict {
    /// Nothing: open, or no cover nearby, or partly buried at the deepest level.
    Keep,
    /// Wholly buried.
    Bury,
    /// Split it; its children are at the given level below a cell (0: still cells or
    /// unions of cells).
    Split(u32),
}

impl Solver<'_> {
    /// True when patch `n` spans more than one cell of the scene's mesh: a union of cells
    /// on the grid, or a patch off the lattice (a triangle of odd m) larger than a cell.
    fn spans_cells(&self, n: u32, cell_area: f64) -> bool {
        let node = &self.nodes[n as usize];
        let [cu, cv] = node.grid;
        let on_grid = if node.count == 4 {
            cu * cv > 1
        } else {
            cu >= 2
        };
        on_grid || (node.grid == [0, 0] && node.area > cell_area * (1.0 + 1e-9))
    }

    /// Sets every patch's `open_area`: its area less that of its buried descendants, from
    /// the leaves up (roots are the first `root_count` nodes; clusters are left as they are).
    pub(super) fn set_open_areas(&mut self) {
        fn open(nodes: &mut [super::tree::Node], n: usize) -> f64 {
            let (count, children) = (nodes[n].child_count as usize, nodes[n].children);
            let a = if nodes[n].buried {
                0.0
            } else if count == 0 {
                nodes[n].area
            } else {
                (0..count).map(|c| open(nodes, children[c] as usize)).sum()
            };
            nodes[n].open_area = a;
            a
        }
        for r in 0..self.root_count {
            open(&mut self.nodes, r);
        }
    }

    /// Splits the patches along the contacts and marks the buried ones (see the module
    /// documentation); `max_patch_area` is the scene's MAX_PATCH_AREA, the largest cell.
    pub(super) fn refine_contacts(&mut self, scene: &Scene, max_patch_area: f64) -> ContactCount {
        let mut count = ContactCount::default();
        let cells: u64 = scene
            .surfaces
            .iter()
            .map(|s| {
                let fans = if s.vertices.len() <= 4 {
                    1
                } else {
                    s.vertices.len() as u64
                };
                match crate::mesh::grid_of(&s.vertices, max_patch_area) {
                    Some([m, 0]) => fans * m as u64 * m as u64,
                    Some([nu, nv]) => nu as u64 * nv as u64,
                    None => 1,
                }
            })
            .sum();
        if cells > CONTACT_MAX_ELEMENTS as u64 {
            count.skipped = true;
            return count;
        }
        let probe = Probe::new(scene, self.occluders);
        // (patch, its level below a cell), level by level.
        let mut frontier: Vec<(u32, u32)> = (0..self.root_count as u32).map(|r| (r, 0)).collect();
        while !frontier.is_empty() {
            let this = &*self;
            let verdicts: Vec<Verdict> = frontier
                .par_iter()
                .map(|&(n, level)| {
                    let node = &this.nodes[n as usize];
                    let normal = this.normal[node.surface as usize];
                    let corners = node.polygon();
                    if level == 0 && !probe.has_cover_nearby(node.surface, corners, normal) {
                        return Verdict::Keep;
                    }
                    if level == 0 && this.spans_cells(n, max_patch_area) {
                        return Verdict::Split(0);
                    }
                    match probe.cover(node.surface, corners, normal) {
                        // Its patches cannot be cut along an outline: a rim between the
                        // samples of a buried patch is refined as a straddling one, and
                        // kept at the last level where some part of it is open (a seam
                        // between two boxes standing side by side crosses a patch wholly
                        // under them: buried); an open patch crossed by one is kept as its
                        // samples judge it.
                        // (`Shade` only where near faces are followed: not here.)
                        Cover::Open | Cover::Crossed { buried: false } | Cover::Shade => {
                            Verdict::Keep
                        }
                        Cover::Buried => Verdict::Bury,
                        Cover::Partly if level >= CONTACT_DEPTH => Verdict::Keep,
                        Cover::Crossed { buried: true } if level >= CONTACT_DEPTH => {
                            if probe.has_open_part(node.surface, corners, normal) {
                                Verdict::Keep
                            } else {
                                Verdict::Bury
                            }
                        }
                        Cover::Partly | Cover::Crossed { buried: true } => {
                            Verdict::Split(level + 1)
                        }
                    }
                })
                .collect();
            let mut next = Vec::new();
            for (&(n, _), verdict) in frontier.iter().zip(verdicts) {
                match verdict {
                    Verdict::Keep => {}
                    Verdict::Bury => {
                        let node = &mut self.nodes[n as usize];
                        node.buried = true;
                        count.buried += 1;
                        count.buried_area += node.area;
                    }
                    Verdict::Split(level) => {
                        if level > 0 {
                            self.nodes[n as usize].straddles = true;
                        }
                        next.extend(self.split_patch(n).into_iter().map(|c| (c, level)));
                    }
                }
            }
            frontier = next;
        }
        count
    }
}
