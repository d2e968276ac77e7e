//! Tests of the scene reader: every error with its line and column, recovery, the box
//! primitive, and robustness against garbled input.

use super::*;
use crate::geometry;
use glam::dvec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// A valid one-patch scene; the line numbers below refer to it.
const VALID: &str = "MAX_PATCH_AREA 100
INTEGRAL_STEPS 2
SCENEBEGIN
PATCHBEGIN
#Floor
VERTICES 4
Er 0.0
Eg 0.0
Eb 0.0
Rr 0.5
Rg 0.5
Rb 0.5
VERTEX0 0 0 0
VERTEX1 1 0 0
VERTEX2 1 1 0
VERTEX3 0 1 0
PATCHEND
SCENEEND
";

/// `VALID` with line `n` (from 1) replaced by `text` (which may hold several lines, or none).
fn with_line(n: usize, text: &str) -> String {
    let mut lines: Vec<&str> = VALID.lines().collect();
    if text.is_empty() {
        lines.remove(n - 1);
    } else {
        lines[n - 1] = text;
    }
    lines.join("\n") + "\n"
}

/// `VALID` with each line `n` replaced by its `text`.
fn with_lines(edits: &[(usize, &str)]) -> String {
    let mut lines: Vec<&str> = VALID.lines().collect();
    for &(n, text) in edits {
        lines[n - 1] = text;
    }
    lines.join("\n") + "\n"
}

/// The (line, column, message) of each error in `text`.
fn errors(text: &str) -> Vec<(usize, usize, String)> {
    match parse_scene(text, "t.scene") {
        Ok(_) => Vec::new(),
        Err(e) => e
            .errors
            .into_iter()
            .map(|e| (e.line, e.column, e.message))
            .collect(),
    }
}

/// Asserts that `text` has exactly one error, at `line`:`column`, whose message contains
/// `needle`.
#[track_caller]
fn one_error(text: &str, line: usize, column: usize, needle: &str) {
    let errs = errors(text);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    let (l, c, m) = &errs[0];
    assert_eq!((*l, *c), (line, column), "{m}");
    assert!(m.contains(needle), "message {m:?} lacks {needle:?}");
}

#[test]
fn valid_scene() {
    let SceneFile { settings, scene } = parse_scene(VALID, "t.scene").unwrap();
    assert_eq!(settings.max_patch_area, 100.0);
    assert_eq!(settings.integral_steps, 2);
    assert_eq!(scene.camera, None);
    assert_eq!(scene.surfaces.len(), 1);
    let s = &scene.surfaces[0];
    assert_eq!(s.name, "Floor");
    assert_eq!(s.emission, Rgb([0.0; 3]));
    assert_eq!(s.reflectance, Rgb([0.5; 3]));
    assert_eq!(
        s.vertices,
        vec![
            dvec3(0., 0., 0.),
            dvec3(1., 0., 0.),
            dvec3(1., 1., 0.),
            dvec3(0., 1., 0.)
        ]
    );
}

#[test]
fn case_comments_blank_lines_and_number_forms() {
    let text = "// a header comment

max_patch_area 0.25   // decimals are fine
Integral_Steps 3.0    // a whole number written with a fraction
   SceneBegin
patchbegin
  #  My floor // the name ends at the comment

vertices 3
er 1e-1
EG +2
eb 3.
rr .5
RG 0.25e0
rb 0
vertex0 0 0 0
Vertex1 1E0 0 0  // comment after numbers
VERTEX2 0 1 0
patchEnd
sceneend
// trailing comment

";
    let SceneFile { settings, scene } = parse_scene(text, "t.scene").unwrap();
    assert_eq!(settings.max_patch_area, 0.25);
    assert_eq!(settings.integral_steps, 3);
    let s = &scene.surfaces[0];
    assert_eq!(s.name, "My floor");
    assert_eq!(s.emission, Rgb([0.1, 2.0, 3.0]));
    assert_eq!(s.reflectance, Rgb([0.5, 0.25, 0.0]));
    assert_eq!(s.vertices[1], dvec3(1.0, 0.0, 0.0));
}

#[test]
fn windows_line_ends_and_byte_order_mark() {
    let text = format!("\u{feff}{}", VALID.replace('\n', "\r\n"));
    assert_eq!(
        parse_scene(&text, "t").unwrap(),
        parse_scene(VALID, "t").unwrap()
    );
}

#[test]
fn missing_or_misordered_keyword() {
    one_error(&with_line(8, ""), 8, 1, "expected Eg, found \"Eb\"");
    one_error(
        &with_line(8, "Eb 0\nEg 0"),
        8,
        1,
        "expected Eg, found \"Eb\"",
    );
    one_error(
        &with_line(5, ""),
        5,
        1,
        "expected a \"#NAME\" line, found \"VERTICES\"",
    );
    one_error(
        &with_line(17, ""),
        17,
        1,
        "expected PATCHEND, found \"SCENEEND\"",
    );
    one_error(
        &with_line(4, ""),
        4,
        1,
        "expected PATCHBEGIN, BOXBEGIN, SPHEREBEGIN, CYLINDERBEGIN, CONEBEGIN, LIGHTBEGIN or SCENEEND",
    );
}

#[test]
fn unknown_keyword() {
    one_error(
        &with_line(8, "Eq 0.0"),
        8,
        1,
        "unknown keyword \"Eq\"; expected Eg",
    );
    one_error(
        &with_line(13, "VERTEXO 0 0 0"),
        13,
        1,
        "unknown keyword \"VERTEXO\"",
    );
}

