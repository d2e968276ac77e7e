//! The OBJ reader: the Cornell box as OBJ, the statements read, and every bad-file case.

use std::path::Path;

use glam::dvec3;

use super::*;
use crate::io::import::read_any_scene;
use crate::io::scene_file::read_scene;

/// Reads `obj` with the MTL files of `mtls` (name, text); none other exist.
fn read_text(obj: &str, mtls: &[(&str, &str)]) -> Result<Imported, ImportError> {
    let mut loader = |name: &str| {
        mtls.iter()
            .find(|(n, _)| *n == name)
            .map(|(n, t)| (n.to_string(), t.to_string()))
            .ok_or_else(|| "No such file or directory".to_string())
    };
    parse(obj, "m.obj", &ImportOptions::default(), &mut loader)
}

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

fn repo(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

#[test]
fn cornell_box_obj_is_the_scene_file_surface_for_surface() {
    let scene_file = read_scene(&repo("examples/cornell_box.scene")).unwrap();
    let options = ImportOptions {
        scale: 1.0,
        settings: Some(scene_file.settings),
    };
    let imported = read_any_scene(&repo("tests/data/cornell_box.obj"), &options).unwrap();
    assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
    assert_eq!(imported.format, Format::Obj);
    assert_eq!(imported.unit, "metres (OBJ states no unit; metres assumed)");
    // The same numbers written the same way read into the same f64s: equal bit for bit.
    assert_eq!(imported.file, scene_file);
}

#[test]
fn cornell_box_obj_solves_as_the_scene_file() {
    use crate::pipeline::{self, Overrides, Prepared, SolveRequest};
    use crate::progress::NoProgress;
    use crate::solve::Solver;
    let scene_file = read_scene(&repo("examples/cornell_box.scene")).unwrap();
    let imported = read_any_scene(
        &repo("tests/data/cornell_box.obj"),
        &ImportOptions::default(),
    )
    .unwrap()
    .file;
    // Coarse, to keep the test quick; the same settings for both.
    let coarse = Overrides {
        max_patch_area: Some(20_000.0),
        integral_steps: Some(1),
    }
    .apply(scene_file.settings);
    let solve = |scene| {
        let prepared = Prepared::new(scene, coarse, &NoProgress).unwrap();
        let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
        pipeline::solve(
            &prepared,
            &request,
            &mut crate::solve::keep_going,
            &NoProgress,
        )
        .unwrap()
    };
    let a = solve(scene_file.scene);
    let b = solve(imported.scene);
    let (a, b) = (a.radiosity.as_slice(), b.radiosity.as_slice());
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        for k in 0..3 {
            // The same scene and settings: equal to the last bits of rounding.
            assert!(
                (x.0[k] - y.0[k]).abs() <= 1e-12 * x.0[k].abs().max(1.0),
                "{x:?} {y:?}"
            );
        }
    }
}

#[test]
fn faces_of_any_size_negative_indices_and_slashed_corners() {
    let obj = "o Pentagon\nv 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\n\
               vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3//1 4/1 -1\n\
               o Tri\nf -5 -4 -3\n";
    let imported = read_text(obj, &[]).unwrap();
    let s = &imported.file.scene.surfaces;
    assert_eq!(s.len(), 2);
    assert_eq!(s[0].name, "Pentagon");
    assert_eq!(s[0].vertices.len(), 5);
    assert_eq!(s[0].vertices[4], dvec3(-1.0, 1.0, 0.0));
    assert_eq!(s[1].name, "Tri");
    assert_eq!(
        s[1].vertices,
        [
            dvec3(0.0, 0.0, 0.0),
            dvec3(2.0, 0.0, 0.0),
            dvec3(3.0, 1.0, 0.0)
        ]
    );
    // No material file: grey 0.5, no emission; faces before any `o` would be "default".
    assert_eq!(s[0].reflectance.0, [DEFAULT_REFLECTANCE; 3]);
    assert_eq!(s[0].emission.0, [0.0; 3]);
}

#[test]
fn homogeneous_w_divides_and_colours_are_ignored() {
    let obj = "v 0 0 0 2\nv 2 0 0 2\nv 0 2 0 2\nv 0 0 1 0.5 0.5 0.5\nf 1 2 3\n";
    let s = read_text(obj, &[]).unwrap().file.scene.surfaces;
    assert_eq!(s[0].name, "default");
    assert_eq!(s[0].vertices[1], dvec3(1.0, 0.0, 0.0));
}

