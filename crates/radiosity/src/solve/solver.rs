//! Which solver, with its settings: one closed set, matched in one place
//! ([`crate::pipeline::solve`]), and the automatic choice between them.
//!
//! Each variant carries only the settings it uses, and the dense solvers, which need the
//! form-factor matrix, form a type of their own ([`DenseSolver`]) so that no function that
//! takes a matrix can be handed a solver that does not use one.

use std::fmt;
use std::str::FromStr;

use crate::mesh::compact;

use super::hierarchical::HierarchicalSettings;
use super::progressive::DEFAULT_PROGRESSIVE_TOLERANCE;

/// Gauss-Seidel's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussSeidelSettings {
    /// Stop when the max-norm residual |E + rho F B - B| relative to max |E| is below
    /// this, in every band (default 1e-9).
    pub tolerance: f64,
    /// Give up with [`super::SolveError::NotConverged`] after this many sweeps (default
    /// 10 000).
    pub max_iterations: usize,
}

impl Default for GaussSeidelSettings {
    /// Relative residual 1e-9, at most 10 000 sweeps.
    fn default() -> GaussSeidelSettings {
        GaussSeidelSettings {
            tolerance: 1e-9,
            max_iterations: 10_000,
        }
    }
}

/// Progressive refinement's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProgressiveSettings {
    /// Stop when the unshot power is below this fraction of the emitted power in every
    /// band (the paper's convergence value; default 0.01 = 1 %).
    pub tolerance: f64,
    /// Give up with [`super::SolveError::ProgressiveNotConverged`] after this many shots.
    pub max_shots: usize,
}

impl Default for ProgressiveSettings {
    /// 1 % unshot power, at most 1 000 000 shots.
    fn default() -> ProgressiveSettings {
        ProgressiveSettings {
            tolerance: DEFAULT_PROGRESSIVE_TOLERANCE,
            max_shots: 1_000_000,
        }
    }
}

impl HierarchicalSettings {
    /// The default refinement threshold epsilon: fast, and with the final gather about
    /// 1.6 % RMS element by element on the Cornell box at 2,046 elements (8.9 % without it;
    /// BENCHMARKS.md).
    pub const DEFAULT_EPSILON: f64 = 0.05;

    /// The defaults for a scene meshed at `max_patch_area`: epsilon
    /// [`HierarchicalSettings::DEFAULT_EPSILON`], minimum area `max_patch_area / 16`,
    /// tolerance [`super::DEFAULT_HIERARCHICAL_TOLERANCE`], memory limit 80 % of what is
    /// available, the final gather on at up to [`super::GATHER_POINTS_DEFAULT`] points.
    pub fn defaults_for(max_patch_area: f64) -> HierarchicalSettings {
        HierarchicalSettings {
            epsilon: HierarchicalSettings::DEFAULT_EPSILON,
            min_area: max_patch_area / 16.0,
            tolerance: super::DEFAULT_HIERARCHICAL_TOLERANCE,
            max_memory_bytes: None,
            final_gather: true,
            gather_points: super::GATHER_POINTS_DEFAULT,
        }
    }
}

/// A solver of (I - rho F) B = E on the stored form-factor matrix (paper figure 6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DenseSolver {
    /// Direct solution by LU factorisation with partial pivoting (faer), as the paper's
    /// Gaussian elimination. Needs a dense n x n f64 matrix (8 n^2 bytes) on top of the
    /// form factors and O(n^3) time; exact up to rounding. Bands with identical reflectance
    /// vectors share one factorisation.
    Lu,
    /// Gauss-Seidel iteration B_i <- E_i + rho_i sum_j F_ij B_j, in place, all three bands
    /// per sweep, from B = E or a given start. O(n^2) time per sweep, O(n) extra memory.
    GaussSeidel(GaussSeidelSettings),
}

