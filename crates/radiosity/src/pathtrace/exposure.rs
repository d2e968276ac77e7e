//! The automatic exposure of a path-traced view by the rule that radiosity renders use
//! ([`crate::render::tonemap::Exposure::Auto`]): the mean radiosity (largest band) of the
//! brightest [`AUTO_EXPOSURE_TOP_AREA`] (2 %) of the non-emitting surfaces' area is white.
//!
//! The radiosity rule reads element radiosities; the path tracer has none, so it estimates
//! the radiosity B = pi L leaving points spread uniformly over the surfaces' area, each by
//! paths started just in front of the point and looking straight back at it (the path's
//! first hit is the point itself, so its estimate is the point's radiosity). The brightest
//! points are then estimated again with fresh paths: selecting the largest of noisy
//! estimates favours those that came out high, and the second, independent estimate of the
//! selected points has no such upward bias (a smaller downward one remains: where noise
//! swapped points across the cut, the set is not quite the true top 2 %). Issue #11: the view's own statistic (the brightest 2 %
//! of its pixels) made the Cornell box's path-traced picture half as bright as its
//! radiosity render, where the view sees little of the brightest area.

use glam::DVec3;
use rayon::prelude::*;

use super::integrator::PathTracer;
use super::sampling::{pixel_rng, point_in_triangles, uniform};
use super::settings::PathTraceSettings;
use crate::render::tonemap::{scale_for, top_mean, AUTO_EXPOSURE_TOP_AREA};
use crate::scene::Scene;

/// Points spread over the surfaces' area by default: the top 2 % is then 82 points.
pub const EXPOSURE_POINTS: usize = 4096;

/// Paths per point in each of the two passes by default.
pub const EXPOSURE_PATHS: u32 = 64;

/// Keeps the points' generators apart from the pixels' under the same seed.
const EXPOSURE_STREAM: u64 = 0x5851_F42D_4C95_7F2D;

/// The surfaces' fan triangles with cumulative area, to draw points uniformly by area.
struct AreaSampler {
    triangles: Vec<[DVec3; 3]>,
    surface: Vec<u32>,
    cumulative: Vec<f64>,
}

impl AreaSampler {
    /// The surfaces of `scene` for which `keep` holds; `None` when they have no area.
    fn new(scene: &Scene, keep: impl Fn(usize) -> bool) -> Option<AreaSampler> {
        let (mut triangles, mut surface, mut cumulative) = (Vec::new(), Vec::new(), Vec::new());
        let mut total = 0.0;
        for (j, s) in scene.surfaces.iter().enumerate().filter(|(j, _)| keep(*j)) {
            let v = &s.vertices;
            for k in 1..v.len().saturating_sub(1) {
                let t = [v[0], v[k], v[k + 1]];
                let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
                if area > 0.0 && area.is_finite() {
                    total += area;
                    triangles.push(t);
                    surface.push(j as u32);
                    cumulative.push(total);
                }
            }
        }
        if !(total > 0.0) {
            return None;
        }
        cumulative.iter_mut().for_each(|c| *c /= total);
        Some(AreaSampler {
            triangles,
            surface,
            cumulative,
        })
    }

    /// A point and its surface from three uniform numbers, as [`super::lights`] draws
    /// points on emitters ([`point_in_triangles`]).
    fn sample(&self, u0: f64, u1: f64, u2: f64) -> (DVec3, usize) {
        let (k, point) = point_in_triangles(&self.triangles, &self.cumulative, u0, u1, u2);
        (point, self.surface[k] as usize)
    }
}

impl PathTracer {
    /// The exposure scale of the radiosity rule (see the module documentation), estimated
    /// with `points` points and `paths` paths a point in each pass, drawn from
    /// `settings.seed` (with `settings`' bounces and roulette): 1 when the scene has no
    /// lit area. When every surface emits, all surfaces count, as in the radiosity rule.
    pub fn area_exposure_scale(
        &self,
        scene: &Scene,
        settings: &PathTraceSettings,
        points: usize,
        paths: u32,
    ) -> f64 {
        scale_for(self.area_exposure_white(scene, settings, points, paths))
    }

    /// The radiosity [`Self::area_exposure_scale`] makes white: `None` when the scene has
    /// no area or the estimate is zero (nothing lit), where the scale falls back to 1.
    pub fn area_exposure_white(
        &self,
        scene: &Scene,
        settings: &PathTraceSettings,
        points: usize,
        paths: u32,
    ) -> Option<f64> {
        let sampler = AreaSampler::new(scene, |j| !self.emits(j))
            .or_else(|| AreaSampler::new(scene, |_| true))?;
        // Point i, drawn from its own generator, so that both passes find it again; the
        // triangle by a stratified number, so each surface gets its share of the points.
        let point = |i: usize| {
            let mut rng = pixel_rng(settings.seed ^ EXPOSURE_STREAM, i as u64);
            let u0 = (i as f64 + uniform(&mut rng)) / points as f64;
            sampler.sample(u0, uniform(&mut rng), uniform(&mut rng))
        };
        // Its radiosity by `paths` paths from just in front of it, looking back at it: the
        // first hit is the point (nothing lies closer), so each path estimates B there.
        // `pass` keeps the two passes' random numbers apart.
        let radiosity = |i: usize, pass: u64| -> f64 {
            let (x, j) = point(i);
            let n = self.normal(j);
            let origin = x + 1e3 * self.epsilon() * n;
            let mut rng = pixel_rng(settings.seed ^ EXPOSURE_STREAM ^ (pass + 1), i as u64);
            let mut sum = crate::light::Rgb::BLACK;
            for _ in 0..paths {
                sum += self.sample(origin, -n, settings, &mut rng).radiosity;
            }
            sum.max_band() / paths.max(1) as f64
        };
        let mut ranked: Vec<(usize, f64)> = (0..points)
            .into_par_iter()
            .map(|i| (i, radiosity(i, 0)))
            .collect();
        ranked.sort_unstable_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        let top = ((AUTO_EXPOSURE_TOP_AREA * points as f64).ceil() as usize).clamp(1, points);
        // The selected points again, with fresh paths.
        let again: Vec<f64> = ranked[..top]
            .par_iter()
            .map(|&(i, _)| radiosity(i, 1))
            .collect();
        top_mean(again.iter().map(|&b| (b, 1.0)), 1.0).filter(|w| *w > 0.0 && w.is_finite())
    }
}
