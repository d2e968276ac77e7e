//! The ray caster: a BVH of the mesh's elements ([`Renderer`]) that colours the element a
//! ray hits first in one of the paper's three display modes ([`Shading`]):
//!
//! * [`Shading::Flat`] (plate 1): every element in its own radiosity.
//! * [`Shading::Smooth`] (plate 2, section 2.5): the vertex radiosities of
//!   [`crate::shade::vertex_radiosity`] interpolated across the element, bilinearly on a
//!   quadrilateral (as OpenGL's Gouraud shading of a quad approximates, [`inverse_bilinear`])
//!   and barycentrically on a triangle ([`barycentric`]).
//! * [`Shading::Wireframe`] (plate 4): element edges as white lines about one pixel wide
//!   on black. Unlike the paper's OpenGL line mode, hidden lines are removed (only edges of
//!   the element a ray hits first are drawn).
//!
//! Surfaces are one-sided: a ray that reaches the back of an element sees black (the back
//! reflects and emits nothing). A ray that hits nothing sees black. Given the scene
//! ([`Renderer::for_settings`]), a ray that meets a surface where no element covers it (a
//! buried piece dropped, seen through a gap) sees the nearest element's light there
//! ([`super::holes`]), not what lies behind the surface.
//!
//! [`Renderer::film`] casts the rays of a view, n x n per pixel, in parallel by rows, and
//! writes what each sees into a linear [`Film`]: radiosity for flat and smooth shading,
//! line coverage for wireframe. Exposure and gamma come after, in
//! [`crate::render::tonemap`].

use std::collections::HashMap;
use std::ops::Range;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::adaptive::{brighter_beside, refinement, FirstRows, Refine, Seen};
use super::direct::DirectCorrection;
use super::film::{sample_offset, Film, FilmContent};
use super::holes::{closest_on_segment, nearest_element, Holes, Uncovered};
use super::Camera;
use crate::mesh::Mesh;
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::Scene;
use crate::visibility::PolygonBvh;

/// The camera's near distance, relative to the scene's bounding-box diagonal.
const CAMERA_NEAR: f64 = 1e-9;

/// How the hit element is coloured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Shading {
    /// Vertex radiosities interpolated across each element (paper 2.5, plate 2).
    #[default]
    Smooth,
    /// Each element in its own radiosity (plate 1).
    Flat,
    /// White element edges on black, hidden lines removed (plate 4).
    Wireframe,
}

/// The mesh of a scene, in a BVH of its elements (one polygon per element, tagged with the
/// element index), ready to render any number of views.
pub struct Renderer<'m> {
    mesh: &'m Mesh,
    bvh: PolygonBvh,
    /// Bounding box of all vertices (min, max).
    bounds: (DVec3, DVec3),
    /// Per element, bit i set when edge i (corner i to corner i + 1) is on the boundary of
    /// its surface (no other element lies beyond it, whole or in pieces).
    boundary_edges: Vec<u8>,
    /// Smooth shading's direct light gathered per ray, when asked for
    /// ([`Renderer::with_direct_light`]).
    direct: Option<DirectCorrection<'m>>,
    /// Adaptive antialiasing's contrast threshold, when on ([`Renderer::with_adaptive_sampling`]).
    adaptive: Option<f64>,
    /// The scene's surfaces, where rays meet the holes that dropped buried pieces leave
    /// ([`Renderer::with_holes_covered`]).
    holes: Option<Holes>,
    /// A ray that meets a hole's front counts whole, not times its open share
    /// ([`Renderer::counting_coverage`]).
    coverage: bool,
}

impl<'m> Renderer<'m> {
    /// Builds the element BVH of `mesh`.
    pub fn new(mesh: &'m Mesh) -> Renderer<'m> {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in &mesh.vertices {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        // Edges of the display polygons (T-vertices included), so that an element's edge
        // with smaller elements on its far side is not taken for the surface's boundary.
        let display = mesh.display();
        let edge = |polygon: &[u32], k: usize| {
            let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
            (a.min(b), a.max(b))
        };
        let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
        for e in 0..mesh.len() {
            let polygon = display.polygon(e);
            for k in 0..polygon.len() {
                *uses.entry(edge(polygon, k)).or_default() += 1;
            }
        }
        let boundary_edges = mesh
            .elements
            .iter()
            .enumerate()
            .map(|(e, el)| {
                // Element edge i starts at corner i; its first display edge says whether
                // another element lies beyond it.
                let polygon = display.polygon(e);
                let corners = el.corners();
                let mut mask = 0u8;
                let mut i = 0;
                for k in 0..polygon.len() {
                    if i < corners.len() && polygon[k] == corners[i] {
                        if uses[&edge(polygon, k)] == 1 {
                            mask |= 1 << i;
                        }
                        i += 1;
                    }
                }
                mask
            })
            .collect();
        Renderer {
            mesh,
            bvh: PolygonBvh::over_elements(mesh),
            bounds: (lo, hi),
            boundary_edges,
            direct: None,
            adaptive: None,
            holes: None,
            coverage: false,
        }
    }

    /// For a render of ones that says which share of each pixel's rays met a front: a ray
    /// that meets a hole's front (a dropped buried piece seen through a gap) counts 1, not
    /// its open share (QA of issue #16: `--false-colour` divides the illuminance by this
    /// share, and the gap above a light panel, open share 0, came out as background white).
    pub fn counting_coverage(mut self) -> Renderer<'m> {
        self.coverage = true;
        self
    }

    /// The renderer of `mesh` (cut from `scene`) that `settings` ask for: with the direct
    /// light gathered and adaptive antialiasing when they say so.
    pub fn for_settings(
        mesh: &'m Mesh,
        scene: &Scene,
        settings: &super::RenderSettings,
    ) -> Renderer<'m> {
        let mut renderer = Renderer::new(mesh)
            .with_surfaces_on_top(scene)
            .with_holes_covered(scene);
        if settings.direct_light {
            renderer = renderer.with_direct_light(scene);
        }
        if let Some(contrast) = settings.adaptive_contrast {
            renderer = renderer.with_adaptive_sampling(contrast);
        }
        renderer
    }