/// How the radiosity system is solved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solver {
    /// On the dense form-factor matrix (computed, read from a file or given).
    Dense(DenseSolver),
    /// Progressive refinement (Cohen, Chen, Wallace and Greenberg 1988): shoot the unshot
    /// power of the brightest element, one row of F computed per shot, no matrix stored
    /// (O(n) memory).
    Progressive(ProgressiveSettings),
    /// Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991) with BF refinement and
    /// clustering: quadtrees over the input surfaces, clusters above them, links instead of
    /// a matrix; its solution lives on its own elements (the leaves).
    Hierarchical(HierarchicalSettings),
}

impl Solver {
    /// LU on the dense matrix.
    pub const LU: Solver = Solver::Dense(DenseSolver::Lu);

    /// Gauss-Seidel with the default settings: relative residual 1e-9, at most 10 000 sweeps.
    pub const DEFAULT_GAUSS_SEIDEL: Solver =
        Solver::Dense(DenseSolver::GaussSeidel(GaussSeidelSettings {
            tolerance: 1e-9,
            max_iterations: 10_000,
        }));

    /// Progressive refinement to 1 % unshot power, at most 1 000 000 shots.
    pub const DEFAULT_PROGRESSIVE: Solver = Solver::Progressive(ProgressiveSettings {
        tolerance: DEFAULT_PROGRESSIVE_TOLERANCE,
        max_shots: 1_000_000,
    });

    /// True for solvers that need the dense form-factor matrix.
    pub fn needs_matrix(&self) -> bool {
        matches!(self, Solver::Dense(_))
    }

    /// Which kind of solver this is.
    pub fn kind(&self) -> SolverKind {
        match self {
            Solver::Dense(DenseSolver::Lu) => SolverKind::Lu,
            Solver::Dense(DenseSolver::GaussSeidel(_)) => SolverKind::GaussSeidel,
            Solver::Progressive(_) => SolverKind::Progressive,
            Solver::Hierarchical(_) => SolverKind::Hierarchical,
        }
    }

    /// The kind's name and its main settings, short enough for a table cell
    /// (`gauss-seidel 1e-9`); [`fmt::Display`] gives the full sentence.
    pub fn short_label(&self) -> String {
        let name = self.kind().name();
        match self {
            Solver::Dense(DenseSolver::Lu) => name.into(),
            Solver::Dense(DenseSolver::GaussSeidel(s)) => format!("{name} {:e}", s.tolerance),
            Solver::Progressive(s) => format!("{name} {:e}", s.tolerance),
            Solver::Hierarchical(h) => format!(
                "{name} eps {} min {} tol {:e}{}",
                h.epsilon,
                h.min_area,
                h.tolerance,
                if h.final_gather { "" } else { " no gather" }
            ),
        }
    }
}

impl Default for Solver {
    /// [`Solver::DEFAULT_GAUSS_SEIDEL`].
    fn default() -> Solver {
        Solver::DEFAULT_GAUSS_SEIDEL
    }
}

impl fmt::Display for DenseSolver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DenseSolver::Lu => write!(f, "LU"),
            DenseSolver::GaussSeidel(GaussSeidelSettings {
                tolerance,
                max_iterations,
            }) => write!(
                f,
                "Gauss-Seidel (tolerance {}, at most {max_iterations} sweeps)",
                compact(*tolerance)
            ),
        }
    }
}

impl fmt::Display for Solver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Solver::Dense(d) => d.fmt(f),
            Solver::Progressive(ProgressiveSettings {
                tolerance,
                max_shots,
            }) => write!(
                f,
                "progressive refinement (unshot power below {} of emitted, at most {max_shots} shots)",
                compact(*tolerance)
            ),
            Solver::Hierarchical(h) => write!(
                f,
                "hierarchical radiosity with clustering (BF refinement, epsilon {}, minimum area {}, changing power below {} of emitted)",
                compact(h.epsilon), compact(h.min_area), compact(h.tolerance)
            ),
        }
    }
}

