//! The path tracer against closed forms: the furnace, a receiver under a parallel square
//! light, black backs and escaping rays, determinism, and refused requests.

use glam::{dvec3, DVec3};

use super::*;
use crate::form_factor::{exact, reference};
use crate::light::Rgb;
use crate::progress::NoProgress;
use crate::scene::Surface;

fn scene(surfaces: Vec<Surface>) -> Scene {
    Scene {
        surfaces,
        camera: None,
        lights: Vec::new(),
    }
}

fn surface(name: &str, emission: Rgb, reflectance: Rgb, vertices: Vec<DVec3>) -> Surface {
    Surface {
        name: name.into(),
        emission,
        reflectance,
        vertices,
        photometry: Default::default(),
    }
}

/// The square [-0.5, 0.5]^2 in the plane z, facing +z (`up`) or -z.
fn square_at_z(z: f64, up: bool) -> Vec<DVec3> {
    let v = vec![
        dvec3(-0.5, -0.5, z),
        dvec3(0.5, -0.5, z),
        dvec3(0.5, 0.5, z),
        dvec3(-0.5, 0.5, z),
    ];
    if up {
        v
    } else {
        v.into_iter().rev().collect()
    }
}

/// The unit cube [0, 1]^3 as six squares facing into it, all with emission `e` and
/// reflectance `rho`.
fn furnace(e: Rgb, rho: Rgb) -> Scene {
    let centre = DVec3::splat(0.5);
    let mut faces = Vec::new();
    for axis in 0..3 {
        for side in [0.0, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |a: f64, b: f64| {
                let mut p = DVec3::ZERO;
                p[axis] = side;
                p[u] = a;
                p[v] = b;
                p
            };
            let mut sq = vec![
                corner(0., 0.),
                corner(1., 0.),
                corner(1., 1.),
                corner(0., 1.),
            ];
            let n = crate::geometry::polygon_normal(&sq).unwrap();
            if n.dot(centre - sq[0]) < 0.0 {
                sq.reverse();
            }
            faces.push(surface(&format!("face{}", faces.len()), e, rho, sq));
        }
    }
    scene(faces)
}

fn camera(eye: DVec3, look_at: DVec3, fov_y_degrees: f64, size: u32) -> Camera {
    Camera {
        eye,
        look_at,
        up: DVec3::Y,
        fov_y_degrees,
        width: size,
        height: size,
    }
}

#[test]
fn furnace_pixels_are_e_over_one_minus_rho() {
    // In a closed box where every face has emission E and reflectance rho, B = E + rho B
    // everywhere: B = E / (1 - rho) whatever the view. Every pixel must be within 1 % of
    // B, and the test asserts that this is at least 5 standard errors of that pixel's
    // mean, so a failure is a bias, not bad luck. Every hit is on an emitter, so every
    // hit weighs a light sample against a bounce: a wrong MIS weight shows here.
    //
    // Grey (E 1, rho 0.5: B = 2) with the default roulette after 3 bounces: the roulette
    // dominates the noise (no light is ever lost, so it kills paths that carry 1/8 of
    // the value), 24 000 paths a pixel for a standard error of at most 0.0037 (measured),
    // 5 sigma 0.019. Coloured (rho 0.3, 0.5, 0.7 and E 1, 0.5, 0.25: B = 1/0.7, 1,
    // 0.25/0.3), the blue band's paths the longest (the roulette follows the largest
    // band), with the first 12 bounces certain: 10 000 paths a pixel, blue's standard
    // error at most 0.0014 (measured), 5 sigma 0.0070 against a tolerance of 0.0083.
    let mut coloured = PathTraceSettings::DEFAULT.with_samples(10_000);
    coloured.roulette_after_bounces = 12;
    let cases = [
        (
            Rgb::splat(1.0),
            Rgb::splat(0.5),
            PathTraceSettings::DEFAULT.with_samples(24_000),
        ),
        (Rgb([1.0, 0.5, 0.25]), Rgb([0.3, 0.5, 0.7]), coloured),
    ];
    for (e, rho, settings) in cases {
        let s = furnace(e, rho);
        // Four by four pixels of 100 degrees: walls, edges and corners of the box.
        let cam = camera(dvec3(0.5, 0.45, 0.55), dvec3(0.9, 0.6, 0.2), 100.0, 4);
        let view = path_trace(&s, &cam, &settings, &NoProgress).unwrap();
        let b = e.zip_map(rho, |e, r| e / (1.0 - r));
        for y in 0..4 {
            for x in 0..4 {
                let (v, se) = (view.radiosity(x, y), view.standard_error(x, y));
                for k in 0..3 {
                    let tol = 0.01 * b[k];
                    assert!(
                        5.0 * se[k] <= tol,
                        "pixel ({x}, {y}) band {k}: se {}",
                        se[k]
                    );
                    assert!(
                        (v[k] - b[k]).abs() < tol,
                        "pixel ({x}, {y}) band {k}: {} for {} (se {})",
                        v[k],
                        b[k],
                        se[k]
                    );
                }
                // Every face emits, so every pixel shows an emitter.
                assert!(view.shows_emitter(x, y));
            }
        }
    }
}

