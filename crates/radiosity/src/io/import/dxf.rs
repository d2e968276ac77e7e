//! AutoCAD DXF (ASCII), the format the paper weighed beside VRML (section 3.2), with a
//! TOML side file for the colours DXF does not carry.
//!
//! Written here by hand, not with the `dxf` crate (0.6): that crate has no `MESH` entity,
//! brings chrono, uuid, num and an image decoder for the five entities read here, and its
//! hand-written parts hold some 150 `unwrap`s and indexings whose safety on a hostile file
//! would have to be audited; a DXF file is a flat list of group-code/value line pairs, and
//! the subset below reads it with every count checked and every error at its line.
//!
//! What is read (from the `ENTITIES` section, and the `BLOCKS` that `INSERT`s name):
//!
//! * `3DFACE`: three or four corners (a fourth equal to the third makes a triangle);
//! * polyface meshes: `POLYLINE` with flag 64, its position `VERTEX`es (flag 192) and face
//!   records (flag 128, corners 71 to 74 counting from 1, negative for an invisible edge);
//! * `MESH` (AcDbSubDMesh): its vertices (92, then 10/20/30) and face list (93, then 90s:
//!   a corner count and that many vertex indices counting from 0), at subdivision level
//!   0 (the control cage);
//! * `INSERT`: a block placed at 10/20/30 (in the insert's object coordinate system, from
//!   its extrusion 210/220/230 by the arbitrary axis algorithm), rotated by 50 (degrees),
//!   scaled by 41/42/43, the block's base point 10/20/30 at the insertion point, and
//!   repeated in a grid of 70 columns by 71 rows spaced 44 and 45; blocks may insert
//!   blocks (a block that inserts itself, directly or not, is refused); entities on layer
//!   `0` in a block take the inserting entity's layer, as in AutoCAD;
//! * the header's `$INSUNITS`, which the unit reported names (coordinates are not
//!   converted: `--scale` does that).
//!
//! A face's corners are taken as counter-clockwise seen from its front (DXF gives a face
//! no front); an insert that mirrors turns the winding so that the front stays the front.
//! Each layer is one object: its surfaces are named after the layer (`Floor`, or
//! `Floor.0`, `Floor.1`, ... when it has several).
//!
//! # The materials file
//!
//! DXF has no reflectance or emission, so a TOML file beside the drawing gives them per
//! layer: for `room.dxf`, `room.materials.toml`:
//!
//! ```toml
//! # Reflectance per band in [0, 1); emission (exitance, the scene's emission units) >= 0,
//! # 0 when not given.
//! [layers.Floor]
//! reflectance = [0.5, 0.5, 0.5]
//!
//! [layers.Light]
//! reflectance = [0.78, 0.78, 0.78]
//! emission = [53.4, 37.7, 12.6]
//!
//! # Optional: for every layer not listed above.
//! [default]
//! reflectance = [0.5, 0.5, 0.5]
//! ```
//!
//! A layer with faces that the file does not list, when it has no `[default]`, is an
//! error that lists every layer the drawing has; so is a missing materials file.
//!
//! Ignored: every other entity (lines, arcs, circles, `SOLID`, `LWPOLYLINE`, 3D polygon
//! meshes (`POLYLINE` flag 16), text, dimensions, `3DSOLID` ACIS bodies; counted in a
//! warning), attributes, colours and line types, `MESH` creases and subdivision, and
//! binary DXF (refused with a message).

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};
use serde::Deserialize;

use super::face_soup::{material_problem, MaterialField};
use super::{
    check_count, default_settings, scaled_unit, FaceSoup, Format, ImportError, ImportOptions,
    ImportWarning, Imported, SoupFace, SoupMaterial,
};
use crate::io::scene_file::SceneFile;
use crate::light::Rgb;

/// How deeply blocks may insert blocks.
pub const MAX_INSERT_DEPTH: usize = 32;

/// The most faces the scene may have once every insert is placed.
pub const MAX_FACES: usize = 2_000_000;

/// The most block placements (each INSERT, and each cell of an INSERT's grid, once per
/// placement of the block holding it): blocks that insert a block twice, nested k deep,
/// ask for 2^k even when they hold no face.
pub const MAX_PLACEMENTS: usize = 1_000_000;

/// The materials file of a drawing: `room.dxf` -> `room.materials.toml`.
pub fn materials_path(dxf: &Path) -> PathBuf {
    dxf.with_extension("materials.toml")
}

/// Reads the DXF file at `path` with its materials file ([`materials_path`]).
pub fn read(path: &Path, options: &ImportOptions) -> Result<Imported, ImportError> {
    let file = path.display().to_string();
    crate::io::note_input(path);
    let bytes = std::fs::read(path).map_err(|e| ImportError::Io {
        what: "the scene file",
        file: file.clone(),
        message: e.to_string(),
    })?;
    let side = materials_path(path);
    let side_name = side.display().to_string();
    crate::io::note_input(&side);
    let materials = match std::fs::read(&side) {
        Ok(b) => Some(String::from_utf8(b).map_err(|_| ImportError::Syntax {
            file: side_name.clone(),
            line: 0,
            message: "the materials file is not UTF-8 text".into(),
        })?),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(e) => {
            return Err(ImportError::Io {
                what: "the materials file",
                file: side_name,
                message: e.to_string(),
            })
        }
    };
    parse(&file, &bytes, &side_name, materials.as_deref(), options)
}

