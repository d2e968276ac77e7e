//! The glTF reader: the Cornell box as glTF (embedded, external and binary buffers) against
//! the scene file, transforms, materials, primitive modes, and hostile files.

use std::path::PathBuf;

use base64::Engine as _;
use glam::{dvec3, DVec3};
use serde_json::{json, Value};

use super::*;
use crate::io::import::read_any_scene;
use crate::progress::NoProgress;
use crate::scene::Scene;
use crate::{pipeline, Overrides, Prepared, SolveRequest, Solver};

/// A glTF document under construction: one buffer, a view and an accessor per array.
#[derive(Default)]
pub(crate) struct Builder {
    pub bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn view(&mut self, bytes: &[u8], target: u32) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len(), "target": target
        }));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// A VEC3 float accessor (with the min and max glTF requires of positions).
    pub fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = p.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, 34962);
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for q in p {
            for k in 0..3 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5126, "count": p.len(), "type": "VEC3",
            "min": lo, "max": hi
        }));
        self.accessors.len() - 1
    }

    /// A SCALAR unsigned-int accessor.
    pub fn indices(&mut self, i: &[u32]) -> usize {
        let bytes: Vec<u8> = i.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, 34963);
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5125, "count": i.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    /// A VEC3 float accessor of vertex colours.
    pub fn colours_f32(&mut self, c: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = c.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, 34962);
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5126, "count": c.len(), "type": "VEC3"
        }));
        self.accessors.len() - 1
    }

    /// A VEC4 accessor of normalized unsigned-byte vertex colours (RGBA).
    pub fn colours_u8(&mut self, c: &[[u8; 4]]) -> usize {
        let bytes: Vec<u8> = c.iter().flatten().copied().collect();
        let view = self.view(&bytes, 34962);
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5121, "normalized": true, "count": c.len(),
            "type": "VEC4"
        }));
        self.accessors.len() - 1
    }

    /// A buffer view holding `bytes` (an image).
    pub fn raw_view(&mut self, bytes: &[u8]) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()
        }));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// The document: `rest` (meshes, nodes, materials, scenes, ...) with the asset, the
    /// buffer (`uri`: a data URI when `Some("")`, that file name when `Some(name)`, the
    /// GLB chunk when `None`), views and accessors.
    pub fn json(&self, mut rest: Value, uri: Option<&str>) -> Value {
        let mut buffer = json!({ "byteLength": self.bin.len() });
        match uri {
            Some("") => {
                buffer["uri"] = Value::String(format!(
                    "data:application/octet-stream;base64,{}",
                    base64::engine::general_purpose::STANDARD.encode(&self.bin)
                ))
            }
            Some(name) => buffer["uri"] = Value::String(name.to_string()),
            None => {}
        }
        rest["asset"] = json!({ "version": "2.0", "generator": "radiosity tests" });
        rest["buffers"] = json!([buffer]);
        rest["bufferViews"] = Value::Array(self.views.clone());
        rest["accessors"] = Value::Array(self.accessors.clone());
        rest
    }

    /// The binary glTF of `rest` with the buffer as its BIN chunk.
    pub fn glb(&self, rest: Value) -> Vec<u8> {
        let mut json = serde_json::to_vec(&self.json(rest, None)).unwrap();
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::new();
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }
}

/// The glTF of a scene: one node, mesh and material per surface (named after it), each
/// polygon as the fan of triangles from its first corner; emission as `emissiveFactor`
/// (scaled to at most 1) times `KHR_materials_emissive_strength`.
pub(crate) fn scene_to_gltf(scene: &Scene) -> (Builder, Value) {
    let mut b = Builder::default();
    let (mut meshes, mut nodes, mut materials) = (vec![], vec![], vec![]);
    for (i, s) in scene.surfaces.iter().enumerate() {
        let p: Vec<[f32; 3]> = s
            .vertices
            .iter()
            .map(|v| [v.x as f32, v.y as f32, v.z as f32])
            .collect();
        let fan: Vec<u32> = (1..s.vertices.len() as u32 - 1)
            .flat_map(|k| [0, k, k + 1])
            .collect();
        let pos = b.positions(&p);
        let ind = b.indices(&fan);
        meshes.push(json!({
            "name": s.name,
            "primitives": [{ "attributes": { "POSITION": pos }, "indices": ind, "material": i }]
        }));
        nodes.push(json!({ "name": s.name, "mesh": i }));
        let r = s.reflectance.0;
        let e = s.emission.0;
        let strength = e.iter().copied().fold(0.0, f64::max);
        let mut m = json!({
            "name": s.name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [r[0], r[1], r[2], 1.0], "metallicFactor": 0.0
            }
        });
        if strength > 0.0 {
            m["emissiveFactor"] = json!(e.map(|x| x / strength));
            m["extensions"] =
                json!({ "KHR_materials_emissive_strength": { "emissiveStrength": strength } });
        }
        materials.push(m);
    }
    let n = nodes.len();
    let rest = json!({
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{ "name": "Cornell box", "nodes": (0..n).collect::<Vec<_>>() }],
        "nodes": nodes, "meshes": meshes, "materials": materials
    });
    (b, rest)
}

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

/// The committed `tests/data/cornell_box.gltf`, as [`scene_to_gltf`] writes it.
fn cornell_gltf_text() -> String {
    let (b, rest) = scene_to_gltf(&cornell_scene());
    serde_json::to_string_pretty(&b.json(rest, Some(""))).unwrap() + "\n"
}

/// Rewrites `tests/data/cornell_box.gltf` (run with `--ignored` after changing the box).
#[test]
#[ignore]
fn write_cornell_box_gltf() {
    std::fs::write(
        repo_file("tests/data/cornell_box.gltf"),
        cornell_gltf_text(),
    )
    .unwrap();
}

#[test]
fn committed_cornell_box_gltf_is_the_scene_files_box() {
    let committed = std::fs::read_to_string(repo_file("tests/data/cornell_box.gltf")).unwrap();
    assert!(
        committed == cornell_gltf_text(),
        "tests/data/cornell_box.gltf is not what scene_to_gltf makes of \
         examples/cornell_box.scene; rewrite it with the ignored test write_cornell_box_gltf"
    );
}

