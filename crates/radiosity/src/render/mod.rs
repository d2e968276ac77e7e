//! A CPU ray-casting camera that turns a radiosity solution into an image (paper section
//! 2.6, "Walkthrough Ability", and the plates of Appendix B).
//!
//! Radiosity is view-independent: once element radiosities are known, any [`Camera`] can
//! look at the scene without solving again. The paper draws the patches with OpenGL; here
//! each pixel casts a ray into a BVH of the mesh's elements ([`Renderer`]) and colours it by
//! the element it hits first, in one of the paper's three display modes ([`Shading`]).
//!
//! * `camera`: the pinhole [`Camera`] and its automatic placement ([`Camera::for_scene`]).
//! * `renderer`: the element BVH, what a ray sees ([`Shading`]), the interpolation weights
//!   of smooth shading ([`inverse_bilinear`], [`barycentric`]), and the ray loop that
//!   writes a view into a [`Film`] ([`Renderer::film`]).
//! * `film`: the linear film: f64 values per ray sample, no exposure or gamma yet.
//! * [`tonemap`]: exposure, the paper's gamma correction (section 2.7) and 8-bit encoding,
//!   from a film to an image.
//! * [`render`] (here): film then tone map, the one call the CLI makes. Images are written
//!   by [`crate::io::png`] ([`write_png`] here is the same function).
//!
//! Rows are rendered in parallel with rayon; each finished row is reported to the
//! [`Progress`] sink as one unit of [`Stage::Render`].

use image::RgbImage;
use rayon::prelude::*;

use crate::progress::{run_stage, Progress, Stage};
use tonemap::ToneMap;

mod adaptive;
mod camera;
mod direct;
mod film;
mod hole_cover;
mod holes;
mod renderer;
#[cfg(test)]
mod test_support;
pub mod tonemap;

pub use camera::{in_top_quarter, z_is_up, Camera, DEFAULT_FOV_Y_DEGREES};
pub use direct::{DirectCorrection, DirectLight, COARSE_RAYS};
pub use film::{sample_offset, Film, FilmContent};
pub use hole_cover::HoleCover;
pub use renderer::{
    barycentric, interpolation, inverse_bilinear, Interpolation, Renderer, Shading,
};

/// The PNG writer, at the path the command line uses; it lives in [`crate::io::png`].
pub use crate::io::png::write_png;

/// Everything about how to render except the camera and the radiosities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// The display mode.
    pub shading: Shading,
    /// Radiosities are multiplied by this before clamping to [0, 1] (see
    /// [`tonemap::Exposure::scale`]).
    pub exposure_scale: f64,
    /// Gamma factor of paper 2.7: display = value^(1 / gamma). 1 means no correction.
    pub gamma: f64,
    /// Antialiasing: each pixel is the mean of n x n rays on a regular grid inside it
    /// (averaged before gamma). 1 (the default) casts one ray through the pixel centre;
    /// 0 is treated as 1.
    pub supersample: u32,
    /// Adaptive antialiasing's contrast threshold (see [`Renderer::with_adaptive_sampling`]);
    /// `None` casts every pixel's full grid.
    pub adaptive_contrast: Option<f64>,
    /// Smooth shading gathers the direct light per ray (see [`Renderer::with_direct_light`]).
    pub direct_light: bool,
}

impl Default for RenderSettings {
    /// Smooth shading from the mesh alone, exposure 1, gamma 2.2, no supersampling.
    fn default() -> Self {
        RenderSettings {
            shading: Shading::Smooth,
            exposure_scale: 1.0,
            gamma: 2.2,
            supersample: 1,
            adaptive_contrast: None,
            direct_light: false,
        }
    }
}

/// At most this many film samples (48 MiB of them) are held at once by [`render`], which
/// traces and tone-maps a large or heavily supersampled image in strips of rows.
const STRIP_SAMPLES: usize = 1 << 21;

/// Renders the view of `camera` into a `camera.width` x `camera.height` image.
///
/// `element_b` holds one radiosity per element of the renderer's mesh; `vertex_b` one per
/// mesh vertex (from [`crate::shade::vertex_radiosity`]) and is read only for
/// [`Shading::Smooth`] (it may be empty otherwise). Rows are rendered in parallel; the work
/// is reported as [`Stage::Render`] with one `advance(1)` per finished row. An image with
/// no pixels is returned at once.
///
/// The rays write a linear [`Film`] ([`Renderer::film`]), which [`tonemap::ToneMap`] turns
/// into 8-bit colour: per pixel, each sample exposed and clamped, the mean, then gamma.
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
    render_counting(renderer, camera, element_b, vertex_b, settings, progress).0
}

