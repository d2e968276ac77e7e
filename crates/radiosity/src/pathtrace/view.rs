//! A camera's view, path traced: every pixel's paths from the eye through uniformly random
//! points of the pixel (a box filter, as the radiosity renderer's supersampling grid),
//! rows in parallel.

use glam::DVec3;
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
            let mask = self.emitter_mask(camera);
            (0..h)
                .into_par_iter()
                .map(|y| {
                    let row = (0..w)
                        .map(|x| self.pixel(camera, x, y, settings, mask[y * w + x]))
                        .collect();
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
        shows_emitter: bool,
    ) -> PixelEstimate {
        let mut rng = pixel_rng(settings.seed, (y * camera.width as usize + x) as u64);
        let mut acc = Accumulator::default();
        for _ in 0..settings.samples_per_pixel {
            let (u, v) = (uniform(&mut rng), uniform(&mut rng));
            let dir = camera.ray_direction(x as f64 + u, y as f64 + v);
            let path = self.sample(camera.eye, dir, settings, &mut rng);
            acc.add(path.radiosity);
        }
        acc.finish(shows_emitter)
    }

    /// Which pixels show an emitter (row by row): those where any ray of an
    /// [`EMITTER_GRID`] x [`EMITTER_GRID`] grid over the pixel sees an emitting front
    /// first, and the pixels next to one of those that the outline of an emitting front
    /// overlaps, seen from the eye (where its edge cuts a sliver off a pixel: an emitter is
    /// so much brighter than what it lights that a sliver of a thirtieth of a pixel made a
    /// pixel 8 times too bright). Geometry and camera alone decide it, not the paths (QA of
    /// issue #16: the pixels left out of the noise and of `--compare` changed with
    /// `--paths`, 10 at 16 paths and 18 at 64, because a path's first hit decided).
    fn emitter_mask(&self, camera: &Camera) -> Vec<bool> {
        let (w, h) = (camera.width as usize, camera.height as usize);
        let n = EMITTER_GRID;
        let coarse: Vec<bool> = (0..w * h)
            .into_par_iter()
            .map(|p| {
                (0..n * n).any(|k| {
                    let u = (f64::from(k % n) + 0.5) / f64::from(n);
                    let v = (f64::from(k / n) + 0.5) / f64::from(n);
                    let dir = camera.ray_direction((p % w) as f64 + u, (p / w) as f64 + v);
                    self.first_hit_emits(camera.eye, dir)
                })
            })
            .collect();
        // Each emitting front's outline in the image, clipped to the part in front of the
        // eye (review of issue #16: an emitter with a corner behind the eye counted as
        // overlapping every pixel beside a found one).
        let (forward, _, _) = camera.basis();
        let near = self.epsilon();
        let outlines: Vec<Vec<(f64, f64)>> = self
            .emitters
            .iter()
            .filter(|(v, n)| n.dot(camera.eye - v[0]) > 0.0)
            .filter_map(|(v, _)| {
                let depth = |c: DVec3| (c - camera.eye).dot(forward) - near;
                let front = clip_to_front(v, depth);
                let outline: Option<Vec<(f64, f64)>> =
                    front.iter().map(|&c| camera.project(c)).collect();
                outline.filter(|o| o.len() >= 3)
            })
            .collect();
        (0..w * h)
            .into_par_iter()
            .map(|p| {
                let (x, y) = (p % w, p / w);
                if coarse[p] {
                    return true;
                }
                let beside = (y.saturating_sub(1)..(y + 2).min(h))
                    .any(|j| (x.saturating_sub(1)..(x + 2).min(w)).any(|i| coarse[j * w + i]));
                beside
                    && outlines
                        .iter()
                        .any(|o| overlaps_pixel(o, x as f64, y as f64))
            })
            .collect()
    }
}

/// Rays a pixel along each side for [`PathTracer::emitter_mask`]'s first look.
pub const EMITTER_GRID: u32 = 4;

/// The part of the convex polygon `corners` where `depth` (linear along the polygon) is
/// above 0: one Sutherland-Hodgman step against the camera's near plane.
fn clip_to_front(corners: &[DVec3], depth: impl Fn(DVec3) -> f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(corners.len() + 1);
    for i in 0..corners.len() {
        let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
        let (da, db) = (depth(a), depth(b));
        if da > 0.0 {
            out.push(a);
        }
        if (da > 0.0) != (db > 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// Whether the convex polygon `outline` (image coordinates, either winding) overlaps the
/// open pixel square [x, x + 1] x [y, y + 1]: no separating axis among the square's two and
/// the outline's edge normals.
fn overlaps_pixel(outline: &[(f64, f64)], x: f64, y: f64) -> bool {
    let square = [(x, y), (x + 1.0, y), (x + 1.0, y + 1.0), (x, y + 1.0)];
    let separated = |axis: (f64, f64)| {
        let range = |pts: &mut dyn Iterator<Item = (f64, f64)>| {
            pts.map(|(px, py)| px * axis.0 + py * axis.1)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
                    (lo.min(d), hi.max(d))
                })
        };
        let (a0, a1) = range(&mut outline.iter().copied());
        let (b0, b1) = range(&mut square.iter().copied());
        a1 <= b0 || b1 <= a0
    };
    let k = outline.len();
    if k < 3 {
        return false;
    }
    // A corner repeated, or an edge seen end on, gives no axis (review of issue #16: the
    // zero axis "separated" everything).
    let edges = (0..k)
        .map(|i| {
            let (a, b) = (outline[i], outline[(i + 1) % k]);
            (b.1 - a.1, a.0 - b.0)
        })
        .filter(|&(u, v)| u * u + v * v > 1e-24);
    ![(1.0, 0.0), (0.0, 1.0)]
        .into_iter()
        .chain(edges)
        .any(separated)
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
