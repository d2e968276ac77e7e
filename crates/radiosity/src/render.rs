//! A CPU ray-casting camera that turns a radiosity solution into an image (paper section
//! 2.6, "Walkthrough Ability", and the plates of Appendix B).
//!
//! Radiosity is view-independent: once element radiosities are known, any [`Camera`] can
//! look at the scene without solving again. The paper draws the patches with OpenGL; here
//! each pixel casts a ray into a BVH of the mesh's elements ([`Renderer`]) and colours it by
//! the element it hits first, in one of the paper's three display modes ([`Shading`]):
//!
//! * [`Shading::Flat`] (plate 1): every element in its own radiosity.
//! * [`Shading::Smooth`] (plate 2, section 2.5): the vertex radiosities of
//!   [`crate::shade::vertex_radiosity`] interpolated across the element, bilinearly on a
//!   quadrilateral (as OpenGL's Gouraud shading of a quad approximates) and barycentrically
//!   on a triangle.
//! * [`Shading::Wireframe`] (plate 4): element edges as white lines about one pixel wide
//!   on black. Unlike the paper's OpenGL line mode, hidden lines are removed (only edges of
//!   the element a ray hits first are drawn).
//!
//! Surfaces are one-sided: a ray that reaches the back of an element sees black (the back
//! reflects and emits nothing). A ray that hits nothing sees black. Colours go through
//! [`crate::shade::expose`] and the paper's gamma correction (section 2.7,
//! [`crate::shade::encode`]). Rows are rendered in parallel with rayon; each finished row is
//! reported to the [`Progress`] sink as one unit of [`Stage::Render`].

use std::collections::HashMap;
use std::io;
use std::path::Path;

use glam::{DVec2, DVec3};
use image::RgbImage;
use rayon::prelude::*;

use crate::mesh::Mesh;
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::{CameraHint, Scene};
use crate::shade::{expose, GammaEncoder};
use crate::visibility::PolygonBvh;

/// A pinhole camera (right-handed): `forward = normalize(look_at - eye)`,
/// `right = normalize(forward x up)`, `true_up = right x forward`. Image pixel (x, y) has
/// y = 0 at the top row and x = 0 at the left column.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: DVec3,
    /// The point at the centre of the image.
    pub look_at: DVec3,
    /// Up direction; need not be perpendicular to the view direction (nor unit).
    pub up: DVec3,
    /// Vertical field of view, degrees (in (0, 180)).
    pub fov_y_degrees: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

/// True when most of a 5 x 5 grid of rays from the bounding box's centre towards its front
/// (-z) face leave the scene without hitting a surface: the box is open there.
fn front_side_is_open(scene: &Scene, lo: DVec3, hi: DVec3) -> bool {
    let bvh = PolygonBvh::over_surfaces(scene);
    let centre = 0.5 * (lo + hi);
    let mut escaped = 0;
    for i in 0..5 {
        for j in 0..5 {
            let target = DVec3::new(
                lo.x + (i as f64 + 0.5) / 5.0 * (hi.x - lo.x),
                lo.y + (j as f64 + 0.5) / 5.0 * (hi.y - lo.y),
                lo.z - 1e-3 * (hi - lo).length(),
            );
            let d = target - centre;
            if let Some(dir) = d.try_normalize() {
                if bvh.closest_hit(centre, dir, 0.0, d.length()).is_none() {
                    escaped += 1;
                }
            }
        }
    }
    escaped > 12
}

/// The field of view of the cameras [`Camera::framing`] and [`Camera::for_scene`] make.
pub const DEFAULT_FOV_Y_DEGREES: f64 = 60.0;

impl Camera {
    /// The camera a scene suggests, at the given image size.
    pub fn from_hint(hint: &CameraHint, width: u32, height: u32) -> Camera {
        Camera {
            eye: hint.eye,
            look_at: hint.look_at,
            up: hint.up,
            fov_y_degrees: hint.fov_y_degrees,
            width,
            height,
        }
    }

