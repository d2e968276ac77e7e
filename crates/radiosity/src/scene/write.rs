//! Writing scenes in the Appendix A format.
//!
//! Numbers are printed with Rust's `{}` formatting of `f64`, the shortest text that reads
//! back as the same value, so reading a written scene gives back exactly the scene written
//! (for any scene that [`super::parse_scene`] could have produced). Boxes are written as their
//! six patches; the camera hint is not part of the format and is not written.

use std::io::{self, Write};
use std::path::Path;

use super::{Scene, Surface};

/// Writes `scene` as scene-file text to `out`.
///
/// Fails with [`io::ErrorKind::InvalidInput`] for a surface name that would not read back as
/// itself (one with a line break, a `//`, or leading or trailing whitespace).
pub fn write_scene(scene: &Scene, out: &mut impl Write) -> io::Result<()> {
    for (i, s) in scene.surfaces.iter().enumerate() {
        check_name(i, &s.name)?;
    }
    writeln!(
        out,
        "// Radiosity scene (De Angelis 1998, Appendix A format), written by radiosity {}.",
        env!("CARGO_PKG_VERSION")
    )?;
    writeln!(out, "// {} surfaces.", scene.surfaces.len())?;
    writeln!(out, "MAX_PATCH_AREA {}", scene.settings.max_patch_area)?;
    writeln!(out, "INTEGRAL_STEPS {}", scene.settings.integral_steps)?;
    writeln!(out, "SCENEBEGIN")?;
    for surface in &scene.surfaces {
        writeln!(out)?;
        write_patch(surface, out)?;
    }
    writeln!(out)?;
    writeln!(out, "SCENEEND")
}

/// Writes `scene` to the file at `path`, replacing it atomically (temporary file and rename).
pub fn write_scene_file(scene: &Scene, path: &Path) -> io::Result<()> {
    crate::write_atomically(path, |w| write_scene(scene, w))
}

/// One `PATCHBEGIN` ... `PATCHEND` block.
fn write_patch(s: &Surface, out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "PATCHBEGIN")?;
    writeln!(out, "#{}", s.name)?;
    writeln!(out, "VERTICES {}", s.vertices.len())?;
    for (key, value) in ["Er", "Eg", "Eb"].iter().zip(s.emission.0) {
        writeln!(out, "{key} {value}")?;
    }
    for (key, value) in ["Rr", "Rg", "Rb"].iter().zip(s.reflectance.0) {
        writeln!(out, "{key} {value}")?;
    }
    for (k, v) in s.vertices.iter().enumerate() {
        writeln!(out, "VERTEX{k} {} {} {}", v.x, v.y, v.z)?;
    }
    writeln!(out, "PATCHEND")
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
