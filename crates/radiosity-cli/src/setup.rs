//! The command line's flags, second stage: the library's objects built from the parsed
//! flags of [`crate::args`] (the scene prepared for a method, the solver, the render
//! settings and the camera), with the checks that need more than one flag or the scene.

use crate::progress_bar::run_file_stage;
use std::path::Path;

use anyhow::{bail, Result};
use glam::DVec3;
use radiosity::form_factor::FormFactorMethod;
use radiosity::io::import::{read_any_scene, Format, ImportOptions};
use radiosity::mesh::{AdaptSettings, MeshError};
use radiosity::pipeline::{Overrides, PipelineError, Prepared};
use radiosity::progress::{run_stage, Stage};
use radiosity::render::{Camera, RenderSettings, Shading};
use radiosity::scene::{self, Scene, SceneFile};
use radiosity::solve::{GaussSeidelSettings, ProgressiveSettings, Solver, SolverKind};

use crate::args::{
    CameraArgs, DirectLightArg, MethodArg, MethodArgs, RayArgs, RenderArgs, SceneArgs, ShadingArg,
    SolveOptions, ToneArgs,
};
use crate::progress_bar::Reporter;

/// The scene (from its file or built in), meshed for the form-factor method of `args`,
/// with a short name for default outputs. Refuses, before any work, a problem whose
/// form-factor matrix would not fit in memory.
pub fn prepare(args: &SceneArgs, reporter: &Reporter) -> Result<(Prepared, String)> {
    let (prepared, stem) = prepare_scene(args, reporter)?;
    prepared.check_memory(None)?;
    if !args.no_work_limit {
        prepared.check_work()?;
    }
    note_scene(&prepared, &stem, reporter);
    Ok((prepared, stem))
}

/// [`prepare`], and the solver `options` ask for; refuses a problem whose matrices for that
/// solver would not fit in memory.
pub fn prepare_solve(
    args: &SceneArgs,
    options: &SolveOptions,
    reporter: &Reporter,
) -> Result<(Prepared, String, Solver)> {
    prepare_solve_as(args, options, reporter, false)
}

/// [`prepare_solve`] without the warning that hierarchical radiosity ignores `--method`:
/// for `compare`, whose dense reference uses it whatever the solver compared, and for
/// `bench`'s repeated runs, which say it once.
pub fn prepare_solve_with_reference(
    args: &SceneArgs,
    options: &SolveOptions,
    reporter: &Reporter,
) -> Result<(Prepared, String, Solver)> {
    prepare_solve_as(args, options, reporter, true)
}

fn prepare_solve_as(
    args: &SceneArgs,
    options: &SolveOptions,
    reporter: &Reporter,
    method_used_elsewhere: bool,
) -> Result<(Prepared, String, Solver)> {
    check_scene_flags(args)?;
    check_solve_flags(options)?;
    check_form_factor_file(options)?;
    let (prepared, stem) = prepare_scene(args, reporter)?;
    let solver = solver(
        options,
        prepared.mesh.len(),
        prepared.settings.max_patch_area,
        reporter,
    )?;
    prepared.check_memory(Some(&solver))?;
    // QA pass 16 of #16: `--min-area 1e-9` refined for minutes, its memory growing; the
    // leaves it allows are held to the element budget, as --max-area's elements are.
    if let Solver::Hierarchical(h) = &solver {
        radiosity::solve::check_min_area(
            &prepared.scene,
            prepared.settings.max_patch_area,
            h.min_area,
        )?;
    }
    reporter.solving_with(&solver);
    // The form factors are computed by the dense solvers (unless read from a file) and,
    // row by row, by progressive refinement; hierarchical radiosity computes its own.
    let computes = match solver {
        Solver::Dense(_) => options.form_factors.is_none(),
        Solver::Progressive(_) => true,
        Solver::Hierarchical(_) => false,
    };
    if computes && !args.no_work_limit {
        prepared.check_work()?;
    }
    if let (Solver::Hierarchical(_), Some(method), false) = (
        &solver,
        method_flag_given(&args.method),
        method_used_elsewhere,
    ) {
        // Printed even with --quiet: the run does not do what the flags say.
        errln!(
            "warning: --method {method} ignored: hierarchical radiosity computes each \
             link's form factor by its own estimate (point-to-polygon with visibility rays), \
             not by a form-factor method; use --solver gauss-seidel or lu for --method {method}"
        );
    }
    note_scene(&prepared, &stem, reporter);
    Ok((prepared, stem, solver))
}

/// `--form-factors FILE` against the flags it cannot go with, and the file readable, before
/// the scene is read and meshed (QA of issue #16: a missing file, or `--solver progressive`
/// beside it, was found only after the meshing and contact refinement, seconds on a large
/// scene). Whether the file fits the mesh is checked when it is read.
fn check_form_factor_file(options: &SolveOptions) -> Result<()> {
    let Some(path) = options.form_factors.as_deref() else {
        return Ok(());
    };
    match options.solver.0 {
        SolverKind::Progressive => bail!(
            "--form-factors cannot be used with --solver progressive, which computes its rows \
             as it shoots"
        ),
        SolverKind::Hierarchical => bail!(
            "--form-factors cannot be used with --solver hierarchical, which uses links, not a \
             matrix"
        ),
        _ => {}
    }
    if options.adapt_rounds.is_some_and(|r| r > 0) {
        bail!(
            "--adapt-rounds cannot be used with --form-factors: adaptive subdivision computes \
             the form factors of the meshes it makes"
        );
    }
    if let Err(e) = std::fs::File::open(path) {
        bail!("cannot read form-factor file {}: {e}", path.display());
    }
    Ok(())
}

/// The method `--method` names when it was given (an explicit `--method area` too), which
/// every solver but hierarchical radiosity uses.
fn method_flag_given(args: &MethodArgs) -> Option<&'static str> {
    Some(method_name(args.method?))
}

/// The scene loaded, meshed with its file's settings overridden by the flags, and its
/// form-factor method set; none of [`prepare`]'s memory and work checks (for a caller that
/// computes the matrix in blocks and never holds it: `radiosity-mpi`).
pub fn prepare_scene(args: &SceneArgs, reporter: &Reporter) -> Result<(Prepared, String)> {
    check_scene_flags(args)?;
    let (file, stem) = load_scene(args.scene.as_deref(), args.scale, reporter)?;
    let overrides = Overrides {
        max_patch_area: args.max_area,
        integral_steps: args.steps,
    };
    let settings = overrides.apply(file.settings);
    let mut prepared = Prepared::new(file.scene, settings, reporter).map_err(|e| match e {
        // Say where the MAX_PATCH_AREA that cannot be met came from.
        PipelineError::Mesh(
            MeshError::TooManyElements { .. } | MeshError::BadElementArea { .. },
        ) => anyhow::Error::new(e).context(max_area_origin(args)),
        e => e.into(),
    })?;
    let m = &args.method;
    warn_ignored_method_flags(m, args.steps.is_some());
    let steps = prepared.settings.integral_steps;
    prepared.method = match m.method.unwrap_or(MethodArg::Area) {
        MethodArg::Area => FormFactorMethod::AreaIntegral { steps },
        MethodArg::Contour => FormFactorMethod::Contour { steps },
        MethodArg::Analytic => FormFactorMethod::Analytic { steps },
        // --resolution (2 to 16384) and --samples (1 or more) are checked while parsing.
        MethodArg::Hemicube => FormFactorMethod::Hemicube {
            resolution: m.resolution,
        },
        MethodArg::Montecarlo => FormFactorMethod::MonteCarlo {
            samples: m.samples,
            seed: m.seed,
        },
    };
    Ok((prepared, stem))
}