/// An unknown line does not hide the block's other mistakes (QA of issue #16: an extra
/// line before `Er` hid a bad `VERTEX` in the same patch), and each is reported once.
#[test]
fn an_unknown_line_does_not_hide_the_rest_of_its_block() {
    // An extra line (the expected Er follows it), then a bad VERTEX1: two errors.
    let text = with_lines(&[(6, "VERTICES 4\nTEXTURE wood"), (14, "VERTEX1 1 zero 0")]);
    let e = errors(&text);
    assert_eq!(e.len(), 2, "{e:#?}");
    assert_eq!((e[0].0, e[0].1), (7, 1), "{e:#?}");
    assert!(e[0].2.contains("unknown keyword \"TEXTURE\""), "{e:#?}");
    assert!(e[0].2.contains("expected Er"), "{e:#?}");
    // VERTEX1 is on line 15 now; "zero" starts at column 11.
    assert_eq!((e[1].0, e[1].1), (15, 11), "{e:#?}");
    assert!(e[1].2.contains("the y coordinate"), "{e:#?}");
    // A misspelt line in place of an expected one (Rg), then a bad reflectance (Rb):
    // the misspelling once, the reflectance once.
    let e = errors(&with_lines(&[(11, "Rgg 0.5"), (12, "Rb 1.5")]));
    assert_eq!(e.len(), 2, "{e:#?}");
    assert_eq!(
        (
            e[0].0,
            e[0].2.contains("unknown keyword \"Rgg\"; expected Rg")
        ),
        (11, true)
    );
    assert_eq!((e[1].0, e[1].2.contains("reflectance must be")), (12, true));
    // Two unknown lines before a box's ORIGIN, and a bad SIZE: three errors.
    let boxed = "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\nBOXBEGIN\n#B\nFACING OUT\n\
                 Er 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\nSHAPE box\nWOOD 1\n\
                 ORIGIN 0 0 0\nSIZE 1 -1 1\nBOXEND\nSCENEEND\n";
    let e = errors(boxed);
    let lines: Vec<usize> = e.iter().map(|e| e.0).collect();
    assert_eq!(lines, [13, 14, 16], "{e:#?}");
}

/// QA pass 16 of #16: `hello world` said that "hello" is not a keyword, then that "world"
/// is not a number after it; the line is not the one expected there, whatever its words.
#[test]
fn an_unknown_keyword_is_reported_alone_not_its_words() {
    // In place of MAX_PATCH_AREA, of Er (a value line), of VERTEX1 (three numbers), and
    // with too few words for the line it stands in for.
    one_error(
        &with_line(1, "hello world"),
        1,
        1,
        "unknown keyword \"hello\"",
    );
    one_error(
        &with_line(7, "hello world"),
        7,
        1,
        "unknown keyword \"hello\"",
    );
    one_error(
        &with_line(14, "hello big wide world"),
        14,
        1,
        "unknown keyword \"hello\"",
    );
    one_error(&with_line(14, "hello"), 14, 1, "unknown keyword \"hello\"");
    // The file of that one line: the keyword, then what is missing after the line.
    let e = errors("hello world\n");
    assert!(e[0].2.contains("unknown keyword \"hello\""), "{e:#?}");
    assert!(e.iter().all(|e| !e.2.contains("\"world\"")), "{e:#?}");
}

#[test]
fn missing_header_lines_give_one_error_each() {
    one_error(
        &with_line(1, ""),
        1,
        1,
        "expected MAX_PATCH_AREA, found \"INTEGRAL_STEPS\"",
    );
    one_error(
        &with_line(1, "MAX_PATCH_AREAS 100"),
        1,
        1,
        "unknown keyword",
    );
    one_error(
        &with_line(2, ""),
        2,
        1,
        "expected INTEGRAL_STEPS, found \"SCENEBEGIN\"",
    );
    one_error(
        &with_line(3, ""),
        3,
        1,
        "expected SCENEBEGIN, found \"PATCHBEGIN\"",
    );
    // The two header lines swapped, or one given twice: one error, not one for every line
    // after it (QA of issue #16: three).
    let (area, steps) = (VALID.lines().next().unwrap(), VALID.lines().nth(1).unwrap());
    one_error(
        &with_lines(&[(1, steps), (2, area)]),
        1,
        1,
        "swap the two lines",
    );
    one_error("", 1, 1, "the file is empty");
    one_error("// only a comment\n\n", 1, 1, "the file is empty");
    let doubled = format!("{area}\n{VALID}");
    one_error(&doubled, 2, 1, "MAX_PATCH_AREA is given twice");
    let doubled = VALID.replacen(steps, &format!("{steps}\n{steps}"), 1);
    one_error(&doubled, 3, 1, "INTEGRAL_STEPS is given twice");
}

#[test]
fn not_a_number() {
    one_error(
        &with_line(11, "Rg abc"),
        11,
        4,
        "expected a number after \"Rg\", found \"abc\"",
    );
    one_error(&with_line(11, "Rg"), 11, 3, "found end of line");
    one_error(
        &with_line(14, "VERTEX1 1 zero 0"),
        14,
        11,
        "the y coordinate",
    );
    one_error(&with_line(14, "VERTEX1 1 0"), 14, 12, "the z coordinate");
}

#[test]
fn not_finite() {
    for bad in ["NaN", "nan", "inf", "-inf", "infinity", "1e400"] {
        one_error(
            &with_line(7, &format!("Er {bad}")),
            7,
            4,
            "expected a finite number after \"Er\"",
        );
    }
    one_error(&with_line(15, "VERTEX2 1 1 NaN"), 15, 13, "finite number");
}

