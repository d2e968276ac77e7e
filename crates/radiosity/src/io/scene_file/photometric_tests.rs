//! The photometric keywords (LUMINANCE, FLUX, OPENING) and point luminaires (LIGHTBEGIN):
//! what they read as, their errors with line and column, and the writer's round trip.

use std::f64::consts::PI;

use glam::{dvec3, DVec3};

use super::super::write_scene;
use super::*;
use crate::luminaire::{Distribution, Output};

/// A 2 x 3 floor patch whose light lines (7-9) and reflectance lines are given.
fn patch(light: &str, reflect: &str) -> String {
    format!(
        "MAX_PATCH_AREA 100\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#Floor\nVERTICES 4\n\
         {light}\n{reflect}\nVERTEX0 0 0 0\nVERTEX1 2 0 0\nVERTEX2 2 3 0\nVERTEX3 0 3 0\n\
         PATCHEND\nSCENEEND\n"
    )
}

const GREY: &str = "Rr 0.5\nRg 0.5\nRb 0.5";

fn read(text: &str) -> SceneFile {
    parse_scene(text, "t.scene").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn errors(text: &str) -> Vec<(usize, usize, String)> {
    match parse_scene(text, "t.scene") {
        Ok(_) => Vec::new(),
        Err(e) => e
            .errors
            .into_iter()
            .map(|e| (e.line, e.column, e.message))
            .collect(),
    }
}

/// Writes the file and reads it back: the same scene, and the same text when written again.
#[track_caller]
fn round_trip(file: &SceneFile) -> String {
    let mut out = Vec::new();
    write_scene(&file.scene, file.settings, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    let back = read(&text);
    assert_eq!(&back, file, "{text}");
    let mut again = Vec::new();
    write_scene(&back.scene, back.settings, &mut again).unwrap();
    assert_eq!(String::from_utf8(again).unwrap(), text);
    text
}

#[test]
fn luminance_is_a_lambertian_exitance_of_pi_l_in_every_band() {
    let file = read(&patch("LUMINANCE 1000", GREY));
    let s = &file.scene.surfaces[0];
    assert_eq!(s.emission, Rgb::splat(PI * 1000.0));
    assert_eq!(s.photometry.emission, EmissionGiven::Luminance(1000.0));
    let text = round_trip(&file);
    assert!(text.contains("\nLUMINANCE 1000\n"), "{text}");
}

#[test]
fn flux_is_spread_over_the_patch_area() {
    // 600 lm on 2 m x 3 m: 100 lm/m^2.
    let file = read(&patch("FLUX 600", GREY));
    let s = &file.scene.surfaces[0];
    assert!((s.emission.luminance() - 100.0).abs() < 1e-12);
    assert_eq!(s.photometry.emission, EmissionGiven::Flux(600.0));
    let text = round_trip(&file);
    assert!(text.contains("\nFLUX 600\n"), "{text}");
    // Recoloured since it was read: written as its exitance, not as a flux it no longer has.
    let mut changed = file.clone();
    changed.scene.surfaces[0].emission = Rgb::splat(7.0);
    let mut out = Vec::new();
    write_scene(&changed.scene, changed.settings, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains("Er 7\nEg 7\nEb 7\n") && !text.contains("FLUX"),
        "{text}"
    );
}

#[test]
fn flux_on_a_box_is_spread_over_all_six_faces() {
    // A 1 x 2 x 3 box: area 2 (2 + 3 + 6) = 22 m^2.
    let text = "MAX_PATCH_AREA 100\nINTEGRAL_STEPS 2\nSCENEBEGIN\nBOXBEGIN\n#Lamp\nFACING OUT\n\
                FLUX 2200\nRr 0\nRg 0\nRb 0\nORIGIN 0 0 0\nSIZE 1 2 3\nBOXEND\nSCENEEND\n";
    let file = read(text);
    assert_eq!(file.scene.surfaces.len(), 6);
    for s in &file.scene.surfaces {
        assert!((s.emission.luminance() - 100.0).abs() < 1e-12, "{}", s.name);
        // Six pieces: shares of the block's flux, written back as their exitance.
        assert_eq!(s.photometry.emission, EmissionGiven::FluxShare);
    }
    let mut out = Vec::new();
    write_scene(&file.scene, file.settings, &mut out).unwrap();
    let back = read(&String::from_utf8(out).unwrap());
    for (a, b) in file.scene.surfaces.iter().zip(&back.scene.surfaces) {
        assert_eq!(a.emission, b.emission, "{}", a.name);
        assert_eq!(b.photometry.emission, EmissionGiven::Exitance);
    }
    round_trip(&back);
}

#[test]
fn an_opening_has_reflectance_zero_and_reads_back_as_one() {
    let file = read(&patch("LUMINANCE 2000", "OPENING"));
    let s = &file.scene.surfaces[0];
    assert_eq!(s.reflectance, Rgb::BLACK);
    assert!(s.photometry.opening);
    let text = round_trip(&file);
    assert!(
        text.contains("\nOPENING\n") && !text.contains("Rr"),
        "{text}"
    );
    // An opening without light (light leaves the room through it).
    let dark = read(&patch("Er 0\nEg 0\nEb 0", "OPENING"));
    assert!(dark.scene.surfaces[0].photometry.opening);
    round_trip(&dark);
}

#[test]
fn photometric_keyword_errors_name_the_line_and_what_would_work() {
    let e = errors(&patch("LUMINANCE -3", GREY));
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!((e[0].0, e[0].1), (7, 11));
    assert!(
        e[0].2.contains("LUMINANCE (cd/m^2) must not be negative"),
        "{e:?}"
    );
    let e = errors(&patch("FLUX x", GREY));
    assert_eq!((e[0].0, e[0].1), (7, 6));
    assert!(e[0].2.contains("expected a number after \"FLUX\""), "{e:?}");
    // OPENING then Rr: the reflectance of an opening is 0.
    let e = errors(&patch("Er 0\nEg 0\nEb 0", "OPENING\nRr 0.5"));
    assert_eq!(e[0].0, 11, "{e:?}");
    assert!(e[0].2.contains("an opening has reflectance 0"), "{e:?}");
    // Neither Er nor the photometric keywords: the message names all three.
    let e = errors(&patch("Lum 3", GREY));
    assert!(
        e[0].2.contains("expected Er (or LUMINANCE L, or FLUX P)"),
        "{e:?}"
    );
    let e = errors(&patch("Er 0\nEg 0\nEb 0", "Reflect 0"));
    assert!(e[0].2.contains("expected Rr (or OPENING)"), "{e:?}");
}

/// The floor patch and one light block.
fn with_light(block: &str) -> String {
    patch("Er 0\nEg 0\nEb 0", GREY).replace("SCENEEND", &format!("{block}\nSCENEEND"))
}

#[test]
fn a_light_block_reads_with_its_defaults_and_round_trips() {
    // The example (comments and all).
    let file = read(&with_light(
        "LIGHTBEGIN\n#Downlight\nPOSITION 2 2 3\nAIM 0 0 -1              // the axis\n\
         INTENSITY 1000          // cd on the axis\nDISTRIBUTION COSINE\nLIGHTEND",
    ));
    let l = &file.scene.lights[0];
    assert_eq!(l.name, "Downlight");
    assert_eq!(l.position, dvec3(2.0, 2.0, 3.0));
    assert_eq!(l.aim, dvec3(0.0, 0.0, -1.0));
    assert_eq!(l.output, Output::Intensity(1000.0));
    assert_eq!(l.distribution, Distribution::Cosine);
    assert_eq!(l.colour, Rgb::splat(1.0));
    round_trip(&file);
    // Any order; AIM left out (straight down); FLUX; a tint; the American spelling.
    let file = read(&with_light(
        "LIGHTBEGIN\n#Bulb\nDISTRIBUTION isotropic\nFLUX 10000\nCOLOR 1 0.8 0.6\n\
         POSITION 1 1 2.5\nLIGHTEND",
    ));
    let l = &file.scene.lights[0];
    assert_eq!(l.aim, dvec3(0.0, 0.0, -1.0));
    assert_eq!(l.output, Output::Flux(10000.0));
    assert_eq!(l.distribution, Distribution::Isotropic);
    assert_eq!(l.colour, Rgb([1.0, 0.8, 0.6]));
    let text = round_trip(&file);
    assert!(text.contains("COLOUR 1 0.8 0.6"), "{text}");
}

#[test]
fn light_block_errors_name_the_line_and_what_was_expected() {
    let lines = |block: &str| errors(&with_light(block));
    // The floor patch takes lines 1-17; LIGHTBEGIN is line 18.
    let e = lines("LIGHTBEGIN\n#L\nDISTRIBUTION ISOTROPIC\nINTENSITY 5\nLIGHTEND");
    assert_eq!((e[0].0, e[0].1), (18, 1), "{e:?}");
    assert!(e[0].2.contains("the light \"L\" has no POSITION"), "{e:?}");
    let e = lines("LIGHTBEGIN\n#L\nPOSITION 0 0 1\nINTENSITY 5\nLIGHTEND");
    assert!(
        e[0].2
            .contains("has no DISTRIBUTION line: expected ISOTROPIC, COSINE"),
        "{e:?}"
    );
    let e = lines("LIGHTBEGIN\n#L\nPOSITION 0 0 1\nDISTRIBUTION COSINE\nLIGHTEND");
    assert!(
        e[0].2.contains("needs INTENSITY (cd) or FLUX (lm)"),
        "{e:?}"
    );
    let e =
        lines("LIGHTBEGIN\n#L\nPOSITION 0 0 1\nINTENSITY 5\nFLUX 3\nDISTRIBUTION COSINE\nLIGHTEND");
    assert_eq!(e[0].0, 22, "{e:?}");
    assert!(e[0]
        .2
        .contains("INTENSITY or FLUX is given twice in this light (first on line 21)"));
    let e = lines("LIGHTBEGIN\n#L\nPOSITION 0 0 1\nINTENSITY 5\nDISTRIBUTION SPOT\nLIGHTEND");
    assert_eq!((e[0].0, e[0].1), (22, 14), "{e:?}");
    assert!(
        e[0].2
            .contains("expected ISOTROPIC, COSINE or IES file.ies"),
        "{e:?}"
    );
    let e = lines(
        "LIGHTBEGIN\n#L\nPOSITION 0 0 1\nAIM 0 0 0\nINTENSITY 5\nDISTRIBUTION COSINE\nLIGHTEND",
    );
    // Once (QA of issue #16: the zero aim was reported by the reader and again by the
    // light's own check).
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!(e[0].0, 21, "{e:?}");
    assert!(e[0].2.contains("AIM must be a direction"), "{e:?}");
    let e = lines("LIGHTBEGIN\n#L\nPOSITION 0 0 1\nINTENSITY -5\nDISTRIBUTION COSINE\nLIGHTEND");
    assert!(e[0].2.contains("INTENSITY must not be negative"), "{e:?}");
    let e = lines("LIGHTBEGIN\n#L\nPOSITION 0 0 1\nWATTS 5\nLIGHTEND");
    // The unknown line, and then (the rest of the block still read) the missing
    // DISTRIBUTION, at the block's first line.
    assert_eq!(e.len(), 2, "{e:?}");
    assert!(e[1].2.contains("has no DISTRIBUTION"), "{e:?}");
    assert_eq!((e[0].0, e[0].1), (21, 1), "{e:?}");
    assert!(
        e[0].2
            .contains("unknown keyword \"WATTS\"; expected POSITION, AIM"),
        "{e:?}"
    );
    // A missing LIGHTEND at the end of the scene.
    let e = lines("LIGHTBEGIN\n#L\nPOSITION 0 0 1\nINTENSITY 5\nDISTRIBUTION COSINE");
    assert!(
        e[0].2.contains("expected LIGHTEND, found \"SCENEEND\""),
        "{e:?}"
    );
    // Lights alone are no scene.
    let text = "MAX_PATCH_AREA 1\nINTEGRAL_STEPS 1\nSCENEBEGIN\nLIGHTBEGIN\n#L\nPOSITION 0 0 1\n\
                INTENSITY 5\nDISTRIBUTION COSINE\nLIGHTEND\nSCENEEND\n";
    let e = errors(text);
    assert!(e[0].2.contains("no patches"), "{e:?}");
    // QA pass 13 of #16: a colour's numbers are named as bands, and a black light is
    // refused at its line (it passed, and `check` said nothing emits light).
    let e = lines(
        "LIGHTBEGIN\n#L\nPOSITION 0 0 1\nINTENSITY 5\nCOLOUR 1 0.5\nDISTRIBUTION COSINE\nLIGHTEND",
    );
    assert_eq!(e[0].0, 22, "{e:?}");
    assert!(e[0].2.contains("the blue"), "{e:?}");
    let e = lines(
        "LIGHTBEGIN\n#L\nPOSITION 0 0 1\nINTENSITY 5\nCOLOUR 0 0 0\nDISTRIBUTION COSINE\nLIGHTEND",
    );
    assert_eq!((e.len(), e[0].0, e[0].1), (1, 22, 1), "{e:?}");
    assert!(
        e[0].2.contains("COLOUR 0 0 0 makes the light emit nothing"),
        "{e:?}"
    );
    // QA pass 14 of #16: an IES file that cannot be read hid the errors after it.
    let e = lines(
        "LIGHTBEGIN\n#L\nPOSITION 0 0 1\nDISTRIBUTION IES no/such.ies\nCOLOUR 0 0 0\nLIGHTEND",
    );
    assert_eq!(e.len(), 2, "{e:?}");
    assert!(e[0].2.contains("IES file \"no/such.ies\""), "{e:?}");
    assert_eq!(e[1].0, 22, "{e:?}");
}

#[test]
fn an_ies_light_reads_its_file_relative_to_the_scene_and_round_trips() {
    // The scene's name is a path in the repository's tests/data; the IES path is relative
    // to its folder.
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/x.scene");
    let text = with_light(
        "LIGHTBEGIN\n#Iso\nPOSITION 0 0 2\nFLUX 1000\nDISTRIBUTION IES ies/isotropic_lm63_2002.ies\nLIGHTEND",
    );
    let file = parse_scene(&text, data).unwrap_or_else(|e| panic!("{e}"));
    let l = &file.scene.lights[0];
    let Distribution::Ies { written, .. } = &l.distribution else {
        panic!("{:?}", l.distribution)
    };
    assert_eq!(written, "ies/isotropic_lm63_2002.ies");
    // FLUX scales the table to 1000 lm: an isotropic table then gives 1000 / (4 pi) cd
    // everywhere (to the table's interpolation, which is exact for a constant).
    assert!((l.flux() - 1000.0).abs() < 1e-9, "{}", l.flux());
    for d in [DVec3::Z, -DVec3::Z, dvec3(1.0, 1.0, 0.3).normalize()] {
        assert!((l.candela(d) - 1000.0 / (4.0 * PI)).abs() < 1e-9, "{d}");
    }
    let mut out = Vec::new();
    write_scene(&file.scene, file.settings, &mut out).unwrap();
    let written_text = String::from_utf8(out).unwrap();
    assert!(written_text.contains("DISTRIBUTION IES ies/isotropic_lm63_2002.ies\n"));
    assert_eq!(parse_scene(&written_text, data).unwrap(), file);
    // A missing file: the scene's line, the path as written, and the reason.
    let text = with_light("LIGHTBEGIN\n#X\nPOSITION 0 0 2\nDISTRIBUTION IES no/such.ies\nLIGHTEND");
    let e = parse_scene(&text, data).unwrap_err().errors;
    assert_eq!((e[0].line, e[0].column), (21, 18), "{e:?}");
    assert!(e[0].message.contains("IES file \"no/such.ies\""), "{e:?}");
    assert!(e[0].message.contains("cannot read"), "{e:?}");
    // INTENSITY with IES is refused (FLUX or the file's own values).
    let text = with_light(
        "LIGHTBEGIN\n#X\nPOSITION 0 0 2\nINTENSITY 3\nDISTRIBUTION IES ies/isotropic_lm63_2002.ies\nLIGHTEND",
    );
    let e = parse_scene(&text, data).unwrap_err().errors;
    assert!(
        e[0].message
            .contains("takes FLUX (to scale the table) or neither"),
        "{e:?}"
    );
}
