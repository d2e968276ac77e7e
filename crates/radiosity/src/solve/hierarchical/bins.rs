//! A cluster's light by direction: six bins, one per signed axis, of the power leaving it
//! (its radiant intensity) and of the irradiance arriving at it (see the module
//! documentation of [`super`], "Clusters: light by direction").

use glam::DVec3;

/// Bin of axis `k` for the sign of `x`.
pub(super) fn bin(k: usize, x: f64) -> usize {
    2 * k + usize::from(x < 0.0)
}

/// (pi times) the intensity of a cluster with power bins `power` along unit `d`.
pub(super) fn cluster_emission(power: &[[f64; 6]; 3], d: DVec3) -> [f64; 3] {
    std::array::from_fn(|band| (0..3).map(|k| d[k].abs() * power[band][bin(k, d[k])]).sum())
}

/// The irradiance bins `incident` as seen by a surface of unit normal `n`.
pub(super) fn irradiance_for(incident: &[[f64; 6]; 3], n: DVec3) -> [f64; 3] {
    std::array::from_fn(|band| {
        (0..3)
            .map(|k| n[k].abs() * incident[band][bin(k, n[k])])
            .sum()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The six axis directions.
    const AXES: [DVec3; 6] = [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];

    #[test]
    fn bins_are_exact_for_axis_aligned_surfaces() {
        // Patches (A, B, normal) facing the six axes: the cluster's intensity towards any d
        // is the sum of the patches' A B max(0, n . d) / pi, to rounding.
        let patches: Vec<(f64, f64, DVec3)> = AXES
            .iter()
            .enumerate()
            .map(|(i, &n)| (1.0 + i as f64, 0.5 + 0.25 * i as f64, n))
            .collect();
        let mut power = [[0.0; 6]; 3];
        for &(a, b, n) in &patches {
            for band in 0..3 {
                for k in 0..3 {
                    power[band][bin(k, n[k])] += a * b * n[k].abs();
                }
            }
        }
        for d in [
            DVec3::new(1.0, 2.0, -3.0),
            DVec3::new(-0.3, 0.1, 0.9),
            DVec3::Y,
        ] {
            let d = d.normalize();
            let want: f64 = patches
                .iter()
                .map(|&(a, b, n)| a * b * n.dot(d).max(0.0))
                .sum();
            let got = cluster_emission(&power, d);
            assert!((got[0] - want).abs() < 1e-12 * want, "{got:?} vs {want}");
        }
        // Light arriving along directions d_j with irradiance I_j (on a surface facing it):
        // a surface of axis normal n receives sum I_j max(0, n . -d_j).
        let arrivals = [
            (DVec3::new(0.2, -1.0, 0.3).normalize(), 2.0),
            (DVec3::new(-1.0, 0.1, 0.0).normalize(), 0.5),
        ];
        let mut incident = [[0.0; 6]; 3];
        for &(d, i) in &arrivals {
            for k in 0..3 {
                for band in 0..3 {
                    incident[band][bin(k, -d[k])] += i * d[k].abs();
                }
            }
        }
        for n in AXES {
            let want: f64 = arrivals.iter().map(|&(d, i)| i * n.dot(-d).max(0.0)).sum();
            let got = irradiance_for(&incident, n);
            assert!((got[1] - want).abs() < 1e-12, "{n}: {got:?} vs {want}");
        }
    }
}
