//! `radiosity render`: solve a scene and render it to a PNG image (with snapshots of a progressive solve).

use crate::progress_bar::run_file_stage;
use std::ops::ControlFlow;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use radiosity::progress::Stage;
use radiosity::render::{self};
use radiosity::solve::Step;

use super::{exposure_note, shade_and_render, shade_and_render_linear, solve_scene};
use crate::args::RenderArgs;
use crate::progress_bar::Reporter;
use crate::setup::{
    camera, check_scene_flags, check_solve_flags, image_format, output_directory, prepare_solve,
    refuse_overwriting_inputs, render_settings, stem_of, ImageFormat,
};

/// What [`check`] found `render`'s flags to ask for.
pub struct Checked {
    /// The image to write (`-o`, default `<scene>.png`).
    pub output: PathBuf,
    /// The render settings of the flags.
    pub settings: render::RenderSettings,
    /// PNG or OpenEXR, by the output's extension.
    pub format: ImageFormat,
}

/// `render`'s output and the flags that need no scene, checked before any work: the
/// output's name ([`image_format`], [`output_directory`], not an input), the render
/// settings, `--false-colour` and `--snapshot-every` against the others, and the scene's
/// and solver's numbers. `radiosity-mpi render` checks them so too, before any rank reads
/// the scene.
pub fn check(args: &RenderArgs) -> Result<Checked> {
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.png", stem_of(args.scene.scene.as_deref()))));
    refuse_overwriting_inputs(
        &output,
        "-o",
        &[
            ("scene file", args.scene.scene.as_deref()),
            ("form-factor file", args.solve.form_factors.as_deref()),
        ],
    )?;
    let settings = render_settings(args)?;
    let format = image_format(Some(&output))?;
    output_directory(&output, "-o")?;
    if format == ImageFormat::Exr && settings.shading == render::Shading::Wireframe {
        bail!(
            "{}: a wireframe has no light to write as linear radiance; give --shading smooth \
             or flat for an .exr, or a .png name",
            output.display()
        );
    }
    if format == ImageFormat::Exr {
        // Printed even with --quiet, as every flag the run ignores (QA of issue #16: only a
        // suffix of the "wrote" line said so).
        if args.tone.exposure != radiosity::shade::Exposure::Auto {
            errln!("warning: --exposure ignored: an .exr holds linear radiance, not exposed");
        }
        if args.tone.gamma != 2.2 {
            errln!("warning: --gamma ignored: an .exr holds linear radiance, without gamma");
        }
    }
    if args.false_colour {
        if format == ImageFormat::Exr {
            bail!(
                "{}: --false-colour draws a PNG (colours and a scale bar, not radiance); give \
                 a .png name",
                output.display()
            );
        }
        if settings.shading == render::Shading::Wireframe {
            bail!("--false-colour colours the surfaces; give --shading smooth or flat");
        }
        if args.snapshots.is_some() {
            bail!("--false-colour draws the solved scene once; drop --snapshots");
        }
    }
    // Refused whether or not --false-colour uses it, as every bad number is (QA pass 15 of
    // #16: without --false-colour it was only warned about).
    if let Some(max) = args.lux_max {
        if !(max.is_finite() && max > 0.0) {
            let max = crate::report::typed(max);
            bail!("--lux-max {max}: give the top of the scale in lux, a number above 0");
        }
    }
    if let Some(dir) = &args.snapshots {
        if dir.exists() && !dir.is_dir() {
            bail!(
                "--snapshots {}: is a file; give a folder for the snapshots (it is created if \
                 missing)",
                dir.display()
            );
        }
    }
    if args.snapshot_every == 0 {
        bail!("--snapshot-every 0: give the shots between snapshots, at least 1");
    }
    check_scene_flags(&args.scene)?;
    check_solve_flags(&args.solve)?;
    crate::setup::check_camera_flags(&args.camera)?;
    Ok(Checked {
        output,
        settings,
        format,
    })
}

