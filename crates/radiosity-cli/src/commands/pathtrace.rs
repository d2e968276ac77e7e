//! `radiosity pathtrace`: the path-traced view of a scene, the yardstick of the radiosity
//! chain; with `--compare`, the radiosity render of the same camera beside it, their pixel
//! difference and an error map; `--save-reference` / `--reference` keep an expensive view
//! in an OpenEXR file.

use crate::progress_bar::run_file_stage;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use radiosity::io::path_traced_file::{read_path_traced, write_path_traced};
use radiosity::pathtrace::{emitter_pixels, path_trace, PathTraceSettings};
use radiosity::progress::{run_stage, Stage};
use radiosity::render::{self, tonemap, Renderer, Shading};
use radiosity::scene::Scene;
use radiosity::shade::{self, Exposure};

use super::solve_as_asked;
use crate::args::PathTraceArgs;
use crate::progress_bar::Reporter;
use crate::report;
use crate::setup::{self, camera, gamma, image_format, load_scene, prepare_solve, ImageFormat};

pub fn run(args: PathTraceArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let format = image_format(args.output.as_deref())?;
    let gamma = gamma(&args.tone)?;
    let settings = PathTraceSettings {
        samples_per_pixel: args.paths,
        max_bounces: args.max_bounces,
        roulette_after_bounces: args.roulette_after,
        next_event_estimation: !args.no_light_sampling,
        seed: args.path_seed,
    };
    settings.check()?;
    if format == ImageFormat::Exr {
        // Printed even with --quiet, as `render` does (QA of issue #16).
        if args.tone.exposure != Exposure::Auto {
            errln!("warning: --exposure ignored: an .exr holds linear radiance, not exposed");
        }
        if args.tone.gamma != 2.2 {
            errln!("warning: --gamma ignored: an .exr holds linear radiance, without gamma");
        }
    }
    if !args.scene.no_work_limit && args.reference.is_none() {
        let (width, height) = args.camera.size();
        radiosity::budget::check_path_trace_work(width, height, args.paths)?;
    }
    // Said once the reference has been read (QA pass 14 of #16: it came before "not a
    // readable OpenEXR file").
    let mut ignored_with_reference = None;
    if let Some(path) = &args.reference {
        // Before any work, in the flag's name (QA of issue #16: a missing file was named
        // only after the scene was read, without the flag).
        // A device or a pipe (/dev/null) is neither a folder nor missing (QA of issue #16:
        // it was "no such file").
        let wrong = if path.is_dir() {
            Some("is a folder")
        } else if !path.exists() {
            Some("no such file")
        } else if !path.is_file() {
            Some("is not a file (a device or a pipe)")
        } else {
            None
        };
        if let Some(wrong) = wrong {
            bail!(
                "--reference {}: {wrong}; save a path-traced view with --save-reference \
                 FILE.exr first",
                path.display()
            );
        }
        // The tracing flags do nothing when the view is read back (QA of issue #16:
        // `--paths` was dropped without a word). Printed even with --quiet.
        let default = PathTraceSettings::DEFAULT;
        let given = [
            ("--paths", args.paths != default.samples_per_pixel),
            ("--path-seed", args.path_seed != default.seed),
            ("--max-bounces", args.max_bounces != default.max_bounces),
            (
                "--roulette-after",
                args.roulette_after != default.roulette_after_bounces,
            ),
            ("--no-light-sampling", args.no_light_sampling),
        ];
        let ignored: Vec<&str> = crate::setup::flags_given(&given);
        if !ignored.is_empty() {
            ignored_with_reference = Some(format!(
                "warning: {} ignored with --reference: the path-traced view is read from {} \
                 as it was traced (its paths a pixel and seed are noted when it is read)",
                ignored.join(", "),
                path.display()
            ));
        }
    }
    if args.compare {
        setup::check_render_budget(
            &args.camera,
            args.rays.supersample,
            true,
            args.scene.no_work_limit,
        )?;
    }
    let shading = setup::shading(args.shading);
    if args.compare && shading == Shading::Wireframe {
        bail!("--compare needs --shading smooth or flat: a wireframe has no radiosity to compare");
    }
    if let Some(path) = &args.save_reference {
        check_exr(path)?;
    }

    setup::check_camera_flags(&args.camera)?;
    // The scene: meshed and with its solver for --compare, as it is for the path tracer.
    let prepared = if args.compare {
        Some(prepare_solve(&args.scene, &args.solve, &reporter)?)
    } else {
        // The radiosity flags set the solve --compare adds (QA of issue #16: without it they
        // were dropped without a word). Printed even with --quiet.
        let s = &args.scene;
        let given = [
            ("--max-area", s.max_area.is_some()),
            ("--steps", s.steps.is_some()),
            ("--method", s.method.method.is_some()),
            (
                "--solver",
                args.solve.solver.0 != radiosity::solve::SolverKind::Auto,
            ),
            ("--tolerance", args.solve.tolerance.is_some()),
            ("--form-factors", args.solve.form_factors.is_some()),
            (
                "--epsilon",
                args.solve.epsilon != radiosity::solve::HierarchicalSettings::DEFAULT_EPSILON,
            ),
            ("--min-area", args.solve.min_area.is_some()),
            ("--no-final-gather", args.solve.no_final_gather),
            (
                "--gather-points",
                args.solve.gather_points != radiosity::solve::GATHER_POINTS_DEFAULT,
            ),
            ("--adapt-rounds", args.solve.adapt_rounds.is_some()),
            (
                "--adapt-contrast",
                args.solve.adapt_contrast != radiosity::mesh::DEFAULT_CONTRAST,
            ),
            (
                "--adapt-max-elements",
                args.solve.adapt_max_elements.is_some(),
            ),
            // The form-factor methods' own settings (QA pass 13 of #16: `--seed 3` went
            // without a word, though the path tracer's seed is --path-seed).
            (
                "--resolution",
                s.method.resolution != crate::args::MethodArgs::RESOLUTION,
            ),
            (
                "--samples",
                s.method.samples != crate::args::MethodArgs::SAMPLES,
            ),
            ("--seed", s.method.seed != crate::args::MethodArgs::SEED),
            (
                "--max-shots",
                args.solve.max_shots != radiosity::solve::ProgressiveSettings::default().max_shots,
            ),
        ];
        // The flags of the radiosity render --compare draws beside it (QA of issue #16:
        // `pathtrace --supersample 2` was ignored without a word). A flag at its default
        // value is not told apart from one left out.
        let render_given = [
            ("--shading", args.shading != crate::args::ShadingArg::Smooth),
            ("--supersample", args.rays.supersample != 8),
            (
                "--adaptive-contrast",
                args.rays.adaptive_contrast != crate::args::RayArgs::ADAPTIVE_CONTRAST,
            ),
            ("--direct-light", args.rays.direct_light.is_some()),
        ];
        let ignored: Vec<&str> = crate::setup::flags_given(&given);
        if !ignored.is_empty() {
            errln!(
                "warning: {} ignored without --compare: the path tracer traces the scene's \
                 polygons (the meshing, form-factor and solver flags set the radiosity solve \
                 --compare adds){}",
                ignored.join(", "),
                if ignored.contains(&"--seed") {
                    "; the path tracer's own seed is --path-seed"
                } else {
                    ""
                }
            );
        }
        if args.error_scale != 0.2 {
            errln!(
                "warning: --error-scale ignored without --compare: it sets the colours of the \
                 error map --compare draws"
            );
        }
        let ignored: Vec<&str> = crate::setup::flags_given(&render_given);
        if !ignored.is_empty() {
            errln!(
                "warning: {} ignored without --compare: {} the radiosity render \
                 --compare draws beside the path-traced view (the path tracer averages over \
                 each pixel with --paths)",
                ignored.join(", "),
                if ignored.len() == 1 {
                    "it sets"
                } else {
                    "they set"
                }
            );
        }
        None
    };
    let loaded;
    let (scene, stem): (&Scene, &str) = match &prepared {
        Some((p, stem, _)) => (&p.scene, stem),
        None => {
            loaded = load_scene(args.scene.scene.as_deref(), args.scene.scale, &reporter)?;
            (&loaded.0.scene, &loaded.1)
        }
    };
    let camera = camera(&args.camera, scene)?;
    if let Some(note) = crate::setup::camera_note(&args.camera, &camera, scene) {
        reporter.note(&note);
    }
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{stem}-pathtrace.png")));
    let inputs = [
        ("scene file", args.scene.scene.as_deref()),
        ("reference", args.reference.as_deref()),
        ("form-factor file", args.solve.form_factors.as_deref()),
    ];
    setup::refuse_overwriting_inputs(&output, "-o", &inputs)?;
    setup::output_directory(&output, "-o")?;
    // The pictures written beside -o are named as such (QA of issue #16: the refusal named
    // -o foo-radiosity.exr, which the user never typed).
    if args.compare {
        for beside in [
            sibling(&output, "radiosity", format),
            sibling(&output, "error", ImageFormat::Png),
        ] {
            let label = format!(
                "-o {} (the picture written beside it, {})",
                output.display(),
                beside.display()
            );
            setup::refuse_overwriting_inputs_as(&beside, "-o", &label, &inputs)?;
            setup::output_directory(&beside, "-o")?;
        }
    }
    if let Some(saved) = &args.save_reference {
        setup::refuse_overwriting_inputs(saved, "--save-reference", &inputs)?;
        setup::output_directory(saved, "--save-reference")?;
    }
    // The scene was read before the outputs were known: the files it named itself (a
    // glTF's textures and buffers, an OBJ's MTL) are checked now, before the tracing.
    if let Some(path) = args.scene.scene.as_deref() {
        setup::refuse_outputs_read(path)?;
    }

    // The path-traced view: traced, or read back.
    let (view, settings) = match &args.reference {
        Some(path) => {
            let saved = run_file_stage(&reporter, Stage::Parse, path, || {
                read_path_traced(path, &camera, scene)
            })?;
            if let Some(warning) = &ignored_with_reference {
                errln!("{warning}");
            }
            reporter.note(&format!(
                "reference read from {} ({} paths a pixel, seed {})",
                path.display(),
                saved.settings.samples_per_pixel,
                saved.settings.seed
            ));
            (saved.view, saved.settings)
        }
        None => {
            let start = std::time::Instant::now();
            let view = path_trace(scene, &camera, &settings, &reporter)?;
            let seconds = start.elapsed().as_secs_f64();
            reporter.note(&format!(
                "path traced {} x {} at {} paths a pixel in {:.2} s ({:.2} M paths/s)",
                camera.width,
                camera.height,
                settings.samples_per_pixel,
                seconds,
                (camera.width as f64 * camera.height as f64 * settings.samples_per_pixel as f64)
                    / seconds.max(1e-9)
                    / 1e6
            ));
            (view, settings)
        }
    };
    if let Some(path) = &args.save_reference {
        run_file_stage(&reporter, Stage::Write, path, || {
            write_path_traced(path, &view, &camera, &settings, scene)
        })?;
        reporter.note(&format!("wrote the reference to {}", path.display()));
    }
    report::path_traced(&view, &settings);

    let Some((prepared, _, solver)) = &prepared else {
        // Alone: render's rule estimated by paths unless an exposure is given.
        if format == ImageFormat::Exr {
            write_linear(view.film(), &camera, &output, &reporter)?;
            reporter.print_timings();
            return Ok(());
        }
        let white = match args.tone.exposure {
            Exposure::Fixed(_) => None,
            Exposure::Auto => area_exposure_white(scene, &settings, &reporter)?,
        };
        let scale = match args.tone.exposure {
            Exposure::Fixed(s) => s,
            Exposure::Auto => tonemap::scale_for(white),
        };
        let shown = report::significant(scale, 4);
        // QA pass 15 of issue #16: a view whose every pixel shows an emitter printed the
        // fallback 1 as what its brightest pixels give; all pixels count there now, and a
        // view with nothing lit says so.
        let own = match view.auto_exposure_white() {
            Some(own) => format!(
                "the view's own brightest 2 % of pixels would give {}",
                report::significant(tonemap::scale_for(Some(own)), 4)
            ),
            None => "the view's own brightest 2 % of pixels give no exposure: no pixel \
                     shows light"
                .to_string(),
        };
        let how = match (args.tone.exposure, white) {
            (Exposure::Auto, Some(white)) => format!(
                "auto: {}, the mean radiosity of the brightest 2 % of the {}, \
                 is white, as `render` makes it, estimated at {} points by {} paths each; \
                 {own}; ",
                report::significant(white, 5),
                // QA of issue #16: said of a scene with no non-emitting area.
                if scene.surfaces.iter().all(|s| s.emission.max_band() > 0.0) {
                    "area (every surface emits, so all of it counts)"
                } else {
                    "non-emitting area"
                },
                radiosity::pathtrace::EXPOSURE_POINTS,
                radiosity::pathtrace::EXPOSURE_PATHS,
            ),
            // QA of issue #16: the fallback was presented as measured.
            (Exposure::Auto, None) => "auto: nothing is lit (no light reaches the surfaces' \
                                       points), so scale 1 is the fallback; "
                .to_string(),
            (Exposure::Fixed(_), _) => String::new(),
        };
        reporter.note(&format!(
            "exposure scale {shown} ({how}`render --exposure {shown}` shows a render with it)"
        ));
        write_image(
            &tonemap::to_image(view.film(), scale, gamma),
            &output,
            &reporter,
        )?;
        reporter.print_timings();
        return Ok(());
    };

    // --compare: the radiosity render of the same camera, with the same exposure.
    let solution = solve_as_asked(prepared, *solver, &args.solve, &reporter)?;
    let b = solution.element_rgb();
    let vertex_b = run_stage(&reporter, Stage::Shade, 0, || {
        let mut vertex_b = shade::vertex_radiosity(&solution.mesh, b);
        shade::smooth_objects(scene, &solution.mesh, &mut vertex_b);
        vertex_b
    });
    let render_settings = setup::ray_settings(&args.rays, args.shading);
    let renderer = Renderer::for_settings(&solution.mesh, scene, &render_settings);
    let film = renderer.film(
        &camera,
        b,
        &vertex_b,
        shading,
        args.rays.supersample,
        &reporter,
    );
    // Pixels that show an emitter in either view are left out: few paths can miss a
    // light's edge that the renderer's grid of rays meets.
    let emitters = emitter_pixels(&renderer, scene, &camera, args.rays.supersample);
    let comparison = view.compare_excluding(&film, &emitters)?;
    let scale = args.tone.exposure.scale(scene, &solution.mesh, b);
    report::path_trace_comparison(&comparison, solution.mesh.len());
    let radiosity_image = sibling(&output, "radiosity", format);
    let error_png = sibling(&output, "error", ImageFormat::Png);
    match format {
        ImageFormat::Png => {
            write_image(
                &tonemap::to_image(view.film(), scale, gamma),
                &output,
                &reporter,
            )?;
            write_image(
                &tonemap::to_image(&film, scale, gamma),
                &radiosity_image,
                &reporter,
            )?;
        }
        ImageFormat::Exr => {
            write_linear(view.film(), &camera, &output, &reporter)?;
            write_linear(&film, &camera, &radiosity_image, &reporter)?;
        }
    }
    write_image(
        &comparison.error_map.to_image(args.error_scale),
        &error_png,
        &reporter,
    )?;
    // One line for the exposure (QA of issue #16: it was printed twice).
    // The path tracer's own estimate is traced only for this note: not with -q.
    let whose = match args.tone.exposure {
        Exposure::Auto if args.scene.quiet => " (auto, the radiosity solution's)".to_string(),
        Exposure::Auto => format!(
            " (auto, the radiosity solution's; the path tracer's own estimate of it would be \
             {})",
            report::significant(
                tonemap::scale_for(area_exposure_white(scene, &settings, &reporter)?),
                4
            )
        ),
        Exposure::Fixed(_) => String::new(),
    };
    let exposure = match format {
        ImageFormat::Png => format!(
            "exposure scale {} for both{whose}",
            report::significant(scale, 4)
        ),
        // Linear radiance: no exposure was applied (QA of issue #16: the note gave one
        // "for both" images that have none).
        ImageFormat::Exr => "both views in linear radiance, unexposed".to_string(),
    };
    reporter.note(&format!(
        "{exposure}; error map: white 0, blue darker and red brighter than the path tracer, \
         full colour at {} % of its RMS luminance, black left out",
        report::significant(100.0 * args.error_scale, 4)
    ));
    reporter.print_timings();
    Ok(())
}

