//! `radiosity`: the command-line program. A thin layer over the `radiosity` library:
//! parse the arguments, run the pipeline, report progress and timings.

#[macro_use]
mod macros;

mod errors;
mod peak_memory;
mod progress_bar;
mod view;

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::DVec3;
use image::RgbImage;
use radiosity::form_factor::{FormFactorMatrix, FormFactorMethod};
use radiosity::mesh::Mesh;
use radiosity::pipeline::{
    self as pipeline, FormFactorStats, FormFactors, Overrides, Prepared, Solution, SolutionReport,
    SolveRequest,
};
use radiosity::progress::{run_stage, Stage};
use radiosity::render::{self, Camera, RenderSettings, Renderer, Shading};
use radiosity::scene::{self, Scene};
use radiosity::shade::{self, Exposure};
use radiosity::solve::{
    keep_going, GaussSeidelSettings, Observer, ProgressiveSettings, Solver, SolverKind, Step,
};

use errors::{describe, hint};
use peak_memory::{peak_memory_bytes, reset_peak_memory};
use progress_bar::{format_duration, Reporter};

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
    View(view::ViewArgs),
    /// Generate a scene file procedurally.
    Generate {
        #[command(subcommand)]
        what: GenerateCommand,
    },
}

#[derive(Subcommand)]
enum GenerateCommand {
    /// A building: a grid of furnished rooms on one or more floors, joined by doors, lit by
    /// a ceiling panel per room and daylight in every exterior window (metres).
    Building(BuildingArgs),
}

#[derive(Args)]
struct BuildingArgs {
    /// Output scene file.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Storeys.
    #[arg(long, default_value_t = 2, value_name = "N")]
    floors: u32,
    /// Rooms along x on each floor.
    #[arg(long, default_value_t = 6, value_name = "N")]
    rooms_x: u32,
    /// Rooms along z on each floor.
    #[arg(long, default_value_t = 6, value_name = "N")]
    rooms_z: u32,
    /// Inner side of each square room (m; at least 5.7 with furniture).
    #[arg(long, default_value_t = 6.0, value_name = "M")]
    room_size: f64,
    /// Floor-to-ceiling height (m).
    #[arg(long, default_value_t = 2.7, value_name = "M")]
    height: f64,
    /// Empty rooms.
    #[arg(long)]
    no_furniture: bool,
    /// Seed of door positions, window widths, furniture placement and colours.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The scene's MAX_PATCH_AREA (m^2): 1 gives about 40,000 elements for the default
    /// building, 0.0125 about a million.
    #[arg(long, default_value_t = 1.0, value_name = "AREA")]
    max_area: f64,
    /// The scene's INTEGRAL_STEPS.
    #[arg(long, default_value_t = 2, value_name = "K")]
    steps: u32,
    /// Exitance of the ceiling panels (W/m^2); windows emit 0.6 of it, bluish.
    #[arg(long, default_value_t = 20.0, value_name = "E")]
    light: f64,
}

/// Options every command shares.
#[derive(Args)]
struct SceneArgs {
    /// Scene file (Appendix A format); the built-in Cornell box when omitted.
    scene: Option<PathBuf>,
    /// Override the scene's MAX_PATCH_AREA (scene units squared).
    #[arg(long, value_name = "AREA")]
    max_area: Option<f64>,
    /// Override the scene's INTEGRAL_STEPS (points along each axis of each element, for
    /// the area method).
    #[arg(long, value_name = "K")]
    steps: Option<u32>,
    #[command(flatten)]
    method: MethodArgs,
    /// No progress bars, timings or notes (errors are still printed).
    #[arg(short, long)]
    quiet: bool,
}

