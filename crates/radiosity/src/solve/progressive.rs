//! Progressive refinement (Cohen, Chen, Wallace and Greenberg 1988, "A Progressive
//! Refinement Approach to Fast Radiosity Image Generation").
//!
//! Instead of gathering (a row of F per element per sweep, the whole matrix kept), each step
//! *shoots*: the element i with the most unshot power A_i dB_i sends it to every element j.
//! Row i of F is computed on the fly (no n x n matrix is ever stored), and by reciprocity
//! F_ji = A_i F_ij / A_j the radiosity that arrives at j from i is
//!
//! dB_j += rho_j dB_i F_ji = rho_j dB_i F_ij A_i / A_j,   B_j += the same,
//!
//! after which dB_i = 0. Starting from B = dB = E this converges to the solution of
//! B = E + rho F' B with F'_ji = A_i F_ij / A_j, which is the F of the dense solve whenever
//! the method is reciprocal (area, contour); for the hemicube, Monte Carlo and analytic
//! methods it is the reciprocal of their rows, as in the paper.
//!
//! Stopping (the paper's "convergence value"): the unshot power sum_i A_i dB_i of each band,
//! as a fraction of that band's emitted power sum_i A_i E_i, below `tolerance` in every band
//! that emits. 0.01 is the customary 1 %.
//!
//! Ambient term (paper section 4): while shooting, the unshot power has not yet reached
//! anything, so pictures are too dark early on. The paper estimates the light it will add as
//! a uniform ambient radiosity
//!
//! ambient = (sum_i A_i dB_i / sum_i A_i) / (1 - rho_avg),  rho_avg = sum_i A_i rho_i / sum_i A_i,
//!
//! per band, shown as B_i + rho_i ambient. It is offered for display through
//! [`ProgressiveState::display_radiosity`] and never added to the returned B.
//!
//! Memory: O(n) vectors plus one row of F.

use std::time::{Duration, Instant};

use super::{EnergyBalance, Observer, ProgressiveSettings, Radiosity, SolveError, Step};
use crate::form_factor::{FormFactorContext, FormFactorMethod, RayCounter, RowComputer};
use crate::light::{ElementLight, Rgb};
use crate::progress::{run_stage, Progress, Stage};

/// The unshot-power fraction progressive refinement stops at unless told otherwise: 1 %.
pub const DEFAULT_PROGRESSIVE_TOLERANCE: f64 = 0.01;

/// The state of a progressive solve after a shot, as given to the observer.
#[derive(Debug)]
pub struct ProgressiveState<'a> {
    /// Shots made so far (1 after the first).
    pub shot: usize,
    /// The element shot last.
    pub shooter: usize,
    /// B per element, without the ambient term.
    pub radiosity: &'a [Rgb],
    /// rho per element, for [`ProgressiveState::display_radiosity`].
    pub reflectance: &'a [Rgb],
    /// The ambient radiosity per band (see the module documentation).
    pub ambient: [f64; 3],
    /// The largest, over the bands that emit, unshot power / emitted power.
    pub unshot_fraction: f64,
}

impl ProgressiveState<'_> {
    /// B_i + rho_i ambient for every element: the radiosity to show while the solve runs.
    pub fn display_radiosity(&self) -> Vec<Rgb> {
        self.radiosity
            .iter()
            .zip(self.reflectance)
            .map(|(b, rho)| Rgb(std::array::from_fn(|k| b[k] + rho[k] * self.ambient[k])))
            .collect()
    }
}

/// How a progressive solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProgressiveReport {
    /// Shots made.
    pub shots: usize,
    /// The unshot-power fraction at the end (largest over the emitting bands).
    pub unshot_fraction: f64,
    /// The ambient term at the end, per band (not included in the returned B).
    pub ambient: [f64; 3],
    /// Where the emitted power went, from the shots' own bookkeeping: `absorbed` is the
    /// (1 - rho_j) share of everything that arrived, `escaped` the share of every shot that
    /// its row of F does not cover. Power still unshot is in neither, so
    /// [`EnergyBalance::relative_error`] equals the unshot fraction (up to rounding).
    pub balance: EnergyBalance,
    /// Power per band still unshot, sum_i A_i dB_i: emitted = absorbed + escaped + unshot.
    pub unshot: [f64; 3],
    /// True when the observer asked to stop before convergence.
    pub stopped: bool,
    /// Visibility rays cast for the rows.
    pub rays: u64,
    /// Wall-clock time of the solve.
    pub elapsed: Duration,
}

