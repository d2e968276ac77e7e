//! The work budget: how much a run would compute, estimated from its settings before it
//! starts, and refused past a limit with what would fit. (The memory budget is
//! [`crate::form_factor::available_memory_bytes`], which every memory estimate is checked
//! against.)
//!
//! Each limit is a count of the run's unit of work, set at about an hour or more of the
//! measured rate on this project's two-core machine (BENCHMARKS.md conditions), so no
//! ordinary run meets it and a run of weeks is refused before it starts. The caller may
//! choose to skip the check (the command line's `--no-work-limit`).

use crate::form_factor::FormFactorMethod;

/// Work past its limit.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
#[error(
    "{what} means {amount:.2e} {unit}, more than the work limit of {limit:.0e} ({rate}); \
     {fits}"
)]
pub struct TooMuchWork {
    /// The settings that make the work ("INTEGRAL_STEPS 1000 on 13 elements").
    pub what: String,
    /// The units of work.
    pub amount: f64,
    /// What one unit is ("point pairs").
    pub unit: &'static str,
    /// The limit.
    pub limit: f64,
    /// The measured rate the limit was set from.
    pub rate: &'static str,
    /// What would fit ("at most INTEGRAL_STEPS 189 on these elements").
    pub fits: String,
}

/// Buffers past the memory budget ([`crate::form_factor::available_memory_bytes`]).
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
#[error(
    "{what} needs {needed_mib:.0} MiB, but only {available_mib:.0} MiB of memory is \
     available; {fits}"
)]
pub struct TooMuchMemory {
    /// The settings and what they allocate.
    pub what: String,
    /// MiB needed.
    pub needed_mib: f64,
    /// MiB available.
    pub available_mib: f64,
    /// What would fit.
    pub fits: String,
}

/// Bytes of MiB.
fn mib(bytes: f64) -> f64 {
    bytes / (1u64 << 20) as f64
}

/// Samples `render::render` keeps at once: it traces the image in strips of rows of
/// about this many samples (its STRIP_SAMPLES), at least one row.
const RENDER_STRIP_SAMPLES: f64 = (1 << 21) as f64;

/// Checks the film of a render against `available` bytes: each camera ray's sample is kept
/// (3 f64, 24 bytes; `render::Film`) until its pixel is filtered, and the 8-bit image takes
/// 3 bytes a pixel. With `whole_film` (the path tracer's comparison) every sample of the
/// image is kept at once; otherwise (`render`) a strip of rows at a time.
pub fn check_render_memory(
    width: u32,
    height: u32,
    supersample: u32,
    whole_film: bool,
    available: u64,
) -> Result<(), TooMuchMemory> {
    let pixels = width as f64 * height as f64;
    let per_pixel = 24.0 * (supersample as f64).powi(2) + 3.0;
    let needed = if whole_film {
        pixels * per_pixel
    } else {
        let row = width as f64 * (supersample as f64).powi(2);
        3.0 * pixels + 24.0 * RENDER_STRIP_SAMPLES.max(row)
    };
    if needed <= available as f64 {
        return Ok(());
    }
    let most = ((available as f64 / pixels - 3.0) / 24.0)
        .max(0.0)
        .sqrt()
        .floor();
    Err(TooMuchMemory {
        what: format!(
            "the film of {width} x {height} pixels at --supersample {supersample} (24 bytes a \
             ray)"
        ),
        needed_mib: mib(needed),
        available_mib: mib(available as f64),
        fits: if most >= 1.0 {
            format!("at most --supersample {most} at this size would fit")
        } else {
            format!(
                "even --supersample 1 fits at most {:.0} pixels",
                available as f64 / 27.0
            )
        },
    })
}

/// Point pairs (element pairs x k^4) the pair methods (area, contour, analytic) may
/// integrate: the Cornell box (2,484 elements, k = 2, 49 million point pairs) takes 1.6 s
/// on two cores, 3e7 a second, so 1e11 is about an hour there.
pub const MAX_POINT_PAIRS: f64 = 1e11;

