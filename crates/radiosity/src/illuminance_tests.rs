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
    // A name given twice, or none: the lux CSV's rows are told apart by name.
    assert_eq!(
        err("name,x,y,z,nx,ny,nz\nA,1,2,3,0,0,1\nA,1,2,3,0,0,1\n"),
        "p.csv:3: error: the name \"A\" is already the point's on line 2; give each point its \
         own name, which labels its row of the lux CSV"
    );
    assert!(err("name,x,y,z,nx,ny,nz\n ,1,2,3,0,0,1\n").contains("the point has no name"));
    // Every wrong line is found, the first ten named (QA of issue #16: one at a time).
    let mut many = String::from("name,x,y,z,nx,ny,nz\nA,1,2,3,0,0,1\nB,1,2\n");
    for k in 0..12 {
        many += &format!("P{k},1,2,3,0,0,0\n");
    }
    let e = err(&many);
    let lines: Vec<&str> = e.lines().collect();
    assert_eq!(lines.len(), 11, "{e}");
    assert!(
        lines[0].starts_with("p.csv:3: error: expected 7 fields"),
        "{e}"
    );
    assert!(lines[9].starts_with("p.csv:12: error: the normal"), "{e}");
    assert_eq!(lines[10], "... and 3 more lines like these");
    // A header and nothing else is a mistake, not an empty table (QA of issue #16).
    assert!(
        err("name,x,y,z,nx,ny,nz\n\n").starts_with("p.csv:2: error: no points after the header")
    );
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
fn a_quoted_name_may_hold_commas_and_comes_back_quoted() {
    // QA pass 13 of #16: `solve` writes names such as "Desk, north" quoted, and the points
    // reader split them at the comma ("expected 7 fields, found 8").
    let pts = parse_points(
        "name,x,y,z,nx,ny,nz\n\"Desk, north\",1,2,3,0,0,1\n\" sill \"\"A\"\"\", 4,5,6,0,1,0\n",
        "p.csv",
    )
    .unwrap();
    assert_eq!(pts[0].name, "Desk, north");
    assert_eq!(pts[0].position, dvec3(1.0, 2.0, 3.0));
    // Quoted: kept as written, inner space and doubled quotes included.
    assert_eq!(pts[1].name, " sill \"A\"");
    assert_eq!(pts[1].position, dvec3(4.0, 5.0, 6.0));
    let lux = Lux {
        direct: 1.0,
        indirect: 2.0,
        total: 3.0,
    };
    let mut out = Vec::new();
    write_lux_csv(&pts, &[lux, lux], &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains("\n\"Desk, north\",1,2,3,0,0,1,1,2,3\n\" sill \"\"A\"\"\",4,5,6,"),
        "{text}"
    );
    // And what it writes reads back as the same points.
    let back: String = text
        .lines()
        .map(|l| l.rsplitn(4, ',').last().unwrap().to_string() + "\n")
        .collect::<String>()
        .replacen(
            "name,x,y,z,nx,ny,nz,direct_lux,indirect_lux,total_lux",
            "name,x,y,z,nx,ny,nz",
            1,
        );
    let err = parse_points("name,x,y,z,nx,ny,nz\n\"Desk,1,2,3,0,0,1\n", "p.csv").unwrap_err();
    assert!(
        err.to_string()
            .starts_with("p.csv:2: error: a quote is not closed"),
        "{err}"
    );
    let again = parse_points(&back, "lux.csv").unwrap();
    assert_eq!(again[0].name, pts[0].name);
    assert_eq!(again[1].name, pts[1].name);
}

