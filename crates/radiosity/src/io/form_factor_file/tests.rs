//! The form-factor file's tests: round trips bit for bit, the documented layout and
//! fingerprint, and a typed refusal naming the file for every kind of damage.

use super::*;
use crate::mesh::mesh_scene;
use crate::scene::{Rgb, Scene, Surface};
use glam::dvec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// A fresh empty directory for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiosity-fff-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// An open box of three unit-ish rectangles; `lift` moves the last one.
fn scene(lift: f64) -> Scene {
    let rect = |z: f64, w: f64| {
        vec![
            dvec3(0., 0., z),
            dvec3(w, 0., z),
            dvec3(w, 1., z),
            dvec3(0., 1., z),
        ]
    };
    Scene {
        surfaces: [rect(0.0, 1.0), rect(1.0, 2.0), rect(2.0 + lift, 1.0)]
            .into_iter()
            .enumerate()
            .map(|(i, vertices)| Surface {
                name: format!("s{i}"),
                emission: Rgb::BLACK,
                reflectance: Rgb([0.5; 3]),
                vertices,
                photometry: Default::default(),
            })
            .collect(),
        camera: None,
        lights: Vec::new(),
    }
}

/// A matrix with awkward f32 values (subnormal, -0, the largest below 1, tiny) among
/// ordinary ones; rows sum to about 1/4 (row 0 to about 1.25), as form factors may.
fn matrix(n: usize) -> FormFactorMatrix {
    let mut rng = Pcg64Mcg::seed_from_u64(0x1234_5678);
    let mut data: Vec<f32> = (0..n * n)
        .map(|_| rng.random::<f32>() / (2 * n) as f32)
        .collect();
    data[1] = f32::MIN_POSITIVE / 8.0;
    data[2] = -0.0;
    data[3] = 1.0 - f32::EPSILON / 2.0;
    data[4] = 1e-30;
    FormFactorMatrix::from_rows(n, data)
}

const METHOD: &str = "area k=2";
const METHOD_VALUE: FormFactorMethod = FormFactorMethod::AreaIntegral { steps: 2 };

/// Writes a valid file for `mesh` and returns its path and the mesh fingerprint.
fn valid_file(dir: &Path, n: usize) -> (PathBuf, u64, FormFactorMatrix) {
    let mesh = mesh_scene(&scene(0.0), 0.5).unwrap();
    let fp = mesh_fingerprint(&mesh);
    let m = matrix(n);
    let path = dir.join("ff.bin");
    write_form_factors(&path, &m, fp, METHOD).unwrap();
    (path, fp, m)
}

/// The message names the file, and neither the program's commands nor its flags (the
/// command line adds those).
fn assert_names_file(err: &FormFactorFileError, path: &Path) {
    let text = err.to_string();
    assert!(text.contains(&path.display().to_string()), "{text}");
    assert!(!text.contains("radiosity formfactors"), "{text}");
    assert!(!text.contains(" --"), "{text}");
}

