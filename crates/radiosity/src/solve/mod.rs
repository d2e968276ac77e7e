//! Solving the radiosity system (I - rho F) B = E, once per red, green and blue band
//! (paper figure 6 and the paragraph after it).
//!
//! Row i of the system says that the radiosity B_i leaving element i is its own emission
//! E_i plus the fraction rho_i of what arrives at it, sum_j F_ij B_j. The paper solves it by
//! Gaussian elimination with pivoting, three times, once per band; [`Solver::Lu`] does the
//! same with faer's partial-pivoting LU (factoring once when the bands share their
//! reflectances). [`Solver::GaussSeidel`] iterates instead, which needs only O(n) memory
//! beyond the form-factor matrix and converges because rho_i < 1 and every row of F sums to
//! at most 1 (the system is strictly diagonally dominant).
//!
//! The result is reported with the max-norm residual of E + rho F B - B relative to max |E|
//! per band, measured on the returned B (never estimated), so both solvers can be compared
//! on the same footing. [`energy_balance`] checks the other invariant: every watt emitted is
//! either absorbed by some element or escapes the scene.

mod gauss_seidel;
mod hierarchical;
mod lu;
mod progressive;

pub use hierarchical::{
    solve_hierarchical, HierarchicalReport, HierarchicalSettings, HierarchicalSolution,
    DEFAULT_HIERARCHICAL_TOLERANCE,
};
pub use progressive::{
    solve_progressive, ProgressiveReport, ProgressiveState, DEFAULT_PROGRESSIVE_TOLERANCE,
};

use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::form_factor::{FormFactorMatrix, OutOfMemory};
use crate::mesh::Mesh;
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::Scene;

/// How the radiosity system is solved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solver {
    /// Direct solution by LU factorisation with partial pivoting (faer), as the paper's
    /// Gaussian elimination. Needs a dense n x n f64 matrix (8 n^2 bytes) on top of the
    /// form factors and O(n^3) time; exact up to rounding. Bands with identical reflectance
    /// vectors share one factorisation.
    Lu,
    /// Gauss-Seidel iteration B_i <- E_i + rho_i sum_j F_ij B_j, in place, all three bands
    /// per sweep, starting from B = E. O(n^2) time per sweep and O(n) extra memory.
    GaussSeidel {
        /// Stop when the max-norm residual |E + rho F B - B| relative to max |E| is below
        /// this, in every band (default 1e-9).
        tolerance: f64,
        /// Give up with [`SolveError::NotConverged`] after this many sweeps (default 10 000).
        max_iterations: usize,
    },
    /// Progressive refinement (Cohen, Chen, Wallace and Greenberg 1988): shoot the unshot
    /// power of the brightest element, one row of F computed per shot, no matrix stored
    /// (O(n) memory). Solved by [`solve_progressive`], not [`solve`], since it needs the
    /// scene rather than a form-factor matrix.
    Progressive {
        /// Stop when the unshot power is below this fraction of the emitted power in every
        /// band (the paper's convergence value; default 0.01 = 1 %).
        tolerance: f64,
        /// Give up with [`SolveError::ProgressiveNotConverged`] after this many shots.
        max_shots: usize,
    },
    /// Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991) with BF refinement and
    /// clustering: quadtrees over the input surfaces, clusters above them, links instead of
    /// a matrix. Solved by [`solve_hierarchical`], which returns its own elements (the
    /// leaves).
    Hierarchical(HierarchicalSettings),
}

impl Solver {
    /// Gauss-Seidel with the default settings: relative residual 1e-9, at most 10 000 sweeps.
    pub const DEFAULT_GAUSS_SEIDEL: Solver = Solver::GaussSeidel {
        tolerance: 1e-9,
        max_iterations: 10_000,
    };
}

impl Solver {
    /// Progressive refinement to 1 % unshot power, at most 1 000 000 shots.
    pub const DEFAULT_PROGRESSIVE: Solver = Solver::Progressive {
        tolerance: DEFAULT_PROGRESSIVE_TOLERANCE,
        max_shots: 1_000_000,
    };