/// The names of the flags given, from `(name, given)` pairs: for the warnings and errors
/// that name only the flags a user typed (QA of issue #16).
pub fn flags_given<'a>(flags: &[(&'a str, bool)]) -> Vec<&'a str> {
    flags.iter().filter(|f| f.1).map(|f| f.0).collect()
}

/// Warns (even with --quiet: the run does not do what the flags say) of the method flags
/// [`ignored_method_flags`] finds, with the methods they apply to; `render` and `bench`
/// alike (QA of issue #16: bench's warning gave no reason).
pub fn warn_ignored_method_flags(m: &MethodArgs, steps_given: bool) {
    let ignored = ignored_method_flags(m, steps_given);
    if !ignored.is_empty() {
        errln!(
            "warning: {} ignored: the form-factor method is {} (--steps applies to the area, \
             contour and analytic methods, --resolution to hemicube, --samples and --seed to \
             montecarlo)",
            ignored.join(", "),
            method_name(m.method.unwrap_or(MethodArg::Area))
        );
    }
}

/// The form-factor flags given (told from their defaults, as a flag at its default value
/// cannot be told from one left out) that the method `--method` chooses does not use:
/// `--resolution` but for the hemicube, `--samples` and `--seed` but for Monte Carlo,
/// `--steps` (`steps_given`) for those two (QA of issue #16: they were dropped without a
/// word).
pub fn ignored_method_flags(m: &MethodArgs, steps_given: bool) -> Vec<&'static str> {
    let method = m.method.unwrap_or(MethodArg::Area);
    let mut ignored = Vec::new();
    // The area, contour and analytic methods take INTEGRAL_STEPS; the other two do not.
    if matches!(method, MethodArg::Hemicube | MethodArg::Montecarlo) && steps_given {
        ignored.push("--steps");
    }
    if !matches!(method, MethodArg::Hemicube) && m.resolution != MethodArgs::RESOLUTION {
        ignored.push("--resolution");
    }
    if !matches!(method, MethodArg::Montecarlo) {
        if m.samples != MethodArgs::SAMPLES {
            ignored.push("--samples");
        }
        if m.seed != MethodArgs::SEED {
            ignored.push("--seed");
        }
    }
    ignored
}

/// The name `--method` gives `method`.
pub fn method_name(method: MethodArg) -> &'static str {
    match method {
        MethodArg::Area => "area",
        MethodArg::Contour => "contour",
        MethodArg::Analytic => "analytic",
        MethodArg::Hemicube => "hemicube",
        MethodArg::Montecarlo => "montecarlo",
    }
}

/// The numbers of the scene's flags that need no scene (`--scale`, `--max-area`,
/// `--steps`), checked before the scene is read, each refusal naming its flag (QA of issue
/// #16: `--max-area 0` was refused as "MAX_PATCH_AREA must be a positive number" and
/// `--scale 0` as "the scale", after the scene file was read, seconds on a large one).
pub fn check_scene_flags(args: &SceneArgs) -> Result<()> {
    check_scale_and_area(args.scale, args.max_area)
}

/// `--scale` and `--max-area`, checked before the scene is read ([`check_scene_flags`],
/// and `view`'s own flags).
pub fn check_scale_and_area(scale: f64, max_area: Option<f64>) -> Result<()> {
    positive(
        "--scale",
        scale,
        "the factor every coordinate is multiplied by",
    )?;
    if let Some(a) = max_area {
        positive(
            "--max-area",
            a,
            "the largest element area (scene units squared)",
        )?;
    }
    Ok(())
}

/// Refuses `value` of `flag` unless it is a finite number above 0: "--scale 0: give
/// `what`, a number above 0".
fn positive(flag: &str, value: f64, what: &str) -> Result<()> {
    if !(value > 0.0 && value.is_finite()) {
        // "a finite number" where the value is infinite (QA pass 20 of #16: `--max-area inf`
        // was told to give "a number above 0").
        bail!(
            "{flag} {}: give {what}, a {}number above 0",
            crate::report::typed(value),
            if value.is_infinite() { "finite " } else { "" }
        );
    }
    Ok(())
}

/// Hierarchical radiosity's `--epsilon` and `--min-area`, refused when they are not numbers
/// above 0, whichever solver runs (`render`, `solve`, `check` and `view` alike).
pub fn check_hierarchical_flags(epsilon: f64, min_area: Option<f64>) -> Result<()> {
    positive(
        "--epsilon",
        epsilon,
        "hierarchical radiosity's refinement threshold",
    )?;
    if let Some(a) = min_area {
        positive(
            "--min-area",
            a,
            "the smallest element area (scene units squared)",
        )?;
    }
    Ok(())
}

/// The numbers of the solver's flags that need no scene, checked before the scene is read
/// (QA of issue #16: `--epsilon -1` or `--max-shots 0` was refused only after the meshing
/// and contact refinement). A flag of a solver the run does not use is checked too: a
/// value that no solver takes is a mistake whichever runs.
pub fn check_solve_flags(options: &SolveOptions) -> Result<()> {
    if let Some(t) = options.tolerance {
        if !(t > 0.0 && t.is_finite()) {
            let t = crate::report::typed(t);
            bail!("--tolerance {t}: give where the solver stops, a number above 0");
        }
        if options.solver.0 == SolverKind::Hierarchical && t >= 1.0 {
            let t = crate::report::typed(t);
            bail!("--tolerance {t}: give hierarchical radiosity's stopping change, a number above 0 and below 1");
        }
        // A share of the emitted power of 1 or more stops progressive refinement before any
        // shot (QA of issue #16: `--tolerance 2` gave 0 shots and a black picture).
        if options.solver.0 == SolverKind::Progressive && t >= 1.0 {
            let t = crate::report::typed(t);
            bail!("--tolerance {t}: give the unshot share of the emitted power at which progressive refinement stops, a number above 0 and below 1 (0.01 is 1 %)");
        }
        // A relative residual of 1 or more stops Gauss-Seidel after one sweep (QA of issue
        // #16: `--tolerance 5` left 36 % of the light unsolved); `auto` may take either.
        if matches!(options.solver.0, SolverKind::GaussSeidel | SolverKind::Auto) && t >= 1.0 {
            let t = crate::report::typed(t);
            bail!("--tolerance {t}: give where the solver stops, a number above 0 and below 1 (Gauss-Seidel's relative residual, 1e-9 by default; hierarchical radiosity's changing power, 1e-6)");
        }
    }
    check_hierarchical_flags(options.epsilon, options.min_area)?;
    // --gather-points 0 is refused while parsing (args::parse_gather_points).
    if options.max_shots == 0 {
        bail!("--max-shots 0: give the most shots progressive radiosity takes, at least 1");
    }
    // A step is a fraction of the brighter element's luminance, so 1 or more never splits
    // (QA of issue #16: `--adapt-contrast 2` ran and reported "no visible steps").
    if !(options.adapt_contrast > 0.0 && options.adapt_contrast < 1.0) {
        bail!(
            "--adapt-contrast {}: give the step that splits, as a fraction of the brighter \
             element's luminance, a number above 0 and below 1",
            crate::report::typed(options.adapt_contrast)
        );
    }
    if options.adapt_max_elements == Some(0) {
        bail!("--adapt-max-elements 0: give the most elements adaptive subdivision may make, at least 1");
    }
    Ok(())
}