/// Reads DXF from `bytes` (named `file` in messages) with the materials file's text
/// `materials` (named `materials_file`; `None` when there is none).
pub fn parse(
    file: &str,
    bytes: &[u8],
    materials_file: &str,
    materials: Option<&str>,
    options: &ImportOptions,
) -> Result<Imported, ImportError> {
    let syntax = |line: usize, message: String| ImportError::Syntax {
        file: file.to_string(),
        line,
        message,
    };
    if bytes.starts_with(b"AutoCAD Binary DXF") {
        return Err(syntax(
            0,
            "a binary DXF file, which this reader does not read; save the drawing as ASCII DXF"
                .into(),
        ));
    }
    let text = String::from_utf8_lossy(bytes);
    let pairs = pairs(file, &text)?;
    let drawing = Drawing::read(file, &pairs)?;
    let mut builder = Builder {
        file: file.to_string(),
        drawing: &drawing,
        faces: Vec::new(),
        layers: Vec::new(),
        layer_index: HashMap::new(),
        stack: Vec::new(),
        placements: 0,
    };
    for e in &drawing.entities {
        builder.entity(e, &DMat4::IDENTITY, None)?;
    }
    // No face at all: said before the materials file is asked for (QA of issue #16: a
    // drawing of lines asked for a materials file for its layers with faces, of which it
    // had none).
    if builder.faces.is_empty() {
        let left_out: Vec<String> = drawing
            .ignored
            .iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect();
        return Err(syntax(
            0,
            format!(
                "no usable faces: the drawing has no 3DFACE, polyface mesh or MESH{}",
                match left_out.is_empty() {
                    true => String::new(),
                    false => format!(
                        " (its entities, which give no faces: {})",
                        left_out.join(", ")
                    ),
                }
            ),
        ));
    }
    let table = materials
        .map(|t| MaterialsFile::parse(materials_file, t))
        .transpose()?;
    let mut warnings = drawing.warnings(file);
    if let Some(table) = &table {
        warnings.extend(table.unused_layers(materials_file, file, &builder.layers));
    }
    let soup = builder.soup(materials_file, table.as_ref())?;
    let (scene, mut more) = soup.to_scene(options.scale)?;
    warnings.append(&mut more);
    let settings = options.settings.unwrap_or_else(|| default_settings(&scene));
    let unit = match drawing.insunits {
        Some((code, line)) => format!(
            "{} (the DXF's $INSUNITS {code}, line {line})",
            unit_name(code)
        ),
        None => "drawing units (the DXF states no $INSUNITS)".to_string(),
    };
    Ok(Imported {
        file: SceneFile { settings, scene },
        warnings,
        unit: scaled_unit(&unit, options.scale),
        format: Format::Dxf,
    })
}

/// `$INSUNITS` in words.
fn unit_name(code: i64) -> &'static str {
    match code {
        1 => "inches",
        2 => "feet",
        3 => "miles",
        4 => "millimetres",
        5 => "centimetres",
        6 => "metres",
        7 => "kilometres",
        8 => "microinches",
        9 => "mils",
        10 => "yards",
        11 => "angstroms",
        12 => "nanometres",
        13 => "microns",
        14 => "decimetres",
        15 => "decametres",
        16 => "hectometres",
        17 => "gigametres",
        18 => "astronomical units",
        19 => "light years",
        20 => "parsecs",
        _ => "drawing units",
    }
}

// ---- Group-code pairs

/// One group code and its value, with the line of the code.
#[derive(Clone, Copy, Debug)]
struct Pair<'a> {
    code: i32,
    value: &'a str,
    line: usize,
}

/// The file as group-code / value pairs.
fn pairs<'a>(file: &str, text: &'a str) -> Result<Vec<Pair<'a>>, ImportError> {
    let mut lines = text.lines().enumerate();
    let mut out = Vec::new();
    while let Some((i, code)) = lines.next() {
        let code = code.trim();
        if code.is_empty() && lines.clone().all(|(_, l)| l.trim().is_empty()) {
            break;
        }
        let Ok(c) = code.parse::<i32>() else {
            return Err(ImportError::Syntax {
                file: file.to_string(),
                line: i + 1,
                message: format!(
                    "expected a group code (a whole number) on this line, found \"{}\"",
                    code.chars().take(40).collect::<String>()
                ),
            });
        };
        let Some((_, value)) = lines.next() else {
            return Err(ImportError::Syntax {
                file: file.to_string(),
                line: i + 1,
                message: format!("the file ends after the group code {c}, before its value"),
            });
        };
        if c == 999 {
            continue; // a comment
        }
        out.push(Pair {
            code: c,
            value: value.trim(),
            line: i + 1,
        });
        if c == 0 && value.trim() == "EOF" {
            break;
        }
    }
    Ok(out)
}

