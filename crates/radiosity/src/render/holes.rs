//! Where a ray meets a surface at a point that no element covers, and what it shows there.
//!
//! Contact refinement ([`crate::mesh::contact`]) and hierarchical radiosity's buried leaves
//! drop the pieces of a surface that lie buried under or inside other surfaces: no light
//! reaches them, so they carry none. A camera ray can still reach the edge of such a region
//! through a gap: the ceiling above a light panel hanging 5 cm below it, seen at a grazing
//! angle past the panel's far edge. Without the surfaces, the ray went through the hole and
//! showed what lay behind the ceiling: black (a strip along the far edge of each panel of
//! `examples/room.scene`), or a room beyond the wall. Rays grazing a surface's outline
//! between its elements' edges slipped through the same way (dotted cracks).
//!
//! [`Holes`] casts each ray against the scene's surfaces as well. Where a front face is met
//! nearer than any element (by more than [`HOLE_DEPTH`] of the scene's size), the ray has
//! found an uncovered point x of that surface. It shows the radiosity of the surface's
//! nearest element, at the point of that element nearest to x, times the share of x's
//! cosine-weighted hemisphere that is open ([`Holes::open_share`]: [`OPEN_SHARE_RAYS`]
//! directions whose first hit is a front face, or nothing): a point a camera ray reaches
//! through a gap sees some of the room, but much of its sky is the back of what buries it,
//! and its irradiance is about the neighbour's scaled by what it sees of the room (exact
//! where the light arriving is uniform over the hemisphere). A back face met there stops the
//! ray (black), as the surface does. The share scales the whole radiosity, emission
//! included: a buried piece of an emitter seen through a gap would show darker than its
//! emission (the renderer holds no emission per element; no scene here has one).

use glam::DVec3;

use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::visibility::PolygonBvh;

/// How much nearer than the element hit (relative to the scene's size) a surface hit must be
/// to count as a hole: far above the rounding between an element and the surface it was
/// cut from (and the 1e-7 lift of a surface lying on another, `with_surfaces_on_top`), far
/// below any gap a hole opens onto.
pub const HOLE_DEPTH: f64 = 1e-5;

/// Directions [`Holes::open_share`] casts from an uncovered point: a cosine-weighted
/// spiral (Fibonacci lattice on the unit disc, lifted to the hemisphere), the same for
/// every point (deterministic, no noise between neighbouring pixels).
pub const OPEN_SHARE_RAYS: usize = 32;

/// The scene's surfaces, to find where a ray meets one that no element covers.
pub(super) struct Holes {
    surfaces: PolygonBvh,
    normals: Vec<DVec3>,
    /// [`HOLE_DEPTH`] times the scene's size.
    depth: f64,
}

/// What a ray met where no element covers a surface.
pub(super) enum Uncovered {
    /// The front of surface `surface` at point `x`.
    Front { surface: u32, x: DVec3 },
    /// The back of a surface: black.
    Back,
}

impl Holes {
    /// The surfaces of `scene` (from which the mesh was cut).
    pub(super) fn new(scene: &Scene) -> Holes {
        let surfaces = PolygonBvh::over_surfaces(scene);
        let depth = HOLE_DEPTH * surfaces.scale();
        Holes {
            surfaces,
            normals: scene
                .surfaces
                .iter()
                .map(|s| crate::geometry::polygon_normal(&s.vertices).unwrap_or(DVec3::ZERO))
                .collect(),
            depth,
        }
    }

    /// The uncovered surface the ray from `eye` along unit `dir` meets before the element
    /// it hits at `t_element` (None: it hits none, within `t_max`), if any.
    pub(super) fn uncovered(
        &self,
        eye: DVec3,
        dir: DVec3,
        t_min: f64,
        t_element: Option<f64>,
        t_max: f64,
    ) -> Option<Uncovered> {
        let limit = t_element.map_or(t_max, |t| t - self.depth);
        if limit <= t_min {
            return None;
        }
        let hit = self.surfaces.closest_hit(eye, dir, t_min, limit)?;
        if self.normals[hit.id as usize].dot(dir) >= 0.0 {
            return Some(Uncovered::Back);
        }
        Some(Uncovered::Front {
            surface: hit.id,
            x: eye + hit.t * dir,
        })
    }

    /// The cosine-weighted share of the hemisphere above the point `x` of `surface` whose
    /// first hit is a front face or nothing (module documentation): 1 in the open, 0 where
    /// every direction meets the back of what buries it.
    pub(super) fn open_share(&self, surface: u32, x: DVec3) -> f64 {
        let n = self.normals[surface as usize];
        if n == DVec3::ZERO {
            return 0.0;
        }
        let (t, b) = n.any_orthonormal_pair();
        let origin = x + self.depth * n;
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let open = (0..OPEN_SHARE_RAYS)
            .filter(|&i| {
                let u = (i as f64 + 0.5) / OPEN_SHARE_RAYS as f64;
                let (r, phi) = (u.sqrt(), golden * i as f64);
                let dir = r * phi.cos() * t + r * phi.sin() * b + (1.0 - u).sqrt() * n;
                match self.surfaces.closest_hit(origin, dir, 0.0, f64::INFINITY) {
                    None => true,
                    Some(hit) => self.normals[hit.id as usize].dot(dir) < 0.0,
                }
            })
            .count();
        open as f64 / OPEN_SHARE_RAYS as f64
    }
}

