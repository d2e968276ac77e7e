//! `radiosity generate`: scene files made procedurally.

use anyhow::{bail, Context, Result};
use radiosity::scene;

use crate::args::BuildingArgs;
use crate::report;

pub fn building(args: BuildingArgs) -> Result<()> {
    let params = scene::BuildingParams {
        floors: args.floors,
        rooms_x: args.rooms_x,
        rooms_z: args.rooms_z,
        room_size: args.room_size,
        height: args.height,
        furniture: !args.no_furniture,
        seed: args.seed,
        max_patch_area: args.max_area,
        integral_steps: args.steps,
        light: args.light,
    };
    if let Err(e) = params.check() {
        bail!("{e}");
    }
    let built = scene::building(&params);
    scene::write_scene_file(&built.scene, built.settings, &args.output)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    // The element count, also where meshing would refuse it (more than MAX_ELEMENTS).
    let elements = match radiosity::mesh::mesh_scene(&built.scene, built.settings.max_patch_area) {
        Ok(mesh) => format!("{} elements", mesh.len()),
        Err(radiosity::mesh::MeshError::TooManyElements { count, limit, .. }) => {
            format!("{count} elements (more than the meshing limit of {limit})")
        }
        Err(e) => return Err(e.into()),
    };
    report::building(&args.output, &params, &built.scene, &elements);
    Ok(())
}
