//! The form-factor file: the matrix written by `radiosity formfactors` and read back with
//! `--form-factors FILE` (paper section 2.8, where the form factors take 90 to 99 % of the
//! run time and are therefore computed once, written to a file, and read by the part of the
//! program that solves and renders).
//!
//! # Layout (version 3)
//!
//! All integers and floats little-endian. L is the length of the method string in bytes.
//!
//! | offset        | size   | content                                                  |
//! |---------------|--------|----------------------------------------------------------|
//! | 0             | 8      | magic `RADFF\0\0\0`                                      |
//! | 8             | 4      | format version, u32 (3)                                  |
//! | 12            | 8      | element count n, u64                                     |
//! | 20            | 4      | L, u32 (at most [`MAX_METHOD_LEN`])                      |
//! | 24            | L      | method, UTF-8 (the `FormFactorMethod` Display, `area k=2`) |
//! | 24 + L        | 8      | mesh fingerprint, u64 ([`mesh_fingerprint`])             |
//! | 32 + L        | 4      | header CRC-32 of bytes [0, 32 + L)                       |
//! | 36 + L        | 4 n^2  | F_ij as f32, row by row                                  |
//! | 36 + L + 4n^2 | 4      | CRC-32 of every byte before it                           |
//!
//! The file is 40 + L + 4 n^2 bytes. The header checksum lets a reader trust n, the method
//! and the fingerprint (and refuse a stale file) before reading the matrix; the final
//! checksum covers the whole file. A reader checks the file length against n before it
//! allocates anything, so a damaged n cannot make it allocate terabytes, and never returns a
//! partially read matrix. A reader that checks the method parses the stored text back into a
//! [`FormFactorMethod`] (its `FromStr`, which accepts exactly what `Display` writes) and
//! compares the values.

use std::hash::Hasher;
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

use crate::form_factor::{
    available_memory_bytes, check_dense_fits, FormFactorMatrix, FormFactorMethod, OutOfMemory,
    ParseMethodError,
};
use crate::mesh::Mesh;

/// The first 8 bytes of every form-factor file.
pub const FORM_FACTOR_MAGIC: [u8; 8] = *b"RADFF\0\0\0";

/// The format version this library writes and reads: 3 since the `area` method computes
/// pairs within two elements exactly (2: within half an element; 1: none). The layout is
/// version 1's; older files' `area` values are the older rules' and are refused so that
/// they are computed again.
pub const FORM_FACTOR_FILE_VERSION: u32 = 3;

/// The longest method string a form-factor file may hold, in bytes.
pub const MAX_METHOD_LEN: u32 = 4096;

/// Bytes of a form-factor file besides the method string and the matrix.
const FIXED_BYTES: u64 = 8 + 4 + 8 + 4 + 8 + 4 + 4;

/// The largest row sum a form-factor file may hold. Each row of F sums to at most 1 (the
/// fractions of the energy leaving an element that arrive anywhere), and this program's
/// methods stay below 1.18 where their discretisation overshoots (contour and analytic at
/// k = 2 in the furnished room at a coarse mesh; area at most 1.06; hemicube and Monte Carlo
/// 1 + f32 rounding: tests/suite/methods_on_examples.rs), 1.4 with the area method's older
/// near-pair rule (form_factor/area.rs). 1.5 refuses nothing this program writes and keeps
/// rho s < 1.5 rho: a row far above it (the forged file of issue 12 had 5,230) makes the
/// solve diverge.
pub const MAX_ROW_SUM: f64 = 1.5;

/// Entries converted per read or write call.
const CHUNK_ENTRIES: usize = 1 << 16;

