//! glTF 2.0 (`.gltf` with external or embedded buffers, and `.glb`), read with the `gltf`
//! crate's document model; the buffers, accessors and images are read here, with every
//! offset, stride and count checked against the bytes there are before anything is
//! allocated for them.
//!
//! What is read:
//!
//! * the default scene (or the first, or, in a file without scenes, every node that is no
//!   other node's child), its node hierarchy's transforms applied (`matrix` or
//!   translation-rotation-scale); a node whose transform mirrors (negative determinant)
//!   has its triangles' winding turned, as the specification says;
//! * each mesh primitive's `POSITION`s (`f32`) and indices (`u8`, `u16`, `u32`, or none):
//!   triangles as they are, triangle strips and fans converted to triangles (with a
//!   warning), points and lines left out (with a warning: they have no area);
//!   edge-adjacent triangles of one primitive that lie in one plane and make a convex
//!   polygon are joined into it (module `merge`), so that a quad exported as two
//!   triangles meshes as the quad;
//! * the material: reflectance is `baseColorFactor` (RGB, alpha ignored) times the mean of
//!   the base-colour texture when there is one (PNG or JPEG; decoded from sRGB to linear
//!   and averaged over its texels, not weighted by how the surface's UVs use it; a texture
//!   that cannot be read is left out with a warning); a reflectance of 1 or more (glTF's
//!   default white) is taken as [`MAX_REFLECTANCE`] with a warning, since the scene
//!   format needs it below 1. Emission is `emissiveFactor` times
//!   `KHR_materials_emissive_strength` (1 without it), taken as the exitance in the
//!   scene's emission units, as OBJ's `Ke` is;
//! * vertex colours (`COLOR_0`) on a lit material multiply its base colour face by face:
//!   each face (after the joining, which goes by geometry alone) takes the mean of
//!   `COLOR_0` over its corners (a corner where vertices of several colours meet counting
//!   with their mean), its reflectance the base colour times that mean, capped at
//!   [`MAX_REFLECTANCE`] where it reaches 1 (one warning counts the faces), a material
//!   of its own per distinct colour;
//! * a material with `extras.radiosity` (`reflectance` and `emission`, three numbers
//!   each, as `radiosity export` writes them) has exactly those, and nothing above is
//!   read for it: an exported scene read back has its own colours and lights;
//! * a mesh with `extras.radiosity.polygon` (its one primitive's surface's corners, as
//!   `radiosity export` writes them) is read as that polygon, placed by the node, instead
//!   of its triangles, and `asset.extras.radiosity.meshSettings` (`maxPatchArea`,
//!   `integralSteps`) gives the meshing settings (the area times the scale squared;
//!   [`super::ImportOptions::settings`] wins): an exported scene reads back with the same
//!   surfaces and settings, so the same elements. A polygon that is not one is warned
//!   about and the triangles read instead;
//! * an unlit material (`KHR_materials_unlit`) without them holds baked light, not a
//!   reflectance: what it shows is what it sends out. It is taken as an emitter that
//!   reflects nothing, its emission the base colour (times the texture mean) times the
//!   mean of the primitive's `COLOR_0` (over the vertices its triangles use; floats or
//!   normalized bytes or shorts), divided by the exposure the file says it applied
//!   (`asset.extras.radiosity.exposureScale` of a radiosity export; 1 in other files),
//!   so that solving it gives back the light it shows, a primitive's mean for each
//!   primitive (colours clamped at 1 when baked, such as lights, stay clamped).
//!
//! Each node with a mesh is one object: its surfaces are named after the node (or its
//! mesh, or `node N`). Unit: metres, glTF's unit, times [`super::ImportOptions::scale`].
//!
//! The first perspective camera in the node tree (depth first, as the meshes are placed)
//! is the scene's camera (eye, viewing direction and up from its node's transform, the
//! vertical field of view from `yfov`), so a scene that `radiosity export` wrote renders
//! from the view it was exported with; orthographic cameras are warned about and passed
//! over.
//!
//! Ignored: lights (`KHR_lights_punctual`), normals, UVs beyond the texture
//! mean, the emissive texture, metallic-roughness, alpha and
//! `doubleSided` (every surface is one-sided: it reflects on its front only), morph
//! targets and skins, animations. Sparse accessors and quantized positions
//! (`KHR_mesh_quantization`) are refused with an error.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use base64::Engine as _;
use glam::{DMat4, DVec3};
use gltf::mesh::Mode;

use super::merge::join_coplanar;
use super::{
    check_count, default_settings, scaled_unit, FaceSoup, Format, ImportError, ImportOptions,
    ImportWarning, Imported, SoupFace, SoupMaterial,
};
use crate::io::scene_file::SceneFile;
use crate::light::Rgb;
use crate::mesh::MeshSettings;

/// The reflectance a colour of 1 or more becomes (glTF's default material is white, 1).
pub const MAX_REFLECTANCE: f64 = 0.99;

/// The most triangles the scene may have once every node's mesh is placed (meshes used by
/// several nodes count once per node): a file that asks for more is refused before it
/// is expanded.
pub const MAX_TRIANGLES: usize = 2_000_000;

