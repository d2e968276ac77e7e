//! The `radiosity` program end to end: each command as a user runs it.

use std::path::Path;

use crate::fixtures::{example, radiosity, scratch_dir, stderr, stdout};

#[test]
fn render_writes_png_of_requested_size() {
    let dir = scratch_dir("render");
    // The built-in Cornell box, coarsely meshed so the test is quick.
    let out = radiosity(
        &[
            "render",
            "--max-area",
            "20000",
            "--width",
            "48",
            "--height",
            "64",
            "-o",
            "box.png",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.join("box.png")).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (48, 64));
    // Not a blank picture: the red wall is on the left, the green wall on the right.
    let (left, right) = (img.get_pixel(2, 32), img.get_pixel(45, 32));
    assert!(left[0] > left[1], "left edge should be red, got {left:?}");
    assert!(
        right[1] > right[0],
        "right edge should be green, got {right:?}"
    );
    assert!(
        stderr(&out).contains("timings:"),
        "render prints stage timings"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn render_default_output_name_and_shadings() {
    let dir = scratch_dir("shadings");
    for shading in ["smooth", "flat", "wireframe"] {
        let out = radiosity(
            &[
                "render",
                "--max-area",
                "20000",
                "--width",
                "32",
                "--height",
                "32",
                "--shading",
                shading,
                "-q",
            ],
            &dir,
        );
        assert!(out.status.success(), "{shading}: {}", stderr(&out));
        assert!(
            out.stderr.is_empty(),
            "--quiet prints nothing: {}",
            stderr(&out)
        );
        let img = image::open(dir.join("cornell.png")).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (32, 32));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn solve_writes_csv_with_exact_header_and_one_row_per_element() {
    let dir = scratch_dir("solve");
    let out = radiosity(
        // One solve on the file's own mesh (no adaptive subdivision), whose element count
        // `check` prints.
        &[
            "solve",
            &example("triangles.scene"),
            "-o",
            "tri.csv",
            "-q",
            "--adapt-rounds",
            "0",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = std::fs::read_to_string(dir.join("tri.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "surface,element,area,centroid_x,centroid_y,centroid_z,radiosity_r,radiosity_g,radiosity_b"
    );
    let check = radiosity(&["check", &example("triangles.scene")], &dir);
    let text = String::from_utf8_lossy(&check.stdout);
    let elements: usize = text
        .lines()
        .find(|l| l.starts_with("elements"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|n| n.parse().ok())
        .expect("check prints the element count");
    assert_eq!(lines.count(), elements);
    // And the length unit (a .scene file states none: metres, as the README says).
    assert!(
        text.lines().any(|l| l
            == "unit              metres (a .scene file states no unit; metres assumed)"),
        "{text}"
    );

    // The same solution as JSON.
    let out = radiosity(
        &[
            "solve",
            &example("triangles.scene"),
            "-o",
            "tri.json",
            "-q",
            "--adapt-rounds",
            "0",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("tri.json")).unwrap()).unwrap();
    // The contract of issue #2: an array of records with the CSV's fields.
    assert_eq!(json.as_array().unwrap().len(), elements);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn form_factor_file_round_trip_and_refusals() {
    let dir = scratch_dir("ff");
    let scene = example("triangles.scene");
    let out = radiosity(&["formfactors", &scene, "-o", "t.ff", "-q"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));

    // Solving from the file gives the same numbers as computing afresh on the same mesh
    // (adaptive subdivision, which makes new meshes, left out).
    let a = radiosity(
        &["solve", &scene, "-o", "a.csv", "-q", "--adapt-rounds", "0"],
        &dir,
    );
    let b = radiosity(
        &[
            "solve",
            &scene,
            "--form-factors",
            "t.ff",
            "-o",
            "b.csv",
            "-q",
        ],
        &dir,
    );
    assert!(
        a.status.success() && b.status.success(),
        "{}{}",
        stderr(&a),
        stderr(&b)
    );
    assert_eq!(
        std::fs::read(dir.join("a.csv")).unwrap(),
        std::fs::read(dir.join("b.csv")).unwrap()
    );

    // A file for another mesh is stale.
    let out = radiosity(
        &[
            "solve",
            &scene,
            "--max-area",
            "0.1",
            "--form-factors",
            "t.ff",
            "-o",
            "c.csv",
        ],
        &dir,
    );
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("t.ff"), "{err}");
    assert!(err.contains("different mesh"), "{err}");
    assert!(
        err.contains("; recompute it with `radiosity formfactors`"),
        "{err}"
    );
    assert!(!dir.join("c.csv").exists(), "no output from a refused run");

    // A file made with another method is refused, naming both and the flags of each.
    let out = radiosity(
        &[
            "solve",
            &scene,
            "--method",
            "contour",
            "--form-factors",
            "t.ff",
            "-o",
            "e.csv",
        ],
        &dir,
    );
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("was computed with method `area k=2`, not `contour k=2`"),
        "{err}"
    );
    assert!(
        err.contains(
            "; recompute it with `radiosity formfactors` and --method contour --steps 2, or use \
             the settings it was made with (--method area --steps 2)"
        ),
        "{err}"
    );
    assert!(!dir.join("e.csv").exists(), "no output from a refused run");

    // A corrupted byte is caught by the checksum.
    let mut bytes = std::fs::read(dir.join("t.ff")).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x40;
    std::fs::write(dir.join("bad.ff"), &bytes).unwrap();
    let out = radiosity(
        &["solve", &scene, "--form-factors", "bad.ff", "-o", "d.csv"],
        &dir,
    );
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("bad.ff"), "{err}");
    assert!(
        err.contains("; recompute it with `radiosity formfactors`"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_scene_reports_file_line_and_column() {
    let dir = scratch_dir("bad");
    std::fs::write(
        dir.join("bad.scene"),
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#a\nVERTICES 3\nEr 0\nEg zero\n",
    )
    .unwrap();
    let out = radiosity(&["render", "bad.scene"], &dir);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("bad.scene:8:4"), "{err}");
    assert!(!dir.join("bad.png").exists());
    let out = radiosity(&["check", "missing.scene"], &dir);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("missing.scene"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_prints_statistics() {
    let dir = scratch_dir("check");
    let out = radiosity(
        &["check", &example("occluder.scene"), "--max-area", "2"],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    for field in [
        "surfaces",
        "elements",
        "total area",
        "row sums",
        "reciprocity error",
        "escaped from",
        "stage times",
    ] {
        assert!(text.contains(field), "check output lacks {field}:\n{text}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_arguments_are_refused_with_a_message() {
    let dir = scratch_dir("args");
    for (args, needle) in [
        (vec!["render", "--eye", "1,2"], "--eye"),
        (vec!["render", "--gamma", "0"], "--gamma"),
        (vec!["render", "--exposure", "bright"], "--exposure"),
        (vec!["render", "--width", "0"], "--width"),
        (
            vec!["render", "--max-area=-1"],
            "--max-area -1: give the largest element area",
        ),
        (vec!["check", "--steps", "0"], "--steps"),
        // 1000^2 points on each of the coarse box's elements: more than 5e7 in all.
        (
            vec!["check", "--max-area", "20000", "--steps", "1000"],
            "integration points (more than 5e7); use fewer steps (--steps) or larger elements \
             (--max-area)",
        ),
    ] {
        let out = radiosity(&args, &dir);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn progressive_render_writes_snapshots() {
    let dir = scratch_dir("progressive");
    let out = radiosity(
        &[
            "render",
            "--max-area",
            "20000",
            "--solver",
            "progressive",
            "--snapshots",
            "snaps",
            "--snapshot-every",
            "20",
            "--width",
            "32",
            "--height",
            "32",
            "-o",
            "box.png",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("shots, unshot power"), "{err}");
    assert!(dir.join("box.png").exists());
    let mut snaps: Vec<String> = std::fs::read_dir(dir.join("snaps"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    snaps.sort();
    assert!(!snaps.is_empty());
    assert_eq!(snaps[0], "shot-00020.png");
    for (k, name) in snaps.iter().enumerate() {
        assert_eq!(*name, format!("shot-{:05}.png", 20 * (k + 1)));
        let img = image::open(dir.join("snaps").join(name)).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (32, 32));
    }

    // check and solve with the progressive solver; no form-factor statistics.
    let out = radiosity(
        &[
            "check",
            "--max-area",
            "20000",
            "--solver",
            "progressive",
            "--tolerance",
            "0.001",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("progressive "), "{text}");
    assert!(!text.contains("row sums"), "{text}");
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "20000",
            "--solver",
            "progressive",
            "-o",
            "b.csv",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join("b.csv").exists());

    for (args, needle) in [
        (vec!["render", "--snapshots", "s"], "--snapshots"),
        (
            vec!["render", "--solver", "progressive", "--snapshot-every", "0"],
            "--snapshot-every",
        ),
        (
            vec!["solve", "--solver", "progressive", "--tolerance", "0"],
            "--tolerance",
        ),
        (
            vec!["solve", "--solver", "progressive", "--form-factors", "x.ff"],
            "--form-factors",
        ),
    ] {
        let out = radiosity(&args, &dir);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn generate_building_writes_a_scene_that_reads_back() {
    let dir = scratch_dir("generate");
    let out = radiosity(
        &[
            "generate",
            "building",
            "-o",
            "b.scene",
            "--floors",
            "1",
            "--rooms-x",
            "2",
            "--rooms-z",
            "1",
            "--max-area",
            "4",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    // 2 rooms x (6 + 294) + 6 windows x 9 + 1 door x 10.
    assert!(stdout.contains("664 surfaces"), "{stdout}");
    assert!(stdout.contains("elements"), "{stdout}");
    let file = radiosity::scene::read_scene(&dir.join("b.scene")).unwrap();
    assert_eq!(file.scene.surfaces.len(), 664);
    assert_eq!(file.settings.max_patch_area, 4.0);
    // The committed examples are what the documented commands write.
    for (file, args) in [
        (
            "building.scene",
            &["--floors", "2", "--rooms-x", "3", "--rooms-z", "3"][..],
        ),
        (
            "building_small.scene",
            &[
                "--floors",
                "1",
                "--rooms-x",
                "2",
                "--rooms-z",
                "2",
                "--max-area",
                "2",
            ][..],
        ),
    ] {
        // As the README regenerates them: over the file of the last run, with --force.
        let mut all = vec!["generate", "building", "--force", "-o", "x.scene"];
        all.extend_from_slice(args);
        let out = radiosity(&all, &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        let written = radiosity::scene::read_scene(&dir.join("x.scene")).unwrap();
        let committed = radiosity::scene::read_scene(Path::new(&example(file))).unwrap();
        assert!(written == committed, "examples/{file} is out of date");
    }
    let bad = radiosity(
        &["generate", "building", "-o", "c.scene", "--room-size", "3"],
        &dir,
    );
    assert!(!bad.status.success());
    assert!(
        stderr(&bad).contains("--room-size 3: give the inner side of a room"),
        "{}",
        stderr(&bad)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hierarchical_solves_checks_and_renders_its_leaves() {
    let dir = scratch_dir("hierarchical");
    let out = radiosity(
        &["check", "--solver", "hierarchical", "--epsilon", "0.2"],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("hierarchical "), "{text}");
    assert!(text.contains("leaves"), "{text}");
    assert!(!text.contains("row sums"), "{text}");
    let out = radiosity(
        &[
            "render",
            "--solver",
            "hierarchical",
            "--epsilon",
            "0.2",
            "--width",
            "32",
            "--height",
            "32",
            "-o",
            "h.png",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join("h.png").exists());
    // The solution file lists the leaves, not the prepared mesh's elements.
    let out = radiosity(
        &[
            "solve",
            "--solver",
            "hierarchical",
            "--epsilon",
            "0.2",
            "-o",
            "h.csv",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = std::fs::read_to_string(dir.join("h.csv"))
        .unwrap()
        .lines()
        .count();
    assert!(rows > 100, "{rows} rows");
    for (args, needle) in [
        (
            vec!["solve", "--solver", "hierarchical", "--epsilon", "0"],
            "--epsilon",
        ),
        (
            vec!["solve", "--solver", "hierarchical", "--min-area", "0"],
            "--min-area",
        ),
        (
            vec![
                "solve",
                "--solver",
                "hierarchical",
                "--form-factors",
                "x.ff",
            ],
            "--form-factors",
        ),
    ] {
        let out = radiosity(&args, &dir);
        assert!(!out.status.success());
        assert!(stderr(&out).contains(needle), "{}", stderr(&out));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_prints_a_row_against_the_chosen_dense_reference() {
    let dir = scratch_dir("compare");
    let out = radiosity(
        &[
            "compare",
            "--max-area",
            "20000",
            "--solver",
            "hierarchical",
            "--epsilon",
            "0.01",
            "--method",
            "contour",
            "--steps",
            "2",
            "--quiet",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    let row = text
        .lines()
        .find(|l| l.starts_with("| cornell |"))
        .unwrap_or_else(|| panic!("no row for the built-in box: {text}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    // | scene | elements | solver | its elements | time | peak | reference | ... | RMS | max | mean |
    assert_eq!(cells[7], "contour k=2", "{row}");
    // --method is the reference's here: no warning that hierarchical radiosity ignores it
    // (warnings print even with --quiet).
    assert!(
        !stderr(&out).contains("--method contour ignored"),
        "{}",
        stderr(&out)
    );
    let rms: f64 = cells[10].parse().unwrap_or_else(|_| panic!("RMS in {row}"));
    // The coarse box (about 130 elements) at epsilon 0.01: a few per cent; a broken
    // projection or reference gives tens of per cent.
    assert!(rms > 0.0 && rms < 15.0, "{row}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The RMS cell of `compare`'s row for `stem`, in per cent.
fn compare_rms(out: &std::process::Output, stem: &str) -> f64 {
    let text = String::from_utf8_lossy(&out.stdout);
    let row = text
        .lines()
        .find(|l| l.starts_with(&format!("| {stem} |")))
        .unwrap_or_else(|| panic!("no row for {stem}: {text}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    cells[10].parse().unwrap_or_else(|_| panic!("RMS in {row}"))
}

#[test]
fn compare_works_where_surfaces_lie_on_and_touch_others() {
    // Issue #11: every example but the Cornell box failed with "lies on no element of the
    // other mesh", even dense against dense. The furnished room (metres; a rug on the floor,
    // boxes standing on it) and the library's contact scene (a rug in the floor's plane,
    // blocks standing on floor and rug), coarsely meshed: dense against the same dense
    // solve is exactly 0, progressive (to 1 % unshot) on the same mesh about 1 %, and
    // hierarchical at its defaults on its own, finer leaves 6 to 14 % (the coarse dense
    // reference's own error is most of it); a point given another surface's element would
    // show as tens of per cent or more.
    let dir = scratch_dir("compare-contact");
    let contact = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../radiosity/tests/suite/contact.scene")
        .display()
        .to_string();
    for (scene, stem, area) in [
        (example("room.scene"), "room", "1"),
        (contact, "contact", "0.1"),
    ] {
        for (solver, bound) in [
            ("gauss-seidel", 0.0),
            ("progressive", 5.0),
            ("hierarchical", 15.0),
        ] {
            let out = radiosity(
                &[
                    "compare",
                    &scene,
                    "--max-area",
                    area,
                    "--solver",
                    solver,
                    "-q",
                ],
                &dir,
            );
            assert!(out.status.success(), "{stem} {solver}: {}", stderr(&out));
            let rms = compare_rms(&out, stem);
            assert!(rms <= bound, "{stem} {solver}: RMS {rms} %");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn adapt_rounds_refine_the_mesh_and_refuse_a_form_factor_file() {
    let dir = scratch_dir("adapt");
    let scene = example("room.scene");
    let once = radiosity(
        &["solve", &scene, "-o", "once.csv", "--adapt-rounds", "0"],
        &dir,
    );
    let twice = radiosity(
        &["solve", &scene, "-o", "adapted.csv", "--adapt-rounds", "1"],
        &dir,
    );
    assert!(
        once.status.success() && twice.status.success(),
        "{}{}",
        stderr(&once),
        stderr(&twice)
    );
    let rows = |f: &str| {
        std::fs::read_to_string(dir.join(f))
            .unwrap()
            .lines()
            .count()
    };
    // The refined solution has more elements, and says how it got them.
    assert!(rows("adapted.csv") > rows("once.csv"));
    let notes = stderr(&twice);
    // Each round is told before the solve of the mesh it made (QA of issue #16: the rounds
    // came after the last "solved" line).
    let round = notes.find("adaptive subdivision, round 1: ").expect(&notes);
    let solved_before = notes[..round].matches("\nsolved ").count();
    let solved_after = notes[round..].matches("\nsolved ").count();
    assert_eq!((solved_before, solved_after), (1, 1), "{notes}");
    // The room's area is kept: the elements are split, none lost (column 3 is the area).
    let area = |f: &str| -> f64 {
        std::fs::read_to_string(dir.join(f))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(2).unwrap().parse::<f64>().unwrap())
            .sum()
    };
    assert!((area("adapted.csv") - area("once.csv")).abs() < 1e-9 * area("once.csv"));

    let ff = radiosity(&["formfactors", &scene, "-o", "r.ff", "-q"], &dir);
    assert!(ff.status.success(), "{}", stderr(&ff));
    let refused = radiosity(
        &[
            "solve",
            &scene,
            "--form-factors",
            "r.ff",
            "--adapt-rounds",
            "1",
        ],
        &dir,
    );
    assert!(!refused.status.success());
    assert!(
        stderr(&refused).contains("--adapt-rounds cannot be used with --form-factors"),
        "{}",
        stderr(&refused)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A 4 x 4 floor, a 2 x 1 rug `lift` above it and a light panel over them, as a scene file.
fn floor_and_rug_scene(lift: f64) -> String {
    let patch = |name: &str, e: f64, corners: [[f64; 3]; 4]| {
        let mut text = format!("PATCHBEGIN\n#{name}\nVERTICES 4\nEr {e}\nEg {e}\nEb {e}\n");
        text += "Rr 0.5\nRg 0.5\nRb 0.5\n";
        for (i, [x, y, z]) in corners.iter().enumerate() {
            text += &format!("VERTEX{i} {x} {y} {z}\n");
        }
        text + "PATCHEND\n"
    };
    let y = lift;
    let mut text = String::from("MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\n");
    text += &patch(
        "Floor",
        0.0,
        [[4., 0., 0.], [0., 0., 0.], [0., 0., 4.], [4., 0., 4.]],
    );
    text += &patch(
        "Rug",
        0.0,
        [[3., y, 1.], [1., y, 1.], [1., y, 2.], [3., y, 2.]],
    );
    text += &patch(
        "Light",
        10.0,
        [[1., 2., 1.], [3., 2., 1.], [3., 2., 3.], [1., 2., 3.]],
    );
    text + "SCENEEND\n"
}

#[test]
fn check_lists_surfaces_lying_on_others() {
    // Issue #11: a rug exactly in the floor's plane, or 1e-4 above it, is reported by
    // index and name, and the floor under it is left out: the total area is the floor's 16
    // + the rug's 2 + the light's 4, less the 2 under the rug (the rug's outline lies on the
    // lines of the floor's 1 x 1 grid: nothing is split, so this is exact to rounding).
    let dir = scratch_dir("lying_on");
    for (lift, same_plane) in [(0.0, 1), (1e-4, 0)] {
        let path = dir.join(format!("rug_{lift}.scene"));
        std::fs::write(&path, floor_and_rug_scene(lift)).unwrap();
        let out = radiosity(&["check", path.to_str().unwrap()], &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        let text = stdout(&out);
        let note = format!("1 surface lies on others ({same_plane} in the same plane)");
        assert!(text.contains(&note), "lift {lift}:\n{text}");
        assert!(
            text.contains("surface 1 \"Rug\" on surface 0 \"Floor\""),
            "lift {lift}:\n{text}"
        );
        let area: f64 = text
            .lines()
            .find_map(|l| l.strip_prefix("total area"))
            .and_then(|v| v.split_whitespace().next()?.parse().ok())
            .unwrap();
        assert!(
            (area - 20.0).abs() < 1e-9,
            "lift {lift}: total area {area}\n{text}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A box scene (a room facing in, its floor... all faces emitting) with the given ORIGIN
/// and SIZE lines and MAX_PATCH_AREA.
fn box_room_scene(max_area: &str, origin: &str, size: &str) -> String {
    format!(
        "MAX_PATCH_AREA {max_area}\nINTEGRAL_STEPS 1\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
         Er 1\nEg 1\nEb 1\nRr 0.5\nRg 0.5\nRb 0.5\nORIGIN {origin}\nSIZE {size}\nBOXEND\n\
         SCENEEND\n"
    )
}

// Regression (issue 12): these panicked (SIZE 1 1, the +-1e20 quad), headed for ~100 GB
// (SIZE 1e-300 ...), or were refused without a file and line (SIZE 1e308, a tiny
// MAX_PATCH_AREA); a floor given twice was accepted silently.
#[test]
fn hostile_scene_geometry_is_refused_with_file_and_line() {
    let dir = scratch_dir("hostile_geometry");
    let cases = [
        (
            "1",
            "0 0 0",
            "1 1",
            "h.scene:14:9: error: expected a number (the z size)",
        ),
        (
            "1",
            "0 0 0",
            "1 abc 1",
            "h.scene:14:8: error: expected a number (the y size)",
        ),
        (
            "1",
            "0 0 0",
            "1e-300 1e-300 1e-300",
            "h.scene:14:1: error: the box's face \"Room.base\"",
        ),
        (
            "1",
            "0 0 0",
            "1e308 1 1",
            "h.scene:14:6: error: the box reaches x = 1e308",
        ),
        (
            "1e-300",
            "0 0 0",
            "1 1 1",
            "h.scene:1: error: MAX_PATCH_AREA 1e-300: meshing",
        ),
    ];
    for (max_area, origin, size, expected) in cases {
        std::fs::write(dir.join("h.scene"), box_room_scene(max_area, origin, size)).unwrap();
        let out = radiosity(&["check", "h.scene"], &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "SIZE {size}: {err}");
        assert!(err.contains(expected), "SIZE {size}: {err}");
        assert!(
            !err.contains("panicked") && !err.contains(" inf"),
            "SIZE {size}: {err}"
        );
    }
    // The floor of the rug scene given twice.
    let scene = floor_and_rug_scene(0.0).replace("#Rug", "#Floor2").replace(
        "VERTEX0 3 0 1\nVERTEX1 1 0 1\nVERTEX2 1 0 2\nVERTEX3 3 0 2",
        "VERTEX0 4 0 0\nVERTEX1 0 0 0\nVERTEX2 0 0 4\nVERTEX3 4 0 4",
    );
    std::fs::write(dir.join("twice.scene"), scene).unwrap();
    let out = radiosity(&["check", "twice.scene"], &dir);
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(
        err.contains("twice.scene:27:1: error: surface \"Floor2\" lies exactly on surface \"Floor\" (line 13)"),
        "{err}"
    );
    // A quad of +-1e20 is within the supported range: solved.
    let q = "MAX_PATCH_AREA 1e41\nINTEGRAL_STEPS 1\nSCENEBEGIN\nPATCHBEGIN\n#Q\nVERTICES 4\n\
             Er 1\nEg 1\nEb 1\nRr 0.5\nRg 0.5\nRb 0.5\nVERTEX0 -1e20 -1e20 0\n\
             VERTEX1 1e20 -1e20 0\nVERTEX2 1e20 1e20 0\nVERTEX3 -1e20 1e20 0\nPATCHEND\nSCENEEND\n";
    std::fs::write(dir.join("q.scene"), q).unwrap();
    let out = radiosity(&["check", "q.scene"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}
