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
        "bad.obj:4: error: face 1 of object \"default\": vertex index 4 is out of range (3 \
         vertices can be named there)"
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
        "error: --scale 0: give the factor every coordinate is multiplied by, a number above 0"
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

/// `solve` of the Cornell box as DXF (with its materials file) and as VRML writes the scene
/// file's per-element CSV (the surfaces are the scene file's bit for bit; VRML names have
/// `_` for spaces), and as glTF runs and says how it read the file.
#[test]
fn solve_reads_dxf_vrml_and_gltf_as_the_scene_file() {
    let dir = scratch_dir("import-dxf-vrml-gltf");
    let run = |scene: &str, out: &str| {
        let args = [
            "solve",
            scene,
            "-o",
            out,
            "--max-area",
            "20000",
            "--steps",
            "1",
            "--adapt-rounds",
            "0",
        ];
        radiosity(&args, &dir)
    };
    let from_scene = run(&example("cornell_box.scene"), "scene.csv");
    assert!(from_scene.status.success(), "{}", stderr(&from_scene));
    let scene_csv = std::fs::read_to_string(dir.join("scene.csv")).unwrap();
    let from_dxf = run(&data("cornell_box.dxf"), "dxf.csv");
    assert!(from_dxf.status.success(), "{}", stderr(&from_dxf));
    assert!(
        stderr(&from_dxf).contains("read as DXF; unit: millimetres (the DXF's $INSUNITS 4"),
        "{}",
        stderr(&from_dxf)
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("dxf.csv")).unwrap(),
        scene_csv
    );
    let from_vrml = run(&data("cornell_box.wrl"), "wrl.csv");
    assert!(from_vrml.status.success(), "{}", stderr(&from_vrml));
    assert!(stderr(&from_vrml).contains("read as VRML97; unit: metres (VRML97's unit)"));
    // The same numbers; VRML's names have `_` where the scene file's have spaces.
    assert_eq!(
        std::fs::read_to_string(dir.join("wrl.csv"))
            .unwrap()
            .replace(' ', "_"),
        scene_csv.replace(' ', "_")
    );
    let from_gltf = run(&data("cornell_box.gltf"), "gltf.csv");
    assert!(from_gltf.status.success(), "{}", stderr(&from_gltf));
    assert!(stderr(&from_gltf).contains("read as glTF; unit: metres (glTF's unit)"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A DXF without its materials file: the error names the file expected and the layers.
#[test]
fn dxf_without_materials_lists_its_layers() {
    let dir = scratch_dir("import-dxf-materials");
    std::fs::copy(data("cornell_box.dxf"), dir.join("box.dxf")).unwrap();
    let out = radiosity(&["check", "box.dxf"], &dir);
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(
        e.starts_with("box.materials.toml: error: the materials file of box.dxf is missing"),
        "{e}"
    );
    assert!(e.contains("\"Back wall\", \"Ceiling back\""), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
