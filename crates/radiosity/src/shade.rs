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

/// The radiosity at every vertex of `mesh`, by [`vertex_rule`]: inside a surface the
/// area-weighted mean of `element_b` over the elements that touch the vertex, as a corner
/// or with the vertex inside one of their edges (a T-vertex: it is a corner of their
/// display polygons, [`Mesh::display`]) (paper 2.5's neighbour averaging, generalised); on a
/// surface's boundary, the linear fit of the elements around it evaluated at the vertex.
/// Values below zero (an extrapolation past a steep fall) are raised to zero. A vertex no
/// element uses (there are none in a mesh from [`crate::mesh::mesh_scene`]) gets zero.
///
/// # Panics
/// If `element_b` does not have one entry per element of `mesh`.
pub fn vertex_radiosity(mesh: &Mesh, element_b: &[[f64; 3]]) -> Vec<[f64; 3]> {
    assert_eq!(
        element_b.len(),
        mesh.len(),
        "one radiosity per element expected"
    );
    let rule = vertex_rule(mesh);
    (0..mesh.vertices.len())
        .map(|v| {
            let mut sum = [0.0f64; 3];
            for (e, w) in rule.terms(v) {
                for k in 0..3 {
                    sum[k] += w * element_b[e][k];
                }
            }
            sum.map(|x| x.max(0.0))
        })
        .collect()
}

/// Per vertex, the elements whose values make its value and their weights (the value is
/// sum w_e B_e): see [`vertex_rule`]. Shared by smooth shading and the renderer's direct
/// correction, whose interpolated direct light must follow the same rule.
#[derive(Clone, Debug, Default)]
pub struct VertexRule {
    offsets: Vec<u32>,
    elements: Vec<u32>,
    weights: Vec<f64>,
}

impl VertexRule {
    /// The (element, weight) pairs of vertex `v`.
    pub fn terms(&self, v: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let range = self.offsets[v] as usize..self.offsets[v + 1] as usize;
        self.elements[range.clone()]
            .iter()
            .zip(&self.weights[range])
            .map(|(&e, &w)| (e as usize, w))
    }
}

/// The most that the weights of a boundary vertex's fit may add up to in absolute value;
/// beyond it (a fit from few, badly placed elements) the vertex takes the mean. A corner of
/// a regular grid, fitted from its 2 x 2 block, adds up to 2.5.
const MAX_FIT_GAIN: f64 = 4.0;

/// How every vertex of `mesh` takes its value from the elements' (paper 2.5's neighbour
/// averaging, extended at boundaries).
///
/// Inside a surface (the angles of the display polygons around the vertex add up to a full
/// turn) a vertex takes the area-weighted mean of the elements that touch it: on a regular
/// grid the plain mean of its four, which reproduces a field linear in position. On a
/// surface's boundary (its edges, and the rims of holes that contact refinement left) the
/// mean is biased: a corner vertex took the value at its element's centre, so the light
/// falling into a concave corner (where a wall meets the ceiling) stopped half an element
/// short, and every corner showed as a bright line against the path tracer. There the
/// vertex takes the weighted least-squares plane through the centroids of the elements
/// that touch it and of their neighbours (Cohen and Wallace 1993, section 9.2.2, on
/// extrapolating nodal values at boundaries), evaluated at the vertex: exact for a linear
/// field, as inside. Where the plane is ill-determined (fewer than three elements not in a
/// line) or too steep a lever ([`MAX_FIT_GAIN`]), the mean is kept.
pub fn vertex_rule(mesh: &Mesh) -> VertexRule {
    let display = mesh.display();
    let n = mesh.vertices.len();
    // Vertex -> elements touching it (CSR).
    let mut offsets = vec![0u32; n + 1];
    for e in 0..mesh.len() {
        for &c in display.polygon(e) {
            offsets[c as usize + 1] += 1;
        }
    }
    for i in 1..offsets.len() {
        offsets[i] += offsets[i - 1];
    }
    let mut fill = offsets.clone();
    let mut touching = vec![0u32; offsets[n] as usize];
    // The angle each element's display polygon makes at each of its corners.
    let mut angle = vec![0.0f64; n];
    for e in 0..mesh.len() {
        let poly = display.polygon(e);
        let m = poly.len();
        for (i, &c) in poly.iter().enumerate() {
            touching[fill[c as usize] as usize] = e as u32;
            fill[c as usize] += 1;
            let p = mesh.vertices[c as usize];
            let a = mesh.vertices[poly[(i + m - 1) % m] as usize] - p;
            let b = mesh.vertices[poly[(i + 1) % m] as usize] - p;
            angle[c as usize] += a.angle_between(b);
        }
    }
    let around = |v: usize| &touching[offsets[v] as usize..offsets[v + 1] as usize];
    let mut rule = VertexRule {
        offsets: Vec::with_capacity(n + 1),
        elements: Vec::with_capacity(touching.len()),
        weights: Vec::with_capacity(touching.len()),
    };
    rule.offsets.push(0);
    let mut ring: Vec<u32> = Vec::new();
    for v in 0..n {
        let ring1 = around(v);
        let interior = angle[v] > 2.0 * std::f64::consts::PI * (1.0 - 1e-6);
        let fitted = if interior || ring1.is_empty() {
            None
        } else {
            ring.clear();
            for &e in ring1 {
                for &c in display.polygon(e as usize) {
                    ring.extend_from_slice(around(c as usize));
                }
            }
            ring.sort_unstable();
            ring.dedup();
            plane_fit_weights(mesh, v, &ring)
        };
        match fitted {
            Some(weights) => {
                rule.elements.extend_from_slice(&ring);
                rule.weights.extend(weights);
            }
            None => {
                let total: f64 = ring1.iter().map(|&e| mesh.elements[e as usize].area).sum();
                if total > 0.0 {
                    rule.elements.extend_from_slice(ring1);
                    rule.weights.extend(
                        ring1
                            .iter()
                            .map(|&e| mesh.elements[e as usize].area / total),
                    );
                }
            }
        }
        rule.offsets.push(rule.elements.len() as u32);
    }
    rule
}