/// How form factors are computed.
#[derive(Args, Clone)]
struct MethodArgs {
    /// Form-factor method.
    #[arg(long, value_enum, default_value_t = MethodArg::Area)]
    method: MethodArg,
    /// Hemicube resolution: cells across the top face.
    #[arg(long, default_value_t = 128, value_name = "CELLS")]
    resolution: u32,
    /// Monte Carlo rays per element.
    #[arg(long, default_value_t = 1024, value_name = "N")]
    samples: u32,
    /// Monte Carlo generator seed (the same seed gives the same numbers).
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// Options of commands that solve.
#[derive(Args)]
struct SolveOptions {
    /// Solver for (I - rho F) B = E.
    #[arg(long, value_enum, default_value_t = SolverArg(SolverKind::Auto))]
    solver: SolverArg,
    /// Where the solver stops. Gauss-Seidel: the relative residual (default 1e-9).
    /// Progressive: the unshot power as a fraction of the emitted power, in every band (the
    /// convergence value of Cohen et al. 1988; default 0.01 = 1 %).
    #[arg(long, value_name = "TOL")]
    tolerance: Option<f64>,
    /// Hierarchical: the BF refinement threshold, relative to the mean radiosity (smaller is
    /// finer and slower).
    #[arg(long, default_value_t = 0.05, value_name = "E")]
    epsilon: f64,
    /// Hierarchical: nodes of at most this area (scene units squared) are not split
    /// (default: MAX_PATCH_AREA / 16).
    #[arg(long, value_name = "AREA")]
    min_area: Option<f64>,
    /// Progressive: give up after this many shots.
    #[arg(long, default_value_t = 1_000_000, value_name = "N")]
    max_shots: usize,
    /// Read form factors from this file (written by `radiosity formfactors`) instead of
    /// computing them; refused if it was made for another mesh or method.
    #[arg(long, value_name = "FILE")]
    form_factors: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum MethodArg {
    /// The paper's double area integral, INTEGRAL_STEPS^2 points per element, a ray per
    /// point pair for occlusion.
    Area,
    /// Exact element-to-element form factors (the double contour integral); pairs that an
    /// occluder may block are scaled by the visible fraction of INTEGRAL_STEPS^2 point pairs.
    Contour,
    /// Lambert's exact point-to-polygon form factor at INTEGRAL_STEPS^2 receiver points,
    /// with rays to the source's points for occlusion.
    Analytic,
    /// Hemicube (Cohen and Greenberg 1985) rasterised on the CPU, --resolution; occlusion
    /// by depth buffer.
    Hemicube,
    /// Stratified Monte Carlo ray casting, --samples rays per element, --seed; occlusion by
    /// each ray's first hit.
    Montecarlo,
}

/// `--solver`: the library's [`SolverKind`], its names and help as the library gives them.
#[derive(Clone, Copy)]
struct SolverArg(SolverKind);

impl ValueEnum for SolverArg {
    fn value_variants<'a>() -> &'a [Self] {
        const ALL: [SolverArg; 5] = [
            SolverArg(SolverKind::ALL[0]),
            SolverArg(SolverKind::ALL[1]),
            SolverArg(SolverKind::ALL[2]),
            SolverArg(SolverKind::ALL[3]),
            SolverArg(SolverKind::ALL[4]),
        ];
        &ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()).help(self.0.help()))
    }
}

impl std::fmt::Display for SolverArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum ShadingArg {
    /// Vertex radiosities interpolated across elements (paper plate 2).
    Smooth,
    /// One colour per element (paper plate 1).
    Flat,
    /// Element edges (paper plate 4).
    Wireframe,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    solve: SolveOptions,
    /// Output PNG (default: cornell.png for the built-in box, else the scene's name).
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// Shading.
    #[arg(long, value_enum, default_value_t = ShadingArg::Smooth)]
    shading: ShadingArg,
    /// Gamma: displayed = value^(1/gamma) (paper 2.7).
    #[arg(long, default_value_t = 2.2)]
    gamma: f64,
    /// Exposure: "auto" scales the brightest non-emitting element to white (the paper's
    /// normalisation), a number multiplies radiosities by it.
    #[arg(long, default_value = "auto")]
    exposure: String,
    /// Eye position "x,y,z" (default: the scene's camera, or one that frames the scene).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    eye: Option<String>,
    /// Point looked at "x,y,z".
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    look_at: Option<String>,
    /// Up direction "x,y,z".
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    up: Option<String>,
    /// Vertical field of view in degrees.
    #[arg(long, value_name = "DEGREES", allow_hyphen_values = true)]
    fov: Option<f64>,
    /// Image width in pixels.
    #[arg(long, default_value_t = 512)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 512)]
    height: u32,
    /// Rays per pixel along each axis: 2 or more antialiases edges (N^2 times the rays).
    #[arg(long, default_value_t = 1, value_name = "N")]
    supersample: u32,
    /// Progressive: write the picture as it converges to DIR/shot-00010.png and so on, every
    /// --snapshot-every shots (with the ambient term added for display).
    #[arg(long, value_name = "DIR")]
    snapshots: Option<PathBuf>,
    /// Progressive: shots between snapshots.
    #[arg(long, default_value_t = 10, value_name = "N")]
    snapshot_every: usize,
}

