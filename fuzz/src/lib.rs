//! The fuzz targets' bodies, one function per reader, and the bounds they put on the work
//! after a successful read (see `fuzz/README.md`, "Harness bounds").
//!
//! A target fails only by panicking or aborting: a clean error from a reader, the mesher or
//! a solver is a correct answer to hostile input.

use std::path::PathBuf;
use std::sync::{Once, OnceLock};

use radiosity::form_factor::FormFactorMethod;
use radiosity::geometry;
use radiosity::io::form_factor_file::read_form_factors;
use radiosity::io::scene_file::{parse_scene, read_scene, write_scene};
use radiosity::progress::NoProgress;
use radiosity::solve::keep_going;
use radiosity::{pipeline, shade, MeshSettings, Prepared, SolveRequest, Solver};

/// Harness bound: scenes of more surfaces than this (a box is six) are parsed, written and
/// parsed again, but not meshed (the contact refinement's probe rays would dominate the run).
pub const MESH_SURFACES: usize = 12;

/// Harness bound: after a successful parse, `MAX_PATCH_AREA` is raised so that the mesh has
/// about this many elements by area (the program's own limit is `mesh::MAX_ELEMENTS`, 8
/// million, seconds of work per input).
pub const MESH_ELEMENTS: f64 = 64.0;

/// Harness bound: form factors and a Gauss-Seidel solve run on meshes of at most this many
/// elements ...
pub const SOLVE_ELEMENTS: usize = 16;

/// ... with `INTEGRAL_STEPS` lowered to at most this.
pub const SOLVE_STEPS: u32 = 3;

/// Sets up what every target shares: one rayon thread (fuzzing takes one core; a second
/// thread would only add noise to coverage).
fn init() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build_global();
    });
}

