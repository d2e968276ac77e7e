//! Progressive refinement against closed forms and the independent dense solve.

use std::ops::ControlFlow;

use radiosity::form_factor::{
    compute_rows, FormFactorContext, FormFactorMatrix, FormFactorMethod, RayCounter, RowComputer,
};
use radiosity::light::ElementLight;
use radiosity::progress::NoProgress;
use radiosity::scene::{cornell_box, Rgb, Scene};
use radiosity::solve::{
    energy_balance, keep_going, solve, solve_progressive, DenseSolver, GaussSeidelSettings,
    ProgressiveReport, ProgressiveSettings, Radiosity, SolveError, Step,
};

use crate::fixtures::{element_areas, lit_closed_cube, Meshed};

/// A closed unit cube, every face facing in, rho (0.5, 0.3, 0.7) everywhere; `emit` gives
/// each face's emission.
fn unit_cube(emit: impl Fn(usize) -> [f64; 3]) -> Scene {
    lit_closed_cube(emit, [0.5, 0.3, 0.7])
}

/// A meshed scene with its light, and the per-element values the tests check against.
struct Setup {
    meshed: Meshed,
    light: ElementLight,
    rho: Vec<Rgb>,
    e: Vec<Rgb>,
    areas: Vec<f64>,
}

fn setup(scene: &Scene, max_area: f64) -> Setup {
    let meshed = Meshed::new(scene, max_area);
    let light = ElementLight::of_mesh(&meshed.mesh, scene).unwrap();
    let (rho, e) = (light.reflectance().to_vec(), light.emission().to_vec());
    let areas = element_areas(&meshed.mesh);
    Setup {
        meshed,
        light,
        rho,
        e,
        areas,
    }
}

impl Setup {
    fn ctx(&self) -> FormFactorContext<'_> {
        self.meshed.ctx()
    }

    /// The number of elements.
    fn n(&self) -> usize {
        self.meshed.mesh.len()
    }

    fn progressive(
        &self,
        method: FormFactorMethod,
        tolerance: f64,
    ) -> (Radiosity, ProgressiveReport, Vec<f64>) {
        let mut fractions = Vec::new();
        let (b, report) = solve_progressive(
            &self.ctx(),
            method,
            &self.light,
            &ProgressiveSettings {
                tolerance,
                max_shots: 1_000_000,
            },
            &mut |step| {
                if let Step::Shot(s) = step {
                    fractions.push(s.unshot_fraction);
                }
                ControlFlow::Continue(())
            },
            &NoProgress,
        )
        .unwrap();
        (b, report, fractions)
    }

    fn dense(&self, method: FormFactorMethod) -> FormFactorMatrix {
        self.meshed.matrix(method)
    }

    fn gauss_seidel(&self, f: &FormFactorMatrix) -> Radiosity {
        let solver = DenseSolver::GaussSeidel(GaussSeidelSettings {
            tolerance: 1e-13,
            max_iterations: 100_000,
        });
        solve(f, &self.light, &solver, None, &mut keep_going, &NoProgress)
            .unwrap()
            .0
    }
}

/// max_i |a_i - b_i| / max_i |b_i| over all bands.
fn max_relative_difference(a: &Radiosity, b: &Radiosity) -> f64 {
    let scale = b
        .as_arrays()
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    a.as_arrays()
        .iter()
        .flatten()
        .zip(b.as_arrays().iter().flatten())
        .map(|(x, y)| (x - y).abs() / scale)
        .fold(0.0, f64::max)
}

/// The Cornell box at about 200 elements.
fn small_cornell() -> (Scene, f64) {
    (cornell_box().scene, 10_000.0)
}

#[test]
fn row_computer_matches_compute_rows() {
    // ~650 elements, so the pair methods take the chunked parallel path (chunks of 256).
    let scene = cornell_box().scene;
    let s = setup(&scene, 3_000.0);
    let n = s.n();
    assert!(n > 512, "{n}");
    let ctx = s.ctx();
    for method in [
        FormFactorMethod::AreaIntegral { steps: 1 },
        FormFactorMethod::Contour { steps: 1 },
        FormFactorMethod::Hemicube { resolution: 16 },
        FormFactorMethod::MonteCarlo {
            samples: 16,
            seed: 3,
        },
    ] {
        let mut rows = RowComputer::new(&ctx, method);
        assert_eq!(rows.n(), n);
        for i in [0, 1, n / 2, n - 1] {
            let rays = RayCounter::default();
            let row: Vec<f32> = rows.row(i, &rays).into_iter().map(|f| f as f32).collect();
            let block = compute_rows(&ctx, method, i..i + 1, &RayCounter::default());
            // The same code per entry, only split differently over threads: identical.
            assert_eq!(row, block.data, "{method} row {i}");
        }
    }
}