    /// The mesh being rendered.
    pub fn mesh(&self) -> &'m Mesh {
        self.mesh
    }

    /// From now on a ray that meets a surface of `scene` (from which the mesh was cut) and
    /// one lying on it ([`crate::scene::lying_on`]: a rug in the floor's plane) at the same
    /// distance sees the one on top: the elements of the surfaces on top are found as if
    /// [`crate::scene::overlap::SAME_PLANE_GAP`] of the scene's size in front of their plane
    /// (1e-7: far above the rounding of a ray's distance, far below a pixel). Without it, a
    /// mesh that keeps the floor under the rug (hierarchical radiosity's leaves) shows the
    /// floor through the rug wherever rounding picks it.
    pub fn with_surfaces_on_top(mut self, scene: &Scene) -> Renderer<'m> {
        let occluders = PolygonBvh::over_surfaces(scene);
        let pairs = crate::scene::lying_on(scene, &occluders);
        if pairs.is_empty() {
            return self;
        }
        let mut on_top = vec![false; scene.surfaces.len()];
        for o in &pairs {
            on_top[o.upper as usize] = true;
        }
        let lift = crate::scene::overlap::SAME_PLANE_GAP * occluders.scale();
        let polygons: Vec<Vec<DVec3>> = (0..self.mesh.len())
            .map(|e| {
                let el = &self.mesh.elements[e];
                let up = if on_top.get(el.surface as usize) == Some(&true) {
                    lift * el.normal
                } else {
                    DVec3::ZERO
                };
                self.mesh.corner_positions(e).map(|p| p + up).collect()
            })
            .collect();
        let ids: Vec<u32> = (0..self.mesh.len() as u32).collect();
        self.bvh = PolygonBvh::new(&polygons, &ids);
        self
    }

    /// From now on a ray that meets a surface of `scene` (from which the mesh was cut)
    /// where no element covers it, nearer than any element, shows the light of that
    /// surface's nearest element there, or black at the back of the surface, instead of
    /// passing through (see [`super::holes`]).
    pub fn with_holes_covered(mut self, scene: &Scene) -> Renderer<'m> {
        self.holes = Some(Holes::new(scene));
        self
    }

    /// Smooth shading from now on gathers the direct light of `scene` (from which the mesh
    /// was cut) at every ray's hit point, with Lambert's formula and shadow rays, and takes
    /// only the indirect light's variation from the mesh (see [`DirectCorrection`]).
    pub fn with_direct_light(mut self, scene: &Scene) -> Renderer<'m> {
        self.direct = Some(DirectCorrection::new(scene, self.mesh));
        self
    }

    /// From now on an even supersampling n > 2 is adaptive: each pixel first casts four
    /// rays, at the centres of its quadrants, and casts the full n x n grid only when they
    /// see different surfaces (a silhouette, a miss) or luminances that spread by more than
    /// `contrast` times the largest of them (a shadow edge); otherwise each of the four
    /// stands for its quadrant, and the pixel is what plain 2 x 2 supersampling gives
    /// (Whitted 1980, "An improved illumination model for shaded display", CACM 23, section
    /// 4's adaptive subdivision of pixels). Wireframe is never adaptive (its lines are
    /// thinner than a quadrant).
    pub fn with_adaptive_sampling(mut self, contrast: f64) -> Renderer<'m> {
        self.adaptive = Some(contrast);
        self
    }

    /// True when smooth shading gathers the direct light per ray.
    pub fn gathers_direct_light(&self) -> bool {
        self.direct.is_some()
    }

    /// The linear film of `camera`'s view, `supersample` x `supersample` rays a pixel (0 is
    /// treated as 1), before exposure and gamma: turn it into an image with
    /// [`crate::render::tonemap::to_image`]. `element_b`, `vertex_b` and the progress report
    /// are as for [`crate::render::render`], which is this followed by the tone map (in
    /// strips of rows, so that it never holds the samples of a whole large image).
    ///
    /// The film holds 24 bytes per sample: `24 n^2 width height` in all.
    ///
    /// # Panics
    /// If `element_b` (or, for smooth shading, `vertex_b`) has the wrong length.
    pub fn film(
        &self,
        camera: &Camera,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        shading: Shading,
        supersample: u32,
        progress: &dyn Progress,
    ) -> Film {
        self.check_inputs(element_b, vertex_b, shading);
        let (w, h) = (camera.width as usize, camera.height as usize);
        let n = supersample.max(1) as usize;
        if w == 0 || h == 0 {
            return Film::new(w, h, n, film_content(shading));
        }
        run_stage(progress, Stage::Render, h as u64, || {
            let mut carried = FirstRows::default();
            self.film_rows(
                camera,
                0..h,
                element_b,
                vertex_b,
                shading,
                n,
                &mut carried,
                progress,
            )
        })
    }

    /// Asserts that there is one radiosity per element and, for smooth shading, one per
    /// vertex.
    pub(super) fn check_inputs(
        &self,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        shading: Shading,
    ) {
        assert_eq!(
            element_b.len(),
            self.mesh.len(),
            "one radiosity per element"
        );
        if shading == Shading::Smooth {
            assert_eq!(
                vertex_b.len(),
                self.mesh.vertices.len(),
                "one radiosity per vertex"
            );
        }
    }

    /// The film of the image rows `rows` of `camera`'s view (film row 0 is image row
    /// `rows.start`), `n` x `n` rays a pixel: the ray loop. Rows are traced in parallel;
    /// each finished row is reported as `progress.advance(1)`. Under adaptive sampling the
    /// first rays of the rows `carried` holds are taken from it, not cast again, and it is
    /// left holding those of the last two rows looked at (the next strip's first row and
    /// the one above it).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn film_rows(
        &self,
        camera: &Camera,
        rows: Range<usize>,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        shading: Shading,
        n: usize,
        carried: &mut FirstRows,
        progress: &dyn Progress,
    ) -> Film {
        let mut film = Film::new(camera.width as usize, rows.len(), n, film_content(shading));
        let screen = camera.screen();
        let footprint = camera.pixel_angle();
        let adaptive = self
            .adaptive
            .filter(|_| n > 2 && n % 2 == 0 && shading != Shading::Wireframe);
        let width = camera.width as usize;
        // What ray (sx, sy) of pixel `index` sees. Each ray of the pixel jitters the direct
        // light's strata its own way (see `direct`), so that a pixel's rays average the
        // shadow rays' noise.
        let seen = |index: u64, sx: f64, sy: f64| {
            let dir = camera.direction_in(screen, sx, sy);
            let salt = crate::splitmix::splitmix64(
                index ^ sx.to_bits().rotate_left(17) ^ sy.to_bits().rotate_left(41),
            );
            self.trace(
                camera.eye, dir, footprint, element_b, vertex_b, shading, salt,
            )
        };
        let first_rays = |x: usize, y: usize| -> [Seen; 4] {
            let index = (y * width + x) as u64;
            std::array::from_fn(|q| {
                let (i, j) = ((q % 2) as f64, (q / 2) as f64);
                seen(index, x as f64 + 0.25 + 0.5 * i, y as f64 + 0.25 + 0.5 * j)
            })
        };
        // Under adaptive sampling, the four first rays of every pixel of these rows and of
        // the rows either side, so that a pixel can look at its neighbours' (see
        // `brighter_beside`).
        let around = rows.start.saturating_sub(1)..(rows.end + 1).min(camera.height as usize);
        let firsts: Vec<[Seen; 4]> = if adaptive.is_some() {
            // The rows the last strip left that begin this one's, then the rest, pixel by
            // pixel, so that a strip of a few rows still keeps every core busy.
            let kept_rows = carried.rays.len() / width.max(1);
            let mut firsts = if carried.start == around.start && kept_rows <= around.len() {
                std::mem::take(&mut carried.rays)
            } else {
                Vec::new()
            };
            let from = around.start + firsts.len() / width.max(1);
            firsts.par_extend(
                (0..(around.end - from) * width)
                    .into_par_iter()
                    .map(|i| first_rays(i % width, from + i / width)),
            );
            // The last two rows for the next strip (rows.end - 1 and rows.end).
            let keep = around.len().min(2);
            *carried = FirstRows {
                start: around.end - keep,
                rays: firsts[(around.len() - keep) * width..].to_vec(),
            };
            firsts
        } else {
            Vec::new()
        };
        let first_at = |x: usize, y: usize| &firsts[(y - around.start) * width + x];
        film.par_rows_mut().for_each(|(r, row)| {
            let y = rows.start + r;
            let mut rays_scratch: Vec<[f64; 3]> = Vec::new();
            for (x, pixel) in row.chunks_exact_mut(n * n).enumerate() {
                let index = (y * width + x) as u64;
                let seen = |sx: f64, sy: f64| seen(index, sx, sy);
                // The grid this pixel gets: n x n, or under adaptive sampling four rays at
                // the quadrants' centres first and then 2 x 2 (those four), n/2 x n/2 or
                // n x n as they ask (see `refinement`). A coarser grid's g x g rays each
                // stand for (n/g)^2 slots, so the pixel's mean is that of the g x g grid.
                let mut grid = n;
                let mut coarse = None;
                if let Some(contrast) = adaptive {
                    let first = *first_at(x, y);
                    let neighbours = (y.saturating_sub(1)..(y + 2).min(around.end))
                        .flat_map(|ny| {
                            (x.saturating_sub(1)..(x + 2).min(width)).map(move |nx| (nx, ny))
                        })
                        .filter(|&(nx, ny)| (nx, ny) != (x, y))
                        .map(|(nx, ny)| first_at(nx, ny));
                    let bright_beside = brighter_beside(&first, neighbours);
                    grid = match refinement(&first, contrast) {
                        Refine::No | Refine::Contrast if bright_beside => n,
                        Refine::No => 2,
                        Refine::Contrast => (n / 2).max(2),
                        Refine::Silhouette => n,
                    };
                    coarse = Some(first);
                }
                let mut rays = [[0.0; 3]; 4];
                let values: &[[f64; 3]] = match coarse {
                    Some(first) if grid == 2 => {
                        for (r, f) in rays.iter_mut().zip(&first) {
                            *r = f.value;
                        }
                        &rays
                    }
                    _ => {
                        for j in 0..grid {
                            for i in 0..grid {
                                let sx = x as f64 + sample_offset(i, grid);
                                let sy = y as f64 + sample_offset(j, grid);
                                pixel[j * grid + i] = seen(sx, sy).value;
                            }
                        }
                        if grid == n {
                            continue;
                        }
                        rays_scratch.clear();
                        rays_scratch.extend_from_slice(&pixel[..grid * grid]);
                        &rays_scratch
                    }
                };
                for j in 0..n {
                    for i in 0..n {
                        pixel[j * n + i] = values[(j * grid / n) * grid + i * grid / n];
                    }
                }
            }
            progress.advance(1);
        });
        film
    }

    /// What the unit ray `eye + t dir` sees: the radiosity of the element it hits first
    /// (flat), the vertex radiosities interpolated there (smooth), or 1 on an element edge
    /// and 0 elsewhere (wireframe); 0 for a miss or the back of an element. `footprint` is
    /// the angle one pixel subtends (for wireframe lines); `salt` shifts the direct light's
    /// shadow rays.
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        eye: DVec3,
        dir: DVec3,
        footprint: f64,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        shading: Shading,
        salt: u64,
    ) -> Seen {
        if self.mesh.is_empty() {
            return Seen::NOTHING;
        }
        let (lo, hi) = self.bounds;
        let t_max = (eye - 0.5 * (lo + hi)).length() + (hi - lo).length() + 1.0;
        // Hits nearer than 1e-9 of the scene are not seen: an eye exactly on a wall sees
        // the room in front of it, not the wall's back at t = 0 (QA of issue #16: 94 % of
        // such a picture was black, with no warning).
        let t_min = CAMERA_NEAR * (hi - lo).length();
        let hit = self.bvh.closest_hit(eye, dir, t_min, t_max);
        if let Some(holes) = &self.holes {
            match holes.uncovered(eye, dir, t_min, hit.map(|h| h.t), t_max) {
                None => {}
                Some(Uncovered::Back) => return Seen::NOTHING,
                Some(Uncovered::Front { surface, x }) => {
                    let Some((e, at)) = nearest_element(self.mesh, surface, x) else {
                        return Seen::NOTHING;
                    };
                    let near = match shading {
                        Shading::Flat => element_b[e],
                        Shading::Smooth => interpolation(self.mesh, e, at).of(vertex_b),
                        Shading::Wireframe => [0.0; 3],
                    };
                    let open = if self.coverage {
                        1.0
                    } else {
                        holes.open_share(surface, x)
                    };
                    let value = near.map(|b| b * open);
                    return Seen {
                        value,
                        surface: Some(surface),
                    };
                }
            }
        }
        let Some(hit) = hit else {
            return Seen::NOTHING;
        };
        let e = hit.id as usize;
        let el = &self.mesh.elements[e];
        if el.normal.dot(dir) >= 0.0 {
            return Seen::NOTHING; // the back of a one-sided surface
        }
        let x = eye + hit.t * dir;
        let value = match shading {
            Shading::Flat => element_b[e],
            Shading::Smooth => {
                // Interpolation weights at x (no allocation: this runs once per ray).
                let weights = interpolation(self.mesh, e, x);
                let sum = weights.of(vertex_b);
                match &self.direct {
                    Some(direct) => {
                        let d = direct.at(e, x, &weights, salt);
                        std::array::from_fn(|k| (sum[k] + d[k]).max(0.0))
                    }
                    None => sum,
                }
            }
            Shading::Wireframe => {
                // A shared edge is drawn from both of its elements, half a pixel into each;
                // a surface's boundary edge from its one element, a whole pixel in. The
                // distance to an edge is measured as seen from the eye: the part across
                // the ray of the in-plane offset perpendicular to the edge.
                let pixel = hit.t * footprint;
                let p: Vec<DVec3> = self.mesh.corner_positions(e).collect();
                let boundary = self.boundary_edges[e];
                let near_edge = (0..p.len()).any(|i| {
                    let (a, b) = (p[i], p[(i + 1) % p.len()]);
                    let across = (b - a).cross(el.normal).normalize_or_zero();
                    let seen = (1.0 - across.dot(dir).powi(2)).max(0.0).sqrt();
                    let half_width = if boundary & (1 << i) != 0 { 1.0 } else { 0.5 };
                    segment_distance(x, a, b) * seen <= half_width * pixel
                });
                if near_edge {
                    [1.0; 3]
                } else {
                    [0.0; 3]
                }
            }
        };
        Seen {
            value,
            surface: Some(el.surface),
        }
    }
}

