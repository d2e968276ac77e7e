//! `radiosity formfactors`: compute the form-factor matrix and write it to a file.

use std::path::PathBuf;

use anyhow::Result;

use crate::args::FormFactorArgs;
use crate::progress_bar::Reporter;
use crate::report;
use crate::setup::prepare;

pub fn run(args: FormFactorArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let (prepared, stem) = prepare(&args.scene, &reporter)?;
    reporter.note(&format!(
        "form factors by {}; occlusion: {}",
        prepared.method(),
        prepared.method().occlusion()
    ));
    let (f, stats) = prepared.form_factors(&reporter)?;
    report::form_factor_stats(&prepared, &stats, &reporter);
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