// Furnace: a closed cube emitting E everywhere with uniform rho. The exact (contour) form
// factors of a closed cube sum to 1 per row, so B = E / (1 - rho) for every element.
// Stopping at unshot fraction 1e-10 leaves at most 1e-10 of the emitted power to shoot;
// in this uniform case the remaining unshot radiosity is uniform too, so every B_i is low by
// about 1e-10 E / (1 - rho): 1e-8 relative covers it and the rounding of the row sums.
//
// The hemicube's rows also sum to 1 in a closed box (its delta form factors are normalised
// and every cell sees an element), so nothing escapes and the energy balance is exact; but
// progressive refinement gathers at element j through F'_ji = A_i F_ij / A_j, whose rows
// sum to 1 only as far as the hemicube is reciprocal, so its B is only within the
// hemicube's reciprocity error (about 1 % at 64 cells and 4 x 4 elements a face) of E / (1 - rho).
#[test]
fn furnace_in_closed_cube() {
    let scene = unit_cube(|_| [1.0, 2.0, 0.5]);
    let s = setup(&scene, 0.25);
    assert_eq!(s.n(), 24);
    for (method, tolerance) in [
        (FormFactorMethod::Contour { steps: 2 }, 1e-8),
        (FormFactorMethod::Hemicube { resolution: 64 }, 2e-2),
    ] {
        let (b, report, _) = s.progressive(method, 1e-10);
        assert!(report.unshot_fraction < 1e-10, "{report:?}");
        let mut worst = 0.0f64;
        for i in 0..s.n() {
            for k in 0..3 {
                let expected = s.e[i][k] / (1.0 - s.rho[i][k]);
                let got = b.0[i][k];
                worst = worst.max(((got - expected) / expected).abs());
            }
        }
        eprintln!("furnace, {method}: largest relative error {worst:.2e}");
        assert!(worst < tolerance, "{method}: {worst:e}");
        // Closed box: nothing escapes (rows sum to 1 up to rounding), so everything
        // emitted is absorbed.
        let bal = report.balance;
        for k in 0..3 {
            assert!(bal.escaped[k].abs() < 1e-9 * bal.emitted[k], "{bal:?}");
            let err = (bal.absorbed[k] + report.unshot[k] - bal.emitted[k]).abs();
            assert!(err < 1e-12 * bal.emitted[k], "{bal:?}");
        }
    }
}

// Progressive converges to the solution of B = E + rho F B for a reciprocal method (contour
// in the empty cube, area in the Cornell box, where compute_matrix fills the lower triangle
// by reciprocity). Stopping at unshot fraction 1e-6 leaves power U <= 1e-6 P to shoot; the
// radiosity it will still add is at most U / (1 - rho F) spread over the receivers, which
// for these scenes is a few times 1e-6 of the largest B (the emitter's). The dense side is
// Gauss-Seidel to a 1e-13 residual on the f32 matrix (entries rounded to 6e-8 relative), so
// 1e-5 of max B bounds the difference with margin; the measured difference is printed.
#[test]
fn agrees_with_dense_gauss_seidel() {
    let cube = unit_cube(|i| if i == 1 { [1.0, 2.0, 3.0] } else { [0.0; 3] });
    let (cornell, area) = small_cornell();
    let cases = [
        (cube, 0.25, FormFactorMethod::Contour { steps: 2 }),
        (cornell, area, FormFactorMethod::AreaIntegral { steps: 2 }),
    ];
    for (scene, max_area, method) in cases {
        let s = setup(&scene, max_area);
        let n = s.n();
        let (b, report, _) = s.progressive(method, 1e-6);
        let f = s.dense(method);
        let reference = s.gauss_seidel(&f);
        let d = max_relative_difference(&b, &reference);
        eprintln!(
            "{n} elements, {method}: {} shots, max |B_prog - B_GS| / max B = {d:.2e}",
            report.shots
        );
        assert!(d < 1e-5, "{n} elements, {method}: {d:e}");
        // Energy balance of the progressive B through the dense matrix: what is unaccounted
        // for is the unshot power (1e-6) plus the f32 reciprocity rounding of F.
        let bal = energy_balance(&f, &s.areas, &s.light, b.as_slice());
        assert!(bal.relative_error() < 1e-5, "{bal:?}");
    }
}