#[test]
fn the_grid_picture_colours_cells_by_value_with_a_legend() {
    // 3 x 2 cells, values rising along the row; the largest is red, 0 dark blue.
    let values = [0.0, 50.0, 100.0, 25.0, 75.0, 100.0];
    let img = grid_picture(&values, [3, 2]);
    assert!(img.height() >= 260);
    assert_eq!(false_colour(0.0), [0, 0, 153]);
    assert_eq!(false_colour(1.0), [230, 26, 0]);
    // The cells are 38 px: the widest value, "50.0", is 4 glyphs of 8 px less the last
    // gap (30 px), plus 8. Row 0 is drawn at the bottom: cell (0, 0) holds 0 (dark blue)
    // at its corner pixel just inside the white grid line; the top of the scale is 100
    // (a round number already), so 25 is a quarter of it.
    let cell = 38;
    let (x, top) = ((GRID_MARGIN + 1) as u32, GRID_TOP);
    let bottom_left = img.get_pixel(x, (top + 2 * cell - 2) as u32).0;
    assert_eq!(bottom_left, false_colour(0.0));
    let top_left = img.get_pixel(x, (top + 1) as u32).0;
    assert_eq!(top_left, false_colour(0.25));
    // The summary line is drawn above the cells: black ink between y = 10 and 20.
    let inked = (10..20)
        .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0 == [0; 3])
        .count();
    assert!(inked > 100, "{inked}");
    assert_eq!(lux_label(1234.4), "1234");
    assert_eq!(lux_label(12.34), "12.3");
    assert_eq!(lux_label(1.234), "1.23");
    // Dim and bright values keep two or three significant figures.
    assert_eq!(lux_label(0.01434), "0.014");
    assert_eq!(lux_label(0.001234), "0.0012");
    assert_eq!(lux_label(0.0), "0");
    assert_eq!(lux_label(2.5e-9), "2.5e-9");
    assert_eq!(lux_label(4.5e30), "4.50e30");
}

#[test]
fn the_grid_summary_gives_min_mean_max_and_the_uniformity() {
    // 40, 60, 80, 100: mean 70, U0 = 40 / 70 = 0.571.
    let s = GridSummary::of(&[40.0, 60.0, 80.0, 100.0, f64::NAN]).unwrap();
    assert_eq!((s.min, s.mean, s.max), (40.0, 70.0, 100.0));
    assert!((s.uniformity() - 4.0 / 7.0).abs() < 1e-15);
    assert_eq!(s.line(), "MIN 40.0  MEAN 70.0  MAX 100 lx  U0 0.57");
    // A dark grid: U0 0, not a division by zero, and drawn as "-" (it has no value).
    let dark = GridSummary::of(&[0.0, 0.0]).unwrap();
    assert_eq!(dark.uniformity(), 0.0);
    assert_eq!(dark.line(), "MIN 0  MEAN 0  MAX 0 lx  U0 -");
    assert_eq!(GridSummary::of(&[]), None);
    // Every character of a summary line has a glyph (none is skipped in the picture).
    for c in s.line().chars() {
        assert!(glyph(c).is_some(), "{c:?}");
    }
}

#[test]
fn tick_labels_have_the_decimals_of_their_step() {
    // 160 in 8 steps of 20: whole numbers (before, "0.00" and "20.0" beside "100").
    assert_eq!(
        tick_labels(160.0, 8),
        ["0", "20", "40", "60", "80", "100", "120", "140", "160"]
    );
    // 250 in 5 steps of 50 (the 5.7 view's scale read "0.00", "50.0", "100").
    assert_eq!(
        tick_labels(250.0, 5),
        ["0", "50", "100", "150", "200", "250"]
    );
    // Steps of 0.25 need two decimals, of 0.5 one, of 2500 none.
    assert_eq!(
        tick_labels(1.25, 5),
        ["0.00", "0.25", "0.50", "0.75", "1.00", "1.25"]
    );
    assert_eq!(
        tick_labels(2.5, 5),
        ["0.0", "0.5", "1.0", "1.5", "2.0", "2.5"]
    );
    assert_eq!(tick_labels(12_500.0, 5)[5], "12500");
    // Past the bar's room, or finer than 4 decimals: exponents (QA pass 14 of #16).
    // 123456 / 5 = 24691.2: 2.47E4, 4.94E4, 7.41E4, 9.88E4, 1.23E5.
    assert_eq!(
        tick_labels(123_456.0, 5),
        ["0", "2.47E4", "4.94E4", "7.41E4", "9.88E4", "1.23E5"]
    );
    assert_eq!(tick_labels(1e-6, 5)[1..3], ["2.0E-7", "4.0E-7"]);
    assert_eq!(tick_labels(1e30, 5)[5], "1.0E30");
    assert_eq!(tick_labels(1e-30, 5)[1], "2E-31");
    // A step of 2.5e-4 needs 5 decimals: not 0.0003, 0.0005, ... (review of #16).
    assert_eq!(tick_labels(1e-3, 4)[1..3], ["2.5E-4", "5.0E-4"]);
    // A nice scale's top of 1.25 x 10^6 keeps its three digits.
    assert_eq!(tick_labels(1.25e6, 5)[5], "1.25E6");
    // Each label fits the scale bar beside a view at the legend's font.
    for (max, ticks) in [
        (12_500.0, 5),
        (0.4, 8),
        (1.25, 5),
        (123_456.0, 5),
        (1e30, 7),
        (1e-30, 8),
        (1e-6, 7),
    ] {
        for label in tick_labels(max, ticks) {
            assert!(
                27 + text_width(&label, LEGEND_FONT) <= SCALE_BAR_WIDTH as i64 - 8,
                "{label}"
            );
        }
    }
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
    // 18 px wide, 8 px right of the view, from y = 34 to 16 px above the bottom).
    let (x, h) = (1 + 8 + 9, img.height());
    assert_eq!(img.get_pixel(x, 34).0, false_colour(1.0));
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
    assert_eq!(nice_scale(0.0), (1.0, 5));
}

