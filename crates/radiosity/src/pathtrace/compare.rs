//! Two linear views of one scene compared pixel by pixel on luminance
//! ([`compare_films`], [`PathTraced::compare`]), and the signed error of every pixel as a
//! false-colour image ([`ErrorMap::to_image`]).
//!
//! Every number is relative to the reference's RMS luminance over the compared pixels (the
//! root of the mean of Y^2, Y = 0.2126 R + 0.7152 G + 0.0722 B of the pixel's mean), not to
//! each pixel's own value: dark pixels (shadows, the backs of surfaces) would otherwise
//! blow small absolute errors up, and the map's RMS is then the reported RMS.

use image::RgbImage;
use thiserror::Error;

use super::estimate::PathTraced;
use crate::light::Rgb;
use crate::progress::NoProgress;
use crate::render::{Camera, Film, FilmContent, Renderer, Shading};
use crate::scene::Scene;

/// The false-colour scale [`ErrorMap::to_image`] falls back to: 20 % of the reference's
/// RMS luminance saturates.
pub const DEFAULT_ERROR_FULL_SCALE: f64 = 0.2;

/// How far one view is from a reference, on luminance, over the pixels compared.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmComparison {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels left out (by the mask).
    pub excluded: usize,
    /// True where every pixel showed an emitter in one view or the other, so none was left
    /// out ([`PathTraced::compare_excluding`]): the emitters themselves are compared.
    pub all_emitters: bool,
    /// The reference's RMS luminance over the compared pixels (the scene's units): the
    /// normaliser of every relative number here.
    pub reference_rms_luminance: f64,
    /// RMS over the compared pixels of Y_other - Y_reference, relative.
    pub rms: f64,
    /// Mean of Y_other - Y_reference, relative (negative: the other view is darker).
    pub bias: f64,
    /// Largest |Y_other - Y_reference|, relative.
    pub max: f64,
    /// For a path-traced reference: the RMS over the compared pixels of its standard error
    /// of luminance, relative. The reference's own noise: a view equal to the true image
    /// would show an `rms` about this size.
    pub reference_noise: Option<f64>,
    /// Every pixel's signed relative difference.
    pub error_map: ErrorMap,
}

impl FilmComparison {
    /// The RMS with the reference's noise taken out, sqrt(max(rms^2 - noise^2, 0)): an
    /// estimate of the other view's own error (the noise is independent of it, so their
    /// squares add). `rms` when the noise is not known.
    pub fn rms_less_noise(&self) -> f64 {
        let noise = self.reference_noise.unwrap_or(0.0);
        (self.rms * self.rms - noise * noise).max(0.0).sqrt()
    }
}

/// Per pixel, row by row from the top-left corner, (Y_other - Y_reference) / the
/// reference's RMS luminance; NaN for a pixel left out.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorMap {
    width: usize,
    height: usize,
    values: Vec<f64>,
}

impl ErrorMap {
    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Every pixel's value, row by row (NaN: left out).
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The value at pixel (x, y), or `None` for a pixel left out.
    ///
    /// # Panics
    /// If (x, y) is outside the map.
    pub fn get(&self, x: usize, y: usize) -> Option<f64> {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) is off the map"
        );
        let v = self.values[y * self.width + x];
        (!v.is_nan()).then_some(v)
    }

    /// The map in false colour (see [`false_colour`]), `full_scale` the relative error that
    /// saturates (not positive and finite: [`DEFAULT_ERROR_FULL_SCALE`]).
    pub fn to_image(&self, full_scale: f64) -> RgbImage {
        let buf: Vec<u8> = self
            .values
            .iter()
            .flat_map(|&v| false_colour((!v.is_nan()).then_some(v), full_scale))
            .collect();
        RgbImage::from_raw(self.width as u32, self.height as u32, buf)
            .expect("buffer has the map's size")
    }
}