// The non-reciprocal hemicube: progressive shoots row i, so it solves with
// F'_ji = A_i F_ij / A_j, the reciprocal of the rows. Gauss-Seidel on F' (built from the
// dense hemicube matrix) agrees to the same 1e-5 as above.
#[test]
fn hemicube_solves_with_reciprocal_of_rows() {
    let (scene, max_area) = small_cornell();
    let s = setup(&scene, max_area);
    let n = s.n();
    let method = FormFactorMethod::Hemicube { resolution: 64 };
    let f = s.dense(method);
    let mut transposed = vec![0.0f32; n * n];
    for i in 0..n {
        for j in 0..n {
            transposed[j * n + i] = (s.areas[i] * f.get(i, j) / s.areas[j]) as f32;
        }
    }
    let f_prime = FormFactorMatrix::from_rows(n, transposed);
    let reference = s.gauss_seidel(&f_prime);
    let (b, report, _) = s.progressive(method, 1e-6);
    let d = max_relative_difference(&b, &reference);
    eprintln!(
        "hemicube, {n} elements: {} shots, difference {d:.2e}",
        report.shots
    );
    assert!(d < 1e-5, "{d:e}");
}

// emitted = absorbed + escaped + unshot, from the solver's own bookkeeping, at every
// tolerance: each shot moves power between these accounts, so only rounding (1e-12
// relative over a few thousand shots) separates them. The balance's relative error is the
// unshot fraction.
#[test]
fn energy_bookkeeping_balances() {
    let (scene, max_area) = small_cornell();
    let s = setup(&scene, max_area);
    for tolerance in [0.5, 0.01, 1e-6] {
        let (_, report, _) = s.progressive(FormFactorMethod::AreaIntegral { steps: 2 }, tolerance);
        let bal = report.balance;
        for k in 0..3 {
            let sum = bal.absorbed[k] + bal.escaped[k] + report.unshot[k];
            assert!(
                (sum - bal.emitted[k]).abs() < 1e-12 * bal.emitted[k],
                "band {k}: {bal:?} {report:?}"
            );
            // The Cornell box is open at the front: some light escapes.
            assert!(bal.escaped[k] > 0.01 * bal.emitted[k], "{bal:?}");
        }
        assert!(
            (bal.relative_error() - report.unshot_fraction).abs() < 1e-12,
            "{report:?}"
        );
        assert!(report.unshot_fraction < tolerance);
    }
}

// Every shot removes A_i dB_i from the unshot power and adds back at most
// rho_max * (row sum) * A_i dB_i < A_i dB_i, so the unshot power of each band, and hence
// its largest fraction, never grows (up to the rounding of the running sum, 1e-12).
#[test]
fn unshot_energy_decreases_monotonically() {
    let (scene, max_area) = small_cornell();
    let s = setup(&scene, max_area);
    let (_, report, fractions) = s.progressive(FormFactorMethod::Hemicube { resolution: 32 }, 1e-4);
    assert_eq!(fractions.len(), report.shots);
    assert!(fractions.len() > 10);
    for w in fractions.windows(2) {
        assert!(w[1] <= w[0] + 1e-12, "{} then {}", w[0], w[1]);
    }
    assert!(*fractions.last().unwrap() < 1e-4);
}

#[test]
fn deterministic() {
    let (scene, max_area) = small_cornell();
    let s = setup(&scene, max_area);
    for method in [
        FormFactorMethod::AreaIntegral { steps: 2 },
        FormFactorMethod::MonteCarlo {
            samples: 64,
            seed: 7,
        },
    ] {
        let (b1, r1, f1) = s.progressive(method, 1e-3);
        let (b2, r2, f2) = s.progressive(method, 1e-3);
        assert_eq!(b1, b2, "{method}");
        assert_eq!(r1.shots, r2.shots);
        assert_eq!(r1.balance, r2.balance);
        assert_eq!(f1, f2);
    }
}

