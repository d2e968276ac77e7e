//! The DXF reader: the Cornell box (as 3DFACEs, polyface meshes and MESHes) against the
//! scene file, inserts and their transforms, the materials file, and bad files.

use std::fmt::Write as _;
use std::path::PathBuf;

use glam::{dvec3, DVec3};

use super::*;
use crate::geometry;
use crate::io::import::read_any_scene;
use crate::progress::NoProgress;
use crate::scene::Scene;
use crate::{pipeline, Overrides, Prepared, SolveRequest, Solver};

fn repo_file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(name)
}

fn cornell_scene() -> Scene {
    crate::io::scene_file::read_scene(&repo_file("examples/cornell_box.scene"))
        .unwrap()
        .scene
}

/// Group-code / value lines.
fn g(out: &mut String, code: i32, value: impl std::fmt::Display) {
    writeln!(out, "{code}\n{value}").unwrap();
}

fn point(out: &mut String, k: i32, p: DVec3) {
    g(out, 10 + k, p.x);
    g(out, 20 + k, p.y);
    g(out, 30 + k, p.z);
}

/// The DXF of a scene: each surface on a layer of its name, as a 3DFACE, a polyface mesh
/// and a MESH in turn (surface k as kind k mod 3); numbers as Rust writes an f64 (the
/// shortest text that reads back the same). Millimetres ($INSUNITS 4).
pub(crate) fn scene_to_dxf(scene: &Scene) -> String {
    let mut o = String::new();
    g(&mut o, 999, "The Cornell box of examples/cornell_box.scene, written by the radiosity tests (dxf_tests.rs)");
    g(&mut o, 0, "SECTION");
    g(&mut o, 2, "HEADER");
    g(&mut o, 9, "$INSUNITS");
    g(&mut o, 70, 4);
    g(&mut o, 0, "ENDSEC");
    g(&mut o, 0, "SECTION");
    g(&mut o, 2, "ENTITIES");
    for (k, s) in scene.surfaces.iter().enumerate() {
        let v = &s.vertices;
        match k % 3 {
            0 => {
                assert!(v.len() <= 4);
                g(&mut o, 0, "3DFACE");
                g(&mut o, 8, &s.name);
                for c in 0..4 {
                    point(&mut o, c as i32, v[c.min(v.len() - 1)]);
                }
            }
            1 => {
                g(&mut o, 0, "POLYLINE");
                g(&mut o, 8, &s.name);
                g(&mut o, 66, 1);
                g(&mut o, 70, 64);
                g(&mut o, 71, v.len());
                g(&mut o, 72, 1);
                for p in v {
                    g(&mut o, 0, "VERTEX");
                    g(&mut o, 8, &s.name);
                    point(&mut o, 0, *p);
                    g(&mut o, 70, 192);
                }
                g(&mut o, 0, "VERTEX");
                g(&mut o, 8, &s.name);
                point(&mut o, 0, DVec3::ZERO);
                g(&mut o, 70, 128);
                for c in 0..v.len() {
                    g(&mut o, 71 + c as i32, c + 1);
                }
                g(&mut o, 0, "SEQEND");
            }
            _ => {
                g(&mut o, 0, "MESH");
                g(&mut o, 8, &s.name);
                g(&mut o, 71, 2);
                g(&mut o, 72, 0);
                g(&mut o, 91, 0);
                g(&mut o, 92, v.len());
                for p in v {
                    point(&mut o, 0, *p);
                }
                g(&mut o, 93, v.len() + 1);
                g(&mut o, 90, v.len());
                for c in 0..v.len() {
                    g(&mut o, 90, c);
                }
                g(&mut o, 94, 0);
                g(&mut o, 95, 0);
            }
        }
    }
    g(&mut o, 0, "ENDSEC");
    g(&mut o, 0, "EOF");
    o
}

