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
    // The view and a 100 pixel scale bar beside it; the bar's height at least 160.
    assert_eq!(png.width(), 64 + 100);
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
        (vec!["--lux-max", "100", "-o", "n.png"], "--false-colour"),
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
    std::fs::remove_dir_all(&dir).unwrap();
}

fn room_ref() -> &'static str {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/downlight_room.scene"
    )
}
