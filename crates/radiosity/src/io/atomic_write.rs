//! Writing output files so that a reader never sees a half-written one.

use std::io::{self, Write};
use std::path::Path;

/// Writes `path` by calling `write` on a temporary file beside it, then renaming it into place;
/// refused (`AlreadyExists`) when `path` is a file this process has read as an input, once
/// the process protects its inputs ([`super::inputs`]).
///
/// The temporary file is [`tempfile`]'s, made in the directory of `path` (a rename within
/// one directory is atomic on POSIX file systems), so `path` either keeps its old content or
/// gets the whole new content, never part of it. On error the temporary file is removed and
/// `path` is left as it was. The new file gets the permissions [`std::fs::File::create`]
/// would give it (0666 less the umask), not the owner-only ones of a temporary file.
///
/// The temporary file is named `.NAME.PID.RANDOM.tmp` (PID this process's id). `tempfile`
/// removes it on every exit path that unwinds, but a run killed by a signal (or an abort)
/// leaves it behind; so before writing, the temporary files of `path` whose PID is no
/// longer a running process (on Linux: no /proc/PID) and that were last written a minute or
/// more ago are removed ([`remove_stale_temporaries`]). The age spares a file another
/// machine is writing through a shared file system, where its PID means nothing here.
///
/// A symbolic link is followed (its target is replaced, the link kept), and an existing
/// path that is not a regular file (a device such as /dev/stdout, a named pipe) is written
/// to directly, since it cannot be replaced by renaming.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut io::BufWriter<std::fs::File>) -> io::Result<()>,
) -> io::Result<()> {
    super::inputs::refuse_output(path)?;
    if let Ok(meta) = std::fs::metadata(path) {
        if !meta.is_file() {
            let mut out = io::BufWriter::new(std::fs::OpenOptions::new().write(true).open(path)?);
            write(&mut out)?;
            return out.flush();
        }
    }
    let (file, tmp, target) = temporary_beside(path)?;
    let mut out = io::BufWriter::new(file);
    write(&mut out)?;
    out.flush()?;
    out.get_ref().sync_all()?;
    drop(out);
    tmp.persist(target).map_err(|e| e.error)
}

/// The temporary file that [`write_atomically`] writes and renames onto `path`: made beside
/// `path` (beside the target of a symbolic link), named `.NAME.PID.RANDOM.tmp`, with the
/// permissions [`std::fs::File::create`] would give, after the stale temporaries of `path`
/// are removed. Returns the file, its path, and the path to rename it to (`path`, or the
/// target of the link): `tmp.persist(target)` puts it in place; dropping `tmp` removes it. For writers
/// that fill a file out of order (`form_factor_file::FormFactorStreamWriter`); the caller
/// refuses inputs and non-regular files first.
pub(crate) fn temporary_beside(
    path: &Path,
) -> io::Result<(std::fs::File, tempfile::TempPath, std::path::PathBuf)> {
    let resolved = link_target(path);
    let path = resolved.as_path();
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(io::ErrorKind::InvalidInput, "output path has no file name")
    })?;
    remove_stale_temporaries(dir, &name.to_string_lossy(), STALE_AFTER);
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{}.{}.", name.to_string_lossy(), std::process::id());
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    // The file is written through its own handle; `tmp` removes it when dropped, which is
    // what happens on every early return of the callers.
    // tempfile's error names the temporary file ("permission denied at path
    // \"ro/.x.png.3551.W83OrR.tmp\""), which the user never asked for: its cause alone.
    let made = builder.tempfile_in(dir).map_err(|e| {
        let text = e.to_string();
        let cause = text.split(" at path ").next().unwrap_or(&text).to_string();
        io::Error::new(e.kind(), cause)
    })?;
    let (file, tmp) = made.into_parts();
    Ok((file, tmp, path.to_path_buf()))
}

/// Whether [`write_atomically`] can write `path`, found without writing it: a temporary
/// file is made beside it and removed (a device or other non-regular file that exists is
/// taken as writable). For checking outputs before long work (QA of issue #16: a render
/// into a read-only folder failed only after its solve).
pub fn check_writable(path: &Path) -> io::Result<()> {
    if let Ok(meta) = std::fs::metadata(path) {
        if !meta.is_file() {
            return Ok(());
        }
    }
    let (_file, _tmp, _) = temporary_beside(path)?;
    Ok(())
}

/// Where writing `path` writes: `path`, or where the symbolic links it is lead (each
/// target taken relative to its link's folder), whether or not the last one exists yet (a
/// link to a file not yet written is written through; `canonicalize` refused it). A loop
/// of links stops after 40, as the system's resolution does, and the write then fails
/// there.
pub fn link_target(path: &Path) -> std::path::PathBuf {
    let mut at = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::read_link(&at) {
            Ok(target) => {
                at = match at.parent() {
                    Some(folder) => folder.join(target),
                    None => target,
                }
            }
            Err(_) => break,
        }
    }
    at
}

/// How long a dead run's temporary file is left alone: longer than any write of ours takes
/// between two writes to the file.
const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(60);

