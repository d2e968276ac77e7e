//! `radiosity solve`: solve a scene and write the radiosity of every element as CSV or JSON.

use crate::progress_bar::run_file_stage;
use std::path::PathBuf;

use anyhow::{Context, Result};
use radiosity::progress::Stage;

use super::solve_as_asked;
use crate::args::SolveArgs;
use crate::progress_bar::Reporter;
use crate::setup::{check_output, check_scene_flags, check_solve_flags, prepare_solve, stem_of};

/// The outputs `args` name (`-o`, default `<scene>.csv`, and `--report`), checked before
/// any work ([`check_output`]), with the flags' numbers; `radiosity-mpi solve` checks them
/// so too, before any rank reads the scene.
pub fn outputs(args: &SolveArgs) -> Result<PathBuf> {
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.csv", stem_of(args.scene.scene.as_deref()))));
    let inputs = [
        ("scene file", args.scene.scene.as_deref()),
        ("form-factor file", args.solve.form_factors.as_deref()),
    ];
    check_output(
        &output,
        "-o",
        "the element radiosities are written as CSV, or JSON for a .json name",
        &["csv", "json"],
        &inputs,
    )?;
    if let Some(report) = &args.report {
        check_output(
            report,
            "--report",
            "the per-surface report is a CSV table",
            &["csv"],
            &inputs,
        )?; // also refused when it is -o's file (`setup::note_output`)
    }
    check_scene_flags(&args.scene)?;
    check_solve_flags(&args.solve)?;
    Ok(output)
}

pub fn run(args: SolveArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let output = outputs(&args)?;
    let (prepared, _, solver) = prepare_solve(&args.scene, &args.solve, &reporter)?;
    let solution = solve_as_asked(&prepared, solver, &args.solve, &reporter)?;
    run_file_stage(&reporter, Stage::Write, &output, || {
        radiosity::solution::write_solution(
            &output,
            &prepared.scene,
            &solution.mesh,
            solution.element_rgb(),
        )
    })
    .with_context(|| format!("cannot write {}", output.display()))?;
    reporter.note(&format!(
        "wrote {} ({}; radiosity in the scene's emission units, W/m^2 or lm/m^2 \
         as the scene gives E; area and centroids in {})",
        output.display(),
        crate::report::count(solution.mesh.len() as u64, "element"),
        crate::setup::scene_unit()
    ));
    if let Some(report) = &args.report {
        run_file_stage(&reporter, Stage::Write, report, || {
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
            "wrote {} ({}; radiosity in the scene's emission units; lengths in {})",
            report.display(),
            crate::report::count(prepared.scene.surfaces.len() as u64, "surface"),
            crate::setup::scene_unit()
        ));
    }
    reporter.print_timings();
    Ok(())
}