/// A receiver [-0.5, 0.5]^2 at z = 0 facing +z (rho 0.5, no emission) under an emitting
/// unit square (E 1, rho 0) at z = 1 facing it.
fn receiver_under_light() -> Scene {
    scene(vec![
        surface(
            "receiver",
            Rgb::BLACK,
            Rgb::splat(0.5),
            square_at_z(0.0, true),
        ),
        surface(
            "light",
            Rgb::splat(1.0),
            Rgb::BLACK,
            square_at_z(1.0, false),
        ),
    ])
}

#[test]
fn receiver_centre_is_rho_e_times_the_point_form_factor() {
    // The receiver's radiosity at its centre is rho E F, F the form factor from the centre
    // point to the parallel light square: four times Howell's B-3 (the point under a
    // corner of a 0.5 x 0.5 rectangle at distance 1), 0.2395, which Lambert's formula
    // (exact::point_to_polygon) gives too. The light does not reflect, so nothing else
    // reaches the receiver. One pixel of 0.5 degrees from 0.5 away looks at a 4.4 mm
    // patch, over which B falls by under 1e-5 relative (B is flat at the centre): the
    // pixel is the point value. Both estimators must be within 5 of their standard
    // errors of it: the plain one (a 2.8 % band at 100 000 paths) and the one with light
    // samples (a 0.3 % band at 20 000).
    let s = receiver_under_light();
    let light = &s.surfaces[1].vertices;
    let f = exact::point_to_polygon(DVec3::ZERO, DVec3::Z, light);
    let howell = 4.0 * reference::differential_to_parallel_rectangle(0.5, 0.5, 1.0);
    assert!((f - howell).abs() < 1e-12, "{f} vs {howell}");
    let expected = 0.5 * f;
    let cam = camera(dvec3(0.0, 0.0, 0.5), DVec3::ZERO, 0.5, 1);
    let trace = |samples: u32, nee: bool| {
        let mut settings = PathTraceSettings::DEFAULT.with_samples(samples);
        settings.next_event_estimation = nee;
        let view = path_trace(&s, &cam, &settings, &NoProgress).unwrap();
        assert!(!view.shows_emitter(0, 0));
        (view.radiosity(0, 0), view.standard_error(0, 0))
    };
    let n = 100_000;
    let (plain, plain_se) = trace(n, false);
    let (nee, nee_se) = trace(20_000, true);
    // Without light samples each path returns 0.5 (it reached the light) or 0 (it
    // escaped): a Bernoulli variable, whose standard error 0.5 sqrt(F (1 - F) / N) the
    // estimate must report, to the precision of a variance estimated from 100 000 draws
    // (well under 2 %).
    let bernoulli = 0.5 * (f * (1.0 - f) / n as f64).sqrt();
    for k in 0..3 {
        for (b, se) in [(plain[k], plain_se[k]), (nee[k], nee_se[k])] {
            assert!(
                (b - expected).abs() < 5.0 * se,
                "{b} for {expected} (se {se})"
            );
        }
        assert!(
            (plain_se[k] / bernoulli - 1.0).abs() < 0.02,
            "{} vs {bernoulli}",
            plain_se[k]
        );
        // Light samples are worth it: measured 0.23 of the error from a fifth of the paths
        // (a tenth at equal paths).
        assert!(
            nee_se[k] < 0.3 * plain_se[k],
            "{} vs {}",
            nee_se[k],
            plain_se[k]
        );
    }
    // Looking up at the light from the same point: the light's own radiosity, E (it
    // reflects nothing), exactly, with no noise.
    let up = camera(dvec3(0.0, 0.0, 0.5), dvec3(0.0, 0.0, 1.0), 20.0, 3);
    let view = path_trace(
        &s,
        &up,
        &PathTraceSettings::DEFAULT.with_samples(16),
        &NoProgress,
    )
    .unwrap();
    for (y, x) in [(0, 0), (1, 1), (2, 2)] {
        assert_eq!(view.radiosity(x, y), Rgb::splat(1.0));
        assert_eq!(view.standard_error(x, y), Rgb::BLACK);
        assert!(view.shows_emitter(x, y));
    }
}