/// A form-factor file cannot be used. Every message names the file and says what is wrong
/// with it; none says how to make a new one (that is the caller's business: the command line
/// adds its own hint).
#[derive(Debug, thiserror::Error)]
pub enum FormFactorFileError {
    /// The file could not be opened or read.
    #[error("cannot read form-factor file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: io::Error,
    },
    /// The file does not start with the form-factor magic bytes.
    #[error("{path} is not a form-factor file (it does not start with RADFF)")]
    NotFormFactorFile {
        /// The file.
        path: PathBuf,
    },
    /// The file has a format version this library does not read.
    #[error(
        "form-factor file {path} has format version {version}, but this program reads only \
         version {FORM_FACTOR_FILE_VERSION}"
    )]
    UnsupportedVersion {
        /// The file.
        path: PathBuf,
        /// The version found.
        version: u32,
    },
    /// The header is damaged (checksum mismatch, impossible method length, bad UTF-8).
    #[error("form-factor file {path} has a corrupt header ({reason})")]
    CorruptHeader {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The file is shorter than its header says.
    #[error(
        "form-factor file {path} is truncated: a matrix of {n} elements needs {expected} \
         bytes, but the file has {actual}"
    )]
    Truncated {
        /// The file.
        path: PathBuf,
        /// The element count in the header.
        n: u64,
        /// The length the file should have (saturated at u128::MAX).
        expected: u128,
        /// The length it has.
        actual: u64,
    },
    /// The file is longer than its header says.
    #[error(
        "form-factor file {path} has {extra} unexpected bytes after the matrix of {n} elements"
    )]
    TrailingBytes {
        /// The file.
        path: PathBuf,
        /// The element count in the header.
        n: u64,
        /// How many bytes too many.
        extra: u128,
    },
    /// The data does not match its checksum.
    #[error(
        "form-factor file {path} is corrupt: checksum {computed:08x} does not match the \
         stored {stored:08x}"
    )]
    ChecksumMismatch {
        /// The file.
        path: PathBuf,
        /// The checksum stored in the file.
        stored: u32,
        /// The checksum of the bytes read.
        computed: u32,
    },
    /// The file was computed for a different mesh (other scene, area limit or geometry).
    /// The file records its element count, method and a fingerprint of the mesh's
    /// geometry, not the scene's name or MAX_PATCH_AREA.
    #[error(
        "form-factor file {path} was computed for a different mesh: it holds {elements} \
         elements, made with method `{method}` (geometry fingerprint {found:016x}, this mesh is \
         {expected:016x}; the file records the element count, the method and this hash of the \
         elements' corners, not the scene or the MAX_PATCH_AREA it was made for)"
    )]
    Stale {
        /// The file.
        path: PathBuf,
        /// The element count in the file.
        elements: u64,
        /// The method tag in the file, as written.
        method: String,
        /// The fingerprint in the file.
        found: u64,
        /// The fingerprint of the current mesh.
        expected: u64,
    },
    /// The file's method tag is not a [`FormFactorMethod`] (its `FromStr` refuses it), so
    /// it cannot be checked against the method asked for.
    #[error("form-factor file {path} has a method tag this program does not read: {source}")]
    UnknownMethod {
        /// The file.
        path: PathBuf,
        /// The method tag in the file.
        tag: String,
        /// Why it does not parse (boxed: it holds the tag again, and this error travels in
        /// every `Result` of the pipeline).
        source: Box<ParseMethodError>,
    },
    /// The file was computed with a different form-factor method than asked for.
    #[error("form-factor file {path} was computed with method `{found}`, not `{expected}`")]
    MethodMismatch {
        /// The file.
        path: PathBuf,
        /// The method in the file.
        found: FormFactorMethod,
        /// The method asked for.
        expected: FormFactorMethod,
    },
    /// An entry is NaN, infinite or negative: a form factor is a fraction of energy.
    #[error(
        "form-factor file {path}: row {row} has F[{row}][{col}] = {value}, but every form \
         factor is a number in [0, 1]"
    )]
    BadEntry {
        /// The file.
        path: PathBuf,
        /// The row (element the energy leaves).
        row: usize,
        /// The column.
        col: usize,
        /// The value found.
        value: f32,
    },
    /// A row sums to more than [`MAX_ROW_SUM`]: more energy would arrive than leaves.
    #[error(
        "form-factor file {path}: row {row} sums to {sum}, more than {limit} (each row of \
         form factors sums to at most 1, plus the methods' discretisation error)"
    )]
    RowSumTooLarge {
        /// The file.
        path: PathBuf,
        /// The row.
        row: usize,
        /// Its sum.
        sum: f64,
        /// [`MAX_ROW_SUM`].
        limit: f64,
    },
    /// The matrix would not fit in memory (nothing was allocated).
    #[error("cannot load form-factor file {path}: {source}")]
    OutOfMemory {
        /// The file.
        path: PathBuf,
        /// The sizes involved.
        source: OutOfMemory,
    },
}

