//! `radiosity illuminance`: lux at calculation points or on a grid, from the solved scene.

use anyhow::{bail, Context, Result};
use radiosity::illuminance::{self, CalcPoint};
use radiosity::progress::{run_stage, Stage};

use super::solve_as_asked;
use crate::args::IlluminanceArgs;
use crate::progress_bar::Reporter;
use crate::setup::{output_extension, prepare_solve, refuse_overwriting_inputs};

/// The most grid points one run computes.
const MAX_GRID_POINTS: usize = 1_000_000;

pub fn run(args: IlluminanceArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    let inputs = [
        ("scene file", args.scene.scene.as_deref()),
        ("points file", args.points.as_deref()),
        ("form-factor file", args.solve.form_factors.as_deref()),
    ];
    refuse_overwriting_inputs(&args.output, &inputs)?;
    output_extension(
        &args.output,
        "-o",
        "the illuminance is written as a CSV table",
        &["csv"],
    )?;
    if let Some(png) = &args.png {
        refuse_overwriting_inputs(png, &inputs)?;
        output_extension(png, "--png", "the grid's picture is a PNG", &["png"])?;
    }
    let (points, dims) = match (&args.points, args.grid) {
        (Some(path), _) => (illuminance::read_points(path)?, None),
        (None, Some((a, b, spacing))) => {
            let normal = args.normal.unwrap_or(glam::DVec3::Z);
            if normal.length_squared() == 0.0 {
                bail!("--normal 0,0,0 is no direction; give the way the meters face, e.g. 0,0,1");
            }
            let Some((points, dims)) = illuminance::grid(a, b, spacing, normal, MAX_GRID_POINTS)
            else {
                bail!(
                    "--grid {a},{b}:{spacing}: the corners must agree in at least one axis (a \
                     rectangle, not a box), and the grid may have at most {MAX_GRID_POINTS} \
                     points; use a larger spacing"
                );
            };
            (points, Some(dims))
        }
        (None, None) => bail!("give --points P.csv or --grid x0,y0,z0:x1,y1,z1:SPACING"),
    };
    let (prepared, _, solver) = prepare_solve(&args.scene, &args.solve, &reporter)?;
    let solution = solve_as_asked(&prepared, solver, &args.solve, &reporter)?;
    let lux = run_stage(&reporter, Stage::Render, points.len() as u64, || {
        illuminance::illuminance(&prepared, &solution, &points)
    });
    write(&args, &points, &lux)?;
    reporter.note(&format!(
        "wrote {} ({} points; lux = lm/m^2 with scene lengths in metres; the scene's unit: {})",
        args.output.display(),
        points.len(),
        crate::setup::scene_unit()
    ));
    if let (Some(png), Some(dims)) = (&args.png, dims) {
        let totals: Vec<f64> = lux.iter().map(|l| l.total).collect();
        let img = illuminance::grid_picture(&totals, dims);
        radiosity::io::png::write_png(&img, png)
            .with_context(|| format!("cannot write {}", png.display()))?;
        reporter.note(&format!(
            "wrote {} ({} x {} cells)",
            png.display(),
            dims[0],
            dims[1]
        ));
    }
    reporter.print_timings();
    Ok(())
}

fn write(args: &IlluminanceArgs, points: &[CalcPoint], lux: &[illuminance::Lux]) -> Result<()> {
    radiosity::io::write_atomically(&args.output, |w| illuminance::write_lux_csv(points, lux, w))
        .with_context(|| format!("cannot write {}", args.output.display()))
}
