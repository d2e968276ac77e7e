//! Writing scenes in the Appendix A format.
//!
//! Numbers are printed with Rust's `{}` formatting of `f64`, the shortest text that reads
//! back as the same value, so reading a written scene gives back exactly the scene written
//! (for any scene that [`super::parse_scene`] could have produced). The settings are written
//! first, from the [`MeshSettings`] given beside the scene. Boxes are written as their six
//! patches; the camera hint is not part of the format and is not written.

use std::io::{self, Write};
use std::path::Path;

use std::f64::consts::PI;

use crate::geometry;
use crate::light::Rgb;
use crate::luminaire::{Distribution, Luminaire, Output};
use crate::mesh::MeshSettings;
use crate::scene::{EmissionGiven, Scene, Surface};

/// Writes `scene` with `settings` as scene-file text to `out`.
///
/// Fails with [`io::ErrorKind::InvalidInput`] for a surface name that would not read back as
/// itself (one with a line break, a `//`, or leading or trailing whitespace).
pub fn write_scene(scene: &Scene, settings: MeshSettings, out: &mut impl Write) -> io::Result<()> {
    for (i, s) in scene.surfaces.iter().enumerate() {
        check_name(i, &s.name)?;
    }
    for (i, l) in scene.lights.iter().enumerate() {
        check_name(i, &l.name)
            .map_err(|e| io::Error::new(e.kind(), e.to_string().replacen("surface", "light", 1)))?;
    }
    writeln!(
        out,
        "// Radiosity scene (De Angelis 1998, Appendix A format), written by radiosity {}.",
        env!("CARGO_PKG_VERSION")
    )?;
    writeln!(out, "// {} surfaces.", scene.surfaces.len())?;
    writeln!(out, "MAX_PATCH_AREA {}", settings.max_patch_area)?;
    writeln!(out, "INTEGRAL_STEPS {}", settings.integral_steps)?;
    writeln!(out, "SCENEBEGIN")?;
    for surface in &scene.surfaces {
        writeln!(out)?;
        write_patch(surface, out)?;
    }
    for light in &scene.lights {
        writeln!(out)?;
        write_light(light, out)?;
    }
    writeln!(out)?;
    writeln!(out, "SCENEEND")
}

/// Writes `scene` with `settings` to the file at `path`, replacing it atomically (temporary
/// file and rename).
pub fn write_scene_file(scene: &Scene, settings: MeshSettings, path: &Path) -> io::Result<()> {
    crate::io::write_atomically(path, |w| write_scene(scene, settings, w))
}

/// One `PATCHBEGIN` ... `PATCHEND` block.
fn write_patch(s: &Surface, out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "PATCHBEGIN")?;
    writeln!(out, "#{}", s.name)?;
    writeln!(out, "VERTICES {}", s.vertices.len())?;
    // The photometric keywords only where they give back exactly the values the surface
    // has (a surface recoloured since it was read is written with its new exitance).
    match s.photometry.emission {
        EmissionGiven::Luminance(l) if s.emission == Rgb::splat(PI * l) => {
            writeln!(out, "LUMINANCE {l}")?;
        }
        EmissionGiven::Flux(p)
            if s.emission == Rgb::splat(p / geometry::polygon_area(&s.vertices)) =>
        {
            writeln!(out, "FLUX {p}")?;
        }
        _ => {
            for (key, value) in ["Er", "Eg", "Eb"].iter().zip(s.emission.0) {
                writeln!(out, "{key} {value}")?;
            }
        }
    }
    if s.photometry.opening && s.reflectance == Rgb::BLACK {
        writeln!(out, "OPENING")?;
    } else {
        for (key, value) in ["Rr", "Rg", "Rb"].iter().zip(s.reflectance.0) {
            writeln!(out, "{key} {value}")?;
        }
    }
    for (k, v) in s.vertices.iter().enumerate() {
        writeln!(out, "VERTEX{k} {} {} {}", v.x, v.y, v.z)?;
    }
    writeln!(out, "PATCHEND")
}