fn number(file: &str, p: &Pair) -> Result<f64, ImportError> {
    match p.value.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(ImportError::NotFinite {
            file: file.to_string(),
            line: p.line + 1,
            element: format!("group {}", p.code),
            value: v,
        }),
        Err(_) => Err(ImportError::Syntax {
            file: file.to_string(),
            line: p.line + 1,
            message: format!(
                "group {} needs a number, found \"{}\"",
                p.code,
                p.value.chars().take(40).collect::<String>()
            ),
        }),
    }
}

fn integer(file: &str, p: &Pair) -> Result<i64, ImportError> {
    p.value.parse::<i64>().map_err(|_| ImportError::Syntax {
        file: file.to_string(),
        line: p.line + 1,
        message: format!(
            "group {} needs a whole number, found \"{}\"",
            p.code,
            p.value.chars().take(40).collect::<String>()
        ),
    })
}

// ---- Entities

/// A face: corners in the entity's coordinates, its layer, the line of its entity.
#[derive(Clone, Debug)]
struct Face {
    corners: Vec<DVec3>,
    layer: String,
    line: usize,
}

#[derive(Clone, Debug)]
enum Entity {
    /// Faces given outright (3DFACE, polyface, MESH).
    Faces(Vec<Face>),
    Insert(Insert),
}

#[derive(Clone, Debug)]
struct Insert {
    block: String,
    layer: String,
    line: usize,
    at: DVec3,
    scale: DVec3,
    rotation_degrees: f64,
    extrusion: DVec3,
    columns: i64,
    rows: i64,
    column_spacing: f64,
    row_spacing: f64,
}

struct Block {
    base: DVec3,
    entities: Vec<Entity>,
}

#[derive(Default)]
struct Drawing {
    entities: Vec<Entity>,
    blocks: HashMap<String, Block>,
    insunits: Option<(i64, usize)>,
    /// Entity types left out, with counts.
    ignored: BTreeMap<String, usize>,
}

impl Drawing {
    fn read(file: &str, pairs: &[Pair]) -> Result<Drawing, ImportError> {
        let mut d = Drawing::default();
        let mut i = 0;
        let err = |line: usize, message: String| ImportError::Syntax {
            file: file.to_string(),
            line,
            message,
        };
        while i < pairs.len() {
            let p = pairs[i];
            if p.code == 0 && p.value == "EOF" {
                break;
            }
            if !(p.code == 0 && p.value == "SECTION") {
                return Err(err(
                    p.line,
                    format!(
                        "expected \"0 SECTION\" (or \"0 EOF\"), found \"{} {}\"",
                        p.code, p.value
                    ),
                ));
            }
            let name = match pairs.get(i + 1) {
                Some(q) if q.code == 2 => q.value,
                _ => return Err(err(p.line, "a SECTION without its name (group 2)".into())),
            };
            i += 2;
            let end = (i..pairs.len())
                .find(|&k| pairs[k].code == 0 && pairs[k].value == "ENDSEC")
                .ok_or_else(|| {
                    err(
                        p.line,
                        format!(
                            "the {name} section that starts here has no ENDSEC: the file is \
                             truncated"
                        ),
                    )
                })?;
            let body = &pairs[i..end];
            match name {
                "HEADER" => d.header(file, body)?,
                "BLOCKS" => d.blocks(file, body)?,
                "ENTITIES" => {
                    let entities = d.entities(file, body)?;
                    d.entities.extend(entities);
                }
                _ => {}
            }
            i = end + 1;
        }
        Ok(d)
    }

    fn header(&mut self, file: &str, body: &[Pair]) -> Result<(), ImportError> {
        for (k, p) in body.iter().enumerate() {
            if p.code == 9 && p.value == "$INSUNITS" {
                if let Some(v) = body.get(k + 1).filter(|q| q.code == 70) {
                    self.insunits = Some((integer(file, v)?, v.line));
                }
            }
        }
        Ok(())
    }

    fn blocks(&mut self, file: &str, body: &[Pair]) -> Result<(), ImportError> {
        let mut i = 0;
        while i < body.len() {
            let p = body[i];
            if !(p.code == 0 && p.value == "BLOCK") {
                i += 1;
                continue;
            }
            let end = (i + 1..body.len())
                .find(|&k| body[k].code == 0 && body[k].value == "ENDBLK")
                .ok_or_else(|| ImportError::Syntax {
                    file: file.to_string(),
                    line: p.line,
                    message: "a BLOCK without its ENDBLK: the file is truncated".into(),
                })?;
            // The block's own groups run to its first entity.
            let first = (i + 1..end).find(|&k| body[k].code == 0).unwrap_or(end);
            let mut name = None;
            let mut base = [0.0; 3];
            for q in &body[i + 1..first] {
                match q.code {
                    2 => name = Some(q.value.to_string()),
                    10 | 20 | 30 => base[(q.code / 10 - 1) as usize] = number(file, q)?,
                    _ => {}
                }
            }
            let Some(name) = name else {
                return Err(ImportError::Syntax {
                    file: file.to_string(),
                    line: p.line,
                    message: "a BLOCK without its name (group 2)".into(),
                });
            };
            let entities = self.entities(file, &body[first..end])?;
            self.blocks.insert(
                name,
                Block {
                    base: DVec3::from(base),
                    entities,
                },
            );
            // ENDBLK's own groups are skipped by the search for the next BLOCK.
            i = end + 1;
        }
        Ok(())
    }

