//! The holes that dropped buried pieces leave, covered for a rasteriser.
//!
//! The CPU renderer finds a hole by casting each camera ray against the scene's surfaces as
//! well as the elements ([`super::holes`]). A rasteriser (the walkthrough window) draws only
//! triangles, so there a hole showed whatever lay behind the surface: a black line along
//! the foot of a sofa's back, black dots round the feet of furniture, a dark strip past a
//! light panel hanging below the ceiling. [`HoleCover`] gives it triangles to draw a little
//! behind the elements: every surface whose elements cover less than its area is cut again
//! into cells about its elements' size ([`crate::mesh::mesh_scene`] of that surface alone),
//! and each cell corner x carries what the CPU renderer shows at x: the radiosity of the
//! surface's nearest element at the point of it nearest to x, times the share of x's
//! hemisphere that is open. Under the depth test the cells show only where no element
//! covers the surface; inside a hole the light runs linearly between the cell corners,
//! where the CPU renderer evaluates it at every pixel.

use glam::DVec3;
use rayon::prelude::*;

use super::holes::{nearest_element, Holes};
use super::interpolation;
use crate::geometry;
use crate::mesh::{mesh_scene, Mesh};
use crate::scene::Scene;

/// A surface counts as holed where its elements cover less than this share of its area
/// (far above the rounding of the elements' areas, far below any piece contact refinement
/// drops: 1/64 of an element).
const COVERED: f64 = 1.0 - 1e-6;

/// Triangles that cover the holes in a mesh's surfaces (module documentation).
#[derive(Clone, Debug, Default)]
pub struct HoleCover {
    /// Corner positions, three per triangle, counter-clockwise from the surface's front.
    pub corners: Vec<DVec3>,
    /// The surface of each triangle.
    pub surfaces: Vec<u32>,
    /// Per corner: the element whose light it shows, the point of that element nearest to
    /// the corner, and the corner's open share.
    sources: Vec<Source>,
}

#[derive(Clone, Copy, Debug)]
struct Source {
    element: usize,
    at: DVec3,
    open: f64,
}

impl HoleCover {
    /// The cover of the holes of `mesh`, cut from `scene`: empty where every surface is
    /// covered by its elements.
    pub fn new(scene: &Scene, mesh: &Mesh) -> HoleCover {
        let mut covered = vec![(0.0, 0usize); scene.surfaces.len()];
        for el in &mesh.elements {
            if let Some(c) = covered.get_mut(el.surface as usize) {
                c.0 += el.area;
                c.1 += 1;
            }
        }
        let holed: Vec<usize> = (0..scene.surfaces.len())
            .filter(|&s| {
                let (area, count) = covered[s];
                count > 0 && area < COVERED * geometry::polygon_area(&scene.surfaces[s].vertices)
            })
            .collect();
        if holed.is_empty() {
            return HoleCover::default();
        }
        let holes = Holes::new(scene);
        let parts: Vec<(Vec<DVec3>, Vec<u32>, Vec<Source>)> = holed
            .par_iter()
            .map(|&s| {
                let (area, count) = covered[s];
                // Cells about the size of the surface's elements.
                let alone = Scene {
                    surfaces: vec![scene.surfaces[s].clone()],
                    camera: None,
                    lights: Vec::new(),
                };
                let Ok(cells) = mesh_scene(&alone, area / count as f64) else {
                    return (Vec::new(), Vec::new(), Vec::new());
                };
                let mut corners = Vec::new();
                for e in 0..cells.len() {
                    let c: Vec<DVec3> = cells.corner_positions(e).collect();
                    corners.extend([c[0], c[1], c[2]]);
                    if c.len() == 4 {
                        corners.extend([c[0], c[2], c[3]]);
                    }
                }
                let mut sources = Vec::with_capacity(corners.len());
                for &x in &corners {
                    let Some((element, at)) = nearest_element(mesh, s as u32, x) else {
                        return (Vec::new(), Vec::new(), Vec::new());
                    };
                    let open = holes.open_share(s as u32, x);
                    sources.push(Source { element, at, open });
                }
                let surfaces = vec![s as u32; corners.len() / 3];
                (corners, surfaces, sources)
            })
            .collect();
        let mut cover = HoleCover::default();
        for (corners, surfaces, sources) in parts {
            cover.corners.extend(corners);
            cover.surfaces.extend(surfaces);
            cover.sources.extend(sources);
        }
        cover
    }