/// `out.png` -> `out-<suffix>.png` (or `.exr`), beside it.
fn sibling(output: &Path, suffix: &str, format: ImageFormat) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or("pathtrace".into(), |s| s.to_string_lossy().into_owned());
    let ext = match format {
        ImageFormat::Png => "png",
        ImageFormat::Exr => "exr",
    };
    output.with_file_name(format!("{stem}-{suffix}.{ext}"))
}

/// Writes `film` as linear radiance (radiosity / pi) to the OpenEXR file `path`.
fn write_linear(
    film: &render::Film,
    camera: &render::Camera,
    path: &Path,
    reporter: &Reporter,
) -> Result<()> {
    run_file_stage(reporter, Stage::Write, path, || {
        radiosity::io::exr::write_radiance(
            path,
            film.width(),
            film.height(),
            &film.pixel_means(),
            camera,
            "radiosity pathtrace",
            &crate::setup::scene_unit(),
        )
    })
    .with_context(|| format!("cannot write {}", path.display()))?;
    reporter.note(&format!(
        "wrote {} ({} x {}, linear radiance = radiosity / pi in the scene's units per \
         steradian, lengths in {}; --exposure and --gamma are not applied)",
        path.display(),
        film.width(),
        film.height(),
        crate::setup::scene_unit()
    ));
    Ok(())
}

