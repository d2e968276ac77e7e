//! `radiosity validate cie171`: the CIE 171:2006 analytical cases
//! ([`radiosity::validation::cie171`]) run through the program's own illuminance
//! calculation, printed as a table of case, point, reference, computed and difference.

use std::path::Path;

use anyhow::{bail, Context, Result};
use radiosity::validation::cie171::{self, Case, Row};

use crate::args::Cie171Args;

/// Runs (or, with `--write`, writes) the CIE 171 cases.
pub fn cie171(args: Cie171Args) -> Result<()> {
    let cases: Vec<Case> = cie171::cases()
        .into_iter()
        .filter(|c| {
            args.case
                .as_deref()
                .is_none_or(|prefix| c.id.starts_with(prefix))
        })
        .collect();
    if cases.is_empty() {
        bail!(
            "no CIE 171 case has an id starting with {:?}; the cases are 5.2, 5.3, 5.6, 5.7, \
             5.8 (one per reflectance), 5.9 and 5.11",
            args.case.unwrap_or_default()
        );
    }
    // --write with --case writes only those cases' files (QA of issue #16: --case was
    // ignored and every case written).
    if let Some(dir) = &args.write {
        if dir.exists() && !dir.is_dir() {
            bail!(
                "--write {}: is a file; give a folder to write the cases into",
                dir.display()
            );
        }
        // As every other output: a missing folder's parent is not made (QA of issue #16:
        // `--write nowhere/deep/x` made three folders without a word).
        crate::setup::parent_folder_exists(dir, "--write")?;
        // As `generate`: no scene file is written over without --force (QA pass 13 of #16:
        // a second --write replaced all 26 files without a word).
        if !args.force {
            let existing: Vec<String> = cases
                .iter()
                .flat_map(|c| {
                    [
                        format!("{}.scene", c.stem),
                        format!("{}.points.csv", c.stem),
                    ]
                })
                .filter(|name| dir.join(name).exists())
                .collect();
            if let Some(first) = existing.first() {
                bail!(
                    "--write {}: {} of the case files {} already there ({first}{}); give \
                     another folder, or --force to replace them",
                    dir.display(),
                    existing.len(),
                    if existing.len() == 1 { "is" } else { "are" },
                    if existing.len() > 1 { ", ..." } else { "" }
                );
            }
        }
        let written = cie171::write_case_files(dir, &cases)
            .with_context(|| format!("cannot write the validation files into {}", dir.display()))?;
        if !args.quiet {
            println!("wrote {} files into {}", written.len(), dir.display());
        }
        return Ok(());
    }
    let dir = tempfile_dir()?;
    let quiet = args.quiet;
    // The table and the sources are left out with --quiet; the verdict never is.
    let say = |line: &str| {
        if !quiet {
            println!("{line}");
        }
    };
    say("| case | point | reference (lx) | computed (lx) | difference (%) | target (%) | reference from |");
    say("|---|---|---:|---:|---:|---:|---|");
    let mut failures = Vec::new();
    let mut values = 0usize;
    for case in &cases {
        let scene = dir.join(format!("{}.scene", case.stem));
        std::fs::write(&scene, &case.scene)
            .with_context(|| format!("cannot write {}", scene.display()))?;
        let computed = illuminance(&scene, case)
            .with_context(|| format!("case {} ({})", case.id, case.title))?;
        for row in case.compare(&computed) {
            say(&table_row(&row, case));
            values += 1;
            if !row.passes(case.tolerance_percent) {
                failures.push(format!("{} {}", row.case, row.point));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    say("");
    say(&format!("{}.", cie171::GEOMETRY_NOTE));
    // One paragraph per description, with the ids of all its cases (QA of issue #16: the
    // 5.8 paragraph was printed seven times, once per reflectance).
    let mut paragraphs: Vec<(Vec<&str>, String)> = Vec::new();
    for case in &cases {
        let text = case.provenance_text();
        match paragraphs.iter_mut().find(|(_, t)| *t == text) {
            Some((ids, _)) => ids.push(case.id.as_str()),
            None => paragraphs.push((vec![case.id.as_str()], text)),
        }
    }
    for (ids, text) in &paragraphs {
        say(&format!("\n{}: {text}", ids.join(", ")));
    }
    let (line, passed) = verdict(values, &failures);
    say("");
    println!("{line}");
    if !passed {
        bail!("{line}");
    }
    Ok(())
}

/// The run's last line, and whether it passed: every value within its target, or how many
/// and which are not (QA of issue #16: a passing run ended with the list of sources and no
/// word on the outcome).
pub fn verdict(values: usize, failures: &[String]) -> (String, bool) {
    if failures.is_empty() {
        (
            format!("verdict: PASS, all {values} values within their targets"),
            true,
        )
    } else {
        (
            format!(
                "verdict: FAIL, {} of {values} values outside their targets: {}",
                failures.len(),
                failures.join(", ")
            ),
            false,
        )
    }
}

fn table_row(row: &Row, case: &Case) -> String {
    let difference = match row.difference_percent() {
        Some(d) => crate::report::signed(d, 3),
        None => "(reference 0)".to_string(),
    };
    format!(
        "| {} | {} | {:.3} | {:.3} | {} | {} | {} |",
        row.case,
        row.point,
        row.reference,
        row.computed,
        difference,
        case.tolerance_percent,
        case.reference_from.label()
    )
}

/// A fresh folder for the scenes of this run, under the system's temporary folder.
fn tempfile_dir() -> Result<std::path::PathBuf> {
    let dir = std::env::temp_dir().join(format!("radiosity-cie171-{}", std::process::id()));
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    Ok(dir)
}

/// `(direct, indirect)` lux at each of the case's points: the scene written at `scene`
/// (kept for the user to look at while the run lasts) solved by dense Gauss-Seidel to a
/// relative residual of 1e-9 (the cube at reflectance 0.95 needs the tight tolerance).
fn illuminance(scene: &Path, case: &Case) -> Result<Vec<(f64, f64)>> {
    let _ = scene;
    Ok(cie171::compute(
        case,
        radiosity::Solver::DEFAULT_GAUSS_SEIDEL,
    )?)
}

#[cfg(test)]
mod tests {
    use super::verdict;

    #[test]
    fn the_verdict_says_pass_or_names_what_failed() {
        let (line, passed) = verdict(3, &[]);
        assert!(passed);
        assert_eq!(line, "verdict: PASS, all 3 values within their targets");
        let failed = ["5.7 ceiling_2".to_string(), "5.8 rho 0.95".to_string()];
        let (line, passed) = verdict(40, &failed);
        assert!(!passed);
        assert_eq!(
            line,
            "verdict: FAIL, 2 of 40 values outside their targets: 5.7 ceiling_2, 5.8 rho 0.95"
        );
    }
}
