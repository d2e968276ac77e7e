//! The residual of a solution, measured on the returned B (never estimated), so that every
//! solver is reported on the same footing.

use rayon::prelude::*;

use crate::form_factor::FormFactorMatrix;
use crate::light::{ElementLight, Rgb};

/// max_i |E_i| per band.
pub(super) fn max_abs_emission(emission: &[Rgb]) -> [f64; 3] {
    let mut m = [0.0f64; 3];
    for e in emission {
        for b in 0..3 {
            m[b] = m[b].max(e[b].abs());
        }
    }
    m
}

/// Divides an absolute residual by max |E| of its band, where that is not zero.
pub(super) fn relative(absolute: [f64; 3], scale: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|b| {
        if scale[b] > 0.0 {
            absolute[b] / scale[b]
        } else {
            absolute[b]
        }
    })
}

/// The irradiance-like sums sum_j F_ij B_j of row i in the three bands.
#[inline]
pub(super) fn row_dot3(row: &[f32], b: &[Rgb]) -> [f64; 3] {
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
pub fn relative_residual(f: &FormFactorMatrix, light: &ElementLight, b: &[Rgb]) -> [f64; 3] {
    let (reflectance, emission) = (light.reflectance(), light.emission());
    let absolute = (0..f.n())
        .into_par_iter()
        .map(|i| {
            let h = row_dot3(f.row(i), b);
            std::array::from_fn(|k| (emission[i][k] + reflectance[i][k] * h[k] - b[i][k]).abs())
        })
        .reduce(
            || [0.0f64; 3],
            |x, y| std::array::from_fn(|k| x[k].max(y[k])),
        );
    relative(absolute, max_abs_emission(emission))
}
