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

/// The four first rays of every pixel of a run of image rows, kept from one strip of rows to
/// the next: a strip looks at the rows either side of it ([`brighter_beside`]), and the
/// two rows where strips meet were cast twice (review of QA pass 15 of #16: 3 % more first
/// rays at 512 x 512 with 8 x 8 supersampling, 50 % at 1920 wide with 16 x 16).
#[derive(Debug, Default)]
pub(super) struct FirstRows {
    /// The image row of `rays`' first row.
    pub(super) start: usize,
    /// Row by row, pixel by pixel.
    pub(super) rays: Vec<[Seen; 4]>,
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

/// True when a neighbouring pixel's first rays saw a surface that none of `coarse` saw, more
/// than twice as bright as the brightest of `coarse`: the edge of a light (or of anything
/// bright) may cross this pixel between its four rays, which then see none of it. Without
/// this, the pixels along a light's edge showed nothing of it: in a 32-pixel Cornell box the
/// row under the light read 0.10 cd/m^2 against the path tracer's 0.59 to 1.15, about 8 %
/// of the light's flux in the image lost (QA pass 15 of issue #16). Only brighter
/// neighbours count: a dark sliver missed costs little light, and every edge of every
/// object would otherwise be refined three pixels wide.
pub(super) fn brighter_beside<'a>(
    coarse: &[Seen; 4],
    neighbours: impl Iterator<Item = &'a [Seen; 4]>,
) -> bool {
    let lum = |s: &Seen| crate::light::Rgb(s.value).luminance();
    let brightest = coarse.iter().map(lum).fold(0.0, f64::max);
    neighbours.flatten().any(|s| {
        s.surface.is_some()
            && coarse.iter().all(|c| c.surface != s.surface)
            && lum(s) > 2.0 * brightest
    })
}