/// One `LIGHTBEGIN` ... `LIGHTEND` block.
fn write_light(l: &Luminaire, out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "LIGHTBEGIN")?;
    writeln!(out, "#{}", l.name)?;
    let (p, a) = (l.position, l.aim);
    writeln!(out, "POSITION {} {} {}", p.x, p.y, p.z)?;
    writeln!(out, "AIM {} {} {}", a.x, a.y, a.z)?;
    match l.output {
        Output::Intensity(i) => writeln!(out, "INTENSITY {i}")?,
        Output::Flux(f) => writeln!(out, "FLUX {f}")?,
        Output::AsTabulated => {}
    }
    match &l.distribution {
        Distribution::Isotropic => writeln!(out, "DISTRIBUTION ISOTROPIC")?,
        Distribution::Cosine => writeln!(out, "DISTRIBUTION COSINE")?,
        Distribution::Ies { written, .. } => writeln!(out, "DISTRIBUTION IES {written}")?,
    }
    if l.colour != Rgb::splat(1.0) {
        let c = l.colour.0;
        writeln!(out, "COLOUR {} {} {}", c[0], c[1], c[2])?;
    }
    writeln!(out, "LIGHTEND")
}

/// An error for a name that the reader would not give back unchanged.
fn check_name(index: usize, name: &str) -> io::Result<()> {
    let bad = name.contains(['\n', '\r']) || name.contains("//") || name.trim() != name;
    if bad {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "surface {index} has the name {name:?}, which cannot be written to a scene \
                 file (no line breaks, \"//\", or leading or trailing spaces)"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{parse_scene, read_scene, SceneFile};
    use super::*;
    use crate::geometry;
    use crate::scene::cornell_box;

    /// The example scene files at the repository root, by name.
    const EXAMPLES: [(&str, &str); 5] = [
        (
            "cornell_box.scene",
            include_str!("../../../../../examples/cornell_box.scene"),
        ),
        (
            "room.scene",
            include_str!("../../../../../examples/room.scene"),
        ),
        (
            "occluder.scene",
            include_str!("../../../../../examples/occluder.scene"),
        ),
        (
            "triangles.scene",
            include_str!("../../../../../examples/triangles.scene"),
        ),
        (
            "paper196.scene",
            include_str!("../../../../../examples/paper196.scene"),
        ),
    ];

    fn written(file: &SceneFile) -> String {
        let mut out = Vec::new();
        write_scene(&file.scene, file.settings, &mut out).unwrap();
        String::from_utf8(out).unwrap()
    }

    /// Asserts that reading the written scene gives it and its settings back bit for bit.
    #[track_caller]
    fn round_trips(file: &SceneFile) {
        let text = written(file);
        let mut back = parse_scene(&text, "written").unwrap_or_else(|e| panic!("{e}\n{text}"));
        back.scene.camera = file.scene.camera;
        assert_eq!(&back, file);
        let bits = |f: &SceneFile| -> Vec<u64> {
            f.scene
                .surfaces
                .iter()
                .flat_map(|s| s.vertices.iter().flat_map(|v| v.to_array()))
                .chain([f.settings.max_patch_area])
                .map(f64::to_bits)
                .collect()
        };
        assert_eq!(bits(&back), bits(file));
        // Writing again gives the same text.
        assert_eq!(written(&back), text);
    }

    #[test]
    fn every_example_parses_and_round_trips() {
        for (name, text) in EXAMPLES {
            let file = parse_scene(text, name).unwrap_or_else(|e| panic!("{e}"));
            assert!(text.starts_with("// "), "{name} needs a header comment");
            round_trips(&file);
        }
    }

    #[test]
    fn builtin_box_round_trips() {
        round_trips(&cornell_box());
    }

    #[test]
    fn written_layout() {
        let text = written(&cornell_box());
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines[0].starts_with("// "));
        let code: Vec<&str> = lines
            .iter()
            .copied()
            .filter(|l| !l.starts_with("//"))
            .collect();
        assert_eq!(
            &code[..4],
            ["MAX_PATCH_AREA 1000", "INTEGRAL_STEPS 2", "SCENEBEGIN", ""]
        );
        assert_eq!(
            &code[4..15],
            [
                "PATCHBEGIN",
                "#Light",
                "VERTICES 4",
                "Er 53.40707511102649",
                "Eg 37.69911184307752",
                "Eb 12.566370614359172",
                "Rr 0.78",
                "Rg 0.78",
                "Rb 0.78",
                "VERTEX0 343 548.8 227",
                "VERTEX1 343 548.8 332",
            ]
        );
        assert_eq!(lines.last(), Some(&"SCENEEND"));
    }

    #[test]
    fn room_example_contents() {
        let SceneFile { settings, scene } = parse_scene(EXAMPLES[1].1, "room.scene").unwrap();
        let (lo, hi) = scene.bounds();
        assert_eq!((lo, hi), (glam::DVec3::ZERO, glam::dvec3(5.0, 2.7, 4.0)));
        let lights = scene
            .surfaces
            .iter()
            .filter(|s| s.emission.max_band() > 0.0);
        assert_eq!(lights.count(), 2);
        // The ottoman (a box from a face and a height) rises from the floor.
        let top = &scene
            .surfaces
            .iter()
            .find(|s| s.name == "Ottoman.top")
            .unwrap();
        assert!(top.vertices.iter().all(|v| (v.y - 0.42).abs() < 1e-12));
        let mesh = crate::mesh::mesh_scene(&scene, settings.max_patch_area).unwrap();
        println!(
            "room.scene: {} surfaces, {} elements",
            scene.surfaces.len(),
            mesh.len()
        );
    }

    #[test]
    fn paper196_example_meshes_to_196_elements() {
        let SceneFile { settings, scene } = parse_scene(EXAMPLES[4].1, "paper196.scene").unwrap();
        assert_eq!(settings.integral_steps, 2);
        let mesh = crate::mesh::mesh_scene(&scene, settings.max_patch_area).unwrap();
        assert_eq!(mesh.len(), 196);
    }

    #[test]
    fn occluder_example_contents() {
        let scene = parse_scene(EXAMPLES[2].1, "occluder.scene").unwrap().scene;
        let occluder = scene
            .surfaces
            .iter()
            .find(|s| s.name == "Occluder")
            .unwrap();
        assert_eq!(occluder.reflectance.0, [0.0; 3]);
        // The occluder lies between the light and the floor, under the light.
        let light = scene.surfaces.iter().find(|s| s.name == "Light").unwrap();
        let l = geometry::polygon_centroid(&light.vertices);
        let o = geometry::polygon_centroid(&occluder.vertices);
        assert!(o.y > 0.0 && o.y < l.y);
        assert!((o.x - l.x).abs() < 0.5 && (o.z - l.z).abs() < 0.5);
        // The room's faces look inwards: the floor is the box's base, facing up.
        let floor = scene
            .surfaces
            .iter()
            .find(|s| s.name == "Room.base")
            .unwrap();
        assert_eq!(
            geometry::polygon_normal(&floor.vertices),
            Some(glam::DVec3::Y)
        );
    }

    #[test]
    fn unwritable_names_are_refused() {
        let SceneFile {
            settings,
            mut scene,
        } = cornell_box();
        for bad in ["a\nb", "a // b", " padded", "x\r"] {
            scene.surfaces[0].name = bad.to_string();
            let mut out = Vec::new();
            let err = write_scene(&scene, settings, &mut out).unwrap_err();
            assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        }
    }

    #[test]
    fn file_round_trip() {
        let dir = std::env::temp_dir().join(format!("radiosity-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("box.scene");
        let file = cornell_box();
        write_scene_file(&file.scene, file.settings, &path).unwrap();
        let mut back = read_scene(&path).unwrap();
        back.scene.camera = file.scene.camera;
        assert_eq!(back, file);
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "temporary file left"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