#[test]
fn illuminance_reports_one_unit_of_progress_per_point() {
    use std::sync::atomic::{AtomicU64, Ordering};
    struct Count(AtomicU64);
    impl crate::progress::Progress for Count {
        fn start(&self, _: crate::progress::Stage, _: u64) {}
        fn advance(&self, done: u64) {
            self.0.fetch_add(done, Ordering::Relaxed);
        }
        fn finish(&self, _: crate::progress::Stage, _: std::time::Duration) {}
    }
    let (p, s) = solved(&black_floor(
        "LIGHTBEGIN\n#L\nPOSITION 0 0 2\nINTENSITY 1000\nDISTRIBUTION ISOTROPIC\nLIGHTEND",
    ));
    // 7 points, one of them with no normal (it returns early and still counts).
    let mut points: Vec<CalcPoint> = (0..6)
        .map(|k| at(k as f64 * 0.5, 0.0, 0.0, DVec3::Z))
        .collect();
    points.push(at(0.0, 0.0, 0.0, DVec3::ZERO));
    let count = Count(AtomicU64::new(0));
    let lux = illuminance_with_progress(&p, &s, &points, &count);
    assert_eq!(count.0.load(Ordering::Relaxed), 7);
    // The same numbers as without progress: at (0, 0, 0), 2 m below 1000 cd, 250 lx.
    assert_eq!(lux, illuminance(&p, &s, &points));
    assert!((lux[0].total - 250.0).abs() < 1e-9);
}

#[test]
fn the_grid_picture_prints_the_coordinates_of_its_columns_and_rows() {
    // The work plane of the README's example: x from 0.25 every 0.5 (columns), z from 0.25
    // every 0.5 (rows), at y = 0.8.
    let axes = GridAxes::of(dvec3(0.25, 0.8, 0.25), dvec3(4.75, 0.8, 3.75), 0.5).unwrap();
    assert_eq!(axes.names, ['x', 'z']);
    assert_eq!(axes.labels(0, 3), ["0.25", "0.75", "1.25"]);
    assert_eq!(axes.labels(1, 8)[7], "3.75");
    // Whole spacings print whole numbers; a grid run backwards counts down.
    let back = GridAxes::of(dvec3(4.0, 2.0, 0.0), dvec3(0.0, 0.0, 0.0), 1.0).unwrap();
    assert_eq!(back.names, ['x', 'y']);
    assert_eq!(back.labels(0, 5), ["4", "3", "2", "1", "0"]);
    assert_eq!(back.labels(1, 3), ["2", "1", "0"]);
    // A line's one row is labelled by the first axis it does not vary along (QA of issue
    // #16: it had no coordinates); a point has none.
    let line = GridAxes::of(dvec3(0.0, 1.0, 2.0), dvec3(1.0, 1.0, 2.0), 0.5).unwrap();
    assert_eq!(line.names, ['x', 'y']);
    assert_eq!(line.labels(0, 3), ["0.0", "0.5", "1.0"]);
    assert_eq!(line.labels(1, 1), ["1"]);
    assert_eq!(GridAxes::of(DVec3::ONE, DVec3::ONE, 0.5), None);
    // Drawn: ink left of the cells (the row labels) and below them (the column labels),
    // none there without axes.
    let values = [10.0, 20.0, 30.0, 40.0, 50.0, 60.0];
    let ink = |img: &image::RgbImage, x0: u32, x1: u32, y0: u32, y1: u32| {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0 == [0; 3])
            .count()
    };
    let with = grid_picture_with_axes(&values, [3, 2], Some(axes), "");
    let without = grid_picture(&values, [3, 2]);
    // The cells are 38 px ("10.0": 30 px + 8); 2 rows from GRID_TOP, labels 6 px below.
    let below = (GRID_TOP + 2 * 38 + 6) as u32;
    assert!(ink(&with, 0, 150, below, below + 10) > 40);
    // Row labels ("0.25", 30 px) end 6 px left of the cells, which start at 10 + 30 + 8.
    assert!(ink(&with, 10, 42, GRID_TOP as u32, below) > 40);
    assert_eq!(ink(&without, 0, 120, below, below + 10), 0);
}