/// A stable 64-bit fingerprint of a mesh's geometry: FNV-1a (64-bit) over the bytes, all
/// little-endian, of n (u64), then for each element its surface index (u32), its corner
/// count (u64), each corner's x, y, z (f64 bit patterns, u64) and its area (f64 bits).
///
/// Unlike std's `DefaultHasher` it is the same across runs, builds and platforms, so a file
/// written on one machine can be checked on another.
pub fn mesh_fingerprint(mesh: &Mesh) -> u64 {
    let mut h = fnv::FnvHasher::default();
    h.write(&(mesh.len() as u64).to_le_bytes());
    for (e, element) in mesh.elements.iter().enumerate() {
        h.write(&element.surface.to_le_bytes());
        let corners = mesh.corner_positions(e);
        h.write(&(corners.len() as u64).to_le_bytes());
        for c in corners {
            for x in [c.x, c.y, c.z] {
                h.write(&x.to_bits().to_le_bytes());
            }
        }
        h.write(&element.area.to_bits().to_le_bytes());
    }
    h.finish()
}

/// Passes writes through, keeping a CRC-32 of the bytes.
struct CrcWriter<W> {
    inner: W,
    crc: crc32fast::Hasher,
}

impl<W: Write> CrcWriter<W> {
    fn put(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.crc.update(bytes);
        self.inner.write_all(bytes)
    }

    /// Writes the CRC of everything so far (the CRC itself is then part of the running CRC).
    fn put_crc(&mut self) -> io::Result<()> {
        let crc = self.crc.clone().finalize();
        self.put(&crc.to_le_bytes())
    }
}

/// Writes `matrix` to `path` in the layout above, atomically (a reader sees the old file or
/// the whole new one). `fingerprint` is [`mesh_fingerprint`] of the mesh the matrix was
/// computed for; `method` is how, as `FormFactorMethod`'s Display writes it (a reader that
/// checks the method refuses a file whose text does not parse back).
pub fn write_form_factors(
    path: &Path,
    matrix: &FormFactorMatrix,
    fingerprint: u64,
    method: &str,
) -> io::Result<()> {
    if method.len() > MAX_METHOD_LEN as usize {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "form-factor method description is {} bytes, more than {MAX_METHOD_LEN}",
                method.len()
            ),
        ));
    }
    crate::io::write_atomically(path, |out| {
        let mut w = CrcWriter {
            inner: out,
            crc: crc32fast::Hasher::new(),
        };
        w.put(&FORM_FACTOR_MAGIC)?;
        w.put(&FORM_FACTOR_FILE_VERSION.to_le_bytes())?;
        w.put(&(matrix.n() as u64).to_le_bytes())?;
        w.put(&(method.len() as u32).to_le_bytes())?;
        w.put(method.as_bytes())?;
        w.put(&fingerprint.to_le_bytes())?;
        w.put_crc()?;
        let mut bytes = Vec::with_capacity(4 * CHUNK_ENTRIES);
        for chunk in matrix.as_slice().chunks(CHUNK_ENTRIES) {
            bytes.clear();
            bytes.extend(chunk.iter().flat_map(|x| x.to_le_bytes()));
            w.put(&bytes)?;
        }
        w.put_crc()
    })
}

/// Writes a form-factor file block by block, in any order, with the same bytes as
/// [`write_form_factors`] of the whole matrix: for a matrix computed in blocks by several
/// processes ([`crate::form_factor::BlockComputer`]), so that the writer never holds more
/// than the block at hand.
///
/// The file is made beside `path` as [`crate::io::write_atomically`] makes its temporary
/// file, sized for the whole matrix (zeros), and each block is written at its place. Where
/// the blocks hold the upper triangle only (`areas` given: the method fills the lower one by
/// reciprocity), each block's entries F_ij, j > i, are written in their rows and their
/// mirrors F_ji ([`crate::form_factor::mirrored_entry`]) in the rows below. [`Self::finish`]
/// refuses to finish while a row is missing, then appends the checksum and renames the file
/// onto `path`; dropped unfinished, the file is removed and `path` left as it was.
pub struct FormFactorStreamWriter {
    file: std::fs::File,
    tmp: tempfile::TempPath,
    target: PathBuf,
    n: usize,
    header_len: u64,
    areas: Option<Vec<f64>>,
    written: Vec<bool>,
}