/// Where the MAX_PATCH_AREA in force came from: `--max-area`, the scene file's line
/// (`room.scene:1: MAX_PATCH_AREA 0.001`), or the built-in box.
fn max_area_origin(args: &SceneArgs) -> String {
    if let Some(a) = args.max_area {
        return format!("--max-area {}", crate::report::typed(a));
    }
    let Some(path) = args.scene.as_deref() else {
        return "the built-in Cornell box's MAX_PATCH_AREA".to_string();
    };
    if Format::of_path(path) != Some(Format::Scene) {
        return format!(
            "{}: error: the MAX_PATCH_AREA given to an imported scene (its total area / 1000)",
            path.display()
        );
    }
    // The first line that starts with the keyword (the reader has accepted the file, so it
    // is there, in its place before SCENEBEGIN).
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let line = text.lines().enumerate().find_map(|(i, l)| {
        let code = l
            .split("//")
            .next()
            .unwrap_or("")
            .trim_start_matches('\u{feff}');
        let mut words = code.split_whitespace();
        let head = words.next()?;
        head.eq_ignore_ascii_case("MAX_PATCH_AREA")
            .then(|| (i + 1, words.next().unwrap_or("").to_string()))
    });
    match line {
        // In the compiler's form of the reader's errors ("file:line: error: ..."; QA of
        // issue #16: "error: m.scene:1: MAX_PATCH_AREA" stood beside "m.scene:1:16: error:").
        Some((n, value)) => format!("{}:{n}: error: MAX_PATCH_AREA {value}", path.display()),
        None => format!("{}: error: MAX_PATCH_AREA", path.display()),
    }
}

/// The note on the scene every command prints: surfaces, elements and mesh settings.
pub fn note_scene(prepared: &Prepared, stem: &str, reporter: &Reporter) {
    reporter.note(&format!(
        "{}: {}, {} (MAX_PATCH_AREA {}, INTEGRAL_STEPS {})",
        stem,
        crate::report::count(prepared.scene.surfaces.len() as u64, "surface"),
        crate::report::count(prepared.mesh.len() as u64, "element"),
        // Six digits: an imported scene's total area / 1000 printed with seventeen was
        // noise (QA of issue #16).
        crate::report::significant(prepared.settings.max_patch_area, 6),
        prepared.settings.integral_steps
    ));
}

/// The short name of default outputs: "cornell" for the built-in box, else the scene
/// file's stem.
pub fn stem_of(scene: Option<&Path>) -> String {
    match scene {
        None => "cornell".into(),
        Some(path) => path
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned()),
    }
}

/// Refuses, before any work, to write `output` (given with `flag`) over one of the
/// `inputs` (what it is, its path): the same file by device and inode, whatever the
/// spelling (`./x.scene`, a link). The output is noted for [`refuse_outputs_read`].
pub fn refuse_overwriting_inputs(
    output: &Path,
    flag: &str,
    inputs: &[(&str, Option<&Path>)],
) -> Result<()> {
    refuse_overwriting_inputs_as(
        output,
        flag,
        &format!("{flag} {}", output.display()),
        inputs,
    )
}

/// [`refuse_overwriting_inputs`] for a file written beside the one `flag` names (a glTF's
/// `.bin`, pathtrace's `-radiosity` picture), named in messages by `label`: "-o x.gltf (its
/// buffer x.bin)" (QA of issue #16: the refusal named a file the user never typed).
pub fn refuse_overwriting_inputs_as(
    output: &Path,
    flag: &str,
    label: &str,
    inputs: &[(&str, Option<&Path>)],
) -> Result<()> {
    note_output(output, flag, label)?;
    for &(what, input) in inputs {
        if let Some(input) = input {
            if radiosity::io::is_same_file(output, input) {
                bail!(
                    "{label}: this is the {what} {}: writing it would destroy the input; \
                     give {flag} another file name",
                    input.display()
                );
            }
        }
    }
    Ok(())
}

/// An output this run will write, as [`refuse_outputs_read`] names it.
#[derive(Clone)]
struct Output {
    path: std::path::PathBuf,
    /// The flag that names it ("-o").
    flag: String,
    /// How to name it: "-o x.gltf", or "-o x.gltf (its buffer x.bin)" for a file written
    /// beside the one given.
    label: String,
}

/// The outputs [`refuse_overwriting_inputs`] was asked about, checked again against the
/// files a scene names itself once it is read ([`refuse_outputs_read`]).
static OUTPUTS: std::sync::Mutex<Vec<Output>> = std::sync::Mutex::new(Vec::new());

/// Notes `path` as an output of this run, named by `flag`, described as `label`; refuses
/// it when an output noted before is the same file, which one write would destroy (QA of
/// issue #16: `pathtrace --save-reference r.exr -o r.exr` wrote its picture over the
/// reference it had just saved).
pub fn note_output(path: &Path, flag: &str, label: &str) -> Result<()> {
    let Ok(mut outputs) = OUTPUTS.lock() else {
        return Ok(());
    };
    // The same output noted again (a command checked twice, or run again in one process,
    // as `radiosity-mpi` and the tests do) is no clash.
    let same = |o: &Output| {
        resolved(&o.path) == resolved(path) || radiosity::io::is_same_file(&o.path, path)
    };
    if outputs
        .iter()
        .any(|o| same(o) && o.flag == flag && o.label == label)
    {
        return Ok(());
    }
    if let Some(earlier) = outputs.iter().find(|o| same(o)) {
        bail!(
            "{label} is {} too: one output would overwrite the other; give {flag} another \
             file name",
            earlier.label
        );
    }
    outputs.push(Output {
        path: path.to_path_buf(),
        flag: flag.to_string(),
        label: label.to_string(),
    });
    Ok(())
}

/// Where writing `path` would write: [`lexical_absolute`], through the links that the
/// name and its folders are (QA of issue #16: `--report link.csv`, a link to the `-o`
/// file not yet written, wrote over it), whether or not the file itself exists yet.
fn resolved(path: &Path) -> std::path::PathBuf {
    let at = lexical_absolute(&radiosity::io::link_target(&lexical_absolute(path)));
    match (at.parent().map(std::fs::canonicalize), at.file_name()) {
        (Some(Ok(folder)), Some(name)) => folder.join(name),
        _ => at,
    }
}