#[test]
fn extra_tokens() {
    one_error(
        &with_line(10, "Rr 0.5 0.6"),
        10,
        8,
        "expected end of line after the value of \"Rr\", found \"0.6\"",
    );
    one_error(
        &with_line(13, "VERTEX0 0 0 0 0"),
        13,
        15,
        "the 3 values of \"VERTEX0\"",
    );
    one_error(
        &with_line(4, "PATCHBEGIN now"),
        4,
        12,
        "after \"PATCHBEGIN\"",
    );
}

#[test]
fn reflectance_range() {
    for bad in ["1", "1.0", "-0.1", "2"] {
        one_error(
            &with_line(11, &format!("Rg {bad}")),
            11,
            4,
            "reflectance must be at least 0 and below 1",
        );
    }
    assert!(parse_scene(&with_line(11, "Rg 0.999"), "t").is_ok());
    assert!(parse_scene(&with_line(11, "Rg 0"), "t").is_ok());
}

#[test]
fn negative_emission() {
    one_error(
        &with_line(9, "Eb -1"),
        9,
        4,
        "emission must not be negative",
    );
}

#[test]
fn vertex_count() {
    one_error(&with_line(6, "VERTICES 2"), 6, 10, "at least 3");
    one_error(&with_line(6, "VERTICES 3.5"), 6, 10, "whole number");
    one_error(&with_line(6, "VERTICES -4"), 6, 10, "whole number");
    // Fewer VERTEXk lines than VERTICES says.
    one_error(
        &with_line(6, "VERTICES 5"),
        17,
        1,
        "expected VERTEX4 (VERTICES says 5 vertices, but only 4 are given), found \"PATCHEND\"",
    );
    // More.
    one_error(
        &with_line(6, "VERTICES 3"),
        16,
        1,
        "more VERTEX lines than VERTICES says",
    );
    // Out of order.
    one_error(
        &with_line(14, "VERTEX2 1 1 0\nVERTEX1 1 0 0"),
        14,
        1,
        "expected VERTEX1, found \"VERTEX2\"",
    );
    // "4.0" is a whole number.
    assert!(parse_scene(&with_line(6, "VERTICES 4.0"), "t").is_ok());
}

#[test]
fn polygon_errors_point_at_vertex0() {
    one_error(&with_line(15, "VERTEX2 1 1 0.1"), 13, 1, "not planar");
    // A bow tie (the outline crosses itself: corners in the wrong order) is not convex and
    // stays an error; a simple non-convex outline is triangulated (next test).
    one_error(
        &with_lines(&[(15, "VERTEX2 0 1 0"), (16, "VERTEX3 2 1 0")]),
        13,
        1,
        "the outline crosses itself or goes round more than once (a bow tie",
    );
    one_error(
        &with_line(15, "VERTEX2 1 0 0"),
        13,
        1,
        "VERTEX1 and VERTEX2 are the same",
    );
    one_error(
        &with_lines(&[(15, "VERTEX2 2 0 0"), (16, "VERTEX3 3 0 0")]),
        13,
        1,
        "area is zero",
    );
    // A clockwise square is fine: it just faces the other way.
    let flipped = parse_scene(
        &with_lines(&[(14, "VERTEX1 0 1 0"), (16, "VERTEX3 1 0 0")]),
        "t",
    )
    .unwrap()
    .scene;
    let n = geometry::polygon_normal(&flipped.surfaces[0].vertices).unwrap();
    assert_eq!(n, -DVec3::Z);
}

#[test]
fn planarity_message_states_deviation_limit_and_units() {
    let errs = errors(&with_line(15, "VERTEX2 1 1 0.1"));
    let m = &errs[0].2;
    assert!(m.contains("scene units"), "{m}");
    assert!(m.contains("0.2%"), "{m}");
}

#[test]
fn slightly_non_planar_polygon_is_flattened() {
    // 0.004 / 4 = 0.001 off the plane, under the limit 0.002 * sqrt(2).
    let scene = parse_scene(&with_line(15, "VERTEX2 1 1 0.004"), "t")
        .unwrap()
        .scene;
    let v = &scene.surfaces[0].vertices;
    assert!(geometry::max_plane_deviation(v) < 1e-12);
    assert!((v[2].z - 0.003).abs() < 1e-4, "{:?}", v[2]);
}

#[test]
fn scene_structure_errors() {
    // Nothing between SCENEBEGIN and SCENEEND.
    let empty = "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\nSCENEEND\n";
    one_error(empty, 4, 1, "no patches");
    // Nothing at all after SCENEBEGIN.
    one_error(
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\n",
        3,
        11,
        "no patches",
    );
    // Missing SCENEEND: reported at the end of the last line.
    one_error(
        &with_line(18, ""),
        17,
        9,
        "expected SCENEEND, found end of file",
    );
    // Text after SCENEEND.
    one_error(
        &with_line(18, "SCENEEND\n\nPATCHBEGIN"),
        20,
        1,
        "expected end of file after SCENEEND, found \"PATCHBEGIN\"",
    );
    // An empty file: one error that says so and what the file starts with.
    let errs = errors("");
    assert_eq!(errs.len(), 1, "{errs:?}");
    assert!(errs[0].2.contains("the file is empty") && errs[0].2.contains("MAX_PATCH_AREA"));
}