/// The materials file of a scene's DXF: a [layers."NAME"] table per surface.
pub(crate) fn scene_to_materials(scene: &Scene) -> String {
    let mut o = String::from(
        "# The Cornell box's colours by layer, written by the radiosity tests (dxf_tests.rs).\n",
    );
    for s in &scene.surfaces {
        let [r, gr, b] = s.reflectance.0;
        let [er, eg, eb] = s.emission.0;
        writeln!(
            o,
            "\n[layers.\"{}\"]\nreflectance = [{r:?}, {gr:?}, {b:?}]\nemission = [{er:?}, {eg:?}, {eb:?}]",
            s.name
        )
        .unwrap();
    }
    o
}

#[test]
#[ignore]
fn write_cornell_box_dxf() {
    let scene = cornell_scene();
    std::fs::write(
        repo_file("tests/data/cornell_box.dxf"),
        scene_to_dxf(&scene),
    )
    .unwrap();
    std::fs::write(
        repo_file("tests/data/cornell_box.materials.toml"),
        scene_to_materials(&scene),
    )
    .unwrap();
}

#[test]
fn committed_cornell_box_dxf_is_the_scene_files_box() {
    let scene = cornell_scene();
    let dxf = std::fs::read_to_string(repo_file("tests/data/cornell_box.dxf")).unwrap();
    let toml = std::fs::read_to_string(repo_file("tests/data/cornell_box.materials.toml")).unwrap();
    assert!(
        dxf == scene_to_dxf(&scene) && toml == scene_to_materials(&scene),
        "tests/data/cornell_box.dxf or .materials.toml is not what the tests make of \
         examples/cornell_box.scene; rewrite them with the ignored test write_cornell_box_dxf"
    );
}

fn solve(scene: Scene) -> Vec<[f64; 3]> {
    let coarse = Overrides {
        max_patch_area: Some(20_000.0),
        integral_steps: Some(1),
    };
    let settings = coarse.apply(crate::scene::cornell_box().settings);
    let prepared = Prepared::new(scene, settings, &NoProgress).unwrap();
    let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
    pipeline::solve(
        &prepared,
        &request,
        &mut crate::solve::keep_going,
        &NoProgress,
    )
    .unwrap()
    .element_rgb()
    .to_vec()
}

#[test]
fn cornell_box_dxf_is_the_scene_file_and_solves_the_same() {
    let imported = read_any_scene(
        &repo_file("tests/data/cornell_box.dxf"),
        &ImportOptions::default(),
    )
    .unwrap();
    assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
    assert!(
        imported
            .unit
            .starts_with("millimetres (the DXF's $INSUNITS 4, line "),
        "{}",
        imported.unit
    );
    let want = cornell_scene();
    let got = &imported.file.scene;
    assert_eq!(got.surfaces.len(), want.surfaces.len());
    for (g, w) in got.surfaces.iter().zip(&want.surfaces) {
        // Every number reads back as written and the polygons are already flat: the
        // scene file's surfaces bit for bit, whichever entity each came as.
        assert_eq!(g, w);
    }
    assert_eq!(solve(imported.file.scene), solve(want));
}

const GREY: &str = "[default]\nreflectance = [0.5, 0.5, 0.5]\n";

fn dxf(blocks: &str, entities: &str) -> String {
    format!("0\nSECTION\n2\nBLOCKS\n{blocks}0\nENDSEC\n0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n")
}

fn read(text: &str, materials: Option<&str>) -> Result<Imported, ImportError> {
    parse(
        "t.dxf",
        text.as_bytes(),
        "t.materials.toml",
        materials,
        &ImportOptions::default(),
    )
}

fn err(text: &str, materials: Option<&str>) -> String {
    read(text, materials).unwrap_err().to_string()
}

/// A 3DFACE of the unit square at (x0, y0) in the plane z = 0 (normal +z), on `layer`.
fn square(layer: &str, x0: f64, y0: f64) -> String {
    let mut o = String::new();
    g(&mut o, 0, "3DFACE");
    g(&mut o, 8, layer);
    for (k, (x, y)) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        point(&mut o, k as i32, dvec3(x0 + x, y0 + y, 0.0));
    }
    o
}