/// QA of issue #16: a y-up floor grid was drawn as the plan seen from below (z up the
/// picture), and (pass 12) a wall's height ran down where its corners were given high to
/// low. Plans are seen from above with x to the right; a wall's height runs up.
#[test]
fn grids_are_drawn_as_plans_and_elevations() {
    let grid = |a: DVec3, b: DVec3| GridAxes::of(a, b, 1.0).unwrap();
    // A z-up floor: y up the picture, whichever corner comes first.
    let floor = grid(dvec3(0.0, 0.0, 0.8), dvec3(2.0, 3.0, 0.8));
    assert!(!floor.as_drawn(true).rows_down);
    assert!(
        grid(dvec3(0.0, 3.0, 0.8), dvec3(2.0, 0.0, 0.8))
            .as_drawn(true)
            .rows_down
    );
    // A y-up floor: z down the picture.
    let y_up = grid(dvec3(0.0, 0.8, 0.0), dvec3(2.0, 0.8, 3.0));
    assert_eq!(y_up.names, ['x', 'z']);
    assert!(y_up.as_drawn(false).rows_down);
    assert!(
        !grid(dvec3(0.0, 0.8, 3.0), dvec3(2.0, 0.8, 0.0))
            .as_drawn(false)
            .rows_down
    );
    // Walls: y-up (x, y) and z-up (x, z) have their height up.
    assert!(
        !grid(dvec3(0.5, 0.5, 3.99), dvec3(4.5, 2.5, 3.99))
            .as_drawn(false)
            .rows_down
    );
    assert!(
        grid(dvec3(0.5, 2.5, 3.99), dvec3(4.5, 0.5, 3.99))
            .as_drawn(false)
            .rows_down
    );
    assert!(
        !grid(dvec3(0.0, 3.9, 0.0), dvec3(4.0, 3.9, 2.5))
            .as_drawn(true)
            .rows_down
    );
    // Drawn: the cell of row 0 (the least value) at the top when rows run down.
    let values = [1.0, 1.0, 100.0, 100.0];
    let drawn = |axes: GridAxes| grid_picture_with_axes(&values, [2, 2], Some(axes), "");
    let top_left = |img: &image::RgbImage| {
        let c = img.get_pixel(60, (GRID_TOP + 10) as u32).0;
        c[0] as u32 + c[1] as u32 + c[2] as u32
    };
    let (down, up) = (drawn(y_up.as_drawn(false)), drawn(y_up));
    assert_ne!(top_left(&down), top_left(&up));
}

/// QA pass 17 of #16: the grid of a wall was drawn with x to the right whichever way the
/// wall faced, so the far wall of a room came out as seen from behind it. Seen from the
/// side the meters face, with up up: looking along -z (a wall facing +z) x runs right,
/// looking along +z it runs left (right = forward x up).
#[test]
fn a_wall_grid_is_drawn_as_seen_from_the_side_its_meters_face() {
    let cols_left = |a: DVec3, b: DVec3, normal: DVec3, z_up: bool| {
        GridAxes::of(a, b, 1.0)
            .unwrap()
            .as_drawn(z_up)
            .seen_from(normal, z_up)
            .cols_left
    };
    // A y-up room's walls at z = 0 (facing +z) and z = 4 (facing -z).
    let (a, b) = (dvec3(0.5, 0.5, 0.0), dvec3(4.5, 2.5, 0.0));
    assert!(!cols_left(a, b, DVec3::Z, false));
    let (a4, b4) = (dvec3(0.5, 0.5, 4.0), dvec3(4.5, 2.5, 4.0));
    assert!(cols_left(a4, b4, -DVec3::Z, false));
    // Corners given the other way round draw the same picture: their column 0 is the
    // other end, so it is drawn on the other side.
    assert!(!cols_left(b4, a4, -DVec3::Z, false));
    assert!(cols_left(b, a, DVec3::Z, false));
    // A z-up room's wall at x = 4 facing -x, columns along y: looking along +x, y runs
    // left (forward x up = x x z = -y).
    let (c, d) = (dvec3(4.0, 0.5, 0.5), dvec3(4.0, 3.5, 2.5));
    assert!(cols_left(c, d, -DVec3::X, true));
    assert!(!cols_left(c, d, DVec3::X, true));
    // A z-up room's wall at y = 0 facing +y: looking along -y, x runs left (-y x z = -x).
    let (e, f) = (dvec3(0.5, 0.0, 0.5), dvec3(4.5, 0.0, 2.5));
    assert!(cols_left(e, f, DVec3::Y, true));
    assert!(!cols_left(e, f, -DVec3::Y, true));
    // Plans are drawn as seen from above, whichever way their meters face.
    let (g, h) = (dvec3(0.0, 0.8, 0.0), dvec3(2.0, 0.8, 3.0));
    assert!(!cols_left(g, h, DVec3::Y, false));
    assert!(!cols_left(g, h, -DVec3::Y, false));
}