/// The film content a shading mode makes: line coverage for wireframe, else radiosity.
fn film_content(shading: Shading) -> FilmContent {
    match shading {
        Shading::Wireframe => FilmContent::Coverage,
        Shading::Flat | Shading::Smooth => FilmContent::Radiosity,
    }
}

/// The distance from `x` to the segment from `a` to `b`.
fn segment_distance(x: DVec3, a: DVec3, b: DVec3) -> f64 {
    (x - closest_on_segment(x, a, b)).length()
}

/// The vertices smooth shading interpolates at a point of an element, with their weights
/// (non-negative, summing to 1): up to four, see [`interpolation`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interpolation {
    vertices: [u32; 4],
    weights: [f64; 4],
    len: usize,
}

impl Interpolation {
    /// The (vertex index, weight) pairs.
    pub fn pairs(&self) -> impl Iterator<Item = (u32, f64)> + '_ {
        self.vertices[..self.len]
            .iter()
            .copied()
            .zip(self.weights[..self.len].iter().copied())
    }

    /// The weighted sum of the per-vertex values `vertex_b` (one per mesh vertex).
    pub fn of(&self, vertex_b: &[[f64; 3]]) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for (v, w) in self.pairs() {
            let b = vertex_b[v as usize];
            for k in 0..3 {
                sum[k] += w * b[k];
            }
        }
        sum
    }
}