impl FormFactorStreamWriter {
    /// Starts the file for an n x n matrix with this mesh's `fingerprint` and `method`;
    /// `areas` (n element areas) when blocks hold the upper triangle only.
    pub fn create(
        path: &Path,
        n: usize,
        fingerprint: u64,
        method: &str,
        areas: Option<Vec<f64>>,
    ) -> io::Result<FormFactorStreamWriter> {
        if method.len() > MAX_METHOD_LEN as usize {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "form-factor method description is {} bytes, more than {MAX_METHOD_LEN}",
                    method.len()
                ),
            ));
        }
        if areas.as_ref().is_some_and(|a| a.len() != n) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "one area per element is needed to mirror the upper triangle",
            ));
        }
        crate::io::inputs::refuse_output(path)?;
        if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "a form-factor file written in blocks must be a regular file (it is filled \
                 out of order, then renamed into place)",
            ));
        }
        let (file, tmp, target) = crate::io::atomic_write::temporary_beside(path)?;
        let mut header = Vec::new();
        {
            let mut w = CrcWriter {
                inner: &mut header,
                crc: crc32fast::Hasher::new(),
            };
            w.put(&FORM_FACTOR_MAGIC)?;
            w.put(&FORM_FACTOR_FILE_VERSION.to_le_bytes())?;
            w.put(&(n as u64).to_le_bytes())?;
            w.put(&(method.len() as u32).to_le_bytes())?;
            w.put(method.as_bytes())?;
            w.put(&fingerprint.to_le_bytes())?;
            w.put_crc()?;
        }
        let header_len = header.len() as u64;
        let mut writer = FormFactorStreamWriter {
            file,
            tmp,
            target,
            n,
            header_len,
            areas,
            written: vec![false; n],
        };
        writer.write_at(&header, 0)?;
        // The matrix as zeros (sparse where the file system allows), then the blocks.
        writer
            .file
            .set_len(header_len + 4 * (n as u64) * (n as u64))?;
        Ok(writer)
    }

    /// The number of rows.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Rows written so far.
    pub fn rows_written(&self) -> usize {
        self.written.iter().filter(|&&w| w).count()
    }

    fn write_at(&mut self, bytes: &[u8], offset: u64) -> io::Result<()> {
        use std::io::{Seek, SeekFrom};
        self.file.seek(SeekFrom::Start(offset))?;
        self.file.write_all(bytes)
    }

    fn entry_offset(&self, row: usize, col: usize) -> u64 {
        self.header_len + 4 * (row as u64 * self.n as u64 + col as u64)
    }

    /// Writes rows `rows` (`data` row-major, n entries a row): whole rows, or with `areas`
    /// the entries after the diagonal and their mirrors. A block written twice writes the
    /// same bytes again.
    pub fn write_block(&mut self, rows: std::ops::Range<usize>, data: &[f32]) -> io::Result<()> {
        let n = self.n;
        if rows.end > n || data.len() != rows.len() * n {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "block of rows {}..{} with {} entries does not fit a matrix of {n} rows",
                    rows.start,
                    rows.end,
                    data.len()
                ),
            ));
        }
        let mut bytes = Vec::with_capacity(4 * n);
        for (k, i) in rows.clone().enumerate() {
            let row = &data[k * n..(k + 1) * n];
            let from = if self.areas.is_some() { i + 1 } else { 0 };
            bytes.clear();
            bytes.extend(row[from..].iter().flat_map(|x| x.to_le_bytes()));
            self.write_at(&bytes, self.entry_offset(i, from))?;
        }
        if let Some(areas) = self.areas.take() {
            // Row j > rows.start gets columns rows.start..min(rows.end, j), one write a row.
            let result: io::Result<()> = (|| {
                for j in rows.start + 1..n {
                    let cols = rows.start..rows.end.min(j);
                    bytes.clear();
                    for i in cols.clone() {
                        let f_ij = data[(i - rows.start) * n + j];
                        let f_ji = crate::form_factor::mirrored_entry(f_ij, areas[i], areas[j]);
                        bytes.extend(f_ji.to_le_bytes());
                    }
                    self.write_at(&bytes, self.entry_offset(j, cols.start))?;
                }
                Ok(())
            })();
            self.areas = Some(areas);
            result?;
        }
        for w in &mut self.written[rows] {
            *w = true;
        }
        Ok(())
    }

    /// Appends the checksum and renames the file onto the path given to
    /// [`Self::create`]; refused (`InvalidData`, naming the first missing rows) while a
    /// row has not been written.
    pub fn finish(mut self) -> io::Result<()> {
        use std::io::{Seek, SeekFrom};
        if let Some(first) = self.written.iter().position(|w| !w) {
            let end = self.written[first..]
                .iter()
                .position(|&w| w)
                .map_or(self.n, |k| first + k);
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "rows {first}..{end} of the form-factor matrix were never written ({} of \
                     {} rows are)",
                    self.rows_written(),
                    self.n
                ),
            ));
        }
        self.file.seek(SeekFrom::Start(0))?;
        let mut crc = crc32fast::Hasher::new();
        let mut buf = vec![0u8; 4 * CHUNK_ENTRIES];
        let mut reader = (&self.file).take(self.header_len + 4 * (self.n as u64).pow(2));
        loop {
            let got = reader.read(&mut buf)?;
            if got == 0 {
                break;
            }
            crc.update(&buf[..got]);
        }
        let end = self.header_len + 4 * (self.n as u64).pow(2);
        self.write_at(&crc.finalize().to_le_bytes(), end)?;
        self.file.sync_all()?;
        drop(self.file);
        self.tmp.persist(&self.target).map_err(|e| e.error)
    }
}