/// The colour of a signed relative error `d` on a diverging blue-white-red scale: white
/// for 0; towards pure blue (0, 0, 255) for d < 0 (too dark) and pure red (255, 0, 0) for
/// d > 0 (too bright), reached at |d| = `full_scale` and held beyond. In between the two
/// other channels are round(255 (1 - |d| / full_scale)): linear in 8-bit values, so at
/// full scale 0.2 a pixel 10 % too dark is (128, 128, 255). `None` (a pixel left out) is
/// black. A `full_scale` that is not positive and finite is treated as
/// [`DEFAULT_ERROR_FULL_SCALE`].
pub fn false_colour(d: Option<f64>, full_scale: f64) -> [u8; 3] {
    let Some(d) = d else {
        return [0; 3];
    };
    let scale = if full_scale.is_finite() && full_scale > 0.0 {
        full_scale
    } else {
        DEFAULT_ERROR_FULL_SCALE
    };
    let t = (d.abs() / scale).min(1.0);
    let other = (255.0 * (1.0 - t)).round() as u8;
    if d < 0.0 {
        [other, other, 255]
    } else {
        [255, other, other]
    }
}

/// Why two views could not be compared.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum FilmCompareError {
    /// The films differ in size.
    #[error("the films differ in size: {reference:?} and {other:?} pixels")]
    Sizes {
        /// The reference's width and height.
        reference: (usize, usize),
        /// The other's.
        other: (usize, usize),
    },
    /// The mask does not have one entry per pixel.
    #[error("the mask has {mask} entries for {pixels} pixels")]
    Mask {
        /// Entries given.
        mask: usize,
        /// Pixels of the films.
        pixels: usize,
    },
    /// A film holds wireframe coverage, not radiosity.
    #[error("a film holds wireframe line coverage, not radiosity")]
    NotRadiosity,
    /// The reference is black over the compared pixels (or every pixel is left out).
    #[error("the reference is black over the {pixels} pixels compared: nothing to be relative to")]
    Dark {
        /// Pixels compared.
        pixels: usize,
    },
}

/// The mean luminance of each pixel of `film` (its samples averaged first).
fn pixel_luminance(film: &Film) -> Vec<f64> {
    let n = film.samples_per_pixel();
    film.samples()
        .chunks_exact(n)
        .map(|s| {
            let sum = s.iter().fold(Rgb::BLACK, |a, &b| a + Rgb(b));
            (sum * (1.0 / n as f64)).luminance()
        })
        .collect()
}

/// Compares `other` with `reference` on luminance, leaving out the pixels where `exclude`
/// (one entry per pixel, row by row) is true. Each film's pixel is the mean of its samples
/// (unclamped), so a supersampled radiosity film and a path-traced one compare directly.
/// Every number is relative to the reference's RMS luminance over the compared pixels,
/// not to each pixel's own value (see [`FilmComparison`]), so the error map's RMS is the
/// reported RMS.
pub fn compare_films(
    reference: &Film,
    other: &Film,
    exclude: &[bool],
) -> Result<FilmComparison, FilmCompareError> {
    let size = |f: &Film| (f.width(), f.height());
    if size(reference) != size(other) {
        return Err(FilmCompareError::Sizes {
            reference: size(reference),
            other: size(other),
        });
    }
    let pixels = reference.width() * reference.height();
    if exclude.len() != pixels {
        return Err(FilmCompareError::Mask {
            mask: exclude.len(),
            pixels,
        });
    }
    if [reference, other]
        .iter()
        .any(|f| f.content() != FilmContent::Radiosity)
    {
        return Err(FilmCompareError::NotRadiosity);
    }
    let (yr, yo) = (pixel_luminance(reference), pixel_luminance(other));
    let compared = exclude.iter().filter(|&&e| !e).count();
    let square_sum: f64 = (0..pixels)
        .filter(|&i| !exclude[i])
        .map(|i| yr[i] * yr[i])
        .sum();
    let rms_y = (square_sum / compared.max(1) as f64).sqrt();
    if !(rms_y > 0.0 && rms_y.is_finite()) {
        return Err(FilmCompareError::Dark { pixels: compared });
    }
    let values: Vec<f64> = (0..pixels)
        .map(|i| {
            if exclude[i] {
                f64::NAN
            } else {
                (yo[i] - yr[i]) / rms_y
            }
        })
        .collect();
    let (mut sum, mut squares, mut max) = (0.0, 0.0, 0.0f64);
    for &d in values.iter().filter(|d| !d.is_nan()) {
        sum += d;
        squares += d * d;
        max = max.max(d.abs());
    }
    let k = compared as f64;
    Ok(FilmComparison {
        pixels: compared,
        excluded: pixels - compared,
        all_emitters: false,
        reference_rms_luminance: rms_y,
        rms: (squares / k).sqrt(),
        bias: sum / k,
        max,
        reference_noise: None,
        error_map: ErrorMap {
            width: reference.width(),
            height: reference.height(),
            values,
        },
    })
}

