//! A CPU ray-casting camera that turns a radiosity solution into an image (paper section
//! 2.6, "Walkthrough Ability", and the plates of Appendix B).
//!
//! Radiosity is view-independent: once element radiosities are known, any [`Camera`] can
//! look at the scene without solving again. The paper draws the patches with OpenGL; here
//! each pixel casts a ray into a BVH of the mesh's elements ([`Renderer`]) and colours it by
//! the element it hits first, in one of the paper's three display modes ([`Shading`]).
//!
//! * `camera`: the pinhole [`Camera`] and its automatic placement ([`Camera::for_scene`]).
//! * `renderer`: the element BVH, what a ray sees ([`Shading`]), and the interpolation
//!   weights of smooth shading ([`inverse_bilinear`], [`barycentric`]).
//! * [`tonemap`]: exposure, the paper's gamma correction (section 2.7) and 8-bit encoding.
//! * [`render`] (here): the ray loop over the image, and [`write_png`].
//!
//! Colours go through [`tonemap::expose`] and [`tonemap::encode`]. Rows are rendered in parallel with rayon; each finished
//! row is reported to the [`Progress`] sink as one unit of [`Stage::Render`].

use std::io;
use std::path::Path;

use image::RgbImage;
use rayon::prelude::*;

use crate::progress::{run_stage, Progress, Stage};
use tonemap::GammaEncoder;

mod camera;
mod renderer;
#[cfg(test)]
mod test_support;
pub mod tonemap;

pub use camera::{Camera, DEFAULT_FOV_Y_DEGREES};
pub use renderer::{barycentric, inverse_bilinear, Renderer, Shading};

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
}
