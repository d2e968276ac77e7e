//! The per-surface report (`solve --report report.csv`): one row per input surface with its
//! area and the radiosity over its elements, for a spreadsheet or a lighting check.
//!
//! The file starts with one comment line giving the units ([`unit_comment`]), then the
//! header line [`HEADER`] (a contract: scripts key on these names), then one row per
//! surface of the scene, in scene order:
//!
//! * `area`: the surface's area, the sum of its elements' areas (scene units squared);
//! * `mean_r` .. `mean_b`: its radiosity B per band averaged over its elements weighted by
//!   their areas (the power it sends out per unit area), in the scene's emission units;
//! * `min_*`, `max_*`: the smallest and largest element radiosity per band;
//! * `mean_luminance`: 0.2126 mean_r + 0.7152 mean_g + 0.0722 mean_b (ITU-R BT.709).
//!
//! Numbers are written as for [`crate::io::solution`] (shortest exact form, no exponent);
//! names are quoted per RFC 4180 where needed, and also when they start with `#` (so that
//! no row reads as a comment line) or with or end in a space. A surface that no element covers (none in a
//! mesh from [`crate::mesh::mesh_scene`]) gets area 0 and empty radiosity fields. The file
//! is written atomically ([`crate::io::write_atomically`]).

use std::io::{self, Write};
use std::path::Path;

use crate::light::Rgb;
use crate::mesh::Mesh;
use crate::scene::Scene;

/// The header line (without its line ending).
pub const HEADER: &str =
    "surface,area,mean_r,mean_g,mean_b,min_r,min_g,min_b,max_r,max_g,max_b,mean_luminance";

/// The comment line on top of the file (without its line ending), `length_unit` the
/// scene's length unit in words (as the importers give it, e.g. `metres (glTF's unit)`;
/// `scene units` where none is known).
pub fn unit_comment(length_unit: &str) -> String {
    format!(
        "# radiosity in the scene's emission units (W/m^2 or lm/m^2, as the scene gives E); \
         area in the square of the scene's unit of length, {length_unit}; mean over \
         each surface's elements weighted by area; luminance with Rec. 709 weights"
    )
}

/// One surface's row.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceRecord {
    /// The surface's name.
    pub surface: String,
    /// Its area: the sum of its elements' areas (scene units squared).
    pub area: f64,
    /// Area-weighted mean radiosity per band; `None` when no element covers it.
    pub mean: Option<[f64; 3]>,
    /// Smallest element radiosity per band.
    pub min: Option<[f64; 3]>,
    /// Largest element radiosity per band.
    pub max: Option<[f64; 3]>,
}

impl SurfaceRecord {
    /// The luminance of the mean radiosity (Rec. 709 weights).
    pub fn mean_luminance(&self) -> Option<f64> {
        self.mean.map(|m| Rgb(m).luminance())
    }
}

/// The rows of every surface of `scene`, in scene order, from the elements of `mesh`
/// (cut from `scene`, possibly refined: elements are grouped by their surface index, not
/// by position) with radiosities `element_b`.
///
/// # Panics
/// If `element_b` does not have one entry per element.
pub fn surface_records(scene: &Scene, mesh: &Mesh, element_b: &[[f64; 3]]) -> Vec<SurfaceRecord> {
    assert_eq!(element_b.len(), mesh.len(), "one radiosity per element");
    let n = scene.surfaces.len();
    let mut area = vec![0.0; n];
    let mut weighted = vec![[0.0; 3]; n];
    let mut min = vec![[f64::INFINITY; 3]; n];
    let mut max = vec![[f64::NEG_INFINITY; 3]; n];
    let mut count = vec![0usize; n];
    for (el, b) in mesh.elements.iter().zip(element_b) {
        let s = el.surface as usize;
        if s >= n {
            continue;
        }
        area[s] += el.area;
        count[s] += 1;
        for k in 0..3 {
            weighted[s][k] += el.area * b[k];
            min[s][k] = min[s][k].min(b[k]);
            max[s][k] = max[s][k].max(b[k]);
        }
    }
    scene
        .surfaces
        .iter()
        .enumerate()
        .map(|(s, surface)| {
            let covered = count[s] > 0;
            SurfaceRecord {
                surface: surface.name.clone(),
                area: area[s],
                mean: (covered && area[s] > 0.0).then(|| weighted[s].map(|w| w / area[s])),
                min: covered.then_some(min[s]),
                max: covered.then_some(max[s]),
            }
        })
        .collect()
}

