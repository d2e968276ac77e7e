//! The VRML97 reader: the Cornell box against the scene file, the box primitive against
//! the scene format's, the sphere's area, transforms, DEF/USE, and bad files.

use std::fmt::Write as _;
use std::path::PathBuf;

use glam::{dvec3, DVec3};

use super::*;
use crate::geometry;
use crate::io::import::read_any_scene;
use crate::io::scene_file::parse_scene;
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

/// A surface name as a VRML name (no spaces).
fn vrml_name(name: &str) -> String {
    name.replace(' ', "_")
}

/// The VRML97 of a scene: a `DEF`-named Shape per surface, its polygon an
/// IndexedFaceSet, its colours a Material (emission as `emissiveColor`, scale 1). Numbers
/// are written as Rust writes an f64 (the shortest text that reads back the same).
pub(crate) fn scene_to_vrml(scene: &Scene) -> String {
    let mut out = String::from("#VRML V2.0 utf8\n# Written from examples/cornell_box.scene by the radiosity tests (vrml_tests.rs).\n");
    for s in &scene.surfaces {
        let [rr, rg, rb] = s.reflectance.0;
        let [er, eg, eb] = s.emission.0;
        let points: Vec<String> = s
            .vertices
            .iter()
            .map(|v| format!("{} {} {}", v.x, v.y, v.z))
            .collect();
        let index: Vec<String> = (0..s.vertices.len()).map(|k| k.to_string()).collect();
        writeln!(
            out,
            "DEF {} Shape {{\n  appearance Appearance {{ material Material {{ diffuseColor {rr} {rg} {rb} emissiveColor {er} {eg} {eb} }} }}\n  geometry IndexedFaceSet {{\n    coord Coordinate {{ point [ {} ] }}\n    coordIndex [ {} -1 ]\n  }}\n}}",
            vrml_name(&s.name),
            points.join(", "),
            index.join(" ")
        )
        .unwrap();
    }
    out
}

#[test]
#[ignore]
fn write_cornell_box_wrl() {
    std::fs::write(
        repo_file("tests/data/cornell_box.wrl"),
        scene_to_vrml(&cornell_scene()),
    )
    .unwrap();
}

