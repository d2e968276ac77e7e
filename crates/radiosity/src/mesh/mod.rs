//! Area-based subdivision of surfaces into elements (paper section 2.4).
//!
//! Every surface whose area exceeds `MAX_PATCH_AREA` is cut into elements of at most that
//! area with aspect ratio near 1: a quadrilateral into an m x n grid of quadrilaterals (the
//! bilinear map of the unit square), a triangle into m^2 triangles (each edge cut into m), and
//! a polygon of five or more corners first into a fan of triangles from its centroid, each
//! cut the same way. Elements of one surface share their corner vertices, so the mesh is
//! conforming within a surface; surfaces never share vertices (shading does not cross
//! surface boundaries, as in the paper). Neighbours (elements sharing an edge on the same
//! surface) are recorded for shading.
//!
//! [`MeshSettings`] are the two numbers at the top of a scene file that say how finely a
//! scene is discretised: `MAX_PATCH_AREA` for this subdivision, `INTEGRAL_STEPS` for the
//! area integral over the elements. They travel beside the [`Scene`], not in it: the scene
//! is geometry and materials only.

mod adapt;
mod conforming;
mod contact;
mod outline_cut;

pub use adapt::{
    mark_steps, split_marked, AdaptSettings, Origin, DEFAULT_CONTRAST, DEFAULT_FLOOR,
    DEFAULT_MAX_ELEMENTS, MIN_PAIR_BUDGET,
};
#[cfg(test)]
pub(crate) use conforming::split_corner_mesh;
pub use conforming::{DisplayPolygons, DisplayTriangle};
pub use contact::{
    refine_contacts, refine_contacts_as_quadtrees, ContactReport, CONTACT_DEPTH,
    CONTACT_MAX_ELEMENTS, PROBE_DIRECTIONS, PROBE_SLACK,
};
pub(crate) use contact::{Cover, Probe};

use std::collections::HashMap;
use std::ops::Range;
use std::sync::OnceLock;

use glam::DVec3;

use crate::geometry;
use crate::scene::Scene;

/// The meshing and integration settings at the top of a scene file (`MAX_PATCH_AREA` and
/// `INTEGRAL_STEPS`), which the command line and the window may override.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSettings {
    /// `MAX_PATCH_AREA`: surfaces larger than this (scene units squared) are subdivided into
    /// elements of at most this area.
    pub max_patch_area: f64,
    /// `INTEGRAL_STEPS`: k, the number of sample points along each axis of each element in
    /// the double area integral (paper 2.8; 1 means one point per element).
    pub integral_steps: u32,
}

/// One element: a planar convex triangle or quadrilateral, a piece of one surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Element {
    /// Index of the scene surface this element belongs to.
    pub surface: u32,
    corners: [u32; 4],
    corner_count: u8,
    /// Area (scene units squared).
    pub area: f64,
    /// Area centroid.
    pub centroid: DVec3,
    /// Unit front normal (the surface's normal).
    pub normal: DVec3,
}

impl Element {
    /// Indices into [`Mesh::vertices`] of the 3 or 4 corners, counter-clockwise from the front.
    pub fn corners(&self) -> &[u32] {
        &self.corners[..self.corner_count as usize]
    }

    /// True for a quadrilateral element.
    pub fn is_quad(&self) -> bool {
        self.corner_count == 4
    }
}

/// Surfaces cut into elements.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Corner positions. Each surface has its own vertices (see [`Mesh::surface_vertices`]).
    pub vertices: Vec<DVec3>,
    /// All elements, surface by surface.
    pub elements: Vec<Element>,
    /// For each surface, the range of its elements in [`Mesh::elements`].
    pub surface_elements: Vec<Range<u32>>,
    /// For each surface, the range of its vertices in [`Mesh::vertices`].
    pub surface_vertices: Vec<Range<u32>>,
    neighbour_offsets: Vec<u32>,
    neighbour_list: Vec<u32>,
    /// The display polygons, found on first use ([`Mesh::display`]).
    display: OnceLock<DisplayPolygons>,
}

/// Meshing cannot proceed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MeshError {
    /// `MAX_PATCH_AREA` is not a positive finite number.
    #[error("MAX_PATCH_AREA must be a positive number, got {0}")]
    BadMaxArea(f64),
    /// A surface is not a usable polygon ([`geometry::validate_polygon`]): the scene was
    /// not read by the scene reader, which refuses these with the file and line.
    #[error("surface {surface} ({name:?}) is not a usable polygon: {error}")]
    InvalidSurface {
        /// The surface's index in the scene.
        surface: usize,
        /// Its name.
        name: String,
        /// What is wrong with it.
        error: geometry::PolygonError,
    },
    /// An element came out with a zero or non-finite area (a surface at the edge of the
    /// supported range of scales cut very finely).
    #[error(
        "an element of surface {surface} has area {area}, not a positive finite number; \
         use a larger MAX_PATCH_AREA"
    )]
    BadElementArea {
        /// The surface the element belongs to.
        surface: usize,
        /// Its area.
        area: f64,
    },
    /// The subdivision would make more elements than the limit.
    #[error(
        "meshing with MAX_PATCH_AREA = {} would make {} elements, more than the \
         limit of {limit}; {}",
        compact(*max_area),
        if *count == u64::MAX { "more than 1.8e19".to_string() } else { count.to_string() },
        match suggested {
            Some(a) => format!("raise MAX_PATCH_AREA to at least {}", four_digits_up(*a)),
            None => format!(
                "no MAX_PATCH_AREA fits: the scene's {surfaces} surfaces make at least \
                 {fewest} elements at any area (one a surface, more for polygons of more \
                 than four corners); use fewer surfaces"
            ),
        }
    )]
    TooManyElements {
        /// The requested maximum element area.
        max_area: f64,
        /// The element count it would give.
        count: u64,
        /// The largest element count allowed.
        limit: u64,
        /// The largest maximum area that stays within the limit; `None` where none does
        /// (the surfaces alone make more elements than the limit).
        suggested: Option<f64>,
        /// The scene's surfaces.
        surfaces: usize,
        /// The fewest elements the scene meshes into, at any area.
        fewest: u64,
    },
}