/// `path` made absolute (against the working folder) with its `.` and `..` taken out by
/// name, so that `r.exr` and `./r.exr` compare equal before either exists (review of issue
/// #16: `is_same_file` needs both files to exist, and a first run's outputs do not).
fn lexical_absolute(path: &Path) -> std::path::PathBuf {
    use std::path::Component;
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = std::path::PathBuf::new();
    for part in absolute.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// Refuses, right after the scene is read and before any work, an output that is a file
/// the scene named and was read with it: an OBJ's MTL, a glTF's buffer, a DXF's materials
/// (QA of issue #16: `export scene.gltf -o copy.gltf`, its buffer `copy.bin` one the scene
/// read, was refused only when written, after the solve; nothing was overwritten).
pub fn refuse_outputs_read(scene: &Path) -> Result<()> {
    let outputs = OUTPUTS.lock().map(|o| o.clone()).unwrap_or_default();
    for Output { path, flag, label } in outputs {
        if let Some(input) = radiosity::io::input_at(&path) {
            bail!(
                "{label}: {} is a file the scene {} reads; writing it would destroy the \
                 input; give {flag} another file name",
                input.display(),
                scene.display()
            );
        }
    }
    Ok(())
}

/// What the illuminance figures of `illuminance` and `render --false-colour` are in. The
/// light of emitting surfaces reaches a point through form factors, which have no unit, so
/// it is in the emission's units whatever the length unit; only point luminaires (I / d^2)
/// and `FLUX` (lumens over an area) depend on lengths (QA of issue #16: the note said lux
/// needed lengths in metres, which the Cornell box in millimetres seemed to break).
pub const LUX_NOTE: &str = "lux where Er Eg Eb are in lm/m^2, whatever the length unit; \
                            point luminaires and FLUX need lengths in metres (--scale)";

/// The length unit of the scene [`load_scene`] read last, in the reader's words (with
/// `--scale`), for the reports that give lengths or areas.
static SCENE_UNIT: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// The length unit of the scene read ([`SCENE_UNIT`]); `scene units` before one is read.
pub fn scene_unit() -> String {
    SCENE_UNIT
        .lock()
        .ok()
        .and_then(|u| u.clone())
        .unwrap_or_else(|| "scene units".to_string())
}

/// The note on the unit of the scene [`load_scene`] read last ([`millimetres_perhaps`]),
/// for `check`'s report, whose reporter prints no notes.
static UNIT_NOTE: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// The note on the scene's unit, if it has one.
pub fn unit_note() -> Option<String> {
    UNIT_NOTE.lock().ok().and_then(|n| n.clone())
}

fn note_unit(unit: &str) {
    if let Ok(mut u) = SCENE_UNIT.lock() {
        *u = Some(unit.to_string());
    }
}

/// The scene file at `path` (any format [`radiosity::io::import`] reads, by extension; every
/// coordinate times `scale`), or the built-in Cornell box, with a short name for default
/// outputs ("cornell", or the file's stem). The reader's warnings are printed (even with
/// --quiet: they say what of the file was left out), and the scene's unit noted.
pub fn load_scene(
    path: Option<&Path>,
    scale: f64,
    reporter: &Reporter,
) -> Result<(SceneFile, String)> {
    match path {
        None => {
            if scale != 1.0 {
                bail!(
                    "--scale applies to a scene file; the built-in Cornell box is in millimetres \
                     (examples/cornell_box.scene --scale 0.001 reads the same box in metres)"
                );
            }
            note_unit("millimetres (the built-in Cornell box)");
            Ok((
                run_stage(reporter, Stage::Parse, 0, scene::cornell_box),
                "cornell".to_string(),
            ))
        }
        Some(path) => {
            let options = ImportOptions {
                scale,
                settings: None,
            };
            let imported = run_file_stage(reporter, Stage::Parse, path, || {
                read_any_scene(path, &options)
            })?;
            for w in &imported.warnings {
                errln!("{}", crate::errors::plain_io_words(&w.to_string()));
            }
            reporter.note(&format!(
                "{}: read as {}; unit: {}",
                path.display(),
                imported.format,
                imported.unit
            ));
            note_unit(&imported.unit);
            refuse_outputs_read(path)?;
            // A note, as -q's help says notes are left out (QA of issue #16).
            let unit_note = millimetres_perhaps(&imported.file.scene, &imported.unit, scale);
            if let Some(n) = &unit_note {
                reporter.note(&format!("{}: note: {n}", path.display()));
            }
            if let Ok(mut slot) = UNIT_NOTE.lock() {
                *slot = unit_note;
            }
            if let Some(w) = far_from_origin(&imported.file.scene) {
                errln!("{}: warning: {w}", path.display());
            }
            if let Some(w) = no_emitter(&imported.file.scene, imported.format) {
                errln!("{}: warning: {w}", path.display());
            }
            for w in sideways_lights(&imported.file.scene) {
                errln!("{}: warning: {w}", path.display());
            }
            if let Some(w) = unnamed_surfaces(&imported.file.scene) {
                errln!("{}: warning: {w}", path.display());
            }
            // The importers number their faces' names; a scene file's are the user's own.
            if imported.format == Format::Scene {
                if let Some(w) = shared_names(&imported.file.scene) {
                    errln!("{}: warning: {w}", path.display());
                }
            }
            Ok((imported.file, stem_of(Some(path))))
        }
    }
}

/// A warning for surfaces whose name is empty (a bare `#` line): the reports' rows and an
/// export name them otherwise (QA of issue #16: the `--report` CSV row began with an empty
/// field, and `export` called the surface "surface6").
pub fn unnamed_surfaces(scene: &Scene) -> Option<String> {
    let unnamed: Vec<String> = scene
        .surfaces
        .iter()
        .enumerate()
        .filter(|(_, s)| s.name.is_empty())
        .map(|(i, _)| i.to_string())
        .collect();
    if unnamed.is_empty() {
        return None;
    }
    Some(format!(
        "{} no name (an empty # line): {} {}; reports show an empty name for {} and exports \
         call {} \"surfaceN\"; give each a name after its #",
        if unnamed.len() == 1 {
            "a surface has"
        } else {
            "surfaces have"
        },
        if unnamed.len() == 1 {
            "surface"
        } else {
            "surfaces"
        },
        crate::report::first_three(&unnamed),
        if unnamed.len() == 1 { "it" } else { "them" },
        if unnamed.len() == 1 { "it" } else { "them" },
    ))
}

/// A warning for surfaces that share a name (QA of issue #16: two patches named `#A` gave
/// two report rows called "A", and `view --select A` could pick either).
pub fn shared_names(scene: &Scene) -> Option<String> {
    let mut first: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    let mut shared = Vec::new();
    for (i, s) in scene.surfaces.iter().enumerate() {
        if s.name.is_empty() {
            continue;
        }
        match first.get(s.name.as_str()) {
            Some(&j) => shared.push(format!("{:?} (surfaces {j} and {i})", s.name)),
            None => {
                first.insert(&s.name, i);
            }
        }
    }
    if shared.is_empty() {
        return None;
    }
    Some(format!(
        "{} a name with an earlier surface: {}; reports show them as rows of one name and \
         `view --select` picks the first; give each its own name",
        if shared.len() == 1 {
            "a surface shares"
        } else {
            "surfaces share"
        },
        crate::report::first_three(&shared)
    ))
}

/// Warnings for luminaires with a shaped distribution (COSINE, IES) aimed along the default
/// AIM 0 0 -1 that hang in the top quarter of the scene's y extent and not of its z extent
/// (a y-up scene, where -z is horizontal): a downlight left at the default aim in a y-up
/// room lights a wall (QA of issue #16: `check` said all its lumens land and nothing more).
/// The default, straight down in a z-up scene, is the format's; an aim written as 0 0 -1 on
/// purpose is warned of too, which AIM 0 0 -1.0001 silences.
pub fn sideways_lights(scene: &Scene) -> Vec<String> {
    // Where the light hangs says which way is up (review of issue #16: the largest polygon,
    // or the area facing each axis, took a z-up corridor's walls for floors).
    if scene.surfaces.is_empty() {
        return Vec::new();
    }
    let bounds = scene.bounds();
    let near_top = |p: DVec3, axis: usize| radiosity::render::in_top_quarter(bounds, p, axis);
    scene
        .lights
        .iter()
        .filter(|l| {
            !matches!(
                l.distribution,
                radiosity::luminaire::Distribution::Isotropic
            ) && l.aim == radiosity::luminaire::DEFAULT_AIM
                && near_top(l.position, 1)
                && !near_top(l.position, 2)
        })
        .map(|l| {
            format!(
                "light {:?} is aimed along AIM 0 0 -1 (the default: straight down in a z-up \
                 scene), which is horizontal here, where it hangs near the top of the y \
                 extent (y up); for a downlight in a y-up scene give AIM 0 -1 0",
                l.name
            )
        })
        .collect()
}

/// A warning when nothing in `scene` emits light (QA of issue #16: such a scene rendered
/// black without a word): no surface emits in any band and no point luminaire gives light
/// (a `FLUX 0` or black `COLOUR` gives none), with what would emit in a file of `format`.
pub fn no_emitter(scene: &Scene, format: Format) -> Option<String> {
    let emits = scene
        .surfaces
        .iter()
        .any(|s| s.emission.0.iter().any(|&e| e > 0.0))
        || scene.lights.iter().any(|l| l.gives_light());
    if emits || scene.surfaces.is_empty() {
        return None;
    }
    let would_emit = match format {
        Format::Scene => {
            "a surface with Er, Eg or Eb above 0, LUMINANCE or FLUX, or a LIGHTBEGIN block"
        }
        Format::Obj => "a material with Ke above 0 in the MTL file",
        Format::Gltf | Format::Glb => "a material with an emissiveFactor above 0",
        Format::Dxf => "a layer with an emission above 0 in NAME.materials.toml",
        Format::Vrml => "a Material with an emissiveColor above 0",
    };
    Some(format!(
        "nothing in the scene emits light, so every radiosity is 0 and pictures are black; \
         give it {would_emit}"
    ))
}

/// How far, in units of its own size, a scene may lie from the origin before precision runs
/// out (single precision in parts of the ray casting, not yet pinned down): measured on a 4 x 4 x 3 m room shifted along x, 1e7
/// m (2e6 sizes) rendered within 2 / 255 of the unshifted room, 1e9 m (2e8) had pixels 45
/// / 255 off, 3e9 m blotches, 1e10 m lost 28 % of its light.
const FAR_FROM_ORIGIN: f64 = 1e7;

/// Above this area in square metres one surface of a scene read as metres is more likely
/// a model in millimetres: a face 140 m square (the Cornell box in millimetres has faces
/// of 310,000 "m^2"; a generated building of any size has none above some 40 m^2, so a
/// large building does not set it off, where a size across would).
const LARGER_THAN_A_SURFACE_M2: f64 = 20_000.0;

/// A note when a scene read as metres, unscaled, has a surface larger than any building's
/// (QA of issue #16: examples/cornell_box.scene, in millimetres, was reported as 1874940
/// m^2 without a word).
fn millimetres_perhaps(scene: &radiosity::scene::Scene, unit: &str, scale: f64) -> Option<String> {
    if scale != 1.0 || !unit.starts_with("metres") {
        return None;
    }
    let largest = scene
        .surfaces
        .iter()
        .map(|s| radiosity::geometry::polygon_area(&s.vertices))
        .fold(0.0, f64::max);
    if largest <= LARGER_THAN_A_SURFACE_M2 {
        return None;
    }
    // Whether the light itself depends on the unit: point luminaires' I / d^2 and FLUX's
    // lumens over an area do; exitances and luminances given as such do not (QA of issue
    // #16: the note read as an alarm on the shipped examples/cornell_box.scene, whose light
    // is the same in any unit).
    use radiosity::scene::EmissionGiven;
    let light_depends = !scene.lights.is_empty()
        || scene.surfaces.iter().any(|s| {
            matches!(
                s.photometry.emission,
                EmissionGiven::Flux(_) | EmissionGiven::FluxShare
            )
        });
    let consequence = if light_depends {
        "its point luminaires' and FLUX surfaces' light assumes metres"
    } else {
        "the light does not depend on it here, with no point luminaires or FLUX; only \
         areas and powers in m^2 do"
    };
    // Three significant digits, as `check`'s areas: no 46 digits of a float for a model
    // scaled by 1e20 (QA pass 16 of #16: "3082310488436984963922169586038057680706207744
    // m^2").
    Some(format!(
        "the largest surface is {} m^2 read as metres; if the numbers are millimetres, \
         --scale 0.001 reads them as metres; {consequence}",
        crate::report::significant(largest, 3)
    ))
}

/// A warning when `scene` lies more than [`FAR_FROM_ORIGIN`] times its size from the
/// origin (a model in millimetres at map coordinates): its light would be silently wrong.
fn far_from_origin(scene: &radiosity::scene::Scene) -> Option<String> {
    if scene.surfaces.is_empty() {
        return None;
    }
    let (lo, hi) = scene.bounds();
    let size = (hi - lo).length();
    let centre = 0.5 * (lo + hi);
    let ratio = centre.length() / size;
    (ratio > FAR_FROM_ORIGIN).then(|| {
        format!(
            "the scene lies {:.3e} units from the origin, {ratio:.1e} times its own size \
             ({size:.3e}); scenes more than {FAR_FROM_ORIGIN:.0e} times their size out were \
             measured to render wrong (blotches, light lost: precision runs out); move the \
             model near the origin (subtract about {:.3e}, {:.3e}, {:.3e} from its \
             coordinates)",
            centre.length(),
            centre.x,
            centre.y,
            centre.z
        )
    })
}

/// The solver the options ask for; `auto` is decided from the element count `n` and the
/// memory available, and the choice and its reason are noted.
fn solver(
    options: &SolveOptions,
    n: usize,
    max_patch_area: f64,
    reporter: &Reporter,
) -> Result<Solver> {
    // The numbers alone were checked before the scene was read (check_solve_flags).
    let choice = match options.solver.0 {
        SolverKind::Auto if options.form_factors.is_some() => {
            let file = options.form_factors.as_deref().unwrap_or(Path::new(""));
            reporter.note(&format!(
                "solver auto: Gauss-Seidel on the dense matrix of the form factors in {} \
                 (--form-factors)",
                file.display()
            ));
            SolverKind::GaussSeidel
        }
        SolverKind::Auto => {
            let choice =
                radiosity::solve::choose(n, radiosity::form_factor::available_memory_bytes());
            reporter.note(&format!("solver auto: {choice}"));
            choice.kind()
        }
        other => other,
    };
    // Flags of one solver given to another: said, as --tolerance with LU is (QA of issue
    // #16: they were dropped without a word). A flag at its default value is not told apart
    // from one left out.
    let mut hierarchical = Vec::new();
    if choice != SolverKind::Hierarchical {
        if options.epsilon != radiosity::solve::HierarchicalSettings::DEFAULT_EPSILON {
            hierarchical.push("--epsilon");
        }
        if options.min_area.is_some() {
            hierarchical.push("--min-area");
        }
        if options.no_final_gather {
            hierarchical.push("--no-final-gather");
        }
        if options.gather_points != radiosity::solve::GATHER_POINTS_DEFAULT {
            hierarchical.push("--gather-points");
        }
    }
    let progressive = choice != SolverKind::Progressive
        && options.max_shots != radiosity::solve::ProgressiveSettings::default().max_shots;
    // Each flag's solver named for the flags given, not for all the flags of the command
    // (QA of issue #16: bench's warning named --no-final-gather, which bench has not).
    let mut why = Vec::new();
    if !hierarchical.is_empty() {
        why.push(format!(
            "{} {} to hierarchical radiosity",
            crate::report::and_list(&hierarchical),
            if hierarchical.len() == 1 {
                "applies"
            } else {
                "apply"
            }
        ));
    }
    if progressive {
        why.push("--max-shots applies to progressive refinement".to_string());
    }
    if !why.is_empty() {
        let mut ignored = hierarchical.clone();
        if progressive {
            ignored.push("--max-shots");
        }
        // Printed even with --quiet: the run does not do what the flags say.
        errln!(
            "warning: {} ignored: the solver is {} ({})",
            ignored.join(", "),
            choice.name(),
            why.join("; ")
        );
    }
    if choice == SolverKind::Hierarchical
        && options.no_final_gather
        && options.gather_points != radiosity::solve::GATHER_POINTS_DEFAULT
    {
        errln!("warning: --gather-points ignored: --no-final-gather leaves the gather out");
    }
    Ok(match choice {
        SolverKind::Auto => unreachable!("auto is resolved above"),
        SolverKind::Lu => {
            if options.tolerance.is_some() {
                // Printed even with --quiet: the run does not do what the flags say.
                errln!("warning: --tolerance ignored: the LU solver solves directly, to rounding");
            }
            Solver::LU
        }
        SolverKind::GaussSeidel => Solver::Dense(radiosity::solve::DenseSolver::GaussSeidel(
            GaussSeidelSettings {
                tolerance: options.tolerance.unwrap_or(1e-9),
                ..GaussSeidelSettings::default()
            },
        )),
        SolverKind::Progressive => {
            // --form-factors with it is refused before the scene is read.
            Solver::Progressive(ProgressiveSettings {
                tolerance: options
                    .tolerance
                    .unwrap_or(radiosity::solve::DEFAULT_PROGRESSIVE_TOLERANCE),
                max_shots: options.max_shots,
            })
        }
        SolverKind::Hierarchical => {
            // --form-factors with it is refused before the scene is read.
            let min_area = options.min_area.unwrap_or(max_patch_area / 16.0);
            // The flags' numbers were checked before the scene was read; the tolerance's
            // upper bound is checked here too, where `auto` chose hierarchical radiosity.
            let tolerance = options
                .tolerance
                .unwrap_or(radiosity::solve::DEFAULT_HIERARCHICAL_TOLERANCE);
            if !(tolerance > 0.0 && tolerance < 1.0) {
                let tolerance = crate::report::typed(tolerance);
                bail!("--tolerance {tolerance}: give hierarchical radiosity's stopping change, a number above 0 and below 1");
            }
            Solver::Hierarchical(radiosity::solve::HierarchicalSettings {
                epsilon: options.epsilon,
                min_area,
                tolerance,
                max_memory_bytes: None,
                final_gather: !options.no_final_gather,
                gather_points: options.gather_points,
            })
        }
    })
}

pub fn render_settings(args: &RenderArgs) -> Result<RenderSettings> {
    image_format(args.output.as_deref())?;
    let (width, height) = args.camera.size();
    image_size(width, height)?;
    check_render_budget(
        &args.camera,
        args.rays.supersample,
        false,
        args.scene.no_work_limit,
    )?;
    let gamma = gamma(&args.tone)?;
    Ok(RenderSettings {
        gamma,
        ..ray_settings(&args.rays, args.shading)
    })
}

/// Refuses, before any work, a render whose film would not fit in memory (`whole_film`: all
/// of it at once, as the path tracer's comparison keeps it), or (unless `no_work_limit`)
/// whose camera rays pass the work limit.
pub fn check_render_budget(
    camera: &CameraArgs,
    supersample: u32,
    whole_film: bool,
    no_work_limit: bool,
) -> Result<()> {
    let (w, h) = camera.size();
    radiosity::budget::check_render_memory(
        w,
        h,
        supersample,
        whole_film,
        radiosity::form_factor::available_memory_bytes(),
    )?;
    if !no_work_limit {
        radiosity::budget::check_render_work(w, h, supersample)?;
    }
    Ok(())
}

/// The render settings `--supersample`, `--adaptive-contrast`, `--direct-light` and
/// `--shading` ask for (exposure and gamma at their defaults).
pub fn ray_settings(rays: &RayArgs, shading_arg: ShadingArg) -> RenderSettings {
    let n = rays.supersample;
    let adaptive = n > 2 && n % 2 == 0 && shading_arg != ShadingArg::Wireframe;
    if !adaptive && rays.adaptive_contrast != RayArgs::ADAPTIVE_CONTRAST {
        // Printed even with --quiet: the run does not do what the flags say.
        // The reason that holds (QA of issue #16: a wireframe's warning pointed at
        // --supersample 8, which is even).
        if shading_arg == ShadingArg::Wireframe {
            errln!(
                "warning: --adaptive-contrast ignored: a wireframe is drawn without adaptive \
                 antialiasing (it takes smooth or flat shading)"
            );
        } else {
            errln!(
                "warning: --adaptive-contrast ignored: adaptive antialiasing takes an even \
                 --supersample above 2 (given {n})"
            );
        }
    }
    if rays.direct_light.is_some() && shading_arg != ShadingArg::Smooth {
        // QA of issue #16: --direct-light mesh with --shading flat ran without a word (and
        // `gather`, the default given explicitly, until QA pass 12).
        errln!(
            "warning: --direct-light ignored: it chooses smooth shading's direct light, and \
             --shading {}",
            match shading_arg {
                ShadingArg::Flat => "flat draws each element's own radiosity",
                // QA of issue #16: wireframe draws white edges, not radiosity.
                _ => "wireframe draws the elements' edges",
            }
        );
    }
    RenderSettings {
        shading: shading(shading_arg),
        supersample: rays.supersample,
        adaptive_contrast: (rays.adaptive_contrast > 0.0).then_some(rays.adaptive_contrast),
        direct_light: rays.direct_light() == DirectLightArg::Gather,
        ..RenderSettings::default()
    }
}

/// The library's shading for `--shading`.
pub fn shading(arg: ShadingArg) -> Shading {
    match arg {
        ShadingArg::Smooth => Shading::Smooth,
        ShadingArg::Flat => Shading::Flat,
        ShadingArg::Wireframe => Shading::Wireframe,
    }
}

/// How an output image is written, by its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// `*.png`: exposed, clamped, gamma-corrected 8-bit colour.
    Png,
    /// `*.exr`: linear radiance (radiosity / pi), no exposure, clamping or gamma.
    Exr,
}

