//! `radiosity validate cie171`: the files it writes are the repository's `validation/`, and
//! a case id that names nothing is refused with the list of cases.

use std::path::Path;

use crate::fixtures::{radiosity, scratch_dir, stderr, stdout};

#[test]
fn validate_cie171_write_reproduces_the_validation_folder() {
    let dir = scratch_dir("validate-write");
    let out = radiosity(&["validate", "cie171", "--write", "cases"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("wrote 26 files"), "{}", stdout(&out));
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../validation");
    for entry in std::fs::read_dir(dir.join("cases")).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap();
        let ours = std::fs::read_to_string(&path).unwrap();
        let theirs = std::fs::read_to_string(committed.join(name))
            .unwrap_or_else(|e| panic!("validation/{}: {e}", name.to_string_lossy()));
        assert_eq!(ours, theirs, "{}", name.to_string_lossy());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn validate_cie171_unknown_case_lists_the_cases() {
    let dir = scratch_dir("validate-unknown");
    let out = radiosity(&["validate", "cie171", "--case", "9.9"], &dir);
    assert!(!out.status.success());
    let message = stderr(&out);
    assert!(
        message.contains("\"9.9\"") && message.contains("5.2, 5.3, 5.6, 5.7"),
        "{message}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn validate_cie171_says_where_each_reference_comes_from() {
    let dir = scratch_dir("validate-provenance");
    let out = radiosity(&["validate", "cie171", "--case", "5.2"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = stdout(&out);
    assert!(table.contains("| target (%) | reference from |"), "{table}");
    // Every row of 5.2 (8 points) names its reference's source in the last column.
    let rows: Vec<&str> = table.lines().filter(|l| l.starts_with("| 5.2 |")).collect();
    assert_eq!(rows.len(), 8, "{table}");
    for row in rows {
        assert!(
            row.ends_with("| first principles (recomputed here) |"),
            "{row}"
        );
    }
    // The notes: what was available, and the published description the case follows.
    assert!(
        table.contains("CIE 171:2006 itself was not available here"),
        "{table}"
    );
    assert!(
        table.contains("Scene: after CIE 171:2006 5.2 (light source directional output"),
        "{table}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn validate_cie171_write_with_case_writes_only_that_case() {
    // QA of issue #16: --case was ignored by --write, which wrote every case.
    let dir = scratch_dir("validate-write-case");
    let out = radiosity(
        &["validate", "cie171", "--write", "cases", "--case", "5.11"],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("wrote 2 files"), "{}", stdout(&out));
    let mut names: Vec<String> = std::fs::read_dir(dir.join("cases"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), 2, "{names:?}");
    assert!(names[0].ends_with(".points.csv") && names[1].ends_with(".scene"));
    // Again into the same folder: refused without --force, the files left as they were
    // (QA pass 13 of #16: all were written over without a word); replaced with it.
    let scene = dir.join("cases").join(&names[1]);
    std::fs::write(&scene, "edited").unwrap();
    let again = ["validate", "cie171", "--write", "cases", "--case", "5.11"];
    let out = radiosity(&again, &dir);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("2 of the case files are already there")
            && stderr(&out).contains("--force"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), "edited");
    let out = radiosity(&[&again[..], &["--force"]].concat(), &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_ne!(std::fs::read_to_string(&scene).unwrap(), "edited");
    let out = radiosity(
        &["validate", "cie171", "--write", "more", "--case", "9.9"],
        &dir,
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("\"9.9\""), "{}", stderr(&out));
    assert!(!dir.join("more").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