/// The element of `surface` nearest to the point `x` of its plane, and the point of that
/// element nearest to `x` (its boundary's, x lying outside every element of the surface);
/// None when the surface has no element. A scan of the surface's elements: it runs only
/// for the few rays that meet a hole.
pub(super) fn nearest_element(mesh: &Mesh, surface: u32, x: DVec3) -> Option<(usize, DVec3)> {
    let range = mesh.surface_elements.get(surface as usize)?.clone();
    let mut best: Option<(f64, usize, DVec3)> = None;
    for e in range {
        let e = e as usize;
        let p: Vec<DVec3> = mesh.corner_positions(e).collect();
        for i in 0..p.len() {
            let q = closest_on_segment(x, p[i], p[(i + 1) % p.len()]);
            let d = (x - q).length_squared();
            if best.is_none_or(|(bd, _, _)| d < bd) {
                best = Some((d, e, q));
            }
        }
    }
    best.map(|(_, e, q)| (e, q))
}

/// The point of the segment from `a` to `b` nearest to `x`.
pub(super) fn closest_on_segment(x: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 {
        ((x - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + s * ab
}

#[cfg(test)]
mod tests {
    use glam::dvec3;

    use super::*;
    use crate::mesh::mesh_scene;
    use crate::progress::NoProgress;
    use crate::render::test_support::{facing_up, scene, surface};
    use crate::render::{Camera, Renderer, Shading};

    #[test]
    fn a_ray_through_a_dropped_piece_sees_the_surface_not_what_lies_behind() {
        // A 2 x 2 floor cut into four 1 x 1 elements, one of them dropped (as contact
        // refinement drops a buried piece), every element at B = 0.5, seen from above with
        // nothing over it: every ray that lands on the floor (1 cm in from its outline, against
        // rounding there) must show 0.5, the open share being 1 with nothing above. Without
        // the surfaces the rays over the dropped quarter see nothing behind it (0).
        let s = scene(vec![surface("floor", 0.0, facing_up(0., 2., 0., 2., 0.))]);
        let grid = mesh_scene(&s, 1.0).unwrap();
        assert_eq!(grid.len(), 4);
        let mut pieces = vec![None; 4];
        pieces[0] = Some(Vec::new());
        let mesh = grid.with_pieces(1, &pieces);
        assert_eq!(mesh.len(), 3);
        let eb = vec![[0.5; 3]; mesh.len()];
        let cam = Camera {
            eye: dvec3(1.0, 3.0, 1.0),
            look_at: dvec3(1.0, 0.0, 1.0),
            up: DVec3::Z,
            fov_y_degrees: 40.0,
            width: 40,
            height: 40,
        };
        let screen = cam.screen();
        let count = |r: &Renderer| {
            let film = r.film(&cam, &eb, &[], Shading::Flat, 1, &NoProgress);
            let (mut on_floor, mut other) = (0, 0);
            for y in 0..cam.height as usize {
                for x in 0..cam.width as usize {
                    let dir = cam.direction_in(screen, x as f64 + 0.5, y as f64 + 0.5);
                    let p = cam.eye + (-cam.eye.y / dir.y) * dir;
                    if p.x > 0.01 && p.x < 1.99 && p.z > 0.01 && p.z < 1.99 {
                        on_floor += 1;
                        if film.pixel(x, y)[0][0] != 0.5 {
                            other += 1;
                        }
                    }
                }
            }
            (on_floor, other)
        };
        let (on_floor, black) = count(&Renderer::new(&mesh));
        assert!(on_floor > 1000, "{on_floor}");
        assert!(
            black > on_floor / 8,
            "{black} of {on_floor}: the hole did not show"
        );
        let (_, wrong) = count(&Renderer::new(&mesh).with_holes_covered(&s));
        assert_eq!(
            wrong, 0,
            "{wrong} of {on_floor} floor pixels not at B = 0.5"
        );
    }

    #[test]
    fn open_share_under_a_lid_is_one_less_the_point_to_square_form_factor() {
        // A point of a floor under a lid: the square of half-width a = 0.5 at height
        // h = 0.5 centred over it, its back facing the floor. The cosine-weighted share of
        // the point's hemisphere the lid's back takes is the form factor from a point to a
        // parallel square centred over it, four times that to an a x a rectangle from its
        // corner (Howell's catalogue, B-3; A = B = a / h = 1):
        // F = (1 / 2 pi) (2 A / sqrt(1 + A^2) atan(A / sqrt(1 + A^2))) = 0.138 53, so the open
        // share is 1 - 4 F = 0.4459. Tolerance 2 / 32: each of the 32 directions carries
        // 1/32 of the measure, and the lattice may misplace one ray on each side of the
        // lid's outline.
        let s = scene(vec![
            surface("floor", 0.0, facing_up(-5., 5., -5., 5., 0.)),
            surface("lid", 0.0, facing_up(-0.5, 0.5, -0.5, 0.5, 0.5)),
        ]);
        let holes = Holes::new(&s);
        let a = 1.0f64;
        let corner = (2.0 * a / (1.0 + a * a).sqrt() * (a / (1.0 + a * a).sqrt()).atan())
            / (2.0 * std::f64::consts::PI);
        let want = 1.0 - 4.0 * corner;
        assert!((want - 0.4459).abs() < 1e-4, "{want}");
        let got = holes.open_share(0, DVec3::ZERO);
        assert!(
            (got - want).abs() <= 2.0 / 32.0,
            "open share {got}, closed form {want}"
        );
        // Far from the lid (seen 4.7 degrees above the horizon at most, below the lowest of
        // the 32 directions, 7.2 degrees): wholly open.
        assert_eq!(holes.open_share(0, dvec3(4.5, 0.0, 4.5)), 1.0);
    }
}
