//! `radiosity check`: the statistics of a scene and its solution, or the accuracy table of
//! the form-factor methods (`--compare-methods`).

use anyhow::{bail, Result};
use radiosity::pipeline::{self as pipeline, FormFactors, SolveRequest};
use radiosity::solve::{escaped_by_surface, keep_going};

use super::solve_scene;
use crate::args::CheckArgs;
use crate::progress_bar::Reporter;
use crate::report;
use crate::setup::prepare_solve;

pub fn run(args: CheckArgs) -> Result<()> {
    if args.compare_methods {
        // The table measures every method on its own test geometry: flags that choose a
        // scene or a method would silently do nothing.
        if let Some(scene) = &args.scene.scene {
            bail!(
                "check --compare-methods measures every form-factor method on its own test \
                 geometry (unit squares, coaxial discs, a closed box), not on a scene: drop \
                 {} (or drop --compare-methods to check that scene)",
                scene.display()
            );
        }
        let m = &args.scene.method;
        // A flag at its default value is not told apart from one left out.
        let changed = m.method.is_some()
            || args.scene.steps.is_some()
            || m.resolution != crate::args::MethodArgs::RESOLUTION
            || m.samples != crate::args::MethodArgs::SAMPLES
            || m.seed != crate::args::MethodArgs::SEED;
        if changed {
            bail!(
                "check --compare-methods measures every method at its listed settings: drop \
                 --method, --steps, --resolution, --samples and --seed (--max-area sets the \
                 elements' size)"
            );
        }
        // Nothing is solved: the solver's flags would do nothing either (QA of issue #16).
        let o = &args.solve;
        let solver_flags = [
            ("--solver", o.solver.0 != radiosity::solve::SolverKind::Auto),
            ("--tolerance", o.tolerance.is_some()),
            ("--form-factors", o.form_factors.is_some()),
            ("--adapt-rounds", o.adapt_rounds.is_some()),
        ];
        let given: Vec<&str> = crate::setup::flags_given(&solver_flags);
        if !given.is_empty() {
            bail!(
                "check --compare-methods computes form factors and solves nothing: drop {}",
                given.join(", ")
            );
        }
        let max_area = args.scene.max_area.unwrap_or(1.0 / 64.0);
        if !(max_area > 0.0 && max_area <= 1.0) {
            let max_area = crate::report::typed(max_area);
            bail!("--max-area {max_area}: give the element area --compare-methods meshes its unit squares at, above 0 and at most 1");
        }
        report::method_accuracy(max_area, args.scene.quiet);
        return Ok(());
    }
    // `check` always prints its report (the notes of the other commands are in it); --quiet
    // only silences the progress bars or lines (QA of issue #16: there were none, so a 40 s
    // form-factor stage was silent).
    let reporter = Reporter::progress_only(args.scene.quiet);
    let (prepared, stem, solver) = prepare_solve(&args.scene, &args.solve, &reporter)?;
    // What is being checked, before the long stages (QA of issue #16: a large scene showed
    // only progress lines until the report came at the end).
    if !args.scene.quiet {
        errln!(
            "checking {stem}: {} by {}, solver {}; the report follows the solve",
            crate::report::count(prepared.mesh.len() as u64, "element"),
            match solver {
                radiosity::solve::Solver::Hierarchical(_) =>
                    "its links' own form factors".to_string(),
                _ => prepared.method().to_string(),
            },
            solver.kind().name()
        );
    }
    let (solution, stats, escaped) = if solver.needs_matrix() {
        let (f, stats) = match args.solve.form_factors.as_deref() {
            Some(path) => {
                let f = prepared.load_form_factors(path, &reporter)?;
                let stats = radiosity::pipeline::FormFactorStats {
                    rays: 0,
                    candidates: 0,
                    seconds: 0.0,
                    row_sums: f.row_sums(&prepared.areas()),
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
        // As solve_scene warns for the other commands (review of issue #16).
        if let Some(warning) = crate::report::light_lost(&prepared.scene, &solution) {
            errln!("warning: {warning}");
        }
        let surface_of: Vec<u32> = solution.mesh.elements.iter().map(|e| e.surface).collect();
        let escaped = escaped_by_surface(
            &f,
            &prepared.areas(),
            &surface_of,
            prepared.scene.surfaces.len(),
            solution.radiosity.as_slice(),
        );
        (solution, Some(stats), Some(escaped))
    } else {
        // Progressive refinement never holds the matrix: no row sums or reciprocity.
        let (solution, stats) =
            solve_scene(&prepared, solver, None, None, &mut keep_going, &reporter)?;
        (solution, stats, None)
    };
    report::check(
        &stem,
        &prepared,
        &solver,
        &solution,
        stats.as_ref(),
        escaped.as_deref(),
        &reporter,
    );
    Ok(())
}
