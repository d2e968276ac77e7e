//! Point luminaires against closed forms.

use std::f64::consts::PI;

use glam::{dvec3, DVec3};

use super::*;

fn light(distribution: Distribution, output: Output, aim: DVec3) -> Luminaire {
    Luminaire {
        name: "l".into(),
        position: DVec3::ZERO,
        aim,
        output,
        distribution,
        colour: Rgb::splat(1.0),
    }
}

/// The six faces of the cube [-h, h]^3, each counter-clockwise seen from inside (fronts
/// facing the centre).
fn cube_faces(h: f64) -> Vec<Vec<DVec3>> {
    let c = |x: f64, y: f64, z: f64| dvec3(x * h, y * h, z * h);
    vec![
        vec![
            c(-1., -1., -1.),
            c(1., -1., -1.),
            c(1., 1., -1.),
            c(-1., 1., -1.),
        ], // floor
        vec![
            c(-1., -1., 1.),
            c(-1., 1., 1.),
            c(1., 1., 1.),
            c(1., -1., 1.),
        ], // ceiling
        vec![
            c(-1., -1., -1.),
            c(-1., -1., 1.),
            c(1., -1., 1.),
            c(1., -1., -1.),
        ], // y = -h
        vec![
            c(-1., 1., -1.),
            c(1., 1., -1.),
            c(1., 1., 1.),
            c(-1., 1., 1.),
        ], // y = +h
        vec![
            c(-1., -1., -1.),
            c(-1., 1., -1.),
            c(-1., 1., 1.),
            c(-1., -1., 1.),
        ], // x = -h
        vec![
            c(1., -1., -1.),
            c(1., -1., 1.),
            c(1., 1., 1.),
            c(1., 1., -1.),
        ], // x = +h
    ]
}

fn clear(_: DVec3, _: DVec3) -> bool {
    false
}

#[test]
fn isotropic_light_in_a_closed_cube_puts_every_lumen_on_the_walls() {
    let l = light(Distribution::Isotropic, Output::Flux(1000.0), DEFAULT_AIM);
    let got: f64 = cube_faces(2.0)
        .iter()
        .map(|f| power_onto(&l, f, 3, clear).luminance())
        .sum();
    // The sub-triangles' solid angles tile the sphere exactly: only rounding is left.
    assert!((got - 1000.0).abs() < 1e-9, "{got}");
    assert!((l.flux() - 1000.0).abs() < 1e-12);
}

#[test]
fn cosine_light_emits_pi_times_its_axial_intensity() {
    // Any aim: the flux is the integral of I0 cos over the hemisphere, pi I0, found here by
    // summing what falls on a cube round the light.
    for aim in [DEFAULT_AIM, dvec3(1.0, 2.0, 0.5), dvec3(0.0, 0.0, 1.0)] {
        let l = light(Distribution::Cosine, Output::Intensity(100.0), aim);
        let got: f64 = cube_faces(1.0)
            .iter()
            .map(|f| power_onto(&l, f, 32, clear).luminance())
            .sum();
        // Midpoint rule on 6 x 2 x 32^2 sub-triangles of a smooth integrand: second order,
        // about 1e-4 relative; 1e-3 leaves room and still catches a missing cos or a 2 pi.
        assert!((got / (PI * 100.0) - 1.0).abs() < 1e-3, "{aim}: {got}");
        assert!((l.flux() - PI * 100.0).abs() < 1e-12);
    }
}