#[test]
fn header_values() {
    one_error(&with_line(1, "MAX_PATCH_AREA 0"), 1, 16, "greater than 0");
    one_error(&with_line(1, "MAX_PATCH_AREA -5"), 1, 16, "greater than 0");
    one_error(
        &with_line(2, "INTEGRAL_STEPS 2.5"),
        2,
        16,
        "whole number of at least 1",
    );
    one_error(
        &with_line(2, "INTEGRAL_STEPS 0"),
        2,
        16,
        "whole number of at least 1",
    );
    one_error(&with_line(2, "INTEGRAL_STEPS 1e10"), 2, 16, "at most");
    let s = parse_scene(&with_line(1, "MAX_PATCH_AREA 12.5"), "t").unwrap();
    assert_eq!(s.settings.max_patch_area, 12.5);
    let s = parse_scene(&with_line(2, "INTEGRAL_STEPS 2.0"), "t").unwrap();
    assert_eq!(s.settings.integral_steps, 2);
}

/// A patch block with the given colour line and third vertex.
fn patch(name: &str, colour: &str, vertex2: &str) -> String {
    format!(
        "PATCHBEGIN\n#{name}\nVERTICES 4\nEr 0\nEg 0\nEb 0\nRr 0.5\n{colour}\nRb 0.5\n\
         VERTEX0 0 0 0\nVERTEX1 1 0 0\n{vertex2}\nVERTEX3 0 1 0\nPATCHEND\n"
    )
}

#[test]
fn several_bad_patches_are_all_reported() {
    // Each patch is 14 lines; the scene starts with 3 header lines.
    let text = [
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\n".to_string(),
        patch("a", "Rg x", "VERTEX2 1 1 0"), // lines 4..17, error on 11
        patch("b", "Rg 0.5", "VERTEX2 1 1 0"), // lines 18..31, fine
        patch("c", "Rg 0.5", "VERTEX2 1 1 5"), // lines 32..45, not planar: VERTEX0 is 41
        patch("d", "Rg 0.5", "VERTEX9 1 1 0"), // lines 46..59, wrong vertex on 57
        "SCENEEND\n".to_string(),
    ]
    .concat();
    let errs = errors(&text);
    let places: Vec<(usize, usize)> = errs.iter().map(|e| (e.0, e.1)).collect();
    assert_eq!(places, vec![(11, 4), (41, 1), (57, 1)], "{errs:#?}");
    assert!(errs[2].2.contains("expected VERTEX2, found \"VERTEX9\""));
}

#[test]
fn recovery_when_patchend_is_missing() {
    let text = [
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\n".to_string(),
        patch("a", "Rg 0.5", "VERTEX2 1 1 0").replace("PATCHEND\n", ""),
        patch("b", "Rg 7", "VERTEX2 1 1 0"),
        "SCENEEND\n".to_string(),
    ]
    .concat();
    let errs = errors(&text);
    assert_eq!(errs.len(), 2, "{errs:#?}");
    assert_eq!((errs[0].0, errs[0].1), (17, 1));
    assert!(errs[0]
        .2
        .contains("expected PATCHEND, found \"PATCHBEGIN\""));
    assert_eq!((errs[1].0, errs[1].1), (24, 4));
}

#[test]
fn error_display() {
    let err = parse_scene(&with_line(11, "Rg abc"), "room.scene").unwrap_err();
    assert_eq!(
        err.to_string(),
        "room.scene:11:4: error: expected a number after \"Rg\", found \"abc\""
    );
    let err = parse_scene(&with_lines(&[(10, "Rr 3"), (11, "Rg 3")]), "room.scene").unwrap_err();
    let text = err.to_string();
    assert!(
        text.starts_with("room.scene:10:4: error: reflectance"),
        "{text}"
    );
    assert!(
        text.contains("\nroom.scene:11:4: error: reflectance"),
        "{text}"
    );
    assert!(text.ends_with("\n2 errors"), "{text}");
}

