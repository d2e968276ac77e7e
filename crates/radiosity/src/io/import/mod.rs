//! Scenes from the files other tools write, chosen by the file's extension and converted to
//! a [`Scene`] the rest of the library works on.
//!
//! [`read_any_scene`] reads a scene file of any supported format:
//!
//! | extension | format | reader |
//! | --- | --- | --- |
//! | `.scene` | the paper's Appendix A format | [`crate::io::scene_file`] |
//! | `.obj` | Wavefront OBJ with its MTL materials | [`obj`] |
//! | `.gltf`, `.glb` | glTF 2.0 | [`gltf`] |
//! | `.dxf` | AutoCAD DXF (ASCII) with a `.materials.toml` side file | [`dxf`] |
//! | `.wrl` | VRML97 | [`vrml`] |
//!
//! Every importer other than the scene file's reads its file into a [`FaceSoup`] (named
//! objects, faces as lists of indices into one vertex array, a material per face) and
//! converts it with [`FaceSoup::to_scene`], which is where the rules common to every
//! format live:
//!
//! * each face becomes one planar convex [`Surface`](crate::scene::Surface) when it is one
//!   (within the scene reader's planarity tolerance, and flattened as the reader does);
//!   a face that is not planar or not convex is triangulated (ear clipping, `earcutr`, on
//!   its best-fit plane; each triangle keeps the face's own corners, so it is exactly
//!   planar, and is wound to face the way the face did);
//! * degenerate faces (fewer than three distinct corners, zero area, too small to use)
//!   are dropped with one [`ImportWarning`] that counts them and names the first few;
//! * a face that repeats another exactly (same polygon, facing the same way) is dropped with
//!   a warning, where the scene reader refuses the file;
//! * coordinates that are not finite, beyond [`crate::geometry::MAX_COORDINATE`] after
//!   scaling, vertex indices out of range, and materials outside the ranges of the scene
//!   format (reflectance in [0, 1), emission >= 0) are errors naming the file and the
//!   element (and the line, for text formats);
//! * surfaces are named after their object: the object's name when it gives one surface,
//!   `NAME.0`, `NAME.1`, ... in file order when it gives several.
//!
//! Faces of one object become separate surfaces, and the mesher gives every surface its
//! own vertices (see [`crate::mesh`]); the shading joins them again:
//! [`crate::shade::smooth_objects`] gives the vertices where facets of one object (`NAME.k`)
//! meet at less than [`crate::shade::CREASE_DEGREES`] one value, so a tessellated sphere's
//! radiosity interpolates smoothly. The renderer's per-pixel direct light is gathered on
//! each facet's own plane, so bands of the facets' orientation remain in it (README,
//! "Importing scenes").
//!
//! # Units and settings
//!
//! [`ImportOptions::scale`] multiplies every coordinate read (for a `.scene` file too,
//! whose `MAX_PATCH_AREA` is then multiplied by the square of the scale so that it meshes
//! the same). [`Imported::unit`] says in words what one scene unit is. Formats other than
//! the scene file carry no meshing settings: unless [`ImportOptions::settings`] gives them,
//! an imported scene gets [`default_settings`].
//!
//! # Adding a format
//!
//! A reader is a function `read(path: &Path, options: &ImportOptions) -> Result<Imported,
//! ImportError>` in its own module here, called from [`read_any_scene`]; it builds a
//! [`FaceSoup`], calls [`FaceSoup::to_scene`], and adds its own warnings. Counts read from
//! a binary file are checked with [`check_count`] before anything is allocated for them.

pub mod dxf;
mod face_soup;
pub mod gltf;
mod merge;
pub mod obj;
mod tessellate;
pub mod vrml;

use std::fmt;
use std::path::Path;

use thiserror::Error;

pub(crate) use face_soup::triangulate;
pub use face_soup::{FaceSoup, SoupFace, SoupMaterial};

use crate::geometry;
use crate::io::scene_file::{read_scene, SceneError, SceneFile};
use crate::light::Rgb;
use crate::mesh::MeshSettings;
use crate::scene::{EmissionGiven, Scene};

