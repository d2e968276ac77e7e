//! Wavefront OBJ with its MTL material files.
//!
//! # What is read
//!
//! * `v x y z` vertices (`v x y z w` is divided by `w`; the colours of `v x y z r g b` are
//!   ignored);
//! * `f` faces of any number of corners, each corner `v`, `v/vt`, `v//vn` or `v/vt/vn`
//!   (only `v` is used), counting from 1, or back from the last vertex read when negative;
//! * `o` and `g` names: a face belongs to the object named by the last `o` or `g` line
//!   before it (its surfaces are named after it, see [`super`]); `default` before any;
//! * `mtllib` files (relative to the OBJ's folder) and `usemtl`: in each material,
//!   `Kd r [g b]` is the reflectance and `Ke r [g b]` the emission (an exitance, in the
//!   scene's emission units, as `Er Eg Eb` in the scene format). A material without `Kd`
//!   reflects 0.5 in each band, one without `Ke` emits nothing.
//!
//! `Kd` must be at least 0 and below 1 in every band, as the scene format's reflectance:
//! a material with `Kd 1 1 1` is refused (naming the MTL file and line), not clamped or
//! scaled, since either would change the light in the scene without saying so.
//!
//! # What is ignored
//!
//! Texture coordinates and normals (`vt`, `vn`), smoothing groups (`s`), points and lines
//! (`p`, `l`: no area), free-form geometry (`curv`, `surf`, ...), and every other MTL
//! statement (`Ka`, `Ks`, `Ns`, `d`, `illum`, texture maps). Statements other than those read
//! or listed are counted in one warning; an MTL file's texture maps get one of their own. A missing MTL file, or a `usemtl` naming a material
//! none of them has, gives a warning and the default grey (reflectance 0.5).
//!
//! OBJ states no unit: the numbers are taken as metres, times
//! [`ImportOptions::scale`](super::ImportOptions::scale).
//!
//! # Meshing settings
//!
//! OBJ has no place for them; `radiosity export -o out.obj` writes the scene's as comment
//! lines `# MAX_PATCH_AREA a` and `# INTEGRAL_STEPS n`, and this reader takes them back
//! (a comment with exactly that keyword first and one valid value; `a` in the file's
//! units squared, so scaled with the coordinates), so that scene -> OBJ -> scene keeps
//! the meshing. A setting the file does not give is [`super::default_settings`]'s, and
//! [`ImportOptions::settings`](super::ImportOptions::settings) overrides both.
//!
//! # Why not the `tobj` crate
//!
//! tobj 4.0 (MIT) was looked at first: its `LoadError` (e.g. "face vertex index out of
//! bounds") carries neither line nor element, so it cannot say where a file is wrong, and it
//! reads coordinates as `f32` unless built with a feature (the Cornell box's 548.8 mm
//! becomes 548.7999878), which would keep an OBJ from giving the scene file's solution.
//! The subset above is a few hundred lines, reports every problem at its line, and
//! allocates only in proportion to the file's lines.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;

use super::face_soup::{material_problem, MaterialField};
use super::{
    default_settings, scaled_unit, FaceSoup, Format, ImportError, ImportOptions, ImportWarning,
    Imported, SoupFace, SoupMaterial, MAX_IMPORT_ERRORS,
};
use crate::io::scene_file::SceneFile;
use crate::light::Rgb;
use crate::mesh::MeshSettings;

/// The reflectance of a face without a material, or whose material is missing.
pub const DEFAULT_REFLECTANCE: f64 = 0.5;

/// The unit an OBJ file is read in.
const UNIT: &str = "metres (OBJ states no unit; metres assumed)";

/// Gives an MTL file's name for messages and its text, from the name a `mtllib` line
/// gives, or why it cannot be read.
pub type MtlLoader<'a> = dyn FnMut(&str) -> Result<(String, String), String> + 'a;

