//! The estimator of one path: the scene's surfaces in a BVH ([`PathTracer`]) and the random
//! walk that estimates the radiosity a ray sees ([`PathTracer::sample`]).
//!
//! For one-sided Lambertian surfaces the rendering equation (Kajiya 1986) reads
//! `L(x) = E(x) / pi + rho(x) / pi * int L(y(x, w)) cos(theta) dw` over the hemisphere in
//! front of x, y(x, w) the first point seen from x along w and L its radiance towards x
//! (zero on a back face and on a ray that escapes). Multiplied by pi it is the continuous
//! radiosity equation `B(x) = E(x) + rho(x) int B(y) cos(theta) / pi dw`, B = pi L. The
//! walk estimates B: at each front-face hit it adds the path's throughput times E, then
//! draws the next direction with density cos(theta) / pi, for which the weight
//! `rho cos(theta) / pi / (cos(theta) / pi)` is rho, so the throughput is multiplied by
//! rho. Each path is an unbiased estimate of the Neumann series
//! `E + rho K E + (rho K)^2 E + ...` up to [`PathTraceSettings::max_bounces`]; Russian
//! roulette (Arvo and Kirk 1990) ends it without bias.
//!
//! With [`PathTraceSettings::next_event_estimation`] the direct light of every bounce is
//! estimated twice, by a point drawn on an emitter (density p_light per solid angle:
//! the area density of `lights` times d^2 / cos at the light) and by the bounce itself
//! (p_bounce = cos / pi), and the two are weighted by the power heuristic
//! `w_s = p_s^2 / (p_light^2 + p_bounce^2)` (Veach and Guibas 1995, "Optimally combining
//! sampling techniques for Monte Carlo rendering", SIGGRAPH 95), whose weights sum to one
//! for every light path, so the sum stays unbiased. A light sample from x adds
//! `throughput rho E cos_x / (pi p_light) w_light` when nothing blocks the segment; a
//! bounce that reaches the front of an emitter adds `throughput E w_bounce`. Light seen
//! straight from the camera has weight 1 (no light sample competes with it), and so has
//! emission reached by a bounce when next-event estimation is off.

use std::f64::consts::FRAC_1_PI;

use glam::DVec3;
use rand::Rng;

use super::lights::Lights;
use super::sampling::{cosine_hemisphere, uniform};
use super::settings::{PathTraceError, PathTraceSettings};
use crate::light::{check_surface, Rgb};
use crate::scene::Scene;
use crate::visibility::PolygonBvh;

/// The largest survival probability of Russian roulette: even a path through white
/// surfaces ends with probability at least 1/20 a bounce, so paths stay short.
pub const MAX_SURVIVAL_PROBABILITY: f64 = 0.95;

/// What the path tracer needs of a surface.
#[derive(Clone, Copy, Debug)]
struct Traced {
    normal: DVec3,
    emission: Rgb,
    reflectance: Rgb,
}

/// The surfaces of a scene in a BVH of whole polygons, ready to trace any number of paths.
pub struct PathTracer {
    bvh: PolygonBvh,
    /// The scene's point luminaires: sampled at every hit (next-event estimation to a
    /// point, with no competing strategy: no bounce can reach a point).
    points: Vec<crate::luminaire::Luminaire>,
    surfaces: Vec<Traced>,
    lights: Lights,
    /// Centre of the scene's bounding box.
    centre: DVec3,
    /// Rays start this far beyond the point they leave (1e-9 of the scene's diagonal, the
    /// BVH's own edge tolerance), so they do not hit their own surface again.
    epsilon: f64,
    /// The emitting surfaces' corners and unit normals, for the emitter mask of a view.
    pub(super) emitters: Vec<(Vec<DVec3>, DVec3)>,
}

/// What one path from a ray found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSample {
    /// The estimate of the radiosity B = pi L seen along the ray, per band.
    pub radiosity: Rgb,
    /// True when the ray's first hit is the front of an emitting surface.
    pub sees_emitter: bool,
    /// The diffuse reflections the path made.
    pub bounces: u32,
}

