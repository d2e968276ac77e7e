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
use crate::setup::prepare;

pub fn run(args: CompareArgs) -> Result<()> {
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

fn mib(bytes: Option<u64>, reset: bool) -> String {
    match bytes {
        Some(b) if reset => format!("{:.0}", b as f64 / (1024.0 * 1024.0)),
        Some(b) => format!("<= {:.0}", b as f64 / (1024.0 * 1024.0)),
        None => "?".into(),
    }
}