/// Reads the OBJ file at `path` and the MTL files it names.
pub fn read(path: &Path, options: &ImportOptions) -> Result<Imported, ImportError> {
    let file = path.display().to_string();
    crate::io::note_input(path);
    let bytes = std::fs::read(path).map_err(|e| ImportError::Io {
        what: "the scene file",
        file: file.clone(),
        message: e.to_string(),
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut loader = |name: &str| {
        let p = folder.join(name);
        crate::io::note_input(&p);
        std::fs::read(&p)
            .map(|b| {
                (
                    p.display().to_string(),
                    String::from_utf8_lossy(&b).into_owned(),
                )
            })
            .map_err(|e| e.to_string())
    };
    parse(&text, &file, options, &mut loader)
}

/// Reads OBJ text; `load_mtl` gives an MTL file's name for messages and its text, from the
/// name a `mtllib` line gives, or why it cannot be read. The fuzz target calls this with
/// a loader that finds nothing.
pub fn parse(
    text: &str,
    file: &str,
    options: &ImportOptions,
    load_mtl: &mut MtlLoader,
) -> Result<Imported, ImportError> {
    let mut reader = Reader {
        soup: FaceSoup {
            file: file.to_string(),
            ..FaceSoup::default()
        },
        library: HashMap::new(),
        used: HashMap::new(),
        objects: HashMap::new(),
        object: None,
        material: None,
        warnings: Vec::new(),
        ignored: HashMap::new(),
        missing: Vec::new(),
        max_patch_area: None,
        integral_steps: None,
        errors: Vec::new(),
        more_errors: 0,
        bad_materials: std::collections::HashSet::new(),
        faces_read: 0,
    };
    for (i, raw) in text.lines().enumerate() {
        if let Err(e) = reader.line(i + 1, raw, load_mtl) {
            reader.report(e);
        }
    }
    let errors = std::mem::take(&mut reader.errors);
    if let Some(e) = ImportError::from_several(errors, reader.more_errors) {
        return Err(e);
    }
    let Reader {
        soup,
        mut warnings,
        ignored,
        missing,
        max_patch_area,
        integral_steps,
        ..
    } = reader;
    if soup.faces.is_empty() {
        return Err(ImportError::NoSurfaces {
            file: file.to_string(),
            faces: 0,
        });
    }
    let (scene, more) = soup.to_scene(options.scale)?;
    if !missing.is_empty() {
        let names: Vec<String> = missing
            .iter()
            .map(|(n, l)| format!("\"{n}\" (line {l})"))
            .collect();
        warnings.push(ImportWarning {
            file: file.to_string(),
            line: 0,
            message: format!(
                "no material file defines {}: {} given the default reflectance {DEFAULT_REFLECTANCE}",
                names.join(", "),
                if missing.len() == 1 { "its faces are" } else { "their faces are" }
            ),
        });
    }
    if !ignored.is_empty() {
        let mut kinds: Vec<(&String, &usize)> = ignored.iter().collect();
        kinds.sort();
        let list: Vec<String> = kinds.iter().map(|(k, n)| format!("{n} \"{k}\"")).collect();
        warnings.push(ImportWarning {
            file: file.to_string(),
            line: 0,
            message: format!(
                "ignored statements this reader does not use: {}",
                list.join(", ")
            ),
        });
    }
    warnings.extend(more);
    let settings = options.settings.unwrap_or_else(|| {
        let defaults = default_settings(&scene);
        MeshSettings {
            // In the file's units, as the scene file's: scaled with the coordinates.
            // (A product that leaves the f64 range falls back to the default.)
            max_patch_area: max_patch_area
                .map(|a| a * options.scale * options.scale)
                .filter(|a| *a > 0.0 && a.is_finite())
                .unwrap_or(defaults.max_patch_area),
            integral_steps: integral_steps.unwrap_or(defaults.integral_steps),
        }
    });
    Ok(Imported {
        file: SceneFile { settings, scene },
        warnings,
        unit: scaled_unit(UNIT, options.scale),
        format: Format::Obj,
    })
}

/// One material of an MTL file as written.
#[derive(Clone)]
struct MtlEntry {
    file: String,
    line: usize,
    kd: Option<(Rgb, usize)>,
    ke: Option<(Rgb, usize)>,
}

struct Reader {
    soup: FaceSoup,
    /// Every material the MTL files define, by name.
    library: HashMap<String, MtlEntry>,
    /// The soup's index of each material used so far, by name.
    used: HashMap<String, u32>,
    /// The soup's index of each object name.
    objects: HashMap<String, u32>,
    object: Option<u32>,
    material: Option<u32>,
    warnings: Vec<ImportWarning>,
    /// Statements ignored, by keyword, with counts.
    ignored: HashMap<String, usize>,
    /// `usemtl` names no MTL file defines, with the first line naming each.
    missing: Vec<(String, usize)>,
    /// The meshing settings in `# MAX_PATCH_AREA a` and `# INTEGRAL_STEPS n` comments.
    max_patch_area: Option<f64>,
    integral_steps: Option<u32>,
    /// The errors found so far, in the OBJ and its MTL files (each reported, and the
    /// reading goes on: QA pass 14 of #16 found four, one a run): the first
    /// [`MAX_IMPORT_ERRORS`], and how many more.
    errors: Vec<ImportError>,
    more_errors: usize,
    /// Materials whose `usemtl` was an error: named once, not at every use.
    bad_materials: std::collections::HashSet<String>,
    /// Face lines read so far.
    faces_read: usize,
}

/// Statements read silently for what they are: ignored by design (see the module
/// documentation) and not worth a warning.
const QUIET: [&str; 4] = ["vt", "vn", "s", "vp"];

impl Reader {
    /// A comment line `# MAX_PATCH_AREA a` or `# INTEGRAL_STEPS n` (as `radiosity export
    /// -o out.obj` writes them) gives that meshing setting; a value that is not one is left
    /// out with a warning (it is a comment: the file is still good OBJ). Other comments
    /// are comments.
    fn setting_comment(&mut self, n: usize, comment: &str) {
        let mut words = comment.split_whitespace();
        let (key, value) = (words.next(), words.next());
        let extra = words.next().is_some();
        let problem = match key {
            Some("MAX_PATCH_AREA") => match value.and_then(|v| v.parse::<f64>().ok()) {
                Some(a) if a > 0.0 && a.is_finite() && !extra => {
                    self.max_patch_area = Some(a);
                    return;
                }
                _ => "MAX_PATCH_AREA needs one number greater than 0 (e.g. \"# MAX_PATCH_AREA 1000\")",
            },
            Some("INTEGRAL_STEPS") => match value.and_then(|v| v.parse::<u32>().ok()) {
                Some(k) if k >= 1 && !extra => {
                    self.integral_steps = Some(k);
                    return;
                }
                _ => "INTEGRAL_STEPS needs one whole number of at least 1 (e.g. \"# INTEGRAL_STEPS 2\")",
            },
            _ => return,
        };
        self.warnings.push(ImportWarning {
            file: self.soup.file.clone(),
            line: n,
            message: format!(
                "the comment \"#{}\" is left out: {problem}; the default is used",
                comment.trim_end()
            ),
        });
    }

    /// Keeps `e` among the first [`MAX_IMPORT_ERRORS`], or counts it.
    fn report(&mut self, e: ImportError) {
        if self.errors.len() < MAX_IMPORT_ERRORS {
            self.errors.push(e);
        } else {
            self.more_errors += 1;
        }
    }

    fn syntax(&self, line: usize, message: String) -> ImportError {
        ImportError::Syntax {
            file: self.soup.file.clone(),
            line,
            message,
        }
    }

    fn line(&mut self, n: usize, raw: &str, load_mtl: &mut MtlLoader) -> Result<(), ImportError> {
        if let Some(comment) = raw.trim_start().strip_prefix('#') {
            self.setting_comment(n, comment);
            return Ok(());
        }
        let code = raw.split('#').next().unwrap_or("");
        let mut words = code.split_whitespace();
        let Some(key) = words.next() else {
            return Ok(());
        };
        let rest = || code.trim_start().get(key.len()..).unwrap_or("").trim();
        match key {
            "v" => {
                let read = self.vertex(n, words.collect());
                if read.is_err() && self.soup.vertices.len() < u32::MAX as usize {
                    // A stand-in, so that the faces after it name the vertices they mean
                    // (the file is refused anyway).
                    self.soup.vertices.push(DVec3::ZERO);
                    self.soup.vertex_lines.push(n);
                }
                read
            }
            "f" | "fo" => self.face(n, words),
            "o" | "g" => {
                let name = rest().to_string();
                let name = if name.is_empty() {
                    "default".to_string()
                } else {
                    name
                };
                let next = self.soup.objects.len() as u32;
                let index = *self.objects.entry(name.clone()).or_insert_with(|| {
                    self.soup.objects.push(name);
                    next
                });
                self.object = Some(index);
                Ok(())
            }
            "usemtl" => {
                let name = rest().to_string();
                if self.bad_materials.contains(&name) {
                    return Ok(());
                }
                match self.use_material(&name, n) {
                    Ok(m) => {
                        self.material = Some(m);
                        Ok(())
                    }
                    Err(problems) => {
                        self.bad_materials.insert(name);
                        for e in problems {
                            self.report(e);
                        }
                        Ok(())
                    }
                }
            }
            "mtllib" => {
                for name in words {
                    match load_mtl(name) {
                        Ok((mtl_file, text)) => {
                            let read = self.read_mtl(&mtl_file, &text);
                            // QA pass 16 of #16: `mtllib /etc/passwd` was read without a
                            // word, every `usemtl` of it then missing.
                            if read.materials == 0 {
                                let what = if read.mtl_lines == 0 {
                                    "is not an MTL file (no line starts with an MTL \
                                     keyword such as newmtl, Kd or Ke), so it defines no \
                                     materials"
                                        .to_string()
                                } else {
                                    "defines no materials (no \"newmtl\" line)".to_string()
                                };
                                self.warnings.push(ImportWarning {
                                    file: self.soup.file.clone(),
                                    line: n,
                                    message: format!(
                                        "the material file \"{name}\"{} {what}; faces \
                                         whose material is not defined get the default \
                                         reflectance {DEFAULT_REFLECTANCE}",
                                        if mtl_file == name {
                                            String::new()
                                        } else {
                                            format!(" ({mtl_file})")
                                        }
                                    ),
                                });
                            }
                        }
                        Err(why) => self.warnings.push(ImportWarning {
                            file: self.soup.file.clone(),
                            line: n,
                            message: format!(
                                "cannot read the material file \"{name}\" ({why}): its \
                                 materials get the default reflectance {DEFAULT_REFLECTANCE}"
                            ),
                        }),
                    }
                }
                Ok(())
            }
            k if QUIET.contains(&k) => Ok(()),
            k => {
                // Bounded: at most one entry per distinct keyword, each at most a line long;
                // a file of distinct junk words is counted under one key.
                let key = if self.ignored.len() < 32 { k } else { "other" };
                *self.ignored.entry(key.to_string()).or_insert(0) += 1;
                Ok(())
            }
        }
    }

    fn vertex(&mut self, n: usize, words: Vec<&str>) -> Result<(), ImportError> {
        if !matches!(words.len(), 3 | 4 | 6 | 7) {
            return Err(self.syntax(
                n,
                format!(
                    "a vertex needs 3 coordinates (\"v x y z\", optionally a w or an r g b \
                     colour after them), found {} numbers",
                    words.len()
                ),
            ));
        }
        let mut xyzw = [0.0, 0.0, 0.0, 1.0];
        let count = if words.len() == 4 { 4 } else { 3 };
        for (k, w) in words.iter().take(count).enumerate() {
            xyzw[k] = w.parse::<f64>().map_err(|_| {
                self.syntax(
                    n,
                    format!(
                        "expected a number for the {} coordinate of the vertex, found \"{w}\"",
                        ["x", "y", "z", "w"][k]
                    ),
                )
            })?;
        }
        for w in words.iter().skip(count) {
            if w.parse::<f64>().is_err() {
                return Err(self.syntax(
                    n,
                    format!("expected a number for the vertex colour, found \"{w}\""),
                ));
            }
        }
        let element = || format!("vertex {}", self.soup.vertices.len() + 1);
        for value in xyzw {
            if !value.is_finite() {
                return Err(ImportError::NotFinite {
                    file: self.soup.file.clone(),
                    line: n,
                    element: element(),
                    value,
                });
            }
        }
        if xyzw[3] == 0.0 {
            return Err(self.syntax(
                n,
                format!("{}: its weight w is 0 (a point at infinity)", element()),
            ));
        }
        if self.soup.vertices.len() >= u32::MAX as usize {
            return Err(self.syntax(n, "more than 4294967295 vertices".into()));
        }
        let w = xyzw[3];
        self.soup
            .vertices
            .push(DVec3::new(xyzw[0] / w, xyzw[1] / w, xyzw[2] / w));
        self.soup.vertex_lines.push(n);
        Ok(())
    }

    fn face<'a>(
        &mut self,
        n: usize,
        words: impl Iterator<Item = &'a str>,
    ) -> Result<(), ImportError> {
        let object = match self.object {
            Some(o) => o,
            None => {
                self.soup.objects.push("default".into());
                let o = self.soup.objects.len() as u32 - 1;
                self.objects.insert("default".into(), o);
                self.object = Some(o);
                o
            }
        };
        let material = match self.material {
            Some(m) => m,
            None => {
                let m = self.default_material();
                self.material = Some(m);
                m
            }
        };
        let first = self.soup.indices.len();
        // Counted over every face line, refused ones too, so that the numbers after a bad
        // face still name the faces of the file (review of QA pass 14).
        self.faces_read += 1;
        let face_number = self.faces_read;
        let count = self.soup.vertices.len();
        for word in words {
            let v = word.split('/').next().unwrap_or("");
            let element = || {
                format!(
                    "face {face_number} of object \"{}\"",
                    self.soup.objects[object as usize]
                )
            };
            let Ok(index) = v.parse::<i64>() else {
                return Err(self.syntax(
                    n,
                    format!(
                        "{}: expected a vertex index (a whole number, optionally followed by \
                         /TEXTURE/NORMAL) for a corner, found \"{word}\"",
                        element()
                    ),
                ));
            };
            // 1 .. count forwards, -1 .. -count back from the last vertex read.
            let resolved = match index {
                i if i > 0 && (i as u64) <= count as u64 => Some(i as u64 - 1),
                i if i < 0 && i.unsigned_abs() <= count as u64 => {
                    Some(count as u64 - i.unsigned_abs())
                }
                _ => None,
            };
            let Some(resolved) = resolved else {
                return Err(ImportError::BadIndex {
                    file: self.soup.file.clone(),
                    line: n,
                    element: element(),
                    index,
                    count,
                });
            };
            self.soup.indices.push(resolved as u32);
        }
        let corners = self.soup.indices.len() - first;
        self.soup.faces.push(SoupFace {
            object,
            material,
            first,
            count: u32::try_from(corners).unwrap_or(u32::MAX),
            line: n,
        });
        Ok(())
    }

    fn default_material(&mut self) -> u32 {
        *self.used.entry(String::new()).or_insert_with(|| {
            self.soup.materials.push(SoupMaterial {
                name: "(none)".into(),
                reflectance: Rgb([DEFAULT_REFLECTANCE; 3]),
                emission: Rgb([0.0; 3]),
                defined_at: None,
            });
            self.soup.materials.len() as u32 - 1
        })
    }

    /// The soup's material for `usemtl name` at line `n`: checked on first use, every bad
    /// colour of it reported (QA pass 16 of #16: a `Kd 1 1 1` hid the `Ke -1 0 0` on the
    /// next line until it was fixed), each at its own line.
    fn use_material(&mut self, name: &str, n: usize) -> Result<u32, Vec<ImportError>> {
        if let Some(&m) = self.used.get(name) {
            return Ok(m);
        }
        let Some(entry) = self.library.get(name).cloned() else {
            if self.missing.len() < 1000 && !self.missing.iter().any(|(m, _)| m == name) {
                self.missing.push((name.to_string(), n));
            }
            let m = self.default_material();
            self.used.insert(name.to_string(), m);
            return Ok(m);
        };
        let bad = |line: usize, message: String| ImportError::BadMaterial {
            file: entry.file.clone(),
            line,
            name: name.to_string(),
            message,
        };
        let mut problems = Vec::new();
        let reflectance = entry.kd.map_or(Rgb([DEFAULT_REFLECTANCE; 3]), |(c, _)| c);
        let mut reflectance_bad = false;
        if let Some((c, line)) = entry.kd {
            if let Some((band, v)) = bands(&c).find(|(_, v)| !(0.0..1.0).contains(v)) {
                reflectance_bad = true;
                problems.push(bad(
                    line,
                    format!(
                        "Kd (the reflectance) is {v} in the {band} band; it must be at least 0 \
                         and below 1 in every band (a surface cannot reflect all the light it \
                         receives): edit the line to values below 1, such as 0.8"
                    ),
                ));
            }
        }
        let emission = entry.ke.map_or(Rgb([0.0; 3]), |(c, _)| c);
        let mut emission_bad = false;
        if let Some((c, line)) = entry.ke {
            if let Some((band, v)) = bands(&c).find(|(_, v)| *v < 0.0) {
                emission_bad = true;
                problems.push(bad(
                    line,
                    format!("Ke (the emission) is {v} in the {band} band; it must be at least 0"),
                ));
            }
        }
        // The soup's own check (an emission past MAX_EMISSION) at the line of the colour it
        // names, not at `newmtl` (QA pass 13 of #16: "kd.mtl:1" for a Ke on line 3); a
        // colour already refused above stands in as a good one, so it is not said twice and
        // the other is still checked.
        let checked = (
            if reflectance_bad {
                Rgb([DEFAULT_REFLECTANCE; 3])
            } else {
                reflectance
            },
            if emission_bad {
                Rgb([0.0; 3])
            } else {
                emission
            },
        );
        if let Some((field, message)) = material_problem(checked.0, checked.1) {
            let line = match field {
                MaterialField::Reflectance => entry.kd.map(|(_, l)| l),
                MaterialField::Emission => entry.ke.map(|(_, l)| l),
            };
            problems.push(bad(line.unwrap_or(entry.line), message));
        }
        if !problems.is_empty() {
            return Err(problems);
        }
        self.soup.materials.push(SoupMaterial {
            name: name.to_string(),
            reflectance,
            emission,
            defined_at: Some((entry.file.clone(), entry.line)),
        });
        let m = self.soup.materials.len() as u32 - 1;
        self.used.insert(name.to_string(), m);
        Ok(m)
    }

    /// Adds the materials of one MTL file to the library (a later definition of a name
    /// replaces an earlier one, as in the file); says how many it defined and how many of
    /// its lines were MTL statements.
    fn read_mtl(&mut self, file: &str, text: &str) -> MtlRead {
        let mut read = MtlRead {
            materials: 0,
            mtl_lines: 0,
        };
        let mut current: Option<String> = None;
        // Texture maps, by keyword, with the first line of each: said in one warning, as a
        // material's colour in a map is lost (QA of issue #16: map_Kd went without a word).
        let mut maps: Vec<(String, usize)> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let n = i + 1;
            let code = raw.split('#').next().unwrap_or("");
            let mut words = code.split_whitespace();
            let Some(key) = words.next() else { continue };
            if MTL_KEYWORDS.contains(&key) || key.starts_with("map_") {
                read.mtl_lines += 1;
            }
            let syntax = |message: String| ImportError::Syntax {
                file: file.to_string(),
                line: n,
                message,
            };
            match key {
                "newmtl" => {
                    read.materials += 1;
                    let name = code.trim_start().get(key.len()..).unwrap_or("").trim();
                    self.library.insert(
                        name.to_string(),
                        MtlEntry {
                            file: file.to_string(),
                            line: n,
                            kd: None,
                            ke: None,
                        },
                    );
                    current = Some(name.to_string());
                }
                "Kd" | "Ke" => {
                    let Some(entry) = current.as_ref().and_then(|c| self.library.get_mut(c)) else {
                        self.report(syntax(format!("{key} before any \"newmtl\" line")));
                        continue;
                    };
                    let values: Vec<&str> = words.collect();
                    let Some(colour) = colour(&values) else {
                        self.report(syntax(format!(
                            "expected \"{key} r g b\" (or \"{key} v\" for a grey) with finite \
                             numbers, found \"{}\"",
                            code.trim()
                        )));
                        continue;
                    };
                    if key == "Kd" {
                        entry.kd = Some((colour, n));
                    } else {
                        entry.ke = Some((colour, n));
                    }
                }
                k if k.starts_with("map_") => {
                    if maps.len() < 32 && !maps.iter().any(|(m, _)| m == k) {
                        maps.push((k.to_string(), n));
                    }
                }
                _ => {}
            }
        }
        if let Some(&(_, first)) = maps.first() {
            let names: Vec<&str> = maps.iter().map(|(m, _)| m.as_str()).collect();
            self.warnings.push(ImportWarning {
                file: file.to_string(),
                line: first,
                message: format!(
                    "texture maps are not read ({}): each face takes its material's Kd, or the \
                     default reflectance {DEFAULT_REFLECTANCE} where it has none; give Kd the \
                     texture's mean colour",
                    names.join(", ")
                ),
            });
        }
        read
    }
}

