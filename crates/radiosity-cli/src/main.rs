//! `radiosity`: the command-line program. A thin layer over the `radiosity` library:
//! parse the arguments, run the pipeline, report progress and timings.
//!
//! The modules live in the library (src/lib.rs), shared with `radiosity-mpi`.

#[macro_use]
extern crate radiosity_cli;

use radiosity_cli::{args, commands, errors};

use std::process::ExitCode;

mod out_of_memory;

/// A failed allocation stops the program with an error, not an abort (see the module).
#[global_allocator]
static ALLOCATOR: out_of_memory::CleanOutOfMemory = out_of_memory::CleanOutOfMemory;

use anyhow::Result;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

use args::{
    BenchArgs, CheckArgs, CompareArgs, ExportArgs, FormFactorArgs, GenerateCommand,
    IlluminanceArgs, PathTraceArgs, RenderArgs, SolveArgs, ValidateCommand, ViewArgs,
};
use errors::describe;

/// A radiosity renderer after De Angelis, "Radiosity: A Study in Photorealistic Rendering".
///
/// Every command but `generate` and `validate` takes an optional scene file (the paper's
/// Appendix A format, OBJ with its MTL, glTF, DXF or VRML97, by extension); without one it
/// uses the built-in Cornell box.
#[derive(Parser)]
#[command(name = "radiosity", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene and render it to a PNG image (or linear radiance as OpenEXR).
    Render(RenderArgs),
    /// Compute the form-factor matrix and write it to a file (paper 2.8).
    Formfactors(FormFactorArgs),
    /// Solve a scene and write the radiosity of every element as CSV (or JSON for *.json).
    Solve(SolveArgs),
    /// Illuminance in lux at calculation points (--points P.csv) or on a grid (--grid, with
    /// --png for a picture): direct (from emitting surfaces and point luminaires) and
    /// indirect (from reflected light), computed at each point from the solution.
    Illuminance(IlluminanceArgs),
    /// Print statistics of a scene: surfaces, elements, area, form-factor row sums,
    /// reciprocity, energy balance and stage times.
    Check(CheckArgs),
    /// Time the whole pipeline (parse, mesh, BVH, form factors, solve, shade, render) and
    /// print one Markdown table row per MAX_PATCH_AREA with the median time of each stage;
    /// "other" is the end-to-end time less those stages (contact refinement, the memory
    /// and work checks, the exposure, and the renderer's own BVH built before the render).
    Bench(BenchArgs),
    /// Solve a scene with one solver and with the dense reference (Gauss-Seidel on the
    /// form factors of --method and --steps; for a reference more accurate than the default
    /// area k = 2, use --method contour --steps 4) on the same mesh; print time, peak memory
    /// and the difference of element radiosity as a Markdown table row.
    Compare(CompareArgs),
    /// Path trace a scene (an unbiased Monte Carlo render of the same polygons and camera,
    /// no form factors) to a PNG image and print its noise; with --compare, also render the
    /// radiosity solution and print its pixel difference from the path-traced view.
    // Its exposure is render's rule estimated by paths alone, the radiosity solution's
    // with --compare (QA of issue #16: the shared help spoke of radiosities only, then of
    // the view's pixels after the rule had changed).
    #[command(mut_arg("exposure", |a| a.help("Exposure of the PNG images: \"auto\" makes \
        the mean radiosity of the brightest 2 % of the non-emitting area white, as `render` \
        does, estimated by paths at points over the surfaces (with --compare, both images \
        take the radiosity solution's auto exposure), a number multiplies the light by it; \
        an .exr output holds linear radiance, unexposed")))]
    Pathtrace(PathTraceArgs),
    /// Export a scene for other tools: the solved mesh with the radiosity baked into vertex
    /// colours as glTF (-o out.glb or out.gltf), or the scene's surfaces as OBJ + MTL
    /// (-o out.obj).
    // The camera flags are `render`'s, but export draws no image: --width and --height
    // give the glTF camera's aspect ratio (QA of issue #16: they said "Image width").
    #[command(
        mut_arg("width", |a| a.help("glTF: the camera's width, in proportion to --height: \
            the camera node's aspect ratio is WIDTH / HEIGHT (no image is drawn)")),
        mut_arg("height", |a| a.help("glTF: the camera's height, in proportion to --width \
            (see --width)"))
    )]
    Export(ExportArgs),
    /// Open the walkthrough window and modeller on a solved scene (feature `viewer`).
    View(ViewArgs),
    /// Generate a scene file procedurally.
    Generate {
        #[command(subcommand)]
        what: GenerateCommand,
    },
    /// Run published validation cases and compare with their reference values.
    Validate {
        #[command(subcommand)]
        what: ValidateCommand,
    },
}

