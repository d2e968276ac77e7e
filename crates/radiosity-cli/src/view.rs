//! `radiosity view`: the walkthrough window and modeller (crate `radiosity-viewer`, cargo
//! feature `viewer`, on by default).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

/// Options of `radiosity view`.
#[derive(Args)]
#[cfg_attr(not(feature = "viewer"), allow(dead_code))]
pub struct ViewArgs {
    /// Scene file (Appendix A format); the built-in Cornell box when omitted.
    scene: Option<PathBuf>,
    /// Override the scene's MAX_PATCH_AREA (scene units squared).
    #[arg(long, value_name = "AREA")]
    max_area: Option<f64>,
    /// Override the scene's INTEGRAL_STEPS.
    #[arg(long, value_name = "K")]
    steps: Option<u32>,
    /// Always solve by progressive refinement (no form-factor matrix; colour edits re-run
    /// it). By default the dense solve is used up to 6,000 elements (see --dense).
    #[arg(long, conflicts_with = "dense")]
    progressive: bool,
    /// Compute the dense form-factor matrix whenever it fits (up to 20,000 elements), so
    /// edits are quick re-solves; by default only up to 6,000 elements, beyond which
    /// progressive refinement shows light sooner.
    #[arg(long)]
    dense: bool,
    /// The solver: auto (the two options above decide), dense or gauss-seidel (Gauss-Seidel
    /// on the cached matrix when it fits), lu, progressive, hierarchical (hierarchical
    /// radiosity with clustering, --epsilon, --min-area; the window shows its leaves and an
    /// edit re-runs it).
    #[arg(long, value_name = "SOLVER", default_value = "auto", conflicts_with_all = ["dense", "progressive"])]
    solver: String,
    /// Hierarchical: the BF refinement threshold (as for `render --epsilon`).
    #[arg(long, default_value_t = 0.05, value_name = "E")]
    epsilon: f64,
    /// Hierarchical: the minimum node area (default: MAX_PATCH_AREA / 16).
    #[arg(long, value_name = "AREA")]
    min_area: Option<f64>,
    /// Open the window, draw `--frames` frames of the solved scene, save the window to this
    /// PNG and exit.
    #[arg(long, value_name = "FILE")]
    screenshot: Option<PathBuf>,
    /// Frames drawn before `--screenshot`.
    #[arg(long, default_value_t = 30, value_name = "N")]
    frames: u32,
    /// Show the modeller panel in the `--screenshot` (the window always shows it otherwise).
    #[arg(long)]
    panel: bool,
    /// The shading the window starts with: smooth, flat or wireframe.
    #[arg(long, default_value = "smooth", value_name = "MODE")]
    shading: String,
    /// Select the first surface whose name starts with this (as a click on it would).
    #[arg(long, value_name = "NAME")]
    select: Option<String>,
    /// No window: measure frame time offscreen (Cornell box and a tiled scene of
    /// `--bench-triangles`) and edit-to-picture time at `--bench-elements`, print Markdown.
    #[arg(long)]
    bench: bool,
    /// Triangles of the large frame-time scene (0 skips it).
    #[arg(long, default_value_t = 1_000_000, value_name = "N")]
    bench_triangles: usize,
    /// Element counts for edit-to-picture timing (comma-separated).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1000,5000,20000",
        value_name = "N,.."
    )]
    bench_elements: Vec<usize>,
    /// Frames timed per scene.
    #[arg(long, default_value_t = 30, value_name = "N")]
    bench_frames: u32,
}

#[cfg(feature = "viewer")]
pub fn view_command(args: ViewArgs) -> Result<()> {
    use anyhow::bail;
    use radiosity::pipeline::Overrides;
    use radiosity::solve::SolverKind;
    use radiosity_viewer::{worker::ViewSolver, ViewerOptions};

    if args.steps == Some(0) {
        bail!("--steps must be at least 1");
    }
    if args.bench {
        let table = radiosity_viewer::bench::run_all(
            &args.bench_elements,
            args.bench_triangles,
            args.bench_frames,
            &mut |line| errln!("{}", line.trim_end()),
        )
        .map_err(anyhow::Error::msg)?;
        outln!("{table}");
        return Ok(());
    }
    let scene = match &args.scene {
        Some(path) => radiosity::scene::read_scene(path)?,
        None => radiosity::scene::cornell_box(),
    };
    let mut options = ViewerOptions::new(scene, args.scene.clone());
    options.overrides = Overrides {
        max_patch_area: args.max_area,
        integral_steps: args.steps,
    };
    // `dense` is the window's name for Gauss-Seidel on the cached matrix; every other name
    // is the library's.
    let mut kind = match args.solver.as_str() {
        "dense" => SolverKind::GaussSeidel,
        name => name.parse::<SolverKind>()?,
    };
    if args.progressive {
        kind = SolverKind::Progressive;
    } else if args.dense {
        kind = SolverKind::GaussSeidel;
    }
    let mut hierarchical = None;
    if kind == SolverKind::Hierarchical {
        let max_area = args
            .max_area
            .unwrap_or(options.scene.settings.max_patch_area);
        let min_area = args.min_area.unwrap_or(max_area / 16.0);
        if !(args.epsilon > 0.0 && args.epsilon.is_finite()) {
            bail!("--epsilon must be a positive number, got {}", args.epsilon);
        }
        if !(min_area > 0.0 && min_area.is_finite()) {
            bail!("--min-area must be a positive number, got {min_area}");
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
    options.shading = match args.shading.as_str() {
        "smooth" => radiosity::render::Shading::Smooth,
        "flat" => radiosity::render::Shading::Flat,
        "wireframe" => radiosity::render::Shading::Wireframe,
        other => bail!("--shading must be smooth, flat or wireframe, got {other}"),
    };
    for note in radiosity_viewer::run(options)? {
        outln!("{note}");
    }
    Ok(())
}

#[cfg(not(feature = "viewer"))]
pub fn view_command(_args: ViewArgs) -> Result<()> {
    anyhow::bail!(
        "this radiosity was built without the window (cargo feature `viewer`); rebuild with \
         `cargo build --release --features viewer` (it is on by default unless \
         --no-default-features was given)"
    )
}
