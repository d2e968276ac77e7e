//! The shared conversion of every importer: a face soup (objects, faces as index lists
//! into one vertex array, a material per face) into checked scene surfaces. The rules are
//! in the [parent module's documentation](super).

use std::collections::HashMap;

use glam::DVec3;

use super::merge::join_coplanar_polygons;
use super::{ImportError, ImportWarning};
use crate::geometry::{self, PolygonError};
use crate::io::scene_file::duplicate_surfaces;
use crate::light::Rgb;
use crate::scene::{Scene, Surface};

/// How many faces a warning names before it says "and N more".
const NAMED_IN_WARNING: usize = 3;

/// A model as most formats hold it: named objects, faces as lists of indices into one
/// shared vertex array, a material per face. Build it, then call [`FaceSoup::to_scene`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceSoup {
    /// The file's name, for messages.
    pub file: String,
    /// The vertices, as read (before [`super::ImportOptions::scale`]).
    pub vertices: Vec<DVec3>,
    /// Where each vertex was given (line, counting from 1; 0 when unknown), parallel to
    /// `vertices`, or empty when the format has no lines.
    pub vertex_lines: Vec<usize>,
    /// Every face's vertex indices, one face after another (see [`SoupFace::first`]).
    pub indices: Vec<u32>,
    /// The faces, in file order.
    pub faces: Vec<SoupFace>,
    /// The objects' names (indexed by [`SoupFace::object`]).
    pub objects: Vec<String>,
    /// The materials (indexed by [`SoupFace::material`]).
    pub materials: Vec<SoupMaterial>,
}

/// One face of a [`FaceSoup`]: the corners `indices[first .. first + count]`,
/// counter-clockwise seen from the front.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SoupFace {
    /// Index into [`FaceSoup::objects`].
    pub object: u32,
    /// Index into [`FaceSoup::materials`].
    pub material: u32,
    /// The first of its indices in [`FaceSoup::indices`].
    pub first: usize,
    /// How many corners.
    pub count: u32,
    /// The line it was given on, counting from 1; 0 for a binary format.
    pub line: usize,
}

/// A material: the colours every face that uses it gets.
#[derive(Clone, Debug, PartialEq)]
pub struct SoupMaterial {
    /// Its name, for messages.
    pub name: String,
    /// Diffuse reflectance per band, in [0, 1).
    pub reflectance: Rgb,
    /// Emitted exitance per band, >= 0.
    pub emission: Rgb,
    /// Where it was defined (file and line), for messages; the soup's file and 0 when unknown.
    pub defined_at: Option<(String, usize)>,
}

/// Which colour of a material the scene format cannot hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum MaterialField {
    /// The reflectance.
    Reflectance,
    /// The emission.
    Emission,
}

/// The first colour of a material that the scene format cannot hold, and why: reflectance
/// at least 0 and below 1, emission finite, at least 0 and at most
/// [`crate::scene::MAX_EMISSION`]. Importers that know each colour's own line (the DXF
/// materials file) use the field to point at it.
pub(crate) fn material_problem(reflectance: Rgb, emission: Rgb) -> Option<(MaterialField, String)> {
    for (band, &r) in ["red", "green", "blue"].iter().zip(&reflectance.0) {
        if !(0.0..1.0).contains(&r) {
            return Some((
                MaterialField::Reflectance,
                format!(
                    "the {band} reflectance is {r}; reflectance must be at least 0 and below 1 \
                     (a surface cannot reflect all the light it receives, or more)"
                ),
            ));
        }
    }
    for (band, &e) in ["red", "green", "blue"].iter().zip(&emission.0) {
        if !(e >= 0.0 && e.is_finite()) {
            return Some((
                MaterialField::Emission,
                format!(
                    "the {band} emission is {e}; emission must be a finite number of at least 0"
                ),
            ));
        }
        if e > crate::scene::MAX_EMISSION {
            return Some((
                MaterialField::Emission,
                format!(
                    "the {band} emission is {e:e}, above the largest the program supports \
                     ({:e}): the power summed over the scene would overflow",
                    crate::scene::MAX_EMISSION
                ),
            ));
        }
    }
    None
}