#[test]
fn materials_give_reflectance_and_emission() {
    let mtl = "newmtl lamp\nKd 0.1 0.2 0.3\nKe 5 4 3\nNs 10\nillum 2\n\nnewmtl grey\nKd 0.25\n";
    let obj = format!("mtllib m.mtl\n{SQUARE}usemtl lamp\nf 1 2 3 4\nusemtl grey\nf 4 3 2 1\n");
    let imported = read_text(&obj, &[("m.mtl", mtl)]).unwrap();
    assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
    let s = &imported.file.scene.surfaces;
    assert_eq!(s[0].reflectance.0, [0.1, 0.2, 0.3]);
    assert_eq!(s[0].emission.0, [5.0, 4.0, 3.0]);
    assert_eq!(s[1].reflectance.0, [0.25; 3]);
    assert_eq!(s[1].emission.0, [0.0; 3]);
    // Both faces in object "default": numbered.
    assert_eq!(s[1].name, "default.1");
}

/// QA pass 16 of #16: `mtllib /etc/passwd` was read without a word.
#[test]
fn a_material_file_of_no_materials_is_warned_about_at_its_mtllib_line() {
    let obj = format!("# a square\nmtllib p.mtl e.mtl\n{SQUARE}f 1 2 3 4\n");
    let passwd = "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1::/usr/sbin:/bin/false\n";
    let empty = "# only a comment\nKd 0.5 0.5 0.5\n";
    let e = read_text(&obj, &[("p.mtl", passwd), ("e.mtl", empty)]);
    // The Kd before any newmtl is an error of its own (as before); the file is still an
    // MTL file that defines nothing.
    let text = e.unwrap_err().to_string();
    assert!(
        text.starts_with("e.mtl:2: error: Kd before any \"newmtl\" line"),
        "{text}"
    );
    let imported = read_text(&obj, &[("p.mtl", passwd), ("e.mtl", "# nothing\nNs 10\n")]).unwrap();
    let w: Vec<String> = imported.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        w[0],
        "m.obj:2: warning: the material file \"p.mtl\" is not an MTL file (no line starts \
         with an MTL keyword such as newmtl, Kd or Ke), so it defines no materials; faces \
         whose material is not defined get the default reflectance 0.5"
    );
    assert_eq!(
        w[1],
        "m.obj:2: warning: the material file \"e.mtl\" defines no materials (no \"newmtl\" \
         line); faces whose material is not defined get the default reflectance 0.5"
    );
    assert_eq!(w.len(), 2, "{w:?}");
    // A file of materials says nothing.
    let imported = read_text(
        &obj,
        &[("p.mtl", "newmtl a\nKd 0.2\n"), ("e.mtl", "newmtl b\n")],
    );
    assert!(imported.unwrap().warnings.is_empty());
}

#[test]
fn missing_material_file_warns_and_gives_grey() {
    let obj = format!("mtllib gone.mtl\n{SQUARE}usemtl red\nf 1 2 3 4\n");
    let imported = read_text(&obj, &[]).unwrap();
    let w: Vec<String> = imported.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        w[0],
        "m.obj:1: warning: cannot read the material file \"gone.mtl\" (No such file or \
         directory): its materials get the default reflectance 0.5"
    );
    assert_eq!(
        w[1],
        "m.obj: warning: no material file defines \"red\" (line 6): its faces are given the \
         default reflectance 0.5"
    );
    assert_eq!(imported.file.scene.surfaces[0].reflectance.0, [0.5; 3]);
}

