//! `radiosity view`: the walkthrough window and modeller (crate `radiosity-viewer`, cargo
//! feature `viewer`, on by default).

use crate::args::ViewArgs;
use anyhow::Result;

#[cfg(feature = "viewer")]
pub fn run(args: ViewArgs) -> Result<()> {
    use anyhow::bail;
    use radiosity::pipeline::Overrides;
    use radiosity::solve::SolverKind;
    use radiosity_viewer::{worker::ViewSolver, ViewerOptions};

    let quiet = args.quiet;
    // Before any thread starts: the window system's libraries complain at every probe
    // where XDG_RUNTIME_DIR is missing (root under Xvfb).
    crate::runtime_dir::ensure_runtime_dir();
    if args.bench {
        // Refused before anything runs (QA of issue #16: 0 elements ran the frame timing
        // and then failed with "MAX_PATCH_AREA ... got inf"; 0 frames printed an inf row).
        if args.bench_elements.contains(&0) {
            bail!(
                "--bench-elements {}: give element counts of at least 1",
                args.bench_elements
                    .iter()
                    .map(|n| n.to_string())
                    .collect::<Vec<_>>()
                    .join(",")
            );
        }
        if args.bench_frames == 0 {
            bail!("--bench-frames 0: give the frames timed per scene, at least 1");
        }
        // Progress on stderr, the tables once on stdout.
        let table = radiosity_viewer::bench::run_all(
            &args.bench_elements,
            args.bench_triangles,
            args.bench_frames,
            &mut |line| {
                if !quiet {
                    errln!("view --bench: {}", line.trim_end())
                }
            },
        )
        .map_err(anyhow::Error::msg)?;
        outln!("{table}");
        return Ok(());
    }
    // The bench's flags without --bench (QA of issue #16: `--bench-elements 0` passed
    // without a word here, and was refused with --bench).
    let mut unused = Vec::new();
    if args.bench_triangles != 1_000_000 {
        unused.push("--bench-triangles");
    }
    if args.bench_elements != [1000, 5000, 20000] {
        unused.push("--bench-elements");
    }
    if args.bench_frames != 30 {
        unused.push("--bench-frames");
    }
    if !unused.is_empty() {
        errln!(
            "warning: {} ignored without --bench (they set what the offscreen timing measures)",
            unused.join(" and ")
        );
    }
    check_flags(&args)?;
    let file = match &args.scene {
        Some(path) => {
            let options = radiosity::io::import::ImportOptions {
                scale: args.scale,
                settings: None,
            };
            let imported = radiosity::io::import::read_any_scene(path, &options)?;
            for w in &imported.warnings {
                errln!("{}", crate::errors::plain_io_words(&w.to_string()));
            }
            imported.file
        }
        None if args.scale != 1.0 => {
            bail!("--scale applies to a scene file; the built-in Cornell box is in millimetres")
        }
        None => radiosity::scene::cornell_box(),
    };
    let mut options = ViewerOptions::new(file, args.scene.clone());
    options.overrides = Overrides {
        max_patch_area: args.max_area,
        integral_steps: args.steps,
    };
    // `--solver dense` arrives as Gauss-Seidel (on the cached matrix).
    let mut kind = args.solver;
    if args.progressive {
        kind = SolverKind::Progressive;
    } else if args.dense {
        kind = SolverKind::GaussSeidel;
    }
    let mut hierarchical = None;
    if kind == SolverKind::Hierarchical {
        let max_area = args.max_area.unwrap_or(options.settings.max_patch_area);
        let min_area = args.min_area.unwrap_or(max_area / 16.0);
        if !(min_area > 0.0 && min_area.is_finite()) {
            let min_area = crate::report::typed(min_area);
            bail!("--min-area {min_area}: give the smallest element area (scene units squared), a number above 0");
        }
        hierarchical = Some(radiosity::solve::HierarchicalSettings {
            epsilon: args.epsilon,
            min_area,
            ..radiosity::solve::HierarchicalSettings::defaults_for(max_area)
        });
    }
    options.solver = ViewSolver { kind, hierarchical };
    options.screenshot = args.screenshot;
    options.frames = args.frames;
    options.panel = args.panel;
    options.select = args.select;
    options.shading = args.shading;
    for note in radiosity_viewer::run(options)? {
        if !quiet {
            outln!("{note}");
        }
    }
    Ok(())
}

/// `view`'s numbers and output, checked before the scene is read and the window opens
/// (QA of issue #16: `--max-area -1` or `--screenshot shot.txt` was refused only after the
/// solve, or by the window).
#[cfg(feature = "viewer")]
fn check_flags(args: &ViewArgs) -> Result<()> {
    use anyhow::bail;
    use radiosity::solve::SolverKind;
    crate::setup::check_scale_and_area(args.scale, args.max_area)?;
    if let Some(shot) = &args.screenshot {
        crate::setup::check_output(
            shot,
            "--screenshot",
            "the window is saved as a PNG",
            &["png"],
            &[("scene file", args.scene.as_deref())],
        )?;
        if args.frames == 0 {
            bail!("--frames 0: give the frames drawn before the screenshot, at least 1");
        }
    } else {
        // Printed even with --quiet: the run does not do what the flags say. Only the flags
        // given are named (QA of issue #16).
        let given =
            crate::setup::flags_given(&[("--frames", args.frames != 30), ("--panel", args.panel)]);
        if !given.is_empty() {
            errln!(
                "warning: {} ignored: without --screenshot the window stays open",
                given.join(", ")
            );
        }
    }
    // Refused whether or not the solver uses them, as `render` refuses them (QA pass 15 of
    // #16: `view --epsilon 0` was only warned about without --solver hierarchical).
    crate::setup::check_hierarchical_flags(args.epsilon, args.min_area)?;
    let hierarchical = args.solver == SolverKind::Hierarchical;
    let given = crate::setup::flags_given(&[
        ("--epsilon", !hierarchical && args.epsilon != 0.05),
        ("--min-area", !hierarchical && args.min_area.is_some()),
    ]);
    if !given.is_empty() {
        errln!(
            "warning: {} ignored: {} hierarchical radiosity's (--solver hierarchical)",
            given.join(", "),
            if given.len() == 1 {
                "it is"
            } else {
                "they are"
            }
        );
    }
    Ok(())
}

#[cfg(not(feature = "viewer"))]
pub fn run(_args: ViewArgs) -> Result<()> {
    anyhow::bail!(
        "this radiosity was built without the window (cargo feature `viewer`); rebuild with \
         `cargo build --release --features viewer` (it is on by default unless \
         --no-default-features was given)"
    )
}
