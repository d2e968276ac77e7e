//! The solved scene as glTF 2.0 (`radiosity export SCENE -o out.glb`, or `.gltf` with its
//! buffer in a `.bin` file beside it): the mesh with the radiosity baked into vertex colours
//! on unlit materials, so that the walkthrough opens in Blender, a browser glTF viewer or a
//! game engine without lights.
//!
//! What is written:
//!
//! * one node and one mesh per input surface, named after the surface, with one triangle
//!   primitive: `POSITION` (f32, the mesh's vertices in scene units, untransformed; glTF
//!   readers take them as metres with +y up), `COLOR_0` (f32 RGB) and u32 indices. The
//!   triangles are the mesh's display triangles ([`crate::mesh::Mesh::display`]), which
//!   take every T-vertex of the mesh as a corner, so the colours meet without cracks;
//!   vertices are shared within a surface, so a surface shades smooth (Gouraud) as in
//!   `render --shading smooth`, and each surface keeps its own vertices, so the colours
//!   may step where surfaces meet, as they do in the solution; a surface with no elements
//!   (buried whole under another, which the contact refinement drops) is written as its
//!   own polygon in triangles, coloured by its emission, so that every surface is there;
//! * `COLOR_0` = min(1, s B) per band, linear (not sRGB-encoded): B the vertex radiosity
//!   ([`crate::shade::vertex_radiosity`]) and s the exposure scale (`render`'s automatic
//!   exposure unless one is given), clamped as `render` clamps, so that lights are white.
//!   s, how it was chosen and the largest s B before clamping are in
//!   `asset.extras.radiosity` (`exposureScale`, `exposure`, `maxExposedValue`); where
//!   `COLOR_0` is below 1, B = `COLOR_0` / s in the scene's emission units;
//! * one material per distinct pair of reflectance and emission (named after the first
//!   surface with it), white, `KHR_materials_unlit` (declared in `extensionsUsed`), single
//!   sided as the scene's surfaces are (their backs are black in the solution), so that a
//!   viewer shows `COLOR_0` as it is; the surfaces' own reflectance and emission (scene
//!   units, full precision) are in the material's `extras.radiosity` (`reflectance`,
//!   `emission`), which the glTF reader takes back, so that `export` then import keeps
//!   the scene's colours, not only its picture (`crate::io::import::gltf`);
//! * a perspective camera node for the given view (`render`'s camera for the same flags);
//! * what rebuilds the scene rather than the mesh: each mesh's `extras.radiosity.polygon`
//!   is its surface's corners (scene units, full precision, in order: counter-clockwise
//!   from the front) and `asset.extras.radiosity.meshSettings` the settings it was meshed
//!   with (`maxPatchArea`, `integralSteps`), which the glTF reader takes instead of the
//!   triangles, so that `export` then import gives the same surfaces, and so the same
//!   elements, as the scene exported (the triangles alone join back into several polygons
//!   per surface: the Cornell box's 20 surfaces came back as about 520).
//!
//! The JSON is written with `serde_json`: the document is one mesh per surface and four
//! buffer views, small enough that the typed builder of `gltf-json` would add a dependency
//! tree and no safety that the round-trip test (read back with the `gltf` crate) does not.

use std::collections::HashMap;
use std::io::{self, Write};
use std::path::Path;

use glam::{DMat3, DQuat, DVec3};
use serde_json::{json, Value};

use crate::mesh::{Mesh, MeshSettings};
use crate::render::Camera;
use crate::scene::Scene;

/// What the baked colours are and how they were exposed.
#[derive(Clone, Copy, Debug)]
pub struct Bake<'a> {
    /// The scene the mesh was cut from.
    pub scene: &'a Scene,
    /// The solved mesh.
    pub mesh: &'a Mesh,
    /// One radiosity per mesh vertex ([`crate::shade::vertex_radiosity`]).
    pub vertex_b: &'a [[f64; 3]],
    /// Radiosities are multiplied by this (then clamped to 1).
    pub exposure_scale: f64,
    /// How the scale was chosen ("auto" or "fixed"), for the extras.
    pub exposure: &'a str,
    /// The view the camera node shows.
    pub camera: &'a Camera,
    /// The settings the mesh was cut with, written so that the file reads back meshing
    /// the same.
    pub settings: MeshSettings,
}

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