    fn ignore(&mut self, kind: &str) {
        *self.ignored.entry(kind.to_string()).or_insert(0) += 1;
    }

    fn warnings(&self, file: &str) -> Vec<ImportWarning> {
        if self.ignored.is_empty() {
            return Vec::new();
        }
        let list: Vec<String> = self
            .ignored
            .iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect();
        vec![ImportWarning {
            file: file.to_string(),
            line: 0,
            message: format!(
                "entities left out (no faces read from them): {}",
                list.join(", ")
            ),
        }]
    }

    /// The entities of a section or block body (a list of `0 TYPE` records).
    fn entities(&mut self, file: &str, body: &[Pair]) -> Result<Vec<Entity>, ImportError> {
        let mut out = Vec::new();
        let mut i = 0;
        // Each record: its `0 TYPE` pair and the groups up to the next 0.
        let record_end = |start: usize| {
            (start + 1..body.len())
                .find(|&k| body[k].code == 0)
                .unwrap_or(body.len())
        };
        while i < body.len() {
            let p = body[i];
            let end = record_end(i);
            let groups = &body[i + 1..end];
            match (p.code, p.value) {
                (0, "3DFACE") => out.push(Entity::Faces(vec![face3d(file, p.line, groups)?])),
                (0, "MESH") => out.push(Entity::Faces(mesh(file, p.line, groups)?)),
                (0, "INSERT") => out.push(Entity::Insert(insert(file, p.line, groups)?)),
                (0, "POLYLINE") => {
                    // Its VERTEX records run to SEQEND.
                    let mut k = end;
                    let mut vertices = Vec::new();
                    while k < body.len() && body[k].code == 0 && body[k].value == "VERTEX" {
                        let e = record_end(k);
                        vertices.push((body[k].line, &body[k + 1..e]));
                        k = e;
                    }
                    if !(k < body.len() && body[k].code == 0 && body[k].value == "SEQEND") {
                        let found = body
                            .get(k)
                            .map_or("the end of the section".to_string(), |q| {
                                format!("\"{} {}\" (line {})", q.code, q.value, q.line)
                            });
                        return Err(ImportError::Syntax {
                            file: file.to_string(),
                            line: p.line,
                            message: format!(
                                "the POLYLINE of this line has {} VERTEX records and then \
                                 {found}, not its SEQEND",
                                vertices.len()
                            ),
                        });
                    }
                    let flags = groups
                        .iter()
                        .find(|q| q.code == 70)
                        .map(|q| integer(file, q))
                        .transpose()?
                        .unwrap_or(0);
                    if flags & 64 != 0 {
                        out.push(Entity::Faces(polyface(file, p.line, groups, &vertices)?));
                    } else {
                        self.ignore(if flags & 16 != 0 {
                            "POLYLINE (3D polygon mesh)"
                        } else {
                            "POLYLINE (not a polyface mesh)"
                        });
                    }
                    i = record_end(k);
                    continue;
                }
                (0, kind) => self.ignore(kind),
                _ => {
                    return Err(ImportError::Syntax {
                        file: file.to_string(),
                        line: p.line,
                        message: format!(
                            "expected an entity (\"0 TYPE\"), found \"{} {}\"",
                            p.code, p.value
                        ),
                    })
                }
            }
            i = end;
        }
        Ok(out)
    }
}

fn layer_of(groups: &[Pair]) -> String {
    groups
        .iter()
        .find(|q| q.code == 8)
        .map_or_else(|| "0".to_string(), |q| q.value.to_string())
}

/// A 3DFACE's corners (10..13 / 20..23 / 30..33).
fn face3d(file: &str, line: usize, groups: &[Pair]) -> Result<Face, ImportError> {
    let mut c = [[0.0f64; 3]; 4];
    let mut given = [false; 4];
    for q in groups {
        if let 10..=13 | 20..=23 | 30..=33 = q.code {
            let axis = (q.code / 10 - 1) as usize;
            let corner = (q.code % 10) as usize;
            c[corner][axis] = number(file, q)?;
            given[corner] = true;
        }
    }
    if !given[..3].iter().all(|&g| g) {
        return Err(ImportError::Syntax {
            file: file.to_string(),
            line,
            message: "a 3DFACE needs at least three corners (groups 10/20/30, 11/21/31, \
                      12/22/32)"
                .into(),
        });
    }
    let mut corners: Vec<DVec3> = c.iter().map(|&p| DVec3::from(p)).collect();
    if !given[3] || corners[3] == corners[2] {
        corners.pop();
    }
    Ok(Face {
        corners,
        layer: layer_of(groups),
        line,
    })
}

