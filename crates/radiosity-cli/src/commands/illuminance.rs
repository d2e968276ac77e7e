//! `radiosity illuminance`: lux at calculation points or on a grid, from the solved scene.

use anyhow::{bail, Context, Result};
use radiosity::illuminance::{self, CalcPoint};
use radiosity::progress::{run_stage, Stage};

use super::solve_as_asked;
use crate::args::IlluminanceArgs;
use crate::progress_bar::Reporter;
use crate::setup::{check_output, prepare_solve};

/// The most grid points one run computes.
const MAX_GRID_POINTS: usize = 1_000_000;

pub fn run(args: IlluminanceArgs) -> Result<()> {
    let reporter = Reporter::new(args.scene.quiet);
    // Checked here rather than by clap, whose messages named only --points when neither
    // was given and asked for --grid and --normal beside --points for --png (QA of issue
    // #16).
    if args.png.is_some() && args.grid.is_none() {
        bail!(
            "--png draws the cells of a --grid; --points P.csv gives no grid, so drop --png \
             (the CSV holds every point's lux) or use --grid X0,Y0,Z0:X1,Y1,Z1:SPACING \
             --normal NX,NY,NZ instead of --points"
        );
    }
    let inputs = [
        ("scene file", args.scene.scene.as_deref()),
        ("points file", args.points.as_deref()),
        ("form-factor file", args.solve.form_factors.as_deref()),
    ];
    check_output(
        &args.output,
        "-o",
        "the illuminance is written as a CSV table",
        &["csv"],
        &inputs,
    )?;
    if let Some(png) = &args.png {
        check_output(
            png,
            "--png",
            "the grid's picture is a PNG",
            &["png"],
            &inputs,
        )?;
    }
    let (points, dims) = match (&args.points, args.grid) {
        (Some(path), _) => {
            if args.normal.is_some() {
                // Printed even with --quiet (QA of issue #16: clap refused the pair, asking
                // for a --grid that --points excludes).
                errln!(
                    "warning: --normal ignored with --points: each point's normal is in the \
                     file (nx,ny,nz)"
                );
            }
            (illuminance::read_points(path)?, None)
        }
        (None, Some((a, b, spacing))) => {
            let Some(normal) = args.normal else {
                // No default: the help says why.
                bail!(
                    "--grid needs --normal NX,NY,NZ, the way the meters face: 0,0,1 for a \
                     horizontal work plane in a z-up scene, 0,1,0 in a y-up one"
                );
            };
            if normal.length_squared() == 0.0 {
                bail!(
                    "--normal 0,0,0 is no direction; give the way the meters face: 0,0,1 for a \
                     horizontal work plane in a z-up scene, 0,1,0 in a y-up one"
                );
            }
            let Some((points, dims)) = illuminance::grid(a, b, spacing, normal, MAX_GRID_POINTS)
            else {
                bail!("{}", grid_refusal(a, b, spacing));
            };
            if let Some(short) = grid_short_of_corner(a, b, spacing) {
                // Printed even with --quiet: the grid does not cover what was asked.
                errln!("warning: {short}");
            }
            (points, Some(dims))
        }
        (None, None) => bail!(
            "give the points to compute: --points P.csv, or a grid with --grid \
             X0,Y0,Z0:X1,Y1,Z1:SPACING --normal NX,NY,NZ"
        ),
    };
    // The points are in the scene file's units, so --scale applies to them as to the scene
    // (a room in millimetres with --scale 0.001, points in millimetres: lux as in metres);
    // the CSV gives them back as they were written.
    let scale = args.scene.scale;
    let scaled: Vec<CalcPoint> = points
        .iter()
        .map(|p| CalcPoint {
            position: p.position * scale,
            ..p.clone()
        })
        .collect();
    let (prepared, _, solver) = prepare_solve(&args.scene, &args.solve, &reporter)?;
    // Refused before the solve when the prepared mesh already makes it too much, and again
    // after it on the solved mesh (adaptive subdivision and hierarchical radiosity's
    // leaves have more elements).
    let check_work = |elements: usize| -> Result<()> {
        if args.scene.no_work_limit {
            return Ok(());
        }
        if let Err(mut e) = radiosity::budget::check_illuminance_work(points.len(), elements) {
            if let Some((a, b, s)) = args.grid {
                let most = radiosity::budget::most_illuminance_points(elements);
                if let Some(wider) = smallest_spacing(a, b, s, most) {
                    e.fits
                        .push_str(&format!("; for this grid, a spacing of {wider} or more"));
                }
            }
            return Err(e.into());
        }
        Ok(())
    };
    check_work(prepared.mesh.len())?;
    let solution = solve_as_asked(&prepared, solver, &args.solve, &reporter)?;
    check_work(solution.mesh.len())?;
    let lux = run_stage(&reporter, Stage::Illuminance, points.len() as u64, || {
        illuminance::illuminance_with_progress(&prepared, &solution, &scaled, &reporter)
    });
    crate::progress_bar::run_file_stage(&reporter, Stage::Write, &args.output, || {
        write(&args, &points, &lux)
    })?;
    // A scene with no light was warned of when it was read: every point is dark there.
    let lit =
        crate::setup::no_emitter(&prepared.scene, radiosity::io::import::Format::Scene).is_none();
    if let Some(w) = dark_points(&prepared, &points, &lux, args.grid.is_some()).filter(|_| lit) {
        // Printed even with --quiet: figures that are surely not what was meant.
        errln!("warning: {w}");
    }
    if let Some(w) = points_at_lights(&prepared.scene, &points) {
        errln!("warning: {w}");
    }
    reporter.note(&format!(
        "wrote {} ({}; {}; the scene's unit: {})",
        args.output.display(),
        crate::report::count(points.len() as u64, "point"),
        crate::setup::LUX_NOTE,
        crate::setup::scene_unit()
    ));
    if let (Some(png), Some(dims)) = (&args.png, dims) {
        let totals: Vec<f64> = lux.iter().map(|l| l.total).collect();
        let z_up = radiosity::render::z_is_up(&prepared.scene);
        let (totals, dims, axes) = match args
            .grid
            .and_then(|(a, b, spacing)| illuminance::GridAxes::of(a, b, spacing))
        {
            Some(axes) => {
                let (totals, dims, axes) = axes.upright(&totals, dims, z_up);
                let drawn = axes.as_drawn(z_up);
                let drawn = match args.normal {
                    Some(normal) => drawn.seen_from(normal, z_up),
                    None => drawn,
                };
                (totals, dims, Some(drawn))
            }
            None => (totals, dims, None),
        };
        let held = args
            .grid
            .map(|(a, b, _)| illuminance::held_coordinates(a, b))
            .unwrap_or_default();
        let img = illuminance::grid_picture_with_axes(&totals, dims, axes, &held);
        crate::progress_bar::run_file_stage(&reporter, Stage::Write, png, || {
            radiosity::io::png::write_png(&img, png)
        })
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

/// A warning when the grid's spacing does not divide its span along an axis, so that its
/// last row or column stops short of the second corner (QA of issue #16: `:1.5` over 4 m
/// stopped 1 m short, `:10` gave one point, without a word).
fn grid_short_of_corner(a: glam::DVec3, b: glam::DVec3, spacing: f64) -> Option<String> {
    let short: Vec<String> = (0..3)
        .filter_map(|axis| {
            let span = (b[axis] - a[axis]).abs();
            if span == 0.0 {
                return None;
            }
            let steps = (span / spacing + 1e-9).floor();
            let last = steps * spacing;
            if span - last <= 1e-9 * spacing {
                return None;
            }
            let name = ["x", "y", "z"][axis];
            let end = a[axis] + (b[axis] - a[axis]).signum() * last;
            Some(format!(
                "along {name} it stops at {name} = {}, {} short of {}",
                crate::report::significant(end, 6),
                crate::report::significant(span - last, 4),
                crate::report::significant(b[axis], 6),
            ))
        })
        .collect();
    (!short.is_empty()).then(|| {
        format!(
            "--grid spacing {}: the grid does not reach its second corner: {} (corners a \
             whole number of spacings apart make it reach)",
            crate::report::typed(spacing),
            short.join("; ")
        )
    })
}

/// A warning when points lie at a point light (within 1e-9 of the scene's size): its
/// direct light there, I / d^2 at d = 0, has no value and is counted 0 (QA pass 17 of #16:
/// a point exactly at a lamp read 0 direct lux from it without a word).
fn points_at_lights(scene: &radiosity::scene::Scene, points: &[CalcPoint]) -> Option<String> {
    let (lo, hi) = scene.bounds();
    let near = 1e-9 * (hi - lo).length().max(f64::MIN_POSITIVE);
    let at: Vec<(&CalcPoint, &str)> = points
        .iter()
        .filter_map(|p| {
            scene
                .lights
                .iter()
                .find(|l| (l.position - p.position).length() <= near)
                .map(|l| (p, l.name.as_str()))
        })
        .collect();
    let (p, light) = at.first()?;
    Some(format!(
        "{} at a point light (the first: \"{}\" at the light \"{light}\"): a point \
         light's illuminance at its own position has no value (I / d^2 at d = 0) and is \
         counted 0 there; move the {} off it",
        if at.len() == 1 {
            "1 point lies".to_string()
        } else {
            format!("{} points lie", at.len())
        },
        p.name,
        if at.len() == 1 { "point" } else { "points" },
    ))
}

/// A warning when some points get no light at all (QA of issue #16: points inside the
/// cupboard, under the floor and outside the room gave 0 lx without a word, and spoiled a
/// grid's minimum and uniformity), and why: a point that sees more fronts of surfaces
/// than backs ([`sees_a_front`]) is in the open, in full shadow among surfaces that pass no light on (QA of issue #16:
/// points in a black room's shadow were asked whether they were inside furniture).
fn dark_points(
    prepared: &radiosity::pipeline::Prepared,
    points: &[CalcPoint],
    lux: &[illuminance::Lux],
    grid: bool,
) -> Option<String> {
    let dark: Vec<&CalcPoint> = points
        .iter()
        .zip(lux)
        .filter(|(_, l)| l.total == 0.0)
        .map(|(p, _)| p)
        .collect();
    dark.first()?;
    let (open, shut): (Vec<&CalcPoint>, Vec<&CalcPoint>) = dark
        .iter()
        .partition(|p| sees_a_front(prepared, p.position, p.normal));
    let first = |p: &[&CalcPoint]| {
        p.first().map(|p| {
            format!(
                "the first: \"{}\" at {},{},{}",
                p.name, p.position.x, p.position.y, p.position.z
            )
        })
    };
    let mut why = Vec::new();
    if let Some(f) = first(&shut) {
        why.push(format!(
            "{} ({f}) {} only the backs of faces, or nothing: inside furniture, under the \
             floor or outside the scene?",
            shut.len(),
            if shut.len() == 1 { "sees" } else { "see" },
        ));
    }
    if let Some(f) = first(&open) {
        why.push(format!(
            "{} ({f}) {} surfaces but no light: in full shadow, where what {} sees \
             reflects nothing (reflectance 0, or unlit itself)",
            open.len(),
            if open.len() == 1 { "sees" } else { "see" },
            if open.len() == 1 { "it" } else { "each" },
        ));
    }
    Some(format!(
        "{} of {} {} no light at all (0 lx): {}{}",
        crate::report::count(dark.len() as u64, "point"),
        points.len(),
        if dark.len() == 1 { "gets" } else { "get" },
        why.join("; "),
        if grid {
            "; the grid's minimum and uniformity count them"
        } else {
            ""
        }
    ))
}

/// Whether a meter at `p` facing `normal` is in the open: of 64 rays over its hemisphere
/// (an 8 x 8 grid in solid angle, cosine-weighted), more meet the front of a surface first
/// than meet a back. A meter under a floor sees the floor's back overhead, though rays
/// near its horizon may pass the floor's edge and meet the front of something outside.
fn sees_a_front(
    prepared: &radiosity::pipeline::Prepared,
    p: glam::DVec3,
    normal: glam::DVec3,
) -> bool {
    let Some(n) = normal.try_normalize() else {
        return false;
    };
    let (u, v) = n.any_orthonormal_pair();
    let start = 1e-7 * prepared.occluders.scale();
    let (mut fronts, mut backs) = (0, 0);
    for k in 0..64 {
        let (a, b) = ((k % 8) as f64 + 0.5, (k / 8) as f64 + 0.5);
        let (r, phi) = ((a / 8.0).sqrt(), std::f64::consts::TAU * b / 8.0);
        let dir =
            (u * (r * phi.cos()) + v * (r * phi.sin()) + n * (1.0 - r * r).sqrt()).normalize();
        let facing = prepared
            .occluders
            .closest_hit(p, dir, start, f64::INFINITY)
            .and_then(|hit| prepared.scene.surfaces.get(hit.id as usize))
            .and_then(|s| radiosity::geometry::polygon_normal(&s.vertices))
            .map(|m| m.dot(dir));
        match facing {
            Some(c) if c < 0.0 => fronts += 1,
            Some(_) => backs += 1,
            None => {}
        }
    }
    fronts > backs
}

/// Why a `--grid` is refused, with what would fit: corners that differ in all three axes,
/// a spacing that is no length, or more than [`MAX_GRID_POINTS`] points (then the smallest
/// spacing that fits).
fn grid_refusal(a: glam::DVec3, b: glam::DVec3, spacing: f64) -> String {
    let head = format!(
        "--grid {},{},{}:{},{},{}:{spacing}",
        a.x, a.y, a.z, b.x, b.y, b.z
    );
    if !(spacing.is_finite() && spacing > 0.0) {
        return format!("{head}: the spacing must be a positive length");
    }
    if (0..3).all(|i| a[i] != b[i]) {
        return format!(
            "{head}: the corners differ in x, y and z; a grid is a rectangle, so they must \
             agree in at least one axis (the height of a work plane, say)"
        );
    }
    // Exact below a trillion, else to three digits (QA pass 14 of #16: the float's
    // "309136000001111989682176").
    let count = grid_count(a, b, spacing);
    let count = if count < 1e12 {
        format!("{count:.0}")
    } else {
        format!("about {count:.2e}")
    };
    match smallest_spacing(a, b, spacing, MAX_GRID_POINTS) {
        Some(wider) => format!(
            "{head} makes {count} points, more than the {MAX_GRID_POINTS} one run \
             computes, --no-work-limit or not; a spacing of {wider} or more fits (or split \
             the grid into several runs)"
        ),
        None => format!(
            "{head} makes {count} points, more than one run computes, --no-work-limit or not"
        ),
    }
}

/// The points of the grid from `a` to `b` every `spacing` (as [`illuminance::grid`]
/// counts them).
fn grid_count(a: glam::DVec3, b: glam::DVec3, spacing: f64) -> f64 {
    (0..3)
        .filter(|&i| a[i] != b[i])
        .map(|i| ((b[i] - a[i]).abs() / spacing + 1e-9).floor() + 1.0)
        .product()
}

/// The smallest spacing of 3 significant digits, from `spacing` up, that makes at most
/// `most` points of the grid from `a` to `b`, as text; `None` when even one point a side
/// is too many.
fn smallest_spacing(a: glam::DVec3, b: glam::DVec3, spacing: f64, most: usize) -> Option<String> {
    let longest = (0..3).map(|i| (b[i] - a[i]).abs()).fold(0.0, f64::max);
    if most == 0 || !(spacing.is_finite() && spacing > 0.0) {
        return None;
    }
    // Bisection: the count falls as the spacing grows, and beyond the longest side the
    // grid is one point a side.
    let (mut lo, mut hi) = (spacing, longest.max(spacing) * 2.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if grid_count(a, b, mid) > most as f64 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(round_up_3(hi))
}

/// `x` rounded up to 3 significant digits, as text (a spacing to type that still fits).
fn round_up_3(x: f64) -> String {
    let k = x.log10().floor() as i32 - 2;
    let v = (x / 10f64.powi(k)).ceil() * 10f64.powi(k);
    format!("{v:.*}", (-k).max(0) as usize)
}

fn write(args: &IlluminanceArgs, points: &[CalcPoint], lux: &[illuminance::Lux]) -> Result<()> {
    radiosity::io::write_atomically(&args.output, |w| illuminance::write_lux_csv(points, lux, w))
        .with_context(|| format!("cannot write {}", args.output.display()))
}