/// The extensions [`read_any_scene`] knows, as a message lists them.
pub const EXTENSIONS: &str = ".scene, .obj, .gltf, .glb, .dxf or .wrl";

/// How to read a file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImportOptions {
    /// Every coordinate read is multiplied by this (> 0, finite): 0.001 reads a model in
    /// millimetres as metres.
    pub scale: f64,
    /// The meshing settings for formats that carry none (every format but the scene
    /// file); [`default_settings`] when `None`. A `.scene` file's own settings are kept.
    pub settings: Option<MeshSettings>,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            scale: 1.0,
            settings: None,
        }
    }
}

/// The formats [`read_any_scene`] tells apart by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// `.scene`: the paper's Appendix A format.
    Scene,
    /// `.obj`: Wavefront OBJ (with MTL).
    Obj,
    /// `.gltf`: glTF 2.0, JSON.
    Gltf,
    /// `.glb`: glTF 2.0, binary.
    Glb,
    /// `.dxf`: AutoCAD DXF.
    Dxf,
    /// `.wrl`: VRML97.
    Vrml,
}

impl Format {
    /// The format named by `path`'s extension (case-insensitive), if it is one of
    /// [`EXTENSIONS`].
    pub fn of_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "scene" => Format::Scene,
            "obj" => Format::Obj,
            "gltf" => Format::Gltf,
            "glb" => Format::Glb,
            "dxf" => Format::Dxf,
            "wrl" => Format::Vrml,
            _ => return None,
        })
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Scene => "scene (Appendix A)",
            Format::Obj => "OBJ",
            Format::Gltf => "glTF",
            Format::Glb => "binary glTF (.glb)",
            Format::Dxf => "DXF",
            Format::Vrml => "VRML97",
        })
    }
}

/// A scene read from a file, with what the reader has to say about it.
#[derive(Clone, Debug, PartialEq)]
pub struct Imported {
    /// The scene and its meshing settings.
    pub file: SceneFile,
    /// What was repaired or left out (degenerate faces dropped, a missing material file),
    /// for the caller to show.
    pub warnings: Vec<ImportWarning>,
    /// What one scene unit is, in words: "metres (a .scene file states no unit; metres
    /// assumed)", "metres (OBJ states no unit; metres assumed)", ...; with
    /// [`ImportOptions::scale`] not 1, metres made of the file's numbers ([`scaled_unit`]).
    pub unit: String,
    /// The format the file was read as.
    pub format: Format,
}

/// Something a reader repaired or left out. Displays as `FILE:LINE: warning: MESSAGE`
/// (`FILE: warning: MESSAGE` when `line` is 0).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImportWarning {
    /// The file it is about.
    pub file: String,
    /// The line, counting from 1; 0 for the file as a whole or a binary format.
    pub line: usize,
    /// What happened.
    pub message: String,
}

impl fmt::Display for ImportWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: warning: {}",
            location(&self.file, self.line),
            self.message
        )
    }
}

/// `FILE:LINE`, or `FILE` when the line is 0.
fn location(file: &str, line: usize) -> String {
    if line == 0 {
        file.to_string()
    } else {
        format!("{file}:{line}")
    }
}

/// The most errors of one imported file kept to be named one by one; the rest are
/// counted.
pub const MAX_IMPORT_ERRORS: usize = 20;

impl ImportError {
    /// The file and line an error names, where it names a line.
    fn place(&self) -> Option<(&str, usize)> {
        match self {
            ImportError::Syntax { file, line, .. }
            | ImportError::BadIndex { file, line, .. }
            | ImportError::NotFinite { file, line, .. }
            | ImportError::OutOfRange { file, line, .. }
            | ImportError::BadMaterial { file, line, .. }
            | ImportError::TooLarge { file, line, .. } => Some((file, *line)),
            _ => None,
        }
    }