/// `x` rounded up to four significant digits, plainly written where it is an everyday
/// number: a value to type back (QA of issue #16: "at least 2.522e-1").
pub fn four_digits_up(x: f64) -> String {
    if !(x.is_finite() && x > 0.0) {
        return compact(x);
    }
    let step = 10f64.powf(x.log10().floor() - 3.0);
    let up = (x / step).ceil() * step;
    // Printed from the digits, so no float noise (0.25220000000000004) shows.
    let decimals = (3.0 - x.log10().floor()).max(0.0) as usize;
    if (1e-4..1e15).contains(&up) {
        format!("{up:.decimals$}")
    } else {
        format!("{up:.3e}")
    }
}

/// `x` as Rust writes it where that is short (1e-4 to 1e15 in magnitude, or 0), else with
/// an exponent: a MAX_PATCH_AREA of 1e-300 is not three hundred zeros.
pub(crate) fn compact(x: f64) -> String {
    if x == 0.0 || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Elements a [`plan`] makes, counted in f64: a refused request may be astronomically large.
fn planned_count(plan: &Result<Plan, f64>) -> f64 {
    plan.map_or_else(|n| n, |p| p.element_count() as f64)
}

/// The elements [`mesh_scene`] makes of `scene` at MAX_PATCH_AREA `a` (before contact
/// refinement), counted in f64 from the plans without meshing: a refused request may be
/// astronomically large.
pub fn planned_elements(scene: &Scene, a: f64) -> f64 {
    scene
        .surfaces
        .iter()
        .map(|s| planned_count(&plan(&s.vertices, a)))
        .sum()
}

/// The fewest elements `scene` meshes into at any MAX_PATCH_AREA: at an area as large as
/// the whole scene's, every surface is one element, or a fan of triangles.
pub fn fewest_elements(scene: &Scene) -> f64 {
    planned_elements(scene, scene.total_area().max(f64::MIN_POSITIVE) * 2.0)
}

/// The largest MAX_PATCH_AREA at which `scene` meshes to at most `limit` elements
/// ([`MAX_ELEMENTS`] but in tests): a
/// property of the scene, found by bisection on the planned counts, so that the refusal
/// suggests the same value whatever too-small area was asked (QA of issue #16: 1.498e-5
/// against 1.500e-5 from the old proportional estimate). `None` where even the fewest
/// elements are too many (QA pass 14 of #16: a building of 11.6 million surfaces was told
/// to "raise" its area to one smaller than it had, after minutes of doubling).
pub fn largest_area_that_fits(scene: &Scene, limit: u64) -> Option<f64> {
    let limit = limit as f64;
    if fewest_elements(scene) > limit {
        return None;
    }
    let fallback = scene.total_area() / limit;
    if !(fallback > 0.0 && fallback.is_finite()) {
        return None;
    }
    // `fits` meshes within the limit, `over` does not; start from the area that the
    // limit's elements would have without rounding (every grid rounds up, so it is over).
    // Doubling ends by the scene's total area at the latest, where the fewest are made.
    let (mut over, mut fits) = (fallback, fallback);
    while planned_elements(scene, fits) > limit {
        fits *= 2.0;
    }
    if planned_elements(scene, over) <= limit {
        return Some(over);
    }
    // Geometric bisection to a relative width of 1e-9.
    while fits / over > 1.0 + 1e-9 {
        let mid = (over * fits).sqrt();
        if planned_elements(scene, mid) <= limit {
            fits = mid;
        } else {
            over = mid;
        }
    }
    Some(fits)
}

/// The most elements [`mesh_scene`] will make: about 1.2 GB of mesh (112 bytes per element
/// and about as many vertices of 24 bytes), enough for the million-element scenes that
/// progressive and hierarchical radiosity handle; larger requests are refused before any
/// allocation. (The dense solvers refuse much smaller problems: see
/// [`crate::pipeline::Prepared::check_memory`].)
pub const MAX_ELEMENTS: u64 = 8_000_000;

/// How one surface is cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Plan {
    /// A quadrilateral cut into `nu` x `nv` quadrilaterals.
    QuadGrid { nu: u32, nv: u32 },
    /// A fan of `fans` triangles (1 for a triangle), each cut into `m`^2 triangles.
    TriangleFan { fans: u32, m: u32 },
}

impl Plan {
    fn element_count(self) -> u64 {
        match self {
            Plan::QuadGrid { nu, nv } => nu as u64 * nv as u64,
            Plan::TriangleFan { fans, m } => fans as u64 * (m as u64).pow(2),
        }
    }
}

/// `x` rounded up to a whole number, but a whole number exceeded only by rounding (by
/// 1e-12 of it) rounded down to it: the area ratio of a 5 x 3 wall and a MAX_PATCH_AREA of
/// 0.25 is 60, and scaled by 0.001 (`--scale`: 0.005 x 0.003 against 0.25 x 0.001^2) it
/// can come out as 60.00000000000001, which must not make a 61st element (QA of issue #16:
/// the unit changed the mesh). The cells are checked against the area with the same slack.
fn ceil_relative(x: f64) -> f64 {
    (x * (1.0 - 1e-12)).ceil()
}