/// The format of an output image by its extension (any case); PNG when no output is
/// named. Refuses any other name.
pub fn image_format(output: Option<&Path>) -> Result<ImageFormat> {
    let Some(out) = output else {
        return Ok(ImageFormat::Png);
    };
    only_an_extension(out, "-o")?;
    if out.is_dir() {
        bail!(
            "-o {}: is a folder; give the image a file name in it, ending .png \
             (tone-mapped) or .exr (linear radiance)",
            out.display()
        );
    }
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("png") => Ok(ImageFormat::Png),
        Some("exr") => Ok(ImageFormat::Exr),
        _ => bail!(
            "-o {}: images are written as PNG (tone-mapped) or OpenEXR (linear radiance); \
             give it a .png name, or .exr for linear radiance",
            out.display()
        ),
    }
}

/// Refuses a file name that is only an extension (`-o .png`: a hidden file with no
/// extension, which the extension check refused with advice it already followed; QA of
/// issue #16).
fn only_an_extension(output: &Path, flag: &str) -> Result<()> {
    let name = output
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if name.starts_with('.') && name.len() > 1 && output.extension().is_none() {
        bail!(
            "{flag} {}: the name is only an extension; give a name before it (room{name})",
            output.display()
        );
    }
    Ok(())
}

/// Refuses, before any work, an output named with none of the `extensions` (any case) it
/// can be written as (QA of issue #16: `solve -o x.txt` wrote CSV into it without a word,
/// an extensionless name too). `flag` names the option, `what` what is written.
pub fn output_extension(output: &Path, flag: &str, what: &str, extensions: &[&str]) -> Result<()> {
    only_an_extension(output, flag)?;
    let ext = output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if ext.as_deref().is_some_and(|e| extensions.contains(&e)) {
        return Ok(());
    }
    let names: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
    let names = match names.as_slice() {
        [one] => one.clone(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
        [] => String::new(),
    };
    bail!(
        "{flag} {}: {what}; give it a {names} name",
        output.display()
    )
}

/// Refuses, before any work, an output that cannot be written: named with none of the
/// `extensions` ([`output_extension`]), in a directory that does not exist, a directory
/// itself, or one of the `inputs` ([`refuse_overwriting_inputs`]). Every command that
/// writes a file checks its name so, and so does `radiosity-mpi` before any rank reads the
/// scene. `flag` names the option, `what` what is written.
pub fn check_output(
    output: &Path,
    flag: &str,
    what: &str,
    extensions: &[&str],
    inputs: &[(&str, Option<&Path>)],
) -> Result<()> {
    refuse_overwriting_inputs(output, flag, inputs)?;
    // A folder is named as one before its (missing) extension is (QA of issue #16).
    output_directory(output, flag)?;
    output_extension(output, flag, what, extensions)
}

/// Refuses an output whose directory does not exist or that is a directory (QA of issue
/// #16: `solve -o nowhere/x.csv` solved the scene, then failed to write).
pub fn output_directory(output: &Path, flag: &str) -> Result<()> {
    if output.is_dir() {
        bail!(
            "{flag} {}: is a folder; give a file name in it",
            output.display()
        );
    }
    parent_folder_exists(output, flag)?;
    // A folder that exists but cannot be written in (QA of issue #16: found only after the
    // render, with the temporary file's name).
    if let Err(e) = radiosity::io::check_writable(output) {
        bail!("{flag} {}: cannot write there: {}", output.display(), e);
    }
    Ok(())
}

/// Refuses `path` (given with `flag`) whose folder does not exist: no output makes the
/// folders above it (a file's, or a folder's that a command creates itself).
pub fn parent_folder_exists(path: &Path, flag: &str) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => return Ok(()),
    };
    if !dir.is_dir() {
        bail!(
            "{flag} {}: the directory {} does not exist; create it first (mkdir -p {})",
            path.display(),
            dir.display(),
            dir.display()
        );
    }
    Ok(())
}