impl PathTracer {
    /// The BVH over the scene's surfaces (each a planar convex polygon), checking that
    /// every surface has an area (a front) and a reflectance in [0, 1) and a finite
    /// non-negative emission.
    pub fn new(scene: &Scene) -> Result<PathTracer, PathTraceError> {
        let mut surfaces = Vec::with_capacity(scene.surfaces.len());
        for (i, s) in scene.surfaces.iter().enumerate() {
            check_surface(i, s.reflectance, s.emission)?;
            let normal = crate::geometry::polygon_normal(&s.vertices)
                .filter(|_| s.vertices.len() >= 3)
                .ok_or_else(|| PathTraceError::Degenerate {
                    surface: i,
                    name: s.name.clone(),
                })?;
            surfaces.push(Traced {
                normal,
                emission: s.emission,
                reflectance: s.reflectance,
            });
        }
        let bvh = PolygonBvh::over_surfaces(scene);
        let (lo, hi) = if scene.surfaces.is_empty() {
            (DVec3::ZERO, DVec3::ZERO)
        } else {
            scene.bounds()
        };
        let emitters = scene
            .surfaces
            .iter()
            .zip(&surfaces)
            .filter(|(_, t)| t.emission.max_band() > 0.0)
            .map(|(s, t)| (s.vertices.clone(), t.normal))
            .collect();
        Ok(PathTracer {
            emitters,
            epsilon: 1e-9 * bvh.scale(),
            lights: Lights::new(scene),
            points: scene.lights.clone(),
            bvh,
            surfaces,
            centre: 0.5 * (lo + hi),
        })
    }

    /// True when surface `surface` emits in some band.
    pub fn emits(&self, surface: usize) -> bool {
        self.surfaces[surface].emission.max_band() > 0.0
    }

    /// The unit normal of surface `surface` (its front).
    pub(super) fn normal(&self, surface: usize) -> DVec3 {
        self.surfaces[surface].normal
    }

    /// How far beyond the point they leave rays start (see the field).
    pub(super) fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// Whether the ray `origin + t dir` (t past 1e-9 of the scene) first meets the front
    /// of an emitting surface.
    pub(super) fn first_hit_emits(&self, origin: DVec3, dir: DVec3) -> bool {
        let t_max = (origin - self.centre).length() + self.bvh.scale() + 1.0;
        self.bvh
            .closest_hit(origin, dir, self.epsilon, t_max)
            .map(|hit| &self.surfaces[hit.id as usize])
            .is_some_and(|s| s.normal.dot(dir) < 0.0 && s.emission.max_band() > 0.0)
    }