fn block(name: &str, base: DVec3, body: &str) -> String {
    let mut o = String::new();
    g(&mut o, 0, "BLOCK");
    g(&mut o, 2, name);
    point(&mut o, 0, base);
    o.push_str(body);
    g(&mut o, 0, "ENDBLK");
    o
}

fn insert_of(name: &str, layer: &str, at: DVec3, extra: &[(i32, f64)]) -> String {
    let mut o = String::new();
    g(&mut o, 0, "INSERT");
    g(&mut o, 8, layer);
    g(&mut o, 2, name);
    point(&mut o, 0, at);
    for &(c, v) in extra {
        g(&mut o, c, v);
    }
    o
}

#[test]
fn inserts_place_blocks_by_base_scale_rotation_and_point_and_lend_their_layer() {
    // Block base (1, 0, 0); its square's corner (2, 0, 0): minus the base -> (1, 0, 0),
    // scale 2 -> (2, 0, 0), rotate 90 degrees -> (0, 2, 0), at (10, 0, 0) -> (10, 2, 0).
    let text = dxf(
        &block("Seat", dvec3(1.0, 0.0, 0.0), &square("0", 1.0, 0.0)),
        &insert_of(
            "Seat",
            "Chairs",
            dvec3(10.0, 0.0, 0.0),
            &[(41, 2.0), (42, 2.0), (43, 2.0), (50, 90.0)],
        ),
    );
    let s = read(&text, Some(GREY)).unwrap().file.scene;
    assert_eq!(s.surfaces.len(), 1);
    assert_eq!(
        s.surfaces[0].name, "Chairs",
        "layer 0 in a block takes the insert's"
    );
    let v = &s.surfaces[0].vertices;
    // The corners (1,0,0), (2,0,0), (2,1,0), (1,1,0) go to (10,0,0), (10,2,0), (8,2,0),
    // (8,0,0); sin and cos of 90 degrees leave 1e-16.
    let want = [
        dvec3(10.0, 0.0, 0.0),
        dvec3(10.0, 2.0, 0.0),
        dvec3(8.0, 2.0, 0.0),
        dvec3(8.0, 0.0, 0.0),
    ];
    for (a, b) in v.iter().zip(want) {
        assert!((*a - b).length() < 1e-12, "{a} vs {b}");
    }
    assert_eq!(
        read(&text, Some(GREY)).unwrap().unit,
        "drawing units (the DXF states no $INSUNITS)"
    );
}

#[test]
fn insert_grids_extrusions_and_mirrors() {
    // A 2 x 3 grid spaced 5 and 7: six squares.
    let text = dxf(
        &block("Tile", DVec3::ZERO, &square("Tiles", 0.0, 0.0)),
        &insert_of(
            "Tile",
            "0",
            DVec3::ZERO,
            &[(70, 2.0), (71, 3.0), (44, 5.0), (45, 7.0)],
        ),
    );
    let s = read(&text, Some(GREY)).unwrap().file.scene;
    assert_eq!(s.surfaces.len(), 6);
    let corners: Vec<DVec3> = s.surfaces.iter().map(|s| s.vertices[0]).collect();
    assert!(corners.contains(&dvec3(5.0, 14.0, 0.0)), "{corners:?}");
    // Extrusion (0, 0, -1): the arbitrary axis algorithm gives the OCS x axis -x, y +y,
    // z -z (a half turn about y, not a mirror): the point (5, 0, 0) is (-5, 0, 0), and
    // the square, turned over, faces -z.
    let text = dxf(
        &block("Tile", DVec3::ZERO, &square("0", 0.0, 0.0)),
        &insert_of("Tile", "Under", dvec3(5.0, 0.0, 0.0), &[(230, -1.0)]),
    );
    let s = read(&text, Some(GREY)).unwrap().file.scene;
    assert_eq!(s.surfaces[0].vertices[0], dvec3(-5.0, 0.0, 0.0));
    let n = geometry::polygon_normal(&s.surfaces[0].vertices).unwrap();
    assert!((n + DVec3::Z).length() < 1e-12, "{n}");
    // A mirroring scale (41 = -1): the corners mirror but the front stays +z.
    let text = dxf(
        &block("Tile", DVec3::ZERO, &square("0", 0.0, 0.0)),
        &insert_of("Tile", "M", DVec3::ZERO, &[(41, -1.0)]),
    );
    let s = read(&text, Some(GREY)).unwrap().file.scene;
    let n = geometry::polygon_normal(&s.surfaces[0].vertices).unwrap();
    assert!((n - DVec3::Z).length() < 1e-12, "{n}");
    assert!(s.surfaces[0].vertices.iter().all(|p| p.x <= 0.0));
}