/// QA pass 17 of #16: a wall at constant x in a y-up scene has its axes as (y, z), so its
/// picture lay on its side, height to the right. Upright, its columns run along z and its
/// rows up y, each value where it was.
#[test]
fn a_wall_whose_columns_run_up_is_turned_upright() {
    let (a, b) = (dvec3(4.0, 0.5, 0.5), dvec3(4.0, 2.5, 1.5));
    let axes = GridAxes::of(a, b, 1.0).unwrap();
    assert_eq!(axes.names, ['y', 'z']);
    // Three columns (y = 0.5, 1.5, 2.5) of two rows (z = 0.5, 1.5); value 10 i + j.
    let values: Vec<f64> = (0..6).map(|k| (10 * (k % 3) + k / 3) as f64).collect();
    let (turned, dims, upright) = axes.upright(&values, [3, 2], false);
    assert_eq!(dims, [2, 3]);
    assert_eq!(upright.names, ['z', 'y']);
    assert_eq!(upright.first, [0.5, 0.5]);
    for i in 0..3 {
        for j in 0..2 {
            // Column j (z), row i (y) of the upright grid.
            assert_eq!(turned[i * 2 + j], (10 * i + j) as f64, "y {i} z {j}");
        }
    }
    // In a z-up scene the same axes are a floor strip's, and a y-up floor (x, z) or wall
    // (x, y) is already upright.
    assert_eq!(axes.upright(&values, [3, 2], true).2, axes);
    let wall = GridAxes::of(dvec3(0.5, 0.5, 4.0), dvec3(2.5, 1.5, 4.0), 1.0).unwrap();
    assert_eq!(wall.upright(&values, [3, 2], false).2, wall);
}

/// QA passes 14 and 15 of #16: a grid whose corners were given high to low drew its
/// columns mirrored (x growing to the left) though its rows were put right. The same cells
/// given from either corner, in any order, draw the same picture, pixel for pixel.
#[test]
fn a_grid_given_from_any_corner_draws_the_same_picture() {
    let (lo, hi) = (dvec3(0.0, 0.8, 0.0), dvec3(3.0, 0.8, 2.0));
    let corners = [
        (lo, hi),
        (hi, lo),
        (dvec3(3.0, 0.8, 0.0), dvec3(0.0, 0.8, 2.0)),
        (dvec3(0.0, 0.8, 2.0), dvec3(3.0, 0.8, 0.0)),
    ];
    let up = DVec3::Y;
    let pictures: Vec<image::RgbImage> = corners
        .iter()
        .map(|&(a, b)| {
            let (points, dims) = grid(a, b, 1.0, up, 100).unwrap();
            // A value that differs at every cell, so that any mirroring shows.
            let values: Vec<f64> = points
                .iter()
                .map(|p| 10.0 * p.position.x + p.position.z + 1.0)
                .collect();
            let axes = GridAxes::of(a, b, 1.0).unwrap().as_drawn(false);
            grid_picture_with_axes(&values, dims, Some(axes), "")
        })
        .collect();
    for (k, picture) in pictures.iter().enumerate().skip(1) {
        assert!(
            picture == &pictures[0],
            "corners {:?} draw another picture than {:?}",
            corners[k],
            corners[0]
        );
    }
}

