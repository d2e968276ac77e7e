//! A new user's first hour (issue 16): every message, help text and default says what is
//! true. Each test guards one case that once puzzled a user.

use crate::fixtures::{radiosity, scratch_dir, stderr};

#[test]
fn progressive_max_shots_caps_the_run_and_still_writes_the_picture() {
    let dir = scratch_dir("max-shots");
    // The coarse Cornell box needs far more than 3 shots to bring the unshot power below
    // 1 % (every shot leaves the reflected part of its power unshot, and the walls reflect
    // about half), so 3 shots stop at the cap.
    let out = radiosity(
        &[
            "render",
            "--max-area",
            "20000",
            "--solver",
            "progressive",
            "--max-shots",
            "3",
            "--snapshots",
            "snaps",
            "--snapshot-every",
            "1",
            "--width",
            "16",
            "--height",
            "16",
            "--supersample",
            "1",
            "-o",
            "capped.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "a capped run is not a failure: {err}");
    assert!(dir.join("capped.png").exists(), "{err}");
    assert!(dir.join("snaps/shot-00003.png").exists(), "{err}");
    assert!(!dir.join("snaps/shot-00004.png").exists(), "{err}");
    // The folder is announced before the solve, as made by this run, with the most
    // pictures the shot cap allows (3 shots, one picture each).
    assert!(
        err.contains("snapshots to snaps (created): a picture every 1 shot, at most 3"),
        "{err}"
    );
    assert!(
        err.contains("stopped at --max-shots 3: the unshot power is")
            && err.contains("not yet below the tolerance 1 %"),
        "says how far it got: {err}"
    );
    // Reaching the tolerance first is no cap: nothing said.
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "20000",
            "--solver",
            "progressive",
            "--tolerance",
            "0.5",
            "--max-shots",
            "100000",
            "-o",
            "b.csv",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("--max-shots"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The element count `generate building` prints for its file.
fn printed_elements(out: &std::process::Output) -> usize {
    let text = crate::fixtures::stdout(out);
    let tail = text.rsplit(": ").next().unwrap_or("");
    tail.split_whitespace()
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no element count in {text:?}"))
}

#[test]
fn generate_help_states_the_element_count_it_makes() {
    let dir = scratch_dir("generate-help");
    let help = radiosity(&["generate", "building", "--help"], &dir);
    let help = crate::fixtures::stdout(&help);
    assert!(help.contains("1 gives 92,946 elements"), "{help}");
    // The default building at --max-area 1 (the default) makes what the help promises,
    // within 5 % (the count moves a little with the seed's furniture), counted as the
    // other commands mesh it (contact refinement included).
    let out = radiosity(&["generate", "building", "-o", "b.scene"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let n = printed_elements(&out) as f64;
    assert!((n - 92_946.0).abs() < 0.05 * 92_946.0, "{n}");
    // One room is "1 room".
    let out = radiosity(
        &[
            "generate",
            "building",
            "--floors",
            "1",
            "--rooms-x",
            "1",
            "--rooms-z",
            "1",
            "-o",
            "one.scene",
        ],
        &dir,
    );
    let text = crate::fixtures::stdout(&out);
    assert!(text.contains(": 1 room, "), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn help_texts_name_every_solver_and_default() {
    let dir = scratch_dir("help-texts");
    let view = crate::fixtures::stdout(&radiosity(&["view", "--help"], &dir));
    for name in [
        "auto",
        "dense",
        "gauss-seidel",
        "lu",
        "progressive",
        "hierarchical",
    ] {
        assert!(view.contains(name), "view --help names {name}: {view}");
    }
    let render = crate::fixtures::stdout(&radiosity(&["render", "--help"], &dir));
    // Each iterative solver's default tolerance, as setup uses it.
    for default in [
        "default 1e-9",
        "default 0.01 = 1 %",
        "Hierarchical: the power still changing",
        "default 1e-6",
    ] {
        assert!(
            render.contains(default),
            "render --help gives {default}: {render}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bench_header_says_what_auto_picks_and_quiet_silences_it() {
    let dir = scratch_dir("bench-quiet");
    let args = [
        "bench",
        "--max-area",
        "20000",
        "--repeat",
        "1",
        "--size",
        "8",
    ];
    let out = radiosity(&args, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    // `auto` picks hierarchical radiosity past the dense limit (solve::choose), never
    // progressive refinement.
    let err = stderr(&out);
    assert!(err.contains("else hierarchical)"), "{err}");
    assert!(!err.contains("progressive"), "{err}");
    // It times what `render` draws by default, and says so (QA of issue #16: one ray a
    // pixel from the mesh alone, unsaid).
    assert!(
        err.contains("render 8x8, 4 to 64 rays a pixel (adaptive), direct light gathered per ray (as `render`)"),
        "{err}"
    );
    let mut paper = args.to_vec();
    paper.extend(["--supersample", "1", "--direct-light", "mesh"]);
    let out = radiosity(&paper, &dir);
    assert!(
        stderr(&out)
            .contains("render 8x8, 1 ray a pixel, shading from the mesh alone (the paper's)"),
        "{}",
        stderr(&out)
    );
    let table = crate::fixtures::stdout(&out);
    assert!(table.starts_with("| scene |"), "{table}");
    let mut quiet = args.to_vec();
    quiet.push("-q");
    let out = radiosity(&quiet, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(out.stderr.is_empty(), "bench -q: {}", stderr(&out));
    assert_eq!(
        crate::fixtures::stdout(&out).lines().count(),
        3,
        "header, rule, one row"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_gives_the_reason_beside_odd_row_sums_and_the_escaped_share() {
    let dir = scratch_dir("check-reasons");
    // The furnished room: boxes stand on the floor, so their bases face it at no distance
    // and see nothing (row sum 0); the cupboard stands 2 cm from the left wall, a pair far
    // closer than its 0.5 m elements, which k = 2 over-counts (rows above 1).
    let out = radiosity(&["check", &crate::fixtures::example("room.scene")], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = crate::fixtures::stdout(&out);
    assert!(
        text.contains("see no other element (row sum 0; the first is element")
            && text.contains(".base\"): they see no other element's front, most often as faces pressed against another surface"),
        "{text}"
    );
    // Explained, but not a warning: 70 of 1,675 rows, most of them small pieces cut along
    // the furniture's feet, the largest 1.04, count 0.03 % of the power twice (below
    // ROW_SUM_WARN = 1.1 and a twentieth of the area; one element in twenty, the rule
    // before, warned on the shipped room).
    let line = text
        .lines()
        .find(|l| l.contains("elements have form-factor rows summing above 1.01"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(!line.contains("warning:"), "{line}");
    // The escaped power as a share of the emitted, beside the absolute figure, and what it
    // is.
    assert!(text.contains(" %) + escaped "), "{text}");
    assert!(
        text.contains("escaped: light that reached no element"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_explains_the_hemicube_rays_and_sampled_reciprocity() {
    let dir = scratch_dir("check-methods");
    let coarse = ["check", "--max-area", "20000"];
    let mut hemicube = coarse.to_vec();
    hemicube.extend(["--method", "hemicube", "--resolution", "16"]);
    let out = radiosity(&hemicube, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = crate::fixtures::stdout(&out);
    assert!(
        text.contains(
            "visibility rays   none: the hemicube finds what is visible with a depth buffer"
        ),
        "{text}"
    );
    assert!(!text.contains("0.0 M rays/s"), "{text}");
    let mut montecarlo = coarse.to_vec();
    montecarlo.extend(["--method", "montecarlo", "--samples", "64"]);
    let out = radiosity(&montecarlo, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = crate::fixtures::stdout(&out);
    assert!(
        text.contains("(expected: Monte Carlo estimates each row with its own random rays"),
        "{text}"
    );
    // The exact method computes one number per pair: no excuse printed.
    let mut contour = coarse.to_vec();
    contour.extend(["--method", "contour"]);
    let out = radiosity(&contour, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!crate::fixtures::stdout(&out).contains("(expected:"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_methods_refuses_a_scene_and_reports_progress() {
    let dir = scratch_dir("compare-methods");
    for (args, needle) in [
        (
            vec!["check", "room.scene", "--compare-methods"],
            "not on a scene: drop room.scene",
        ),
        (
            vec!["check", "--compare-methods", "--method", "hemicube"],
            "drop --method, --steps, --resolution, --samples and --seed",
        ),
        // They were ignored without a word (QA of issue #16).
        (
            vec!["check", "--compare-methods", "--samples", "64"],
            "drop --method, --steps, --resolution, --samples and --seed",
        ),
    ] {
        let out = radiosity(&args, &dir);
        assert!(!out.status.success(), "{args:?}");
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    }
    // One element per unit square: the cheapest table (the fixed-resolution hemicubes
    // still take about a second), with a line per method on stderr.
    let out = radiosity(&["check", "--compare-methods", "--max-area", "1"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    let n = crate::fixtures::stdout(&out)
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| method"))
        .count();
    assert!(n >= 2, "{}", crate::fixtures::stdout(&out));
    assert!(err.contains(&format!("measuring {n} of {n}: ")), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_reports_the_dense_matrix_size_not_a_leftover_peak() {
    let dir = scratch_dir("compare-matrix");
    let out = radiosity(
        &[
            "compare",
            "--max-area",
            "20000",
            "--solver",
            "progressive",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = crate::fixtures::stdout(&out);
    assert!(text.contains("| dense matrix (MiB) |"), "{text}");
    let row = text.lines().find(|l| l.starts_with("| cornell |")).unwrap();
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    // | scene | elements | ... | dense time | dense matrix | ...: the f32 matrix of the
    // elements' count, 4 n^2 bytes, whichever solver ran first.
    let n: f64 = cells[2].parse().unwrap();
    let mib: f64 = cells[9].parse().unwrap();
    let expected = 4.0 * n * n / (1024.0 * 1024.0);
    assert!(
        (mib - expected).abs() <= 0.005,
        "{row}: expected {expected}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn flags_of_another_solver_are_said_to_be_ignored() {
    // QA of issue #16: `--epsilon` (hierarchical radiosity's) with the dense solver, and
    // `--adapt-rounds` (the dense solvers') with hierarchical radiosity, were dropped
    // without a word, where `--tolerance` with LU is warned about.
    let dir = scratch_dir("ignored-flags");
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "5000",
            "--epsilon",
            "0.01",
            "-o",
            "a.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("--epsilon ignored"), "{err}");
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "5000",
            "--solver",
            "hierarchical",
            "--adapt-rounds",
            "1",
            "-o",
            "b.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("--adapt-rounds ignored"), "{err}");
    assert!(!err.contains("--epsilon ignored"), "{err}");
}

/// A 1 m floor lit from 1 m above by a lamp of emission `e` (Er Eg Eb) facing down; the
/// floor reflects the bands differently (0.1, 0.5, 0.9), so each band's share absorbed
/// differs, and most of the light escapes past the floor's edges.
fn lamp_over_floor(e: [f64; 3]) -> String {
    format!(
        "MAX_PATCH_AREA 0.25\nINTEGRAL_STEPS 2\nSCENEBEGIN\n\
         PATCHBEGIN\n#Floor\nVERTICES 4\nEr 0\nEg 0\nEb 0\nRr 0.1\nRg 0.5\nRb 0.9\n\
         VERTEX0 1 0 0\nVERTEX1 0 0 0\nVERTEX2 0 0 1\nVERTEX3 1 0 1\nPATCHEND\n\
         PATCHBEGIN\n#Lamp\nVERTICES 4\nEr {}\nEg {}\nEb {}\nRr 0\nRg 0\nRb 0\n\
         VERTEX0 1 1 1\nVERTEX1 0 1 1\nVERTEX2 0 1 0\nVERTEX3 1 1 0\nPATCHEND\nSCENEEND\n",
        e[0], e[1], e[2]
    )
}

#[test]
fn flags_the_method_or_command_does_not_use_are_said_to_be_ignored() {
    // QA of issue #16: --samples with the area method, --snapshot-every without
    // --snapshots and --adaptive-contrast with --supersample 1 were dropped without a word.
    let dir = scratch_dir("ignored-method-flags");
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "20000",
            "--samples",
            "64",
            "-o",
            "a.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: --samples ignored: the form-factor method is area"),
        "{err}"
    );
    // The method that takes them: nothing said.
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "20000",
            "--method",
            "montecarlo",
            "--samples",
            "64",
            "-o",
            "b.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("ignored"), "{err}");
    let out = radiosity(
        &[
            "render",
            "--max-area",
            "20000",
            "--snapshot-every",
            "5",
            "--adaptive-contrast",
            "0.1",
            "--supersample",
            "1",
            "--width",
            "8",
            "--height",
            "8",
            "-o",
            "c.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("warning: --snapshot-every ignored"), "{err}");
    assert!(
        err.contains("warning: --adaptive-contrast ignored"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_scene_that_emits_nothing_is_said_to_render_black() {
    // QA of issue #16: it rendered black without a word.
    let dir = scratch_dir("no-emitter");
    std::fs::write(dir.join("dark.scene"), lamp_over_floor([0.0; 3])).unwrap();
    let out = radiosity(&["solve", "dark.scene", "-o", "dark.csv"], &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("dark.scene: warning: nothing in the scene emits light")
            && err.contains("Er, Eg or Eb above 0, LUMINANCE or FLUX, or a LIGHTBEGIN block"),
        "{err}"
    );
    // A point luminaire of no flux gives no light either (QA: FLUX 0 rendered black
    // without a word).
    let zero_light = lamp_over_floor([0.0; 3]).replace(
        "SCENEEND",
        "LIGHTBEGIN\n#Off\nPOSITION 0 1 0\nFLUX 0\nDISTRIBUTION ISOTROPIC\nLIGHTEND\nSCENEEND",
    );
    std::fs::write(dir.join("off.scene"), zero_light).unwrap();
    let out = radiosity(&["solve", "off.scene", "-o", "off.csv"], &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("off.scene: warning: nothing in the scene emits light"),
        "{err}"
    );
    // A lit scene: nothing said.
    std::fs::write(dir.join("lit.scene"), lamp_over_floor([1.0; 3])).unwrap();
    let out = radiosity(&["solve", "lit.scene", "-o", "lit.csv"], &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("emits light"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The number before `marker` in `text`, as the last whitespace-separated word ending
/// there (a "(" before it dropped).
fn number_before(text: &str, marker: &str) -> f64 {
    let at = text
        .find(marker)
        .unwrap_or_else(|| panic!("{marker:?} in {text}"));
    let word = text[..at].split_whitespace().last().unwrap();
    word.trim_start_matches('(').parse().unwrap()
}

#[test]
fn check_and_solve_give_the_energy_of_the_same_band() {
    // QA of issue #16: `solve` and `render` gave the energy account of the band emitting
    // most, `check` the red band's, so the same scene showed two different figures. The
    // lamp emits most in blue, and the floor reflects the bands differently, so the
    // blue and red shares absorbed differ.
    let dir = scratch_dir("energy-band");
    std::fs::write(dir.join("lamp.scene"), lamp_over_floor([1.0, 1.0, 3.0])).unwrap();
    let out = radiosity(&["solve", "lamp.scene", "-o", "lamp.csv"], &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let note = err
        .lines()
        .find(|l| l.starts_with("energy (B, the band emitting most)"))
        .unwrap_or_else(|| panic!("{err}"));
    let solve_absorbed = number_before(note, "% absorbed");
    let out = radiosity(&["check", "lamp.scene"], &dir);
    let text = crate::fixtures::stdout(&out);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = text
        .lines()
        .find(|l| l.starts_with("energy (B)"))
        .unwrap_or_else(|| panic!("{text}"));
    let after = &line[line.find("absorbed").unwrap()..];
    let check_absorbed = number_before(after, "%)");
    // Both print two decimals of the same number.
    assert_eq!(solve_absorbed, check_absorbed, "{note}\n{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hierarchical_energy_notes_do_not_promise_what_check_cannot_say() {
    // QA of issue #16: the energy note said "`check` says where" the light escapes, but
    // for hierarchical radiosity `check` lists no surfaces (it keeps no form-factor rows).
    let dir = scratch_dir("hierarchical-where");
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "20000",
            "--solver",
            "hierarchical",
            "-o",
            "h.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("energy (") && !err.contains("says where"),
        "{err}"
    );
    let out = radiosity(
        &["check", "--max-area", "20000", "--solver", "hierarchical"],
        &dir,
    );
    let text = crate::fixtures::stdout(&out);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        text.contains("escaped from      not traced to surfaces"),
        "{text}"
    );
    // The dense solve does say where, and check lists the surfaces.
    let out = radiosity(&["solve", "--max-area", "20000", "-o", "d.csv"], &dir);
    assert!(
        stderr(&out).contains("`check` says where"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_gives_the_reason_for_a_non_reciprocal_energy_account() {
    // QA of issue #16: Monte Carlo form factors' account was off by 3.5 % with no reason.
    // 64 rays per element leave the rows' estimates of a pair far apart from its two ends.
    let dir = scratch_dir("account-reason");
    let out = radiosity(
        &[
            "check",
            "--max-area",
            "20000",
            "--method",
            "montecarlo",
            "--samples",
            "64",
        ],
        &dir,
    );
    let text = crate::fixtures::stdout(&out);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        text.contains(
            "(relative error: montecarlo samples=64 seed=1's form factors are not reciprocal"
        ),
        "{text}"
    );
    // One wording for escaped light on the energy line and the list of surfaces.
    let escaped = text
        .lines()
        .filter(|l| {
            l.contains("out of the scene where it is open, into gaps and contacts or onto the backs of faces")
        })
        .count();
    assert_eq!(escaped, 2, "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_form_factor_file_for_another_mesh_says_both_meshes_settings() {
    // QA of issue #16: the refusal gave two fingerprints and no settings.
    let dir = scratch_dir("stale-settings");
    let out = radiosity(&["formfactors", "--max-area", "20000", "-o", "c.ff"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "10000",
            "--form-factors",
            "c.ff",
            "-o",
            "c.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("elements, made with method `area k=2`"),
        "{err}"
    );
    assert!(
        err.contains("this run's mesh has")
            && err.contains("(MAX_PATCH_AREA 10000, INTEGRAL_STEPS 2"),
        "{err}"
    );
    assert!(
        err.contains("recompute it with `radiosity formfactors`"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bench_says_what_its_other_column_holds() {
    // QA of issue #16: the "other" column was unexplained.
    let dir = scratch_dir("bench-other");
    let out = radiosity(
        &[
            "bench",
            "--max-area",
            "20000",
            "--repeat",
            "1",
            "--size",
            "8",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("other: end to end less the stages listed"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_names_the_point_luminaires_it_cannot_write() {
    // QA: an exported scene with LIGHTBEGIN blocks read back black, and nothing said so.
    let dir = scratch_dir("export-lights");
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/room_downlights.scene"
    );
    for out_name in ["dl.obj", "dl.glb"] {
        let out = radiosity(
            &["export", scene, "--max-area", "4", "-o", out_name, "-q"],
            &dir,
        );
        let err = stderr(&out);
        assert!(out.status.success(), "{err}");
        assert!(
            err.contains("warning: 2 point luminaires left out of")
                && err.contains("(Down1, Down2)"),
            "{out_name}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_lists_the_point_lights_and_warns_of_one_whose_light_is_lost() {
    // QA: a luminaire moved outside the room by a typo lost all its light, and `check`
    // said nothing (its energy account counts only what lands).
    let dir = scratch_dir("check-lights");
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/room_downlights.scene"
    ))
    .unwrap();
    assert!(text.contains("POSITION 1.5 2.6 1.5"));
    std::fs::write(
        dir.join("far.scene"),
        text.replace("POSITION 1.5 2.6 1.5", "POSITION 100 100 100")
            .replace(
                "POSITION 3.5 2.6 2.5",
                "POSITION 3.5 2.6 2.5\nCOLOUR 1 0.8 0.6",
            ),
    )
    .unwrap();
    let out = radiosity(&["check", "far.scene", "--max-area", "4"], &dir);
    let (text, err) = (crate::fixtures::stdout(&out), stderr(&out));
    assert!(out.status.success(), "{err}");
    assert!(
        text.contains("point lights      Down1 3000.0 lm at (100, 100, 100) m; 0.0 % lands"),
        "{text}"
    );
    assert!(
        err.contains("warning: point luminaire Down1 at (100, 100, 100): only 0.0 %"),
        "{err}"
    );
    // The other one, in the room, lands (almost) whole and is not warned about. Its
    // COLOUR scales its output in each band, so it emits FLUX times the colour's
    // luminance: 3000 x (0.2126 + 0.7152 x 0.8 + 0.0722 x 0.6) = 2484.24 lm (Rec. 709
    // weights; QA pass 13 of #16: COLOUR 2 2 2 emitted twice what this line said).
    assert!(!err.contains("luminaire Down2"), "{err}");
    assert!(
        text.contains("Down2 2484.2 lm (3000 lm times COLOUR 1 0.8 0.6, luminance 0.8281) at"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_negative_number_is_taken_as_the_flags_value() {
    // QA of issue #16: `--tolerance -1` was read as an unknown flag "-1", and clap's tip, to
    // write `-- -1`, made it a scene file name. Every flag that takes a value takes a
    // negative number; those that must be positive are then refused naming the flag (exit
    // 1, after parsing), the vectors take it as a coordinate.
    let dir = scratch_dir("negative");
    for (args, needle) in [
        (
            vec!["solve", "--tolerance", "-1", "-o", "x.csv"],
            "--tolerance -1: give where the solver stops, a number above 0",
        ),
        (
            vec!["render", "--gamma", "-2.2", "-o", "x.png"],
            "--gamma -2.2: give the gamma",
        ),
        (
            vec!["render", "--fov", "-45", "-o", "x.png"],
            "--fov -45: give the vertical field of view in degrees, above 0 and below 180",
        ),
        (
            vec!["render", "--solver", "hierarchical", "--epsilon", "-0.5"],
            "--epsilon -0.5: give hierarchical radiosity's refinement threshold, a number above 0",
        ),
    ] {
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
    }
    // A negative coordinate of the camera is a position like any other: the box's own eye
    // moved to -x renders (a tiny picture, one ray a pixel, on the coarse box).
    let out = radiosity(
        &[
            "render",
            "--max-area",
            "20000",
            "--eye",
            "-278,273,-800",
            "--look-at",
            "-100,273,280",
            "--width",
            "8",
            "--height",
            "8",
            "--supersample",
            "1",
            "-q",
            "-o",
            "neg.png",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join("neg.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_output_name_of_a_format_not_written_is_refused_before_any_work() {
    // QA of issue #16: `solve -o x.txt` wrote CSV into x.txt without a word (an
    // extensionless name too), `illuminance --png g.jpg` a PNG. Each output's name is now
    // checked first; the run stops with exit 1 and writes nothing.
    let dir = scratch_dir("out-ext");
    for (args, needle, file) in [
        (
            vec!["solve", "-o", "x.txt"],
            "-o x.txt: the element radiosities are written as CSV, or JSON for a .json name; \
             give it a .csv or .json name",
            "x.txt",
        ),
        (
            vec!["solve", "-o", "radiosities"],
            "give it a .csv or .json name",
            "radiosities",
        ),
        (
            vec!["solve", "-o", "ok.csv", "--report", "surfaces.json"],
            "--report surfaces.json: the per-surface report is a CSV table; give it a .csv name",
            "ok.csv",
        ),
        (
            vec!["formfactors", "-o", "matrix.csv"],
            "-o matrix.csv: the form factors are written in this program's binary matrix \
             format, read back by --form-factors (`solve` writes radiosities as CSV); give it \
             a .ff name",
            "matrix.csv",
        ),
        (
            vec!["render", "-o", "out.jpg"],
            "-o out.jpg: images are written as PNG (tone-mapped) or OpenEXR (linear radiance); give it a .png name, or .exr for linear radiance",
            "out.jpg",
        ),
        (
            vec![
                "illuminance",
                "--grid",
                "0,0,0:500,0,500:100",
                "--normal",
                "0,1,0",
                "-o",
                "lux.txt",
            ],
            "-o lux.txt: the illuminance is written as a CSV table; give it a .csv name",
            "lux.txt",
        ),
        (
            vec![
                "illuminance",
                "--grid",
                "0,0,0:500,0,500:100",
                "--normal",
                "0,1,0",
                "-o",
                "lux.csv",
                "--png",
                "lux.jpg",
            ],
            "--png lux.jpg: the grid's picture is a PNG; give it a .png name",
            "lux.csv",
        ),
        (
            vec!["generate", "building", "-o", "b.txt"],
            "-o b.txt: the building is written in the scene format (Appendix A), which the \
             other commands read by the extension .scene; give it a .scene name",
            "b.txt",
        ),
        (
            vec!["export", "-o", "scene.fbx"],
            "give the output one of these extensions",
            "scene.fbx",
        ),
    ] {
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        // Before any work: not even the scene was read (its note would come first).
        assert!(!err.contains("elements"), "{args:?}: {err}");
        assert!(!dir.join(file).exists(), "{args:?} wrote {file}");
    }
    // Any case of the right extension is taken.
    let out = radiosity(
        &["solve", "--max-area", "20000", "-q", "-o", "UP.CSV"],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::read_to_string(dir.join("UP.CSV"))
        .unwrap()
        .starts_with("surface,element,area,"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_command_that_prints_notes_takes_quiet() {
    // QA of issue #16: `generate`, `validate` and `view` had no -q.
    let dir = scratch_dir("quiet-all");
    let out = radiosity(
        &[
            "generate",
            "building",
            "-q",
            "-o",
            "b.scene",
            "--floors",
            "1",
            "--rooms-x",
            "1",
            "--rooms-z",
            "1",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join("b.scene").exists());
    assert_eq!(crate::fixtures::stdout(&out), "", "nothing but the file");
    assert_eq!(stderr(&out), "");
    // The same without -q says what it wrote: the quiet run above left something out.
    let out = radiosity(
        &[
            "generate",
            "building",
            "-o",
            "c.scene",
            "--floors",
            "1",
            "--rooms-x",
            "1",
            "--rooms-z",
            "1",
        ],
        &dir,
    );
    assert!(crate::fixtures::stdout(&out).contains("c.scene: 1 room, "));

    // validate -q: the verdict alone, on the fastest case (direct light only).
    let out = radiosity(&["validate", "cie171", "--case", "5.2", "-q"], &dir);
    let text = crate::fixtures::stdout(&out);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(
        text.starts_with("verdict: PASS, all ") && text.contains("values within their targets"),
        "{text}"
    );

    // view takes -q (clap's exit 2 would be an unknown flag): the flag check before any
    // window runs.
    let out = radiosity(&["view", "-q", "--steps", "0"], &dir);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("unexpected argument"), "{err}");
    assert!(
        err.contains("give the points along each axis of an element, a whole number of at least 1"),
        "{err}"
    );
    // A bad --epsilon is refused as `render` refuses it, whichever solver runs (QA pass 15:
    // without --solver hierarchical it was only warned about).
    for solver in ["auto", "hierarchical"] {
        let out = radiosity(&["view", "-q", "--solver", solver, "--epsilon", "0"], &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{solver}: {err}");
        assert!(
            err.contains("--epsilon 0: give hierarchical radiosity's refinement threshold"),
            "{solver}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn validate_ends_with_a_verdict() {
    // QA of issue #16: a passing run ended with the list of sources and nothing saying it
    // passed.
    let dir = scratch_dir("validate-verdict");
    let out = radiosity(&["validate", "cie171", "--case", "5.2"], &dir);
    let text = crate::fixtures::stdout(&out);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(text.contains("| 5.2 |"), "the table is there: {text}");
    let last = text.lines().last().unwrap_or("");
    assert!(last.starts_with("verdict: PASS, all "), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hierarchical_radiositys_final_gather_is_timed_as_its_own_stage() {
    // QA of issue #16: the final gather ran inside the solve stage, whose progress lines
    // went on counting refinement rounds through a minute of gathering.
    let dir = scratch_dir("gather-stage");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "solve",
            "--max-area",
            "20000",
            "--solver",
            "hierarchical",
            "-o",
            "h.csv",
        ];
        args.extend_from_slice(extra);
        let out = radiosity(&args, &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        stderr(&out)
    };
    let err = run(&[]);
    let timings = err.lines().find(|l| l.starts_with("timings: ")).unwrap();
    assert!(
        timings.contains(", solve ") && timings.contains(", final gather "),
        "{timings}"
    );
    let err = run(&["--no-final-gather"]);
    let timings = err.lines().find(|l| l.starts_with("timings: ")).unwrap();
    assert!(!timings.contains("final gather"), "{timings}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pathtrace_says_which_compare_flags_it_ignores_without_compare() {
    // QA of issue #16: `pathtrace --supersample 2 --shading flat` (the radiosity render's
    // flags) and `--epsilon` (its solve's) did nothing without --compare, without a word.
    let dir = scratch_dir("pathtrace-ignored");
    let out = radiosity(
        &[
            "pathtrace",
            "--supersample",
            "2",
            "--shading",
            "flat",
            "--epsilon",
            "0.1",
            "--seed",
            "3",
            "--adapt-contrast",
            "0.5",
            "--paths",
            "2",
            "--width",
            "8",
            "--height",
            "8",
            "-q",
            "-o",
            "p.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: --shading, --supersample ignored without --compare"),
        "{err}"
    );
    // QA pass 13: --seed (the form factors', not the path tracer's --path-seed) and the
    // adaptive subdivision's flags were ignored without a word.
    assert!(
        err.contains("warning: --epsilon, --adapt-contrast, --seed ignored without --compare")
            && err.contains("the path tracer's own seed is --path-seed"),
        "{err}"
    );
    // With --compare they are used: no such warning.
    let out = radiosity(
        &[
            "pathtrace",
            "--compare",
            "--max-area",
            "20000",
            "--supersample",
            "2",
            "--shading",
            "flat",
            "--paths",
            "2",
            "--width",
            "8",
            "--height",
            "8",
            "-q",
            "-o",
            "c.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("ignored"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn form_factors_flag_is_checked_before_the_scene_is_meshed() {
    // QA of issue #16: `--form-factors missing.ff`, or beside --solver progressive, was
    // refused only after the scene was read and meshed (its note printed first); `auto`
    // said nothing of the solver it took for the file.
    let dir = scratch_dir("ff-order");
    for (args, needle) in [
        (
            vec!["render", "--form-factors", "missing.ff", "-o", "x.png"],
            "cannot read form-factor file missing.ff",
        ),
        (
            vec![
                "solve",
                "--form-factors",
                "missing.ff",
                "--solver",
                "progressive",
            ],
            "--form-factors cannot be used with --solver progressive",
        ),
        (
            vec![
                "solve",
                "--form-factors",
                "missing.ff",
                "--solver",
                "hierarchical",
            ],
            "--form-factors cannot be used with --solver hierarchical",
        ),
        (
            vec![
                "solve",
                "--form-factors",
                "missing.ff",
                "--adapt-rounds",
                "2",
            ],
            "--adapt-rounds cannot be used with --form-factors",
        ),
    ] {
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(
            !err.contains("elements"),
            "before the scene's note: {args:?}: {err}"
        );
    }
    // A file that is there: auto says what it took.
    let out = radiosity(
        &["formfactors", "--max-area", "20000", "-q", "-o", "c.ff"],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = radiosity(
        &[
            "solve",
            "--max-area",
            "20000",
            "--form-factors",
            "c.ff",
            "-o",
            "c.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("solver auto: Gauss-Seidel on the dense matrix of the form factors in c.ff"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_obj_export_says_which_solve_and_camera_flags_it_ignores() {
    // QA of issue #16: `export -o x.obj --solver hierarchical --exposure 2 --eye 1,2,3`
    // wrote the unsolved surfaces without a word about the flags.
    let dir = scratch_dir("obj-ignored");
    let out = radiosity(
        &[
            "export",
            "-o",
            "x.obj",
            "--solver",
            "hierarchical",
            "--exposure",
            "2",
            "--eye",
            "-1,2,3",
            "-q",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(dir.join("x.obj").exists() && dir.join("x.mtl").exists());
    assert!(
        err.contains("warning: --solver, --exposure, --eye ignored: an .obj export writes"),
        "{err}"
    );
    // Plain, nothing is said.
    let out = radiosity(&["export", "-o", "y.obj", "-q"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stderr(&out), "");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn flag_numbers_are_refused_before_the_scene_is_read() {
    // QA of issue #16: `--max-area 0` was refused as "MAX_PATCH_AREA must be a positive
    // number" and `--scale 0` as "the scale", and `--epsilon -1` or `--max-shots 0` only
    // after the meshing and contact refinement. The scene named does not exist: a refusal
    // that names the flag, not the missing file, was made before the scene was read.
    let dir = scratch_dir("flag-numbers");
    for (args, needle) in [
        (
            vec!["check", "absent.scene", "--max-area", "0"],
            "--max-area 0: give the largest element area",
        ),
        (
            vec!["formfactors", "absent.scene", "--max-area", "-1"],
            "--max-area -1: give the largest element area",
        ),
        (
            vec!["check", "absent.scene", "--scale", "NaN"],
            "--scale NaN: give the factor",
        ),
        (
            vec!["solve", "absent.scene", "--epsilon", "-1"],
            "--epsilon -1: give hierarchical radiosity's refinement threshold",
        ),
        (
            vec!["solve", "absent.scene", "--max-shots", "0"],
            "--max-shots 0: give the most shots",
        ),
        (
            vec!["render", "absent.scene", "--gather-points", "0"],
            "--gather-points 0: give the most points",
        ),
        (
            vec!["render", "absent.scene", "--adapt-contrast", "0"],
            "--adapt-contrast 0: give the step that splits",
        ),
        (
            vec!["render", "absent.scene", "--adapt-contrast", "2"],
            "a number above 0 and below 1",
        ),
        (
            vec!["check", "absent.scene", "--min-area", "inf"],
            "--min-area inf: give the smallest element area",
        ),
        // QA pass 20: an infinite value was told to give "a number above 0".
        (
            vec!["check", "absent.scene", "--max-area", "inf"],
            "--max-area inf: give the largest element area (scene units squared), a finite \
             number above 0",
        ),
        (
            vec![
                "solve",
                "absent.scene",
                "--solver",
                "hierarchical",
                "--tolerance",
                "2",
            ],
            "--tolerance 2: give hierarchical radiosity's stopping change, a number above 0 and below 1",
        ),
    ] {
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(
            !err.contains("absent.scene"),
            "{args:?} read the scene first: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn outputs_that_cannot_be_written_are_refused_before_any_work() {
    // QA of issue #16: `solve -o nowhere/x.csv` solved the scene, then failed to write. The
    // scene named does not exist, so a refusal naming the output came before it was read.
    let dir = scratch_dir("output-dirs");
    std::fs::create_dir(dir.join("taken.csv")).unwrap();
    for (args, needle) in [
        (
            vec!["solve", "absent.scene", "-o", "nowhere/x.csv"],
            "-o nowhere/x.csv: the directory nowhere does not exist",
        ),
        (
            vec![
                "solve",
                "absent.scene",
                "-o",
                "x.csv",
                "--report",
                "no/r.csv",
            ],
            "--report no/r.csv: the directory no does not exist",
        ),
        (
            vec!["solve", "absent.scene", "-o", "taken.csv"],
            "-o taken.csv: is a folder",
        ),
        (
            vec!["render", "absent.scene", "-o", "nowhere/x.png"],
            "the directory nowhere does not exist",
        ),
        (
            vec!["formfactors", "absent.scene", "-o", "nowhere/x.ff"],
            "the directory nowhere does not exist",
        ),
        (
            vec!["export", "absent.scene", "-o", "nowhere/x.glb"],
            "the directory nowhere does not exist",
        ),
        (
            vec![
                "illuminance",
                "absent.scene",
                "--points",
                "p.csv",
                "-o",
                "nowhere/l.csv",
            ],
            "the directory nowhere does not exist",
        ),
        (
            vec!["generate", "building", "-o", "nowhere/b.scene"],
            "the directory nowhere does not exist",
        ),
        // A folder that exists but takes no new files (even for root: /proc), found before
        // the work, and named without the temporary file's name (QA of issue #16).
        (
            vec!["render", "absent.scene", "-o", "/proc/radiosity-test.png"],
            "-o /proc/radiosity-test.png: cannot write there: ",
        ),
    ] {
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(
            !err.contains("absent.scene"),
            "{args:?} read the scene first: {err}"
        );
        assert!(!err.contains(".tmp"), "{args:?}: {err}");
    }
    assert!(!dir.join("nowhere").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn generate_refusals_name_the_flag_at_fault() {
    // QA of issue #16: `--rooms-z 0` was "floors, rooms-x and rooms-z must be at least 1",
    // `--max-area 0` "MAX_PATCH_AREA must be a positive number".
    let dir = scratch_dir("generate-flags");
    // The counts are refused as every whole-number flag is (exit 1, "at least 1"; QA of
    // issue #16: `--floors -1` said "at least 0" and `--floors 0` then "at least 1").
    for flag in ["--floors", "--rooms-x", "--rooms-z"] {
        for value in ["0", "-1"] {
            let out = radiosity(
                &["generate", "building", "-o", "b.scene", flag, value],
                &dir,
            );
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(1), "{flag} {value}: {err}");
            assert!(err.contains("give a whole number of at least 1"), "{err}");
        }
    }
    for (flags, needle) in [
        (
            vec!["--room-size", "3"],
            "--room-size 3: give the inner side of a room in metres, 5.7 to 100",
        ),
        (
            vec!["--room-size", "2", "--no-furniture"],
            "--room-size 2: give the inner side of a room in metres, 2.5 to 100",
        ),
        (
            vec!["--height", "30"],
            "--height 30: give the floor-to-ceiling height",
        ),
        (
            vec!["--max-area", "0"],
            "--max-area 0: give the largest element area",
        ),
        (
            vec!["--steps", "0"],
            "--steps 0: give the points along each axis",
        ),
        (
            vec!["--light", "-1"],
            "--light -1: give the ceiling panels' exitance",
        ),
        // QA pass 16 of #16: written, then refused by every other command as above the
        // largest emission the readers take (1e30).
        (
            vec!["--light", "1e31"],
            "--light 1e31: give the ceiling panels' exitance in lm/m^2, at most 1e30",
        ),
        (
            vec!["--light", "1e300"],
            "--light 1e300: give the ceiling panels' exitance in lm/m^2, at most 1e30",
        ),
        (
            vec!["--rooms-x", "1000", "--rooms-z", "1000"],
            "make 2000000 rooms, more than the limit of 100000",
        ),
        // QA pass 14: refused from one storey at once (minutes and gigabytes before), and
        // with no "raise MAX_PATCH_AREA" to a smaller area where none fits.
        (
            vec!["--floors", "1000"],
            "each at least one element at any --max-area, past the limit of 8000000 elements",
        ),
        (
            vec!["--floors", "600"],
            "600 floors), past the limit of 8000000 that the other commands mesh; give at most",
        ),
    ] {
        let mut args = vec!["generate", "building", "-o", "b.scene"];
        args.extend(&flags);
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{flags:?}: {err}");
        assert!(err.contains(needle), "{flags:?}: {err}");
        assert!(!dir.join("b.scene").exists(), "{flags:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The number after `key` on the first line of `text` that has it.
fn number_after(text: &str, key: &str) -> f64 {
    let line = text
        .lines()
        .find(|l| l.contains(key))
        .unwrap_or_else(|| panic!("no {key:?} in {text}"));
    let rest = &line[line.find(key).unwrap() + key.len()..];
    rest.split_whitespace()
        .next()
        .and_then(|w| w.trim_end_matches([',', ';', ')']).parse().ok())
        .unwrap_or_else(|| panic!("no number after {key:?} in {line:?}"))
}

#[test]
fn check_gives_plain_numbers_with_units_and_lists_that_add_up() {
    // QA of issue #16: `check` printed "buried and left out: 7.2977e0 area" and
    // "emitted 2.000000e1"; its five "escaped from" shares did not make the escaped share,
    // with no word that the list was the largest five.
    let dir = scratch_dir("check-numbers");
    let out = radiosity(&["check", &crate::fixtures::example("room.scene")], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = crate::fixtures::stdout(&out);
    for key in ["total area", "contacts", "lying on", "energy (R)"] {
        let line = text.lines().find(|l| l.starts_with(key)).unwrap();
        let figures = line.split("relative error").next().unwrap();
        assert!(!figures.contains("e0") && !figures.contains("e1"), "{line}");
    }
    assert!(text.contains(" m^2 (of the grid's elements)"), "{text}");
    assert!(text.contains(": gap 0.005 m, covering 3.08 m^2"), "{text}");
    // The lists: the largest five of how many, all of them together, and that total less
    // the part counted twice is the energy line's escaped share (to the 0.01 % printed).
    let escaped_line = text.lines().find(|l| l.starts_with("energy (R)")).unwrap();
    assert_eq!(number_after(escaped_line, "emitted "), 20.0, "{text}");
    let escaped = number_after(escaped_line, "escaped ");
    let escaped_percent: f64 = escaped_line
        .split("escaped ")
        .nth(1)
        .and_then(|r| r.split('(').nth(1))
        .and_then(|p| p.split_whitespace().next())
        .and_then(|p| p.parse().ok())
        .unwrap();
    assert!(escaped > 0.0);
    let from = text
        .lines()
        .find(|l| l.starts_with("escaped from"))
        .unwrap();
    // Five of more, or all of them where fewer reach 0.01 % (the room since the pieces
    // along its furniture's feet are cut along them: "the 4 of 26 surfaces with 0.01 % or
    // more, 0.35 % in all").
    let out_all = if from.contains("the 5 largest of") {
        number_after(from, "surfaces, ")
    } else {
        assert!(from.contains(" surfaces with 0.01 % or more, "), "{from}");
        number_after(from, "or more, ")
    };
    let twice = number_after(from, "less ");
    let net = number_after(from, "counted twice below: ");
    assert!(
        ((out_all - twice) - net).abs() <= 0.011,
        "{out_all} - {twice} != {net}"
    );
    assert!(
        (net - escaped_percent).abs() <= 0.011,
        "{net} % != {escaped_percent} %"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_exposure_scale_is_printed_to_four_figures() {
    // QA of issue #16: "exposure scale 0.5080691785954333".
    let dir = scratch_dir("exposure-digits");
    let out = radiosity(
        &[
            "render",
            "--max-area",
            "20000",
            "--width",
            "8",
            "--height",
            "8",
            "--supersample",
            "1",
            "-o",
            "e.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let scale = err
        .split("exposure scale ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .unwrap_or_else(|| panic!("no scale in {err}"));
    let digits = scale.chars().filter(char::is_ascii_digit).count();
    let leading = scale.trim_start_matches(['0', '.']).len();
    assert!(leading <= 4 && digits <= 6, "{scale}");
    assert!(scale.parse::<f64>().unwrap() > 0.0, "{scale}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn illuminance_says_when_its_figures_are_lux() {
    // QA of issue #16: the note said lux needed scene lengths in metres, and the built-in
    // box, in millimetres, printed lux: the surfaces' light reaches a point through form
    // factors, which have no unit; only point luminaires and FLUX depend on lengths.
    let dir = scratch_dir("lux-note");
    let out = radiosity(
        &[
            "illuminance",
            "--max-area",
            "20000",
            "--grid",
            "200,1,200:300,1,300:100",
            "--normal",
            "0,1,0",
            "-o",
            "lux.csv",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("lux where Er Eg Eb are in lm/m^2, whatever the length unit")
            && err.contains("point luminaires and FLUX need lengths in metres"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn help_texts_give_the_ranges_and_units_the_commands_hold_to() {
    let dir = scratch_dir("help-ranges");
    let out = radiosity(&["generate", "building", "--help"], &dir);
    let help = crate::fixtures::stdout(&out);
    assert!(help.contains("2.4 to 20"), "{help}");
    assert!(
        help.contains("5.7 to 100 with furniture, from 2.5 without"),
        "{help}"
    );
    assert!(help.contains("(lm/m^2"), "{help}");
    assert!(!help.contains("W/m^2"), "{help}");
    // --gather-points: the times measured, not "about a minute of CPU" (the building's
    // gather took about 110 s of CPU).
    let out = radiosity(&["render", "--help"], &dir);
    let help = crate::fixtures::stdout(&out);
    assert!(!help.contains("about a minute of CPU"), "{help}");
    assert!(
        help.contains("236,916 points in about 110 s of CPU"),
        "{help}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bench_takes_width_and_height_as_render_does_and_keeps_size() {
    // QA of issue #16: bench had only --size, and its zero check was worded unlike the
    // other commands' --width.
    let dir = scratch_dir("bench-size");
    let base = ["bench", "--max-area", "20000", "--repeat", "1"];
    let run = |extra: &[&str]| {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        radiosity(&args, &dir)
    };
    let out = run(&["--size", "8", "--width", "12"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("render 12x8, "), "{}", stderr(&out));
    let out = run(&["--size", "8"]);
    assert!(stderr(&out).contains("render 8x8, "), "{}", stderr(&out));
    for flag in ["--size", "--width", "--height"] {
        let out = run(&[flag, "0"]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.contains(&format!(
                "error: {flag} 0: give a whole number of at least 1"
            )),
            "{err}"
        );
    }
    // The same size limit as render's (QA of issue #16: bench capped each side at 10,000,
    // render did not): a 20,000 x 1 strip is fine, 10,001 x 10,000 is over 100 megapixels.
    let out = run(&["--width", "10001", "--height", "10000"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out)
            .contains("an image of 10001 x 10000 pixels is too large (at most 100 megapixels)"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn one_image_side_given_sets_both() {
    // QA of issue #16: `render --width 64` gave a 64 x 512 picture, the box a sliver in the
    // middle of a black strip; the side given now sets both, as the default is square.
    let dir = scratch_dir("one-side");
    for (flag, other) in [("--width", "--height"), ("--height", "--width")] {
        let png = dir.join(format!("{}.png", &flag[2..]));
        let out = radiosity(
            &[
                "render",
                "--max-area",
                "20000",
                flag,
                "24",
                "-o",
                png.to_str().unwrap(),
            ],
            &dir,
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let image = image::open(&png).unwrap();
        assert_eq!(
            (image.width(), image.height()),
            (24, 24),
            "{flag} alone, no {other}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_help_wireframe_exposure_and_fov_say_what_is_true() {
    // QA of issue #16: export's --width/--height said "Image width"; a wireframe render
    // printed an exposure line though its lines are white whatever the exposure; the
    // --fov message said "between 0 and 180" with both ends excluded.
    let dir = scratch_dir("export-help-wireframe");
    let help = crate::fixtures::stdout(&radiosity(&["export", "--help"], &dir));
    assert!(
        help.contains("aspect ratio is WIDTH / HEIGHT") && !help.contains("Image width"),
        "{help}"
    );
    let out = radiosity(
        &[
            "render",
            "--max-area",
            "20000",
            "--shading",
            "wireframe",
            "--width",
            "8",
            "--height",
            "8",
            "--exposure",
            "2",
            "--gamma",
            "1.8",
            "-o",
            "w.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("exposure scale"), "{err}");
    assert!(
        err.contains("warning: --exposure ignored with --shading wireframe"),
        "{err}"
    );
    assert!(
        err.contains("warning: --gamma ignored with --shading wireframe"),
        "{err}"
    );
    let out = radiosity(&["render", "--fov", "180", "-o", "f.png"], &dir);
    assert!(
        stderr(&out).contains(
            "--fov 180: give the vertical field of view in degrees, above 0 and below 180"
        ),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn errors_say_error_once_and_name_a_folder_as_a_folder() {
    // QA of issue #16: "error: P.csv:1: error: expected the header ...", an IES file's
    // "error:" inside the scene's, `extension ""` for a folder given as the scene, and
    // `render -o DIR` answered with the list of image formats.
    let dir = scratch_dir("error-once");
    std::fs::write(dir.join("p.csv"), "x,y,z\n1,2,3\n").unwrap();
    std::fs::create_dir(dir.join("folder")).unwrap();
    std::fs::write(
        dir.join("lamp.scene"),
        lamp_over_floor([0.0, 0.0, 0.0]).replace(
            "SCENEEND",
            "LIGHTBEGIN\n#Spot\nPOSITION 0.5 0.5 0.5\nDISTRIBUTION IES bad.ies\nLIGHTEND\nSCENEEND",
        ),
    )
    .unwrap();
    std::fs::write(dir.join("bad.ies"), "IESNA:LM-63-2002\nno tilt line\n").unwrap();
    for (args, needle) in [
        (
            vec!["illuminance", "--points", "p.csv", "-o", "l.csv"],
            "p.csv:1: error: expected the header",
        ),
        (
            vec!["check", "folder"],
            "folder: error: this is a folder, not a scene file",
        ),
        (
            vec!["render", "-o", "folder"],
            "-o folder: is a folder; give the image a file name in it",
        ),
        (vec!["check", "lamp.scene"], "IES file \"bad.ies\""),
    ] {
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        let first = err.lines().find(|l| l.contains("error")).unwrap();
        assert_eq!(first.matches("error:").count(), 1, "{args:?}: {first}");
        assert!(!err.contains("extension \"\""), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn timings_name_the_files_read_and_written() {
    // QA of issue #16: "write #1 ..., write #2 ..., write #3" did not say which file.
    let dir = scratch_dir("timing-names");
    let out = radiosity(
        &[
            "pathtrace",
            "--width",
            "8",
            "--height",
            "8",
            "--paths",
            "2",
            "--compare",
            "--max-area",
            "20000",
            "-o",
            "v.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let timings = err.lines().find(|l| l.starts_with("timings:")).unwrap();
    for name in ["write v.png", "write v-radiosity.png", "write v-error.png"] {
        assert!(timings.contains(name), "{name}: {timings}");
    }
    assert!(!timings.contains('#'), "{timings}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_building_without_light_is_said_to_render_black() {
    let dir = scratch_dir("dark-building");
    let args = [
        "generate",
        "building",
        "-o",
        "b.scene",
        "--light",
        "0",
        "--floors",
        "1",
        "--rooms-x",
        "1",
        "--rooms-z",
        "1",
    ];
    let out = radiosity(&args, &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("warning: --light 0"), "{err}");
    assert!(err.contains("renders black"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hierarchical_leaves_are_explained_beside_the_element_count() {
    // QA of issue #16: `render` said 2484 elements, then 5694 leaves, and `check` 5694
    // elements, with no word why the count changed.
    let dir = scratch_dir("leaves");
    let out = radiosity(
        &["check", "--solver", "hierarchical", "--max-area", "20000"],
        &dir,
    );
    let (err, text) = (stderr(&out), crate::fixtures::stdout(&out));
    assert!(out.status.success(), "{err}");
    let line = text.lines().find(|l| l.starts_with("elements")).unwrap();
    assert!(
        line.contains("hierarchical radiosity's leaves")
            && line.contains("the uniform mesh at MAX_PATCH_AREA has"),
        "{line}"
    );
    let args = [
        "render",
        "--solver",
        "hierarchical",
        "--max-area",
        "20000",
        "--width",
        "8",
        "--height",
        "8",
        "-o",
        "h.png",
    ];
    let err = stderr(&radiosity(&args, &dir));
    assert!(
        err.contains("leaves (the elements of its solution"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn second_pass_findings_are_said() {
    // QA of issue #16, second pass: a scene in millimetres read as metres, an .exr with
    // --exposure and --gamma, compare's two solves, and bench's rays/s with no
    // form-factor stage.
    let dir = scratch_dir("second-pass");
    // In check's report, under the unit line (its reporter prints no notes).
    let err = crate::fixtures::stdout(&radiosity(
        &[
            "check",
            &crate::fixtures::example("cornell_box.scene"),
            "--max-area",
            "20000",
        ],
        &dir,
    ));
    assert!(
        err.contains("(note: the largest surface is ")
            && err.contains("m^2 read as metres")
            && err.contains("--scale 0.001")
            // Its light is given as exitances: the note says the unit changes none of it
            // (fifth pass: the note read as an alarm on the shipped example).
            && err.contains("the light does not depend on it"),
        "{err}"
    );
    let args = [
        "render",
        "--max-area",
        "20000",
        "--width",
        "8",
        "--height",
        "8",
        "--exposure",
        "2",
        "--gamma",
        "1.8",
        "-o",
        "e.exr",
    ];
    let out = radiosity(&args, &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: --exposure ignored: an .exr"),
        "{err}"
    );
    assert!(err.contains("warning: --gamma ignored: an .exr"), "{err}");
    let args = ["compare", "--max-area", "20000", "--solver", "progressive"];
    let err = stderr(&radiosity(&args, &dir));
    let timings = err.lines().find(|l| l.starts_with("timings:")).unwrap();
    assert!(
        timings.contains("solve (progressive, tested)")
            && timings.contains("solve (dense reference)")
            && !timings.contains('#'),
        "{timings}"
    );
    let args = [
        "bench",
        "--max-area",
        "20000",
        "--solver",
        "hierarchical",
        "--repeat",
        "1",
        "--width",
        "8",
        "--height",
        "8",
    ];
    let out = radiosity(&args, &dir);
    let row = crate::fixtures::stdout(&out);
    let row = row.lines().last().unwrap();
    let rate: f64 = row
        .trim_end_matches(" M |")
        .rsplit("| ")
        .next()
        .unwrap()
        .parse()
        .unwrap_or_else(|e| panic!("{e}: {row}"));
    // Hierarchical radiosity casts its rays in the solve stage: tens of M rays/s on this
    // machine, not the billions a 0 ms form-factor stage gave.
    assert!(rate > 0.01 && rate < 1000.0, "{row}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn camera_flags_are_refused_before_the_scene_is_read() {
    // QA of issue #16: --fov 180 and --up 0,0,0 came after the scene was read and meshed.
    let dir = scratch_dir("camera-early");
    for (args, needle) in [
        (
            vec!["render", "absent.scene", "--fov", "180"],
            "--fov 180: give the vertical field of view",
        ),
        (
            vec!["pathtrace", "absent.scene", "--up", "0,0,0"],
            "--up 0,0,0: give a direction of finite, non-zero length",
        ),
        (
            vec!["export", "absent.scene", "-o", "a.glb", "--fov", "0"],
            "--fov 0: give",
        ),
    ] {
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(
            !err.contains("absent.scene"),
            "{args:?} read the scene first: {err}"
        );
    }
    // A lone surface's zero rows get their own reason, not the furniture's.
    std::fs::write(
        dir.join("tri.scene"),
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#T\nVERTICES 3\nEr 1\n\
         Eg 1\nEb 1\nRr 0.5\nRg 0.5\nRb 0.5\nVERTEX0 0 0 0\nVERTEX1 1 0 0\nVERTEX2 0 1 0\n\
         PATCHEND\nSCENEEND\n",
    )
    .unwrap();
    let text = crate::fixtures::stdout(&radiosity(&["check", "tri.scene"], &dir));
    assert!(text.contains("the scene is one flat surface"), "{text}");
    assert!(!text.contains("furniture"), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn points_that_get_no_light_are_warned_of() {
    // QA of issue #16: points under the floor or outside the room gave 0 lx without a word.
    let dir = scratch_dir("dark-points");
    std::fs::write(
        dir.join("p.csv"),
        "name,x,y,z,nx,ny,nz\nlit,2.5,1,2,0,1,0\nbelow,2.5,-1,2,0,1,0\nout,20,1,2,0,1,0\n\
         cupboard,0.3,0.6,0.6,0,1,0\n",
    )
    .unwrap();
    // "cupboard" is inside the closed cupboard: it got 1.3e-6 lx (QA pass 20 of #16: up to
    // 0.009 lx in room_downlights) from wall elements whose 3 x 3 shadow-ray points all
    // lay below its plane, which counted them seen without a ray.
    let room = crate::fixtures::example("room.scene");
    let args = [
        "illuminance",
        &room,
        "--points",
        "p.csv",
        "-o",
        "l.csv",
        "-q",
        "--max-area",
        "1",
    ];
    let out = radiosity(&args, &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains(
            "warning: 3 points of 4 get no light at all (0 lx): 3 (the first: \"below\" at \
             2.5,-1,2) see only the backs of faces, or nothing"
        ),
        "{err}"
    );
    // QA of issue #16: a point in the open, in a black room whose lamp lights only the
    // black ceiling, was asked whether it was inside furniture.
    std::fs::write(
        dir.join("black.scene"),
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 2\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
         Er 0\nEg 0\nEb 0\nRr 0\nRg 0\nRb 0\nORIGIN 0 0 0\nSIZE 4 3 4\nBOXEND\n\
         PATCHBEGIN\n#Up light\nVERTICES 4\nEr 15\nEg 15\nEb 15\nRr 0\nRg 0\nRb 0\n\
         VERTEX0 2.5 2.9 1.5\nVERTEX1 1.5 2.9 1.5\nVERTEX2 1.5 2.9 2.5\nVERTEX3 2.5 2.9 2.5\n\
         PATCHEND\nSCENEEND\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("q.csv"),
        "name,x,y,z,nx,ny,nz\nfloor,2,0.8,2,0,1,0\n",
    )
    .unwrap();
    let args = [
        "illuminance",
        "black.scene",
        "--points",
        "q.csv",
        "-o",
        "m.csv",
    ];
    let err = stderr(&radiosity(&args, &dir));
    assert!(
        err.contains(
            "1 (the first: \"floor\" at 2,0.8,2) sees surfaces but no light: in full \
                      shadow"
        ),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn third_pass_findings_are_said() {
    // QA of issue #16, third pass: a capped progressive solve's energy account balances
    // with its unshot power; `check`'s stage table keeps a space after a file's name;
    // repeated stages of one purpose are numbered; bench names the method; a lone
    // emitting surface's exposure is said to be the fallback.
    let dir = scratch_dir("third-pass");
    let paper = crate::fixtures::example("paper196.scene");
    let out = radiosity(
        &[
            "check",
            &paper,
            "--solver",
            "progressive",
            "--max-shots",
            "40",
        ],
        &dir,
    );
    let text = crate::fixtures::stdout(&out);
    let energy = text.lines().find(|l| l.starts_with("energy (R)")).unwrap();
    let emitted = number_after(energy, "emitted ");
    let parts = number_after(energy, "absorbed ")
        + number_after(energy, "escaped ")
        + number_after(energy, "not yet shot ");
    // The three terms are printed to seven significant digits.
    assert!((parts - emitted).abs() < 1e-5 * emitted, "{energy}");
    assert!(text.contains("  parse paper196.scene "), "{text}");
    let err = stderr(&radiosity(
        &["compare", "--max-area", "20000", "--adapt-rounds", "1"],
        &dir,
    ));
    let timings = err.lines().find(|l| l.starts_with("timings:")).unwrap();
    assert!(
        timings.contains("solve (gauss-seidel, tested) #1")
            && timings.contains("solve (gauss-seidel, tested) #2"),
        "{timings}"
    );
    let args = [
        "bench",
        "--max-area",
        "20000",
        "--method",
        "hemicube",
        "--repeat",
        "1",
        "--width",
        "8",
        "--height",
        "8",
        "-q",
    ];
    let table = crate::fixtures::stdout(&radiosity(&args, &dir));
    assert!(table.contains("| method |"), "{table}");
    assert!(table.contains("| hemicube resolution=128 |"), "{table}");
    std::fs::write(
        dir.join("tri.scene"),
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#T\nVERTICES 3\nEr 1\n\
         Eg 1\nEb 1\nRr 0.5\nRg 0.5\nRb 0.5\nVERTEX0 0 0 0\nVERTEX1 1 0 0\nVERTEX2 0 1 0\n\
         PATCHEND\nSCENEEND\n",
    )
    .unwrap();
    let args = [
        "render",
        "tri.scene",
        "--width",
        "8",
        "--height",
        "8",
        "-o",
        "t.png",
    ];
    let err = stderr(&radiosity(&args, &dir));
    assert!(err.contains("auto: every surface emits"), "{err}");
    assert!(!err.contains("non-emitting element"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn refusals_give_the_flag_to_type() {
    // QA of issue #16: the work limit named the scene keyword (INTEGRAL_STEPS 13), clap
    // said "0 is not in 1..=4294967295".
    let dir = scratch_dir("flag-to-type");
    let err = stderr(&radiosity(&["check", "--steps", "100"], &dir));
    assert!(
        err.contains(": --steps 12 (or pass --no-work-limit"),
        "{err}"
    );
    let err = stderr(&radiosity(&["render", "--width", "0"], &dir));
    assert!(err.contains("give a whole number of at least 1"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn number_flags_are_refused_in_one_wording() {
    // QA of issue #16 (fourth pass): the standard library's parse errors came through
    // clap as "-1 is not in 0..=4294967295", "invalid digit found in string" and "invalid
    // float literal", beside the project's "give a whole number of at least 1".
    let dir = scratch_dir("number-words");
    for (args, needle) in [
        (
            vec!["render", "--steps", "-1"],
            "error: --steps -1: give the points along each axis of an element, a whole number of at least 1",
        ),
        (
            vec!["check", "--steps", "0"],
            "error: --steps 0: give the points along each axis of an element, a whole number of at least 1",
        ),
        (vec!["render", "--seed", "x"], "error: --seed x: give a whole number"),
        (vec!["render", "--max-area", "abc"], "error: --max-area abc: give a number"),
        (
            vec!["render", "--adapt-rounds", "-3"],
            "error: --adapt-rounds -3: give a whole number of at least 0",
        ),
        (
            vec!["render", "--supersample", "17"],
            "error: --supersample 17: give a whole number from 1 to 16",
        ),
        // Past a u32's top, "at least 0" was true of the value given (QA pass 15).
        (
            vec!["render", "--adapt-rounds", "5000000000"],
            "error: --adapt-rounds 5000000000: give a whole number from 0 to 4294967295",
        ),
        (
            vec!["render", "--solver", "hierarchica"],
            "error: --solver hierarchica: give one of auto, lu, gauss-seidel, progressive, \
             hierarchical (did you mean hierarchical?)",
        ),
    ] {
        // Exit 1 and the frame of the checks made after parsing ("--max-area 0: give ..."),
        // not clap's "invalid value '0' for '--steps <K>'" with exit 2 (QA of issue #16,
        // fifth pass).
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        for clap_words in ["is not in", "invalid digit", "float literal", "invalid value"] {
            assert!(!err.contains(clap_words), "{args:?}: {err}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Fourth QA pass of issue #16: work no command could do is refused before anything is
/// written or timed, in the flag's words.
#[test]
fn impossible_work_is_refused_before_anything_is_written_or_timed() {
    let dir = scratch_dir("refused-first");
    // A building that would mesh past MAX_ELEMENTS: no file, and the area that fits.
    let out = radiosity(
        &[
            "generate",
            "building",
            "-o",
            "big.scene",
            "--max-area",
            "0.0001",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--max-area 0.0001") && stderr(&out).contains("no file written"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("big.scene").exists());
    // bench: a bad number or work past the limit before the table's header.
    for args in [
        vec!["bench", "--tolerance", "-1"],
        vec!["bench", "--size", "10000", "--supersample", "16"],
    ] {
        let out = radiosity(&args, &dir);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        assert!(out.stdout.is_empty(), "{args:?} printed its header");
    }
    // pathtrace: a missing reference named with its flag, before the scene is traced.
    let out = radiosity(&["pathtrace", "--reference", "nope.exr", "--compare"], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).starts_with("error: --reference nope.exr: no such file"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_light_that_reaches_no_surface_is_warned_of() {
    // QA of issue #16 (sixth pass): a ceiling light facing up (its corners clockwise seen
    // from the room) or lying 5 cm above the ceiling rendered black with only notes.
    let dir = scratch_dir("light-lost");
    let scene = |corners: &str| {
        format!(
            "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 2\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
             Er 0\nEg 0\nEb 0\nRr 0.7\nRg 0.7\nRb 0.7\nORIGIN 0 0 0\nSIZE 4 3 4\nBOXEND\n\
             PATCHBEGIN\n#Light\nVERTICES 4\nEr 15\nEg 15\nEb 15\nRr 0.7\nRg 0.7\nRb 0.7\n\
             {corners}PATCHEND\nSCENEEND\n"
        )
    };
    let cases = [
        (
            "up.scene",
            "VERTEX0 2.5 3 1.5\nVERTEX1 1.5 3 1.5\nVERTEX2 1.5 3 2.5\nVERTEX3 2.5 3 2.5\n",
            "100.00 % of the emitted light reaches no surface (so nothing is lit: pictures \
             show at most the emitters themselves): surface 6 \"Light\" faces out of the scene, with no surface in front of it",
        ),
        (
            "above.scene",
            "VERTEX0 2.5 3.05 1.5\nVERTEX1 2.5 3.05 2.5\nVERTEX2 1.5 3.05 2.5\nVERTEX3 1.5 3.05 1.5\n",
            "nothing emits: the emitter surface 6 \"Light\" was dropped whole",
        ),
        (
            "down.scene",
            "VERTEX0 2.5 2.95 1.5\nVERTEX1 2.5 2.95 2.5\nVERTEX2 1.5 2.95 2.5\nVERTEX3 1.5 2.95 1.5\n",
            "",
        ),
    ];
    for (name, corners, needle) in cases {
        std::fs::write(dir.join(name), scene(corners)).unwrap();
        let out = radiosity(&["solve", name, "-o", "b.csv", "-q"], &dir);
        let err = stderr(&out);
        assert!(out.status.success(), "{name}: {err}");
        if needle.is_empty() {
            // The light facing down into the room: no warning.
            assert!(!err.contains("warning"), "{name}: {err}");
        } else {
            assert!(err.contains(&format!("warning: {needle}")), "{name}: {err}");
        }
    }
    // QA of issue #16 (ninth pass): a lamp facing a ground 20 m below it lights the ground
    // (a picture of it is not black) and is not turned the wrong way; the scene is open.
    std::fs::write(
        dir.join("far.scene"),
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 2\nSCENEBEGIN\n\
         PATCHBEGIN\n#Ground\nVERTICES 4\nEr 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\n\
         VERTEX0 0 0 0\nVERTEX1 0 0 2\nVERTEX2 2 0 2\nVERTEX3 2 0 0\nPATCHEND\n\
         PATCHBEGIN\n#Lamp\nVERTICES 4\nEr 100\nEg 100\nEb 100\nRr 0\nRg 0\nRb 0\n\
         VERTEX0 0.9 20 0.9\nVERTEX1 1.1 20 0.9\nVERTEX2 1.1 20 1.1\nVERTEX3 0.9 20 1.1\n\
         PATCHEND\nSCENEEND\n",
    )
    .unwrap();
    let out = radiosity(&["solve", "far.scene", "-o", "b.csv", "-q"], &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("% of the emitted light reaches no surface (pictures show only the 0.")
            && err.contains("it leaves an open scene, or lands on the backs of faces")
            && !err.contains("reverse"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn light_lost_over_many_reflections_is_not_said_to_reach_no_surface() {
    // QA pass 15 of issue #16: a closed box of reflectance 0.9999 with a panel 10 cm under
    // its ceiling absorbs 0.51 % of the emitted light and loses the rest on the panel's black
    // back after hundreds of bounces; it was warned of as light that "reaches no surface",
    // the pictures showing "only the 0.51 % that lands".
    let dir = scratch_dir("light-lost-bright");
    std::fs::write(
        dir.join("hi.scene"),
        "MAX_PATCH_AREA 0.5\nINTEGRAL_STEPS 2\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
         Er 0\nEg 0\nEb 0\nRr 0.9999\nRg 0.9999\nRb 0.9999\nORIGIN 0 0 0\nSIZE 2 2 2\n\
         BOXEND\nPATCHBEGIN\n#Light\nVERTICES 4\nEr 1\nEg 1\nEb 1\nRr 0.9999\nRg 0.9999\n\
         Rb 0.9999\nVERTEX0 0.5 1.9 0.5\nVERTEX1 1.5 1.9 0.5\nVERTEX2 1.5 1.9 1.5\n\
         VERTEX3 0.5 1.9 1.5\nPATCHEND\nSCENEEND\n",
    )
    .unwrap();
    let out = radiosity(&["solve", "hi.scene", "-o", "b.csv", "-q"], &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("% of the emitted light is lost over many reflections (its surfaces absorb only 0.")
            && err.contains("with reflectance up to 0.9999 the light lands ")
            && err.contains("times its emitted power, bouncing until it leaves the scene or meets the back of a face"),
        "{err}"
    );
    assert!(
        !err.contains("reaches no surface") && !err.contains("pictures show only"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn generate_keeps_an_existing_scene_file_unless_forced() {
    // QA of issue #16 (sixth pass): `generate building -o examples/room.scene` replaced the
    // shipped example without a word.
    let dir = scratch_dir("generate-force");
    let before = "// a scene someone wrote\n";
    std::fs::write(dir.join("room.scene"), before).unwrap();
    let args = [
        "generate",
        "building",
        "--floors",
        "1",
        "--rooms-x",
        "1",
        "--rooms-z",
        "1",
    ];
    let mut kept = args.to_vec();
    kept.extend(["-o", "room.scene"]);
    let out = radiosity(&kept, &dir);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("-o room.scene: the file exists; give another name, or --force"),
        "{}",
        stderr(&out)
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("room.scene")).unwrap(),
        before
    );
    let mut forced = kept.clone();
    forced.push("--force");
    let out = radiosity(&forced, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::read_to_string(dir.join("room.scene"))
        .unwrap()
        .contains("SCENEBEGIN"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_grid_short_of_its_corner_is_warned_of_and_its_coordinates_are_clean() {
    // QA of issue #16 (sixth pass): a spacing of 1.5 over 4 m stopped 1 m short without a
    // word, and 0.7 + 0.1 was written 0.7999999999999999.
    let dir = scratch_dir("grid-short");
    let scene = crate::fixtures::example("room.scene");
    let out = radiosity(
        &[
            "illuminance",
            &scene,
            "--grid",
            "0.5,0.8,0.5:4.5,0.8,3.5:1.5",
            "--normal",
            "0,1,0",
            "-o",
            "a.csv",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains(
            "warning: --grid spacing 1.5: the grid does not reach its second corner: along x \
             it stops at x = 3.5, 1 short of 4.5"
        ) && !stderr(&out).contains("along z"),
        "{}",
        stderr(&out)
    );
    let out = radiosity(
        &[
            "illuminance",
            &scene,
            "--grid",
            "0.7,0.8,0.1:1.5,0.8,0.5:0.1",
            "--normal",
            "0,1,0",
            "-o",
            "b.csv",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("second corner"), "{}", stderr(&out));
    let csv = std::fs::read_to_string(dir.join("b.csv")).unwrap();
    // Every coordinate is the decimal it stands for: 0.7 + i 0.1, at most one decimal.
    for line in csv.lines().skip(1) {
        for field in line.split(',').skip(1).take(3) {
            assert!(field.len() <= 3, "{line}");
        }
    }
    assert_eq!(csv.lines().count(), 1 + 9 * 5, "{csv}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn snapshots_that_would_be_none_or_nested_are_refused_and_old_ones_named() {
    // QA of issue #16 (sixth pass): --max-shots 3 with a picture every 10 made nested
    // folders for no picture; an earlier run's pictures stayed among the new without a word.
    let dir = scratch_dir("snapshot-checks");
    let base = [
        "render",
        "--max-area",
        "20000",
        "--solver",
        "progressive",
        "--width",
        "8",
        "--supersample",
        "1",
        "-o",
        "p.png",
    ];
    let run = |extra: &[&str]| {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        radiosity(&args, &dir)
    };
    let out = run(&[
        "--snapshots",
        "s",
        "--snapshot-every",
        "10",
        "--max-shots",
        "3",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains(
            "--snapshot-every 10: no snapshot would be taken within --max-shots 3; give \
             --snapshot-every at most 3"
        ),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("s").exists());
    let out = run(&[
        "--snapshots",
        "no/s",
        "--max-shots",
        "3",
        "--snapshot-every",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--snapshots no/s: the directory no does not exist"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("no").exists());
    std::fs::create_dir(dir.join("s")).unwrap();
    std::fs::write(dir.join("s/shot-00099.png"), b"old").unwrap();
    let out = run(&[
        "--snapshots",
        "s",
        "--max-shots",
        "2",
        "--snapshot-every",
        "1",
        "-q",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("warning: --snapshots s already holds 1 picture (shot-NNNNN.png)"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_camera_outside_a_closed_room_is_warned_of() {
    // QA of issue #16 (sixth pass): an eye outside examples/occluder.scene's closed room
    // wrote a black picture without a word; from the automatic camera, no warning.
    let dir = scratch_dir("camera-outside");
    let scene = crate::fixtures::example("occluder.scene");
    let base = [
        "render",
        &scene,
        "--width",
        "16",
        "--supersample",
        "1",
        "-q",
    ];
    let mut outside = base.to_vec();
    outside.extend(["--eye", "2,1.5,10", "--look-at", "2,1.5,2", "-o", "out.png"]);
    let out = radiosity(&outside, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains(
            "warning: 100.0 % of the picture shows nothing lit: the camera sees the backs"
        ),
        "{}",
        stderr(&out)
    );
    let mut inside = base.to_vec();
    inside.extend(["-o", "in.png"]);
    let out = radiosity(&inside, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_downlight_left_at_the_default_aim_in_a_y_up_room_is_warned_of() {
    // QA of issue #16 (sixth pass): the default AIM 0 0 -1 lit a wall of a y-up room and
    // `check` said only that all its lumens landed.
    let dir = scratch_dir("sideways-light");
    let scene = |aim: &str| {
        format!(
            "MAX_PATCH_AREA 4\nINTEGRAL_STEPS 2\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
             Er 0\nEg 0\nEb 0\nRr 0.5\nRg 0.5\nRb 0.5\nORIGIN 0 0 0\nSIZE 4 3 4\nBOXEND\n\
             LIGHTBEGIN\n#Down\nPOSITION 2 2.9 2\n{aim}INTENSITY 100\nDISTRIBUTION COSINE\n\
             LIGHTEND\nSCENEEND\n"
        )
    };
    for (name, aim, warned) in [
        ("default.scene", "", true),
        ("down.scene", "AIM 0 -1 0\n", false),
    ] {
        std::fs::write(dir.join(name), scene(aim)).unwrap();
        let out = radiosity(&["solve", name, "-o", "b.csv", "-q"], &dir);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).contains(
                "warning: light \"Down\" is aimed along AIM 0 0 -1 (the default: straight down \
                 in a z-up scene), which is horizontal here"
            ),
            warned,
            "{name}: {}",
            stderr(&out)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn seventh_pass_findings_are_said() {
    // QA of issue #16, seventh pass.
    let dir = scratch_dir("seventh-pass");
    let occluder = crate::fixtures::example("occluder.scene");
    let expect = |args: &[&str], code: i32, needle: &str| {
        let out = radiosity(args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        err
    };
    // An empty file name: "give one of " and nothing after it.
    expect(
        &["render", "-o", ""],
        1,
        "error: --output \"\": empty; give a FILE name",
    );
    expect(
        &["check", ""],
        1,
        "error: SCENE \"\": empty; give a SCENE name",
    );
    // A name that is only an extension.
    expect(
        &["render", "-o", ".png"],
        1,
        "-o .png: the name is only an extension",
    );
    // --adapt-max-elements below the first mesh.
    expect(
        &[
            "solve",
            &occluder,
            "-o",
            "x.csv",
            "--adapt-rounds",
            "1",
            "--adapt-max-elements",
            "10",
        ],
        1,
        "--adapt-max-elements 10: the first mesh already has 2068 elements",
    );
    // A file where a folder is asked for.
    std::fs::write(dir.join("f"), "x").unwrap();
    expect(
        &["validate", "cie171", "--write", "f"],
        1,
        "--write f: is a file",
    );
    // compare's default solver on a small scene is the reference's own.
    expect(
        &["compare", "--max-area", "20000", "-q"],
        0,
        "warning: auto chose Gauss-Seidel on the dense matrix, the reference's own solver",
    );
    // bench --width alone sets both sides, as render's does.
    let err = expect(
        &[
            "bench",
            "--max-area",
            "20000",
            "--repeat",
            "1",
            "--width",
            "12",
        ],
        0,
        "",
    );
    assert!(err.contains("render 12x12, "), "{err}");
    // The analytic method's account, visibly not adding up, has its reason.
    let out = radiosity(
        &["check", "--max-area", "20000", "--method", "analytic"],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        crate::fixtures::stdout(&out)
            .contains("relative error: analytic k=2's form factors are not reciprocal"),
        "{}",
        crate::fixtures::stdout(&out)
    );
    // The picture pathtrace --compare writes beside -o is named as such.
    std::fs::write(dir.join("foo-radiosity.exr"), "x").unwrap();
    expect(
        &[
            "pathtrace",
            "--max-area",
            "20000",
            "--width",
            "8",
            "--reference",
            "foo-radiosity.exr",
            "--compare",
            "-o",
            "foo.exr",
        ],
        1,
        "-o foo.exr (the picture written beside it, foo-radiosity.exr): this is the reference",
    );
    // A scene with no light is said so once, not blamed on the camera.
    let dark = std::fs::read_to_string(&occluder)
        .unwrap()
        .replace("Er 15", "Er 0")
        .replace("Eg 15", "Eg 0")
        .replace("Eb 15", "Eb 0");
    std::fs::write(dir.join("dark.scene"), dark).unwrap();
    let err = expect(
        &[
            "render",
            "dark.scene",
            "--width",
            "8",
            "--supersample",
            "1",
            "-o",
            "d.png",
            "-q",
        ],
        0,
        "nothing in the scene emits light",
    );
    assert!(!err.contains("shows nothing lit"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn eighth_pass_findings_are_said() {
    // QA of issue #16, eighth pass.
    let dir = scratch_dir("eighth-pass");
    let run = |args: &[&str]| {
        let out = radiosity(args, &dir);
        (out.status.code(), stderr(&out))
    };
    // A progressive tolerance of 1 or more would stop before any shot.
    let (code, err) = run(&[
        "solve",
        "--solver",
        "progressive",
        "--tolerance",
        "2",
        "-o",
        "t.csv",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--tolerance 2: give the unshot share"),
        "{err}"
    );
    // pathtrace's fallback exposure is said to be one.
    let (code, err) = run(&[
        "pathtrace",
        "--max-bounces",
        "0",
        "--paths",
        "2",
        "--width",
        "8",
        "-o",
        "p.png",
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("auto: nothing is lit"), "{err}");
    // A .glb that is not binary glTF.
    std::fs::write(dir.join("r.glb"), "{\"asset\": {\"version\": \"2.0\"}}").unwrap();
    let (code, err) = run(&["check", "r.glb"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("r.glb: error: not a binary glTF file"),
        "{err}"
    );
    // A flag given no value at all keeps clap's usage message (exit 2); an empty value is
    // named as empty (exit 1).
    let (code, err) = run(&["render", "-o"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("a value is required for '--output <FILE>'"),
        "{err}"
    );
    // A grid crossing zero writes 0 there, not a rounding leftover (-0.3 + 3 x 0.1).
    let (code, err) = run(&[
        "illuminance",
        &crate::fixtures::example("room.scene"),
        "--grid",
        "-0.3,0.8,0.5:0.3,0.8,0.5:0.1",
        "--normal",
        "0,1,0",
        "-o",
        "z.csv",
        "-q",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let csv = std::fs::read_to_string(dir.join("z.csv")).unwrap();
    assert!(csv.contains("g3_0,0,0.8,0.5,"), "{csv}");
    // The camera note says which parts were given.
    let (_, err) = run(&[
        "render",
        "--max-area",
        "20000",
        "--width",
        "8",
        "--fov",
        "50",
        "-o",
        "c.png",
    ]);
    assert!(
        err.contains("--fov 50 (the camera flags given, the rest the scene's own;"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_usage_line_after_an_error_is_the_commands_own() {
    // QA of issue #16: clap's usage line listed the flags typed as if they were required
    // ("Usage: radiosity generate building --output <FILE.scene> --rooms-z <N>").
    let dir = scratch_dir("usage-line");
    let out = radiosity(&["generate", "building", "--rooms", "2"], &dir);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("a similar argument exists: '--rooms-z'"),
        "{err}"
    );
    let usage: Vec<&str> = err.lines().filter(|l| l.starts_with("Usage: ")).collect();
    assert_eq!(
        usage,
        ["Usage: radiosity generate building [OPTIONS] --output <FILE.scene>"],
        "{err}"
    );
    let out = radiosity(&["illuminance", "--grid", "0,0,0:1,1,0:0.5"], &dir);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("Usage: radiosity illuminance [OPTIONS] --output <OUT.csv> [SCENE]\n"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn ninth_pass_findings_are_said() {
    let dir = scratch_dir("ninth-pass");
    // Two outputs of one run naming the same file: refused before the trace.
    let out = radiosity(
        &[
            "pathtrace",
            "--width",
            "8",
            "--paths",
            "2",
            "--save-reference",
            "r.exr",
            "-o",
            "r.exr",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains(
            "error: --save-reference r.exr is -o r.exr too: one output would overwrite the other"
        ),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("r.exr").exists());
    // A camera inside a closed room facing a wall of reflectance 0, the light behind it:
    // the picture is black, and the camera is not blamed.
    std::fs::write(
        dir.join("black.scene"),
        "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 2\nSCENEBEGIN\nBOXBEGIN\n#Room\nFACING IN\n\
         Er 0\nEg 0\nEb 0\nRr 0\nRg 0\nRb 0\nORIGIN 0 0 0\nSIZE 4 3 4\nBOXEND\n\
         PATCHBEGIN\n#Light\nVERTICES 4\nEr 15\nEg 15\nEb 15\nRr 0.7\nRg 0.7\nRb 0.7\n\
         VERTEX0 2.5 2.95 1.5\nVERTEX1 2.5 2.95 2.5\nVERTEX2 1.5 2.95 2.5\nVERTEX3 1.5 2.95 1.5\n\
         PATCHEND\nSCENEEND\n",
    )
    .unwrap();
    let out = radiosity(
        &[
            "render",
            "black.scene",
            "--eye",
            "2,1.5,1",
            "--look-at",
            "2,1.5,4",
            "--width",
            "16",
            "-o",
            "b.png",
            "-q",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains(
            "the surfaces in view face the camera, but no light reaches them or they reflect none"
        ),
        "{err}"
    );
    assert!(!err.contains("move --eye"), "{err}");
    // A wireframe of the dense mesh draws its lines without form factors or a solve.
    let out = radiosity(
        &[
            "render",
            "--shading",
            "wireframe",
            "--width",
            "16",
            "-o",
            "w.png",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("wireframe of the mesh: no form factors or solve"),
        "{err}"
    );
    let timings = err
        .lines()
        .find(|l| l.starts_with("timings:"))
        .unwrap_or("");
    assert!(
        timings.contains("render")
            && !timings.contains("form factors")
            && !timings.contains("solve"),
        "{err}"
    );
    // --false-colour through the 5 cm gap above a luminaire housing: the ceiling there
    // (dropped as buried) is dark, not the white of the background.
    let scene = crate::fixtures::example("room_downlights.scene");
    let out = radiosity(
        &[
            "render",
            &scene,
            "--eye",
            "2.6,2.45,1.5",
            "--look-at",
            "1.8,2.68,1.5",
            "--fov",
            "30",
            "--width",
            "48",
            "--false-colour",
            "-o",
            "fc.png",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.join("fc.png")).unwrap().to_rgb8();
    // Whitish: every channel above 200 (no colour of the scale is; the background mixed
    // with blue at the strip's edges is).
    let whitish = (0..48)
        .flat_map(|x| (0..48).map(move |y| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c > 200))
        .count();
    assert_eq!(whitish, 0, "background in the view of a closed room");
    // Row sums of 0 where nothing lies in front (two squares facing away from each other)
    // are not blamed on furniture (QA of issue #16, tenth pass).
    std::fs::write(
        dir.join("apart.scene"),
        "MAX_PATCH_AREA 0.25\nINTEGRAL_STEPS 2\nSCENEBEGIN\n\
         PATCHBEGIN\n#Down\nVERTICES 4\nEr 1\nEg 1\nEb 1\nRr 0.5\nRg 0.5\nRb 0.5\n\
         VERTEX0 0 0 0\nVERTEX1 1 0 0\nVERTEX2 1 0 1\nVERTEX3 0 0 1\nPATCHEND\n\
         PATCHBEGIN\n#Up\nVERTICES 4\nEr 1\nEg 1\nEb 1\nRr 0.5\nRg 0.5\nRb 0.5\n\
         VERTEX0 0 1 0\nVERTEX1 0 1 1\nVERTEX2 1 1 1\nVERTEX3 1 1 0\nPATCHEND\nSCENEEND\n",
    )
    .unwrap();
    let out = radiosity(&["check", "apart.scene"], &dir);
    let text = crate::fixtures::stdout(&out);
    assert!(
        text.contains("no surface lies in front of the first, so what they send leaves the scene"),
        "{text}"
    );
    // A number past the largest a flag takes is told its range, not "at least 1".
    let out = radiosity(&["render", "--width", "4294967297"], &dir);
    assert!(
        stderr(&out).contains("--width 4294967297: give a whole number from 1 to 4294967295"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn twelfth_pass_findings_are_said() {
    // QA pass 12 of issue #16: a progressive wireframe wrote identical snapshots after the
    // whole solve; --false-colour ignored --direct-light without a word; `check` named a
    // method that hierarchical radiosity had just said it ignores.
    let dir = scratch_dir("twelfth-pass");
    let args = [
        "render",
        "--max-area",
        "5000",
        "--solver",
        "progressive",
        "--snapshots",
        "sn",
        "--shading",
        "wireframe",
        "-o",
        "w.png",
    ];
    let out = radiosity(&args, &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("drop --snapshots"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("sn").exists());
    let args = [
        "render",
        "--max-area",
        "5000",
        "--false-colour",
        "--direct-light",
        "mesh",
        "--width",
        "16",
        "-q",
        "-o",
        "f.png",
    ];
    let out = radiosity(&args, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("warning: --direct-light ignored with --false-colour"),
        "{}",
        stderr(&out)
    );
    // QA pass 12: the default given explicitly, where flat shading ignores it, was silent;
    // left out, no warning.
    for (given, warned) in [(&["--direct-light", "gather"][..], true), (&[][..], false)] {
        let mut args = vec![
            "render",
            "--max-area",
            "5000",
            "--shading",
            "flat",
            "--width",
            "16",
            "-q",
            "-o",
            "flat.png",
        ];
        args.extend_from_slice(given);
        let out = radiosity(&args, &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        assert_eq!(
            stderr(&out).contains("warning: --direct-light ignored: it chooses smooth shading's"),
            warned,
            "{given:?}: {}",
            stderr(&out)
        );
    }
    let args = [
        "check",
        "--max-area",
        "5000",
        "--solver",
        "hierarchical",
        "--method",
        "hemicube",
    ];
    let out = radiosity(&args, &dir);
    let text = crate::fixtures::stdout(&out);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        text.contains("method            hierarchical radiosity's own"),
        "{text}"
    );
    assert!(!text.contains("hemicube"), "{text}");
    // compare without a reference, and bench (once, and its table), say so too.
    let ignored = "warning: --method contour ignored: hierarchical radiosity";
    let args = [
        "compare",
        "--solver",
        "hierarchical",
        "--method",
        "contour",
        "--no-reference",
        "--max-area",
        "5000",
    ];
    let out = radiosity(&args, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains(ignored), "{}", stderr(&out));
    let args = [
        "bench",
        "--solver",
        "hierarchical",
        "--method",
        "contour",
        "--max-area",
        "5000",
        "--width",
        "16",
        "--height",
        "16",
        "--supersample",
        "1",
    ];
    let out = radiosity(&args, &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stderr(&out).matches(ignored).count(), 1, "{}", stderr(&out));
    let text = crate::fixtures::stdout(&out);
    assert!(text.contains("| links' own |"), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bench_refuses_its_counts_and_areas_as_every_flag_does() {
    // QA pass 14 of #16: `--repeat 0` said "at least 1" and `--repeat -1` "at least 0";
    // `--max-area ,,` showed the float parser's "cannot parse float from empty string".
    let dir = scratch_dir("bench-flags");
    for (flags, needle) in [
        (
            ["--repeat", "0"],
            "--repeat 0: give a whole number of at least 1",
        ),
        (
            ["--repeat", "-1"],
            "--repeat -1: give a whole number of at least 1",
        ),
        (
            ["--max-area", ",,"],
            "--max-area \"\": give a number above 0",
        ),
        (["--max-area", "1,0"], "--max-area 0: give a number above 0"),
    ] {
        let mut args = vec!["bench"];
        args.extend(flags);
        let out = radiosity(&args, &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{flags:?}: {err}");
        assert!(err.contains(needle), "{flags:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