#[test]
fn layers_take_their_materials_and_a_default() {
    let text = dxf(
        "",
        &(square("Floor", 0.0, 0.0) + &square("Lamp", 2.0, 0.0) + &square("Other", 4.0, 0.0)),
    );
    let materials = "[layers.Floor]\nreflectance = [0.1, 0.2, 0.3]\n\n[layers.Lamp]\nreflectance = [0.5, 0.5, 0.5]\nemission = [10, 20, 30]\n\n[default]\nreflectance = [0.4, 0.4, 0.4]\n";
    let s = read(&text, Some(materials)).unwrap().file.scene;
    let names: Vec<&str> = s.surfaces.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["Floor", "Lamp", "Other"]);
    assert_eq!(s.surfaces[0].reflectance, Rgb([0.1, 0.2, 0.3]));
    assert_eq!(s.surfaces[0].emission, Rgb([0.0; 3]));
    assert_eq!(s.surfaces[1].emission, Rgb([10.0, 20.0, 30.0]));
    assert_eq!(s.surfaces[2].reflectance, Rgb([0.4; 3]));
}

#[test]
fn a_missing_layer_or_materials_file_lists_the_layers_found() {
    let text = dxf("", &(square("Floor", 0.0, 0.0) + &square("Wall", 2.0, 0.0)));
    assert_eq!(
        err(
            &text,
            Some("[layers.Floor]\nreflectance = [0.5, 0.5, 0.5]\n")
        ),
        "t.materials.toml: error: material \"Wall\": the layer \"Wall\" of t.dxf has faces \
         but no [layers.\"Wall\"] table here, and there is no [default] table; the drawing's \
         layers with faces: \"Floor\", \"Wall\""
    );
    let e = err(&text, None);
    assert!(
        e.starts_with("t.materials.toml: error: the materials file of t.dxf is missing"),
        "{e}"
    );
    assert!(
        e.ends_with("layers with faces: \"Floor\", \"Wall\", or a [default] table for all"),
        "{e}"
    );
    // A reflectance of 1 is the shared check's error, at the line of the value, naming
    // the table it is in (QA of issue #16: line 1, and the layer's name alone).
    assert_eq!(
        err(&text, Some("[default]\nreflectance = [1, 0.5, 0.5]\n")),
        "t.materials.toml:2: error: material \"[default] for layer Floor\": the red \
         reflectance is 1; reflectance must be at least 0 and below 1 (a surface cannot \
         reflect all the light it receives, or more)"
    );
    let e = err(
        &text,
        Some("[default]\nreflectance = [0.5, 0.5, 0.5]\nemission = [nan, 1, 1]\n"),
    );
    assert!(
        e.starts_with(
            "t.materials.toml:3: error: material \"[default] for layer Floor\": the \
                       red emission is NaN"
        ),
        "{e}"
    );
    let e = err(
        &text,
        Some(
            "[layers.Floor]\nreflectance = [0.5, 0.5, 0.5]\n\n[layers.Wall]\n\
             reflectance = [0.5, -0.5, 0.5]\n",
        ),
    );
    assert!(
        e.starts_with("t.materials.toml:5: error: material \"Wall\": the green reflectance"),
        "{e}"
    );
    // A table no layer takes is checked as well, at the value's line (QA pass 15: an
    // emission of -5 on a misspelt layer's table passed unremarked), and so is a [default]
    // that every layer's own table overrides.
    let e = err(
        &text,
        Some(
            "[layers.Floor]\nreflectance = [0.5, 0.5, 0.5]\n[layers.Wall]\n\
             reflectance = [0.5, 0.5, 0.5]\n[layers.Lamp]\nreflectance = [0.5, 0.5, 0.5]\n\
             emission = [-5, 1, 1]\n",
        ),
    );
    assert!(
        e.starts_with(
            "t.materials.toml:7: error: material \"[layers.\"Lamp\"], used by no layer with \
             faces\": the red emission is -5"
        ),
        "{e}"
    );
    let e = err(
        &text,
        Some(
            "[layers.Floor]\nreflectance = [0.5, 0.5, 0.5]\n[layers.Wall]\n\
             reflectance = [0.5, 0.5, 0.5]\n[default]\nreflectance = [1.5, 0.5, 0.5]\n",
        ),
    );
    assert!(
        e.starts_with("t.materials.toml:6: error: material \"[default], used by no layer"),
        "{e}"
    );
    // Not TOML, or a misspelt key: the line.
    let e = err(
        &text,
        Some("[default]\nreflectance = [0.5, 0.5, 0.5]\nemision = [1, 1, 1]\n"),
    );
    assert!(
        e.starts_with("t.materials.toml:3: error: not a materials file (unknown field `emision`"),
        "{e}"
    );
}