/// Plans the cut of one polygon so that no element exceeds `max_area`, or returns the
/// (estimated) element count when that would exceed [`MAX_ELEMENTS`] on its own, before any
/// integer could overflow or any loop run long.
fn plan(vertices: &[DVec3], max_area: f64) -> Result<Plan, f64> {
    let area = geometry::polygon_area(vertices);
    // Area alone needs this many elements; the cut below stays within a small factor of it.
    let target = ceil_relative(area / max_area).max(1.0);
    if target > MAX_ELEMENTS as f64 {
        return Err(target);
    }
    match vertices.len() {
        4 => {
            // Grid counts follow the mean lengths of opposite edges, so elements are near
            // square where the area allows (never more columns than the area needs: a
            // sliver within the area limit stays one element); then the finer direction
            // grows until the largest bilinear cell fits.
            let [a, b, c, d] = [vertices[0], vertices[1], vertices[2], vertices[3]];
            let lu = 0.5 * ((b - a).length() + (c - d).length());
            let lv = 0.5 * ((d - a).length() + (c - b).length());
            // In f64 and checked before the casts: a degenerate quad (a zero edge length,
            // a zero or infinite area) would make NaN, which casts to 0, and a grid of
            // 0 x 4,294,967,295. Surfaces are validated before planning; this keeps the
            // planner safe on its own.
            // Ties (3.5) and near-ties by rounding go up alike, whatever the unit.
            let nu_f = ((target * lu / lv).sqrt() * (1.0 + 1e-12))
                .round()
                .clamp(1.0, target);
            if !(nu_f.is_finite() && area.is_finite() && area > 0.0) {
                return Err(f64::INFINITY);
            }
            let nv_f = (target / nu_f).ceil().max(1.0);
            if nu_f * nv_f > MAX_ELEMENTS as f64 {
                return Err(nu_f * nv_f);
            }
            let (mut nu, mut nv) = (nu_f as u32, nv_f as u32);
            while max_quad_cell_area(vertices, nu, nv) > max_area * (1.0 + 1e-12) {
                if lu / nu as f64 >= lv / nv as f64 * (1.0 - 1e-12) {
                    nu += 1;
                } else {
                    nv += 1;
                }
                if nu as u64 * nv as u64 > MAX_ELEMENTS {
                    return Err(nu as f64 * nv as f64);
                }
            }
            Ok(Plan::QuadGrid { nu, nv })
        }
        k => {
            let fans = if k == 3 { 1 } else { k as u32 };
            let fan_areas =
                fan_triangles(vertices).map(|[a, b, c]| 0.5 * (b - a).cross(c - a).length());
            let largest = fan_areas.fold(0.0, f64::max);
            let m = ceil_relative((largest / max_area).sqrt()).max(1.0);
            if fans as f64 * m * m > MAX_ELEMENTS as f64 {
                return Err(fans as f64 * m * m);
            }
            Ok(Plan::TriangleFan { fans, m: m as u32 })
        }
    }
}

/// How [`mesh_scene`] cuts a polygon at `max_area`: `Some([nu, nv])` for a quadrilateral
/// cut into an nu x nv grid (u along corner 0 -> 1, v along 0 -> 3, as [`bilinear`]),
/// `Some([m, 0])` for a triangle, or each fan triangle of a larger polygon, cut into m^2;
/// `None` where meshing would refuse the surface. Hierarchical radiosity splits its patches
/// along these grid lines, so that its elements nest with the mesh's.
pub(crate) fn grid_of(vertices: &[DVec3], max_area: f64) -> Option<[u32; 2]> {
    if !(max_area.is_finite() && max_area > 0.0) {
        return None;
    }
    match plan(vertices, max_area).ok()? {
        Plan::QuadGrid { nu, nv } => Some([nu, nv]),
        Plan::TriangleFan { m, .. } => Some([m, 0]),
    }
}

/// The triangles a polygon is cut into before subdivision: itself for a triangle, otherwise
/// a fan from the area centroid (so the fan triangles are as fat as the polygon allows).
fn fan_triangles(vertices: &[DVec3]) -> impl Iterator<Item = [DVec3; 3]> + '_ {
    let k = vertices.len();
    let centre = geometry::polygon_centroid(vertices);
    let fans = if k == 3 { 1 } else { k };
    (0..fans).map(move |i| {
        if k == 3 {
            [vertices[0], vertices[1], vertices[2]]
        } else {
            [centre, vertices[i], vertices[(i + 1) % k]]
        }
    })
}

/// The point of the bilinear patch with corners `q` at parameters (u, v) in [0, 1]^2:
/// (0,0) -> q0, (1,0) -> q1, (1,1) -> q2, (0,1) -> q3.
pub fn bilinear(q: &[DVec3], u: f64, v: f64) -> DVec3 {
    (1.0 - u) * (1.0 - v) * q[0] + u * (1.0 - v) * q[1] + u * v * q[2] + (1.0 - u) * v * q[3]
}

/// |d/du x d/dv| of the bilinear map of [`bilinear`] at (u, v): the area a unit of
/// parameter area covers there.
pub(crate) fn bilinear_jacobian(q: &[DVec3], u: f64, v: f64) -> f64 {
    let du = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
    let dv = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
    du.cross(dv).length()
}