/// A polyface mesh's faces from its VERTEX records.
fn polyface(
    file: &str,
    line: usize,
    groups: &[Pair],
    vertices: &[(usize, &[Pair])],
) -> Result<Vec<Face>, ImportError> {
    let layer = layer_of(groups);
    let mut points = Vec::new();
    let mut faces = Vec::new();
    for &(vline, g) in vertices {
        let flags = g
            .iter()
            .find(|q| q.code == 70)
            .map(|q| integer(file, q))
            .transpose()?
            .unwrap_or(0);
        if flags & 128 == 0 {
            continue;
        }
        if flags & 64 != 0 {
            let mut p = [0.0; 3];
            for q in g {
                if let 10 | 20 | 30 = q.code {
                    p[(q.code / 10 - 1) as usize] = number(file, q)?;
                }
            }
            points.push(DVec3::from(p));
            continue;
        }
        // A face record: corners 71..74, counting from 1; negative: an invisible edge.
        let mut idx = [0i64; 4];
        for q in g {
            if let 71..=74 = q.code {
                idx[(q.code - 71) as usize] = integer(file, q)?;
            }
        }
        let mut corners = Vec::with_capacity(4);
        for (k, &i) in idx.iter().enumerate() {
            if i == 0 {
                continue;
            }
            let n = i.unsigned_abs() as usize;
            let Some(&p) = points.get(n.wrapping_sub(1)) else {
                return Err(ImportError::BadIndex {
                    file: file.to_string(),
                    line: vline,
                    element: format!(
                        "face record (group {}) of the POLYLINE of line {line}",
                        71 + k
                    ),
                    index: i,
                    count: points.len(),
                });
            };
            corners.push(p);
        }
        faces.push(Face {
            corners,
            layer: g
                .iter()
                .find(|q| q.code == 8)
                .map_or_else(|| layer.clone(), |q| q.value.to_string()),
            line: vline,
        });
    }
    Ok(faces)
}

/// A MESH's faces (level-0 control cage).
fn mesh(file: &str, line: usize, groups: &[Pair]) -> Result<Vec<Face>, ImportError> {
    let layer = layer_of(groups);
    let err = |l: usize, message: String| ImportError::Syntax {
        file: file.to_string(),
        line: l,
        message,
    };
    let mut k = 0;
    let mut points: Vec<DVec3> = Vec::new();
    let mut faces = Vec::new();
    while k < groups.len() {
        let q = groups[k];
        match q.code {
            92 => {
                let n = integer(file, &q)?;
                let left = (groups.len() - k - 1) as u64;
                if n < 0 {
                    return Err(err(q.line, format!("MESH vertex count {n} is negative")));
                }
                // Three groups a vertex.
                check_count(
                    file,
                    q.line,
                    "MESH vertex count (group 92)",
                    n as u64,
                    3,
                    left,
                )?;
                points.reserve(n as usize);
                for v in 0..n as usize {
                    let base = k + 1 + 3 * v;
                    let mut p = [0.0; 3];
                    for (axis, code) in [10, 20, 30].into_iter().enumerate() {
                        let g = groups[base + axis];
                        if g.code != code {
                            return Err(err(
                                g.line,
                                format!(
                                    "MESH vertex {v} of {n}: expected group {code}, found group {}",
                                    g.code
                                ),
                            ));
                        }
                        p[axis] = number(file, &g)?;
                    }
                    points.push(DVec3::from(p));
                }
                k += 1 + 3 * n as usize;
            }
            93 => {
                let n = integer(file, &q)?;
                let left = (groups.len() - k - 1) as u64;
                if n < 0 {
                    return Err(err(q.line, format!("MESH face list size {n} is negative")));
                }
                check_count(
                    file,
                    q.line,
                    "MESH face list size (group 93)",
                    n as u64,
                    1,
                    left,
                )?;
                let list = &groups[k + 1..k + 1 + n as usize];
                let mut at = 0;
                while at < list.len() {
                    let count = integer(file, &list[at])?;
                    let fline = list[at].line + 1;
                    let Some(corners_idx) = usize::try_from(count)
                        .ok()
                        .and_then(|c| list.get(at + 1..at + 1 + c))
                    else {
                        return Err(err(
                            fline,
                            format!(
                                "MESH face of {count} corners runs past the end of its face \
                                 list ({n} entries)"
                            ),
                        ));
                    };
                    let mut corners = Vec::with_capacity(corners_idx.len());
                    for g in corners_idx {
                        let i = integer(file, g)?;
                        let Some(&p) = usize::try_from(i).ok().and_then(|i| points.get(i)) else {
                            return Err(ImportError::BadIndex {
                                file: file.to_string(),
                                line: g.line + 1,
                                element: format!(
                                    "face {} of the MESH of line {line}",
                                    faces.len() + 1
                                ),
                                index: i,
                                count: points.len(),
                            });
                        };
                        corners.push(p);
                    }
                    faces.push(Face {
                        corners,
                        layer: layer.clone(),
                        line: fline,
                    });
                    at += 1 + corners_idx.len();
                }
                k += 1 + n as usize;
            }
            _ => k += 1,
        }
    }
    Ok(faces)
}