/// The committed `tests/data/vertex_colours.gltf`: three lit squares with `COLOR_0`, the
/// colours chosen so that each face's mean is exact in binary.
///
/// * `Floor` (y = 0, facing up): white base colour (glTF's 1), float colours (0.25, 0.5,
///   0.75), (0.5, 0.5, 0.75), (0.75, 0.5, 0.75), (0.5, 0.5, 0.75) at its corners, shared by
///   its two triangles: reflectance their mean, (0.5, 0.5, 0.75);
/// * `Wall` (z = 0, facing +z): base 0.5, two triangles with vertices of their own, one
///   red and one blue (normalized bytes, RGBA): joined back into the quad, whose corners
///   on the diagonal are both colours (mean (0.5, 0, 0.5)), the others red and blue, so
///   the face's mean is (0.5, 0, 0.5) and its reflectance (0.25, 0, 0.25);
/// * `Lamp` (y = 1, facing down): base 1 and colours 1, so 1 and capped at 0.99 (counted
///   in a warning), emitting `emissiveFactor` 1 x strength 10.
fn vertex_colours_gltf_text() -> String {
    let mut b = Builder::default();
    let floor_pos = b.positions(&[
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ]);
    let floor_col = b.colours_f32(&[
        [0.25, 0.5, 0.75],
        [0.5, 0.5, 0.75],
        [0.75, 0.5, 0.75],
        [0.5, 0.5, 0.75],
    ]);
    let floor_ind = b.indices(&[0, 1, 2, 0, 2, 3]);
    let (p0, p1, p2, p3) = (
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    );
    let wall_pos = b.positions(&[p0, p1, p2, p0, p2, p3]);
    let (red, blue) = ([255, 0, 0, 255], [0, 0, 255, 255]);
    let wall_col = b.colours_u8(&[red, red, red, blue, blue, blue]);
    let wall_ind = b.indices(&[0, 1, 2, 3, 4, 5]);
    let lamp_pos = b.positions(&[
        [0.25, 1.0, 0.25],
        [0.75, 1.0, 0.25],
        [0.75, 1.0, 0.75],
        [0.25, 1.0, 0.75],
    ]);
    let lamp_col = b.colours_f32(&[[1.0; 3]; 4]);
    let lamp_ind = b.indices(&[0, 1, 2, 0, 2, 3]);
    let prim = |pos: usize, col: usize, ind: usize, material: usize| {
        json!({ "attributes": { "POSITION": pos, "COLOR_0": col }, "indices": ind,
                "material": material })
    };
    let rest = json!({
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{ "name": "vertex colours", "nodes": [0, 1, 2] }],
        "nodes": [
            { "name": "Floor", "mesh": 0 },
            { "name": "Wall", "mesh": 1 },
            { "name": "Lamp", "mesh": 2 },
        ],
        "meshes": [
            { "name": "Floor", "primitives": [prim(floor_pos, floor_col, floor_ind, 0)] },
            { "name": "Wall", "primitives": [prim(wall_pos, wall_col, wall_ind, 1)] },
            { "name": "Lamp", "primitives": [prim(lamp_pos, lamp_col, lamp_ind, 2)] },
        ],
        "materials": [
            { "name": "white", "pbrMetallicRoughness": { "metallicFactor": 0.0 } },
            { "name": "grey", "pbrMetallicRoughness": {
                "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0 } },
            { "name": "lamp", "pbrMetallicRoughness": { "metallicFactor": 0.0 },
              "emissiveFactor": [1.0, 1.0, 1.0],
              "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 10.0 } } },
        ],
    });
    serde_json::to_string_pretty(&b.json(rest, Some(""))).unwrap() + "\n"
}

/// Rewrites `tests/data/vertex_colours.gltf` (run with `--ignored`).
#[test]
#[ignore]
fn write_vertex_colours_gltf() {
    std::fs::write(
        repo_file("tests/data/vertex_colours.gltf"),
        vertex_colours_gltf_text(),
    )
    .unwrap();
}

/// Issue #13: a foreign file's `COLOR_0` on lit materials multiplies the base colour, one
/// mean per face (tests/data/vertex_colours.gltf, described at
/// [`vertex_colours_gltf_text`]).
#[test]
fn vertex_colours_multiply_the_base_colour_face_by_face() {
    let path = repo_file("tests/data/vertex_colours.gltf");
    let committed = std::fs::read_to_string(&path).unwrap();
    assert!(
        committed == vertex_colours_gltf_text(),
        "tests/data/vertex_colours.gltf is not what vertex_colours_gltf_text makes; rewrite \
         it with the ignored test write_vertex_colours_gltf"
    );
    let got = read_any_scene(&path, &ImportOptions::default()).unwrap();
    let names: Vec<&str> = got
        .file
        .scene
        .surfaces
        .iter()
        .map(|s| s.name.as_str())
        .collect();
    // The wall's two triangles joined back into one face, whatever their colours.
    assert_eq!(names, ["Floor", "Wall", "Lamp"]);
    let surfaces = &got.file.scene.surfaces;
    // The colours and their means are exact in binary (quarters; bytes 0 and 255 are 0
    // and 1 exactly), so the products are exact.
    assert_eq!(surfaces[0].reflectance, Rgb([0.5, 0.5, 0.75]));
    assert_eq!(surfaces[1].reflectance, Rgb([0.25, 0.0, 0.25]));
    assert_eq!(surfaces[2].reflectance, Rgb([MAX_REFLECTANCE; 3]));
    assert_eq!(surfaces[2].emission, Rgb([10.0; 3]));
    assert_eq!(surfaces[0].emission, Rgb([0.0; 3]));
    // One warning: the lamp's face capped. The white base of the floor is no warning:
    // its colours bring it below 1.
    assert_eq!(got.warnings.len(), 1, "{:?}", got.warnings);
    assert!(
        got.warnings[0]
            .message
            .starts_with("1 face whose base colour times the mean of its COLOR_0 is 1 or more"),
        "{}",
        got.warnings[0]
    );
    // Without COLOR_0 the same file reads as before: the base colours, white capped with
    // the material's warning.
    let mut doc: Value = serde_json::from_str(&committed).unwrap();
    for m in doc["meshes"].as_array_mut().unwrap() {
        m["primitives"][0]["attributes"]
            .as_object_mut()
            .unwrap()
            .remove("COLOR_0");
    }
    let plain = read_doc(&doc).unwrap();
    let s = &plain.file.scene.surfaces;
    assert_eq!(s.len(), 3);
    assert_eq!(s[0].reflectance, Rgb([MAX_REFLECTANCE; 3]));
    assert_eq!(s[1].reflectance, Rgb([0.5; 3]));
    assert_eq!(plain.warnings.len(), 2, "{:?}", plain.warnings);
    assert!(plain.warnings[0].message.contains("material \"white\""));
}

/// The surfaces of `got` are those of `want`: same names, order and colours, corners
/// within single precision's rounding. The corners went through `f32`: 548.8 becomes
/// 548.79998779..., 1.2e-5 off, and flattening moves them by as little again; 1e-4 mm
/// is 2e-7 of the box.
fn assert_same_surfaces(got: &Scene, want: &Scene) {
    assert_eq!(got.surfaces.len(), want.surfaces.len());
    for (g, w) in got.surfaces.iter().zip(&want.surfaces) {
        assert_eq!(g.name, w.name);
        assert_eq!(g.vertices.len(), w.vertices.len(), "{}", w.name);
        for (a, b) in g.vertices.iter().zip(&w.vertices) {
            assert!(
                (*a - *b).abs().max_element() < 1e-4,
                "{}: {a} vs {b}",
                w.name
            );
        }
        // Colours went through f32 too (and emission through a quotient and a product
        // of f32s): relative 1e-6 is eight times f32's rounding.
        for k in 0..3 {
            let (r, s) = (g.reflectance.0[k], w.reflectance.0[k]);
            assert!(
                (r - s).abs() <= 1e-6 * s.abs().max(1e-3),
                "{}: {r} vs {s}",
                w.name
            );
            let (e, f) = (g.emission.0[k], w.emission.0[k]);
            assert!(
                (e - f).abs() <= 1e-6 * f.abs().max(1e-3),
                "{}: {e} vs {f}",
                w.name
            );
        }
    }
}

/// The element radiosities of a coarse solve.
fn solve(scene: Scene) -> Vec<[f64; 3]> {
    let coarse = Overrides {
        max_patch_area: Some(20_000.0),
        integral_steps: Some(1),
    };
    let settings = coarse.apply(crate::scene::cornell_box().settings);
    let prepared = Prepared::new(scene, settings, &NoProgress).unwrap();
    let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
    let solution = pipeline::solve(
        &prepared,
        &request,
        &mut crate::solve::keep_going,
        &NoProgress,
    )
    .unwrap();
    solution.element_rgb().to_vec()
}

#[test]
fn cornell_box_gltf_solves_as_the_scene_file() {
    let imported = read_any_scene(
        &repo_file("tests/data/cornell_box.gltf"),
        &ImportOptions::default(),
    )
    .unwrap();
    assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
    assert_eq!(imported.format, Format::Gltf);
    assert_eq!(imported.unit, "metres (glTF's unit)");
    let want = cornell_scene();
    assert_same_surfaces(&imported.file.scene, &want);
    let a = solve(imported.file.scene);
    let b = solve(want);
    assert_eq!(a.len(), b.len());
    let top = b.iter().flatten().copied().fold(0.0, f64::max);
    // The geometry differs by f32 rounding (2e-8 of the box); form factors and so the
    // radiosities move by about as much relatively. 1e-5 of the brightest element is a
    // thousand times that and far below anything visible.
    for (x, y) in a.iter().zip(&b) {
        for k in 0..3 {
            assert!((x[k] - y[k]).abs() <= 1e-5 * top, "{x:?} vs {y:?}");
        }
    }
}

#[test]
fn glb_and_external_buffer_read_as_the_embedded_gltf() {
    let want = cornell_scene();
    let (b, rest) = scene_to_gltf(&want);
    let glb = parse(
        "box.glb",
        &b.glb(rest.clone()),
        None,
        &ImportOptions::default(),
    )
    .unwrap();
    assert_eq!(glb.format, Format::Glb);
    assert_same_surfaces(&glb.file.scene, &want);

    let dir = tempfile::tempdir().unwrap();
    let gltf_path = dir.path().join("box.gltf");
    std::fs::write(
        &gltf_path,
        serde_json::to_vec(&b.json(rest, Some("box%20data.bin"))).unwrap(),
    )
    .unwrap();
    std::fs::write(dir.path().join("box data.bin"), &b.bin).unwrap();
    let external = read_any_scene(&gltf_path, &ImportOptions::default()).unwrap();
    assert_same_surfaces(&external.file.scene, &want);
    // The scale multiplies every coordinate and says so in the unit.
    let scaled = read_any_scene(
        &gltf_path,
        &ImportOptions {
            scale: 0.001,
            settings: None,
        },
    )
    .unwrap();
    assert_eq!(
        scaled.unit,
        "metres = the file's numbers x 0.001; unscaled, metres (glTF's unit)"
    );
    let (lo, hi) = scaled.file.scene.bounds();
    assert!((hi.x - lo.x - 0.556).abs() < 1e-6, "{lo} {hi}");

    // Without the folder the external buffer cannot be had: an error, not a panic.
    let text = std::fs::read(&gltf_path).unwrap();
    let err = parse("box.gltf", &text, None, &ImportOptions::default()).unwrap_err();
    assert!(err.to_string().contains("box%20data.bin"), "{err}");
}

/// One unit square in the xy plane (normal +z) as two triangles, used by `nodes`.
fn square_doc(nodes: Value, materials: Value, mode: Option<u32>) -> Value {
    let mut b = Builder::default();
    let pos = b.positions(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]);
    let mut prim = json!({ "attributes": { "POSITION": pos } });
    match mode {
        // Strip 0 1 3 2: triangles 0 1 3 and (odd, turned) 1 2 3.
        Some(5) => {
            prim["indices"] = json!(b.indices(&[0, 1, 3, 2]));
            prim["mode"] = json!(5);
        }
        // Fan about 0: triangles 0 1 2 and 0 2 3, as glTF orders them (1 2 0, 2 3 0).
        Some(6) => {
            prim["indices"] = json!(b.indices(&[0, 1, 2, 3]));
            prim["mode"] = json!(6);
        }
        Some(m) => {
            prim["indices"] = json!(b.indices(&[0, 1, 2, 3]));
            prim["mode"] = json!(m);
        }
        None => prim["indices"] = json!(b.indices(&[0, 1, 2, 0, 2, 3])),
    }
    if materials.as_array().is_some_and(|m| !m.is_empty()) {
        prim["material"] = json!(0);
    }
    let n = nodes.as_array().unwrap().len();
    let roots: Vec<usize> = (0..n)
        .filter(|i| {
            !nodes.as_array().unwrap().iter().any(|m| {
                m["children"]
                    .as_array()
                    .is_some_and(|c| c.contains(&json!(i)))
            })
        })
        .collect();
    let mut rest = json!({
        "scenes": [{ "nodes": roots }], "nodes": nodes,
        "meshes": [{ "primitives": [prim] }],
        "extensionsUsed": ["KHR_materials_emissive_strength"]
    });
    if materials.as_array().is_some_and(|m| !m.is_empty()) {
        rest["materials"] = materials;
    }
    b.json(rest, Some(""))
}

fn read_doc(doc: &Value) -> Result<Imported, ImportError> {
    parse(
        "t.gltf",
        &serde_json::to_vec(doc).unwrap(),
        None,
        &ImportOptions::default(),
    )
}

fn grey() -> Value {
    json!([{ "name": "grey", "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.5, 0.5, 1] } }])
}

#[test]
fn a_gltf_1_file_is_refused_by_its_version() {
    // QA pass 15 of issue #16: "asset.version": "1.0" was read as 2.0 without a word.
    let mut doc = square_doc(json!([{ "mesh": 0 }]), grey(), None);
    doc["asset"]["version"] = json!("1.0");
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(
        e.contains("asset.version is \"1.0\": this reader takes glTF 2.0"),
        "{e}"
    );
    doc["asset"]["version"] = json!("2.0");
    assert!(read_doc(&doc).is_ok());
    // A glTF 1.0 file as such files are: collections keyed by id (review: the typed reader
    // refused these as "invalid type: map" before the version was looked at).
    let v1 = json!({
        "asset": { "version": "1.0" },
        "meshes": { "mesh_0": { "primitives": [] } },
        "accessors": {}, "buffers": {}, "bufferViews": {}
    });
    let e = read_doc(&v1).unwrap_err().to_string();
    assert!(
        e.contains("asset.version is \"1.0\": this reader takes glTF 2.0"),
        "{e}"
    );
}

#[test]
fn node_transforms_compose_parent_first() {
    // Parent: translate (10, 0, 0). Child: rotate 90 degrees about z, scale 2, translate
    // (0, 1, 0). The square's corner (1, 0, 0) goes: scale -> (2, 0, 0), rotate -> (0, 2,
    // 0), child translation -> (0, 3, 0), parent -> (10, 3, 0).
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let nodes = json!([
        { "name": "parent", "translation": [10, 0, 0], "children": [1] },
        { "name": "child", "mesh": 0, "translation": [0, 1, 0], "rotation": [0, 0, s, s],
          "scale": [2, 2, 2] }
    ]);
    let got = read_doc(&square_doc(nodes, grey(), None)).unwrap();
    let s = &got.file.scene.surfaces;
    assert_eq!(s.len(), 1, "the two triangles join into the square");
    assert_eq!(s[0].name, "child");
    let want = [
        dvec3(10.0, 1.0, 0.0),
        dvec3(10.0, 3.0, 0.0),
        dvec3(8.0, 3.0, 0.0),
        dvec3(8.0, 1.0, 0.0),
    ];
    for (a, b) in s[0].vertices.iter().zip(want) {
        // f32 rotation quaternion (0.70710677): 1e-6 of the coordinates.
        assert!((*a - b).length() < 1e-5, "{a} vs {b}");
    }
    assert_eq!(s[0].reflectance, Rgb([0.5; 3]));
}

#[test]
fn a_rotation_that_is_not_a_unit_quaternion_is_refused() {
    // QA pass 18 of #16: [0, 0, 0, 0] was read as no rotation, silently. glTF requires a
    // unit quaternion; [0, 0, 0.5, 0.5] (length 0.71) is as wrong.
    for rotation in [json!([0, 0, 0, 0]), json!([0, 0, 0.5, 0.5])] {
        let nodes = json!([{ "name": "turned", "mesh": 0, "rotation": rotation }]);
        let e = read_doc(&square_doc(nodes, grey(), None))
            .unwrap_err()
            .to_string();
        assert!(e.contains("is not a unit quaternion"), "{e}");
        assert!(e.contains("turned"), "{e}");
    }
}

#[test]
fn a_mirroring_node_keeps_the_front_as_the_author_saw_it() {
    // A column-major matrix mirroring x. glTF says a negative determinant turns the
    // winding, so the square still faces +z.
    let nodes = json!([{ "mesh": 0,
        "matrix": [-1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1] }]);
    let got = read_doc(&square_doc(nodes, grey(), None)).unwrap();
    let v = &got.file.scene.surfaces[0].vertices;
    let normal = crate::geometry::polygon_normal(v).unwrap();
    assert!((normal - DVec3::Z).length() < 1e-12, "{normal}");
    assert!(v.iter().all(|p| p.x <= 0.0));
    assert_eq!(got.file.scene.surfaces[0].name, "node 0");
}

#[test]
fn strips_and_fans_become_triangles_with_a_warning() {
    for mode in [5, 6] {
        let nodes = json!([{ "mesh": 0 }]);
        let got = read_doc(&square_doc(nodes, grey(), Some(mode))).unwrap();
        let s = &got.file.scene.surfaces;
        assert_eq!(s.len(), 1, "mode {mode}: {s:?}");
        assert!((crate::geometry::polygon_area(&s[0].vertices) - 1.0).abs() < 1e-12);
        let n = crate::geometry::polygon_normal(&s[0].vertices).unwrap();
        assert!((n - DVec3::Z).length() < 1e-12, "mode {mode}: {n}");
        assert!(
            got.warnings
                .iter()
                .any(|w| w.message == "1 triangle strip or fan primitive converted to triangles"),
            "{:?}",
            got.warnings
        );
    }
}

#[test]
fn lines_are_left_out_with_a_warning_and_leave_no_surface() {
    let nodes = json!([{ "mesh": 0 }]);
    let err = read_doc(&square_doc(nodes, grey(), Some(1))).unwrap_err();
    assert_eq!(
        err.to_string(),
        "t.gltf: error: no usable faces: the file has 0 faces"
    );
}

#[test]
fn emissive_strength_multiplies_the_emissive_factor() {
    let materials = json!([{
        "pbrMetallicRoughness": { "baseColorFactor": [0.2, 0.3, 0.4, 1] },
        "emissiveFactor": [1.0, 0.5, 0.25],
        "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 4.0 } }
    }]);
    let got = read_doc(&square_doc(json!([{ "mesh": 0 }]), materials, None)).unwrap();
    let s = &got.file.scene.surfaces[0];
    assert_eq!(s.emission, Rgb([4.0, 2.0, 1.0]));
    // 0.2 as f32, widened: compare to that.
    assert_eq!(s.reflectance.0[0], f64::from(0.2f32));
}

#[test]
fn white_and_missing_materials_are_taken_below_one_with_a_warning() {
    let got = read_doc(&square_doc(json!([{ "mesh": 0 }]), json!([]), None)).unwrap();
    assert_eq!(
        got.file.scene.surfaces[0].reflectance,
        Rgb([MAX_REFLECTANCE; 3])
    );
    assert!(
        got.warnings[0].message.contains("default, white"),
        "{:?}",
        got.warnings
    );
}

#[test]
fn base_colour_texture_mean_multiplies_the_factor() {
    // A 2 x 1 PNG: pure red and pure blue, sRGB 255 = linear 1. Mean (0.5, 0, 0.5), times
    // the factor 0.8: (0.4, 0, 0.4).
    let mut png = Vec::new();
    image::RgbImage::from_raw(2, 1, vec![255, 0, 0, 0, 0, 255])
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let mut doc = square_doc(
        json!([{ "mesh": 0 }]),
        json!([{ "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.8, 0.8, 1], "baseColorTexture": { "index": 0 } } }]),
        None,
    );
    doc["images"] = json!([{ "uri": format!("data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&png)) }]);
    doc["textures"] = json!([{ "source": 0 }]);
    let got = read_doc(&doc).unwrap();
    let r = got.file.scene.surfaces[0].reflectance.0;
    let f = f64::from(0.8f32);
    assert_eq!(r, [0.5 * f, 0.0, 0.5 * f]);
    assert!(got.warnings.is_empty(), "{:?}", got.warnings);

    // The same image in a buffer view (as a .glb holds it), with and without its MIME
    // type (which glTF requires; the format is told from the bytes).
    let mut b = Builder::default();
    let pos = b.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]);
    let view = b.raw_view(&png);
    for image in [
        json!({ "bufferView": view, "mimeType": "image/png" }),
        json!({ "bufferView": view }),
    ] {
        let doc = b.json(
            json!({ "scenes": [{ "nodes": [0] }], "nodes": [{ "mesh": 0 }],
                    "meshes": [{ "primitives": [{ "attributes": { "POSITION": pos }, "material": 0 }] }],
                    "materials": [{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }],
                    "images": [image], "textures": [{ "source": 0 }] }),
            Some(""),
        );
        let got = read_doc(&doc).unwrap();
        assert_eq!(got.file.scene.surfaces[0].reflectance, Rgb([0.5, 0.0, 0.5]));
    }

    // An image that is no image: the factor alone, with a warning.
    doc["images"] = json!([{ "uri": "data:image/png;base64,AAAA" }]);
    let got = read_doc(&doc).unwrap();
    assert_eq!(got.file.scene.surfaces[0].reflectance, Rgb([f; 3]));
    assert!(
        got.warnings[0].message.contains("texture is left out"),
        "{:?}",
        got.warnings
    );
    // An image with neither a URI nor a view (the gltf crate would panic on it).
    doc["images"] = json!([{ "name": "nothing" }]);
    let got = read_doc(&doc).unwrap();
    assert!(
        got.warnings[0].message.contains("neither a uri"),
        "{:?}",
        got.warnings
    );
}

// ---- Bad and hostile files: an error naming the file and the element, never a panic.

fn error_of(bytes: &[u8]) -> String {
    parse("bad.gltf", bytes, None, &ImportOptions::default())
        .unwrap_err()
        .to_string()
}

#[test]
fn truncated_glb_header_is_refused() {
    let (b, rest) = scene_to_gltf(&cornell_scene());
    let glb = b.glb(rest);
    let e = error_of(&glb[..10]);
    assert!(
        e.starts_with("bad.gltf: error: binary glTF truncated: 10 bytes"),
        "{e}"
    );
    // A length field below the header's own size (the gltf crate underflows on it).
    let mut short = glb.clone();
    short[8..12].copy_from_slice(&4u32.to_le_bytes());
    let e = error_of(&short);
    assert!(e.contains("header gives the length 4"), "{e}");
    // Cut in the middle of the binary chunk.
    let e = error_of(&glb[..glb.len() / 2]);
    assert!(e.contains("header gives the length"), "{e}");
}

#[test]
fn truncated_json_is_refused_with_its_position() {
    let text = cornell_gltf_text();
    let e = error_of(&text.as_bytes()[..200]);
    assert!(
        e.starts_with("bad.gltf: error: not a valid glTF 2.0 file: "),
        "{e}"
    );
}

#[test]
fn index_out_of_range_is_refused_naming_the_primitive() {
    let mut b = Builder::default();
    let pos = b.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]);
    let ind = b.indices(&[0, 1, 7]);
    let doc = b.json(
        json!({ "scenes": [{ "nodes": [0] }], "nodes": [{ "name": "n", "mesh": 0 }],
                "meshes": [{ "primitives": [{ "attributes": { "POSITION": pos }, "indices": ind }] }] }),
        Some(""),
    );
    assert_eq!(
        read_doc(&doc).unwrap_err().to_string(),
        "t.gltf: error: node 0 (\"n\") primitive 0, index 2: vertex index 7 is out of range \
         (3 vertices can be named there)"
    );
}

#[test]
fn huge_counts_are_refused_before_allocating() {
    let mut b = Builder::default();
    let pos = b.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]);
    let mut doc = b.json(
        json!({ "scenes": [{ "nodes": [0] }], "nodes": [{ "mesh": 0 }],
                "meshes": [{ "primitives": [{ "attributes": { "POSITION": pos } }] }] }),
        Some(""),
    );
    // A count the plan refuses outright (1.3e9 triangles) ...
    doc["accessors"][0]["count"] = json!(4_000_000_000u64);
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(e.contains("would have 1333333333 triangles"), "{e}");
    // ... and one it allows that the buffer cannot hold (36 bytes for 1.8 million).
    doc["accessors"][0]["count"] = json!(1_800_000u64);
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(
        e.starts_with("t.gltf: error: accessor 0 (POSITION) says 1800000 items, more than"),
        "{e}"
    );
    // A view past its buffer's end.
    doc["accessors"][0]["count"] = json!(3);
    doc["bufferViews"][0]["byteLength"] = json!(1u64 << 40);
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(
        e.contains("buffer view 0 runs from byte 0 for 1099511627776 bytes"),
        "{e}"
    );
    // A buffer shorter than its byteLength.
    doc["buffers"][0]["byteLength"] = json!(1u64 << 40);
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(
        e.contains("buffer 0 should hold 1099511627776 bytes"),
        "{e}"
    );
}

#[test]
fn nan_positions_are_refused_naming_the_vertex() {
    let mut b = Builder::default();
    let pos = b.positions(&[[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [1.0, 1.0, 0.0]]);
    let mut doc = b.json(
        json!({ "scenes": [{ "nodes": [0] }], "nodes": [{ "mesh": 0 }],
                "meshes": [{ "primitives": [{ "attributes": { "POSITION": pos } }] }] }),
        Some(""),
    );
    // serde_json writes the NaN bound as null; the bounds are not what is tested.
    doc["accessors"][0]["min"] = json!([0, 0, 0]);
    doc["accessors"][0]["max"] = json!([1, 1, 0]);
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(
        e.starts_with("t.gltf: error: node 0 primitive 0, POSITION 1 (["),
        "{e}"
    );
    assert!(e.ends_with("is not a finite number"), "{e}");
}

#[test]
fn node_cycles_and_shared_children_are_refused() {
    let cycle = json!([{ "mesh": 0, "children": [1] }, { "mesh": 0, "children": [0] }]);
    let mut doc = square_doc(cycle, grey(), None);
    doc["scenes"] = json!([{ "nodes": [0] }]);
    let e = read_doc(&doc).unwrap_err().to_string();
    // The gltf crate's validation or the walk: either names the problem.
    assert!(e.starts_with("t.gltf: error: "), "{e}");
    assert!(e.contains("node") || e.contains("cycle"), "{e}");
    // A node reached twice (two parents).
    let shared = json!([{ "children": [2] }, { "children": [2] }, { "name": "x", "mesh": 0 }]);
    let mut doc = square_doc(shared, grey(), None);
    doc["scenes"] = json!([{ "nodes": [0, 1] }]);
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(e.contains("node 2 (\"x\") is reached twice"), "{e}");
    // No scene, every node a child: a cycle with no root.
    let mut doc = square_doc(
        json!([{ "mesh": 0, "children": [1] }, { "children": [0] }]),
        grey(),
        None,
    );
    doc.as_object_mut().unwrap().remove("scenes");
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(e.contains("cycle"), "{e}");
}

#[test]
fn bad_base64_and_wrong_types_are_refused() {
    let mut doc = square_doc(json!([{ "mesh": 0 }]), grey(), None);
    doc["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@@");
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(
        e.contains("buffer 0: its data URI is not valid base64"),
        "{e}"
    );
    let mut doc = square_doc(json!([{ "mesh": 0 }]), grey(), None);
    doc["accessors"][0]["componentType"] = json!(5123);
    let e = read_doc(&doc).unwrap_err().to_string();
    assert!(
        e.contains("POSITION (accessor 0) must be VEC3 of 32-bit floats"),
        "{e}"
    );
}

#[test]
fn a_mesh_placed_by_too_many_nodes_is_refused_before_it_is_read() {
    // 1000 triangles (no indices: 3000 positions), placed by 2001 nodes: 2,001,000
    // triangles, over the 2,000,000 allowed, from a 36 kB buffer.
    let mut b = Builder::default();
    let p: Vec<[f32; 3]> = (0..3000).map(|k| [k as f32, (k % 3) as f32, 0.0]).collect();
    let pos = b.positions(&p);
    let nodes: Vec<Value> = (0..2001).map(|_| json!({ "mesh": 0 })).collect();
    let doc = b.json(
        json!({ "scenes": [{ "nodes": (0..2001).collect::<Vec<_>>() }], "nodes": nodes,
                "meshes": [{ "primitives": [{ "attributes": { "POSITION": pos } }] }] }),
        Some(""),
    );
    assert_eq!(
        read_doc(&doc).unwrap_err().to_string(),
        format!(
            "t.gltf: error: the scene would have 2001000 triangles once every node's mesh is \
             placed, more than the {MAX_TRIANGLES} this reader takes; split it or simplify it"
        )
    );
}

#[test]
fn a_position_accessor_the_file_lacks_is_refused_not_a_panic() {
    // The gltf crate's validation indexes the accessors with it unchecked: the glTF fuzz
    // target's first crash (corpus/gltf/position_accessor_missing.gltf).
    let mut doc = square_doc(json!([{ "mesh": 0 }]), grey(), None);
    doc.as_object_mut().unwrap().remove("accessors");
    let e = read_doc(&doc).unwrap_err().to_string();
    assert_eq!(
        e,
        "t.gltf: error: mesh 0 primitive 0: POSITION names accessor 0, but the file has 0 \
         accessors"
    );
}

/// The Cornell box solved coarsely and exported as `radiosity export` bakes it (vertex
/// radiosity, exposure `scale` so that nothing clamps), as a `.glb` and a `.gltf`.
struct Exported {
    /// The scene as baked (prepared: measured walls flattened).
    scene: Scene,
    /// Area-weighted mean radiosity per surface.
    surface_b: Vec<[f64; 3]>,
    /// The area of each surface's elements (the floor's under the boxes is not meshed).
    surface_area: Vec<f64>,
    /// Mean of the exported `COLOR_0` over each surface's vertices.
    surface_colour: Vec<[f64; 3]>,
    scale: f64,
    glb: PathBuf,
    gltf: PathBuf,
}

fn coarse_settings() -> crate::MeshSettings {
    Overrides {
        max_patch_area: Some(20_000.0),
        integral_steps: Some(1),
    }
    .apply(crate::scene::cornell_box().settings)
}

/// Solves `scene` coarsely; the area-weighted mean radiosity of each group of surfaces
/// (`groups[k]` the surfaces of group k).
fn surface_means(scene: Scene, groups: &[Vec<usize>]) -> Vec<[f64; 3]> {
    let prepared = Prepared::new(scene, coarse_settings(), &NoProgress).unwrap();
    let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
    let solution = pipeline::solve(
        &prepared,
        &request,
        &mut crate::solve::keep_going,
        &NoProgress,
    )
    .unwrap();
    let b = solution.element_rgb();
    let mesh = &solution.mesh;
    groups
        .iter()
        .map(|group| {
            let (mut sum, mut area) = ([0.0; 3], 0.0);
            for &s in group {
                for e in mesh.surface_elements[s].clone() {
                    let a = mesh.elements[e as usize].area;
                    area += a;
                    for k in 0..3 {
                        sum[k] += a * b[e as usize][k];
                    }
                }
            }
            sum.map(|x| x / area)
        })
        .collect()
}

/// [`Exported`] into `dir`.
fn export_cornell_box(dir: &std::path::Path) -> Exported {
    use crate::io::export::gltf::{write_glb, write_gltf, Bake};
    let scene = cornell_scene();
    let prepared = Prepared::new(scene.clone(), coarse_settings(), &NoProgress).unwrap();
    let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
    let solution = pipeline::solve(
        &prepared,
        &request,
        &mut crate::solve::keep_going,
        &NoProgress,
    )
    .unwrap();
    let mesh = &solution.mesh;
    let vertex_b = crate::shade::vertex_radiosity(mesh, solution.element_rgb());
    let top = vertex_b.iter().flatten().copied().fold(0.0, f64::max);
    // Below 1 everywhere: COLOR_0 is then s B unclamped.
    let scale = 0.5 / top;
    let camera = crate::render::Camera {
        eye: dvec3(278.0, 273.0, -800.0),
        look_at: dvec3(278.0, 273.0, 0.0),
        up: DVec3::Y,
        fov_y_degrees: 40.0,
        width: 64,
        height: 64,
    };
    let bake = Bake {
        scene: &prepared.scene,
        mesh,
        vertex_b: &vertex_b,
        exposure_scale: scale,
        exposure: "fixed",
        camera: &camera,
        settings: coarse_settings(),
    };
    let glb = dir.join("box.glb");
    let gltf = dir.join("box.gltf");
    write_glb(&glb, &bake).unwrap();
    write_gltf(&gltf, &bake).unwrap();
    // The scene as baked: the prepared one (the measured walls flattened onto a plane).
    let scene = prepared.scene.clone();
    let groups: Vec<Vec<usize>> = (0..scene.surfaces.len()).map(|s| vec![s]).collect();
    let surface_b = surface_means(scene.clone(), &groups);
    // The exported colours: the vertices the surface's display triangles use, each once,
    // exposed and rounded to f32 as the file holds them.
    let display = mesh.display();
    let surface_colour = mesh
        .surface_elements
        .iter()
        .map(|elements| {
            let mut used = std::collections::BTreeSet::new();
            for e in elements.clone() {
                for t in display.triangles(e as usize) {
                    used.extend(t.vertices.iter().copied());
                }
            }
            let mut sum = [0.0; 3];
            for &v in &used {
                for k in 0..3 {
                    sum[k] += f64::from((scale * vertex_b[v as usize][k]) as f32);
                }
            }
            sum.map(|x| x / used.len() as f64)
        })
        .collect();
    let surface_area = mesh
        .surface_elements
        .iter()
        .map(|r| r.clone().map(|e| mesh.elements[e as usize].area).sum())
        .collect();
    Exported {
        scene,
        surface_b,
        surface_area,
        surface_colour,
        scale,
        glb,
        gltf,
    }
}

/// The imported surfaces that came from each original surface: named after it (`name`,
/// or `name.k` where the export's triangles joined into several polygons).
fn groups_by_name(imported: &Scene, original: &Scene) -> Vec<Vec<usize>> {
    original
        .surfaces
        .iter()
        .map(|o| {
            let prefix = format!("{}.", o.name);
            let group: Vec<usize> = imported
                .surfaces
                .iter()
                .enumerate()
                .filter(|(_, s)| s.name == o.name || s.name.starts_with(&prefix))
                .map(|(i, _)| i)
                .collect();
            assert!(!group.is_empty(), "nothing imported for {}", o.name);
            group
        })
        .collect()
}

/// Removes what a radiosity export writes to rebuild the scene (each mesh's
/// `extras.radiosity.polygon`, the asset's `meshSettings`) from the `.gltf` at `path`, as a
/// tool that keeps only the geometry would.
fn strip_polygons(path: &std::path::Path) {
    let mut doc: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    for m in doc["meshes"].as_array_mut().unwrap() {
        m.as_object_mut().unwrap().remove("extras");
    }
    doc["asset"]["extras"]["radiosity"]
        .as_object_mut()
        .unwrap()
        .remove("meshSettings");
    std::fs::write(path, serde_json::to_vec(&doc).unwrap()).unwrap();
}

/// Issue #13: an exported file read back is the scene exported, not its mesh: the same
/// surfaces (names, corners to the last bit, colours), the same meshing settings, so the
/// same elements, and the same light. (Before, the triangles joined back into 113 polygons
/// at these coarse settings, and `radiosity export` of the default box then `check` gave
/// 535 surfaces and 18,608 elements for 20 and 2,484.)
#[test]
fn exported_glb_reads_back_as_the_scene_it_was_baked_from() {
    let dir = tempfile::tempdir().unwrap();
    let ex = export_cornell_box(dir.path());
    let want_prepared = Prepared::new(ex.scene.clone(), coarse_settings(), &NoProgress).unwrap();
    for path in [&ex.glb, &ex.gltf] {
        let imported = read_any_scene(path, &ImportOptions::default()).unwrap();
        assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
        let got = &imported.file.scene;
        assert_eq!(got.surfaces.len(), ex.scene.surfaces.len());
        for (g, w) in got.surfaces.iter().zip(&ex.scene.surfaces) {
            // JSON keeps an f64 exactly (serde_json writes the shortest form that reads
            // back to the same bits), so the corners and colours are the scene's own.
            assert_eq!(g.name, w.name);
            assert_eq!(g.vertices, w.vertices, "{}", w.name);
            assert_eq!(g.reflectance, w.reflectance, "{}", w.name);
            assert_eq!(g.emission, w.emission, "{}", w.name);
        }
        assert_eq!(imported.file.settings, coarse_settings());
        let prepared = Prepared::new(got.clone(), imported.file.settings, &NoProgress).unwrap();
        assert_eq!(prepared.mesh.len(), want_prepared.mesh.len());
        assert_eq!(got.total_area(), ex.scene.total_area());
        let groups: Vec<Vec<usize>> = (0..got.surfaces.len()).map(|s| vec![s]).collect();
        // The same scene and settings: the same solve, to rounding.
        let again = surface_means(got.clone(), &groups);
        for ((a, b), s) in again.iter().zip(&ex.surface_b).zip(&ex.scene.surfaces) {
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-12 * b[k].abs().max(1e-12),
                    "{}: {a:?} vs {b:?}",
                    s.name
                );
            }
        }
    }
    // --scale scales the corners and the written MAX_PATCH_AREA (by its square), so the
    // scaled scene meshes into as many elements.
    let scaled = read_any_scene(
        &ex.glb,
        &ImportOptions {
            scale: 0.001,
            settings: None,
        },
    )
    .unwrap();
    let area = coarse_settings().max_patch_area * 1e-6;
    assert!((scaled.file.settings.max_patch_area - area).abs() <= 1e-15 * area);
    let prepared =
        Prepared::new(scaled.file.scene.clone(), scaled.file.settings, &NoProgress).unwrap();
    assert_eq!(prepared.mesh.len(), want_prepared.mesh.len());
}

/// A buffer file shorter than its byteLength is named in the error (QA pass 18 of #16:
/// "buffer 0 should hold 1392 bytes ... but has 1221" did not say which file it read).
#[test]
fn a_short_buffer_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let ex = export_cornell_box(dir.path());
    let doc: Value = serde_json::from_slice(&std::fs::read(&ex.gltf).unwrap()).unwrap();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap().to_string();
    let bin = dir.path().join(&uri);
    let bytes = std::fs::read(&bin).unwrap();
    std::fs::write(&bin, &bytes[..bytes.len() / 2]).unwrap();
    let e = read_any_scene(&ex.gltf, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("buffer 0 (read from \"{uri}\") should hold")),
        "{e}"
    );
}

/// A polygon that is not one falls back to the triangles, with a warning naming the mesh.
#[test]
fn a_malformed_exported_polygon_reads_the_triangles_instead() {
    let dir = tempfile::tempdir().unwrap();
    let ex = export_cornell_box(dir.path());
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&ex.gltf).unwrap()).unwrap();
    doc["meshes"][0]["extras"]["radiosity"]["polygon"] = json!([[0, 0, 0], [1, "x", 0], [1, 1, 0]]);
    std::fs::write(&ex.gltf, serde_json::to_vec(&doc).unwrap()).unwrap();
    let imported = read_any_scene(&ex.gltf, &ImportOptions::default()).unwrap();
    assert_eq!(imported.warnings.len(), 1, "{:?}", imported.warnings);
    let w = imported.warnings[0].to_string();
    assert!(w.contains("mesh 0 (corner 1 is [1,\"x\",0])"), "{w}");
    let got = &imported.file.scene;
    // Every other surface is the scene's; the first came from its triangles, named
    // after it, covering its meshed area.
    let first = &ex.scene.surfaces[0].name;
    let pieces = got
        .surfaces
        .iter()
        .filter(|s| s.name == *first || s.name.starts_with(&format!("{first}.")))
        .count();
    assert!(pieces >= 1);
    assert_eq!(got.surfaces.len(), ex.scene.surfaces.len() - 1 + pieces);
}

