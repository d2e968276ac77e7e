//! The wgpu pipeline against the CPU renderer: the Cornell box from the default camera,
//! drawn offscreen (on lavapipe where there is no GPU) and by `radiosity::render::render`,
//! at the same size, exposure and gamma.
//!
//! Where no adapter exists the test says it was skipped and why; with the environment
//! variable `CI` set it fails instead (CI installs lavapipe, so an adapter must be there).

use radiosity::pipeline::Prepared;
use radiosity::pipeline::{self, SolveRequest};
use radiosity::progress::NoProgress;
use radiosity::render::{self, Camera, RenderSettings, Renderer, Shading};
use radiosity::scene::cornell_box;
use radiosity::shade::{self, Exposure};
use radiosity::solve::{keep_going, Solver};
use radiosity_viewer::gpu::{Headless, Style};

/// Mean absolute difference per channel (0-255) allowed between the two images.
///
/// Measured on lavapipe (llvmpipe, LLVM 15) at 256 x 256: smooth 0.047, flat 0.015, with
/// a largest single difference of 160 (a silhouette pixel). The differences come from (1)
/// edge pixels: the GPU covers a pixel by its centre with the top-left rule, the CPU casts
/// one ray through the centre, so along a silhouette a pixel can go to either surface; and
/// (2) smooth shading inside quadrilateral elements: the GPU interpolates vertex
/// radiosities linearly over two triangles, the CPU bilinearly over the quad. The bounds
/// leave a factor of 10 for other drivers' rasterisation and rounding; a wrong camera, a
/// flipped image, or a missing gamma or exposure moves the mean by tens of levels.
const SMOOTH_BOUND: f64 = 0.5;
const FLAT_BOUND: f64 = 0.2;

fn mean_abs_difference(gpu: &image::RgbaImage, cpu: &image::RgbImage) -> (f64, u8) {
    assert_eq!(gpu.dimensions(), cpu.dimensions());
    let mut sum = 0u64;
    let mut worst = 0u8;
    for (g, c) in gpu.pixels().zip(cpu.pixels()) {
        for k in 0..3 {
            let d = g.0[k].abs_diff(c.0[k]);
            sum += d as u64;
            worst = worst.max(d);
        }
    }
    (sum as f64 / (3 * cpu.width() * cpu.height()) as f64, worst)
}

#[test]
fn offscreen_cornell_box_matches_the_cpu_render() {
    let gpu = match Headless::new() {
        Ok(gpu) => gpu,
        Err(e) => {
            if std::env::var_os("CI").is_some() {
                panic!("CI is set but no wgpu adapter is available: {e}");
            }
            eprintln!("SKIPPED offscreen_cornell_box_matches_the_cpu_render: {e}");
            return;
        }
    };
    eprintln!("adapter: {}", gpu.adapter);
    let file = cornell_box();
    let prepared = Prepared::new(file.scene, file.settings, &NoProgress).unwrap();
    let solution = pipeline::solve(
        &prepared,
        &SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL),
        &mut keep_going,
        &NoProgress,
    )
    .unwrap();
    let mesh = &prepared.mesh;
    let b = solution.element_rgb().to_vec();
    let vb = shade::vertex_radiosity(mesh, &b);
    let scale = Exposure::Auto.scale(&prepared.scene, mesh, &b);
    let camera = Camera::for_scene(&prepared.scene, 256, 256);
    let renderer = Renderer::new(mesh);
    for (shading, bound) in [(Shading::Smooth, SMOOTH_BOUND), (Shading::Flat, FLAT_BOUND)] {
        let cpu = render::render(
            &renderer,
            &camera,
            &b,
            &vb,
            &RenderSettings {
                shading,
                exposure_scale: scale,
                gamma: 2.2,
                supersample: 1,
                ..RenderSettings::default()
            },
            &NoProgress,
        );
        let style = Style {
            shading,
            exposure_scale: scale,
            gamma: 2.2,
            ..Default::default()
        };
        let image = gpu.render(mesh, &b, &vb, &camera, &style).unwrap();
        let (mean, worst) = mean_abs_difference(&image, &cpu);
        if let Some(dir) = std::env::var_os("RADIOSITY_TEST_IMAGES") {
            let dir = std::path::PathBuf::from(dir);
            image
                .save(dir.join(format!("gpu-{shading:?}.png")))
                .unwrap();
            cpu.save(dir.join(format!("cpu-{shading:?}.png"))).unwrap();
        }
        eprintln!("{shading:?}: mean |gpu - cpu| = {mean:.3} levels, largest {worst}");
        assert!(
            mean < bound,
            "{shading:?}: the GPU image differs from the CPU render by {mean:.3} levels on \
             average (bound {bound}; largest {worst}), {} elements, camera {camera:?}, adapter {}",
            mesh.len(),
            gpu.adapter
        );
    }
}