    /// One path from `origin` along the unit direction `dir`: an unbiased estimate of the
    /// radiosity B = pi L that the ray sees (see the module documentation), drawing its
    /// random numbers from `rng`.
    ///
    /// A ray that escapes, or reaches the back of a surface (black: it absorbs, emits and
    /// reflects nothing), ends the path and adds nothing. The first
    /// [`PathTraceSettings::roulette_after_bounces`] reflections always happen unless the
    /// throughput is black; each later one survives with probability
    /// q = min(max band of the throughput, [`MAX_SURVIVAL_PROBABILITY`]) and then divides
    /// the throughput by q. A light sample at a hit stands for one more reflection, so
    /// none is taken at the hit where the path has made its
    /// [`PathTraceSettings::max_bounces`].
    pub fn sample(
        &self,
        origin: DVec3,
        dir: DVec3,
        settings: &PathTraceSettings,
        rng: &mut impl Rng,
    ) -> PathSample {
        let nee = settings.next_event_estimation && !self.lights.is_empty();
        let mut radiosity = Rgb::BLACK;
        let mut throughput = Rgb::splat(1.0);
        // The first segment too starts past 1e-9 of the scene: a camera exactly on a wall sees
        // the room in front of it, not the wall's back at t = 0 (QA of issue #16).
        let (mut origin, mut dir, mut t_min) = (origin, dir, self.epsilon);
        let mut sees_emitter = false;
        let mut bounces = 0;
        // The cosine-weighted density (per solid angle) of the bounce that made `dir`.
        let mut bounce_density = 0.0;
        loop {
            let t_max = (origin - self.centre).length() + self.bvh.scale() + 1.0;
            let Some(hit) = self.bvh.closest_hit(origin, dir, t_min, t_max) else {
                break; // escaped
            };
            let s = &self.surfaces[hit.id as usize];
            let cos_hit = -s.normal.dot(dir);
            if cos_hit <= 0.0 {
                break; // the back of a one-sided surface: black
            }
            if bounces == 0 {
                sees_emitter = s.emission.max_band() > 0.0;
                radiosity += throughput * s.emission;
            } else if s.emission.max_band() > 0.0 {
                let weight = if nee {
                    let light_density = self.lights.area_density(hit.id) * hit.t * hit.t / cos_hit;
                    power_heuristic(bounce_density, light_density)
                } else {
                    1.0
                };
                radiosity += throughput * s.emission * weight;
            }
            if bounces >= settings.max_bounces {
                break;
            }
            let x = origin + hit.t * dir;
            if nee && s.reflectance.max_band() > 0.0 {
                radiosity += throughput * s.reflectance * self.light_sample(x, s.normal, rng);
            }
            if !self.points.is_empty() && s.reflectance.max_band() > 0.0 {
                radiosity += throughput * s.reflectance * self.point_irradiance(x, s.normal);
            }
            throughput = throughput * s.reflectance;
            if bounces >= settings.roulette_after_bounces {
                let q = throughput.max_band().min(MAX_SURVIVAL_PROBABILITY);
                if uniform(rng) >= q {
                    break;
                }
                throughput = throughput * (1.0 / q);
            } else if throughput.max_band() <= 0.0 {
                break;
            }
            bounces += 1;
            origin = x;
            dir = cosine_hemisphere(s.normal, uniform(rng), uniform(rng));
            bounce_density = dir.dot(s.normal).max(0.0) * FRAC_1_PI;
            t_min = self.epsilon;
        }
        PathSample {
            radiosity,
            sees_emitter,
            bounces,
        }
    }

    /// The MIS-weighted light-sample estimate of the irradiance-like integral
    /// `int E(y) cos_x / pi dw` over the emitters seen from `x` (normal `n`): one point on
    /// an emitter, `E cos_x / (pi p_light) w_light` when it faces x and nothing blocks the
    /// segment, else 0. Always draws three numbers, so the stream does not depend on
    /// where the point falls.
    fn light_sample(&self, x: DVec3, n: DVec3, rng: &mut impl Rng) -> Rgb {
        let (u0, u1, u2) = (uniform(rng), uniform(rng), uniform(rng));
        let Some(y) = self.lights.sample(u0, u1, u2) else {
            return Rgb::BLACK;
        };
        let d = y.position - x;
        let dist2 = d.length_squared();
        if dist2.is_nan() || dist2 <= 0.0 {
            return Rgb::BLACK;
        }
        let w = d / dist2.sqrt();
        let light = &self.surfaces[y.surface as usize];
        let (cos_x, cos_y) = (n.dot(w), -light.normal.dot(w));
        if cos_x <= 0.0 || cos_y <= 0.0 || self.bvh.segment_blocked(x, y.position) {
            return Rgb::BLACK;
        }
        let light_density = y.area_density * dist2 / cos_y;
        let bounce_density = cos_x * FRAC_1_PI;
        let weight = power_heuristic(light_density, bounce_density);
        light.emission * (bounce_density / light_density * weight)
    }
}

impl PathTracer {
    /// The illuminance at `x` (normal `n`) from the point luminaires, I cos / d^2 for each
    /// whose segment to `x` is clear: exact, no random numbers.
    fn point_irradiance(&self, x: DVec3, n: DVec3) -> Rgb {
        let mut sum = Rgb::BLACK;
        for l in &self.points {
            let e = l.irradiance_unoccluded(x, n);
            if e.max_band() > 0.0 && !self.bvh.segment_blocked(x, l.position) {
                sum += e;
            }
        }
        sum
    }
}

/// Veach's power heuristic (exponent 2): the weight of the strategy whose density is `a`
/// against the one whose density is `b`, at a sample both could have drawn.
fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}
