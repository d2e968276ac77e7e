//! `radiosity check`: the statistics of a scene and its solution, or the accuracy table of
//! the form-factor methods (`--compare-methods`).

use anyhow::Result;
use radiosity::pipeline::{self as pipeline, FormFactors, SolutionReport, SolveRequest};
use radiosity::solve::keep_going;

use super::solve_scene;
use crate::args::CheckArgs;
use crate::progress_bar::{format_duration, Reporter};
use crate::setup::prepare;

pub fn run(args: CheckArgs) -> Result<()> {
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