/// A file of this process's own for the readers that take a path: in /dev/shm where there
/// is one (no disk traffic), else the temporary directory.
fn scratch_file(name: &str) -> PathBuf {
    let dir = if std::path::Path::new("/dev/shm").is_dir() {
        PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    dir.join(format!("radiosity-fuzz-{}-{name}", std::process::id()))
}

/// The scene reader on arbitrary bytes, then what a user runs next on a small scene.
///
/// Bytes that are not UTF-8 go through [`read_scene`] (via a file), which must refuse them
/// with the line of the first bad byte; text goes to [`parse_scene`]. Every error must format.
/// A scene that parses is written back and must parse again (the writer's output is the
/// reader's input), then, within the bounds above, is meshed, and small meshes get form
/// factors, a Gauss-Seidel solve and vertex shading.
pub fn scene_file(data: &[u8]) {
    init();
    let text = match std::str::from_utf8(data) {
        Ok(text) => text,
        Err(_) => {
            let path = scratch_file("scene");
            std::fs::write(&path, data).expect("writing the scratch file");
            let result = read_scene(&path);
            let _ = std::fs::remove_file(&path);
            let error = result.expect_err("bytes that are not UTF-8 must be refused");
            assert!(!error.to_string().is_empty());
            return;
        }
    };
    let file = match parse_scene(text, "fuzz.scene") {
        Ok(file) => file,
        Err(error) => {
            assert!(!error.errors.is_empty(), "an error without a message");
            let _ = error.to_string();
            return;
        }
    };

    // The writer's output must read back. The writer may refuse, cleanly, a name the
    // reader accepts: one with a lone carriage return; see fuzz/RESULTS.md.
    let mut written = Vec::new();
    if write_scene(&file.scene, file.settings, &mut written).is_ok() {
        let written = String::from_utf8(written).expect("the writer writes UTF-8");
        if let Err(e) = parse_scene(&written, "written.scene") {
            panic!(
                "a parsed scene, written back, does not parse again: {e}\n--- written:\n{written}"
            );
        }
    }

    if file.scene.surfaces.len() > MESH_SURFACES {
        return;
    }
    let total_area: f64 = file
        .scene
        .surfaces
        .iter()
        .map(|s| geometry::polygon_area(&s.vertices))
        .sum();
    let settings = MeshSettings {
        max_patch_area: file.settings.max_patch_area.max(total_area / MESH_ELEMENTS),
        integral_steps: file.settings.integral_steps,
    };
    let Ok(mut prepared) = Prepared::new(file.scene, settings, &NoProgress) else {
        return;
    };
    if prepared.mesh.len() > SOLVE_ELEMENTS {
        return;
    }
    prepared.method = FormFactorMethod::AreaIntegral {
        steps: settings.integral_steps.min(SOLVE_STEPS),
    };
    if prepared
        .check_memory(Some(&Solver::DEFAULT_GAUSS_SEIDEL))
        .is_err()
    {
        return;
    }
    let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
    if let Ok(solution) = pipeline::solve(&prepared, &request, &mut keep_going, &NoProgress) {
        let b = solution.element_rgb();
        let _ = shade::vertex_radiosity(&solution.mesh, b);
    }
}

/// The scene every form-factor input is read against: two facing unit squares, one
/// element each, and a floor of two (four elements in all), with its fingerprint and method.
pub const FORM_FACTOR_SCENE: &str = "MAX_PATCH_AREA 0.5
INTEGRAL_STEPS 2
SCENEBEGIN
PATCHBEGIN
#Floor
VERTICES 4
Er 0
Eg 0
Eb 0
Rr 0.5
Rg 0.5
Rb 0.5
VERTEX0 0 0 0
VERTEX1 1 0 0
VERTEX2 1 0 -1
VERTEX3 0 0 -1
PATCHEND
PATCHBEGIN
#Light
VERTICES 4
Er 1
Eg 1
Eb 1
Rr 0
Rg 0
Rb 0
VERTEX0 0 1 0
VERTEX1 0 1 -1
VERTEX2 1 1 -1
VERTEX3 1 1 0
PATCHEND
SCENEEND
";

/// The prepared [`FORM_FACTOR_SCENE`] (meshed once per process).
pub fn form_factor_scene() -> &'static Prepared {
    static PREPARED: OnceLock<Prepared> = OnceLock::new();
    PREPARED.get_or_init(|| {
        init();
        let file = parse_scene(FORM_FACTOR_SCENE, "form_factor_scene").expect("the scene parses");
        Prepared::new(file.scene, file.settings, &NoProgress).expect("the scene meshes")
    })
}

/// The form-factor reader on arbitrary bytes (written to a file: the reader takes a path),
/// read against [`form_factor_scene`]'s fingerprint and method as `solve --form-factors`
/// does. Every refusal must name the file. A matrix that is accepted is solved as the command
/// would, with Gauss-Seidel.
///
/// The bytes are read twice: as they are, and, where they are long enough to hold both
/// checksums, with the header and file CRC-32s recomputed ([`with_checksums_fixed`]), so that
/// mutations of n, the method, the fingerprint and the matrix reach the checks behind the
/// checksums (a forged file, as #12 describes, has valid CRCs).
pub fn form_factor_file(data: &[u8]) {
    read_and_solve(data);
    if let Some(fixed) = with_checksums_fixed(data) {
        if fixed != data {
            read_and_solve(&fixed);
        }
    }
}

/// `data` with the header checksum (at 32 + L, over the bytes before it) and the final
/// checksum (the last 4 bytes, over all before them) recomputed, as the writer computes them;
/// `None` when `data` is too short to hold the header (L from bytes 20..24) and a final CRC.
pub fn with_checksums_fixed(data: &[u8]) -> Option<Vec<u8>> {
    let method_len = u32::from_le_bytes(data.get(20..24)?.try_into().ok()?) as usize;
    let header_crc_at = 32usize.checked_add(method_len)?;
    let final_crc_at = data.len().checked_sub(4)?;
    if header_crc_at + 4 > final_crc_at {
        return None;
    }
    let mut fixed = data.to_vec();
    let header_crc = crc32fast::hash(&fixed[..header_crc_at]);
    fixed[header_crc_at..header_crc_at + 4].copy_from_slice(&header_crc.to_le_bytes());
    let final_crc = crc32fast::hash(&fixed[..final_crc_at]);
    fixed[final_crc_at..].copy_from_slice(&final_crc.to_le_bytes());
    Some(fixed)
}