    /// A default camera for a scene with bounding box `scene_bounds` = (min, max), looking
    /// along +z at the box centre with +y up and a 60 degree field of view.
    ///
    /// When the box has depth (its z extent is at least a quarter of its larger x or y
    /// extent) the scene is taken to be a room and the eye is put *inside* it, near the
    /// -z face at mid height: `eye = centre - (0, 0, 0.47 dz)`, which sees the far wall
    /// whole and strips of the floor, ceiling and side walls (for the Cornell box, which is
    /// open at -z, this is just inside the opening). A light in the middle of the ceiling is
    /// out of this view; scenes that want it in view bring a [`CameraHint`]. A flat box (a wall, a floor plan) is seen from
    /// outside, from -z, at a distance that fits it in the view.
    pub fn framing(scene_bounds: (DVec3, DVec3), width: u32, height: u32) -> Camera {
        let (lo, hi) = scene_bounds;
        let mut cam = Camera {
            eye: DVec3::new(0.0, 0.0, -1.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: DEFAULT_FOV_Y_DEGREES,
            width,
            height,
        };
        if !(lo.is_finite() && hi.is_finite()) {
            return cam; // no geometry
        }
        let centre = 0.5 * (lo + hi);
        let size = hi - lo;
        let extent = size.x.max(size.y);
        cam.look_at = centre;
        if size.z >= 0.25 * extent && size.z > 0.0 {
            cam.eye = centre - DVec3::Z * (0.47 * size.z);
        } else {
            let tan_half = (0.5 * DEFAULT_FOV_Y_DEGREES).to_radians().tan();
            let aspect = (width.max(1) as f64 / height.max(1) as f64).min(1.0);
            // Fit the larger extent in the narrower image direction, with a 10% margin.
            let dist = (0.55 * extent / (tan_half * aspect)).max(1e-3) + 0.5 * size.z;
            cam.eye = centre - DVec3::Z * dist;
        }
        cam
    }

    /// A camera that frames a point cloud from outside, looking at its bounding-box centre
    /// from the direction (0.3, 0.35, -1) (front, a little right and above in scene
    /// coordinates), far enough that the bounding sphere fits the view.
    pub fn outside(scene_bounds: (DVec3, DVec3), width: u32, height: u32) -> Camera {
        let (lo, hi) = scene_bounds;
        let mut cam = Camera::framing(scene_bounds, width, height);
        if !(lo.is_finite() && hi.is_finite()) {
            return cam;
        }
        let centre = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo).length()).max(1e-3);
        let tan_half = (0.5 * DEFAULT_FOV_Y_DEGREES).to_radians().tan();
        let aspect = (width.max(1) as f64 / height.max(1) as f64).min(1.0);
        let half_angle = (tan_half * aspect).atan();
        let dist = 1.05 * radius / half_angle.sin();
        cam.look_at = centre;
        cam.eye = centre + DVec3::new(0.3, 0.35, -1.0).normalize() * dist;
        cam
    }

    /// In the room of the scene's most powerful emitter that faces down: 1.5 m (or 55 % of
    /// the way) below it towards what is under it, looking level along the room's diagonal
    /// with a 75 degree view. `None` without such an emitter.
    fn under_brightest_light(scene: &Scene, width: u32, height: u32) -> Option<Camera> {
        let light = scene
            .surfaces
            .iter()
            .filter(|s| crate::geometry::polygon_normal(&s.vertices).is_some_and(|n| n.y < -0.7))
            .max_by(|a, b| {
                let power = |s: &crate::scene::Surface| {
                    crate::geometry::polygon_area(&s.vertices) * s.emission.max_band()
                };
                power(a).total_cmp(&power(b))
            })
            .filter(|s| s.emission.max_band() > 0.0)?;
        let centre = crate::geometry::polygon_centroid(&light.vertices);
        let bvh = PolygonBvh::over_surfaces(scene);
        let scale = bvh.scale();
        let below = bvh
            .closest_hit(centre, -DVec3::Y, 1e-6 * scale, scale)
            .map_or(0.25 * scale, |h| h.t);
        let drop = (below - 1.5).clamp(0.45 * below, 0.55 * below);
        let eye = centre - DVec3::Y * drop;
        // Step back from the light along the diagonal, to the room's far corner's opposite.
        let diagonal = DVec3::new(1.0, 0.0, 1.0).normalize();
        let back = bvh
            .closest_hit(eye, -diagonal, 1e-6 * scale, scale)
            .map_or(0.0, |h| 0.6 * h.t);
        let eye = eye - diagonal * back;
        Some(Camera {
            eye,
            look_at: eye + diagonal + DVec3::new(0.0, -0.15, 0.0),
            up: DVec3::Y,
            fov_y_degrees: 75.0,
            width,
            height,
        })
    }

    /// The camera to render `scene` with when the user gives none:
    ///
    /// * the scene's own [`Scene::camera`] when it has one;
    /// * for a box open at its front (-z) side, like the Cornell box without its camera: from
    ///   outside, through the opening, with the Cornell camera's 39.3 degree view;
    /// * for a closed room (most surface area faces the inside eye): [`Camera::framing`]'s
    ///   eye moved to eye height (60 % up) just inside the front wall, looking down a little
    ///   across the room with a 75 degree view;
    /// * for several rooms (more than one emitter facing down, like a generated building):
    ///   in the room of the most powerful one (see `under_brightest_light`);
    /// * otherwise (objects): [`Camera::outside`].
    pub fn for_scene(scene: &Scene, width: u32, height: u32) -> Camera {
        if let Some(hint) = &scene.camera {
            return Camera::from_hint(hint, width, height);
        }
        // Several rooms (more than one light facing down): any eye chosen from the bounding
        // box alone may stand inside a wall or outside every room, seeing only backs.
        let ceiling_lights = scene
            .surfaces
            .iter()
            .filter(|s| s.emission.max_band() > 0.0)
            .filter(|s| crate::geometry::polygon_normal(&s.vertices).is_some_and(|n| n.y < -0.7))
            .count();
        if ceiling_lights > 1 {
            if let Some(camera) = Camera::under_brightest_light(scene, width, height) {
                return camera;
            }
        }
        let bounds = scene.bounds();
        let (lo, hi) = bounds;
        let inside = Camera::framing(bounds, width, height);
        if !(lo.is_finite() && hi.is_finite()) {
            return inside;
        }
        let (centre, size) = (0.5 * (lo + hi), hi - lo);
        let (mut front, mut total) = (0.0, 0.0);
        for s in &scene.surfaces {
            let area = crate::geometry::area_vector(&s.vertices);
            let c = crate::geometry::vertex_mean(&s.vertices);
            total += area.length();
            if area.dot(inside.eye - c) > 0.0 {
                front += area.length();
            }
        }
        if front < 0.5 * total {
            return Camera::outside(bounds, width, height);
        }
        if front_side_is_open(scene, lo, hi) {
            let fov: f64 = 39.3;
            let aspect = (width.max(1) as f64 / height.max(1) as f64).min(1.0);
            let tan_half = (0.5 * fov).to_radians().tan();
            let dist = 0.52 * size.x.max(size.y) / (tan_half * aspect);
            return Camera {
                eye: DVec3::new(centre.x, centre.y, lo.z - dist),
                look_at: DVec3::new(centre.x, centre.y, lo.z),
                up: DVec3::Y,
                fov_y_degrees: fov,
                width,
                height,
            };
        }
        if size.z >= 0.25 * size.x.max(size.y) {
            return Camera {
                eye: DVec3::new(centre.x, lo.y + 0.6 * size.y, lo.z + 0.03 * size.z),
                look_at: DVec3::new(centre.x, lo.y + 0.3 * size.y, centre.z + 0.2 * size.z),
                up: DVec3::Y,
                fov_y_degrees: 75.0,
                width,
                height,
            };
        }
        inside
    }

    /// The unit vectors (forward, right, true_up) of the camera frame. When `up` is parallel
    /// to the view direction another up (+z, or +x) is used.
    pub fn basis(&self) -> (DVec3, DVec3, DVec3) {
        let forward = (self.look_at - self.eye)
            .try_normalize()
            .unwrap_or(DVec3::Z);
        let mut right = forward.cross(self.up);
        if right.length_squared() < 1e-20 * self.up.length_squared().max(1e-300) {
            let alt = if forward.z.abs() < 0.9 {
                DVec3::Z
            } else {
                DVec3::X
            };
            right = forward.cross(alt);
        }
        let right = right.normalize();
        (forward, right, right.cross(forward))
    }

    /// tan of half the vertical field of view.
    fn tan_half(&self) -> f64 {
        (0.5 * self.fov_y_degrees.to_radians()).tan()
    }

    fn aspect(&self) -> f64 {
        self.width.max(1) as f64 / self.height.max(1) as f64
    }

    /// The unit direction of the ray through image point (x, y), in pixels from the image's
    /// top-left corner (the centre of pixel (i, j) is (i + 0.5, j + 0.5)).
    pub fn ray_direction(&self, x: f64, y: f64) -> DVec3 {
        self.direction_in(self.screen(), x, y)
    }

    /// The camera frame scaled to the image plane at distance 1: (forward, the right edge's
    /// offset, the top edge's offset), computed once per image rather than per ray.
    fn screen(&self) -> (DVec3, DVec3, DVec3) {
        let (forward, right, up) = self.basis();
        let t = self.tan_half();
        (forward, right * (t * self.aspect()), up * t)
    }

    fn direction_in(&self, (forward, right, up): (DVec3, DVec3, DVec3), x: f64, y: f64) -> DVec3 {
        let sx = 2.0 * x / self.width.max(1) as f64 - 1.0;
        let sy = 1.0 - 2.0 * y / self.height.max(1) as f64;
        (forward + sx * right + sy * up).normalize()
    }

    /// Where `p` appears in the image, as (x, y) in pixels from the top-left corner, or
    /// `None` when it is not in front of the eye.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let (forward, right, up) = self.basis();
        let d = p - self.eye;
        let z = d.dot(forward);
        if z <= 0.0 {
            return None;
        }
        let t = self.tan_half();
        let sx = d.dot(right) / (z * t * self.aspect());
        let sy = d.dot(up) / (z * t);
        Some((
            0.5 * (sx + 1.0) * self.width as f64,
            0.5 * (1.0 - sy) * self.height as f64,
        ))
    }

    /// The angle one pixel subtends (vertically, at the image centre), radians.
    pub fn pixel_angle(&self) -> f64 {
        2.0 * self.tan_half() / self.height.max(1) as f64
    }
}

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