/// `--gamma`, checked.
pub fn gamma(args: &ToneArgs) -> Result<f64> {
    if !(args.gamma > 0.0 && args.gamma.is_finite()) {
        bail!(
            "--gamma {}: give the gamma (displayed = value^(1/gamma)), a number above 0",
            crate::report::typed(args.gamma)
        );
    }
    Ok(args.gamma)
}

/// Refuses an image with no pixels or more than 100 megapixels (`render`, `pathtrace` and
/// `bench` alike; QA of issue #16: bench capped each side at 10,000 where render did not).
pub fn image_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 {
        bail!("--width {width} --height {height}: give image sides of at least 1 pixel");
    }
    if (width as u64) * (height as u64) > 100_000_000 {
        bail!("an image of {width} x {height} pixels is too large (at most 100 megapixels)");
    }
    Ok(())
}

/// Refuses, before the scene is read, the camera flags that are wrong whatever the scene:
/// the image size, `--fov` outside (0, 180), a zero or infinite `--up`, `--eye` equal to
/// `--look-at` (QA of issue #16: these came after the scene was read and meshed, where
/// `--gamma` and `--exposure` came before). [`camera`] checks them again with the scene.
pub fn check_camera_flags(args: &CameraArgs) -> Result<()> {
    let (width, height) = args.size();
    image_size(width, height)?;
    if let Some(fov) = args.fov {
        if !(fov > 0.0 && fov < 180.0) {
            let fov = crate::report::typed(fov);
            bail!("--fov {fov}: give the vertical field of view in degrees, above 0 and below 180");
        }
    }
    if let Some(up) = args.up {
        if !(up.length().is_finite() && up.length() > 0.0) {
            bail!(
                "--up {},{},{}: give a direction of finite, non-zero length",
                crate::report::typed(up.x),
                crate::report::typed(up.y),
                crate::report::typed(up.z)
            );
        }
    }
    if let (Some(eye), Some(at)) = (args.eye, args.look_at) {
        if eye == at {
            bail!("--eye and --look-at must differ");
        }
    }
    Ok(())
}

