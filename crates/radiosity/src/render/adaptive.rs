//! Adaptive antialiasing's decision: what a pixel's four first rays saw ([`Seen`]) and
//! whether they ask for more ([`refinement`]); the ray loop in `renderer` acts on it.

/// What one ray saw: its value and the surface it hit (none for a miss or a back face).
#[derive(Clone, Copy, Debug)]
pub(super) struct Seen {
    pub(super) value: [f64; 3],
    pub(super) surface: Option<u32>,
}

impl Seen {
    pub(super) const NOTHING: Seen = Seen {
        value: [0.0; 3],
        surface: None,
    };
}

/// What a pixel's four first rays ask for under adaptive sampling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Refine {
    /// One surface, nearly one value: the four rays are the pixel.
    No,
    /// One surface whose light changes within the pixel (a shadow edge): n/2 x n/2 rays.
    Contrast,
    /// Different surfaces, or a miss (an edge of an object): the full n x n.
    Silhouette,
}

/// Silhouette when the four rays do not all see one surface; contrast when their
/// luminances spread by more than `contrast` times their largest.
pub(super) fn refinement(coarse: &[Seen; 4], contrast: f64) -> Refine {
    let surface = coarse[0].surface;
    if coarse.iter().any(|s| s.surface != surface) {
        return Refine::Silhouette;
    }
    let lum = |s: &Seen| crate::light::Rgb(s.value).luminance();
    let (lo, hi) = coarse
        .iter()
        .map(lum)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), l| {
            (a.min(l), b.max(l))
        });
    if hi - lo > contrast * hi.abs() {
        Refine::Contrast
    } else {
        Refine::No
    }
}