pub fn run(args: RenderArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let Checked {
        output,
        settings,
        format,
    } = check(&args)?;
    if args.snapshots.is_none() && args.snapshot_every != RenderArgs::SNAPSHOT_EVERY {
        // Printed even with --quiet: the run does not do what the flags say.
        errln!("warning: --snapshot-every ignored: no --snapshots DIR to write snapshots to");
    }
    if !args.false_colour && args.lux_max.is_some() {
        // A warning, as for every flag the run does not use (QA of issue #16: clap refused
        // it with "the following required arguments were not provided").
        errln!("warning: --lux-max ignored: it sets the top of --false-colour's scale");
    }
    if args.false_colour {
        // The colours stand for lux, not for exposed light.
        if args.tone.exposure != radiosity::shade::Exposure::Auto {
            errln!("warning: --exposure ignored with --false-colour: its colours are lux");
        }
        if args.tone.gamma != 2.2 {
            errln!("warning: --gamma ignored with --false-colour: its colours are lux");
        }
        // QA of issue #16: the picture was the same with either.
        if args.rays.direct_light.is_some() {
            errln!(
                "warning: --direct-light ignored with --false-colour: its colours are the \
                 elements' lux"
            );
        }
    }
    // A wireframe is the same at every step of a progressive solve (QA of issue #16: five
    // identical snapshots after the whole solve).
    if args.shading == crate::args::ShadingArg::Wireframe && args.snapshots.is_some() {
        bail!("--shading wireframe draws the mesh, the same at every shot; drop --snapshots");
    }
    let wireframe = settings.shading == render::Shading::Wireframe;
    if wireframe && args.tone.exposure != radiosity::shade::Exposure::Auto {
        // Printed even with --quiet (QA of issue #16): the lines are drawn white whatever
        // the exposure.
        errln!("warning: --exposure ignored with --shading wireframe: its lines are drawn white");
    }
    if wireframe && args.tone.gamma != 2.2 {
        errln!("warning: --gamma ignored with --shading wireframe: its lines are drawn white");
    }
    let (prepared, _, solver) = prepare_solve(&args.scene, &args.solve, &reporter)?;
    if args.snapshots.is_some() && !matches!(solver, radiosity::solve::Solver::Progressive(_)) {
        bail!(
            "--snapshots needs --solver progressive (the solver is {}{}, which has no shots \
             to take pictures of)",
            solver.kind().name(),
            // QA of issue #16: the user chose `auto`, not the solver it picked.
            if args.solve.solver.0 == radiosity::solve::SolverKind::Auto {
                ", auto's choice"
            } else {
                ""
            }
        );
    }
    let camera = camera(&args.camera, &prepared.scene)?;
    if let Some(note) = crate::setup::camera_note(&args.camera, &camera, &prepared.scene) {
        reporter.note(&note);
    }
    let exposure = args.tone.exposure;
    if let Some(dir) = &args.snapshots {
        let radiosity::solve::Solver::Progressive(p) = &solver else {
            unreachable!("--snapshots without progressive refinement is refused above")
        };
        // QA of issue #16 (sixth pass): `--max-shots 3` with a picture every 10 shots made
        // a folder for no picture; nested folders were made where every other output
        // refuses a missing folder; an earlier run's pictures were left among the new.
        if p.max_shots < args.snapshot_every {
            bail!(
                "--snapshot-every {}: no snapshot would be taken within --max-shots {}; give \
                 --snapshot-every at most {}",
                args.snapshot_every,
                p.max_shots,
                p.max_shots
            );
        }
        let existed = dir.is_dir();
        if !existed {
            crate::setup::parent_folder_exists(dir, "--snapshots")?;
            std::fs::create_dir(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        }
        let earlier = std::fs::read_dir(dir)
            .map(|entries| {
                entries
                    .filter_map(|e| e.ok())
                    .filter(|e| {
                        let name = e.file_name().to_string_lossy().into_owned();
                        name.starts_with("shot-") && name.ends_with(".png")
                    })
                    .count()
            })
            .unwrap_or(0);
        if earlier > 0 {
            // Printed even with --quiet: the folder will not hold this run's pictures only.
            errln!(
                "warning: --snapshots {} already holds {} (shot-NNNNN.png); this run writes \
                 over those with its own numbers and leaves the others: empty the folder for \
                 one run's pictures",
                dir.display(),
                crate::report::count(earlier as u64, "picture")
            );
        }
        // What the snapshots will cost, before the solve (QA of issue #16: a long run of
        // snapshots gave no estimate, and a new folder appeared without a word).
        reporter.note(&format!(
            "snapshots to {}{}: a picture every {}, at most {} (--max-shots {}), each a \
             {} x {} render named shot-NNNNN.png",
            dir.display(),
            if existed { "" } else { " (created)" },
            crate::report::count(args.snapshot_every as u64, "shot"),
            p.max_shots / args.snapshot_every,
            p.max_shots,
            camera.width,
            camera.height
        ));
    }
    // A wireframe of a mesh that the solve does not change (dense or progressive, no
    // adaptive subdivision) needs no light: no form factors and no solve (QA of issue #16:
    // it computed both, minutes on a large scene, for white lines on black).
    let adapt = crate::setup::adapt(&args.solve, &prepared, &solver)?;
    if wireframe
        && args.snapshots.is_none()
        && adapt.is_none()
        && args.solve.form_factors.is_none()
        && !matches!(solver, radiosity::solve::Solver::Hierarchical(_))
    {
        reporter.note(
            "wireframe of the mesh: no form factors or solve (the lines are the same \
             whatever the light; hierarchical radiosity and --adapt-rounds solve first, as \
             they make their own elements)",
        );
        // Flags for the light it does not compute (QA of issue #16: `--method hemicube
        // --solver lu` passed without a word, where --gamma and --exposure were warned of;
        // --tolerance has its own warning).
        let mut unused = Vec::new();
        if let Some(m) = args.scene.method.method {
            unused.push(format!(
                "--method {}",
                clap::ValueEnum::to_possible_value(&m)
                    .map_or_else(String::new, |v| v.get_name().to_string())
            ));
        }
        if args.solve.solver.0 != radiosity::solve::SolverKind::Auto {
            unused.push(format!("--solver {}", args.solve.solver));
        }
        if !unused.is_empty() {
            errln!(
                "warning: {} ignored: a wireframe of this mesh needs no light, so nothing is \
                 solved",
                unused.join(" and ")
            );
        }
        let black = vec![[0.0; 3]; prepared.mesh.len()];
        let image = shade_and_render(
            &prepared,
            &prepared.mesh,
            &black,
            &camera,
            settings,
            1.0,
            &reporter,
        )?;
        run_file_stage(&reporter, Stage::Write, &output, || {
            render::write_png(&image, &output)
        })
        .with_context(|| format!("cannot write {}", output.display()))?;
        reporter.note(&format!(
            "wrote {} ({} x {})",
            output.display(),
            image.width(),
            image.height()
        ));
        reporter.print_timings();
        return Ok(());
    }
    // Snapshots render the display radiosity (B plus the ambient term) with a quiet
    // reporter, so that their shading and rendering do not count in the stage times.
    let mut snapshot_error = None;
    let mut written = 0usize;
    let mut observer = |step: &Step| {
        let (Some(dir), Step::Shot(state)) = (&args.snapshots, step) else {
            return ControlFlow::Continue(());
        };
        if state.shot % args.snapshot_every != 0 {
            return ControlFlow::Continue(());
        }
        let quiet = Reporter::new(true);
        let display = state.display_radiosity();
        let display = radiosity::light::Rgb::as_arrays(&display);
        let scale = exposure.scale(&prepared.scene, &prepared.mesh, display);
        let path = dir.join(format!("shot-{:05}.png", state.shot));
        let image = shade_and_render(
            &prepared,
            &prepared.mesh,
            display,
            &camera,
            settings,
            scale,
            &quiet,
        );
        let written_png = image
            .map_err(anyhow::Error::new)
            .and_then(|image| Ok(render::write_png(&image, &path)?));
        match written_png {
            Ok(()) => {
                written += 1;
                ControlFlow::Continue(())
            }
            Err(e) => {
                snapshot_error = Some(e.context(format!("cannot write {}", path.display())));
                ControlFlow::Break(())
            }
        }
    };
    let (solution, _) = solve_scene(
        &prepared,
        solver,
        adapt,
        args.solve.form_factors.as_deref(),
        &mut observer,
        &reporter,
    )?;
    if let Some(e) = snapshot_error {
        return Err(e);
    }
    if let Some(dir) = &args.snapshots {
        reporter.note(&format!(
            "wrote {written} snapshot{} to {}",
            if written == 1 { "" } else { "s" },
            dir.display()
        ));
    }
    if args.false_colour {
        return false_colour(
            &args, &prepared, &solution, &camera, settings, &output, &reporter,
        );
    }
    if format == ImageFormat::Exr {
        let pixels = shade_and_render_linear(
            &prepared,
            &solution.mesh,
            solution.element_rgb(),
            &camera,
            settings,
            &reporter,
        )?
        .expect("a wireframe .exr is refused above");
        run_file_stage(&reporter, Stage::Write, &output, || {
            radiosity::io::exr::write_radiance(
                &output,
                camera.width as usize,
                camera.height as usize,
                &pixels,
                &camera,
                "radiosity render",
                &crate::setup::scene_unit(),
            )
        })
        .with_context(|| format!("cannot write {}", output.display()))?;
        reporter.note(&format!(
            "wrote {} ({} x {}, linear radiance = radiosity / pi in the scene's units per \
             steradian, lengths in {}; --exposure and --gamma are not applied)",
            output.display(),
            camera.width,
            camera.height,
            crate::setup::scene_unit()
        ));
        reporter.print_timings();
        return Ok(());
    }
    let scale = exposure.scale(&prepared.scene, &solution.mesh, solution.element_rgb());
    let image = shade_and_render(
        &prepared,
        &solution.mesh,
        solution.element_rgb(),
        &camera,
        settings,
        scale,
        &reporter,
    )?;
    run_file_stage(&reporter, Stage::Write, &output, || {
        render::write_png(&image, &output)
    })
    .with_context(|| format!("cannot write {}", output.display()))?;
    // A wireframe's lines are not scaled by the exposure (QA of issue #16: its note was
    // printed for them).
    if !wireframe {
        reporter.note(&exposure_note(
            &prepared,
            &solution.mesh,
            solution.element_rgb(),
            exposure,
            scale,
        ));
    }
    reporter.note(&format!(
        "wrote {} ({} x {})",
        output.display(),
        image.width(),
        image.height()
    ));
    if !wireframe && picture_can_be_lit(&prepared, &solution) {
        if let Some(warning) = black_picture(
            image.pixels().map(|p| p.0 == [0, 0, 0]),
            fronts_in_view(&prepared, &camera),
            false,
            camera.fov_y_degrees,
        )
        .map(|w| with_exposure_hint(w, exposure))
        {
            // Printed even with --quiet: the picture shows nothing.
            errln!("warning: {warning}");
        }
    }
    reporter.print_timings();
    Ok(())
}

/// A vertical field of view (degrees) past which a black picture may be the width's fault.
const WIDE_FOV: f64 = 120.0;

/// Above this share of black pixels a picture of a lit scene is said to show nothing.
const BLACK_PICTURE_SHARE: f64 = 0.95;

/// A warning when nearly every pixel of `image` is black though the scene's light reaches
/// its surfaces (a lost light is warned of by the solve): the camera outside the scene,
/// seeing the backs of its faces, or inside a closed piece of furniture (QA of issue #16:
/// a camera outside a closed room wrote a black picture without a word; `illuminance`
/// warns of points that see only backs).
/// `fronts` is the share of the view whose camera rays meet the front of a surface
/// ([`fronts_in_view`]): where most do, the camera is not to blame, what it sees gets no
/// light or (unless the picture shows `lux`) reflects none (QA of issue #16: a camera inside a room facing a wall of
/// reflectance 0 was told to move into the scene).
/// `fov` is the vertical field of view in degrees: past [`WIDE_FOV`] the scene may be in
/// view but small (QA of issue #16: `--fov 170` was told to move --eye).
fn black_picture(
    dark: impl Iterator<Item = bool>,
    fronts: f64,
    lux: bool,
    fov: f64,
) -> Option<String> {
    let (mut pixels, mut black) = (0u64, 0u64);
    for is_dark in dark {
        pixels += 1;
        black += u64::from(is_dark);
    }
    let share = black as f64 / pixels.max(1) as f64;
    (share > BLACK_PICTURE_SHARE).then(|| {
        if fronts >= 0.5 {
            // Reflectance does not matter to lux, which is the light arriving.
            format!(
                "{:.1} % of the picture shows nothing lit: the surfaces in view face the \
                 camera, but no light reaches them{}",
                100.0 * share,
                if lux {
                    ""
                } else {
                    " or they reflect none (reflectance 0)"
                }
            )
        } else if fov > WIDE_FOV {
            format!(
                "{:.1} % of the picture shows nothing lit: at --fov {} the view is so wide \
                 that what is lit may be a few pixels in it, the rest the backs of faces or \
                 nothing; a narrower --fov shows more of the scene, or move --eye into it",
                100.0 * share,
                crate::report::typed(fov)
            )
        } else {
            format!(
                "{:.1} % of the picture shows nothing lit: the camera sees the backs of faces \
                 (outside a closed room, or inside furniture or a wall) or nothing; move \
                 --eye into the scene",
                100.0 * share
            )
        }
    })
}

/// The share of a 32 x 32 grid of the camera's rays whose first hit, among the scene's
/// surfaces, is a front face.
fn fronts_in_view(
    prepared: &radiosity::pipeline::Prepared,
    camera: &radiosity::render::Camera,
) -> f64 {
    const GRID: u32 = 32;
    let surfaces = &prepared.scene.surfaces;
    let (lo, hi) = prepared.scene.bounds();
    let near = 1e-9 * (hi - lo).length();
    let fronts = (0..GRID * GRID)
        .filter(|k| {
            let x = (f64::from(k % GRID) + 0.5) / f64::from(GRID) * f64::from(camera.width);
            let y = (f64::from(k / GRID) + 0.5) / f64::from(GRID) * f64::from(camera.height);
            let dir = camera.ray_direction(x, y);
            prepared
                .occluders
                .closest_hit(camera.eye, dir, near, f64::INFINITY)
                .and_then(|hit| surfaces.get(hit.id as usize))
                .and_then(|s| radiosity::geometry::polygon_normal(&s.vertices))
                .is_some_and(|n| n.dot(dir) < 0.0)
        })
        .count();
    fronts as f64 / f64::from(GRID * GRID)
}

/// The nothing-lit warning, with the other likely cause where the exposure was given
/// (review of issue #16: a very low --exposure blackens the 8-bit picture too).
fn with_exposure_hint(warning: String, exposure: radiosity::shade::Exposure) -> String {
    match exposure {
        radiosity::shade::Exposure::Fixed(s) => format!(
            "{warning}, or raise --exposure {} (too low to show the light)",
            crate::report::significant(s, 4)
        ),
        radiosity::shade::Exposure::Auto => warning,
    }
}

/// Whether a black picture is the camera's doing: the scene's light reaches its surfaces
/// (QA of issue #16: a scene with no light got this warning after the one saying nothing
/// emits, and its camera, inside the room, was blamed).
fn picture_can_be_lit(
    prepared: &radiosity::pipeline::Prepared,
    solution: &radiosity::pipeline::Solution,
) -> bool {
    crate::report::energy_band(&solution.balance).is_some()
        && (crate::report::light_lost(&prepared.scene, solution).is_none()
            // QA pass 15 of issue #16: light lost over many reflections lights them.
            || crate::report::light_lands(&prepared.scene, solution))
}

/// `render --false-colour`: the illuminance of every element
/// ([`radiosity::illuminance::element_illuminance`]) rendered as smooth or flat shading
/// renders radiosity (without the per-ray direct light), divided per pixel by the fraction
/// of its rays that met a surface (a second render of ones), then coloured with a scale bar.
fn false_colour(
    args: &RenderArgs,
    prepared: &radiosity::pipeline::Prepared,
    solution: &radiosity::pipeline::Solution,
    camera: &radiosity::render::Camera,
    settings: render::RenderSettings,
    output: &std::path::Path,
    reporter: &Reporter,
) -> Result<()> {
    use radiosity::illuminance::{element_illuminance_with_progress, false_colour_picture};
    // Reported as the illuminance stage, a unit per element whose illuminance is computed
    // at its centroid (a black surface's): a long run shows its progress and time left.
    let lux = element_illuminance_with_progress(prepared, solution, reporter);
    let largest = lux
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    // The top of the scale: the user's, in as many steps as read well (5 when none fits),
    // or the largest element's illuminance rounded up to a round number of round steps.
    let (max, ticks) = match args.lux_max {
        Some(m) => match radiosity::illuminance::nice_scale(m) {
            (top, n) if (top - m).abs() <= 1e-9 * m => (m, n),
            _ => (m, 5),
        },
        None => radiosity::illuminance::nice_scale(largest),
    };
    let settings = render::RenderSettings {
        direct_light: false,
        ..settings
    };
    let values: Vec<[f64; 3]> = lux.iter().map(|&v| [v; 3]).collect();
    let ones = vec![[1.0; 3]; values.len()];
    let linear = |b: &[[f64; 3]], reporter: &Reporter| {
        shade_and_render_linear(prepared, &solution.mesh, b, camera, settings, reporter)
            .map(|p| p.expect("a wireframe is refused above"))
    };
    let pixels = linear(&values, reporter)?;
    // The share of each pixel's rays that met a front, a hole's front (a dropped buried
    // piece seen through a gap) counted whole, so that its open share darkens the lux
    // rather than turning it into background.
    let coverage = {
        let renderer =
            radiosity::render::Renderer::for_settings(&solution.mesh, &prepared.scene, &settings)
                .counting_coverage();
        let vertex_ones = radiosity::shade::vertex_radiosity(&solution.mesh, &ones);
        radiosity::render::render_linear(
            &renderer,
            camera,
            &ones,
            &vertex_ones,
            &settings,
            &Reporter::new(true),
        )?
        .expect("a wireframe is refused above")
    };
    let (pixel_lux, coverage): (Vec<f64>, Vec<f64>) = pixels
        .iter()
        .zip(&coverage)
        .map(|(v, c)| {
            if c[0] > 0.0 {
                (v[0] / c[0], c[0])
            } else {
                (0.0, 0.0)
            }
        })
        .unzip();
    let image = false_colour_picture(
        &pixel_lux,
        &coverage,
        camera.width,
        camera.height,
        max,
        ticks,
    );
    run_file_stage(reporter, Stage::Write, output, || {
        render::write_png(&image, output)
    })
    .with_context(|| format!("cannot write {}", output.display()))?;
    // A view lower than the scale bar needs leaves white below it (QA of issue #16: a
    // 128 x 128 view came out 238 x 160 with a white strip and no word why).
    let taller = if image.height() > camera.height {
        format!(
            ", {} pixels tall for the scale's labels (white below the view)",
            image.height()
        )
    } else {
        String::new()
    };
    // The view shows nothing where no pixel met a front (QA of issue #16: a camera
    // outside the room gave a white false-colour picture without the warning the shaded
    // render gives).
    if picture_can_be_lit(prepared, solution) {
        let nothing = pixel_lux
            .iter()
            .zip(&coverage)
            .map(|(&lux, &c)| c <= 0.0 || lux <= 0.0);
        let fronts = fronts_in_view(prepared, camera);
        if let Some(warning) = black_picture(nothing, fronts, true, camera.fov_y_degrees) {
            errln!("warning: {warning}");
        }
    }
    reporter.note(&format!(
        "wrote {} ({} x {}: the {} x {} view and a {} pixel wide scale bar{taller}; false \
         colour from 0 to {} lx, the largest element illuminance is {} lx; {})",
        output.display(),
        image.width(),
        image.height(),
        camera.width,
        camera.height,
        radiosity::illuminance::SCALE_BAR_WIDTH,
        radiosity::illuminance::lux_label(max),
        radiosity::illuminance::lux_label(largest),
        crate::setup::LUX_NOTE,
    ));
    reporter.print_timings();
    Ok(())
}