/// Solves by progressive refinement, computing one row of F per shot with `method`.
///
/// `light` holds rho and E of every element of `ctx.mesh`. Stops when the unshot power is below `tolerance` times the emitted
/// power in every band that emits (see the module documentation), or when `observer`,
/// called after every shot, returns `ControlFlow::Break` (the report says `stopped`).
/// Fails with [`SolveError::ProgressiveNotConverged`] after `max_shots` shots. Reports to
/// `progress` as stage Solve (total unknown, one unit per shot) and a final message.
///
/// Deterministic: ties for the brightest element go to the lowest index, and each row is
/// computed by the method's deterministic code.
pub fn solve_progressive(
    ctx: &FormFactorContext,
    method: FormFactorMethod,
    light: &ElementLight,
    settings: &ProgressiveSettings,
    observer: &mut Observer,
    progress: &dyn Progress,
) -> Result<(Radiosity, ProgressiveReport), SolveError> {
    let ProgressiveSettings {
        tolerance,
        max_shots,
    } = *settings;
    let (reflectance, emission) = (light.reflectance(), light.emission());
    let n = ctx.mesh.len();
    if light.len() != n {
        return Err(SolveError::LengthMismatch {
            what: "the element light",
            len: light.len(),
            n,
        });
    }
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(SolveError::BadSettings {
            setting: "the progressive tolerance (unshot fraction)",
            expected: "a positive number",
            value: tolerance,
        });
    }
    let start = Instant::now();
    let areas: Vec<f64> = ctx.mesh.elements.iter().map(|e| e.area).collect();
    let total_area: f64 = areas.iter().sum();
    let rho_avg: [f64; 3] = std::array::from_fn(|k| {
        if total_area > 0.0 {
            areas
                .iter()
                .zip(reflectance)
                .map(|(a, r)| a * r[k])
                .sum::<f64>()
                / total_area
        } else {
            0.0
        }
    });
    let emitted: [f64; 3] =
        std::array::from_fn(|k| areas.iter().zip(emission).map(|(a, e)| a * e[k]).sum());
    let mut b: Vec<Rgb> = emission.to_vec();
    let mut unshot: Vec<Rgb> = emission.to_vec();
    let mut absorbed = [0.0f64; 3];
    let mut escaped = [0.0f64; 3];
    // Running total of unshot power per band, recomputed exactly every 64 shots so that
    // rounding in the running sum cannot drift.
    let total_unshot = |u: &[Rgb]| -> [f64; 3] {
        std::array::from_fn(|k| areas.iter().zip(u).map(|(a, d)| a * d[k]).sum())
    };
    let fraction = |u: [f64; 3]| -> f64 {
        (0..3)
            .filter(|&k| emitted[k] > 0.0)
            .map(|k| u[k] / emitted[k])
            .fold(0.0, f64::max)
    };
    let ambient_of = |u: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|k| {
            if total_area > 0.0 {
                u[k] / total_area / (1.0 - rho_avg[k])
            } else {
                0.0
            }
        })
    };
    // Selection weight: unshot power relative to the band's emission, summed over bands.
    let weight: [f64; 3] = std::array::from_fn(|k| {
        if emitted[k] > 0.0 {
            1.0 / emitted[k]
        } else {
            0.0
        }
    });

    let rays = RayCounter::default();
    let mut rows = RowComputer::new(ctx, method);
    let mut power = total_unshot(&unshot);
    let mut shots = 0usize;
    let mut stopped = false;
    let mut smallest_fraction = f64::INFINITY;
    let result = run_stage(progress, Stage::Solve, 0, || -> Result<(), SolveError> {
        loop {
            if fraction(power) < tolerance {
                return Ok(());
            }
            if shots >= max_shots {
                return Err(SolveError::ProgressiveNotConverged {
                    shots,
                    unshot_fraction: fraction(power),
                    tolerance,
                });
            }
            // The brightest unshot element (first of equals).
            let mut shooter = 0;
            let mut best = f64::NEG_INFINITY;
            for (i, (a, d)) in areas.iter().zip(&unshot).enumerate() {
                let w = a * (d[0] * weight[0] + d[1] * weight[1] + d[2] * weight[2]);
                if w > best {
                    best = w;
                    shooter = i;
                }
            }
            let shot = unshot[shooter];
            let a_i = areas[shooter];
            unshot[shooter] = Rgb::BLACK;
            let row = rows.row(shooter, &rays);
            // A NaN entry would spread NaN to every element it reaches, and the unshot
            // fraction, folded with f64::max, would read as converged.
            crate::form_factor::check_row(shooter, row.iter().copied())?;
            let mut row_sum = 0.0;
            let mut reflected_power = [0.0f64; 3];
            for (j, &fij) in row.iter().enumerate() {
                if fij == 0.0 {
                    continue;
                }
                row_sum += fij;
                let scale = fij * a_i / areas[j];
                for k in 0..3 {
                    let arriving = shot[k] * scale;
                    let reflected = reflectance[j][k] * arriving;
                    unshot[j][k] += reflected;
                    b[j][k] += reflected;
                    absorbed[k] += (arriving - reflected) * areas[j];
                    reflected_power[k] += reflected * areas[j];
                }
            }
            for k in 0..3 {
                escaped[k] += a_i * shot[k] * (1.0 - row_sum);
            }
            shots += 1;
            power = if shots % 64 == 0 {
                total_unshot(&unshot)
            } else {
                // Shooting removed A_i dB_i and added the reflected power.
                std::array::from_fn(|k| (power[k] - a_i * shot[k] + reflected_power[k]).max(0.0))
            };
            progress.advance(1);
            let now = fraction(power);
            if shots % 16 == 1 {
                // QA pass 15 of #16: the progress lines counted shots with no word of how
                // far the solve was from stopping.
                progress.status(&format!(
                    "unshot power {} of the emitted (stops below {})",
                    percent(now),
                    percent(tolerance)
                ));
            }
            if !now.is_finite() || power.iter().any(|p| !p.is_finite()) {
                super::finite::check_finite(&b, "progressive refinement", || {
                    format!("shot {shots}")
                })?;
                return Err(SolveError::NotFinite {
                    solver: "progressive refinement",
                    element: shooter,
                    value: now,
                    after: format!("shot {shots} (the unshot power)"),
                });
            }
            // Each shot moves power A_i dB_i and reflects at most rho_max s of it (s the
            // row's sum): with valid rows the unshot power only shrinks.
            if now > 1e6 * smallest_fraction {
                return Err(SolveError::Diverged {
                    solver: "progressive refinement",
                    what: "the unshot power (fraction of the emitted)",
                    value: now,
                    bound: 1e6 * smallest_fraction,
                    reason: format!(
                        "a million times its smallest so far, {smallest_fraction:e}: shots \
                         with rows summing to at most 1 only shrink it"
                    ),
                    after: format!("shot {shots}"),
                });
            }
            smallest_fraction = smallest_fraction.min(now);
            let state = ProgressiveState {
                shot: shots,
                shooter,
                radiosity: &b,
                reflectance,
                ambient: ambient_of(power),
                unshot_fraction: fraction(power),
            };
            if observer(&Step::Shot(&state)).is_break() {
                stopped = true;
                return Ok(());
            }
        }
    });
    result?;
    let power = total_unshot(&unshot);
    let report = ProgressiveReport {
        shots,
        unshot_fraction: fraction(power),
        ambient: ambient_of(power),
        balance: EnergyBalance {
            emitted,
            absorbed,
            escaped,
        },
        unshot: power,
        stopped,
        rays: rays.get(),
        elapsed: start.elapsed(),
    };
    progress.message(&format!(
        "progressive refinement ({method}): {n} elements, {shots} shots, unshot power {:.3} % of emitted (the band with the most left), {} visibility rays, {:.3} s{}",
        100.0 * report.unshot_fraction,
        report.rays,
        report.elapsed.as_secs_f64(),
        if stopped { " (stopped early)" } else { "" }
    ));
    Ok((Radiosity(b), report))
}

/// A fraction as a percentage with two significant digits or more: "3.2 %", "0.0041 %".
fn percent(fraction: f64) -> String {
    let p = 100.0 * fraction;
    if !p.is_finite() || p >= 1.0 || p == 0.0 {
        format!("{p:.1} %")
    } else {
        let decimals = (1.0 - p.log10().floor()).clamp(1.0, 12.0) as usize;
        format!("{p:.decimals$} %")
    }
}
