//! `radiosity check`: the statistics of a scene and its solution, or the accuracy table of
//! the form-factor methods (`--compare-methods`).

use anyhow::Result;
use radiosity::pipeline::{self as pipeline, FormFactors, SolveRequest};
use radiosity::solve::keep_going;

use super::solve_scene;
use crate::args::CheckArgs;
use crate::progress_bar::Reporter;
use crate::report;
use crate::setup::prepare_solve;

pub fn run(args: CheckArgs) -> Result<()> {
    if args.compare_methods {
        report::method_accuracy(args.scene.max_area.unwrap_or(1.0 / 64.0));
        return Ok(());
    }
    // `check` always prints its report; --quiet only silences the progress bars.
    let reporter = Reporter::new(true);
    let (prepared, stem, solver) = prepare_solve(&args.scene, &args.solve, &reporter)?;
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
        solve_scene(&prepared, solver, None, None, &mut keep_going, &reporter)?
    };
    report::check(
        &stem,
        &prepared,
        &solver,
        &solution,
        stats.as_ref(),
        &reporter,
    );
    Ok(())
}
