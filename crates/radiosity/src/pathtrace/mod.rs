//! A path tracer over the radiosity renderer's scene and camera: the yardstick that checks
//! the whole radiosity chain (meshing, form factors, solve, shading) without form factors.
//!
//! It solves the same model exactly: one-sided Lambertian surfaces that emit an exitance E
//! per band from their front (radiance E / pi) and reflect a fraction rho per band
//! diffusely; the back of a surface is black (it absorbs, emits nothing, reflects nothing).
//! Each pixel's value is the radiosity B = pi L seen through it, in the scene's units: the
//! quantity [`crate::render::render`] shows (a surface of uniform radiosity B renders as B),
//! so the two films compare directly ([`compare_films`]) and tone-map alike
//! ([`crate::render::tonemap`], with the same exposure and gamma).
//!
//! The estimator is the plainest unbiased one, paths from the camera (Kajiya 1986, "The
//! rendering equation", SIGGRAPH 86): at every front-face hit the emitted E is added, then
//! the path goes on in a cosine-weighted direction with its throughput multiplied by rho,
//! and after a few bounces Russian roulette (Arvo and Kirk 1990, "Particle transport and
//! image synthesis", SIGGRAPH 90) ends it without bias. By default each bounce also
//! samples a point on an emitter (next-event estimation), combined with the bounce by
//! multiple importance sampling (Veach and Guibas 1995) so that no light is counted twice;
//! switched off, the plain path tracer is left, a second estimator of the same image that
//! the tests hold the first to.
//!
//! * `settings`: [`PathTraceSettings`] (paths per pixel, a bounce cap, the roulette, the
//!   seed) and [`PathTraceError`].
//! * `sampling`: a generator per pixel; cosine-weighted directions (Malley's method) in an
//!   orthonormal frame (Duff et al. 2017).
//! * `integrator`: [`PathTracer`], the scene's surfaces in a BVH, and one path
//!   ([`PathTracer::sample`]), with next-event estimation combined by MIS.
//! * `lights`: the emitters as one distribution of points, for next-event estimation.
//! * `view`: a camera's view ([`PathTracer::render`]), rows in parallel, deterministic for
//!   a seed whatever the number of threads.
//! * `estimate`: the result, [`PathTraced`]: the film of pixel means, each mean's standard
//!   error (per band and on luminance), and the mask of pixels that show an emitter.
//! * `compare`: two films compared on luminance ([`compare_films`],
//!   [`PathTraced::compare`], [`PathTraced::compare_excluding`] with the radiosity
//!   renderer's own [`emitter_pixels`]) and the per-pixel error in false colour
//!   ([`ErrorMap`]).
//!
//! ```
//! use radiosity::pathtrace::{self, PathTraceSettings, PathTracer};
//! use radiosity::progress::NoProgress;
//! use radiosity::render::{tonemap, Camera};
//!
//! let scene = radiosity::scene::cornell_box().scene;
//! let camera = Camera::for_scene(&scene, 8, 8);
//! let settings = PathTraceSettings::DEFAULT.with_samples(4);
//! let view = pathtrace::path_trace(&scene, &camera, &settings, &NoProgress)?;
//! let exposure = PathTracer::new(&scene)?.area_exposure_scale(&scene, &settings, 256, 4);
//! let image = tonemap::to_image(view.film(), exposure, 2.2);
//! assert_eq!(image.dimensions(), (8, 8));
//! assert!(view.noise().mean_standard_error > 0.0);
//! # Ok::<(), radiosity::pathtrace::PathTraceError>(())
//! ```

mod compare;
mod estimate;
mod exposure;
mod integrator;
mod lights;
mod sampling;
mod settings;
#[cfg(test)]
mod tests;
mod view;

pub use compare::{
    compare_films, emitter_pixels, false_colour, ErrorMap, FilmCompareError, FilmComparison,
    DEFAULT_ERROR_FULL_SCALE,
};
pub use estimate::{NoiseSummary, PathTraced};
pub use exposure::{EXPOSURE_PATHS, EXPOSURE_POINTS};
pub use integrator::{PathSample, PathTracer, MAX_SURVIVAL_PROBABILITY};
pub use settings::{PathTraceError, PathTraceSettings, MIN_SAMPLES_PER_PIXEL};

use crate::progress::Progress;
use crate::render::Camera;
use crate::scene::Scene;

/// Path traces `camera`'s view of `scene`: [`PathTracer::new`] then
/// [`PathTracer::render`] (build a [`PathTracer`] once to trace several views).
pub fn path_trace(
    scene: &Scene,
    camera: &Camera,
    settings: &PathTraceSettings,
    progress: &dyn Progress,
) -> Result<PathTraced, PathTraceError> {
    settings.check()?;
    PathTracer::new(scene)?.render(camera, settings, progress)
}