/// A file of triangles alone (the export's polygons taken out, as a tool that keeps only
/// the geometry would leave it) still reads as before: the triangles joined back.
#[test]
fn exported_triangles_without_the_polygons_read_back_joined() {
    let dir = tempfile::tempdir().unwrap();
    let ex = export_cornell_box(dir.path());
    strip_polygons(&ex.gltf);
    {
        let path = &ex.gltf;
        let imported = read_any_scene(path, &ImportOptions::default()).unwrap();
        assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
        let got = &imported.file.scene;
        let groups = groups_by_name(got, &ex.scene);
        assert_eq!(
            groups.iter().map(Vec::len).sum::<usize>(),
            got.surfaces.len(),
            "every imported surface comes from one original"
        );
        for ((group, want), &want_area) in
            groups.iter().zip(&ex.scene.surfaces).zip(&ex.surface_area)
        {
            // Geometry: the pieces cover the surface's meshed part (the floor under the
            // boxes is buried and not meshed, so not exported). Positions went through f32
            // (about 3e-5 at 550 mm); the summed area is within 1e-6 relative of the
            // mesh's, ten times f32's rounding of the products, and every corner lies on
            // the original's plane within 1e-3 mm and inside its bounds as closely.
            let plane_point = crate::geometry::polygon_centroid(&want.vertices);
            let normal = crate::geometry::polygon_normal(&want.vertices).unwrap();
            let (lo, hi) = want
                .vertices
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), v| {
                    (l.min(*v), h.max(*v))
                });
            let area: f64 = group
                .iter()
                .map(|&i| crate::geometry::polygon_area(&got.surfaces[i].vertices))
                .sum();
            assert!(
                (area - want_area).abs() <= 1e-6 * want_area,
                "{}: area {area} vs {want_area}",
                want.name
            );
            for &i in group {
                let s = &got.surfaces[i];
                for v in &s.vertices {
                    let off_plane = (*v - plane_point).dot(normal).abs();
                    assert!(off_plane < 1e-3, "{}: {v} is {off_plane} off", want.name);
                    assert!(
                        v.cmpge(lo - 1e-3).all() && v.cmple(hi + 1e-3).all(),
                        "{}: {v} outside {lo} {hi}",
                        want.name
                    );
                }
                // Colours: the scene's own, read from the material's extras as written
                // (JSON's decimal round trip of an f64: equal to the last bit or two).
                for k in 0..3 {
                    for (a, b) in [
                        (s.reflectance.0[k], want.reflectance.0[k]),
                        (s.emission.0[k], want.emission.0[k]),
                    ] {
                        assert!((a - b).abs() <= 1e-15 * b.abs(), "{}: {a} vs {b}", s.name);
                    }
                }
            }
        }
        // And so the light: solved again, each surface's mean radiosity is the original's.
        // The pieces mesh differently from the original quads (the display triangles
        // join back into 113 convex polygons, not the 20 quads), so the element grid and
        // the discretisation error differ: measured 2.8e-4 of the brightest surface's mean
        // at most (on the dimmest surfaces; the light itself is emission plus little);
        // 1e-3 of it is the bound, far below a visible step and far above rounding.
        let again = surface_means(got.clone(), &groups);
        let top = ex.surface_b.iter().flatten().copied().fold(0.0, f64::max);
        for ((a, b), s) in again.iter().zip(&ex.surface_b).zip(&ex.scene.surfaces) {
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-3 * top,
                    "{}: {a:?} vs {b:?}",
                    s.name
                );
            }
        }
    }
}

