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

use std::collections::HashMap;

use glam::DVec3;

use crate::mesh::Mesh;
use crate::scene::Scene;

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

/// The largest angle between two facets' normals across which [`smooth_objects`] makes
/// the shading continuous: a tessellated sphere, cylinder or cone of resolution 7 or more
/// (facets at most 51.4 degrees apart) shades smooth; a box's edges (90 degrees), a
/// cylinder's rim and a prism of six sides or fewer keep their creases.
pub const CREASE_DEGREES: f64 = 60.0;

/// The object a surface belongs to, for [`smooth_objects`]: its name up to the last `.`
/// (`ball.12` is a facet of `ball`, as the scene reader names a `SPHEREBEGIN` block's
/// faces and the importers an object's faces); `None` for a name without one.
pub fn object_of(name: &str) -> Option<&str> {
    name.rfind('.')
        .map(|i| &name[..i])
        .filter(|o| !o.is_empty())
}

/// Makes smooth shading continuous across the facets of one curved object, in place:
/// [`vertex_radiosity`] averages within a surface only, so a tessellated sphere (one
/// surface per facet) shaded faceted, each facet's edge extrapolated from its own
/// elements. Vertices at one position (within 1e-9 of the scene's extent) whose surfaces
/// are facets of one object ([`object_of`]) with the same reflectance and emission and
/// whose normals are less than [`CREASE_DEGREES`] apart (joined in chains, so a sphere's
/// pole joins every facet round it) all take the mean of their values, weighted by the
/// area of the elements around each. A box's faces (90 degrees), different objects,
/// and a light set into a ceiling (another colour) are left as they are. The mesh is not
/// changed (its vertices stay one surface's each, as the solvers need), only the colours
/// that interpolate across it; where two facets' edges were cut at different points, the
/// points they share are joined and the others keep their own values. The joins are
/// [`ObjectJoins`]; the renderer's direct light takes its shading normals from them.
///
/// # Panics
/// If `vertex_b` does not have one entry per mesh vertex or the mesh is not `scene`'s.
pub fn smooth_objects(scene: &Scene, mesh: &Mesh, vertex_b: &mut [[f64; 3]]) {
    assert_eq!(vertex_b.len(), mesh.vertices.len(), "one value per vertex");
    ObjectJoins::new(scene, mesh).apply(vertex_b);
}

/// Which vertices of a mesh [`smooth_objects`] joins (the facets of one curved object
/// meeting at a point), with their weights, and the shading normals that follow from the
/// same joins: a joined vertex's normal is the area-weighted mean of its facets' normals,
/// as its value is the area-weighted mean of theirs; every other vertex keeps its
/// surface's (flat) normal.
#[derive(Clone, Debug)]
pub struct ObjectJoins {
    /// Per vertex, its group in `groups`, or `u32::MAX` when it is not joined.
    group_of: Vec<u32>,
    /// Each group's vertices (in the order they are summed) and their total weight.
    groups: Vec<(Vec<u32>, f64)>,
    /// Per vertex, its weight: the area of the elements around it.
    ring_area: Vec<f64>,
    /// Per vertex, the unit shading normal.
    normal: Vec<DVec3>,
    /// Per vertex, whether its group joins facets of different normals (so its shading
    /// normal is not its surface's).
    curved: Vec<bool>,
}