#[test]
fn light_samples_and_bounces_estimate_the_same_image() {
    // With interreflection (the light reflects half, in colour) there is no closed form,
    // but the two estimators are independent: the plain one finds the light only by
    // bouncing into it, the other mostly by light samples. A view of the receiver and
    // the light, and the Cornell box (a small light, occluding blocks): each pixel mean,
    // and the image mean, must agree within 5 of their combined standard errors.
    let mut s = receiver_under_light();
    s.surfaces[1].reflectance = Rgb([0.5, 0.3, 0.1]);
    let side = camera(dvec3(0.0, -0.9, 0.5), dvec3(0.0, 0.0, 0.5), 90.0, 4);
    let cornell = crate::scene::cornell_box().scene;
    let cornell_cam = Camera::for_scene(&cornell, 6, 6);
    for (scene, cam, plain_samples) in [(&s, side, 20_000), (&cornell, cornell_cam, 4_000)] {
        let mut settings = PathTraceSettings::DEFAULT.with_samples(plain_samples);
        settings.next_event_estimation = false;
        let plain = path_trace(scene, &cam, &settings, &NoProgress).unwrap();
        settings.next_event_estimation = true;
        settings.samples_per_pixel = 1_000;
        let nee = path_trace(scene, &cam, &settings, &NoProgress).unwrap();
        let (mut diff, mut var) = (0.0, 0.0);
        for y in 0..cam.height as usize {
            for x in 0..cam.width as usize {
                let d = plain.radiosity(x, y).luminance() - nee.radiosity(x, y).luminance();
                let v = plain.luminance_standard_error(x, y).powi(2)
                    + nee.luminance_standard_error(x, y).powi(2);
                assert!(
                    d.abs() <= 5.0 * v.sqrt(),
                    "pixel ({x}, {y}): {d} (se {})",
                    v.sqrt()
                );
                diff += d;
                var += v;
            }
        }
        assert!(
            diff.abs() <= 5.0 * var.sqrt(),
            "image: {diff} (se {})",
            var.sqrt()
        );
    }
}

#[test]
fn backs_are_black_and_escaping_rays_return_nothing() {
    let s = receiver_under_light();
    let settings = PathTraceSettings::DEFAULT.with_samples(64);
    // The back of the light, from above it: black, though it emits from its front.
    let above = camera(dvec3(0.0, 0.0, 2.0), dvec3(0.0, 0.0, 1.0), 20.0, 3);
    let view = path_trace(&s, &above, &settings, &NoProgress).unwrap();
    // Looking away from everything: the rays escape.
    let away = camera(dvec3(0.0, 0.0, 2.0), dvec3(0.0, 0.0, 3.0), 20.0, 3);
    let nothing = path_trace(&s, &away, &settings, &NoProgress).unwrap();
    for v in [&view, &nothing] {
        for y in 0..3 {
            for x in 0..3 {
                assert_eq!(v.radiosity(x, y), Rgb::BLACK);
                assert_eq!(v.standard_error(x, y), Rgb::BLACK);
                assert!(!v.shows_emitter(x, y));
            }
        }
    }
    // A receiver that sees only the back of a light gets nothing from it.
    let mut flipped = receiver_under_light();
    flipped.surfaces[1].vertices = square_at_z(1.0, true);
    let below = camera(dvec3(0.0, 0.0, 0.5), DVec3::ZERO, 20.0, 3);
    let dark = path_trace(&flipped, &below, &settings, &NoProgress).unwrap();
    assert!(dark.film().samples().iter().all(|s| *s == [0.0; 3]));
    // One path: an escaping ray makes no bounce and returns black.
    let tracer = PathTracer::new(&s).unwrap();
    let mut rng = super::sampling::pixel_rng(1, 0);
    let path = tracer.sample(dvec3(5.0, 0.0, 0.5), DVec3::X, &settings, &mut rng);
    assert_eq!(
        path,
        PathSample {
            radiosity: Rgb::BLACK,
            sees_emitter: false,
            bounces: 0
        }
    );
}