    /// The number of triangles.
    pub fn len(&self) -> usize {
        self.surfaces.len()
    }

    /// True when nothing needs covering.
    pub fn is_empty(&self) -> bool {
        self.surfaces.is_empty()
    }

    /// Per corner, (smooth, flat): the radiosity the CPU renderer shows there with smooth
    /// shading (interpolated from `vertex_b`, per vertex of `mesh`; the element's radiosity
    /// where `vertex_b` is empty) and with flat shading (`element_b`, per element), both
    /// times the corner's open share.
    pub fn radiosity(
        &self,
        mesh: &Mesh,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
    ) -> Vec<([f64; 3], [f64; 3])> {
        self.sources
            .iter()
            .map(|s| {
                let flat = element_b.get(s.element).copied().unwrap_or([0.0; 3]);
                let smooth = if vertex_b.is_empty() {
                    flat
                } else {
                    interpolation(mesh, s.element, s.at).of(vertex_b)
                };
                (smooth.map(|b| b * s.open), flat.map(|b| b * s.open))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::refine_contacts;
    use crate::render::test_support::{facing_up, scene, surface};
    use crate::visibility::PolygonBvh;

    #[test]
    fn a_floor_under_a_lid_is_covered_where_its_pieces_were_dropped() {
        // A 4 x 4 floor with a 2 x 2 lid 1 mm above its middle, facing up: contact
        // refinement drops the floor's pieces under the lid. The cover is the floor cut
        // into cells, its corners in the open showing the floor's light whole and those
        // deep under the lid none of it.
        let s = scene(vec![
            surface("floor", 0.0, facing_up(0.0, 4.0, 0.0, 4.0, 0.0)),
            surface("lid", 0.0, facing_up(1.0, 3.0, 1.0, 3.0, 0.001)),
        ]);
        let grid = mesh_scene(&s, 0.25).unwrap();
        let bvh = PolygonBvh::over_surfaces(&s);
        let (mesh, report) = refine_contacts(&grid, &s, &bvh);
        assert!(report.dropped > 0, "{report:?}");
        let cover = HoleCover::new(&s, &mesh);
        assert!(!cover.is_empty());
        assert!(
            cover.surfaces.iter().all(|&s| s == 0),
            "only the floor has holes"
        );
        // The cells tile the floor: their area is the floor's.
        let area: f64 = cover
            .corners
            .chunks(3)
            .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
            .sum();
        assert!((area - 16.0).abs() < 1e-9, "cells' area {area}");
        let b = vec![[1.0; 3]; mesh.len()];
        let light = cover.radiosity(&mesh, &b, &[]);
        for (x, (smooth, flat)) in cover.corners.iter().zip(&light) {
            assert_eq!(smooth, flat, "no vertex radiosity: both the element's");
            // How far from the floor's centre, along the farther axis: the lid covers 1.
            let from_centre = (x.x - 2.0).abs().max((x.z - 2.0).abs());
            if from_centre <= 0.5 {
                // Half a metre or more under a lid 1 mm up: the most grazing of the open
                // share's directions (83 degrees from the normal) meets the lid's back.
                assert_eq!(flat[0], 0.0, "corner {x} under the lid shows {flat:?}");
            } else if from_centre >= 1.5 {
                // Half a metre past the lid's edge: no direction meets it.
                assert_eq!(flat[0], 1.0, "corner {x} in the open shows {flat:?}");
            }
        }
    }

    #[test]
    fn a_mesh_without_holes_needs_no_cover() {
        let s = scene(vec![surface(
            "floor",
            0.0,
            facing_up(0.0, 4.0, 0.0, 4.0, 0.0),
        )]);
        let mesh = mesh_scene(&s, 0.25).unwrap();
        assert!(HoleCover::new(&s, &mesh).is_empty());
    }
}