#[test]
fn a_drawing_without_faces_says_so_before_asking_for_materials() {
    // QA of issue #16: a drawing of lines asked for a materials file naming its layers
    // with faces, of which it had none.
    let line = "0\nLINE\n8\nWalls\n10\n0\n20\n0\n30\n0\n11\n1\n21\n0\n31\n0\n";
    assert_eq!(
        err(&dxf("", line), None),
        "t.dxf: error: no usable faces: the drawing has no 3DFACE, polyface mesh or MESH (its \
         entities, which give no faces: 1 LINE)"
    );
    assert_eq!(
        err(&dxf("", ""), None),
        "t.dxf: error: no usable faces: the drawing has no 3DFACE, polyface mesh or MESH"
    );
}

#[test]
fn a_table_that_names_no_layer_is_pointed_out() {
    let text = dxf("", &(square("Floor", 0.0, 0.0) + &square("Wall", 2.0, 0.0)));
    // Misspelt beside a [default]: read, with a warning at the table's line.
    let materials = "[layers.floor]\nreflectance = [0.1, 0.2, 0.3]\n\n[default]\nreflectance = [0.4, 0.4, 0.4]\n";
    let imported = read(&text, Some(materials)).unwrap();
    let warnings: Vec<String> = imported.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        warnings,
        [
            "t.materials.toml:1: warning: [layers.\"floor\"] names no layer of t.dxf with faces, \
          so it is not used (layer names are case sensitive: \"Floor\"?); the layers with \
          faces: \"Floor\", \"Wall\""
        ]
    );
    assert_eq!(imported.file.scene.surfaces[0].reflectance, Rgb([0.4; 3]));
    // Without a [default]: the refusal names the table too.
    let e = err(
        &text,
        Some("[layers.Flor]\nreflectance = [0.5, 0.5, 0.5]\n[layers.Wall]\nreflectance = [0.5, 0.5, 0.5]\n"),
    );
    assert!(
        e.ends_with("tables here that name no layer with faces: [layers.\"Flor\"]"),
        "{e}"
    );
}