#[test]
fn read_scene_reports_file_problems() {
    let missing = Path::new("/nonexistent/dir/x.scene");
    let err = read_scene(missing).unwrap_err();
    assert_eq!(err.errors.len(), 1);
    assert!(err
        .to_string()
        .starts_with("/nonexistent/dir/x.scene: error: cannot read the scene file"));

    let dir = std::env::temp_dir().join(format!("radiosity-parse-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.scene");
    std::fs::write(&path, b"MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\n\xff\n").unwrap();
    let err = read_scene(&path).unwrap_err();
    assert_eq!(err.errors[0].line, 3);
    assert!(err.errors[0].message.contains("UTF-8"));
    std::fs::write(&path, VALID).unwrap();
    assert_eq!(read_scene(&path).unwrap(), parse_scene(VALID, "x").unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}

// ----- boxes -----

/// A box block with the given facing and shape lines.
fn box_scene(facing: &str, shape: &str) -> String {
    format!(
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\nBOXBEGIN\n#Table\nFACING {facing}\n\
         Er 0\nEg 0\nEb 0\nRr 0.1\nRg 0.2\nRb 0.3\n{shape}\nBOXEND\nSCENEEND\n"
    )
}

/// Volume enclosed by faces (divergence theorem), positive when they face out.
fn enclosed_volume(faces: &[Surface]) -> f64 {
    faces
        .iter()
        .map(|f| {
            let v = &f.vertices;
            geometry::polygon_centroid(v).dot(geometry::area_vector(v)) / 3.0
        })
        .sum()
}

/// Checks each face looks away from (`out`) or towards the mean of all corners.
#[track_caller]
fn check_facing(faces: &[Surface], out: bool) {
    let all: Vec<DVec3> = faces.iter().flat_map(|f| f.vertices.clone()).collect();
    let centre = geometry::vertex_mean(&all);
    for f in faces {
        let n = geometry::polygon_normal(&f.vertices).unwrap();
        let away = (geometry::polygon_centroid(&f.vertices) - centre).dot(n);
        assert!(
            if out { away > 0.0 } else { away < 0.0 },
            "{} {away}",
            f.name
        );
        assert!(geometry::is_convex(&f.vertices));
        assert_eq!(f.vertices.len(), 4);
    }
}

#[test]
fn axis_aligned_box() {
    let scene = parse_scene(&box_scene("OUT", "ORIGIN 1 0 2\nSIZE 2 0.8 1"), "t")
        .unwrap()
        .scene;
    let faces = &scene.surfaces;
    let names: Vec<&str> = faces.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "Table.base",
            "Table.top",
            "Table.side0",
            "Table.side1",
            "Table.side2",
            "Table.side3"
        ]
    );
    for f in faces {
        assert_eq!(f.emission, Rgb([0.0; 3]));
        assert_eq!(f.reflectance, Rgb([0.1, 0.2, 0.3]));
    }
    check_facing(faces, true);
    assert!((enclosed_volume(faces) - 2.0 * 0.8 * 1.0).abs() < 1e-12);
    assert_eq!(scene.bounds(), (dvec3(1., 0., 2.), dvec3(3., 0.8, 3.)));
    // The base is the y-min face, the top the y-max face.
    assert!(faces[0].vertices.iter().all(|v| v.y == 0.0));
    assert!(faces[1].vertices.iter().all(|v| v.y == 0.8));
    assert_eq!(
        geometry::polygon_normal(&faces[0].vertices),
        Some(-DVec3::Y)
    );

    let room = parse_scene(&box_scene("in", "ORIGIN 1 0 2\nSIZE 2 0.8 1"), "t")
        .unwrap()
        .scene;
    check_facing(&room.surfaces, false);
    assert!((enclosed_volume(&room.surfaces) + 1.6).abs() < 1e-12);
    assert_eq!(
        geometry::polygon_normal(&room.surfaces[0].vertices),
        Some(DVec3::Y)
    );
}

#[test]
fn box_from_a_face_and_a_height() {
    // A skewed parallelogram base in a tilted plane; its right-hand-rule normal sets the
    // sweep direction.
    let base = [
        dvec3(0.0, 0.0, 0.0),
        dvec3(2.0, 0.5, 0.0),
        dvec3(2.5, 0.5, 1.0),
        dvec3(0.5, 0.0, 1.0),
    ];
    let lines: String = base
        .iter()
        .enumerate()
        .map(|(k, v)| format!("VERTEX{k} {} {} {}\n", v.x, v.y, v.z))
        .collect();
    let shape = format!("VERTICES 4\n{lines}HEIGHT 0.75");
    let expected = geometry::polygon_area(&base) * 0.75;
    let n = geometry::polygon_normal(&base).unwrap();
    for (facing, out) in [("OUT", true), ("IN", false)] {
        let scene = parse_scene(&box_scene(facing, &shape), "t").unwrap().scene;
        let faces = &scene.surfaces;
        assert_eq!(faces.len(), 6);
        check_facing(faces, out);
        let volume = enclosed_volume(faces);
        let sign = if out { 1.0 } else { -1.0 };
        assert!(
            (volume - sign * expected).abs() < 1e-12,
            "{volume} {expected}"
        );
        // The top is the base moved along the base normal.
        let top_mean = geometry::vertex_mean(&faces[1].vertices);
        let base_mean = geometry::vertex_mean(&base);
        assert!((top_mean - (base_mean + 0.75 * n)).length() < 1e-12);
    }
}

#[test]
fn box_errors() {
    let ok = "ORIGIN 1 0 2\nSIZE 2 0.8 1";
    one_error(
        &box_scene("SIDEWAYS", ok),
        6,
        8,
        "expected OUT or IN after \"FACING\"",
    );
    one_error(&box_scene("", ok), 6, 7, "found end of line");
    one_error(
        &box_scene("OUT", "ORIGIN 1 0 2\nSIZE 2 0 1"),
        14,
        8,
        "greater than 0",
    );
    one_error(
        &box_scene("OUT", "SIZE 2 1 1"),
        13,
        1,
        "expected ORIGIN or VERTICES",
    );
    one_error(
        &box_scene("OUT", "ORIGIN 1 0\nSIZE 2 1 1"),
        13,
        11,
        "z coordinate",
    );
    let tri = "VERTICES 3\nVERTEX0 0 0 0\nVERTEX1 1 0 0\nVERTEX2 0 1 0\nHEIGHT 1";
    one_error(&box_scene("OUT", tri), 13, 10, "exactly 4 vertices");
    let flat = "VERTICES 4\nVERTEX0 0 0 0\nVERTEX1 1 0 0\nVERTEX2 1 1 0\nVERTEX3 0 1 0\nHEIGHT 0";
    one_error(
        &box_scene("OUT", flat),
        18,
        8,
        "HEIGHT must be greater than 0",
    );
    let dart = "VERTICES 4\nVERTEX0 0 0 0\nVERTEX1 2 1 0\nVERTEX2 0 2 0\nVERTEX3 1 1 0\nHEIGHT 1";
    one_error(&box_scene("OUT", dart), 14, 1, "not convex");
    let no_end = box_scene("OUT", ok).replace("BOXEND\n", "");
    one_error(&no_end, 15, 1, "expected BOXEND, found \"SCENEEND\"");
}

