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

/// Where the escaped power of [`energy_balance`] leaves: per input surface s, the sum over
/// its elements i of A_i B_i (1 - sum_j F_ij), per band. In a closed scene every row sums
/// to 1 and this is the form factors' error, element by element: positive where light is
/// lost (into gaps, backs of faces, or missed by the quadrature), negative where it is
/// counted twice (rows above 1). `surface_of[i]` is element i's surface; the result has
/// `surfaces` entries and sums to [`EnergyBalance::escaped`].
pub fn escaped_by_surface(
    f: &FormFactorMatrix,
    areas: &[f64],
    surface_of: &[u32],
    surfaces: usize,
    radiosity: &[Rgb],
) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0; 3]; surfaces];
    for i in 0..f.n() {
        let lost = 1.0 - f.row_sum(i);
        if let Some(s) = out.get_mut(surface_of[i] as usize) {
            for b in 0..3 {
                s[b] += areas[i] * radiosity[i][b] * lost;
            }
        }
    }
    out
}

#[cfg(test)]
mod escaped_tests {
    use super::*;

    #[test]
    fn escaped_power_by_surface_sums_to_the_balance_and_lands_where_rows_fall_short() {
        // Three elements on two surfaces: rows 0.5 (loses half), 1.0, 1.2 (counts 0.2 twice).
        let f = FormFactorMatrix::from_rows(3, vec![0.0, 0.25, 0.25, 0.5, 0.0, 0.5, 0.6, 0.6, 0.0]);
        let areas = [1.0, 2.0, 1.0];
        let light = ElementLight::new(vec![Rgb([0.5; 3]); 3], vec![Rgb([1.0; 3]); 3]).unwrap();
        let b = [Rgb([2.0; 3]), Rgb([1.0; 3]), Rgb([3.0; 3])];
        let by_surface = escaped_by_surface(&f, &areas, &[0, 1, 1], 2, &b);
        // Surface 0: 1 x 2 x 0.5 = 1; surface 1: 2 x 1 x 0 + 1 x 3 x (-0.2) = -0.6.
        assert!((by_surface[0][0] - 1.0).abs() < 1e-6, "{by_surface:?}");
        assert!((by_surface[1][0] + 0.6).abs() < 1e-6, "{by_surface:?}");
        let balance = energy_balance(&f, &areas, &light, &b);
        let total: f64 = by_surface.iter().map(|s| s[1]).sum();
        assert!((total - balance.escaped[1]).abs() < 1e-9);
    }
}
