//! Hostile input (issue 12): files and flags that once were solved to NaN, overwrote their
//! own input or were misread, each refused with a message that says what is wrong.

use std::path::Path;

use radiosity::form_factor::FormFactorMatrix;
use radiosity::io::form_factor_file::write_form_factors;

use crate::fixtures::{example, radiosity, scratch_dir, stderr};

/// Copies the example `name` into `dir` as `as_name`.
fn copy_example(name: &str, dir: &Path, as_name: &str) {
    std::fs::copy(example(name), dir.join(as_name)).unwrap();
}

#[test]
fn an_output_that_is_an_input_is_refused_before_any_work() {
    let dir = scratch_dir("output-is-input");
    copy_example("triangles.scene", &dir, "x.scene");
    let before = std::fs::read(dir.join("x.scene")).unwrap();
    for args in [
        vec!["solve", "x.scene", "-o", "x.scene"],
        vec!["formfactors", "x.scene", "-o", "./x.scene"],
        vec!["render", "x.scene", "-o", "../{dir}/x.scene"],
    ] {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let args: Vec<String> = args.iter().map(|a| a.replace("{dir}", &name)).collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = radiosity(&args, &dir);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = stderr(&out);
        assert!(err.contains("is the scene file x.scene"), "{args:?}: {err}");
        assert!(err.contains("give -o another file name"), "{err}");
        assert_eq!(
            std::fs::read(dir.join("x.scene")).unwrap(),
            before,
            "{args:?}"
        );
    }
    // A scene named *.png rendered without -o: the default output is its own name.
    copy_example("triangles.scene", &dir, "y.png");
    let out = radiosity(&["render", "y.png", "--width", "8", "--height", "8"], &dir);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("is the scene file y.png"),
        "{}",
        stderr(&out)
    );
    // Through a hard link as well.
    std::fs::hard_link(dir.join("x.scene"), dir.join("link.csv")).unwrap();
    let out = radiosity(&["solve", "x.scene", "-o", "link.csv"], &dir);
    assert!(
        stderr(&out).contains("is the scene file"),
        "{}",
        stderr(&out)
    );
    // The form-factor file read is an input too.
    let out = radiosity(&["formfactors", "x.scene", "-o", "t.ff", "-q"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = radiosity(
        &["solve", "x.scene", "--form-factors", "t.ff", "-o", "t.ff"],
        &dir,
    );
    assert!(
        stderr(&out).contains("is the form-factor file t.ff"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Rewrites the form-factor file at `path` with `data` (valid checksums, the same
/// fingerprint and method): a forged file.
fn forge(path: &Path, data: Vec<f32>) {
    let bytes = std::fs::read(path).unwrap();
    let method_len = u32::from_le_bytes(bytes[20..24].try_into().unwrap()) as usize;
    let method = std::str::from_utf8(&bytes[24..24 + method_len])
        .unwrap()
        .to_string();
    let at = 24 + method_len;
    let fingerprint = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    let n = (data.len() as f64).sqrt() as usize;
    let matrix = FormFactorMatrix::from_rows(n, data);
    write_form_factors(path, &matrix, fingerprint, &method).unwrap();
}

#[test]
fn forged_form_factor_files_are_refused_naming_file_and_row() {
    let dir = scratch_dir("forged-ff");
    let scene = example("triangles.scene");
    let out = radiosity(&["formfactors", &scene, "-o", "t.ff", "-q"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let bytes = std::fs::read(dir.join("t.ff")).unwrap();
    let n = u64::from_le_bytes(bytes[12..20].try_into().unwrap()) as usize;
    for (fill, expect) in [
        (f32::NAN, "row 0 has F[0][0] = NaN"),
        (f32::INFINITY, "row 0 has F[0][0] = inf"),
        (-0.5, "row 0 has F[0][0] = -0.5"),
        (5230.0 / n as f32, "row 0 sums to 52"),
    ] {
        forge(&dir.join("t.ff"), vec![fill; n * n]);
        let out = radiosity(
            &["solve", &scene, "--form-factors", "t.ff", "-o", "b.csv"],
            &dir,
        );
        let err = stderr(&out);
        assert!(!out.status.success(), "{fill}: solved: {err}");
        assert!(
            err.contains("t.ff") && err.contains(expect),
            "{fill}: {err}"
        );
        assert!(!dir.join("b.csv").exists());
    }
    // n = 0 with this mesh's fingerprint: named, with both sizes.
    forge(&dir.join("t.ff"), vec![]);
    let out = radiosity(
        &["solve", &scene, "--form-factors", "t.ff", "-o", "b.csv"],
        &dir,
    );
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(
        err.contains("form-factor file t.ff holds 0 rows")
            && err.contains(&format!("{n} elements")),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hierarchical_solver_warns_that_it_ignores_method() {
    let dir = scratch_dir("hier-method");
    let args = [
        "check",
        "--solver",
        "hierarchical",
        "--epsilon",
        "0.5",
        "--method",
        "hemicube",
        "-q",
    ];
    let out = radiosity(&args, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("warning: --method hemicube ignored"),
        "{}",
        stderr(&out)
    );
    // An explicit `--method area` is ignored as well, and said so.
    let mut area = args;
    area[6] = "area";
    let out = radiosity(&area, &dir);
    assert!(
        stderr(&out).contains("warning: --method area ignored"),
        "{}",
        stderr(&out)
    );
    // No --method, or a dense solver, says nothing.
    let out = radiosity(&args[..5], &dir);
    assert!(
        !stderr(&out).contains("warning: --method"),
        "{}",
        stderr(&out)
    );
    let mut dense = args;
    dense[2] = "gauss-seidel";
    let out = radiosity(&dense[..], &dir);
    assert!(
        !stderr(&out).contains("warning: --method"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_eye_out_of_range_is_not_called_parallel() {
    let dir = scratch_dir("far-eye");
    for eye in ["1e300,0,0", "1e300,1e300,1e300", "3e12,1,1"] {
        let out = radiosity(
            &[
                "render", "--eye", eye, "--width", "8", "--height", "8", "-o", "a.png",
            ],
            &dir,
        );
        let err = stderr(&out);
        assert!(!out.status.success(), "{eye}");
        assert!(
            err.contains("--eye") && err.contains("out of range"),
            "{eye}: {err}"
        );
        assert!(!err.contains("parallel"), "{eye}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_scene_the_automatic_camera_cannot_frame_does_not_blame_eye() {
    // QA pass 15 of issue #16: a patch 1e-20 m across was told "--eye 0.00057,... is out of
    // range" with no --eye given; the point was the automatic camera's.
    let dir = scratch_dir("tiny-scene");
    std::fs::write(
        dir.join("tiny.scene"),
        "MAX_PATCH_AREA 0.5\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#A\nVERTICES 4\n\
         Er 1\nEg 1\nEb 1\nRr 0.5\nRg 0.5\nRb 0.5\nVERTEX0 0 0 0\nVERTEX1 1e-20 0 0\n\
         VERTEX2 1e-20 1e-20 0\nVERTEX3 0 1e-20 0\nPATCHEND\nSCENEEND\n",
    )
    .unwrap();
    let out = radiosity(
        &["render", "tiny.scene", "--width", "8", "-o", "t.png"],
        &dir,
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the automatic camera cannot frame this scene: it is 1.414e-20 across")
            && err.contains("give --eye and --look-at, or --scale"),
        "{err}"
    );
    assert!(!err.contains("--eye 0"), "{err}");
    assert!(!dir.join("t.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn work_past_the_limit_is_refused_before_it_starts_with_what_fits() {
    let dir = scratch_dir("work-limit");
    let scene = example("triangles.scene");
    // A few elements (one a surface, and the pieces where they touch): 21 pairs x 1000^4
    // point pairs, weeks of work.
    let out = radiosity(
        &[
            "formfactors",
            &scene,
            "--max-area",
            "100",
            "--steps",
            "1000",
            "-o",
            "t.ff",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("INTEGRAL_STEPS 1000 on 7 elements"), "{err}");
    assert!(err.contains("at most INTEGRAL_STEPS"), "{err}");
    assert!(err.contains("--no-work-limit"), "{err}");
    assert!(!dir.join("t.ff").exists());
    for (args, expect) in [
        (
            vec![
                "solve",
                &scene,
                "--method",
                "montecarlo",
                "--samples",
                "4294967295",
            ],
            "--samples 4294967295",
        ),
        (
            vec![
                "solve",
                &scene,
                "--method",
                "hemicube",
                "--resolution",
                "16384",
            ],
            "--resolution 16384",
        ),
        (
            vec![
                "render",
                "--supersample",
                "16",
                "--width",
                "10000",
                "--height",
                "10000",
            ],
            "--supersample 16",
        ),
        (
            vec![
                "pathtrace",
                "--paths",
                "100000",
                "--width",
                "4000",
                "--height",
                "4000",
            ],
            "--paths 100000",
        ),
    ] {
        let mut args = args.clone();
        // Each command's own kind of output (the name is checked first).
        let output = if args[0] == "solve" {
            "out.csv"
        } else {
            "out.png"
        };
        args.extend(["-o", output]);
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert!(!out.status.success(), "{args:?}: {err}");
        assert!(
            err.contains(expect) && err.contains("would fit"),
            "{args:?}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn memory_budget_honours_ulimit_v() {
    // Under a 1 GiB address-space limit a 3 GiB hemicube is refused with the sizes, not
    // aborted by a failed allocation (which MemAvailable alone would not foresee).
    let dir = scratch_dir("ulimit-v");
    let bin = env!("CARGO_BIN_EXE_radiosity");
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 1048576 && exec '{bin}' formfactors --method hemicube --resolution 8192 -o t.ff"
        ))
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("MiB of memory is available"), "{err}");
    assert!(err.contains("at most --resolution"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failed_allocation_is_an_error_not_an_abort() {
    // QA of issue #16: under tight `ulimit -v` limits the hierarchical solve aborted
    // ("memory allocation of 2048 bytes failed", a backtrace, status 134). Under an
    // address-space limit glibc's malloc reserves 64 MiB at a time per thread, so whether
    // a run fits depends on the threads and cannot be foreseen exactly: each run either
    // finishes, or ends with status 1 and a message that names the limit. At 60,000 KiB
    // (less than the program maps once its threads run) it cannot finish, so the message
    // is seen.
    let dir = scratch_dir("ulimit-oom");
    let bin = env!("CARGO_BIN_EXE_radiosity");
    for kib in [60_000, 250_000, 400_000] {
        let out = std::process::Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -v {kib} && exec '{bin}' solve --max-area 30 -o x.csv"
            ))
            .current_dir(&dir)
            .output()
            .unwrap();
        let err = stderr(&out);
        assert!(!err.contains("backtrace"), "ulimit -v {kib}: {err}");
        if kib == 60_000 || out.status.code() != Some(0) {
            assert_eq!(out.status.code(), Some(1), "ulimit -v {kib}: {err}");
            assert!(err.contains("ulimit -v"), "ulimit -v {kib}: {err}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_scene_far_from_the_origin_is_warned_about() {
    // A 1 x 1 x 1 closed box of six quads shifted by 3e9 along x and z: 2e9 times its size
    // out, where such scenes were measured to render wrong; the same box at the origin
    // says nothing.
    let dir = scratch_dir("far-origin");
    let cube = |shift: f64| {
        let v = |x: f64, y: f64, z: f64| format!("v {} {} {}\n", x + shift, y, z + shift);
        let mut s = String::new();
        for (x, y, z) in [
            (0., 0., 0.),
            (1., 0., 0.),
            (1., 1., 0.),
            (0., 1., 0.),
            (0., 0., 1.),
            (1., 0., 1.),
            (1., 1., 1.),
            (0., 1., 1.),
        ] {
            s += &v(x, y, z);
        }
        // Faces looking in.
        s += "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n";
        s
    };
    for (name, shift, warned) in [("far.obj", 3e9, true), ("near.obj", 0.0, false)] {
        let path = dir.join(name);
        std::fs::write(&path, cube(shift)).unwrap();
        let out = radiosity(&["check", path.to_str().unwrap(), "-q"], &dir);
        let err = stderr(&out);
        assert_eq!(err.contains("from the origin"), warned, "{name}: {err}");
        if warned {
            assert!(err.contains("far.obj: warning:"), "{err}");
            assert!(err.contains("subtract about 3.000e9"), "{err}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_objs_material_file_is_never_written_over() {
    // QA found `solve room.obj -o room.mtl`, `--report room.mtl`, `formfactors ... -o
    // room.mtl` and an OBJ export named after the input's own MTL replacing the MTL that
    // the OBJ reads (exit 0): every output is now refused over any file read as an input.
    let dir = scratch_dir("mtl-input");
    let obj = "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0 1 0\nv 1 1 0\n\
               usemtl wall\nf 4 3 2 1\nusemtl light\nf 5 6 2 1\n";
    let mtl = "newmtl wall\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0.5 0.5 0.5\nKe 1 1 1\n";
    std::fs::write(dir.join("room.obj"), obj).unwrap();
    std::fs::write(dir.join("room.mtl"), mtl).unwrap();
    for args in [
        vec!["solve", "room.obj", "-o", "room.mtl"],
        vec!["solve", "room.obj", "-o", "out.csv", "--report", "room.mtl"],
        vec!["formfactors", "room.obj", "-o", "room.mtl"],
        vec!["export", "room.obj", "-o", "room.obj"],
        vec!["export", "room.obj", "-o", "./room.obj"],
    ] {
        let out = radiosity(&args, &dir);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = stderr(&out);
        // The scene file itself has the command line's own message; every other input
        // the library's. `solve` and `formfactors` refuse a .mtl name before reading
        // anything (they write .csv or .json, and .ff): the MTL is as safe (below, the
        // library's refusal is shown for material files named as they may write).
        assert!(
            err.contains("an output never replaces an input")
                || err.contains("destroy the input")
                || (args[0] != "export" && err.contains(" room.mtl: the ")),
            "{args:?}: {err}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("room.mtl")).unwrap(),
            mtl,
            "{args:?}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("room.obj")).unwrap(),
            obj,
            "{args:?}"
        );
    }
    // Material files with names `solve` and `formfactors` write: refused as soon as the
    // scene has been read, before any work (QA of issue #16: the library refused them only
    // when writing, after the solve).
    for (command, flag, name) in [
        ("solve", "-o", "mat.csv"),
        ("solve", "--report", "mat.csv"),
        ("formfactors", "-o", "mat.ff"),
    ] {
        let scene = format!("{command}.obj");
        std::fs::write(dir.join(&scene), obj.replace("room.mtl", name)).unwrap();
        std::fs::write(dir.join(name), mtl).unwrap();
        let mut args = vec![command, &scene, flag, name];
        if flag == "--report" {
            args.extend(["-o", "out.csv"]);
        }
        let out = radiosity(&args, &dir);
        assert!(!out.status.success(), "{}", stderr(&out));
        assert!(
            stderr(&out).contains(&format!(
                "{flag} {name}: {name} is a file the scene {scene} reads; writing it would \
                 destroy the input"
            )) && !stderr(&out).contains("solved "),
            "{command}: {}",
            stderr(&out)
        );
        assert_eq!(std::fs::read_to_string(dir.join(name)).unwrap(), mtl);
    }
    // An export named so that its own MTL is the input's (`mat.obj` writes `mat.mtl`).
    std::fs::write(dir.join("other.obj"), obj.replace("room.mtl", "mat.mtl")).unwrap();
    std::fs::write(dir.join("mat.mtl"), mtl).unwrap();
    let out = radiosity(&["export", "other.obj", "-o", "mat.obj"], &dir);
    assert!(!out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("-o mat.obj (its material library mat.mtl): mat.mtl is a file")
            && !stderr(&out).contains("solved "),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read_to_string(dir.join("mat.mtl")).unwrap(), mtl);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_million_bench_repeats_are_refused_after_the_first_run() {
    // QA pass 16 of #16: `bench --repeat 1000000` started some 100 hours of runs at once.
    // Any run of the pipeline takes more than 0.84 us, so 4294967295 of them are past the
    // hour's limit after the first (a million would fit on a machine where a run takes
    // under 3.6 ms, and the test would run an hour); the refusal says how many fit.
    let dir = scratch_dir("bench-repeat");
    let args = [
        "bench",
        "--max-area",
        "20000",
        "--size",
        "8",
        "--supersample",
        "1",
        "--repeat",
        "4294967295",
    ];
    let start = std::time::Instant::now();
    let out = radiosity(&args, &dir);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("error: --repeat 4294967295 at "), "{err}");
    assert!(err.contains("more than the limit of 60.0 min"), "{err}");
    assert!(err.contains("at most --repeat "), "{err}");
    assert!(err.contains("--no-work-limit"), "{err}");
    // No row of the table: nothing was timed past the first run.
    assert!(
        !crate::fixtures::stdout(&out).contains("| cornell"),
        "{err}"
    );
    assert!(start.elapsed().as_secs() < 120, "{:?}", start.elapsed());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_hierarchical_min_area_past_the_element_budget_is_refused_before_the_solve() {
    // QA pass 16 of #16: `--min-area 1e-9` was accepted and refined for minutes, memory
    // growing. The built-in Cornell box has some 2e6 mm^2 of surfaces: cut to 1e-9 mm^2
    // that is some 2e15 leaves, far past the 8,000,000 elements --max-area is held to.
    let dir = scratch_dir("min-area-budget");
    for (command, output) in [
        ("check", None),
        ("solve", Some("out.csv")),
        ("render", Some("out.png")),
    ] {
        let mut args = vec![command, "--solver", "hierarchical", "--min-area", "1e-9"];
        if let Some(output) = output {
            args.extend(["-o", output]);
        }
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{command}: {err}");
        assert!(
            err.contains("a minimum element area of 1e-9 lets hierarchical radiosity cut"),
            "{command}: {err}"
        );
        assert!(
            err.contains("more than the limit of 8000000 elements"),
            "{command}: {err}"
        );
        assert!(err.contains("--min-area"), "{command}: {err}");
        assert!(!err.contains("solve: "), "{command}: {err}");
        if let Some(output) = output {
            assert!(!dir.join(output).exists(), "{command}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
