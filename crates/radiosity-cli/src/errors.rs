//! What the command line says when a run fails: the library's message, its causes, and the
//! hint in this program's own commands and flags that the library cannot give.

use radiosity::form_factor::{FormFactorFileError, FormFactorMethod, OutOfMemory};
use radiosity::io::path_traced_file::PathTracedFileError;
use radiosity::pipeline::PipelineError;
use radiosity::render::Camera;
use radiosity::scene;
use radiosity::solve::SolveError;

/// The message for a failed run: the error and the causes its text does not already
/// include, then the command-line hint for it (see [`hint`]), after "error: " (scene errors
/// carry their own "file:line:column: error:", and so do import errors).
pub fn describe(err: &anyhow::Error) -> String {
    let mut text = err.to_string();
    for cause in err.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text = format!("{text}: {cause}");
        }
    }
    if let Some(hint) = err.chain().find_map(hint) {
        text.push_str(&hint);
    }
    let text = plain_io_words(&text);
    // Messages in the compiler's form ("file:line: error: what") carry their own prefix:
    // scene and import errors always, and any other library error that names a place in a
    // file (a points CSV, an IES file).
    if err.downcast_ref::<scene::SceneError>().is_some()
        || err
            .downcast_ref::<radiosity::io::import::ImportError>()
            .is_some()
        || text.starts_with("error: ")
        || text.contains(": error: ")
    {
        text
    } else {
        format!("error: {text}")
    }
}

/// The operating system's words put in the project's: "No such file or directory (os
/// error 2)" becomes "no such file or folder" (QA of issue #16: the raw text and its error
/// number puzzled more than they told).
pub fn plain_io_words(text: &str) -> String {
    const WORDS: [(&str, &str); 4] = [
        ("No such file or directory", "no such file or folder"),
        ("Permission denied", "permission denied"),
        ("Is a directory", "is a folder"),
        (
            "Not a directory",
            "a part of the path is a file, not a folder",
        ),
    ];
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(" (os error ") {
        out.push_str(&rest[..at]);
        let tail = &rest[at + " (os error ".len()..];
        let digits = tail.bytes().take_while(u8::is_ascii_digit).count();
        if digits > 0 && tail[digits..].starts_with(')') {
            rest = &tail[digits + 1..];
        } else {
            out.push_str(" (os error ");
            rest = tail;
        }
    }
    out.push_str(rest);
    WORDS
        .iter()
        .fold(out, |text, (os, ours)| text.replace(os, ours))
}

/// For an LU matrix past the memory, how long LU takes at the size that would fit (QA of
/// issue #16: the refusal offered 43,004 elements, half an hour of LU or more): its time
/// grows as the cube of the elements, 2.45 s measured at 4,584 elements on two cores
/// (`radiosity solve --solver lu --max-area 500`, December 2026).
fn lu_time(m: &radiosity::form_factor::OutOfMemory) -> String {
    if !m.what.contains("LU") {
        return String::new();
    }
    let seconds = 2.45 * (m.fits as f64 / 4584.0).powi(3);
    let time = if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else {
        format!("{:.0} minutes", seconds / 60.0)
    };
    format!(
        "; LU's time grows as the cube of the elements: about {time} on two cores at {} \
         elements (Gauss-Seidel's, --solver gauss-seidel, as the square)",
        m.fits
    )
}