/// The glTF JSON document and its binary buffer (`uri` the buffer's, `None` in a GLB).
///
/// # Panics
/// If `vertex_b` does not have one entry per mesh vertex.
pub fn document(bake: &Bake, uri: Option<&str>) -> (Value, Vec<u8>) {
    let (scene, mesh) = (bake.scene, bake.mesh);
    assert_eq!(
        bake.vertex_b.len(),
        mesh.vertices.len(),
        "one radiosity per vertex"
    );
    let display = mesh.display();
    let (mut positions, mut colours, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    let (mut accessors, mut meshes, mut nodes) = (Vec::new(), Vec::new(), Vec::new());
    let mut max_exposed = 0.0f64;
    let mut local = vec![u32::MAX; mesh.vertices.len()];
    // One material per distinct (reflectance, emission), in first use: white and unlit for
    // the viewers, the scene's colours in its extras for the way back in.
    let mut materials: Vec<Value> = Vec::new();
    let mut material_of: HashMap<[u64; 6], usize> = HashMap::new();
    for (s, surface) in scene.surfaces.iter().enumerate() {
        let Some(elements) = mesh.surface_elements.get(s) else {
            continue;
        };
        // The surface's vertices (those its triangles use), numbered from 0 in first use.
        let (first_vertex, first_index) = (positions.len() / 3, indices.len());
        let mut used: Vec<u32> = Vec::new();
        for e in elements.clone() {
            for t in display.triangles(e as usize) {
                for &v in &t.vertices {
                    if local[v as usize] == u32::MAX {
                        local[v as usize] = used.len() as u32;
                        used.push(v);
                    }
                    indices.push(local[v as usize]);
                }
            }
        }
        // Each vertex's position and radiosity. A surface with no elements (buried whole
        // under another, as the base of a box standing on the floor) is written as its
        // own polygon, fanned into triangles, showing its emission (what its radiosity
        // would be: no light reaches it), so that the file still holds every surface.
        let corners: Vec<(DVec3, [f64; 3])> = if used.is_empty() {
            let n = surface.vertices.len() as u32;
            indices.extend((1..n.saturating_sub(1)).flat_map(|k| [0, k, k + 1]));
            surface
                .vertices
                .iter()
                .map(|&p| (p, surface.emission.0))
                .collect()
        } else {
            used.iter()
                .map(|&v| {
                    local[v as usize] = u32::MAX;
                    (mesh.vertices[v as usize], bake.vertex_b[v as usize])
                })
                .collect()
        };
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for (p, b) in &corners {
            let pf = p.as_vec3();
            positions.extend(pf.to_array());
            lo = lo.min(pf.as_dvec3());
            hi = hi.max(pf.as_dvec3());
            let exposed = b.map(|b| b * bake.exposure_scale);
            for x in exposed {
                if x.is_finite() {
                    max_exposed = max_exposed.max(x);
                }
            }
            colours.extend(exposed.map(|x| if x > 0.0 { x.min(1.0) as f32 } else { 0.0 }));
        }
        let count = corners.len();
        let a = accessors.len();
        accessors.push(json!({
            "bufferView": 0, "byteOffset": first_vertex * 12, "componentType": FLOAT,
            "count": count, "type": "VEC3",
            "min": lo.to_array(), "max": hi.to_array(),
        }));
        accessors.push(json!({
            "bufferView": 1, "byteOffset": first_vertex * 12, "componentType": FLOAT,
            "count": count, "type": "VEC3",
        }));
        accessors.push(json!({
            "bufferView": 2, "byteOffset": first_index * 4, "componentType": UNSIGNED_INT,
            "count": indices.len() - first_index, "type": "SCALAR",
        }));
        let (r, e) = (surface.reflectance.0, surface.emission.0);
        let key = [r[0], r[1], r[2], e[0], e[1], e[2]].map(f64::to_bits);
        let material = *material_of.entry(key).or_insert_with(|| {
            materials.push(json!({
                "name": surface.name,
                "pbrMetallicRoughness": {
                    "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": 1.0,
                },
                "extensions": { "KHR_materials_unlit": {} },
                "extras": { "radiosity": { "reflectance": r, "emission": e } },
            }));
            materials.len() - 1
        });
        let polygon: Vec<[f64; 3]> = surface.vertices.iter().map(|v| v.to_array()).collect();
        meshes.push(json!({
            "name": surface.name,
            "extras": { "radiosity": { "polygon": polygon } },
            "primitives": [{
                "attributes": { "POSITION": a, "COLOR_0": a + 1 },
                "indices": a + 2,
                "material": material,
                "mode": 4,
            }],
        }));
        nodes.push(json!({ "name": surface.name, "mesh": meshes.len() - 1 }));
    }

    // The buffer: positions, colours, indices, each a whole number of 4-byte values.
    let mut bin = Vec::with_capacity(4 * (positions.len() + colours.len() + indices.len()));
    let views = [
        bytes(&mut bin, positions.iter().map(|x| x.to_le_bytes())),
        bytes(&mut bin, colours.iter().map(|x| x.to_le_bytes())),
        bytes(&mut bin, indices.iter().map(|x| x.to_le_bytes())),
    ];
    let targets = [ARRAY_BUFFER, ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER];
    let buffer_views: Vec<Value> = views
        .iter()
        .zip(targets)
        .filter(|((_, len), _)| *len > 0)
        .map(|((offset, len), target)| {
            let mut view =
                json!({ "buffer": 0, "byteOffset": offset, "byteLength": len, "target": target });
            // Vertex attributes of many accessors share a view: glTF then requires the
            // stride (12 bytes, one f32 VEC3); index views may not have one.
            if target == ARRAY_BUFFER {
                view["byteStride"] = json!(12);
            }
            view
        })
        .collect();

    // The camera: glTF's looks down its node's -z with +y up.
    let c = bake.camera;
    let (forward, right, up) = c.basis();
    let rotation = DQuat::from_mat3(&DMat3::from_cols(right, up, -forward)).normalize();
    let camera_node = nodes.len();
    nodes.push(json!({
        "name": "camera",
        "camera": 0,
        "translation": c.eye.to_array(),
        "rotation": rotation.to_array(),
    }));
    let mut buffer = json!({ "byteLength": bin.len() });
    if let Some(uri) = uri {
        buffer["uri"] = json!(uri);
    }
    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("radiosity ", env!("CARGO_PKG_VERSION")),
            "extras": { "radiosity": {
                "exposureScale": bake.exposure_scale,
                "exposure": bake.exposure,
                "maxExposedValue": max_exposed,
                "colour": "COLOR_0 = min(1, exposureScale x B) per band, linear; B the vertex \
                           radiosity in the scene's emission units",
                "units": "positions in scene units, untransformed",
                "meshSettings": {
                    "maxPatchArea": bake.settings.max_patch_area,
                    "integralSteps": bake.settings.integral_steps,
                },
            }},
        },
        "extensionsUsed": ["KHR_materials_unlit"],
        "scene": 0,
        "scenes": [{ "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{
            "type": "perspective",
            "perspective": {
                "yfov": c.fov_y_degrees.to_radians(),
                "aspectRatio": c.width.max(1) as f64 / c.height.max(1) as f64,
                "znear": znear(bake.scene, c),
            },
        }],
        "accessors": accessors,
        "bufferViews": buffer_views,
        "buffers": [buffer],
    });
    debug_assert!(camera_node + 1 == doc["nodes"].as_array().map_or(0, Vec::len));
    if bin.is_empty() {
        // No geometry: no buffer (glTF forbids a buffer of length 0).
        let obj = doc.as_object_mut().expect("an object");
        for key in ["buffers", "bufferViews", "accessors", "meshes", "materials"] {
            obj.remove(key);
        }
    }
    (doc, bin)
}