#[test]
fn unlit_export_without_its_colours_reads_as_the_baked_light() {
    let dir = tempfile::tempdir().unwrap();
    let ex = export_cornell_box(dir.path());
    // A baked file from elsewhere: the materials' extras taken out.
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&ex.gltf).unwrap()).unwrap();
    for m in doc["materials"].as_array_mut().unwrap() {
        m.as_object_mut().unwrap().remove("extras");
    }
    std::fs::write(&ex.gltf, serde_json::to_vec(&doc).unwrap()).unwrap();
    let imported = read_any_scene(&ex.gltf, &ImportOptions::default()).unwrap();
    let got = &imported.file.scene;
    let groups = groups_by_name(got, &ex.scene);
    for ((group, want), colour) in groups
        .iter()
        .zip(&ex.scene.surfaces)
        .zip(&ex.surface_colour)
    {
        for &i in group {
            let s = &got.surfaces[i];
            assert_eq!(s.reflectance.0, [0.0; 3], "{}", s.name);
            // Emission = mean COLOR_0 / exposureScale, the colours as the file holds
            // them (f32): equal within f64's rounding of the sum and quotient.
            for k in 0..3 {
                let e = colour[k] / ex.scale;
                assert!(
                    (s.emission.0[k] - e).abs() <= 1e-12 * e.max(1e-9),
                    "{} ({}): {} vs {e}",
                    s.name,
                    want.name,
                    s.emission.0[k]
                );
            }
        }
    }
    // Nothing reflects: solved, each surface sends out what the file showed, its mean.
    let again = surface_means(got.clone(), &groups);
    for (a, c) in again.iter().zip(&ex.surface_colour) {
        for k in 0..3 {
            let e = c[k] / ex.scale;
            assert!((a[k] - e).abs() <= 1e-9 * e.max(1e-9), "{a:?} vs {e}");
        }
    }
}

