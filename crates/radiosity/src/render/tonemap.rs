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

/// The share of the lit surface area whose mean radiosity [`Exposure::Auto`] makes white:
/// the brightest 2 % (see [`lit_radiosity_top_mean`]). Part of the 2 % is above its mean:
/// 0.4 to 1 % of the lit area clips in the scenes measured.
///
/// Chosen by measurement (BENCHMARKS.md, "Automatic exposure"). On the Cornell box at
/// three mesh sizes and by hierarchical radiosity at two, the mean of the brightest 2 %
/// moved by 1.1 %, the 99th area percentile by 2.6 % and the brightest element (the old
/// statistic) by 6.7 %; on `examples/room.scene`'s dense solves at four mesh sizes (whose
/// mean radiosity itself rises by 2.8 % as the mesh is refined) by 3.9 %, 2.6 % and
/// 18.6 %. A percentile jumps where the distribution has a gap (the Cornell box's tall
/// block top, 1.5 % of the area, lies between the 98.5th and 99th percentiles; at
/// `--max-area 2000` the 99th percentile fell 5 % below the finer meshes'), a mean over
/// the tail does not. The brightest 1 % left the Cornell walls darker (its mean is
/// 1.3 times the 2 % mean); the brightest 5 % turned the short block's top nearly white.
pub const AUTO_EXPOSURE_TOP_AREA: f64 = 0.02;

/// How radiosities are scaled before display.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// An exposure for the room, not for its brightest element: the mean radiosity of the
    /// brightest [`AUTO_EXPOSURE_TOP_AREA`] (2 %) of the non-emitting surfaces' area
    /// becomes white ([`lit_radiosity_top_mean`], on each element's largest band), so at most
    /// about 1 % of the lit area clips (0.4 to 1 % in the scenes measured), as in a
    /// photograph exposed for the room, and the lights are white. The statistic is a property of the radiosity over the
    /// surfaces, which a finer mesh or another solver only samples more or less finely, so
    /// it converges as the mesh is refined. The paper's normalisation (section 2.2,
    /// "fractions of the largest radiosity value", here the largest non-emitting element,
    /// which the command line's `auto` was until issue #11) does not: a finer mesh resolves
    /// the peak under a light into smaller, brighter elements, and hierarchical
    /// radiosity's leaves differ again, so the same scene came out darker the finer it was
    /// meshed. When every surface emits, all elements count; when the statistic is zero or
    /// not finite the scale is 1.
    Auto,
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
            Exposure::Auto => scale_for(lit_radiosity_top_mean(
                scene,
                mesh,
                element_b,
                AUTO_EXPOSURE_TOP_AREA,
            )),
        }
    }
}

/// The exposure scale that makes `white` white: 1 / `white`, or 1 when there is none or
/// when it is not a positive number whose inverse is finite.
pub fn scale_for(white: Option<f64>) -> f64 {
    match white.map(|w| 1.0 / w) {
        Some(s) if s > 0.0 && s.is_finite() => s,
        _ => 1.0,
    }
}

/// The mean radiosity of the brightest `fraction` of the area of the surfaces that do not
/// emit (see [`top_mean`]), each element's value its largest band; `fraction` 0 gives the
/// brightest element's value (the paper's normalisation). When every surface emits, all
/// elements count. `None` when there is no element of positive area. `element_b` holds
/// one radiosity per element of `mesh`, which was cut from `scene`.
pub fn lit_radiosity_top_mean(
    scene: &Scene,
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    fraction: f64,
) -> Option<f64> {
    let emits = |s: u32| {
        scene
            .surfaces
            .get(s as usize)
            .is_some_and(|s| s.emission.max_band() > 0.0)
    };
    let values = |lit_only: bool| {
        mesh.elements
            .iter()
            .zip(element_b)
            .filter(move |(el, _)| !(lit_only && emits(el.surface)))
            .map(|(el, b)| (b[0].max(b[1]).max(b[2]), el.area))
    };
    top_mean(values(true), fraction).or_else(|| top_mean(values(false), fraction))
}