    /// True for solvers that need the dense form-factor matrix (all but progressive and
    /// hierarchical).
    pub fn needs_matrix(&self) -> bool {
        !matches!(self, Solver::Progressive { .. } | Solver::Hierarchical(_))
    }
}

impl Default for Solver {
    /// [`Solver::DEFAULT_GAUSS_SEIDEL`].
    fn default() -> Solver {
        Solver::DEFAULT_GAUSS_SEIDEL
    }
}

impl std::fmt::Display for Solver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Solver::Lu => write!(f, "LU"),
            Solver::GaussSeidel {
                tolerance,
                max_iterations,
            } => write!(
                f,
                "Gauss-Seidel (tolerance {tolerance:e}, at most {max_iterations} sweeps)"
            ),
            Solver::Progressive {
                tolerance,
                max_shots,
            } => write!(
                f,
                "progressive refinement (unshot power below {tolerance:e} of emitted, at most {max_shots} shots)"
            ),
            Solver::Hierarchical(h) => write!(
                f,
                "hierarchical radiosity with clustering (BF refinement, epsilon {:e}, minimum area {:e}, changing power below {:e} of emitted)",
                h.epsilon, h.min_area, h.tolerance
            ),
        }
    }
}

/// Element radiosities: B per element, per band (0 red, 1 green, 2 blue), in the scene's
/// emission units (unnormalised).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Radiosity {
    /// `bands[b][i]` is B_i in band b.
    pub bands: [Vec<f64>; 3],
}

impl Radiosity {
    /// The number of elements.
    pub fn len(&self) -> usize {
        self.bands[0].len()
    }

    /// True when there are no elements.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// B of element i in the three bands.
    pub fn element(&self, i: usize) -> [f64; 3] {
        [self.bands[0][i], self.bands[1][i], self.bands[2][i]]
    }
}

/// How a solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveReport {
    /// Gauss-Seidel sweeps made; `None` for the direct LU solver.
    pub iterations: Option<usize>,
    /// Per band, max_i |E_i + rho_i sum_j F_ij B_j - B_i| / max_i |E_i| for the returned B
    /// (the absolute max-norm when a band emits nothing).
    pub residual: [f64; 3],
    /// Wall-clock time of the solve.
    pub elapsed: Duration,
}

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
         available unless set); raise --epsilon or --min-area"
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
    /// The progressive solver was given to [`solve`], which takes a matrix.
    #[error(
        "progressive refinement and hierarchical radiosity compute their own form factors: use \
         solve_progressive or solve_hierarchical"
    )]
    NeedsScene,
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
    #[error("element {element}: {what} {value} in band {band} is {why}")]
    BadValue {
        /// The element.
        element: usize,
        /// "reflectance" or "emission".
        what: &'static str,
        /// The band (0 red, 1 green, 2 blue).
        band: usize,
        /// The offending value.
        value: f64,
        /// What is wrong with it.
        why: &'static str,
    },
    /// The solver settings are unusable (for example a tolerance that is not positive).
    #[error("bad solver settings: {0}")]
    BadSettings(String),
}

/// Solves (I - rho F) B = E for each band.
///
/// `reflectance[i]` and `emission[i]` are rho and E of element i in the three bands. Needs
/// rho in [0, 1) and finite E. A scene that emits nothing gets B = 0.
pub fn solve(
    f: &FormFactorMatrix,
    reflectance: &[[f64; 3]],
    emission: &[[f64; 3]],
    solver: Solver,
    progress: &dyn Progress,
) -> Result<(Radiosity, SolveReport), SolveError> {
    solve_with_memory(
        f,
        reflectance,
        emission,
        solver,
        progress,
        crate::form_factor::available_memory_bytes(),
    )
}

