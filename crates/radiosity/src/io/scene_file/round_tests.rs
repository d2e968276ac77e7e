//! The sphere, cylinder and cone primitives: their faces against closed forms, their
//! facing, their errors, an enclosed sphere's light, and the writer's round trip.

use std::f64::consts::PI;

use glam::DVec3;

use super::*;
use crate::geometry;
use crate::io::scene_file::write_scene;

/// A scene of `blocks` with the given settings.
fn scene_text(max_area: f64, blocks: &str) -> String {
    format!("MAX_PATCH_AREA {max_area}\nINTEGRAL_STEPS 1\nSCENEBEGIN\n{blocks}SCENEEND\n")
}

/// One round block: `kind` is SPHERE, CYLINDER or CONE; `geometry` its lines after the
/// colours.
fn round(kind: &str, name: &str, facing: &str, e: f64, rho: f64, geometry: &str) -> String {
    format!(
        "{kind}BEGIN\n#{name}\nFACING {facing}\nEr {e}\nEg {e}\nEb {e}\nRr {rho}\nRg {rho}\n\
         Rb {rho}\n{geometry}{kind}END\n"
    )
}

fn surfaces(text: &str) -> Vec<Surface> {
    parse_scene(text, "t.scene").unwrap().scene.surfaces
}

fn area(s: &[Surface]) -> f64 {
    s.iter().map(|s| geometry::polygon_area(&s.vertices)).sum()
}

fn sphere_area(n: u32) -> f64 {
    let g = format!("CENTER 1 2 3\nRADIUS 2\nRESOLUTION {n}\n");
    area(&surfaces(&scene_text(
        1.0,
        &round("SPHERE", "S", "OUT", 0.0, 0.5, &g),
    )))
}

#[test]
fn sphere_area_converges_to_four_pi_r_squared() {
    let exact = 4.0 * PI * 4.0;
    let deficit = |n| (exact - sphere_area(n)) / exact;
    let d: Vec<f64> = [16, 32, 64, 128, 256].into_iter().map(deficit).collect();
    // Inscribed: always short of the sphere, and second order in the angle 2 pi / n, so
    // doubling the resolution quarters the deficit (within 10 %: the next term of the
    // series is fourth order).
    for w in d.windows(2) {
        assert!(w[0] > 0.0 && w[1] > 0.0, "{d:?}");
        let ratio = w[0] / w[1];
        assert!((3.6..4.4).contains(&ratio), "{d:?}");
    }
    assert!(d[4] < 2e-4, "{d:?}");
    // The default resolution (16): the deficit the shape module states (3.2 %).
    assert!((d[0] - 0.032).abs() < 0.001, "{}", d[0]);
}