/// Monte Carlo form-factor rays (elements x samples): BVH rays run at 1e7 a second or so on
/// two cores; 1e10 is some 20 minutes.
pub const MAX_MONTE_CARLO_RAYS: f64 = 1e10;

/// Hemicube cells scanned (elements x 3 resolution^2, the five faces' cells): 1e11 is
/// about as long as the point-pair limit.
pub const MAX_HEMICUBE_CELLS: f64 = 1e11;

/// Camera rays of a render (pixels x supersample^2, each gathering direct light): the
/// Cornell box at 512 x 512 x 64 (17 million rays) took 75 s on two cores, 2.2e5 a second;
/// 2e9 is about 2.5 hours.
pub const MAX_RENDER_RAYS: f64 = 2e9;

/// Paths a path trace may follow (pixels x paths per pixel): 256 x 256 x 16 (1 million)
/// took 1.8 s on two cores, 5.9e5 a second; 2e9 is about an hour.
pub const MAX_PATHS: f64 = 2e9;

/// Point-element pairs `radiosity illuminance` may compute (calculation points x elements
/// of the solved mesh; each pair is an exact point-to-polygon form factor and up to 9 shadow
/// rays, more where a point luminaire's first bounce is integrated at the point): measured
/// on the two-core machine (load about 5) at 1.5e5 pairs a second in the downlight room
/// (6,561 points x 320 elements in 14.1 s) and 6.5e5 with surface emitters only
/// (examples/room.scene, 7,821 x 899 in 10.8 s; BENCHMARKS.md, "illuminance"), so 1e9 is
/// about 2 hours at the slower rate and 25 minutes at the faster.
pub const MAX_POINT_ELEMENT_PAIRS: f64 = 1e9;

/// Checks an illuminance run of `points` calculation points on a solution of `elements`
/// elements; the error says how many points (or elements) would fit, and the caller may
/// add what that means for its grid.
pub fn check_illuminance_work(points: usize, elements: usize) -> Result<(), TooMuchWork> {
    let (p, n) = (points as f64, elements as f64);
    let amount = p * n;
    if amount <= MAX_POINT_ELEMENT_PAIRS {
        return Ok(());
    }
    Err(TooMuchWork {
        what: format!("{points} calculation points on {elements} elements"),
        amount,
        unit: "point-element pairs",
        limit: MAX_POINT_ELEMENT_PAIRS,
        rate: "about 2 hours on two cores at the 1.5e5 a second measured with a point \
               luminaire",
        fits: format!(
            "at most {} points on these elements would fit, or these points on at most {} \
             elements (a larger MAX_PATCH_AREA, --max-area)",
            most_illuminance_points(elements),
            (MAX_POINT_ELEMENT_PAIRS / p).floor()
        ),
    })
}

/// The most calculation points [`check_illuminance_work`] lets through on `elements`
/// elements.
pub fn most_illuminance_points(elements: usize) -> usize {
    (MAX_POINT_ELEMENT_PAIRS / (elements.max(1) as f64)).floor() as usize
}