fn read_and_solve(data: &[u8]) {
    let prepared = form_factor_scene();
    let path = scratch_file("ff");
    std::fs::write(&path, data).expect("writing the scratch file");
    let result = read_form_factors(&path, prepared.fingerprint(), Some(prepared.method()));
    let _ = std::fs::remove_file(&path);
    let matrix = match result {
        Ok(matrix) => matrix,
        Err(error) => {
            let message = error.to_string();
            assert!(
                message.contains(path.to_str().unwrap()),
                "the message does not name the file: {message}"
            );
            return;
        }
    };
    // A forged file whose n is not the mesh's but whose fingerprint is (n = 0 or 5, say)
    // is read here: the file reader does not know the mesh's element count. The program
    // loads through `Prepared::load_form_factors`, which refuses it (naming the file, since
    // #12); before that, `check` panicked in `reciprocity` (index out of bounds). So such a
    // matrix goes no further here either.
    if matrix.n() != prepared.mesh.len() {
        std::fs::write(&path, data).expect("writing the scratch file");
        let refused = prepared.load_form_factors(&path, &NoProgress);
        let _ = std::fs::remove_file(&path);
        assert!(refused.is_err(), "a matrix of another size was loaded");
        return;
    }
    let _ = matrix.row_sums(&prepared.areas());
    let _ = matrix.reciprocity(&prepared.areas());
    let mut request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
    request.form_factors = pipeline::FormFactors::Matrix(&matrix);
    let _ = pipeline::solve(prepared, &request, &mut keep_going, &NoProgress);
}

/// Where an `obj` input's MTL text starts: the bytes after this line are the material file
/// that every `mtllib` of the OBJ text before it reads.
pub const MTL_SEPARATOR: &str = "\n%%MTL\n";

/// The OBJ reader (`io::import::obj::parse`) on arbitrary bytes (read as UTF-8 with
/// replacement characters, as the reader reads a file), with the bytes after
/// [`MTL_SEPARATOR`] as the text of every material file named. Every error must format; a
/// scene read must hold only usable polygons with colours in the scene format's ranges, and
/// written in the scene format it must parse again (the writer may refuse, cleanly, a name
/// the OBJ reader accepts: see `scene_file`).
pub fn obj(data: &[u8]) {
    use radiosity::io::import::{obj, ImportOptions};
    init();
    let text = String::from_utf8_lossy(data);
    let (obj_text, mtl_text) = match text.split_once(MTL_SEPARATOR) {
        Some((o, m)) => (o, Some(m)),
        None => (&*text, None),
    };
    let mut loader = |name: &str| match mtl_text {
        Some(m) => Ok((format!("fuzz/{name}"), m.to_string())),
        None => Err("no material file in this input".to_string()),
    };
    check_import(obj::parse(
        obj_text,
        "fuzz.obj",
        &ImportOptions::default(),
        &mut loader,
    ));
}