impl PathTraced {
    /// Compares `other` (for example the radiosity renderer's film of the same camera)
    /// with this view as the reference, leaving out the pixels that show an emitter
    /// ([`PathTraced::emitter_mask`]), and reports this view's own noise
    /// ([`FilmComparison::reference_noise`]).
    pub fn compare(&self, other: &Film) -> Result<FilmComparison, FilmCompareError> {
        self.compare_excluding(other, &vec![false; self.emitter_mask().len()])
    }

    /// [`PathTraced::compare`], leaving out also the pixels where `exclude` (one entry per
    /// pixel, row by row) is true: for example those where the other view shows an emitter
    /// ([`emitter_pixels`]), which few paths a pixel can miss on a pixel the light's edge
    /// crosses, and whose emission would then count as the other view's error.
    pub fn compare_excluding(
        &self,
        other: &Film,
        exclude: &[bool],
    ) -> Result<FilmComparison, FilmCompareError> {
        let pixels = self.emitter_mask().len();
        if exclude.len() != pixels {
            return Err(FilmCompareError::Mask {
                mask: exclude.len(),
                pixels,
            });
        }
        let mask: Vec<bool> = self
            .emitter_mask()
            .iter()
            .zip(exclude)
            .map(|(&a, &b)| a || b)
            .collect();
        // Where the two views leave out every pixel between them, every pixel shows an
        // emitter in one: the emitters themselves are compared.
        let all_emitters = mask.iter().all(|&m| m);
        let mask = if all_emitters {
            vec![false; mask.len()]
        } else {
            mask
        };
        let mut c = compare_films(self.film(), other, &mask)?;
        c.all_emitters = all_emitters;
        let squares: f64 = self
            .luminance_standard_errors()
            .iter()
            .zip(&mask)
            .filter(|(_, &e)| !e)
            .map(|(s, _)| s * s)
            .sum();
        c.reference_noise = Some((squares / c.pixels as f64).sqrt() / c.reference_rms_luminance);
        Ok(c)
    }
}