/// Issue #13: the camera `radiosity export` writes reads back as the scene's camera, so
/// `render out.glb` shows the view it was exported with, at any `--scale`. glTF holds the
/// node's translation and rotation and `yfov` in single precision (the `gltf` crate reads
/// them as f32), so the eye agrees to f32 rounding of its coordinates (6e-8 of them; 1e-6
/// allowed, of the eye's distance from the origin) and the camera's axes, from an f32
/// unit quaternion, to a few f32 roundings too (1e-6); the field of view to 1e-6 of it.
#[test]
fn exported_camera_reads_back_as_the_scene_camera() {
    use crate::io::export::gltf::{write_glb, write_gltf, Bake};
    use crate::render::Camera;
    let dir = tempfile::tempdir().unwrap();
    let prepared = Prepared::new(cornell_scene(), coarse_settings(), &NoProgress).unwrap();
    let vertex_b = vec![[0.1; 3]; prepared.mesh.vertices.len()];
    // The box's own view (a half turn about y), and an oblique one with a tilted up.
    let views = [
        (
            dvec3(278.0, 273.0, -800.0),
            dvec3(278.0, 273.0, 0.0),
            DVec3::Y,
            39.3,
        ),
        (
            dvec3(100.0, 450.0, -300.0),
            dvec3(300.0, 200.0, 250.0),
            dvec3(0.2, 1.0, 0.1),
            55.0,
        ),
    ];
    for (eye, look_at, up, fov_y_degrees) in views {
        let camera = Camera {
            eye,
            look_at,
            up,
            fov_y_degrees,
            width: 64,
            height: 48,
        };
        let bake = Bake {
            scene: &prepared.scene,
            mesh: &prepared.mesh,
            vertex_b: &vertex_b,
            exposure_scale: 1.0,
            exposure: "fixed",
            camera: &camera,
            settings: coarse_settings(),
        };
        let (glb, gltf) = (dir.path().join("view.glb"), dir.path().join("view.gltf"));
        write_glb(&glb, &bake).unwrap();
        write_gltf(&gltf, &bake).unwrap();
        let (forward, right, up) = camera.basis();
        for (path, scale) in [(&glb, 1.0), (&gltf, 1.0), (&glb, 0.001)] {
            let options = ImportOptions {
                scale,
                settings: None,
            };
            let imported = read_any_scene(path, &options).unwrap();
            assert!(imported.warnings.is_empty(), "{:?}", imported.warnings);
            let scene = &imported.file.scene;
            let hint = scene.camera.expect("the exported camera");
            let got = Camera::for_scene(scene, 64, 48);
            let what = format!(
                "{} at scale {scale}, view from {eye} to {look_at}",
                path.display()
            );
            assert!(
                got.eye.distance(eye * scale) <= 1e-6 * eye.length() * scale,
                "{what}: eye {}",
                got.eye
            );
            let (f, r, u) = got.basis();
            for (a, b, axis) in [(f, forward, "forward"), (r, right, "right"), (u, up, "up")] {
                assert!(a.distance(b) <= 1e-6, "{what}: {axis} {a} against {b}");
            }
            assert!(
                (hint.fov_y_degrees / fov_y_degrees - 1.0).abs() <= 1e-6,
                "{what}: field of view {}",
                hint.fov_y_degrees
            );
        }
    }
}