fn insert(file: &str, line: usize, groups: &[Pair]) -> Result<Insert, ImportError> {
    let mut ins = Insert {
        block: String::new(),
        layer: layer_of(groups),
        line,
        at: DVec3::ZERO,
        scale: DVec3::ONE,
        rotation_degrees: 0.0,
        extrusion: DVec3::Z,
        columns: 1,
        rows: 1,
        column_spacing: 0.0,
        row_spacing: 0.0,
    };
    for q in groups {
        match q.code {
            2 => ins.block = q.value.to_string(),
            10 => ins.at.x = number(file, q)?,
            20 => ins.at.y = number(file, q)?,
            30 => ins.at.z = number(file, q)?,
            41 => ins.scale.x = number(file, q)?,
            42 => ins.scale.y = number(file, q)?,
            43 => ins.scale.z = number(file, q)?,
            50 => ins.rotation_degrees = number(file, q)?,
            210 => ins.extrusion.x = number(file, q)?,
            220 => ins.extrusion.y = number(file, q)?,
            230 => ins.extrusion.z = number(file, q)?,
            70 => ins.columns = integer(file, q)?,
            71 => ins.rows = integer(file, q)?,
            44 => ins.column_spacing = number(file, q)?,
            45 => ins.row_spacing = number(file, q)?,
            _ => {}
        }
    }
    if ins.block.is_empty() {
        return Err(ImportError::Syntax {
            file: file.to_string(),
            line,
            message: "an INSERT without its block name (group 2)".into(),
        });
    }
    Ok(ins)
}

/// The object coordinate system of `extrusion` (DXF's arbitrary axis algorithm) as the
/// matrix from it to world coordinates; `None` for a zero vector.
fn ocs(extrusion: DVec3) -> Option<DMat4> {
    let z = extrusion.try_normalize()?;
    let x = if z.x.abs() < 1.0 / 64.0 && z.y.abs() < 1.0 / 64.0 {
        DVec3::Y.cross(z)
    } else {
        DVec3::Z.cross(z)
    }
    .normalize();
    let y = z.cross(x);
    Some(DMat4::from_cols(
        x.extend(0.0),
        y.extend(0.0),
        z.extend(0.0),
        glam::DVec4::W,
    ))
}

// ---- From entities to the face soup.

struct Builder<'a> {
    file: String,
    drawing: &'a Drawing,
    /// Placed faces: corners in world coordinates, layer index, line.
    faces: Vec<(Vec<DVec3>, u32, usize)>,
    layers: Vec<String>,
    layer_index: HashMap<String, u32>,
    /// The blocks being inserted, outermost first.
    stack: Vec<String>,
    /// Block placements so far.
    placements: usize,
}

