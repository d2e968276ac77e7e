//! Display polygons: every element with the T-vertices that lie on its edges.
//!
//! A mesh refined as quadtrees (contact refinement, hierarchical radiosity's leaves,
//! solution-driven subdivision) has T-junctions: a corner M of the small elements on one side
//! of an edge A-B lies inside the edge of the one large element on the other side. Drawn as
//! its own corners only, the large element's colour along A-B is interpolated between A and
//! B while the small ones pass through M, so smooth shading jumps across the edge, and a
//! rasteriser leaves pinholes along it (the triangles do not share the edge's vertices).
//!
//! [`DisplayPolygons`] gives each element its **display polygon**: its corners with the
//! T-vertices inserted in order along each edge (A, M, B, ...), which is the same convex
//! region with more corners, and a triangulation of it that uses every one of them. Triangles
//! of neighbouring elements then share whole edges, so the display is watertight inside every
//! surface, and a T-vertex is a corner of every element it touches, so the radiosity shared by
//! all display vertices ([`crate::shade::vertex_radiosity`]) is interpolated continuously
//! across the edge. This is the usual fix for T-junctions in radiosity meshes, the
//! "anchoring" of Baum, Mann, Smith and Winget, "Making radiosity usable: automatic
//! preprocessing and meshing techniques for the generation of accurate radiosity solutions",
//! SIGGRAPH 1991: the T-vertices become corners of the neighbouring elements' display
//! triangles.
//!
//! T-vertices are found from the mesh's topology and geometry: an edge no other element shares
//! is either on the surface's boundary or a T-edge, and a T-vertex M inside a T-edge A-B is an
//! end of the small elements' own unshared edges along it (A-M, M-B, or only one of them where
//! a piece beyond was dropped as buried). So only unshared edges are searched, and only the
//! ends of unshared edges, kept per surface in a grid of cubes, are candidates. It needs the
//! elements of one surface to share vertices where their corners coincide, which every mesh
//! builder does (by exact position).

use std::collections::HashMap;

use glam::DVec3;

use super::Mesh;

/// Relative tolerance of "lies on the edge": a vertex within this fraction of the edge's
/// length of the segment, and this far from its ends (quadtree midpoints are computed from
/// the edge's two ends and lie on it to rounding, 1e-16; anything beyond 1e-9 is a real bend).
const ON_EDGE_TOLERANCE: f64 = 1e-9;

/// One triangle of an element's display polygon.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DisplayTriangle {
    /// Indices into [`Mesh::vertices`], counter-clockwise seen from the front.
    pub vertices: [u32; 3],
    /// Bit k set when the triangle's edge opposite its vertex k lies on the outline of the
    /// element (not a diagonal drawn inside it).
    pub outline: u8,
}

/// Every element's display polygon and its triangles (module documentation). Built once per
/// mesh, on first use, by [`Mesh::display`].
#[derive(Clone, Debug, Default)]
pub struct DisplayPolygons {
    polygon_offsets: Vec<u32>,
    polygon_vertices: Vec<u32>,
    triangle_offsets: Vec<u32>,
    triangles: Vec<DisplayTriangle>,
    t_vertices: usize,
    t_elements: usize,
}

