//! Solving the radiosity system (I - rho F) B = E, once per red, green and blue band
//! (paper figure 6 and the paragraph after it).
//!
//! Row i of the system says that the radiosity B_i leaving element i is its own emission
//! E_i plus the fraction rho_i of what arrives at it, sum_j F_ij B_j. The paper solves it by
//! Gaussian elimination with pivoting, three times, once per band; [`DenseSolver::Lu`] does
//! the same with faer's partial-pivoting LU (factoring once when the bands share their
//! reflectances). [`DenseSolver::GaussSeidel`] iterates instead, which needs only O(n) memory
//! beyond the form-factor matrix and converges because rho_i < 1 and every row of F sums to
//! at most 1 (the system is strictly diagonally dominant).
//!
//! The result is reported with the max-norm residual of E + rho F B - B relative to max |E|
//! per band, measured on the returned B (never estimated), so both solvers can be compared
//! on the same footing. [`energy_balance`] checks the other invariant: every watt emitted is
//! either absorbed by some element or escapes the scene.
//!
//! Files: [`Solver`] and the automatic choice in `solver.rs`; the dense solvers in `lu.rs`
//! and `gauss_seidel.rs`, dispatched by [`solve`] here; progressive refinement and
//! hierarchical radiosity, which need the scene rather than a matrix, in their own files;
//! the result types in `radiosity.rs`, the residual and the energy account beside them.
//! [`crate::pipeline::solve`] is the one entry point that takes any [`Solver`].

mod energy;
mod error;
mod finite;
mod gauss_seidel;
mod hierarchical;
mod lu;
mod progressive;
mod radiosity;
mod residual;
mod solver;
#[cfg(test)]
pub(crate) mod tests;

pub use energy::{energy_balance, escaped_by_surface, EnergyBalance};
pub use error::SolveError;
pub use hierarchical::{
    check_min_area, solve_hierarchical, HierarchicalReport, HierarchicalSettings,
    HierarchicalSolution, DEFAULT_HIERARCHICAL_TOLERANCE, GATHER_POINTS_DEFAULT,
};
pub use progressive::{
    solve_progressive, ProgressiveReport, ProgressiveState, DEFAULT_PROGRESSIVE_TOLERANCE,
};
pub use radiosity::{keep_going, Observer, Radiosity, SolveReport, Step};
pub use residual::relative_residual;
pub use solver::{
    choose, AutoChoice, AutoReason, DenseSolver, GaussSeidelSettings, ProgressiveSettings, Solver,
    SolverKind, UnknownSolver, AUTO_DENSE_MAX_ELEMENTS,
};

use std::time::Instant;

use crate::form_factor::FormFactorMatrix;
use crate::light::{ElementLight, Rgb};
use crate::progress::{run_stage, Progress, Stage};

/// Solves (I - rho F) B = E for each band on the matrix `f`.
///
/// `light` holds rho and E of every element (checked when it was built). Gauss-Seidel starts
/// from `start` when given (a warm start from an earlier solution), from B = E otherwise,
/// and shows `observer` every sweep; LU calls it never. A scene that emits nothing gets
/// B = 0.
pub fn solve(
    f: &FormFactorMatrix,
    light: &ElementLight,
    solver: &DenseSolver,
    start: Option<&[Rgb]>,
    observer: &mut Observer,
    progress: &dyn Progress,
) -> Result<(Radiosity, SolveReport), SolveError> {
    solve_with_memory(
        f,
        light,
        solver,
        start,
        observer,
        progress,
        crate::form_factor::available_memory_bytes(),
    )
}

/// [`solve`] with the available memory given, so that the refusal can be tested.
fn solve_with_memory(
    f: &FormFactorMatrix,
    light: &ElementLight,
    solver: &DenseSolver,
    start: Option<&[Rgb]>,
    observer: &mut Observer,
    progress: &dyn Progress,
    available: u64,
) -> Result<(Radiosity, SolveReport), SolveError> {
    check_inputs(f, light, solver, start)?;
    let started = Instant::now();
    let (radiosity, iterations, stopped) = match solver {
        DenseSolver::Lu => {
            lu::check_memory(f.n(), available)?;
            let b = lu::solve(f, light, true, progress);
            // A singular or wildly invalid system gives NaN or infinity, or a B no solution
            // of a valid system has (rounding allowed for: 1e-6 relative).
            finite::check_finite(b.as_slice(), "LU", || "the LU solve".into())?;
            if let Some(bound) = finite::SolutionBound::new(light, f.max_abs_row_sum()) {
                let limit = bound.bound * (1.0 + 1e-6);
                bound.check(b.as_slice(), limit, "LU", || "the LU solve".into())?;
            }
            finite::check_at_least_emission(b.as_slice(), light, "LU")?;
            (b, None, false)
        }
        DenseSolver::GaussSeidel(settings) => {
            let run = run_stage(progress, Stage::Solve, 0, || {
                gauss_seidel::solve(f, light, settings, start, observer, progress)
            })?;
            (run.radiosity, Some(run.sweeps), run.stopped)
        }
    };
    let residual = residual::relative_residual(f, light, radiosity.as_slice());
    let report = SolveReport {
        iterations,
        residual,
        elapsed: started.elapsed(),
        stopped,
    };
    progress.message(&format!(
        "solved {} elements by {solver}: relative residual (R / G / B: the largest element's, over the brightest emission) {:.1e} / {:.1e} / {:.1e}",
        f.n(),
        residual[0],
        residual[1],
        residual[2]
    ));
    Ok((radiosity, report))
}

fn check_inputs(
    f: &FormFactorMatrix,
    light: &ElementLight,
    solver: &DenseSolver,
    start: Option<&[Rgb]>,
) -> Result<(), SolveError> {
    let n = f.n();
    // A NaN or negative form factor would make NaN radiosities that every max-based test
    // reads as converged.
    f.check_entries()?;
    for (what, len) in [
        ("the element light", Some(light.len())),
        ("the starting solution", start.map(<[Rgb]>::len)),
    ] {
        match len {
            Some(len) if len != n => return Err(SolveError::LengthMismatch { what, len, n }),
            _ => {}
        }
    }
    match solver {
        DenseSolver::GaussSeidel(s) if !(s.tolerance > 0.0 && s.tolerance.is_finite()) => {
            Err(SolveError::BadSettings {
                setting: "the Gauss-Seidel tolerance",
                expected: "a positive number",
                value: s.tolerance,
            })
        }
        _ => Ok(()),
    }
}