/// What every importer's target checks of a read: an error must format; a scene read must
/// hold only usable polygons with colours in the scene format's ranges, have usable
/// settings, and, written in the scene format, parse again (the writer may refuse, cleanly,
/// a name the importer accepts: see `scene_file`).
fn check_import(
    result: Result<radiosity::io::import::Imported, radiosity::io::import::ImportError>,
) {
    let imported = match result {
        Ok(imported) => imported,
        Err(error) => {
            assert!(!error.to_string().is_empty(), "an error without a message");
            return;
        }
    };
    for w in &imported.warnings {
        assert!(!w.to_string().is_empty());
    }
    let file = imported.file;
    assert!(
        !file.scene.surfaces.is_empty(),
        "an imported scene without surfaces"
    );
    for s in &file.scene.surfaces {
        if let Err(e) = geometry::validate_polygon(&s.vertices) {
            panic!(
                "surface {:?} is not a usable polygon: {e}: {:?}",
                s.name, s.vertices
            );
        }
        assert!(s.reflectance.0.iter().all(|r| (0.0..1.0).contains(r)));
        assert!(s.emission.0.iter().all(|e| *e >= 0.0 && e.is_finite()));
    }
    assert!(file.settings.max_patch_area > 0.0 && file.settings.max_patch_area.is_finite());
    let mut written = Vec::new();
    if write_scene(&file.scene, file.settings, &mut written).is_ok() {
        let written = String::from_utf8(written).expect("the writer writes UTF-8");
        if let Err(e) = parse_scene(&written, "written.scene") {
            panic!("an imported scene, written, does not parse: {e}\n--- written:\n{written}");
        }
    }
}

/// The glTF reader (`io::import::gltf::parse`) on arbitrary bytes: JSON glTF or binary
/// `.glb` (told apart by the `glTF` magic, as the reader does), with no folder, so that
/// URIs other than `data:` are refused; then [`check_import`].
pub fn gltf(data: &[u8]) {
    use radiosity::io::import::{gltf, ImportOptions};
    init();
    check_import(gltf::parse(
        "fuzz.gltf",
        data,
        None,
        &ImportOptions::default(),
    ));
}

/// The VRML97 reader (`io::import::vrml::parse`) on arbitrary bytes, then [`check_import`].
pub fn vrml(data: &[u8]) {
    use radiosity::io::import::{vrml, ImportOptions};
    init();
    check_import(vrml::parse("fuzz.wrl", data, &ImportOptions::default()));
}

/// Where a `dxf` input's materials file starts: the bytes after this line are the TOML
/// side file; without it the materials are [`DXF_DEFAULT_MATERIALS`].
pub const TOML_SEPARATOR: &[u8] = b"\n%%TOML\n";

/// The materials of a `dxf` input that gives none: every layer grey (so that the drawing's
/// faces get past the layer lookup).
pub const DXF_DEFAULT_MATERIALS: &str = "[default]\nreflectance = [0.5, 0.5, 0.5]\n";

/// The DXF reader (`io::import::dxf::parse`) on arbitrary bytes, the bytes after
/// [`TOML_SEPARATOR`] as its materials file (read as UTF-8 with replacement characters),
/// then [`check_import`].
pub fn dxf(data: &[u8]) {
    use radiosity::io::import::{dxf, ImportOptions};
    init();
    let split = data
        .windows(TOML_SEPARATOR.len())
        .position(|w| w == TOML_SEPARATOR);
    let (drawing, materials) = match split {
        Some(k) => (
            &data[..k],
            String::from_utf8_lossy(&data[k + TOML_SEPARATOR.len()..]).into_owned(),
        ),
        None => (data, DXF_DEFAULT_MATERIALS.to_string()),
    };
    check_import(dxf::parse(
        "fuzz.dxf",
        drawing,
        "fuzz.materials.toml",
        Some(&materials),
        &ImportOptions::default(),
    ));
}

