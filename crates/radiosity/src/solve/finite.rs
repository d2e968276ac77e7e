//! Guards that keep a solver from reporting NaN, infinity or a runaway iteration as a
//! solution: NaN compares false with every tolerance and `f64::max` drops it, so a residual
//! computed from NaN radiosities reads as 0 unless it is looked for.

use super::SolveError;
use crate::light::{ElementLight, Rgb};

/// The first entry of `b` that is not finite, with its element.
pub(super) fn first_non_finite(b: &[Rgb]) -> Option<(usize, f64)> {
    b.iter()
        .enumerate()
        .find_map(|(i, v)| v.0.iter().find(|x| !x.is_finite()).map(|&x| (i, x)))
}

/// Fails with [`SolveError::NotFinite`] when any radiosity of `b` is not finite.
pub(super) fn check_finite(
    b: &[Rgb],
    solver: &'static str,
    after: impl FnOnce() -> String,
) -> Result<(), SolveError> {
    match first_non_finite(b) {
        Some((element, value)) => Err(SolveError::NotFinite {
            solver,
            element,
            value,
            after: after(),
        }),
        None => Ok(()),
    }
}

/// The largest |B| any solution of B = E + rho F B can have, when rows of |F| sum to at
/// most `row_sum_max`: |B| <= max |E| + rho_max row_sum_max |B|, so
/// |B| <= max |E| / (1 - rho_max row_sum_max) where rho_max row_sum_max < 1 (`None`
/// otherwise: no bound follows).
pub(super) struct SolutionBound {
    pub bound: f64,
    pub row_sum_max: f64,
    pub rho_max: f64,
}

impl SolutionBound {
    pub(super) fn new(light: &ElementLight, row_sum_max: f64) -> Option<SolutionBound> {
        let rho_max = light
            .reflectance()
            .iter()
            .flat_map(|r| r.0)
            .fold(0.0, f64::max);
        let e_max = light
            .emission()
            .iter()
            .flat_map(|e| e.0)
            .fold(0.0, |m: f64, x| m.max(x.abs()));
        let q = rho_max * row_sum_max;
        (q < 1.0).then(|| SolutionBound {
            bound: e_max / (1.0 - q),
            row_sum_max,
            rho_max,
        })
    }

    /// Fails with [`SolveError::Diverged`] when max |B| passes `limit` (the bound itself for
    /// a solution, more for an iterate).
    pub(super) fn check(
        &self,
        b: &[Rgb],
        limit: f64,
        solver: &'static str,
        after: impl FnOnce() -> String,
    ) -> Result<(), SolveError> {
        let largest = max_abs(b);
        if largest <= limit {
            return Ok(());
        }
        Err(SolveError::Diverged {
            solver,
            what: "the largest |B|",
            value: largest,
            bound: limit,
            reason: format!(
                "no solution passes max |E| / (1 - rho_max s) = {:e} when rho <= {} and the rows \
                 of |F| sum to at most s = {:.4}",
                self.bound, self.rho_max, self.row_sum_max
            ),
            after: after(),
        })
    }
}

/// max_i max_k |B_ik|.
pub(super) fn max_abs(b: &[Rgb]) -> f64 {
    b.iter()
        .flat_map(|v| v.0)
        .fold(0.0, |m: f64, x| m.max(x.abs()))
}

/// Fails with [`SolveError::Diverged`] when some B_i is below its own emission E_i (beyond
/// rounding: 1e-9 of max |B|). With E >= 0, rho >= 0 and F >= 0 the solution of a system
/// whose reflections converge is the Neumann series B = sum_k (rho F)^k E >= E; a direct
/// solve of a system whose series diverges (rows of F summing far above 1) gives a finite
/// B that breaks this instead.
pub(super) fn check_at_least_emission(
    b: &[Rgb],
    light: &ElementLight,
    solver: &'static str,
) -> Result<(), SolveError> {
    let slack = 1e-9 * max_abs(b);
    for (i, (bi, ei)) in b.iter().zip(light.emission()).enumerate() {
        for k in 0..3 {
            if bi[k] < ei[k] - slack {
                return Err(SolveError::Diverged {
                    solver,
                    what: "B (below its emission E)",
                    value: bi[k],
                    bound: ei[k],
                    reason: format!(
                        "element {i} ends below its own emission; B = sum_k (rho F)^k E >= E \
                         when the reflections converge, and they do not here"
                    ),
                    after: "the direct solve".into(),
                });
            }
        }
    }
    Ok(())
}