/// Smooth shading's interpolation at the point `x` of element `e` (paper 2.5): bilinear in
/// the corners of a quadrilateral ([`inverse_bilinear`]), barycentric in those of a triangle;
/// on an element with T-vertices on its edges ([`Mesh::display`]), barycentric in the display
/// triangle that holds x, so that along an edge the value runs linearly between consecutive
/// display vertices, as it does on the smaller elements on the other side (no seam).
pub fn interpolation(mesh: &Mesh, e: usize, x: DVec3) -> Interpolation {
    let el = &mesh.elements[e];
    let c = el.corners();
    let display = mesh.display();
    let mut out = Interpolation {
        vertices: [0; 4],
        weights: [0.0; 4],
        len: 0,
    };
    if display.polygon(e).len() == c.len() {
        let mut p = [DVec3::ZERO; 4];
        for (slot, v) in p.iter_mut().zip(mesh.corner_positions(e)) {
            *slot = v;
        }
        out.weights = if el.is_quad() {
            let (u, v) = inverse_bilinear(&p, x);
            [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v]
        } else {
            let w = barycentric(&p[..3], x);
            [w[0], w[1], w[2], 0.0]
        };
        out.vertices[..c.len()].copy_from_slice(c);
        out.len = c.len();
        return out;
    }
    // The display triangle that holds x: the one whose smallest barycentric weight is
    // largest (x may lie a rounding error outside every triangle, on an edge).
    let mut best = (f64::NEG_INFINITY, [DVec3::ZERO; 3], [0u32; 3]);
    for t in display.triangles(e) {
        let p = t.vertices.map(|v| mesh.vertices[v as usize]);
        if let Some(w) = barycentric_unclamped(&p, x) {
            let least = w[0].min(w[1]).min(w[2]);
            if least > best.0 {
                best = (least, p, t.vertices);
            }
        }
    }
    let w = barycentric(&best.1, x);
    out.vertices[..3].copy_from_slice(&best.2);
    out.weights[..3].copy_from_slice(&w);
    out.len = 3;
    out
}