/// [`solve`] with the available memory given, so that the refusal can be tested.
fn solve_with_memory(
    f: &FormFactorMatrix,
    reflectance: &[[f64; 3]],
    emission: &[[f64; 3]],
    solver: Solver,
    progress: &dyn Progress,
    available: u64,
) -> Result<(Radiosity, SolveReport), SolveError> {
    check_inputs(f, reflectance, emission, solver)?;
    let start = Instant::now();
    let (radiosity, iterations) = match solver {
        Solver::Lu => {
            lu::check_memory(f.n(), available)?;
            let b = lu::solve(f, reflectance, emission, true, progress);
            (b, None)
        }
        Solver::GaussSeidel {
            tolerance,
            max_iterations,
        } => {
            let (b, iterations) = run_stage(progress, Stage::Solve, 0, || {
                gauss_seidel::solve(
                    f,
                    reflectance,
                    emission,
                    tolerance,
                    max_iterations,
                    progress,
                )
            })?;
            (b, Some(iterations))
        }
        Solver::Progressive { .. } | Solver::Hierarchical(_) => return Err(SolveError::NeedsScene),
    };
    let residual = relative_residual(f, reflectance, emission, &radiosity);
    let report = SolveReport {
        iterations,
        residual,
        elapsed: start.elapsed(),
    };
    progress.message(&format!(
        "solved {} elements by {solver}: relative residual {:.1e} / {:.1e} / {:.1e}",
        f.n(),
        residual[0],
        residual[1],
        residual[2]
    ));
    Ok((radiosity, report))
}

/// Reflectance and emission of every element: those of the scene surface it belongs to.
pub fn element_properties(mesh: &Mesh, scene: &Scene) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    mesh.elements
        .iter()
        .map(|e| {
            let s = &scene.surfaces[e.surface as usize];
            (s.reflectance.0, s.emission.0)
        })
        .unzip()
}

/// [`solve`] for a meshed scene: element i has the reflectance and emission of
/// `scene.surfaces[mesh.elements[i].surface]`.
pub fn solve_scene(
    f: &FormFactorMatrix,
    mesh: &Mesh,
    scene: &Scene,
    solver: Solver,
    progress: &dyn Progress,
) -> Result<(Radiosity, SolveReport), SolveError> {
    let (reflectance, emission) = element_properties(mesh, scene);
    solve(f, &reflectance, &emission, solver, progress)
}

fn check_inputs(
    f: &FormFactorMatrix,
    reflectance: &[[f64; 3]],
    emission: &[[f64; 3]],
    solver: Solver,
) -> Result<(), SolveError> {
    check_properties(f.n(), reflectance, emission)?;
    match solver {
        Solver::GaussSeidel { tolerance, .. } if !(tolerance > 0.0 && tolerance.is_finite()) => {
            Err(SolveError::BadSettings(format!(
                "the Gauss-Seidel tolerance must be a positive number, got {tolerance}"
            )))
        }
        Solver::Progressive { .. } | Solver::Hierarchical(_) => Err(SolveError::NeedsScene),
        _ => Ok(()),
    }
}

/// One reflectance in [0, 1) and one finite emission per element, n elements.
fn check_properties(
    n: usize,
    reflectance: &[[f64; 3]],
    emission: &[[f64; 3]],
) -> Result<(), SolveError> {
    for (what, len) in [
        ("reflectance", reflectance.len()),
        ("emission", emission.len()),
    ] {
        if len != n {
            return Err(SolveError::LengthMismatch { what, len, n });
        }
    }
    for (element, (rho, e)) in reflectance.iter().zip(emission).enumerate() {
        for band in 0..3 {
            let bad = |what, value, why| SolveError::BadValue {
                element,
                what,
                band,
                value,
                why,
            };
            if !(rho[band] >= 0.0 && rho[band] < 1.0) {
                return Err(bad("reflectance", rho[band], "outside [0, 1)"));
            }
            if !e[band].is_finite() {
                return Err(bad("emission", e[band], "not a finite number"));
            }
        }
    }
    Ok(())
}

/// max_i |E_i| per band.
fn max_abs_emission(emission: &[[f64; 3]]) -> [f64; 3] {
    let mut m = [0.0f64; 3];
    for e in emission {
        for b in 0..3 {
            m[b] = m[b].max(e[b].abs());
        }
    }
    m
}