/// Checks the form factors of `elements` elements by `method` against the limits above.
pub fn check_form_factor_work(
    method: FormFactorMethod,
    elements: usize,
) -> Result<(), TooMuchWork> {
    let n = elements as f64;
    let pairs = n * (n - 1.0).max(0.0) / 2.0;
    match method {
        FormFactorMethod::AreaIntegral { steps }
        | FormFactorMethod::Contour { steps }
        | FormFactorMethod::Analytic { steps } => {
            let amount = pairs * (steps as f64).powi(4);
            if amount <= MAX_POINT_PAIRS {
                return Ok(());
            }
            let k = (MAX_POINT_PAIRS / pairs).powf(0.25).floor();
            let fits = if k >= 1.0 {
                format!("at most INTEGRAL_STEPS {k} on these elements would fit")
            } else {
                let most = ((2.0 * MAX_POINT_PAIRS).sqrt()).floor();
                format!("even INTEGRAL_STEPS 1 fits at most {most:.0} elements")
            };
            Err(TooMuchWork {
                what: format!(
                    "INTEGRAL_STEPS {steps} on {elements} elements ({pairs:.0} element pairs x \
                     {steps}^4)"
                ),
                amount,
                unit: "point pairs",
                limit: MAX_POINT_PAIRS,
                rate: "about an hour on two cores at the 3e7 a second measured",
                fits,
            })
        }
        FormFactorMethod::MonteCarlo { samples, .. } => {
            let m = (samples.max(1) as f64).sqrt().ceil();
            let amount = n * m * m;
            if amount <= MAX_MONTE_CARLO_RAYS {
                return Ok(());
            }
            Err(TooMuchWork {
                what: format!("--samples {samples} on {elements} elements"),
                amount,
                unit: "rays",
                limit: MAX_MONTE_CARLO_RAYS,
                rate: "some 20 minutes on two cores",
                fits: format!(
                    "at most --samples {:.0} on these elements would fit",
                    (MAX_MONTE_CARLO_RAYS / n).floor()
                ),
            })
        }
        FormFactorMethod::Hemicube { resolution } => {
            let r = resolution as f64;
            let amount = n * 3.0 * r * r;
            if amount <= MAX_HEMICUBE_CELLS {
                return Ok(());
            }
            Err(TooMuchWork {
                what: format!("--resolution {resolution} on {elements} elements"),
                amount,
                unit: "hemicube cells",
                limit: MAX_HEMICUBE_CELLS,
                rate: "about an hour on two cores",
                fits: format!(
                    "at most --resolution {:.0} on these elements would fit",
                    (MAX_HEMICUBE_CELLS / (3.0 * n)).sqrt().floor()
                ),
            })
        }
    }
}

/// Checks a render of `width` x `height` pixels at `supersample`^2 rays a pixel.
pub fn check_render_work(width: u32, height: u32, supersample: u32) -> Result<(), TooMuchWork> {
    let pixels = width as f64 * height as f64;
    let amount = pixels * (supersample as f64).powi(2);
    if amount <= MAX_RENDER_RAYS {
        return Ok(());
    }
    let most = (MAX_RENDER_RAYS / pixels).sqrt().floor();
    Err(TooMuchWork {
        what: format!("{width} x {height} pixels at --supersample {supersample}"),
        amount,
        unit: "camera rays",
        limit: MAX_RENDER_RAYS,
        rate: "about 2.5 hours on two cores at the 2.2e5 a second measured",
        fits: if most >= 1.0 {
            format!("at most --supersample {most} at this size would fit")
        } else {
            format!(
                "even --supersample 1 fits at most {:.0} pixels",
                MAX_RENDER_RAYS
            )
        },
    })
}

