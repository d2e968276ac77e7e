//! Illuminance at points against closed forms.

use std::f64::consts::PI;

use glam::{dvec3, DVec3};

use super::*;
use crate::pipeline::{solve, SolveRequest};
use crate::progress::NoProgress;
use crate::solve::{keep_going, DenseSolver, Solver};

fn solved(text: &str) -> (Prepared, Solution) {
    let file = crate::io::scene_file::parse_scene(text, "t.scene").unwrap();
    let p = Prepared::new(file.scene, file.settings, &NoProgress).unwrap();
    let s = solve(
        &p,
        &SolveRequest::new(Solver::Dense(DenseSolver::Lu)),
        &mut keep_going,
        &NoProgress,
    )
    .unwrap();
    (p, s)
}

fn at(x: f64, y: f64, z: f64, n: DVec3) -> CalcPoint {
    CalcPoint {
        name: "p".into(),
        position: dvec3(x, y, z),
        normal: n,
    }
}

/// A black 10 m x 10 m floor (nothing reflected) and `extra` blocks.
fn black_floor(extra: &str) -> String {
    format!(
        "MAX_PATCH_AREA 100\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#Floor\nVERTICES 4\n\
         Er 0\nEg 0\nEb 0\nRr 0\nRg 0\nRb 0\nVERTEX0 -5 -5 0\nVERTEX1 5 -5 0\nVERTEX2 5 5 0\n\
         VERTEX3 -5 5 0\nPATCHEND\n{extra}\nSCENEEND\n"
    )
}

#[test]
fn a_point_source_gives_i_cos_over_d_squared_and_nothing_indirect() {
    let (p, s) = solved(&black_floor(
        "LIGHTBEGIN\n#L\nPOSITION 0 0 2\nINTENSITY 1000\nDISTRIBUTION ISOTROPIC\nLIGHTEND",
    ));
    for x in [0.0, 1.0, 2.0, 4.0] {
        let lux = illuminance(&p, &s, &[at(x, 0.0, 0.0, DVec3::Z)])[0];
        let d2 = x * x + 4.0;
        let want = 1000.0 * (2.0 / d2.sqrt()) / d2;
        assert!(
            (lux.direct - want).abs() < 1e-9 * want,
            "{x}: {lux:?} {want}"
        );
        assert_eq!(lux.indirect, 0.0);
        assert_eq!(lux.total, lux.direct);
    }
}

#[test]
fn an_area_source_gives_its_exitance_times_the_exact_form_factor() {
    // A 2 m x 2 m LUMINANCE 1000 panel facing down, 2 m above the origin: on the axis, the
    // form factor to a parallel square is four corner rectangles with X = Y = a / h = 1/2,
    // F = 1/(2 pi) (X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))).
    let (p, s) = solved(&black_floor(
        "PATCHBEGIN\n#Panel\nVERTICES 4\nLUMINANCE 1000\nRr 0\nRg 0\nRb 0\n\
         VERTEX0 -1 -1 2\nVERTEX1 -1 1 2\nVERTEX2 1 1 2\nVERTEX3 1 -1 2\nPATCHEND",
    ));
    let x: f64 = 0.5;
    let q = (1.0 + x * x).sqrt();
    let corner = 1.0 / (2.0 * PI) * (2.0 * x / q * (x / q).atan());
    let want = PI * 1000.0 * 4.0 * corner;
    let lux = illuminance(&p, &s, &[at(0.0, 0.0, 0.0, DVec3::Z)])[0];
    assert!((lux.direct - want).abs() < 1e-9 * want, "{lux:?} {want}");
    assert_eq!(lux.indirect, 0.0);
}

#[test]
fn in_a_glowing_closed_box_direct_is_e_and_the_total_is_e_over_one_minus_rho() {
    // Every wall emits E = 100 and reflects rho = 0.5: B = E / (1 - rho) = 200 everywhere,
    // and any point inside, facing any way, sees walls only: direct = E (the exact form
    // factors add up to 1), indirect = B - E = 100.
    let text = "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 3\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
                Er 100\nEg 100\nEb 100\nRr 0.5\nRg 0.5\nRb 0.5\nORIGIN 0 0 0\nSIZE 2 2 2\n\
                BOXEND\nSCENEEND\n";
    let (p, s) = solved(text);
    let points = [
        at(1.0, 1.0, 1.0, DVec3::Z),
        at(0.5, 1.5, 0.3, dvec3(1.0, -2.0, 0.5)),
        at(1.0, 1.0, 0.0, DVec3::Y),
    ];
    for lux in illuminance(&p, &s, &points) {
        assert!((lux.direct - 100.0).abs() < 1e-9, "{lux:?}");
        // The solve's form factors (area integral, 3 x 3 points, elements 1 m^2 in a 2 m
        // box) keep row sums to about 1 %, which the indirect part inherits; 3 % catches
        // any missing bounce (a single bounce would give 50).
        assert!((lux.indirect / 100.0 - 1.0).abs() < 0.03, "{lux:?}");
    }
}