/// A solver by name, as a user picks it: the settings come separately. `Auto` is decided
/// per scene by [`choose`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SolverKind {
    /// Decided from the element count and the memory ([`choose`]).
    Auto,
    /// [`DenseSolver::Lu`].
    Lu,
    /// [`DenseSolver::GaussSeidel`].
    GaussSeidel,
    /// [`Solver::Progressive`].
    Progressive,
    /// [`Solver::Hierarchical`].
    Hierarchical,
}

impl SolverKind {
    /// Every kind, in the order offered to users.
    pub const ALL: [SolverKind; 5] = [
        SolverKind::Auto,
        SolverKind::Lu,
        SolverKind::GaussSeidel,
        SolverKind::Progressive,
        SolverKind::Hierarchical,
    ];

    /// The one printed name (`gauss-seidel`), as parsed by [`FromStr`].
    pub fn name(self) -> &'static str {
        match self {
            SolverKind::Auto => "auto",
            SolverKind::Lu => "lu",
            SolverKind::GaussSeidel => "gauss-seidel",
            SolverKind::Progressive => "progressive",
            SolverKind::Hierarchical => "hierarchical",
        }
    }

    /// One line on what it does.
    pub fn help(self) -> &'static str {
        match self {
            SolverKind::Auto => {
                "Gauss-Seidel on the dense matrix when it fits comfortably and the scene is \
                 small, hierarchical radiosity otherwise; says which and why"
            }
            SolverKind::Lu => {
                "LU factorisation with partial pivoting (the paper's Gaussian elimination)"
            }
            SolverKind::GaussSeidel => "Gauss-Seidel iteration on the dense matrix",
            SolverKind::Progressive => {
                "progressive refinement (Cohen et al. 1988): shoot the brightest element's \
                 unshot power, one row of form factors per shot, no matrix stored"
            }
            SolverKind::Hierarchical => {
                "hierarchical radiosity (Hanrahan et al. 1991) with clustering: quadtrees and \
                 links, no matrix; the leaves are the elements shaded"
            }
        }
    }
}

impl fmt::Display for SolverKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not a solver's.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("unknown solver {0:?} (expected one of auto, lu, gauss-seidel, progressive, hierarchical)")]
pub struct UnknownSolver(pub String);

impl FromStr for SolverKind {
    type Err = UnknownSolver;
    fn from_str(s: &str) -> Result<SolverKind, UnknownSolver> {
        SolverKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| UnknownSolver(s.to_string()))
    }
}

/// The most elements [`choose`] gives the dense solve: its form factors cost O(n^2)
/// (about 5 s at 10,000 elements on two cores, BENCHMARKS.md), so beyond this the
/// hierarchical solver (no matrix) is chosen even when the matrix would fit.
pub const AUTO_DENSE_MAX_ELEMENTS: usize = 20_000;

/// Why [`choose`] chose as it did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AutoReason {
    /// Few enough elements and the matrix takes at most half the memory: dense.
    Fits,
    /// More than [`AUTO_DENSE_MAX_ELEMENTS`] elements.
    TooManyElements,
    /// The matrix would take more than half the available memory.
    MatrixTooLarge,
}

/// The automatic choice for a scene, with the facts behind it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutoChoice {
    /// Elements of the mesh.
    pub elements: usize,
    /// Bytes the f32 form-factor matrix would take ([`FormFactorMatrix::bytes_for`]; the
    /// choice allows 10 % headroom on top).
    ///
    /// [`FormFactorMatrix::bytes_for`]: crate::form_factor::FormFactorMatrix::bytes_for
    pub matrix_bytes: f64,
    /// Bytes of memory available.
    pub available_bytes: u64,
    /// Why.
    pub reason: AutoReason,
}