/// Appends `values` to `bin`; returns where they start and how many bytes they take.
fn bytes(bin: &mut Vec<u8>, values: impl Iterator<Item = [u8; 4]>) -> (usize, usize) {
    let start = bin.len();
    for v in values {
        bin.extend(v);
    }
    (start, bin.len() - start)
}

/// A near plane for the camera: a thousandth of the scene's diagonal (positive, as glTF
/// requires).
fn znear(scene: &Scene, _camera: &Camera) -> f64 {
    let (lo, hi) = scene.bounds();
    let d = (hi - lo).length();
    if d.is_finite() && d > 0.0 {
        d * 1e-3
    } else {
        1e-3
    }
}

/// Writes the baked scene as a binary glTF (GLB) file at `path`, atomically.
pub fn write_glb(path: &Path, bake: &Bake) -> io::Result<()> {
    let (doc, bin) = document(bake, None);
    let mut json = serde_json::to_vec(&doc).map_err(io::Error::other)?;
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut bin = bin;
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let chunks = 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let total = u32::try_from(12 + chunks)
        .map_err(|_| io::Error::other("the scene is too large for a GLB file (4 GiB)"))?;
    crate::io::write_atomically(path, |w| {
        w.write_all(b"glTF")?;
        w.write_all(&2u32.to_le_bytes())?;
        w.write_all(&total.to_le_bytes())?;
        w.write_all(&(json.len() as u32).to_le_bytes())?;
        w.write_all(b"JSON")?;
        w.write_all(&json)?;
        if !bin.is_empty() {
            w.write_all(&(bin.len() as u32).to_le_bytes())?;
            w.write_all(b"BIN\0")?;
            w.write_all(&bin)?;
        }
        Ok(())
    })
}