#[test]
fn a_grid_runs_from_corner_to_corner_at_the_spacing() {
    let (pts, dims) = grid(
        dvec3(0.0, 0.0, 0.8),
        dvec3(2.0, 1.0, 0.8),
        0.5,
        DVec3::Z,
        100,
    )
    .unwrap();
    assert_eq!(dims, [5, 3]);
    assert_eq!(pts.len(), 15);
    assert_eq!(pts[0].position, dvec3(0.0, 0.0, 0.8));
    assert_eq!(pts[14].position, dvec3(2.0, 1.0, 0.8));
    assert_eq!(pts[6].name, "g1_1");
    // Reversed corners go the other way; a spacing that does not divide stops inside.
    let (pts, dims) = grid(
        dvec3(1.0, 0.0, 0.0),
        dvec3(0.0, 0.0, 0.0),
        0.3,
        DVec3::Z,
        100,
    )
    .unwrap();
    assert_eq!(dims, [4, 1]);
    assert!((pts[3].position.x - 0.1).abs() < 1e-12);
    assert!(grid(DVec3::ZERO, DVec3::ONE, 0.5, DVec3::Z, 100).is_none());
    assert!(grid(DVec3::ZERO, DVec3::X, 0.0, DVec3::Z, 100).is_none());
    assert!(grid(DVec3::ZERO, dvec3(100.0, 100.0, 0.0), 0.01, DVec3::Z, 1000).is_none());
}

#[test]
fn points_files_are_read_and_bad_lines_named() {
    let pts = parse_points(
        "name,x,y,z,nx,ny,nz\nA,1,2,3,0,0,1\n\nB, 0.5 ,0,0,0,1,0\n",
        "p.csv",
    )
    .unwrap();
    assert_eq!(pts.len(), 2);
    assert_eq!(pts[1].position, dvec3(0.5, 0.0, 0.0));
    assert_eq!(pts[1].normal, DVec3::Y);
    let err = |t: &str| parse_points(t, "p.csv").unwrap_err().to_string();
    assert_eq!(
        err("name,x,y\n"),
        "p.csv:1: error: expected the header \"name,x,y,z,nx,ny,nz\", found \"name,x,y\""
    );
    assert!(
        err("name,x,y,z,nx,ny,nz\nA,1,2,3,0,0\n").starts_with("p.csv:2: error: expected 7 fields")
    );
    assert!(
        err("name,x,y,z,nx,ny,nz\nA,1,q,3,0,0,1\n").contains("finite number for y, found \"q\"")
    );
    assert!(err("name,x,y,z,nx,ny,nz\nA,1,2,3,0,0,0\n").contains("the normal nx,ny,nz is 0,0,0"));
    let mut out = Vec::new();
    write_lux_csv(
        &pts[..1],
        &[Lux {
            direct: 1.5,
            indirect: 0.25,
            total: 1.75,
        }],
        &mut out,
    )
    .unwrap();
    assert_eq!(
        String::from_utf8(out).unwrap(),
        "name,x,y,z,nx,ny,nz,direct_lux,indirect_lux,total_lux\nA,1,2,3,0,0,1,1.5,0.25,1.75\n"
    );
}

#[test]
fn the_grid_picture_colours_cells_by_value_with_a_legend() {
    // 3 x 2 cells, values rising along the row; the largest is red, 0 dark blue.
    let values = [0.0, 50.0, 100.0, 25.0, 75.0, 100.0];
    let img = grid_picture(&values, [3, 2]);
    assert!(img.width() > 3 * 24 && img.height() >= 240);
    assert_eq!(false_colour(0.0), [0, 0, 153]);
    assert_eq!(false_colour(1.0), [230, 26, 0]);
    // Row 0 is drawn at the bottom: cell (0, 0) holds 0 (dark blue) at its corner pixel
    // just inside the white grid line.
    let cell = (img.width() as i64 - 20 - 90) / 3;
    let bottom_left = img.get_pixel(10 + 1, (10 + 2 * cell - 2) as u32).0;
    assert_eq!(bottom_left, false_colour(0.0));
    let top_left = img.get_pixel(10 + 1, 10 + 1).0;
    assert_eq!(top_left, false_colour(0.25));
    assert_eq!(lux_label(1234.4), "1234");
    assert_eq!(lux_label(12.34), "12.3");
    assert_eq!(lux_label(1.234), "1.23");
}