#[test]
fn reflectance_of_one_is_refused_at_its_mtl_line() {
    let mtl = "newmtl white\nKd 1 1 1\n";
    let obj = format!("mtllib m.mtl\n{SQUARE}usemtl white\nf 1 2 3 4\n");
    let e = read_text(&obj, &[("m.mtl", mtl)]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.mtl:2: error: material \"white\": Kd (the reflectance) is 1 in the red band; it \
         must be at least 0 and below 1 in every band (a surface cannot reflect all the light \
         it receives): edit the line to values below 1, such as 0.8"
    );
    // An unused material is not checked.
    let obj = format!("mtllib m.mtl\n{SQUARE}f 1 2 3 4\n");
    assert!(read_text(&obj, &[("m.mtl", mtl)]).is_ok());
    let e = read_text(
        &format!("mtllib m.mtl\n{SQUARE}usemtl e\nf 1 2 3 4\n"),
        &[("m.mtl", "newmtl e\nKe 1 -1 1\n")],
    )
    .unwrap_err();
    assert!(
        e.to_string().starts_with(
            "m.mtl:2: error: material \"e\": Ke (the emission) is -1 in the green band"
        ),
        "{e}"
    );
    // An emission too large for the scene is reported at its Ke line, not at newmtl.
    let e = read_text(
        &format!("mtllib m.mtl\n{SQUARE}usemtl e\nf 1 2 3 4\n"),
        &[("m.mtl", "newmtl e\nKd 0.5\nKe 1e39 1 1\n")],
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("m.mtl:3: error: material \"e\": the red emission is 1e39"),
        "{e}"
    );
    let e = read_text(
        &format!("mtllib m.mtl\n{SQUARE}f 1 2 3 4\n"),
        &[("m.mtl", "Kd 0.5 0.5\n")],
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.mtl:1: error: Kd before any \"newmtl\" line"
    );
}

#[test]
fn wrong_index_is_an_error_at_its_line() {
    let e = read_text(&format!("{SQUARE}o Box\nf 1 2 5\n"), &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.obj:6: error: face 1 of object \"Box\": vertex index 5 is out of range (4 \
         vertices can be named there)"
    );
    for bad in ["0", "-5"] {
        let e = read_text(&format!("{SQUARE}f 1 2 {bad}\n"), &[]).unwrap_err();
        assert!(matches!(e, ImportError::BadIndex { line: 5, .. }), "{e}");
    }
    let e = read_text(&format!("{SQUARE}f 1 2 x/1\n"), &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.obj:5: error: face 1 of object \"default\": expected a vertex index (a whole \
         number, optionally followed by /TEXTURE/NORMAL) for a corner, found \"x/1\""
    );
}

#[test]
fn nan_and_infinite_coordinates_are_errors_at_their_line() {
    let e = read_text("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.obj:2: error: vertex 2: the coordinate NaN is not a finite number"
    );
    let e = read_text("v 0 0 inf\n", &[]).unwrap_err();
    assert!(matches!(e, ImportError::NotFinite { line: 1, .. }), "{e}");
    // Finite in the file, beyond f64 once read: 1e400 reads as infinity.
    let e = read_text("v 0 0 1e400\n", &[]).unwrap_err();
    assert!(matches!(e, ImportError::NotFinite { line: 1, .. }), "{e}");
}