/// The camera as flags that give it back, when any of --eye, --look-at and --fov was left
/// to the scene (QA of issue #16: the automatic camera was never printed, so a user could
/// not move it a little): "--eye X,Y,Z --look-at X,Y,Z --up X,Y,Z --fov D".
pub fn camera_note(args: &CameraArgs, camera: &Camera, scene: &Scene) -> Option<String> {
    if args.eye.is_some() && args.look_at.is_some() && args.fov.is_some() {
        return None;
    }
    let v = |p: DVec3| {
        format!(
            "{},{},{}",
            crate::report::significant(p.x, 6),
            crate::report::significant(p.y, 6),
            crate::report::significant(p.z, 6)
        )
    };
    Some(format!(
        "camera --eye {} --look-at {} --up {} --fov {} ({}; give these flags to move it)",
        v(camera.eye),
        v(camera.look_at),
        v(camera.up),
        crate::report::significant(camera.fov_y_degrees, 4),
        match (
            scene.camera.is_some(),
            args.eye.is_some() || args.look_at.is_some() || args.up.is_some() || args.fov.is_some(),
        ) {
            (true, false) => "the scene's own",
            (false, false) => "chosen to frame the scene",
            // QA of issue #16: "chosen to frame the scene, with the camera flags given" when
            // only the field of view was chosen.
            (true, true) => "the camera flags given, the rest the scene's own",
            (false, true) => "the camera flags given, the rest chosen to frame the scene",
        }
    ))
}