/// The pixels of `camera`'s view in which any of the `supersample` x `supersample` rays of
/// the radiosity renderer (over `renderer`'s mesh, cut from `scene`) first hits an element
/// of an emitting surface: the renderer's own emitter mask, one entry per pixel, row by row.
pub fn emitter_pixels(
    renderer: &Renderer,
    scene: &Scene,
    camera: &Camera,
    supersample: u32,
) -> Vec<bool> {
    let mesh = renderer.mesh();
    let emits: Vec<[f64; 3]> = mesh
        .elements
        .iter()
        .map(|e| {
            let lit = scene
                .surfaces
                .get(e.surface as usize)
                .is_some_and(|s| s.emission.max_band() > 0.0);
            [if lit { 1.0 } else { 0.0 }; 3]
        })
        .collect();
    let film = renderer.film(camera, &emits, &[], Shading::Flat, supersample, &NoProgress);
    film.samples()
        .chunks_exact(film.samples_per_pixel().max(1))
        .map(|s| s.iter().any(|v| v[0] > 0.0))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// A 3 x 2 radiosity film with `f(pixel index)` in every band of each of its samples.
    fn film(supersample: usize, f: impl Fn(usize) -> f64 + Sync) -> Film {
        let mut film = Film::new(3, 2, supersample, FilmContent::Radiosity);
        let n = supersample * supersample;
        film.par_rows_mut().for_each(|(y, row)| {
            for (k, s) in row.iter_mut().enumerate() {
                *s = [f(y * 3 + k / n); 3];
            }
        });
        film
    }

    #[test]
    fn relative_numbers_and_the_mask() {
        // Reference 1..=6, the last pixel masked; the other 10 % brighter everywhere and
        // wildly wrong on the masked pixel: rms = bias = max = 0.1 * (each Y over the RMS
        // of 1..=5), whatever the supersampling.
        let reference = film(1, |i| (i + 1) as f64);
        let other = film(2, |i| if i == 5 { 100.0 } else { 1.1 * (i + 1) as f64 });
        let mask = [false, false, false, false, false, true];
        let c = compare_films(&reference, &other, &mask).unwrap();
        let rms_y = (55.0f64 / 5.0).sqrt();
        assert_eq!((c.pixels, c.excluded), (5, 1));
        assert!((c.reference_rms_luminance - rms_y).abs() < 1e-12);
        assert!((c.rms - 0.1).abs() < 1e-12, "{c:?}");
        assert!((c.bias - 0.1 * 3.0 / rms_y).abs() < 1e-12);
        assert!((c.max - 0.5 / rms_y).abs() < 1e-12);
        assert_eq!(c.error_map.get(2, 1), None);
        assert!((c.error_map.get(1, 0).unwrap() - 0.2 / rms_y).abs() < 1e-12);
        assert_eq!(c.rms_less_noise(), c.rms);
        // Equal films: zero.
        let same = compare_films(&reference, &reference, &[false; 6]).unwrap();
        assert_eq!((same.rms, same.max), (0.0, 0.0));
    }

    #[test]
    fn mismatches_are_refused() {
        let a = film(1, |_| 1.0);
        let small = Film::new(2, 2, 1, FilmContent::Radiosity);
        assert!(matches!(
            compare_films(&a, &small, &[false; 6]),
            Err(FilmCompareError::Sizes { .. })
        ));
        assert_eq!(
            compare_films(&a, &a, &[false; 4]),
            Err(FilmCompareError::Mask { mask: 4, pixels: 6 })
        );
        let lines = Film::new(3, 2, 1, FilmContent::Coverage);
        assert_eq!(
            compare_films(&a, &lines, &[false; 6]),
            Err(FilmCompareError::NotRadiosity)
        );
        let black = film(1, |_| 0.0);
        assert_eq!(
            compare_films(&black, &a, &[false; 6]),
            Err(FilmCompareError::Dark { pixels: 6 })
        );
        assert_eq!(
            compare_films(&a, &a, &[true; 6]),
            Err(FilmCompareError::Dark { pixels: 0 })
        );
    }

    #[test]
    fn false_colour_scale() {
        assert_eq!(false_colour(Some(0.0), 0.2), [255; 3]);
        assert_eq!(false_colour(Some(-0.1), 0.2), [128, 128, 255]);
        assert_eq!(false_colour(Some(0.1), 0.2), [255, 128, 128]);
        assert_eq!(false_colour(Some(-5.0), 0.2), [0, 0, 255]);
        assert_eq!(false_colour(Some(0.2), 0.2), [255, 0, 0]);
        assert_eq!(false_colour(None, 0.2), [0; 3]);
        // A bad scale falls back to the default.
        assert_eq!(
            false_colour(Some(0.1), f64::NAN),
            false_colour(Some(0.1), 0.2)
        );
        // The image: one pixel a colour, row by row.
        let reference = film(1, |i| (i + 1) as f64);
        let darker = film(1, |i| (i + 1) as f64 * if i == 0 { 0.0 } else { 1.0 });
        let mut mask = [false; 6];
        mask[4] = true;
        let c = compare_films(&reference, &darker, &mask).unwrap();
        let img = c.error_map.to_image(0.1);
        assert_eq!(img.dimensions(), (3, 2));
        assert_eq!(img.get_pixel(0, 0).0, [0, 0, 255]);
        assert_eq!(img.get_pixel(1, 0).0, [255; 3]);
        assert_eq!(img.get_pixel(1, 1).0, [0; 3]);
    }
}