/// What [`Reader::read_mtl`] found in one MTL file.
struct MtlRead {
    /// `newmtl` lines.
    materials: usize,
    /// Lines that start with an MTL keyword ([`MTL_KEYWORDS`], or a `map_` texture): none
    /// in a file that is not an MTL file at all.
    mtl_lines: usize,
}

/// The statements of the MTL format (Wavefront's, with the common PBR extensions), by
/// which a file is known to be one.
const MTL_KEYWORDS: [&str; 22] = [
    "newmtl",
    "Ka",
    "Kd",
    "Ks",
    "Ke",
    "Kt",
    "Tf",
    "Ns",
    "Ni",
    "d",
    "Tr",
    "illum",
    "sharpness",
    "bump",
    "disp",
    "decal",
    "refl",
    "Pr",
    "Pm",
    "Ps",
    "Pc",
    "aniso",
];

/// `r g b`, or one value for all three; every number finite.
fn colour(values: &[&str]) -> Option<Rgb> {
    let numbers: Vec<f64> = values
        .iter()
        .map(|v| v.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()?;
    match numbers[..] {
        [v] => Some(Rgb([v; 3])),
        [r, g, b] => Some(Rgb([r, g, b])),
        _ => None,
    }
}

fn bands(c: &Rgb) -> impl Iterator<Item = (&'static str, f64)> + '_ {
    ["red", "green", "blue"]
        .into_iter()
        .zip(c.0.iter().copied())
}

#[cfg(test)]
#[path = "obj_tests.rs"]
mod tests;
