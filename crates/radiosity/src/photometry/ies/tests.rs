//! The IES reader against files written from closed forms (`tests/data/ies/generate.py`):
//! their table flux against their stated lumens, symmetric files against the full table,
//! and every refusal at its line.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use super::*;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ies")
        .join(name)
}

fn read(name: &str) -> IesPhotometry {
    IesPhotometry::read(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Values are printed to 6 decimals in the files: relative agreement to this much is all a
/// table of such numbers holds.
const PRINTED: f64 = 1e-8;

/// Relative error bound of the flux of I0 cos(theta) interpolated linearly in steps of
/// `h_deg`: the chord of cos lies within h^2/8 I0 of it, so the flux within
/// 2 pi (h^2/8) I0 of pi I0, h^2/4 relative.
fn cosine_chord_bound(h_deg: f64) -> f64 {
    h_deg.to_radians().powi(2) / 4.0
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn isotropic_table_gives_four_pi_i_lumens_with_the_multiplier_applied() {
    let ies = read("isotropic_lm63_2002.ies");
    assert_eq!(ies.version(), IesVersion::Lm63_2002);
    // 50 cd in the file times the multiplier 2.
    assert_eq!(ies.candela(0.3, 1.0), 100.0);
    assert_eq!(ies.candela(PI, 4.0), 100.0);
    let exact = 4.0 * PI * 100.0;
    assert!(
        relative(ies.table_lumens(), exact) < 1e-12,
        "{}",
        ies.table_lumens()
    );
    let stated = ies.stated_lumens().expect("the file states 1256.637061 lm");
    assert!(
        relative(ies.table_lumens(), stated) < PRINTED,
        "{} vs {stated}",
        ies.table_lumens()
    );
    assert_eq!(
        ies.keywords()[1],
        ("MANUFAC".to_string(), "radiosity project".to_string())
    );
}

#[test]
fn cosine_table_gives_pi_i0_lumens_and_nothing_above_the_horizon() {
    let ies = read("cosine_lm63_1995.ies");
    assert_eq!(ies.version(), IesVersion::Lm63_1995);
    let stated = ies.stated_lumens().unwrap();
    let bound = cosine_chord_bound(1.0) + PRINTED;
    let flux = ies.table_lumens();
    assert!(
        relative(flux, PI * 1000.0) < bound,
        "{flux} against pi 1000, bound {bound}"
    );
    assert!(
        relative(flux, stated) < bound,
        "{flux} against stated {stated}"
    );
    // On a knot the value is the file's; between knots the chord, within h^2/8 I0 of cos.
    assert!((ies.candela(0.0, 0.0) - 1000.0).abs() < 1e-9);
    let theta = 37.5_f64.to_radians();
    let chord = 0.5 * 1000.0 * (37f64.to_radians().cos() + 38f64.to_radians().cos());
    assert!((ies.candela(theta, 2.0) - chord).abs() < 1e-3);
    assert_eq!(ies.candela(91f64.to_radians(), 0.0), 0.0);
    assert_eq!(ies.candela(f64::NAN, 0.0), 0.0);
}

/// Directions spread over the sphere (a golden-angle spiral) for comparing distributions.
fn directions() -> impl Iterator<Item = (f64, f64)> {
    (0..500).map(|i| {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / 500.0;
        (z.acos(), i as f64 * 2.399_963_229_728_653)
    })
}

fn assert_same_distribution(a: &IesPhotometry, b: &IesPhotometry) {
    for (theta, phi) in
        directions().chain([(0.2, 0.0), (0.2, PI / 2.0), (0.2, PI), (0.2, -PI / 2.0)])
    {
        let (ia, ib) = (a.candela(theta, phi), b.candela(theta, phi));
        // The same printed values, interpolated between the same knots: equal to rounding.
        assert!(
            (ia - ib).abs() <= 1e-9 * ia.abs().max(1.0),
            "{} and {} differ at theta {theta}, phi {phi}: {ia} against {ib}",
            a.path().display(),
            b.path().display()
        );
    }
    assert!(relative(a.table_lumens(), b.table_lumens()) < 1e-12);
}

#[test]
fn quadrant_half_and_open_tables_equal_the_full_table() {
    let full = read("quadrant_full_lm63_2019.ies");
    assert_eq!(full.version(), IesVersion::Lm63_2019);
    for name in [
        "quadrant_half_lm63_2019.ies",
        "quadrant_quarter_lm63_2019.ies",
        "quadrant_open_lm63_2019.ies",
    ] {
        assert_same_distribution(&read(name), &full);
    }
    // 1000 cos(theta) (1 + 0.5 cos 2 phi): 1500 cd at nadir towards phi = 0, 500 at 90.
    assert!((full.candela(0.0, 0.0) - 1500.0).abs() < 1e-9);
    assert!((full.candela(1e-9, PI / 2.0) - 500.0).abs() < 1e-3);
    // The 2019 file generation type (1.00001) is not a multiplier.
    let bound = cosine_chord_bound(5.0) + PRINTED;
    let flux = full.table_lumens();
    assert!(
        relative(flux, full.stated_lumens().unwrap()) < bound,
        "{flux}"
    );
}

#[test]
fn bilateral_tables_equal_the_full_table() {
    assert_same_distribution(
        &read("bilateral0_half_lm63_2002.ies"),
        &read("bilateral0_full_lm63_2002.ies"),
    );
    let half90 = read("bilateral90_half_lm63_2002.ies");
    assert_same_distribution(&half90, &read("bilateral90_full_lm63_2002.ies"));
    // 1000 cos(theta) (1 + 0.3 sin phi): 1300 cd near nadir towards 90, 700 towards 270.
    assert!((half90.candela(1e-9, PI / 2.0) - 1300.0).abs() < 1e-3);
    assert!((half90.candela(1e-9, -PI / 2.0) - 700.0).abs() < 1e-3);
    for name in [
        "bilateral0_half_lm63_2002.ies",
        "bilateral90_half_lm63_2002.ies",
    ] {
        let ies = read(name);
        let bound = cosine_chord_bound(5.0) + PRINTED;
        assert!(relative(ies.table_lumens(), PI * 1000.0) < bound, "{name}");
    }
}

#[test]
fn tilt_include_is_read_and_ballast_factors_apply() {
    let ies = read("tilt_include_iesna91.ies");
    assert_eq!(ies.version(), IesVersion::Lm63_1991);
    let tilt = ies.tilt().expect("TILT=INCLUDE");
    assert_eq!(tilt.geometry, 1);
    assert_eq!(tilt.angles_deg, vec![0.0, 45.0, 90.0]);
    assert_eq!(tilt.factors, vec![1.0, 0.9, 0.8]);
    assert!((ies.tilt_factor(22.5f64.to_radians()) - 0.95).abs() < 1e-12);
    assert_eq!(ies.tilt_factor(2.0), 0.8);
    // Two lamps of 1000 lm, 2000 / 2 pi cd over the lower hemisphere (ballast factor 0.5
    // and ballast-lamp factor 2, both applied: net 1).
    assert_eq!(ies.stated_lumens(), Some(2000.0));
    assert!(
        relative(ies.table_lumens(), 2000.0) < PRINTED,
        "{}",
        ies.table_lumens()
    );
}

#[test]
fn lm63_1986_absolute_photometry_in_feet() {
    let ies = read("absolute_lm63_1986.ies");
    assert_eq!(ies.version(), IesVersion::Lm63_1986);
    assert_eq!(ies.labels().len(), 2);
    assert_eq!(ies.stated_lumens(), None);
    assert!(relative(ies.table_lumens(), 4.0 * PI * 10.0) < 1e-12);
    let [w, l, h] = ies.dimensions_m();
    assert!((w - 0.3048).abs() < 1e-12 && (l - 0.6096).abs() < 1e-12 && (h - 0.1524).abs() < 1e-12);
}

#[test]
fn latin1_text_is_read() {
    let mut bytes = b"IESNA:LM-63-2002\n[LUMINAIRE] 90\xb0 spot\nTILT=NONE\n".to_vec();
    bytes.extend_from_slice(b"1 100 1 2 1 1 2 0 0 0\n1 1 5\n0 90\n0\n10 10\n");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.ies");
    std::fs::write(&path, bytes).unwrap();
    let ies = IesPhotometry::read(&path).unwrap();
    assert_eq!(ies.keywords()[0].1, "90\u{b0} spot");
}

const HEAD: &str = "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n";

/// Parses `text` and returns the line and problem it is refused with.
fn refused(text: &str) -> (usize, IesProblem) {
    match IesPhotometry::parse(text, Path::new("bad.ies")) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(error) => {
            let message = error.to_string();
            assert!(message.starts_with("bad.ies:"), "{message}");
            let (line, problem) = error.problem().expect("an invalid file, not an I/O error");
            (line, problem.clone())
        }
    }
}

#[test]
fn bad_files_are_refused_at_their_line() {
    let good_tail = "1 100 1 2 1 1 2 0 0 0\n1 1 5\n0 90\n0\n10 10\n";
    assert!(IesPhotometry::parse(&format!("{HEAD}{good_tail}"), Path::new("good.ies")).is_ok());

    assert_eq!(refused("").1, IesProblem::Empty);
    assert_eq!(
        refused("IESNA:LM-63-2002\n[TEST] x\n1 2 3\n"),
        (3, IesProblem::NoTilt)
    );
    assert_eq!(
        refused("IESNA:LM-63-1995\nTILT=lamp.tlt\n1 100 1 2 1 1 2 0 0 0\n"),
        (2, IesProblem::TiltFile("lamp.tlt".to_string()))
    );
    let (line, problem) = refused(&format!("{HEAD}1 abc 1 2 1 1 2 0 0 0\n"));
    assert_eq!(line, 4);
    assert!(matches!(problem, IesProblem::NotANumber { ref found, .. } if found == "abc"));
    assert!(matches!(
        refused(&format!("{HEAD}1 nan 1 2 1 1 2 0 0 0\n")).1,
        IesProblem::NotANumber { .. }
    ));
    // Ends early: at the last line, naming what was expected.
    let (line, problem) = refused(&format!(
        "{HEAD}1 100 1 2 1 1 2 0 0 0\n1 1 5\n0 90\n0\n10\n"
    ));
    assert_eq!(line, 8);
    assert!(
        matches!(problem, IesProblem::UnexpectedEnd { ref expected } if expected.contains("vertical angle 90"))
    );
    // Lamps, lumens, multiplier, counts, type, units.
    for (tail, what) in [
        ("0 100 1 2 1 1 2 0 0 0", "number of lamps"),
        ("1.5 100 1 2 1 1 2 0 0 0", "number of lamps"),
        ("1 0 1 2 1 1 2 0 0 0", "lumens per lamp"),
        ("1 -2 1 2 1 1 2 0 0 0", "lumens per lamp"),
        ("1 100 0 2 1 1 2 0 0 0", "candela multiplier"),
        ("1 100 1 1 1 1 2 0 0 0", "vertical angles"),
        ("1 100 1 2 0 1 2 0 0 0", "horizontal angles"),
        ("1 100 1 2 1 4 2 0 0 0", "photometric type"),
        ("1 100 1 2 1 1 3 0 0 0", "units type"),
    ] {
        let (line, problem) = refused(&format!("{HEAD}{tail}\n1 1 5\n0 90\n0\n10 10\n"));
        assert_eq!(line, 4, "{tail}");
        assert!(
            matches!(&problem, IesProblem::OutOfRange { what: w, .. } if w.contains(what)),
            "{tail}: {problem}"
        );
    }
    assert_eq!(
        refused(&format!(
            "{HEAD}1 100 1 2 1 2 2 0 0 0\n1 1 5\n0 90\n0\n10 10\n"
        )),
        (4, IesProblem::UnsupportedType(2))
    );
    assert!(refused(&format!("{HEAD}1 100 1 2 1 3 2 0 0 0\n"))
        .1
        .to_string()
        .contains("type A"));
    // Ballast factor.
    let (line, problem) = refused(&format!(
        "{HEAD}1 100 1 2 1 1 2 0 0 0\n0 1 5\n0 90\n0\n10 10\n"
    ));
    assert_eq!(line, 5);
    assert!(problem.to_string().contains("ballast factor"));
    // Angles: out of range, not increasing, and a horizontal run of no symmetry.
    let (line, problem) = refused(&format!(
        "{HEAD}1 100 1 2 1 1 2 0 0 0\n1 1 5\n0 190\n0\n10 10\n"
    ));
    assert_eq!(line, 6);
    assert!(
        problem.to_string().contains("vertical angle 2"),
        "{problem}"
    );
    assert_eq!(
        refused(&format!(
            "{HEAD}1 100 1 2 1 1 2 0 0 0\n1 1 5\n90\n90\n0\n10 10\n"
        )),
        (
            7,
            IesProblem::NotIncreasing {
                what: "vertical",
                index: 2,
                previous: 90.0,
                value: 90.0
            }
        )
    );
    assert_eq!(
        refused(&format!(
            "{HEAD}1 100 1 2 2 1 2 0 0 0\n1 1 5\n0 90\n0 45\n10 10 10 10\n"
        )),
        (
            7,
            IesProblem::HorizontalRange {
                first: 0.0,
                last: 45.0
            }
        )
    );
    assert_eq!(
        refused(&format!(
            "{HEAD}1 100 1 2 2 1 2 0 0 0\n1 1 5\n0 90\n10 360\n10 10 10 10\n"
        ))
        .1,
        IesProblem::HorizontalRange {
            first: 10.0,
            last: 360.0
        }
    );
    // Intensities past MAX_CANDELA once multiplied, and factors whose product overflows.
    let (line, problem) = refused(&format!(
        "{HEAD}1 100 1e10 2 1 1 2 0 0 0\n1 1 5\n0 90\n0\n10 1000\n"
    ));
    assert_eq!(line, 8);
    assert!(problem.to_string().contains("at most 1e12 cd"), "{problem}");
    let (line, problem) = refused(&format!(
        "{HEAD}1 100 1e300 2 1 1 2 0 0 0\n1e300 1 5\n0 90\n0\n0 10\n"
    ));
    assert_eq!(line, 5);
    assert!(
        problem
            .to_string()
            .contains("multiplier times the ballast factors"),
        "{problem}"
    );
    // Negative candela, trailing numbers.
    let (line, problem) = refused(&format!(
        "{HEAD}1 100 1 2 1 1 2 0 0 0\n1 1 5\n0 90\n0\n10\n-1\n"
    ));
    assert_eq!(line, 9);
    assert!(problem
        .to_string()
        .contains("intensities must be 0 or more"));
    assert_eq!(
        refused(&format!("{HEAD}{good_tail}10\n")),
        (9, IesProblem::TrailingData("10".to_string()))
    );
    // Tilt data: geometry, count, factors.
    let tilt = "IESNA:LM-63-1995\nTILT=INCLUDE\n";
    assert!(refused(&format!("{tilt}4\n"))
        .1
        .to_string()
        .contains("lamp-to-luminaire geometry"));
    assert!(refused(&format!("{tilt}1\n0\n"))
        .1
        .to_string()
        .contains("number of tilt angles"));
    assert_eq!(refused(&format!("{tilt}1\n2\n0 90\n1 -0.5\n")).0, 6);
    // A missing file.
    let error = IesPhotometry::read(Path::new("/nonexistent/lamp.ies")).unwrap_err();
    assert!(matches!(error, IesError::Io { .. }));
    assert!(error.to_string().contains("/nonexistent/lamp.ies"));
}

#[test]
fn a_count_larger_than_its_angles_names_the_count_line() {
    // QA pass 15 of issue #16: 5 vertical angles declared on line 4 and 4 given on line 6;
    // the 0 on line 7 (the horizontal angles) was refused as "vertical angle 5 is 0
    // degrees, not above the one before it (90)" at line 7.
    let tail = "0\n159 159 159 159\n";
    let (line, problem) = refused(&format!(
        "{HEAD}1 1000 1 5 1 1 2 0 0 0\n1 1 10\n0 30 60 90\n{tail}"
    ));
    assert_eq!(line, 4, "{problem}");
    assert_eq!(
        problem,
        IesProblem::CountTooLarge {
            what: "vertical",
            count: 5,
            given: 4,
            given_on: "line 6 gives".to_string(),
            value: 0.0,
            value_line: 7,
            previous: 90.0,
            next: "horizontal angles",
        }
    );
    assert_eq!(
        problem.to_string(),
        "this line declares 5 vertical angles, but line 6 gives 4: vertical angle 5 would be \
         the 0 that starts line 7, not above the 90 before it, and the file holds fewer \
         numbers than its counts need, so line 7 likely begins the horizontal angles (give \
         the count of angles listed, or the missing angle)"
    );
    // A list that wraps is named by its lines.
    let (line, problem) = refused(&format!(
        "{HEAD}1 1000 1 5 1 1 2 0 0 0\n1 1 10\n0 30\n60 90\n{tail}"
    ));
    assert_eq!(line, 4);
    assert!(
        matches!(&problem, IesProblem::CountTooLarge { given_on, value_line: 8, .. } if given_on == "lines 6 to 7 give"),
        "{problem}"
    );
    // Wrapping is allowed: the same list over two lines with its count right is read.
    let ies = IesPhotometry::parse(
        &format!("{HEAD}1 1000 1 4 1 1 2 0 0 0\n1 1 10\n0 30\n60 90\n{tail}"),
        Path::new("wrapped.ies"),
    )
    .unwrap();
    assert_eq!(ies.vertical_angles_deg(), [0.0, 30.0, 60.0, 90.0]);
    // Where the file is not short of numbers, an angle out of order at a line's start is
    // just that.
    assert!(matches!(
        refused(&format!(
            "{HEAD}1 100 1 2 1 1 2 0 0 0\n1 1 5\n90\n90\n0\n10 10\n"
        )),
        (7, IesProblem::NotIncreasing { .. })
    ));
}

#[test]
fn a_stray_number_on_the_lamp_or_ballast_line_is_named_at_its_line() {
    // QA pass 15 of issue #16: a fourth number on the ballast line (`1 1 10 5`) was read
    // as vertical angle 1, and the error named the next line's 0 as vertical angle 2.
    let table = "0 30 60 90\n0\n159 159 159 159\n";
    let (line, problem) = refused(&format!("{HEAD}1 1000 1 4 1 1 2 0 0 0\n1 1 10 5\n{table}"));
    assert_eq!(line, 5, "{problem}");
    assert_eq!(
        problem,
        IesProblem::ExtraNumbers {
            name: "ballast line",
            found: 4,
            expected: 3,
            names: "the ballast factor, the third factor and the input watts",
            then_line: 6,
            then: Box::new(IesProblem::NotIncreasing {
                what: "vertical",
                index: 2,
                previous: 5.0,
                value: 0.0
            }),
        }
    );
    assert_eq!(
        problem.to_string(),
        "this line has 4 numbers, where the ballast line takes 3 (the ballast factor, the \
         third factor and the input watts): the extra one moves every number after it one \
         place on, and line 6 then reads: vertical angle 2 is 0 degrees, not above the one \
         before it (5): angles must increase"
    );
    // An eleventh number on the lamp line.
    let (line, problem) = refused(&format!("{HEAD}1 1000 1 4 1 1 2 0 0 0 7\n1 1 10\n{table}"));
    assert_eq!(line, 4, "{problem}");
    assert!(
        matches!(
            &problem,
            IesProblem::ExtraNumbers {
                name: "lamp line",
                found: 11,
                expected: 10,
                then_line: 6,
                ..
            }
        ),
        "{problem}"
    );
    // The lamp and ballast lines on one line, as some writers give them, are read.
    assert!(IesPhotometry::parse(
        &format!("{HEAD}1 1000 1 4 1 1 2 0 0 0 1 1 10\n{table}"),
        Path::new("one-line.ies"),
    )
    .is_ok());
}

#[test]
fn messages_name_file_line_and_what_was_expected() {
    let error = IesPhotometry::parse(
        &format!("{HEAD}1 100 1 2 1 1 2 0 0 0\n1 1 5\n0 90\n0\n10 x\n"),
        Path::new("lamp.ies"),
    )
    .unwrap_err();
    assert_eq!(
        error.to_string(),
        "lamp.ies:8: error: expected the candela value at vertical angle 90 and horizontal \
         angle 0, found `x`"
    );
}

/// Regression (fuzz target `ies`, crash-0880ca90): a label line whose fifth byte falls inside
/// a two-byte character panicked the `TILT=` check, which sliced the line at byte 5.
#[test]
fn tilt_check_on_a_line_with_a_multibyte_character_near_its_start() {
    let text = "close\u{9f}form isotropic\nclo\u{9f}se\nTILT=NONE\n1 100 1 2 1 1 2 0 0 0\n1 1 5\n0 90\n0\n10 10\n";
    let ies = IesPhotometry::parse(text, Path::new("multibyte.ies")).unwrap();
    assert_eq!(ies.labels().len(), 2);
    let (line, problem) = refused("clo\u{9f}se\n1 2 3\n");
    assert_eq!((line, problem), (2, IesProblem::NoTilt));
}

/// An asymmetric type C table (LM-63-2002, metres, absolute photometry) with a different
/// candela column in every C plane, so that each value read back names the plane it came
/// from. Vertical angles 0, 45, 90; C planes as given; `columns` one per plane.
fn asymmetric(horizontal: &str, columns: &[&str]) -> IesPhotometry {
    let n = horizontal.split_whitespace().count();
    assert_eq!(n, columns.len());
    let text = format!(
        "IESNA:LM-63-2002\n[TEST] asymmetric\nTILT=NONE\n1 -1 1 3 {n} 1 2 0 0 0\n1 1 0\n\
         0 45 90\n{horizontal}\n{}\n",
        columns.join("\n")
    );
    IesPhotometry::parse(&text, Path::new("asymmetric.ies")).unwrap()
}

/// The table's values at the knots, and linear in each angle between them: the expected
/// numbers below are read off the table by hand (a half-way point is the mean of the two
/// values; a point a quarter of the way is 3/4 of the first plus 1/4 of the second).
#[test]
fn asymmetric_full_table_reads_each_c_plane_and_interpolates_between_them() {
    let deg = f64::to_radians;
    // C0: 100 80 0; C90: 200 150 0; C180: 300 210 0; C270: 400 260 0.
    let columns = ["100 80 0", "200 150 0", "300 210 0", "400 260 0"];
    let open = asymmetric("0 90 180 270", &columns);
    // The same table closed at 360 with the C0 column again.
    let mut closed_columns = columns.to_vec();
    closed_columns.push("100 80 0");
    let closed = asymmetric("0 90 180 270 360", &closed_columns);
    for ies in [&open, &closed] {
        let at = |theta: f64, phi: f64| ies.candela(deg(theta), deg(phi));
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        // On the knots: each plane's own value at 45 degrees.
        for (phi, expected) in [(0.0, 80.0), (90.0, 150.0), (180.0, 210.0), (270.0, 260.0)] {
            assert!(close(at(45.0, phi), expected), "C{phi}: {}", at(45.0, phi));
        }
        // Half-way between planes at a knot: (80 + 150) / 2, (150 + 210) / 2.
        assert!(close(at(45.0, 45.0), 115.0), "{}", at(45.0, 45.0));
        assert!(close(at(45.0, 135.0), 180.0), "{}", at(45.0, 135.0));
        // A quarter of the way from C180 to C270: 0.75 * 210 + 0.25 * 260.
        assert!(close(at(45.0, 202.5), 222.5), "{}", at(45.0, 202.5));
        // Between C270 and C360 = C0 (the open table wraps to its first column):
        // (260 + 80) / 2, at 315 degrees and at -45 degrees alike.
        assert!(close(at(45.0, 315.0), 170.0), "{}", at(45.0, 315.0));
        assert!(close(at(45.0, -45.0), 170.0), "{}", at(45.0, -45.0));
        // Bilinear inside a cell: theta 22.5 (half-way from 0 to 45) and C135 (half-way
        // from C90 to C180): the mean of 200, 150, 300, 210.
        assert!(close(at(22.5, 135.0), 215.0), "{}", at(22.5, 135.0));
        // Nothing at 90 degrees in any plane, nothing beyond the table's last angle.
        assert!(close(at(90.0, 123.0), 0.0));
        assert_eq!(at(120.0, 0.0), 0.0);
    }
}

#[test]
fn half_and_quarter_tables_mirror_their_planes_into_the_rest_of_the_circle() {
    let deg = f64::to_radians;
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    // 0-180: C0 80, C90 150, C180 210 at 45 degrees; mirrored about the C0-C180 plane, so
    // C270 is C90 and C225 is C135 = (150 + 210) / 2.
    let half = asymmetric("0 90 180", &["100 80 0", "200 150 0", "300 210 0"]);
    let at = |phi: f64| half.candela(deg(45.0), deg(phi));
    assert!(close(at(270.0), 150.0), "{}", at(270.0));
    assert!(close(at(225.0), 180.0), "{}", at(225.0));
    assert!(close(at(-90.0), 150.0), "{}", at(-90.0));
    // C300 mirrors to C60: 2/3 of the way from C0 to C90, 80 + (150 - 80) * 2 / 3.
    assert!(close(at(300.0), 80.0 + 70.0 * 2.0 / 3.0), "{}", at(300.0));
    // 0-90: C0 80, C45 120, C90 150; mirrored in each quadrant: C135 is C45, C200 is C20
    // (4/9 of the way from C0 to C45: 80 + 40 * 4 / 9), C330 is C30 (80 + 40 * 2 / 3).
    let quarter = asymmetric("0 45 90", &["100 80 0", "150 120 0", "200 150 0"]);
    let at = |phi: f64| quarter.candela(deg(45.0), deg(phi));
    assert!(close(at(135.0), 120.0), "{}", at(135.0));
    assert!(close(at(180.0), 80.0), "{}", at(180.0));
    assert!(close(at(270.0), 150.0), "{}", at(270.0));
    assert!(close(at(200.0), 80.0 + 40.0 * 4.0 / 9.0), "{}", at(200.0));
    assert!(close(at(330.0), 80.0 + 40.0 * 2.0 / 3.0), "{}", at(330.0));
}
