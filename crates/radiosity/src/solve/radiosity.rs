//! The solution of the radiosity system per element, how a solve went, and what a running
//! solve shows its observer.

use std::ops::ControlFlow;
use std::time::Duration;

use super::progressive::ProgressiveState;
use crate::light::Rgb;

/// Element radiosities: B per element in the three bands, in the scene's emission units
/// (unnormalised). One layout everywhere: element `i` is `self.0[i]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Radiosity(pub Vec<Rgb>);

impl Radiosity {
    /// The number of elements.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True when there are no elements.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// B of element i.
    pub fn element(&self, i: usize) -> Rgb {
        self.0[i]
    }

    /// B per element.
    pub fn as_slice(&self) -> &[Rgb] {
        &self.0
    }

    /// B per element as plain triples (the same memory: [`Rgb`] is transparent).
    pub fn as_arrays(&self) -> &[[f64; 3]] {
        Rgb::as_arrays(&self.0)
    }

    /// B of every element in band `b` (0 red, 1 green, 2 blue).
    pub fn band(&self, b: usize) -> impl ExactSizeIterator<Item = f64> + '_ {
        self.0.iter().map(move |x| x[b])
    }
}

/// How a dense solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveReport {
    /// Gauss-Seidel sweeps made; `None` for the direct LU solver.
    pub iterations: Option<usize>,
    /// Per band, max_i |E_i + rho_i sum_j F_ij B_j - B_i| / max_i |E_i| for the returned B
    /// (the absolute max-norm when a band emits nothing).
    pub residual: [f64; 3],
    /// Wall-clock time of the solve.
    pub elapsed: Duration,
    /// True when the observer stopped the solve before it converged.
    pub stopped: bool,
}

/// What a running solve shows its observer after each step.
#[derive(Debug)]
pub enum Step<'a> {
    /// A Gauss-Seidel sweep ended.
    Sweep {
        /// Sweeps made so far (1 after the first).
        sweep: usize,
        /// The sweep's largest change relative to max |E|, over the bands (an upper bound
        /// on the relative residual after it).
        change: f64,
        /// B per element now.
        radiosity: &'a [Rgb],
    },
    /// A progressive-refinement shot ended.
    Shot(&'a ProgressiveState<'a>),
}

/// Watches a long solve step by step and may stop it (`ControlFlow::Break`); the window
/// shows intermediate solutions this way, the command line writes snapshots.
pub type Observer<'a> = dyn FnMut(&Step<'_>) -> ControlFlow<()> + 'a;

/// An observer that never stops the solve.
pub fn keep_going(_: &Step<'_>) -> ControlFlow<()> {
    ControlFlow::Continue(())
}