/// The parameters (u, v) in [0, 1]^2 at which the bilinear patch with corners `q`
/// (see [`crate::mesh::bilinear`]) passes through `p`, for `p` on or near the patch of a
/// planar convex quadrilateral. Inverse of [`crate::mesh::bilinear`].
///
/// The quadrilateral and `p` are projected to the coordinate plane the quad is most nearly
/// parallel to; v solves the quadratic `k2 v^2 + k1 v + k0 = 0` (with the cancellation-free
/// root formula, and the linear case of a parallelogram handled by the same formula), the
/// root nearest [0, 1] is taken, and u follows by least squares. The result is clamped to
/// [0, 1]^2, so a point just outside the quad maps to its edge.
pub fn inverse_bilinear(q: &[DVec3], p: DVec3) -> (f64, f64) {
    let n = crate::geometry::area_vector(q).abs();
    let flat = |v: DVec3| -> DVec2 {
        if n.x >= n.y && n.x >= n.z {
            DVec2::new(v.y, v.z)
        } else if n.y >= n.z {
            DVec2::new(v.z, v.x)
        } else {
            DVec2::new(v.x, v.y)
        }
    };
    let [a, b, c, d] = [flat(q[0]), flat(q[1]), flat(q[2]), flat(q[3])];
    let h = flat(p) - a;
    let e = b - a;
    let f = d - a;
    let g = a - b + c - d;
    let cross = |x: DVec2, y: DVec2| x.x * y.y - x.y * y.x;
    let k2 = cross(g, f);
    let k1 = cross(e, f) + cross(h, g);
    let k0 = cross(h, e);
    let disc = (k1 * k1 - 4.0 * k0 * k2).max(0.0);
    let qq = -0.5 * (k1 + disc.sqrt().copysign(k1));
    let distance_to_unit = |t: f64| {
        if t < 0.0 {
            -t
        } else if t > 1.0 {
            t - 1.0
        } else {
            0.0
        }
    };
    let mut v = 0.5;
    let mut best = f64::INFINITY;
    for root in [(qq != 0.0).then(|| k0 / qq), (k2 != 0.0).then(|| qq / k2)]
        .into_iter()
        .flatten()
    {
        let dist = distance_to_unit(root);
        if root.is_finite() && dist < best {
            best = dist;
            v = root;
        }
    }
    let along = e + g * v;
    let len2 = along.length_squared();
    let u = if len2 > 0.0 {
        (h - f * v).dot(along) / len2
    } else {
        0.5
    };
    (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0))
}

/// The barycentric weights of `p` in triangle `t` (p = w0 t0 + w1 t1 + w2 t2 for p in the
/// triangle's plane), clamped to be non-negative and renormalised to sum to 1, so a point
/// just outside maps to the nearest edge.
pub fn barycentric(t: &[DVec3], p: DVec3) -> [f64; 3] {
    let Some(w) = barycentric_unclamped(t, p) else {
        return [1.0 / 3.0; 3];
    };
    let w = w.map(|x| x.max(0.0));
    let s = w[0] + w[1] + w[2];
    if s > 0.0 {
        w.map(|x| x / s)
    } else {
        [1.0 / 3.0; 3]
    }
}

