//! The film the ray loop exposes: linear, floating-point values per ray sample, before any
//! exposure, clamping, gamma correction (paper section 2.7) or 8-bit encoding, which
//! [`crate::render::tonemap`] applies afterwards.
//!
//! A pixel of an image supersampled n x n times is the mean of n^2 rays on a regular grid
//! inside it. Exposure clamps each sample to [0, 1] *before* the mean (a pixel half on a
//! light and half on a wall is a half-bright light, not a clipped one), so the film keeps
//! every sample rather than a per-pixel sum: the tone map exposes, sums and divides in the
//! order the renderer always has, and the 8-bit image is the same to the last bit.
//!
//! Values are `f64`, what the renderer computes with, so nothing is rounded between the
//! ray and the tone map.

use rayon::prelude::*;

/// What the values of a [`Film`] are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilmContent {
    /// Radiosity (or interpolated radiosity) in the scene's units; the tone map scales it
    /// by the exposure and clamps it to [0, 1].
    Radiosity,
    /// Line coverage of a wireframe drawing, 0 (background) or 1 (an edge) per band: a
    /// display value already, which exposure does not scale.
    Coverage,
}

/// A `width` x `height` film with `supersample` x `supersample` RGB samples per pixel.
///
/// Sample (i, j) of pixel (x, y) (i across, j down, both in `0..supersample`) is the ray
/// through image point (x + [`sample_offset`]`(i, n)`, y + `sample_offset(j, n)`); the
/// samples of a pixel are stored row by row (index j n + i), pixels row by row from the
/// top-left corner.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: usize,
    height: usize,
    supersample: usize,
    content: FilmContent,
    samples: Vec<[f64; 3]>,
}

/// Where sample `i` of `n` lies across a pixel, in pixels from its left (or top) edge: the
/// centres of n equal strips, (i + 0.5) / n.
pub fn sample_offset(i: usize, n: usize) -> f64 {
    (i as f64 + 0.5) / n as f64
}

impl Film {
    /// A black film (every sample zero). `supersample` 0 is treated as 1.
    pub fn new(width: usize, height: usize, supersample: usize, content: FilmContent) -> Film {
        let supersample = supersample.max(1);
        Film {
            width,
            height,
            supersample,
            content,
            samples: vec![[0.0; 3]; width * height * supersample * supersample],
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Samples per pixel along each axis (at least 1).
    pub fn supersample(&self) -> usize {
        self.supersample
    }

    /// Samples per pixel: `supersample` squared.
    pub fn samples_per_pixel(&self) -> usize {
        self.supersample * self.supersample
    }

    /// What the values are.
    pub fn content(&self) -> FilmContent {
        self.content
    }

    /// Every sample, in the order described at [`Film`].
    pub fn samples(&self) -> &[[f64; 3]] {
        &self.samples
    }

    /// The samples of pixel (x, y), row by row.
    ///
    /// # Panics
    /// If (x, y) is outside the film.
    pub fn pixel(&self, x: usize, y: usize) -> &[[f64; 3]] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) is off the film"
        );
        let n = self.samples_per_pixel();
        let first = (y * self.width + x) * n;
        &self.samples[first..first + n]
    }

    /// The rows of samples, in parallel, each with its row index (0 at the top): what the
    /// ray loop writes into.
    pub fn par_rows_mut(
        &mut self,
    ) -> impl IndexedParallelIterator<Item = (usize, &mut [[f64; 3]])> {
        let row = (self.width * self.samples_per_pixel()).max(1);
        self.samples.par_chunks_mut(row).enumerate()
    }

    /// Each pixel's value: the plain mean of its samples, unclamped and unexposed (what a
    /// linear image such as OpenEXR holds), pixels row by row from the top-left corner.
    pub fn pixel_means(&self) -> Vec<[f64; 3]> {
        let n = self.samples_per_pixel();
        self.samples
            .chunks_exact(n)
            .map(|pixel| {
                let mut sum = [0.0; 3];
                for s in pixel {
                    for k in 0..3 {
                        sum[k] += s[k];
                    }
                }
                sum.map(|x| x / n as f64)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_and_sample_grid() {
        let mut film = Film::new(3, 2, 2, FilmContent::Radiosity);
        assert_eq!(film.samples().len(), 3 * 2 * 4);
        assert_eq!(film.samples_per_pixel(), 4);
        film.par_rows_mut().for_each(|(y, row)| {
            for (k, s) in row.iter_mut().enumerate() {
                *s = [y as f64, (k / 4) as f64, (k % 4) as f64];
            }
        });
        // Pixel (2, 1): row 1, third pixel, its four samples in order.
        assert_eq!(
            film.pixel(2, 1),
            &[
                [1.0, 2.0, 0.0],
                [1.0, 2.0, 1.0],
                [1.0, 2.0, 2.0],
                [1.0, 2.0, 3.0]
            ]
        );
        assert_eq!(Film::new(1, 1, 0, FilmContent::Coverage).supersample(), 1);
        assert_eq!(
            (0..4).map(|i| sample_offset(i, 4)).collect::<Vec<_>>(),
            [0.125, 0.375, 0.625, 0.875]
        );
        assert_eq!(sample_offset(0, 1), 0.5);
        // Pixel means: the mean of each pixel's four samples, nothing clamped.
        let means = film.pixel_means();
        assert_eq!(means.len(), 6);
        assert_eq!(means[5], [1.0, 2.0, 1.5]);
        // An empty film has no rows to write.
        assert_eq!(
            Film::new(0, 5, 1, FilmContent::Radiosity)
                .par_rows_mut()
                .count(),
            0
        );
    }
}
