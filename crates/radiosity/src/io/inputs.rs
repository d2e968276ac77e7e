//! The files this process has read as inputs, so that no output is ever written over one.
//!
//! Once a program calls [`protect_inputs`] (the command line does, first thing), every
//! reader in [`crate::io`] notes the files it opens (a scene, an OBJ's material files, a
//! glTF's buffers, a DXF's materials file, a form-factor file, a path-traced reference),
//! and [`super::write_atomically`], which every writer uses, refuses to replace one of
//! them. A check by name in each command missed the files an input names itself: an OBJ's
//! `mtllib room.mtl` was replaced by `solve room.obj -o room.mtl` and by an OBJ export's
//! own MTL. Files are compared by device and inode ([`super::is_same_file`]), so another
//! spelling or a link to an input is caught too. An editor that saves over the file it
//! opened, as the viewer's modeller does, releases it first ([`release_input`]).
//!
//! Off unless asked for: a library caller (or a test) that reads a file, changes it and
//! writes it back would otherwise be refused, and in a long-lived process a deleted
//! input's inode may be reused by a new file.

use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// A set of input files, compared by device and inode.
#[derive(Debug, Default)]
pub struct Inputs {
    paths: Mutex<Vec<PathBuf>>,
}

impl Inputs {
    /// An empty set.
    pub const fn new() -> Inputs {
        Inputs {
            paths: Mutex::new(Vec::new()),
        }
    }

    /// Notes `path` as an input.
    pub fn note(&self, path: &Path) {
        let mut paths = self.paths.lock().unwrap_or_else(|e| e.into_inner());
        if !paths.iter().any(|p| p == path) {
            paths.push(path.to_path_buf());
        }
    }

    /// Forgets `path` (and any other spelling of it).
    pub fn release(&self, path: &Path) {
        let mut paths = self.paths.lock().unwrap_or_else(|e| e.into_inner());
        paths.retain(|p| !(p == path || super::is_same_file(p, path)));
    }

    /// The input that `path` is (by device and inode, whatever the spelling), if any.
    pub fn input_at(&self, path: &Path) -> Option<PathBuf> {
        let paths = self.paths.lock().unwrap_or_else(|e| e.into_inner());
        paths.iter().find(|p| super::is_same_file(p, path)).cloned()
    }

    /// An `AlreadyExists` error naming `path` when it is one of the inputs.
    pub fn refuse_output(&self, path: &Path) -> io::Result<()> {
        match self.input_at(path) {
            None => Ok(()),
            Some(input) => {
                let spelled = if input.as_os_str() == path.as_os_str() {
                    String::new()
                } else {
                    format!(" (read as {})", input.display())
                };
                Err(io::Error::new(
                    io::ErrorKind::AlreadyExists,
                    format!(
                        "{} is an input of this run{spelled}: an output never replaces an \
                         input; give the output another name",
                        path.display(),
                    ),
                ))
            }
        }
    }
}

/// Whether [`protect_inputs`] was called.
static PROTECTED: AtomicBool = AtomicBool::new(false);

/// This process's inputs (noted only once protected).
static INPUTS: Inputs = Inputs::new();

/// Turns the protection on for the rest of the process: from now on the readers note their
/// files, and no writer here replaces one.
pub fn protect_inputs() {
    PROTECTED.store(true, Ordering::SeqCst);
}

/// Notes `path` as an input of this process, when protected.
pub fn note_input(path: &Path) {
    if PROTECTED.load(Ordering::SeqCst) {
        INPUTS.note(path);
    }
}

/// Forgets `path` as an input, so that it may be written: for an editor saving over the
/// file it opened.
pub fn release_input(path: &Path) {
    INPUTS.release(path);
}

/// The input of this process that `path` is (by device and inode), if any, when protected:
/// for a program that checks its outputs before the work that leads to writing them.
pub fn input_at(path: &Path) -> Option<PathBuf> {
    if PROTECTED.load(Ordering::SeqCst) {
        INPUTS.input_at(path)
    } else {
        None
    }
}

/// An error when `path` is an input of this process (see [`Inputs::refuse_output`]).
pub(crate) fn refuse_output(path: &Path) -> io::Result<()> {
    if PROTECTED.load(Ordering::SeqCst) {
        INPUTS.refuse_output(path)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_is_refused_as_an_output_until_released() {
        // A set of its own: the process-wide one is off in the library's tests, which
        // rewrite the files they read.
        let dir = std::env::temp_dir().join(format!("radiosity-inputs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("room.mtl");
        std::fs::write(&input, "newmtl wall\n").unwrap();
        let inputs = Inputs::new();
        inputs.note(&input);
        // Another spelling of the same file is caught, and named as read.
        let other = dir.join(".").join("room.mtl");
        assert_eq!(inputs.input_at(&other), Some(input.clone()));
        let err = inputs.refuse_output(&other).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::AlreadyExists);
        assert!(err.to_string().contains("read as"), "{err}");
        assert!(inputs.refuse_output(&dir.join("other.mtl")).is_ok());
        inputs.release(&other);
        assert_eq!(inputs.input_at(&input), None);
        assert!(inputs.refuse_output(&input).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