/// Reads the glTF or binary glTF file at `path`; buffers and images it names by URI are
/// read relative to the file's folder.
pub fn read(path: &Path, options: &ImportOptions) -> Result<Imported, ImportError> {
    let file = path.display().to_string();
    crate::io::note_input(path);
    let bytes = std::fs::read(path).map_err(|e| ImportError::Io {
        what: "the scene file",
        file: file.clone(),
        message: e.to_string(),
    })?;
    // A .glb must be binary glTF (QA of issue #16: random bytes named .glb got the JSON
    // parser's "expected value at line 1 column 1").
    let named_glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if named_glb && !bytes.starts_with(b"glTF") {
        return Err(ImportError::Syntax {
            file,
            line: 0,
            message: "not a binary glTF file: a .glb starts with the 4 bytes \"glTF\" (a glTF \
                      file in JSON is named .gltf)"
                .to_string(),
        });
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    parse(&file, &bytes, Some(dir), options)
}

/// Reads glTF or binary glTF from `bytes` (named `file` in messages). URIs other than
/// `data:` ones are read from `dir`; with `dir` `None` they are refused.
pub fn parse(
    file: &str,
    bytes: &[u8],
    dir: Option<&Path>,
    options: &ImportOptions,
) -> Result<Imported, ImportError> {
    let mut reader = Reader {
        file: file.to_string(),
        dir,
        warnings: Vec::new(),
        buffers: Vec::new(),
        baked: Vec::new(),
        lit: Vec::new(),
        white: Vec::new(),
        capped_faces: 0,
        exposure_scale: 1.0,
        derived: Vec::new(),
        settings: None,
        camera: None,
    };
    let (soup, format) = reader.soup(bytes)?;
    let (mut scene, mut warnings) = soup.to_scene(options.scale)?;
    scene.camera = reader.camera.map(|(eye, forward, up, fov_y_degrees)| {
        camera_hint(&scene, eye * options.scale, forward, up, fov_y_degrees)
    });
    let mut all = std::mem::take(&mut reader.warnings);
    all.append(&mut warnings);
    // Settings given win; then those a radiosity export wrote (its area in the file's
    // units squared, scaled as the coordinates are); then the defaults.
    let settings = options
        .settings
        .or_else(|| {
            reader.settings.map(|m| MeshSettings {
                max_patch_area: m.max_patch_area * options.scale * options.scale,
                ..m
            })
        })
        .unwrap_or_else(|| default_settings(&scene));
    Ok(Imported {
        file: SceneFile { settings, scene },
        warnings: all,
        unit: scaled_unit("metres (glTF's unit)", options.scale),
        format,
    })
}

struct Reader<'a> {
    file: String,
    dir: Option<&'a Path>,
    warnings: Vec<ImportWarning>,
    /// Every buffer's bytes, in the document's order.
    buffers: Vec<Vec<u8>>,
    /// Per material of the file: `Some(colour)` where it is unlit without the scene's own
    /// colours (`extras.radiosity`), so that it is taken as baked light: its emission
    /// before a primitive's `COLOR_0` mean multiplies it.
    baked: Vec<Option<[f64; 3]>>,
    /// Per material of the file: `Some(base colour)` (times the texture mean, before the
    /// cap at [`MAX_REFLECTANCE`]) where it is lit and without the scene's own colours, so
    /// that a primitive's `COLOR_0` can multiply it face by face.
    lit: Vec<Option<[f64; 3]>>,
    /// Per material of the file: the warning that its base colour was capped, given when
    /// a primitive without `COLOR_0` first uses it (with `COLOR_0` each face is capped,
    /// and counted, on its own).
    white: Vec<Option<String>>,
    /// Faces whose base colour times their `COLOR_0` mean was capped.
    capped_faces: usize,
    /// The exposure a radiosity export applied (`asset.extras.radiosity.exposureScale`),
    /// 1 in other files.
    exposure_scale: f64,
    /// Materials made for single primitives (baked light times their `COLOR_0` mean),
    /// numbered [`DERIVED`] + k in the faces until they are placed after the file's own.
    derived: Vec<SoupMaterial>,
    /// The meshing settings a radiosity export wrote (`asset.extras.radiosity.meshSettings`).
    settings: Option<MeshSettings>,
    /// The first perspective camera met in the walk, in the file's units: (eye, unit
    /// viewing direction, unit up, vertical field of view in degrees).
    camera: Option<(DVec3, DVec3, DVec3, f64)>,
}

/// The bit that marks a face's material as one of [`Reader::derived`] during the walk.
const DERIVED: u32 = 1 << 31;

/// What counts warn about, summed over the file.
#[derive(Default)]
struct Counts {
    converted: usize,
    no_area: usize,
    leftover_indices: usize,
}

