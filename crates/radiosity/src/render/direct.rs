//! Direct light gathered where the eye looks: the irradiance a point receives straight from
//! the emitters, computed at the point itself with Lambert's exact point-to-polygon form
//! factor and shadow rays, instead of read off the mesh.
//!
//! A radiosity solution is piecewise constant on its elements, and smooth shading
//! interpolates it linearly; where the light changes faster than an element (shadow edges,
//! the lines where a box stands on a floor, the corners where walls meet a lit ceiling) the
//! interpolation smears it. Most of that fast change is the *direct* part of the light, the
//! irradiance `D(x) = sum_j E_j F(x -> j) V(x, j)` from the emitters j (exitance E_j, exact
//! unoccluded form factor F, visible fraction V). So the renderer replaces the mesh's linear
//! approximation of the direct part by the point's own value, and keeps the mesh for the
//! rest (the indirect light, which varies slowly):
//!
//! ```text
//! B(x) = B_smooth(x) + rho(x) (D(x) - D_smooth(x))
//! ```
//!
//! where `B_smooth` is the smooth-shaded radiosity and `D_smooth` is the element averages of
//! D interpolated exactly as B is (the same vertex averaging and the same weights). Where D
//! is linear across the elements the correction vanishes; an element's average of the
//! corrected B stays the solver's B_i (up to the interpolation), so the solution's energy
//! is not changed, only where within the element the light falls. This is the "ray-traced
//! direct illumination" pass of lighting-design tools (Lightscape; Shirley 1990, "A ray
//! tracing method for illumination calculation in diffuse-specular scenes", Graphics
//! Interface 90, which gathers the direct light per pixel and takes the indirect part from
//! a radiosity pass), and the direct-light half of a final gather (Lischinski, Tampieri and
//! Greenberg 1993, "Combining hierarchical radiosity and discontinuity meshing", SIGGRAPH 93).
//!
//! The visible fraction is estimated with shadow rays to stratified points of the emitter
//! (each point weighted by its area and the point-to-point kernel cos cos / r^2, so that a
//! fully visible emitter gives Lambert's exact value and a fully hidden one exactly 0): a
//! first pass of about [`COARSE_RAYS`] rays, and where they disagree (a penumbra) a finer
//! pass of four times as many. Each stratum's point is jittered by a hash of a caller's
//! salt and the stratum (stratified sampling: the strata's errors are independent and
//! mostly cancel, where one shift for all of them would add up). The renderer salts by
//! ray (pixel and position in it), so that penumbrae show fine noise rather than bands,
//! and a pixel's rays average it: salted by pixel alone, every ray of a pixel shared its
//! strata and the penumbrae came out visibly grainy at 400 pixels across (QA of issue
//! #16). The noise then also asks adaptive antialiasing for more rays in penumbrae, which
//! is where they are needed: the default Cornell box render took 4.25 -> 4.78 s, the
//! occluder's shadow seen close 2.22 -> 4.10 s, the pixel RMS against the path tracer
//! unchanged (2.25 / 2.24 %; BENCHMARKS.md). The result depends on the point and the salt only, not on
//! threads or order.

use std::sync::OnceLock;

use glam::DVec3;

use super::renderer::Interpolation;
use crate::form_factor::exact::point_to_polygon;
use crate::geometry;
use crate::light::Rgb;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::splitmix::jitter;
use crate::visibility::PolygonBvh;

/// Shadow rays per emitter in the first pass at a point (about: the strata are whole
/// grids on each of the emitter's triangles).
pub const COARSE_RAYS: usize = 16;

/// Each element's average direct irradiance is taken over this many x this many points
/// (see [`Mesh::integration_points`]).
const ELEMENT_POINTS: u32 = 3;

/// One emitting surface: its polygon, exitance, and how its points are sampled.
#[derive(Clone, Debug)]
struct Emitter {
    /// Its surface's index (the occluders' id of it).
    surface: u32,
    polygon: Vec<DVec3>,
    normal: DVec3,
    exitance: Rgb,
    /// Where the strata lie: the quadrilateral's bilinear map, or a fan of triangles.
    strata: Strata,
    /// Strata per axis in the coarse pass (the fine pass has twice as many).
    coarse: usize,
}

/// The parameter domains that a grid of strata covers.
#[derive(Clone, Debug)]
enum Strata {
    /// A quadrilateral: one grid over its bilinear parameters, weighted by the Jacobian
    /// (most emitters are rectangles, and one grid across the whole light resolves a shadow
    /// edge far better than grids on the two halves of a diagonal).
    Quad([DVec3; 4]),
    /// A triangle or a polygon of five or more corners: a fan of triangles from corner 0
    /// with their areas, a grid on each through the area-preserving square-to-triangle map.
    Fan(Vec<([DVec3; 3], f64)>),
}