#[test]
#[allow(clippy::needless_range_loop)]
fn ambient_is_for_display_only_and_observer_can_stop() {
    let (scene, max_area) = small_cornell();
    let s = setup(&scene, max_area);
    let mut seen = Vec::new();
    let (b, report) = solve_progressive(
        &s.ctx(),
        FormFactorMethod::AreaIntegral { steps: 2 },
        &s.light,
        &ProgressiveSettings {
            tolerance: 1e-6,
            max_shots: 1_000_000,
        },
        &mut |step| {
            let Step::Shot(state) = step else {
                panic!("progressive refinement shows shots, not {step:?}")
            };
            let display = state.display_radiosity();
            for (i, d) in display.iter().enumerate() {
                for k in 0..3 {
                    let expected = state.radiosity[i][k] + s.rho[i][k] * state.ambient[k];
                    assert_eq!(d[k], expected);
                }
            }
            seen.push((state.shot, state.ambient, state.radiosity.to_vec()));
            if state.shot == 5 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
        &NoProgress,
    )
    .unwrap();
    assert!(report.stopped);
    assert_eq!(report.shots, 5);
    assert_eq!(seen.len(), 5);
    let (shot, ambient, last) = seen.last().unwrap();
    assert_eq!(*shot, 5);
    // The ambient term is positive while power is unshot, and not in the returned B.
    assert!(ambient.iter().all(|&a| a > 0.0), "{ambient:?}");
    // The report's ambient uses the exactly summed unshot power, the state's the running
    // sum: equal up to rounding.
    for k in 0..3 {
        assert!((report.ambient[k] - ambient[k]).abs() < 1e-12 * ambient[k]);
    }
    for i in 0..s.n() {
        assert_eq!(b.element(i), last[i]);
    }
}

#[test]
fn refusals() {
    let (scene, max_area) = small_cornell();
    let s = setup(&scene, max_area);
    let method = FormFactorMethod::AreaIntegral { steps: 1 };
    let run = |tolerance, max_shots| {
        solve_progressive(
            &s.ctx(),
            method,
            &s.light,
            &ProgressiveSettings {
                tolerance,
                max_shots,
            },
            &mut keep_going,
            &NoProgress,
        )
    };
    assert!(matches!(
        run(0.0, 10),
        Err(SolveError::BadSettings { value: 0.0, .. })
    ));
    let err = run(1e-6, 3).unwrap_err();
    let SolveError::ProgressiveNotConverged {
        shots,
        unshot_fraction,
        ..
    } = err
    else {
        panic!("{err:?}")
    };
    assert_eq!(shots, 3);
    assert!(unshot_fraction > 1e-6);
    // (The matrix solver entry point takes a `DenseSolver`: it cannot be handed progressive
    // refinement at all.)
    // Nothing emitted: B = 0 after no shots.
    let dark = ElementLight::new(s.rho.clone(), vec![Rgb::BLACK; s.n()]).unwrap();
    let (b, report) = solve_progressive(
        &s.ctx(),
        method,
        &dark,
        &ProgressiveSettings {
            tolerance: 0.01,
            max_shots: 10,
        },
        &mut keep_going,
        &NoProgress,
    )
    .unwrap();
    assert_eq!(report.shots, 0);
    assert!(b.0.iter().all(|&x| x == Rgb::BLACK));
}

/// Records the statuses a solve reports ([`radiosity::progress::Progress::status`]).
#[derive(Default)]
struct Statuses(std::sync::Mutex<Vec<String>>);

impl radiosity::progress::Progress for Statuses {
    fn start(&self, _stage: radiosity::progress::Stage, _total: u64) {}
    fn advance(&self, _done: u64) {}
    fn finish(&self, _stage: radiosity::progress::Stage, _elapsed: std::time::Duration) {}
    fn status(&self, text: &str) {
        self.0.lock().unwrap().push(text.to_string());
    }
}

/// QA pass 15 of #16: progressive refinement's progress lines counted shots and said
/// nothing of how far the solve was from stopping. Its status gives the unshot power after
/// shots 1, 17, 33, ..., the fraction the observer is shown after the same shot.
#[test]
fn progressive_status_gives_the_unshot_power_the_observer_sees() {
    let scene = unit_cube(|i| if i == 1 { [1.0, 2.0, 3.0] } else { [0.0; 3] });
    let s = setup(&scene, 0.05);
    let statuses = Statuses::default();
    let mut fractions = Vec::new();
    solve_progressive(
        &s.ctx(),
        FormFactorMethod::AreaIntegral { steps: 1 },
        &s.light,
        &ProgressiveSettings {
            tolerance: 0.01,
            max_shots: 1_000_000,
        },
        &mut |step| {
            if let Step::Shot(shot) = step {
                fractions.push(shot.unshot_fraction);
            }
            ControlFlow::Continue(())
        },
        &statuses,
    )
    .unwrap();
    let statuses = statuses.0.into_inner().unwrap();
    assert!(fractions.len() > 16, "{} shots", fractions.len());
    assert_eq!(statuses.len(), fractions.len().div_ceil(16));
    for (k, status) in statuses.iter().enumerate() {
        let percent: f64 = status
            .strip_prefix("unshot power ")
            .and_then(|t| t.split(' ').next())
            .and_then(|t| t.parse().ok())
            .unwrap_or_else(|| panic!("{status}"));
        let expected = 100.0 * fractions[16 * k];
        // Printed to two significant digits or one decimal: within 5 % of the value.
        assert!(
            (percent - expected).abs() <= 0.05 * expected,
            "after shot {}: {status} against {expected} %",
            16 * k + 1
        );
        assert!(
            status.ends_with("of the emitted (stops below 1.0 %)"),
            "{status}"
        );
    }
}