/// The buffer file that goes with the glTF file `path`: `NAME.bin` beside `NAME.gltf`.
pub fn buffer_path(path: &Path) -> std::path::PathBuf {
    path.with_extension("bin")
}

/// Writes the baked scene as a glTF JSON file at `path` with its buffer in
/// [`buffer_path`]`(path)` (referred to by its file name), both atomically, the buffer first.
pub fn write_gltf(path: &Path, bake: &Bake) -> io::Result<()> {
    let bin_path = buffer_path(path);
    let uri = bin_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| io::Error::other("the output has no file name"))?;
    let (doc, bin) = document(bake, Some(&percent_encode(&uri)));
    if !bin.is_empty() {
        crate::io::write_atomically(&bin_path, |w| w.write_all(&bin))?;
    }
    crate::io::write_atomically(path, |w| {
        serde_json::to_writer_pretty(&mut *w, &doc).map_err(io::Error::other)?;
        writeln!(w)
    })
}

/// `uri` with the characters a URI reference may not hold percent-encoded (a file name
/// with a space or a '#').
fn percent_encode(uri: &str) -> String {
    let mut out = String::new();
    for b in uri.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~!$&'()*+,;=:@".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::scene::{Rgb, Surface};
    use glam::dvec3;

    /// A 2 x 1 floor under a 1 x 1 light facing it, meshed at area 0.5.
    fn scene() -> Scene {
        let floor = Surface {
            name: "floor".into(),
            emission: Rgb::BLACK,
            reflectance: Rgb([0.5; 3]),
            vertices: vec![
                dvec3(0., 0., 0.),
                dvec3(0., 0., 1.),
                dvec3(2., 0., 1.),
                dvec3(2., 0., 0.),
            ],
            photometry: Default::default(),
        };
        let light = Surface {
            name: "light #1".into(),
            emission: Rgb([4.0; 3]),
            reflectance: Rgb::BLACK,
            vertices: vec![
                dvec3(0., 1., 0.),
                dvec3(1., 1., 0.),
                dvec3(1., 1., 1.),
                dvec3(0., 1., 1.),
            ],
            photometry: Default::default(),
        };
        Scene {
            surfaces: vec![floor, light],
            camera: None,
            lights: Vec::new(),
        }
    }

    fn read_back(path: &Path) -> (gltf::Document, Vec<Vec<u8>>) {
        let bytes = std::fs::read(path).unwrap();
        let g = gltf::Gltf::from_slice(&bytes).unwrap();
        let buffers = g
            .buffers()
            .map(|b| match b.source() {
                gltf::buffer::Source::Bin => g.blob.clone().unwrap(),
                gltf::buffer::Source::Uri(uri) => {
                    std::fs::read(path.with_file_name(uri.replace("%20", " "))).unwrap()
                }
            })
            .collect();
        (g.document, buffers)
    }

    #[test]
    fn glb_and_gltf_read_back_with_the_mesh_positions_and_exposed_colours() {
        let s = scene();
        let mesh = mesh_scene(&s, 0.5).unwrap();
        // Radiosity rising along x, so that a vertex mix-up shows; the light at 4.
        let vertex_b: Vec<[f64; 3]> = mesh
            .vertices
            .iter()
            .map(|p| {
                if p.y > 0.5 {
                    [4.0; 3]
                } else {
                    [p.x, 0.5 * p.x, 0.1]
                }
            })
            .collect();
        let camera = Camera {
            eye: dvec3(1., 0.5, 3.),
            look_at: dvec3(1., 0.5, 0.),
            up: DVec3::Y,
            fov_y_degrees: 50.0,
            width: 64,
            height: 32,
        };
        let bake = Bake {
            scene: &s,
            mesh: &mesh,
            vertex_b: &vertex_b,
            exposure_scale: 0.5,
            exposure: "fixed",
            camera: &camera,
            settings: MeshSettings {
                max_patch_area: 0.5,
                integral_steps: 2,
            },
        };
        let dir = tempfile::tempdir().unwrap();
        let glb = dir.path().join("out.glb");
        let gltf_path = dir.path().join("out file.gltf");
        write_glb(&glb, &bake).unwrap();
        write_gltf(&gltf_path, &bake).unwrap();
        assert!(dir.path().join("out file.bin").exists());
        for path in [&glb, &gltf_path] {
            let (doc, buffers) = read_back(path);
            assert!(doc.extensions_used().any(|e| e == "KHR_materials_unlit"));
            let material = doc.materials().next().unwrap();
            assert!(material.unlit());
            let names: Vec<_> = doc
                .meshes()
                .map(|m| m.name().unwrap().to_string())
                .collect();
            assert_eq!(names, ["floor", "light #1"]);
            let mut vertices = 0;
            for (s, m) in doc.meshes().enumerate() {
                let p = m.primitives().next().unwrap();
                let r = p.reader(|b| Some(&buffers[b.index()][..]));
                let positions: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
                let colours: Vec<[f32; 3]> = r.read_colors(0).unwrap().into_rgb_f32().collect();
                let indices: Vec<u32> = r.read_indices().unwrap().into_u32().collect();
                vertices += positions.len();
                // Every position is one of the surface's mesh vertices, with its colour.
                let range = mesh.surface_vertices[s].clone();
                assert_eq!(
                    positions.len(),
                    range.len(),
                    "surface {s} uses all its vertices"
                );
                for (p, c) in positions.iter().zip(&colours) {
                    let v = range
                        .clone()
                        .find(|&v| mesh.vertices[v as usize].as_vec3().to_array() == *p)
                        .expect("a mesh vertex");
                    let want = vertex_b[v as usize].map(|b| (0.5 * b).min(1.0) as f32);
                    assert_eq!(*c, want, "vertex at {p:?}");
                    assert!(c.iter().all(|&x| (0.0..=1.0).contains(&x)));
                }
                // The display triangles, counter-clockwise from the front as the mesh's.
                let triangles: usize = mesh.surface_elements[s]
                    .clone()
                    .map(|e| mesh.display().triangles(e as usize).len())
                    .sum();
                assert_eq!(indices.len(), 3 * triangles);
                let normal = if s == 0 { DVec3::Y } else { -DVec3::Y };
                for t in indices.chunks(3) {
                    let [a, b, c] =
                        [0, 1, 2].map(|k| glam::Vec3::from(positions[t[k] as usize]).as_dvec3());
                    assert!(
                        (b - a).cross(c - a).dot(normal) > 0.0,
                        "triangle {t:?} faces its surface's front"
                    );
                }
            }
            assert_eq!(vertices, mesh.vertices.len());
            // The light's exposed value is 2, clamped to 1; the extras say so.
            let extras: Value =
                serde_json::from_str(doc.as_json().asset.extras.as_ref().unwrap().get()).unwrap();
            assert_eq!(extras["radiosity"]["exposureScale"], 0.5);
            assert_eq!(extras["radiosity"]["maxExposedValue"], 2.0);
            // The camera node looks from the eye to the look-at point: its -z axis.
            let node = doc.nodes().find(|n| n.camera().is_some()).unwrap();
            let (t, r, _) = node.transform().decomposed();
            assert_eq!(t, [1.0, 0.5, 3.0]);
            let forward = glam::Quat::from_array(r) * -glam::Vec3::Z;
            assert!((forward - -glam::Vec3::Z).length() < 1e-6, "{forward}");
        }
    }
}
