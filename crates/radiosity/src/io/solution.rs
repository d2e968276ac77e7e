//! The per-element solution, for scripts: one record per element with its surface, its
//! index within the surface, its area and centroid, and its radiosity B per band (the
//! unnormalised values of the solve, before the display normalisation of paper 2.2 and the
//! gamma correction of paper 2.7).
//!
//! Two formats, chosen by the file name: CSV (RFC 4180) by default, a JSON array of objects
//! when the name ends in `.json` (any case). Both use the field names of [`HEADER`].
//!
//! Units: areas and centroids in the scene's length unit (squared for areas), radiosity in
//! the scene's emission units (W/m^2, or lm/m^2 for the photometric scenes). Both shapes
//! are a contract (issue #2: the CSV's header on line 1, the JSON an array of records with
//! the same fields), so the units are documented (README, "Exporting") and printed by
//! `solve` on stderr, not written into the files.

use std::io::{self, Write};
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::mesh::Mesh;
use crate::scene::Scene;

/// The CSV header line (without its line ending); also the JSON field names.
pub const HEADER: &str =
    "surface,element,area,centroid_x,centroid_y,centroid_z,radiosity_r,radiosity_g,radiosity_b";

/// One element of the solution, as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ElementRecord {
    /// The name of the element's surface.
    pub surface: String,
    /// The element's index within its surface, from 0.
    pub element: u32,
    /// The element's area (scene units squared).
    pub area: f64,
    /// The x coordinate of the element's centroid.
    pub centroid_x: f64,
    /// The y coordinate of the element's centroid.
    pub centroid_y: f64,
    /// The z coordinate of the element's centroid.
    pub centroid_z: f64,
    /// Red radiosity.
    pub radiosity_r: f64,
    /// Green radiosity.
    pub radiosity_g: f64,
    /// Blue radiosity.
    pub radiosity_b: f64,
}

/// The records of every element of `mesh` (cut from `scene`) with radiosities `element_b`,
/// in mesh order.
///
/// # Panics
/// If `element_b` does not have one entry per element.
pub fn records(scene: &Scene, mesh: &Mesh, element_b: &[[f64; 3]]) -> Vec<ElementRecord> {
    assert_eq!(element_b.len(), mesh.len(), "one radiosity per element");
    mesh.elements
        .iter()
        .zip(element_b)
        .enumerate()
        .map(|(e, (el, b))| {
            let s = el.surface as usize;
            let first = mesh.surface_elements.get(s).map_or(0, |r| r.start);
            ElementRecord {
                surface: scene
                    .surfaces
                    .get(s)
                    .map_or_else(|| s.to_string(), |x| x.name.clone()),
                element: e as u32 - first,
                area: el.area,
                centroid_x: el.centroid.x,
                centroid_y: el.centroid.y,
                centroid_z: el.centroid.z,
                radiosity_r: b[0],
                radiosity_g: b[1],
                radiosity_b: b[2],
            }
        })
        .collect()
}

/// The fields of one CSV row, in [`HEADER`] order, numbers as Rust's `Display` writes them.
///
/// The rows go through the `csv` crate, which quotes per RFC 4180 (a field holding a comma,
/// a double quote, a carriage return or a line feed is quoted, inner quotes doubled), but
/// not through its serde support: that writes floats its own way (`1.0`, `1.5e-7`), and
/// the files keep the shortest exact form without an exponent (`1`, `0.00000015`).
fn csv_fields(r: &ElementRecord) -> [String; 9] {
    [
        r.surface.clone(),
        r.element.to_string(),
        r.area.to_string(),
        r.centroid_x.to_string(),
        r.centroid_y.to_string(),
        r.centroid_z.to_string(),
        r.radiosity_r.to_string(),
        r.radiosity_g.to_string(),
        r.radiosity_b.to_string(),
    ]
}

/// An `InvalidInput` error unless `element_b` has one entry per element of `mesh` (what
/// the solution and the surface report check before writing anything).
pub(crate) fn one_per_element(mesh: &Mesh, element_b: &[[f64; 3]]) -> io::Result<()> {
    if element_b.len() == mesh.len() {
        return Ok(());
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{} radiosities for {} elements",
            element_b.len(),
            mesh.len()
        ),
    ))
}