#[test]
fn element_illuminance_reads_the_solution_back_and_computes_black_surfaces() {
    // The glowing box: E = 100, rho = 0.5, B = E / (1 - rho) = 200, so every element
    // receives H = (B - E) / rho = 200 lux (within the solve's 1 % row sums; 3 % tells it
    // from a single bounce's 150 or the exitance's 200 + 100).
    let text = "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 3\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
                Er 100\nEg 100\nEb 100\nRr 0.5\nRg 0.5\nRb 0.5\nORIGIN 0 0 0\nSIZE 2 2 2\n\
                BOXEND\nSCENEEND\n";
    let (p, s) = solved(text);
    let lux = element_illuminance(&p, &s);
    assert_eq!(lux.len(), s.mesh.len());
    for v in &lux {
        assert!((v / 200.0 - 1.0).abs() < 0.03, "{v}");
    }
    // A black floor (one 100 m^2 element, centroid at the origin) 2 m below a 1000 cd
    // isotropic light: nothing to read back, so the centroid's I / d^2 = 250 lux.
    let (p, s) = solved(&black_floor(
        "LIGHTBEGIN\n#L\nPOSITION 0 0 2\nINTENSITY 1000\nDISTRIBUTION ISOTROPIC\nLIGHTEND",
    ));
    let lux = element_illuminance(&p, &s);
    assert_eq!(lux.len(), 1);
    assert!((lux[0] - 250.0).abs() < 1e-9, "{}", lux[0]);
}

#[test]
fn the_false_colour_picture_colours_pixels_by_lux_on_white_with_a_scale_bar() {
    // Three pixels: at the top of the scale, at half of it with half coverage (blended
    // half-way to white), and background.
    let img = false_colour_picture(&[200.0, 100.0, 0.0], &[1.0, 0.5, 0.0], 3, 1, 200.0, 4);
    assert_eq!(img.width(), 3 + SCALE_BAR_WIDTH);
    assert!(img.height() >= 160);
    assert_eq!(img.get_pixel(0, 0).0, false_colour(1.0));
    let half = false_colour(0.5).map(|c| ((c as f64 + 255.0) / 2.0).round() as u8);
    assert_eq!(img.get_pixel(1, 0).0, half);
    assert_eq!(img.get_pixel(2, 0).0, [255; 3]);
    // Brighter than the top of the scale: the top colour.
    let img = false_colour_picture(&[500.0], &[1.0], 1, 1, 200.0, 4);
    assert_eq!(img.get_pixel(0, 0).0, false_colour(1.0));
    // The bar: the top colour near its top, the bottom colour near its bottom (the bar is
    // 18 px wide, 8 px right of the view, from y = 30 to 16 px above the bottom).
    let (x, h) = (1 + 8 + 9, img.height());
    assert_eq!(img.get_pixel(x, 30).0, false_colour(1.0));
    assert_eq!(img.get_pixel(x, h - 17).0, false_colour(0.0));
    // Black text ("lx" and the values) left of and beside the bar.
    let inked = (0..img.height())
        .flat_map(|y| (x + 20..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0 == [0; 3])
        .count();
    assert!(inked > 50, "{inked}");
}

#[test]
fn nice_scales_step_in_round_numbers() {
    // 150.3: 8 steps of 20 (160) is the tightest of 4-8 steps of 1, 2, 2.5, 5 x 10^k.
    assert_eq!(nice_scale(150.3), (160.0, 8));
    // A round value is its own top: 100 as 4 steps of 25 (or 5 of 20: the first found).
    assert_eq!(nice_scale(100.0).0, 100.0);
    // Small and large values: 0.37 -> 0.4 (4 x 0.1, or 8 x 0.05); 12 345 -> 12 500 (5 x 2500).
    assert!((nice_scale(0.37).0 - 0.4).abs() < 1e-12);
    assert_eq!(nice_scale(12_345.0), (12_500.0, 5));
    assert_eq!(nice_scale(0.0), (0.0, 5));
}
