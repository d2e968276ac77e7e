//! The iterative solver: Gauss-Seidel sweeps over (I - rho F) B = E.
//!
//! Starts from B = E, or from an earlier solution (a warm start, as the window uses after
//! a colour edit). Each sweep visits the elements in order and sets B_i <- E_i + rho_i sum_j F_ij B_j using
//! the values already updated in this sweep, for all three bands at once, so that every row
//! of F (f32, widened to f64) is read once per sweep. Since rho_i < 1 and each row of F sums
//! to at most 1, the iteration matrix has norm below 1 and the sweeps converge.
//!
//! Stopping: the change d_i made to B_i during a sweep is the residual of the vector as it
//! stood just before that update. The residual of the vector after the sweep is
//! r_i = rho_i sum_{j >= i} F_ij d_j, so |r_i| <= max |d|; once max |d| / max |E| is below
//! the tolerance the true residual is computed (one more pass over F) and the solve ends
//! when that too is below the tolerance.
//!
//! Failing loudly: after every sweep B is checked finite ([`SolveError::NotFinite`]), and
//! against the bound no iterate of a valid system passes: with rho_max s < 1 (s the
//! largest row sum of |F|) the sweeps contract the error in the max norm, so every iterate
//! stays within |B*| + |B_0 - B*| <= 2 |B*|max + |B_0|max of the origin, where
//! |B*| <= max |E| / (1 - rho_max s). Where no such bound follows (rho_max s >= 1), a
//! sweep change 1e6 times its smallest so far is called divergence: a contraction's changes
//! never grow. Both give [`SolveError::Diverged`].

use std::ops::ControlFlow;

use super::finite::{check_finite, max_abs, SolutionBound};
use super::residual::{max_abs_emission, relative, relative_residual, row_dot3};
use super::{GaussSeidelSettings, Observer, Radiosity, SolveError, Step};
use crate::form_factor::FormFactorMatrix;
use crate::light::{ElementLight, Rgb};
use crate::progress::Progress;

/// The name errors give.
const SOLVER: &str = "Gauss-Seidel";

/// What a Gauss-Seidel run returns.
pub(super) struct Run {
    pub radiosity: Radiosity,
    pub sweeps: usize,
    /// The observer stopped it before it converged.
    pub stopped: bool,
}

/// Iterates from `start` (or B = E) until the relative residual is below the tolerance in
/// every band, or until `observer`, shown every sweep, says stop.
pub(super) fn solve(
    f: &FormFactorMatrix,
    light: &ElementLight,
    settings: &GaussSeidelSettings,
    start: Option<&[Rgb]>,
    observer: &mut Observer,
    progress: &dyn Progress,
) -> Result<Run, SolveError> {
    let GaussSeidelSettings {
        tolerance,
        max_iterations,
    } = *settings;
    let (reflectance, emission) = (light.reflectance(), light.emission());
    let n = f.n();
    let scale = max_abs_emission(emission);
    let mut b: Vec<Rgb> = start.unwrap_or(emission).to_vec();
    check_finite(&b, SOLVER, || "the start".into())?;
    let bound = SolutionBound::new(light, f.max_abs_row_sum());
    let iterate_limit = bound
        .as_ref()
        .map(|s| (2.0 * s.bound + max_abs(&b)) * (1.0 + 1e-9));
    let mut smallest_change = f64::INFINITY;
    let mut residual = f64::INFINITY;
    for sweep in 1..=max_iterations {
        let mut change = [0.0f64; 3];
        for i in 0..n {
            let h = row_dot3(f.row(i), &b);
            for k in 0..3 {
                let new = emission[i][k] + reflectance[i][k] * h[k];
                change[k] = change[k].max((new - b[i][k]).abs());
                b[i][k] = new;
            }
        }
        progress.advance(1);
        // NaN would be dropped by f64::max below and read as converged: look for it first.
        check_finite(&b, SOLVER, || format!("sweep {sweep}"))?;
        if let (Some(bound), Some(limit)) = (&bound, iterate_limit) {
            bound.check(&b, limit, SOLVER, || format!("sweep {sweep}"))?;
        }
        let estimate = relative(change, scale).into_iter().fold(0.0, f64::max);
        if estimate > 1e6 * smallest_change {
            return Err(SolveError::Diverged {
                solver: SOLVER,
                what: "the change made by one sweep (relative to max |E|)",
                value: estimate,
                bound: 1e6 * smallest_change,
                reason: format!(
                    "a million times its smallest so far, {smallest_change:e}: a convergent \
                     iteration's changes shrink"
                ),
                after: format!("sweep {sweep}"),
            });
        }
        smallest_change = smallest_change.min(estimate);
        residual = estimate;
        progress.status(&format!(
            "the last sweep changed B by {estimate:.1e} of the largest emission (it stops \
             once the relative residual is below {tolerance:e})"
        ));
        if estimate < tolerance {
            let true_residual = relative_residual(f, light, &b)
                .into_iter()
                .fold(0.0, f64::max);
            residual = true_residual;
            if true_residual < tolerance {
                return Ok(Run {
                    radiosity: Radiosity(b),
                    sweeps: sweep,
                    stopped: false,
                });
            }
        }
        let step = Step::Sweep {
            sweep,
            change: estimate,
            radiosity: &b,
        };
        if let ControlFlow::Break(()) = observer(&step) {
            return Ok(Run {
                radiosity: Radiosity(b),
                sweeps: sweep,
                stopped: true,
            });
        }
    }
    Err(SolveError::NotConverged {
        iterations: max_iterations,
        residual,
        tolerance,
    })
}