// ----- robustness -----

#[test]
fn garbled_input_never_panics() {
    let source = format!(
        "{}{}",
        VALID.replace("SCENEEND\n", ""),
        box_scene(
            "OUT",
            "VERTICES 4\nVERTEX0 0 0 0\nVERTEX1 1 0 0\nVERTEX2 1 0 1\nVERTEX3 0 0 1\nHEIGHT 2"
        )
        .split_once("SCENEBEGIN\n")
        .map_or(String::new(), |(_, rest)| rest.to_string())
    );
    assert!(parse_scene(&source, "t").is_ok());
    // Every truncation.
    for (i, _) in source.char_indices() {
        let _ = parse_scene(&source[..i], "t");
    }
    // Every line removed, duplicated, or moved one down.
    let lines: Vec<&str> = source.lines().collect();
    for i in 0..lines.len() {
        let mut removed = lines.clone();
        removed.remove(i);
        let _ = parse_scene(&removed.join("\n"), "t");
        let mut doubled = lines.clone();
        doubled.insert(i, lines[i]);
        let _ = parse_scene(&doubled.join("\n"), "t");
        if i + 1 < lines.len() {
            let mut swapped = lines.clone();
            swapped.swap(i, i + 1);
            let _ = parse_scene(&swapped.join("\n"), "t");
        }
    }
    // Random character edits.
    let alphabet: Vec<char> = "# /\n\t0123456789.-+eEnaNinfXVERTEX\u{e9}\u{feff}\r"
        .chars()
        .collect();
    let chars: Vec<char> = source.chars().collect();
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    for _ in 0..3000 {
        let mut edited = chars.clone();
        for _ in 0..1 + rng.random_range(0..4) {
            let at = rng.random_range(0..edited.len());
            match rng.random_range(0..3) {
                0 => {
                    edited.remove(at);
                }
                1 => edited.insert(at, alphabet[rng.random_range(0..alphabet.len())]),
                _ => edited[at] = alphabet[rng.random_range(0..alphabet.len())],
            }
        }
        let text: String = edited.into_iter().collect();
        if let Err(e) = parse_scene(&text, "t") {
            assert!(!e.errors.is_empty());
            let _ = e.to_string();
        }
    }
    // Pathological counts and values.
    let _ = parse_scene(&with_line(6, "VERTICES 1e300"), "t");
    let _ = parse_scene(&with_line(6, "VERTICES 18446744073709551616"), "t");
    let _ = parse_scene(&with_line(13, "VERTEX0 1e308 -1e308 1e308"), "t");
    let _ = parse_scene(&with_line(14, "VERTEX99999999999999999999999 0 0 0"), "t");
}

#[test]
fn error_count_is_bounded() {
    let mut text = String::from("MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\n");
    for _ in 0..500 {
        text.push_str(&patch("x", "Rg 2", "VERTEX2 1 1 0"));
    }
    text.push_str("SCENEEND\n");
    let errs = errors(&text);
    assert_eq!(errs.len(), MAX_ERRORS + 1);
    assert!(errs[MAX_ERRORS].2.contains("too many errors"));
}

// Regression (QA): a bad number used to end the reading of its patch, hiding later
// mistakes in the same patch. Now each is reported at its own line.
#[test]
fn bad_numbers_do_not_hide_later_errors_in_the_patch() {
    let text = with_lines(&[(10, "Rr x"), (12, "Rb 1.5"), (16, "VERTEX3 0 y 0")]);
    let errs = errors(&text);
    let at: Vec<(usize, usize)> = errs.iter().map(|e| (e.0, e.1)).collect();
    assert_eq!(at, vec![(10, 4), (12, 4), (16, 11)], "{errs:#?}");
}

// ----- issue 12: hostile geometry -----

// Regression (issue 12): `SIZE` with fewer than three good numbers indexed past the end of
// the line and panicked; `SIZE 1 abc 1` blamed z for the y that could not be read.
#[test]
fn box_size_with_missing_or_bad_numbers_is_an_error_naming_the_axis() {
    let at = |size: &str| errors(&box_scene("OUT", &format!("ORIGIN 0 0 0\n{size}")));
    let e = at("SIZE 1 1");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert_eq!((e[0].0, e[0].1), (14, 9));
    assert!(
        e[0].2.contains("(the z size)") && e[0].2.contains("end of line"),
        "{e:#?}"
    );
    let e = at("SIZE -1");
    assert!(e.iter().any(|e| e.2.contains("(the y size)")), "{e:#?}");
    assert!(e
        .iter()
        .any(|e| e.2.contains("greater than 0") && e.2.contains("for x")));
    let e = at("SIZE 1 nan");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(e[0]
        .2
        .contains("expected a finite number (the y size) after \"SIZE\", found \"nan\""));
    let e = at("SIZE 1 abc 1");
    assert_eq!(e.len(), 1, "{e:#?}");
    assert_eq!((e[0].0, e[0].1), (14, 8));
    assert!(
        e[0].2.contains("(the y size)") && !e[0].2.contains(" z"),
        "{e:#?}"
    );
}