#[test]
fn block_cycles_and_missing_blocks_are_refused() {
    let blocks = block("A", DVec3::ZERO, &insert_of("B", "0", DVec3::ZERO, &[]))
        + &block(
            "B",
            DVec3::ZERO,
            &(square("0", 0.0, 0.0) + &insert_of("A", "0", DVec3::ZERO, &[])),
        );
    let e = err(
        &dxf(&blocks, &insert_of("A", "L", DVec3::ZERO, &[])),
        Some(GREY),
    );
    assert!(
        e.ends_with(
            "error: the block \"A\" inserts itself (A -> B -> A): a cycle of block references"
        ),
        "{e}"
    );
    let e = err(
        &dxf(&blocks, &insert_of("C", "L", DVec3::ZERO, &[])),
        Some(GREY),
    );
    assert!(
        e.ends_with("INSERT of the block \"C\", which the BLOCKS section does not define (it defines: A, B)"),
        "{e}"
    );
}

#[test]
fn insert_explosions_are_refused() {
    // B0 holds nothing; Bk inserts B(k-1) twice: 2^30 placements from 30 blocks (within
    // the depth limit of 32).
    let mut blocks = block("B0", DVec3::ZERO, "");
    for k in 1..=30 {
        let body = insert_of(&format!("B{}", k - 1), "0", DVec3::ZERO, &[])
            + &insert_of(&format!("B{}", k - 1), "0", DVec3::ZERO, &[]);
        blocks += &block(&format!("B{k}"), DVec3::ZERO, &body);
    }
    let e = err(
        &dxf(&blocks, &insert_of("B30", "L", DVec3::ZERO, &[])),
        Some(GREY),
    );
    assert!(
        e.contains(&format!("more than {MAX_PLACEMENTS} block placements")),
        "{e}"
    );
    let e = err(
        &dxf(
            &block("T", DVec3::ZERO, ""),
            &insert_of("T", "L", DVec3::ZERO, &[(70, 1e9)]),
        ),
        Some(GREY),
    );
    assert!(
        e.contains("grid of 1000000000 columns (70) by 1 rows (71) is outside 1 to 100000"),
        "{e}"
    );
}

#[test]
fn truncated_and_malformed_files_say_where() {
    assert_eq!(
        err("0\nSECTION\n2\nENTITIES\n0\n3DFACE\n8\n", Some(GREY)),
        "t.dxf:7: error: the file ends after the group code 8, before its value"
    );
    assert_eq!(
        err(
            "0\nSECTION\n2\nENTITIES\n0\n3DFACE\n8\nL\n10\n1\n",
            Some(GREY)
        ),
        "t.dxf:1: error: the ENTITIES section that starts here has no ENDSEC: the file is \
         truncated"
    );
    assert_eq!(
        err(&dxf("", "0\n3DFACE\n10\nabc\n"), Some(GREY)),
        "t.dxf:14: error: group 10 needs a number, found \"abc\""
    );
    assert_eq!(
        err(&dxf("", "0\n3DFACE\n10\nNaN\n"), Some(GREY)),
        "t.dxf:14: error: group 10: the coordinate NaN is not a finite number"
    );
    assert_eq!(
        err("x\n0\n", Some(GREY)),
        "t.dxf:1: error: expected a group code (a whole number) on this line, found \"x\""
    );
    assert!(err(&dxf("", "0\n3DFACE\n8\nL\n10\n0\n"), Some(GREY))
        .contains("a 3DFACE needs at least three corners"));
    let e = parse(
        "t.dxf",
        b"AutoCAD Binary DXF\r\n\x1a\0",
        "m",
        Some(GREY),
        &ImportOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("binary DXF"), "{e}");
    // A POLYLINE cut before its SEQEND.
    let e = err(
        &dxf("", "0\nPOLYLINE\n70\n64\n0\nVERTEX\n70\n192\n"),
        Some(GREY),
    );
    assert!(
        e.contains("has 1 VERTEX records and then the end of the section, not its SEQEND"),
        "{e}"
    );
}

