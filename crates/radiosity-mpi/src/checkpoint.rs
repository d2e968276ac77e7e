//! The checkpoint directory of `radiosity-mpi --checkpoint DIR`: a manifest naming the job
//! (scene, element count, mesh fingerprint, method) and one file per finished row block,
//! each written atomically as it arrives, so that a killed job resumed from the directory
//! loses no finished block.
//!
//! # Layout
//!
//! `DIR/manifest`, text, one `KEY VALUE` a line:
//!
//! ```text
//! radiosity-mpi checkpoint 1
//! scene examples/room.scene
//! elements 412
//! fingerprint 0123456789abcdef
//! method area k=2
//! ```
//!
//! `DIR/rows-START-END.blk` (START and END zero-padded to 10 digits), little-endian:
//! magic `RADBLK\0\0`, mesh fingerprint u64, n u64, START u64, END u64, the block's
//! (END - START) x n entries as f32 (as `BlockComputer::block` gives them), CRC-32 of every
//! byte before it.

use std::io;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The first line of a manifest.
const MANIFEST_HEADER: &str = "radiosity-mpi checkpoint 1";

/// The first 8 bytes of a block file.
const BLOCK_MAGIC: [u8; 8] = *b"RADBLK\0\0";

/// Bytes of a block file besides its entries: magic, four u64, the CRC.
const BLOCK_FIXED_BYTES: u64 = 8 + 4 * 8 + 4;

/// The most bytes of a manifest read: this program writes five short lines (the scene's
/// path is the only long one), so a longer file is not one of its manifests, and reading
/// it whole (a hostile or misplaced file of gigabytes) would only cost memory.
pub const MANIFEST_MAX_BYTES: u64 = 64 * 1024;

/// What a checkpoint belongs to: a job with another identity cannot use it.
#[derive(Clone, Debug, PartialEq)]
pub struct JobIdentity {
    /// The scene file as given (for messages only: a moved file is the same scene).
    pub scene: String,
    /// Elements of the mesh (rows of the matrix).
    pub elements: usize,
    /// The mesh fingerprint (`Prepared::fingerprint`, as in form-factor files).
    pub fingerprint: u64,
    /// The form-factor method, as `FormFactorMethod`'s Display writes it.
    pub method: String,
}

/// A checkpoint directory that cannot be used for this job. Every message names the
/// directory and says why.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// Reading or writing the directory failed.
    #[error("checkpoint {path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What went wrong.
        source: io::Error,
    },
    /// A fresh job was asked for, but the directory holds another job's blocks.
    #[error(
        "checkpoint directory {dir} already holds a job ({blocks} finished row blocks of {scene})"
    )]
    NotEmpty {
        /// The directory.
        dir: PathBuf,
        /// Its block files.
        blocks: usize,
        /// The scene its manifest names.
        scene: String,
    },
    /// A resume was asked for, but the directory holds no job.
    #[error("checkpoint directory {dir} holds no job to resume (it has no manifest)")]
    NothingToResume {
        /// The directory.
        dir: PathBuf,
    },
    /// The manifest is longer than any this program writes.
    #[error(
        "checkpoint manifest {path} is over {limit} bytes: not a manifest this program wrote \
         (it writes five short lines)"
    )]
    ManifestTooLong {
        /// The manifest file.
        path: PathBuf,
        /// `MANIFEST_MAX_BYTES`.
        limit: u64,
    },
    /// The manifest is not one this program writes.
    #[error("checkpoint manifest {path} line {line}: expected {expected}, found `{found}`")]
    BadManifest {
        /// The manifest file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What the line should hold.
        expected: &'static str,
        /// What it holds.
        found: String,
    },
    /// The checkpoint was computed with another method.
    #[error(
        "checkpoint {dir} was made with form-factor method `{found}`, but this job computes \
         `{expected}`; its blocks would mix two methods"
    )]
    OtherMethod {
        /// The directory.
        dir: PathBuf,
        /// The manifest's method.
        found: String,
        /// This job's.
        expected: String,
    },
    /// The checkpoint is for a mesh with another element count.
    #[error(
        "checkpoint {dir} is for a mesh of {found} elements (scene {scene}), but this scene \
         meshes to {expected}: another scene, or another MAX_PATCH_AREA"
    )]
    OtherElementCount {
        /// The directory.
        dir: PathBuf,
        /// The manifest's scene.
        scene: String,
        /// The manifest's element count.
        found: usize,
        /// This job's.
        expected: usize,
    },
    /// The checkpoint is for other geometry with the same element count.
    #[error(
        "checkpoint {dir} is for another mesh (fingerprint {found:016x}, scene {scene}; this \
         mesh is {expected:016x}): the scene's geometry differs"
    )]
    OtherMesh {
        /// The directory.
        dir: PathBuf,
        /// The manifest's scene.
        scene: String,
        /// The manifest's fingerprint.
        found: u64,
        /// This job's.
        expected: u64,
    },
}