/// The automatic choice for `elements` elements and `available` bytes of memory: the dense
/// solve (Gauss-Seidel on the stored matrix) when the scene has at most
/// [`AUTO_DENSE_MAX_ELEMENTS`] elements and the matrix takes at most half the memory,
/// hierarchical radiosity otherwise.
pub fn choose(elements: usize, available: u64) -> AutoChoice {
    let matrix_bytes = crate::form_factor::FormFactorMatrix::bytes_for(elements) as f64;
    let reason = if elements > AUTO_DENSE_MAX_ELEMENTS {
        AutoReason::TooManyElements
    } else if 1.1 * matrix_bytes > 0.5 * available as f64 {
        AutoReason::MatrixTooLarge
    } else {
        AutoReason::Fits
    };
    AutoChoice {
        elements,
        matrix_bytes,
        available_bytes: available,
        reason,
    }
}

impl AutoChoice {
    /// True when the dense matrix is chosen.
    pub fn dense(&self) -> bool {
        self.reason == AutoReason::Fits
    }

    /// The kind chosen: Gauss-Seidel or hierarchical radiosity.
    pub fn kind(&self) -> SolverKind {
        if self.dense() {
            SolverKind::GaussSeidel
        } else {
            SolverKind::Hierarchical
        }
    }

    /// "N elements; the dense form-factor matrix needs X MiB of the Y MiB available" (the
    /// matrix alone, as `compare` reports it; MiB = 2^20 bytes).
    pub fn estimate(&self) -> String {
        let mib = |b: f64| b / (1u64 << 20) as f64;
        format!(
            "{} elements; the dense form-factor matrix (f32, 4 n^2 bytes) needs {} MiB of \
             the {:.0} MiB available (MiB = 2^20 bytes)",
            self.elements,
            crate::form_factor::format_mib(self.matrix_bytes as u64),
            mib(self.available_bytes as f64)
        )
    }
}

impl fmt::Display for AutoChoice {
    /// The estimate and the choice, as told to the user.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let estimate = self.estimate();
        let hierarchical = "hierarchical radiosity with clustering (no matrix; links, memory about linear in the elements)";
        match self.reason {
            AutoReason::TooManyElements => write!(
                f,
                "{estimate}; more than {AUTO_DENSE_MAX_ELEMENTS} elements: {hierarchical}"
            ),
            AutoReason::MatrixTooLarge => {
                write!(f, "{estimate}, more than half of it: {hierarchical}")
            }
            AutoReason::Fits => write!(f, "{estimate}: Gauss-Seidel on the dense matrix"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_picks_dense_only_when_small_and_comfortable() {
        let gib = 1u64 << 30;
        assert!(choose(2_000, 16 * gib).dense());
        // 20,000 elements need 1.64 GiB with headroom: dense with 16 GiB, not with 2 GiB
        // (more than half of it).
        assert!(choose(20_000, 16 * gib).dense());
        assert_eq!(choose(20_000, 2 * gib).reason, AutoReason::MatrixTooLarge);
        assert_eq!(choose(20_001, 1 << 50).reason, AutoReason::TooManyElements);
        assert_eq!(choose(20_001, 1 << 50).kind(), SolverKind::Hierarchical);
        assert!(
            choose(9_805, 16 * gib).to_string().contains("MiB"),
            "the reason states the estimate"
        );
    }

    #[test]
    fn auto_states_the_matrix_size_compare_reports() {
        // QA of issue #16: `render` said 26 MiB (4 n^2 with 10 % headroom) where `compare`
        // said 24 MiB (4 n^2) for the same matrix. 2,560 elements: 4 * 2560^2 bytes =
        // 26,214,400 = 25.0 MiB exactly.
        let text = choose(2_560, 16 << 30).estimate();
        assert!(text.contains("needs 25 MiB"), "{text}");
    }

    #[test]
    fn names_parse_back() {
        for kind in SolverKind::ALL {
            assert_eq!(kind.name().parse::<SolverKind>(), Ok(kind));
        }
        assert!("dense".parse::<SolverKind>().is_err());
        assert_eq!(Solver::LU.kind(), SolverKind::Lu);
        assert_eq!(
            Solver::DEFAULT_GAUSS_SEIDEL.short_label(),
            "gauss-seidel 1e-9"
        );
    }
}