#[test]
fn round_trip_is_bit_identical() {
    let dir = temp_dir("roundtrip");
    let (path, fp, m) = valid_file(&dir, 37);
    let back = read_form_factors(&path, fp, Some(METHOD_VALUE)).unwrap();
    assert_eq!(back.n(), 37);
    let bits = |m: &FormFactorMatrix| m.as_slice().iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back), bits(&m));
    // Without a method to check, it reads too.
    assert!(read_form_factors(&path, fp, None).is_ok());
    // An empty matrix is a valid file as well.
    let empty = dir.join("empty.bin");
    write_form_factors(&empty, &FormFactorMatrix::from_rows(0, vec![]), 7, METHOD).unwrap();
    assert_eq!(
        read_form_factors(&empty, 7, Some(METHOD_VALUE))
            .unwrap()
            .n(),
        0
    );
    // Nor does a method tag matter when none is asked for.
    write_form_factors(&empty, &FormFactorMatrix::from_rows(0, vec![]), 7, "").unwrap();
    assert_eq!(read_form_factors(&empty, 7, None).unwrap().n(), 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn layout_matches_documentation() {
    let dir = temp_dir("layout");
    let path = dir.join("two.bin");
    let m = FormFactorMatrix::from_rows(2, vec![0.0, 0.25, 0.5, 0.0]);
    write_form_factors(&path, &m, 0x0102_0304_0506_0708, "ab").unwrap();
    let bytes = std::fs::read(&path).unwrap();
    // 40 fixed bytes + L = 2 + 4 n^2 = 16.
    assert_eq!(bytes.len(), 58);
    assert_eq!(&bytes[0..8], b"RADFF\0\0\0");
    assert_eq!(bytes[8..12], 3u32.to_le_bytes());
    assert_eq!(bytes[12..20], 2u64.to_le_bytes());
    assert_eq!(bytes[20..24], 2u32.to_le_bytes());
    assert_eq!(&bytes[24..26], b"ab");
    assert_eq!(bytes[26..34], 0x0102_0304_0506_0708u64.to_le_bytes());
    assert_eq!(bytes[34..38], crc32fast::hash(&bytes[..34]).to_le_bytes());
    assert_eq!(bytes[38..42], 0.0f32.to_le_bytes());
    assert_eq!(bytes[42..46], 0.25f32.to_le_bytes());
    assert_eq!(bytes[46..50], 0.5f32.to_le_bytes());
    assert_eq!(bytes[50..54], 0.0f32.to_le_bytes());
    assert_eq!(bytes[54..58], crc32fast::hash(&bytes[..54]).to_le_bytes());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fingerprint_is_fnv1a_of_documented_bytes() {
    let mesh = mesh_scene(&scene(0.0), 0.5).unwrap();
    // FNV-1a 64 written out here (offset basis and prime from the FNV specification).
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    eat(&(mesh.len() as u64).to_le_bytes());
    for (e, el) in mesh.elements.iter().enumerate() {
        eat(&el.surface.to_le_bytes());
        eat(&(el.corners().len() as u64).to_le_bytes());
        for &c in el.corners() {
            let v = mesh.vertices[c as usize];
            for x in [v.x, v.y, v.z] {
                eat(&x.to_bits().to_le_bytes());
            }
        }
        eat(&el.area.to_bits().to_le_bytes());
        assert_eq!(mesh.corner_positions(e).len(), el.corners().len());
    }
    assert_eq!(mesh_fingerprint(&mesh), h);
    // Any geometric change changes it.
    let moved = mesh_scene(&scene(1e-9), 0.5).unwrap();
    assert_ne!(mesh_fingerprint(&moved), h);
    let finer = mesh_scene(&scene(0.0), 0.25).unwrap();
    assert_ne!(mesh_fingerprint(&finer), h);
}

#[test]
fn flipped_data_byte_is_a_checksum_error() {
    let dir = temp_dir("flip");
    let (path, fp, _) = valid_file(&dir, 10);
    let mut bytes = std::fs::read(&path).unwrap();
    let data_start = 36 + METHOD.len();
    bytes[data_start + 123] ^= 0x10;
    std::fs::write(&path, &bytes).unwrap();
    let err = read_form_factors(&path, fp, Some(METHOD_VALUE)).unwrap_err();
    assert!(
        matches!(err, FormFactorFileError::ChecksumMismatch { .. }),
        "{err}"
    );
    assert_names_file(&err, &path);
    // The final checksum itself damaged: the same refusal.
    bytes[data_start + 123] ^= 0x10;
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&path, &bytes).unwrap();
    let err = read_form_factors(&path, fp, Some(METHOD_VALUE)).unwrap_err();
    assert!(
        matches!(err, FormFactorFileError::ChecksumMismatch { .. }),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn flipped_header_byte_is_a_corrupt_header() {
    let dir = temp_dir("header");
    let (path, fp, _) = valid_file(&dir, 10);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[25] ^= 0x01; // inside the method string
    std::fs::write(&path, &bytes).unwrap();
    let err = read_form_factors(&path, fp, None).unwrap_err();
    assert!(
        matches!(err, FormFactorFileError::CorruptHeader { .. }),
        "{err}"
    );
    assert_names_file(&err, &path);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn truncated_and_padded_files_are_refused() {
    let dir = temp_dir("trunc");
    let (path, fp, _) = valid_file(&dir, 10);
    let bytes = std::fs::read(&path).unwrap();
    for keep in [bytes.len() - 1, bytes.len() - 200, 40, 14] {
        std::fs::write(&path, &bytes[..keep]).unwrap();
        let err = read_form_factors(&path, fp, None).unwrap_err();
        assert!(
            matches!(err, FormFactorFileError::Truncated { .. }),
            "{keep}: {err}"
        );
        assert_names_file(&err, &path);
    }
    let mut longer = bytes.clone();
    longer.push(0);
    std::fs::write(&path, &longer).unwrap();
    let err = read_form_factors(&path, fp, None).unwrap_err();
    assert!(
        matches!(err, FormFactorFileError::TrailingBytes { extra: 1, .. }),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn different_mesh_is_stale() {
    let dir = temp_dir("stale");
    let (path, fp_file, _) = valid_file(&dir, 10);
    let other = mesh_fingerprint(&mesh_scene(&scene(0.1), 0.5).unwrap());
    let err = read_form_factors(&path, other, Some(METHOD_VALUE)).unwrap_err();
    assert!(matches!(err, FormFactorFileError::Stale { .. }), "{err}");
    let text = err.to_string();
    assert!(text.contains("different mesh"), "{text}");
    // Both fingerprints, and no command-line advice (the program adds its own).
    assert!(text.contains(&format!("{fp_file:016x}")), "{text}");
    assert!(text.contains(&format!("{other:016x}")), "{text}");
    assert!(!text.contains("radiosity formfactors"), "{text}");
    assert_names_file(&err, &path);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn different_method_is_refused() {
    let dir = temp_dir("method");
    let (path, fp, _) = valid_file(&dir, 4);
    let other = FormFactorMethod::AreaIntegral { steps: 4 };
    let err = read_form_factors(&path, fp, Some(other)).unwrap_err();
    let FormFactorFileError::MethodMismatch {
        found, expected, ..
    } = &err
    else {
        panic!("{err}")
    };
    assert_eq!((*found, *expected), (METHOD_VALUE, other));
    let text = err.to_string();
    assert!(text.contains("`area k=2`, not `area k=4`"), "{text}");
    assert_names_file(&err, &path);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn unparsable_method_tag_is_refused_naming_it() {
    let dir = temp_dir("tag");
    let mesh = mesh_scene(&scene(0.0), 0.5).unwrap();
    let fp = mesh_fingerprint(&mesh);
    let path = dir.join("ff.bin");
    // Tags an older or newer writer might have left, and near misses of real ones.
    for tag in [
        "",
        "area",
        "area k=2 ",
        "radiosity k=2",
        "contour k=+2",
        "gpu-hemicube",
    ] {
        write_form_factors(&path, &matrix(3), fp, tag).unwrap();
        let err = read_form_factors(&path, fp, Some(METHOD_VALUE)).unwrap_err();
        let FormFactorFileError::UnknownMethod {
            tag: found, source, ..
        } = &err
        else {
            panic!("{tag:?}: {err}")
        };
        assert_eq!(found, tag);
        assert_eq!(tag.parse::<FormFactorMethod>(), Err(*source.clone()));
        let text = err.to_string();
        assert!(text.contains(&format!("`{tag}`")), "{text}");
        assert_names_file(&err, &path);
        // Without a method to check, the tag is not looked at.
        assert_eq!(read_form_factors(&path, fp, None).unwrap().n(), 3);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn garbage_is_not_a_form_factor_file() {
    let dir = temp_dir("garbage");
    let path = dir.join("scene.txt");
    for content in [
        &b"MAX_PATCH_AREA 0.1\nINTEGRAL_STEPS 2\n"[..],
        b"",
        b"RADFF",
    ] {
        std::fs::write(&path, content).unwrap();
        let err = read_form_factors(&path, 0, None).unwrap_err();
        assert!(
            matches!(err, FormFactorFileError::NotFormFactorFile { .. }),
            "{err}"
        );
        assert_names_file(&err, &path);
    }
    let err = read_form_factors(&dir.join("missing.bin"), 0, None).unwrap_err();
    assert!(matches!(err, FormFactorFileError::Io { .. }), "{err}");
    assert!(err.to_string().contains("missing.bin"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn newer_version_is_refused() {
    let dir = temp_dir("version");
    let (path, fp, _) = valid_file(&dir, 3);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[8..12].copy_from_slice(&4u32.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let err = read_form_factors(&path, fp, None).unwrap_err();
    assert!(
        matches!(
            err,
            FormFactorFileError::UnsupportedVersion { version: 4, .. }
        ),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn version_1_and_2_files_of_the_older_area_rules_are_refused() {
    // Version 1 files hold the area method's values from before its near pairs were exact,
    // version 2 from when only pairs within half an element were: refused, so that they
    // are computed again rather than solved with stale values.
    let dir = temp_dir("version1");
    for old in [1u32, 2] {
        let (path, fp, _) = valid_file(&dir, 3);
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[8..12].copy_from_slice(&old.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read_form_factors(&path, fp, None).unwrap_err();
        assert!(
            matches!(err, FormFactorFileError::UnsupportedVersion { version, .. } if version == old),
            "{err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn huge_n_is_refused_without_allocating() {
    let dir = temp_dir("huge");
    let path = dir.join("huge.bin");
    // A header claiming n = 2^40 (4 * 2^80 bytes of data) or n = u64::MAX, with a valid
    // header checksum, followed by a few bytes: only the length check can stop it, and a
    // vec![0; n * n] would abort the test.
    for n in [1u64 << 40, u64::MAX] {
        let mut bytes = Vec::new();
        bytes.extend_from_slice(&FORM_FACTOR_MAGIC);
        bytes.extend_from_slice(&FORM_FACTOR_FILE_VERSION.to_le_bytes());
        bytes.extend_from_slice(&n.to_le_bytes());
        bytes.extend_from_slice(&0u32.to_le_bytes());
        bytes.extend_from_slice(&42u64.to_le_bytes());
        let crc = crc32fast::hash(&bytes);
        bytes.extend_from_slice(&crc.to_le_bytes());
        bytes.extend_from_slice(&[0u8; 64]);
        std::fs::write(&path, &bytes).unwrap();
        let err = read_form_factors(&path, 42, None).unwrap_err();
        let FormFactorFileError::Truncated { n: got, actual, .. } = err else {
            panic!("{err}")
        };
        assert_eq!((got, actual), (n, bytes.len() as u64));
    }
    // A damaged n without a matching header checksum is a corrupt header.
    let (path, fp, _) = valid_file(&dir, 5);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[19] = 0x7f;
    std::fs::write(&path, &bytes).unwrap();
    let err = read_form_factors(&path, fp, None).unwrap_err();
    assert!(
        matches!(err, FormFactorFileError::CorruptHeader { .. }),
        "{err}"
    );
    // A method length beyond the limit is refused before it is allocated.
    bytes[19] = 0;
    bytes[20..24].copy_from_slice(&u32::MAX.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let err = read_form_factors(&path, fp, None).unwrap_err();
    assert!(
        matches!(err, FormFactorFileError::CorruptHeader { .. }),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn matrix_too_big_for_memory_is_refused() {
    let dir = temp_dir("oom");
    let (path, fp, _) = valid_file(&dir, 20);
    // 20 x 20 f32 = 1600 bytes (1760 with headroom) do not fit in 1000.
    let err = read_with_memory(&path, fp, None, 1000).unwrap_err();
    let FormFactorFileError::OutOfMemory { source, .. } = &err else {
        panic!("{err}")
    };
    assert_eq!(source.n, 20);
    assert_names_file(&err, &path);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A file with valid checksums around a matrix that is not one of form factors (the forged
/// files of issue 12): refused on reading, naming the file, the row and the value.
fn forged(dir: &Path, n: usize, set: impl Fn(&mut [f32])) -> (PathBuf, u64) {
    let mesh = mesh_scene(&scene(0.0), 0.5).unwrap();
    let fp = mesh_fingerprint(&mesh);
    let mut data = vec![0.1f32; n * n];
    set(&mut data);
    let path = dir.join("forged.bin");
    write_form_factors(&path, &FormFactorMatrix::from_rows(n, data), fp, METHOD).unwrap();
    (path, fp)
}

#[test]
fn forged_nan_inf_and_negative_entries_are_refused_naming_the_row() {
    let dir = temp_dir("forged-entries");
    for (value, shown) in [(f32::NAN, "NaN"), (f32::INFINITY, "inf"), (-0.25, "-0.25")] {
        // Row 2, column 1 (n = 4), after rows that are fine.
        let (path, fp) = forged(&dir, 4, |d| d[2 * 4 + 1] = value);
        let err = read_form_factors(&path, fp, Some(METHOD_VALUE)).unwrap_err();
        let FormFactorFileError::BadEntry { row, col, .. } = &err else {
            panic!("{value}: {err:?}");
        };
        assert_eq!((*row, *col), (2, 1), "{err}");
        assert_names_file(&err, &path);
        let text = err.to_string();
        assert!(text.contains("row 2") && text.contains(shown), "{text}");
    }
    // All NaN: the first row is named.
    let (path, fp) = forged(&dir, 3, |d| d.fill(f32::NAN));
    let err = read_form_factors(&path, fp, None).unwrap_err();
    assert!(
        matches!(err, FormFactorFileError::BadEntry { row: 0, col: 0, .. }),
        "{err:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn forged_row_sums_above_one_and_a_half_are_refused() {
    let dir = temp_dir("forged-rowsum");
    // n = 4: rows of 0.1 sum to 0.4; row 3 with 5,230 spread over it sums to 5,230.
    let (path, fp) = forged(&dir, 4, |d| d[12..16].fill(5230.0 / 4.0));
    let err = read_form_factors(&path, fp, None).unwrap_err();
    let FormFactorFileError::RowSumTooLarge { row, sum, .. } = &err else {
        panic!("{err:?}");
    };
    assert_eq!((*row, *sum), (3, 5230.0));
    assert_names_file(&err, &path);
    assert!(err.to_string().contains("row 3 sums to 5230"), "{err}");
    // 1.49 is accepted (within the methods' overshoot), 1.51 is not.
    let (path, fp) = forged(&dir, 2, |d| d.copy_from_slice(&[0.0, 1.49, 1.0, 0.0]));
    assert!(read_form_factors(&path, fp, None).is_ok());
    let (path, fp) = forged(&dir, 2, |d| d.copy_from_slice(&[0.0, 1.51, 1.0, 0.0]));
    assert!(matches!(
        read_form_factors(&path, fp, None),
        Err(FormFactorFileError::RowSumTooLarge { row: 0, .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The Cornell box (its tall block occludes) at a coarse mesh, for every method: the
/// matrix computed in blocks by [`crate::form_factor::BlockComputer`] and written block by
/// block, in a shuffled order, by [`FormFactorStreamWriter`] gives the very bytes of
/// [`write_form_factors`] of [`crate::form_factor::compute_matrix`]. The MPI program relies
/// on it to write what `radiosity formfactors` writes.
#[test]
fn blocks_streamed_in_any_order_give_the_whole_matrix_file() {
    use crate::form_factor::{
        compute_matrix, fills_lower_by_reciprocity, BlockComputer, RayCounter,
    };
    use crate::pipeline::{Overrides, Prepared};
    use crate::progress::NoProgress;
    let file = crate::scene::cornell_box();
    let coarse = Overrides {
        max_patch_area: Some(40_000.0),
        integral_steps: Some(2),
    };
    let mut prepared = Prepared::new(file.scene, coarse.apply(file.settings), &NoProgress).unwrap();
    let n = prepared.mesh.len();
    assert!(
        n > 20,
        "{n} elements: too few for blocks of 7 rows to matter"
    );
    let dir = temp_dir("stream");
    for method in [
        FormFactorMethod::AreaIntegral { steps: 2 },
        FormFactorMethod::Contour { steps: 2 },
        FormFactorMethod::Analytic { steps: 2 },
        FormFactorMethod::Hemicube { resolution: 16 },
        FormFactorMethod::MonteCarlo {
            samples: 16,
            seed: 7,
        },
    ] {
        prepared.method = method;
        let ctx = prepared.context();
        let rays = RayCounter::default();
        let whole = compute_matrix(&ctx, method, &rays, &NoProgress).unwrap();
        let reference = dir.join("whole.ff");
        write_form_factors(
            &reference,
            &whole,
            prepared.fingerprint(),
            &method.to_string(),
        )
        .unwrap();
        let computer = BlockComputer::new(&ctx, method);
        assert_eq!(computer.upper_only(), fills_lower_by_reciprocity(method));
        let streamed = dir.join("streamed.ff");
        let areas = computer.upper_only().then(|| prepared.areas());
        let mut writer = FormFactorStreamWriter::create(
            &streamed,
            n,
            prepared.fingerprint(),
            &method.to_string(),
            areas,
        )
        .unwrap();
        // Blocks of 7 rows (the last shorter), last first, then the even ones, then the odd.
        let blocks: Vec<_> = (0..n).step_by(7).map(|s| s..(s + 7).min(n)).collect();
        let mut order: Vec<usize> = vec![blocks.len() - 1];
        order.extend((0..blocks.len() - 1).filter(|b| b % 2 == 0));
        order.extend((0..blocks.len() - 1).filter(|b| b % 2 == 1));
        for &b in &order {
            let block = computer.block(blocks[b].clone(), &rays);
            writer.write_block(block.rows, &block.data).unwrap();
        }
        writer.finish().unwrap();
        assert!(
            std::fs::read(&reference).unwrap() == std::fs::read(&streamed).unwrap(),
            "{method}: the streamed file differs from the whole matrix's"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A block never written: `finish` refuses, naming the missing rows, and neither the file
/// nor a temporary is left.
#[test]
fn a_stream_with_a_missing_block_is_not_finished() {
    let dir = temp_dir("stream-missing");
    let path = dir.join("out.ff");
    let mut writer = FormFactorStreamWriter::create(&path, 6, 1, METHOD, None).unwrap();
    writer.write_block(0..2, &[0.1; 12]).unwrap();
    writer.write_block(4..6, &[0.1; 12]).unwrap();
    let err = writer.finish().unwrap_err();
    assert_eq!(err.kind(), io::ErrorKind::InvalidData);
    assert!(
        err.to_string()
            .starts_with("rows 2..4 of the form-factor matrix were never written (4 of 6"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "left files behind"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
