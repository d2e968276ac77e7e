//! What a path-traced render is asked for ([`PathTraceSettings`]), and why a request is
//! refused ([`PathTraceError`]).

use thiserror::Error;

use crate::light::BadLight;

/// How many paths a pixel gets, how long they may grow, and the seed they are drawn from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathTraceSettings {
    /// Paths per pixel, each through a uniformly random point of the pixel; at least 2 (the
    /// standard error of a mean needs two samples). The noise falls as 1 / sqrt of this.
    pub samples_per_pixel: u32,
    /// The most diffuse reflections a path may make (it then has at most
    /// `max_bounces + 1` surface hits). Russian roulette ends paths long before this in any
    /// scene with reflectances below 1; the cap only bounds the worst case. It cuts the
    /// series of interreflections, so it biases the estimate low by at most
    /// rho_max^(max_bounces + 1) / (1 - rho_max) times the brightest emission (rho_max the
    /// largest reflectance of the scene): below 1e-5 of it for rho_max = 0.95 and the
    /// default 256. 0 shows the emitters only.
    pub max_bounces: u32,
    /// Russian roulette (Arvo and Kirk 1990) starts after this many bounces: the first
    /// `roulette_after_bounces` reflections of a path always happen (unless its throughput
    /// is zero), every later one survives with probability
    /// min(max band of the throughput, 0.95) and is weighted by its inverse. Unbiased for
    /// any value; smaller values make paths shorter and noisier.
    pub roulette_after_bounces: u32,
    /// Next-event estimation: at every bounce also sample a point on an emitter and add
    /// its direct light when nothing blocks it, the two ways of reaching a light combined
    /// with multiple importance sampling (Veach and Guibas 1995, power heuristic), so
    /// nothing is counted twice. Much less noise where lights are small (the Cornell box);
    /// `false` leaves the plain path tracer, which finds a light only by bouncing into it:
    /// a second, independent estimator of the same image.
    pub next_event_estimation: bool,
    /// The seed: pixel p of an image draws from a generator seeded from (seed, p) only, so
    /// the same request gives the same image, bit for bit, on any number of threads.
    pub seed: u64,
}

impl PathTraceSettings {
    /// 256 paths a pixel, at most 256 bounces, roulette after 3, next-event estimation,
    /// seed 1.
    pub const DEFAULT: PathTraceSettings = PathTraceSettings {
        samples_per_pixel: 256,
        max_bounces: 256,
        roulette_after_bounces: 3,
        next_event_estimation: true,
        seed: 1,
    };

    /// The same settings with another number of paths per pixel.
    pub fn with_samples(self, samples_per_pixel: u32) -> PathTraceSettings {
        PathTraceSettings {
            samples_per_pixel,
            ..self
        }
    }

    /// The same settings with another seed.
    pub fn with_seed(self, seed: u64) -> PathTraceSettings {
        PathTraceSettings { seed, ..self }
    }

    /// Refuses settings that cannot give an estimate with a standard error.
    pub fn check(&self) -> Result<(), PathTraceError> {
        if self.samples_per_pixel < MIN_SAMPLES_PER_PIXEL {
            return Err(PathTraceError::TooFewSamples {
                samples_per_pixel: self.samples_per_pixel,
            });
        }
        Ok(())
    }
}

impl Default for PathTraceSettings {
    /// [`PathTraceSettings::DEFAULT`].
    fn default() -> Self {
        PathTraceSettings::DEFAULT
    }
}

/// The fewest paths per pixel: the standard error of a mean needs two samples.
pub const MIN_SAMPLES_PER_PIXEL: u32 = 2;

/// Why a path-traced render was refused.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum PathTraceError {
    /// Fewer than [`MIN_SAMPLES_PER_PIXEL`] paths a pixel.
    #[error("{samples_per_pixel} samples per pixel: at least 2 are needed (the standard error of a pixel's mean needs two samples)")]
    TooFewSamples {
        /// The number asked for.
        samples_per_pixel: u32,
    },
    /// The camera's field of view is not in (0, 180) degrees, or its eye is not finite.
    #[error("camera: {what}")]
    BadCamera {
        /// What is wrong with it.
        what: String,
    },
    /// A surface's reflectance is outside [0, 1) or its emission is not finite and
    /// non-negative (`element` is the surface index).
    #[error(transparent)]
    Light(#[from] BadLight),
    /// A surface has no area, so no normal to tell its front from its back.
    #[error("surface {surface} ({name}) has no area, so no front")]
    Degenerate {
        /// The surface index.
        surface: usize,
        /// Its name.
        name: String,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn too_few_samples_are_refused() {
        let ok = PathTraceSettings::DEFAULT;
        assert_eq!(ok.check(), Ok(()));
        for n in [0, 1] {
            let err = ok.with_samples(n).check().unwrap_err();
            assert_eq!(
                err,
                PathTraceError::TooFewSamples {
                    samples_per_pixel: n
                }
            );
            assert!(err.to_string().contains("at least 2"), "{err}");
        }
        assert_eq!(ok.with_samples(2).check(), Ok(()));
    }
}
