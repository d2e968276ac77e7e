//! Tests of the dense solvers and the energy account against closed forms.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::residual::max_abs_emission;
use super::*;
use crate::light::ElementLight;
use crate::progress::NoProgress;
use crate::scene::Scene;

/// Solves with `solver` from B = E, no observer.
fn run(
    f: &FormFactorMatrix,
    rho: &[[f64; 3]],
    e: &[[f64; 3]],
    solver: DenseSolver,
) -> Result<(Radiosity, SolveReport), SolveError> {
    let light = ElementLight::from_arrays(rho, e).unwrap();
    solve(f, &light, &solver, None, &mut keep_going, &NoProgress)
}

/// rho and E as checked element light.
fn light(rho: &[[f64; 3]], e: &[[f64; 3]]) -> ElementLight {
    ElementLight::from_arrays(rho, e).unwrap()
}

/// The tests' seeded generator.
pub fn rng(seed: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(seed)
}

/// A random reciprocal form-factor matrix: random areas, a random symmetric coupling
/// G_ij = G_ji >= 0 (zero diagonal), F_ij = G_ij / A_i, scaled so the largest row sum is
/// `max_row_sum`. Returns (F, areas). Reciprocity holds up to f32 rounding of F.
pub fn random_reciprocal(n: usize, max_row_sum: f64, seed: u64) -> (FormFactorMatrix, Vec<f64>) {
    let mut rng = rng(seed);
    let areas: Vec<f64> = (0..n).map(|_| 0.5 + rng.random::<f64>()).collect();
    let mut g = vec![0.0f64; n * n];
    for i in 0..n {
        for j in i + 1..n {
            // Sparse-ish: about a third of the pairs see each other.
            let v = if rng.random::<f64>() < 0.35 {
                rng.random::<f64>()
            } else {
                0.0
            };
            g[i * n + j] = v;
            g[j * n + i] = v;
        }
    }
    let worst = (0..n)
        .map(|i| g[i * n..(i + 1) * n].iter().sum::<f64>() / areas[i])
        .fold(0.0, f64::max);
    let scale = max_row_sum / worst;
    let data = (0..n * n)
        .map(|k| (g[k] * scale / areas[k / n]) as f32)
        .collect();
    (FormFactorMatrix::from_rows(n, data), areas)
}

fn gs(tolerance: f64) -> DenseSolver {
    DenseSolver::GaussSeidel(GaussSeidelSettings {
        tolerance,
        max_iterations: 100_000,
    })
}

/// Four equal-area elements in a closed configuration: F symmetric (reciprocal for equal
/// areas) with dyadic entries, so every row sums to exactly 1 even in f32.
fn closed_four() -> FormFactorMatrix {
    #[rustfmt::skip]
    let data = vec![
        0.0, 0.5, 0.25, 0.25,
        0.5, 0.0, 0.25, 0.25,
        0.25, 0.25, 0.0, 0.5,
        0.25, 0.25, 0.5, 0.0,
    ];
    FormFactorMatrix::from_rows(4, data)
}

#[test]
fn furnace_gives_e_over_one_minus_rho() {
    let f = closed_four();
    for i in 0..4 {
        assert_eq!(f.row_sum(i), 1.0);
    }
    let rho = [[0.5, 0.8, 0.2]; 4];
    let e = [[1.0, 2.0, 3.0]; 4];
    for solver in [DenseSolver::Lu, gs(1e-13)] {
        let (b, report) = run(&f, &rho, &e, solver).unwrap();
        for i in 0..4 {
            for band in 0..3 {
                let expected = e[i][band] / (1.0 - rho[i][band]);
                // LU: the system's condition number is at most (1 + rho)/(1 - rho) = 9,
                // so rounding stays near 1e-15; Gauss-Seidel stops at a relative residual
                // of 1e-13, and the error is at most condition x residual ~ 1e-12.
                let err = (b.0[i][band] - expected).abs() / expected;
                assert!(err < 1e-11, "{solver}: element {i} band {band}: {err:e}");
            }
        }
        assert!(report.residual.iter().all(|&r| r < 1e-12), "{report:?}");
        assert_eq!(report.iterations.is_some(), solver != DenseSolver::Lu);
    }
}