/// What to run instead, in this program's commands and flags, for a library error that can
/// be fixed by other settings: text to append to its message. The library's messages state
/// what is wrong with the numbers; only the command line knows its flags.
pub fn hint(err: &(dyn std::error::Error + 'static)) -> Option<String> {
    let memory = memory_hint();
    let memory = memory.as_str();
    const RECOMPUTE: &str = "; recompute it with `radiosity formfactors`";
    if let Some(e) = err.downcast_ref::<PipelineError>() {
        return match e {
            PipelineError::OutOfMemory(m) | PipelineError::Solve(SolveError::OutOfMemory(m)) => {
                Some(format!("{}{memory}{}", fits_area(m), lu_time(m)))
            }
            PipelineError::TooManyIntegrationPoints { .. } => {
                Some("; use fewer steps (--steps) or larger elements (--max-area)".into())
            }
            PipelineError::FormFactorFile(e) => hint(e),
            PipelineError::FormFactorsForAnotherMesh { source, .. } => hint(source),
            PipelineError::TooMuchWork(e) => hint(e),
            PipelineError::FormFactorsUnused { .. } => {
                Some(" (--form-factors applies to --solver gauss-seidel and lu only)".into())
            }
            PipelineError::Solve(e) => hint(e),
            _ => None,
        };
    }
    if let Some(e) = err.downcast_ref::<radiosity::budget::TooMuchWork>() {
        // The scene keyword the library names, as the flag to type (QA of issue #16).
        let steps = e
            .fits
            .strip_prefix("at most INTEGRAL_STEPS ")
            .and_then(|rest| rest.split_whitespace().next())
            .map(|k| format!(": --steps {k}"))
            .unwrap_or_default();
        return Some(format!(
            "{steps} (or pass --no-work-limit to run it anyway)"
        ));
    }
    if let Some(e) = err.downcast_ref::<FormFactorFileError>() {
        return match e {
            FormFactorFileError::Io { .. } => None,
            FormFactorFileError::NotFormFactorFile { .. } => {
                Some("; write one with `radiosity formfactors`".into())
            }
            FormFactorFileError::MethodMismatch {
                found, expected, ..
            } => Some(format!(
                "{RECOMPUTE} and {}, or use the settings it was made with ({})",
                method_flags(expected),
                method_flags(found)
            )),
            FormFactorFileError::OutOfMemory { source, .. } => {
                Some(format!("{}{memory}", fits_area(source)))
            }
            _ => Some(RECOMPUTE.into()),
        };
    }
    if let Some(e) = err.downcast_ref::<SolveError>() {
        return match e {
            SolveError::OutOfMemory(m) => Some(format!("{}{memory}", fits_area(m))),
            // QA of issue #16: under `ulimit -v` the limit can be nothing at all, which no
            // epsilon cures.
            SolveError::HierarchicalTooBig { limit_mib, .. } if *limit_mib < 64 => Some(format!(
                "; but only {limit_mib} MiB is left to it (the machine's free memory, or what \
                 `ulimit -v` leaves after the program's own mapped memory and its threads' \
                 malloc arenas of 64 MiB each): raise the limit or free memory"
            )),
            SolveError::HierarchicalTooBig { .. } => Some(": raise --epsilon or --min-area".into()),
            // QA pass 16 of #16: the area that fits, as the flag to type.
            SolveError::MinAreaTooSmall { fits, default, .. } => match fits {
                Some(a) if a < default => Some(format!(
                    ": --min-area {}",
                    radiosity::mesh::four_digits_up(*a)
                )),
                Some(_) => Some(": leave --min-area out".into()),
                None => Some(": leave --min-area out, or raise --max-area".into()),
            },
            // QA of issue #16: a closed box of reflectance 0.97 stopped with "rows summing
            // far above 1?", and the CIE 5.8 cube of 0.95 ran 100,000 sweeps.
            SolveError::HierarchicalGrowing { .. }
            | SolveError::HierarchicalNotConverged { .. } => Some(
                "; --solver gauss-seidel (the dense matrix, its rows summing to 1 within \
                     0.2 % in a closed room) or --solver progressive solves it, or a smaller \
                     --epsilon makes the links' estimates finer"
                    .into(),
            ),
            SolveError::NotConverged { .. } => {
                Some(" (--tolerance loosens it; --solver lu solves directly)".into())
            }
            SolveError::ProgressiveNotConverged { .. } => {
                Some(" (--max-shots raises the shot limit, --tolerance loosens it)".into())
            }
            _ => None,
        };
    }
    if let Some(e) = err.downcast_ref::<PathTracedFileError>() {
        const RETRACE: &str = "; trace a new reference with --save-reference";
        return match e {
            PathTracedFileError::Size { found, .. } => Some(format!(
                "{RETRACE}, or use the size it was traced at (--width {} --height {})",
                found.0, found.1
            )),
            PathTracedFileError::Camera { found, .. } => Some(format!(
                "{RETRACE}, or use the camera it was traced with ({})",
                camera_flags(found)
            )),
            PathTracedFileError::Scene { .. } => Some(format!("{RETRACE} for this scene")),
            PathTracedFileError::NotPathTraced { .. } | PathTracedFileError::NotExr { .. } => {
                Some("; write one with `radiosity pathtrace --save-reference FILE.exr`".into())
            }
            _ => None,
        };
    }
    err.downcast_ref::<OutOfMemory>()
        .map(|m| format!("{}{memory}", fits_area(m)))
}

/// The command being run ("formfactors"), for hints that depend on it; set by `main`.
pub static COMMAND: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// What to change when a dense matrix does not fit: a larger MAX_PATCH_AREA, or (where the
/// command solves) a solver that keeps no matrix (QA of issue #16: `formfactors`, whose
/// output is the matrix, was offered `--solver`, a flag it does not have).
fn memory_hint() -> String {
    match COMMAND.get().map(String::as_str) {
        Some("formfactors") => " (raise MAX_PATCH_AREA with --max-area: the matrix is what \
                                `formfactors` writes, so it must fit)"
            .to_string(),
        _ => " (raise MAX_PATCH_AREA with --max-area, or use --solver hierarchical or \
              --solver progressive, which keep no matrix)"
            .to_string(),
    }
}

/// "; about 2.7 times the MAX_PATCH_AREA": the elements go as one over the area, so the
/// area that fits is the one used times n / fits (QA of issue #16: the refusal gave an
/// element count, where the flag takes an area).
fn fits_area(m: &OutOfMemory) -> String {
    if m.fits == 0 || m.n <= m.fits {
        return String::new();
    }
    format!(
        ", at about {} times the MAX_PATCH_AREA",
        crate::report::significant(m.n as f64 / m.fits as f64, 2)
    )
}

/// The flags that give `camera`: `--eye x,y,z --look-at x,y,z --up x,y,z --fov F`.
fn camera_flags(camera: &Camera) -> String {
    let v = |v: glam::DVec3| format!("{},{},{}", v.x, v.y, v.z);
    format!(
        "--eye {} --look-at {} --up {} --fov {}",
        v(camera.eye),
        v(camera.look_at),
        v(camera.up),
        camera.fov_y_degrees
    )
}

/// The flags that select `method`: `--method contour --steps 4`.
fn method_flags(method: &FormFactorMethod) -> String {
    match *method {
        FormFactorMethod::AreaIntegral { steps } => format!("--method area --steps {steps}"),
        FormFactorMethod::Contour { steps } => format!("--method contour --steps {steps}"),
        FormFactorMethod::Analytic { steps } => format!("--method analytic --steps {steps}"),
        FormFactorMethod::Hemicube { resolution } => {
            format!("--method hemicube --resolution {resolution}")
        }
        FormFactorMethod::MonteCarlo { samples, seed } => {
            format!("--method montecarlo --samples {samples} --seed {seed}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity::form_factor::check_dense_fits;

    /// 100,000 x 100,000 f32 (44 GB with headroom) in 1 GiB.
    fn oom() -> OutOfMemory {
        check_dense_fits("the form-factor matrix (f32)", 100_000, 4.0, 1 << 30).unwrap_err()
    }

    #[test]
    fn operating_system_words_are_plain() {
        let err = std::io::Error::from_raw_os_error(2);
        let text = describe(&anyhow::Error::new(err).context("cannot read x.csv"));
        assert_eq!(text, "error: cannot read x.csv: no such file or folder");
        // Not an error number: left as it is.
        assert_eq!(plain_io_words("a (os error x)"), "a (os error x)");
    }

    #[test]
    fn memory_errors_get_the_flags_that_help() {
        let want = "error: the form-factor matrix (f32) for 100000 elements needs 41962 MiB, but \
                    only 1024 MiB of memory is available; at most 15621 elements would fit, at \
                    about 6.4 times the MAX_PATCH_AREA (raise \
                    MAX_PATCH_AREA with --max-area, or use --solver hierarchical or --solver \
                    progressive, which keep no matrix)";
        // However it reaches the command line.
        let direct = anyhow::Error::new(oom());
        let pipeline = anyhow::Error::new(PipelineError::OutOfMemory(oom()));
        let solve = anyhow::Error::new(PipelineError::Solve(SolveError::OutOfMemory(oom())));
        for err in [direct, pipeline, solve] {
            assert_eq!(describe(&err), want);
        }
        let file = anyhow::Error::new(PipelineError::FormFactorFile(
            FormFactorFileError::OutOfMemory {
                path: "f.ff".into(),
                source: oom(),
            },
        ));
        assert_eq!(
            describe(&file),
            want.replace("error: ", "error: cannot load form-factor file f.ff: ")
        );
    }

    #[test]
    fn integration_points_error_gets_the_flags_that_help() {
        let err = anyhow::Error::new(PipelineError::TooManyIntegrationPoints {
            steps: 1000,
            elements: 130,
            points: 1.3e8,
            limit: 5e7,
        });
        assert_eq!(
            describe(&err),
            "error: INTEGRAL_STEPS 1000 on 130 elements means 1.30e8 integration points (more \
             than 5e7); use fewer steps (--steps) or larger elements (--max-area)"
        );
    }

    #[test]
    fn form_factor_file_errors_get_the_command_that_remakes_them() {
        let path = std::path::PathBuf::from("t.ff");
        let recompute = "; recompute it with `radiosity formfactors`";
        let stale = FormFactorFileError::Stale {
            path: path.clone(),
            elements: 10,
            method: "area k=2".into(),
            found: 1,
            expected: 2,
        };
        let text = describe(&PipelineError::FormFactorFile(stale).into());
        assert!(text.ends_with(recompute), "{text}");
        assert!(
            text.contains("0000000000000001, this mesh is 0000000000000002"),
            "{text}"
        );
        let not_one = FormFactorFileError::NotFormFactorFile { path: path.clone() };
        let text = describe(&not_one.into());
        assert!(
            text.ends_with("; write one with `radiosity formfactors`"),
            "{text}"
        );
        let tag = "hemicube-gpu resolution=8";
        let unknown = FormFactorFileError::UnknownMethod {
            path: path.clone(),
            tag: tag.into(),
            source: Box::new(tag.parse::<FormFactorMethod>().unwrap_err()),
        };
        let text = describe(&unknown.into());
        assert!(text.contains(&format!("`{tag}`")), "{text}");
        assert!(text.ends_with(recompute), "{text}");
        let mismatch = FormFactorFileError::MethodMismatch {
            path: path.clone(),
            found: FormFactorMethod::MonteCarlo {
                samples: 64,
                seed: 3,
            },
            expected: FormFactorMethod::Hemicube { resolution: 32 },
        };
        assert_eq!(
            describe(&mismatch.into()),
            "error: form-factor file t.ff was computed with method `montecarlo samples=64 \
             seed=3`, not `hemicube resolution=32`; recompute it with `radiosity formfactors` \
             and --method hemicube --resolution 32, or use the settings it was made with \
             (--method montecarlo --samples 64 --seed 3)"
        );
        // An unreadable file has nothing to recompute.
        let io = FormFactorFileError::Io {
            path,
            source: std::io::Error::from(std::io::ErrorKind::NotFound),
        };
        let text = describe(&io.into());
        assert!(!text.contains("radiosity formfactors"), "{text}");
    }
}
