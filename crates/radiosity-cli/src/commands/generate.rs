//! `radiosity generate`: scene files made procedurally.

use anyhow::{bail, Context, Result};
use radiosity::pipeline::Prepared;
use radiosity::progress::NoProgress;
use radiosity::scene::{self, BuildingError};

use crate::args::BuildingArgs;
use crate::report;

/// The library's refusal of the building's parameters in the words of the flags (QA of
/// issue #16: `--max-area 0` was refused as "MAX_PATCH_AREA must be ...", `--rooms-x 0` as
/// "floors, rooms-x and rooms-z must be at least 1").
fn flag_at_fault(e: &BuildingError, args: &BuildingArgs) -> String {
    match e {
        BuildingError::NoRooms(what) => {
            let (flag, what) = match *what {
                "floors" => ("--floors", "floor"),
                "rooms along x" => ("--rooms-x", "room along x"),
                _ => ("--rooms-z", "room along z"),
            };
            format!("{flag} 0: a building needs at least 1 {what}")
        }
        BuildingError::RoomSize {
            size,
            min,
            furniture,
        } => format!(
            "--room-size {}: give the inner side of a room in metres, {min} to 100{}",
            crate::report::typed(*size),
            if *furniture {
                " (the furniture needs 5.7; --no-furniture allows 2.5)"
            } else {
                ""
            }
        ),
        BuildingError::Height(h) => {
            let h = crate::report::typed(*h);
            format!("--height {h}: give the floor-to-ceiling height in metres, 2.4 to 20")
        }
        BuildingError::MaxPatchArea(a) => format!(
            "--max-area {}: give the largest element area in square metres, a number above 0",
            crate::report::typed(*a)
        ),
        BuildingError::IntegralSteps => {
            "--steps 0: give the points along each axis of an element, at least 1".to_string()
        }
        BuildingError::Light(l) => format!(
            "--light {}: give the ceiling panels' exitance in lm/m^2, a number of at least 0",
            crate::report::typed(*l)
        ),
        // QA pass 16 of #16: the file was written and every other command refused it.
        BuildingError::LightTooBright(l) => format!(
            "--light {}: give the ceiling panels' exitance in lm/m^2, at most {:e} (the \
             largest emission the other commands read)",
            crate::report::typed(*l),
            scene::MAX_EMISSION
        ),
        BuildingError::TooManyRooms(n) => format!(
            "--floors {}, --rooms-x {}, --rooms-z {}: they make {n} rooms, more than the \
             limit of {}; give fewer",
            args.floors,
            args.rooms_x,
            args.rooms_z,
            scene::BuildingParams::MAX_ROOMS
        ),
    }
}

