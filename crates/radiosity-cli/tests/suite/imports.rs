//! Scenes in other formats, by extension, on the command line (#13).

use std::path::Path;

use crate::fixtures::{example, radiosity, scratch_dir, stderr};

fn data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(name)
        .display()
        .to_string()
}

/// `solve` of the Cornell box as OBJ writes the same per-element CSV as of the scene file
/// (the same surfaces, names and numbers), and says how it read the file and in what unit.
#[test]
fn solve_reads_obj_as_the_scene_file() {
    let dir = scratch_dir("import-obj");
    let coarse = ["--max-area", "20000", "--steps", "1", "--adapt-rounds", "0"];
    let mut args = vec!["solve", "", "-o", ""];
    args.extend(coarse);
    let run = |scene: &str, out: &str| {
        let mut a = args.clone();
        a[1] = scene;
        a[3] = out;
        radiosity(&a, &dir)
    };
    let obj = data("cornell_box.obj");
    let from_obj = run(&obj, "obj.csv");
    assert!(from_obj.status.success(), "{}", stderr(&from_obj));
    assert!(
        stderr(&from_obj)
            .contains("read as OBJ; unit: metres (OBJ states no unit; metres assumed)"),
        "{}",
        stderr(&from_obj)
    );
    let scene = example("cornell_box.scene");
    let from_scene = run(&scene, "scene.csv");
    assert!(from_scene.status.success(), "{}", stderr(&from_scene));
    let a = std::fs::read_to_string(dir.join("obj.csv")).unwrap();
    let b = std::fs::read_to_string(dir.join("scene.csv")).unwrap();
    assert_eq!(a, b);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_obj_error_names_file_and_line_once() {
    let dir = scratch_dir("import-bad");
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n").unwrap();
    let out = radiosity(&["check", "bad.obj"], &dir);
    assert!(!out.status.success());
    assert_eq!(
        stderr(&out).trim_end(),
        "bad.obj:4: error: face 1 of object \"default\": vertex index 4 is out of range (the \
         file has 3 vertices)"
    );
    let out = radiosity(&["check", "model.stl"], &dir);
    assert!(stderr(&out).starts_with(
        "model.stl: error: cannot tell the scene format from the extension \".stl\": expected \
         .scene, .obj, .gltf, .glb, .dxf or .wrl"
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scale_is_checked_and_needs_a_file() {
    let dir = scratch_dir("import-scale");
    let out = radiosity(&["check", &data("cornell_box.obj"), "--scale", "0"], &dir);
    assert!(!out.status.success());
    assert_eq!(
        stderr(&out).trim_end(),
        "error: the scale must be a positive finite number, found 0"
    );
    let out = radiosity(&["check", "--scale", "2"], &dir);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("--scale applies to a scene file"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Warnings about what was left out are printed, even with --quiet.
#[test]
fn import_warnings_are_printed_even_when_quiet() {
    let dir = scratch_dir("import-warn");
    std::fs::write(
        dir.join("w.obj"),
        "mtllib none.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 2\n",
    )
    .unwrap();
    let out = radiosity(&["check", "w.obj", "-q"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("w.obj:1: warning: cannot read the material file \"none.mtl\""),
        "{err}"
    );
    assert!(
        err.contains("w.obj: warning: dropped 1 degenerate face"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