impl Reader<'_> {
    fn error(&self, message: String) -> ImportError {
        ImportError::Syntax {
            file: self.file.clone(),
            line: 0,
            message,
        }
    }

    fn warn(&mut self, message: String) {
        self.warnings.push(ImportWarning {
            file: self.file.clone(),
            line: 0,
            message,
        });
    }

    /// Refuses an `asset.version` other than 2.x by name.
    fn check_version(&self, version: &str) -> Result<(), ImportError> {
        let version = version.trim();
        if version.split('.').next() == Some("2") {
            return Ok(());
        }
        Err(self.error(format!(
            "asset.version is \"{version}\": this reader takes glTF 2.0 (a glTF 1.0 file can \
             be converted to 2.0, for instance by Blender's importer and exporter)"
        )))
    }

    fn soup(&mut self, bytes: &[u8]) -> Result<(FaceSoup, Format), ImportError> {
        let format = if bytes.starts_with(b"glTF") {
            self.check_glb_header(bytes)?;
            Format::Glb
        } else {
            Format::Gltf
        };
        // The version first, from the JSON as text: a glTF 1.0 file keeps its meshes and
        // accessors in objects keyed by id, which the typed reader below refuses as "not
        // a valid glTF 2.0 file: invalid type: map" before its version is looked at
        // (review of QA pass 15 of issue #16).
        if format == Format::Gltf {
            if let Ok(value) = serde_json::from_slice::<serde_json::Value>(bytes) {
                if let Some(version) = value["asset"]["version"].as_str() {
                    self.check_version(version)?;
                }
            }
        }
        let invalid = |e: gltf::Error| self.error(format!("not a valid glTF 2.0 file: {e}"));
        // Read, then validated in two steps: the `gltf` crate's own validation indexes the
        // accessor list with a primitive's POSITION index unchecked (gltf-json 1.4.1,
        // mesh.rs:151), so that index is checked here first (the fuzz target's first crash).
        let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(invalid)?;
        let blob = raw.blob;
        let json = raw.document.into_json();
        // The `gltf` crate reads any "asset.version" as 2.0; a glTF 1.0 file (materials as
        // shader techniques, other buffer rules) then failed later in puzzling ways or read
        // wrong (QA pass 15 of issue #16).
        self.check_version(&json.asset.version)?;
        self.check_position_indices(&json)?;
        let document = gltf::Document::from_json(json).map_err(invalid)?;
        let doc = &document;
        for buffer in doc.buffers() {
            let data = self.buffer(&buffer, blob.as_deref())?;
            self.buffers.push(data);
        }
        let mut soup = FaceSoup {
            file: self.file.clone(),
            ..FaceSoup::default()
        };
        self.exposure_scale = exposure_scale(doc);
        self.settings = exported_settings(doc);
        let materials: Vec<SoupMaterial> = doc
            .materials()
            .map(|m| self.material(doc, &m))
            .collect::<Result<_, _>>()?;
        soup.materials = materials;
        // The default material (for primitives without one) goes last, added when used.
        let default_material = soup.materials.len() as u32;
        let mut default_used = false;

        let roots = self.roots(doc)?;
        let planned = planned_triangles(doc, &roots);
        if planned > MAX_TRIANGLES {
            return Err(self.error(format!(
                "the scene would have {planned} triangles once every node's mesh is placed, \
                 more than the {MAX_TRIANGLES} this reader takes; split it or simplify it"
            )));
        }
        let mut counts = Counts::default();
        let mut triangles_total = 0usize;
        let mut bad_polygons: Vec<String> = Vec::new();
        // Depth-first over the tree, each node with its parent's global transform.
        let mut stack: Vec<(gltf::Node, DMat4)> = roots
            .into_iter()
            .rev()
            .map(|n| (n, DMat4::IDENTITY))
            .collect();
        let mut visited = vec![false; doc.nodes().len()];
        while let Some((node, parent)) = stack.pop() {
            if std::mem::replace(&mut visited[node.index()], true) {
                return Err(self.error(format!(
                    "node {} is reached twice in the scene's hierarchy (a node may have one \
                     parent and appear once; the children form a cycle or share a node)",
                    describe_node(&node)
                )));
            }
            // A rotation must be a unit quaternion (glTF 2.0, 5.25); [0, 0, 0, 0] turned into
            // no rotation at all, silently (QA pass 18 of #16). A drift within 1e-3, as
            // exporters' rounding gives, is normalised (unnormalised, the rotation matrix
            // would scale the node).
            let local = match node.transform() {
                gltf::scene::Transform::Decomposed {
                    translation,
                    rotation,
                    scale,
                } => {
                    let q = glam::DQuat::from_array(rotation.map(f64::from));
                    let length = q.length();
                    if !((length - 1.0).abs() <= 1e-3) {
                        return Err(self.error(format!(
                            "node {} has rotation {rotation:?}, which is not a unit quaternion \
                             (its length is {length:.4}; glTF requires 1)",
                            describe_node(&node)
                        )));
                    }
                    DMat4::from_scale_rotation_translation(
                        glam::DVec3::from_array(scale.map(f64::from)),
                        q / length,
                        glam::DVec3::from_array(translation.map(f64::from)),
                    )
                }
                transform => {
                    DMat4::from_cols_array_2d(&transform.matrix().map(|c| c.map(f64::from)))
                }
            };
            let global = parent * local;
            if let (None, Some(camera)) = (self.camera, node.camera()) {
                self.camera = self.camera(&camera, &node, &global);
            }
            if let Some(mesh) = node.mesh() {
                let object = soup.objects.len() as u32;
                soup.objects.push(object_name(&node, &mesh));
                // A radiosity export's surface polygon, in place of its triangles (the
                // mesh's one primitive, its material the scene's own colours).
                let polygon = match exported_polygon(&mesh) {
                    Some(Ok(p)) if mesh.primitives().len() == 1 => Some(p),
                    Some(Err(why)) => {
                        bad_polygons.push(format!("mesh {} ({why})", mesh.index()));
                        None
                    }
                    _ => None,
                };
                for prim in mesh.primitives() {
                    let material = match prim.material().index() {
                        Some(i) => i as u32,
                        None => {
                            // With COLOR_0 the faces get materials of their own.
                            default_used |= prim.get(&gltf::Semantic::Colors(0)).is_none();
                            default_material
                        }
                    };
                    let baked = matches!(self.baked.get(material as usize), Some(Some(_)));
                    if let Some(polygon) = polygon.as_ref().filter(|_| !baked) {
                        self.place_polygon(polygon, &node, &global, object, material, &mut soup)?;
                        triangles_total += polygon.len() - 2;
                        continue;
                    }
                    let n = self.primitive(
                        &prim,
                        &node,
                        &global,
                        object,
                        material,
                        &mut soup,
                        &mut counts,
                        triangles_total,
                    )?;
                    triangles_total += n;
                }
            }
            for child in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((child, global));
            }
        }
        if default_used {
            soup.materials.push(self.default_material());
        }
        let first_derived = soup.materials.len() as u32;
        for face in &mut soup.faces {
            if face.material & DERIVED != 0 {
                face.material = first_derived + (face.material & !DERIVED);
            }
        }
        soup.materials.append(&mut self.derived);
        if self.capped_faces > 0 {
            self.warn(format!(
                "{} face{} whose base colour times the mean of {} COLOR_0 is 1 or more in \
                 some band taken as reflectance {MAX_REFLECTANCE} there (a surface cannot \
                 reflect all the light it receives)",
                self.capped_faces,
                plural(self.capped_faces),
                if self.capped_faces == 1 {
                    "its"
                } else {
                    "their"
                }
            ));
        }
        if !bad_polygons.is_empty() {
            self.warn(format!(
                "{} mesh{} with an extras.radiosity.polygon that is not one (three or more \
                 corners of three finite numbers each) read from {} triangles instead: {}",
                bad_polygons.len(),
                if bad_polygons.len() == 1 { "" } else { "es" },
                if bad_polygons.len() == 1 {
                    "its"
                } else {
                    "their"
                },
                bad_polygons
                    .iter()
                    .take(3)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        if counts.converted > 0 {
            self.warn(format!(
                "{} triangle strip or fan primitive{} converted to triangles",
                counts.converted,
                plural(counts.converted)
            ));
        }
        if counts.no_area > 0 {
            self.warn(format!(
                "{} point or line primitive{} left out (they have no area to light)",
                counts.no_area,
                plural(counts.no_area)
            ));
        }
        if counts.leftover_indices > 0 {
            self.warn(format!(
                "{} trailing index{} that make no whole triangle left out",
                counts.leftover_indices,
                if counts.leftover_indices == 1 {
                    ""
                } else {
                    "es"
                }
            ));
        }
        Ok((soup, format))
    }

    /// Every primitive's POSITION names an accessor the file has (checked before the
    /// `gltf` crate's validation, which would index out of bounds).
    fn check_position_indices(&self, json: &gltf::json::Root) -> Result<(), ImportError> {
        let accessors = json.accessors.len();
        for (m, mesh) in json.meshes.iter().enumerate() {
            for (p, prim) in mesh.primitives.iter().enumerate() {
                let position = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
                if let Some(index) = prim.attributes.get(&position) {
                    if index.value() >= accessors {
                        return Err(self.error(format!(
                            "mesh {m} primitive {p}: POSITION names accessor {}, but the file \
                             has {accessors} accessors",
                            index.value()
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// The GLB header's length must be one the file can hold: the `gltf` crate subtracts
    /// the header's size from it without a check.
    fn check_glb_header(&self, bytes: &[u8]) -> Result<(), ImportError> {
        let Some(len) = bytes.get(8..12) else {
            return Err(self.error(format!(
                "binary glTF truncated: {} bytes, less than the 12 of its header",
                bytes.len()
            )));
        };
        let length = u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
        if length < 20 || length > bytes.len() {
            return Err(self.error(format!(
                "binary glTF header gives the length {length}, but the file has {} bytes (and \
                 the header and JSON chunk header need 20): truncated or corrupt",
                bytes.len()
            )));
        }
        Ok(())
    }

    /// The view of a camera node with global transform `global`: glTF's camera looks down
    /// its node's -z with +y up (glTF 2.0 specification, 3.10 "Cameras"), so the eye is the
    /// node's origin, the viewing direction its -z axis and the up its +y axis, all placed
    /// by the transform. `None`, with a warning, for an orthographic camera or one whose
    /// transform or field of view gives no view (not finite, or a field of view not
    /// strictly between 0 and 180 degrees); the next perspective camera is then looked at.
    fn camera(
        &mut self,
        camera: &gltf::Camera,
        node: &gltf::Node,
        global: &DMat4,
    ) -> Option<(DVec3, DVec3, DVec3, f64)> {
        let gltf::camera::Projection::Perspective(p) = camera.projection() else {
            self.warn(format!(
                "the orthographic camera of node {} ignored (the renderer's camera is a \
                 perspective one)",
                describe_node(node)
            ));
            return None;
        };
        let eye = global.transform_point3(DVec3::ZERO);
        let forward = global.transform_vector3(DVec3::NEG_Z).try_normalize();
        let up = global.transform_vector3(DVec3::Y).try_normalize();
        let fov_y_degrees = f64::from(p.yfov()).to_degrees();
        match (forward, up) {
            (Some(forward), Some(up))
                if eye.is_finite()
                    && fov_y_degrees > 0.0
                    && fov_y_degrees < 180.0
                    && forward.cross(up).length() > 1e-6 =>
            {
                Some((eye, forward, up, fov_y_degrees))
            }
            _ => {
                self.warn(format!(
                    "the camera of node {} ignored: its transform or field of view ({} \
                     degrees) gives no view",
                    describe_node(node),
                    fov_y_degrees
                ));
                None
            }
        }
    }

    /// The nodes the scene starts from.
    fn roots<'d>(&self, doc: &'d gltf::Document) -> Result<Vec<gltf::Node<'d>>, ImportError> {
        if let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) {
            return Ok(scene.nodes().collect());
        }
        let mut is_child = vec![false; doc.nodes().len()];
        for node in doc.nodes() {
            for child in node.children() {
                is_child[child.index()] = true;
            }
        }
        let roots: Vec<_> = doc.nodes().filter(|n| !is_child[n.index()]).collect();
        if roots.is_empty() && doc.nodes().len() > 0 {
            return Err(self.error(
                "every node is another node's child: the node hierarchy has a cycle".into(),
            ));
        }
        Ok(roots)
    }

    /// A buffer's bytes: the GLB's binary chunk, a `data:` URI, or a file beside this one.
    fn buffer(&self, buffer: &gltf::Buffer, blob: Option<&[u8]>) -> Result<Vec<u8>, ImportError> {
        let what = format!("buffer {}", buffer.index());
        let length = buffer.length();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    self.error(format!(
                        "{what} is the binary chunk, but the file has none (a .gltf file's \
                         buffers need a \"uri\")"
                    ))
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => self.uri_bytes(&what, uri, length)?,
        };
        if data.len() < length {
            // Where the bytes came from (QA pass 18 of #16: a file's was not named).
            let from = match buffer.source() {
                gltf::buffer::Source::Uri(uri) if !uri.starts_with("data:") => {
                    format!(" (read from \"{uri}\")")
                }
                _ => String::new(),
            };
            return Err(self.error(format!(
                "{what}{from} should hold {length} bytes (its byteLength) but has {}: truncated",
                data.len()
            )));
        }
        Ok(data)
    }

    /// The bytes a URI names: a base64 `data:` URI, or a file relative to this one's folder
    /// (of which at most `limit` bytes are read).
    fn uri_bytes(&self, what: &str, uri: &str, limit: usize) -> Result<Vec<u8>, ImportError> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let Some((_, payload)) = rest.split_once(";base64,") else {
                return Err(self.error(format!(
                    "{what}: a data URI must be base64 (\"data:...;base64,...\")"
                )));
            };
            return base64::engine::general_purpose::STANDARD
                .decode(payload.trim())
                .map_err(|e| self.error(format!("{what}: its data URI is not valid base64: {e}")));
        }
        let Some(dir) = self.dir else {
            return Err(self.error(format!(
                "{what} names the external file \"{uri}\", which cannot be read here"
            )));
        };
        let path = dir.join(percent_decode(uri));
        crate::io::note_input(&path);
        let opened = std::fs::File::open(&path).map_err(|e| ImportError::Io {
            what: "the file",
            file: path.display().to_string(),
            message: format!("{e} ({what} of {})", self.file),
        })?;
        let mut data = Vec::new();
        opened
            .take(limit as u64)
            .read_to_end(&mut data)
            .map_err(|e| ImportError::Io {
                what: "the file",
                file: path.display().to_string(),
                message: format!("{e} ({what} of {})", self.file),
            })?;
        Ok(data)
    }

    fn default_material(&mut self) -> SoupMaterial {
        self.warn(format!(
            "primitives without a material get glTF's default, white, whose reflectance 1 is \
             taken as {MAX_REFLECTANCE}"
        ));
        SoupMaterial {
            name: "(default material)".into(),
            reflectance: Rgb([MAX_REFLECTANCE; 3]),
            emission: Rgb([0.0; 3]),
            defined_at: None,
        }
    }

    fn material(
        &mut self,
        doc: &gltf::Document,
        m: &gltf::Material,
    ) -> Result<SoupMaterial, ImportError> {
        let name = m.name().map_or_else(
            || format!("material {}", m.index().unwrap_or(0)),
            str::to_string,
        );
        if let Some((reflectance, emission)) = self.scene_colours(&name, m)? {
            self.baked.push(None);
            self.lit.push(None);
            self.white.push(None);
            return Ok(SoupMaterial {
                name,
                reflectance: Rgb(reflectance),
                emission: Rgb(emission),
                defined_at: None,
            });
        }
        let pbr = m.pbr_metallic_roughness();
        let factor = pbr.base_color_factor();
        let mut reflectance = [0.0; 3];
        for (r, f) in reflectance.iter_mut().zip(factor) {
            *r = f64::from(f);
        }
        if let Some(info) = pbr.base_color_texture() {
            match self.texture_mean(doc, &info.texture()) {
                Ok(mean) => {
                    for (r, t) in reflectance.iter_mut().zip(mean) {
                        *r *= t;
                    }
                }
                Err(why) => self.warn(format!(
                    "material \"{name}\": its base-colour texture is left out ({why}); the \
                     reflectance is its baseColorFactor alone"
                )),
            }
        }
        if m.unlit() {
            // Baked light: what the surface shows is what it sends out.
            let s = self.exposure_scale;
            let emission = reflectance.map(|c| c / s);
            self.baked.push(Some(emission));
            self.lit.push(None);
            self.white.push(None);
            return Ok(SoupMaterial {
                name,
                reflectance: Rgb([0.0; 3]),
                emission: Rgb(emission),
                defined_at: None,
            });
        }
        self.baked.push(None);
        self.lit.push(Some(reflectance));
        if reflectance.iter().any(|&r| r >= 1.0) {
            self.white.push(Some(format!(
                "material \"{name}\": a base colour of 1 or more is taken as reflectance \
                 {MAX_REFLECTANCE} (a surface cannot reflect all the light it receives)"
            )));
            for r in &mut reflectance {
                *r = r.min(MAX_REFLECTANCE);
            }
        } else {
            self.white.push(None);
        }
        let strength = f64::from(m.emissive_strength().unwrap_or(1.0));
        let emission = m.emissive_factor().map(|e| f64::from(e) * strength);
        Ok(SoupMaterial {
            name,
            reflectance: Rgb(reflectance),
            emission: Rgb(emission),
            defined_at: None,
        })
    }

    /// The scene's own reflectance and emission where a radiosity export wrote them in the
    /// material's `extras.radiosity`; `None` where the material has no such extras.
    #[allow(clippy::type_complexity)]
    fn scene_colours(
        &self,
        name: &str,
        m: &gltf::Material,
    ) -> Result<Option<([f64; 3], [f64; 3])>, ImportError> {
        let Some(raw) = m.extras() else {
            return Ok(None);
        };
        let Ok(extras) = serde_json::from_str::<serde_json::Value>(raw.get()) else {
            return Ok(None);
        };
        let Some(colours) = extras.get("radiosity") else {
            return Ok(None);
        };
        let band = |key: &str| -> Result<[f64; 3], ImportError> {
            let value = &colours[key];
            let numbers: Option<Vec<f64>> = value
                .as_array()
                .map(|a| a.iter().map(serde_json::Value::as_f64).collect())
                .and_then(|v: Option<Vec<f64>>| v);
            match numbers.as_deref() {
                Some(&[r, g, b]) => Ok([r, g, b]),
                _ => Err(self.error(format!(
                    "material \"{name}\": extras.radiosity.{key} must be three numbers (red, \
                     green, blue), as `radiosity export` writes it; found {value}"
                ))),
            }
        };
        Ok(Some((band("reflectance")?, band("emission")?)))
    }

    /// The faces `polygons` (indices into the primitive's points, to which `remap` takes
    /// each of its vertices) of a lit primitive with vertex colours `colours` (per vertex,
    /// `None` where no triangle uses it): each face's reflectance is `base` times the mean
    /// of `COLOR_0` over its corners (a corner where vertices of several colours meet
    /// taking their mean), capped at [`MAX_REFLECTANCE`] (counted), a material of its own
    /// per distinct colour (derived from `material`, keeping its emission).
    #[allow(clippy::too_many_arguments)]
    fn coloured_faces(
        &mut self,
        polygons: &[Vec<u32>],
        colours: &[Option<[f64; 3]>],
        remap: &[u32],
        base: [f64; 3],
        material: u32,
        object: u32,
        soup: &mut FaceSoup,
        place: &str,
    ) {
        let points = remap
            .iter()
            .filter(|&&r| r != u32::MAX)
            .max()
            .map_or(0, |&m| m as usize + 1);
        let mut sum = vec![([0.0f64; 3], 0usize); points];
        for (k, c) in colours.iter().enumerate() {
            if let (Some(c), Some(&r)) = (c, remap.get(k)) {
                if r != u32::MAX {
                    let (s, n) = &mut sum[r as usize];
                    for (s, x) in s.iter_mut().zip(c) {
                        *s += x;
                    }
                    *n += 1;
                }
            }
        }
        let point_colour: Vec<[f64; 3]> = sum
            .iter()
            .map(|(s, n)| s.map(|x| x / (*n).max(1) as f64))
            .collect();
        let (name, emission) = match soup.materials.get(material as usize) {
            Some(m) => (m.name.clone(), m.emission),
            None => ("(default material)".to_string(), Rgb([0.0; 3])),
        };
        let base_index = soup.vertices.len() as u32;
        let mut made: HashMap<[u64; 3], u32> = HashMap::new();
        for poly in polygons {
            let mut mean = [0.0; 3];
            for &i in poly {
                for (m, x) in mean.iter_mut().zip(point_colour[i as usize]) {
                    *m += x / poly.len() as f64;
                }
            }
            let mut reflectance = [0, 1, 2].map(|b| base[b] * mean[b]);
            if reflectance.iter().any(|&r| r >= 1.0) {
                self.capped_faces += 1;
                reflectance = reflectance.map(|r| r.min(MAX_REFLECTANCE));
            }
            let key = reflectance.map(f64::to_bits);
            let face_material = *made.entry(key).or_insert_with(|| {
                self.derived.push(SoupMaterial {
                    name: format!("{name} x COLOR_0 ({place})"),
                    reflectance: Rgb(reflectance),
                    emission,
                    defined_at: None,
                });
                DERIVED | (self.derived.len() - 1) as u32
            });
            soup.faces.push(SoupFace {
                object,
                material: face_material,
                first: soup.indices.len(),
                count: poly.len() as u32,
                line: 0,
            });
            soup.indices.extend(poly.iter().map(|&i| base_index + i));
        }
    }

    /// A primitive's `COLOR_0` per vertex (RGB, alpha ignored; `None` at the vertices no
    /// triangle uses, `used` false), or `None` where it has none. Floats, and normalized
    /// unsigned bytes and shorts, as the specification allows.
    fn colours(
        &self,
        prim: &gltf::Primitive,
        place: &str,
        used: &[bool],
    ) -> Result<Option<Vec<Option<[f64; 3]>>>, ImportError> {
        let Some(acc) = prim.get(&gltf::Semantic::Colors(0)) else {
            return Ok(None);
        };
        let components = match acc.dimensions() {
            gltf::accessor::Dimensions::Vec3 => 3,
            gltf::accessor::Dimensions::Vec4 => 4,
            other => {
                return Err(self.error(format!(
                    "{place}: COLOR_0 (accessor {}) must be VEC3 or VEC4, found {other:?}",
                    acc.index()
                )))
            }
        };
        let (size, read): (usize, fn(&[u8]) -> f64) = match acc.data_type() {
            gltf::accessor::DataType::F32 => (4, |b| f32_at(b, 0)),
            gltf::accessor::DataType::U8 => (1, |b| f64::from(b[0]) / 255.0),
            gltf::accessor::DataType::U16 => {
                (2, |b| f64::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0)
            }
            other => {
                return Err(self.error(format!(
                    "{place}: COLOR_0 (accessor {}) must be floats or normalized unsigned \
                     bytes or shorts, found {other:?}",
                    acc.index()
                )))
            }
        };
        let elements = self.accessor_elements(&acc, size * components, "COLOR_0")?;
        if elements.len() < used.len() {
            return Err(self.error(format!(
                "{place}: COLOR_0 (accessor {}) has {} values for {} positions",
                acc.index(),
                elements.len(),
                used.len()
            )));
        }
        let mut out = Vec::with_capacity(used.len());
        for (e, &u) in elements.iter().zip(used) {
            if !u {
                out.push(None);
                continue;
            }
            let mut c = [0.0; 3];
            for (k, x) in c.iter_mut().enumerate() {
                *x = read(&e[k * size..]);
                if !x.is_finite() {
                    return Err(ImportError::NotFinite {
                        file: self.file.clone(),
                        line: 0,
                        element: format!("{place}, COLOR_0"),
                        value: *x,
                    });
                }
                if *x < 0.0 {
                    return Err(self.error(format!(
                        "{place}: COLOR_0 (accessor {}) holds {x}, below 0 (colours run from \
                         0 to 1)",
                        acc.index()
                    )));
                }
            }
            out.push(Some(c));
        }
        Ok(Some(out))
    }

    /// The mean of a primitive's `COLOR_0` over the vertices its triangles use (RGB; alpha
    /// ignored), or `None` where it has none. Floats, and normalized unsigned bytes and
    /// shorts, as the specification allows.
    fn colour_mean(
        &self,
        prim: &gltf::Primitive,
        place: &str,
        used: &[bool],
    ) -> Result<Option<[f64; 3]>, ImportError> {
        let Some(colours) = self.colours(prim, place, used)? else {
            return Ok(None);
        };
        let (mut sum, mut n) = ([0.0f64; 3], 0usize);
        for c in colours.iter().flatten() {
            for (s, x) in sum.iter_mut().zip(c) {
                *s += x;
            }
            n += 1;
        }
        Ok((n > 0).then(|| sum.map(|s| s / n as f64)))
    }

    /// The mean linear colour of a texture's image, or why it cannot be had. The image is
    /// looked at in the JSON: the `gltf` crate's `Image::source` panics on an image with
    /// neither a URI nor a buffer view and a MIME type.
    fn texture_mean(
        &self,
        doc: &gltf::Document,
        texture: &gltf::Texture,
    ) -> Result<[f64; 3], String> {
        let index = texture.source().index();
        let what = format!("image {index}");
        let json = &doc.as_json().images[index];
        let bytes = if let Some(view) = &json.buffer_view {
            let view = doc
                .views()
                .nth(view.value())
                .ok_or_else(|| format!("{what}: no buffer view {}", view.value()))?;
            self.view_bytes(&view).map_err(|e| e.to_string())?.to_vec()
        } else if let Some(uri) = &json.uri {
            // An image is never larger than the file format's 4 GiB; a local file is the
            // user's own.
            self.uri_bytes(&what, uri, u32::MAX as usize)
                .map_err(|e| e.to_string())?
        } else {
            return Err(format!("{what} has neither a uri nor a bufferView"));
        };
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes));
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(16_384);
        limits.max_image_height = Some(16_384);
        limits.max_alloc = Some(1 << 30);
        reader.limits(limits);
        let decoded = reader
            .with_guessed_format()
            .map_err(|e| format!("{what}: {e}"))?
            .decode()
            .map_err(|e| format!("{what}: {e}"))?
            .into_rgb8();
        let n = u64::from(decoded.width()) * u64::from(decoded.height());
        if n == 0 {
            return Err(format!("{what} has no pixels"));
        }
        let mut sum = [0.0f64; 3];
        for p in decoded.pixels() {
            for (s, &c) in sum.iter_mut().zip(&p.0) {
                *s += srgb_to_linear(f64::from(c) / 255.0);
            }
        }
        Ok(sum.map(|s| s / n as f64))
    }

    /// A buffer view's bytes.
    fn view_bytes(&self, view: &gltf::buffer::View) -> Result<&[u8], ImportError> {
        let data = &self.buffers[view.buffer().index()];
        let end = view.offset().checked_add(view.length());
        match end {
            Some(end) if end <= data.len() => Ok(&data[view.offset()..end]),
            _ => Err(self.error(format!(
                "buffer view {} runs from byte {} for {} bytes, past the end of buffer {} ({} \
                 bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                data.len()
            ))),
        }
    }

    /// An accessor's elements as raw bytes each `size` long, checked to fit its view.
    fn accessor_elements(
        &self,
        accessor: &gltf::Accessor,
        size: usize,
        what: &str,
    ) -> Result<Vec<&[u8]>, ImportError> {
        let index = accessor.index();
        if accessor.sparse().is_some() {
            return Err(self.error(format!(
                "accessor {index} ({what}) is sparse, which this reader does not support"
            )));
        }
        let Some(view) = accessor.view() else {
            return Err(self.error(format!(
                "accessor {index} ({what}) has no buffer view (its values would all be zero)"
            )));
        };
        let bytes = self.view_bytes(&view)?;
        let stride = view.stride().unwrap_or(size).max(size);
        let count = accessor.count();
        let offset = accessor.offset();
        check_count(
            &self.file,
            0,
            &format!("accessor {index} ({what})"),
            count as u64,
            stride as u64,
            (bytes.len().saturating_sub(offset) + stride - size) as u64,
        )?;
        let mut out = Vec::with_capacity(count);
        for k in 0..count {
            let start = offset + k * stride;
            let Some(e) = bytes.get(start..start + size) else {
                return Err(self.error(format!(
                    "accessor {index} ({what}): element {k} runs past the end of buffer view {}",
                    view.index()
                )));
            };
            out.push(e);
        }
        Ok(out)
    }

    /// A radiosity export's surface polygon (`extras.radiosity.polygon`), placed by the
    /// node's transform (its order turned where the transform mirrors), as one face.
    fn place_polygon(
        &mut self,
        polygon: &[DVec3],
        node: &gltf::Node,
        global: &DMat4,
        object: u32,
        material: u32,
        soup: &mut FaceSoup,
    ) -> Result<(), ImportError> {
        let mut placed = Vec::with_capacity(polygon.len());
        for (k, p) in polygon.iter().enumerate() {
            let q = global.transform_point3(*p);
            if !q.is_finite() {
                return Err(ImportError::NotFinite {
                    file: self.file.clone(),
                    line: 0,
                    element: format!(
                        "node {}, extras.radiosity.polygon corner {k} ({p}) placed by the \
                         node's transform",
                        describe_node(node)
                    ),
                    value: q
                        .to_array()
                        .into_iter()
                        .find(|x| !x.is_finite())
                        .unwrap_or(f64::NAN),
                });
            }
            placed.push(q);
        }
        if global.determinant() < 0.0 {
            placed.reverse();
        }
        let base = soup.vertices.len() as u32;
        soup.faces.push(SoupFace {
            object,
            material,
            first: soup.indices.len(),
            count: placed.len() as u32,
            line: 0,
        });
        soup.indices
            .extend((0..placed.len() as u32).map(|i| base + i));
        soup.vertices.extend(placed);
        Ok(())
    }

    /// One primitive's triangles into the soup; returns how many.
    #[allow(clippy::too_many_arguments)]
    fn primitive(
        &mut self,
        prim: &gltf::Primitive,
        node: &gltf::Node,
        global: &DMat4,
        object: u32,
        material: u32,
        soup: &mut FaceSoup,
        counts: &mut Counts,
        triangles_so_far: usize,
    ) -> Result<usize, ImportError> {
        let mode = prim.mode();
        if matches!(
            mode,
            Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
        ) {
            counts.no_area += 1;
            return Ok(0);
        }
        let place = format!("node {} primitive {}", describe_node(node), prim.index());
        let Some(positions) = prim.get(&gltf::Semantic::Positions) else {
            return Err(self.error(format!("{place} has no POSITION attribute")));
        };
        if positions.data_type() != gltf::accessor::DataType::F32
            || positions.dimensions() != gltf::accessor::Dimensions::Vec3
        {
            return Err(self.error(format!(
                "{place}: POSITION (accessor {}) must be VEC3 of 32-bit floats, found {:?} of \
                 {:?} (quantized positions are not supported)",
                positions.index(),
                positions.dimensions(),
                positions.data_type()
            )));
        }
        let raw = self.accessor_elements(&positions, 12, "POSITION")?;
        let vertex_count = raw.len();
        let indices: Vec<u32> = match prim.indices() {
            None => (0..vertex_count as u32).collect(),
            Some(acc) => {
                if acc.dimensions() != gltf::accessor::Dimensions::Scalar {
                    return Err(self.error(format!(
                        "{place}: indices (accessor {}) must be SCALAR",
                        acc.index()
                    )));
                }
                let (size, read): (usize, fn(&[u8]) -> u32) = match acc.data_type() {
                    gltf::accessor::DataType::U8 => (1, |b| u32::from(b[0])),
                    gltf::accessor::DataType::U16 => {
                        (2, |b| u32::from(u16::from_le_bytes([b[0], b[1]])))
                    }
                    gltf::accessor::DataType::U32 => {
                        (4, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                    }
                    other => {
                        return Err(self.error(format!(
                            "{place}: indices (accessor {}) must be unsigned bytes, shorts or \
                             ints, found {other:?}",
                            acc.index()
                        )))
                    }
                };
                let elements = self.accessor_elements(&acc, size, "indices")?;
                let mut out = Vec::with_capacity(elements.len());
                for (k, e) in elements.into_iter().enumerate() {
                    let i = read(e);
                    if i as usize >= vertex_count {
                        return Err(ImportError::BadIndex {
                            file: self.file.clone(),
                            line: 0,
                            element: format!("{place}, index {k}"),
                            index: i64::from(i),
                            count: vertex_count,
                        });
                    }
                    out.push(i);
                }
                out
            }
        };
        let mut triangles: Vec<[u32; 3]> = match mode {
            Mode::Triangles => {
                counts.leftover_indices += indices.len() % 3;
                indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect()
            }
            Mode::TriangleStrip => {
                counts.converted += 1;
                (0..indices.len().saturating_sub(2))
                    .map(|i| {
                        if i % 2 == 0 {
                            [indices[i], indices[i + 1], indices[i + 2]]
                        } else {
                            [indices[i + 1], indices[i], indices[i + 2]]
                        }
                    })
                    .collect()
            }
            Mode::TriangleFan => {
                counts.converted += 1;
                (1..indices.len().saturating_sub(1))
                    .map(|i| [indices[i], indices[i + 1], indices[0]])
                    .collect()
            }
            _ => Vec::new(),
        };
        if triangles_so_far.saturating_add(triangles.len()) > MAX_TRIANGLES {
            return Err(self.error(format!(
                "{place}: the scene would have more than {MAX_TRIANGLES} triangles once every \
                 node's mesh is placed; split it or simplify it"
            )));
        }
        // The points the triangles use, placed; the same point given twice (a vertex
        // repeated per face for its normals or UVs) made one so that the triangles can be
        // joined. Unused points are not kept (a mesh placed by many nodes costs its
        // triangles, which are bounded, not its vertex list).
        let mut unique: HashMap<[u64; 3], u32> = HashMap::new();
        let mut remap = vec![u32::MAX; vertex_count];
        let base = soup.vertices.len() as u32;
        let mut points: Vec<DVec3> = Vec::new();
        let mirrored = global.determinant() < 0.0;
        for t in &mut triangles {
            for i in t.iter_mut() {
                let k = *i as usize;
                if remap[k] == u32::MAX {
                    let e = raw[k];
                    let p = DVec3::new(f32_at(e, 0), f32_at(e, 4), f32_at(e, 8));
                    let placed = global.transform_point3(p);
                    if !placed.is_finite() {
                        return Err(ImportError::NotFinite {
                            file: self.file.clone(),
                            line: 0,
                            element: format!(
                                "{place}, POSITION {k} ({p}) placed by the node's transform"
                            ),
                            value: placed
                                .to_array()
                                .into_iter()
                                .find(|x| !x.is_finite())
                                .unwrap_or(f64::NAN),
                        });
                    }
                    let key = placed.to_array().map(f64::to_bits);
                    remap[k] = *unique.entry(key).or_insert_with(|| {
                        points.push(placed);
                        (points.len() - 1) as u32
                    });
                }
                *i = remap[k];
            }
            if mirrored {
                t.swap(1, 2);
            }
        }
        let n = triangles.len();
        // Lit (a file's material, or the default one placed after them) or not, before a
        // baked material is swapped for one of its own below.
        let lit = match self.lit.get(material as usize) {
            Some(&base) => base,
            None => Some([1.0; 3]),
        };
        let mut material = material;
        if let Some(&Some(emission)) = self.baked.get(material as usize) {
            // Baked light with vertex colours: the colours' mean multiplies the material's
            // emission, for this primitive alone (a material of its own).
            let used: Vec<bool> = remap.iter().map(|&r| r != u32::MAX).collect();
            if let Some(mean) = self.colour_mean(prim, &place, &used)? {
                let base = &soup.materials[material as usize];
                let derived = SoupMaterial {
                    name: format!("{} ({place})", base.name),
                    reflectance: base.reflectance,
                    emission: Rgb([0, 1, 2].map(|k| emission[k] * mean[k])),
                    defined_at: None,
                };
                material = DERIVED | self.derived.len() as u32;
                self.derived.push(derived);
            }
        }
        let polygons = join_coplanar(&points, &triangles);
        if let Some(base) = lit {
            let used: Vec<bool> = remap.iter().map(|&r| r != u32::MAX).collect();
            if let Some(colours) = self.colours(prim, &place, &used)? {
                self.coloured_faces(
                    &polygons, &colours, &remap, base, material, object, soup, &place,
                );
                soup.vertices.extend(points);
                return Ok(n);
            }
            // Without COLOR_0: the material as it is, its cap told once.
            if let Some(Some(w)) = self.white.get_mut(material as usize).map(Option::take) {
                self.warn(w);
            }
        }
        for poly in polygons {
            soup.faces.push(SoupFace {
                object,
                material,
                first: soup.indices.len(),
                count: poly.len() as u32,
                line: 0,
            });
            soup.indices.extend(poly.iter().map(|&i| base + i));
        }
        soup.vertices.extend(points);
        Ok(n)
    }
}

/// The scene camera for a glTF camera at `eye` (scaled as the scene is) looking along the
/// unit `forward`: it looks at the point that far along as the centre of the scene's
/// bounds (1 unit along for an empty scene or one centred on the eye; only the direction
/// matters to the view).
fn camera_hint(
    scene: &crate::scene::Scene,
    eye: DVec3,
    forward: DVec3,
    up: DVec3,
    fov_y_degrees: f64,
) -> crate::scene::CameraHint {
    let (lo, hi) = scene.bounds();
    let distance = (0.5 * (lo + hi) - eye).length();
    let distance = if distance.is_finite() && distance > 0.0 {
        distance
    } else {
        1.0
    };
    crate::scene::CameraHint {
        eye,
        look_at: eye + forward * distance,
        up,
        fov_y_degrees,
    }
}

/// The exposure scale a radiosity export applied to its `COLOR_0`
/// (`asset.extras.radiosity.exposureScale`, finite and positive), else 1.
fn exposure_scale(doc: &gltf::Document) -> f64 {
    doc.as_json()
        .asset
        .extras
        .as_ref()
        .and_then(|raw| serde_json::from_str::<serde_json::Value>(raw.get()).ok())
        .and_then(|v| v["radiosity"]["exposureScale"].as_f64())
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or(1.0)
}

/// The largest polygon `extras.radiosity.polygon` may give (the scene format's polygons
/// are meshed into at most this many corners' worth of triangles; a larger one is taken
/// as malformed).
const MAX_POLYGON_CORNERS: usize = 4096;

/// A mesh's `extras.radiosity.polygon` as a radiosity export writes it (the surface's
/// corners, in the mesh's coordinates): `None` where the mesh has none, an error in words
/// where it has one that is not a polygon.
fn exported_polygon(mesh: &gltf::Mesh) -> Option<Result<Vec<DVec3>, String>> {
    let raw = mesh.extras().as_ref()?;
    let extras: serde_json::Value = serde_json::from_str(raw.get()).ok()?;
    let polygon = extras.get("radiosity")?.get("polygon")?;
    let Some(corners) = polygon.as_array() else {
        return Some(Err("not an array".into()));
    };
    if corners.len() < 3 || corners.len() > MAX_POLYGON_CORNERS {
        return Some(Err(format!(
            "{} corners, not 3 to {MAX_POLYGON_CORNERS}",
            corners.len()
        )));
    }
    let mut out = Vec::with_capacity(corners.len());
    for (k, c) in corners.iter().enumerate() {
        let xyz: Option<Vec<f64>> = c
            .as_array()
            .and_then(|a| a.iter().map(serde_json::Value::as_f64).collect());
        match xyz.as_deref() {
            Some(&[x, y, z]) if x.is_finite() && y.is_finite() && z.is_finite() => {
                out.push(DVec3::new(x, y, z));
            }
            _ => return Some(Err(format!("corner {k} is {c}"))),
        }
    }
    Some(Ok(out))
}

/// The meshing settings a radiosity export wrote (`asset.extras.radiosity.meshSettings`:
/// `maxPatchArea` > 0 and finite, `integralSteps` a whole number of at least 1), if it did.
fn exported_settings(doc: &gltf::Document) -> Option<MeshSettings> {
    let raw = doc.as_json().asset.extras.as_ref()?;
    let v: serde_json::Value = serde_json::from_str(raw.get()).ok()?;
    let m = &v["radiosity"]["meshSettings"];
    let max_patch_area = m["maxPatchArea"]
        .as_f64()
        .filter(|a| a.is_finite() && *a > 0.0)?;
    let integral_steps = m["integralSteps"]
        .as_u64()
        .filter(|&k| k >= 1)
        .and_then(|k| u32::try_from(k).ok())?;
    Some(MeshSettings {
        max_patch_area,
        integral_steps,
    })
}

/// How many triangles the nodes under `roots` ask for, from their accessors' counts,
/// before anything is read (each node counted once; cycles are the walk's to report).
fn planned_triangles(doc: &gltf::Document, roots: &[gltf::Node]) -> usize {
    let mut seen = vec![false; doc.nodes().len()];
    let mut stack: Vec<gltf::Node> = roots.to_vec();
    let mut total = 0usize;
    while let Some(node) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            continue;
        }
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let count = match (prim.indices(), prim.get(&gltf::Semantic::Positions)) {
                    (Some(i), _) => i.count(),
                    (None, Some(p)) => p.count(),
                    (None, None) => 0,
                };
                total = total.saturating_add(match prim.mode() {
                    Mode::Triangles => count / 3,
                    Mode::TriangleStrip | Mode::TriangleFan => count.saturating_sub(2),
                    _ => 0,
                });
            }
        }
        stack.extend(node.children());
    }
    total
}

fn f32_at(bytes: &[u8], at: usize) -> f64 {
    f64::from(f32::from_le_bytes([
        bytes[at],
        bytes[at + 1],
        bytes[at + 2],
        bytes[at + 3],
    ]))
}

fn describe_node(node: &gltf::Node) -> String {
    match node.name() {
        Some(name) => format!("{} (\"{name}\")", node.index()),
        None => node.index().to_string(),
    }
}

fn object_name(node: &gltf::Node, mesh: &gltf::Mesh) -> String {
    node.name()
        .or_else(|| mesh.name())
        .map_or_else(|| format!("node {}", node.index()), str::to_string)
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// The sRGB transfer function undone: a texel's stored value to linear.
fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// `%XX` escapes in a relative URI decoded (glTF's URIs are percent-encoded).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            if let Some(v) = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
            {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
#[path = "gltf_tests.rs"]
mod tests;