/// Writes the report of `mesh` (cut from `scene`, whose length unit is `length_unit`) with
/// radiosities `element_b` to `path` (module documentation).
///
/// Returns an `InvalidInput` error, writing nothing, when `element_b` does not have one
/// entry per element of `mesh`.
pub fn write_surface_report(
    path: &Path,
    scene: &Scene,
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    length_unit: &str,
) -> io::Result<()> {
    crate::io::solution::one_per_element(mesh, element_b)?;
    let rows = surface_records(scene, mesh, element_b);
    let three = |v: Option<[f64; 3]>| {
        v.map_or([String::new(), String::new(), String::new()], |v| {
            v.map(|x| x.to_string())
        })
    };
    crate::io::write_atomically(path, |w| {
        writeln!(w, "{}", unit_comment(length_unit))?;
        writeln!(w, "{HEADER}")?;
        for r in &rows {
            let mut fields = vec![csv_name(&r.surface), r.area.to_string()];
            fields.extend(three(r.mean));
            fields.extend(three(r.min));
            fields.extend(three(r.max));
            fields.push(r.mean_luminance().map_or(String::new(), |y| y.to_string()));
            writeln!(w, "{}", fields.join(","))?;
        }
        Ok(())
    })
}

/// A surface name as a CSV field: quoted (inner quotes doubled) when it holds a comma, a
/// quote, a line break, or starts with '#' or a space (where a reader that skips comment
/// lines, or trims, would misread it); as it is otherwise. The other fields are numbers.
pub(crate) fn csv_name(name: &str) -> String {
    let needs = name.starts_with(['#', ' ', '\t'])
        || name.ends_with([' ', '\t'])
        || name.contains([',', '"', '\r', '\n']);
    if needs {
        format!("\"{}\"", name.replace('"', "\"\""))
    } else {
        name.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::scene::Surface;
    use glam::dvec3;

    #[test]
    fn names_a_reader_could_take_for_a_comment_or_trim_are_quoted() {
        assert_eq!(csv_name("Floor"), "Floor");
        assert_eq!(csv_name("#2 lamp"), "\"#2 lamp\"");
        assert_eq!(csv_name("a \"b\""), "\"a \"\"b\"\"\"");
        assert_eq!(csv_name(" x"), "\" x\"");
        assert_eq!(csv_name("two\nlines"), "\"two\nlines\"");
    }

    #[test]
    fn rows_are_area_weighted_means_with_extremes_and_luminance() {
        // A 3 x 1 rectangle meshed at area 1 gives three unit squares; the first surface
        // takes radiosities 1, 2 and 6 in red: mean 3, min 1, max 6.
        let rect = |z: f64, w: f64| {
            vec![
                dvec3(0., 0., z),
                dvec3(w, 0., z),
                dvec3(w, 1., z),
                dvec3(0., 1., z),
            ]
        };
        let surface = |name: &str, z, w| Surface {
            name: name.into(),
            emission: Rgb::BLACK,
            reflectance: Rgb([0.5; 3]),
            vertices: rect(z, w),
            photometry: Default::default(),
        };
        let scene = Scene {
            surfaces: vec![surface("wall", 0.0, 3.0), surface("a, b", 1.0, 1.0)],
            camera: None,
            lights: Vec::new(),
        };
        let mesh = mesh_scene(&scene, 1.0).unwrap();
        assert_eq!(mesh.len(), 4);
        let b = [
            [1.0, 0.0, 0.5],
            [2.0, 0.0, 0.5],
            [6.0, 3.0, 0.5],
            [0.25, 0.5, 1.0],
        ];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("report.csv");
        write_surface_report(&path, &scene, &mesh, &b, "metres (glTF's unit)").unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines[0].starts_with('#'), "{}", lines[0]);
        assert!(
            lines[0].contains("unit of length, metres (glTF's unit);"),
            "{}",
            lines[0]
        );
        assert_eq!(
            lines[1],
            "surface,area,mean_r,mean_g,mean_b,min_r,min_g,min_b,max_r,max_g,max_b,mean_luminance"
        );
        // Luminance 0.2126 x 3 + 0.7152 x 1 + 0.0722 x 0.5 = 1.3891.
        let wall: Vec<f64> = lines[2]
            .split(',')
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        let expect = [3.0, 3.0, 1.0, 0.5, 1.0, 0.0, 0.5, 6.0, 3.0, 0.5, 1.3891];
        for (got, want) in wall.iter().zip(expect) {
            assert!((got - want).abs() < 1e-12, "{}: {got} vs {want}", lines[2]);
        }
        assert_eq!(wall.len(), expect.len());
        assert!(lines[3].starts_with("\"a, b\",1,0.25,0.5,1,0.25,0.5,1,0.25,0.5,1,"));
        assert_eq!(lines.len(), 4);
        // A wrong radiosity count is refused, writing nothing.
        let other = dir.path().join("bad.csv");
        let err = write_surface_report(&other, &scene, &mesh, &b[..3], "m").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(!other.exists());
    }
}