/// Divides an absolute residual by max |E| of its band, where that is not zero.
fn relative(absolute: [f64; 3], scale: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|b| {
        if scale[b] > 0.0 {
            absolute[b] / scale[b]
        } else {
            absolute[b]
        }
    })
}

/// The irradiance-like sums sum_j F_ij B_j of row i in the three bands, B interleaved.
#[inline]
fn row_dot3(row: &[f32], b: &[[f64; 3]]) -> [f64; 3] {
    let (mut s0, mut s1, mut s2) = (0.0, 0.0, 0.0);
    for (&fij, bj) in row.iter().zip(b) {
        let fij = fij as f64;
        s0 += fij * bj[0];
        s1 += fij * bj[1];
        s2 += fij * bj[2];
    }
    [s0, s1, s2]
}

/// max_i |E_i + rho_i sum_j F_ij B_j - B_i| / max_i |E_i| per band, in parallel over rows.
pub fn relative_residual(
    f: &FormFactorMatrix,
    reflectance: &[[f64; 3]],
    emission: &[[f64; 3]],
    radiosity: &Radiosity,
) -> [f64; 3] {
    let b: Vec<[f64; 3]> = (0..radiosity.len()).map(|i| radiosity.element(i)).collect();
    let absolute = (0..f.n())
        .into_par_iter()
        .map(|i| {
            let h = row_dot3(f.row(i), &b);
            std::array::from_fn(|k| (emission[i][k] + reflectance[i][k] * h[k] - b[i][k]).abs())
        })
        .reduce(
            || [0.0f64; 3],
            |x, y| std::array::from_fn(|k| x[k].max(y[k])),
        );
    relative(absolute, max_abs_emission(emission))
}

/// Where the emitted power goes, per band (power = exitance x area, in scene units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyBalance {
    /// sum_i A_i E_i.
    pub emitted: [f64; 3],
    /// sum_j (1 - rho_j) P_j, where P_j = sum_i A_i B_i F_ij is the power arriving at j.
    pub absorbed: [f64; 3],
    /// sum_i A_i B_i (1 - sum_j F_ij): power that leaves the elements and hits nothing.
    pub escaped: [f64; 3],
}

impl EnergyBalance {
    /// The largest |emitted - absorbed - escaped| / emitted over the bands that emit (0 when
    /// nothing is emitted).
    pub fn relative_error(&self) -> f64 {
        (0..3)
            .filter(|&b| self.emitted[b] > 0.0)
            .map(|b| (self.emitted[b] - self.absorbed[b] - self.escaped[b]).abs() / self.emitted[b])
            .fold(0.0, f64::max)
    }
}