/// The IES LM-63 reader on arbitrary bytes: text through `IesPhotometry::parse`, bytes that
/// are not UTF-8 through `IesPhotometry::read` (a file, read as Latin-1). Every error must
/// format and name the file; an accepted table must give finite, non-negative intensities in
/// every direction tried, a finite non-negative flux and tilt factors.
pub fn ies(data: &[u8]) {
    use radiosity::photometry::{IesError, IesPhotometry, ies::MAX_CANDELA};
    init();
    let result = match std::str::from_utf8(data) {
        Ok(text) => IesPhotometry::parse(text, std::path::Path::new("fuzz.ies")),
        Err(_) => {
            let path = scratch_file("lamp.ies");
            std::fs::write(&path, data).expect("writing the scratch file");
            let result = IesPhotometry::read(&path);
            let _ = std::fs::remove_file(&path);
            result
        }
    };
    let ies = match result {
        Ok(ies) => ies,
        Err(error) => {
            let message = error.to_string();
            assert!(message.contains("lamp.ies") || message.contains("fuzz.ies"), "{message}");
            if let IesError::Invalid { line, .. } = error {
                assert!(line >= 1, "{message}");
            }
            return;
        }
    };
    for i in 0..64 {
        let theta = f64::from(i) * 0.05 - 0.2;
        let phi = f64::from(i) * 0.7 - 3.0;
        let candela = ies.candela(theta, phi);
        assert!(
            candela.is_finite() && (0.0..=MAX_CANDELA * (1.0 + 1e-12)).contains(&candela),
            "candela {candela} at theta {theta}, phi {phi}"
        );
        let tilt = ies.tilt_factor(theta);
        assert!(tilt.is_finite() && tilt >= 0.0, "tilt factor {tilt}");
    }
    let flux = ies.table_lumens();
    assert!(flux.is_finite() && flux >= 0.0, "table lumens {flux}");
    if let Some(stated) = ies.stated_lumens() {
        assert!(stated > 0.0, "stated lumens {stated}");
    }
}

/// The illuminance command's points CSV reader on arbitrary text: it never panics, refuses
/// with the file and a line from 1, and every point it accepts is finite with a non-zero
/// normal; the accepted points written as a lux CSV give one row each under the header.
pub fn points(data: &[u8]) {
    use radiosity::illuminance::{parse_points, write_lux_csv, Lux, LUX_HEADER};
    init();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match parse_points(text, "fuzz.csv") {
        Ok(points) => {
            for p in &points {
                assert!(p.position.is_finite() && p.normal.is_finite());
                assert!(p.normal.length_squared() > 0.0);
            }
            let lux = vec![Lux::default(); points.len()];
            let mut out = Vec::new();
            write_lux_csv(&points, &lux, &mut out).expect("writing to memory");
            let written = String::from_utf8(out).expect("UTF-8");
            assert!(written.starts_with(LUX_HEADER));
            // Names hold no line break (lines split them), so one row per point.
            assert_eq!(written.lines().count(), 1 + points.len());
        }
        Err(error) => {
            let message = error.to_string();
            assert!(message.starts_with("fuzz.csv:"), "{message}");
        }
    }
}

/// Where a `checkpoint` input's block files start: the bytes before the first such line are
/// the manifest; each `%%BLOCK NAME` line starts a file NAME holding the bytes up to the
/// next (a name of letters, digits, `.`, `-`, `_`, 80 at most, else the section is dropped).
pub const BLOCK_SEPARATOR: &[u8] = b"\n%%BLOCK ";

/// The job the `checkpoint` target resumes: 5 elements, one fingerprint, one method (the
/// seeds' manifests and blocks are this job's).
pub fn checkpoint_job() -> radiosity_mpi::checkpoint::JobIdentity {
    radiosity_mpi::checkpoint::JobIdentity {
        scene: "fuzz.scene".into(),
        elements: 5,
        fingerprint: 0x0123_4567_89ab_cdef,
        method: "area k=2".into(),
    }
}