#[test]
fn a_seed_gives_the_same_image_on_any_number_of_threads() {
    let s = crate::scene::cornell_box().scene;
    let cam = Camera::for_scene(&s, 12, 10);
    let settings = PathTraceSettings::DEFAULT.with_samples(6).with_seed(42);
    let on = |threads: usize, settings: &PathTraceSettings| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| path_trace(&s, &cam, settings, &NoProgress).unwrap())
    };
    let bits = |v: &PathTraced| -> Vec<u64> {
        let film = v.film().samples().iter().flatten();
        let se = v.standard_errors().iter().flat_map(|s| s.0.iter());
        film.chain(se).map(|x| x.to_bits()).collect()
    };
    let one = on(1, &settings);
    let three = on(3, &settings);
    assert_eq!(bits(&one), bits(&three));
    assert_eq!(one.emitter_mask(), three.emitter_mask());
    let other = on(2, &settings.with_seed(43));
    let differing = bits(&one)
        .iter()
        .zip(bits(&other))
        .filter(|(a, b)| **a != *b)
        .count();
    assert!(differing > bits(&one).len() / 2, "{differing}");
}

#[test]
fn the_emitter_pixels_depend_on_the_view_alone() {
    // QA of issue #16: the pixels left out as showing an emitter changed with --paths and
    // --max-bounces (a path's first hit decided). Now a fixed grid of rays decides.
    let s = crate::scene::cornell_box().scene;
    let cam = Camera::for_scene(&s, 32, 32);
    let mask = |settings: &PathTraceSettings| {
        path_trace(&s, &cam, settings, &NoProgress)
            .unwrap()
            .emitter_mask()
            .to_vec()
    };
    let base = mask(&PathTraceSettings::DEFAULT.with_samples(2));
    assert!(
        base.iter().any(|&e| e),
        "the Cornell box's light is in view"
    );
    // An emitter behind the eye, facing it, changes nothing it cannot be seen from
    // (review of issue #16: its outline, not in front of the eye, marked every pixel beside
    // the light's).
    let mut behind = s.clone();
    let z = cam.eye.z - 100.0;
    behind.surfaces.push(surface(
        "behind",
        Rgb::splat(5.0),
        Rgb::splat(0.0),
        vec![
            DVec3::new(0.0, 0.0, z),
            DVec3::new(556.0, 0.0, z),
            DVec3::new(556.0, 548.0, z),
            DVec3::new(0.0, 548.0, z),
        ],
    ));
    let n = crate::geometry::polygon_normal(&behind.surfaces.last().unwrap().vertices).unwrap();
    assert!(n.z > 0.5, "faces the eye's back: {n}");
    let behind_mask = path_trace(
        &behind,
        &cam,
        &PathTraceSettings::DEFAULT.with_samples(2),
        &NoProgress,
    )
    .unwrap()
    .emitter_mask()
    .to_vec();
    assert_eq!(behind_mask, base);
    for settings in [
        PathTraceSettings::DEFAULT.with_samples(64),
        PathTraceSettings::DEFAULT.with_samples(16).with_seed(7),
        PathTraceSettings {
            max_bounces: 0,
            ..PathTraceSettings::DEFAULT.with_samples(16)
        },
    ] {
        assert_eq!(mask(&settings), base);
    }
}