/// Everything about how to render except the camera and the radiosities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// The display mode.
    pub shading: Shading,
    /// Radiosities are multiplied by this before clamping to [0, 1] (see
    /// [`crate::shade::Exposure::scale`]).
    pub exposure_scale: f64,
    /// Gamma factor of paper 2.7: display = value^(1 / gamma). 1 means no correction.
    pub gamma: f64,
    /// Antialiasing: each pixel is the mean of n x n rays on a regular grid inside it
    /// (averaged before gamma). 1 (the default) casts one ray through the pixel centre;
    /// 0 is treated as 1.
    pub supersample: u32,
}

impl Default for RenderSettings {
    /// Smooth shading, exposure 1, gamma 2.2, no supersampling.
    fn default() -> Self {
        RenderSettings {
            shading: Shading::Smooth,
            exposure_scale: 1.0,
            gamma: 2.2,
            supersample: 1,
        }
    }
}

/// The mesh of a scene, in a BVH of its elements (one polygon per element, tagged with the
/// element index), ready to render any number of views.
pub struct Renderer<'m> {
    mesh: &'m Mesh,
    bvh: PolygonBvh,
    /// Bounding box of all vertices (min, max).
    bounds: (DVec3, DVec3),
    /// Per element, bit i set when edge i (corner i to corner i + 1) is on the boundary of
    /// its surface (no other element shares it).
    boundary_edges: Vec<u8>,
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
        let edge = |el: &crate::mesh::Element, i: usize| {
            let c = el.corners();
            let (a, b) = (c[i], c[(i + 1) % c.len()]);
            (a.min(b), a.max(b))
        };
        let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
        for el in &mesh.elements {
            for i in 0..el.corners().len() {
                *uses.entry(edge(el, i)).or_default() += 1;
            }
        }
        let boundary_edges = mesh
            .elements
            .iter()
            .map(|el| {
                (0..el.corners().len())
                    .filter(|&i| uses[&edge(el, i)] == 1)
                    .fold(0u8, |m, i| m | (1 << i))
            })
            .collect();
        Renderer {
            mesh,
            bvh: PolygonBvh::over_elements(mesh),
            bounds: (lo, hi),
            boundary_edges,
        }
    }

    /// The mesh being rendered.
    pub fn mesh(&self) -> &'m Mesh {
        self.mesh
    }

    /// The display value (before gamma, in [0, 1] per band) seen along the unit ray
    /// `eye + t dir`; `footprint` is the angle one pixel subtends (for wireframe lines).
    fn trace(
        &self,
        eye: DVec3,
        dir: DVec3,
        footprint: f64,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        settings: &RenderSettings,
    ) -> [f64; 3] {
        if self.mesh.is_empty() {
            return [0.0; 3];
        }
        let (lo, hi) = self.bounds;
        let t_max = (eye - 0.5 * (lo + hi)).length() + (hi - lo).length() + 1.0;
        let Some(hit) = self.bvh.closest_hit(eye, dir, 0.0, t_max) else {
            return [0.0; 3];
        };
        let e = hit.id as usize;
        let el = &self.mesh.elements[e];
        if el.normal.dot(dir) >= 0.0 {
            return [0.0; 3]; // the back of a one-sided surface
        }
        let x = eye + hit.t * dir;
        match settings.shading {
            Shading::Flat => expose(element_b[e], settings.exposure_scale),
            Shading::Smooth => {
                // Interpolation weights of the element's corners at x (no allocation: this
                // runs once per ray).
                let c = el.corners();
                let mut p = [DVec3::ZERO; 4];
                for (slot, v) in p.iter_mut().zip(self.mesh.corner_positions(e)) {
                    *slot = v;
                }
                let weights: [f64; 4] = if el.is_quad() {
                    let (u, v) = inverse_bilinear(&p, x);
                    [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v]
                } else {
                    let w = barycentric(&p[..3], x);
                    [w[0], w[1], w[2], 0.0]
                };
                let mut sum = [0.0; 3];
                for (i, &w) in weights.iter().enumerate().take(c.len()) {
                    let b = vertex_b[c[i] as usize];
                    for k in 0..3 {
                        sum[k] += w * b[k];
                    }
                }
                expose(sum, settings.exposure_scale)
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
        }
    }
}