#[test]
fn a_lamp_close_to_a_floor_reflects_what_fine_quadrature_says() {
    // QA of issue #16: the first bounce of a lamp a few cm from a surface was taken at a few
    // points of its spike. An isotropic 1000 cd lamp 5 cm above the centre of a 2 m x 2 m
    // floor of reflectance 0.5 (the floor one element: MAX_PATCH_AREA 4); a meter 1 m above
    // the centre facing down reads rho E(y) cos cos / (pi r^2) over the floor, with
    // E(y) = I h / |y - lamp|^3 and nothing else lit (only the floor reflects, and it sees
    // nothing). Independent reference: the midpoint rule on a 2,000 x 2,000 grid (1 mm
    // cells, 50 to a lamp height; its error is well under 0.1 %).
    let (h, meter) = (0.05, 1.0);
    let floor = "MAX_PATCH_AREA 4\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#Floor\nVERTICES 4\n\
         Er 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\nVERTEX0 -1 -1 0\nVERTEX1 1 -1 0\nVERTEX2 1 1 0\n\
         VERTEX3 -1 1 0\nPATCHEND\nLIGHTBEGIN\n#L\nPOSITION 0 0 0.05\nINTENSITY 1000\n\
         DISTRIBUTION ISOTROPIC\nLIGHTEND\nSCENEEND\n";
    let (p, s) = solved(floor);
    // The lamp lies between the meter and the floor: with the meter 1 m up facing down,
    // the segment from the floor to the meter passes 5 cm from nothing solid (a point lamp
    // casts no shadow).
    let lux = illuminance(&p, &s, &[at(0.0, 0.0, meter, -DVec3::Z)])[0];
    let n = 2000;
    let cell = 2.0 / n as f64;
    let mut want = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (
                -1.0 + (i as f64 + 0.5) * cell,
                -1.0 + (j as f64 + 0.5) * cell,
            );
            let r_lamp2 = x * x + y * y + h * h;
            let e = 1000.0 * h / (r_lamp2 * r_lamp2.sqrt());
            let r2 = x * x + y * y + meter * meter;
            let cos = meter / r2.sqrt();
            want += 0.5 * e * cos * cos / (PI * r2) * cell * cell;
        }
    }
    // 1 %: the first bounce's pieces stop at 0.1 sr (second order, a fraction of a per cent)
    // and the visible-fraction rays see the whole floor; the old integral at a few points of
    // the spike was off by tens of per cent here.
    assert!(
        (lux.indirect / want - 1.0).abs() < 0.01,
        "{} against {want}",
        lux.indirect
    );
}

/// QA pass 13 of #16: a one-point grid's picture said nowhere where it was, and a line's
/// named only one of its two fixed coordinates.
#[test]
fn a_grid_picture_says_the_coordinates_it_holds_fixed() {
    let (a, b) = (DVec3::new(1.0, 0.8, 1.0), DVec3::new(3.0, 0.8, 4.0));
    assert_eq!(held_coordinates(a, b), "y = 0.8");
    assert_eq!(
        held_coordinates(a, DVec3::new(1.0, 2.8, 1.0)),
        "x = 1  z = 1"
    );
    assert_eq!(held_coordinates(a, a), "x = 1  y = 0.8  z = 1");
    assert_eq!(held_coordinates(a, DVec3::new(2.0, 1.0, 2.0)), "");
    // Drawn under the summary line (rows 24 to 34, above the scale bar's "lx" at 36),
    // nothing there without it.
    let ink = |img: &image::RgbImage| {
        (24..34)
            .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0 == [0; 3])
            .count()
    };
    let values = [120.0];
    assert!(
        ink(&grid_picture_with_axes(
            &values,
            [1, 1],
            None,
            "x = 1  y = 0.8  z = 1"
        )) > 60
    );
    assert_eq!(ink(&grid_picture(&values, [1, 1])), 0);
}

/// QA pass 12 of #16: a short scale bar of 7 ticks (a prime) labelled only its ends, as the
/// stride had to divide the ticks.
#[test]
fn a_short_scale_bar_of_seven_ticks_labels_more_than_its_ends() {
    // The bar from row 24 to 110: 85 px for 7 ticks, 12.1 px apart, under the 18 px a
    // label needs, so every second is labelled (0, 2, 4) and the top (7); 6 would touch
    // the top's label and is left out.
    let mut img = image::RgbImage::from_pixel(200, 120, image::Rgb([255; 3]));
    draw_scale_bar(&mut img, 0, 0, 110, 7.0, 7);
    // Runs of rows with ink right of the ticks (the labels start 27 px right of the bar).
    let inked: Vec<bool> = (24..120)
        .map(|y| (27..200).any(|x| img.get_pixel(x, y).0 == [0; 3]))
        .collect();
    let runs = inked
        .iter()
        .zip(std::iter::once(&false).chain(&inked))
        .filter(|(&now, &before)| now && !before)
        .count();
    assert_eq!(runs, 4, "{inked:?}");
}

