//! `radiosity solve`: solve a scene and write the radiosity of every element as CSV or JSON.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use radiosity::progress::{run_stage, Stage};

use super::solve_as_asked;
use crate::args::SolveArgs;
use crate::progress_bar::Reporter;
use crate::setup::{output_extension, prepare_solve, refuse_overwriting_inputs, stem_of};

pub fn run(args: SolveArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.csv", stem_of(args.scene.scene.as_deref()))));
    let inputs = [
        ("scene file", args.scene.scene.as_deref()),
        ("form-factor file", args.solve.form_factors.as_deref()),
    ];
    refuse_overwriting_inputs(&output, &inputs)?;
    output_extension(
        &output,
        "-o",
        "the element radiosities are written as CSV, or JSON for a .json name",
        &["csv", "json"],
    )?;
    if let Some(report) = &args.report {
        refuse_overwriting_inputs(report, &inputs)?;
        output_extension(
            report,
            "--report",
            "the per-surface report is a CSV table",
            &["csv"],
        )?;
        if radiosity::io::is_same_file(report, &output) || report == &output {
            bail!(
                "--report {} is the solution's output too; give the report another name",
                report.display()
            );
        }
    }
    let (prepared, _, solver) = prepare_solve(&args.scene, &args.solve, &reporter)?;
    let solution = solve_as_asked(&prepared, solver, &args.solve, &reporter)?;
    run_stage(&reporter, Stage::Write, 0, || {
        radiosity::solution::write_solution(
            &output,
            &prepared.scene,
            &solution.mesh,
            solution.element_rgb(),
            &crate::setup::scene_unit(),
        )
    })
    .with_context(|| format!("cannot write {}", output.display()))?;
    reporter.note(&format!(
        "wrote {} ({} elements; radiosity in the scene's emission units, W/m^2 or lm/m^2 \
         as the scene gives E; area and centroids in {})",
        output.display(),
        solution.mesh.len(),
        crate::setup::scene_unit()
    ));
    if let Some(report) = &args.report {
        run_stage(&reporter, Stage::Write, 0, || {
            radiosity::io::surface_report::write_surface_report(
                report,
                &prepared.scene,
                &solution.mesh,
                solution.element_rgb(),
                &crate::setup::scene_unit(),
            )
        })
        .with_context(|| format!("cannot write {}", report.display()))?;
        reporter.note(&format!(
            "wrote {} ({} surfaces; radiosity in the scene's emission units; lengths in {})",
            report.display(),
            prepared.scene.surfaces.len(),
            crate::setup::scene_unit()
        ));
    }
    reporter.print_timings();
    Ok(())
}