#[test]
fn progress_is_one_unit_a_row() {
    use crate::progress::Stage;
    use std::sync::atomic::{AtomicU64, Ordering};
    struct Count(AtomicU64, AtomicU64);
    impl Progress for Count {
        fn start(&self, stage: Stage, total: u64) {
            assert_eq!(stage, Stage::PathTrace);
            self.0.store(total, Ordering::SeqCst);
        }
        fn advance(&self, done: u64) {
            self.1.fetch_add(done, Ordering::SeqCst);
        }
        fn finish(&self, _: Stage, _: std::time::Duration) {}
    }
    let s = receiver_under_light();
    let count = Count(AtomicU64::new(0), AtomicU64::new(0));
    let cam = Camera {
        width: 5,
        height: 7,
        ..camera(dvec3(0.0, 0.0, 0.5), DVec3::ZERO, 60.0, 0)
    };
    let view = path_trace(
        &s,
        &cam,
        &PathTraceSettings::DEFAULT.with_samples(2),
        &count,
    )
    .unwrap();
    assert_eq!((view.width(), view.height()), (5, 7));
    assert_eq!(count.0.load(Ordering::SeqCst), 7);
    assert_eq!(count.1.load(Ordering::SeqCst), 7);
    // No pixels: an empty view at once.
    let empty = path_trace(
        &s,
        &Camera { width: 0, ..cam },
        &PathTraceSettings::DEFAULT,
        &NoProgress,
    )
    .unwrap();
    assert_eq!((empty.width(), empty.height()), (0, 7));
}