/// An open checkpoint directory.
pub struct Checkpoint {
    dir: PathBuf,
    identity: JobIdentity,
}

/// The blocks a resumed checkpoint holds, and the block files it could not use.
#[derive(Debug, Default)]
pub struct Found {
    /// Finished blocks, by rows, sorted, not overlapping.
    pub blocks: Vec<Range<usize>>,
    /// Block files refused (damaged, truncated, or overlapping another), with why: their
    /// rows are computed again.
    pub refused: Vec<(PathBuf, String)>,
}

impl Checkpoint {
    /// Opens `dir` for the job `identity`: with `resume`, the directory must hold this
    /// job's manifest, and its finished blocks are returned; without, it must hold no job,
    /// and is created with this job's manifest.
    pub fn open(
        dir: &Path,
        identity: &JobIdentity,
        resume: bool,
    ) -> Result<(Checkpoint, Found), CheckpointError> {
        let io_err = |path: &Path| {
            let path = path.to_path_buf();
            move |source| CheckpointError::Io { path, source }
        };
        let manifest = dir.join("manifest");
        let checkpoint = Checkpoint {
            dir: dir.to_path_buf(),
            identity: identity.clone(),
        };
        if !resume {
            if manifest.exists() {
                let found = read_manifest(&manifest)?;
                return Err(CheckpointError::NotEmpty {
                    dir: dir.to_path_buf(),
                    blocks: checkpoint.block_files()?.len(),
                    scene: found.scene,
                });
            }
            std::fs::create_dir_all(dir).map_err(io_err(dir))?;
            radiosity::io::write_atomically(&manifest, |out| {
                use std::io::Write;
                write!(
                    out,
                    "{MANIFEST_HEADER}\nscene {}\nelements {}\nfingerprint {:016x}\nmethod {}\n",
                    identity.scene, identity.elements, identity.fingerprint, identity.method
                )
            })
            .map_err(io_err(&manifest))?;
            return Ok((checkpoint, Found::default()));
        }
        if !manifest.exists() {
            return Err(CheckpointError::NothingToResume {
                dir: dir.to_path_buf(),
            });
        }
        let found = read_manifest(&manifest)?;
        if found.method != identity.method {
            return Err(CheckpointError::OtherMethod {
                dir: dir.to_path_buf(),
                found: found.method,
                expected: identity.method.clone(),
            });
        }
        if found.elements != identity.elements {
            return Err(CheckpointError::OtherElementCount {
                dir: dir.to_path_buf(),
                scene: found.scene,
                found: found.elements,
                expected: identity.elements,
            });
        }
        if found.fingerprint != identity.fingerprint {
            return Err(CheckpointError::OtherMesh {
                dir: dir.to_path_buf(),
                scene: found.scene,
                found: found.fingerprint,
                expected: identity.fingerprint,
            });
        }
        let mut result = Found::default();
        let mut files = checkpoint.block_files()?;
        files.sort_by_key(|(rows, _)| (rows.start, rows.end));
        for (rows, path) in files {
            if rows.end > identity.elements {
                result
                    .refused
                    .push((path, beyond(&rows, identity.elements)));
                continue;
            }
            if result
                .blocks
                .last()
                .is_some_and(|last| last.end > rows.start)
            {
                result.refused.push((path, "overlaps another block".into()));
                continue;
            }
            match checkpoint.load(&rows) {
                Ok(_) => result.blocks.push(rows),
                Err(why) => result.refused.push((path, why)),
            }
        }
        Ok((checkpoint, result))
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn block_path(&self, rows: &Range<usize>) -> PathBuf {
        self.dir
            .join(format!("rows-{:010}-{:010}.blk", rows.start, rows.end))
    }

    /// The block files in the directory, by the rows their names give.
    fn block_files(&self) -> Result<Vec<(Range<usize>, PathBuf)>, CheckpointError> {
        let entries = std::fs::read_dir(&self.dir).map_err(|source| CheckpointError::Io {
            path: self.dir.clone(),
            source,
        })?;
        let mut out = Vec::new();
        for entry in entries.flatten() {
            let name = entry.file_name();
            let Some(rows) = parse_block_name(&name.to_string_lossy()) else {
                continue;
            };
            out.push((rows, entry.path()));
        }
        Ok(out)
    }

    /// Writes a finished block (atomically: a killed job leaves the whole file or none).
    pub fn save(&self, rows: &Range<usize>, data: &[f32]) -> Result<(), CheckpointError> {
        let path = self.block_path(rows);
        let bytes = encode_block(
            self.identity.fingerprint,
            self.identity.elements,
            rows,
            data,
        );
        radiosity::io::write_atomically(&path, |out| {
            use std::io::Write;
            out.write_all(&bytes)
        })
        .map_err(|source| CheckpointError::Io { path, source })
    }

    /// Reads a finished block back; `Err` says why the file cannot be used.
    ///
    /// No more bytes are read than a block of `rows` has, plus one to see that the file is
    /// longer: a block file replaced by something endless (a link to `/dev/zero`, a pipe)
    /// or huge is refused without being read whole.
    pub fn load(&self, rows: &Range<usize>) -> Result<Vec<f32>, String> {
        let n = self.identity.elements;
        if rows.end > n {
            return Err(beyond(rows, n));
        }
        let expected = block_bytes(rows, n).ok_or_else(|| beyond(rows, n))?;
        let path = self.block_path(rows);
        let bytes = read_at_most(&path, expected.saturating_add(1)).map_err(|e| e.to_string())?;
        decode_block(&bytes, self.identity.fingerprint, n, rows)
    }
}

/// Why a block of `rows` is not one of an `n`-element job's.
fn beyond(rows: &Range<usize>, n: usize) -> String {
    format!(
        "its rows {}..{} lie beyond the mesh's {n} elements",
        rows.start, rows.end
    )
}

/// The bytes of a block file of `rows` of `n` entries; `None` past u64.
fn block_bytes(rows: &Range<usize>, n: usize) -> Option<u64> {
    (rows.len() as u64)
        .checked_mul(n as u64)?
        .checked_mul(4)?
        .checked_add(BLOCK_FIXED_BYTES)
}

/// The first `limit` bytes of the file at `path` (all of it if shorter).
fn read_at_most(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(limit)
        .read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// `rows-START-END.blk` to START..END (END > START), for the names this program writes
/// only (START and END of 10 digits or more, without sign): another spelling of the same
/// rows (`rows-0-2.blk`, `rows-+0-2.blk`) would be a second file for one block, and
/// [`Checkpoint::load`] reads the name it writes.
fn parse_block_name(name: &str) -> Option<Range<usize>> {
    let (start, end) = name
        .strip_prefix("rows-")?
        .strip_suffix(".blk")?
        .split_once('-')?;
    let (start, end): (usize, usize) = (start.parse().ok()?, end.parse().ok()?);
    (end > start && name == format!("rows-{start:010}-{end:010}.blk")).then_some(start..end)
}

/// The bytes of a block file.
fn encode_block(fingerprint: u64, n: usize, rows: &Range<usize>, data: &[f32]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(BLOCK_FIXED_BYTES as usize + 4 * data.len());
    bytes.extend(BLOCK_MAGIC);
    for v in [fingerprint, n as u64, rows.start as u64, rows.end as u64] {
        bytes.extend(v.to_le_bytes());
    }
    bytes.extend(data.iter().flat_map(|x| x.to_le_bytes()));
    let crc = crc32fast::hash(&bytes);
    bytes.extend(crc.to_le_bytes());
    bytes
}

/// A block file's entries, checked against the job and the rows its name gives.
fn decode_block(
    bytes: &[u8],
    fingerprint: u64,
    n: usize,
    rows: &Range<usize>,
) -> Result<Vec<f32>, String> {
    let expected = block_bytes(rows, n).ok_or_else(|| beyond(rows, n))?;
    if bytes.len() as u64 != expected {
        // `load` reads at most one byte more than a block has.
        let length = if bytes.len() as u64 > expected {
            "more than that".to_string()
        } else {
            format!("{} bytes", bytes.len())
        };
        return Err(format!(
            "{length}, but rows {}..{} of {n} entries make {expected}",
            rows.start, rows.end
        ));
    }
    let (body, crc) = bytes.split_at(bytes.len() - 4);
    let stored = u32::from_le_bytes(crc.try_into().expect("4 bytes"));
    let computed = crc32fast::hash(body);
    if stored != computed {
        return Err(format!(
            "checksum {computed:08x} does not match the stored {stored:08x}"
        ));
    }
    if body[..8] != BLOCK_MAGIC {
        return Err("not a block file (it does not start with RADBLK)".into());
    }
    let word = |k: usize| u64::from_le_bytes(body[8 + 8 * k..16 + 8 * k].try_into().expect("8"));
    let header = [fingerprint, n as u64, rows.start as u64, rows.end as u64];
    if (0..4).map(word).ne(header) {
        return Err(format!(
            "its header (fingerprint {:016x}, {} elements, rows {}..{}) is not this job's block",
            word(0),
            word(1),
            word(2),
            word(3)
        ));
    }
    Ok(body[40..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect())
}

/// A manifest's fields.
fn read_manifest(path: &Path) -> Result<JobIdentity, CheckpointError> {
    let bytes =
        read_at_most(path, MANIFEST_MAX_BYTES + 1).map_err(|source| CheckpointError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if bytes.len() as u64 > MANIFEST_MAX_BYTES {
        return Err(CheckpointError::ManifestTooLong {
            path: path.to_path_buf(),
            limit: MANIFEST_MAX_BYTES,
        });
    }
    let text = match std::str::from_utf8(&bytes) {
        Ok(text) => text,
        Err(e) => {
            let good = &bytes[..e.valid_up_to()];
            return Err(CheckpointError::BadManifest {
                path: path.to_path_buf(),
                line: 1 + good.iter().filter(|&&b| b == b'\n').count(),
                expected: "UTF-8 text",
                found: format!("the byte 0x{:02x}", bytes[e.valid_up_to()]),
            });
        }
    };
    let mut lines = text.lines();
    let bad =
        |line: usize, expected: &'static str, found: Option<&str>| CheckpointError::BadManifest {
            path: path.to_path_buf(),
            line,
            expected,
            found: found.unwrap_or("end of file").to_string(),
        };
    let first = lines.next();
    if first != Some(MANIFEST_HEADER) {
        return Err(bad(1, "`radiosity-mpi checkpoint 1`", first));
    }
    let mut field = |line: usize, key: &str, expected: &'static str| {
        let text = lines.next();
        text.and_then(|t| t.strip_prefix(key)?.strip_prefix(' '))
            .map(str::to_string)
            .ok_or_else(|| bad(line, expected, text))
    };
    let scene = field(2, "scene", "`scene PATH`")?;
    let elements = field(3, "elements", "`elements N`")?;
    let elements = elements
        .parse()
        .map_err(|_| bad(3, "`elements N` with N a whole number", Some(&elements)))?;
    let fingerprint = field(4, "fingerprint", "`fingerprint HEX`")?;
    let fingerprint = u64::from_str_radix(&fingerprint, 16).map_err(|_| {
        bad(
            4,
            "`fingerprint HEX` with 16 hex digits",
            Some(&fingerprint),
        )
    })?;
    let method = field(5, "method", "`method NAME`")?;
    Ok(JobIdentity {
        scene,
        elements,
        fingerprint,
        method,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn identity() -> JobIdentity {
        JobIdentity {
            scene: "room.scene".into(),
            elements: 5,
            fingerprint: 0xfeed_f00d,
            method: "area k=2".into(),
        }
    }

    /// Blocks saved by one job come back, bit for bit, to the job resumed.
    #[test]
    fn saved_blocks_come_back_on_resume() {
        let dir = tempfile::tempdir().unwrap();
        let (cp, found) = Checkpoint::open(dir.path(), &identity(), false).unwrap();
        assert!(found.blocks.is_empty());
        let data: Vec<f32> = (0..10).map(|k| k as f32 / 7.0).collect();
        cp.save(&(3..5), &data).unwrap();
        cp.save(&(0..1), &data[..5]).unwrap();
        let (cp, found) = Checkpoint::open(dir.path(), &identity(), true).unwrap();
        assert_eq!(found.blocks, vec![0..1, 3..5]);
        assert!(found.refused.is_empty(), "{:?}", found.refused);
        assert_eq!(cp.load(&(3..5)).unwrap(), data);
    }

    /// A damaged block file is refused with its reason (its rows are computed again).
    #[test]
    fn a_damaged_block_is_refused_with_its_reason() {
        let dir = tempfile::tempdir().unwrap();
        let (cp, _) = Checkpoint::open(dir.path(), &identity(), false).unwrap();
        cp.save(&(0..2), &[0.5; 10]).unwrap();
        let path = dir.path().join("rows-0000000000-0000000002.blk");
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[45] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        let (_, found) = Checkpoint::open(dir.path(), &identity(), true).unwrap();
        assert!(found.blocks.is_empty());
        assert_eq!(found.refused.len(), 1);
        assert!(
            found.refused[0].1.starts_with("checksum"),
            "{:?}",
            found.refused
        );
        bytes.truncate(20);
        std::fs::write(&path, &bytes).unwrap();
        let (_, found) = Checkpoint::open(dir.path(), &identity(), true).unwrap();
        assert_eq!(
            found.refused[0].1,
            "20 bytes, but rows 0..2 of 5 entries make 84"
        );
    }

    /// Another method, element count or mesh: refused, saying which.
    #[test]
    fn a_checkpoint_of_another_job_is_refused_saying_why() {
        let dir = tempfile::tempdir().unwrap();
        Checkpoint::open(dir.path(), &identity(), false).unwrap();
        let d = dir.path().display();
        let other = JobIdentity {
            method: "contour k=2".into(),
            ..identity()
        };
        let err = Checkpoint::open(dir.path(), &other, true).err().unwrap();
        assert_eq!(
            err.to_string(),
            format!(
                "checkpoint {d} was made with form-factor method `area k=2`, but this job \
                 computes `contour k=2`; its blocks would mix two methods"
            )
        );
        let other = JobIdentity {
            elements: 9,
            ..identity()
        };
        let err = Checkpoint::open(dir.path(), &other, true).err().unwrap();
        assert_eq!(
            err.to_string(),
            format!(
                "checkpoint {d} is for a mesh of 5 elements (scene room.scene), but this scene \
                 meshes to 9: another scene, or another MAX_PATCH_AREA"
            )
        );
        let other = JobIdentity {
            fingerprint: 1,
            ..identity()
        };
        let err = Checkpoint::open(dir.path(), &other, true).err().unwrap();
        assert_eq!(
            err.to_string(),
            format!(
                "checkpoint {d} is for another mesh (fingerprint 00000000feedf00d, scene \
                 room.scene; this mesh is 0000000000000001): the scene's geometry differs"
            )
        );
        // A fresh job in a directory holding a job, and a resume of nothing.
        let err = Checkpoint::open(dir.path(), &identity(), false)
            .err()
            .unwrap();
        assert!(
            matches!(err, CheckpointError::NotEmpty { blocks: 0, .. }),
            "{err}"
        );
        let empty = tempfile::tempdir().unwrap();
        let err = Checkpoint::open(empty.path(), &identity(), true)
            .err()
            .unwrap();
        assert!(
            matches!(err, CheckpointError::NothingToResume { .. }),
            "{err}"
        );
    }

    /// A manifest edited by hand: the line and what was expected.
    #[test]
    fn a_bad_manifest_names_the_line() {
        let dir = tempfile::tempdir().unwrap();
        Checkpoint::open(dir.path(), &identity(), false).unwrap();
        let path = dir.path().join("manifest");
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, text.replace("elements 5", "elements five")).unwrap();
        let err = Checkpoint::open(dir.path(), &identity(), true)
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            format!(
                "checkpoint manifest {} line 3: expected `elements N` with N a whole number, \
                 found `five`",
                path.display()
            )
        );
    }

    /// A block file whose rows end past the mesh (its header forged to match) is refused,
    /// so the resumed job never writes rows the matrix does not have.
    #[test]
    fn a_block_beyond_the_mesh_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (cp, _) = Checkpoint::open(dir.path(), &identity(), false).unwrap();
        cp.save(&(4..7), &[0.25; 15]).unwrap();
        // Names whose rows overflow any byte count: refused the same way, no overflow.
        let huge = format!("rows-0000000001-{}.blk", usize::MAX);
        std::fs::write(dir.path().join(&huge), b"RADBLK").unwrap();
        let (cp, found) = Checkpoint::open(dir.path(), &identity(), true).unwrap();
        assert!(found.blocks.is_empty());
        let mut why: Vec<&str> = found.refused.iter().map(|(_, w)| w.as_str()).collect();
        why.sort();
        assert_eq!(
            why,
            [
                format!(
                    "its rows 1..{} lie beyond the mesh's 5 elements",
                    usize::MAX
                ),
                "its rows 4..7 lie beyond the mesh's 5 elements".to_string(),
            ]
        );
        assert_eq!(
            cp.load(&(1..usize::MAX)).unwrap_err(),
            format!(
                "its rows 1..{} lie beyond the mesh's 5 elements",
                usize::MAX
            )
        );
    }

    /// A block file that never ends (a link to /dev/zero) is refused after reading one
    /// byte more than its block has, not read until memory runs out.
    #[cfg(target_os = "linux")]
    #[test]
    fn an_endless_block_file_is_refused_without_reading_it_whole() {
        let dir = tempfile::tempdir().unwrap();
        Checkpoint::open(dir.path(), &identity(), false).unwrap();
        let link = dir.path().join("rows-0000000000-0000000002.blk");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        let (_, found) = Checkpoint::open(dir.path(), &identity(), true).unwrap();
        assert!(found.blocks.is_empty());
        // 2 rows x 5 entries x 4 bytes + 44 fixed bytes.
        assert_eq!(
            found.refused[0].1,
            "more than that, but rows 0..2 of 5 entries make 84"
        );
    }

    /// Only the names this program writes are blocks: another spelling of the same rows is
    /// left alone (it would be a second file for one block, and `load` reads the first).
    #[test]
    fn block_names_of_another_spelling_are_not_blocks() {
        assert_eq!(
            parse_block_name("rows-0000000000-0000000002.blk"),
            Some(0..2)
        );
        for name in [
            "rows-0-2.blk",
            "rows-+000000000-0000000002.blk",
            "rows-0000000002-0000000002.blk",
            "rows-0000000000-0000000002.blk.tmp",
        ] {
            assert_eq!(parse_block_name(name), None, "{name}");
        }
    }

    /// A manifest that is not text, or far longer than one: refused saying which, and the
    /// long one without being read whole.
    #[test]
    fn a_manifest_of_bytes_or_of_any_length_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("manifest");
        std::fs::write(&path, b"radiosity-mpi checkpoint 1\nscene \xff\n").unwrap();
        let err = Checkpoint::open(dir.path(), &identity(), true)
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            format!(
                "checkpoint manifest {} line 2: expected UTF-8 text, found `the byte 0xff`",
                path.display()
            )
        );
        let mut long = b"radiosity-mpi checkpoint 1\nscene ".to_vec();
        long.resize(MANIFEST_MAX_BYTES as usize + 1, b'a');
        std::fs::write(&path, &long).unwrap();
        let err = Checkpoint::open(dir.path(), &identity(), true)
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            format!(
                "checkpoint manifest {} is over 65536 bytes: not a manifest this program \
                 wrote (it writes five short lines)",
                path.display()
            )
        );
    }
}
