//! `radiosity export`: the solved scene as glTF with the radiosity in vertex colours, or
//! the scene's surfaces as OBJ + MTL.

use crate::progress_bar::run_file_stage;
use std::path::Path;

use anyhow::{bail, Context, Result};
use radiosity::io::export::gltf::{self, Bake};
use radiosity::io::export::obj;
use radiosity::progress::{run_stage, Stage};
use radiosity::shade::{self, Exposure};

use super::{exposure_note, solve_as_asked};
use crate::args::ExportArgs;
use crate::progress_bar::Reporter;
use crate::setup::{
    camera, load_scene, output_directory, prepare_solve, refuse_overwriting_inputs,
};

/// What `-o` asks for, by extension.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Glb,
    Gltf,
    Obj,
}

fn format(output: &Path) -> Result<Format> {
    let ext = output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if output.is_dir() {
        bail!(
            "-o {}: is a folder; give a file name in it",
            output.display()
        );
    }
    match ext.as_deref() {
        Some("glb") => Ok(Format::Glb),
        Some("gltf") => Ok(Format::Gltf),
        Some("obj") => Ok(Format::Obj),
        _ => bail!(
            "-o {}: export writes glTF (.glb, or .gltf with a .bin beside it) or OBJ (.obj, with \
             an .mtl beside it); give the output one of these extensions",
            output.display()
        ),
    }
}

pub fn run(args: ExportArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let output = &args.output;
    let format = format(output)?;
    let inputs = [
        ("scene file", args.scene.scene.as_deref()),
        ("form-factor file", args.solve.form_factors.as_deref()),
    ];
    refuse_overwriting_inputs(output, "-o", &inputs)?;
    let beside = match format {
        Format::Gltf => Some(("buffer", gltf::buffer_path(output))),
        Format::Obj => Some(("material library", obj::mtl_path(output))),
        Format::Glb => None,
    };
    if let Some((what, path)) = beside {
        let label = format!("-o {} (its {what} {})", output.display(), path.display());
        crate::setup::refuse_overwriting_inputs_as(&path, "-o", &label, &inputs)?;
    }
    output_directory(output, "-o")?;
    // Printed even with --quiet: the file will not hold what the scene holds.
    let warn_lights = |scene: &radiosity::scene::Scene| {
        if !scene.lights.is_empty() {
            let names: Vec<&str> = scene.lights.iter().map(|l| l.name.as_str()).collect();
            errln!(
                "warning: {} left out of {} ({}): glTF and OBJ exports do \
                 not carry LIGHTBEGIN blocks yet, so the file read back has only the emitting \
                 surfaces",
                crate::report::count(names.len() as u64, "point luminaire"),
                output.display(),
                names.join(", ")
            );
        }
    };
    if format == Format::Obj {
        return export_obj(&args, &reporter, warn_lights);
    }
    crate::setup::check_camera_flags(&args.camera)?;
    let (prepared, _, solver) = prepare_solve(&args.scene, &args.solve, &reporter)?;
    warn_lights(&prepared.scene);
    let camera = camera(&args.camera, &prepared.scene)?;
    let solution = solve_as_asked(&prepared, solver, &args.solve, &reporter)?;
    let b = solution.element_rgb();
    let scale = args.exposure.scale(&prepared.scene, &solution.mesh, b);
    let vertex_b = run_stage(&reporter, Stage::Shade, 0, || {
        let mut vertex_b = shade::vertex_radiosity(&solution.mesh, b);
        shade::smooth_objects(&prepared.scene, &solution.mesh, &mut vertex_b);
        vertex_b
    });
    let bake = Bake {
        scene: &prepared.scene,
        mesh: &solution.mesh,
        vertex_b: &vertex_b,
        exposure_scale: scale,
        exposure: match args.exposure {
            Exposure::Auto => "auto",
            Exposure::Fixed(_) => "fixed",
        },
        camera: &camera,
        settings: prepared.settings,
    };
    run_file_stage(&reporter, Stage::Write, output, || match format {
        Format::Glb => gltf::write_glb(output, &bake),
        Format::Gltf | Format::Obj => gltf::write_gltf(output, &bake),
    })
    .with_context(|| format!("cannot write {}", output.display()))?;
    // The exposure is part of what the file means; --quiet drops the note as for every
    // command, and the file's asset.extras keeps it.
    reporter.note(&exposure_note(
        &prepared,
        &solution.mesh,
        b,
        args.exposure,
        scale,
    ));
    let extra = match format {
        Format::Gltf => format!(" and {}", gltf::buffer_path(output).display()),
        Format::Glb | Format::Obj => String::new(),
    };
    reporter.note(&format!(
        "wrote {}{extra} ({} surfaces, {} elements; COLOR_0 = min(1, {} x radiosity), \
         linear, on KHR_materials_unlit)",
        output.display(),
        prepared.scene.surfaces.len(),
        solution.mesh.len(),
        // As the exposure note gives it (QA of issue #16: 1.535 there, 16 digits here).
        crate::report::significant(scale, 4),
    ));
    reporter.print_timings();
    Ok(())
}

/// `-o out.obj`: the scene's surfaces as they are (no meshing or solving; the mesh and
/// solver flags do not apply), with the file's meshing settings (and --max-area,
/// --steps) as comments.
fn export_obj(
    args: &ExportArgs,
    reporter: &Reporter,
    warn_lights: impl Fn(&radiosity::scene::Scene),
) -> Result<()> {
    // The solve, exposure and camera flags bake the glTF; an OBJ holds the surfaces only
    // (QA of issue #16: `-o x.obj --solver hierarchical --exposure 2` said nothing). A flag
    // at its default value is not told apart from one left out. Printed even with --quiet.
    let (s, c) = (&args.solve, &args.camera);
    let given = [
        ("--method", args.scene.method.method.is_some()),
        ("--solver", s.solver.0 != radiosity::solve::SolverKind::Auto),
        ("--tolerance", s.tolerance.is_some()),
        ("--form-factors", s.form_factors.is_some()),
        ("--min-area", s.min_area.is_some()),
        ("--adapt-rounds", s.adapt_rounds.is_some()),
        ("--exposure", !matches!(args.exposure, Exposure::Auto)),
        ("--eye", c.eye.is_some()),
        ("--look-at", c.look_at.is_some()),
        ("--up", c.up.is_some()),
        ("--fov", c.fov.is_some()),
        ("--width", c.width.is_some()),
        ("--height", c.height.is_some()),
    ];
    let ignored: Vec<&str> = crate::setup::flags_given(&given);
    if !ignored.is_empty() {
        errln!(
            "warning: {} ignored: an .obj export writes the scene's surfaces with their \
             reflectance and emission, unsolved (the solve, exposure and camera flags set the \
             baked glTF of a .glb or .gltf name)",
            ignored.join(", ")
        );
    }
    let (file, _) = load_scene(args.scene.scene.as_deref(), args.scene.scale, reporter)?;
    warn_lights(&file.scene);
    let settings = radiosity::mesh::MeshSettings {
        max_patch_area: args.scene.max_area.unwrap_or(file.settings.max_patch_area),
        integral_steps: args.scene.steps.unwrap_or(file.settings.integral_steps),
    };
    let output = &args.output;
    run_file_stage(reporter, Stage::Write, output, || {
        obj::write_obj(output, &file.scene, Some(settings))
    })
    .with_context(|| format!("cannot write {}", output.display()))?;
    reporter.note(&format!(
        "wrote {} and {} ({} surfaces; Kd reflectance, Ke emission)",
        output.display(),
        obj::mtl_path(output).display(),
        file.scene.surfaces.len()
    ));
    Ok(())
}