impl Emitter {
    fn new(index: usize, surface: &crate::scene::Surface) -> Option<Emitter> {
        let normal = geometry::polygon_normal(&surface.vertices)?;
        let v = &surface.vertices;
        let (strata, domains) = if v.len() == 4 {
            (Strata::Quad([v[0], v[1], v[2], v[3]]), 1)
        } else {
            let triangles: Vec<([DVec3; 3], f64)> = (1..v.len() - 1)
                .map(|i| {
                    let t = [v[0], v[i], v[i + 1]];
                    (t, 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
                })
                .filter(|(_, a)| *a > 0.0)
                .collect();
            if triangles.is_empty() {
                return None;
            }
            let n = triangles.len();
            (Strata::Fan(triangles), n)
        };
        let per_domain = COARSE_RAYS as f64 / domains as f64;
        Some(Emitter {
            surface: index as u32,
            polygon: v.clone(),
            normal,
            exitance: surface.emission,
            coarse: per_domain.sqrt().round().max(1.0) as usize,
            strata,
        })
    }

    /// Calls `f(point, area weight)` for the `m` x `m` strata of each domain, each point
    /// jittered within its stratum by a hash of `salt` and the stratum.
    fn for_each_point(&self, m: usize, salt: u64, mut f: impl FnMut(DVec3, f64)) {
        let cell = 1.0 / m as f64;
        let at = |domain: usize, i: usize, j: usize| {
            let (a, b) = jitter(salt, (domain * m + j) * m + i);
            ((i as f64 + a) * cell, (j as f64 + b) * cell)
        };
        match &self.strata {
            Strata::Quad(q) => {
                for j in 0..m {
                    for i in 0..m {
                        let (u, v) = at(0, i, j);
                        let du = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
                        let dv = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
                        f(
                            crate::mesh::bilinear(q, u, v),
                            du.cross(dv).length() * cell * cell,
                        );
                    }
                }
            }
            Strata::Fan(triangles) => {
                for (k, (t, area)) in triangles.iter().enumerate() {
                    for j in 0..m {
                        for i in 0..m {
                            let (u1, u2) = at(k, i, j);
                            // Square to triangle, area-preserving (Shirley 1992, "Nonuniform
                            // random point sets via warping", Graphics Gems III).
                            let s = u1.sqrt();
                            let y = t[0] * (1.0 - s) + t[1] * (s * (1.0 - u2)) + t[2] * (s * u2);
                            f(y, area * cell * cell);
                        }
                    }
                }
            }
        }
    }

    /// The kernel-weighted visible fraction of the emitter seen from `x` (normal `n`), with
    /// `m` x `m` jittered strata per domain (see `for_each_point`): (sum of weight x visibility, sum of
    /// weights, rays all agreed).
    fn visible(
        &self,
        occluders: &PolygonBvh,
        x: DVec3,
        n: DVec3,
        m: usize,
        salt: u64,
    ) -> (f64, f64, bool) {
        let (mut seen, mut total) = (0.0, 0.0);
        let (mut any_seen, mut any_hidden) = (false, false);
        self.for_each_point(m, salt, |y, area| {
            let d = y - x;
            let r2 = d.length_squared();
            let (cx, cy) = (n.dot(d), -self.normal.dot(d));
            if cx <= 0.0 || cy <= 0.0 || r2 <= 0.0 {
                return;
            }
            let w = area * cx * cy / (r2 * r2);
            total += w;
            // The emitter itself cannot hide its own points (see `segment_blocked_except`).
            if occluders.segment_blocked_except(x, y, self.surface) {
                any_hidden = true;
            } else {
                any_seen = true;
                seen += w;
            }
        });
        (seen, total, !(any_seen && any_hidden))
    }
}

/// The emitters of a scene and its surfaces as occluders: the direct irradiance at any
/// point ([`DirectLight::irradiance`]).
pub struct DirectLight {
    emitters: Vec<Emitter>,
    /// The point luminaires: I cos / d^2 with one shadow ray each (sharp shadows).
    points: Vec<crate::luminaire::Luminaire>,
    occluders: PolygonBvh,
}

impl DirectLight {
    /// The emitters (surfaces with some positive exitance) of `scene`, with its surfaces
    /// as occluders.
    pub fn new(scene: &Scene) -> DirectLight {
        DirectLight {
            emitters: scene
                .surfaces
                .iter()
                .enumerate()
                .filter(|(_, s)| s.emission.max_band() > 0.0)
                .filter_map(|(i, s)| Emitter::new(i, s))
                .collect(),
            points: scene.lights.clone(),
            occluders: PolygonBvh::over_surfaces(scene),
        }
    }