#[test]
fn nonsense_requests_are_refused() {
    let s = receiver_under_light();
    let cam = camera(dvec3(0.0, 0.0, 0.5), DVec3::ZERO, 60.0, 4);
    let ok = PathTraceSettings::DEFAULT.with_samples(2);
    assert_eq!(
        path_trace(&s, &cam, &ok.with_samples(0), &NoProgress),
        Err(PathTraceError::TooFewSamples {
            samples_per_pixel: 0
        })
    );
    for fov in [0.0, 180.0, f64::NAN] {
        let bad = Camera {
            fov_y_degrees: fov,
            ..cam
        };
        assert!(matches!(
            path_trace(&s, &bad, &ok, &NoProgress),
            Err(PathTraceError::BadCamera { .. })
        ));
    }
    let nan_eye = Camera {
        eye: DVec3::NAN,
        ..cam
    };
    assert!(matches!(
        path_trace(&s, &nan_eye, &ok, &NoProgress),
        Err(PathTraceError::BadCamera { .. })
    ));
    let mut white = s.clone();
    white.surfaces[0].reflectance = Rgb::splat(1.0);
    assert!(matches!(
        path_trace(&white, &cam, &ok, &NoProgress),
        Err(PathTraceError::Light(_))
    ));
    let mut flat = s.clone();
    flat.surfaces[1].vertices = vec![DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
    assert_eq!(
        path_trace(&flat, &cam, &ok, &NoProgress).err(),
        Some(PathTraceError::Degenerate {
            surface: 1,
            name: "light".into()
        })
    );
}

#[test]
fn a_view_compared_with_itself_and_its_noise() {
    // The comparison of a path-traced view with its own film is zero, and the noise it
    // reports is the RMS standard error over the pixels that show no emitter.
    let s = receiver_under_light();
    // From between the squares, looking along them: the receiver below, the light above.
    let cam = camera(dvec3(0.0, 0.0, 0.5), dvec3(1.0, 0.0, 0.5), 120.0, 6);
    let view = path_trace(
        &s,
        &cam,
        &PathTraceSettings::DEFAULT.with_samples(64),
        &NoProgress,
    )
    .unwrap();
    let mask = view.emitter_mask();
    assert!(mask.iter().any(|&m| m) && mask.iter().any(|&m| !m));
    let c = view.compare(view.film()).unwrap();
    assert_eq!((c.rms, c.bias, c.max), (0.0, 0.0, 0.0));
    assert_eq!(c.pixels + c.excluded, 36);
    let noise = view.noise();
    assert_eq!(noise.pixels, c.pixels);
    let expected = noise.rms_standard_error / c.reference_rms_luminance;
    assert!((c.reference_noise.unwrap() - expected).abs() < 1e-12);
}

#[test]
fn the_renderers_emitter_pixels_are_left_out_too() {
    // From halfway between the squares, a 60 degree view straight up sees only the light
    // (its corner rays reach z = 1 at 0.41 from the axis, inside the half-width 0.5), and
    // straight down only the receiver: the renderer's mask is every pixel, then none.
    let s = receiver_under_light();
    let mesh = crate::mesh::mesh_scene(&s, 0.25).unwrap();
    let renderer = crate::render::Renderer::new(&mesh);
    let eye = dvec3(0.0, 0.0, 0.5);
    let up = camera(eye, dvec3(0.0, 0.0, 1.0), 60.0, 8);
    let down = camera(eye, dvec3(0.0, 0.0, 0.0), 60.0, 8);
    assert_eq!(emitter_pixels(&renderer, &s, &up, 2), vec![true; 64]);
    assert_eq!(emitter_pixels(&renderer, &s, &down, 3), vec![false; 64]);
    // compare_excluding leaves out the union of its mask and the path tracer's own.
    let view = path_trace(
        &s,
        &camera(eye, dvec3(1.0, 0.0, 0.5), 120.0, 8),
        &PathTraceSettings::DEFAULT.with_samples(4),
        &NoProgress,
    )
    .unwrap();
    let own = view.emitter_mask().iter().filter(|&&e| e).count();
    assert!(own > 0 && own < 63, "{own}");
    let mut mask = vec![false; 64];
    let extra = view.emitter_mask().iter().position(|&e| !e).unwrap();
    mask[extra] = true;
    let c = view.compare_excluding(view.film(), &mask).unwrap();
    assert_eq!((c.excluded, c.pixels), (own + 1, 63 - own));
    assert_eq!(view.compare(view.film()).unwrap().excluded, own);
    assert!(!c.all_emitters);
    // Every pixel left out between the two masks: every pixel is compared, and the
    // comparison says so (QA pass 18 of #16: "0 showing an emitter left out").
    let c = view.compare_excluding(view.film(), &[true; 64]).unwrap();
    assert!(c.all_emitters && c.excluded == 0 && c.pixels == 64, "{c:?}");
    assert!(matches!(
        view.compare_excluding(view.film(), &mask[..10]),
        Err(FilmCompareError::Mask {
            mask: 10,
            pixels: 64
        })
    ));
}

/// What a path-traced Cornell box costs, and how far the radiosity renderer's view of it
/// is from the path tracer's (a measurement, not a check; run it with
/// `cargo test -p radiosity --release --lib cornell_box_cost -- --ignored --nocapture`).
#[test]
#[ignore]
fn cornell_box_cost() {
    use crate::render::{Renderer, Shading};
    use crate::{pipeline, Prepared, SolveRequest, Solver};
    let file = crate::scene::cornell_box();
    let scene = file.scene;
    let camera = Camera::for_scene(&scene, 64, 64);
    let mut last = None;
    for samples in [64, 256, 1024] {
        for nee in [false, true] {
            let mut settings = PathTraceSettings::DEFAULT.with_samples(samples);
            settings.next_event_estimation = nee;
            let start = std::time::Instant::now();
            let view = path_trace(&scene, &camera, &settings, &NoProgress).unwrap();
            let noise = view.noise();
            eprintln!(
                "64 x 64, {samples} paths a pixel, light samples {nee}: {:.2} s, mean standard \
                 error of luminance {:.5} (mean luminance {:.4}), relative RMS noise {:.4}",
                start.elapsed().as_secs_f64(),
                noise.mean_standard_error,
                noise.mean_luminance,
                noise.relative()
            );
            if nee {
                last = Some(view);
            }
        }
    }
    let view = last.unwrap();
    let prepared = Prepared::new(scene, file.settings, &NoProgress).unwrap();
    let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
    let solution = pipeline::solve(
        &prepared,
        &request,
        &mut crate::solve::keep_going,
        &NoProgress,
    )
    .unwrap();
    let b = solution.element_rgb();
    let vertex_b = crate::shade::vertex_radiosity(&solution.mesh, b);
    let renderer = Renderer::new(&solution.mesh);
    for shading in [Shading::Flat, Shading::Smooth] {
        let film = renderer.film(&camera, b, &vertex_b, shading, 4, &NoProgress);
        let c = view.compare(&film).unwrap();
        eprintln!(
            "radiosity ({} elements, {shading:?}, 4 x 4 rays a pixel) against the path \
             tracer: RMS {:.4}, bias {:+.4}, max {:.3}, path tracer's noise {:.4}, RMS less \
             noise {:.4}, {} pixels ({} showing the light left out)",
            solution.mesh.len(),
            c.rms,
            c.bias,
            c.max,
            c.reference_noise.unwrap(),
            c.rms_less_noise(),
            c.pixels,
            c.excluded
        );
        if let Some(dir) = std::env::var_os("RADIOSITY_TEST_IMAGE_DIR") {
            let dir = std::path::PathBuf::from(dir);
            let map = c.error_map.to_image(DEFAULT_ERROR_FULL_SCALE);
            map.save(dir.join(format!("pathtrace-error-{shading:?}.png")))
                .unwrap();
            let scale =
                crate::render::tonemap::Exposure::Auto.scale(&prepared.scene, &solution.mesh, b);
            let tone = |f: &crate::render::Film| crate::render::tonemap::to_image(f, scale, 2.2);
            tone(view.film()).save(dir.join("pathtrace.png")).unwrap();
            tone(&film)
                .save(dir.join(format!("radiosity-{shading:?}.png")))
                .unwrap();
        }
    }
}

#[test]
fn the_area_exposure_of_a_furnace_is_its_closed_form() {
    // Every surface emits E and reflects rho, so every point's radiosity is E / (1 - rho)
    // and, every surface emitting, all of them count: white is E / (1 - rho) = 2 (largest
    // band 1 / 0.5). The top 82 of 4096 points, 64 paths each: a path's estimate has a
    // relative standard deviation of about 0.7 here (rho 0.5, roulette), so their mean
    // about 0.7 / sqrt(82 x 64) = 1 %; 4 % is four of those.
    let s = furnace(Rgb([1.0, 0.5, 0.25]), Rgb::splat(0.5));
    let tracer = PathTracer::new(&s).unwrap();
    let scale = tracer.area_exposure_scale(
        &s,
        &PathTraceSettings::DEFAULT,
        EXPOSURE_POINTS,
        EXPOSURE_PATHS,
    );
    assert!((scale * 2.0 - 1.0).abs() < 0.04, "{scale}");
    // The same seed, the same scale.
    let again = tracer.area_exposure_scale(
        &s,
        &PathTraceSettings::DEFAULT,
        EXPOSURE_POINTS,
        EXPOSURE_PATHS,
    );
    assert_eq!(scale, again);
}

#[test]
fn the_area_exposure_agrees_with_the_radiosity_render_of_the_cornell_box() {
    // Issue #11: the view's own brightest 2 % of pixels gave the Cornell box twice the
    // radiosity render's exposure (0.96 against 0.50). The rule the renderer uses, read by
    // paths at points instead of from element radiosities: an independent estimate. Measured
    // 0.4949 against 0.5021 (1.4 %); the two differ by the mesh's averaging over elements,
    // the buried floor under the blocks that the mesh drops (2.4 % of the area) and the
    // paths' noise (about 1 %), so 4 %.
    let box_ = crate::scene::cornell_box();
    let prepared =
        crate::pipeline::Prepared::new(box_.scene.clone(), box_.settings, &NoProgress).unwrap();
    let solution = crate::pipeline::solve(
        &prepared,
        &crate::pipeline::SolveRequest::new(crate::solve::Solver::DEFAULT_GAUSS_SEIDEL),
        &mut |_| std::ops::ControlFlow::Continue(()),
        &NoProgress,
    )
    .unwrap();
    let radiosity = crate::render::tonemap::Exposure::Auto.scale(
        &prepared.scene,
        &solution.mesh,
        solution.element_rgb(),
    );
    let traced = PathTracer::new(&box_.scene).unwrap().area_exposure_scale(
        &box_.scene,
        &PathTraceSettings::DEFAULT,
        EXPOSURE_POINTS,
        EXPOSURE_PATHS,
    );
    assert!(
        (traced / radiosity - 1.0).abs() < 0.04,
        "{traced} {radiosity}"
    );
}