/// The weights w_e (over `ring`) of the area-weighted least-squares plane through the
/// elements' centroids evaluated at vertex `v`: the plane's value there is sum w_e B_e.
/// None where the plane is ill-determined or the weights' absolute sum exceeds
/// [`MAX_FIT_GAIN`].
fn plane_fit_weights(mesh: &Mesh, v: usize, ring: &[u32]) -> Option<Vec<f64>> {
    if ring.len() < 3 {
        return None;
    }
    let x = mesh.vertices[v];
    let normal = mesh.elements[ring[0] as usize].normal;
    let u = normal.any_orthonormal_vector();
    let w = normal.cross(u);
    // Offsets in units of the ring's size, so the normal equations are well scaled.
    let size = ring
        .iter()
        .map(|&e| (mesh.elements[e as usize].centroid - x).length())
        .fold(0.0, f64::max);
    if !(size > 0.0) {
        return None;
    }
    let rows: Vec<(f64, [f64; 3])> = ring
        .iter()
        .map(|&e| {
            let el = &mesh.elements[e as usize];
            let d = (el.centroid - x) / size;
            (el.area, [1.0, d.dot(u), d.dot(w)])
        })
        .collect();
    let mut m = glam::DMat3::ZERO;
    for (a, r) in &rows {
        let r = glam::DVec3::from_array(*r);
        m += glam::DMat3::from_cols(r * r.x, r * r.y, r * r.z) * *a;
    }
    // Ill-determined: centroids (nearly) in a line, or one element.
    let scale = m.x_axis.x.max(f64::MIN_POSITIVE);
    if m.determinant().abs() < 1e-9 * scale.powi(3) {
        return None;
    }
    // The value at the vertex (offset 0) is the first component of the solution:
    // row 0 of M^-1 applied to sum a_e r_e B_e, so w_e = a_e (M^-1 r_e)_0.
    let inv = m.inverse();
    let weights: Vec<f64> = rows
        .iter()
        .map(|(a, r)| a * inv.row(0).dot(glam::DVec3::from_array(*r)))
        .collect();
    let gain: f64 = weights.iter().map(|w| w.abs()).sum();
    (gain.is_finite() && gain <= MAX_FIT_GAIN).then_some(weights)
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
            photometry: Default::default(),
        }
    }

    fn scene(surfaces: Vec<Surface>) -> Scene {
        Scene {
            surfaces,
            camera: None,
            lights: Vec::new(),
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
    fn linear_field_is_exact_at_every_vertex_boundary_included() {
        // f = x + 2 y on a 4 x 4 grid of unit cells: each element holds f at its centroid,
        // and a linear field is reproduced exactly by the mean inside and by the plane fit
        // on the boundary (closed form: f at the vertex). The mean alone gave the corner
        // (0, 0) the value 1.5 (its element's centre) instead of 0.
        let s = scene(vec![surface("a", 0.0, square4())]);
        let mesh = mesh_scene(&s, 1.0).unwrap();
        assert_eq!(mesh.len(), 16); // 1 x 1 cells
        let f = |p: DVec3| p.x + 2.0 * p.y;
        let b: Vec<[f64; 3]> = mesh
            .elements
            .iter()
            .map(|e| [f(e.centroid), 20.0 - f(e.centroid), 1.0])
            .collect();
        let vb = vertex_radiosity(&mesh, &b);
        for i in 0..=4 {
            for j in 0..=4 {
                let p = dvec3(i as f64, j as f64, 0.0);
                let v = vb[vertex_at(&mesh, p)];
                assert!((v[0] - f(p)).abs() < 1e-12, "{p}: {v:?}");
                assert!((v[1] - (20.0 - f(p))).abs() < 1e-12, "{p}: {v:?}");
                assert!((v[2] - 1.0).abs() < 1e-12, "{p}: {v:?}");
            }
        }
    }

    #[test]
    fn a_fall_into_a_corner_is_not_extrapolated_below_zero() {
        // Elements 0 everywhere but 1 far from the corner: the corner's plane would go
        // below zero; the value is raised to zero, never negative.
        let s = scene(vec![surface("a", 0.0, square4())]);
        let mesh = mesh_scene(&s, 1.0).unwrap();
        let b: Vec<[f64; 3]> = mesh
            .elements
            .iter()
            .map(|e| {
                let x = if e.centroid.x > 1.0 && e.centroid.y > 1.0 {
                    1.0
                } else {
                    0.0
                };
                [x; 3]
            })
            .collect();
        for v in vertex_radiosity(&mesh, &b) {
            assert!(v.iter().all(|&x| x >= 0.0), "{v:?}");
        }
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
                // To rounding: a boundary vertex's plane fit sums weights that add to 1.
                let got = vb[v as usize];
                assert!(
                    got.iter().all(|&x| (x - want).abs() < 1e-12 * want),
                    "surface {s} vertex {v}: {got:?}"
                );
            }
        }
    }
}