#[test]
fn sphere_faces_are_quads_and_polar_triangles_facing_out_or_in() {
    let centre = DVec3::new(1.0, 2.0, 3.0);
    for (facing, sign) in [("OUT", 1.0), ("IN", -1.0)] {
        let g = "CENTER 1 2 3\nRADIUS 2\nRESOLUTION 8\n";
        let s = surfaces(&scene_text(
            1.0,
            &round("SPHERE", "Ball", facing, 0.0, 0.5, g),
        ));
        // 8 segments x 4 bands: the two polar bands triangles, the two others quads.
        assert_eq!(s.len(), 32);
        assert_eq!(s.iter().filter(|s| s.vertices.len() == 3).count(), 16);
        assert_eq!(s[0].name, "Ball.0");
        assert_eq!(s[31].name, "Ball.31");
        for f in &s {
            let n = geometry::polygon_normal(&f.vertices).unwrap();
            let out = (geometry::polygon_centroid(&f.vertices) - centre).normalize();
            assert!(sign * n.dot(out) > 0.9, "{}: {n} {out}", f.name);
            // Every corner on the sphere.
            for v in &f.vertices {
                assert!((v.distance(centre) - 2.0).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn cylinder_area_is_the_prisms_closed_form() {
    let (r, h, n) = (1.5f64, 2.0f64, 12u32);
    let g = format!("CENTER 0 1 0\nRADIUS {r}\nHEIGHT {h}\nRESOLUTION {n}\n");
    let s = surfaces(&scene_text(
        1.0,
        &round("CYLINDER", "Pipe", "OUT", 0.0, 0.5, &g),
    ));
    assert_eq!(s.len(), 2 + n as usize);
    assert_eq!(
        (s[0].name.as_str(), s[1].name.as_str(), s[2].name.as_str()),
        ("Pipe.base", "Pipe.top", "Pipe.side0")
    );
    let nf = f64::from(n);
    // n side rectangles of width 2 r sin(pi/n), two regular n-gons of area n/2 r^2 sin(2pi/n).
    let exact = nf * 2.0 * r * (PI / nf).sin() * h + nf * r * r * (2.0 * PI / nf).sin();
    assert!(
        (area(&s) - exact).abs() < 1e-12 * exact,
        "{} {exact}",
        area(&s)
    );
    assert!(geometry::polygon_normal(&s[0].vertices).unwrap().y < -0.999_999);
    assert!(geometry::polygon_normal(&s[1].vertices).unwrap().y > 0.999_999);
    // The top at y = 1 + h.
    assert!(s[1].vertices.iter().all(|v| (v.y - 3.0).abs() < 1e-12));
    for f in &s[2..] {
        let n = geometry::polygon_normal(&f.vertices).unwrap();
        let c = geometry::polygon_centroid(&f.vertices);
        assert!(
            n.dot(DVec3::new(c.x, 0.0, c.z).normalize()) > 0.99,
            "{}",
            f.name
        );
    }
}

#[test]
fn cone_area_is_the_pyramids_closed_form() {
    let (r, h, n) = (1.0f64, 3.0f64, 10u32);
    let g = format!("CENTER 0 0 0\nRADIUS {r}\nHEIGHT {h}\nRESOLUTION {n}\n");
    let s = surfaces(&scene_text(1.0, &round("CONE", "Hat", "IN", 0.0, 0.5, &g)));
    assert_eq!(s.len(), 1 + n as usize);
    let nf = f64::from(n);
    // Base n-gon; each side a triangle of base 2 r sin(pi/n) and slant height (apex to the
    // base edge's midpoint) sqrt(h^2 + (r cos(pi/n))^2).
    let base = nf / 2.0 * r * r * (2.0 * PI / nf).sin();
    let slant = (h * h + (r * (PI / nf).cos()).powi(2)).sqrt();
    let exact = base + nf * r * (PI / nf).sin() * slant;
    assert!((area(&s) - exact).abs() < 1e-12 * exact);
    // Facing in: the base looks up, into the cone.
    assert!(geometry::polygon_normal(&s[0].vertices).unwrap().y > 0.999_999);
    assert_eq!(s[10].name, "Hat.side9");
}

#[test]
fn round_primitive_errors_name_their_line() {
    let cases = [
        (
            round("SPHERE", "S", "OUT", 0.0, 0.5, "CENTER 0 0 0\nRADIUS 0\n"),
            "t.scene:14:8: error: RADIUS must be greater than 0, found \"0\"",
        ),
        (
            round(
                "SPHERE",
                "S",
                "OUT",
                0.0,
                0.5,
                "CENTER 0 0 0\nRADIUS 1\nRESOLUTION 2\n",
            ),
            "t.scene:15:12: error: RESOLUTION must be a whole number from 3 to 512 (the \
             segments round the axis), found \"2\"",
        ),
        (
            round(
                "SPHERE",
                "S",
                "OUT",
                0.0,
                0.5,
                "CENTER 0 0 0\nRADIUS 1\nRESOLUTION 513\n",
            ),
            "t.scene:15:12: error: RESOLUTION must be a whole number from 3 to 512 (the \
             segments round the axis), found \"513\"",
        ),
        (
            round("CYLINDER", "C", "OUT", 0.0, 0.5, "CENTER 0 0 0\nRADIUS 1\n"),
            "t.scene:15:1: error: expected HEIGHT, found \"CYLINDEREND\"",
        ),
        (
            round(
                "CONE",
                "C",
                "OUT",
                0.0,
                0.5,
                "RADIUS 1\nCENTER 0 0 0\nHEIGHT 1\n",
            ),
            "t.scene:13:1: error: expected CENTER, found \"RADIUS\"",
        ),
        (
            round("SPHERE", "S", "OUT", 0.0, 0.5, "CENTER 0 0 nan\nRADIUS 1\n"),
            "t.scene:13:12: error: expected a finite number (the z coordinate) after \
             \"CENTER\", found \"nan\"",
        ),
        (
            round(
                "SPHERE",
                "Dot",
                "OUT",
                0.0,
                0.5,
                "CENTER 1e20 1e20 1e20\nRADIUS 1e-20\n",
            ),
            "t.scene:14:1: error: the sphere's face \"Dot.0\" is not a usable polygon: \
             degenerate polygon: vertices 0 and 1 are the same point (the sphere is too small \
             or too thin for its position, or too large; rescale the scene or change \
             RESOLUTION)",
        ),
    ];
    for (block, expected) in cases {
        let e = parse_scene(&scene_text(1.0, &block), "t.scene").unwrap_err();
        assert_eq!(e.errors[0].to_string(), expected, "{block}");
    }
    // After a bad primitive the reader carries on to the next block.
    let two = format!(
        "{}{}",
        round("SPHERE", "S", "OUT", 0.0, 0.5, "CENTER 0 0 0\nRADIUS -1\n"),
        round(
            "CONE",
            "C",
            "OUT",
            0.0,
            0.5,
            "CENTER 0 0 0\nRADIUS 1\nHEIGHT 0\n"
        )
    );
    let e = parse_scene(&scene_text(1.0, &two), "t.scene").unwrap_err();
    assert_eq!(e.errors.len(), 2, "{e}");
}

#[test]
fn primitives_round_trip_through_the_writer() {
    let blocks = format!(
        "{}{}{}",
        round(
            "SPHERE",
            "Ball",
            "OUT",
            0.0,
            0.5,
            "CENTER 0.1 0.2 0.3\nRADIUS 0.7\nRESOLUTION 9\n"
        ),
        round(
            "CYLINDER",
            "Pipe",
            "IN",
            1.0,
            0.25,
            "CENTER 3 0 0\nRADIUS 0.5\nHEIGHT 2\n"
        ),
        round(
            "CONE",
            "Hat",
            "OUT",
            0.0,
            0.75,
            "CENTER -3 0 0\nRADIUS 1\nHEIGHT 1\nRESOLUTION 5\n"
        ),
    );
    let file = parse_scene(&scene_text(0.5, &blocks), "t.scene").unwrap();
    // 9 segments x 4 bands, 16 + 2 (default resolution), 5 + 1.
    assert_eq!(file.scene.surfaces.len(), 36 + 18 + 6);
    let mut text = Vec::new();
    write_scene(&file.scene, file.settings, &mut text).unwrap();
    let back = parse_scene(std::str::from_utf8(&text).unwrap(), "written.scene").unwrap();
    assert_eq!(back, file);
}

/// A sphere inside a closed room, every surface emitting E and reflecting rho: with every
/// row of form factors summing to 1 (a closed enclosure), B = E + rho B everywhere, so
/// B = E / (1 - rho) exactly; the emitted power is all absorbed, none escapes.
#[test]
fn enclosed_sphere_conserves_energy() {
    use crate::pipeline::{self, Prepared, SolveRequest};
    use crate::progress::NoProgress;
    use crate::solve::Solver;
    let (e, rho) = (1.0, 0.5);
    let room = "BOXBEGIN\n#Room\nFACING IN\nEr 1\nEg 1\nEb 1\nRr 0.5\nRg 0.5\nRb 0.5\n\
                ORIGIN -2 -2 -2\nSIZE 4 4 4\nBOXEND\n";
    let ball = round(
        "SPHERE",
        "Ball",
        "OUT",
        e,
        rho,
        "CENTER 0 0 0\nRADIUS 1\nRESOLUTION 8\n",
    );
    let file = parse_scene(&scene_text(2.0, &format!("{room}{ball}")), "t.scene").unwrap();
    let mut prepared = Prepared::new(file.scene, file.settings, &NoProgress).unwrap();
    // Lambert's exact point-to-polygon form factor: accurate where elements share an edge,
    // as every sphere face and room corner does.
    prepared.method = crate::form_factor::FormFactorMethod::Analytic { steps: 2 };
    let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
    let solution = pipeline::solve(
        &prepared,
        &request,
        &mut crate::solve::keep_going,
        &NoProgress,
    )
    .unwrap();
    let balance = solution.balance;
    let escaped = balance.escaped[0] / balance.emitted[0];
    let b = solution.radiosity.as_slice();
    let worst = b
        .iter()
        .map(|x| (x.0[0] - e / (1.0 - rho)).abs())
        .fold(0.0, f64::max);
    // Emitted = absorbed + escaped to the Gauss-Seidel tolerance (measured 6e-6).
    assert!(balance.relative_error() < 1e-4, "{balance:?}");
    // What escapes is the rows' shortfall from 1: the point-to-polygon estimate with 2 x 2
    // visibility samples per element, where the sphere shadows the room (measured 1.2 %;
    // twice that allowed). With it B falls short of E / (1 - rho) by as much as the
    // shortfall times the bounces (measured 1.0 % at worst; 2.5 times that allowed).
    assert!(escaped < 0.025, "escaped {escaped}");
    assert!(worst < 0.025 * e / (1.0 - rho), "worst B error {worst}");
}