    /// `errors` (at most [`MAX_IMPORT_ERRORS`] kept) and `more` not kept, as one error: the
    /// only one, or [`ImportError::Several`]; `None` where there are none.
    pub fn from_several(mut errors: Vec<ImportError>, more: usize) -> Option<ImportError> {
        // File by file, line by line, as the README promises (QA pass 18 of #16: an MTL
        // file's errors came between the OBJ's, as found): the reading file first, then the
        // files it reads, each in the order first met. The sort is stable, so errors
        // without a line keep their place among their file's.
        let mut files: Vec<String> = Vec::new();
        for e in &errors {
            if let Some((file, _)) = e.place() {
                if !files.iter().any(|f| f == file) {
                    files.push(file.to_string());
                }
            }
        }
        errors.sort_by_key(|e| match e.place() {
            Some((file, line)) => (files.iter().position(|f| f == file).unwrap_or(0), line),
            None => (0, 0),
        });
        match (errors.len(), more) {
            (0, _) => None,
            (1, 0) => errors.pop(),
            _ => Some(ImportError::Several { errors, more }),
        }
    }
}

/// Why a file could not be read as a scene. Every variant displays as
/// `FILE[:LINE]: error: ...` naming what in the file is wrong, like the scene reader's
/// [`SceneError`] (which a `.scene` file gives, as [`ImportError::Scene`]).
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ImportError {
    /// A `.scene` file's errors.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Several errors of one file (and the files it reads), each on its own line, then
    /// their count; at most [`MAX_IMPORT_ERRORS`] are kept.
    #[error("{}\n{} errors{}", errors.iter().map(ToString::to_string).collect::<Vec<_>>().join("\n"),
        errors.len() + more, if *more > 0 { format!(" (the first {} shown)", errors.len()) } else { String::new() })]
    Several {
        /// The errors, in the order found.
        errors: Vec<ImportError>,
        /// How many more there were.
        more: usize,
    },
    /// The file cannot be read.
    #[error("{file}: error: cannot read {what}: {message}")]
    Io {
        /// The file.
        file: String,
        /// What the file is ("the scene file", "the materials file", "the file" for a
        /// glTF's buffer or image, named in the message), as the
        /// `.scene` reader's "cannot read the scene file" says (QA of issue #16).
        what: &'static str,
        /// The system's reason.
        message: String,
    },
    /// The path names a folder.
    #[error("{file}: error: this is a folder, not a scene file: expected {EXTENSIONS}")]
    Folder {
        /// The folder.
        file: String,
    },
    /// The extension is none of [`EXTENSIONS`].
    #[error(
        "{file}: error: cannot tell the scene format from {}: expected {EXTENSIONS}",
        if extension.is_empty() { "a name with no extension".to_string() }
        else { format!("the extension \"{extension}\"") }
    )]
    UnknownFormat {
        /// The file.
        file: String,
        /// Its extension ("" when it has none).
        extension: String,
    },
    /// A format this build does not read yet.
    #[error(
        "{file}: error: reading {format} files is not supported yet; convert the model to \
         OBJ or to the .scene format"
    )]
    NotSupportedYet {
        /// The file.
        file: String,
        /// Its format.
        format: Format,
    },
    /// The scale is not a positive finite number.
    #[error("error: the scale must be a positive finite number, found {scale}")]
    BadScale {
        /// The scale given.
        scale: f64,
    },
    /// A line or element that does not follow the format's grammar.
    #[error("{}: error: {message}", location(file, *line))]
    Syntax {
        /// The file.
        file: String,
        /// The line, counting from 1; 0 for a binary format.
        line: usize,
        /// What was found and what was expected.
        message: String,
    },
    /// A face names a vertex the file does not have (before it, in an OBJ: the count is
    /// of the vertices that can be named there, not of the file's; QA of issue #16).
    #[error(
        "{}: error: {element}: vertex index {index} is out of range ({count} vertices can be \
         named there)",
        location(file, *line)
    )]
    BadIndex {
        /// The file.
        file: String,
        /// The line, counting from 1; 0 for a binary format.
        line: usize,
        /// The face, in words ("face 3 of object \"Box\"").
        element: String,
        /// The index: as written in the file when the format's reader finds it (OBJ counts
        /// from 1); counting from 0 when the shared conversion does.
        index: i64,
        /// How many vertices there are.
        count: usize,
    },
    /// A coordinate that is not a finite number.
    #[error("{}: error: {element}: the coordinate {value} is not a finite number", location(file, *line))]
    NotFinite {
        /// The file.
        file: String,
        /// The line, counting from 1; 0 for a binary format.
        line: usize,
        /// The vertex, in words.
        element: String,
        /// The value read.
        value: f64,
    },
    /// A coordinate (after scaling) beyond [`geometry::MAX_COORDINATE`].
    #[error(
        "{}: error: {element}: the coordinate {value:e} (after scaling) is beyond the \
         largest the program supports ({:e} in magnitude); scale the scene down",
        location(file, *line), geometry::MAX_COORDINATE
    )]
    OutOfRange {
        /// The file.
        file: String,
        /// The line, counting from 1; 0 for a binary format.
        line: usize,
        /// The vertex or surface, in words.
        element: String,
        /// The scaled coordinate.
        value: f64,
    },
    /// A material whose colours the scene format cannot hold.
    #[error("{}: error: material \"{name}\": {message}", location(file, *line))]
    BadMaterial {
        /// The file (the material file, for OBJ).
        file: String,
        /// The line, counting from 1; 0 for a binary format.
        line: usize,
        /// The material's name.
        name: String,
        /// What is wrong and what would do.
        message: String,
    },
    /// A count in the file larger than the file could hold.
    #[error(
        "{}: error: {what} says {count} items, more than the {available} bytes left in the \
         file can hold (the file is truncated or corrupt)",
        location(file, *line)
    )]
    TooLarge {
        /// The file.
        file: String,
        /// The line, counting from 1; 0 for a binary format.
        line: usize,
        /// The element holding the count, in words.
        what: String,
        /// The count.
        count: u64,
        /// The bytes that could hold it.
        available: u64,
    },
    /// No face was left to make a surface of.
    #[error(
        "{file}: error: no usable faces: the file has {faces} {}{}",
        if *faces == 1 { "face" } else { "faces" },
        match *faces {
            0 => String::new(),
            1 => ", and it is degenerate (zero area or fewer than 3 distinct corners)".to_string(),
            _ => format!(", all {faces} degenerate (zero area or fewer than 3 distinct corners)"),
        }
    )]
    NoSurfaces {
        /// The file.
        file: String,
        /// How many faces it has (all dropped).
        faces: usize,
    },
}