/// The checkpoint directory of `radiosity-mpi --resume` (`radiosity_mpi::checkpoint`) on
/// arbitrary bytes: the manifest and block files of [`BLOCK_SEPARATOR`] are written into a
/// directory of this process's own, which is opened for resuming [`checkpoint_job`]. Each
/// input runs as it is and again with every block's CRC-32 (its last 4 bytes) recomputed, so
/// that mutated headers get past the checksum as a forged file would.
///
/// A refusal must name the directory or the manifest; an accepted checkpoint's blocks must
/// be sorted, disjoint and within the mesh's rows, each must load with its rows' entries
/// (what the program writes into the output), every refused file must say why, and the
/// dealer must cover the rows the blocks leave, once each.
pub fn checkpoint(data: &[u8]) {
    init();
    let (manifest, blocks) = split_checkpoint(data);
    resume_checkpoint(manifest, &blocks);
    let fixed: Vec<(&str, Vec<u8>)> = blocks
        .iter()
        .map(|(name, bytes)| {
            let mut bytes = bytes.clone();
            if let Some(at) = bytes.len().checked_sub(4) {
                let crc = crc32fast::hash(&bytes[..at]);
                bytes[at..].copy_from_slice(&crc.to_le_bytes());
            }
            (*name, bytes)
        })
        .collect();
    if fixed != blocks {
        resume_checkpoint(manifest, &fixed);
    }
}

/// The manifest and the named block files of a `checkpoint` input.
pub fn split_checkpoint(data: &[u8]) -> (&[u8], Vec<(&str, Vec<u8>)>) {
    let mut sections = split_on(data, BLOCK_SEPARATOR);
    let manifest = sections.remove(0);
    let blocks = sections
        .into_iter()
        .filter_map(|section| {
            let end = section.iter().position(|&b| b == b'\n')?;
            let name = std::str::from_utf8(&section[..end]).ok()?;
            let usable = !name.is_empty()
                && name.len() <= 80
                && name != "manifest"
                && !name.starts_with('.')
                && name
                    .bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b"._-".contains(&b));
            usable.then(|| (name, section[end + 1..].to_vec()))
        })
        .collect();
    (manifest, blocks)
}

fn split_on<'a>(data: &'a [u8], separator: &[u8]) -> Vec<&'a [u8]> {
    let mut out = Vec::new();
    let mut rest = data;
    while let Some(at) = rest.windows(separator.len()).position(|w| w == separator) {
        out.push(&rest[..at]);
        rest = &rest[at + separator.len()..];
    }
    out.push(rest);
    out
}

fn resume_checkpoint(manifest: &[u8], blocks: &[(&str, Vec<u8>)]) {
    use radiosity_mpi::checkpoint::Checkpoint;
    use radiosity_mpi::deal::Dealer;
    let job = checkpoint_job();
    let dir = scratch_file("checkpoint");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("creating the scratch directory");
    std::fs::write(dir.join("manifest"), manifest).expect("writing the scratch manifest");
    for (name, bytes) in blocks {
        std::fs::write(dir.join(name), bytes).expect("writing a scratch block");
    }
    let result = Checkpoint::open(&dir, &job, true);
    let (cp, found) = match result {
        Ok(opened) => opened,
        Err(error) => {
            let message = error.to_string();
            assert!(
                message.contains(dir.to_str().unwrap()),
                "the message names neither the directory nor its manifest: {message}"
            );
            let _ = std::fs::remove_dir_all(&dir);
            return;
        }
    };
    let n = job.elements;
    for pair in found.blocks.windows(2) {
        assert!(pair[0].end <= pair[1].start, "blocks overlap: {:?}", found.blocks);
    }
    for rows in &found.blocks {
        assert!(rows.start < rows.end && rows.end <= n, "block {rows:?} of {n} rows");
        let data = cp.load(rows).expect("a block open accepted loads");
        assert_eq!(data.len(), rows.len() * n);
    }
    for (path, why) in &found.refused {
        assert!(!why.is_empty(), "{} refused without a reason", path.display());
    }
    // What the program deals next: the rows no accepted block holds, once each.
    let mut dealer = Dealer::new(n, 2, &found.blocks);
    let mut covered = vec![0u32; n];
    for rows in &found.blocks {
        rows.clone().for_each(|r| covered[r] += 1);
    }
    while let Some(rows) = dealer.deal(0) {
        rows.clone().for_each(|r| covered[r] += 1);
        dealer.finish(0);
    }
    assert!(covered.iter().all(|&c| c == 1), "rows covered {covered:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