#[test]
fn illuminance_on_a_plane_is_i_cos_over_d_squared() {
    let mut l = light(
        Distribution::Isotropic,
        Output::Intensity(500.0),
        DEFAULT_AIM,
    );
    l.position = dvec3(1.0, 2.0, 3.0);
    // Floor points at horizontal offsets r: d^2 = 9 + r^2, cos = 3 / d.
    for (x, y) in [(1.0, 2.0), (2.0, 2.0), (4.0, 6.0), (-3.0, 2.0)] {
        let p = dvec3(x, y, 0.0);
        let d2 = (p - l.position).length_squared();
        let want = 500.0 * (3.0 / d2.sqrt()) / d2;
        let got = l.irradiance_unoccluded(p, DVec3::Z).luminance();
        assert!((got - want).abs() <= 1e-12 * want, "{got} {want}");
        // Facing away: nothing.
        assert_eq!(l.irradiance_unoccluded(p, -DVec3::Z), Rgb::BLACK);
    }
    // A 2a x 2a square centred under the light at height h receives I times its solid
    // angle, 4 arcsin(a^2 / (a^2 + h^2)).
    let (a, h) = (1.5, 3.0);
    let sq = vec![
        dvec3(1.0 - a, 2.0 - a, 0.0),
        dvec3(1.0 + a, 2.0 - a, 0.0),
        dvec3(1.0 + a, 2.0 + a, 0.0),
        dvec3(1.0 - a, 2.0 + a, 0.0),
    ];
    let want = 500.0 * 4.0 * (a * a / (a * a + h * h)).asin();
    let got = power_onto(&l, &sq, 2, clear).luminance();
    assert!((got - want).abs() < 1e-9 * want, "{got} {want}");
    // Seen from behind (the square turned over): nothing.
    let back: Vec<DVec3> = sq.iter().rev().copied().collect();
    assert_eq!(power_onto(&l, &back, 2, clear), Rgb::BLACK);
    // COSINE aimed down: I0 cos(theta) cos(theta) / d^2 directly below and off axis.
    let mut c = light(Distribution::Cosine, Output::Intensity(500.0), DEFAULT_AIM);
    c.position = l.position;
    let p = dvec3(4.0, 6.0, 0.0);
    let d2 = (p - c.position).length_squared();
    let cos = 3.0 / d2.sqrt();
    let got = c.irradiance_unoccluded(p, DVec3::Z).luminance();
    assert!((got - 500.0 * cos * cos / d2).abs() < 1e-12 * got);
    // Above the light's horizon a downlight gives nothing.
    assert_eq!(
        c.irradiance_unoccluded(dvec3(1.0, 2.0, 5.0), -DVec3::Z),
        Rgb::BLACK
    );
}

#[test]
fn the_azimuth_frame_follows_the_documented_convention() {
    let down = light(Distribution::Isotropic, Output::Intensity(1.0), DEFAULT_AIM);
    let (u, v, w) = down.frame();
    assert!((u - DVec3::X).length() < 1e-15 && (v - DVec3::Y).length() < 1e-15);
    assert!((w - DEFAULT_AIM).length() < 1e-15);
    let up = light(Distribution::Isotropic, Output::Intensity(1.0), DVec3::Z);
    let (u, v, w) = up.frame();
    assert_eq!((u, v, w), (DVec3::X, -DVec3::Y, DVec3::Z));
    for aim in [
        dvec3(1.0, 0.0, 0.0),
        dvec3(0.3, -2.0, 0.7),
        dvec3(0.0, 1e-9, 1.0),
    ] {
        let l = light(Distribution::Isotropic, Output::Intensity(1.0), aim);
        let (u, v, w) = l.frame();
        assert!((w - aim.normalize()).length() < 1e-12);
        assert!(u.dot(v).abs() < 1e-12 && u.dot(w).abs() < 1e-12 && v.dot(w).abs() < 1e-12);
        assert!((u.length() - 1.0).abs() < 1e-12 && (v.length() - 1.0).abs() < 1e-12);
        // Right-handed like (x, y, -z): u x v = -w.
        assert!((u.cross(v) + w).length() < 1e-12, "{aim}");
    }
}

#[test]
fn an_occluder_hides_what_it_covers() {
    let l = light(
        Distribution::Isotropic,
        Output::Intensity(10.0),
        DEFAULT_AIM,
    );
    let floor = vec![
        dvec3(-1.0, -1.0, -1.0),
        dvec3(1.0, -1.0, -1.0),
        dvec3(1.0, 1.0, -1.0),
        dvec3(-1.0, 1.0, -1.0),
    ];
    // A blocker over the half x > 0.
    let half = power_onto(&l, &floor, 8, |x, _| x.x > 0.0);
    let full = power_onto(&l, &floor, 8, clear);
    assert!((half.luminance() / full.luminance() - 0.5).abs() < 1e-12);
}

#[test]
fn combinations_without_an_output_are_refused() {
    let l = light(Distribution::Cosine, Output::AsTabulated, DEFAULT_AIM);
    assert_eq!(l.check(), Err(LuminaireError::NoOutput));
    let l = light(Distribution::Cosine, Output::Flux(1.0), DVec3::ZERO);
    assert_eq!(l.check(), Err(LuminaireError::ZeroAim));
}