fn max_quad_cell_area(q: &[DVec3], nu: u32, nv: u32) -> f64 {
    // The Jacobian of a planar bilinear map is linear in u and v, so the largest cell lies
    // in a corner of the grid.
    let mut worst: f64 = 0.0;
    for (i, j) in [(0, 0), (nu - 1, 0), (0, nv - 1), (nu - 1, nv - 1)] {
        let p = |a: u32, b: u32| bilinear(q, a as f64 / nu as f64, b as f64 / nv as f64);
        let cell = [p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)];
        worst = worst.max(geometry::polygon_area(&cell));
    }
    worst
}

/// Cuts every surface of `scene` into elements of at most `max_area` (scene units squared).
///
/// Refuses, before allocating, a cut that would make more than [`MAX_ELEMENTS`] elements.
pub fn mesh_scene(scene: &Scene, max_area: f64) -> Result<Mesh, MeshError> {
    if !(max_area.is_finite() && max_area > 0.0) {
        return Err(MeshError::BadMaxArea(max_area));
    }
    // Every surface a usable polygon (finite, within the supported range of scales, of
    // non-zero area), so that the plans below are finite and no element has a zero or
    // infinite area.
    for (surface, s) in scene.surfaces.iter().enumerate() {
        geometry::validate_polygon(&s.vertices).map_err(|error| MeshError::InvalidSurface {
            surface,
            name: s.name.clone(),
            error,
        })?;
    }
    let planned: Vec<Result<Plan, f64>> = scene
        .surfaces
        .iter()
        .map(|s| plan(&s.vertices, max_area))
        .collect();
    let estimate: f64 = planned.iter().map(planned_count).sum();
    if estimate > MAX_ELEMENTS as f64 {
        let count = estimate.min(u64::MAX as f64) as u64;
        return Err(MeshError::TooManyElements {
            max_area,
            count,
            limit: MAX_ELEMENTS,
            suggested: largest_area_that_fits(scene, MAX_ELEMENTS),
            surfaces: scene.surfaces.len(),
            fewest: fewest_elements(scene).min(u64::MAX as f64) as u64,
        });
    }

    let plans: Vec<Plan> = planned
        .into_iter()
        .map(|p| p.expect("checked above"))
        .collect();
    let count: u64 = plans.iter().map(|p| p.element_count()).sum();
    let mut mesh = Mesh {
        elements: Vec::with_capacity(count as usize),
        ..Mesh::default()
    };
    for (s, (surface, plan)) in scene.surfaces.iter().zip(&plans).enumerate() {
        let first_vertex = mesh.vertices.len() as u32;
        let first_element = mesh.elements.len() as u32;
        let normal = geometry::polygon_normal(&surface.vertices).unwrap_or(DVec3::Z);
        match *plan {
            Plan::QuadGrid { nu, nv } => {
                mesh.add_quad_grid(s as u32, &surface.vertices, nu, nv, normal)
            }
            Plan::TriangleFan { m, .. } => {
                let mut shared = HashMap::new();
                for tri in fan_triangles(&surface.vertices) {
                    mesh.add_subdivided_triangle(s as u32, tri, m, normal, &mut shared);
                }
            }
        }
        mesh.surface_vertices
            .push(first_vertex..mesh.vertices.len() as u32);
        mesh.surface_elements
            .push(first_element..mesh.elements.len() as u32);
    }
    // The areas that every later stage divides by or weighs with.
    if let Some(e) = mesh
        .elements
        .iter()
        .find(|e| !(e.area.is_finite() && e.area > 0.0))
    {
        return Err(MeshError::BadElementArea {
            surface: e.surface as usize,
            area: e.area,
        });
    }
    mesh.build_neighbours();
    Ok(mesh)
}

impl Mesh {
    /// A mesh from given elements, surface by surface: `surfaces[s]` holds surface s's
    /// vertices, its elements (3 or 4 indices into those vertices, counter-clockwise from the
    /// front, planar and convex) and its unit normal. Used for the leaves of hierarchical
    /// radiosity, which may have T-junctions (neighbours are then only the elements that
    /// share a whole edge).
    pub(crate) fn from_surfaces(surfaces: Vec<(Vec<DVec3>, Vec<Vec<u32>>, DVec3)>) -> Mesh {
        let mut mesh = Mesh::default();
        for (s, (vertices, elements, normal)) in surfaces.into_iter().enumerate() {
            let first_vertex = mesh.vertices.len() as u32;
            let first_element = mesh.elements.len() as u32;
            mesh.vertices.extend(vertices);
            for corners in elements {
                let global: Vec<u32> = corners.iter().map(|&c| c + first_vertex).collect();
                mesh.push_element(s as u32, &global, normal);
            }
            mesh.surface_vertices
                .push(first_vertex..mesh.vertices.len() as u32);
            mesh.surface_elements
                .push(first_element..mesh.elements.len() as u32);
        }
        mesh.build_neighbours();
        mesh
    }
}