/// The energy balance of a solution `radiosity` of (I - rho F) B = E.
///
/// emitted = absorbed + escaped holds to solver precision when F is reciprocal
/// (A_i F_ij = A_j F_ji): the system's row j counts the power arriving at j as
/// A_j sum_i F_ji B_i, which equals sum_i A_i B_i F_ij only under reciprocity. A large
/// [`EnergyBalance::relative_error`] with a small solver residual therefore measures the
/// reciprocity error of the form factors.
pub fn energy_balance(
    f: &FormFactorMatrix,
    areas: &[f64],
    reflectance: &[[f64; 3]],
    emission: &[[f64; 3]],
    radiosity: &Radiosity,
) -> EnergyBalance {
    let n = f.n();
    let mut emitted = [0.0; 3];
    let mut escaped = [0.0; 3];
    let mut arriving = vec![[0.0f64; 3]; n];
    for i in 0..n {
        let leaving: [f64; 3] = std::array::from_fn(|b| areas[i] * radiosity.bands[b][i]);
        let row = f.row(i);
        let mut row_sum = 0.0;
        for (j, &fij) in row.iter().enumerate() {
            let fij = fij as f64;
            row_sum += fij;
            for b in 0..3 {
                arriving[j][b] += leaving[b] * fij;
            }
        }
        for b in 0..3 {
            emitted[b] += areas[i] * emission[i][b];
            escaped[b] += leaving[b] * (1.0 - row_sum);
        }
    }
    let mut absorbed = [0.0; 3];
    for (p, rho) in arriving.iter().zip(reflectance) {
        for b in 0..3 {
            absorbed[b] += (1.0 - rho[b]) * p[b];
        }
    }
    EnergyBalance {
        emitted,
        absorbed,
        escaped,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::progress::NoProgress;

    /// A small deterministic generator (xorshift64*), so tests need no extra crate.
    pub struct Rng(u64);

    impl Rng {
        pub fn new(seed: u64) -> Rng {
            Rng(seed.max(1))
        }
        /// Uniform in [0, 1).
        pub fn next_f64(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A random reciprocal form-factor matrix: random areas, a random symmetric coupling
    /// G_ij = G_ji >= 0 (zero diagonal), F_ij = G_ij / A_i, scaled so the largest row sum is
    /// `max_row_sum`. Returns (F, areas). Reciprocity holds up to f32 rounding of F.
    pub fn random_reciprocal(
        n: usize,
        max_row_sum: f64,
        seed: u64,
    ) -> (FormFactorMatrix, Vec<f64>) {
        let mut rng = Rng::new(seed);
        let areas: Vec<f64> = (0..n).map(|_| 0.5 + rng.next_f64()).collect();
        let mut g = vec![0.0f64; n * n];
        for i in 0..n {
            for j in i + 1..n {
                // Sparse-ish: about a third of the pairs see each other.
                let v = if rng.next_f64() < 0.35 {
                    rng.next_f64()
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

    fn gs(tolerance: f64) -> Solver {
        Solver::GaussSeidel {
            tolerance,
            max_iterations: 100_000,
        }
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
        for solver in [Solver::Lu, gs(1e-13)] {
            let (b, report) = solve(&f, &rho, &e, solver, &NoProgress).unwrap();
            for i in 0..4 {
                for band in 0..3 {
                    let expected = e[i][band] / (1.0 - rho[i][band]);
                    // LU: the system's condition number is at most (1 + rho)/(1 - rho) = 9,
                    // so rounding stays near 1e-15; Gauss-Seidel stops at a relative residual
                    // of 1e-13, and the error is at most condition x residual ~ 1e-12.
                    let err = (b.bands[band][i] - expected).abs() / expected;
                    assert!(err < 1e-11, "{solver}: element {i} band {band}: {err:e}");
                }
            }
            assert!(report.residual.iter().all(|&r| r < 1e-12), "{report:?}");
            assert_eq!(report.iterations.is_some(), solver != Solver::Lu);
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
        for solver in [Solver::Lu, gs(1e-14)] {
            let (b, _) = solve(&matrix, &rho, &e, solver, &NoProgress).unwrap();
            for band in 0..3 {
                let (r1, r2) = (rho[0][band], rho[1][band]);
                let (e1, e2) = (e[0][band], e[1][band]);
                let det = 1.0 - r1 * r2 * f * f;
                let b1 = (e1 + r1 * f * e2) / det;
                let b2 = (e2 + r2 * f * e1) / det;
                // A 2 x 2 system with condition number ~1.2: rounding is ~1e-16; GS stops at
                // relative residual 1e-14, so its error is about that.
                for (got, want) in [(b.bands[band][0], b1), (b.bands[band][1], b2)] {
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
        let mut rng = Rng::new(11);
        let rho: Vec<[f64; 3]> = (0..n)
            .map(|_| std::array::from_fn(|_| 0.9 * rng.next_f64()))
            .collect();
        let e: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                std::array::from_fn(|_| {
                    if rng.next_f64() < 0.1 {
                        10.0 * rng.next_f64()
                    } else {
                        0.0
                    }
                })
            })
            .collect();
        let (lu, lu_report) = solve(&f, &rho, &e, Solver::Lu, &NoProgress).unwrap();
        let (gs_b, gs_report) = solve(&f, &rho, &e, gs(1e-12), &NoProgress).unwrap();
        assert!(
            lu_report.residual.iter().all(|&r| r < 1e-13),
            "{lu_report:?}"
        );
        assert!(
            gs_report.residual.iter().all(|&r| r < 1e-12),
            "{gs_report:?}"
        );
        let scale = max_abs_emission(&e);
        for (band, s) in scale.into_iter().enumerate() {
            for i in 0..n {
                // rho <= 0.9 and row sums <= 0.95 make ||(I - rho F)^-1||_inf <= 1 / (1 -
                // 0.855) ~ 7, so a 1e-12 residual bounds the difference by ~7e-12 of max E:
                // 1e-8 leaves a wide margin, as the brief asks.
                let d = (lu.bands[band][i] - gs_b.bands[band][i]).abs() / s;
                assert!(d < 1e-8, "band {band} element {i}: {d:e}");
            }
        }
    }

    #[test]
    fn grey_scene_factors_once_with_same_answer() {
        let n = 60;
        let (f, _) = random_reciprocal(n, 0.9, 3);
        let mut rng = Rng::new(5);
        let rho: Vec<[f64; 3]> = (0..n).map(|_| [0.8 * rng.next_f64(); 3]).collect();
        let e: Vec<[f64; 3]> = (0..n)
            .map(|_| [rng.next_f64(), 2.0 * rng.next_f64(), 0.0])
            .collect();
        let shared = lu::solve(&f, &rho, &e, true, &NoProgress);
        let separate = lu::solve(&f, &rho, &e, false, &NoProgress);
        for band in 0..3 {
            for i in 0..n {
                // Same matrix, same pivots: the only difference is the order of the solves,
                // so the answers agree to rounding.
                let d = (shared.bands[band][i] - separate.bands[band][i]).abs();
                assert!(d < 1e-12, "band {band} element {i}: {d:e}");
            }
        }
        assert!(shared.bands[2].iter().all(|&b| b == 0.0));
    }

    #[test]
    fn zero_emission_gives_zero() {
        let f = closed_four();
        let rho = [[0.5; 3]; 4];
        let e = [[0.0; 3]; 4];
        for solver in [Solver::Lu, gs(1e-9)] {
            let (b, report) = solve(&f, &rho, &e, solver, &NoProgress).unwrap();
            assert!(b.bands.iter().flatten().all(|&x| x == 0.0), "{solver}");
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
        let err = solve_with_memory(&f, &rho, &e, Solver::Lu, &NoProgress, 1024).unwrap_err();
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
        let solver = Solver::GaussSeidel {
            tolerance: 1e-12,
            max_iterations: 3,
        };
        let err = solve(&f, &rho, &e, solver, &NoProgress).unwrap_err();
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
        let f = closed_four();
        let e = [[1.0; 3]; 4];
        let mut rho = [[0.5; 3]; 4];
        assert!(matches!(
            solve(&f, &rho[..3], &e, Solver::Lu, &NoProgress),
            Err(SolveError::LengthMismatch { n: 4, len: 3, .. })
        ));
        rho[2][1] = 1.0;
        assert!(matches!(
            solve(&f, &rho, &e, Solver::Lu, &NoProgress),
            Err(SolveError::BadValue {
                element: 2,
                band: 1,
                ..
            })
        ));
        rho[2][1] = 0.5;
        assert!(matches!(
            solve(&f, &rho, &e, gs(0.0), &NoProgress),
            Err(SolveError::BadSettings(_))
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
        let (b, _) = solve(&f, &rho, &e, Solver::Lu, &NoProgress).unwrap();
        let bal = energy_balance(&f, &areas, &rho, &e, &b);
        assert_eq!(bal.escaped, [0.0; 3]);
        assert_eq!(bal.emitted, [2.0, 8.0, 1.0]);
        // Exact arithmetic would balance exactly; LU rounding (~1e-16 relative, condition
        // number below 20 at rho = 0.9) leaves errors near 1e-15.
        assert!(bal.relative_error() < 1e-12, "{bal:?}");

        // Open random scene with reciprocal F: a real split between absorbed and escaped.
        let n = 100;
        let (f, areas) = random_reciprocal(n, 0.8, 21);
        let mut rng = Rng::new(2);
        let rho: Vec<[f64; 3]> = (0..n)
            .map(|_| std::array::from_fn(|_| 0.95 * rng.next_f64()))
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
        let (b, _) = solve(&f, &rho, &e, gs(1e-12), &NoProgress).unwrap();
        let bal = energy_balance(&f, &areas, &rho, &e, &b);
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
        use crate::scene::{MeshSettings, Rgb, Surface};
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
            settings: MeshSettings {
                max_patch_area: 1.0,
                integral_steps: 1,
            },
            surfaces: vec![
                Surface {
                    name: "light".into(),
                    emission: Rgb([1.0, 2.0, 3.0]),
                    reflectance: Rgb([0.1, 0.2, 0.3]),
                    vertices: bottom,
                },
                Surface {
                    name: "ceiling".into(),
                    emission: Rgb::BLACK,
                    reflectance: Rgb([0.5, 0.6, 0.7]),
                    vertices: top,
                },
            ],
            camera: None,
        };
        let mesh = mesh_scene(&scene, 1.0).unwrap();
        assert_eq!(mesh.len(), 2);
        let f = 0.1998249f32;
        let matrix = FormFactorMatrix::from_rows(2, vec![0.0, f, f, 0.0]);
        let (b, _) = solve_scene(&matrix, &mesh, &scene, Solver::Lu, &NoProgress).unwrap();
        let f = f as f64;
        for band in 0..3 {
            let (r1, r2) = (0.1 * (band + 1) as f64, 0.5 + 0.1 * band as f64);
            let e1 = (band + 1) as f64;
            let b1 = e1 / (1.0 - r1 * r2 * f * f);
            // A well-conditioned 2 x 2 system: rounding only.
            assert!((b.bands[band][0] - b1).abs() < 1e-13, "band {band}");
            assert!(
                (b.bands[band][1] - r2 * f * b1).abs() < 1e-13,
                "band {band}"
            );
        }
    }

    #[test]
    fn closed_cube_with_computed_form_factors_stays_within_furnace_bounds() {
        use crate::form_factor::{
            compute_matrix, mesh_fingerprint, occluder_bvh, read_form_factors, write_form_factors,
            FormFactorContext, FormFactorMethod, RayCounter,
        };
        use crate::mesh::mesh_scene;
        use crate::scene::{MeshSettings, Rgb, Surface};
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
            settings: MeshSettings {
                max_patch_area: 0.25,
                integral_steps: 2,
            },
            surfaces: faces
                .into_iter()
                .enumerate()
                .map(|(i, vertices)| Surface {
                    name: format!("face{i}"),
                    emission: Rgb([e; 3]),
                    reflectance: Rgb([rho; 3]),
                    vertices,
                })
                .collect(),
            camera: None,
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
        let sums = f.row_sums();
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

        for solver in [Solver::Lu, gs(1e-12)] {
            let (b, _) = solve_scene(&back, &mesh, &scene, solver, &NoProgress).unwrap();
            // Max principle for B = E + rho F B with F >= 0 and uniform E, rho: every B_i lies
            // between E / (1 - rho s_min) and E / (1 - rho s_max). Slack 1e-9 covers the GS
            // tolerance (1e-12 relative residual, amplified at most 1 / (1 - 0.6) times).
            let lo = e / (1.0 - rho * sums.min) - 1e-9;
            let hi = e / (1.0 - rho * sums.max) + 1e-9;
            for (i, &bi) in b.bands[1].iter().enumerate() {
                assert!(
                    lo <= bi && bi <= hi,
                    "{solver}: B_{i} = {bi} not in [{lo}, {hi}]"
                );
            }
            for (r, g) in b.bands[0].iter().zip(&b.bands[1]) {
                // Identical inputs per band; LU solves them as columns of one right-hand
                // side, which may round differently, so allow a few ulps.
                assert!((r - g).abs() < 1e-14 * g, "{solver}: {r} vs {g}");
            }
        }
    }
}