/// QA pass 15 of #16: the false-colour picture of a 64-pixel view labelled its scale of 7
/// steps 0, 2, 4, 7 (the sixth left out beside the top's). Every scale [`nice_scale`] gives
/// (4 to 8 steps) has all its labels at the smallest picture.
#[test]
fn a_small_false_colour_picture_labels_every_step_of_its_scale() {
    for ticks in 4..=8 {
        let max = ticks as f64;
        let img = false_colour_picture(&[1.0; 64 * 64], &[1.0; 64 * 64], 64, 64, max, ticks);
        // Runs of rows with ink right of the ticks (the labels start 27 px right of the
        // bar, which starts 8 px right of the view).
        let x0 = 64 + 8 + 27;
        let inked: Vec<bool> = (0..img.height())
            .map(|y| (x0..img.width()).any(|x| img.get_pixel(x, y).0 == [0; 3]))
            .collect();
        // Where each run of inked rows starts: one per label.
        let starts: Vec<usize> = (0..inked.len())
            .filter(|&y| inked[y] && (y == 0 || !inked[y - 1]))
            .collect();
        assert_eq!(
            starts.len(),
            ticks + 1,
            "{ticks} steps: labels at {starts:?}"
        );
    }
}

/// Review of QA pass 15 of #16: the elements' first bounce splits where a light's intensity
/// jumps, but the calculation points' point-by-point first bounce did not, so on an element
/// that a cut-off crosses the two disagreed. A light lit only below its horizon (IES, 0 to
/// 90 degrees, 159.15 cd) at the height of the middle of a 2 m x 2 m wall 1 m away (one
/// element, reflectance 0.5); a meter 0.3 m off the light's side, 0.4 m up, facing the
/// wall, reads rho E(y) cos cos / (pi r^2) over the wall's lit lower half. Independent
/// reference: the midpoint rule on a 2,000 x 2,000 grid (1 mm cells).
#[test]
fn a_cut_off_across_a_wall_reflects_what_fine_quadrature_says() {
    let ies = std::env::temp_dir().join(format!("rad-horizon-{}.ies", std::process::id()));
    std::fs::write(
        &ies,
        "IESNA:LM-63-2002\n[TEST] lower hemisphere\nTILT=NONE\n1 -1 1 4 1 1 2 0 0 0\n\
         1 1 0\n0 30 60 90\n0\n159.15 159.15 159.15 159.15\n",
    )
    .unwrap();
    let wall = format!(
        "MAX_PATCH_AREA 4\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#Wall\nVERTICES 4\n\
         Er 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\nVERTEX0 1 1 -1\nVERTEX1 1 -1 -1\n\
         VERTEX2 1 -1 1\nVERTEX3 1 1 1\nPATCHEND\nLIGHTBEGIN\n#L\nPOSITION 0 0 0\nAIM 0 0 -1\n\
         DISTRIBUTION IES {}\nLIGHTEND\nSCENEEND\n",
        ies.display()
    );
    let (p, s) = solved(&wall);
    std::fs::remove_file(&ies).ok();
    let meter = dvec3(0.0, 0.3, 0.4);
    let lux = illuminance(&p, &s, &[at(meter.x, meter.y, meter.z, DVec3::X)])[0];
    let n = 2000;
    let cell = 2.0 / n as f64;
    let mut want = 0.0;
    for i in 0..n {
        for j in 0..n {
            let y = dvec3(
                1.0,
                -1.0 + (i as f64 + 0.5) * cell,
                -1.0 + (j as f64 + 0.5) * cell,
            );
            // Lit below the light's horizon only; E = I cos / r^2, cos = x / r.
            if y.z >= 0.0 {
                continue;
            }
            let r2 = y.length_squared();
            let e = 159.15 * (y.x / r2.sqrt()) / r2;
            // cos at the wall and at the meter are both (1 - 0) / d.
            let d2 = (y - meter).length_squared();
            want += 0.5 * e / (PI * d2 * d2) * cell * cell;
        }
    }
    // The pieces straddling the cut-off split to 9 halvings of the wall's fan triangles (4
    // mm), a band of about 0.4 % of the lit half's light, each piece misjudged by part of
    // its light with either sign: measured 0.03 % off; without the split (0.1 sr pieces at
    // their centroids) 0.74 %, split only to 6 halvings 0.90 %. The reference's cells
    // meet the cut-off at their edges: its error is far below these.
    assert!(
        (lux.indirect / want - 1.0).abs() < 2.5e-3,
        "{} against {want}",
        lux.indirect
    );
}

