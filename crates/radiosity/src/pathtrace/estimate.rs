//! A path-traced image: the mean of each pixel's paths as a linear [`Film`], with the
//! standard error of each mean and the mask of pixels that show an emitter
//! ([`PathTraced`]); and the running mean and variance that make them (`Accumulator`).

use crate::light::Rgb;
use crate::render::tonemap::{scale_for, top_mean, AUTO_EXPOSURE_TOP_AREA};
use crate::render::{Film, FilmContent};

/// The running mean and sum of squared deviations of a pixel's samples, per band and on
/// luminance: Welford's update (Welford 1962, "Note on a method for calculating corrected
/// sums of squares and products", Technometrics 4), which keeps the variance accurate when
/// it is small beside the squared mean (a furnace, where every path returns nearly the
/// same value).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Accumulator {
    count: u64,
    mean: Rgb,
    squares: Rgb,
    mean_y: f64,
    squares_y: f64,
}

impl Accumulator {
    /// Adds one sample.
    #[inline]
    pub(super) fn add(&mut self, x: Rgb) {
        self.count += 1;
        let k = self.count as f64;
        let delta = x - self.mean;
        self.mean += delta * (1.0 / k);
        self.squares += delta * (x - self.mean);
        let y = x.luminance();
        let delta_y = y - self.mean_y;
        self.mean_y += delta_y / k;
        self.squares_y += delta_y * (y - self.mean_y);
    }

    /// The mean and its standard error s / sqrt(n), s^2 the unbiased sample variance, per
    /// band and on luminance (0 for fewer than two samples).
    pub(super) fn finish(&self, shows_emitter: bool) -> PixelEstimate {
        let n = self.count as f64;
        let se = |squares: f64| {
            if self.count < 2 {
                0.0
            } else {
                (squares.max(0.0) / (n - 1.0) / n).sqrt()
            }
        };
        PixelEstimate {
            mean: self.mean,
            standard_error: self.squares.map(se),
            luminance_standard_error: se(self.squares_y),
            shows_emitter,
        }
    }
}

/// One pixel's estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PixelEstimate {
    pub(super) mean: Rgb,
    pub(super) standard_error: Rgb,
    pub(super) luminance_standard_error: f64,
    pub(super) shows_emitter: bool,
}

/// A path-traced view: per pixel the mean radiosity B = pi L of its paths, in the scene's
/// units and the quantity [`crate::render::render`] shows (a surface of uniform
/// radiosity B renders as B), with the standard error of that mean.
///
/// [`PathTraced::film`] is a linear [`Film`] with one sample a pixel (the mean), so
/// [`crate::render::tonemap`] turns it into an image with the exposure and gamma of the
/// radiosity renderer, and [`super::compare_films`] compares it with the radiosity
/// renderer's film. (The radiosity film keeps every ray sample and its tone map clamps
/// each before their mean; this film's mean is clamped once. The two differ only on
/// pixels that straddle an edge between values above and below full scale, such as the
/// rim of a light.)
#[derive(Clone, Debug, PartialEq)]
pub struct PathTraced {
    film: Film,
    standard_error: Vec<Rgb>,
    luminance_standard_error: Vec<f64>,
    shows_emitter: Vec<bool>,
    samples_per_pixel: u32,
}

/// The noise of a [`PathTraced`] view over the pixels that show no emitter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseSummary {
    /// Pixels counted (those whose paths never first hit an emitter).
    pub pixels: usize,
    /// The mean over those pixels of the standard error of luminance.
    pub mean_standard_error: f64,
    /// The root mean square over those pixels of the standard error of luminance.
    pub rms_standard_error: f64,
    /// The mean luminance of those pixels.
    pub mean_luminance: f64,
}

impl NoiseSummary {
    /// [`NoiseSummary::rms_standard_error`] over [`NoiseSummary::mean_luminance`] (NaN
    /// for a black view): the relative noise of the image.
    pub fn relative(&self) -> f64 {
        self.rms_standard_error / self.mean_luminance
    }
}

impl PathTraced {
    /// Assembles a view from its pixels, row by row from the top-left corner.
    pub(super) fn from_pixels(
        width: usize,
        height: usize,
        samples_per_pixel: u32,
        pixels: &[PixelEstimate],
    ) -> PathTraced {
        assert_eq!(pixels.len(), width * height, "one estimate per pixel");
        let mut film = Film::new(width, height, 1, FilmContent::Radiosity);
        use rayon::prelude::*;
        film.par_rows_mut().for_each(|(y, row)| {
            for (sample, p) in row.iter_mut().zip(&pixels[y * width..]) {
                *sample = p.mean.0;
            }
        });
        PathTraced {
            film,
            standard_error: pixels.iter().map(|p| p.standard_error).collect(),
            luminance_standard_error: pixels.iter().map(|p| p.luminance_standard_error).collect(),
            shows_emitter: pixels.iter().map(|p| p.shows_emitter).collect(),
            samples_per_pixel,
        }
    }