#[test]
fn two_opposed_squares_match_closed_form() {
    // The closed form for two parallel unit squares one unit apart. The matrix holds it
    // in f32, so the expected values use the same f32-rounded value.
    let f = 0.1998249f32 as f64;
    let matrix = FormFactorMatrix::from_rows(2, vec![0.0, f as f32, f as f32, 0.0]);
    let rho = [[0.7, 0.3, 0.0], [0.4, 0.9, 0.5]];
    let e = [[1.0, 0.0, 2.0], [0.5, 3.0, 0.0]];
    for solver in [DenseSolver::Lu, gs(1e-14)] {
        let (b, _) = run(&matrix, &rho, &e, solver).unwrap();
        for band in 0..3 {
            let (r1, r2) = (rho[0][band], rho[1][band]);
            let (e1, e2) = (e[0][band], e[1][band]);
            let det = 1.0 - r1 * r2 * f * f;
            let b1 = (e1 + r1 * f * e2) / det;
            let b2 = (e2 + r2 * f * e1) / det;
            // A 2 x 2 system with condition number ~1.2: rounding is ~1e-16; GS stops at
            // relative residual 1e-14, so its error is about that.
            for (got, want) in [(b.0[0][band], b1), (b.0[1][band], b2)] {
                assert!(
                    (got - want).abs() <= 1e-13 * want.abs().max(1.0),
                    "{solver} band {band}: {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn lu_and_gauss_seidel_agree_on_random_matrix() {
    let n = 200;
    let (f, _) = random_reciprocal(n, 0.95, 7);
    let mut rng = rng(11);
    let rho: Vec<[f64; 3]> = (0..n)
        .map(|_| std::array::from_fn(|_| 0.9 * rng.random::<f64>()))
        .collect();
    let e: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            std::array::from_fn(|_| {
                if rng.random::<f64>() < 0.1 {
                    10.0 * rng.random::<f64>()
                } else {
                    0.0
                }
            })
        })
        .collect();
    let (lu, lu_report) = run(&f, &rho, &e, DenseSolver::Lu).unwrap();
    let (gs_b, gs_report) = run(&f, &rho, &e, gs(1e-12)).unwrap();
    assert!(
        lu_report.residual.iter().all(|&r| r < 1e-13),
        "{lu_report:?}"
    );
    assert!(
        gs_report.residual.iter().all(|&r| r < 1e-12),
        "{gs_report:?}"
    );
    let scale = max_abs_emission(Rgb::from_arrays(&e));
    for (band, s) in scale.into_iter().enumerate() {
        for i in 0..n {
            // rho <= 0.9 and row sums <= 0.95 make ||(I - rho F)^-1||_inf <= 1 / (1 -
            // 0.855) ~ 7, so a 1e-12 residual bounds the difference by ~7e-12 of max E:
            // 1e-8 leaves a wide margin, as the brief asks.
            let d = (lu.0[i][band] - gs_b.0[i][band]).abs() / s;
            assert!(d < 1e-8, "band {band} element {i}: {d:e}");
        }
    }
}

#[test]
fn grey_scene_factors_once_with_same_answer() {
    let n = 60;
    let (f, _) = random_reciprocal(n, 0.9, 3);
    let mut rng = rng(5);
    let rho: Vec<[f64; 3]> = (0..n).map(|_| [0.8 * rng.random::<f64>(); 3]).collect();
    let e: Vec<[f64; 3]> = (0..n)
        .map(|_| [rng.random::<f64>(), 2.0 * rng.random::<f64>(), 0.0])
        .collect();
    let shared = lu::solve(&f, &light(&rho, &e), true, &NoProgress);
    let separate = lu::solve(&f, &light(&rho, &e), false, &NoProgress);
    for band in 0..3 {
        for i in 0..n {
            // Same matrix, same pivots: the only difference is the order of the solves,
            // so the answers agree to rounding.
            let d = (shared.0[i][band] - separate.0[i][band]).abs();
            assert!(d < 1e-12, "band {band} element {i}: {d:e}");
        }
    }
    assert!(shared.0.iter().all(|b| b[2] == 0.0));
}

#[test]
fn zero_emission_gives_zero() {
    let f = closed_four();
    let rho = [[0.5; 3]; 4];
    let e = [[0.0; 3]; 4];
    for solver in [DenseSolver::Lu, gs(1e-9)] {
        let (b, report) = run(&f, &rho, &e, solver).unwrap();
        assert!(b.0.iter().all(|x| *x == Rgb::BLACK), "{solver}");
        assert_eq!(report.residual, [0.0; 3]);
    }
}

#[test]
fn lu_refuses_oversized_matrix_before_allocating() {
    // 3 million elements need 8 x 9e12 bytes = 72 TB of f64: refused by the check alone.
    let err = lu::check_memory(3_000_000, 64 << 30).unwrap_err();
    assert_eq!(err.what, "the LU matrix (f64)");
    assert_eq!(err.n, 3_000_000);
    // Through the solver: 1 KiB cannot hold a 20 x 20 f64 matrix (3.5 KiB with headroom).
    let (f, _) = random_reciprocal(20, 0.5, 1);
    let rho = vec![[0.5; 3]; 20];
    let e = vec![[1.0; 3]; 20];
    let err = solve_with_memory(
        &f,
        &light(&rho, &e),
        &DenseSolver::Lu,
        None,
        &mut keep_going,
        &NoProgress,
        1024,
    )
    .unwrap_err();
    let SolveError::OutOfMemory(oom) = &err else {
        panic!("{err:?}")
    };
    assert_eq!(oom.what, "the LU matrix (f64)");
    assert!(err.to_string().contains("20 elements"), "{err}");
}

#[test]
fn gauss_seidel_reports_non_convergence() {
    let f = closed_four();
    let rho = [[0.99; 3]; 4];
    let e = [[1.0; 3]; 4];
    let solver = DenseSolver::GaussSeidel(GaussSeidelSettings {
        tolerance: 1e-12,
        max_iterations: 3,
    });
    let err = run(&f, &rho, &e, solver).unwrap_err();
    let SolveError::NotConverged {
        iterations,
        residual,
        ..
    } = err
    else {
        panic!("{err:?}")
    };
    assert_eq!(iterations, 3);
    assert!(residual > 1e-12);
}

#[test]
fn bad_inputs_are_refused() {
    use crate::light::{BadLight, LightError};
    let f = closed_four();
    let e = [[1.0; 3]; 4];
    let mut rho = [[0.5; 3]; 4];
    // Light for three elements on a four-element matrix.
    let three = light(&rho[..3], &e[..3]);
    assert!(matches!(
        solve(
            &f,
            &three,
            &DenseSolver::Lu,
            None,
            &mut keep_going,
            &NoProgress
        ),
        Err(SolveError::LengthMismatch { n: 4, len: 3, .. })
    ));
    // Bad values are refused once, when the element light is built.
    rho[2][1] = 1.0;
    assert!(matches!(
        ElementLight::from_arrays(&rho, &e),
        Err(LightError::Bad(BadLight {
            element: 2,
            band: 1,
            ..
        }))
    ));
    rho[2][1] = 0.5;
    assert!(matches!(
        run(&f, &rho, &e, gs(0.0)),
        Err(SolveError::BadSettings { value: 0.0, .. })
    ));
}

#[test]
fn energy_is_conserved() {
    // Closed scene: nothing escapes and everything emitted is absorbed.
    let f = closed_four();
    let areas = [2.0; 4];
    let rho = [
        [0.5, 0.1, 0.9],
        [0.2, 0.3, 0.4],
        [0.0, 0.6, 0.7],
        [0.8, 0.8, 0.1],
    ];
    let e = [[1.0, 0.0, 0.5], [0.0; 3], [0.0, 4.0, 0.0], [0.0; 3]];
    let (b, _) = run(&f, &rho, &e, DenseSolver::Lu).unwrap();
    let bal = energy_balance(&f, &areas, &light(&rho, &e), b.as_slice());
    assert_eq!(bal.escaped, [0.0; 3]);
    assert_eq!(bal.emitted, [2.0, 8.0, 1.0]);
    // Exact arithmetic would balance exactly; LU rounding (~1e-16 relative, condition
    // number below 20 at rho = 0.9) leaves errors near 1e-15.
    assert!(bal.relative_error() < 1e-12, "{bal:?}");

    // Open random scene with reciprocal F: a real split between absorbed and escaped.
    let n = 100;
    let (f, areas) = random_reciprocal(n, 0.8, 21);
    let mut rng = rng(2);
    let rho: Vec<[f64; 3]> = (0..n)
        .map(|_| std::array::from_fn(|_| 0.95 * rng.random::<f64>()))
        .collect();
    let e: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            if i % 10 == 0 {
                [1.0, 2.0, 3.0]
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let (b, _) = run(&f, &rho, &e, gs(1e-12)).unwrap();
    let bal = energy_balance(&f, &areas, &light(&rho, &e), b.as_slice());
    for band in 0..3 {
        assert!(bal.escaped[band] > 0.1 * bal.emitted[band], "{bal:?}");
        assert!(bal.absorbed[band] > 0.1 * bal.emitted[band], "{bal:?}");
    }
    // F is reciprocal only up to f32 rounding of its entries (relative 6e-8), and GS
    // stops at residual 1e-12: the balance holds to about 1e-7 relative.
    assert!(bal.relative_error() < 1e-6, "{bal:?}");
}

#[test]
fn scene_convenience_uses_surface_properties() {
    use crate::mesh::mesh_scene;
    use crate::scene::{Rgb, Surface};
    use glam::dvec3;
    // Two unit squares facing each other one unit apart (one element each).
    let bottom = vec![
        dvec3(0., 0., 0.),
        dvec3(1., 0., 0.),
        dvec3(1., 1., 0.),
        dvec3(0., 1., 0.),
    ];
    let top: Vec<_> = bottom
        .iter()
        .rev()
        .map(|v| *v + dvec3(0., 0., 1.))
        .collect();
    let scene = Scene {
        surfaces: vec![
            Surface {
                name: "light".into(),
                emission: Rgb([1.0, 2.0, 3.0]),
                reflectance: Rgb([0.1, 0.2, 0.3]),
                vertices: bottom,
                photometry: Default::default(),
            },
            Surface {
                name: "ceiling".into(),
                emission: Rgb::BLACK,
                reflectance: Rgb([0.5, 0.6, 0.7]),
                vertices: top,
                photometry: Default::default(),
            },
        ],
        camera: None,
        lights: Vec::new(),
    };
    let mesh = mesh_scene(&scene, 1.0).unwrap();
    assert_eq!(mesh.len(), 2);
    let f = 0.1998249f32;
    let matrix = FormFactorMatrix::from_rows(2, vec![0.0, f, f, 0.0]);
    let light = ElementLight::of_mesh(&mesh, &scene).unwrap();
    let (b, _) = solve(
        &matrix,
        &light,
        &DenseSolver::Lu,
        None,
        &mut keep_going,
        &NoProgress,
    )
    .unwrap();
    let f = f as f64;
    for band in 0..3 {
        let (r1, r2) = (0.1 * (band + 1) as f64, 0.5 + 0.1 * band as f64);
        let e1 = (band + 1) as f64;
        let b1 = e1 / (1.0 - r1 * r2 * f * f);
        // A well-conditioned 2 x 2 system: rounding only.
        assert!((b.0[0][band] - b1).abs() < 1e-13, "band {band}");
        assert!((b.0[1][band] - r2 * f * b1).abs() < 1e-13, "band {band}");
    }
}

#[test]
fn closed_cube_with_computed_form_factors_stays_within_furnace_bounds() {
    use crate::form_factor::{
        compute_matrix, occluder_bvh, FormFactorContext, FormFactorMethod, RayCounter,
    };
    use crate::io::form_factor_file::{mesh_fingerprint, read_form_factors, write_form_factors};
    use crate::mesh::mesh_scene;
    use crate::scene::{Rgb, Surface};
    use glam::{dvec3, DVec3};
    // The unit cube seen from inside: each face's front (u x v) points inwards.
    let face = |a: DVec3, u: DVec3, v: DVec3| vec![a, a + u, a + u + v, a + v];
    let (o, x, y, z) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
    let faces = [
        face(o, x, y),
        face(z, y, x),
        face(o, y, z),
        face(x, z, y),
        face(o, z, x),
        face(y, x, z),
    ];
    let (rho, e) = (0.5, 1.0);
    let scene = Scene {
        surfaces: faces
            .into_iter()
            .enumerate()
            .map(|(i, vertices)| Surface {
                name: format!("face{i}"),
                emission: Rgb([e; 3]),
                reflectance: Rgb([rho; 3]),
                vertices,
                photometry: Default::default(),
            })
            .collect(),
        camera: None,
        lights: Vec::new(),
    };
    assert_eq!(scene.surfaces[1].vertices[1], dvec3(0., 1., 1.));
    let mesh = mesh_scene(&scene, 0.25).unwrap();
    assert_eq!(mesh.len(), 24);
    let bvh = occluder_bvh(&scene);
    let ctx = FormFactorContext {
        mesh: &mesh,
        occluders: &bvh,
    };
    let method = FormFactorMethod::AreaIntegral { steps: 2 };
    let f = compute_matrix(&ctx, method, &RayCounter::default(), &NoProgress).unwrap();
    let areas: Vec<f64> = mesh.elements.iter().map(|e| e.area).collect();
    let sums = f.row_sums(&areas);
    // k = 2 on elements that touch along edges is coarse; the bounds below hold for any
    // row sums, this only checks that the test is not vacuous.
    assert!(sums.min > 0.8 && sums.max < 1.2, "{sums:?}");

    // Through the form-factor file, as `--form-factors` would.
    let dir = std::env::temp_dir().join(format!("radiosity-cube-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cube.ff");
    let fp = mesh_fingerprint(&mesh);
    write_form_factors(&path, &f, fp, &method.to_string()).unwrap();
    let back = read_form_factors(&path, fp, Some("area k=2".parse().unwrap())).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(back, f);

    for solver in [DenseSolver::Lu, gs(1e-12)] {
        let light = ElementLight::of_mesh(&mesh, &scene).unwrap();
        let (b, _) = solve(&back, &light, &solver, None, &mut keep_going, &NoProgress).unwrap();
        // Max principle for B = E + rho F B with F >= 0 and uniform E, rho: every B_i lies
        // between E / (1 - rho s_min) and E / (1 - rho s_max). Slack 1e-9 covers the GS
        // tolerance (1e-12 relative residual, amplified at most 1 / (1 - 0.6) times).
        let lo = e / (1.0 - rho * sums.min) - 1e-9;
        let hi = e / (1.0 - rho * sums.max) + 1e-9;
        for (i, bi) in b.band(1).enumerate() {
            assert!(
                lo <= bi && bi <= hi,
                "{solver}: B_{i} = {bi} not in [{lo}, {hi}]"
            );
        }
        for (r, g) in b.band(0).zip(b.band(1)) {
            // Identical inputs per band; LU solves them as columns of one right-hand
            // side, which may round differently, so allow a few ulps.
            assert!((r - g).abs() < 1e-14 * g, "{solver}: {r} vs {g}");
        }
    }
}

/// [`closed_four`] with every entry times `scale`: rows sum to `scale`.
fn closed_four_scaled(scale: f32) -> FormFactorMatrix {
    FormFactorMatrix::from_rows(
        4,
        closed_four().as_slice().iter().map(|f| f * scale).collect(),
    )
}

#[test]
fn every_dense_solver_refuses_nan_and_infinite_form_factors() {
    let (rho, e) = ([[0.5; 3]; 4], [[1.0; 3]; 4]);
    for bad in [f32::NAN, f32::INFINITY, -0.5] {
        let mut data = closed_four().as_slice().to_vec();
        data[4 + 2] = bad;
        let f = FormFactorMatrix::from_rows(4, data);
        for solver in [DenseSolver::Lu, gs(1e-9)] {
            let err = run(&f, &rho, &e, solver).unwrap_err();
            assert!(
                matches!(err, SolveError::FormFactor(ref x) if (x.row, x.col) == (1, 2)),
                "{solver} on F[1][2] = {bad}: {err:?}"
            );
        }
    }
}

#[test]
fn gauss_seidel_fails_loudly_on_divergence_instead_of_converging_to_nan() {
    // Rows summing to 5,230 (the forged file of issue 12) with rho = 0.5: each sweep
    // multiplies B by about 2,615, so NaN or infinity would follow within 90 sweeps.
    let f = closed_four_scaled(5230.0);
    let err = run(&f, &[[0.5; 3]; 4], &[[1.0; 3]; 4], gs(1e-9)).unwrap_err();
    assert!(matches!(err, SolveError::Diverged { .. }), "{err:?}");
    assert!(err.to_string().contains("Gauss-Seidel diverged"), "{err}");
    // Rows summing to 1.5 with rho 0.6 bound B (rho s = 0.9 < 1): the guard must not fire.
    let (f, _) = random_reciprocal(40, 1.5, 7);
    let (rho, e) = (vec![[0.6; 3]; 40], vec![[1.0; 3]; 40]);
    for solver in [DenseSolver::Lu, gs(1e-9)] {
        assert!(run(&f, &rho, &e, solver).is_ok(), "{solver}");
    }
}

#[test]
fn lu_refuses_the_finite_but_unphysical_solution_of_a_divergent_system() {
    // (I - rho F) B = E with rows summing to 5,230 has the finite solution
    // B = E / (1 - 0.5 x 5230) < 0: below the emission, which no convergent system gives.
    let f = closed_four_scaled(5230.0);
    let err = run(&f, &[[0.5; 3]; 4], &[[1.0; 3]; 4], DenseSolver::Lu).unwrap_err();
    assert!(matches!(err, SolveError::Diverged { .. }), "{err:?}");
    assert!(err.to_string().contains("below its emission"), "{err}");
}

#[test]
fn gauss_seidel_never_reads_nan_radiosity_as_converged() {
    // A NaN start (a warm start from a broken solution) must fail, not report residual 0.
    let f = closed_four();
    let light = light(&[[0.5; 3]; 4], &[[1.0; 3]; 4]);
    let mut start = vec![Rgb([1.0; 3]); 4];
    start[3] = Rgb([f64::NAN, 1.0, 1.0]);
    let err = solve(
        &f,
        &light,
        &gs(1e-9),
        Some(&start),
        &mut keep_going,
        &NoProgress,
    )
    .unwrap_err();
    assert!(
        matches!(err, SolveError::NotFinite { element: 3, .. }),
        "{err:?}"
    );
}