    /// True when the scene has no emitter and no point luminaire (every irradiance is then
    /// 0).
    pub fn is_empty(&self) -> bool {
        self.emitters.is_empty() && self.points.is_empty()
    }

    /// The direct illuminance at `x` (unit normal `n`) from the point luminaires alone,
    /// I cos / d^2 for each whose segment to `x` is clear.
    pub fn point_irradiance(&self, x: DVec3, n: DVec3) -> Rgb {
        let mut sum = Rgb::default();
        for l in &self.points {
            let e = l.irradiance_unoccluded(x, n);
            if e.max_band() > 0.0 && !self.occluders.segment_blocked(x, l.position) {
                sum += e;
            }
        }
        sum
    }

    /// The direct irradiance at `x` on a surface with unit front normal `n`:
    /// `sum_j E_j F(x -> j) V_j` over the emitting surfaces plus the point luminaires'
    /// ([`DirectLight::point_irradiance`]), per band (the quantity that, times rho, is the
    /// direct part of the reflected radiosity). `salt` jitters the shadow rays' strata.
    pub fn irradiance(&self, x: DVec3, n: DVec3, salt: u64) -> Rgb {
        self.surface_irradiance(x, n, salt) + self.point_irradiance(x, n)
    }

    /// The direct irradiance at `x` (unit normal `n`) from the emitting surfaces alone.
    ///
    /// Emitters that would bring less than [`WEAK_SHARE`] of the point's unoccluded direct
    /// light start with a coarse pass of half the strata per axis (a quarter of the rays):
    /// in a building, most emitters that face a point are in other rooms, hidden whole,
    /// and their sixteen rays each were most of a render's time. Where those rays disagree
    /// the fine pass runs as for any emitter, so penumbrae are sampled as finely as before.
    /// The weak emitters' shares together are capped at [`WEAK_TOTAL`] (a point seeing
    /// fifty equal small lights samples most of them as strong ones).
    pub fn surface_irradiance(&self, x: DVec3, n: DVec3, salt: u64) -> Rgb {
        let mut sum = Rgb::default();
        // The form factors, on the stack for up to 64 emitters.
        let (mut stack, mut heap) = ([0.0f64; 64], Vec::new());
        let factors: &mut [f64] = if self.emitters.len() <= stack.len() {
            &mut stack[..self.emitters.len()]
        } else {
            heap.resize(self.emitters.len(), 0.0);
            &mut heap
        };
        let mut unoccluded = 0.0;
        for (e, slot) in self.emitters.iter().zip(factors.iter_mut()) {
            let f = point_to_polygon(x, n, &e.polygon);
            *slot = f;
            if f > 0.0 {
                unoccluded += e.exitance.max_band() * f;
            }
        }
        // The weak emitters' shares together stay within WEAK_TOTAL, so that a point seeing
        // fifty equal small lights past a thin occluder does not sample them all coarsely.
        let mut weak_budget = WEAK_TOTAL * unoccluded;
        for (e, &f) in self.emitters.iter().zip(factors.iter()) {
            if f <= 0.0 {
                continue;
            }
            let share = e.exitance.max_band() * f;
            let weak = share < WEAK_SHARE * unoccluded && share <= weak_budget;
            if weak {
                weak_budget -= share;
            }
            let coarse = if weak { e.coarse.div_ceil(2) } else { e.coarse };
            let (mut seen, mut total, agreed) = e.visible(&self.occluders, x, n, coarse, salt);
            if !agreed {
                (seen, total, _) = e.visible(&self.occluders, x, n, 2 * e.coarse, salt ^ FINE_SALT);
            }
            // All strata behind the point's plane while Lambert sees a sliver: count it seen.
            let fraction = if total > 0.0 { seen / total } else { 1.0 };
            sum += e.exitance * (f * fraction);
        }
        sum
    }
}

/// The share of a point's unoccluded direct light below which an emitter's first pass of
/// shadow rays is a quarter as many (see [`DirectLight::surface_irradiance`]).
pub const WEAK_SHARE: f64 = 0.02;

/// The most of a point's unoccluded direct light that weak emitters together may bring
/// (taken in the scene's order of emitters): what a coarse first pass can misjudge at most.
pub const WEAK_TOTAL: f64 = 0.2;

/// Salts the fine pass apart from the coarse one.
const FINE_SALT: u64 = 0x6a09_e667_f3bc_c909;

/// The correction of smooth shading by the direct light at each point (see the module
/// documentation): `rho(x) (D(x) - D_smooth(x))`, for one mesh of one scene, whatever the
/// solution. Element averages of D are computed the first time a view needs them, so a
/// view of a corner of a large mesh costs only the elements it shows.
pub struct DirectCorrection<'m> {
    light: DirectLight,
    mesh: &'m Mesh,
    /// Reflectance per surface.
    reflectance: Vec<Rgb>,
    /// How each vertex takes its value from the elements' ([`crate::shade::vertex_rule`],
    /// the rule of `vertex_radiosity`), so that D is interpolated exactly as B is.
    rule: crate::shade::VertexRule,
    /// Which vertices smooth shading joins across the facets of a curved object
    /// ([`crate::shade::smooth_objects`]), so that D is joined where B is, and the shading
    /// normals that follow from the joins.
    joins: crate::shade::ObjectJoins,
    /// Per element, whether one of its vertices has a shading normal of its own (a facet
    /// of a curved object); the others take their plane's normal.
    curved: Vec<bool>,
    /// Per element, its average direct irradiance, once computed.
    element_direct: Vec<OnceLock<Rgb>>,
    /// Per vertex, its elements' averages combined by the vertex rule, once computed.
    rule_direct: Vec<OnceLock<Rgb>>,
    /// Per vertex, those values joined across facets as B's are, once computed.
    vertex_direct: Vec<OnceLock<Rgb>>,
}

