//! `XDG_RUNTIME_DIR` for the window: the window system's libraries (libwayland, probed by
//! winit and wgpu even under X11) print "XDG_RUNTIME_DIR is invalid or not set in the
//! environment" at every probe where it is missing, as it is for root under Xvfb, six lines
//! of alarm about nothing the user did wrong. `view` sets a private directory first.
#![cfg_attr(not(feature = "viewer"), allow(dead_code))]

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

/// True when `value` (the variable's value) would be refused: unset, empty, not an
/// absolute path, or not a directory.
pub fn needs_runtime_dir(value: Option<&OsStr>) -> bool {
    match value {
        None => true,
        Some(v) => {
            let path = Path::new(v);
            !path.is_absolute() || !path.is_dir()
        }
    }
}

/// A directory of this user's only (mode 0700) under `parent`, named for the user:
/// created when missing; refused when it exists but belongs to another user or others can
/// enter it (a directory someone else prepared).
#[cfg(target_os = "linux")]
pub fn private_runtime_dir(parent: &Path) -> std::io::Result<PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    // /proc/self belongs to the process's user.
    let uid = std::fs::metadata("/proc/self")?.uid();
    let dir = parent.join(format!("radiosity-runtime-{uid}"));
    match std::fs::DirBuilder::new().mode(0o700).create(&dir) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(e) => return Err(e),
    }
    let meta = std::fs::symlink_metadata(&dir)?;
    if !meta.is_dir() || meta.uid() != uid || meta.permissions().mode() & 0o077 != 0 {
        return Err(std::io::Error::other(format!(
            "{} is not a private directory of this user",
            dir.display()
        )));
    }
    Ok(dir)
}

/// Where the variable is missing or unusable, sets it to [`private_runtime_dir`] in the
/// system's temporary directory; where that cannot be made, says once how to silence the
/// libraries' lines. Call before any thread starts (it changes the environment).
pub fn ensure_runtime_dir() {
    #[cfg(target_os = "linux")]
    {
        if !needs_runtime_dir(std::env::var_os("XDG_RUNTIME_DIR").as_deref()) {
            return;
        }
        match private_runtime_dir(&std::env::temp_dir()) {
            Ok(dir) => std::env::set_var("XDG_RUNTIME_DIR", dir),
            Err(e) => errln!(
                "note: XDG_RUNTIME_DIR is not set and no private one could be made ({e}); the \
                 window system may print \"XDG_RUNTIME_DIR is invalid\" lines, harmless: set \
                 XDG_RUNTIME_DIR to a directory of yours with mode 0700 to silence them"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runtime_dir_is_needed_when_unset_relative_or_missing() {
        assert!(needs_runtime_dir(None));
        assert!(needs_runtime_dir(Some(OsStr::new(""))));
        assert!(needs_runtime_dir(Some(OsStr::new("relative/dir"))));
        assert!(needs_runtime_dir(Some(OsStr::new("/no/such/runtime/dir"))));
        let here = std::env::temp_dir();
        assert!(!needs_runtime_dir(Some(here.as_os_str())));
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn private_runtime_dir_is_made_once_with_mode_0700() {
        use std::os::unix::fs::PermissionsExt;
        let parent =
            std::env::temp_dir().join(format!("radiosity-xdg-test-{}", std::process::id()));
        std::fs::create_dir_all(&parent).unwrap();
        let dir = private_runtime_dir(&parent).unwrap();
        let mode = std::fs::metadata(&dir).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o700);
        // A second call takes the same directory.
        assert_eq!(private_runtime_dir(&parent).unwrap(), dir);
        // One others may enter is refused, not used.
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        assert!(private_runtime_dir(&parent).is_err());
        std::fs::remove_dir_all(&parent).unwrap();
    }
}