/// Refuses a building of several storeys whose one storey, times the storeys, is more than
/// 10 % past the meshing limit, before the whole is built (QA pass 14 of #16: `--floors
/// 1000` took minutes and gigabytes to be refused, and was then told to "raise" its area
/// to a smaller one). Nearer the limit the whole building is meshed and judged exactly;
/// the margin covers the storeys' differences (their furniture, from the seed).
fn refuse_far_past_the_limit(params: &scene::BuildingParams, args: &BuildingArgs) -> Result<()> {
    if params.floors <= 1 {
        return Ok(());
    }
    let one = scene::building(&scene::BuildingParams {
        floors: 1,
        ..params.clone()
    });
    let limit = radiosity::mesh::MAX_ELEMENTS;
    let floors = params.floors as f64;
    let fewest = radiosity::mesh::fewest_elements(&one.scene);
    let per_storey = radiosity::mesh::planned_elements(&one.scene, args.max_area);
    // 2 % below the limit, as the area suggested below: the storeys differ (review).
    let most_floors = |per: f64| (0.98 * limit as f64 / per).floor() as u64;
    let rooms = format!("{} x {} rooms", params.rooms_x, params.rooms_z);
    if fewest * floors > 1.1 * limit as f64 {
        let fit = match most_floors(fewest) {
            0 => format!("not one storey of {rooms} fits: give fewer rooms"),
            n => format!("at most about {n} floors of {rooms} fit at any --max-area"),
        };
        bail!(
            "--floors {}: no file written: about {} surfaces ({} a storey), each at least one \
             element at any --max-area, past the limit of {limit} elements that the other \
             commands mesh; {fit}",
            params.floors,
            (one.scene.surfaces.len() as f64 * floors).round(),
            one.scene.surfaces.len(),
        );
    }
    if per_storey * floors > 1.1 * limit as f64 {
        let area = radiosity::mesh::largest_area_that_fits(
            &one.scene,
            // 2 % below a storey's share: the storeys differ.
            (0.98 * limit as f64 / floors).floor() as u64,
        );
        let mut ways = Vec::new();
        if let n @ 1.. = most_floors(per_storey) {
            ways.push(format!("at most {n} floors"));
        }
        if let Some(a) = area {
            ways.push(format!(
                "--max-area about {} or more",
                radiosity::mesh::four_digits_up(a)
            ));
        }
        bail!(
            "--max-area {}: no file written: about {} elements ({} a storey, {} floors), past \
             the limit of {limit} that the other commands mesh; give {}",
            crate::report::typed(args.max_area),
            (per_storey * floors).round(),
            per_storey,
            params.floors,
            if ways.is_empty() {
                format!("fewer rooms than {rooms}")
            } else {
                ways.join(", or ")
            }
        );
    }
    Ok(())
}

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
    // The other commands read a scene by its extension (QA of issue #16: `-o b.txt` was
    // written, then refused by every command that read it).
    crate::setup::check_output(
        &args.output,
        "-o",
        "the building is written in the scene format (Appendix A), which the other \
         commands read by the extension .scene",
        &["scene"],
        &[],
    )?;
    // A scene file is what the other commands read: one that exists is kept unless asked
    // (QA of issue #16: `-o examples/room.scene` replaced the shipped example without a
    // word; the viewer's modeller never saves over the file it opened either).
    if args.output.exists() && !args.force {
        bail!(
            "-o {}: the file exists; give another name, or --force to replace it",
            args.output.display()
        );
    }
    if let Err(e) = params.check() {
        bail!("{}", flag_at_fault(&e, &args));
    }
    refuse_far_past_the_limit(&params, &args)?;
    let built = scene::building(&params);
    // A building no other command could mesh is refused before its file is written (QA of
    // issue #16: it was written, then refused by every command that read it).
    let grid =
        radiosity::mesh::mesh_scene(&built.scene, built.settings.max_patch_area).map_err(|e| {
            anyhow::Error::new(e).context(format!(
                "--max-area {} (the file's MAX_PATCH_AREA): no file written, the other \
                 commands could not mesh it",
                crate::report::typed(args.max_area)
            ))
        })?;
    scene::write_scene_file(&built.scene, built.settings, &args.output)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    if args.light == 0.0 {
        // Every other command refuses a scene with no light only by its dark picture; say
        // so now (QA of issue #16: `--light 0` wrote a building without a word).
        errln!(
            "warning: --light 0: the ceiling panels emit nothing and the building has no \
             other light, so it renders black; give their exitance in lm/m^2 (default {})",
            scene::BuildingParams::default().light
        );
    }
    if args.quiet {
        return Ok(());
    }
    // The element count the other commands will mesh the file into: the grid, then the
    // contact refinement that splits elements along the furniture's footprints (so the
    // count `check` and `render` print); the grid's alone where meshing would refuse it
    // (more than MAX_ELEMENTS).
    let elements = if grid.len() > PREPARE_MAX_ELEMENTS {
        // The refinement takes seconds past this; the grid's count is then given alone.
        format!(
            "{} elements on the grid (contact refinement adds some when the file is loaded)",
            grid.len()
        )
    } else {
        match Prepared::new(built.scene.clone(), built.settings, &NoProgress) {
            Ok(prepared) if prepared.mesh.len() != grid.len() => format!(
                "{} elements ({} on the grid, split along furniture contacts)",
                prepared.mesh.len(),
                grid.len()
            ),
            _ => format!("{} elements", grid.len()),
        }
    };
    report::building(&args.output, &params, &built.scene, &elements);
    Ok(())
}

/// The most grid elements for which `generate building` meshes the file as the other
/// commands will (contact refinement included) to print their count.
const PREPARE_MAX_ELEMENTS: usize = 100_000;
