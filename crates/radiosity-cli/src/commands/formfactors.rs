//! `radiosity formfactors`: compute the form-factor matrix and write it to a file.

use std::path::PathBuf;

use anyhow::Result;

use crate::args::FormFactorArgs;
use crate::progress_bar::Reporter;
use crate::report;
use crate::setup::{check_output, check_scene_flags, prepare, stem_of};

/// The output `args` name (default `<scene>.ff`), checked before any work
/// ([`check_output`]); `radiosity-mpi formfactors` checks it so too, before any rank reads
/// the scene.
pub fn output(args: &FormFactorArgs) -> Result<PathBuf> {
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.ff", stem_of(args.scene.scene.as_deref()))));
    check_output(
        &output,
        "-o",
        "the form factors are written in this program's binary matrix format, read back by \
         --form-factors (`solve` writes radiosities as CSV)",
        &["ff"],
        &[("scene file", args.scene.scene.as_deref())],
    )?;
    check_scene_flags(&args.scene)?;
    Ok(output)
}

pub fn run(args: FormFactorArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let output = output(&args)?;
    let (prepared, _) = prepare(&args.scene, &reporter)?;
    reporter.note(&format!(
        "form factors by {}; occlusion: {}",
        prepared.method(),
        prepared.method().occlusion()
    ));
    let (f, stats) = prepared.form_factors(&reporter)?;
    report::form_factor_stats(&prepared, &prepared.mesh, &stats, &reporter);
    prepared.save_form_factors(&output, &f, &reporter)?;
    reporter.name_last(
        &output
            .file_name()
            .unwrap_or(output.as_os_str())
            .to_string_lossy(),
    );
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