/// Camera samples that were not finite numbers: the tone map shows NaN as black, so an
/// image of them would look like a dark scene.
#[derive(Clone, Copy, Debug, thiserror::Error, PartialEq)]
#[error(
    "the render is not a picture: {bad} of its {total} camera samples are not finite \
     numbers (NaN or infinity), from radiosities or geometry out of reach of f64"
)]
pub struct NonFiniteImage {
    /// Samples that were NaN or infinite.
    pub bad: u64,
    /// Samples in all.
    pub total: u64,
}

/// [`render`], refusing an image any of whose samples is not finite (the stage boundary
/// check of the rendered image).
pub fn try_render(
    renderer: &Renderer,
    camera: &Camera,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
    settings: &RenderSettings,
    progress: &dyn Progress,
) -> Result<RgbImage, NonFiniteImage> {
    let (image, bad, total) =
        render_counting(renderer, camera, element_b, vertex_b, settings, progress);
    if bad > 0 {
        return Err(NonFiniteImage { bad, total });
    }
    Ok(image)
}

/// [`render`], with the count of samples that were not finite and of all samples.
fn render_counting(
    renderer: &Renderer,
    camera: &Camera,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
    settings: &RenderSettings,
    progress: &dyn Progress,
) -> (RgbImage, u64, u64) {
    let w = camera.width as usize;
    let tone = ToneMap::new(settings.exposure_scale, settings.gamma);
    let mut buf = vec![0u8; w * camera.height as usize * 3];
    let (bad, total) = film_strips(
        renderer,
        camera,
        element_b,
        vertex_b,
        settings,
        progress,
        |film, rows| tone.encode_film(film, &mut buf[rows.start * w * 3..rows.end * w * 3]),
    );
    let image =
        RgbImage::from_raw(camera.width, camera.height, buf).expect("buffer has the image's size");
    (image, bad, total)
}

/// Renders the view of `camera` as linear pixels: each pixel the mean of its
/// `settings.supersample`^2 film samples, in the scene's radiosity units (a surface of
/// uniform radiosity B shows as B), with no exposure, clamping or gamma
/// (`settings.exposure_scale` and `settings.gamma` are not used). Pixels row by row from
/// the top-left corner. Traced in strips like [`render`], so a large supersampled image
/// never holds its whole film.
///
/// Refuses [`Shading::Wireframe`], whose film holds line coverage, not light (returned as
/// `Ok(None)`), and an image any of whose samples is not finite.
///
/// # Panics
/// As [`render`].
pub fn render_linear(
    renderer: &Renderer,
    camera: &Camera,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
    settings: &RenderSettings,
    progress: &dyn Progress,
) -> Result<Option<Vec<[f64; 3]>>, NonFiniteImage> {
    if settings.shading == Shading::Wireframe {
        return Ok(None);
    }
    let w = camera.width as usize;
    let mut pixels = vec![[0.0; 3]; w * camera.height as usize];
    let (bad, total) = film_strips(
        renderer,
        camera,
        element_b,
        vertex_b,
        settings,
        progress,
        |film, rows| pixels[rows.start * w..rows.end * w].copy_from_slice(&film.pixel_means()),
    );
    if bad > 0 {
        return Err(NonFiniteImage { bad, total });
    }
    Ok(Some(pixels))
}

