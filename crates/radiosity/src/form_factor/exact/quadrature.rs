//! Fixed quadrature rules on [-1, 1] and an adaptive integrator for the contour integral:
//! Gauss-Legendre with 6 and 10 points, and QUADPACK's 21-point Gauss-Kronrod rule QK21
//! with its error estimate (Piessens, de Doncker-Kapenga, Ueberhuber and Kahaner,
//! *QUADPACK*, Springer 1983), used by adaptive bisection.

#[allow(clippy::excessive_precision)]
/// Positive Gauss-Legendre nodes on [-1, 1] and their weights, 6 points.
pub(super) const GL6: [(f64, f64); 3] = [
    (0.238_619_186_083_196_9, 0.467_913_934_572_691_0),
    (0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
    (0.932_469_514_203_152_1, 0.171_324_492_379_170_4),
];
#[allow(clippy::excessive_precision)]
/// Positive Gauss-Legendre nodes on [-1, 1] and their weights, 10 points.
pub(super) const GL10: [(f64, f64); 5] = [
    (0.148_874_338_981_631_2, 0.295_524_224_714_752_9),
    (0.433_395_394_129_247_2, 0.269_266_719_309_996_3),
    (0.679_409_568_299_024_4, 0.219_086_362_515_982_0),
    (0.865_063_366_688_984_5, 0.149_451_349_150_580_6),
    (0.973_906_528_517_171_7, 0.066_671_344_308_688_1),
];

#[allow(clippy::excessive_precision)]
/// QUADPACK's QK21 rule on [-1, 1]: the positive Kronrod nodes with their Kronrod weights
/// and, for the 10 Gauss nodes among them, their Gauss weights (0 for the others); the
/// centre, a Kronrod node only, is `WGK_CENTRE`.
const GK21: [(f64, f64, f64); 10] = [
    (
        0.995_657_163_025_808_080_735_527_280_689_003,
        0.011_694_638_867_371_874_278_064_396_062_192,
        0.0,
    ),
    (
        0.973_906_528_517_171_720_077_964_012_084_452,
        0.032_558_162_307_964_727_478_818_972_459_390,
        0.066_671_344_308_688_137_593_568_809_893_332,
    ),
    (
        0.930_157_491_355_708_226_001_207_180_059_508,
        0.054_755_896_574_351_996_031_381_300_244_580,
        0.0,
    ),
    (
        0.865_063_366_688_984_510_732_096_688_423_493,
        0.075_039_674_810_919_952_767_043_140_916_190,
        0.149_451_349_150_580_593_145_776_339_657_697,
    ),
    (
        0.780_817_726_586_416_897_063_717_578_345_042,
        0.093_125_454_583_697_605_535_065_465_083_366,
        0.0,
    ),
    (
        0.679_409_568_299_024_406_234_327_365_114_874,
        0.109_387_158_802_297_641_899_210_590_325_805,
        0.219_086_362_515_982_043_995_534_934_228_163,
    ),
    (
        0.562_757_134_668_604_683_339_000_099_272_694,
        0.123_491_976_262_065_851_077_958_109_831_074,
        0.0,
    ),
    (
        0.433_395_394_129_247_190_799_265_943_165_784,
        0.134_709_217_311_473_325_928_054_001_771_707,
        0.269_266_719_309_996_355_091_226_921_569_469,
    ),
    (
        0.294_392_862_701_460_198_131_126_603_103_866,
        0.142_775_938_577_060_080_797_094_273_138_717,
        0.0,
    ),
    (
        0.148_874_338_981_631_210_884_826_001_129_720,
        0.147_739_104_901_338_491_374_841_515_972_068,
        0.295_524_224_714_752_870_173_892_994_651_338,
    ),
];
#[allow(clippy::excessive_precision)]
/// The Kronrod weight of the centre in QK21.
const WGK_CENTRE: f64 = 0.149_445_554_002_916_905_664_936_468_389_821;

/// The 21-point Kronrod estimate of the integral of `f` over [lo, hi] and QUADPACK's error
/// estimate for it (from the 10-point Gauss rule on the same nodes).
fn gk21(f: &impl Fn(f64) -> f64, lo: f64, hi: f64) -> (f64, f64) {
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let mut fv = [(0.0, 0.0); 10];
    let f_centre = f(centre);
    let mut kron = WGK_CENTRE * f_centre;
    let mut gauss = 0.0;
    for (k, &(x, wk, wg)) in GK21.iter().enumerate() {
        fv[k] = (f(centre - half * x), f(centre + half * x));
        let pair = fv[k].0 + fv[k].1;
        kron += wk * pair;
        gauss += wg * pair;
    }
    let mean = 0.5 * kron;
    let mut asc = WGK_CENTRE * (f_centre - mean).abs();
    for (k, &(_, wk, _)) in GK21.iter().enumerate() {
        asc += wk * ((fv[k].0 - mean).abs() + (fv[k].1 - mean).abs());
    }
    let asc = asc * half.abs();
    let mut err = ((kron - gauss) * half).abs();
    if asc != 0.0 && err != 0.0 {
        err = asc * (200.0 * err / asc).powf(1.5).min(1.0);
    }
    (kron * half, err)
}

/// The most intervals [`adaptive_gk21`] evaluates in one integral. Smooth integrands take a
/// handful; graded pieces at a logarithmic singularity a few dozen.
pub(super) const MAX_INTERVALS: usize = 2_000;

/// The integral of `f` over [lo, hi] by adaptive bisection with `gk21`. `scale` is the size of
/// f (here the inner edge length, times the piece length for a graded piece): an interval is
/// accepted when its error estimate is below 1e-13 scale per unit of length, or below
/// 2e-15 scale in all (so that the few intervals at a singularity need not shrink to
/// nothing), or when it is 1e-13 of the whole. QUADPACK's estimate is pessimistic for
/// analytic integrands by orders of magnitude: the results agree with the closed forms to
/// about 1e-15.
///
/// At most [`MAX_INTERVALS`] intervals are evaluated: past that every interval is accepted
/// as it is. An integrand whose rounding noise exceeds the tolerance (two edges a hair from
/// collinear, meeting at an angle of 1e-10, in a mesh of 193,000 elements) would otherwise
/// be bisected to the minimum width everywhere, 2^43 intervals: the refinement of hierarchical
/// radiosity on such a mesh sat in one such integral for minutes.
pub(super) fn adaptive_gk21(f: &impl Fn(f64) -> f64, lo: f64, hi: f64, scale: f64) -> f64 {
    const DEPTH: usize = 64;
    let per_length = 1e-13 * scale;
    let floor = 2e-15 * scale;
    let min_width = 1e-13 * (hi - lo);
    let mut stack = [(0.0, 0.0); DEPTH];
    let mut top = 0;
    let mut total = 0.0;
    let mut evaluated = 0;
    let (mut a, mut b) = (lo, hi);
    loop {
        let (value, err) = gk21(f, a, b);
        evaluated += 1;
        let width = b - a;
        if err <= per_length * width
            || err <= floor
            || width <= min_width
            || top == DEPTH
            || evaluated >= MAX_INTERVALS
        {
            total += value;
            if top == 0 {
                return total;
            }
            top -= 1;
            (a, b) = stack[top];
        } else {
            let mid = 0.5 * (a + b);
            stack[top] = (mid, b);
            top += 1;
            b = mid;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The Kronrod rule integrates polynomials up to degree 31 exactly, the Gauss rule up to
    // 19: a check on the transcribed constants (to rounding).
    #[test]
    fn exact_gk21_weights() {
        for k in 0..=31 {
            let want = if k % 2 == 0 {
                2.0 / (k + 1) as f64
            } else {
                0.0
            };
            let (got, _) = gk21(&|x: f64| x.powi(k), -1.0, 1.0);
            assert!((got - want).abs() < 1e-15, "degree {k}: {got} vs {want}");
        }
        for k in (0..=18).step_by(2) {
            let got: f64 = GK21.iter().map(|(x, _, w)| 2.0 * w * x.powi(k)).sum();
            assert!((got - 2.0 / (k + 1) as f64).abs() < 1e-15, "Gauss {k}");
        }
        // Gauss-Legendre with n points: exact to degree 2n - 1.
        for (rule, n) in [(&GL6[..], 6), (&GL10[..], 10)] {
            for k in (0..2 * n).step_by(2) {
                let got: f64 = rule.iter().map(|(x, w)| 2.0 * w * x.powi(k)).sum();
                assert!((got - 2.0 / (k + 1) as f64).abs() < 1e-15, "{n} {k}");
            }
        }
    }
}

#[cfg(test)]
mod budget_tests {
    use super::*;

    /// An integrand that is pure noise at 1e-6 (far above the 1e-13 tolerance) would be
    /// bisected down to 1e-13 of the interval everywhere: the budget stops it after
    /// MAX_INTERVALS evaluations, and the result is still the integral to the noise.
    #[test]
    fn noise_above_the_tolerance_is_integrated_within_the_interval_budget() {
        let calls = std::cell::Cell::new(0usize);
        let noisy = |x: f64| {
            calls.set(calls.get() + 1);
            // Deterministic noise: the fractional part of a large multiple of x.
            1.0 + 1e-6 * ((x * 1.0e7).sin())
        };
        let got = adaptive_gk21(&noisy, 0.0, 1.0, 1.0);
        assert!((got - 1.0).abs() < 1e-6, "{got}");
        // 21 points per interval: the budget, then at most one evaluation of each of the
        // (at most 64) intervals still waiting on the stack.
        assert!(
            calls.get() <= 21 * (MAX_INTERVALS + 64),
            "{} calls",
            calls.get()
        );
    }
}