    /// A view from its parts, as a file reader finds them ([`crate::io::path_traced_file`]):
    /// a film of one sample a pixel, and per pixel (row by row) the standard error per band
    /// and on luminance and whether it shows an emitter.
    ///
    /// # Panics
    /// If the film has more than one sample a pixel or is not radiosity, or a list does not
    /// have one entry per pixel.
    pub(crate) fn from_parts(
        film: Film,
        standard_error: Vec<Rgb>,
        luminance_standard_error: Vec<f64>,
        shows_emitter: Vec<bool>,
        samples_per_pixel: u32,
    ) -> PathTraced {
        let pixels = film.width() * film.height();
        assert!(film.samples_per_pixel() == 1 && film.content() == FilmContent::Radiosity);
        assert!(
            standard_error.len() == pixels
                && luminance_standard_error.len() == pixels
                && shows_emitter.len() == pixels,
            "one entry per pixel"
        );
        PathTraced {
            film,
            standard_error,
            luminance_standard_error,
            shows_emitter,
            samples_per_pixel,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.film.width()
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.film.height()
    }

    /// Paths per pixel.
    pub fn samples_per_pixel(&self) -> u32 {
        self.samples_per_pixel
    }

    /// The linear film of pixel means (one sample a pixel, [`FilmContent::Radiosity`]).
    pub fn film(&self) -> &Film {
        &self.film
    }

    /// The film, without the error estimates.
    pub fn into_film(self) -> Film {
        self.film
    }

    fn index(&self, x: usize, y: usize) -> usize {
        assert!(
            x < self.width() && y < self.height(),
            "pixel ({x}, {y}) is off the image"
        );
        y * self.width() + x
    }

    /// The mean radiosity of pixel (x, y) (x across from the left, y down from the top).
    ///
    /// # Panics
    /// If (x, y) is outside the image (so for every pixel of an empty one).
    pub fn radiosity(&self, x: usize, y: usize) -> Rgb {
        Rgb(self.film.pixel(x, y)[0])
    }

    /// The standard error of pixel (x, y)'s mean, per band.
    ///
    /// # Panics
    /// If (x, y) is outside the image.
    pub fn standard_error(&self, x: usize, y: usize) -> Rgb {
        self.standard_error[self.index(x, y)]
    }

    /// The standard error of the mean luminance of pixel (x, y) (not a function of the
    /// bands' errors: the bands of one path are correlated).
    ///
    /// # Panics
    /// If (x, y) is outside the image.
    pub fn luminance_standard_error(&self, x: usize, y: usize) -> f64 {
        self.luminance_standard_error[self.index(x, y)]
    }

    /// True when some path of pixel (x, y) first hit the front of an emitting surface.
    ///
    /// # Panics
    /// If (x, y) is outside the image.
    pub fn shows_emitter(&self, x: usize, y: usize) -> bool {
        self.shows_emitter[self.index(x, y)]
    }

    /// Per pixel, row by row, the standard error per band.
    pub fn standard_errors(&self) -> &[Rgb] {
        &self.standard_error
    }

    /// Per pixel, row by row, the standard error of luminance.
    pub fn luminance_standard_errors(&self) -> &[f64] {
        &self.luminance_standard_error
    }

    /// Per pixel, row by row, whether it shows an emitter (see
    /// [`PathTraced::shows_emitter`]): the mask a comparison leaves out, since an
    /// emitter's radiosity is its given E plus a reflected part the other renderer may
    /// or may not compute the same way, and it outshines every error elsewhere.
    pub fn emitter_mask(&self) -> &[bool] {
        &self.shows_emitter
    }

    /// The noise over the pixels that show no emitter, or over all where every pixel
    /// shows one (a view of emitters alone: QA of issue #16 found "none to measure ... 0
    /// pixels" there); zeros for an empty image.
    pub fn noise(&self) -> NoiseSummary {
        let (mut pixels, mut se, mut se2, mut y) = (0usize, 0.0, 0.0, 0.0);
        let leave_out = !self.shows_emitter.iter().all(|&e| e);
        for (i, sample) in self.film.samples().iter().enumerate() {
            if leave_out && self.shows_emitter[i] {
                continue;
            }
            let s = self.luminance_standard_error[i];
            pixels += 1;
            se += s;
            se2 += s * s;
            y += Rgb(*sample).luminance();
        }
        let k = pixels.max(1) as f64;
        NoiseSummary {
            pixels,
            mean_standard_error: se / k,
            rms_standard_error: (se2 / k).sqrt(),
            mean_luminance: y / k,
        }
    }

    /// An exposure for a view without a radiosity solution, by the rule of
    /// [`crate::render::tonemap::Exposure::Auto`] over the film: the radiosity that
    /// [`PathTraced::auto_exposure_white`] gives is white; 1 when there is none. It is a
    /// statistic of the view (the share of the picture), where the radiosity exposure weighs
    /// the whole scene's area, so the two differ where the view leaves out the brightest
    /// surfaces; when a radiosity solution of the scene is at hand, its exposure is the one
    /// to share. A mean of many noisy pixels is far less biased than their largest, which
    /// the noise pushes up.
    pub fn auto_exposure_scale(&self) -> f64 {
        scale_for(self.auto_exposure_white())
    }

    /// The mean of the largest band of the brightest
    /// [`crate::render::tonemap::AUTO_EXPOSURE_TOP_AREA`] (2 %) of the pixels that show no
    /// emitter, each of weight one; of all pixels when those show nothing lit (every pixel
    /// shows an emitter, as the radiosity rule counts all area when every surface emits,
    /// or the rest is black background: a glowing panel against the sky). `None` when the
    /// film has no pixel or neither mean is above 0 (nothing lit to expose for).
    pub fn auto_exposure_white(&self) -> Option<f64> {
        let pixels = |lit_only: bool| {
            self.film
                .samples()
                .iter()
                .zip(&self.shows_emitter)
                .filter(move |(_, &emitter)| !(lit_only && emitter))
                .map(|(s, _)| (Rgb(*s).max_band(), 1.0))
        };
        top_mean(pixels(true), AUTO_EXPOSURE_TOP_AREA)
            .filter(|&white| white > 0.0)
            .or_else(|| top_mean(pixels(false), AUTO_EXPOSURE_TOP_AREA))
            .filter(|&white| white > 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // 101 pixels in a row: 98 at radiosity 1, one at 3 (green), one at 5 (red), and an
    // emitter at 40, left out. The brightest 2 % of the 100 others are the 5 and the 3:
    // mean 4, scale 1 / 4.
    #[test]
    fn auto_exposure_is_the_mean_of_the_brightest_two_percent_of_pixels() {
        use rayon::prelude::*;
        let mut values = vec![[1.0; 3]; 101];
        values[10] = [0.0, 3.0, 1.0];
        values[50] = [5.0, 2.0, 0.0];
        values[70] = [40.0; 3];
        let mut film = Film::new(101, 1, 1, FilmContent::Radiosity);
        film.par_rows_mut()
            .for_each(|(_, row)| row.copy_from_slice(&values));
        let mut emitter = vec![false; 101];
        emitter[70] = true;
        let view = |emitter: Vec<bool>, film: Film| {
            PathTraced::from_parts(film, vec![Rgb::BLACK; 101], vec![0.0; 101], emitter, 4)
        };
        assert_eq!(view(emitter, film.clone()).auto_exposure_scale(), 0.25);
        // Every pixel an emitter (QA pass 15 of issue #16: a glowing box printed the
        // fallback 1): all pixels count, as all area does where every surface emits. The
        // brightest 2 % of 101 pixels are 2.02 of them: 40, 5 and 0.02 of the 3.
        let white = view(vec![true; 101], film).auto_exposure_white().unwrap();
        let expected = (40.0 + 5.0 + 0.02 * 3.0) / 2.02;
        assert!((white - expected).abs() < 1e-12, "{white} vs {expected}");
        // A lit emitter against black background (review: "no pixel shows light" was
        // printed over a glowing panel): the emitter's pixel counts. The brightest 2 % of
        // 101 pixels are the 40 and 1.02 black ones.
        let mut panel = vec![[0.0; 3]; 101];
        panel[70] = [40.0; 3];
        let mut lit = Film::new(101, 1, 1, FilmContent::Radiosity);
        lit.par_rows_mut()
            .for_each(|(_, row)| row.copy_from_slice(&panel));
        let mut emitter = vec![false; 101];
        emitter[70] = true;
        let white = view(emitter, lit).auto_exposure_white().unwrap();
        assert!((white - 40.0 / 2.02).abs() < 1e-12, "{white}");
        // Nothing lit: no white, scale 1.
        let dark = Film::new(101, 1, 1, FilmContent::Radiosity);
        assert_eq!(
            view(vec![false; 101], dark.clone()).auto_exposure_white(),
            None
        );
        assert_eq!(view(vec![false; 101], dark).auto_exposure_scale(), 1.0);
    }

    #[test]
    fn welford_gives_the_textbook_standard_error() {
        // Samples 1, 2, 3, 4 (red), constant 5 (green): mean 2.5, sample variance 5/3,
        // standard error sqrt(5/3 / 4); green has none.
        let mut acc = Accumulator::default();
        for k in 1..=4 {
            acc.add(Rgb([k as f64, 5.0, 0.0]));
        }
        let p = acc.finish(false);
        assert_eq!(p.mean, Rgb([2.5, 5.0, 0.0]));
        assert!((p.standard_error[0] - (5.0f64 / 12.0).sqrt()).abs() < 1e-15);
        assert_eq!(p.standard_error[1], 0.0);
        // Luminance 0.2126 k + 0.7152 * 5: its error is 0.2126 times red's.
        assert!((p.luminance_standard_error - 0.2126 * p.standard_error[0]).abs() < 1e-15);
        // A large mean does not swamp a small variance.
        let mut big = Accumulator::default();
        for k in 0..1000 {
            big.add(Rgb::splat(1e9 + (k % 2) as f64));
        }
        let se = big.finish(false).standard_error[0];
        let exact = (0.25f64 * 1000.0 / 999.0 / 1000.0).sqrt();
        assert!((se - exact).abs() < 1e-9 * exact, "{se} vs {exact}");
    }
}
