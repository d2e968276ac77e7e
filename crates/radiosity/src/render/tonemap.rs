//! From radiosity to 8-bit colour. The paper displays "fractions of the largest radiosity
//! value" (section 2.2) with the gamma correction `color = color ^ (1 / gamma)` of section
//! 2.7; here:
//!
//! * [`Exposure`] chooses the factor that maps radiosity to display values in [0, 1];
//! * [`expose`] applies it and clamps;
//! * [`encode`] (and its table-driven twin [`GammaEncoder`], for images) applies the gamma
//!   correction and quantises to 8 bits;
//! * [`tone_map`] is all of it for one colour.

use crate::mesh::Mesh;
use crate::scene::Scene;

/// How radiosities are scaled before display.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// The paper's normalisation (section 2.2: "radiosities are normalized so that all values
    /// are fractions of the largest radiosity value"), with one change: the largest value is
    /// taken over the elements of surfaces that do **not** emit. Emitters are usually far
    /// brighter than anything they light, so normalising by them leaves the walls dim; this
    /// way the brightest lit wall is at full scale, and the light itself is clipped to white,
    /// as a photograph exposed for the room shows it. When every surface emits, the largest
    /// value over all elements is used. When that is zero or not finite the scale is 1.
    Brightest,
    /// Multiply every radiosity by this factor.
    Fixed(f64),
}

impl Exposure {
    /// The factor that radiosities are multiplied by before clamping to [0, 1].
    ///
    /// `element_b` holds one radiosity per element of `mesh`, which was cut from `scene`.
    pub fn scale(self, scene: &Scene, mesh: &Mesh, element_b: &[[f64; 3]]) -> f64 {
        match self {
            Exposure::Fixed(s) => s,
            Exposure::Brightest => {
                let band_max = |b: &[f64; 3]| b[0].max(b[1]).max(b[2]);
                let emits = |s: u32| {
                    scene
                        .surfaces
                        .get(s as usize)
                        .is_some_and(|s| s.emission.max_band() > 0.0)
                };
                let mut lit: Option<f64> = None;
                let mut all: Option<f64> = None;
                for (el, b) in mesh.elements.iter().zip(element_b) {
                    let m = band_max(b);
                    all = Some(all.map_or(m, |a| a.max(m)));
                    if !emits(el.surface) {
                        lit = Some(lit.map_or(m, |a| a.max(m)));
                    }
                }
                match lit.or(all) {
                    Some(m) if m > 0.0 && m.is_finite() => 1.0 / m,
                    _ => 1.0,
                }
            }
        }
    }
}

/// `value * scale` clamped to [0, 1] per band (NaN becomes 0): the display value before
/// gamma correction.
pub fn expose(value: [f64; 3], scale: f64) -> [f64; 3] {
    value.map(|c| {
        let x = c * scale;
        if x > 0.0 {
            x.min(1.0)
        } else {
            0.0
        }
    })
}

/// Gamma-corrects display values in [0, 1] (paper 2.7: `color ^ (1 / gamma)`) and
/// quantises them to 0..=255 with rounding. A `gamma` that is not a positive finite number
/// is treated as 1 (no correction).
pub fn encode(display: [f64; 3], gamma: f64) -> [u8; 3] {
    let inv = if gamma.is_finite() && gamma > 0.0 {
        1.0 / gamma
    } else {
        1.0
    };
    display.map(|c| {
        let c = if c > 0.0 { c.min(1.0) } else { 0.0 };
        (c.powf(inv) * 255.0).round() as u8
    })
}

/// [`encode`] by table lookup, for images: 8-bit level v is the number of levels u in
/// 1..=255 whose threshold ((u - 0.5) / 255)^gamma the value reaches, which is
/// round(255 c^(1/gamma)) without a power per pixel. A branch-free binary search over the
/// 255 thresholds (eight steps; a branching search mispredicted enough to cost 16 % of a
/// render).
#[derive(Clone, Debug)]
pub struct GammaEncoder {
    /// The 255 thresholds, then +infinity, so the table has 256 entries.
    thresholds: [f64; 256],
}

impl GammaEncoder {
    /// The encoder for `gamma` (not positive and finite: treated as 1, as [`encode`] does).
    pub fn new(gamma: f64) -> GammaEncoder {
        let g = if gamma.is_finite() && gamma > 0.0 {
            gamma
        } else {
            1.0
        };
        let mut thresholds = [f64::INFINITY; 256];
        for (u, t) in thresholds.iter_mut().take(255).enumerate() {
            *t = ((u as f64 + 0.5) / 255.0).powf(g);
        }
        GammaEncoder { thresholds }
    }

