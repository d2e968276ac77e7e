//! `radiosity`: the command-line program. A thin layer over the `radiosity` library:
//! parse the arguments, run the pipeline, report progress and timings.

#[macro_use]
mod macros;

mod args;
mod errors;
mod peak_memory;
mod progress_bar;
mod setup;
mod view;

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use image::RgbImage;
use radiosity::form_factor::FormFactorMatrix;
use radiosity::mesh::Mesh;
use radiosity::pipeline::{
    self as pipeline, FormFactorStats, FormFactors, Prepared, Solution, SolutionReport,
    SolveRequest,
};
use radiosity::progress::{run_stage, Stage};
use radiosity::render::{self, Camera, RenderSettings, Renderer};
use radiosity::scene;
use radiosity::shade::{self, Exposure};
use radiosity::solve::{keep_going, Observer, Solver, SolverKind, Step};

use args::{
    BenchArgs, BuildingArgs, CheckArgs, CompareArgs, FormFactorArgs, GenerateCommand, RenderArgs,
    SceneArgs, SolveArgs, SolveOptions, ViewArgs,
};
use errors::{describe, hint};
use peak_memory::{peak_memory_bytes, reset_peak_memory};
use progress_bar::{format_duration, Reporter};
use setup::{camera, prepare, render_settings};

/// A radiosity renderer after De Angelis, "Radiosity: A Study in Photorealistic Rendering".
///
/// Every command takes an optional scene file in the paper's Appendix A format; without one
/// it uses the built-in Cornell box.
#[derive(Parser)]
#[command(name = "radiosity", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene and render it to a PNG image.
    Render(RenderArgs),
    /// Compute the form-factor matrix and write it to a file (paper 2.8).
    Formfactors(FormFactorArgs),
    /// Solve a scene and write the radiosity of every element as CSV (or JSON for *.json).
    Solve(SolveArgs),
    /// Print statistics of a scene: surfaces, elements, area, form-factor row sums,
    /// reciprocity, energy balance and stage times.
    Check(CheckArgs),
    /// Time the whole pipeline (parse, mesh, BVH, form factors, solve, shade, render) and
    /// print one Markdown table row per MAX_PATCH_AREA with the median time of each stage.
    Bench(BenchArgs),
    /// Solve a scene with one solver and with the dense reference (Gauss-Seidel on the
    /// form factors of --method and --steps; for a reference more accurate than the default
    /// area k = 2, use --method contour --steps 4) on the same mesh; print time, peak memory
    /// and the difference of element radiosity as a Markdown table row.
    Compare(CompareArgs),
    /// Open the walkthrough window and modeller on a solved scene (feature `viewer`).
    View(ViewArgs),
    /// Generate a scene file procedurally.
    Generate {
        #[command(subcommand)]
        what: GenerateCommand,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            errln!("{}", describe(&err));
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render_command(args),
        Command::Formfactors(args) => formfactors_command(args),
        Command::Solve(args) => solve_command(args),
        Command::Check(args) => check_command(args),
        Command::Bench(args) => bench_command(args),
        Command::Compare(args) => compare_command(args),
        Command::View(args) => view::view_command(args),
        Command::Generate {
            what: GenerateCommand::Building(args),
        } => generate_building(args),
    }
}

/// Form factors from the file given, or computed (with their statistics reported and
/// returned).
fn form_factors(
    prepared: &Prepared,
    file: Option<&Path>,
    reporter: &Reporter,
) -> Result<(FormFactorMatrix, Option<FormFactorStats>)> {
    if let Some(path) = file {
        let f = prepared.load_form_factors(path, reporter)?;
        reporter.note(&format!("form factors read from {}", path.display()));
        return Ok((f, None));
    }
    reporter.note(&format!(
        "form factors by {}; occlusion: {}",
        prepared.method(),
        prepared.method().occlusion()
    ));
    let (f, stats) = prepared.form_factors(reporter)?;
    note_form_factor_stats(prepared, &stats, reporter);
    Ok((f, Some(stats)))
}