/// Refuses a reference file not named *.exr.
fn check_exr(path: &Path) -> Result<()> {
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        bail!(
            "--save-reference {}: references are OpenEXR files; give it an .exr name",
            path.display()
        );
    }
    Ok(())
}

fn write_image(image: &image::RgbImage, path: &Path, reporter: &Reporter) -> Result<()> {
    run_file_stage(reporter, Stage::Write, path, || {
        render::write_png(image, path)
    })
    .with_context(|| format!("cannot write {}", path.display()))?;
    reporter.note(&format!(
        "wrote {} ({} x {})",
        path.display(),
        image.width(),
        image.height()
    ));
    Ok(())
}

/// The automatic exposure of `render` estimated by paths
/// ([`radiosity::pathtrace::PathTracer::area_exposure_scale`]; issue #11: the view's own
/// statistic made the Cornell box's path-traced picture half as bright as its render).
fn area_exposure_white(
    scene: &Scene,
    settings: &PathTraceSettings,
    reporter: &Reporter,
) -> Result<Option<f64>> {
    let tracer = radiosity::pathtrace::PathTracer::new(scene)?;
    Ok(run_stage(reporter, Stage::Exposure, 0, || {
        tracer.area_exposure_white(
            scene,
            settings,
            radiosity::pathtrace::EXPOSURE_POINTS,
            radiosity::pathtrace::EXPOSURE_PATHS,
        )
    }))
}