/// The weighted mean of the largest `(value, weight)` pairs that together carry `fraction`
/// of the total weight: pairs are taken in decreasing order of value, the last one only in
/// part. For example values 1, 3 and 5 of weights 8, 1 and 1 have top mean 5 for a
/// fraction up to 0.1, 4 for 0.2 and (5 + 3 + 2 x 1) / 4 = 2.5 for 0.4. A `fraction` of 0
/// or less gives the largest value, above 1 the mean of all. Pairs whose weight is not
/// positive and finite, or whose value is NaN, are left out; `None` when none is left.
pub fn top_mean(pairs: impl IntoIterator<Item = (f64, f64)>, fraction: f64) -> Option<f64> {
    let mut pairs: Vec<(f64, f64)> = pairs
        .into_iter()
        .filter(|&(v, w)| !v.is_nan() && w > 0.0 && w.is_finite())
        .collect();
    pairs.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
    let largest = pairs.first()?.0;
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    let want = fraction.min(1.0) * total;
    if want <= 0.0 || want.is_nan() {
        return Some(largest);
    }
    // Take the brightest pairs until `want` weight is taken, the last in part.
    let (mut sum, mut taken) = (0.0, 0.0);
    for &(v, w) in &pairs {
        let take = w.min(want - taken);
        sum += v * take;
        taken += take;
        if taken >= want {
            break;
        }
    }
    Some(sum / taken)
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
    use crate::render::test_support::{facing_minus_z, scene, surface};
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
    fn auto_exposure_skips_emitters() {
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
                          // The wall is uniform: its top 2 % has its largest band, 2.
        assert_eq!(Exposure::Auto.scale(&s, &mesh, &b), 0.5);
        assert_eq!(Exposure::Fixed(3.0).scale(&s, &mesh, &b), 3.0);
        // Every surface emitting: the light counts after all. Its one element has area 1
        // of the 17, more than the 2 %, so the top 2 % is all light.
        let mut all = s.clone();
        all.surfaces[0].emission = Rgb([1.0; 3]);
        assert_eq!(Exposure::Auto.scale(&all, &mesh, &b), 1.0 / 40.0);
        // All black, or not finite: no division by zero, scale 1.
        assert_eq!(Exposure::Auto.scale(&s, &mesh, &[[0.0; 3]; 5]), 1.0);
        assert_eq!(
            Exposure::Auto.scale(&s, &mesh, &[[f64::INFINITY; 3]; 5]),
            1.0
        );
    }

    // A hand-made mesh of one element per surface (MAX_PATCH_AREA above every area): a
    // floor of area 98 at radiosity 1, two tiles of area 1 at 3 and 5 (the largest band
    // counts: green and red), and a light of area 1 at 40, left out. Of the lit area 100,
    // the brightest 2 % is the two tiles: (5 + 3) / 2 = 4, scale 1 / 4. By hand for other
    // shares: 1 % is the brighter tile, 5; 3 % the tiles and 1 of the floor's 98,
    // (5 + 3 + 1) / 3 = 3; 0 the brightest element, 5 (the paper's normalisation); 100 %
    // the area-weighted mean, (98 + 3 + 5) / 100 = 1.06.
    #[test]
    fn auto_exposure_is_the_mean_of_the_brightest_two_percent_of_lit_area() {
        let s = scene(vec![
            surface("floor", 0.0, facing_minus_z(0.0, 14.0, 0.0, 7.0, 0.0)),
            surface("tile3", 0.0, facing_minus_z(0.0, 1.0, 0.0, 1.0, 1.0)),
            surface("tile5", 0.0, facing_minus_z(0.0, 1.0, 0.0, 1.0, 2.0)),
            surface("light", 10.0, facing_minus_z(0.0, 1.0, 0.0, 1.0, 3.0)),
        ]);
        let mesh = mesh_scene(&s, 100.0).unwrap();
        let areas: Vec<f64> = mesh.elements.iter().map(|e| e.area).collect();
        assert_eq!(areas, [98.0, 1.0, 1.0, 1.0]);
        let b = [[1.0; 3], [0.0, 3.0, 1.0], [5.0, 2.0, 0.0], [40.0; 3]];
        assert_eq!(AUTO_EXPOSURE_TOP_AREA, 0.02);
        assert_eq!(Exposure::Auto.scale(&s, &mesh, &b), 0.25);
        for (fraction, mean) in [
            (0.01, 5.0),
            (0.02, 4.0),
            (0.03, 3.0),
            (0.0, 5.0),
            (1.0, 1.06),
        ] {
            let got = lit_radiosity_top_mean(&s, &mesh, &b, fraction).unwrap();
            // 1e-12: the sums of a few numbers of this size, in another order.
            assert!(
                (got - mean).abs() < 1e-12,
                "top {fraction}: {got}, not {mean}"
            );
        }
    }

    #[test]
    fn top_mean_by_hand() {
        // The doc's example: values 1, 3, 5 of weights 8, 1, 1, given in any order.
        let pairs = [(3.0, 1.0), (1.0, 8.0), (5.0, 1.0)];
        for (fraction, mean) in [(0.05, 5.0), (0.1, 5.0), (0.2, 4.0), (0.4, 2.5), (1.0, 1.6)] {
            let got = top_mean(pairs, fraction).unwrap();
            assert!(
                (got - mean).abs() < 1e-12,
                "top {fraction}: {got}, not {mean}"
            );
        }
        // At most 0: the largest value; above 1: the mean of all.
        assert_eq!(top_mean(pairs, 0.0), Some(5.0));
        assert_eq!(top_mean(pairs, -1.0), Some(5.0));
        assert_eq!(top_mean(pairs, 2.0), Some(1.6));
        // NaN values and weights that are not positive and finite are left out.
        let odd = [
            (f64::NAN, 1.0),
            (9.0, 0.0),
            (8.0, -1.0),
            (7.0, f64::INFINITY),
            (2.0, 1.0),
        ];
        assert_eq!(top_mean(odd, 0.5), Some(2.0));
        assert_eq!(top_mean([], 0.02), None);
        assert_eq!(top_mean([(1.0, 0.0)], 0.02), None);
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