/// The barycentric weights of (the projection of) `p` in triangle `t`, negative outside it;
/// `None` for a triangle of no area.
fn barycentric_unclamped(t: &[DVec3], p: DVec3) -> Option<[f64; 3]> {
    let (v0, v1, v2) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
    let (d20, d21) = (v2.dot(v0), v2.dot(v1));
    let denom = d00 * d11 - d01 * d01;
    if denom == 0.0 {
        return None;
    }
    let w1 = (d11 * d20 - d01 * d21) / denom;
    let w2 = (d00 * d21 - d01 * d20) / denom;
    Some([1.0 - w1 - w2, w1, w2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{bilinear, mesh_scene};
    use crate::progress::NoProgress;
    use crate::render::test_support::{cornell_camera, facing_minus_z, px, scene, surface};
    use crate::render::tonemap::tone_map;
    use crate::render::{render, RenderSettings};
    use crate::shade::vertex_radiosity;
    use glam::dvec3;
    use image::RgbImage;

    #[test]
    fn inverse_bilinear_round_trips() {
        let quads = [
            // A unit square, a trapezoid, a general convex quad, tilted out of any axis plane.
            vec![
                dvec3(0., 0., 0.),
                dvec3(1., 0., 0.),
                dvec3(1., 1., 0.),
                dvec3(0., 1., 0.),
            ],
            vec![
                dvec3(0., 0., 0.),
                dvec3(10., 0., 0.),
                dvec3(7., 3., 0.),
                dvec3(2., 3., 0.),
            ],
            vec![
                dvec3(0., 0., 0.),
                dvec3(4., 0.5, 0.),
                dvec3(5., 4., 0.),
                dvec3(-1., 2., 0.),
            ],
        ];
        let tilt = |p: DVec3| dvec3(p.x, 0.6 * p.y + 0.8 * p.z, -0.8 * p.y + 0.6 * p.z + 7.0);
        for q in &quads {
            for q in [q.clone(), q.iter().map(|&p| tilt(p)).collect::<Vec<_>>()] {
                for j in 0..=10 {
                    for i in 0..=10 {
                        let (u, v) = (i as f64 / 10.0, j as f64 / 10.0);
                        let (u2, v2) = inverse_bilinear(&q, bilinear(&q, u, v));
                        assert!(
                            (u - u2).abs() < 1e-9 && (v - v2).abs() < 1e-9,
                            "({u}, {v}) -> ({u2}, {v2}) on {q:?}"
                        );
                    }
                }
            }
        }
        // Outside points clamp onto the quad.
        let (u, v) = inverse_bilinear(&quads[0], dvec3(1.5, -0.5, 0.0));
        assert_eq!((u, v), (1.0, 0.0));
    }

    #[test]
    fn smooth_shading_is_continuous_across_a_t_edge() {
        // (b) The 2 x 2 grid with its lower left quad split in four: along the T-edge x = 1,
        // y in [0, 1], the whole quad [1, 2] x [0, 1] (element 4) and the small quads
        // [0.5, 1] x [0, 0.5] and [0.5, 1] x [0.5, 1] (elements 1, 3) must interpolate the
        // same value at the same point.
        let mesh = crate::mesh::split_corner_mesh();
        // A radiosity that varies from element to element (from the centroid, not linear, so
        // no interpolation reproduces it by accident).
        let eb: Vec<[f64; 3]> = mesh
            .elements
            .iter()
            .map(|el| {
                let c = el.centroid;
                [
                    1.0 + c.x * c.x + 3.0 * c.y,
                    2.0 - c.y * c.y,
                    0.5 + c.x * c.y,
                ]
            })
            .collect();
        let vb = vertex_radiosity(&mesh, &eb);
        // The T-vertex (1, 0.5) averages the three elements that touch it, weighted by area:
        // elements 1 and 3 (0.25 each) and element 4 (1), the rule of paper 2.5.
        let t = mesh
            .vertices
            .iter()
            .position(|&v| v == dvec3(1.0, 0.5, 0.0))
            .unwrap();
        for k in 0..3 {
            let want = (0.25 * eb[1][k] + 0.25 * eb[3][k] + eb[4][k]) / 1.5;
            assert!((vb[t][k] - want).abs() < 1e-14, "band {k}: {:?}", vb[t]);
        }
        let mut largest_old_jump: f64 = 0.0;
        for i in 0..=20 {
            let y = i as f64 / 20.0;
            let x = dvec3(1.0, y, 0.0);
            let small = if y <= 0.5 { 1 } else { 3 };
            let a = interpolation(&mesh, 4, x).of(&vb);
            let b = interpolation(&mesh, small, x).of(&vb);
            for k in 0..3 {
                // Both sides are linear along the edge between the same two vertices:
                // equal to rounding (values of order 10).
                assert!(
                    (a[k] - b[k]).abs() < 1e-12,
                    "y = {y}, band {k}: {a:?} / {b:?}"
                );
            }
            // What the element's own corners alone gave (bilinear on [1, 2] x [0, 1]):
            // different, so this test would catch the seam.
            let c = mesh.elements[4].corners();
            let old = (1.0 - y) * vb[c[0] as usize][0] + y * vb[c[3] as usize][0];
            largest_old_jump = largest_old_jump.max((old - b[0]).abs());
        }
        assert!(largest_old_jump > 0.05, "{largest_old_jump}");
    }

    #[test]
    fn a_rug_in_the_floors_plane_is_seen_over_it() {
        // The floor meshed whole under a rug in its plane (as hierarchical radiosity's leaves
        // keep it): every ray that meets the plane well inside the rug (1 cm in from its
        // outline, against rounding at the outline) must see the rug, never the floor.
        let quad = |x0: f64, x1: f64, z0: f64, z1: f64| {
            vec![
                dvec3(x0, 0., z0),
                dvec3(x0, 0., z1),
                dvec3(x1, 0., z1),
                dvec3(x1, 0., z0),
            ]
        };
        let s = scene(vec![
            surface("floor", 0.0, quad(0., 4., 0., 4.)),
            surface("rug", 0.0, quad(1.1, 3.1, 1.1, 2.3)),
        ]);
        let mesh = mesh_scene(&s, 0.25).unwrap();
        let eb: Vec<[f64; 3]> = mesh
            .elements
            .iter()
            .map(|el| [el.surface as f64, 0.0, 0.0])
            .collect();
        let r = Renderer::new(&mesh).with_surfaces_on_top(&s);
        let cam = Camera {
            eye: dvec3(2.0, 1.5, -2.0),
            look_at: dvec3(2.0, 0.0, 1.7),
            up: DVec3::Y,
            fov_y_degrees: 40.0,
            width: 160,
            height: 120,
        };
        let film = r.film(&cam, &eb, &[], Shading::Flat, 1, &NoProgress);
        let screen = cam.screen();
        let (mut inside, mut floor) = (0, 0);
        for y in 0..cam.height as usize {
            for x in 0..cam.width as usize {
                let dir = cam.direction_in(screen, x as f64 + 0.5, y as f64 + 0.5);
                if dir.y >= 0.0 {
                    continue;
                }
                let p = cam.eye + (-cam.eye.y / dir.y) * dir;
                if p.x > 1.11 && p.x < 3.09 && p.z > 1.11 && p.z < 2.29 {
                    inside += 1;
                    if film.pixel(x, y)[0][0] != 1.0 {
                        floor += 1;
                    }
                }
            }
        }
        assert!(inside > 1000, "{inside}");
        assert_eq!(floor, 0, "{floor} of {inside} rug pixels show the floor");
    }

    #[test]
    fn barycentric_weights() {
        let t = [dvec3(0., 0., 1.), dvec3(2., 0., 1.), dvec3(0., 4., 1.)];
        let w = barycentric(&t, dvec3(0.5, 1.0, 1.0));
        // p = t0 + 0.25 (t1 - t0) + 0.25 (t2 - t0).
        for (a, b) in w.iter().zip([0.5, 0.25, 0.25]) {
            assert!((a - b).abs() < 1e-15);
        }
        assert_eq!(barycentric(&t, dvec3(-1., -1., 1.)), [1.0, 0.0, 0.0]);
    }

    /// A 2 x 2 quad facing -z seen head-on from (0, 0, -4).
    fn head_on(shading: Shading, b: [f64; 3], gamma: f64) -> (RgbImage, RgbImage) {
        let s = scene(vec![surface(
            "light",
            1.0,
            facing_minus_z(-1., 1., -1., 1., 0.),
        )]);
        let mesh = mesh_scene(&s, 0.3).unwrap();
        assert_eq!(mesh.len(), 16); // 4 x 4 elements of 0.5 x 0.5
        let eb = vec![b; mesh.len()];
        let vb = vertex_radiosity(&mesh, &eb);
        let r = Renderer::new(&mesh);
        let settings = RenderSettings {
            shading,
            exposure_scale: 1.0,
            gamma,
            supersample: 1,
            ..RenderSettings::default()
        };
        let mut cam = Camera {
            eye: dvec3(0., 0., -4.),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 40.0,
            width: 41,
            height: 31,
        };
        let front = render(&r, &cam, &eb, &vb, &settings, &NoProgress);
        cam.eye = dvec3(0., 0., 4.);
        let back = render(&r, &cam, &eb, &vb, &settings, &NoProgress);
        (front, back)
    }

    #[test]
    fn emitter_seen_head_on() {
        // 0.25^(1/2) = 0.5 -> 128, 0.0625^(1/2) = 0.25 -> 63.75 -> 64, 0.04^(1/2) = 0.2 -> 51.
        let (img, back) = head_on(Shading::Flat, [0.25, 0.0625, 0.04], 2.0);
        assert_eq!(img.dimensions(), (41, 31));
        assert_eq!(px(&img, 20, 15), [128, 64, 51]);
        // A corner of the view misses the quad (it spans 2 * 4 tan 20 = 2.9 units): black.
        assert_eq!(px(&img, 0, 0), [0, 0, 0]);
        // Seen from behind, the one-sided quad is black.
        assert_eq!(px(&back, 20, 15), [0, 0, 0]);
        // Smooth shading of a uniform field gives the same image as flat shading.
        for b in [[0.3, 0.6, 0.9], [0.1, 0.02, 0.7]] {
            let (flat, _) = head_on(Shading::Flat, b, 2.2);
            let (smooth, _) = head_on(Shading::Smooth, b, 2.2);
            assert_eq!(flat, smooth);
            assert_eq!(px(&flat, 20, 15), tone_map(b, 1.0, 2.2));
        }
    }

    #[test]
    fn adaptive_sampling_refines_edges_only() {
        // Two flat-shaded quads, red and green, side by side with a gap at x in (256, 300)
        // that shows nothing: within a quad every pixel is its colour, at their edges the
        // pixels mix. Adaptive 8 x 8 sampling must give, pixel for pixel, the plain 2 x 2
        // film inside the quads (where the first four rays agree) and the full 8 x 8 film at
        // the edges where they see different surfaces or nothing.
        let s = scene(vec![
            surface("red", 0.0, facing_minus_z(300., 500., 100., 450., 0.)),
            surface("green", 0.0, facing_minus_z(56., 256., 100., 450., 0.)),
        ]);
        let mesh = mesh_scene(&s, 1e9).unwrap();
        let eb = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let cam = cornell_camera(32, 24);
        let plain = Renderer::new(&mesh);
        let adaptive = Renderer::new(&mesh).with_adaptive_sampling(0.02);
        let film = adaptive.film(&cam, &eb, &[], Shading::Flat, 8, &NoProgress);
        let full = plain.film(&cam, &eb, &[], Shading::Flat, 8, &NoProgress);
        let quarter = plain.film(&cam, &eb, &[], Shading::Flat, 2, &NoProgress);
        let mean = |p: &[[f64; 3]]| {
            let mut m = [0.0; 3];
            for s in p {
                for k in 0..3 {
                    m[k] += s[k] / p.len() as f64;
                }
            }
            m
        };
        let (mut edges, mut inside) = (0, 0);
        for y in 0..24 {
            for x in 0..32 {
                let f = full.pixel(x, y);
                let uniform = f.iter().all(|v| v == &f[0]);
                let got = mean(film.pixel(x, y));
                if uniform {
                    inside += 1;
                    assert_eq!(got, mean(quarter.pixel(x, y)), "pixel ({x}, {y})");
                } else {
                    // An edge: the full grid where the four first rays see it, else (an
                    // edge that only grazes the pixel) the 2 x 2 one.
                    let q = mean(quarter.pixel(x, y));
                    assert!(got == mean(f) || got == q, "edge pixel ({x}, {y})");
                    if got == mean(f) && got != q {
                        edges += 1;
                    }
                }
            }
        }
        assert!(
            edges > 20 && inside > 300,
            "{edges} edge and {inside} inside pixels"
        );
    }

    #[test]
    fn a_bright_edge_between_the_first_rays_is_refined() {
        // A bright quad (a light, 20 times the wall's radiosity) in front of a dim wall,
        // its edges at odd fractions of a pixel. Every pixel that the full 8 x 8 grid
        // finds partly bright but whose four first rays miss the quad has a neighbour
        // whose first rays see it, so adaptive sampling must give it the full grid (QA
        // pass 15 of issue #16: the row under the Cornell box's light showed nothing of it,
        // 8 % of the light's flux in a 32-pixel image).
        let s = scene(vec![
            surface("light", 0.0, facing_minus_z(203., 377., 211., 337., 0.)),
            surface("wall", 0.0, facing_minus_z(0., 556., 0., 548., 10.)),
        ]);
        let mesh = mesh_scene(&s, 1e9).unwrap();
        let eb = vec![[10.0, 10.0, 10.0], [0.5, 0.5, 0.5]];
        let cam = cornell_camera(32, 24);
        let adaptive = Renderer::new(&mesh).with_adaptive_sampling(0.02);
        let film = adaptive.film(&cam, &eb, &[], Shading::Flat, 8, &NoProgress);
        let full = Renderer::new(&mesh).film(&cam, &eb, &[], Shading::Flat, 8, &NoProgress);
        // A plain 2 x 2 film casts exactly the first rays (at 0.25 and 0.75 of the pixel).
        let firsts = Renderer::new(&mesh).film(&cam, &eb, &[], Shading::Flat, 2, &NoProgress);
        let mut grazed = 0;
        for y in 0..24 {
            for x in 0..32 {
                let f = full.pixel(x, y);
                let partly_bright = f.iter().any(|v| v[0] == 10.0) && f.iter().any(|v| v[0] < 10.0);
                if partly_bright && firsts.pixel(x, y).iter().all(|v| v[0] < 10.0) {
                    grazed += 1;
                    assert_eq!(film.pixel(x, y), f, "pixel ({x}, {y})");
                }
            }
        }
        // The quad's edges were placed to graze some pixels between their first rays.
        assert!(grazed > 0, "no pixel grazed");
    }

    #[test]
    fn colours_land_on_the_correct_side() {
        // Red on the x > 278 side, green on the x < 278 side, seen by the Cornell camera;
        // the top half of each quad is brighter.
        let s = scene(vec![
            surface("red", 0.0, facing_minus_z(300., 500., 100., 450., 0.)),
            surface("green", 0.0, facing_minus_z(56., 256., 100., 450., 0.)),
        ]);
        let mesh = mesh_scene(&s, 1e9).unwrap();
        assert_eq!(mesh.len(), 2);
        let eb = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let r = Renderer::new(&mesh);
        let settings = RenderSettings {
            shading: Shading::Flat,
            ..RenderSettings::default()
        };
        let cam = cornell_camera(64, 48);
        let img = render(&r, &cam, &eb, &[], &settings, &NoProgress);
        assert_eq!(px(&img, 16, 24), [255, 0, 0]); // left half: red
        assert_eq!(px(&img, 48, 24), [0, 255, 0]); // right half: green

        // Vertical: the quads span y in [100, 450] around the eye height 273, so a row
        // near the top shows them and the top row (y ~ 556 at z = 0) does not.
        assert_eq!(px(&img, 16, 0), [0, 0, 0]);
        assert_eq!(px(&img, 16, 10), [255, 0, 0]);
    }

    #[test]
    fn no_seams_between_elements() {
        // An 8 x 8 grid of unit elements on [-4, 4]^2; from (0, 0, -4.5) with a 90 degree
        // view, a 9 x 9 image puts every pixel-centre ray exactly through x, y in
        // {-4, ..., 4}: through element edges, corners and the surface's boundary.
        let s = scene(vec![surface(
            "plane",
            0.0,
            facing_minus_z(-4., 4., -4., 4., 0.),
        )]);
        let mesh = mesh_scene(&s, 1.0).unwrap();
        assert_eq!(mesh.len(), 64);
        let eb = vec![[0.5; 3]; mesh.len()];
        let vb = vertex_radiosity(&mesh, &eb);
        let r = Renderer::new(&mesh);
        let cam = Camera {
            eye: dvec3(0., 0., -4.5),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 90.0,
            width: 9,
            height: 9,
        };
        for shading in [Shading::Smooth, Shading::Flat] {
            let settings = RenderSettings {
                shading,
                gamma: 1.0,
                ..RenderSettings::default()
            };
            let img = render(&r, &cam, &eb, &vb, &settings, &NoProgress);
            for (x, y, p) in img.enumerate_pixels() {
                // 0.5 * 255 = 127.5 -> 128 (127 allowed for rounding in the interpolation).
                assert!(p.0[0] >= 127, "{shading:?}: pixel ({x}, {y}) is {:?}", p.0);
            }
        }
        // A subdivided pentagon (triangle elements), with 3 x 3 supersampling: every
        // sample whose ray meets the pentagon's interior is lit, so pixels well inside
        // are fully lit.
        let pent: Vec<DVec3> = (0..5)
            .map(|i| {
                let a = -(i as f64) * std::f64::consts::TAU / 5.0;
                dvec3(4.0 * a.cos(), 4.0 * a.sin(), 0.0)
            })
            .collect();
        let s = scene(vec![surface("pentagon", 0.0, pent)]);
        let mesh = mesh_scene(&s, 0.2).unwrap();
        let eb = vec![[1.0; 3]; mesh.len()];
        let vb = vertex_radiosity(&mesh, &eb);
        let r = Renderer::new(&mesh);
        let cam = Camera {
            width: 63,
            height: 63,
            ..cam
        };
        let settings = RenderSettings {
            supersample: 3,
            gamma: 1.0,
            ..RenderSettings::default()
        };
        let img = render(&r, &cam, &eb, &vb, &settings, &NoProgress);
        let inner_radius = 4.0 * (std::f64::consts::PI / 5.0).cos() - 0.3;
        for (x, y, p) in img.enumerate_pixels() {
            // Pixel centre in the plane: 9 units across 63 pixels, x mirrored.
            let wx = -(x as f64 + 0.5 - 31.5) * 9.0 / 63.0;
            let wy = -(y as f64 + 0.5 - 31.5) * 9.0 / 63.0;
            if wx.hypot(wy) < inner_radius {
                assert_eq!(p.0, [255; 3], "pixel ({x}, {y})");
            }
        }
    }

    #[test]
    fn wireframe_draws_edges() {
        // A 4 x 4 grid on [-1, 1]^2 seen head-on; the 41 x 31 image puts pixel (20, 15)
        // on the vertex (0, 0).
        let (img, _) = head_on(Shading::Wireframe, [0.5; 3], 1.0);
        assert_eq!(px(&img, 20, 15), [255; 3]); // centre: the crossing of the edges
        let cam = Camera {
            eye: dvec3(0., 0., -4.),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 40.0,
            width: 41,
            height: 31,
        };
        // The middle of an element (0.25, 0.25) is dark; the image's corner (no hit) too.
        let (x, y) = cam.project(dvec3(0.25, 0.25, 0.)).unwrap();
        assert_eq!(px(&img, x as u32, y as u32), [0; 3]);
        assert_eq!(px(&img, 0, 0), [0; 3]);
        // The quad's boundary x = 1 is drawn.
        let (x, y) = cam.project(dvec3(1.0, 0.25, 0.)).unwrap();
        let x = x.round() as u32;
        let lit = (x - 1..=x + 1).any(|x| px(&img, x, y as u32) == [255; 3]);
        assert!(lit);
    }
}