/// Notes what computing the form factors found.
fn note_form_factor_stats(prepared: &Prepared, stats: &FormFactorStats, reporter: &Reporter) {
    reporter.note(&format!(
        "form factors ({}): {} visibility rays in {:.3} s ({:.1} M rays/s); row sums min {:.4} mean {:.4} max {:.4}; \
         reciprocity error {:.1e} largest, {:.1e} of exchanged power",
        prepared.method(),
        stats.rays,
        stats.seconds,
        stats.rays as f64 / stats.seconds.max(1e-9) / 1e6,
        stats.row_sums.min,
        stats.row_sums.mean,
        stats.row_sums.max,
        stats.reciprocity.max_relative,
        stats.reciprocity.total_relative
    ));
}

/// Solves with `solver`: the dense solvers on the form factors (read from `file` or
/// computed, then dropped), the others from the scene. Returns the form-factor statistics
/// when they were computed.
fn solve_scene(
    prepared: &Prepared,
    solver: Solver,
    file: Option<&Path>,
    observer: &mut Observer,
    reporter: &Reporter,
) -> Result<(Solution, Option<FormFactorStats>)> {
    let form_factors = match file {
        Some(path) => FormFactors::File(path),
        None => FormFactors::Compute,
    };
    if solver.needs_matrix() {
        match form_factors {
            FormFactors::File(path) => {
                reporter.note(&format!("form factors read from {}", path.display()))
            }
            _ => reporter.note(&format!(
                "form factors by {}; occlusion: {}",
                prepared.method(),
                prepared.method().occlusion()
            )),
        }
    }
    let request = SolveRequest {
        form_factors,
        ..SolveRequest::new(solver)
    };
    let solution = pipeline::solve(prepared, &request, observer, reporter)?;
    if let Some(stats) = &solution.form_factors {
        note_form_factor_stats(prepared, stats, reporter);
    }
    let stats = solution.form_factors;
    Ok((solution, stats))
}

