//! `radiosity compare`: one solver against the dense reference on the same mesh: time, peak
//! memory and the difference of element radiosity.

use std::ops::ControlFlow;

use anyhow::Result;
use radiosity::pipeline::{self as pipeline, SolveRequest};
use radiosity::solve::{keep_going, Solver};

use super::solve_scene;
use crate::args::CompareArgs;
use crate::errors::hint;
use crate::peak_memory::{peak_memory_bytes, reset_peak_memory};
use crate::progress_bar::Reporter;
use crate::report::{self, CompareRow, Peak, Reference};
use crate::setup::prepare_solve_with_reference;

pub fn run(args: CompareArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    // Without a reference nothing uses --method where hierarchical radiosity ignores it
    // (QA of issue #16: no warning then).
    let (prepared, stem, solver) = if args.no_reference {
        crate::setup::prepare_solve(&args.scene, &args.solve, &reporter)?
    } else {
        prepare_solve_with_reference(&args.scene, &args.solve, &reporter)?
    };
    // QA of issue #16: with the default `auto` on a small scene the tested solver is the
    // reference's own, and the row compares it with itself.
    if !args.no_reference
        && args.solve.solver.0 == radiosity::solve::SolverKind::Auto
        && solver == Solver::DEFAULT_GAUSS_SEIDEL
        && args.solve.adapt_rounds.is_none_or(|r| r == 0)
        && args.solve.form_factors.is_none()
    {
        errln!(
            "warning: auto chose Gauss-Seidel on the dense matrix, the reference's own \
             solver: the row compares it with itself (zero differences); give --solver \
             hierarchical or progressive to test another"
        );
    }
    let reset = reset_peak_memory();
    let start = std::time::Instant::now();
    let tested = format!("{}, tested", solver.kind().name());
    reporter.stages_for(Some(&tested));
    let (solution, _) = solve_scene(
        &prepared,
        solver,
        // The solver against the reference on one mesh: adaptive subdivision only when
        // --adapt-rounds asks for it.
        match args.solve.adapt_rounds {
            Some(_) => crate::setup::adapt(&args.solve, &prepared, &solver)?,
            None => None,
        },
        args.solve.form_factors.as_deref(),
        &mut |_| ControlFlow::Continue(()),
        &reporter,
    )?;
    reporter.stages_for(None);
    let seconds = start.elapsed().as_secs_f64();
    let peak = Peak {
        bytes: peak_memory_bytes(),
        reset,
    };
    let mut reference = None;
    if !args.no_reference {
        let dense = Solver::DEFAULT_GAUSS_SEIDEL;
        match prepared.check_memory(Some(&dense)) {
            Err(e) => reporter.note(&format!(
                "no dense reference: {e}{}",
                hint(&e).unwrap_or_default()
            )),
            Ok(()) => {
                reporter.solving_with(&dense);
                reporter.stages_for(Some("dense reference"));
                let start = std::time::Instant::now();
                let exact = pipeline::solve(
                    &prepared,
                    &SolveRequest::new(dense),
                    &mut keep_going,
                    &reporter,
                )?;
                reporter.stages_for(None);
                let seconds = start.elapsed().as_secs_f64();
                let emission = prepared.light.emission();
                let difference = radiosity::compare::compare(
                    &prepared.mesh,
                    &exact.radiosity,
                    emission,
                    &solution.mesh,
                    &solution.radiosity,
                )?;
                reference = Some(Reference {
                    seconds,
                    matrix_bytes: radiosity::form_factor::FormFactorMatrix::bytes_for(
                        prepared.mesh.len(),
                    ),
                    difference,
                });
            }
        }
    }
    report::compare(&CompareRow {
        stem: &stem,
        elements: prepared.mesh.len(),
        solver: solver.short_label(),
        solver_elements: solution.mesh.len(),
        seconds,
        peak,
        reference_method: (!args.no_reference).then(|| prepared.method().to_string()),
        reference,
    });
    reporter.print_timings();
    Ok(())
}
