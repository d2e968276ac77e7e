//! The files this process has read as inputs, so that no output is ever written over one.
//!
//! Every reader in [`crate::io`] notes the files it opens (a scene, an OBJ's material
//! files, a glTF's buffers, a DXF's materials file, a form-factor file, a path-traced
//! reference), and [`super::write_atomically`], which every writer uses, refuses to replace
//! one of them. A check by name in each command missed the files an input names itself: an
//! OBJ's `mtllib room.mtl` was replaced by `solve room.obj -o room.mtl` and by an OBJ
//! export's own MTL. Files are compared by device and inode ([`super::is_same_file`]), so
//! another spelling or a link to an input is caught too. An editor that saves over the file
//! it opened, as the viewer's modeller does, releases it first ([`release_input`]).

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The inputs noted so far, in the order read.
static INPUTS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Notes `path` as an input of this process: outputs may not replace it.
pub fn note_input(path: &Path) {
    let mut inputs = INPUTS.lock().unwrap_or_else(|e| e.into_inner());
    if !inputs.iter().any(|p| p == path) {
        inputs.push(path.to_path_buf());
    }
}

/// Forgets `path` (and any other spelling of it) as an input, so that it may be written:
/// for an editor saving over the file it opened.
pub fn release_input(path: &Path) {
    let mut inputs = INPUTS.lock().unwrap_or_else(|e| e.into_inner());
    inputs.retain(|p| !(p == path || super::is_same_file(p, path)));
}

/// The input that `path` is (by device and inode, whatever the spelling), if any.
pub fn input_at(path: &Path) -> Option<PathBuf> {
    let inputs = INPUTS.lock().unwrap_or_else(|e| e.into_inner());
    inputs
        .iter()
        .find(|p| super::is_same_file(p, path))
        .cloned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_is_refused_as_an_output_until_released() {
        let dir = std::env::temp_dir().join(format!("radiosity-inputs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("room.mtl");
        std::fs::write(&input, "newmtl wall\nKd 0.5 0.5 0.5\n").unwrap();
        note_input(&input);
        // Another spelling of the same file is caught.
        let other = dir.join(".").join("room.mtl");
        assert_eq!(input_at(&other), Some(input.clone()));
        let err = super::super::write_atomically(&other, |w| {
            use std::io::Write;
            w.write_all(b"surface,area\n")
        })
        .unwrap_err();
        assert!(err.to_string().contains("room.mtl"), "{err}");
        assert_eq!(
            std::fs::read_to_string(&input).unwrap(),
            "newmtl wall\nKd 0.5 0.5 0.5\n",
            "the input is untouched"
        );
        release_input(&input);
        assert_eq!(input_at(&input), None);
        super::super::write_atomically(&input, |w| {
            use std::io::Write;
            w.write_all(b"saved")
        })
        .unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