// Regression (issue 12): box faces skipped the polygon checks, and the mesher planned a grid
// of 0 x 4,294,967,295 for them. Each face now passes the checks a patch does; the error is
// at the SIZE line and names the face.
#[test]
fn box_faces_too_small_or_too_thin_are_refused_at_the_size_line() {
    let e = errors(&box_scene("OUT", "ORIGIN 0 0 0\nSIZE 1e-300 1e-300 1e-300"));
    assert_eq!(e.len(), 1, "{e:#?}");
    assert_eq!((e[0].0, e[0].1), (14, 1));
    assert!(
        e[0].2.contains("\"Table.base\"") && e[0].2.contains("1e-30"),
        "{e:#?}"
    );
    // 1e-200 beside 0.2 is lost in rounding: two corners of the base are one point.
    let e = errors(&box_scene("OUT", "ORIGIN 0 0 0\nSIZE 1e-200 1e-200 0.2"));
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(e[0].2.contains("same point"), "{e:#?}");
    // A box of thickness 1e-12 beside 1 (the issue's NaN box was 1e-200 thick): its sides'
    // corners are 1e-12 of their diameter apart, below the 1e-9 that counts as one point.
    let e = errors(&box_scene("OUT", "ORIGIN 0 0 0\nSIZE 1 1e-12 1"));
    assert_eq!(e.len(), 1, "{e:#?}");
    assert!(
        e[0].2.contains("\"Table.side0\"") && e[0].2.contains("same point"),
        "{e:#?}"
    );
    // A prism whose height is lost beside its base's coordinates: reported at HEIGHT.
    let thin =
        "VERTICES 4\nVERTEX0 0 0 0\nVERTEX1 1 0 0\nVERTEX2 1 0 1\nVERTEX3 0 0 1\nHEIGHT 1e-300";
    let e = errors(&box_scene("OUT", thin));
    assert_eq!(e.len(), 1, "{e:#?}");
    assert_eq!(e[0].0, 18, "{e:#?}");
}

// QA of issue #16: an emission of 1e308 was read, and the energy account said "inf %".
// Emission, LUMINANCE and FLUX above 1e30 are refused at their word; 1e30 itself is read.
#[test]
fn emission_beyond_the_supported_range_is_refused_at_its_word() {
    one_error(&with_line(7, "Er 1e308"), 7, 4, "above the largest");
    one_error(&with_line(9, "Eb 2e30"), 9, 4, "(1e30)");
    one_error(
        &with_lines(&[(7, "LUMINANCE 1e31"), (8, ""), (9, "")]),
        7,
        11,
        "LUMINANCE",
    );
    one_error(
        &with_lines(&[(7, "FLUX 1e31"), (8, ""), (9, "")]),
        7,
        6,
        "FLUX",
    );
    assert!(errors(&with_line(8, "Eg 1e30")).is_empty());
    // A point light's FLUX and INTENSITY too (review of issue #16: "inf lm", "NaN %").
    for (word, column) in [("FLUX", 6), ("INTENSITY", 11)] {
        let text = VALID.replace(
            "SCENEEND",
            &format!(
                "LIGHTBEGIN\n#Lamp\nPOSITION 0.5 0.5 1\n{word} 1e308\nDISTRIBUTION ISOTROPIC\n\
                 LIGHTEND\nSCENEEND"
            ),
        );
        one_error(&text, 21, column, "above the largest");
    }
}

// Regression (issue 12): coordinates of 1e20 and more panicked in the BVH builder, and ones
// near 1e154..1e308 gave "VERTEX0 and VERTEX1 are the same point" (the squared length
// overflowed). Coordinates beyond 1e30 are refused at their own word, with the range.
#[test]
fn coordinates_beyond_the_supported_range_are_refused_at_their_word() {
    one_error(
        &with_line(13, "VERTEX0 1e31 0 0"),
        13,
        9,
        "(1e30 in magnitude)",
    );
    let e = errors(&with_lines(&[
        (13, "VERTEX0 -1e300 0 0"),
        (15, "VERTEX2 1 1e200 0"),
    ]));
    let at: Vec<(usize, usize)> = e.iter().map(|e| (e.0, e.1)).collect();
    assert_eq!(at, vec![(13, 9), (15, 11)], "{e:#?}");
    assert!(!e.iter().any(|e| e.2.contains("same point")), "{e:#?}");
    let e = errors(&box_scene("OUT", "ORIGIN 1e308 0 0\nSIZE 1e308 1 1"));
    assert!(
        e.iter()
            .any(|e| (e.0, e.1) == (13, 8) && e.2.contains("1e30")),
        "{e:#?}"
    );
    let e = errors(&box_scene("OUT", "ORIGIN 0 0 0\nSIZE 1e308 1 1"));
    assert_eq!(e.len(), 1, "{e:#?}");
    assert_eq!((e[0].0, e[0].1), (14, 6));
    assert!(e[0].2.contains("reaches x = 1e308"), "{e:#?}");
    // Within the range: a quad of +-1e20 is read.
    let big = with_lines(&[
        (13, "VERTEX0 -1e20 -1e20 0"),
        (14, "VERTEX1 1e20 -1e20 0"),
        (15, "VERTEX2 1e20 1e20 0"),
        (16, "VERTEX3 -1e20 1e20 0"),
    ]);
    assert!(parse_scene(&big, "t").is_ok());
}

// Regression (issue 12): scaled scenes were refused as "not convex" or "area is zero". The
// unit square scaled by 1e-30 .. 1e29 and moved off the origin is read everywhere; a
// square of 1e-31 is refused as too small, not as degenerate.
#[test]
fn scaled_and_moved_polygons_are_judged_as_at_unit_scale() {
    for exp in -30..=29 {
        let s = 10f64.powi(exp);
        let lines: Vec<String> = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)]
            .iter()
            .enumerate()
            .map(|(k, (x, y))| format!("VERTEX{k} {} {} {}", x * s + 5.0 * s, y * s, s))
            .collect();
        let edits: Vec<(usize, &str)> = (0..4).map(|k| (13 + k, lines[k].as_str())).collect();
        let text = with_lines(&edits);
        assert!(
            parse_scene(&text, "t").is_ok(),
            "scale 1e{exp}: {:?}",
            errors(&text)
        );
    }
    let tiny = with_lines(&[
        (13, "VERTEX0 0 0 0"),
        (14, "VERTEX1 1e-31 0 0"),
        (15, "VERTEX2 1e-31 1e-31 0"),
        (16, "VERTEX3 0 1e-31 0"),
    ]);
    one_error(&tiny, 13, 1, "less than the smallest the program supports");
}