impl<'m> DirectCorrection<'m> {
    /// The correction for `mesh`, which was cut from `scene`.
    pub fn new(scene: &Scene, mesh: &'m Mesh) -> DirectCorrection<'m> {
        let joins = crate::shade::ObjectJoins::new(scene, mesh);
        let display = mesh.display();
        let curved = (0..mesh.len())
            .map(|e| {
                display
                    .polygon(e)
                    .iter()
                    .any(|&c| joins.is_curved(c as usize))
            })
            .collect();
        DirectCorrection {
            light: DirectLight::new(scene),
            mesh,
            reflectance: scene.surfaces.iter().map(|s| s.reflectance).collect(),
            rule: crate::shade::vertex_rule(mesh),
            joins,
            curved,
            element_direct: (0..mesh.len()).map(|_| OnceLock::new()).collect(),
            rule_direct: (0..mesh.vertices.len()).map(|_| OnceLock::new()).collect(),
            vertex_direct: (0..mesh.vertices.len()).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The average direct irradiance over element `e`.
    fn element(&self, e: usize) -> Rgb {
        *self.element_direct[e].get_or_init(|| {
            let el = &self.mesh.elements[e];
            let mut points = Vec::with_capacity((ELEMENT_POINTS * ELEMENT_POINTS) as usize);
            self.mesh.integration_points(e, ELEMENT_POINTS, &mut points);
            let mut sum = Rgb::default();
            let mut area = 0.0;
            for (k, &(x, w)) in points.iter().enumerate() {
                // Salts of their own (bit 63 set); the renderer's hashed ones may meet
                // them by chance, which changes nothing but which strata are drawn.
                let salt = (1 << 63) | (e as u64 * 64 + k as u64);
                sum += self.light.irradiance(x, el.normal, salt) * w;
                area += w;
            }
            if area > 0.0 {
                sum * (1.0 / area)
            } else {
                Rgb::default()
            }
        })
    }

    /// The element averages around vertex `v` combined by the rule of
    /// [`crate::shade::vertex_radiosity`] (not raised to zero: D_smooth enters a
    /// difference, and must cancel what the same rule does to the direct part of B).
    fn vertex_by_rule(&self, v: usize) -> Rgb {
        *self.rule_direct[v].get_or_init(|| {
            let mut sum = Rgb::default();
            for (e, w) in self.rule.terms(v) {
                sum += self.element(e) * w;
            }
            sum
        })
    }

    /// D_smooth at vertex `v`: [`DirectCorrection::vertex_by_rule`], joined across the
    /// facets of a curved object as [`crate::shade::smooth_objects`] joins B.
    fn vertex(&self, v: usize) -> Rgb {
        *self.vertex_direct[v].get_or_init(|| match self.joins.group(v) {
            None => self.vertex_by_rule(v),
            Some((members, area)) => {
                let mut sum = Rgb::default();
                for (m, w) in members {
                    sum += self.vertex_by_rule(m) * w;
                }
                sum * (1.0 / area)
            }
        })
    }

    /// D(x), the direct irradiance at `x` on element `e` (interpolation `weights`). On a
    /// flat surface it is received on the element's plane. On a facet of a curved object
    /// it is received as on the smooth surface the facets approximate: the cosine is taken
    /// to the shading normal, the vertices' normals ([`crate::shade::ObjectJoins`])
    /// interpolated with the colours' weights (Phong 1975, "Illumination for computer
    /// generated pictures", CACM 18), and the shadow rays leave from `x` lifted off the
    /// facet onto the curved surface those normals describe (Hanika 2021, "Hacking the
    /// shadow terminator", Ray Tracing Gems II ch. 4: the weighted mean of `x` projected onto
    /// each vertex's tangent plane, where it lies below it), so that near the terminator
    /// the neighbouring facets do not shadow light that the shading normal takes in. On a
    /// convex object a lifted point on or outside the true surface sees all that the
    /// surface's tangent plane there lets through, and D varies smoothly across facet edges,
    /// where the facets' own planes would make it jump.
    fn irradiance_here(&self, e: usize, x: DVec3, weights: &Interpolation, salt: u64) -> Rgb {
        let el = &self.mesh.elements[e];
        if !self.curved[e] {
            return self.light.irradiance(x, el.normal, salt);
        }
        let mut normal = DVec3::ZERO;
        let mut lift = DVec3::ZERO;
        for (c, w) in weights.pairs() {
            let (p, n) = (
                self.mesh.vertices[c as usize],
                self.joins.normal(c as usize),
            );
            normal += n * w;
            lift -= n * (w * (x - p).dot(n).min(0.0));
        }
        self.light
            .irradiance(x + lift, normal.normalize_or(el.normal), salt)
    }

    /// The correction at `x` on element `e`, where smooth shading interpolates the vertices
    /// and weights `weights` (see [`super::renderer::interpolation`]); `salt` jitters the shadow rays' strata (the
    /// renderer passes a hash of the ray's pixel and position).
    pub fn at(&self, e: usize, x: DVec3, weights: &Interpolation, salt: u64) -> Rgb {
        let el = &self.mesh.elements[e];
        let rho = self.reflectance[el.surface as usize];
        if rho.max_band() <= 0.0 || self.light.is_empty() {
            return Rgb::default();
        }
        let mut smooth = Rgb::default();
        for (c, w) in weights.pairs() {
            smooth += self.vertex(c as usize) * w;
        }
        let here = self.irradiance_here(e, x, weights, salt);
        rho * (here - smooth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::test_support::{facing_minus_z, scene, surface};
    use glam::dvec3;
    use std::f64::consts::PI;

    /// The square [-1, 1]^2 at height 1 facing down (-z), emitting `e`.
    fn ceiling_light(e: f64) -> crate::scene::Surface {
        surface("light", e, facing_minus_z(-1.0, 1.0, -1.0, 1.0, 1.0))
    }

    /// Form factor from a point on the axis of a parallel 2 x 2 square at distance 1: four
    /// corner rectangles X = Y = 1 of the closed form (Howell, catalogue B-3),
    /// F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))].
    fn on_axis_form_factor() -> f64 {
        let s = 2f64.sqrt();
        4.0 / (2.0 * PI) * 2.0 * (1.0 / s) * (1.0 / s).atan()
    }

    #[test]
    fn unoccluded_irradiance_is_lamberts_closed_form() {
        let light = DirectLight::new(&scene(vec![ceiling_light(3.0)]));
        let d = light.irradiance(DVec3::ZERO, DVec3::Z, 0);
        // Every shadow ray is clear, so the result is E F with F from Lambert's formula:
        // only rounding separates it from the closed form.
        for k in 0..3 {
            assert!((d[k] - 3.0 * on_axis_form_factor()).abs() < 1e-12, "{d:?}");
        }
        // Facing away, or behind the light: nothing.
        assert_eq!(light.irradiance(DVec3::ZERO, -DVec3::Z, 0), Rgb::default());
        assert_eq!(
            light.irradiance(dvec3(0.0, 0.0, 2.0), DVec3::Z, 0),
            Rgb::default()
        );
    }

    #[test]
    fn a_blocker_hides_all_or_half_of_the_light() {
        // A large square at height 0.5 (facing down) hides the whole light: exactly 0.
        let big = surface("blocker", 0.0, facing_minus_z(-5.0, 5.0, -5.0, 5.0, 0.5));
        let light = DirectLight::new(&scene(vec![ceiling_light(1.0), big]));
        assert_eq!(light.irradiance(DVec3::ZERO, DVec3::Z, 7), Rgb::default());
        // A half-plane x < 0 at height 0.5 hides the half of the light with x < 0, which by
        // symmetry is half of E F. In a penumbra the light is sampled on an 8 x 8 grid of
        // its parameters, four columns of strata on each side of the edge; the jitter
        // within each of the 64 strata moves its kernel weight by up to about 30 % (the
        // kernel 1 / (1 + r^2)^2 across a stratum a quarter wide), independently, so one
        // estimate is within about 30 % / sqrt(64) = 4 % of the split (8 %: two standard
        // errors), and over salts the strata are unbiased in numerator and denominator, so
        // the mean of 64 salts is within 1 %.
        let half = surface("half", 0.0, facing_minus_z(-5.0, 0.0, -5.0, 5.0, 0.5));
        let light = DirectLight::new(&scene(vec![ceiling_light(1.0), half]));
        assert_split_within_tolerance(&light, 0.0, 0.5 * on_axis_form_factor());
    }

    /// The irradiance at the origin (facing up) less `known`, over 64 salts, against
    /// `exact`: each within 8 %, the mean within 1 % (the tolerances of
    /// `a_blocker_hides_all_or_half_of_the_light`).
    fn assert_split_within_tolerance(light: &DirectLight, known: f64, exact: f64) {
        let mut mean = 0.0;
        for salt in 0..64 {
            let d = light.irradiance(DVec3::ZERO, DVec3::Z, salt)[0] - known;
            assert!(
                (d / exact - 1.0).abs() < 0.08,
                "salt {salt}: {d} against {exact}"
            );
            mean += d / 64.0;
        }
        assert!(
            (mean / exact - 1.0).abs() < 0.01,
            "mean {mean} against {exact}"
        );
    }

    #[test]
    fn a_weak_emitter_with_fewer_first_rays_is_hidden_or_split_as_before() {
        // The ceiling light (exitance 100) overhead and a weak one (exitance 1) over
        // x in [3, 5], whose share of the origin's unoccluded direct light is far below
        // WEAK_SHARE, so its first pass has a quarter of the rays.
        let main = 100.0 * on_axis_form_factor();
        let weak_polygon = facing_minus_z(3.0, 5.0, -1.0, 1.0, 1.0);
        let weak_f = point_to_polygon(DVec3::ZERO, DVec3::Z, &weak_polygon);
        assert!(
            weak_f < WEAK_SHARE * main,
            "the test's weak light is not weak"
        );
        let weak = surface("weak", 1.0, weak_polygon);
        // A blocker at height 0.5 over x in [1, 10] hides the whole weak light (its rays
        // cross z = 0.5 at x in [1.5, 2.5]) and none of the main one (|x| <= 0.5): the
        // sum is the main light's closed form, to rounding.
        let wide = surface("wide", 0.0, facing_minus_z(1.0, 10.0, -5.0, 5.0, 0.5));
        let hidden = DirectLight::new(&scene(vec![
            surface("light", 100.0, facing_minus_z(-1.0, 1.0, -1.0, 1.0, 1.0)),
            weak.clone(),
            wide,
        ]));
        for salt in 0..8 {
            let d = hidden.irradiance(DVec3::ZERO, DVec3::Z, salt)[0];
            assert!(
                (d - main).abs() < 1e-9 * main,
                "salt {salt}: {d} against {main}"
            );
        }
        // Over x in [2, 10] it hides the half x > 4 of the weak light: the coarse rays
        // disagree, the fine pass runs as for any emitter, and the weak light's part is
        // the exact form factor of its visible half with the tolerance of the test above
        // (8 % one salt, 1 % the mean of 64).
        let half = surface("half", 0.0, facing_minus_z(2.0, 10.0, -5.0, 5.0, 0.5));
        let split = DirectLight::new(&scene(vec![
            surface("light", 100.0, facing_minus_z(-1.0, 1.0, -1.0, 1.0, 1.0)),
            weak,
            half,
        ]));
        let exact = point_to_polygon(
            DVec3::ZERO,
            DVec3::Z,
            &facing_minus_z(3.0, 4.0, -1.0, 1.0, 1.0),
        );
        assert_split_within_tolerance(&split, main, exact);
    }

    #[test]
    fn the_correction_vanishes_where_the_direct_light_is_uniform() {
        // A floor under a light far larger than it: D is nearly uniform over the floor, so
        // D(x) and its interpolated element averages agree and the correction is tiny
        // against D itself.
        let floor = surface(
            "floor",
            0.0,
            vec![
                dvec3(-0.1, -0.1, 0.0),
                dvec3(0.1, -0.1, 0.0),
                dvec3(0.1, 0.1, 0.0),
                dvec3(-0.1, 0.1, 0.0),
            ],
        );
        let light = surface("light", 1.0, facing_minus_z(-50.0, 50.0, -50.0, 50.0, 1.0));
        let s = scene(vec![floor, light]);
        let mesh = crate::mesh::mesh_scene(&s, 0.01).unwrap();
        let c = DirectCorrection::new(&s, &mesh);
        let x = mesh.elements[0].centroid;
        let d = c.at(0, x, &crate::render::interpolation(&mesh, 0, x), 0);
        // D is about 1 (the light nearly fills the hemisphere); rho = 0.5.
        assert!(d[0].abs() < 1e-3, "{d:?}");
    }

    /// A sphere of radius 1 about the origin tessellated with 32 segments (16 bands of
    /// 11.25 degrees), its facets `ball.k` (one curved object, reflectance 0.5), lit by an
    /// isotropic point light of 1 cd at `light`, and its mesh of one element per facet.
    fn lit_sphere(light: DVec3) -> (Scene, Mesh) {
        use crate::scene::shape::{sphere_faces, Facing};
        let faces = sphere_faces(DVec3::ZERO, 1.0, 32, Facing::Out);
        let surfaces = faces
            .into_iter()
            .enumerate()
            .map(|(k, f)| surface(&format!("ball.{k}"), 0.0, f))
            .collect();
        let mut s = scene(surfaces);
        s.lights.push(crate::luminaire::Luminaire {
            name: "sun".into(),
            position: light,
            aim: -light,
            output: crate::luminaire::Output::Intensity(1.0),
            distribution: crate::luminaire::Distribution::Isotropic,
            colour: Rgb::splat(1.0),
        });
        let mesh = crate::mesh::mesh_scene(&s, 1.0).unwrap();
        assert_eq!(mesh.len(), s.surfaces.len(), "one element per facet");
        (s, mesh)
    }

    /// The element the ray from the sphere's centre along `u` leaves through, and the
    /// point: on a convex polyhedron round the origin, the facet plane it meets first.
    fn facet_along(mesh: &Mesh, u: DVec3) -> (usize, DVec3) {
        let (mut best, mut t_best) = (usize::MAX, f64::INFINITY);
        for (e, el) in mesh.elements.iter().enumerate() {
            let along = el.normal.dot(u);
            if along > 0.0 {
                let t = el.normal.dot(el.centroid) / along;
                if t < t_best {
                    (best, t_best) = (e, t);
                }
            }
        }
        (best, u * t_best)
    }

    #[test]
    fn a_tessellated_sphere_receives_direct_light_as_the_smooth_sphere_does() {
        // Issue #13: each facet's direct light was received on its own plane, in bands.
        // Received with the interpolated shading normal, a point x of a facet gets about
        // I cos(theta) / r^2 with theta the angle to the TRUE sphere normal x / |x| (r from
        // x to the light). The shading normal's error is second order in the band angle
        // D = 11.25 degrees = 0.196 rad: a vertex normal, the area-weighted mean of the
        // four facets round it, leans towards the larger facets by about (D / 2) (D tan(lat)
        // / 2), 0.017 rad up to latitude 60 degrees (the samples stay there), and nlerp
        // across a facet departs from the sphere by about D^2 / 8 = 0.005 rad. So the cosine
        // is within 0.03 (in units of I / r^2), where a facet's flat normal is off by up
        // to D / sqrt(2) = 0.14 rad (the test checks the flat cosines do miss by more than
        // twice that tolerance, so it would catch the old bands). On the dark side (cos
        // below -0.1, beyond any of those errors) nothing arrives: exactly 0.
        let light = 20.0 * dvec3(0.3, 0.5, 0.8).normalize();
        let (s, mesh) = lit_sphere(light);
        let c = DirectCorrection::new(&s, &mesh);
        let (mut worst, mut worst_flat, mut lit) = (0.0f64, 0.0f64, 0);
        for i in 0..25 {
            for j in 0..36 {
                let lat = (-60.0 + 5.0 * i as f64).to_radians();
                let lon = (10.0 * j as f64 + 3.0).to_radians();
                let u = dvec3(lat.cos() * lon.cos(), lat.sin(), lat.cos() * lon.sin());
                let (e, x) = facet_along(&mesh, u);
                let to_light = light - x;
                let (r2, l) = (to_light.length_squared(), to_light.normalize());
                let cos_true = u.dot(l);
                let weights = crate::render::interpolation(&mesh, e, x);
                let d = c.irradiance_here(e, x, &weights, 0)[0] * r2;
                if cos_true < -0.1 {
                    assert_eq!(d, 0.0, "dark side: x {x}, cos {cos_true}");
                } else if cos_true > 0.1 {
                    lit += 1;
                    worst = worst.max((d - cos_true).abs());
                    worst_flat = worst_flat.max((mesh.elements[e].normal.dot(l) - cos_true).abs());
                    assert!(
                        (d - cos_true).abs() < 0.03,
                        "x {x} on facet {e}: D r^2 / I = {d}, cos to the true normal {cos_true}"
                    );
                }
            }
        }
        assert!(lit > 200, "{lit} lit samples");
        assert!(
            worst_flat > 0.06,
            "flat normals miss by {worst_flat} at most, shading normals {worst}"
        );
    }

    #[test]
    fn direct_light_on_a_tessellated_sphere_is_continuous_across_facet_edges() {
        // At a point of an edge two lit facets share, the shading normal and the lifted
        // point are interpolated between the edge's two ends from either side, with the
        // same weights (linear along the edge on a triangle and a quadrilateral alike): D
        // agrees to rounding (1e-9 of D). The flat normals' D jumps there by I / r^2 times
        // the difference of the two facets' cosines, some 0.1 at a band edge facing the
        // light at 45 degrees: the check would have seen the bands.
        let light = 20.0 * dvec3(0.3, 0.5, 0.8).normalize();
        let (s, mesh) = lit_sphere(light);
        let c = DirectCorrection::new(&s, &mesh);
        let (mut edges, mut flat_jump) = (0, 0.0f64);
        for a in 0..s.surfaces.len() {
            for b in a + 1..s.surfaces.len() {
                let shared: Vec<DVec3> = s.surfaces[a]
                    .vertices
                    .iter()
                    .copied()
                    .filter(|p| {
                        s.surfaces[b]
                            .vertices
                            .iter()
                            .any(|q| q.distance(*p) < 1e-12)
                    })
                    .collect();
                if shared.len() != 2 {
                    continue;
                }
                for t in [0.3, 0.5] {
                    let x = shared[0].lerp(shared[1], t);
                    let l = (light - x).normalize();
                    let (na, nb) = (mesh.elements[a].normal, mesh.elements[b].normal);
                    if na.dot(l) < 0.2 || nb.dot(l) < 0.2 {
                        continue;
                    }
                    edges += 1;
                    let r2 = (light - x).length_squared();
                    flat_jump = flat_jump.max((na.dot(l) - nb.dot(l)).abs());
                    let da =
                        c.irradiance_here(a, x, &crate::render::interpolation(&mesh, a, x), 0)[0];
                    let db =
                        c.irradiance_here(b, x, &crate::render::interpolation(&mesh, b, x), 0)[0];
                    assert!(
                        (da - db).abs() <= 1e-9 * da.max(db) && da * r2 > 0.1,
                        "edge of facets {a} and {b} at {x}: D {da} against {db}"
                    );
                }
            }
        }
        assert!(edges > 50, "{edges} lit edge points");
        assert!(flat_jump > 0.05, "flat normals jump by {flat_jump} at most");
    }

    #[test]
    fn the_rendered_sphere_is_rho_times_its_direct_light() {
        // A lone convex object lit by a point light has no indirect light: B_i = rho D_i,
        // with D_i the element's average direct irradiance. Smooth shading joins B across
        // the facets (shade::smooth_objects), and the correction must join D_smooth the same
        // way, so that B_smooth + rho (D(x) - D_smooth) is rho D(x) at every point, to
        // rounding: the rendered radiance is rho / pi D(x), smooth where D is.
        let light = 20.0 * dvec3(0.3, 0.5, 0.8).normalize();
        let (s, mesh) = lit_sphere(light);
        let c = DirectCorrection::new(&s, &mesh);
        let b: Vec<[f64; 3]> = (0..mesh.len()).map(|e| (c.element(e) * 0.5).0).collect();
        let mut vertex_b = crate::shade::vertex_radiosity(&mesh, &b);
        crate::shade::smooth_objects(&s, &mesh, &mut vertex_b);
        let mut checked = 0;
        for j in 0..36 {
            let lon = (10.0 * j as f64 + 3.0).to_radians();
            let u = dvec3(0.6 * lon.cos(), 0.8, 0.6 * lon.sin());
            let (e, x) = facet_along(&mesh, u);
            // Well inside the lit side, so no vertex value is raised from below zero.
            if u.dot((light - x).normalize()) < 0.4 {
                continue;
            }
            checked += 1;
            let weights = crate::render::interpolation(&mesh, e, x);
            let rendered = weights.of(&vertex_b)[0] + c.at(e, x, &weights, 0)[0];
            let expected = 0.5 * c.irradiance_here(e, x, &weights, 0)[0];
            assert!(
                (rendered - expected).abs() <= 1e-9 * expected,
                "x {x} on facet {e}: rendered {rendered}, rho D {expected}"
            );
        }
        assert!(checked > 5, "{checked} points checked");
    }
}
