//! `radiosity formfactors`: compute the form-factor matrix and write it to a file.

use std::path::PathBuf;

use anyhow::Result;

use crate::args::FormFactorArgs;
use crate::progress_bar::Reporter;
use crate::report;
use crate::setup::{output_extension, prepare, refuse_overwriting_inputs, stem_of};

pub fn run(args: FormFactorArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.ff", stem_of(args.scene.scene.as_deref()))));
    refuse_overwriting_inputs(&output, &[("scene file", args.scene.scene.as_deref())])?;
    output_extension(
        &output,
        "-o",
        "the form factors are written in this program's binary matrix format, read back by \
         --form-factors (`solve` writes radiosities as CSV)",
        &["ff"],
    )?;
    let (prepared, _) = prepare(&args.scene, &reporter)?;
    reporter.note(&format!(
        "form factors by {}; occlusion: {}",
        prepared.method(),
        prepared.method().occlusion()
    ));
    let (f, stats) = prepared.form_factors(&reporter)?;
    report::form_factor_stats(&prepared, &prepared.mesh, &stats, &reporter);
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