#[test]
fn committed_cornell_box_wrl_is_the_scene_files_box() {
    let committed = std::fs::read_to_string(repo_file("tests/data/cornell_box.wrl")).unwrap();
    assert!(
        committed == scene_to_vrml(&cornell_scene()),
        "tests/data/cornell_box.wrl is not what scene_to_vrml makes of \
         examples/cornell_box.scene; rewrite it with the ignored test write_cornell_box_wrl"
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
fn cornell_box_wrl_is_the_scene_file_and_solves_the_same() {
    let imported = read_any_scene(
        &repo_file("tests/data/cornell_box.wrl"),
        &ImportOptions::default(),
    )
    .unwrap();
    assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
    assert_eq!(imported.unit, "metres (VRML97's unit)");
    let want = cornell_scene();
    let got = &imported.file.scene;
    assert_eq!(got.surfaces.len(), want.surfaces.len());
    for (g, w) in got.surfaces.iter().zip(&want.surfaces) {
        // Every number is written so that it reads back the same, and the scene file's
        // polygons are already flat: the surfaces are the scene file's, bit for bit.
        assert_eq!(g.name, vrml_name(&w.name));
        assert_eq!(g.vertices, w.vertices, "{}", w.name);
        assert_eq!(g.reflectance, w.reflectance, "{}", w.name);
        assert_eq!(g.emission, w.emission, "{}", w.name);
    }
    assert_eq!(solve(imported.file.scene), solve(want));
}

fn read(text: &str) -> Result<Imported, ImportError> {
    parse("t.wrl", text.as_bytes(), &ImportOptions::default())
}

fn err(text: &str) -> String {
    read(text).unwrap_err().to_string()
}

#[test]
fn a_vrml_box_is_the_scene_formats_box() {
    let scene = parse_scene(
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\nBOXBEGIN\n#Table\nFACING OUT\n\
         Er 0\nEg 0\nEb 0\nRr 0.5\nRg 0.25\nRb 0.125\nORIGIN 1 0 2\nSIZE 2 0.8 1\nBOXEND\nSCENEEND\n",
        "box.scene",
    )
    .unwrap()
    .scene;
    let vrml = read(
        "#VRML V2.0 utf8\nTransform { translation 2 0.4 2.5 children [\n\
         DEF Table Shape { appearance Appearance { material Material { diffuseColor 0.5 0.25 0.125 } }\n\
         geometry Box { size 2 0.8 1 } } ] }",
    )
    .unwrap()
    .file
    .scene;
    assert_eq!(vrml.surfaces.len(), 6);
    for (k, (v, s)) in vrml.surfaces.iter().zip(&scene.surfaces).enumerate() {
        assert_eq!(v.name, format!("Table.{k}"));
        assert_eq!(v.reflectance, s.reflectance);
        assert_eq!(v.vertices.len(), 4);
        // The same corners in the same order; the VRML box was centred and moved, so its
        // coordinates carry a rounding or two (1e-15 of them).
        for (a, b) in v.vertices.iter().zip(&s.vertices) {
            assert!((*a - *b).length() < 1e-12, "{}: {a} vs {b}", s.name);
        }
    }
}

fn sphere_area(segments: u32) -> f64 {
    parse_with(
        "t.wrl",
        b"#VRML V2.0 utf8\nShape { geometry Sphere { radius 2 } }",
        &ImportOptions::default(),
        segments,
    )
    .unwrap()
    .file
    .scene
    .total_area()
}

#[test]
fn a_vrml_spheres_area_converges_to_4_pi_r_squared() {
    let exact = 4.0 * std::f64::consts::PI * 4.0;
    let errors: Vec<f64> = [8, 16, 32, 64, 128]
        .iter()
        .map(|&n| (exact - sphere_area(n)) / exact)
        .collect();
    // An inscribed polyhedron has less area than its sphere, and the shortfall falls as
    // the square of the segment size: a quarter for each doubling (3.5 to 4.5 allows for
    // the coarse start).
    for w in errors.windows(2) {
        assert!(w[0] > 0.0 && w[1] > 0.0, "{errors:?}");
        let ratio = w[0] / w[1];
        assert!((3.5..4.5).contains(&ratio), "{errors:?}");
    }
    assert!(errors[4] < 1e-3, "{errors:?}");
    // The default resolution, 16 segments, is 3.2% short (as the scene format's).
    let default = read("#VRML V2.0 utf8\nShape { geometry Sphere { radius 2 } }")
        .unwrap()
        .file
        .scene;
    assert_eq!(default.surfaces.len(), 16 * 8);
    let short = (exact - default.total_area()) / exact;
    assert!((0.031..0.033).contains(&short), "{short}");
}

#[test]
fn vrml_round_primitives_are_the_scene_formats_of_the_same_resolution() {
    // A scene file's sphere, cylinder and cone (CENTER is a cylinder's or cone's base
    // centre) and the VRML ones placed to match (VRML centres them on the origin).
    let scene = parse_scene(
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\n\
         SPHEREBEGIN\n#Ball\nFACING OUT\nEr 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\n\
         CENTER 0 1 0\nRADIUS 0.5\nRESOLUTION 12\nSPHEREEND\n\
         CYLINDERBEGIN\n#Can\nFACING OUT\nEr 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\n\
         CENTER 3 0 0\nRADIUS 0.5\nHEIGHT 2\nRESOLUTION 12\nCYLINDEREND\n\
         CONEBEGIN\n#Hat\nFACING OUT\nEr 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\n\
         CENTER -3 0 0\nRADIUS 0.5\nHEIGHT 2\nRESOLUTION 12\nCONEEND\nSCENEEND\n",
        "round.scene",
    )
    .unwrap()
    .scene;
    let vrml = parse_with(
        "t.wrl",
        b"#VRML V2.0 utf8\n\
          Transform { translation 0 1 0 children Shape { geometry Sphere { radius 0.5 } } }\n\
          Transform { translation 3 1 0 children Shape { geometry Cylinder { radius 0.5 height 2 } } }\n\
          Transform { translation -3 1 0 children Shape { geometry Cone { bottomRadius 0.5 height 2 } } }",
        &ImportOptions::default(),
        12,
    )
    .unwrap()
    .file
    .scene;
    assert_eq!(vrml.surfaces.len(), scene.surfaces.len());
    assert_eq!(vrml.surfaces.len(), 12 * 6 + (12 + 2) + (12 + 1));
    for (v, s) in vrml.surfaces.iter().zip(&scene.surfaces) {
        assert_eq!(v.vertices.len(), s.vertices.len(), "{}", s.name);
        // The same corners in the same order; VRML's are centred, then moved (a rounding
        // of 1e-16 of the coordinates, flattened after).
        for (a, b) in v.vertices.iter().zip(&s.vertices) {
            assert!((*a - *b).length() < 1e-12, "{}: {a} vs {b}", s.name);
        }
    }
}

#[test]
fn transform_applies_center_and_scale_orientation_in_vrml_order() {
    // P' = T C R SR S -SR -C P. With C = (1, 0, 0), R = 90 degrees about z, SR = 90
    // degrees about z, S = (2, 1, 1), T = (0, 0, 5): the corner P = (2, 0, 0):
    // -C -> (1, 0, 0); -SR (rotate -90 about z) -> (0, -1, 0); S -> (0, -1, 0);
    // SR -> (1, 0, 0); R -> (0, 1, 0); C -> (1, 1, 0); T -> (1, 1, 5).
    let s = read(
        "#VRML V2.0 utf8\nTransform { translation 0 0 5 center 1 0 0 rotation 0 0 1 1.5707963267948966\n\
         scaleOrientation 0 0 1 1.5707963267948966 scale 2 1 1 children Shape { geometry IndexedFaceSet {\n\
         coord Coordinate { point [ 2 0 0, 2 1 0, 1 1 0 ] } coordIndex [ 0 1 2 ] } } }",
    )
    .unwrap()
    .file
    .scene;
    let v = s.surfaces[0].vertices[0];
    assert!((v - dvec3(1.0, 1.0, 5.0)).length() < 1e-12, "{v}");
    // The other corners, by the same steps: (2, 1, 0) -> (1, 0, 0) -> (1, -1, 0) -> (2,
    // -1, 0) -> (1, 2, 0) -> (-2, 1, 0) -> (-1, 1, 0) -> (-1, 1, 5).
    let w = s.surfaces[0].vertices[1];
    assert!((w - dvec3(-1.0, 1.0, 5.0)).length() < 1e-12, "{w}");
    assert_eq!(s.surfaces[0].name, "Shape 1");
    // Material's defaults for a Shape without one.
    assert_eq!(s.surfaces[0].reflectance, Rgb([0.8; 3]));
}

#[test]
fn def_use_places_a_node_again_and_names_surfaces_after_def() {
    let s = read(
        "#VRML V2.0 utf8\n\
         DEF Quad Shape { geometry IndexedFaceSet { coord Coordinate { point [0 0 0, 1 0 0, 1 1 0, 0 1 0] }\n\
         coordIndex [0 1 2 3 -1] ccw FALSE } }\n\
         DEF Moved Transform { translation 0 0 3 children [ USE Quad ] }",
    )
    .unwrap()
    .file
    .scene;
    assert_eq!(s.surfaces.len(), 2);
    assert_eq!(s.surfaces[0].name, "Quad");
    assert_eq!(s.surfaces[1].name, "Quad");
    // ccw FALSE: the corners run clockwise seen from +z, so the front faces -z.
    let n = geometry::polygon_normal(&s.surfaces[0].vertices).unwrap();
    assert!((n + DVec3::Z).length() < 1e-12, "{n}");
    assert!(s.surfaces[1].vertices.iter().all(|v| v.z == 3.0));
}

#[test]
fn primitives_honour_their_part_flags_and_mirrors_keep_them_outward() {
    let s = read("#VRML V2.0 utf8\nShape { geometry Cylinder { top FALSE bottom FALSE } }")
        .unwrap()
        .file
        .scene;
    assert_eq!(s.surfaces.len(), DEFAULT_SEGMENTS as usize);
    let s =
        read("#VRML V2.0 utf8\nTransform { scale -1 1 1 children Shape { geometry Cone { } } }")
            .unwrap()
            .file
            .scene;
    assert_eq!(s.surfaces.len(), 1 + DEFAULT_SEGMENTS as usize);
    for surface in &s.surfaces {
        let n = geometry::polygon_normal(&surface.vertices).unwrap();
        assert!(
            n.dot(geometry::vertex_mean(&surface.vertices)) > 0.0,
            "{}",
            surface.name
        );
    }
}

#[test]
fn viewpoint_becomes_the_camera() {
    let s = read(
        "#VRML V2.0 utf8\nViewpoint { position 1 2 3 fieldOfView 0.5 }\n\
         Shape { geometry Box { } }",
    )
    .unwrap()
    .file
    .scene;
    let c = s.camera.unwrap();
    assert_eq!(c.eye, dvec3(1.0, 2.0, 3.0));
    assert_eq!(c.look_at, dvec3(1.0, 2.0, 2.0));
    assert!((c.fov_y_degrees - 0.5f64.to_degrees()).abs() < 1e-12);
}

#[test]
fn protos_routes_scripts_and_unknown_nodes_are_skipped_with_a_count() {
    let got = read(
        "#VRML V2.0 utf8\n\
         PROTO Thing [ field SFFloat size 1 ] { Shape { geometry Box { size IS size } } }\n\
         EXTERNPROTO Far [ field SFFloat x ] \"far.wrl#Far\"\n\
         DEF S Script { eventIn SFBool go url \"javascript: function go() { }\" }\n\
         Thing { size 3 }\n\
         PointLight { location 0 1 0 }\n\
         Shape { geometry PointSet { } }\n\
         DEF T TimeSensor { } ROUTE T.fraction_changed TO S.go\n\
         Shape { geometry Box { } }",
    )
    .unwrap();
    assert_eq!(got.file.scene.surfaces.len(), 6);
    assert_eq!(
        got.warnings[0].message,
        "left out (no surfaces made of them): 1 Thing node, 1 PointSet geometry"
    );
}

// ---- Bad and hostile files.

#[test]
fn truncated_files_say_what_is_missing() {
    assert_eq!(
        err("#VRML V2.0 utf8\nShape { geometry Box { size 1 1 1 }\n"),
        "t.wrl:3: error: the file ends inside the Shape node of line 2 (a '}' is missing)"
    );
    assert_eq!(
        err("#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coordIndex [ 0 1 2"),
        "t.wrl:2: error: the file ends inside the list of the field coordIndex of line 2 (a ']' is missing)"
    );
    assert_eq!(
        err("#VRML V2.0 utf8\nWorldInfo { title \"never closed }"),
        "t.wrl:2: error: a string that is never closed (\")"
    );
}

#[test]
fn wrong_headers_and_gzip_are_refused() {
    assert!(err("#VRML V1.0 ascii\nSeparator { }").contains("a VRML 1.0 file"));
    assert!(err("solid x\n").starts_with("t.wrl:1: error: expected the VRML97 header"));
    let e = parse("t.wrl", &[0x1f, 0x8b, 8, 0], &ImportOptions::default()).unwrap_err();
    assert!(e.to_string().contains("compressed with gzip"), "{e}");
}

#[test]
fn wrong_indices_are_refused_naming_the_face() {
    assert_eq!(
        err("#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\ncoord Coordinate { point [0 0 0, 1 0 0, 1 1 0] }\ncoordIndex [ 0 1 2 -1 0 2 9 -1 ] } }"),
        "t.wrl:4: error: IndexedFaceSet of line 2, coordIndex entry 6 (face 2): vertex index 9 \
         is out of range (3 vertices can be named there)"
    );
    assert!(err("#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\ncoord Coordinate { point [0 0 0, 1 0 0, 1 1 0] }\ncoordIndex [ 0 1 -2 ] } }").contains("vertex index -2"));
    assert!(err("#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\ncoord Coordinate { point [0 0 0, 1 0] } } }").contains("Coordinate.point has 5 numbers"));
}

#[test]
fn non_finite_numbers_are_refused_at_their_line() {
    assert_eq!(
        err("#VRML V2.0 utf8\nShape { geometry Sphere {\nradius 1e999 } }"),
        "t.wrl:3: error: \"1e999\" is not a finite number (inf)"
    );
    // NaN spelt as a word (QA of issue #16: "expected '{' after the node type nan").
    assert_eq!(
        err("#VRML V2.0 utf8\nShape { geometry Sphere { radius nan } }"),
        "t.wrl:2: error: \"nan\" is not a finite number"
    );
    assert_eq!(
        err(
            "#VRML V2.0 utf8\nShape { appearance Appearance { material Material {\n\
             diffuseColor 0.5 0.5 NaN } } geometry Sphere { } }"
        ),
        "t.wrl:3: error: \"NaN\" is not a finite number"
    );
    assert!(
        err("#VRML V2.0 utf8\nShape { geometry Sphere { radius Infinity } }")
            .contains("\"Infinity\" is not a finite number")
    );
    assert!(
        err("#VRML V2.0 utf8\nShape { geometry Sphere { radius -1 } }")
            .contains("Sphere.radius is -1; it must be positive")
    );
}

#[test]
fn use_cycles_and_unknown_names_are_refused() {
    assert_eq!(
        err("#VRML V2.0 utf8\nDEF A Transform { children [\nUSE A ] }"),
        "t.wrl:3: error: USE A inside the definition of A itself: the node would contain \
         itself (a cycle)"
    );
    assert_eq!(
        err("#VRML V2.0 utf8\nGroup { children USE B }"),
        "t.wrl:2: error: USE B: no node named B is defined (DEF) before it"
    );
}

#[test]
fn deep_nesting_and_use_explosions_are_refused() {
    let mut deep = String::from("#VRML V2.0 utf8\n");
    for _ in 0..100_000 {
        deep.push_str("Group { children [ ");
    }
    assert_eq!(
        err(&deep),
        format!("t.wrl:2: error: nodes nested more than {MAX_DEPTH} deep (the Group here)")
    );
    // Each group uses the last twice: 2^40 visits asked for in 40 lines.
    let mut doubling = String::from("#VRML V2.0 utf8\nDEF G0 Group { }\n");
    for k in 1..=40 {
        writeln!(
            doubling,
            "DEF G{k} Group {{ children [ USE G{} USE G{} ] }}",
            k - 1,
            k - 1
        )
        .unwrap();
    }
    assert!(err(&doubling).contains(&format!("more than {MAX_VISITS} nodes to visit")));
    // The same with a shape at the bottom runs into the face limit first or the visits.
    let mut faces = String::from("#VRML V2.0 utf8\nDEF G0 Shape { geometry Sphere { } }\n");
    for k in 1..=30 {
        writeln!(
            faces,
            "DEF G{k} Group {{ children [ USE G{} USE G{} ] }}",
            k - 1,
            k - 1
        )
        .unwrap();
    }
    let e = err(&faces);
    assert!(
        e.contains(&format!("more than {MAX_FACES} faces")) || e.contains("nodes to visit"),
        "{e}"
    );
}

#[test]
fn a_vrml_sphere_and_a_scene_file_sphere_of_one_resolution_solve_the_same() {
    // The same grey ball (resolution 12) above a floor under a light; floor and light are
    // added to both as the same surfaces, so that only the sphere's way in differs.
    let mut scene = parse_scene(
        "MAX_PATCH_AREA 0.05\nINTEGRAL_STEPS 1\nSCENEBEGIN\n\
         SPHEREBEGIN\n#Ball\nFACING OUT\nEr 0\nEg 0\nEb 0\nRr 0.5\nRg 0.4\nRb 0.3\n\
         CENTER 0 1 0\nRADIUS 0.5\nRESOLUTION 12\nSPHEREEND\nSCENEEND\n",
        "ball.scene",
    )
    .unwrap();
    let mut vrml = parse_with(
        "ball.wrl",
        b"#VRML V2.0 utf8\n\
          Transform { translation 0 1 0 children Shape {\n\
            appearance Appearance { material Material { diffuseColor 0.5 0.4 0.3 } }\n\
            geometry Sphere { radius 0.5 } } }",
        &ImportOptions::default(),
        12,
    )
    .unwrap()
    .file
    .scene;
    let square = |y: f64, up: bool, emission: f64, reflectance: f64, name: &str| {
        let mut v = vec![
            dvec3(-1., y, -1.),
            dvec3(-1., y, 1.),
            dvec3(1., y, 1.),
            dvec3(1., y, -1.),
        ];
        if !up {
            v.reverse();
        }
        crate::scene::Surface {
            name: name.into(),
            emission: crate::light::Rgb([emission; 3]),
            reflectance: crate::light::Rgb([reflectance; 3]),
            vertices: v,
            photometry: Default::default(),
        }
    };
    for s in [&mut scene.scene, &mut vrml] {
        s.surfaces.push(square(0.0, true, 0.0, 0.5, "floor"));
        s.surfaces.push(square(2.5, false, 10.0, 0.0, "light"));
    }
    let settings = scene.settings;
    let solve = |s: Scene| {
        let prepared = Prepared::new(s, settings, &NoProgress).unwrap();
        pipeline::solve(
            &prepared,
            &SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL),
            &mut crate::solve::keep_going,
            &NoProgress,
        )
        .unwrap()
        .element_rgb()
        .to_vec()
    };
    let (a, b) = (solve(scene.scene), solve(vrml));
    assert_eq!(a.len(), b.len());
    let ball_lit = a.iter().any(|x| x[0] > 0.0 && x[0] < 10.0 && x[2] < x[0]);
    assert!(ball_lit, "the ball's colour shows in the solution");
    // The corners agree to 1e-12 (the test above); form factors and radiosities move by as
    // little relatively: 1e-9 of the light's 10 is a thousand times that.
    for (x, y) in a.iter().zip(&b) {
        for k in 0..3 {
            assert!((x[k] - y[k]).abs() <= 1e-8, "{x:?} vs {y:?}");
        }
    }
}