// Regression (issue 12): a second floor quad on the floor was accepted silently (row sums of
// 1.32 in the issue). The same polygon given twice is refused at the second, naming the
// first's line; a smaller rug in the floor's plane is still a model the mesher handles.
#[test]
fn a_surface_given_twice_is_refused_naming_both_lines() {
    let floor_twice = VALID.replace("SCENEEND\n", "")
        + &patch("Floor2", "Rg 0.5", "VERTEX2 1 1 0")
        + "SCENEEND\n";
    let e = errors(&floor_twice);
    assert_eq!(e.len(), 1, "{e:#?}");
    assert_eq!(e[0].0, 27, "{e:#?}");
    assert!(
        e[0].2
            .contains("\"Floor2\" lies exactly on surface \"Floor\" (line 13)"),
        "{e:#?}"
    );
    // Facing the other way (a two-sided wall), or a rug covering part of the floor: read.
    let back = patch("Back", "Rg 0.5", "VERTEX2 1 1 0")
        .replace("VERTEX1 1 0 0", "VERTEX1 0 1 0")
        .replace("VERTEX3 0 1 0\n", "VERTEX3 1 0 0\n");
    let back_to_back = VALID.replace("SCENEEND\n", "") + &back + "SCENEEND\n";
    assert_eq!(errors(&back_to_back), vec![]);
    let rug = VALID.replace("SCENEEND\n", "")
        + &patch("Rug", "Rg 0.5", "VERTEX2 1 0.5 0").replace("VERTEX3 0 1 0", "VERTEX3 0 0.5 0")
        + "SCENEEND\n";
    assert_eq!(errors(&rug), vec![]);
}

// Regression (the DXF fuzz target's crash, in the shared duplicate check): 256 copies of one
// patch made obvhs build a hierarchy deeper than its traversal stack, which its debug
// validation refused with a panic. Each copy is now refused at its line, naming the first.
#[test]
fn hundreds_of_copies_of_a_patch_are_refused_without_a_panic() {
    let mut text = VALID.replace("SCENEEND\n", "");
    for k in 0..256 {
        text += &patch(&format!("Copy{k}"), "Rg 0.5", "VERTEX2 1 1 0");
    }
    text += "SCENEEND\n";
    let e = errors(&text);
    assert_eq!(e.len(), 256, "{:#?}", &e[..3]);
    assert!(e
        .iter()
        .all(|x| x.2.contains("lies exactly on surface \"Floor\" (line 13)")));
}

#[test]
fn non_convex_patch_is_triangulated() {
    // A dart: (0,0) (1,0) (0.2,0.2) (0,1), area 0.2 by the shoelace formula, reflex at
    // VERTEX2.
    let file = parse_scene(&with_line(15, "VERTEX2 0.2 0.2 0"), "t").unwrap();
    let s = &file.scene.surfaces;
    assert_eq!(s.len(), 2);
    assert_eq!(
        (s[0].name.as_str(), s[1].name.as_str()),
        ("Floor.0", "Floor.1")
    );
    let area: f64 = s.iter().map(|s| geometry::polygon_area(&s.vertices)).sum();
    assert!((area - 0.2).abs() < 1e-12, "{area}");
    for t in s {
        assert!(geometry::polygon_normal(&t.vertices).unwrap().z > 0.999_999);
        assert_eq!(t.reflectance.0, [0.5; 3]);
    }
    // An L of six corners, area 3.
    let l = "VERTICES 6\nEr 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\nVERTEX0 0 0 0\n\
             VERTEX1 2 0 0\nVERTEX2 2 1 0\nVERTEX3 1 1 0\nVERTEX4 1 2 0\nVERTEX5 0 2 0";
    let blank: Vec<(usize, &str)> = (7..=16).map(|n| (n, "")).collect();
    let text = with_lines(&[&[(6, l)], &blank[..]].concat());
    let file = parse_scene(&text, "t").unwrap();
    let area: f64 = file
        .scene
        .surfaces
        .iter()
        .map(|s| geometry::polygon_area(&s.vertices))
        .sum();
    assert_eq!(file.scene.surfaces.len(), 4);
    assert!((area - 3.0).abs() < 1e-12, "{area}");
}

/// Regression (found by the obj fuzz target, the same check here): a quad with one corner
/// 1e8 times further off than the others passes the polygon checks, but flattened two
/// corners fall within the same-point distance; the reader must refuse it, not accept an
/// unusable surface.
#[test]
fn sliver_that_flattening_makes_degenerate_is_refused() {
    let text = with_lines(&[
        (13, "VERTEX0 213 548.8 227"),
        (14, "VERTEX1 213 548.8 332"),
        (15, "VERTEX2 0 548.8e8 332"),
        (16, "VERTEX3 0 548.8 227"),
    ]);
    one_error(
        &text,
        13,
        1,
        "degenerate polygon: VERTEX0 and VERTEX1 are the same point",
    );
}