/// Reads a form-factor file written by [`write_form_factors`].
///
/// Refuses, with a message naming the file, anything but an intact current-version file whose
/// fingerprint is `expected_fingerprint` and, if `expected_method` is given, whose method tag
/// parses ([`FormFactorFileError::UnknownMethod`] if not) to that method
/// ([`FormFactorFileError::MethodMismatch`] if not). Without an expected method the tag is
/// not looked at. The length is checked against n, and the memory against the available
/// memory, before the matrix is allocated.
pub fn read_form_factors(
    path: &Path,
    expected_fingerprint: u64,
    expected_method: Option<FormFactorMethod>,
) -> Result<FormFactorMatrix, FormFactorFileError> {
    read_with_memory(
        path,
        expected_fingerprint,
        expected_method,
        available_memory_bytes(),
    )
}

/// Reads exactly `buf.len()` bytes, feeding them to `crc`.
fn read_crc(r: &mut impl Read, crc: &mut crc32fast::Hasher, buf: &mut [u8]) -> io::Result<()> {
    r.read_exact(buf)?;
    crc.update(buf);
    Ok(())
}

/// [`read_form_factors`] with the available memory given, so that the refusal can be tested.
fn read_with_memory(
    path: &Path,
    expected_fingerprint: u64,
    expected_method: Option<FormFactorMethod>,
    available: u64,
) -> Result<FormFactorMatrix, FormFactorFileError> {
    let p = || path.to_path_buf();
    let io_err = |source| FormFactorFileError::Io { path: p(), source };
    crate::io::note_input(path);
    let file = std::fs::File::open(path).map_err(io_err)?;
    let actual = file.metadata().map_err(io_err)?.len();
    let mut r = io::BufReader::with_capacity(1 << 20, file);
    let mut crc = crc32fast::Hasher::new();

    // Magic and version.
    let mut magic = [0u8; 8];
    match read_crc(&mut r, &mut crc, &mut magic) {
        Ok(()) if magic == FORM_FACTOR_MAGIC => {}
        Ok(()) => return Err(FormFactorFileError::NotFormFactorFile { path: p() }),
        Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => {
            return Err(FormFactorFileError::NotFormFactorFile { path: p() })
        }
        Err(e) => return Err(io_err(e)),
    }
    // Past the magic, an early end of file means truncation; `expected` is the least
    // length known to be needed at that point.
    let short = |e: io::Error, n: u64, expected: u128| {
        if e.kind() == io::ErrorKind::UnexpectedEof {
            FormFactorFileError::Truncated {
                path: p(),
                n,
                expected,
                actual,
            }
        } else {
            FormFactorFileError::Io {
                path: p(),
                source: e,
            }
        }
    };
    let mut b4 = [0u8; 4];
    let mut b8 = [0u8; 8];
    read_crc(&mut r, &mut crc, &mut b4).map_err(|e| short(e, 0, FIXED_BYTES.into()))?;
    let version = u32::from_le_bytes(b4);
    if version != FORM_FACTOR_FILE_VERSION {
        return Err(FormFactorFileError::UnsupportedVersion { path: p(), version });
    }

    // The rest of the header, checked by its own CRC before anything in it is trusted.
    read_crc(&mut r, &mut crc, &mut b8).map_err(|e| short(e, 0, FIXED_BYTES.into()))?;
    let n = u64::from_le_bytes(b8);
    read_crc(&mut r, &mut crc, &mut b4).map_err(|e| short(e, n, FIXED_BYTES.into()))?;
    let method_len = u32::from_le_bytes(b4);
    let corrupt = |reason: String| FormFactorFileError::CorruptHeader { path: p(), reason };
    if method_len > MAX_METHOD_LEN {
        return Err(corrupt(format!(
            "method length {method_len} exceeds {MAX_METHOD_LEN}"
        )));
    }
    let header_bytes = (FIXED_BYTES + method_len as u64).into();
    let mut method = vec![0u8; method_len as usize];
    read_crc(&mut r, &mut crc, &mut method).map_err(|e| short(e, n, header_bytes))?;
    read_crc(&mut r, &mut crc, &mut b8).map_err(|e| short(e, n, header_bytes))?;
    let fingerprint = u64::from_le_bytes(b8);
    let header_crc = crc.clone().finalize();
    read_crc(&mut r, &mut crc, &mut b4).map_err(|e| short(e, n, header_bytes))?;
    let stored = u32::from_le_bytes(b4);
    if stored != header_crc {
        return Err(corrupt(format!(
            "header checksum {header_crc:08x} does not match the stored {stored:08x}"
        )));
    }
    let method = String::from_utf8(method)
        .map_err(|_| corrupt("the method description is not UTF-8".into()))?;

    // The length must match n exactly before anything of size n^2 is allocated.
    let expected = (FIXED_BYTES as u128 + method_len as u128)
        .saturating_add((n as u128).saturating_mul(n as u128).saturating_mul(4));
    if (actual as u128) < expected {
        return Err(FormFactorFileError::Truncated {
            path: p(),
            n,
            expected,
            actual,
        });
    }
    if actual as u128 > expected {
        return Err(FormFactorFileError::TrailingBytes {
            path: p(),
            n,
            extra: actual as u128 - expected,
        });
    }
    // n^2 <= file length, so n fits in usize and n * n does not overflow.
    let n = n as usize;

    if fingerprint != expected_fingerprint {
        return Err(FormFactorFileError::Stale {
            path: p(),
            elements: n as u64,
            method,
            found: fingerprint,
            expected: expected_fingerprint,
        });
    }
    if let Some(expected) = expected_method {
        let found = match method.parse::<FormFactorMethod>() {
            Ok(found) => found,
            Err(source) => {
                return Err(FormFactorFileError::UnknownMethod {
                    path: p(),
                    tag: method,
                    source: Box::new(source),
                })
            }
        };
        if found != expected {
            return Err(FormFactorFileError::MethodMismatch {
                path: p(),
                found,
                expected,
            });
        }
    }

    let oom = |source| FormFactorFileError::OutOfMemory { path: p(), source };
    check_dense_fits("the form-factor matrix (f32)", n, 4.0, available).map_err(oom)?;
    let mut data: Vec<f32> = Vec::new();
    if data.try_reserve_exact(n * n).is_err() {
        return Err(oom(OutOfMemory {
            what: "the form-factor matrix (f32)",
            n,
            needed_mib: 4.0 * (n as f64).powi(2) / (1 << 20) as f64,
            available_mib: available as f64 / (1 << 20) as f64,
            fits: 0,
        }));
    }
    let mut bytes = vec![0u8; 4 * CHUNK_ENTRIES];
    let mut left = n * n;
    while left > 0 {
        let take = left.min(CHUNK_ENTRIES);
        let buf = &mut bytes[..4 * take];
        read_crc(&mut r, &mut crc, buf).map_err(|e| short(e, n as u64, expected))?;
        data.extend(
            buf.chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        );
        left -= take;
    }
    let computed = crc.finalize();
    r.read_exact(&mut b4)
        .map_err(|e| short(e, n as u64, expected))?;
    let stored = u32::from_le_bytes(b4);
    if stored != computed {
        return Err(FormFactorFileError::ChecksumMismatch {
            path: p(),
            stored,
            computed,
        });
    }
    // The checksums say the bytes are those written, not that they are form factors: a
    // forged file can carry valid checksums around NaN or rows summing to thousands.
    for (row, entries) in data.chunks_exact(n.max(1)).enumerate() {
        if let Some((col, &value)) = entries
            .iter()
            .enumerate()
            .find(|(_, f)| !(f.is_finite() && **f >= 0.0))
        {
            return Err(FormFactorFileError::BadEntry {
                path: p(),
                row,
                col,
                value,
            });
        }
        let sum: f64 = entries.iter().map(|&f| f as f64).sum();
        if sum > MAX_ROW_SUM {
            return Err(FormFactorFileError::RowSumTooLarge {
                path: p(),
                row,
                sum,
                limit: MAX_ROW_SUM,
            });
        }
    }
    Ok(FormFactorMatrix::from_rows(n, data))
}

#[cfg(test)]
mod tests;