    /// The 8-bit colour of a display value in [0, 1] per band (clamped).
    pub fn encode(&self, display: [f64; 3]) -> [u8; 3] {
        display.map(|c| {
            let mut level = 0usize;
            for step in [128, 64, 32, 16, 8, 4, 2, 1] {
                level += step * usize::from(self.thresholds[level + step - 1] <= c);
            }
            level as u8
        })
    }
}

/// The 8-bit colour of radiosity `value`: `clamp(value * scale, 0, 1) ^ (1 / gamma)` per
/// band (paper 2.7), times 255, rounded. For example 0.25 with scale 1 and gamma 2 is
/// 0.5, which is 127.5 and rounds to 128.
pub fn tone_map(value: [f64; 3], scale: f64, gamma: f64) -> [u8; 3] {
    encode(expose(value, scale), gamma)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::render::test_support::{scene, surface};
    use crate::scene::Rgb;
    use glam::{dvec3, DVec3};

    // The table must give what the formula gives; values on a fine grid, avoiding exact
    // rounding ties (where the two may differ by the last bit of a power).
    #[test]
    fn gamma_encoder_matches_encode() {
        for gamma in [1.0, 1.8, 2.2, 3.0] {
            let table = GammaEncoder::new(gamma);
            for k in 0..=10_000 {
                let c = k as f64 / 9_999.0 - 1e-4;
                assert_eq!(
                    table.encode([c, c * 0.5, 2.0 * c]),
                    encode([c, c * 0.5, 2.0 * c], gamma),
                    "gamma {gamma}, {c}"
                );
            }
        }
    }

    /// The square [0, 4] x [0, 4] in the plane z = 0.
    fn square4() -> Vec<DVec3> {
        vec![
            dvec3(0., 0., 0.),
            dvec3(4., 0., 0.),
            dvec3(4., 4., 0.),
            dvec3(0., 4., 0.),
        ]
    }

    #[test]
    fn brightest_exposure_skips_emitters() {
        let light = vec![
            dvec3(0., 0., 5.),
            dvec3(1., 0., 5.),
            dvec3(1., 1., 5.),
            dvec3(0., 1., 5.),
        ];
        let s = scene(vec![
            surface("wall", 0.0, square4()),
            surface("light", 10.0, light),
        ]);
        let mesh = mesh_scene(&s, 4.0).unwrap();
        assert_eq!(mesh.len(), 5);
        let mut b = vec![[0.5, 2.0, 1.0]; 5];
        b[4] = [40.0; 3]; // the light
        assert_eq!(Exposure::Brightest.scale(&s, &mesh, &b), 0.5);
        assert_eq!(Exposure::Fixed(3.0).scale(&s, &mesh, &b), 3.0);
        // Every surface emitting: the light counts after all.
        let mut all = s.clone();
        all.surfaces[0].emission = Rgb([1.0; 3]);
        assert_eq!(Exposure::Brightest.scale(&all, &mesh, &b), 1.0 / 40.0);
        // All black: no division by zero.
        assert_eq!(Exposure::Brightest.scale(&s, &mesh, &[[0.0; 3]; 5]), 1.0);
    }

    #[test]
    fn tone_map_exact_values() {
        // 0.25^(1/2) = 0.5 -> 127.5 -> 128.
        assert_eq!(tone_map([0.25; 3], 1.0, 2.0), [128; 3]);
        // Scale, clamping above and below, gamma 1.
        assert_eq!(tone_map([0.5, 3.0, -1.0], 2.0, 1.0), [255, 255, 0]);
        // 0.2 * 255 = 51 exactly; 0.1 * 255 = 25.5 -> 26 (rounding, not truncation).
        assert_eq!(tone_map([0.2, 0.1, 0.0], 1.0, 1.0), [51, 26, 0]);
        // 0.064^(1/3) = 0.4 -> 102.
        assert_eq!(tone_map([0.128; 3], 0.5, 3.0), [102; 3]);
        // NaN is black; a bad gamma means no correction.
        assert_eq!(tone_map([f64::NAN, 0.2, 0.2], 1.0, 0.0), [0, 51, 51]);
    }
}