/// One output surface before naming: its object, material and corners.
struct Piece {
    object: u32,
    material: u32,
    vertices: Vec<DVec3>,
    /// The face it comes from (an index into the soup's faces).
    face: usize,
}

impl FaceSoup {
    /// Face `f` in words, for messages: `face 4 of object "Box"` (faces counted from 1 in
    /// file order).
    fn describe_face(&self, f: usize) -> String {
        let face = &self.faces[f];
        let object = self
            .objects
            .get(face.object as usize)
            .map_or("?", String::as_str);
        format!("face {} of object \"{object}\"", f + 1)
    }

    /// The surfaces of the soup, every coordinate times `scale`, with the warnings for
    /// what was dropped or split. See the [parent module's documentation](super).
    pub fn to_scene(&self, scale: f64) -> Result<(Scene, Vec<ImportWarning>), ImportError> {
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(ImportError::BadScale { scale });
        }
        self.check_materials()?;
        let vertices = self.scaled_vertices(scale)?;
        let mut pieces = Vec::new();
        let mut degenerate = Vec::new();
        let mut triangulated = (0usize, 0usize);
        let mut lost_pieces = 0usize;
        for (f, joined) in self.joined_faces(&vertices) {
            let face = &self.faces[f];
            let corners = self.corners(f, face, joined.as_deref(), &vertices)?;
            let push = |pieces: &mut Vec<Piece>, vertices: Vec<DVec3>| {
                pieces.push(Piece {
                    object: face.object,
                    material: face.material,
                    vertices,
                    face: f,
                })
            };
            match geometry::validate_polygon(&corners) {
                Ok(()) => {
                    let mut corners = corners;
                    geometry::flatten(&mut corners);
                    // Flattening can bring two corners of a sliver within the same-point
                    // distance of each other (found by the obj fuzz target): checked again.
                    if geometry::validate_polygon(&corners).is_ok() {
                        push(&mut pieces, corners);
                    } else {
                        degenerate.push(f);
                    }
                }
                Err(
                    PolygonError::NotPlanar { .. }
                    | PolygonError::Reflex { .. }
                    | PolygonError::WindsMoreThanOnce
                    | PolygonError::RepeatedVertex { .. },
                ) => {
                    let (triangles, lost) = triangulate(&corners);
                    if triangles.is_empty() {
                        degenerate.push(f);
                        continue;
                    }
                    triangulated.0 += 1;
                    triangulated.1 += triangles.len();
                    lost_pieces += lost;
                    for t in triangles {
                        push(&mut pieces, t.to_vec());
                    }
                }
                // Every vertex was checked by `scaled_vertices`, so the first two cannot
                // happen; were they to, the face is not usable either.
                Err(
                    PolygonError::NotFinite { .. }
                    | PolygonError::OutOfRange { .. }
                    | PolygonError::TooFewVertices { .. }
                    | PolygonError::TooSmall { .. }
                    | PolygonError::ZeroArea,
                ) => degenerate.push(f),
            }
        }
        let mut warnings = Vec::new();
        if !degenerate.is_empty() {
            warnings.push(self.warning(format!(
                "dropped {} degenerate face{} (zero area, fewer than 3 distinct corners, or too \
                 small to use): {}",
                degenerate.len(),
                plural(degenerate.len()),
                self.list_faces(&degenerate)
            )));
        }
        if triangulated.0 > 0 {
            let lost = if lost_pieces == 0 {
                String::new()
            } else {
                format!(
                    "; {lost_pieces} degenerate triangle{} of them dropped",
                    plural(lost_pieces)
                )
            };
            warnings.push(self.warning(format!(
                "{} face{} not planar and convex (within the 0.2% planarity tolerance) split \
                 into {} triangles{lost}",
                triangulated.0,
                if triangulated.0 == 1 {
                    " was"
                } else {
                    "s were"
                },
                triangulated.1
            )));
        }
        if pieces.is_empty() {
            return Err(ImportError::NoSurfaces {
                file: self.file.clone(),
                faces: self.faces.len(),
            });
        }
        let faces: Vec<usize> = pieces.iter().map(|p| p.face).collect();
        let mut surfaces = self.name_pieces(pieces);
        self.drop_duplicates(&mut surfaces, &faces, &mut warnings);
        Ok((
            Scene {
                surfaces,
                camera: None,
                lights: Vec::new(),
            },
            warnings,
        ))
    }

    fn warning(&self, message: String) -> ImportWarning {
        ImportWarning {
            file: self.file.clone(),
            line: 0,
            message,
        }
    }

    /// The first few of `faces` in words, with their lines, and how many more.
    fn list_faces(&self, faces: &[usize]) -> String {
        let mut named: Vec<String> = faces
            .iter()
            .take(NAMED_IN_WARNING)
            .map(|&f| match self.faces[f].line {
                0 => self.describe_face(f),
                l => format!("{} (line {l})", self.describe_face(f)),
            })
            .collect();
        if faces.len() > NAMED_IN_WARNING {
            named.push(format!("and {} more", faces.len() - NAMED_IN_WARNING));
        }
        named.join(", ")
    }

    /// Every material's colours in the scene format's ranges.
    fn check_materials(&self) -> Result<(), ImportError> {
        for m in &self.materials {
            let bad = |message: String| {
                let (file, line) = m
                    .defined_at
                    .clone()
                    .unwrap_or_else(|| (self.file.clone(), 0));
                ImportError::BadMaterial {
                    file,
                    line,
                    name: m.name.clone(),
                    message,
                }
            };
            if let Some((_, message)) = material_problem(m.reflectance, m.emission) {
                return Err(bad(message));
            }
        }
        Ok(())
    }

    /// The vertices times `scale`, each finite and within the supported range.
    fn scaled_vertices(&self, scale: f64) -> Result<Vec<DVec3>, ImportError> {
        let mut out = Vec::with_capacity(self.vertices.len());
        for (i, v) in self.vertices.iter().enumerate() {
            let line = self.vertex_lines.get(i).copied().unwrap_or(0);
            let element = || format!("vertex {}", i + 1);
            for value in v.to_array() {
                if !value.is_finite() {
                    return Err(ImportError::NotFinite {
                        file: self.file.clone(),
                        line,
                        element: element(),
                        value,
                    });
                }
            }
            let scaled = *v * scale;
            for value in scaled.to_array() {
                if value.abs() > geometry::MAX_COORDINATE {
                    return Err(ImportError::OutOfRange {
                        file: self.file.clone(),
                        line,
                        element: element(),
                        value,
                    });
                }
            }
            out.push(scaled);
        }
        Ok(out)
    }

    /// The faces to make surfaces of, in file order, each by its first face: coplanar
    /// faces of one object and material that share an edge (the same corners, by
    /// position, run in opposite directions) and together make a flat convex polygon are
    /// joined into it ([`super::merge`]), so that a quad given as two triangles, or a
    /// floor given as tiles, meshes as one polygon. `Some(indices)` for a face that
    /// absorbed others (its outline; indices into `vertices`), `None` for one kept as
    /// given.
    fn joined_faces(&self, vertices: &[DVec3]) -> Vec<(usize, Option<Vec<u32>>)> {
        // One index per position, so faces that repeat their corners (3DFACE) connect.
        let mut first_at: HashMap<[u64; 3], u32> = HashMap::new();
        let canonical: Vec<u32> = vertices
            .iter()
            .enumerate()
            .map(|(i, v)| {
                *first_at
                    .entry(v.to_array().map(f64::to_bits))
                    .or_insert(i as u32)
            })
            .collect();
        let mut groups: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (f, face) in self.faces.iter().enumerate() {
            groups
                .entry((face.object, face.material))
                .or_default()
                .push(f);
        }
        let mut out: Vec<(usize, Option<Vec<u32>>)> = Vec::with_capacity(self.faces.len());
        for faces in groups.values() {
            if faces.len() == 1 {
                out.push((faces[0], None));
                continue;
            }
            let polygons: Vec<Vec<u32>> = faces
                .iter()
                .map(|&f| {
                    let face = &self.faces[f];
                    let range = face.first..face.first.saturating_add(face.count as usize);
                    self.indices.get(range).map_or_else(Vec::new, |ix| {
                        ix.iter()
                            .map(|&i| canonical.get(i as usize).copied().unwrap_or(i))
                            .collect()
                    })
                })
                .collect();
            for (k, poly) in join_coplanar_polygons(vertices, polygons) {
                let f = faces[k];
                let face = &self.faces[f];
                let range = face.first..face.first.saturating_add(face.count as usize);
                // Kept as given (also one whose indices are wrong, for its error).
                let as_given = self.indices.get(range).is_none_or(|ix| {
                    ix.len() == poly.len()
                        && ix
                            .iter()
                            .zip(&poly)
                            .all(|(&b, &a)| canonical.get(b as usize).copied().unwrap_or(b) == a)
                });
                out.push((f, (!as_given).then_some(poly)));
            }
        }
        out.sort_unstable_by_key(|(f, _)| *f);
        out
    }

    /// Face `f`'s corners (or those of the joined outline `joined`), with consecutive
    /// repeats (the same point twice in a row, also last to first) taken out; its indices
    /// checked.
    fn corners(
        &self,
        f: usize,
        face: &SoupFace,
        joined: Option<&[u32]>,
        vertices: &[DVec3],
    ) -> Result<Vec<DVec3>, ImportError> {
        let range = face.first..face.first.saturating_add(face.count as usize);
        let Some(indices) = joined.or_else(|| self.indices.get(range)) else {
            return Err(ImportError::Syntax {
                file: self.file.clone(),
                line: face.line,
                message: format!(
                    "{}: its corners run past the end of the index list",
                    self.describe_face(f)
                ),
            });
        };
        let mut corners: Vec<DVec3> = Vec::with_capacity(indices.len());
        for &i in indices {
            let Some(&v) = vertices.get(i as usize) else {
                return Err(ImportError::BadIndex {
                    file: self.file.clone(),
                    line: face.line,
                    element: self.describe_face(f),
                    index: i64::from(i),
                    count: vertices.len(),
                });
            };
            if corners.last() != Some(&v) {
                corners.push(v);
            }
        }
        while corners.len() > 1 && corners.first() == corners.last() {
            corners.pop();
        }
        Ok(corners)
    }

    /// The surfaces, named after their objects (module documentation).
    fn name_pieces(&self, pieces: Vec<Piece>) -> Vec<Surface> {
        let mut per_object = vec![0usize; self.objects.len()];
        for p in &pieces {
            if let Some(n) = per_object.get_mut(p.object as usize) {
                *n += 1;
            }
        }
        let mut next = vec![0usize; self.objects.len()];
        pieces
            .into_iter()
            .map(|p| {
                let o = p.object as usize;
                let base = self
                    .objects
                    .get(o)
                    .map(|n| n.trim())
                    .filter(|n| !n.is_empty())
                    .unwrap_or("surface");
                let name = if per_object.get(o) == Some(&1) {
                    base.to_string()
                } else {
                    let k = next.get(o).copied().unwrap_or(0);
                    if let Some(n) = next.get_mut(o) {
                        *n += 1;
                    }
                    format!("{base}.{k}")
                };
                let m = &self.materials[p.material as usize];
                Surface {
                    name,
                    emission: m.emission,
                    reflectance: m.reflectance,
                    vertices: p.vertices,
                    photometry: Default::default(),
                }
            })
            .collect()
    }

    /// Drops every surface that repeats another exactly (the scene reader's duplicate
    /// check), with a warning.
    fn drop_duplicates(
        &self,
        surfaces: &mut Vec<Surface>,
        faces: &[usize],
        warnings: &mut Vec<ImportWarning>,
    ) {
        let pairs = duplicate_surfaces(surfaces);
        if pairs.is_empty() {
            return;
        }
        let mut drop = vec![false; surfaces.len()];
        let mut named = Vec::new();
        // The face a surface comes from, as the other warnings name faces (QA of issue
        // #16: "face 7 of object \"Room\" (line 21)" beside a bare "\"Room.6\"").
        let face = |s: usize| match self.faces[faces[s]].line {
            0 => self.describe_face(faces[s]),
            l => format!("{}, line {l}", self.describe_face(faces[s])),
        };
        for &(upper, lower) in &pairs {
            if drop[upper] || drop[lower] {
                continue;
            }
            drop[upper] = true;
            if named.len() < NAMED_IN_WARNING {
                // One name for both (a shape placed twice): said once (QA of issue #16:
                // "\"Lamp.0\" (the same as \"Lamp.0\")").
                named.push(if surfaces[upper].name == surfaces[lower].name {
                    format!(
                        "\"{}\" ({}; the same as {})",
                        surfaces[upper].name,
                        face(upper),
                        face(lower)
                    )
                } else {
                    format!(
                        "\"{}\" ({}; the same as \"{}\", {})",
                        surfaces[upper].name,
                        face(upper),
                        surfaces[lower].name,
                        face(lower)
                    )
                });
            }
        }
        let count = drop.iter().filter(|&&d| d).count();
        if count > NAMED_IN_WARNING {
            named.push(format!("and {} more", count - NAMED_IN_WARNING));
        }
        let mut keep = drop.iter().map(|d| !d);
        surfaces.retain(|_| keep.next().unwrap_or(true));
        warnings.push(self.warning(format!(
            "dropped {count} face{} given twice (the same polygon facing the same way): {}",
            plural(count),
            named.join(", ")
        )));
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// A polygon that is not planar or not convex, as triangles: ear clipping (`earcutr`) on
/// its projection onto its best-fit plane (Newell normal); each triangle keeps the
/// polygon's own corners (so it is exactly planar) and is wound to face the way the
/// polygon does. Triangles that fail [`geometry::validate_polygon`] are left out and
/// counted (the second number). Nothing for a polygon without a normal (zero area).
pub(crate) fn triangulate(corners: &[DVec3]) -> (Vec<[DVec3; 3]>, usize) {
    let Some(normal) = geometry::polygon_normal(corners) else {
        return (Vec::new(), 0);
    };
    let (u, v) = normal.any_orthonormal_pair();
    let centre = geometry::vertex_mean(corners);
    let flat: Vec<f64> = corners
        .iter()
        .flat_map(|p| {
            let d = *p - centre;
            [d.dot(u), d.dot(v)]
        })
        .collect();
    let Ok(indices) = earcutr::earcut(&flat, &[], 2) else {
        return (Vec::new(), 0);
    };
    let mut triangles = Vec::with_capacity(indices.len() / 3);
    let mut lost = 0;
    for t in indices.chunks_exact(3) {
        let (Some(&a), Some(&b), Some(&c)) =
            (corners.get(t[0]), corners.get(t[1]), corners.get(t[2]))
        else {
            lost += 1;
            continue;
        };
        let mut tri = [a, b, c];
        if geometry::area_vector(&tri).dot(normal) < 0.0 {
            tri.swap(1, 2);
        }
        if geometry::validate_polygon(&tri).is_ok() {
            triangles.push(tri);
        } else {
            lost += 1;
        }
    }
    (triangles, lost)
}