#[test]
fn truncated_files_are_errors_at_their_last_line() {
    // Cut inside a vertex line.
    let e = read_text("v 0 0 0\nv 1 0 0\nv 1 1", &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.obj:3: error: a vertex needs 3 coordinates (\"v x y z\", optionally a w or an r g \
         b colour after them), found 2 numbers"
    );
    // Cut inside a number.
    let e = read_text("v 0 0 0\nv 1 0 1e", &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.obj:2: error: expected a number for the z coordinate of the vertex, found \"1e\""
    );
    // Cut before the faces: nothing to make a scene of.
    let e = read_text("o Box\nv 0 0 0\nv 1 0 0\n", &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m.obj: error: no usable faces: the file has 0 faces"
    );
    // Cut inside a face: a face of two corners is degenerate, and is all there is.
    let e = read_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2", &[]).unwrap_err();
    assert!(matches!(e, ImportError::NoSurfaces { faces: 1, .. }), "{e}");
}

#[test]
fn ignored_statements_are_counted_in_one_warning() {
    let obj = format!("{SQUARE}s 1\nl 1 2\nl 2 3\np 1\ncstype bezier\nf 1 2 3 4\n");
    let w = read_text(&obj, &[]).unwrap().warnings;
    assert_eq!(w.len(), 1);
    assert_eq!(
        w[0].message,
        "ignored statements this reader does not use: 1 \"cstype\", 2 \"l\", 1 \"p\""
    );
}

#[test]
fn object_and_group_names_name_surfaces() {
    let obj = format!("{SQUARE}o Table\nf 1 2 3\ng Table top\nf 1 3 4\no Table\nf 4 3 2 1\n");
    let s = read_text(&obj, &[]).unwrap().file.scene.surfaces;
    let names: Vec<&str> = s.iter().map(|s| s.name.as_str()).collect();
    // The two `o Table` runs are one object; the group is its own.
    assert_eq!(names, ["Table.0", "Table top", "Table.1"]);
}

#[test]
fn exported_obj_reads_back_with_its_meshing_settings() {
    let scene_file = read_scene(&repo("examples/cornell_box.scene")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box.obj");
    // Settings that are not the importer's defaults (total area / 1000 and 2 steps).
    let settings = crate::MeshSettings {
        max_patch_area: 1234.5,
        integral_steps: 3,
    };
    crate::io::export::obj::write_obj(&path, &scene_file.scene, Some(settings)).unwrap();
    let back = read_any_scene(&path, &ImportOptions::default()).unwrap();
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    assert_eq!(back.file.settings, settings);
    // Scaled, the area is in the new units as the coordinates are: 1234.5 mm^2 read
    // with --scale 0.001 is 1234.5e-6 m^2 (to f64 rounding of the product).
    let scaled = read_any_scene(
        &path,
        &ImportOptions {
            scale: 0.001,
            settings: None,
        },
    )
    .unwrap();
    let area = scaled.file.settings.max_patch_area;
    assert!(
        (area - 1234.5e-6).abs() <= 1e-15 * 1234.5e-6 * 4.0,
        "{area}"
    );
    assert_eq!(scaled.file.settings.integral_steps, 3);
    // Given settings win over the file's.
    let given = crate::MeshSettings {
        max_patch_area: 10.0,
        integral_steps: 1,
    };
    let overridden = read_any_scene(
        &path,
        &ImportOptions {
            scale: 1.0,
            settings: Some(given),
        },
    )
    .unwrap();
    assert_eq!(overridden.file.settings, given);
}

#[test]
fn a_bad_setting_comment_is_left_out_with_a_warning_at_its_line() {
    let obj = format!("# MAX_PATCH_AREA -3\n# INTEGRAL_STEPS 2\n# a comment\n{SQUARE}f 1 2 3 4\n");
    let imported = read_text(&obj, &[]).unwrap();
    assert_eq!(imported.warnings.len(), 1, "{:?}", imported.warnings);
    let w = &imported.warnings[0];
    assert_eq!(w.line, 1);
    assert!(
        w.message
            .contains("MAX_PATCH_AREA needs one number greater than 0"),
        "{}",
        w.message
    );
    // The area is the default's (the unit square's area / 1000); the steps the file's.
    assert_eq!(imported.file.settings.max_patch_area, 1e-3);
    assert_eq!(imported.file.settings.integral_steps, 2);
}

#[test]
fn texture_maps_are_said_to_be_left_out() {
    // QA of issue #16 (eighth pass): a material's map_Kd was ignored without a word, so
    // its faces came out Kd's colour (or grey) with no hint why.
    let mtl = "newmtl wood\nKd 0.4 0.3 0.2\nmap_Kd wood.png\nmap_Bump n.png\nmap_Kd w2.png\n";
    let obj = format!("mtllib m.mtl\n{SQUARE}usemtl wood\nf 1 2 3 4\n");
    let read = read_text(&obj, &[("m.mtl", mtl)]).unwrap();
    let said: Vec<String> = read.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        said.iter().any(|w| w.contains("m.mtl:3")
            && w.contains(
                "texture maps are not read (map_Kd, map_Bump): each face takes its \
                           material's Kd"
            )),
        "{said:?}"
    );
    // Without maps, no such warning.
    let plain = read_text(&obj, &[("m.mtl", "newmtl wood\nKd 0.4 0.3 0.2\n")]).unwrap();
    assert!(plain
        .warnings
        .iter()
        .all(|w| !w.to_string().contains("texture")));
}

/// QA pass 16 of #16: a material's bad Kd hid its bad Ke on the next line until fixed.
#[test]
fn every_bad_colour_of_a_material_comes_in_one_run() {
    let obj = format!("mtllib m.mtl\n{SQUARE}usemtl white\nf 1 2 3 4\n");
    let mtl = "newmtl white\nKd 1 1 1\nKe -1 0 0\n";
    let e = read_text(&obj, &[("m.mtl", mtl)]).unwrap_err();
    let text = e.to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "{text}");
    assert!(
        lines[0].starts_with("m.mtl:2: error: material \"white\": Kd (the reflectance) is 1"),
        "{text}"
    );
    assert!(
        lines[1].starts_with(
            "m.mtl:3: error: material \"white\": Ke (the emission) is -1 in the red band"
        ),
        "{text}"
    );
    assert_eq!(lines[2], "2 errors");
    // A reflectance of 1 beside an emission past the largest supported (1e30): both, each
    // at its line.
    let mtl = "newmtl white\nKd 1 1 1\nKe 1e31 0 0\n";
    let text = read_text(&obj, &[("m.mtl", mtl)]).unwrap_err().to_string();
    assert!(
        text.contains("m.mtl:2: error: material \"white\": Kd"),
        "{text}"
    );
    assert!(
        text.contains("m.mtl:3: error: material \"white\": the red emission is 1e31"),
        "{text}"
    );
    assert!(text.ends_with("2 errors"), "{text}");
    // Bad colours of many materials are held to the first 20, the rest counted.
    let mut mtl = String::new();
    let mut obj = format!("mtllib m.mtl\n{SQUARE}");
    for k in 0..15 {
        mtl.push_str(&format!("newmtl m{k}\nKd 2 2 2\nKe -1 -1 -1\n"));
        obj.push_str(&format!("usemtl m{k}\nf 1 2 3 4\n"));
    }
    let e = read_text(&obj, &[("m.mtl", &mtl)]).unwrap_err();
    let ImportError::Several { errors, more } = &e else {
        panic!("{e}");
    };
    assert_eq!((errors.len(), *more), (20, 10), "{e}");
}