impl Mesh {
    /// This mesh with some elements replaced: `pieces[e]` is `None` where element e stays
    /// as it is, else the polygons it becomes (3 or 4 corners each, wound as e; none drops
    /// it). Surfaces keep their order and each element's pieces take its place, so the new
    /// elements come in the order of the old ones they came from. Vertices are shared
    /// within a surface where corners coincide to 1e-9 of its size ([`VertexWeld`]), so
    /// pieces conform with each other and with the elements left whole wherever their
    /// corners coincide (T-junctions remain where a
    /// split element meets one that was not). `surfaces` is the scene's surface count.
    pub(crate) fn with_pieces(&self, surfaces: usize, pieces: &[Option<Vec<Vec<DVec3>>>]) -> Mesh {
        let surfaces = (0..surfaces)
            .map(|s| {
                let range = self.surface_elements.get(s).cloned().unwrap_or(0..0);
                let mut vertices: Vec<DVec3> = Vec::new();
                let mut index = VertexWeld::new(self.surface_size(s));
                let mut id = |p: DVec3, vertices: &mut Vec<DVec3>| index.id(p, vertices);
                let mut elements: Vec<Vec<u32>> = Vec::new();
                for e in range.clone() {
                    let e = e as usize;
                    match &pieces[e] {
                        None => {
                            let ids = self
                                .corner_positions(e)
                                .map(|p| id(p, &mut vertices))
                                .collect();
                            elements.push(ids);
                        }
                        Some(pieces) => {
                            for piece in pieces {
                                elements
                                    .push(piece.iter().map(|&p| id(p, &mut vertices)).collect());
                            }
                        }
                    }
                }
                let normal = range
                    .clone()
                    .next()
                    .map(|e| self.elements[e as usize].normal)
                    .unwrap_or(DVec3::Z);
                (vertices, elements, normal)
            })
            .collect();
        Mesh::from_surfaces(surfaces)
    }
}

/// Corners within [`VertexWeld::TOLERANCE`] of a surface's size of each other are one
/// vertex: pieces cut along an outline at different quadtree levels, or by two lines in a
/// different order, compute the corner where a cut meets a shared edge from different ends,
/// a bit or two apart (review of #11); as two vertices the edge would not be shared (no
/// neighbours across it, a crack in the display).
struct VertexWeld {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl VertexWeld {
    /// 1e-9 of the surface's size: far above the rounding of a cut's corner (1e-16), far
    /// below the thinnest part a cut makes (`outline_cut::ON_LINE`, 1e-4 of a piece).
    const TOLERANCE: f64 = 1e-9;

    fn new(size: f64) -> VertexWeld {
        VertexWeld {
            cell: (Self::TOLERANCE * size).max(f64::MIN_POSITIVE),
            cells: HashMap::new(),
        }
    }

    /// The index of `p` in `vertices`: a vertex already there within the tolerance, or `p`
    /// pushed.
    fn id(&mut self, p: DVec3, vertices: &mut Vec<DVec3>) -> u32 {
        let key = (p / self.cell).floor().to_array().map(|c| c as i64);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let k = [
                        key[0].saturating_add(dx),
                        key[1].saturating_add(dy),
                        key[2].saturating_add(dz),
                    ];
                    if let Some(ids) = self.cells.get(&k) {
                        for &i in ids {
                            if (vertices[i as usize] - p).length() <= self.cell {
                                return i;
                            }
                        }
                    }
                }
            }
        }
        vertices.push(p);
        let i = vertices.len() as u32 - 1;
        self.cells.entry(key).or_default().push(i);
        i
    }
}

impl Mesh {
    /// The length of the diagonal of the box round surface `s`'s vertices (0 for none).
    fn surface_size(&self, s: usize) -> f64 {
        let range = self.surface_vertices.get(s).cloned().unwrap_or(0..0);
        let (lo, hi) = geometry::bounds(range.map(|v| self.vertices[v as usize]));
        if lo.x <= hi.x {
            (hi - lo).length()
        } else {
            0.0
        }
    }

    /// The number of elements.
    pub fn len(&self) -> usize {
        self.elements.len()
    }