impl Builder<'_> {
    fn layer(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.layer_index.get(name) {
            return i;
        }
        let i = self.layers.len() as u32;
        self.layers.push(name.to_string());
        self.layer_index.insert(name.to_string(), i);
        i
    }

    /// Places `e` by `m`; `inherit`: the layer entities on layer 0 take (in a block).
    fn entity(&mut self, e: &Entity, m: &DMat4, inherit: Option<&str>) -> Result<(), ImportError> {
        match e {
            Entity::Faces(faces) => {
                if self.faces.len() + faces.len() > MAX_FACES {
                    let line = faces.first().map_or(0, |f| f.line);
                    return Err(ImportError::Syntax {
                        file: self.file.clone(),
                        line,
                        message: format!(
                            "the drawing would have more than {MAX_FACES} faces once every \
                             INSERT is placed; simplify it"
                        ),
                    });
                }
                let mirrored = m.determinant() < 0.0;
                for f in faces {
                    let layer = match inherit {
                        Some(l) if f.layer == "0" => l,
                        _ => &f.layer,
                    };
                    let layer = self.layer(layer);
                    let mut corners: Vec<DVec3> =
                        f.corners.iter().map(|&p| m.transform_point3(p)).collect();
                    if mirrored {
                        corners.reverse();
                    }
                    self.faces.push((corners, layer, f.line));
                }
            }
            Entity::Insert(ins) => self.insert(ins, m, inherit)?,
        }
        Ok(())
    }

    fn insert(
        &mut self,
        ins: &Insert,
        m: &DMat4,
        inherit: Option<&str>,
    ) -> Result<(), ImportError> {
        let file = self.file.clone();
        let err = |message: String| ImportError::Syntax {
            file: file.clone(),
            line: ins.line,
            message,
        };
        let drawing = self.drawing;
        let Some(block) = drawing.blocks.get(&ins.block) else {
            let mut names: Vec<&str> = drawing.blocks.keys().map(String::as_str).collect();
            names.sort_unstable();
            return Err(err(format!(
                "INSERT of the block \"{}\", which the BLOCKS section does not define (it \
                 defines: {})",
                ins.block,
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )));
        };
        if let Some(k) = self.stack.iter().position(|b| *b == ins.block) {
            let mut chain: Vec<&str> = self.stack[k..].iter().map(String::as_str).collect();
            chain.push(&ins.block);
            return Err(err(format!(
                "the block \"{}\" inserts itself ({}): a cycle of block references",
                ins.block,
                chain.join(" -> ")
            )));
        }
        if self.stack.len() >= MAX_INSERT_DEPTH {
            return Err(err(format!(
                "blocks inserted in blocks more than {MAX_INSERT_DEPTH} deep"
            )));
        }
        let Some(ocs) = ocs(ins.extrusion) else {
            return Err(err(
                "the INSERT's extrusion direction (210/220/230) is zero".into(),
            ));
        };
        if !(1..=100_000).contains(&ins.columns) || !(1..=100_000).contains(&ins.rows) {
            return Err(err(format!(
                "the INSERT's grid of {} columns (70) by {} rows (71) is outside 1 to 100000",
                ins.columns, ins.rows
            )));
        }
        let rotation = DMat4::from_rotation_z(ins.rotation_degrees.to_radians());
        let local = DMat4::from_scale(ins.scale) * DMat4::from_translation(-block.base);
        let layer = if ins.layer == "0" {
            inherit.unwrap_or("0")
        } else {
            &ins.layer
        };
        let layer = layer.to_string();
        self.stack.push(ins.block.clone());
        for row in 0..ins.rows {
            for col in 0..ins.columns {
                self.placements += 1;
                if self.placements > MAX_PLACEMENTS {
                    return Err(err(format!(
                        "more than {MAX_PLACEMENTS} block placements once every INSERT is \
                         followed (INSERTs of blocks that insert blocks multiply; grids too)"
                    )));
                }
                let offset = DVec3::new(
                    col as f64 * ins.column_spacing,
                    row as f64 * ins.row_spacing,
                    0.0,
                );
                let placed = *m
                    * ocs
                    * DMat4::from_translation(ins.at)
                    * rotation
                    * DMat4::from_translation(offset)
                    * local;
                if !placed.is_finite() {
                    return Err(err(
                        "the INSERT's transform is not finite (a scale or position too large)"
                            .into(),
                    ));
                }
                for e in &block.entities {
                    self.entity(e, &placed, Some(&layer))?;
                }
            }
        }
        self.stack.pop();
        Ok(())
    }

    /// The soup, each layer's material from the materials file.
    fn soup(
        self,
        materials_file: &str,
        table: Option<&MaterialsFile>,
    ) -> Result<FaceSoup, ImportError> {
        let layers_found = || {
            let set: BTreeSet<&str> = self.layers.iter().map(String::as_str).collect();
            set.into_iter()
                .map(|l| format!("\"{l}\""))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let Some(table) = table else {
            return Err(ImportError::Syntax {
                file: materials_file.to_string(),
                line: 0,
                message: format!(
                    "the materials file of {} is missing; DXF has no colours, so write it \
                     with a [layers.NAME] table (reflectance = [r, g, b], emission = [r, g, \
                     b]) for each of the drawing's layers with faces: {}, or a [default] \
                     table for all",
                    self.file,
                    layers_found()
                ),
            });
        };
        let mut soup = FaceSoup {
            file: self.file.clone(),
            objects: self.layers.clone(),
            ..FaceSoup::default()
        };
        let mut material_of_layer = Vec::with_capacity(self.layers.len());
        for name in &self.layers {
            let (m, line, what) = match (table.layers.get(name), &table.default) {
                (Some(m), _) => (m, table.line_of(&format!("[layers.{name}]")), name.clone()),
                (None, Some(d)) => (
                    d,
                    table.line_of("[default]"),
                    format!("[default] for layer {name}"),
                ),
                (None, None) => {
                    // A table that names no layer is most likely this one misspelt.
                    let unused: Vec<String> = table
                        .layers
                        .keys()
                        .filter(|l| !self.layers.contains(l))
                        .map(|l| format!("[layers.\"{l}\"]"))
                        .collect();
                    let unused = match unused.is_empty() {
                        true => String::new(),
                        false => format!(
                            "; tables here that name no layer with faces: {}",
                            unused.join(", ")
                        ),
                    };
                    return Err(ImportError::BadMaterial {
                        file: materials_file.to_string(),
                        line: 0,
                        name: name.clone(),
                        message: format!(
                            "the layer \"{name}\" of {} has faces but no [layers.\"{name}\"] \
                             table here, and there is no [default] table; the drawing's \
                             layers with faces: {}{unused}",
                            self.file,
                            layers_found()
                        ),
                    });
                }
            };
            let reflectance = Rgb(*m.reflectance.get_ref());
            let emission = Rgb(m.emission.as_ref().map_or([0.0; 3], |e| *e.get_ref()));
            // A colour the scene format cannot hold is reported at its own line, and a
            // layer that takes [default] says so (QA of issue #16: an emission of NaN in
            // [default] on line 3 was reported at line 1 as the layer's).
            let line = match material_problem(reflectance, emission) {
                Some((MaterialField::Reflectance, _)) => table.line_at(m.reflectance.span().start),
                Some((MaterialField::Emission, _)) => m
                    .emission
                    .as_ref()
                    .map_or(line, |e| table.line_at(e.span().start)),
                None => line,
            };
            material_of_layer.push(soup.materials.len() as u32);
            soup.materials.push(SoupMaterial {
                name: what,
                reflectance,
                emission,
                defined_at: Some((materials_file.to_string(), line)),
            });
        }
        // Tables no layer with faces takes are checked too, as every glTF material is (QA
        // pass 15 of #16: an emission of -5 on a misspelt layer passed unremarked).
        let unused = table
            .layers
            .iter()
            .filter(|(name, _)| !self.layers.contains(name))
            .map(|(name, m)| (format!("[layers.\"{name}\"]"), m))
            .chain(
                table
                    .default
                    .as_ref()
                    .filter(|_| self.layers.iter().all(|l| table.layers.contains_key(l)))
                    .map(|m| ("[default]".to_string(), m)),
            );
        for (name, m) in unused {
            let reflectance = Rgb(*m.reflectance.get_ref());
            let emission = Rgb(m.emission.as_ref().map_or([0.0; 3], |e| *e.get_ref()));
            if let Some((field, message)) = material_problem(reflectance, emission) {
                let at = match (field, &m.emission) {
                    (MaterialField::Emission, Some(e)) => e.span().start,
                    _ => m.reflectance.span().start,
                };
                return Err(ImportError::BadMaterial {
                    file: materials_file.to_string(),
                    line: table.line_at(at),
                    name: format!("{name}, used by no layer with faces"),
                    message,
                });
            }
        }
        for (corners, layer, line) in self.faces {
            soup.faces.push(SoupFace {
                object: layer,
                material: material_of_layer[layer as usize],
                first: soup.indices.len(),
                count: corners.len() as u32,
                line,
            });
            let base = soup.vertices.len() as u32;
            soup.indices
                .extend((0..corners.len() as u32).map(|k| base + k));
            soup.vertex_lines
                .extend(std::iter::repeat_n(line, corners.len()));
            soup.vertices.extend(corners);
        }
        Ok(soup)
    }
}