impl DisplayPolygons {
    /// Finds the T-vertices of `mesh` and triangulates every element's display polygon.
    pub fn new(mesh: &Mesh) -> DisplayPolygons {
        // Edges used by one element only, as adjacency lists.
        let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
        for el in &mesh.elements {
            let c = el.corners();
            for i in 0..c.len() {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }

        let mut out = DisplayPolygons {
            polygon_offsets: Vec::with_capacity(mesh.len() + 1),
            polygon_vertices: Vec::with_capacity(4 * mesh.len()),
            triangle_offsets: Vec::with_capacity(mesh.len() + 1),
            triangles: Vec::with_capacity(2 * mesh.len()),
            t_vertices: 0,
            t_elements: 0,
        };
        out.polygon_offsets.push(0);
        out.triangle_offsets.push(0);
        let mut polygon = Vec::new();
        let mut grid = EndGrid::default();
        for (e, el) in mesh.elements.iter().enumerate() {
            if mesh.surface_elements[el.surface as usize].start as usize == e {
                grid = EndGrid::new(mesh, el.surface as usize, &uses);
            }
            let c = el.corners();
            polygon.clear();
            for i in 0..c.len() {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                polygon.push(a);
                if uses[&(a.min(b), a.max(b))] == 1 {
                    grid.inside_edge(mesh, a, b, &mut polygon);
                }
            }
            let inserted = polygon.len() - c.len();
            if inserted > 0 {
                out.t_vertices += inserted;
                out.t_elements += 1;
            }
            triangulate(mesh, &polygon, el.normal, &mut out.triangles);
            out.polygon_vertices.extend_from_slice(&polygon);
            out.polygon_offsets.push(out.polygon_vertices.len() as u32);
            out.triangle_offsets.push(out.triangles.len() as u32);
        }
        out
    }

    /// The display polygon of element `e`: indices into [`Mesh::vertices`], its corners with
    /// the T-vertices on its edges, counter-clockwise from the front.
    pub fn polygon(&self, e: usize) -> &[u32] {
        &self.polygon_vertices
            [self.polygon_offsets[e] as usize..self.polygon_offsets[e + 1] as usize]
    }

    /// The triangles of element `e`'s display polygon: (0, 1, 2) and (0, 2, 3) for a
    /// quadrilateral without T-vertices, an ear-clipped triangulation that uses every
    /// T-vertex otherwise.
    pub fn triangles(&self, e: usize) -> &[DisplayTriangle] {
        &self.triangles[self.triangle_offsets[e] as usize..self.triangle_offsets[e + 1] as usize]
    }

    /// All triangles, element by element (element e's are [`DisplayPolygons::triangles`]).
    pub fn all_triangles(&self) -> &[DisplayTriangle] {
        &self.triangles
    }

    /// How many T-vertices were inserted into display polygons, summed over elements.
    pub fn t_vertex_count(&self) -> usize {
        self.t_vertices
    }

    /// How many elements have a T-vertex on an edge.
    pub fn t_element_count(&self) -> usize {
        self.t_elements
    }
}

/// The ends of one surface's unshared edges (the only vertices that can lie inside another
/// element's edge) in a uniform grid of cubes, for the search along an edge.
#[derive(Default)]
struct EndGrid {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl EndGrid {
    /// The grid of surface `s`'s unshared edge ends; cubes as large as the median unshared
    /// edge, or 1/64 of the longest if that is larger (so no edge crosses more than 64).
    fn new(mesh: &Mesh, s: usize, uses: &HashMap<(u32, u32), u32>) -> EndGrid {
        let mut lengths = Vec::new();
        let mut ends = Vec::new();
        for e in mesh.surface_elements[s].clone() {
            let c = mesh.elements[e as usize].corners();
            for i in 0..c.len() {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                if uses[&(a.min(b), a.max(b))] == 1 {
                    lengths.push((mesh.vertices[b as usize] - mesh.vertices[a as usize]).length());
                    ends.extend([a, b]);
                }
            }
        }
        if lengths.is_empty() {
            return EndGrid::default();
        }
        lengths.sort_by(f64::total_cmp);
        let cell = lengths[lengths.len() / 2].max(lengths[lengths.len() - 1] / 64.0);
        if !(cell > 0.0 && cell.is_finite()) {
            return EndGrid::default();
        }
        ends.sort_unstable();
        ends.dedup();
        let mut grid = EndGrid {
            cell,
            cells: HashMap::new(),
        };
        for v in ends {
            let key = grid.key(mesh.vertices[v as usize]);
            grid.cells.entry(key).or_default().push(v);
        }
        grid
    }

    fn key(&self, p: DVec3) -> [i64; 3] {
        (p / self.cell).floor().as_i64vec3().to_array()
    }