/// Traces the view of `camera` in strips of rows of at most [`STRIP_SAMPLES`] samples,
/// handing each strip's film and its rows to `sink`, top to bottom; returns the count of
/// samples that were not finite and of all samples.
fn film_strips(
    renderer: &Renderer,
    camera: &Camera,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
    settings: &RenderSettings,
    progress: &dyn Progress,
    mut sink: impl FnMut(&Film, std::ops::Range<usize>),
) -> (u64, u64) {
    renderer.check_inputs(element_b, vertex_b, settings.shading);
    let (w, h) = (camera.width as usize, camera.height as usize);
    if w == 0 || h == 0 {
        return (0, 0);
    }
    let (mut bad, mut total) = (0u64, 0u64);
    let n = settings.supersample.max(1) as usize;
    let strip = (STRIP_SAMPLES / (w * n * n)).max(1);
    run_stage(progress, Stage::Render, h as u64, || {
        let mut carried = adaptive::FirstRows::default();
        for first in (0..h).step_by(strip) {
            let rows = first..(first + strip).min(h);
            let film = renderer.film_rows(
                camera,
                rows.clone(),
                element_b,
                vertex_b,
                settings.shading,
                n,
                &mut carried,
                progress,
            );
            total += film.samples().len() as u64;
            bad += film
                .samples()
                .par_iter()
                .filter(|s| !s.iter().all(|x| x.is_finite()))
                .count() as u64;
            sink(&film, rows);
        }
    });
    (bad, total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::progress::NoProgress;
    use crate::render::test_support::{facing_minus_z, px, scene, surface};
    use glam::{dvec3, DVec3};
    use std::sync::atomic::{AtomicU64, Ordering};

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
    fn an_image_of_nan_radiosity_is_refused_not_written_black() {
        // One flat-shaded square filling the view: every sample reads its element's B.
        let s = scene(vec![surface(
            "a",
            0.0,
            facing_minus_z(-1., 1., -1., 1., 0.),
        )]);
        let mesh = mesh_scene(&s, 4.0).unwrap();
        let r = Renderer::new(&mesh);
        let cam = Camera {
            eye: dvec3(0., 0., -1.),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 50.0,
            width: 4,
            height: 4,
        };
        let settings = RenderSettings {
            shading: Shading::Flat,
            supersample: 1,
            ..RenderSettings::default()
        };
        let nan = vec![[f64::NAN, 0.5, 0.5]; mesh.len()];
        let err = try_render(&r, &cam, &nan, &[], &settings, &NoProgress).unwrap_err();
        assert_eq!(err, NonFiniteImage { bad: 16, total: 16 });
        let fine = vec![[0.5; 3]; mesh.len()];
        assert!(try_render(&r, &cam, &fine, &[], &settings, &NoProgress).is_ok());
    }

    #[test]
    fn progress_counts_rows() {
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

    #[test]
    fn render_is_the_tone_mapped_film_in_strips() {
        // A light above a floor, 200 x 200 pixels of 8 x 8 samples: 2.56 M samples, which
        // render() traces in two strips; the image must be the whole film's tone map.
        let s = scene(vec![
            surface("floor", 0.0, facing_minus_z(-1., 1., -1., 1., 0.)),
            surface("light", 5.0, facing_minus_z(-0.3, 0.3, -0.3, 0.3, -0.5)),
        ]);
        let mesh = mesh_scene(&s, 0.1).unwrap();
        let eb: Vec<[f64; 3]> = (0..mesh.len())
            .map(|e| [0.1 + 0.01 * e as f64, 0.5, 5.0 * (e % 3) as f64])
            .collect();
        let vb = crate::shade::vertex_radiosity(&mesh, &eb);
        let r = Renderer::new(&mesh);
        let cam = Camera {
            eye: dvec3(0.1, 0.2, -3.),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 45.0,
            width: 200,
            height: 200,
        };
        const { assert!(200 * 200 * 64 > STRIP_SAMPLES && 200 * 64 < STRIP_SAMPLES) };
        for shading in [Shading::Smooth, Shading::Flat, Shading::Wireframe] {
            let settings = RenderSettings {
                shading,
                exposure_scale: 0.7,
                gamma: 1.8,
                supersample: 8,
                ..RenderSettings::default()
            };
            let img = render(&r, &cam, &eb, &vb, &settings, &NoProgress);
            let film = r.film(&cam, &eb, &vb, shading, 8, &NoProgress);
            assert_eq!(
                film.content() == FilmContent::Coverage,
                shading == Shading::Wireframe
            );
            assert_eq!(img, tonemap::to_image(&film, 0.7, 1.8), "{shading:?}");
            // The linear image is the whole film's pixel means, strips or not; wireframe
            // has no light to give.
            let linear = render_linear(&r, &cam, &eb, &vb, &settings, &NoProgress).unwrap();
            match shading {
                Shading::Wireframe => assert_eq!(linear, None),
                _ => assert_eq!(linear, Some(film.pixel_means()), "{shading:?}"),
            }
        }
        // Under adaptive sampling each strip looks at the first rays of the rows either
        // side; the ones kept from the strip above must be those of the right rows.
        let adaptive = Renderer::new(&mesh).with_adaptive_sampling(0.1);
        for shading in [Shading::Smooth, Shading::Flat] {
            let settings = RenderSettings {
                shading,
                supersample: 8,
                ..RenderSettings::default()
            };
            let film = adaptive.film(&cam, &eb, &vb, shading, 8, &NoProgress);
            let linear = render_linear(&adaptive, &cam, &eb, &vb, &settings, &NoProgress);
            assert_eq!(linear.unwrap(), Some(film.pixel_means()), "{shading:?}");
        }
    }
}