/// QA pass 14 of #16: four errors in an OBJ and its MTL took four runs, one each.
#[test]
fn every_error_of_an_obj_and_its_mtl_comes_in_one_run() {
    let mtl = "newmtl white\nKd 1 1 1\nnewmtl half\nKd 0.5 0.5\n";
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl white\nv nan 0 0\n\
               v 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 2 6 7 3\nf 1 2 9\nusemtl white\n";
    let e = read_text(obj, &[("m.mtl", mtl)]).unwrap_err();
    let ImportError::Several { errors, more } = &e else {
        panic!("{e}");
    };
    assert_eq!(*more, 0);
    let text = e.to_string();
    let lines: Vec<&str> = text.lines().collect();
    // The MTL's syntax error as it is read (line 1 of the OBJ), the reflectance of 1 at the
    // first `usemtl white` (not again at the second), the NaN, and the index 9 past the
    // 7 vertices (the NaN's stand-in keeps the count, so `f 2 6 7 3` is fine). File by
    // file, line by line (QA pass 18 of #16: the MTL's line 4 came before its line 2, as
    // found).
    assert_eq!(errors.len(), 4, "{text}");
    assert!(lines[0].starts_with("m.mtl:2: error:"), "{text}");
    assert!(lines[1].starts_with("m.mtl:4: error:"), "{text}");
    assert!(lines[2].starts_with("m.obj:7: error:"), "{text}");
    assert!(lines[3].starts_with("m.obj:12: error:"), "{text}");
    assert!(lines[3].contains("face 3 of object"), "{text}");
    assert_eq!(lines[4], "4 errors");
    // A refused face still counts, so the next one is named by its place in the file.
    let e = read_text(
        &format!(
            "{SQUARE}f 1 2 9
f 1 2 x
"
        ),
        &[],
    )
    .unwrap_err();
    assert!(e.to_string().contains("face 2 of object"), "{e}");
    // Past 20 errors, the rest are counted (a file of bad lines is not held whole).
    let bad: String = (0..25)
        .map(|k| {
            format!(
                "v {k} 0 q
"
            )
        })
        .collect();
    let e = read_text(&bad, &[]).unwrap_err();
    let ImportError::Several { errors, more } = &e else {
        panic!("{e}");
    };
    assert_eq!((errors.len(), *more), (20, 5));
    assert!(
        e.to_string().ends_with(
            "
25 errors (the first 20 shown)"
        ),
        "{e}"
    );
}