/// Removes from `dir` the temporary files `.NAME.PID.RANDOM.tmp` of output `name` left by
/// runs that are no longer running (see [`write_atomically`]) and untouched for `age`.
/// Returns how many were removed. Errors are ignored: cleaning up is a courtesy, and a
/// file another run removes first is fine. Does nothing where it cannot tell whether a
/// process runs (no /proc).
pub fn remove_stale_temporaries(dir: &Path, name: &str, age: std::time::Duration) -> usize {
    if !Path::new("/proc/self").exists() {
        return 0;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let prefix = format!(".{name}.");
    let mut removed = 0;
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let file_name = file_name.to_string_lossy();
        let Some(middle) = file_name
            .strip_prefix(&prefix)
            .and_then(|rest| rest.strip_suffix(".tmp"))
        else {
            continue;
        };
        // PID.RANDOM, the PID all digits.
        let Some(pid) = middle
            .split_once('.')
            .and_then(|(pid, _)| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid == std::process::id() || Path::new(&format!("/proc/{pid}")).exists() {
            continue;
        }
        let old_enough = entry
            .metadata()
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|elapsed| elapsed >= age);
        if old_enough && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// True when `a` and `b` name the same existing file (after symbolic links, through hard
/// links and `..`): same device and inode on Unix, same canonical path elsewhere. A path
/// that does not exist is no file's, so writing it cannot overwrite an input.
pub fn is_same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        (ma.dev(), ma.ino()) == (mb.dev(), mb.ino())
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        matches!(
            (std::fs::canonicalize(a), std::fs::canonicalize(b)),
            (Ok(x), Ok(y)) if x == y
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest PID Linux hands out is 2^22 (pid_max); 4,000,000,000 is never running.
    const DEAD_PID: u32 = 4_000_000_000;

    #[test]
    fn a_killed_runs_temporary_file_is_removed_by_the_next_write() {
        let dir = std::env::temp_dir().join(format!("radiosity-aw-stale-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let make = |name: &str, age_s: u64| {
            let path = dir.join(name);
            let file = std::fs::File::create(&path).unwrap();
            let then = std::time::SystemTime::now() - std::time::Duration::from_secs(age_s);
            file.set_modified(then).unwrap();
            path
        };
        let dead_old = make(&format!(".out.png.{DEAD_PID}.aB3xYz.tmp"), 3600);
        let dead_new = make(&format!(".out.png.{DEAD_PID}.q1w2e3.tmp"), 0);
        let alive = make(&format!(".out.png.{}.zzzzzz.tmp", std::process::id()), 3600);
        let other_output = make(&format!(".other.png.{DEAD_PID}.aB3xYz.tmp"), 3600);
        let not_ours = make(".out.png.notapid.tmp", 3600);
        write_atomically(&dir.join("out.png"), |w| w.write_all(b"png")).unwrap();
        if Path::new("/proc/self").exists() {
            assert!(
                !dead_old.exists(),
                "a dead run's old temporary file is left"
            );
        }
        for kept in [&dead_new, &alive, &other_output, &not_ours] {
            assert!(kept.exists(), "{} removed", kept.display());
        }
        // The write's own temporary file is gone too.
        let left: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(left.len(), 5, "{left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn same_file_is_seen_through_other_spellings_and_links() {
        let dir = std::env::temp_dir().join(format!("radiosity-aw-same-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let file = dir.join("x.scene");
        std::fs::write(&file, "x").unwrap();
        assert!(is_same_file(&file, &dir.join("sub/../x.scene")));
        let hard = dir.join("hard.scene");
        std::fs::hard_link(&file, &hard).unwrap();
        assert!(is_same_file(&file, &hard));
        #[cfg(unix)]
        {
            let soft = dir.join("soft.scene");
            std::os::unix::fs::symlink(&file, &soft).unwrap();
            assert!(is_same_file(&soft, &file));
        }
        std::fs::write(dir.join("other.scene"), "x").unwrap();
        assert!(!is_same_file(&file, &dir.join("other.scene")));
        assert!(!is_same_file(&file, &dir.join("missing.scene")));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn failed_write_leaves_no_file() {
        let dir = std::env::temp_dir().join(format!("radiosity-aw-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.txt");
        let err = write_atomically(&path, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("boom"))
        });
        assert!(err.is_err());
        assert!(!path.exists());
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            0,
            "temporary file left behind"
        );
        write_atomically(&path, |w| w.write_all(b"whole")).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "whole");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn failed_write_leaves_the_old_file_untouched() {
        let dir = std::env::temp_dir().join(format!("radiosity-aw-old-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.txt");
        std::fs::write(&path, "old").unwrap();
        let err = write_atomically(&path, |w| {
            w.write_all(&[b'x'; 100_000])?;
            Err(io::Error::other("boom"))
        });
        assert_eq!(err.unwrap_err().to_string(), "boom");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "temporary file left behind"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn new_file_has_the_permissions_of_file_create() {
        use std::os::unix::fs::PermissionsExt;
        let dir = std::env::temp_dir().join(format!("radiosity-aw-mode-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let created = dir.join("created.txt");
        std::fs::File::create(&created).unwrap();
        let written = dir.join("written.txt");
        write_atomically(&written, |w| w.write_all(b"x")).unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode();
        assert_eq!(mode(&written), mode(&created));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writes_through_symlinks_and_to_devices() {
        let dir = std::env::temp_dir().join(format!("radiosity-aw-link-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("target.txt");
        std::fs::write(&target, "old").unwrap();
        let link = dir.join("link.txt");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        write_atomically(&link, |w| w.write_all(b"new")).unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink(),
            "link kept"
        );
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        // A device is written to, not replaced.
        write_atomically(Path::new("/dev/null"), |w| w.write_all(b"x")).unwrap();
        assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