    /// Appends to `polygon` the unshared edge ends strictly inside the edge `a` -> `b` (within
    /// [`ON_EDGE_TOLERANCE`] of its length), in order from `a`.
    fn inside_edge(&self, mesh: &Mesh, a: u32, b: u32, polygon: &mut Vec<u32>) {
        if self.cells.is_empty() {
            return;
        }
        let (pa, pb) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
        let ab = pb - pa;
        let len2 = ab.length_squared();
        if len2 <= 0.0 {
            return;
        }
        let tol = ON_EDGE_TOLERANCE;
        let mut found: Vec<(f64, u32)> = Vec::new();
        // Points along the edge a cube apart, and the 27 cubes round each.
        let steps = (len2.sqrt() / self.cell).ceil() as usize;
        for k in 0..=steps {
            let centre = self.key(pa + ab * (k as f64 / steps.max(1) as f64));
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let key = [centre[0] + dx, centre[1] + dy, centre[2] + dz];
                        for &q in self.cells.get(&key).map_or(&[][..], |v| v.as_slice()) {
                            let d = mesh.vertices[q as usize] - pa;
                            let t = d.dot(ab) / len2;
                            let off_line = (d - t * ab).length_squared() / len2;
                            if off_line <= tol * tol && t > tol && t < 1.0 - tol {
                                found.push((t, q));
                            }
                        }
                    }
                }
            }
        }
        found.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        found.dedup_by_key(|x| x.1);
        polygon.extend(found.into_iter().map(|(_, q)| q));
    }
}

/// Triangulates the convex polygon `polygon` (vertex indices, counter-clockwise about
/// `normal`, possibly with several corners in a row on one straight side) into `out`.
///
/// A triangle or a quadrilateral with no corner in line with its neighbours is cut as the
/// viewer always cut it: (0, 1, 2), (0, 2, 3). Otherwise ears are clipped, each time at the
/// corner whose ear is fattest (area over the sum of its squared sides) among those that are
/// a real turn and leave a polygon of positive area: a corner in line with its neighbours
/// would make a triangle of no area, and clipping the last real corner opposite a straight
/// side would leave that side's vertices in a line.
fn triangulate(mesh: &Mesh, polygon: &[u32], normal: DVec3, out: &mut Vec<DisplayTriangle>) {
    let n = polygon.len();
    let p = |k: usize| mesh.vertices[polygon[k] as usize];
    let scale2 = (0..n)
        .map(|k| (p((k + 1) % n) - p(k)).length_squared())
        .fold(0.0, f64::max);
    let eps = ON_EDGE_TOLERANCE * scale2;
    // Twice the signed area of (i, j, k) about the normal.
    let turn = |i: usize, j: usize, k: usize| (p(j) - p(i)).cross(p(k) - p(i)).dot(normal);
    let outline = |i: usize, j: usize| (i + 1) % n == j || (j + 1) % n == i;
    let push = |out: &mut Vec<DisplayTriangle>, [i, j, k]: [usize; 3]| {
        let mask = (outline(j, k) as u8) | (outline(k, i) as u8) << 1 | (outline(i, j) as u8) << 2;
        out.push(DisplayTriangle {
            vertices: [polygon[i], polygon[j], polygon[k]],
            outline: mask,
        });
    };
    if n < 3 {
        return;
    }
    if n == 3 {
        push(out, [0, 1, 2]);
        return;
    }
    if n == 4 && (0..4).all(|k| turn((k + 3) % 4, k, (k + 1) % 4) > eps) {
        push(out, [0, 1, 2]);
        push(out, [0, 2, 3]);
        return;
    }
    let mut ring: Vec<usize> = (0..n).collect();
    while ring.len() > 3 {
        let m = ring.len();
        let mut best: Option<(usize, f64)> = None;
        for k in 0..m {
            let (i, j, l) = (ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]);
            let area2 = turn(i, j, l);
            if area2 <= eps {
                continue; // j is in line with its neighbours
            }
            let leaves_area = ring
                .iter()
                .any(|&r| r != i && r != j && r != l && turn(i, l, r).abs() > eps);
            if !leaves_area {
                continue;
            }
            let sides = (p(j) - p(i)).length_squared()
                + (p(l) - p(j)).length_squared()
                + (p(i) - p(l)).length_squared();
            let fatness = area2 / sides;
            if best.is_none_or(|(_, f)| fatness > f) {
                best = Some((k, fatness));
            }
        }
        // A convex polygon of positive area always has such an ear (its remainder keeps two
        // real corners and a vertex off their line); a degenerate one is fanned as it is.
        let Some((k, _)) = best else { break };
        push(out, [ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]]);
        ring.remove(k);
    }
    for k in 1..ring.len() - 1 {
        push(out, [ring[0], ring[k], ring[k + 1]]);
    }
}