/// Refuses a count read from a file before anything is allocated for it: `count` items of
/// at least `bytes_each` bytes each must fit in the `available` bytes of the file left
/// ([`ImportError::TooLarge`] otherwise).
pub fn check_count(
    file: &str,
    line: usize,
    what: &str,
    count: u64,
    bytes_each: u64,
    available: u64,
) -> Result<(), ImportError> {
    if count.saturating_mul(bytes_each.max(1)) <= available {
        return Ok(());
    }
    Err(ImportError::TooLarge {
        file: file.to_string(),
        line,
        what: what.to_string(),
        count,
        available,
    })
}

/// Reads the scene at `path`, in the format its extension names (case-insensitive):
/// see the [module documentation](self).
pub fn read_any_scene(path: &Path, options: &ImportOptions) -> Result<Imported, ImportError> {
    if !(options.scale > 0.0 && options.scale.is_finite()) {
        return Err(ImportError::BadScale {
            scale: options.scale,
        });
    }
    let file = path.display().to_string();
    if path.is_dir() {
        return Err(ImportError::Folder { file });
    }
    let Some(format) = Format::of_path(path) else {
        return Err(ImportError::UnknownFormat {
            file,
            extension: path
                .extension()
                .map_or(String::new(), |e| format!(".{}", e.to_string_lossy())),
        });
    };
    match format {
        Format::Scene => read_scene_scaled(path, options.scale),
        Format::Obj => obj::read(path, options),
        Format::Gltf | Format::Glb => gltf::read(path, options),
        Format::Vrml => vrml::read(path, options),
        Format::Dxf => dxf::read(path, options),
    }
}