// ---- The materials file

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerMaterial {
    /// With its place in the file, so that a wrong colour's message names its own line.
    reflectance: toml::Spanned<[f64; 3]>,
    emission: Option<toml::Spanned<[f64; 3]>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialsToml {
    #[serde(default)]
    layers: BTreeMap<String, LayerMaterial>,
    default: Option<LayerMaterial>,
}

struct MaterialsFile {
    layers: BTreeMap<String, LayerMaterial>,
    default: Option<LayerMaterial>,
    text: String,
}

impl MaterialsFile {
    fn parse(name: &str, text: &str) -> Result<MaterialsFile, ImportError> {
        let parsed: MaterialsToml = toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(0, |s| line_at(text, s.start));
            ImportError::Syntax {
                file: name.to_string(),
                line,
                message: format!(
                    "not a materials file ({}); expected [layers.NAME] tables with \
                     reflectance = [r, g, b] and optionally emission = [r, g, b]",
                    e.message().trim()
                ),
            }
        })?;
        Ok(MaterialsFile {
            layers: parsed.layers,
            default: parsed.default,
            text: text.to_string(),
        })
    }

    /// A warning for each `[layers.NAME]` table that names no layer of the drawing with
    /// faces (`layers`): a misspelt or stale name, whose layer takes `[default]` or is
    /// refused (QA of issue #16: it was passed over without a word).
    fn unused_layers(
        &self,
        materials_file: &str,
        drawing: &str,
        layers: &[String],
    ) -> Vec<ImportWarning> {
        let listed = || {
            layers
                .iter()
                .map(|l| format!("\"{l}\""))
                .collect::<Vec<_>>()
                .join(", ")
        };
        self.layers
            .keys()
            .filter(|name| !layers.contains(name))
            .map(|name| {
                let near = layers
                    .iter()
                    .find(|l| l.eq_ignore_ascii_case(name))
                    .map(|l| format!(" (layer names are case sensitive: \"{l}\"?)"))
                    .unwrap_or_default();
                ImportWarning {
                    file: materials_file.to_string(),
                    line: self.line_of(&format!("[layers.{name}]")),
                    message: format!(
                        "[layers.\"{name}\"] names no layer of {drawing} with faces, so it \
                         is not used{near}; the layers with faces: {}",
                        listed()
                    ),
                }
            })
            .collect()
    }

    /// The line (from 1) of byte `at` of the file.
    fn line_at(&self, at: usize) -> usize {
        line_at(&self.text, at)
    }

    /// The line of a table header (for messages about its colours); 0 when it is written
    /// otherwise (quoted, dotted differently).
    fn line_of(&self, header: &str) -> usize {
        let quoted = header
            .strip_prefix("[layers.")
            .and_then(|h| h.strip_suffix(']'))
            .map(|name| format!("[layers.\"{name}\"]"));
        self.text
            .lines()
            .position(|l| l.trim() == header || Some(l.trim()) == quoted.as_deref())
            .map_or(0, |k| k + 1)
    }
}

/// The line (from 1) of byte `at` of `text`.
fn line_at(text: &str, at: usize) -> usize {
    1 + text[..at.min(text.len())].matches('\n').count()
}

#[cfg(test)]
#[path = "dxf_tests.rs"]
mod tests;