#[cfg(test)]
/// A test mesh with T-junctions: the square [0, 2]^2 (z = 0, facing +z) as a 2 x 2 grid of
/// unit quads whose lower left quad is split in four (elements 0-3; then [1, 2] x [0, 1],
/// [0, 1] x [1, 2], [1, 2]^2): the split's edge midpoints (1, 0.5) and (0.5, 1) are
/// T-vertices of the two whole quads beside it.
pub(crate) fn split_corner_mesh() -> Mesh {
    let mut vertices = Vec::new();
    let mut index: HashMap<[u64; 3], u32> = HashMap::new();
    let mut id = |x: f64, y: f64| {
        let p = glam::dvec3(x, y, 0.0);
        *index
            .entry(p.to_array().map(f64::to_bits))
            .or_insert_with(|| {
                vertices.push(p);
                vertices.len() as u32 - 1
            })
    };
    let mut elements = Vec::new();
    let mut quad = |x0: f64, y0: f64, s: f64| {
        vec![
            id(x0, y0),
            id(x0 + s, y0),
            id(x0 + s, y0 + s),
            id(x0, y0 + s),
        ]
    };
    for (x, y) in [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)] {
        elements.push(quad(x, y, 0.5));
    }
    for (x, y) in [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
        elements.push(quad(x, y, 1.0));
    }
    Mesh::from_surfaces(vec![(vertices, elements, DVec3::Z)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::scene::{Rgb, Scene, Surface};
    use glam::dvec3;
    use std::collections::HashMap;

    /// Edges of the display triangles of `surface`, with how many triangles use each.
    fn triangle_edges(mesh: &Mesh, surface: usize) -> HashMap<(u32, u32), usize> {
        let mut edges = HashMap::new();
        for e in mesh.surface_elements[surface].clone() {
            for t in mesh.display().triangles(e as usize) {
                let v = t.vertices;
                for k in 0..3 {
                    let (a, b) = (v[k], v[(k + 1) % 3]);
                    *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
        }
        edges
    }

    /// True when the segment between the mesh vertices `a` and `b` lies on the boundary of
    /// the axis-aligned square [lo, hi]^2.
    fn on_square_boundary(mesh: &Mesh, (a, b): (u32, u32), lo: f64, hi: f64) -> bool {
        let (p, q) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
        [lo, hi]
            .iter()
            .any(|&c| (p.x == c && q.x == c) || (p.y == c && q.y == c))
    }

    #[test]
    fn t_vertices_join_the_whole_neighbours_polygons() {
        let mesh = split_corner_mesh();
        let d = mesh.display();
        // The quad [1, 2] x [0, 1] gains (1, 0.5) on its left edge, [0, 1] x [1, 2] gains
        // (0.5, 1) on its bottom edge; the others have none.
        assert_eq!(d.t_vertex_count(), 2);
        assert_eq!(d.t_element_count(), 2);
        let at = |e: usize| -> Vec<DVec3> {
            d.polygon(e)
                .iter()
                .map(|&v| mesh.vertices[v as usize])
                .collect()
        };
        assert_eq!(
            at(4),
            vec![
                dvec3(1., 0., 0.),
                dvec3(2., 0., 0.),
                dvec3(2., 1., 0.),
                dvec3(1., 1., 0.),
                dvec3(1., 0.5, 0.)
            ]
        );
        assert_eq!(
            at(5),
            vec![
                dvec3(0., 1., 0.),
                dvec3(0.5, 1., 0.),
                dvec3(1., 1., 0.),
                dvec3(1., 2., 0.),
                dvec3(0., 2., 0.)
            ]
        );
        assert_eq!(d.polygon(6).len(), 4);
    }

    #[test]
    fn display_triangles_are_watertight_and_cover_the_elements() {
        // (a) Inside the surface every triangle edge is shared by exactly two triangles, on
        // its outline by one; (c) the triangles' area is the elements' area, element by
        // element (to rounding: 1e-12 of unit areas).
        let mesh = split_corner_mesh();
        for (&edge, &count) in &triangle_edges(&mesh, 0) {
            let want = if on_square_boundary(&mesh, edge, 0.0, 2.0) {
                1
            } else {
                2
            };
            assert_eq!(count, want, "edge {edge:?}");
        }
        check_areas_and_winding(&mesh);
    }

    fn check_areas_and_winding(mesh: &Mesh) {
        for (e, el) in mesh.elements.iter().enumerate() {
            let mut area = 0.0;
            for t in mesh.display().triangles(e) {
                let [a, b, c] = t.vertices.map(|v| mesh.vertices[v as usize]);
                let signed = 0.5 * (b - a).cross(c - a).dot(el.normal);
                assert!(signed > 0.0, "element {e}: triangle {t:?} of area {signed}");
                area += signed;
            }
            assert!(
                (area - el.area).abs() <= 1e-12 * el.area.max(1.0),
                "element {e}: triangles {area}, element {}",
                el.area
            );
        }
    }

    #[test]
    fn a_conforming_grid_keeps_its_two_triangles_per_quad() {
        let scene = Scene {
            surfaces: vec![Surface {
                name: "floor".into(),
                emission: Rgb::BLACK,
                reflectance: Rgb([0.5; 3]),
                vertices: vec![
                    dvec3(0., 0., 0.),
                    dvec3(3., 0., 0.),
                    dvec3(3., 2., 0.),
                    dvec3(0., 2., 0.),
                ],
                photometry: Default::default(),
            }],
            camera: None,
            lights: Vec::new(),
        };
        let mesh = mesh_scene(&scene, 1.0).unwrap();
        let d = mesh.display();
        assert_eq!(d.t_vertex_count(), 0);
        for (e, el) in mesh.elements.iter().enumerate() {
            let c = el.corners();
            assert_eq!(d.polygon(e), c);
            let tris: Vec<[u32; 3]> = d.triangles(e).iter().map(|t| t.vertices).collect();
            assert_eq!(tris, vec![[c[0], c[1], c[2]], [c[0], c[2], c[3]]]);
            assert_eq!(d.triangles(e)[0].outline, 0b101);
            assert_eq!(d.triangles(e)[1].outline, 0b011);
        }
    }

    #[test]
    fn several_t_vertices_on_one_side_and_a_triangle() {
        // A triangle (0,0) (4,0) (0,4) beside three small squares' corners on its bottom
        // edge: (1,0), (2,0), (3,0) belong to squares below it (y in [-1, 0]); the walk finds
        // all three, the ear clipping leaves no triangle of zero area, and the result is
        // watertight along the shared edge.
        // Vertices 0-2: the triangle; 3-7: (i, -1) for i = 0..4; 8-10: (1, 0), (2, 0), (3, 0).
        let mut vertices = vec![dvec3(0., 0., 0.), dvec3(4., 0., 0.), dvec3(0., 4., 0.)];
        vertices.extend((0..=4).map(|i| dvec3(i as f64, -1.0, 0.0)));
        vertices.extend((1..=3).map(|i| dvec3(i as f64, 0.0, 0.0)));
        let top = |i: u32| match i {
            0 => 0,
            4 => 1,
            _ => 7 + i,
        };
        let mut elements = vec![vec![0, 1, 2]];
        for i in 0..4u32 {
            elements.push(vec![3 + i, 4 + i, top(i + 1), top(i)]);
        }
        let mesh = Mesh::from_surfaces(vec![(vertices, elements, DVec3::Z)]);
        let d = mesh.display();
        assert_eq!(d.polygon(0).len(), 6, "{:?}", d.polygon(0));
        assert_eq!(d.t_vertex_count(), 3);
        check_areas_and_winding(&mesh);
        for (&(a, b), &count) in &triangle_edges(&mesh, 0) {
            let (p, q) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
            // The union's outline: x = 0, y = -1, x = 4 (below y = 0) and x + y = 4.
            let on = |f: fn(DVec3) -> bool| f(p) && f(q);
            let outline = on(|v| v.x == 0.0)
                || on(|v| v.y == -1.0)
                || on(|v| v.x == 4.0)
                || on(|v| v.x + v.y == 4.0);
            assert_eq!(count, if outline { 1 } else { 2 }, "edge {p} - {q}");
        }
    }

    #[test]
    fn contact_refined_floor_is_watertight() {
        // A box standing across grid lines: contact refinement splits the floor's elements
        // round its footprint three levels deep next to whole ones. Every interior edge of
        // the floor's display triangles is shared by two triangles; the floor's outline
        // (the square [0, 4]^2) and the footprint's hole (whose edges have no element on
        // their far side) by one.
        use crate::mesh::refine_contacts;
        use crate::scene::shape::{axis_aligned_base, box_faces, Facing};
        use crate::visibility::PolygonBvh;
        let surface = |name: &str, vertices: Vec<DVec3>| Surface {
            name: name.into(),
            emission: Rgb::BLACK,
            reflectance: Rgb([0.5; 3]),
            vertices,
            photometry: Default::default(),
        };
        let mut surfaces = vec![surface(
            "floor",
            vec![
                dvec3(0., 0., 0.),
                dvec3(0., 0., 4.),
                dvec3(4., 0., 4.),
                dvec3(4., 0., 0.),
            ],
        )];
        let base = axis_aligned_base(dvec3(0.3, 0., 0.3), dvec3(2.0, 0.5, 1.0));
        for face in box_faces(&base, 0.5, Facing::Out) {
            surfaces.push(surface("box", face));
        }
        let scene = Scene {
            surfaces,
            camera: None,
            lights: Vec::new(),
        };
        let grid = mesh_scene(&scene, 1.0).unwrap();
        let (mesh, report) = refine_contacts(&grid, &scene, &PolygonBvh::over_surfaces(&scene));
        assert!(report.split > 0, "{report:?}");
        let d = mesh.display();
        assert!(d.t_vertex_count() > 0);
        check_areas_and_winding(&mesh);
        // Count, per triangle edge, how often it is used, and check that each edge used once
        // is on the outline or on the hole: the hole's edges have the box's footprint on
        // their far side, which is inside [0.3, 2.3] x [0.3, 1.3] widened by one piece.
        let piece = 1.0 / 8.0;
        for (&(a, b), &count) in &triangle_edges(&mesh, 0) {
            let (p, q) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
            let on_outline = [0.0, 4.0]
                .iter()
                .any(|&c| (p.x == c && q.x == c) || (p.z == c && q.z == c));
            let near_hole = [p, q].iter().all(|v| {
                v.x >= 0.3 - piece && v.x <= 2.3 + piece && v.z >= 0.3 - piece && v.z <= 1.3 + piece
            });
            assert!(count <= 2, "edge {p} - {q} used {count} times");
            if count == 1 {
                assert!(on_outline || near_hole, "open edge {p} - {q}");
            }
        }
    }

    #[test]
    fn refined_room_has_no_vertex_inside_a_triangle_edge() {
        // examples/room.scene, contact-refined: floor pieces three levels deep next to whole
        // elements, some pieces beyond a T-vertex dropped as buried. By brute force over every
        // display triangle edge and every vertex of its surface: none lies strictly inside
        // an edge (to 1e-9 of its length, the detection's own tolerance being the same).
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/room.scene");
        let file = crate::scene::read_scene(&path).unwrap();
        let grid = mesh_scene(&file.scene, file.settings.max_patch_area).unwrap();
        let bvh = crate::visibility::PolygonBvh::over_surfaces(&file.scene);
        let (mesh, _) = crate::mesh::refine_contacts(&grid, &file.scene, &bvh);
        assert!(mesh.display().t_vertex_count() > 100);
        check_areas_and_winding(&mesh);
        for s in 0..file.scene.surfaces.len() {
            let points: Vec<DVec3> = mesh.surface_vertices[s]
                .clone()
                .map(|i| mesh.vertices[i as usize])
                .collect();
            for e in mesh.surface_elements[s].clone() {
                for t in mesh.display().triangles(e as usize) {
                    for k in 0..3 {
                        let a = mesh.vertices[t.vertices[k] as usize];
                        let b = mesh.vertices[t.vertices[(k + 1) % 3] as usize];
                        let ab = b - a;
                        for &p in &points {
                            let u = (p - a).dot(ab) / ab.length_squared();
                            if u > 1e-9 && u < 1.0 - 1e-9 {
                                let off = (p - (a + u * ab)).length();
                                assert!(
                                    off > 1e-9 * ab.length(),
                                    "surface {s}: {p} lies on the edge {a} - {b}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}
