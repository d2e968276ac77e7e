//! A camera's view, path traced: every pixel's paths from the eye through uniformly random
//! points of the pixel (a box filter, as the radiosity renderer's supersampling grid),
//! rows in parallel.

use rayon::prelude::*;

use super::estimate::{Accumulator, PathTraced, PixelEstimate};
use super::integrator::PathTracer;
use super::sampling::{pixel_rng, uniform};
use super::settings::{PathTraceError, PathTraceSettings};
use crate::progress::{run_stage, Progress, Stage};
use crate::render::Camera;

impl PathTracer {
    /// The view of `camera`: `settings.samples_per_pixel` paths a pixel, pixel p (row by row
    /// from the top-left corner) drawing from a generator seeded from (`settings.seed`, p)
    /// alone, so the result is the same bit for bit on any number of threads. Rows are
    /// traced in parallel and reported as [`Stage::PathTrace`], one `advance(1)` a row.
    ///
    /// Refuses settings with fewer than two samples a pixel, and a camera whose eye, target
    /// or up is not finite or whose field of view is not in (0, 180) degrees. An image with
    /// no pixels is returned at once.
    pub fn render(
        &self,
        camera: &Camera,
        settings: &PathTraceSettings,
        progress: &dyn Progress,
    ) -> Result<PathTraced, PathTraceError> {
        settings.check()?;
        check_camera(camera)?;
        let (w, h) = (camera.width as usize, camera.height as usize);
        let n = settings.samples_per_pixel;
        if w == 0 || h == 0 {
            return Ok(PathTraced::from_pixels(w, h, n, &[]));
        }
        let rows: Vec<Vec<PixelEstimate>> = run_stage(progress, Stage::PathTrace, h as u64, || {
            (0..h)
                .into_par_iter()
                .map(|y| {
                    let row = (0..w).map(|x| self.pixel(camera, x, y, settings)).collect();
                    progress.advance(1);
                    row
                })
                .collect()
        });
        Ok(PathTraced::from_pixels(w, h, n, &rows.concat()))
    }

    /// The paths of pixel (x, y).
    fn pixel(
        &self,
        camera: &Camera,
        x: usize,
        y: usize,
        settings: &PathTraceSettings,
    ) -> PixelEstimate {
        let mut rng = pixel_rng(settings.seed, (y * camera.width as usize + x) as u64);
        let mut acc = Accumulator::default();
        let mut shows_emitter = false;
        for _ in 0..settings.samples_per_pixel {
            let (u, v) = (uniform(&mut rng), uniform(&mut rng));
            let dir = camera.ray_direction(x as f64 + u, y as f64 + v);
            let path = self.sample(camera.eye, dir, settings, &mut rng);
            acc.add(path.radiosity);
            shows_emitter |= path.sees_emitter;
        }
        acc.finish(shows_emitter)
    }
}

/// Refuses a camera that cannot make rays.
fn check_camera(camera: &Camera) -> Result<(), PathTraceError> {
    let bad = |what: String| Err(PathTraceError::BadCamera { what });
    if !(camera.eye.is_finite() && camera.look_at.is_finite() && camera.up.is_finite()) {
        return bad(format!(
            "eye {}, look-at {} and up {} must be finite",
            camera.eye, camera.look_at, camera.up
        ));
    }
    if !(camera.fov_y_degrees > 0.0 && camera.fov_y_degrees < 180.0) {
        return bad(format!(
            "vertical field of view {} degrees is not in (0, 180)",
            camera.fov_y_degrees
        ));
    }
    Ok(())
}