fn render_command(args: RenderArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let settings = render_settings(&args)?;
    if args.snapshot_every == 0 {
        bail!("--snapshot-every must be at least 1");
    }
    let (prepared, stem, solver) = prepare(&args.scene, Some(&args.solve), &reporter)?;
    let solver = solver.expect("prepare resolves the solver it is given options for");
    if args.snapshots.is_some() && solver.needs_matrix() {
        bail!("--snapshots needs --solver progressive");
    }
    let camera = camera(&args, &prepared.scene)?;
    let exposure = args.exposure;
    if let Some(dir) = &args.snapshots {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
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
        let image = shade_and_render(
            &prepared,
            &prepared.mesh,
            radiosity::light::Rgb::as_arrays(&display),
            &camera,
            settings,
            exposure,
            &quiet,
        );
        let path = dir.join(format!("shot-{:05}.png", state.shot));
        match render::write_png(&image, &path) {
            Ok(()) => {
                written += 1;
                ControlFlow::Continue(())
            }
            Err(e) => {
                snapshot_error =
                    Some(anyhow::Error::new(e).context(format!("cannot write {}", path.display())));
                ControlFlow::Break(())
            }
        }
    };
    let (solution, _) = solve_scene(
        &prepared,
        solver,
        args.solve.form_factors.as_deref(),
        &mut observer,
        &reporter,
    )?;
    if let Some(e) = snapshot_error {
        return Err(e);
    }
    if let Some(dir) = &args.snapshots {
        reporter.note(&format!("wrote {written} snapshots to {}", dir.display()));
    }
    let image = shade_and_render(
        &prepared,
        &solution.mesh,
        solution.element_rgb(),
        &camera,
        settings,
        exposure,
        &reporter,
    );
    let output = args
        .output
        .unwrap_or_else(|| PathBuf::from(format!("{stem}.png")));
    run_stage(&reporter, Stage::Write, 0, || {
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
    Ok(())
}

/// Vertex radiosities (the shade stage), exposure, then the image (the render stage).
fn shade_and_render(
    prepared: &Prepared,
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    camera: &Camera,
    settings: RenderSettings,
    exposure: Exposure,
    reporter: &Reporter,
) -> RgbImage {
    let vertex_b = run_stage(reporter, Stage::Shade, 0, || {
        shade::vertex_radiosity(mesh, element_b)
    });
    let scale = exposure.scale(&prepared.scene, mesh, element_b);
    let settings = RenderSettings {
        exposure_scale: scale,
        ..settings
    };
    let renderer = Renderer::new(mesh);
    render::render(&renderer, camera, element_b, &vertex_b, &settings, reporter)
}

fn formfactors_command(args: FormFactorArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let (prepared, stem, _) = prepare(&args.scene, None, &reporter)?;
    let (f, _) = form_factors(&prepared, None, &reporter)?;
    let output = args
        .output
        .unwrap_or_else(|| PathBuf::from(format!("{stem}.ff")));
    prepared.save_form_factors(&output, &f, &reporter)?;
    reporter.note(&format!(
        "wrote {} ({} x {} form factors, method {})",
        output.display(),
        f.n(),
        f.n(),
        prepared.method()
    ));
    reporter.print_timings();
    Ok(())
}

fn solve_command(args: SolveArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let (prepared, stem, solver) = prepare(&args.scene, Some(&args.solve), &reporter)?;
    let solver = solver.expect("prepare resolves the solver it is given options for");
    let (solution, _) = solve_scene(
        &prepared,
        solver,
        args.solve.form_factors.as_deref(),
        &mut |_| ControlFlow::Continue(()),
        &reporter,
    )?;
    let output = args
        .output
        .unwrap_or_else(|| PathBuf::from(format!("{stem}.csv")));
    run_stage(&reporter, Stage::Write, 0, || {
        radiosity::solution::write_solution(
            &output,
            &prepared.scene,
            &solution.mesh,
            solution.element_rgb(),
        )
    })
    .with_context(|| format!("cannot write {}", output.display()))?;
    reporter.note(&format!(
        "wrote {} ({} elements)",
        output.display(),
        solution.mesh.len()
    ));
    reporter.print_timings();
    Ok(())
}

fn mib(bytes: Option<u64>, reset: bool) -> String {
    match bytes {
        Some(b) if reset => format!("{:.0}", b as f64 / (1024.0 * 1024.0)),
        Some(b) => format!("<= {:.0}", b as f64 / (1024.0 * 1024.0)),
        None => "?".into(),
    }
}

fn compare_command(args: CompareArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let (prepared, stem, solver) = prepare(&args.scene, Some(&args.solve), &reporter)?;
    let solver = solver.expect("prepare resolves the solver it is given options for");
    let reset = reset_peak_memory();
    let start = std::time::Instant::now();
    let (solution, _) = solve_scene(
        &prepared,
        solver,
        args.solve.form_factors.as_deref(),
        &mut |_| ControlFlow::Continue(()),
        &reporter,
    )?;
    let time = start.elapsed().as_secs_f64();
    let peak = peak_memory_bytes();
    let elements = solution.mesh.len();
    let mut reference = ("-".to_string(), "-".to_string(), "-".to_string());
    let mut difference = ("-".to_string(), "-".to_string(), "-".to_string());
    if !args.no_reference {
        let dense = Solver::DEFAULT_GAUSS_SEIDEL;
        match prepared.check_memory(Some(&dense)) {
            Err(e) => reporter.note(&format!(
                "no dense reference: {e}{}",
                hint(&e).unwrap_or_default()
            )),
            Ok(()) => {
                let reset = reset_peak_memory();
                let start = std::time::Instant::now();
                let exact = pipeline::solve(
                    &prepared,
                    &SolveRequest::new(dense),
                    &mut keep_going,
                    &reporter,
                )?;
                reference = (
                    format!("{:.2}", start.elapsed().as_secs_f64()),
                    mib(peak_memory_bytes(), reset),
                    String::new(),
                );
                let emission = prepared.light.emission();
                let c = radiosity::compare::compare(
                    &prepared.mesh,
                    &exact.radiosity,
                    &emission,
                    &solution.mesh,
                    &solution.radiosity,
                )?;
                difference = (
                    format!("{:.2}", 100.0 * c.rms),
                    format!("{:.1}", 100.0 * c.max),
                    format!("{:+.2}", 100.0 * c.bias),
                );
            }
        }
    }
    outln!("| scene | elements | solver | its elements | time (s) | peak (MiB) | dense reference | dense time (s) | dense peak (MiB) | RMS diff (%) | max diff (%) | mean diff (%) |");
    outln!("| --- | ---: | --- | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: |");
    outln!(
        "| {stem} | {} | {} | {elements} | {time:.2} | {} | {} | {} | {} | {} | {} | {} |",
        prepared.mesh.len(),
        solver.short_label(),
        mib(peak, reset),
        if args.no_reference {
            "-".to_string()
        } else {
            prepared.method().to_string()
        },
        reference.0,
        reference.1,
        difference.0,
        difference.1,
        difference.2
    );
    reporter.print_timings();
    Ok(())
}

/// Prints the accuracy table of `form_factor::accuracy` as Markdown.
fn compare_methods(max_area: f64) {
    use radiosity::form_factor::accuracy::{measure, standard_methods};
    outln!(
        "Elements of at most {max_area} (unit squares in {} elements); relative errors.",
        (1.0 / max_area).round()
    );
    outln!();
    outln!(
        "| method | opposed squares | perpendicular squares | coaxial discs | element to rectangle | mean | closed box max abs(row sum - 1) | reciprocity | time (ms) | mean error x time |"
    );
    outln!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for method in standard_methods() {
        let r = measure(method, max_area);
        outln!(
            "| {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.1} | {:.2e} |",
            r.method,
            r.opposed,
            r.perpendicular,
            r.discs,
            r.differential,
            r.mean_error(),
            r.closed_box,
            r.reciprocity,
            r.seconds * 1e3,
            r.mean_error() * r.seconds
        );
    }
}

fn generate_building(args: BuildingArgs) -> Result<()> {
    let params = scene::BuildingParams {
        floors: args.floors,
        rooms_x: args.rooms_x,
        rooms_z: args.rooms_z,
        room_size: args.room_size,
        height: args.height,
        furniture: !args.no_furniture,
        seed: args.seed,
        max_patch_area: args.max_area,
        integral_steps: args.steps,
        light: args.light,
    };
    if let Err(e) = params.check() {
        bail!("{e}");
    }
    let built = scene::building(&params);
    scene::write_scene_file(&built, &args.output)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    // The element count, also where meshing would refuse it (more than MAX_ELEMENTS).
    let elements = match radiosity::mesh::mesh_scene(&built, params.max_patch_area) {
        Ok(mesh) => format!("{} elements", mesh.len()),
        Err(radiosity::mesh::MeshError::TooManyElements { count, limit, .. }) => {
            format!("{count} elements (more than the meshing limit of {limit})")
        }
        Err(e) => return Err(e.into()),
    };
    let (lo, hi) = built.bounds();
    let size = hi - lo;
    outln!(
        "{}: {} rooms, {} surfaces, {:.0} m^2, {:.1} x {:.1} x {:.1} m; MAX_PATCH_AREA {}: {}",
        args.output.display(),
        params.floors * params.rooms_x * params.rooms_z,
        built.surfaces.len(),
        built.total_area(),
        size.x,
        size.y,
        size.z,
        params.max_patch_area,
        elements
    );
    Ok(())
}

fn check_command(args: CheckArgs) -> Result<()> {
    if args.compare_methods {
        compare_methods(args.scene.max_area.unwrap_or(1.0 / 64.0));
        return Ok(());
    }
    // `check` always prints its report; --quiet only silences the progress bars.
    let reporter = Reporter::new(true);
    let (prepared, stem, solver) = prepare(&args.scene, Some(&args.solve), &reporter)?;
    let solver = solver.expect("prepare resolves the solver it is given options for");
    let (solution, stats) = if solver.needs_matrix() {
        let (f, stats) = match args.solve.form_factors.as_deref() {
            Some(path) => {
                let f = prepared.load_form_factors(path, &reporter)?;
                let stats = radiosity::pipeline::FormFactorStats {
                    rays: 0,
                    seconds: 0.0,
                    row_sums: f.row_sums(),
                    reciprocity: f.reciprocity(&prepared.areas()),
                };
                (f, stats)
            }
            None => prepared.form_factors(&reporter)?,
        };
        let request = SolveRequest {
            form_factors: FormFactors::Matrix(&f),
            ..SolveRequest::new(solver)
        };
        let solution = pipeline::solve(&prepared, &request, &mut keep_going, &reporter)?;
        (solution, Some(stats))
    } else {
        // Progressive refinement never holds the matrix: no row sums or reciprocity.
        solve_scene(&prepared, solver, None, &mut keep_going, &reporter)?
    };
    let scene = &prepared.scene;
    outln!("scene             {stem}");
    outln!("surfaces          {}", scene.surfaces.len());
    outln!("elements          {}", solution.mesh.len());
    outln!("total area        {:.6}", solution.mesh.total_area());
    outln!("MAX_PATCH_AREA    {}", scene.settings.max_patch_area);
    outln!("INTEGRAL_STEPS    {}", scene.settings.integral_steps);
    outln!("method            {}", prepared.method());
    outln!("occlusion         {}", prepared.method().occlusion());
    outln!("solver            {solver}");
    if let Some(stats) = &stats {
        outln!(
            "row sums          min {:.6}  mean {:.6}  max {:.6}",
            stats.row_sums.min,
            stats.row_sums.mean,
            stats.row_sums.max
        );
        outln!(
            "reciprocity error {:.3e} largest |A_i F_ij - A_j F_ji| / max; {:.3e} of all exchanged power",
            stats.reciprocity.max_relative, stats.reciprocity.total_relative
        );
        if stats.rays > 0 {
            outln!(
                "visibility rays   {} ({:.1} M rays/s)",
                stats.rays,
                stats.rays as f64 / stats.seconds.max(1e-9) / 1e6
            );
        }
    }
    match &solution.report {
        SolutionReport::Matrix(report) => {
            let r = report.residual;
            outln!(
                "solve residual    {:.1e} / {:.1e} / {:.1e} (relative, R / G / B)",
                r[0],
                r[1],
                r[2]
            );
        }
        SolutionReport::Hierarchical(report) => {
            outln!(
                "hierarchical      {} leaves, {} clusters, {} links ({} before the first solve), about {:.0} MiB, {} rounds, {} sweeps (changing power {:.1e} of emitted), {} rays, {:.3} s",
                report.leaves,
                report.clusters,
                report.links,
                report.initial_links,
                report.memory_bytes as f64 / (1024.0 * 1024.0),
                report.rounds,
                report.iterations,
                report.residual,
                report.rays,
                report.elapsed.as_secs_f64()
            );
        }
        SolutionReport::Progressive(report) => {
            outln!(
                "progressive       {} shots; unshot power {:.2e} of emitted; ambient {:.3e} / {:.3e} / {:.3e}",
                report.shots,
                report.unshot_fraction,
                report.ambient[0],
                report.ambient[1],
                report.ambient[2]
            );
        }
    }
    let b = &solution.balance;
    outln!(
        "energy (R)        emitted {:.6e} = absorbed {:.6e} + escaped {:.6e} (relative error {:.1e})",
        b.emitted[0],
        b.absorbed[0],
        b.escaped[0],
        b.relative_error()
    );
    if let SolutionReport::Progressive(_) = solution.report {
        outln!(
            "                  (progressive: the unshot power is neither absorbed nor escaped yet)"
        );
    }
    outln!("stage times:");
    for (stage, d) in reporter.timings() {
        outln!("  {:<14}{}", stage.name(), format_duration(d));
    }
    Ok(())
}

/// One timed run of the whole pipeline.
struct BenchRun {
    elements: usize,
    steps: u32,
    /// Seconds per stage, in the order of [`BENCH_STAGES`].
    stages: [f64; BENCH_STAGES.len()],
    /// Wall-clock seconds from before parsing to the rendered image.
    total: f64,
    rays: u64,
}

/// The stages a bench run reports, in pipeline order.
const BENCH_STAGES: [Stage; 7] = [
    Stage::Parse,
    Stage::Mesh,
    Stage::Bvh,
    Stage::FormFactors,
    Stage::Solve,
    Stage::Shade,
    Stage::Render,
];

fn bench_run(args: &BenchArgs, max_area: Option<f64>) -> Result<BenchRun> {
    let scene_args = SceneArgs {
        scene: args.scene.clone(),
        max_area,
        steps: args.steps,
        method: args.method.clone(),
        quiet: true,
    };
    let options = SolveOptions {
        solver: args.solver,
        tolerance: args.tolerance,
        max_shots: 1_000_000,
        form_factors: None,
        epsilon: args.epsilon,
        min_area: args.min_area,
    };
    let settings = RenderSettings {
        supersample: args.supersample,
        ..RenderSettings::default()
    };
    let reporter = Reporter::new(true);
    let start = std::time::Instant::now();
    let (prepared, _, solver) = prepare(&scene_args, Some(&options), &reporter)?;
    let solver = solver.expect("prepare resolves the solver it is given options for");
    let (solution, stats) = solve_scene(&prepared, solver, None, &mut keep_going, &reporter)?;
    let rays = match (&stats, &solution.report) {
        (Some(s), _) => s.rays,
        (None, SolutionReport::Progressive(r)) => r.rays,
        (None, SolutionReport::Hierarchical(r)) => r.rays,
        (None, _) => 0,
    };
    let camera = Camera::for_scene(&prepared.scene, args.size, args.size);
    let image = shade_and_render(
        &prepared,
        &solution.mesh,
        solution.element_rgb(),
        &camera,
        settings,
        Exposure::Brightest,
        &reporter,
    );
    let total = start.elapsed().as_secs_f64();
    std::hint::black_box(image);
    let mut stages = [0.0; BENCH_STAGES.len()];
    for (stage, d) in reporter.timings() {
        if let Some(k) = BENCH_STAGES.iter().position(|s| *s == stage) {
            stages[k] += d.as_secs_f64();
        }
    }
    Ok(BenchRun {
        elements: solution.mesh.len(),
        steps: prepared.scene.settings.integral_steps,
        stages,
        total,
        rays,
    })
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// Milliseconds with three significant digits or so.
fn ms(seconds: f64) -> String {
    let ms = seconds * 1e3;
    if ms >= 100.0 {
        format!("{ms:.0}")
    } else if ms >= 10.0 {
        format!("{ms:.1}")
    } else {
        format!("{ms:.2}")
    }
}

fn bench_command(args: BenchArgs) -> Result<()> {
    if args.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    if args.size == 0 || args.size > 10_000 {
        bail!("--size must be between 1 and 10000");
    }
    if args.supersample == 0 || args.supersample > 16 {
        bail!("--supersample must be between 1 and 16");
    }
    if let Some(&a) = args.max_area.iter().find(|a| !(**a > 0.0 && a.is_finite())) {
        bail!("--max-area must be a positive number, got {a}");
    }
    let name = args
        .scene
        .as_deref()
        .and_then(Path::file_name)
        .map_or("cornell (built in)".to_string(), |s| {
            s.to_string_lossy().into_owned()
        });
    let areas: Vec<Option<f64>> = if args.max_area.is_empty() {
        vec![None]
    } else {
        args.max_area.iter().copied().map(Some).collect()
    };
    let solver_name = match args.solver.0 {
        SolverKind::Auto => {
            "auto (dense Gauss-Seidel up to 20,000 elements when it fits, else progressive)"
        }
        SolverKind::Lu => "LU",
        SolverKind::GaussSeidel => "Gauss-Seidel",
        SolverKind::Progressive => "progressive (form factors computed within the solve)",
        SolverKind::Hierarchical => "hierarchical (links computed within the solve)",
    };
    errln!(
        "median of {} runs; times in ms; render {1}x{1} at {2}x{2} supersampling; solver {solver_name}",
        args.repeat, args.size, args.supersample
    );
    outln!(
        "| scene | max area | elements | k | parse | mesh | bvh | form factors | solve | shade | render | other | end to end | end to end less render | visibility rays | rays/s |"
    );
    outln!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for max_area in areas {
        let runs = (0..args.repeat)
            .map(|_| bench_run(&args, max_area))
            .collect::<Result<Vec<_>>>()?;
        let first = &runs[0];
        if runs.iter().any(|r| r.rays != first.rays) {
            errln!("note: the ray count differed between runs");
        }
        let stage = |k: usize| median(runs.iter().map(|r| r.stages[k]).collect());
        let total = median(runs.iter().map(|r| r.total).collect());
        let other = median(
            runs.iter()
                .map(|r| r.total - r.stages.iter().sum::<f64>())
                .collect(),
        );
        let no_render = median(
            runs.iter()
                .map(|r| r.total - r.stages[BENCH_STAGES.len() - 1])
                .collect(),
        );
        let ff = stage(3);
        let area = max_area.map_or("scene's".to_string(), |a| a.to_string());
        let stages: Vec<String> = (0..BENCH_STAGES.len()).map(|k| ms(stage(k))).collect();
        outln!(
            "| {name} | {area} | {} | {} | {} | {} | {} | {} | {} | {:.2} M |",
            first.elements,
            first.steps,
            stages.join(" | "),
            ms(other),
            ms(total),
            ms(no_render),
            first.rays,
            first.rays as f64 / ff.max(1e-9) / 1e6,
        );
    }
    Ok(())
}