/// An orthographic glTF camera is passed over with a warning, and the scene keeps no
/// camera (the renderer then frames the scene itself).
#[test]
fn an_orthographic_camera_is_warned_about_and_not_used() {
    use crate::io::export::gltf::{write_gltf, Bake};
    let dir = tempfile::tempdir().unwrap();
    let prepared = Prepared::new(cornell_scene(), coarse_settings(), &NoProgress).unwrap();
    let vertex_b = vec![[0.1; 3]; prepared.mesh.vertices.len()];
    let camera = crate::render::Camera::for_scene(&prepared.scene, 64, 48);
    let bake = Bake {
        scene: &prepared.scene,
        mesh: &prepared.mesh,
        vertex_b: &vertex_b,
        exposure_scale: 1.0,
        exposure: "fixed",
        camera: &camera,
        settings: coarse_settings(),
    };
    let path = dir.path().join("ortho.gltf");
    write_gltf(&path, &bake).unwrap();
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    doc["cameras"][0] = json!({
        "type": "orthographic",
        "orthographic": { "xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 10.0 },
    });
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let imported = read_any_scene(&path, &ImportOptions::default()).unwrap();
    assert!(imported.file.scene.camera.is_none());
    assert_eq!(imported.warnings.len(), 1, "{:?}", imported.warnings);
    let w = imported.warnings[0].to_string();
    assert!(w.contains("orthographic camera of node"), "{w}");
}

/// QA of issue #16: room.scene exported to glTF came back with a table leg's corner
/// 3.6999999999999997 read as 3.7 (serde_json's default float parsing can be an ulp off),
/// and its solve differed by up to 0.13 %. An export's numbers, as `exported_polygon`
/// reads them (through a `serde_json::Value`), are the written ones to the last bit.
#[test]
fn json_numbers_read_back_to_the_last_bit() {
    // The doubles beside a positive x.
    let beside = |x: f64| {
        [
            f64::from_bits(x.to_bits() - 1),
            f64::from_bits(x.to_bits() + 1),
        ]
    };
    let mut values = vec![beside(3.7)[0], 0.1 + 0.2, 1e-300, 5e-324, 1.0 / 3.0];
    // A spread of awkward doubles: consecutive ones near decimal round numbers.
    for k in 1..2000u64 {
        let x = k as f64 * 0.0370001;
        values.push(x);
        values.extend(beside(x));
    }
    for x in values {
        let text = serde_json::to_string(&serde_json::json!([x, -x])).unwrap();
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        let got = [back[0].as_f64().unwrap(), back[1].as_f64().unwrap()];
        assert_eq!(got.map(f64::to_bits), [x, -x].map(f64::to_bits), "{text}");
    }
}