impl ObjectJoins {
    /// The joins of `mesh`, which was cut from `scene` (see [`smooth_objects`]).
    pub fn new(scene: &Scene, mesh: &Mesh) -> ObjectJoins {
        let n_vertices = mesh.vertices.len();
        let display = mesh.display();
        let mut ring_area = vec![0.0f64; n_vertices];
        let mut surface_of = vec![u32::MAX; n_vertices];
        let mut normal = vec![DVec3::ZERO; n_vertices];
        for (e, element) in mesh.elements.iter().enumerate() {
            for &c in display.polygon(e) {
                ring_area[c as usize] += element.area;
                surface_of[c as usize] = element.surface;
                normal[c as usize] = element.normal;
            }
        }
        let mut joins = ObjectJoins {
            group_of: vec![u32::MAX; n_vertices],
            groups: Vec::new(),
            ring_area,
            normal,
            curved: vec![false; n_vertices],
        };
        let surfaces = &scene.surfaces;
        // Which surfaces can be joined at all: those of an object with another facet.
        let mut facets: HashMap<&str, usize> = HashMap::new();
        for s in surfaces {
            if let Some(o) = object_of(&s.name) {
                *facets.entry(o).or_default() += 1;
            }
        }
        if !facets.values().any(|&n| n > 1) {
            return joins;
        }
        let surface_normal: Vec<Option<DVec3>> = surfaces
            .iter()
            .map(|s| crate::geometry::polygon_normal(&s.vertices))
            .collect();
        let (lo, hi) = scene.bounds();
        let extent = (hi - lo).max_element();
        if !(extent.is_finite() && extent > 0.0) {
            return joins;
        }
        let cell = 1e-9 * extent;
        let joinable = |s: usize| {
            object_of(&surfaces[s].name).is_some_and(|o| facets.get(o).is_some_and(|&n| n > 1))
        };
        let mut at: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (v, p) in mesh.vertices.iter().enumerate() {
            let s = surface_of[v];
            if s != u32::MAX && joinable(s as usize) {
                let key = (*p / cell).round().to_array().map(|x| x as i64);
                at.entry(key).or_default().push(v as u32);
            }
        }
        let cos_crease = CREASE_DEGREES.to_radians().cos();
        let same = |a: usize, b: usize| {
            let (x, y) = (&surfaces[a], &surfaces[b]);
            object_of(&x.name) == object_of(&y.name)
                && x.reflectance == y.reflectance
                && x.emission == y.emission
                && match (surface_normal[a], surface_normal[b]) {
                    (Some(m), Some(n)) => m.dot(n) > cos_crease,
                    _ => false,
                }
        };
        // Points in a fixed order, so the groups (and the normals' rounding) do not depend
        // on the hash map's.
        let mut points: Vec<&Vec<u32>> = at.values().filter(|m| m.len() > 1).collect();
        points.sort_unstable_by_key(|m| m[0]);
        for members in points {
            // Union-find over the few vertices at this point.
            let n = members.len();
            let mut parent: Vec<usize> = (0..n).collect();
            fn root(parent: &mut [usize], mut i: usize) -> usize {
                while parent[i] != i {
                    parent[i] = parent[parent[i]];
                    i = parent[i];
                }
                i
            }
            for i in 0..n {
                for j in i + 1..n {
                    let (a, b) = (members[i] as usize, members[j] as usize);
                    if same(surface_of[a] as usize, surface_of[b] as usize) {
                        let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                        parent[ri] = rj;
                    }
                }
            }
            let mut by_root: Vec<(usize, Vec<u32>)> = Vec::new();
            for (i, &v) in members.iter().enumerate() {
                let r = root(&mut parent, i);
                match by_root.iter_mut().find(|(q, _)| *q == r) {
                    Some((_, group)) => group.push(v),
                    None => by_root.push((r, vec![v])),
                }
            }
            for (_, group) in by_root {
                let area: f64 = group.iter().map(|&v| joins.ring_area[v as usize]).sum();
                let joined = group.len() > 1 && area > 0.0;
                if !joined {
                    continue;
                }
                // The shading normal: the facets' normals weighted as the values are.
                let first = joins.normal[group[0] as usize];
                let curved = group
                    .iter()
                    .any(|&v| joins.normal[v as usize].dot(first) < 1.0 - 1e-12);
                let mean = group
                    .iter()
                    .map(|&v| joins.ring_area[v as usize] * joins.normal[v as usize])
                    .sum::<DVec3>()
                    .normalize_or_zero();
                let index = joins.groups.len() as u32;
                for &v in &group {
                    joins.group_of[v as usize] = index;
                    if curved && mean != DVec3::ZERO {
                        joins.normal[v as usize] = mean;
                        joins.curved[v as usize] = true;
                    }
                }
                joins.groups.push((group, area));
            }
        }
        joins
    }

    /// The vertices joined with `v` (itself included) and their weights, with the sum of
    /// the weights; `None` for a vertex that keeps its own value.
    pub fn group(&self, v: usize) -> Option<(impl Iterator<Item = (usize, f64)> + '_, f64)> {
        let g = *self.group_of.get(v)?;
        if g == u32::MAX {
            return None;
        }
        let (members, area) = &self.groups[g as usize];
        Some((
            members
                .iter()
                .map(|&m| (m as usize, self.ring_area[m as usize])),
            *area,
        ))
    }

    /// Replaces the values of every group of joined vertices by their weighted mean.
    pub fn apply(&self, values: &mut [[f64; 3]]) {
        for (members, area) in &self.groups {
            let mut sum = [0.0f64; 3];
            for &v in members {
                let v = v as usize;
                for (s, b) in sum.iter_mut().zip(values[v]) {
                    *s += self.ring_area[v] * b;
                }
            }
            for &v in members {
                values[v as usize] = sum.map(|x| x / area);
            }
        }
    }

    /// The unit shading normal at vertex `v`: the area-weighted mean of the normals of
    /// the facets joined there, or its surface's normal where none are.
    pub fn normal(&self, v: usize) -> DVec3 {
        self.normal[v]
    }