/// The distance from `x` to the segment from `a` to `b`.
fn segment_distance(x: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 {
        ((x - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (x - (a + s * ab)).length()
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
    let (v0, v1, v2) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
    let (d20, d21) = (v2.dot(v0), v2.dot(v1));
    let denom = d00 * d11 - d01 * d01;
    if denom == 0.0 {
        return [1.0 / 3.0; 3];
    }
    let w1 = (d11 * d20 - d01 * d21) / denom;
    let w2 = (d00 * d21 - d01 * d20) / denom;
    let w = [(1.0 - w1 - w2).max(0.0), w1.max(0.0), w2.max(0.0)];
    let s = w[0] + w[1] + w[2];
    if s > 0.0 {
        w.map(|x| x / s)
    } else {
        [1.0 / 3.0; 3]
    }
}

/// Renders the view of `camera` into a `camera.width` x `camera.height` image.
///
/// `element_b` holds one radiosity per element of the renderer's mesh; `vertex_b` one per
/// mesh vertex (from [`crate::shade::vertex_radiosity`]) and is read only for
/// [`Shading::Smooth`] (it may be empty otherwise). Rows are rendered in parallel; the work
/// is reported as [`Stage::Render`] with one `advance(1)` per finished row. An image with
/// no pixels is returned at once.
///
/// # Panics
/// If `element_b` (or, for smooth shading, `vertex_b`) has the wrong length.
pub fn render(
    renderer: &Renderer,
    camera: &Camera,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
    settings: &RenderSettings,
    progress: &dyn Progress,
) -> RgbImage {
    let mesh = renderer.mesh;
    assert_eq!(element_b.len(), mesh.len(), "one radiosity per element");
    if settings.shading == Shading::Smooth {
        assert_eq!(
            vertex_b.len(),
            mesh.vertices.len(),
            "one radiosity per vertex"
        );
    }
    let (w, h) = (camera.width as usize, camera.height as usize);
    if w == 0 || h == 0 {
        return RgbImage::new(camera.width, camera.height);
    }
    let screen = camera.screen();
    let footprint = camera.pixel_angle();
    let n = settings.supersample.max(1);
    let mut buf = vec![0u8; w * h * 3];
    let encoder = GammaEncoder::new(settings.gamma);
    run_stage(progress, Stage::Render, h as u64, || {
        buf.par_chunks_mut(w * 3).enumerate().for_each(|(y, row)| {
            for x in 0..w {
                let mut sum = [0.0; 3];
                for j in 0..n {
                    for i in 0..n {
                        let sx = x as f64 + (i as f64 + 0.5) / n as f64;
                        let sy = y as f64 + (j as f64 + 0.5) / n as f64;
                        let dir = camera.direction_in(screen, sx, sy);
                        let c = renderer
                            .trace(camera.eye, dir, footprint, element_b, vertex_b, settings);
                        for k in 0..3 {
                            sum[k] += c[k];
                        }
                    }
                }
                let samples = (n * n) as f64;
                let rgb = encoder.encode(sum.map(|s| s / samples));
                row[3 * x..3 * x + 3].copy_from_slice(&rgb);
            }
            progress.advance(1);
        });
    });
    RgbImage::from_raw(camera.width, camera.height, buf).expect("buffer has the image's size")
}

/// Writes `image` as a PNG file at `path`, atomically (a temporary file beside it, then a
/// rename; see [`crate::write_atomically`]).
pub fn write_png(image: &RgbImage, path: &Path) -> io::Result<()> {
    use image::ImageEncoder;
    crate::write_atomically(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(
                image.as_raw(),
                image.width(),
                image.height(),
                image::ExtendedColorType::Rgb8,
            )
            .map_err(io::Error::other)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{bilinear, mesh_scene};
    use crate::progress::NoProgress;
    use crate::scene::{MeshSettings, Rgb, Surface};
    use crate::shade::{tone_map, vertex_radiosity};
    use glam::dvec3;
    use std::sync::atomic::{AtomicU64, Ordering};

    fn scene(surfaces: Vec<Surface>) -> Scene {
        Scene {
            settings: MeshSettings {
                max_patch_area: 1.0,
                integral_steps: 1,
            },
            surfaces,
            camera: None,
        }
    }

    fn surface(name: &str, emission: f64, vertices: Vec<DVec3>) -> Surface {
        Surface {
            name: name.into(),
            emission: Rgb([emission; 3]),
            reflectance: Rgb([0.5; 3]),
            vertices,
        }
    }

    /// The rectangle [x0, x1] x [y0, y1] in the plane z, facing -z.
    fn facing_minus_z(x0: f64, x1: f64, y0: f64, y1: f64, z: f64) -> Vec<DVec3> {
        vec![
            dvec3(x0, y0, z),
            dvec3(x0, y1, z),
            dvec3(x1, y1, z),
            dvec3(x1, y0, z),
        ]
    }

    fn cornell_camera(width: u32, height: u32) -> Camera {
        Camera {
            eye: dvec3(278.0, 273.0, -800.0),
            look_at: dvec3(278.0, 273.0, 0.0),
            up: DVec3::Y,
            fov_y_degrees: 39.3077,
            width,
            height,
        }
    }

    fn test_image_dir() -> Option<std::path::PathBuf> {
        std::env::var_os("RADIOSITY_TEST_IMAGE_DIR").map(Into::into)
    }

    fn px(img: &RgbImage, x: u32, y: u32) -> [u8; 3] {
        img.get_pixel(x, y).0
    }

    #[test]
    fn cornell_camera_orientation() {
        let cam = cornell_camera(200, 100);
        let (f, r, u) = cam.basis();
        assert!((f - DVec3::Z).length() < 1e-15);
        assert!((r + DVec3::X).length() < 1e-15); // image right is scene -x
        assert!((u - DVec3::Y).length() < 1e-15);
        // The look-at point is the image centre.
        let (x, y) = cam.project(cam.look_at).unwrap();
        assert!((x - 100.0).abs() < 1e-9 && (y - 50.0).abs() < 1e-9);
        // The red wall (x = 556) is on the left, the green wall (x = 0) on the right.
        let (red_x, _) = cam.project(dvec3(556.0, 273.0, 0.0)).unwrap();
        let (green_x, _) = cam.project(dvec3(0.0, 273.0, 0.0)).unwrap();
        assert!(red_x < 100.0 && green_x > 100.0);
        // Larger y is nearer the top (smaller row index).
        let (_, high) = cam.project(dvec3(278.0, 500.0, 0.0)).unwrap();
        let (_, low) = cam.project(dvec3(278.0, 50.0, 0.0)).unwrap();
        assert!(high < 50.0 && low > 50.0);
        assert!(cam.project(dvec3(278.0, 273.0, -900.0)).is_none());
        // The ray through a projected point leads back to it.
        let p = dvec3(400.0, 100.0, 300.0);
        let (x, y) = cam.project(p).unwrap();
        let d = cam.ray_direction(x, y);
        assert!((d - (p - cam.eye).normalize()).length() < 1e-12);
    }

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

    struct Count(AtomicU64, AtomicU64);
    impl Progress for Count {
        fn start(&self, stage: Stage, total: u64) {
            assert_eq!(stage, Stage::Render);
            self.0.store(total, Ordering::SeqCst);
        }
        fn advance(&self, done: u64) {
            self.1.fetch_add(done, Ordering::SeqCst);
        }
        fn finish(&self, _: Stage, _: std::time::Duration) {}
    }

    #[test]
    fn progress_counts_rows_and_png_round_trips() {
        let s = scene(vec![surface(
            "a",
            0.0,
            facing_minus_z(-1., 1., -1., 1., 0.),
        )]);
        let mesh = mesh_scene(&s, 1.0).unwrap();
        let eb = vec![[0.2, 0.4, 0.6]; mesh.len()];
        let r = Renderer::new(&mesh);
        let cam = Camera {
            eye: dvec3(0., 0., -3.),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 50.0,
            width: 13,
            height: 7,
        };
        let count = Count(AtomicU64::new(0), AtomicU64::new(0));
        let settings = RenderSettings {
            shading: Shading::Flat,
            gamma: 1.0,
            ..RenderSettings::default()
        };
        let img = render(&r, &cam, &eb, &[], &settings, &count);
        assert_eq!(img.dimensions(), (13, 7));
        assert_eq!(count.0.load(Ordering::SeqCst), 7);
        assert_eq!(count.1.load(Ordering::SeqCst), 7);
        assert_eq!(px(&img, 6, 3), [51, 102, 153]);
        let dir = std::env::temp_dir().join(format!("radiosity-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("view.png");
        write_png(&img, &path).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back, img);
        std::fs::remove_dir_all(&dir).unwrap();
        // Zero-sized requests give empty images.
        let empty = render(
            &r,
            &Camera { width: 0, ..cam },
            &eb,
            &[],
            &settings,
            &NoProgress,
        );
        assert_eq!(empty.dimensions(), (0, 7));
    }

    /// A closed room, faces inward, with a light in the ceiling: the Cornell box layout
    /// (red wall at x = 556, green at x = 0) closed by a front wall at z = 0.
    fn room() -> Scene {
        let (w, h, d) = (556.0, 548.0, 559.0);
        // Each wall's corners run counter-clockwise seen from inside.
        let floor = vec![
            dvec3(0., 0., 0.),
            dvec3(0., 0., d),
            dvec3(w, 0., d),
            dvec3(w, 0., 0.),
        ];
        let ceiling = floor
            .iter()
            .rev()
            .map(|p| dvec3(p.x, h - 0.5, p.z))
            .collect();
        let back = vec![
            dvec3(0., 0., d),
            dvec3(0., h, d),
            dvec3(w, h, d),
            dvec3(w, 0., d),
        ];
        let front = back.iter().rev().map(|p| dvec3(p.x, p.y, 0.)).collect();
        let green = vec![
            dvec3(0., 0., 0.),
            dvec3(0., h, 0.),
            dvec3(0., h, d),
            dvec3(0., 0., d),
        ];
        let red = green.iter().rev().map(|p| dvec3(w, p.y, p.z)).collect();
        let light = vec![
            dvec3(213., h - 1.0, 227.),
            dvec3(343., h - 1.0, 227.),
            dvec3(343., h - 1.0, 332.),
            dvec3(213., h - 1.0, 332.),
        ];
        let mut s = scene(vec![
            surface("floor", 0.0, floor),
            surface("ceiling", 0.0, ceiling),
            surface("back", 0.0, back),
            surface("front", 0.0, front),
            surface("green", 0.0, green),
            surface("red", 0.0, red),
            surface("light", 1.0, light),
        ]);
        s.surfaces[4].reflectance = Rgb([0.1, 0.6, 0.1]);
        s.surfaces[5].reflectance = Rgb([0.6, 0.1, 0.1]);
        s
    }

    /// Made-up radiosities: emitters 10, others reflectance x (inverse-square-like falloff
    /// from the light's centre) x cosine at the receiver.
    fn made_up_b(s: &Scene, mesh: &Mesh) -> Vec<[f64; 3]> {
        let light = dvec3(278.0, 547.0, 279.5);
        mesh.elements
            .iter()
            .map(|el| {
                let surf = &s.surfaces[el.surface as usize];
                if surf.emission.max_band() > 0.0 {
                    return [10.0; 3];
                }
                let d = light - el.centroid;
                let cos = (el.normal.dot(d) / d.length()).max(0.0);
                let fall = cos / (1.0 + d.length_squared() / 300.0f64.powi(2));
                surf.reflectance.0.map(|r| r * fall + 0.02)
            })
            .collect()
    }

    #[test]
    fn room_camera_sees_the_room_from_inside() {
        let s = room();
        let cam = Camera::for_scene(&s, 96, 72);
        let (lo, hi) = s.bounds();
        // Inside the box.
        assert!(
            cam.eye.cmpgt(lo).all() && cam.eye.cmplt(hi).all(),
            "{cam:?}"
        );
        let mesh = mesh_scene(&s, 1500.0).unwrap();
        let eb = made_up_b(&s, &mesh);
        let vb = vertex_radiosity(&mesh, &eb);
        let r = Renderer::new(&mesh);
        let scale = crate::shade::Exposure::Brightest.scale(&s, &mesh, &eb);
        let settings = RenderSettings {
            exposure_scale: scale,
            ..RenderSettings::default()
        };
        let img = render(&r, &cam, &eb, &vb, &settings, &NoProgress);
        // Every ray from inside a closed room hits a front face: no black pixel.
        for (x, y, p) in img.enumerate_pixels() {
            assert_ne!(p.0, [0; 3], "pixel ({x}, {y})");
        }
        // The red wall (x = 556) is on the left, green on the right, at mid height.
        let left = px(&img, 1, 36);
        let right = px(&img, 94, 36);
        assert!(
            left[0] > left[1] && right[1] > right[0],
            "{left:?} {right:?}"
        );
        if let Some(dir) = test_image_dir() {
            for (name, shading, n) in [
                ("smooth", Shading::Smooth, 2),
                ("flat", Shading::Flat, 1),
                ("wireframe", Shading::Wireframe, 2),
            ] {
                let settings = RenderSettings {
                    shading,
                    supersample: n,
                    ..settings
                };
                let cam = Camera::for_scene(&s, 320, 240);
                let img = render(&r, &cam, &eb, &vb, &settings, &NoProgress);
                write_png(&img, &dir.join(format!("room-{name}.png"))).unwrap();
            }
            // Without its front wall, through the Cornell camera (outside, at z = -800):
            // the light in the ceiling is in view, and clipped to white.
            let mut open = room();
            open.surfaces.remove(3);
            let mesh = mesh_scene(&open, 1500.0).unwrap();
            let eb = made_up_b(&open, &mesh);
            let vb = vertex_radiosity(&mesh, &eb);
            let settings = RenderSettings {
                supersample: 2,
                exposure_scale: crate::shade::Exposure::Brightest.scale(&open, &mesh, &eb),
                ..settings
            };
            let cam = cornell_camera(320, 320);
            let img = render(
                &Renderer::new(&mesh),
                &cam,
                &eb,
                &vb,
                &settings,
                &NoProgress,
            );
            write_png(&img, &dir.join("room-cornell-camera.png")).unwrap();
        }
    }

    #[test]
    fn outside_camera_for_objects() {
        // A closed cube with outward faces is seen from outside, and a flat wall from -z.
        let c = |x: f64, y: f64, z: f64| dvec3(x, y, z);
        let cube = vec![
            facing_minus_z(0., 1., 0., 1., 0.),
            vec![c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
            vec![c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            vec![c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)],
            vec![c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)],
            vec![c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
        ];
        let s = scene(
            cube.into_iter()
                .enumerate()
                .map(|(i, v)| surface(&format!("f{i}"), 0.0, v))
                .collect(),
        );
        let cam = Camera::for_scene(&s, 32, 32);
        let outside = cam.eye.cmplt(DVec3::ZERO).any() || cam.eye.cmpgt(DVec3::ONE).any();
        assert!(outside, "{cam:?}");
        let mesh = mesh_scene(&s, 1.0).unwrap();
        let eb = vec![[1.0; 3]; mesh.len()];
        let vb = vertex_radiosity(&mesh, &eb);
        let img = render(
            &Renderer::new(&mesh),
            &cam,
            &eb,
            &vb,
            &RenderSettings::default(),
            &NoProgress,
        );
        assert_eq!(px(&img, 16, 16), [255; 3]);
        let wall = scene(vec![surface("w", 0.0, facing_minus_z(0., 4., 0., 2., 3.))]);
        let cam = Camera::for_scene(&wall, 40, 30);
        assert!(cam.eye.z < 3.0 && (cam.look_at - dvec3(2., 1., 3.)).length() < 1e-12);
        // The whole wall is in view.
        for p in &wall.surfaces[0].vertices {
            let (x, y) = cam.project(*p).unwrap();
            assert!((0.0..=40.0).contains(&x) && (0.0..=30.0).contains(&y));
        }
    }
}