/// `unit`, or when `scale` is not 1, metres with what they were made of: a scale is given
/// to bring a model's numbers to metres (0.001 for millimetres), and lux and areas in m^2
/// take the scaled numbers as metres (QA of issue #16: "metres x 0.001" beside "square
/// units (see unit)" left the unit of every figure to be worked out).
pub fn scaled_unit(unit: &str, scale: f64) -> String {
    if scale == 1.0 {
        unit.to_string()
    } else {
        format!("metres = the file's numbers x {scale}; unscaled, {unit}")
    }
}

/// The length unit of a `.scene` file: the format states none, and lengths are taken as
/// metres (what point luminaires' I / d^2 and `FLUX` over an area need for lux), as an OBJ's
/// are (QA of issue #16: it was "scene units" beside a README that said metres).
pub const SCENE_FILE_UNIT: &str = "metres (a .scene file states no unit; metres assumed)";

/// A `.scene` file, scaled: every coordinate (the camera and the point luminaires too)
/// times `scale`, `MAX_PATCH_AREA` times its square, so that the scene meshes into the same
/// elements, and a `FLUX` block's exitance over its scaled area, so that it emits the same
/// lumens (the same room in millimetres with `--scale 0.001` gives the same lux).
fn read_scene_scaled(path: &Path, scale: f64) -> Result<Imported, ImportError> {
    let mut file = read_scene(path)?;
    if scale != 1.0 {
        let name = path.display().to_string();
        for s in &mut file.scene.surfaces {
            for v in &mut s.vertices {
                *v *= scale;
            }
            if let Err(e) = geometry::validate_polygon(&s.vertices) {
                let element = format!("surface \"{}\"", s.name);
                return Err(match e {
                    geometry::PolygonError::OutOfRange { value, .. }
                    | geometry::PolygonError::NotFinite { value, .. } => ImportError::OutOfRange {
                        file: name,
                        line: 0,
                        element,
                        value,
                    },
                    e => ImportError::Syntax {
                        file: name,
                        line: 0,
                        message: format!("{element}, scaled by {scale}: {e}"),
                    },
                });
            }
        }
        if let Some(c) = &mut file.scene.camera {
            c.eye *= scale;
            c.look_at *= scale;
        }
        // Point luminaires stand where the scaled surfaces are (their candela and lumens
        // do not depend on lengths).
        for light in &mut file.scene.lights {
            light.position *= scale;
        }
        // A FLUX was spread over the areas as written: the same lumens over areas scale^2
        // times as large (exitance in lm/m^2 of the scaled lengths). Er Eg Eb and LUMINANCE
        // are per unit area of the scaled scene already (lm/m^2, cd/m^2).
        for s in &mut file.scene.surfaces {
            match s.photometry.emission {
                EmissionGiven::Flux(p) => {
                    s.emission = Rgb::splat(p / geometry::polygon_area(&s.vertices));
                }
                EmissionGiven::FluxShare => s.emission = s.emission * (1.0 / (scale * scale)),
                EmissionGiven::Exitance | EmissionGiven::Luminance(_) => {}
            }
        }
        file.settings.max_patch_area *= scale * scale;
    }
    Ok(Imported {
        file,
        warnings: Vec::new(),
        unit: scaled_unit(SCENE_FILE_UNIT, scale),
        format: Format::Scene,
    })
}

/// The meshing settings an imported scene gets when none are given: `MAX_PATCH_AREA` the
/// scene's total area / 1000 (so about a thousand elements or more: every surface larger
/// than that is cut, smaller ones are kept whole) and `INTEGRAL_STEPS` 2, as the built-in
/// Cornell box has.
pub fn default_settings(scene: &Scene) -> MeshSettings {
    let area = scene.total_area();
    MeshSettings {
        max_patch_area: if area > 0.0 && area.is_finite() {
            area / 1000.0
        } else {
            1.0
        },
        integral_steps: 2,
    }
}

#[cfg(test)]
mod tests;
