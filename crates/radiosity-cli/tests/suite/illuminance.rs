//! `radiosity illuminance`: the CSV contract, closed-form direct light, the grid picture and
//! the points file's errors.

use crate::fixtures::*;

/// The test room: 4 m x 4 m x 3 m, grey 0.5, a 1000 cd COSINE downlight at (2, 2, 2.9).
fn room() -> String {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/downlight_room.scene"
    )
    .to_string()
}

#[test]
fn illuminance_at_points_and_on_a_grid() {
    let dir = scratch_dir("illuminance");
    std::fs::write(
        dir.join("p.csv"),
        "name,x,y,z,nx,ny,nz\ncentre,2,2,0.8,0,0,1\ncorner,0.25,0.25,0.8,0,0,1\n",
    )
    .unwrap();
    let out = radiosity(
        &[
            "illuminance",
            &room(),
            "--points",
            "p.csv",
            "-o",
            "o.csv",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = std::fs::read_to_string(dir.join("o.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "name,x,y,z,nx,ny,nz,direct_lux,indirect_lux,total_lux"
    );
    let row = |line: &str| -> Vec<f64> {
        line.split(',')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect()
    };
    // Under the light: I0 / h^2 with h = 2.1; at the corner point I0 cos^2 / d^2.
    let centre = row(lines.next().unwrap());
    assert!(
        (centre[6] - 1000.0 / (2.1 * 2.1)).abs() < 1e-9,
        "{centre:?}"
    );
    let corner = row(lines.next().unwrap());
    let d2: f64 = 1.75 * 1.75 * 2.0 + 2.1 * 2.1;
    assert!(
        (corner[6] - 1000.0 * 2.1 * 2.1 / (d2 * d2)).abs() < 1e-9,
        "{corner:?}"
    );
    // Indirect: positive and the total is the sum.
    assert!(centre[7] > 0.0 && (centre[8] - centre[6] - centre[7]).abs() < 1e-9);

    let out = radiosity(
        &[
            "illuminance",
            &room(),
            "--grid",
            "0.25,0.25,0.8:3.75,3.75,0.8:0.5",
            "--normal",
            "0,0,1",
            "-o",
            "g.csv",
            "--png",
            "g.png",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = std::fs::read_to_string(dir.join("g.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 64);
    let png = image::open(dir.join("g.png")).unwrap();
    assert!(png.width() > 8 * 24);

    // A bad points file: its name, line and what was expected.
    std::fs::write(dir.join("bad.csv"), "name,x,y,z,nx,ny,nz\na,1,2,3,0,0\n").unwrap();
    let out = radiosity(
        &["illuminance", &room(), "--points", "bad.csv", "-o", "x.csv"],
        &dir,
    );
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("bad.csv:2: error: expected 7 fields"),
        "{}",
        stderr(&out)
    );
    // --grid without --normal is refused by the parser.
    let out = radiosity(
        &[
            "illuminance",
            &room(),
            "--grid",
            "0,0,0:1,1,0:0.5",
            "-o",
            "x.csv",
        ],
        &dir,
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--normal"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_point_at_a_point_light_is_warned_of() {
    // QA pass 17 of #16: a point exactly at the lamp read 0 direct lux from it without a
    // word. The downlight is at (2, 2, 2.9); the point a meter below it is not warned of.
    let dir = scratch_dir("illuminance-at-lamp");
    std::fs::write(
        dir.join("p.csv"),
        "name,x,y,z,nx,ny,nz\nlamp,2,2,2.9,0,0,-1\nbelow,2,2,1.9,0,0,1\n",
    )
    .unwrap();
    let out = radiosity(
        &[
            "illuminance",
            &room(),
            "--points",
            "p.csv",
            "-o",
            "o.csv",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("warning: 1 point lies at a point light (the first: \"lamp\" at the light"),
        "{err}"
    );
    assert!(err.contains("has no value (I / d^2 at d = 0)"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn auto_takes_hierarchical_radiosity_for_a_large_scene_with_point_lights() {
    // Above 20,000 elements `auto` picks hierarchical radiosity, which takes the point
    // luminaires' first bounce at its leaves (before, it refused them and `auto` fell back
    // to progressive refinement). The CIE 171 point-source room (96 m^2) at MAX_PATCH_AREA
    // 0.004 meshes to just over 20,000 elements. (The numbers are checked in the library:
    // `hierarchical_radiosity_balances_a_point_light_and_agrees_with_the_dense_solve`.)
    let dir = scratch_dir("auto-lights");
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../validation/cie171_5_2_point_source.scene"
    );
    let out = radiosity(
        &["solve", scene, "--max-area", "0.004", "-o", "out.csv"],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("hierarchical"), "{err}");
    assert!(!err.contains("progressive refinement instead"), "{err}");
    assert!(dir.join("out.csv").exists(), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn render_false_colour_draws_lux_with_a_scale_bar_and_refuses_what_it_cannot_draw() {
    let dir = scratch_dir("false-colour");
    let out = radiosity(
        &[
            "render",
            &room(),
            "--false-colour",
            "--width",
            "64",
            "--height",
            "48",
            "-o",
            "fc.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("false colour from 0 to"), "{err}");
    let png = image::open(dir.join("fc.png")).unwrap().to_rgb8();
    // The view and a 110 pixel scale bar beside it (its values in 9 x 15 px figures);
    // the bar's height at least 160.
    assert_eq!(png.width(), 64 + 110);
    assert!(png.height() >= 160);
    // The view is coloured (the ramp has no grey), not shaded grey.
    let coloured = png
        .enumerate_pixels()
        .filter(|(x, y, _)| *x < 64 && *y < 48)
        .filter(|(_, _, p)| !(p.0[0] == p.0[1] && p.0[1] == p.0[2]))
        .count();
    assert!(coloured > 64 * 48 / 2, "{coloured}");

    for (args, expected) in [
        (
            vec!["--false-colour", "-o", "fc.exr"],
            "--false-colour draws a PNG",
        ),
        (
            vec!["--false-colour", "--shading", "wireframe", "-o", "w.png"],
            "--shading smooth or flat",
        ),
        (
            vec!["--false-colour", "--lux-max", "0", "-o", "z.png"],
            "--lux-max 0",
        ),
        // A bad number is refused whether or not the run would use it (QA pass 15).
        (vec!["--lux-max", "0", "-o", "z.png"], "--lux-max 0"),
    ] {
        let mut full = vec!["render", room_ref()];
        full.extend(args.iter().copied());
        let out = radiosity(&full, &dir);
        assert!(!out.status.success(), "{args:?} was accepted");
        assert!(
            stderr(&out).contains(expected),
            "{args:?}: {}",
            stderr(&out)
        );
    }
    // Without --false-colour, --lux-max is a flag the run does not use: a warning, as for
    // every such flag, and the render goes on.
    let out = radiosity(
        &[
            "render",
            room_ref(),
            "--lux-max",
            "100",
            "--width",
            "16",
            "--height",
            "16",
            "-o",
            "n.png",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("warning: --lux-max ignored"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

fn room_ref() -> &'static str {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/downlight_room.scene"
    )
}

/// The downlight room with a FLUX ceiling panel, every length times `unit` (1 for metres,
/// 1000 for millimetres): a grey 0.5 box of 4 x 4 x 3 m, a 1000 cd cosine downlight at
/// (2, 2, 2.9) m, and a black 1 x 1 m panel 1 cm below the ceiling, centred, facing down,
/// giving FLUX 1000 (1000 lm/m^2).
fn room_in(unit: f64) -> String {
    let l = |m: f64| m * unit;
    format!(
        "MAX_PATCH_AREA {}\nINTEGRAL_STEPS 2\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
         Er 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\nVERTICES 4\nVERTEX0 0 0 0\n\
         VERTEX1 {w} 0 0\nVERTEX2 {w} {w} 0\nVERTEX3 0 {w} 0\nHEIGHT {h}\nBOXEND\n\
         PATCHBEGIN\n#Panel\nVERTICES 4\nFLUX 1000\nRr 0\nRg 0\nRb 0\n\
         VERTEX0 {a} {a} {z}\nVERTEX1 {a} {b} {z}\nVERTEX2 {b} {b} {z}\nVERTEX3 {b} {a} {z}\n\
         PATCHEND\nLIGHTBEGIN\n#Downlight\nPOSITION {c} {c} {lz}\nINTENSITY 1000\n\
         DISTRIBUTION COSINE\nLIGHTEND\nSCENEEND\n",
        0.25 * unit * unit,
        w = l(4.0),
        h = l(3.0),
        a = l(1.5),
        b = l(2.5),
        z = l(2.99),
        c = l(2.0),
        lz = l(2.9),
    )
}

/// The rows of an illuminance CSV: the numbers after the name.
fn lux_rows(path: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|line| {
            line.split(',')
                .skip(1)
                .map(|v| v.parse().unwrap())
                .collect()
        })
        .collect()
}

#[test]
fn a_room_in_millimetres_with_scale_gives_the_lux_of_the_room_in_metres() {
    // Before, --scale moved the surfaces but not the point luminaires (the downlight stood
    // 1000 times too far away), spread a FLUX over the areas in mm^2 (10^6 times too dim)
    // and left the points in mm: the room in mm read 0.000227 lx where metres read 258.
    let dir = scratch_dir("illuminance-scale");
    std::fs::write(dir.join("m.scene"), room_in(1.0)).unwrap();
    std::fs::write(dir.join("mm.scene"), room_in(1000.0)).unwrap();
    std::fs::write(
        dir.join("m.csv"),
        "name,x,y,z,nx,ny,nz\ncentre,2,2,0.8,0,0,1\nwall,0,1,1.5,1,0,0\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("mm.csv"),
        "name,x,y,z,nx,ny,nz\ncentre,2000,2000,800,0,0,1\nwall,0,1000,1500,1,0,0\n",
    )
    .unwrap();
    for (scene, points, scale, out) in [
        ("m.scene", "m.csv", "1", "om.csv"),
        ("mm.scene", "mm.csv", "0.001", "omm.csv"),
    ] {
        let out = radiosity(
            &[
                "illuminance",
                scene,
                "--scale",
                scale,
                "--points",
                points,
                "-o",
                out,
                "-q",
            ],
            &dir,
        );
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let (m, mm) = (
        lux_rows(&dir.join("om.csv")),
        lux_rows(&dir.join("omm.csv")),
    );
    // The CSV gives the points back as written (in mm for the mm run).
    assert_eq!(&mm[0][..3], &[2000.0, 2000.0, 800.0]);
    // Direct light at the centre of the floor plane, 2.1 m below the downlight and 2.19 m
    // below the panel: I0 / 2.1^2 plus M F, F of a 1 x 1 m square centred above the point
    // (four corner rectangles of 0.5 x 0.5 m, Siegel and Howell's parallel-rectangle
    // corner formula). Exact contour integrals and clear shadow rays: 1e-9.
    let corner = |x: f64, y: f64| {
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
    };
    let h = 2.19;
    let expected = 1000.0 / (2.1 * 2.1) + 1000.0 * 4.0 * corner(0.5 / h, 0.5 / h);
    for rows in [&m, &mm] {
        assert!(
            (rows[0][6] / expected - 1.0).abs() < 1e-9,
            "{} against {expected}",
            rows[0][6]
        );
        assert!(
            rows[0][7] > 1.0,
            "the grey room reflects light: {:?}",
            rows[0]
        );
    }
    // Direct, indirect and total at both points: the same lux in mm as in m. The two runs
    // differ only in the rounding of lengths times 0.001 (1e-16 relative), which the solve
    // carries to 1e-12 or so; 1e-9 relative is far below what a unit error makes (10^6).
    for (a, b) in m.iter().zip(&mm) {
        for k in 6..9 {
            assert!((a[k] / b[k] - 1.0).abs() < 1e-9, "m {a:?}, mm {b:?}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn illuminance_refuses_a_grid_too_large_and_work_of_hours_saying_what_fits() {
    let dir = scratch_dir("illuminance-limits");
    // 0.001 m over 4 x 4 m: 4001^2 = 16 million points, above the 1,000,000 one run takes.
    // A spacing fits when floor(4 / s) + 1 <= 1000 points a side, so above 0.004: rounded
    // up to 3 significant digits, 0.00401 (998^2 = 996,004 points).
    let out = radiosity(
        &[
            "illuminance",
            &room(),
            "--grid",
            "0,0,0.8:4,4,0.8:0.001",
            "--normal",
            "0,0,1",
            "-o",
            "g.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(
        err.contains("makes 16008001 points") && err.contains("a spacing of 0.00401 or more"),
        "{err}"
    );
    // QA pass 14 of #16: past a trillion, the count is given to three digits, not with
    // the float's noise: (4 / 1e-9 + 1)^2 = 1.6e19.
    let out = radiosity(
        &[
            "illuminance",
            &room(),
            "--grid",
            "0,0,0.8:4,4,0.8:1e-9",
            "--normal",
            "0,0,1",
            "-o",
            "g.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(err.contains("makes about 1.60e19 points"), "{err}");
    // 0.005 m: 801^2 = 641,601 points. On the room's 320 elements (80 m^2 at 0.25) that
    // is 2.1e8 point-element pairs, within the 1e9 work limit; on a mesh of 0.0025 m^2
    // elements (32,000) it is 2.1e10: refused before the solve, with what fits: 31,250
    // points, so at most 176 a side (176^2 = 30,976; 177^2 = 31,329), floor(4 / s) <= 175,
    // 4 / s < 176: a spacing above 0.022727, rounded up to 3 digits 0.0228.
    let out = radiosity(
        &[
            "illuminance",
            &room(),
            "--max-area",
            "0.0025",
            "--grid",
            "0,0,0.8:4,4,0.8:0.005",
            "--normal",
            "0,0,1",
            "-o",
            "g.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(
        err.contains("641601 calculation points on")
            && err.contains("point-element pairs")
            && err.contains("at most 31250 points")
            && err.contains("for this grid, a spacing of 0.0228 or more")
            && err.contains("--no-work-limit"),
        "{err}"
    );
    assert!(!dir.join("g.csv").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn illuminance_usage_errors_name_both_ways_to_give_points() {
    // QA of issue #16: neither --points nor --grid named only --points; --png with
    // --points asked for --grid and --normal beside --points.
    let dir = scratch_dir("illuminance-usage");
    let out = radiosity(&["illuminance", "-o", "o.csv"], &dir);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--points P.csv") && err.contains("--grid") && err.contains("--normal"),
        "{err}"
    );
    std::fs::write(dir.join("p.csv"), "name,x,y,z,nx,ny,nz\na,1,1,1,0,0,1\n").unwrap();
    let out = radiosity(
        &[
            "illuminance",
            "--points",
            "p.csv",
            "--png",
            "g.png",
            "-o",
            "o.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--png draws the cells of a --grid") && !err.contains("required"),
        "{err}"
    );
    assert!(!dir.join("o.csv").exists() && !dir.join("g.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_progressive_run_stopped_early_reads_the_light_shot_so_far() {
    // QA pass 13 of #16: a point of the Cornell box read 0.425 lx indirect after one shot
    // and fell towards 0.241 lx (the dense solve) as more were shot: the ambient term, a
    // uniform guess at the unshot light, was added. Shooting only adds light, so the
    // indirect illuminance of a capped run grows with the shots and stays below the
    // converged value (dense Gauss-Seidel to a residual of 1e-9: an independent solver).
    // Tolerance 1e-9 relative: the converged value is within about that of the exact one,
    // far below the gap the ambient term made (+76 %), and 40 shots leave most of the
    // reflected light unshot, so a capped run stays well below it.
    let dir = scratch_dir("illuminance-progressive-cap");
    std::fs::write(
        dir.join("p.csv"),
        "name,x,y,z,nx,ny,nz\np1,278,400,280,0,1,0\np2,100,200,5,0,0,1\n",
    )
    .unwrap();
    let run = |solver: &[&str], out: &str| {
        let mut args = vec!["illuminance", "--points", "p.csv", "-o", out, "-q"];
        args.extend_from_slice(solver);
        let o = radiosity(&args, &dir);
        assert!(o.status.success(), "{}", stderr(&o));
        lux_rows(&dir.join(out))
    };
    let dense = run(
        &["--solver", "gauss-seidel", "--tolerance", "1e-9"],
        "dense.csv",
    );
    let mut last = vec![0.0; dense.len()];
    for shots in ["1", "5", "40"] {
        let capped = run(
            &["--solver", "progressive", "--max-shots", shots],
            &format!("shots{shots}.csv"),
        );
        for (k, row) in capped.iter().enumerate() {
            let indirect = row[7];
            assert!(
                indirect >= last[k] && indirect <= dense[k][7] * (1.0 + 1e-9),
                "point {k} after {shots} shots: {indirect} lx (before {}, converged {})",
                last[k],
                dense[k][7]
            );
            last[k] = indirect;
        }
    }
}
