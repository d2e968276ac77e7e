//! The energy account of a solution: every watt emitted is either absorbed by some element
//! or escapes the scene.

use crate::form_factor::FormFactorMatrix;
use crate::light::{ElementLight, Rgb};

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
    light: &ElementLight,
    radiosity: &[Rgb],
) -> EnergyBalance {
    let (reflectance, emission) = (light.reflectance(), light.emission());
    let n = f.n();
    let mut emitted = [0.0; 3];
    let mut escaped = [0.0; 3];
    let mut arriving = vec![[0.0f64; 3]; n];
    for i in 0..n {
        let leaving: [f64; 3] = std::array::from_fn(|b| areas[i] * radiosity[i][b]);
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