/// Writes the solution to `path`: CSV with the header line [`HEADER`] and one row per
/// element (numbers in Rust's `Display` form, the shortest that reads back exactly, never
/// with an exponent: 1.5e-7 is written `0.00000015`; lines end in `\n`), or, when the file name ends in `.json` (any case), a JSON array of
/// objects with the same fields (non-finite numbers become `null`). The file is written
/// atomically (see [`crate::io::write_atomically`]).
///
/// Returns an `InvalidInput` error, writing nothing, when `element_b` does not have one
/// entry per element of `mesh`.
pub fn write_solution(
    path: &Path,
    scene: &Scene,
    mesh: &Mesh,
    element_b: &[[f64; 3]],
) -> io::Result<()> {
    one_per_element(mesh, element_b)?;
    let rows = records(scene, mesh, element_b);
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    crate::io::write_atomically(path, |w| {
        if json {
            serde_json::to_writer_pretty(&mut *w, &rows).map_err(io::Error::other)?;
            writeln!(w)
        } else {
            let mut csv = csv::Writer::from_writer(w);
            csv.write_record(HEADER.split(','))?;
            for r in &rows {
                csv.write_record(csv_fields(r))?;
            }
            csv.flush()
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::scene::{Rgb, Surface};
    use glam::dvec3;

    fn scene() -> Scene {
        let rect = |z: f64| {
            vec![
                dvec3(0., 0., z),
                dvec3(2., 0., z),
                dvec3(2., 1., z),
                dvec3(0., 1., z),
            ]
        };
        let surface = |name: &str, z| Surface {
            name: name.into(),
            emission: Rgb::BLACK,
            reflectance: Rgb([0.5; 3]),
            vertices: rect(z),
            photometry: Default::default(),
        };
        Scene {
            surfaces: vec![surface("plain", 0.0), surface("a, \"b\"\nc", 1.0)],
            camera: None,
            lights: Vec::new(),
        }
    }

    fn temp(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("radiosity-solution-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn csv_header_rows_and_quoting() {
        let s = scene();
        let mesh = mesh_scene(&s, 1.0).unwrap();
        assert_eq!(mesh.len(), 4); // each 2 x 1 rectangle in two unit squares
        let b = vec![
            [0.1, 0.2, 1.0 / 3.0],
            [1.0, 2.0, 3.0],
            [0.0; 3],
            [1.5e-7, 5.5, 7.0],
        ];
        let path = temp("sol.csv");
        write_solution(&path, &s, &mesh, &b).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.split('\n').collect();
        assert_eq!(
            lines[0],
            "surface,element,area,centroid_x,centroid_y,centroid_z,radiosity_r,radiosity_g,radiosity_b"
        );
        // The unit squares of surface 0 have centroids (0.5, 0.5, 0) and (1.5, 0.5, 0).
        assert_eq!(lines[1], "plain,0,1,0.5,0.5,0,0.1,0.2,0.3333333333333333");
        assert_eq!(lines[2], "plain,1,1,1.5,0.5,0,1,2,3");
        // The second surface's name holds a comma, quotes and a newline, so its record
        // spans two physical lines.
        assert_eq!(lines[3], "\"a, \"\"b\"\"");
        assert_eq!(lines[4], "c\",0,1,0.5,0.5,1,0,0,0");
        assert_eq!(lines[6], "c\",1,1,1.5,0.5,1,0.00000015,5.5,7");
        assert_eq!(lines.len(), 8); // header, 4 records over 6 lines, final empty piece
        assert_eq!(lines[7], "");
        // Numbers read back exactly.
        assert_eq!(
            lines[1].rsplit(',').next().unwrap().parse::<f64>().unwrap(),
            1.0 / 3.0
        );
        std::fs::remove_file(&path).unwrap();
    }

    /// The hand-written CSV of the writer before it used the `csv` crate.
    fn old_csv(rows: &[ElementRecord]) -> String {
        let field = |s: &str| {
            if s.contains([',', '"', '\n', '\r']) {
                format!("\"{}\"", s.replace('"', "\"\""))
            } else {
                s.to_string()
            }
        };
        let mut out = format!("{HEADER}\n");
        for r in rows {
            out += &format!(
                "{},{},{},{},{},{},{},{},{}\n",
                field(&r.surface),
                r.element,
                r.area,
                r.centroid_x,
                r.centroid_y,
                r.centroid_z,
                r.radiosity_r,
                r.radiosity_g,
                r.radiosity_b
            );
        }
        out
    }

    #[test]
    fn csv_bytes_are_those_of_the_hand_written_writer() {
        let mut s = scene();
        let names = [
            "",
            " lead",
            "tab\there",
            "cr\rlf",
            "q\"",
            "#hash",
            "é, ü",
            "x",
        ];
        let values = [
            0.0,
            -0.0,
            1.0,
            1e300,
            -2.5e-300,
            f64::MIN_POSITIVE / 3.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1.0 / 3.0,
            123456789.125,
            -1.5e-7,
        ];
        for (k, name) in names.iter().enumerate() {
            s.surfaces[k % 2].name = name.to_string();
            let mesh = mesh_scene(&s, 1.0).unwrap();
            let b: Vec<[f64; 3]> = (0..mesh.len())
                .map(|e| [0, 1, 2].map(|i| values[(k + 3 * e + i) % values.len()]))
                .collect();
            let path = temp(&format!("bytes-{k}.csv"));
            write_solution(&path, &s, &mesh, &b).unwrap();
            let text = std::fs::read_to_string(&path).unwrap();
            assert_eq!(text, old_csv(&records(&s, &mesh, &b)), "{name:?}");
            std::fs::remove_file(&path).unwrap();
        }
    }

    #[test]
    fn json_parses_back() {
        let s = scene();
        let mesh = mesh_scene(&s, 1.0).unwrap();
        let b = vec![
            [0.1, 0.2, 1.0 / 3.0],
            [1.0, 2.0, 3.0],
            [0.0; 3],
            [1.5e-7, 5.5, 7.0],
        ];
        let path = temp("sol.JSON");
        write_solution(&path, &s, &mesh, &b).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let back: Vec<ElementRecord> = serde_json::from_str(&text).unwrap();
        assert_eq!(back.len(), 4);
        assert_eq!(back[3].surface, "a, \"b\"\nc");
        assert_eq!(back[3].element, 1);
        assert_eq!(back[3].radiosity_r, 1.5e-7);
        assert_eq!(back[0].radiosity_b, 1.0 / 3.0);
        assert_eq!((back[1].centroid_x, back[1].centroid_y), (1.5, 0.5));
        assert_eq!(back[2].centroid_z, 1.0);
        assert_eq!(back[2].area, 1.0);
        // The field names are those of the CSV header, in order.
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let keys: Vec<&str> = v[0]
            .as_object()
            .unwrap()
            .keys()
            .map(|k| k.as_str())
            .collect();
        let mut want: Vec<&str> = HEADER.split(',').collect();
        let mut got = keys.clone();
        want.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, want);
        std::fs::remove_file(&path).unwrap();
        // A wrong radiosity count is refused and writes nothing.
        let err = write_solution(&path, &s, &mesh, &b[..3]).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(!path.exists());
    }
}