    /// True when the mesh has no elements.
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }

    /// The corner positions of element `e`.
    pub fn corner_positions(&self, e: usize) -> impl ExactSizeIterator<Item = DVec3> + '_ {
        self.elements[e]
            .corners()
            .iter()
            .map(|&v| self.vertices[v as usize])
    }

    /// Every element's display polygon (its corners and the T-vertices on its edges) and
    /// triangles, found on the first call (see [`DisplayPolygons`]). Smooth shading, the
    /// renderer and the viewer draw these, so that a mesh with T-junctions shows no seams.
    pub fn display(&self) -> &DisplayPolygons {
        self.display.get_or_init(|| DisplayPolygons::new(self))
    }

    /// The elements that share an edge with element `e` on the same surface.
    pub fn neighbours(&self, e: usize) -> &[u32] {
        let lo = self.neighbour_offsets[e] as usize;
        let hi = self.neighbour_offsets[e + 1] as usize;
        &self.neighbour_list[lo..hi]
    }

    /// The total area of all elements.
    pub fn total_area(&self) -> f64 {
        self.elements.iter().map(|e| e.area).sum()
    }

    /// Appends to `out` the `k` x `k` midpoint-rule integration points of element `e` with
    /// their area weights (which sum to the element's area).
    ///
    /// A quadrilateral is sampled at the centres of a k x k grid in its bilinear parameters,
    /// weighted by the bilinear Jacobian; a triangle at the centroids of its k^2 congruent
    /// sub-triangles, each weighted area / k^2.
    pub fn integration_points(&self, e: usize, k: u32, out: &mut Vec<(DVec3, f64)>) {
        let el = &self.elements[e];
        let p: Vec<DVec3> = self.corner_positions(e).collect();
        let kf = k as f64;
        if el.is_quad() {
            let start = out.len();
            let mut total = 0.0;
            for j in 0..k {
                for i in 0..k {
                    let (u, v) = ((i as f64 + 0.5) / kf, (j as f64 + 0.5) / kf);
                    // The Jacobian times the cell's parameter area.
                    let w = bilinear_jacobian(&p, u, v) / (kf * kf);
                    total += w;
                    out.push((bilinear(&p, u, v), w));
                }
            }
            // Rescale so the weights sum exactly to the element area (the midpoint Jacobian
            // is exact for parallelograms and second-order accurate otherwise).
            let scale = if total > 0.0 { el.area / total } else { 0.0 };
            for (_, w) in &mut out[start..] {
                *w *= scale;
            }
        } else {
            let w = el.area / (kf * kf);
            for_each_subtriangle([p[0], p[1], p[2]], k, |t| {
                out.push(((t[0] + t[1] + t[2]) / 3.0, w))
            });
        }
    }

    fn push_element(&mut self, surface: u32, corners: &[u32], normal: DVec3) {
        let pos: Vec<DVec3> = corners.iter().map(|&c| self.vertices[c as usize]).collect();
        let mut c = [u32::MAX; 4];
        c[..corners.len()].copy_from_slice(corners);
        self.elements.push(Element {
            surface,
            corners: c,
            corner_count: corners.len() as u8,
            area: geometry::polygon_area(&pos),
            centroid: geometry::polygon_centroid(&pos),
            normal,
        });
    }

    fn add_quad_grid(&mut self, surface: u32, q: &[DVec3], nu: u32, nv: u32, normal: DVec3) {
        let base = self.vertices.len() as u32;
        for j in 0..=nv {
            for i in 0..=nu {
                self.vertices
                    .push(bilinear(q, i as f64 / nu as f64, j as f64 / nv as f64));
            }
        }
        let id = |i: u32, j: u32| base + j * (nu + 1) + i;
        for j in 0..nv {
            for i in 0..nu {
                self.push_element(
                    surface,
                    &[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)],
                    normal,
                );
            }
        }
    }

    /// Cuts triangle `t` into m^2 triangles on the lattice of points
    /// t0 + (a/m)(t1 - t0) + (b/m)(t2 - t0). Lattice points are shared through `shared`
    /// (keyed by exact position), so fan triangles of one surface meet conformingly.
    fn add_subdivided_triangle(
        &mut self,
        surface: u32,
        t: [DVec3; 3],
        m: u32,
        normal: DVec3,
        shared: &mut HashMap<[u64; 3], u32>,
    ) {
        let mf = m as f64;
        let mut index = |mesh: &mut Mesh, a: u32, b: u32| -> u32 {
            // Edge points are computed from the edge's two ends only, so that the fan
            // triangle on the other side of the edge computes bit-identical positions.
            let p = lattice_point(t, a, b, mf);
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            *shared.entry(key).or_insert_with(|| {
                mesh.vertices.push(p);
                mesh.vertices.len() as u32 - 1
            })
        };
        for b in 0..m {
            for a in 0..m - b {
                let (p00, p10, p01) = (
                    index(self, a, b),
                    index(self, a + 1, b),
                    index(self, a, b + 1),
                );
                self.push_element(surface, &[p00, p10, p01], normal);
                if a + b + 1 < m {
                    let p11 = index(self, a + 1, b + 1);
                    self.push_element(surface, &[p10, p11, p01], normal);
                }
            }
        }
    }

    fn build_neighbours(&mut self) {
        // Two elements are neighbours when they share an edge (a pair of corner indices);
        // corner indices are per surface, so neighbours never cross surfaces.
        let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        for (e, el) in self.elements.iter().enumerate() {
            let c = el.corners();
            for i in 0..c.len() {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                edges
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(e as u32);
            }
        }
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); self.elements.len()];
        for owners in edges.values() {
            for &x in owners {
                for &y in owners {
                    if x != y {
                        lists[x as usize].push(y);
                    }
                }
            }
        }
        self.neighbour_offsets = Vec::with_capacity(lists.len() + 1);
        self.neighbour_offsets.push(0);
        self.neighbour_list.clear();
        for mut l in lists {
            l.sort_unstable();
            l.dedup();
            self.neighbour_list.extend_from_slice(&l);
            self.neighbour_offsets
                .push(self.neighbour_list.len() as u32);
        }
    }
}

/// The lattice point (a, b) of triangle `t` cut into `m` along each edge. Points on an edge
/// are interpolated between that edge's two ends alone, so neighbouring triangles that share
/// the edge compute bit-identical positions.
fn lattice_point(t: [DVec3; 3], a: u32, b: u32, m: f64) -> DVec3 {
    let (a, b) = (a as f64, b as f64);
    let c = m - a - b;
    if b == 0.0 {
        t[0] + (a / m) * (t[1] - t[0])
    } else if a == 0.0 {
        t[0] + (b / m) * (t[2] - t[0])
    } else if c == 0.0 {
        t[1] + (b / m) * (t[2] - t[1])
    } else {
        (c * t[0] + a * t[1] + b * t[2]) / m
    }
}