/// Review of QA pass 16 of #16: the elements' first bounce followed a light a hair from a
/// surface to its foot, but the calculation points' stopped at 9 halvings, and a COSINE
/// light 0.1 mm under a ceiling gave half its reflected lux. A 1000 lm COSINE light aimed
/// up, a gap below the centre of a 4 m x 4 m ceiling (reflectance 0.5, nothing else); a
/// meter at (1, 1, 1) facing up. As the gap closes, every lumen lands within a few gaps of
/// the foot (2, 2, 3), so the meter reads rho Phi cos cos / (pi r^2) from there:
/// r^2 = 6, both cosines 2 / sqrt(6): 0.5 x 1000 x (4 / 6) / (6 pi) = 17.684 lx.
#[test]
fn a_light_a_hair_from_a_ceiling_reflects_all_its_lumens_to_a_meter() {
    let want = 0.5 * 1000.0 * (4.0 / 6.0) / (6.0 * PI);
    for gap in [1e-2, 1e-4, 1e-6] {
        let ceiling = format!(
            "MAX_PATCH_AREA 0.5\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#Ceiling\n\
             VERTICES 4\nEr 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\nVERTEX0 0 0 3\n\
             VERTEX1 0 4 3\nVERTEX2 4 4 3\nVERTEX3 4 0 3\nPATCHEND\nLIGHTBEGIN\n#L\n\
             POSITION 2 2 {}\nAIM 0 0 1\nFLUX 1000\nDISTRIBUTION COSINE\nLIGHTEND\nSCENEEND\n",
            3.0 - gap
        );
        let (p, s) = solved(&ceiling);
        let lux = illuminance(&p, &s, &[at(1.0, 1.0, 1.0, DVec3::Z)])[0];
        // Measured 0.04 % off at most (the limit's own error is (gap / 2.4 m)^2, far
        // less); 9 halvings were 4.4 % short at 0.1 mm.
        assert!(
            (lux.indirect / want - 1.0).abs() < 2e-3,
            "gap {gap}: {} against {want}",
            lux.indirect
        );
    }
}

#[test]
fn an_odd_top_is_labelled_in_round_steps_below_it_and_itself() {
    // `--lux-max 123456`: the largest round step of which 4 to 8 fit below the top, 25000,
    // then the top (QA pass 17 of #16: its fifths read 2.47E4, 4.94E4, ...).
    let scale = scale_ticks(123_456.0, 5);
    let labels: Vec<&str> = scale.iter().map(|(_, l)| l.as_str()).collect();
    assert_eq!(labels, ["0", "25000", "50000", "75000", "100000", "123456"]);
    assert_eq!(scale.last().unwrap().0, 123_456.0);
    assert_eq!(scale[1].0, 25_000.0);
    // A top past the bar's 6 characters keeps three digits and an exponent; one that is a
    // round number of round steps, or whose fifths read plainly, keeps its equal steps.
    assert_eq!(scale_ticks(1_234_567.0, 5).last().unwrap().1, "1.23E6");
    // (Its round steps up to 1000000 pass the 6 characters: exponents, as tick_labels.)
    assert_eq!(scale_ticks(1_234_567.0, 5)[1].1, "2.50E5");
    assert_eq!(scale_ticks(0.123_456, 5).last().unwrap().1, "0.123");
    assert_eq!(scale_ticks(0.123_456, 5)[1].1, "0.025");
    assert_eq!(scale_ticks(160.0, 8).len(), 9);
    assert_eq!(scale_ticks(300.0, 5)[1], (60.0, "60".to_string()));
    assert_eq!(scale_ticks(1.25e6, 5).last().unwrap().1, "1.25E6");
    // A tiny top keeps its digits (it read "0").
    assert_eq!(scale_ticks(3.3e-7, 5).last().unwrap().1, "3.3E-7");
    // Every label fits beside the bar.
    for max in [123_456.0, 1_234_567.0, 0.123_456, 7.777_7e29, 3.3e-7] {
        for (_, label) in scale_ticks(max, 5) {
            assert!(
                27 + text_width(&label, LEGEND_FONT) <= SCALE_BAR_WIDTH as i64 - 8,
                "{max}: {label}"
            );
        }
    }
}
