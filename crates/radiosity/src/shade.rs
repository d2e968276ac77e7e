//! Vertex radiosities for smooth shading (paper section 2.5).
//!
//! [`vertex_radiosity`] gives each mesh vertex the area-weighted mean radiosity of the
//! elements that have it as a corner. The paper averages the (up to four) coplanar
//! neighbours of a quadrilateral patch's corner; this is the same rule for any conforming
//! mesh of triangles and quadrilaterals. On a mesh with T-junctions (quadtree refinement) a
//! vertex that lies inside another element's edge (a T-vertex) counts that element as one of
//! its own: the averaging runs over display polygons ([`crate::mesh::DisplayPolygons`]), so
//! the value at a T-vertex is the one every element touching it interpolates, and smooth
//! shading is continuous across the edge. Vertices belong to one surface each (see
//! [`crate::mesh`]), so the averaging never crosses a surface boundary and smooth shading
//! has no seams inside a surface.
//!
//! Exposure, gamma and 8-bit encoding live in [`crate::render::tonemap`]; they are
//! re-exported here under their old paths.

use crate::mesh::Mesh;

pub use crate::render::tonemap::{encode, expose, tone_map, Exposure, GammaEncoder};

/// The radiosity at every vertex of `mesh`: the area-weighted mean of `element_b` over the
/// elements that touch the vertex, as a corner or with the vertex inside one of their edges
/// (a T-vertex: it is a corner of their display polygons, [`Mesh::display`]) (paper 2.5's
/// neighbour averaging, generalised).
///
/// Element areas are the weights, so on a regular grid an interior vertex gets the plain
/// mean of its four elements, and a field linear in position is reproduced exactly there.
/// A vertex on a surface's boundary gets the mean of the elements that touch it (one at a
/// corner of a quadrilateral surface, two along an edge). A vertex no element uses (there
/// are none in a mesh from [`crate::mesh::mesh_scene`]) gets zero.
///
/// # Panics
/// If `element_b` does not have one entry per element of `mesh`.
pub fn vertex_radiosity(mesh: &Mesh, element_b: &[[f64; 3]]) -> Vec<[f64; 3]> {
    assert_eq!(
        element_b.len(),
        mesh.len(),
        "one radiosity per element expected"
    );
    let mut sum = vec![[0.0f64; 3]; mesh.vertices.len()];
    let mut weight = vec![0.0f64; mesh.vertices.len()];
    let display = mesh.display();
    for (e, (el, b)) in mesh.elements.iter().zip(element_b).enumerate() {
        for &v in display.polygon(e) {
            let v = v as usize;
            weight[v] += el.area;
            for k in 0..3 {
                sum[v][k] += el.area * b[k];
            }
        }
    }
    sum.iter()
        .zip(&weight)
        .map(|(s, &w)| {
            if w > 0.0 {
                [s[0] / w, s[1] / w, s[2] / w]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::scene::{Rgb, Scene, Surface};
    use glam::{dvec3, DVec3};

    fn surface(name: &str, emission: f64, vertices: Vec<DVec3>) -> Surface {
        Surface {
            name: name.into(),
            emission: Rgb([emission; 3]),
            reflectance: Rgb([0.5; 3]),
            vertices,
        }
    }

    fn scene(surfaces: Vec<Surface>) -> Scene {
        Scene {
            surfaces,
            camera: None,
        }
    }

    /// The square [0, 4] x [0, 4] in the plane z = 0.
    fn square4() -> Vec<DVec3> {
        vec![
            dvec3(0., 0., 0.),
            dvec3(4., 0., 0.),
            dvec3(4., 4., 0.),
            dvec3(0., 4., 0.),
        ]
    }

    fn vertex_at(mesh: &Mesh, p: DVec3) -> usize {
        mesh.vertices
            .iter()
            .position(|v| (*v - p).length() < 1e-9)
            .unwrap()
    }

    #[test]
    fn constant_field_is_constant_at_vertices() {
        let tri = vec![dvec3(0., 0., 1.), dvec3(3., 0., 1.), dvec3(0., 3., 2.)];
        let s = scene(vec![surface("a", 0.0, square4()), surface("b", 0.0, tri)]);
        let mesh = mesh_scene(&s, 0.3).unwrap();
        let b = vec![[0.2, 0.7, 3.0]; mesh.len()];
        for v in vertex_radiosity(&mesh, &b) {
            for k in 0..3 {
                assert!((v[k] - b[0][k]).abs() < 1e-14, "{v:?}");
            }
        }
    }

    #[test]
    fn linear_field_is_exact_inside_and_averaged_on_the_boundary() {
        let s = scene(vec![surface("a", 0.0, square4())]);
        let mesh = mesh_scene(&s, 1.0).unwrap();
        assert_eq!(mesh.len(), 16); // 1 x 1 cells
        let f = |p: DVec3| p.x + 2.0 * p.y;
        let b: Vec<[f64; 3]> = mesh
            .elements
            .iter()
            .map(|e| [f(e.centroid), -f(e.centroid), 1.0])
            .collect();
        let vb = vertex_radiosity(&mesh, &b);
        // Interior vertices: f at the vertex itself.
        for i in 1..4 {
            for j in 1..4 {
                let p = dvec3(i as f64, j as f64, 0.0);
                let v = vb[vertex_at(&mesh, p)];
                assert!((v[0] - (i as f64 + 2.0 * j as f64)).abs() < 1e-12);
                assert!((v[1] + (i as f64 + 2.0 * j as f64)).abs() < 1e-12);
                assert!((v[2] - 1.0).abs() < 1e-12);
            }
        }
        // Corner (0,0): the one element with centroid (0.5, 0.5): 0.5 + 1 = 1.5.
        assert!((vb[vertex_at(&mesh, dvec3(0., 0., 0.))][0] - 1.5).abs() < 1e-12);
        // Edge vertex (2,0): centroids (1.5,0.5) -> 2.5 and (2.5,0.5) -> 3.5; mean 3.0.
        assert!((vb[vertex_at(&mesh, dvec3(2., 0., 0.))][0] - 3.0).abs() < 1e-12);
        // Edge vertex (4,1): centroids (3.5,0.5) -> 4.5 and (3.5,1.5) -> 6.5; mean 5.5.
        assert!((vb[vertex_at(&mesh, dvec3(4., 1., 0.))][0] - 5.5).abs() < 1e-12);
    }

    #[test]
    fn values_do_not_leak_between_surfaces() {
        // A floor and a wall that meet along the edge y = 0, z = 0.
        let floor = vec![
            dvec3(0., 0., 0.),
            dvec3(0., 0., 2.),
            dvec3(2., 0., 2.),
            dvec3(2., 0., 0.),
        ];
        let wall = vec![
            dvec3(0., 0., 0.),
            dvec3(2., 0., 0.),
            dvec3(2., 2., 0.),
            dvec3(0., 2., 0.),
        ];
        let s = scene(vec![
            surface("floor", 0.0, floor),
            surface("wall", 0.0, wall),
        ]);
        let mesh = mesh_scene(&s, 1.0).unwrap();
        let b: Vec<[f64; 3]> = mesh
            .elements
            .iter()
            .map(|e| if e.surface == 0 { [1.0; 3] } else { [5.0; 3] })
            .collect();
        let vb = vertex_radiosity(&mesh, &b);
        for (s, range) in mesh.surface_vertices.iter().enumerate() {
            let want = if s == 0 { 1.0 } else { 5.0 };
            for v in range.clone() {
                assert_eq!(vb[v as usize], [want; 3], "surface {s} vertex {v}");
            }
        }
    }
}