    /// True when the shading normal at vertex `v` differs from its surface's (it joins
    /// facets of a curved object).
    pub fn is_curved(&self, v: usize) -> bool {
        self.curved[v]
    }
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

    /// Facets named `prefix.k`, reflectance 0.5, no emission.
    fn facets(prefix: &str, faces: Vec<Vec<DVec3>>) -> Vec<Surface> {
        faces
            .into_iter()
            .enumerate()
            .map(|(k, f)| surface(&format!("{prefix}.{k}"), 0.0, f))
            .collect()
    }

    /// A field that is not linear in position (so each facet's own boundary fit gives
    /// its own value at a shared corner), per element.
    fn curved_field(mesh: &Mesh) -> Vec<[f64; 3]> {
        mesh.elements
            .iter()
            .map(|e| {
                let c = e.centroid;
                let x = 1.0 + c.y * c.y + 0.3 * c.x * c.z;
                [x, 2.0 * x, 0.5 * x]
            })
            .collect()
    }

    /// The largest difference between vertices at one position, over the pairs whose
    /// surfaces `pair` accepts.
    fn largest_step(
        scene: &Scene,
        mesh: &Mesh,
        vb: &[[f64; 3]],
        pair: impl Fn(&str, &str) -> bool,
    ) -> (f64, usize) {
        let surface_of: Vec<usize> = {
            let mut s = vec![usize::MAX; mesh.vertices.len()];
            for e in &mesh.elements {
                for &c in e.corners() {
                    s[c as usize] = e.surface as usize;
                }
            }
            s
        };
        let (mut step, mut pairs) = (0.0f64, 0);
        for a in 0..mesh.vertices.len() {
            for b in a + 1..mesh.vertices.len() {
                let (sa, sb) = (surface_of[a], surface_of[b]);
                if sa == usize::MAX || sb == usize::MAX || sa == sb {
                    continue;
                }
                if (mesh.vertices[a] - mesh.vertices[b]).length() > 1e-9 {
                    continue;
                }
                if !pair(&scene.surfaces[sa].name, &scene.surfaces[sb].name) {
                    continue;
                }
                pairs += 1;
                for k in 0..3 {
                    step = step.max((vb[a][k] - vb[b][k]).abs());
                }
            }
        }
        (step, pairs)
    }

    #[test]
    fn a_tessellated_sphere_shades_continuous_across_its_facets() {
        use crate::scene::shape::{sphere_faces, Facing};
        let faces = sphere_faces(dvec3(0., 0., 0.), 1.0, 12, Facing::Out);
        let s = scene(facets("ball", faces));
        let mesh = mesh_scene(&s, 0.02).unwrap();
        let eb = curved_field(&mesh);
        let mut vb = vertex_radiosity(&mesh, &eb);
        let any = |_: &str, _: &str| true;
        let (before, pairs) = largest_step(&s, &mesh, &vb, any);
        // The facets' own fits disagree at their shared corners (else this test could not
        // fail): the field's curvature over an element is of order 0.1.
        assert!(pairs > 100 && before > 1e-3, "{before} over {pairs} pairs");
        smooth_objects(&s, &mesh, &mut vb);
        let (after, _) = largest_step(&s, &mesh, &vb, any);
        // Joined: the same value to rounding (sums of a few terms of size 3).
        assert!(after < 1e-12, "{after}");
    }

    #[test]
    fn creases_other_objects_and_other_colours_are_not_smoothed() {
        use crate::scene::shape::{axis_aligned_base, box_faces, Facing};
        // A box (faces at 90 degrees), and a second object and a light touching it.
        let base = axis_aligned_base(dvec3(0., 0., 0.), dvec3(1., 0., 1.));
        let mut surfaces = facets("box", box_faces(&base, 1.0, Facing::Out).to_vec());
        // Beside the box's x = 1 face, in its plane's continuation: a plate of another
        // object, and one of the box's own name but emitting.
        surfaces.push(surface(
            "plate.0",
            0.0,
            vec![
                dvec3(1., 0., 0.),
                dvec3(2., 0., 0.),
                dvec3(2., 0., 1.),
                dvec3(1., 0., 1.),
            ]
            .into_iter()
            .rev()
            .collect(),
        ));
        surfaces.push(surface(
            "box.light",
            3.0,
            vec![
                dvec3(1., 1., 0.),
                dvec3(1., 1., 1.),
                dvec3(2., 1., 1.),
                dvec3(2., 1., 0.),
            ],
        ));
        let s = scene(surfaces);
        let mesh = mesh_scene(&s, 0.05).unwrap();
        let eb = curved_field(&mesh);
        let before = vertex_radiosity(&mesh, &eb);
        let mut after = before.clone();
        smooth_objects(&s, &mesh, &mut after);
        assert_eq!(before, after, "nothing here is one curved object");
    }
}