/// Calls `f` with each of the k^2 congruent sub-triangles of `t`.
pub fn for_each_subtriangle(t: [DVec3; 3], k: u32, mut f: impl FnMut([DVec3; 3])) {
    let kf = k as f64;
    let p = |a: u32, b: u32| lattice_point(t, a, b, kf);
    for b in 0..k {
        for a in 0..k - b {
            f([p(a, b), p(a + 1, b), p(a, b + 1)]);
            if a + b + 1 < k {
                f([p(a + 1, b), p(a + 1, b + 1), p(a, b + 1)]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Rgb, Surface};
    use glam::dvec3;

    #[test]
    fn pieces_whose_shared_corner_differs_by_rounding_share_one_vertex() {
        // A 2 x 1 floor of two 1 x 1 elements, each replaced by two pieces cut at z = 0.3,
        // the left ones' cut corner on the shared edge x = 1 a bit off the right ones' (as
        // when the two sides computed it from different ends). Welded, the pieces share it:
        // the 3 x 3 lattice of corners, 9 vertices (10 unwelded), and every piece has two
        // neighbours (the one above or below it and the one across x = 1).
        let floor = vec![
            dvec3(0., 0., 0.),
            dvec3(0., 0., 1.),
            dvec3(2., 0., 1.),
            dvec3(2., 0., 0.),
        ];
        let mesh = mesh_scene(&scene_of(vec![floor]), 1.0).unwrap();
        assert_eq!(mesh.len(), 2);
        let x_of = |e: usize| mesh.corner_positions(e).map(|p| p.x).sum::<f64>() / 4.0;
        let (left, right) = if x_of(0) < x_of(1) { (0, 1) } else { (1, 0) };
        let off = f64::from_bits(0.3f64.to_bits() + 1);
        let halves = |x0: f64, z_mid_left: f64, z_mid_right: f64| {
            vec![
                vec![
                    dvec3(x0, 0., 0.),
                    dvec3(x0, 0., z_mid_left),
                    dvec3(x0 + 1., 0., z_mid_right),
                    dvec3(x0 + 1., 0., 0.),
                ],
                vec![
                    dvec3(x0, 0., z_mid_left),
                    dvec3(x0, 0., 1.),
                    dvec3(x0 + 1., 0., 1.),
                    dvec3(x0 + 1., 0., z_mid_right),
                ],
            ]
        };
        let mut pieces = vec![None, None];
        pieces[left] = Some(halves(0., 0.3, off));
        pieces[right] = Some(halves(1., 0.3, 0.3));
        let cut = mesh.with_pieces(1, &pieces);
        assert_eq!(cut.len(), 4);
        assert_eq!(cut.vertices.len(), 9, "{:?}", cut.vertices);
        for e in 0..4 {
            assert_eq!(cut.neighbours(e).len(), 2, "element {e}");
        }
    }

    fn scene_of(polys: Vec<Vec<DVec3>>) -> Scene {
        Scene {
            surfaces: polys
                .into_iter()
                .enumerate()
                .map(|(i, vertices)| Surface {
                    name: format!("s{i}"),
                    emission: Rgb::BLACK,
                    reflectance: Rgb([0.5; 3]),
                    vertices,
                    photometry: Default::default(),
                })
                .collect(),
            camera: None,
            lights: Vec::new(),
        }
    }

    fn rect(w: f64, h: f64) -> Vec<DVec3> {
        vec![
            dvec3(0., 0., 0.),
            dvec3(w, 0., 0.),
            dvec3(w, h, 0.),
            dvec3(0., h, 0.),
        ]
    }

    fn check_invariants(scene: &Scene, mesh: &Mesh, max_area: f64) {
        for (s, surf) in scene.surfaces.iter().enumerate() {
            let range = mesh.surface_elements[s].clone();
            let sum: f64 = range.clone().map(|e| mesh.elements[e as usize].area).sum();
            let a = geometry::polygon_area(&surf.vertices);
            assert!(
                (sum - a).abs() < 1e-9 * a,
                "surface {s}: elements cover {sum}, surface {a}"
            );
            for e in range {
                let el = &mesh.elements[e as usize];
                assert!(
                    el.area <= max_area * (1.0 + 1e-9),
                    "element {e} area {} > {max_area}",
                    el.area
                );
                assert!(el.area > 0.0);
                let pos: Vec<DVec3> = mesh.corner_positions(e as usize).collect();
                assert!(geometry::is_convex(&pos), "element {e} not convex");
                assert!((geometry::polygon_normal(&pos).unwrap() - el.normal).length() < 1e-9);
            }
        }
    }

    /// The unit does not change the grid (QA of issue #16): a 5 x 3 wall under 0.25 is 60
    /// cells of 0.25 (15 / 0.25), in metres, millimetres or kilometres, where the ratio of
    /// the scaled areas can exceed 60 by rounding.
    #[test]
    fn the_grid_does_not_depend_on_the_unit() {
        for scale in [1.0, 0.001, 1000.0, 0.1, 3.0] {
            let wall: Vec<DVec3> = rect(5.0, 3.0).into_iter().map(|v| v * scale).collect();
            let mesh = mesh_scene(&scene_of(vec![wall]), 0.25 * scale * scale).unwrap();
            assert_eq!(mesh.len(), 60, "scale {scale}");
        }
    }

    #[test]
    fn rectangle_grid_is_near_square() {
        let scene = scene_of(vec![rect(4.0, 1.0)]);
        let mesh = mesh_scene(&scene, 0.25).unwrap();
        assert_eq!(mesh.len(), 16); // 8 x 2 cells of 0.5 x 0.5
        check_invariants(&scene, &mesh, 0.25);
        for el in &mesh.elements {
            assert!((el.area - 0.25).abs() < 1e-12);
        }
        assert_eq!(mesh.vertices.len(), 9 * 3);
    }

    #[test]
    fn small_surface_is_one_element() {
        let scene = scene_of(vec![rect(1.0, 1.0)]);
        let mesh = mesh_scene(&scene, 2.0).unwrap();
        assert_eq!(mesh.len(), 1);
        assert!(mesh.neighbours(0).is_empty());
    }

    #[test]
    fn trapezoid_cells_all_fit() {
        let q = vec![
            dvec3(0., 0., 0.),
            dvec3(10., 0., 0.),
            dvec3(7., 3., 0.),
            dvec3(2., 3., 0.),
        ];
        let scene = scene_of(vec![q]);
        let mesh = mesh_scene(&scene, 0.7).unwrap();
        check_invariants(&scene, &mesh, 0.7);
    }

    #[test]
    fn triangle_and_pentagon_are_conforming() {
        let tri = vec![dvec3(0., 0., 0.), dvec3(3., 0., 0.), dvec3(0., 3., 1.)];
        let pent: Vec<DVec3> = (0..5)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 5.0;
                dvec3(2.0 * a.cos(), 2.0 * a.sin(), 5.0)
            })
            .collect();
        let scene = scene_of(vec![tri, pent]);
        let mesh = mesh_scene(&scene, 0.3).unwrap();
        check_invariants(&scene, &mesh, 0.3);
        // Conforming: every interior edge is shared by exactly two elements, so Euler's
        // formula for a disc holds: V - E + F = 1 on each surface.
        for s in 0..2 {
            let mut edges = std::collections::HashSet::new();
            for e in mesh.surface_elements[s].clone() {
                let c = mesh.elements[e as usize].corners();
                for i in 0..c.len() {
                    let (a, b) = (c[i], c[(i + 1) % c.len()]);
                    edges.insert((a.min(b), a.max(b)));
                }
            }
            let v = mesh.surface_vertices[s].len() as i64;
            let f = mesh.surface_elements[s].len() as i64;
            assert_eq!(
                v - edges.len() as i64 + f,
                1,
                "surface {s} is not a conforming disc"
            );
        }
    }

    #[test]
    fn neighbours_of_grid_cell() {
        let scene = scene_of(vec![rect(3.0, 3.0)]);
        let mesh = mesh_scene(&scene, 1.0).unwrap();
        assert_eq!(mesh.len(), 9);
        assert_eq!(mesh.neighbours(4), &[1, 3, 5, 7]); // the centre cell
        assert_eq!(mesh.neighbours(0), &[1, 3]);
    }

    #[test]
    fn integration_weights_sum_to_area() {
        let q = vec![
            dvec3(0., 0., 0.),
            dvec3(10., 0., 0.),
            dvec3(7., 3., 0.),
            dvec3(2., 3., 0.),
        ];
        let tri = vec![dvec3(0., 0., 0.), dvec3(3., 0., 0.), dvec3(0., 3., 1.)];
        let scene = scene_of(vec![q, tri]);
        let mesh = mesh_scene(&scene, 100.0).unwrap();
        for e in 0..mesh.len() {
            for k in 1..5 {
                let mut pts = Vec::new();
                mesh.integration_points(e, k, &mut pts);
                assert_eq!(pts.len(), (k * k) as usize);
                let w: f64 = pts.iter().map(|p| p.1).sum();
                assert!((w - mesh.elements[e].area).abs() < 1e-12 * w);
                // The weighted mean of the points is the centroid for a triangle exactly;
                // for the trapezoid the midpoint rule is within its O(1/k^2) error.
                let c = pts.iter().map(|p| p.0 * p.1).sum::<DVec3>() / w;
                assert!((c - mesh.elements[e].centroid).length() < 0.2 / (k * k) as f64);
            }
        }
    }

    #[test]
    fn refuses_absurd_areas_at_once() {
        // Regression (QA): these overflowed u32 grid counts and then looped for ever.
        for tiny in [1e-16, 1e-30, 1e-300] {
            let scene = scene_of(vec![
                rect(1.0, 1.0),
                vec![dvec3(0., 0., 1.), dvec3(3., 0., 1.), dvec3(0., 3., 1.)],
            ]);
            assert!(matches!(
                mesh_scene(&scene, tiny),
                Err(MeshError::TooManyElements { .. })
            ));
        }
    }

    #[test]
    fn sliver_within_the_area_limit_is_one_element() {
        let scene = scene_of(vec![rect(1.0, 1e-7)]);
        assert_eq!(mesh_scene(&scene, 0.5).unwrap().len(), 1);
    }

    #[test]
    fn refuses_too_many_elements_before_allocating() {
        let scene = scene_of(vec![rect(1000.0, 1000.0)]);
        let err = mesh_scene(&scene, 1e-3).unwrap_err();
        assert!(matches!(err, MeshError::TooManyElements { count, .. } if count >= 1_000_000_000));
        assert_eq!(
            mesh_scene(&scene, 0.0).unwrap_err(),
            MeshError::BadMaxArea(0.0)
        );
    }

    /// QA pass 14 of #16: a scene whose surfaces alone are more elements than the limit
    /// was told to "raise" its area to one smaller than it had; no area fits such a scene.
    #[test]
    fn no_area_is_suggested_where_the_surfaces_alone_are_too_many() {
        // Twelve unit squares: twelve elements at the fewest, 48 at area 0.25.
        let scene = scene_of((0..12).map(|_| rect(1.0, 1.0)).collect());
        assert_eq!(fewest_elements(&scene), 12.0);
        assert_eq!(largest_area_that_fits(&scene, 11), None);
        // Within 48 elements: every square cut 2 x 2 (area 0.25) and no finer; the
        // bisection stops within 1e-9 of the boundary.
        let a = largest_area_that_fits(&scene, 48).unwrap();
        assert!((0.25..0.25 * (1.0 + 2e-9)).contains(&a), "{a}");
        let e = MeshError::TooManyElements {
            max_area: 1.0,
            count: 16_638_582,
            limit: MAX_ELEMENTS,
            suggested: None,
            surfaces: 11_616_000,
            fewest: 11_616_000,
        };
        assert!(
            e.to_string().ends_with(
                "limit of 8000000; no MAX_PATCH_AREA fits: the scene's 11616000 surfaces \
                 make at least 11616000 elements at any area (one a surface, more for \
                 polygons of more than four corners); use fewer surfaces"
            ),
            "{e}"
        );
    }
}