fn main() -> ExitCode {
    let cli = command()
        .try_get_matches()
        .and_then(|m| Cli::from_arg_matches(&m))
        .unwrap_or_else(|e| exit_with(e));
    let _ = errors::COMMAND.set(command_name(&cli.command).to_string());
    // No output of this run may replace a file it read (an OBJ's MTL as much as the scene).
    radiosity::io::protect_inputs();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            errln!("{}", describe(&err));
            ExitCode::FAILURE
        }
    }
}

/// Exits on a command-line error: a wrong value in the project's frame and exit status,
/// as the checks after parsing give it (`error: --steps 0: give a whole number of at least
/// 1`, exit 1; [`radiosity_cli::args::value_error`]); anything else (an unknown flag, a
/// missing value) as clap does (exit 2; help and version on stdout, 0).
fn exit_with(e: clap::Error) -> ! {
    match radiosity_cli::args::value_error(&e) {
        Some(line) => {
            errln!("error: {line}");
            std::process::exit(1);
        }
        None if e.use_stderr() => {
            // clap's "Usage:" line after an error lists the flags typed as if they were
            // required (QA of issue #16: `generate building --rooms 2` gave "Usage: ...
            // --output <FILE.scene> --rooms-z <N>"); the command's own usage replaces it.
            let text = e.render().to_string();
            let usage = plain_usage(std::env::args_os().skip(1));
            let text = match text.lines().find(|l| l.starts_with("Usage: ")) {
                Some(line) if !usage.is_empty() => text.replacen(line, &usage, 1),
                _ => text,
            };
            eprint!("{text}");
            std::process::exit(e.exit_code());
        }
        None => e.exit(),
    }
}

/// The name of `command` as typed ("formfactors").
fn command_name(command: &Command) -> &'static str {
    match command {
        Command::Render(_) => "render",
        Command::Formfactors(_) => "formfactors",
        Command::Solve(_) => "solve",
        Command::Illuminance(_) => "illuminance",
        Command::Check(_) => "check",
        Command::Bench(_) => "bench",
        Command::Compare(_) => "compare",
        Command::Pathtrace(_) => "pathtrace",
        Command::Export(_) => "export",
        Command::View(_) => "view",
        Command::Generate { .. } => "generate",
        Command::Validate { .. } => "validate",
    }
}

/// "Usage: radiosity generate building [OPTIONS] --output <FILE.scene>": the usage of the
/// deepest subcommand that `args` name, as its `--help` gives it; empty when there is none.
fn plain_usage(args: impl Iterator<Item = std::ffi::OsString>) -> String {
    let mut cmd = command();
    cmd.build();
    let mut current = &mut cmd;
    for arg in args {
        let Some(arg) = arg.to_str() else { break };
        if arg.starts_with('-') {
            continue;
        }
        let Some(name) = current
            .find_subcommand(arg)
            .map(|sub| sub.get_name().to_string())
        else {
            break;
        };
        current = current
            .find_subcommand_mut(&name)
            .expect("found just above");
    }
    current.render_usage().to_string()
}

/// The command line with every flag that takes a value accepting a negative number
/// ([`radiosity_cli::args::negative_numbers`], QA of issue #16).
fn command() -> clap::Command {
    radiosity_cli::args::negative_numbers(Cli::command())
        // `check` prints its report, stage times included, whatever -q says: the shared
        // help ("no progress bars, timings or notes") was untrue there.
        .mut_subcommand("check", |check| {
            check.mut_arg("quiet", |quiet| {
                quiet.help(
                    "No progress bars or lines (the report, with its stage times, is still \
                     printed; errors and warnings too)",
                )
            })
        })
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => commands::render::run(args),
        Command::Formfactors(args) => commands::formfactors::run(args),
        Command::Solve(args) => commands::solve::run(args),
        Command::Illuminance(args) => commands::illuminance::run(args),
        Command::Check(args) => commands::check::run(args),
        Command::Bench(args) => commands::bench::run(args),
        Command::Compare(args) => commands::compare::run(args),
        Command::Pathtrace(args) => commands::pathtrace::run(args),
        Command::Export(args) => commands::export::run(args),
        Command::View(args) => commands::view::run(args),
        Command::Generate {
            what: GenerateCommand::Building(args),
        } => commands::generate::building(args),
        Command::Validate {
            what: ValidateCommand::Cie171(args),
        } => commands::validate::cie171(args),
    }
}
