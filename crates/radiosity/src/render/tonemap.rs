//! From radiosity to 8-bit colour. The paper displays "fractions of the largest radiosity
//! value" (section 2.2) with the gamma correction `color = color ^ (1 / gamma)` of section
//! 2.7; here:
//!
//! * [`Exposure`] chooses the factor that maps radiosity to display values in [0, 1];
//! * [`expose`] applies it and clamps;
//! * [`encode`] (and its table-driven twin [`GammaEncoder`], for images) applies the gamma
//!   correction and quantises to 8 bits;
//! * [`tone_map`] is all of it for one colour;
//! * [`ToneMap`] (and [`to_image`]) all of it for a [`Film`]: per pixel, each sample exposed
//!   and clamped, their mean, then gamma and 8 bits.

use image::RgbImage;
use rayon::prelude::*;

use super::film::{Film, FilmContent};
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

/// Exposure and gamma for whole films, with the gamma table of [`GammaEncoder`] built once.
#[derive(Clone, Debug)]
pub struct ToneMap {
    exposure_scale: f64,
    encoder: GammaEncoder,
}

impl ToneMap {
    /// Multiplies radiosity by `exposure_scale` (see [`Exposure::scale`]) and corrects for
    /// `gamma` (not positive and finite: treated as 1, as [`encode`] does).
    pub fn new(exposure_scale: f64, gamma: f64) -> ToneMap {
        ToneMap {
            exposure_scale,
            encoder: GammaEncoder::new(gamma),
        }
    }

    /// The 8-bit colour of a pixel with the film samples `samples`: each sample exposed
    /// ([`expose`], for a [`FilmContent::Radiosity`] film; coverage is used as it is), the
    /// samples summed in order and divided by their number, then gamma-encoded.
    pub fn pixel(&self, samples: &[[f64; 3]], content: FilmContent) -> [u8; 3] {
        let mut sum = [0.0; 3];
        for s in samples {
            let c = match content {
                FilmContent::Radiosity => expose(*s, self.exposure_scale),
                FilmContent::Coverage => *s,
            };
            for k in 0..3 {
                sum[k] += c[k];
            }
        }
        let count = samples.len() as f64;
        self.encoder.encode(sum.map(|s| s / count))
    }

    /// Writes the 8-bit colours of `film` into `out`, three bytes a pixel, row by row from
    /// the top-left corner; rows in parallel.
    ///
    /// # Panics
    /// If `out` does not have three bytes per pixel of `film`.
    pub fn encode_film(&self, film: &Film, out: &mut [u8]) {
        let (w, n) = (film.width(), film.samples_per_pixel());
        assert_eq!(out.len(), 3 * w * film.height(), "three bytes per pixel");
        if out.is_empty() {
            return;
        }
        let content = film.content();
        out.par_chunks_mut(3 * w)
            .zip(film.samples().par_chunks(w * n))
            .for_each(|(row, samples)| {
                for (rgb, pixel) in row.chunks_exact_mut(3).zip(samples.chunks_exact(n)) {
                    rgb.copy_from_slice(&self.pixel(pixel, content));
                }
            });
    }

    /// `film` as an 8-bit image.
    pub fn image(&self, film: &Film) -> RgbImage {
        let mut buf = vec![0u8; 3 * film.width() * film.height()];
        self.encode_film(film, &mut buf);
        RgbImage::from_raw(film.width() as u32, film.height() as u32, buf)
            .expect("buffer has the image's size")
    }
}

/// `film` as an 8-bit image with exposure `exposure_scale` and `gamma`: see [`ToneMap`].
pub fn to_image(film: &Film, exposure_scale: f64, gamma: f64) -> RgbImage {
    ToneMap::new(exposure_scale, gamma).image(film)
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

    #[test]
    fn films_are_exposed_per_sample_before_the_mean() {
        // One pixel, 2 x 2 samples: a light (4) and three black samples. Exposed and
        // clamped first, 1 / 4 of white: 63.75 -> 64 at gamma 1; the mean first would be 1,
        // white.
        let mut film = Film::new(1, 1, 2, FilmContent::Radiosity);
        film.par_rows_mut()
            .for_each(|(_, row)| row[0] = [4.0, 0.5, 0.0]);
        let img = to_image(&film, 1.0, 1.0);
        assert_eq!(img.get_pixel(0, 0).0, [64, 32, 0]);
        // The exposure scales radiosity: 0.5 * 2 = 1, clamped, over four samples.
        assert_eq!(to_image(&film, 2.0, 1.0).get_pixel(0, 0).0, [64, 64, 0]);
        // Wireframe coverage is not scaled by the exposure.
        let mut lines = Film::new(2, 1, 1, FilmContent::Coverage);
        lines.par_rows_mut().for_each(|(_, row)| row[1] = [1.0; 3]);
        let img = to_image(&lines, 0.25, 2.2);
        assert_eq!(img.get_pixel(0, 0).0, [0; 3]);
        assert_eq!(img.get_pixel(1, 0).0, [255; 3]);
        // A film without pixels makes an empty image.
        let empty = Film::new(0, 3, 1, FilmContent::Radiosity);
        assert_eq!(to_image(&empty, 1.0, 2.2).dimensions(), (0, 3));
    }
}