#[derive(Args)]
struct FormFactorArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output file (default: the scene's name with .ff).
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
}

#[derive(Args)]
struct SolveArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    solve: SolveOptions,
    /// Output file: CSV, or JSON when it ends in .json (default: the scene's name with .csv).
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
}

#[derive(Args)]
struct CheckArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    solve: SolveOptions,
    /// Instead of checking a scene, print the accuracy table: every form-factor method
    /// against closed forms (opposed and perpendicular squares, coaxial discs, a small
    /// element under a rectangle), its row-sum error in a closed box, its reciprocity
    /// error and its time, as Markdown.
    #[arg(long)]
    compare_methods: bool,
}

#[derive(Args)]
struct CompareArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    solve: SolveOptions,
    /// Only time the solver (no dense reference).
    #[arg(long)]
    no_reference: bool,
}

#[derive(Args)]
struct BenchArgs {
    /// Scene file (Appendix A format); the built-in Cornell box when omitted.
    scene: Option<PathBuf>,
    #[command(flatten)]
    method: MethodArgs,
    /// MAX_PATCH_AREA values to time, one table row each (repeat the option or give several
    /// values); the scene's own when omitted.
    #[arg(long, value_name = "AREA", num_args = 1..)]
    max_area: Vec<f64>,
    /// Override the scene's INTEGRAL_STEPS.
    #[arg(long, value_name = "K")]
    steps: Option<u32>,
    /// Runs per configuration; the table shows the median of each column.
    #[arg(long, default_value_t = 5, value_name = "N")]
    repeat: usize,
    /// Solver for (I - rho F) B = E.
    #[arg(long, value_enum, default_value_t = SolverArg(SolverKind::Auto))]
    solver: SolverArg,
    /// Where the solver stops (as for `render --tolerance`: 1e-9 residual for Gauss-Seidel,
    /// 0.01 unshot for progressive).
    #[arg(long, value_name = "TOL")]
    tolerance: Option<f64>,
    /// Image width and height in pixels.
    #[arg(long, default_value_t = 512, value_name = "PIXELS")]
    size: u32,
    /// Rays per pixel along each axis (as `render --supersample`).
    #[arg(long, default_value_t = 1, value_name = "N")]
    supersample: u32,
    /// Hierarchical: the BF refinement threshold (as for `render --epsilon`).
    #[arg(long, default_value_t = 0.05, value_name = "E")]
    epsilon: f64,
    /// Hierarchical: the minimum node area (as for `render --min-area`).
    #[arg(long, value_name = "AREA")]
    min_area: Option<f64>,
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

/// The scene (from its file or built in), meshed, with a short name for default outputs.
/// Refuses, before any work, a problem whose matrices would not fit in memory (for
/// `solver`, or the form factors alone when `None`).
fn prepare(
    args: &SceneArgs,
    options: Option<&SolveOptions>,
    reporter: &Reporter,
) -> Result<(Prepared, String, Option<Solver>)> {
    let (scene, stem) = load_scene(args.scene.as_deref(), reporter)?;
    let overrides = Overrides {
        max_patch_area: args.max_area,
        integral_steps: args.steps,
    };
    if let Some(k) = args.steps {
        if k == 0 {
            bail!("--steps must be at least 1");
        }
    }
    let mut prepared = Prepared::new(scene, overrides, reporter)?;
    let m = &args.method;
    let steps = prepared.scene.settings.integral_steps;
    prepared.method = match m.method {
        MethodArg::Area => FormFactorMethod::AreaIntegral { steps },
        MethodArg::Contour => FormFactorMethod::Contour { steps },
        MethodArg::Analytic => FormFactorMethod::Analytic { steps },
        MethodArg::Hemicube => {
            if m.resolution < 2 || m.resolution > 16_384 {
                bail!(
                    "--resolution must be between 2 and 16384, got {}",
                    m.resolution
                );
            }
            FormFactorMethod::Hemicube {
                resolution: m.resolution,
            }
        }
        MethodArg::Montecarlo => {
            if m.samples == 0 {
                bail!("--samples must be at least 1");
            }
            FormFactorMethod::MonteCarlo {
                samples: m.samples,
                seed: m.seed,
            }
        }
    };
    let solver = match options {
        Some(options) => Some(solver(
            options,
            prepared.mesh.len(),
            prepared.scene.settings.max_patch_area,
            reporter,
        )?),
        None => None,
    };
    prepared.check_memory(solver.as_ref())?;
    reporter.note(&format!(
        "{}: {} surfaces, {} elements (MAX_PATCH_AREA {}, INTEGRAL_STEPS {})",
        stem,
        prepared.scene.surfaces.len(),
        prepared.mesh.len(),
        prepared.scene.settings.max_patch_area,
        prepared.scene.settings.integral_steps
    ));
    Ok((prepared, stem, solver))
}

fn load_scene(path: Option<&Path>, reporter: &Reporter) -> Result<(Scene, String)> {
    match path {
        None => Ok((
            run_stage(reporter, Stage::Parse, 0, scene::cornell_box),
            "cornell".to_string(),
        )),
        Some(path) => {
            let scene = run_stage(reporter, Stage::Parse, 0, || scene::read_scene(path))?;
            let stem = path
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
            Ok((scene, stem))
        }
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

/// The solver the options ask for; `auto` is decided from the element count `n` and the
/// memory available, and the choice and its reason are noted.
fn solver(
    options: &SolveOptions,
    n: usize,
    max_patch_area: f64,
    reporter: &Reporter,
) -> Result<Solver> {
    if let Some(t) = options.tolerance {
        if !(t > 0.0 && t.is_finite()) {
            bail!("--tolerance must be a positive number, got {t}");
        }
    }
    let choice = match options.solver.0 {
        SolverKind::Auto if options.form_factors.is_some() => SolverKind::GaussSeidel,
        SolverKind::Auto => {
            let choice =
                radiosity::solve::choose(n, radiosity::form_factor::available_memory_bytes());
            reporter.note(&format!("solver auto: {choice}"));
            choice.kind()
        }
        other => other,
    };
    Ok(match choice {
        SolverKind::Auto => unreachable!("auto is resolved above"),
        SolverKind::Lu => Solver::LU,
        SolverKind::GaussSeidel => Solver::Dense(radiosity::solve::DenseSolver::GaussSeidel(
            GaussSeidelSettings {
                tolerance: options.tolerance.unwrap_or(1e-9),
                ..GaussSeidelSettings::default()
            },
        )),
        SolverKind::Progressive => {
            if options.form_factors.is_some() {
                bail!("--form-factors cannot be used with --solver progressive, which computes its rows as it shoots");
            }
            if options.max_shots == 0 {
                bail!("--max-shots must be at least 1");
            }
            Solver::Progressive(ProgressiveSettings {
                tolerance: options
                    .tolerance
                    .unwrap_or(radiosity::solve::DEFAULT_PROGRESSIVE_TOLERANCE),
                max_shots: options.max_shots,
            })
        }
        SolverKind::Hierarchical => {
            if options.form_factors.is_some() {
                bail!("--form-factors cannot be used with --solver hierarchical, which uses links, not a matrix");
            }
            let min_area = options.min_area.unwrap_or(max_patch_area / 16.0);
            if !(options.epsilon > 0.0 && options.epsilon.is_finite()) {
                bail!(
                    "--epsilon must be a positive number, got {}",
                    options.epsilon
                );
            }
            if !(min_area > 0.0 && min_area.is_finite()) {
                bail!("--min-area must be a positive number, got {min_area}");
            }
            let tolerance = options
                .tolerance
                .unwrap_or(radiosity::solve::DEFAULT_HIERARCHICAL_TOLERANCE);
            if !(tolerance > 0.0 && tolerance < 1.0) {
                bail!("--tolerance must be a number in (0, 1) for --solver hierarchical, got {tolerance}");
            }
            Solver::Hierarchical(radiosity::solve::HierarchicalSettings {
                epsilon: options.epsilon,
                min_area,
                tolerance,
                max_memory_bytes: None,
            })
        }
    })
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
    let exposure = parse_exposure(&args.exposure)?;
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

fn render_settings(args: &RenderArgs) -> Result<RenderSettings> {
    if let Some(out) = &args.output {
        let png = out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !png {
            bail!(
                "{}: only PNG images are written; give the output a .png name",
                out.display()
            );
        }
    }
    if args.width == 0 || args.height == 0 {
        bail!("--width and --height must be at least 1");
    }
    if (args.width as u64) * (args.height as u64) > 100_000_000 {
        bail!(
            "an image of {} x {} pixels is too large (at most 100 megapixels)",
            args.width,
            args.height
        );
    }
    if !(args.gamma > 0.0 && args.gamma.is_finite()) {
        bail!("--gamma must be a positive number, got {}", args.gamma);
    }
    if args.supersample == 0 || args.supersample > 16 {
        bail!("--supersample must be between 1 and 16");
    }
    let shading = match args.shading {
        ShadingArg::Smooth => Shading::Smooth,
        ShadingArg::Flat => Shading::Flat,
        ShadingArg::Wireframe => Shading::Wireframe,
    };
    Ok(RenderSettings {
        shading,
        gamma: args.gamma,
        supersample: args.supersample,
        ..RenderSettings::default()
    })
}

fn parse_exposure(text: &str) -> Result<Exposure> {
    if text.eq_ignore_ascii_case("auto") {
        return Ok(Exposure::Brightest);
    }
    match text.parse::<f64>() {
        Ok(s) if s > 0.0 && s.is_finite() => Ok(Exposure::Fixed(s)),
        _ => bail!("--exposure must be \"auto\" or a positive number, got \"{text}\""),
    }
}

fn parse_vec3(name: &str, text: &str) -> Result<DVec3> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let values: Vec<f64> = parts
        .iter()
        .filter_map(|p| p.parse::<f64>().ok())
        .filter(|v| v.is_finite())
        .collect();
    if parts.len() != 3 || values.len() != 3 {
        bail!("--{name} expects three numbers \"x,y,z\", got \"{text}\"");
    }
    Ok(DVec3::new(values[0], values[1], values[2]))
}

fn camera(args: &RenderArgs, scene: &Scene) -> Result<Camera> {
    let mut camera = Camera::for_scene(scene, args.width, args.height);
    if let Some(eye) = &args.eye {
        camera.eye = parse_vec3("eye", eye)?;
    }
    if let Some(at) = &args.look_at {
        camera.look_at = parse_vec3("look-at", at)?;
    }
    if let Some(up) = &args.up {
        camera.up = parse_vec3("up", up)?;
    }
    if let Some(fov) = args.fov {
        if !(fov > 0.0 && fov < 180.0) {
            bail!("--fov must be between 0 and 180 degrees, got {fov}");
        }
        camera.fov_y_degrees = fov;
    }
    let forward = camera.look_at - camera.eye;
    if forward.length() == 0.0 {
        bail!("--eye and --look-at must differ");
    }
    if forward.cross(camera.up).length() <= 1e-12 * forward.length() * camera.up.length() {
        bail!("--up must not be parallel to the viewing direction (or zero)");
    }
    Ok(camera)
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
