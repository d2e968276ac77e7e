//! `radiosity bench`: time every stage of the whole pipeline, the median of several runs.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use radiosity::pipeline::SolutionReport;
use radiosity::progress::Stage;
use radiosity::render::{Camera, RenderSettings};
use radiosity::shade::Exposure;
use radiosity::solve::keep_going;

use super::{bench_time, shade_and_render, solve_scene};
use crate::args::{BenchArgs, SceneArgs, SolveOptions};
use crate::progress_bar::{Reporter, LINE_EVERY};
use crate::report::{self, BenchRow};
use crate::setup::prepare_solve;

pub fn run(args: BenchArgs) -> Result<()> {
    let areas: Vec<Option<f64>> = if args.max_area.is_empty() {
        vec![None]
    } else {
        args.max_area.iter().copied().map(Some).collect()
    };
    // Every flag and every configuration checked before the header, so that a mistake or
    // work past the limits is refused before any time is spent on the runs before it (QA
    // of issue #16): each area's scene is read and meshed once, quietly, as a run would.
    let (width, height) = image_size(&args);
    crate::setup::image_size(width, height)?;
    radiosity::budget::check_render_memory(
        width,
        height,
        args.rays.supersample,
        false,
        radiosity::form_factor::available_memory_bytes(),
    )?;
    if !args.no_work_limit {
        radiosity::budget::check_render_work(width, height, args.rays.supersample)?;
    }
    // Said once here (its warnings too), not once per run.
    let settings = crate::setup::ray_settings(&args.rays, crate::args::ShadingArg::Smooth);
    for (k, &max_area) in areas.iter().enumerate() {
        let (scene_args, options) = run_settings(&args, max_area);
        crate::setup::check_scene_flags(&scene_args)?;
        crate::setup::check_solve_flags(&options)?;
        // The first says that hierarchical radiosity ignores --method, once (QA of issue
        // #16: nothing said it); the others and the runs below do not repeat it.
        if k == 0 {
            prepare_solve(&scene_args, &options, &Reporter::new(true))?;
        } else {
            crate::setup::prepare_solve_with_reference(
                &scene_args,
                &options,
                &Reporter::new(true),
            )?;
        }
    }
    let name = args
        .scene
        .as_deref()
        .and_then(Path::file_name)
        .map_or("cornell (built in)".to_string(), |s| {
            s.to_string_lossy().into_owned()
        });
    // Flags the method does not use, said once here, not once per run.
    crate::setup::warn_ignored_method_flags(&args.method, args.steps.is_some());
    report::bench_header(
        args.repeat as usize,
        image_size(&args),
        &settings,
        args.solver.0,
        args.quiet,
    );
    for max_area in areas {
        let runs = repeat_runs(&args, max_area, settings)?;
        let first = &runs[0];
        if !args.quiet && runs.iter().any(|r| r.rays != first.rays) {
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
        let row = BenchRow {
            elements: first.elements,
            method: first.method.clone(),
            stages: (0..BENCH_STAGES.len()).map(stage).collect(),
            form_factors: stage(3),
            solve: stage(4),
            other,
            total,
            no_render,
            rays: first.rays,
        };
        report::bench_row(&name, max_area, &row);
    }
    Ok(())
}

/// The `--repeat` runs of one configuration, refused after the first when the rest would
/// take longer than [`bench_time::MAX_BENCH_SECONDS`] (unless `--no-work-limit`), with a
/// progress bar on a terminal or a line every [`LINE_EVERY`] elsewhere unless `--quiet`
/// (QA pass 16 of #16: `--repeat 1000000` started some 100 hours of runs, silent).
fn repeat_runs(
    args: &BenchArgs,
    max_area: Option<f64>,
    settings: RenderSettings,
) -> Result<Vec<BenchRun>> {
    let start = Instant::now();
    let first = bench_run(args, max_area, settings)?;
    if !args.no_work_limit {
        bench_time::check_repeat_time(start.elapsed(), args.repeat).map_err(anyhow::Error::msg)?;
    }
    let terminal = std::io::stderr().is_terminal();
    let bar = (!args.quiet && terminal && args.repeat > 1).then(|| {
        let bar =
            ProgressBar::with_draw_target(Some(args.repeat as u64), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>13} [{bar:40}] {percent:>3}% ({pos} of {len} runs) \
                 {elapsed_precise} eta {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar.set_prefix("bench");
        bar.set_position(1);
        bar
    });
    let mut last_line = Instant::now();
    let mut runs = vec![first];
    while runs.len() < args.repeat as usize {
        runs.push(bench_run(args, max_area, settings)?);
        if let Some(bar) = &bar {
            bar.inc(1);
        } else if !args.quiet && last_line.elapsed() >= LINE_EVERY {
            last_line = Instant::now();
            errln!(
                "{}",
                bench_time::repeat_progress_line(runs.len() as u32, args.repeat, start.elapsed())
            );
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    Ok(runs)
}

/// One timed run of the whole pipeline.
struct BenchRun {
    elements: usize,
    method: String,
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

/// The scene and solver options of one configuration's runs.
fn run_settings(args: &BenchArgs, max_area: Option<f64>) -> (SceneArgs, SolveOptions) {
    let scene_args = SceneArgs {
        scene: args.scene.clone(),
        scale: args.scale,
        max_area,
        // Hemicube and Monte Carlo take no INTEGRAL_STEPS (warned about above).
        steps: match args.method.method {
            Some(crate::args::MethodArg::Hemicube | crate::args::MethodArg::Montecarlo) => None,
            _ => args.steps,
        },
        method: args.method.without_unused(),
        quiet: true,
        no_work_limit: args.no_work_limit,
    };
    let options = SolveOptions {
        solver: args.solver,
        tolerance: args.tolerance,
        max_shots: 1_000_000,
        form_factors: None,
        epsilon: args.epsilon,
        min_area: args.min_area,
        no_final_gather: false,
        gather_points: radiosity::solve::GATHER_POINTS_DEFAULT,
        adapt_rounds: None,
        adapt_contrast: radiosity::mesh::DEFAULT_CONTRAST,
        adapt_max_elements: None,
    };
    (scene_args, options)
}

fn bench_run(
    args: &BenchArgs,
    max_area: Option<f64>,
    settings: RenderSettings,
) -> Result<BenchRun> {
    let (scene_args, options) = run_settings(args, max_area);
    let reporter = Reporter::new(true);
    let start = std::time::Instant::now();
    let (prepared, _, solver) =
        crate::setup::prepare_solve_with_reference(&scene_args, &options, &reporter)?;
    let (solution, stats) = solve_scene(
        &prepared,
        solver,
        crate::setup::adapt(&options, &prepared, &solver)?,
        None,
        &mut keep_going,
        &reporter,
    )?;
    let rays = match (&stats, &solution.report) {
        (Some(s), _) => s.rays,
        (None, SolutionReport::Progressive(r)) => r.rays,
        (None, SolutionReport::Hierarchical(r)) => r.rays,
        (None, _) => 0,
    };
    let (width, height) = image_size(args);
    let camera = Camera::for_scene(&prepared.scene, width, height);
    let scale = Exposure::Auto.scale(&prepared.scene, &solution.mesh, solution.element_rgb());
    let image = shade_and_render(
        &prepared,
        &solution.mesh,
        solution.element_rgb(),
        &camera,
        settings,
        scale,
        &reporter,
    )?;
    let total = start.elapsed().as_secs_f64();
    std::hint::black_box(image);
    let mut stages = [0.0; BENCH_STAGES.len()];
    for (stage, d) in reporter.timings() {
        // Hierarchical radiosity's final gather is part of its solve, as the tables of
        // BENCHMARKS.md count it.
        let stage = match stage {
            Stage::Gather => Stage::Solve,
            s => s,
        };
        if let Some(k) = BENCH_STAGES.iter().position(|s| *s == stage) {
            stages[k] += d.as_secs_f64();
        }
    }
    Ok(BenchRun {
        elements: solution.mesh.len(),
        // Hierarchical radiosity estimates its links itself (QA of issue #16: the table
        // named the --method it ignores).
        method: match solver {
            radiosity::solve::Solver::Hierarchical(_) => "links' own".to_string(),
            _ => prepared.method().to_string(),
        },
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

/// The rendered image's width and height: `--width` and `--height`, each `--size` when
/// not given; without `--size`, one side given sets both, as for `render` (QA of issue
/// #16: `bench --width 64` timed a 64 x 512 picture where `render --width 64` draws 64 x
/// 64). At least 1 pixel each, checked by clap; at most 100 megapixels, as `render`.
fn image_size(args: &BenchArgs) -> (u32, u32) {
    match (args.width, args.height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, args.size.unwrap_or(w)),
        (None, Some(h)) => (args.size.unwrap_or(h), h),
        (None, None) => {
            let side = args.size.unwrap_or(crate::args::CameraArgs::DEFAULT_SIDE);
            (side, side)
        }
    }
}