/// The camera the flags ask for: the scene's (or one that frames it) at `--width` x
/// `--height`, with `--eye`, `--look-at`, `--up` and `--fov` put in.
pub fn camera(args: &CameraArgs, scene: &Scene) -> Result<Camera> {
    let (width, height) = args.size();
    image_size(width, height)?;
    let mut camera = Camera::for_scene(scene, width, height);
    if let Some(eye) = args.eye {
        camera.eye = eye;
    }
    if let Some(at) = args.look_at {
        camera.look_at = at;
    }
    if let Some(up) = args.up {
        camera.up = up;
    }
    if let Some(fov) = args.fov {
        if !(fov > 0.0 && fov < 180.0) {
            let fov = crate::report::typed(fov);
            bail!("--fov {fov}: give the vertical field of view in degrees, above 0 and below 180");
        }
        camera.fov_y_degrees = fov;
    }
    let forward = camera.look_at - camera.eye;
    if forward.length() == 0.0 {
        bail!("--eye and --look-at must differ");
    }
    // Beyond 1e9 scene sizes a ray's hit point carries less than 1e-7 of the scene in
    // f64 (16 digits), and past 1e154 the distance itself overflows: neither is "parallel".
    let (lo, hi) = scene.bounds();
    let size = (hi - lo).length();
    let size = if size.is_finite() && size > 0.0 {
        size
    } else {
        1.0
    };
    let reach = 1e9 * size;
    let far = |p: DVec3| -> bool {
        let d = (p - (lo + hi) * 0.5).length();
        !d.is_finite() || d > reach
    };
    for (flag, point, given) in [
        ("--eye", camera.eye, args.eye.is_some()),
        ("--look-at", camera.look_at, args.look_at.is_some()),
    ] {
        // A point the automatic camera chose (QA pass 15 of issue #16: a scene 1e-20 m
        // across was told "--eye ... is out of range" without any --eye given).
        // The scene file's own camera, where it has one, else the automatic camera
        // (review: a file's far camera was called automatic).
        if far(point) && !given {
            bail!(
                "{} cannot frame this scene: it is {} across, and its {} \
                 ({},{},{}) lands farther than 1e9 times that from its centre, where rays \
                 lose their precision; give --eye and --look-at, or --scale to bring the \
                 scene's numbers nearer to 1",
                if scene.camera.is_some() {
                    "the scene file's own camera"
                } else {
                    "the automatic camera"
                },
                crate::report::significant(size, 4),
                if flag == "--eye" {
                    "eye"
                } else {
                    "look-at point"
                },
                crate::report::typed(point.x),
                crate::report::typed(point.y),
                crate::report::typed(point.z),
            );
        }
        if far(point) {
            bail!(
                "{flag} {},{},{} is out of range: farther than {} (1e9 times the scene's size, \
                 {}) from the scene's centre, where rays lose their precision; bring it closer \
                 (a larger --fov frames the scene from nearer)",
                crate::report::typed(point.x),
                crate::report::typed(point.y),
                crate::report::typed(point.z),
                crate::report::significant(reach, 4),
                crate::report::significant(size, 4)
            );
        }
    }
    if !(camera.up.length().is_finite()) {
        bail!(
            "--up {},{},{}: give a direction of finite, non-zero length",
            crate::report::typed(camera.up.x),
            crate::report::typed(camera.up.y),
            crate::report::typed(camera.up.z)
        );
    }
    if forward
        .normalize()
        .cross(camera.up.normalize_or_zero())
        .length()
        <= 1e-12
    {
        // QA of issue #16: with no --up given, the message blamed a flag never typed.
        match args.up {
            Some(up) => bail!(
                "--up {},{},{}: give a direction not parallel to the view (from --eye to \
                 --look-at)",
                crate::report::typed(up.x),
                crate::report::typed(up.y),
                crate::report::typed(up.z)
            ),
            None => bail!(
                "the camera's up direction ({},{},{}; no --up was given) is parallel to the \
                 view from the eye to the look-at point; give --up, e.g. --up 0,0,1",
                crate::report::typed(camera.up.x),
                crate::report::typed(camera.up.y),
                crate::report::typed(camera.up.z)
            ),
        }
    }
    Ok(camera)
}

/// The adaptive subdivision `options` ask for on the prepared mesh, for `solver`: `None`
/// for the solvers that do not take it (progressive, hierarchical), with form factors read
/// from a file, or with 0 rounds.
pub fn adapt(
    options: &SolveOptions,
    prepared: &Prepared,
    solver: &Solver,
) -> Result<Option<AdaptSettings>> {
    let rounds = options.adapt_rounds.unwrap_or(DEFAULT_ADAPT_ROUNDS);
    // The tuning flags given (a value other than the default: clap does not say whether
    // the default was typed).
    let mut tuning = Vec::new();
    if options.adapt_contrast != radiosity::mesh::DEFAULT_CONTRAST {
        tuning.push("--adapt-contrast");
    }
    if options.adapt_max_elements.is_some() {
        tuning.push("--adapt-max-elements");
    }
    // Printed even with --quiet: the run does not do what the flags say.
    if !solver.needs_matrix() && options.adapt_rounds.is_some_and(|r| r > 0) {
        errln!(
            "warning: --adapt-rounds{} ignored: adaptive subdivision refines the dense \
             solvers' mesh (choose --solver gauss-seidel or lu)",
            tuning.iter().map(|f| format!(", {f}")).collect::<String>()
        );
    } else if rounds == 0 && !tuning.is_empty() {
        // QA of issue #16: --adapt-contrast alone ran without a word.
        errln!(
            "warning: {} ignored: adaptive subdivision is off (it takes --adapt-rounds N, N \
             above 0)",
            tuning.join(" and ")
        );
    }
    if !solver.needs_matrix() || rounds == 0 {
        return Ok(None);
    }
    if options.form_factors.is_some() {
        if options.adapt_rounds.is_some_and(|r| r > 0) {
            bail!("--adapt-rounds cannot be used with --form-factors: adaptive subdivision computes the form factors of the meshes it makes");
        }
        return Ok(None);
    }
    let defaults = AdaptSettings::defaults(
        prepared.mesh.len(),
        prepared.settings.max_patch_area,
        rounds,
    );
    // A budget below the first mesh could split nothing (QA of issue #16: `10` was taken
    // and the rounds stopped "at the most elements allowed, 10").
    if let Some(max) = options.adapt_max_elements {
        let n = prepared.mesh.len();
        if max < n + 3 {
            bail!(
                "--adapt-max-elements {max}: the first mesh already has {} and each split adds \
                 3; give at least {}",
                crate::report::count(n as u64, "element"),
                n + 3
            );
        }
    }
    Ok(Some(match options.adapt_max_elements {
        // Given, only this limit holds.
        Some(max_elements) => AdaptSettings {
            contrast: options.adapt_contrast,
            max_elements,
            max_new_pairs: u64::MAX,
            ..defaults
        },
        None => AdaptSettings {
            contrast: options.adapt_contrast,
            ..defaults
        },
    }))
}

/// Rounds of adaptive subdivision when `--adapt-rounds` is not given: none. Against the
/// path tracer (BENCHMARKS.md) two rounds take examples/room.scene from 4.24 % to 2.81 %
/// pixel RMS, leave the Cornell box where it was (2.44 % -> 2.43 %, twice the time), and make
/// building_small worse (5.18 % -> 5.56 %, 3 x the time): its refined elements among the
/// bookcases and chairs inherit the area method's over-counted near pairs (rows up to
/// 1.13), and the whole picture gets brighter. Until that is fixed it is asked for.
pub const DEFAULT_ADAPT_ROUNDS: u32 = 0;

#[cfg(test)]
mod tests {
    use super::*;

    /// One square of `side` metres, lit.
    fn square(side: f64) -> Scene {
        let v = |x: f64, z: f64| glam::DVec3::new(x, 0.0, z);
        Scene {
            surfaces: vec![radiosity::scene::Surface {
                name: "floor".into(),
                vertices: vec![v(0.0, 0.0), v(side, 0.0), v(side, side), v(0.0, side)],
                reflectance: radiosity::scene::Rgb([0.5; 3]),
                emission: radiosity::scene::Rgb([1.0; 3]),
                photometry: Default::default(),
            }],
            camera: None,
            lights: Vec::new(),
        }
    }

    #[test]
    fn a_huge_surface_is_noted_in_three_digits_not_fifty() {
        // QA pass 16 of #16: a glTF scaled by 1e20 was noted as "the largest surface is
        // 3082310488436984963922169586038057680706207744 m^2". A square of 5.552e22 m has
        // 3.0825e45 m^2.
        let note = millimetres_perhaps(&square(5.552e22), "metres", 1.0).unwrap();
        assert!(
            note.starts_with("the largest surface is 3.08e45 m^2 read as metres"),
            "{note}"
        );
        // An everyday millimetre model keeps its whole number: 1,000 m square.
        let note = millimetres_perhaps(&square(1000.0), "metres", 1.0).unwrap();
        assert!(
            note.starts_with("the largest surface is 1000000 m^2 read as metres"),
            "{note}"
        );
    }
}
