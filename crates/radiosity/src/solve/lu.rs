//! The direct solver: LU factorisation with partial pivoting (faer), the paper's "Gaussian
//! elimination with pivoting" (text after figure 6).
//!
//! faer stores matrices column by column, while the form factors are stored row by row. So
//! instead of M = I - diag(rho) F we fill A = M^T, whose column i is row i of M, reading each
//! row of F contiguously, factor P A = L U in place (no second n x n copy: the low-level
//! faer routine overwrites A with L and U), and solve M x = A^T x = E with the transposed
//! solve. Partial pivoting on M^T is column pivoting on M; M^T is column diagonally dominant
//! (rho < 1, row sums of F <= 1), a case in which LU is stable.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve as lu_solve};
use faer::{get_global_parallelism, Mat};

use super::Radiosity;
use crate::form_factor::{check_dense_fits, FormFactorMatrix, OutOfMemory};
use crate::light::{ElementLight, Rgb};
use crate::progress::{run_stage, Progress, Stage};

/// Bytes per matrix entry the LU solver needs: the f64 matrix, factored in place. faer's
/// other needs (the pivot permutation, the right-hand sides) are O(n) and covered by the
/// 10 % headroom of [`check_dense_fits`].
const BYTES_PER_ENTRY: f64 = 8.0;

/// Refuses, before any allocation, an LU matrix that would not fit in `available` bytes.
pub(super) fn check_memory(n: usize, available: u64) -> Result<(), OutOfMemory> {
    check_dense_fits("the LU matrix (f64)", n, BYTES_PER_ENTRY, available)
}

/// Solves all three bands. With `share`, bands whose reflectance vectors are identical (all
/// three in a grey scene) share one factorisation and are solved together.
///
/// The caller has checked the inputs and the memory ([`check_memory`]).
pub(super) fn solve(
    f: &FormFactorMatrix,
    light: &ElementLight,
    share: bool,
    progress: &dyn Progress,
) -> Radiosity {
    let (reflectance, emission) = (light.reflectance(), light.emission());
    let n = f.n();
    // Group the bands by reflectance vector: groups[g] lists the bands factored together.
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for band in 0..3 {
        let same = |g: &Vec<usize>| {
            share
                && reflectance
                    .iter()
                    .all(|rho| rho[g[0]].to_bits() == rho[band].to_bits())
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(band),
            None => groups.push(vec![band]),
        }
    }
    let mut out = Radiosity(vec![Rgb::BLACK; n]);
    run_stage(progress, Stage::Solve, groups.len() as u64, || {
        let par = get_global_parallelism();
        for bands in &groups {
            let rho_band = bands[0];
            // A = M^T: A[i][j] = M[j][i] = delta_ij - rho_j F_ji; column j of A is row j of M.
            let mut a = Mat::<f64>::from_fn(n, n, |i, j| {
                let m = -reflectance[j][rho_band] * f.get(j, i);
                if i == j {
                    1.0 + m
                } else {
                    m
                }
            });
            let mut rhs = Mat::<f64>::from_fn(n, bands.len(), |i, k| emission[i][bands[k]]);

            let mut perm = vec![0usize; n];
            let mut perm_inv = vec![0usize; n];
            let scratch = StackReq::any_of(&[
                factor::lu_in_place_scratch::<usize, f64>(n, n, par, Default::default()),
                lu_solve::solve_transpose_in_place_scratch::<usize, f64>(n, bands.len(), par),
            ]);
            let mut buffer = MemBuffer::new(scratch);
            let stack = MemStack::new(&mut buffer);
            let (_, p) = factor::lu_in_place(
                a.as_mut(),
                &mut perm,
                &mut perm_inv,
                par,
                stack,
                Default::default(),
            );
            // L (unit lower) and U (upper) share the storage of A: the triangular solves read
            // only their own triangle.
            lu_solve::solve_transpose_in_place(a.as_ref(), a.as_ref(), p, rhs.as_mut(), par, stack);

            for (k, &band) in bands.iter().enumerate() {
                for (b, &x) in out.0.iter_mut().zip(rhs.col_as_slice(k)) {
                    b[band] = x;
                }
            }
            progress.advance(1);
        }
    });
    out
}
