//! Why a solve failed.

use crate::form_factor::{NonFiniteFormFactor, OutOfMemory};
use crate::light::LightError;

/// The radiosity system cannot be solved.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SolveError {
    /// The dense LU matrix would not fit in memory (nothing was allocated).
    #[error(transparent)]
    OutOfMemory(#[from] OutOfMemory),
    /// Hierarchical radiosity's nodes and links would outgrow the memory.
    #[error(
        "hierarchical radiosity stopped refining at {nodes} nodes and {links} links: they \
         take about {used_mib} MiB, past the limit of {limit_mib} MiB (80 % of the memory \
         available unless set); a larger epsilon or minimum area refines less"
    )]
    HierarchicalTooBig {
        /// Estimated bytes held, in MiB.
        used_mib: u64,
        /// The limit, in MiB.
        limit_mib: u64,
        /// Nodes made.
        nodes: usize,
        /// Links held.
        links: usize,
    },
    /// Hierarchical radiosity's minimum area would let the surfaces be cut into more leaves
    /// than the element budget ([`crate::solve::check_min_area`]); nothing was refined.
    #[error(
        "a minimum element area of {} lets hierarchical radiosity cut the surfaces into up \
         to {leaves:.3e} leaves, more than the limit of {limit} elements; {}",
        crate::mesh::compact(*min_area),
        match fits {
            Some(a) if *a >= *default => format!(
                "the default, MAX_PATCH_AREA / 16 = {}, or more fits",
                crate::mesh::four_digits_up(*default)
            ),
            Some(a) => format!("a minimum area of {} or more fits", crate::mesh::four_digits_up(*a)),
            None => "no minimum area below the default (MAX_PATCH_AREA / 16) fits".to_string(),
        }
    )]
    MinAreaTooSmall {
        /// The minimum area given (scene units squared).
        min_area: f64,
        /// The leaves the surfaces make cut to that area.
        leaves: f64,
        /// The element budget ([`crate::mesh::MAX_ELEMENTS`]).
        limit: u64,
        /// The smallest minimum area that fits, at most the default; `None` where none does.
        fits: Option<f64>,
        /// The default minimum area, `MAX_PATCH_AREA / 16`, never refused.
        default: f64,
    },
    /// Gauss-Seidel did not reach the tolerance within the allowed sweeps.
    #[error(
        "Gauss-Seidel did not converge: after {iterations} sweeps the relative residual is \
         {residual:e}, above the tolerance {tolerance:e} (raise the iteration limit, loosen \
         the tolerance, or use the LU solver)"
    )]
    NotConverged {
        /// Sweeps made.
        iterations: usize,
        /// The largest relative residual over the bands after the last sweep.
        residual: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// Progressive refinement did not reach the tolerance within the allowed shots.
    #[error(
        "progressive refinement did not converge: after {shots} shots the unshot power is \
         {unshot_fraction:e} of the emitted power, above the tolerance {tolerance:e} (raise \
         the shot limit or loosen the tolerance)"
    )]
    ProgressiveNotConverged {
        /// Shots made.
        shots: usize,
        /// Unshot power / emitted power, the largest over the bands.
        unshot_fraction: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// Hierarchical radiosity's sweeps did not settle.
    #[error("hierarchical radiosity did not converge in {sweeps} sweeps")]
    HierarchicalNotConverged {
        /// Sweeps made.
        sweeps: usize,
    },
    /// Hierarchical radiosity's light grew sweep after sweep: its links' form factors,
    /// estimates, sum a little above 1 for some elements, and with reflectances near 1 that
    /// is enough to make the light grow without end (QA of issue #16: a closed box of
    /// reflectance 0.97 "diverged" with "rows summing far above 1?").
    #[error(
        "hierarchical radiosity's light grows without settling: the power a sweep changes \
         rose for {rising} sweeps in a row, to {change:.3} of the emitted power after sweep \
         {sweep}; its links estimate form factors, which can sum a little above 1, and with \
         reflectance up to {rho_max} (light kept {kept:.0} times over) that is enough to make \
         the light grow"
    )]
    HierarchicalGrowing {
        /// Consecutive sweeps whose change rose.
        rising: usize,
        /// The last sweep's change, a fraction of the emitted power.
        change: f64,
        /// The sweep.
        sweep: usize,
        /// The largest reflectance.
        rho_max: f64,
        /// 1 / (1 - rho_max): how often light is passed on before it is spent.
        kept: f64,
    },
    /// A solver produced a radiosity that is not a finite number (NaN or infinity). It is
    /// never treated as converged: NaN compares false with every tolerance.
    #[error(
        "{solver} produced a radiosity that is not a finite number: element {element} has \
         B = {value} after {after}; the input is not a valid radiosity system (a form factor, \
         area or emission that is not finite, or surfaces too small for f64)"
    )]
    NotFinite {
        /// Which solver ("Gauss-Seidel").
        solver: &'static str,
        /// The first element (or hierarchical node) whose radiosity is not finite.
        element: usize,
        /// Its value (NaN or +-infinity).
        value: f64,
        /// When ("sweep 3", "the LU solve", "shot 12").
        after: String,
    },
    /// A solver's iterates grew past what any solution of a valid system can reach.
    #[error(
        "{solver} diverged: {what} is {value:e} after {after}, beyond the bound {bound:e} \
         ({reason}); the form factors are not a valid matrix (rows summing far above 1?)"
    )]
    Diverged {
        /// Which solver.
        solver: &'static str,
        /// What grew ("the largest |B|").
        what: &'static str,
        /// Its value.
        value: f64,
        /// The bound it passed.
        bound: f64,
        /// Why nothing valid passes that bound.
        reason: String,
        /// When.
        after: String,
    },
    /// A form factor handed to the solver, or computed by it, is not a finite number.
    #[error(transparent)]
    FormFactor(#[from] NonFiniteFormFactor),
    /// There is nothing to solve.
    #[error("the scene has no surfaces")]
    NoSurfaces,
    /// An input vector does not have one entry per row of the form-factor matrix.
    #[error("{what} has {len} entries but the form-factor matrix has {n} rows")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The matrix size.
        n: usize,
    },
    /// A reflectance is outside [0, 1) or an emission is not a finite number.
    #[error(transparent)]
    Light(#[from] LightError),
    /// The solver settings are unusable (for example a tolerance that is not positive).
    #[error("bad solver settings: {setting} must be {expected}, got {value}")]
    BadSettings {
        /// Which setting ("the Gauss-Seidel tolerance").
        setting: &'static str,
        /// What it must be ("a positive number").
        expected: &'static str,
        /// The value given.
        value: f64,
    },
}