#[test]
fn wrong_indices_and_huge_counts_are_refused() {
    // A polyface face naming vertex 5 of 3.
    let mut p = String::new();
    g(&mut p, 0, "POLYLINE");
    g(&mut p, 70, 64);
    for v in [DVec3::ZERO, DVec3::X, DVec3::Y] {
        g(&mut p, 0, "VERTEX");
        point(&mut p, 0, v);
        g(&mut p, 70, 192);
    }
    g(&mut p, 0, "VERTEX");
    g(&mut p, 70, 128);
    g(&mut p, 71, 1);
    g(&mut p, 72, -2);
    g(&mut p, 73, 5);
    g(&mut p, 0, "SEQEND");
    let e = err(&dxf("", &p), Some(GREY));
    assert!(
        e.contains("error: face record (group 73) of the POLYLINE of line 11: vertex index 5 is out of range (3 vertices can be named there)"),
        "{e}"
    );
    // A MESH that says it has four billion vertices, in a file of a few lines.
    let e = err(&dxf("", "0\nMESH\n92\n4000000000\n10\n0\n"), Some(GREY));
    assert!(
        e.contains("MESH vertex count (group 92) says 4000000000 items"),
        "{e}"
    );
    // A MESH face naming vertex 3 of 3, and a face running past its list.
    let mut m = String::new();
    g(&mut m, 0, "MESH");
    g(&mut m, 92, 3);
    for v in [DVec3::ZERO, DVec3::X, DVec3::Y] {
        point(&mut m, 0, v);
    }
    g(&mut m, 93, 4);
    for i in [3, 0, 1, 3] {
        g(&mut m, 90, i);
    }
    let e = err(&dxf("", &m), Some(GREY));
    assert!(e.starts_with("t.dxf:42: error: "), "{e}");
    assert!(e.contains("face 1 of the MESH of line 11: vertex index 3 is out of range (3 vertices can be named there)"), "{e}");
    let e = err(
        &dxf("", &m.replace("93\n4\n90\n3\n", "93\n4\n90\n9\n")),
        Some(GREY),
    );
    assert!(
        e.contains("MESH face of 9 corners runs past the end of its face list (4 entries)"),
        "{e}"
    );
}

#[test]
fn other_entities_are_counted_in_a_warning() {
    let text = dxf(
        "",
        &("0\nLINE\n8\nL\n10\n0\n0\nCIRCLE\n8\nL\n0\nLINE\n".to_string() + &square("F", 0.0, 0.0)),
    );
    let got = read(&text, Some(GREY)).unwrap();
    assert_eq!(got.file.scene.surfaces.len(), 1);
    assert_eq!(
        got.warnings[0].message,
        "entities left out (no faces read from them): 1 CIRCLE, 2 LINE"
    );
}

#[test]
fn an_insert_grid_stacking_hundreds_of_copies_drops_them_without_a_panic() {
    // The DXF fuzz target's crash (corpus/dxf/insert_grid_stacked_copies.dxf): a grid of
    // 64 x 4 cells spaced 0 puts 256 copies of a triangle in one place; the duplicate
    // check's hierarchy over 256 identical boxes was deeper than obvhs's traversal stack.
    let mut tri = String::new();
    g(&mut tri, 0, "3DFACE");
    g(&mut tri, 8, "0");
    for (k, p) in [
        dvec3(-1.0, 0.0, 0.0),
        dvec3(-1.1, 0.0, 0.0),
        dvec3(-1.0, 0.0, -1.0),
    ]
    .into_iter()
    .enumerate()
    {
        point(&mut tri, k as i32, p);
    }
    let text = dxf(
        &block("Leg", DVec3::ZERO, &tri),
        &insert_of("Leg", "Legs", DVec3::ZERO, &[(70, 64.0), (71, 4.0)]),
    );
    let got = read(&text, Some(GREY)).unwrap();
    assert_eq!(got.file.scene.surfaces.len(), 1);
    assert!(
        got.warnings
            .iter()
            .any(|w| w.message.starts_with("dropped 255 faces given twice")),
        "{:?}",
        got.warnings
    );
}