/// Checks a path trace of `width` x `height` pixels at `paths` paths a pixel.
pub fn check_path_trace_work(width: u32, height: u32, paths: u32) -> Result<(), TooMuchWork> {
    let pixels = width as f64 * height as f64;
    let amount = pixels * paths as f64;
    if amount <= MAX_PATHS {
        return Ok(());
    }
    Err(TooMuchWork {
        what: format!("{width} x {height} pixels at --paths {paths}"),
        amount,
        unit: "paths",
        limit: MAX_PATHS,
        rate: "about an hour on two cores at the 5.9e5 a second measured",
        fits: format!(
            "at most --paths {:.0} at this size would fit",
            (MAX_PATHS / pixels).floor()
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_illuminance_run_of_hours_is_refused_with_the_points_that_fit() {
        // 1,000,000 points on 100,000 elements: 1e11 pairs, 100 times the 1e9 limit, so
        // 10,000 points fit on these elements, or 1,000 elements for these points.
        let err = check_illuminance_work(1_000_000, 100_000).unwrap_err();
        assert_eq!(err.amount, 1e11);
        let text = err.to_string();
        assert!(text.contains("at most 10000 points"), "{text}");
        assert!(text.contains("at most 1000 elements"), "{text}");
        // What it says fits does fit; one more point does not.
        assert_eq!(most_illuminance_points(100_000), 10_000);
        assert!(check_illuminance_work(10_000, 100_000).is_ok());
        assert!(check_illuminance_work(10_001, 100_000).is_err());
        assert!(check_illuminance_work(1_000_000, 1_000).is_ok());
        // An ordinary run passes: a 100 x 100 grid in a room of 20,000 elements is 2e8.
        assert!(check_illuminance_work(10_000, 20_000).is_ok());
    }

    #[test]
    fn integral_steps_1000_on_13_elements_is_refused_with_what_fits() {
        // 78 pairs x 1000^4 = 7.8e13 point pairs; (1e11 / 78)^(1/4) = 189.2.
        let err =
            check_form_factor_work(FormFactorMethod::AreaIntegral { steps: 1000 }, 13).unwrap_err();
        assert_eq!(err.amount, 78.0 * 1e12);
        assert!(err.to_string().contains("INTEGRAL_STEPS 189 "), "{err}");
        assert!(check_form_factor_work(FormFactorMethod::AreaIntegral { steps: 189 }, 13).is_ok());
        assert!(check_form_factor_work(FormFactorMethod::Contour { steps: 190 }, 13).is_err());
        // The default room-sized runs pass: 20,000 elements at k = 2 is 3.2e9.
        assert!(
            check_form_factor_work(FormFactorMethod::AreaIntegral { steps: 2 }, 20_000).is_ok()
        );
    }

    #[test]
    fn huge_samples_and_resolution_are_refused() {
        let mc = FormFactorMethod::MonteCarlo {
            samples: u32::MAX,
            seed: 1,
        };
        // 65,536^2 rays an element (u32::MAX rounded up to a square) on 13 elements.
        let err = check_form_factor_work(mc, 13).unwrap_err();
        assert_eq!(err.amount, 13.0 * 65536.0 * 65536.0);
        assert!(err.to_string().contains("--samples 769230769 "), "{err}");
        let hc = FormFactorMethod::Hemicube { resolution: 16_384 };
        let err = check_form_factor_work(hc, 2_484).unwrap_err();
        // (1e11 / (3 x 2484))^(1/2) = 3663.8
        assert!(err.to_string().contains("--resolution 3663 "), "{err}");
    }

    #[test]
    fn a_render_film_past_the_memory_is_refused_with_the_supersample_that_fits() {
        // 1e8 pixels x (24 x 256 + 3) bytes = 614 GB; with 16 GiB,
        // sqrt((16 GiB / 1e8 - 3) / 24) = 2.6: at most 2.
        let err = check_render_memory(10_000, 10_000, 16, true, 16 << 30).unwrap_err();
        assert!(
            (err.needed_mib - 1e8 * 6147.0 / 1048576.0).abs() < 1.0,
            "{err:?}"
        );
        assert!(err.to_string().contains("--supersample 2 "), "{err}");
        assert!(check_render_memory(512, 512, 8, true, 1 << 30).is_ok());
        // In strips: 3e8 bytes of image and a strip of 2.56 million samples (one row of
        // 10,000 x 256), 61 MB.
        assert!(check_render_memory(10_000, 10_000, 16, false, 400 << 20).is_ok());
        assert!(check_render_memory(10_000, 10_000, 16, false, 300 << 20).is_err());
    }

    #[test]
    fn huge_renders_and_path_traces_are_refused() {
        // 1e8 pixels x 256 rays = 2.56e10; sqrt(2e9 / 1e8) = 4.47.
        let err = check_render_work(10_000, 10_000, 16).unwrap_err();
        assert!(err.to_string().contains("--supersample 4 "), "{err}");
        assert!(check_render_work(512, 512, 16).is_ok());
        // 512 x 512 x 256 (the defaults) pass; 1e8 pixels x 256 do not (at most 20).
        assert!(check_path_trace_work(512, 512, 256).is_ok());
        let err = check_path_trace_work(10_000, 10_000, 256).unwrap_err();
        assert!(err.to_string().contains("--paths 20 "), "{err}");
    }
}
