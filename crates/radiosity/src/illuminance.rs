//! Illuminance at calculation points: what a lighting designer's light meter would read at
//! a point with a given normal, split into the direct and the indirect light.
//!
//! * **Direct**: the light that arrives straight from emission: each emitting surface's
//!   own exitance times Lambert's exact point-to-polygon form factor times the visible
//!   fraction (shadow rays, [`crate::render::DirectLight`]), plus each point luminaire's
//!   I cos / d^2 where its segment is clear.
//! * **Indirect**: the light that arrives from reflected light: every element's reflected
//!   exitance (its radiosity less its surface's own emission; of a progressive run stopped
//!   early, the light shot so far, as `solve` writes it, not the paper's ambient term for
//!   the unshot rest, a uniform guess that put a point of the Cornell box at 0.43 lx after
//!   one shot against 0.24 lx converged) times the exact point-to-polygon form factor to the element
//!   times the visible fraction of the element (kernel-weighted shadow rays to 3 x 3 points
//!   of it; an element seen whole needs no more). The first reflection of the point
//!   luminaires' light is not taken from the element's mean: the solver's share of it
//!   (rho times [`crate::luminaire::element_irradiance`]) is taken out of the element's
//!   exitance and put back as rho E(y) at points y of the element, E with its own shadow
//!   ray to each light and each y with its own shadow ray to the calculation point,
//!   kernel-weighted, on sub-triangles refined where the shadows cut the element (down to
//!   1/64 of its size): a floor half in a shadow, or half hidden from the point, counts as
//!   the half that is lit and seen ([`FIRST_BOUNCE_MAX_DEPTH`]).
//!
//! Both are computed at the point from the solution, not interpolated from vertices. Values
//! are photometric: the luminance-weighted Y = 0.2126 R + 0.7152 G + 0.0722 B of the bands
//! ([`crate::light::Rgb::luminance`]); with lengths in metres and exitances in lm/m^2 they
//! are lux.

use glam::DVec3;
use rayon::prelude::*;

use crate::form_factor::exact::point_to_polygon;
use crate::light::Rgb;
use crate::pipeline::{Prepared, Solution};
use crate::render::DirectLight;

/// A calculation point: where, and the unit normal of the (imaginary) meter's face.
#[derive(Clone, Debug, PartialEq)]
pub struct CalcPoint {
    /// A label (the CSV's `name`).
    pub name: String,
    /// The point.
    pub position: DVec3,
    /// The normal the illuminance is measured on (normalised on use).
    pub normal: DVec3,
}

/// The illuminance at one point, in lux (Y of the bands).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Lux {
    /// Straight from emitting surfaces and point luminaires.
    pub direct: f64,
    /// From reflected light.
    pub indirect: f64,
    /// direct + indirect.
    pub total: f64,
}

/// The shadow-ray points per element side for the indirect light's visibility.
const ELEMENT_POINTS: u32 = 3;

/// Each element's reflectance (its surface's) and its radiosity (of a progressive run
/// stopped early, the light shot so far: no ambient term, see the module documentation).
fn reflectance_and_shown(scene: &crate::scene::Scene, solution: &Solution) -> (Vec<Rgb>, Vec<Rgb>) {
    let reflectance: Vec<Rgb> = solution
        .mesh
        .elements
        .iter()
        .map(|e| scene.surfaces[e.surface as usize].reflectance)
        .collect();
    (reflectance, solution.radiosity.0.clone())
}

/// The illuminance at each of `points` for the scene of `prepared` solved as `solution`
/// (any solver's: its mesh may be the prepared one, adaptive subdivision's or hierarchical
/// radiosity's leaves). Points run in parallel; the result is in the order of `points` and
/// does not depend on threads.
pub fn illuminance(prepared: &Prepared, solution: &Solution, points: &[CalcPoint]) -> Vec<Lux> {
    illuminance_with_progress(prepared, solution, points, &crate::progress::NoProgress)
}

/// [`illuminance`], reporting each finished point to `progress` as one `advance(1)` of
/// the current stage (the caller starts and finishes [`crate::progress::Stage::Illuminance`]
/// with `points.len()` units), so that a run of hours is never silent.
pub fn illuminance_with_progress(
    prepared: &Prepared,
    solution: &Solution,
    points: &[CalcPoint],
    progress: &dyn crate::progress::Progress,
) -> Vec<Lux> {
    let scene = &prepared.scene;
    let direct = DirectLight::new(scene);
    let mesh = &solution.mesh;
    let (reflectance, shown) = reflectance_and_shown(scene, solution);
    // The point lights' first bounce as the solver added it to the emission
    // ([`crate::light::ElementLight::of_mesh`]: the same call on the same mesh and
    // occluders), taken out of the element's exitance and integrated at the point instead.
    let lit: Vec<Rgb> = if scene.lights.is_empty() {
        vec![Rgb::BLACK; mesh.len()]
    } else {
        let occluders = crate::visibility::PolygonBvh::over_surfaces(scene);
        crate::luminaire::element_irradiance(mesh, &scene.lights, &occluders)
    };
    // Each element's reflected exitance (Y) less the first bounce of the point lights, its
    // reflectance when the point lights reach it, and its corners; the elements that
    // reflect nothing are left out.
    let reflecting: Vec<Reflecting> = mesh
        .elements
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let own = scene.surfaces[e.surface as usize].emission;
            let rho = reflectance[i];
            let first = rho * lit[i];
            let rest = (shown[i] - own - first).luminance();
            let first_bounce = (first.luminance() > 0.0).then_some(rho);
            (rest != 0.0 || first_bounce.is_some()).then(|| Reflecting {
                element: i,
                rest,
                first_bounce,
                corners: mesh.corner_positions(i).collect(),
            })
        })
        .collect();
    let occluders = &prepared.occluders;
    // Each light's lumens, once: an IES table's is a sum over the table.
    let fluxes: Vec<f64> = scene.lights.iter().map(|l| l.flux()).collect();
    points
        .par_iter()
        .enumerate()
        .map(|(k, p)| {
            // One unit of progress per point, whichever way it returns.
            struct Tick<'a>(&'a dyn crate::progress::Progress);
            impl Drop for Tick<'_> {
                fn drop(&mut self) {
                    self.0.advance(1);
                }
            }
            let _tick = Tick(progress);
            let n = p.normal.normalize_or_zero();
            if n == DVec3::ZERO {
                return Lux::default();
            }
            let salt = 0x5eed_0000_0000_0000 ^ k as u64;
            let d = direct.irradiance(p.position, n, salt).luminance();
            let mut ind = 0.0;
            let mut samples = Vec::with_capacity((ELEMENT_POINTS * ELEMENT_POINTS) as usize);
            for r in &reflecting {
                let f = point_to_polygon(p.position, n, &r.corners);
                if f <= 0.0 {
                    continue;
                }
                let normal = mesh.elements[r.element].normal;
                let mut first_done = false;
                if let Some(rho) = r.first_bounce {
                    let sampler = FirstBounce {
                        p: p.position,
                        n,
                        normal,
                        lights: &scene.lights,
                        fluxes: &fluxes,
                        occluders,
                    };
                    if let Some(mean) = sampler.mean(&r.corners) {
                        ind += f * (rho * mean).luminance();
                        first_done = true;
                    }
                }
                let exitance = if first_done {
                    r.rest
                } else {
                    r.rest
                        + r.first_bounce
                            .map_or(0.0, |rho| (rho * lit[r.element]).luminance())
                };
                if exitance == 0.0 {
                    continue;
                }
                samples.clear();
                mesh.integration_points(r.element, ELEMENT_POINTS, &mut samples);
                let (mut seen, mut total) = (0.0, 0.0);
                for &(y, w) in &samples {
                    let dv = y - p.position;
                    let r2 = dv.length_squared();
                    let (cx, cy) = (n.dot(dv), -normal.dot(dv));
                    if cx <= 0.0 || cy <= 0.0 || r2 <= 0.0 {
                        continue;
                    }
                    let kw = w * cx * cy / (r2 * r2);
                    total += kw;
                    if !occluders.segment_blocked(p.position, y) {
                        seen += kw;
                    }
                }
                // All points behind the meter's plane while Lambert sees a sliver: the share
                // of the element's corners in front of it (nudged a millionth towards the
                // centre, off the edges they share; the element's own surface ignored, as
                // the rays may run along it) that the point sees. Counting the sliver seen
                // without a ray let light through the closed cupboard of
                // examples/room_downlights.scene (up to 0.009 lx inside it, QA pass 20 of
                // #16), from the small pieces of the wall behind it whose tops rose past the
                // meter's plane.
                let fraction = if total > 0.0 {
                    seen / total
                } else {
                    let element = &mesh.elements[r.element];
                    let centre = element.centroid;
                    let (mut front, mut clear) = (0u32, 0u32);
                    for &c in &r.corners {
                        let y = c + 1e-6 * (centre - c);
                        if n.dot(y - p.position) > 0.0 {
                            front += 1;
                            clear += u32::from(!occluders.segment_blocked_except(
                                p.position,
                                y,
                                element.surface,
                            ));
                        }
                    }
                    if front > 0 {
                        f64::from(clear) / f64::from(front)
                    } else {
                        0.0
                    }
                };
                ind += exitance * f * fraction;
            }
            Lux {
                direct: d,
                indirect: ind,
                total: d + ind,
            }
        })
        .collect()
}

/// An element that sends light to the calculation points.
struct Reflecting {
    element: usize,
    /// Its reflected exitance (Y) less the point lights' first bounce where that is
    /// integrated point by point ([`FirstBounce`]).
    rest: f64,
    /// Its reflectance, when the point lights reach it.
    first_bounce: Option<Rgb>,
    corners: Vec<DVec3>,
}

/// The first bounce's sub-triangles are halved down to this many times (1/64 of the
/// element's fan triangles' size) where the shadow rays at their corners and centre
/// disagree: a shadow edge's error is then that of a band 1/64 of an element wide.
pub const FIRST_BOUNCE_MAX_DEPTH: u32 = 6;

/// A first-bounce piece that a point light sees wider than this (sr) is halved, down to
/// [`FIRST_BOUNCE_MAX_SOLID_DEPTH`] times: over a cone of 0.1 sr (10 degrees across) a
/// COSINE light's intensity is near quadratic, so taking its mean at the piece's edges'
/// midpoints ([`crate::luminaire::mean_intensity`]) is well under 0.1 % off, and a light's
/// whole sphere holds at most about 130 such pieces of one element.
pub const FIRST_BOUNCE_MAX_SOLID_ANGLE: f64 = 0.1;

/// A first-bounce piece whose farthest corner from a point light is more than this many
/// times as far as its nearest is halved too (down to [`FIRST_BOUNCE_MAX_SOLID_DEPTH`]
/// times): over it E varies by at most 1.1^3 = 1.33, and the kernel's weight is taken
/// where the light lands.
pub const FIRST_BOUNCE_MAX_DISTANCE_RATIO: f64 = 1.1;

/// How many times a wide piece, or one across which a light's intensity jumps
/// ([`crate::luminaire::intensity_jumps`]), may be halved (4^9 pieces of a fan triangle at
/// most), so that an element through a light cannot split without end.
pub const FIRST_BOUNCE_MAX_SOLID_DEPTH: u32 = 9;

/// Every sub-triangle is halved at least this many times (4 per fan triangle), so that the
/// illuminance's variation across a lit, seen element is integrated, not taken at one point.
const FIRST_BOUNCE_MIN_DEPTH: u32 = 1;

/// The point lights' illuminance over an element as a calculation point sees it.
struct FirstBounce<'a> {
    p: DVec3,
    n: DVec3,
    /// The element's unit normal.
    normal: DVec3,
    lights: &'a [crate::luminaire::Luminaire],
    /// Each light's lumens.
    fluxes: &'a [f64],
    occluders: &'a crate::visibility::PolygonBvh,
}

impl FirstBounce<'_> {
    /// What the shadow rays say at y: bit 0 set when y is hidden from the point, bit i + 1
    /// when light i (of the first 63) is blocked from y.
    fn state(&self, y: DVec3) -> u64 {
        let mut s = u64::from(self.occluders.segment_blocked(self.p, y));
        for (i, l) in self.lights.iter().take(63).enumerate() {
            if self.occluders.segment_blocked(l.position, y) {
                s |= 1 << (i + 1);
            }
        }
        s
    }

    /// The mean over the element `poly` of E(y) V(p, y), weighted by the point-to-area
    /// kernel cos cos / r^2 (E per band, each light with its own shadow ray from y; V the
    /// visibility of y from the point); `None` when no part of the element is in front of
    /// both (a sliver the form factor sees, left to the caller).
    fn mean(&self, poly: &[DVec3]) -> Option<Rgb> {
        let mut sum = (Rgb::BLACK, 0.0);
        for i in 1..poly.len().saturating_sub(1) {
            let (a, b, c) = (poly[0], poly[i], poly[i + 1]);
            let (sa, sb, sc) = (self.state(a), self.state(b), self.state(c));
            self.triangle([a, b, c], [sa, sb, sc], 0, &mut sum);
        }
        (sum.1 > 0.0).then(|| sum.0 * (1.0 / sum.1))
    }

    /// The solid angle (sr) the triangle `t` (counter-clockwise from its front) subtends
    /// seen from the light at `light`; 0 when the light is behind it.
    fn solid_angle_from(light: DVec3, t: &[DVec3; 3]) -> f64 {
        (-crate::luminaire::triangle_solid_angle(t[0] - light, t[1] - light, t[2] - light)).max(0.0)
    }

    fn triangle(&self, t: [DVec3; 3], s: [u64; 3], depth: u32, sum: &mut (Rgb, f64)) {
        let centre = (t[0] + t[1] + t[2]) / 3.0;
        let sm = self.state(centre);
        let uniform = s.iter().all(|&x| x == sm);
        // A piece that a light sees wide is split too: over it the light's intensity
        // changes with direction (QA of issue #16: a COSINE light 5 cm below a ceiling
        // gave half the indirect lux, its first bounce taken at a few points of a spike).
        // So is one whose corners lie at distances from a light that differ by more than
        // a tenth: E falls as the cube of the distance, so over such a piece the light lands
        // mostly at its near end, not round its centroid where the kernel is taken (a floor
        // 5 cm under a lamp read 1.4 % low with the solid angle alone, 1.2 % at a ratio of
        // 1.5; the README's downlight grid took 0.95 s against 0.91 s at 1.1).
        // And one across which a light's intensity jumps (a cut-off), by the elements' own
        // first bounce's test ([`crate::luminaire::intensity_jumps`]) but to this depth and
        // without its 1e-4 sr floor, so that the two agree on elements the cut-off crosses
        // (review of QA pass 15 of #16).
        // A piece seen wider than FIRST_BOUNCE_MAX_SOLID_ANGLE splits as far as the
        // elements' own ([`crate::luminaire::MAX_WIDE_PIECE_DEPTH`]), so that a light a hair
        // from a surface is followed to its foot (review: at 9 halvings a COSINE light 0.1
        // mm from a ceiling gave half its reflected lux); the other reasons stop at 9.
        let wide = self.lights.iter().zip(self.fluxes).any(|(l, &flux)| {
            let omega = Self::solid_angle_from(l.position, &t);
            if omega > FIRST_BOUNCE_MAX_SOLID_ANGLE
                && depth < crate::luminaire::MAX_WIDE_PIECE_DEPTH
            {
                return true;
            }
            let d = t.map(|c| c.distance(l.position));
            let (near, far) = (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]));
            depth < FIRST_BOUNCE_MAX_SOLID_DEPTH
                && (far > FIRST_BOUNCE_MAX_DISTANCE_RATIO * near
                    || crate::luminaire::intensity_jumps(l, &t, omega, || flux))
        });
        if depth < FIRST_BOUNCE_MIN_DEPTH || (!uniform && depth < FIRST_BOUNCE_MAX_DEPTH) || wide {
            let m = [
                0.5 * (t[0] + t[1]),
                0.5 * (t[1] + t[2]),
                0.5 * (t[2] + t[0]),
            ];
            let ms = m.map(|y| self.state(y));
            self.triangle([t[0], m[0], m[2]], [s[0], ms[0], ms[2]], depth + 1, sum);
            self.triangle([m[0], t[1], m[1]], [ms[0], s[1], ms[1]], depth + 1, sum);
            self.triangle([m[2], m[1], t[2]], [ms[2], ms[1], s[2]], depth + 1, sum);
            self.triangle([m[0], m[1], m[2]], ms, depth + 1, sum);
            return;
        }
        let dv = centre - self.p;
        let r2 = dv.length_squared();
        let (cx, cy) = (self.n.dot(dv), -self.normal.dot(dv));
        if cx <= 0.0 || cy <= 0.0 || r2 <= 0.0 {
            return;
        }
        let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        let kw = area * cx * cy / (r2 * r2);
        sum.1 += kw;
        if sm & 1 == 1 {
            return;
        }
        // The light's power onto the piece, I towards its centre times the solid angle it
        // subtends (exact for an isotropic light however close: the irradiance at the
        // centre times the area is not, near a light), times the kernel per unit area.
        let kernel = cx * cy / (r2 * r2);
        for (i, l) in self.lights.iter().enumerate() {
            let blocked = if i < 63 {
                sm >> (i + 1) & 1 == 1
            } else {
                self.occluders.segment_blocked(l.position, centre)
            };
            let omega = Self::solid_angle_from(l.position, &t);
            if !blocked && omega > 0.0 {
                let d = t.map(|c| (c - l.position).normalize_or_zero());
                sum.0 += crate::luminaire::mean_intensity(l, d) * (omega * kernel);
            }
        }
    }
}

/// The points of a rectangular grid from corner `a` to corner `b` (an axis-aligned
/// rectangle: the corners agree in at least one axis; or a line, or one point) every
/// `spacing`, all with `normal`: along each axis where the corners differ, `a + i spacing`
/// for i = 0, 1, ... while within the span (the far corner itself when the span is a whole
/// number of spacings, to 1e-9 of a spacing). Named `gI_J` (column I along the first varying
/// axis, x before y before z; row J along the second). `None` for a spacing that is not
/// positive and finite, corners that differ in all three axes, or a grid of more than
/// `max_points`.
pub fn grid(
    a: DVec3,
    b: DVec3,
    spacing: f64,
    normal: DVec3,
    max_points: usize,
) -> Option<(Vec<CalcPoint>, [usize; 2])> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return None;
    }
    let varying: Vec<usize> = (0..3).filter(|&i| a[i] != b[i]).collect();
    if varying.len() > 2 {
        return None;
    }
    let count = |axis: usize| -> f64 { ((b[axis] - a[axis]).abs() / spacing + 1e-9).floor() + 1.0 };
    let counts: Vec<f64> = varying.iter().map(|&i| count(i)).collect();
    if counts.iter().product::<f64>() > max_points as f64 {
        return None;
    }
    let (nu, nv) = (
        counts.first().copied().unwrap_or(1.0) as usize,
        counts.get(1).copied().unwrap_or(1.0) as usize,
    );
    let mut out = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let mut p = a;
            for (index, &axis) in varying.iter().enumerate() {
                let k = if index == 0 { i } else { j } as f64;
                // To 12 significant digits: the decimals asked for, not 0.7 + 0.1 =
                // 0.7999999999999999 (QA of issue #16).
                let x = a[axis] + (b[axis] - a[axis]).signum() * k * spacing;
                // A leftover near zero is zero (-0.7 + 7 x 0.1 = 1.1e-16).
                let x = if x.abs() <= 1e-9 * spacing { 0.0 } else { x };
                p[axis] = format!("{x:.11e}").parse().unwrap_or(x);
            }
            out.push(CalcPoint {
                name: format!("g{i}_{j}"),
                position: p,
                normal,
            });
        }
    }
    Some((out, [nu, nv]))
}

#[cfg(test)]
#[path = "illuminance_tests.rs"]
mod tests;

/// The header a points file must start with (the contract of `radiosity illuminance`).
pub const POINTS_HEADER: &str = "name,x,y,z,nx,ny,nz";

/// The header of the illuminance CSV written for the points.
pub const LUX_HEADER: &str = "name,x,y,z,nx,ny,nz,direct_lux,indirect_lux,total_lux";

/// A problem in a points file, at a line.
#[derive(Debug, thiserror::Error)]
pub enum PointsError {
    /// The file cannot be read.
    #[error("{path}: error: cannot read the points file: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// A line is not what the format says.
    #[error("{path}:{line}: error: {message}")]
    Invalid {
        /// The file.
        path: String,
        /// The line, from 1.
        line: usize,
        /// What was found and what was expected.
        message: String,
    },
    /// Several lines are not (QA of issue #16: one error at a time cost a run per line),
    /// each displayed on its own line as [`PointsError::Invalid`] is.
    #[error("{}", several_lines(.errors, *.more))]
    Several {
        /// The first [`MAX_POINTS_ERRORS`] errors, each an [`PointsError::Invalid`].
        errors: Vec<PointsError>,
        /// How many more lines were wrong.
        more: usize,
    },
}

/// The most wrong lines of a points file named one by one.
pub const MAX_POINTS_ERRORS: usize = 10;

fn several_lines(errors: &[PointsError], more: usize) -> String {
    let mut text: Vec<String> = errors.iter().map(ToString::to_string).collect();
    if more > 0 {
        text.push(format!("... and {more} more lines like these"));
    }
    text.join("\n")
}

/// Reads a points CSV: the header `name,x,y,z,nx,ny,nz`, then one point a line (blank lines
/// skipped); every name given and different, every number finite, the normal not zero.
pub fn read_points(path: &std::path::Path) -> Result<Vec<CalcPoint>, PointsError> {
    let name = path.display().to_string();
    crate::io::note_input(path);
    let text = std::fs::read_to_string(path).map_err(|source| PointsError::Io {
        path: name.clone(),
        source,
    })?;
    parse_points(&text, &name)
}

/// [`read_points`] on text; `source_name` names it in errors. Every wrong line is found,
/// and the first [`MAX_POINTS_ERRORS`] are named.
pub fn parse_points(text: &str, source_name: &str) -> Result<Vec<CalcPoint>, PointsError> {
    let bad = |line: usize, message: String| PointsError::Invalid {
        path: source_name.to_string(),
        line,
        message,
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((i, header)) = lines.next() else {
        return Err(bad(
            1,
            format!("expected the header \"{POINTS_HEADER}\", found an empty file"),
        ));
    };
    let cols: Vec<String> = header
        .split(',')
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    if cols.join(",") != POINTS_HEADER {
        return Err(bad(
            i + 1,
            format!(
                "expected the header \"{POINTS_HEADER}\", found \"{}\"",
                header.trim()
            ),
        ));
    }
    let header_line = i + 1;
    let mut out = Vec::new();
    let mut errors = Vec::new();
    // Each name's first line: the lux CSV's rows are told apart by name.
    let mut first_line_of: std::collections::HashMap<String, usize> =
        std::collections::HashMap::new();
    for (i, line) in lines {
        match point_of_line(line, i + 1, &mut first_line_of) {
            Ok(p) => out.push(p),
            Err(message) => errors.push(bad(i + 1, message)),
        }
    }
    match errors.len() {
        0 => {}
        1 => return Err(errors.remove(0)),
        n => {
            errors.truncate(MAX_POINTS_ERRORS);
            return Err(PointsError::Several {
                errors,
                more: n.saturating_sub(MAX_POINTS_ERRORS),
            });
        }
    }
    if out.is_empty() {
        return Err(bad(
            header_line + 1,
            "no points after the header: expected one point a line \
             (name,x,y,z,nx,ny,nz)"
                .to_string(),
        ));
    }
    Ok(out)
}

/// One line of a points file (line number `line`), or what is wrong with it; its name is
/// recorded in `first_line_of` and refused when it is already there.
fn point_of_line(
    line_text: &str,
    line: usize,
    first_line_of: &mut std::collections::HashMap<String, usize>,
) -> Result<CalcPoint, String> {
    // CSV fields, so that a quoted name may hold commas, as `solve` and this program's
    // other CSV files write them (QA pass 13 of #16); a quoted name is taken as written,
    // the other fields trimmed.
    if line_text.matches('"').count() % 2 == 1 {
        return Err(
            "a quote is not closed: a name in quotes ends with a quote, and a quote \
                    inside it is written twice (\"\")"
                .into(),
        );
    }
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(line_text.as_bytes());
    let mut record = csv::StringRecord::new();
    match reader.read_record(&mut record) {
        Ok(true) => {}
        Ok(false) => return Err("expected 7 fields (name,x,y,z,nx,ny,nz), found none".into()),
        Err(e) => return Err(format!("not a CSV line: {e}")),
    }
    let quoted = line_text.trim_start().starts_with('"');
    let fields: Vec<&str> = record
        .iter()
        .enumerate()
        .map(|(k, f)| if k == 0 && quoted { f } else { f.trim() })
        .collect();
    if fields.len() != 7 {
        return Err(format!(
            "expected 7 fields (name,x,y,z,nx,ny,nz), found {}",
            fields.len()
        ));
    }
    let mut v = [0.0; 6];
    for (k, f) in fields[1..].iter().enumerate() {
        let what = ["x", "y", "z", "nx", "ny", "nz"][k];
        v[k] = match f.parse::<f64>() {
            Ok(x) if x.is_finite() => x,
            _ => {
                return Err(format!(
                    "expected a finite number for {what}, found \"{f}\""
                ))
            }
        };
    }
    let normal = DVec3::new(v[3], v[4], v[5]);
    if normal.length_squared() == 0.0 {
        return Err(
            "the normal nx,ny,nz is 0,0,0; give the direction the meter faces (0,0,1 \
                    for a horizontal work plane in a z-up scene)"
                .to_string(),
        );
    }
    let name = fields[0];
    if name.is_empty() {
        return Err(
            "the point has no name; give each point a name (the first field), \
                    which labels its row of the lux CSV"
                .to_string(),
        );
    }
    if let Some(&first) = first_line_of.get(name) {
        return Err(format!(
            "the name \"{name}\" is already the point's on line {first}; give each point \
             its own name, which labels its row of the lux CSV"
        ));
    }
    first_line_of.insert(name.to_string(), line);
    Ok(CalcPoint {
        name: name.to_string(),
        position: DVec3::new(v[0], v[1], v[2]),
        normal,
    })
}

/// Writes the illuminance CSV ([`LUX_HEADER`]), one row per point, numbers as Rust's
/// shortest round-trip text.
pub fn write_lux_csv(
    points: &[CalcPoint],
    lux: &[Lux],
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    writeln!(out, "{LUX_HEADER}")?;
    for (p, l) in points.iter().zip(lux) {
        let (x, n) = (p.position, p.normal);
        writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{}",
            crate::io::surface_report::csv_name(&p.name),
            x.x,
            x.y,
            x.z,
            n.x,
            n.y,
            n.z,
            l.direct,
            l.indirect,
            l.total
        )?;
    }
    Ok(())
}

/// A 3 x 5 pixel font for the grid picture's numbers and unit: each glyph is five rows of
/// three bits (most significant bit left).
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        '-' => [0, 0, 7, 0, 0],
        'l' => [6, 2, 2, 2, 3],
        'x' => [0, 5, 2, 5, 5],
        'y' => [5, 5, 7, 1, 7],
        // Lower case, as 'x' and 'y' are: drawn full height it read as a "2" (QA pass 20 of
        // #16).
        'z' => [0, 7, 1, 2, 7],
        'u' => [0, 5, 5, 5, 7],
        'e' => [7, 5, 7, 4, 7],
        '+' => [0, 2, 7, 2, 0],
        '/' => [1, 1, 2, 4, 4],
        '=' => [0, 7, 0, 7, 0],
        'A' => [2, 5, 7, 5, 5],
        'E' => [7, 4, 6, 4, 7],
        'I' => [7, 2, 2, 2, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'U' => [5, 5, 5, 5, 7],
        'X' => [5, 5, 2, 5, 5],
        ' ' => [0; 5],
        _ => return None,
    })
}

/// Draws `text` with its top left corner at (x, y), each font pixel `s` x `s`.
fn draw_text(img: &mut image::RgbImage, x: i64, y: i64, s: i64, text: &str, colour: [u8; 3]) {
    for (k, c) in text.chars().enumerate() {
        let Some(rows) = glyph(c) else { continue };
        for (r, bits) in rows.iter().enumerate() {
            for col in 0..3 {
                if bits >> (2 - col) & 1 == 1 {
                    for dy in 0..s {
                        for dx in 0..s {
                            let px = x + (k as i64 * 4 + col) * s + dx;
                            let py = y + r as i64 * s + dy;
                            if px >= 0
                                && py >= 0
                                && (px as u32) < img.width()
                                && (py as u32) < img.height()
                            {
                                img.put_pixel(px as u32, py as u32, image::Rgb(colour));
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The width in pixels of `text` at font scale `s`.
fn text_width(text: &str, s: i64) -> i64 {
    (text.chars().count() as i64 * 4 - 1).max(0) * s
}

/// The false-colour scale: dark blue at 0 through cyan, green and yellow to red at 1 (the
/// ramp of lighting tools' false-colour views).
pub fn false_colour(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [0.0, 0.0, 0.6],
        [0.0, 0.7, 1.0],
        [0.1, 0.8, 0.2],
        [1.0, 0.9, 0.0],
        [0.9, 0.1, 0.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let c: [f64; 3] = std::array::from_fn(|b| STOPS[i][b] * (1.0 - f) + STOPS[i + 1][b] * f);
    c.map(|v| (v * 255.0).round() as u8)
}

/// A value as lighting tools print it: whole lux from 100, one decimal from 10, two below,
/// and two significant figures below 0.1 (exponent form below 1e-6 and from a million).
pub fn lux_label(v: f64) -> String {
    let a = v.abs();
    // Below 0.1 and above a million, two or three significant figures (QA of issue #16: a
    // dim room's grid read 0.00 and 0.01 in every cell beside a scale to 0.014).
    if a >= 1e6 {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else if a == 0.0 {
        // Plain 0 among whole lux (QA pass 13 of #16: "MIN 0.00 ... MAX 516").
        "0".to_string()
    } else if a >= 0.1 || !a.is_finite() {
        format!("{v:.2}")
    } else if a >= 1e-6 {
        let decimals = (-a.log10()).floor() as usize + 2;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.1e}")
    }
}

/// The figures a lighting designer reads off a grid: the least, the mean and the largest
/// illuminance, and the uniformity U0 = min / mean (EN 12464-1's measure); over the finite
/// values, `None` when there are none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSummary {
    /// The least value, lux.
    pub min: f64,
    /// The mean of the values (the points of a regular grid stand for equal areas), lux.
    pub mean: f64,
    /// The largest value, lux.
    pub max: f64,
}

impl GridSummary {
    /// The summary of `values` (non-finite ones left out).
    pub fn of(values: &[f64]) -> Option<Self> {
        let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if finite.is_empty() {
            return None;
        }
        Some(Self {
            min: finite.iter().copied().fold(f64::INFINITY, f64::min),
            mean: finite.iter().sum::<f64>() / finite.len() as f64,
            max: finite.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }

    /// U0 = min / mean; 0 when the mean is not above 0.
    pub fn uniformity(&self) -> f64 {
        if self.mean > 0.0 {
            self.min / self.mean
        } else {
            0.0
        }
    }

    /// The line printed above the grid: "MIN 12.3  MEAN 45.6  MAX 78.9 lx  U0 0.27" (the
    /// picture's font has capitals for these words only).
    pub fn line(&self) -> String {
        // U0 = min / mean has no value on a dark grid (QA pass 14 of #16: "U0 0.00").
        let u0 = if self.mean > 0.0 {
            format!("{:.2}", self.uniformity())
        } else {
            "-".to_string()
        };
        format!(
            "MIN {}  MEAN {}  MAX {} lx  U0 {u0}",
            lux_label(self.min),
            lux_label(self.mean),
            lux_label(self.max),
        )
    }
}

/// The labels of a scale from 0 to `max` in `ticks` equal steps, all with the decimals the
/// step needs and no more (0, 20, ..., 160; 0, 0.25, ..., 1.25; 0, 0.5, ..., 2.5 as
/// 0.0, 0.5, ..., 2.5), so that a column of them reads at a glance.
///
/// Where such labels would pass 6 characters (the scale bar's room) or 4 decimals do not
/// write the step exactly, every label but 0 is written with an exponent to three digits
/// where they fit, else fewer, "1.25E6", "2.5E-7", "2E-31" (QA pass 14 of #16:
/// `--lux-max 123456` ran off the picture and `--lux-max 1e-6` read 0 at every tick).
pub fn tick_labels(max: f64, ticks: usize) -> Vec<String> {
    let ticks = ticks.max(1);
    let step = max / ticks as f64;
    let decimals = decimals_of(step);
    let plain: Vec<String> = (0..=ticks)
        .map(|k| format!("{:.*}", decimals, step * k as f64))
        .collect();
    if step >= 1e-4 && exact_decimals(step).is_some() && plain.iter().all(|l| l.len() <= 6) {
        return plain;
    }
    // A capital E: the pictures' small 'e' reads as a 2. Three digits where they fit
    // (1.25E6, a nice scale's top), else two, else one.
    (0..=ticks)
        .map(|k| {
            let v = step * k as f64;
            match k {
                0 => "0".to_string(),
                _ => [2, 1, 0]
                    .iter()
                    .map(|&d| format!("{v:.d$E}"))
                    .find(|l| l.len() <= 6)
                    .unwrap_or_else(|| format!("{v:.0E}")),
            }
        })
        .collect()
}

/// The values and labels of a scale bar from 0 to `max`: `ticks` equal steps
/// ([`tick_labels`]) where their labels are plain numbers or `max` is a round number of
/// round steps ([`nice_scale`]); else, for a top such as a user's `--lux-max 123456`, the
/// round steps below it (0, 25000, ..., 100000) and the top itself, so that every label but
/// perhaps the top's reads at a glance (QA pass 17 of #16: the fifths of 123456 read
/// "2.47E4", "4.94E4", ...).
pub fn scale_ticks(max: f64, ticks: usize) -> Vec<(f64, String)> {
    let equal = |max: f64, ticks: usize| -> Vec<(f64, String)> {
        let n = ticks.max(1);
        tick_labels(max, n)
            .into_iter()
            .enumerate()
            .map(|(k, l)| (max * k as f64 / n as f64, l))
            .collect()
    };
    let labels = tick_labels(max, ticks);
    let round_top = (nice_scale(max).0 - max).abs() <= 1e-9 * max;
    if !(max.is_finite() && max > 0.0) || round_top || labels.iter().all(|l| !l.contains('E')) {
        return equal(max, ticks);
    }
    // The largest round step (1, 2, 2.5 or 5 times a power of ten) of which 4 to 8 fit
    // below the top.
    let e = max.log10().floor() as i32;
    let Some((step, n)) = (e - 2..=e)
        .rev()
        .flat_map(|k| [5.0, 2.5, 2.0, 1.0].map(|m| m * 10f64.powi(k)))
        .map(|step| (step, (max / step * (1.0 + 1e-12)).floor() as usize))
        .find(|&(_, n)| (4..=8).contains(&n))
    else {
        return equal(max, ticks);
    };
    let mut out = equal(step * n as f64, n);
    out.push((max, top_label(max)));
    out
}

/// A scale's top that is not a round number: plain where it fits the bar's 6 characters
/// exactly (123456) or to three significant digits (0.123), else with an exponent
/// (1.23E6), as [`tick_labels`] writes.
fn top_label(max: f64) -> String {
    // Below 1e-4 four decimals write nothing of it (review of #16: 3.3e-7 read "0").
    if let Some(d) = exact_decimals(max).filter(|_| max >= 1e-4) {
        let plain = format!("{max:.d$}");
        if plain.len() <= 6 {
            return plain;
        }
    }
    let decimals = (2 - max.log10().floor() as i32).max(0) as usize;
    let plain = format!("{max:.decimals$}");
    if plain.len() <= 6 && max >= 1e-3 {
        return plain;
    }
    [2, 1, 0]
        .iter()
        .map(|&d| format!("{max:.d$E}"))
        .find(|l| l.len() <= 6)
        .unwrap_or_else(|| format!("{max:.0E}"))
}

/// The fewest decimals (up to 4) that write every multiple of `step` exactly.
fn decimals_of(step: f64) -> usize {
    exact_decimals(step).unwrap_or(4)
}

/// The fewest decimals (up to 4) that write every multiple of `step` exactly, if any do.
fn exact_decimals(step: f64) -> Option<usize> {
    (0..=4).find(|&d| {
        let scaled = step.abs() * 10f64.powi(d as i32);
        (scaled - scaled.round()).abs() <= 1e-6 * scaled.max(1.0)
    })
}

/// Where a grid's columns and rows stand, for the coordinates printed along the picture's
/// edges (a plan reads by its coordinates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridAxes {
    /// The axes along the columns and along the rows: 'x', 'y' or 'z'.
    pub names: [char; 2],
    /// The coordinate of column 0 and of row 0.
    pub first: [f64; 2],
    /// From one column (row) to the next: the spacing, signed.
    pub step: [f64; 2],
    /// Row 0 drawn at the top, not the bottom ([`GridAxes::as_drawn`]).
    pub rows_down: bool,
    /// Column 0 drawn at the right, not the left ([`GridAxes::as_drawn`]).
    pub cols_left: bool,
}

impl GridAxes {
    /// The axes of [`grid`]`(a, b, spacing, ..)` when it varies along two axes, or along
    /// one (a line: its one row labelled by the first axis it does not vary along, QA of
    /// issue #16: a line's picture had no coordinates); a point has none to print.
    pub fn of(a: DVec3, b: DVec3, spacing: f64) -> Option<Self> {
        let varying: Vec<usize> = (0..3).filter(|&i| a[i] != b[i]).collect();
        let name = |i: usize| ['x', 'y', 'z'][i];
        if let [u] = varying[..] {
            let w = (0..3).find(|&i| i != u).unwrap_or(0);
            return Some(Self {
                names: [name(u), name(w)],
                first: [a[u], a[w]],
                step: [(b[u] - a[u]).signum() * spacing, 0.0],
                rows_down: false,
                cols_left: false,
            });
        }
        let [u, v] = varying[..] else { return None };
        Some(Self {
            names: [name(u), name(v)],
            first: [a[u], a[v]],
            step: [
                (b[u] - a[u]).signum() * spacing,
                (b[v] - a[v]).signum() * spacing,
            ],
            rows_down: false,
            cols_left: false,
        })
    }

    /// The axes drawn as lighting plans and elevations are, columns left to right: rows
    /// running up the picture as their coordinate grows, except on a horizontal grid of a
    /// y-up scene (`z_up` false; axes x and z), a plan seen from above with x to the
    /// right, where z grows down the picture (QA of issue #16: it was drawn as seen from
    /// below). A wall's height (y, or z in a z-up scene) runs up when it is the row axis.
    /// Corners given high to low along either axis draw the same picture (QA passes 14
    /// and 15 of #16: reversed corners mirrored the columns).
    pub fn as_drawn(self, z_up: bool) -> Self {
        let plan_z_down = !z_up && self.names == ['x', 'z'];
        Self {
            rows_down: plan_z_down != (self.step[1] < 0.0),
            cols_left: self.step[0] < 0.0,
            ..self
        }
    }

    /// The grid of `values` (`dims` = [columns, rows], as [`grid`] makes them) with its
    /// columns and rows swapped where its columns run along the scene's up axis (z when
    /// `z_up`, else y) and its rows do not: a wall at constant x in a y-up scene, whose
    /// axes come as (y, z), so that its height runs up the picture as every other wall's
    /// does (QA pass 17 of #16: it was drawn lying on its side). Other grids come back as
    /// they are.
    pub fn upright(
        self,
        values: &[f64],
        dims: [usize; 2],
        z_up: bool,
    ) -> (Vec<f64>, [usize; 2], Self) {
        let up = if z_up { 'z' } else { 'y' };
        let [nu, nv] = dims;
        if self.names[0] != up || self.names[1] == up || nu * nv != values.len() {
            return (values.to_vec(), dims, self);
        }
        // Value (i, j) (column i, row j) becomes (j, i).
        let swapped: Vec<f64> = (0..nu * nv)
            .map(|k| values[(k % nv) * nu + k / nv])
            .collect();
        let axes = Self {
            names: [self.names[1], self.names[0]],
            first: [self.first[1], self.first[0]],
            step: [self.step[1], self.step[0]],
            rows_down: self.cols_left,
            cols_left: self.rows_down,
        };
        (swapped, [nv, nu], axes)
    }

    /// A wall's grid drawn as a person standing before the meters sees it, looking against
    /// `normal` (the way they face) with the scene's up (z when `z_up`, else y) up the
    /// picture: its columns mirrored where their axis then runs to the left (QA pass 17 of
    /// #16: the wall at the far end of a room was drawn as seen from behind it). Plans and
    /// grids whose rows are not the up axis are left as they are, as is a normal along the
    /// columns' axis.
    pub fn seen_from(self, normal: DVec3, z_up: bool) -> Self {
        let (up, up_name) = if z_up {
            (DVec3::Z, 'z')
        } else {
            (DVec3::Y, 'y')
        };
        if self.names[1] != up_name {
            return self;
        }
        let column = match self.names[0] {
            'x' => DVec3::X,
            'y' => DVec3::Y,
            _ => DVec3::Z,
        };
        let right = (-normal).cross(up);
        let along = right.dot(column);
        if along.abs() <= 1e-9 * right.length() {
            return self;
        }
        Self {
            cols_left: self.cols_left != (along < 0.0),
            ..self
        }
    }

    /// The labels of `n` columns (`axis` 0) or rows (1), with the decimals of the step.
    pub fn labels(&self, axis: usize, n: usize) -> Vec<String> {
        let d = decimals_of(self.step[axis]).max(decimals_of(self.first[axis]));
        (0..n)
            .map(|k| {
                let v = self.first[axis] + k as f64 * self.step[axis];
                // + 0.0 writes -0 as 0.
                format!("{:.*}", d, v + 0.0)
            })
            .collect()
    }
}

/// The coordinates a grid from `a` to `b` holds fixed, as the grid picture prints them under
/// its summary: "z = 0.8" for a plan, "y = 0.8  z = 1" for a line, all three for a point
/// (QA pass 13 of #16: a one-point grid's picture said nowhere where it was, a line's only
/// one of its two fixed coordinates). Empty when every coordinate varies.
pub fn held_coordinates(a: DVec3, b: DVec3) -> String {
    (0..3)
        .filter(|&i| a[i] == b[i])
        .map(|i| {
            let d = decimals_of(a[i]);
            format!("{} = {:.*}", ['x', 'y', 'z'][i], d, a[i] + 0.0)
        })
        .collect::<Vec<_>>()
        .join("  ")
}

/// The font scale of the scale bars' text (3 x 5 glyphs drawn 3 times: 9 x 15 pixels).
const LEGEND_FONT: i64 = 3;

/// The grid as lighting tools draw it: above it, the least, mean and largest illuminance and
/// the uniformity U0 ([`GridSummary`]); one cell per point coloured by its value on the
/// false-colour scale from 0 to a round top ([`nice_scale`] of the largest value), the value
/// printed in the cell (where it fits), row 0 at the bottom (a plan seen from above for a
/// z-up floor grid) unless the axes say otherwise ([`GridAxes::as_drawn`]); on the right a scale bar with its values and the unit `lx`. `values`
/// run column by column within rows (as [`grid`] makes them); `dims` = [columns, rows].
pub fn grid_picture(values: &[f64], dims: [usize; 2]) -> image::RgbImage {
    grid_picture_with_axes(values, dims, None, "")
}

/// [`grid_picture`] with the coordinates of the columns below the cells and of the rows
/// left of them (every column or row where the labels fit, else every second, third, ...),
/// each axis named at the end of its labels, and `held` (the coordinates the grid holds
/// fixed, [`held_coordinates`]) under the summary line.
pub fn grid_picture_with_axes(
    values: &[f64],
    dims: [usize; 2],
    axes: Option<GridAxes>,
    held: &str,
) -> image::RgbImage {
    let [nu, nv] = dims;
    let summary = GridSummary::of(values);
    let (max, ticks) = nice_scale(summary.map_or(0.0, |s| s.max));
    let scale_of = |v: f64| if max > 0.0 { v / max } else { 0.0 };
    // Cells wide enough for the longest label at font scale 2 where the grid allows it.
    let longest = values
        .iter()
        .map(|&v| lux_label(v).len())
        .max()
        .unwrap_or(1) as i64;
    let want = (text_width(&"8".repeat(longest as usize), 2) + 8).max(24);
    let cell = want
        .min((1600 / nu.max(1) as i64).max(4))
        .min((1200 / nv.max(1) as i64).max(4));
    let (gw, gh) = (cell * nu as i64, cell * nv as i64);
    let top = GRID_TOP;
    let labels = axes.map(|a| (a.labels(0, nu), a.labels(1, nv)));
    // Where row j is drawn, counted from the top.
    let rows_down = axes.is_some_and(|a| a.rows_down);
    let row_at = |j: usize| if rows_down { j } else { nv - 1 - j };
    // Where column i is drawn, counted from the left.
    let cols_left = axes.is_some_and(|a| a.cols_left);
    let col_at = |i: usize| if cols_left { nu - 1 - i } else { i };
    // Room for the row labels on the left and the column labels below.
    let (left, below) = match &labels {
        Some((_, rows)) => {
            let widest = rows.iter().map(|l| text_width(l, 2)).max().unwrap_or(0);
            (GRID_MARGIN + widest + 8, GRID_MARGIN + 20)
        }
        None => (GRID_MARGIN, GRID_MARGIN),
    };
    let margin = left;
    let line = summary.map(|s| s.line()).unwrap_or_default();
    // The scale bar runs beside the cells, 200 px at least.
    let bar_bottom = top + gh.max(200);
    let height = bar_bottom + below;
    let width = (gw + margin + GRID_MARGIN + GRID_LEGEND_WIDTH)
        .max(text_width(&line, 2) + 2 * GRID_MARGIN)
        .max(text_width(held, 2) + 2 * GRID_MARGIN);
    // Where the scale bar stands, right of the cells.
    let bar_x = gw + margin + GRID_MARGIN + 8;
    let mut img = image::RgbImage::from_pixel(width as u32, height as u32, image::Rgb([255; 3]));
    draw_text(&mut img, GRID_MARGIN, 10, 2, &line, [0; 3]);
    draw_text(&mut img, GRID_MARGIN, 24, 2, held, [0; 3]);
    if let (Some((cols, rows)), Some(axes)) = (&labels, axes) {
        // Every k-th column so that the labels keep 6 px apart; every k-th row so that
        // they keep 4 px apart (10 px tall).
        let widest = cols.iter().map(|l| text_width(l, 2)).max().unwrap_or(0);
        let every_col = ((widest + 6 + cell - 1) / cell).max(1) as usize;
        let every_row = ((14 + cell - 1) / cell).max(1) as usize;
        // The column axis's name goes right of the cells, or of the last label where that
        // reaches further (QA pass 14 of #16: "5200x").
        let mut name_x = margin + gw + 6;
        for (i, label) in cols.iter().enumerate().step_by(every_col) {
            let centre = margin + col_at(i) as i64 * cell + cell / 2;
            let x = centre - text_width(label, 2) / 2;
            draw_text(&mut img, x, top + gh + 6, 2, label, [0; 3]);
            name_x = name_x.max(x + text_width(label, 2) + 8);
        }
        for (j, label) in rows.iter().enumerate().step_by(every_row) {
            let centre = top + row_at(j) as i64 * cell + cell / 2;
            let x = margin - 6 - text_width(label, 2);
            draw_text(&mut img, x, centre - 5, 2, label, [0; 3]);
        }
        // The axis names: the columns' right of their labels, the rows' above theirs.
        let name = |c: char| c.to_string();
        // Where that would reach the scale bar, under the last column, a row lower.
        let column_name = name(axes.names[0]);
        let (name_x, name_y) = if name_x + text_width(&column_name, 2) + 2 <= bar_x {
            (name_x, top + gh + 6)
        } else {
            (margin + gw - text_width(&column_name, 2), top + gh + 19)
        };
        draw_text(&mut img, name_x, name_y, 2, &column_name, [0; 3]);
        draw_text(
            &mut img,
            margin - 18,
            top - 16,
            2,
            &name(axes.names[1]),
            [0; 3],
        );
    }
    for j in 0..nv {
        for i in 0..nu {
            let v = values.get(j * nu + i).copied().unwrap_or(0.0);
            let c = false_colour(scale_of(v));
            let (x0, y0) = (
                margin + col_at(i) as i64 * cell,
                top + row_at(j) as i64 * cell,
            );
            for y in y0..y0 + cell {
                for x in x0..x0 + cell {
                    let edge = x == x0 || y == y0;
                    let px = if edge && cell >= 8 { [255; 3] } else { c };
                    img.put_pixel(x as u32, y as u32, image::Rgb(px));
                }
            }
            let label = lux_label(v);
            let tw = text_width(&label, 2);
            if tw + 4 <= cell && cell >= 14 {
                let lum = 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
                let ink = if lum > 110.0 { [0; 3] } else { [255; 3] };
                draw_text(
                    &mut img,
                    x0 + (cell - tw) / 2,
                    y0 + (cell - 10) / 2,
                    2,
                    &label,
                    ink,
                );
            }
        }
    }
    draw_scale_bar(&mut img, bar_x, top - 24, bar_bottom, max, ticks);
    img
}

/// The grid picture's margin left, right and below, pixels.
pub const GRID_MARGIN: i64 = 10;
/// Where the grid picture's cells start from the top (below the summary line), pixels.
pub const GRID_TOP: i64 = 60;
/// The width of the grid picture's scale bar and its values, pixels.
pub const GRID_LEGEND_WIDTH: i64 = SCALE_BAR_WIDTH as i64;

/// The scale bar of a false-colour picture, `lx` at its top left corner (x, y), the bar
/// from y + 24 down to `bottom` (top = `max`, bottom = 0), and `ticks` + 1 values beside it
/// ([`tick_labels`]), in the [`LEGEND_FONT`]; [`SCALE_BAR_WIDTH`] wide at most.
fn draw_scale_bar(img: &mut image::RgbImage, bx: i64, y: i64, bottom: i64, max: f64, ticks: usize) {
    let (by0, by1) = (y + 24, bottom);
    draw_text(img, bx, y, LEGEND_FONT, "lx", [0; 3]);
    for y in by0..by1 {
        let t = 1.0 - (y - by0) as f64 / (by1 - by0 - 1).max(1) as f64;
        for x in bx..bx + 18 {
            img.put_pixel(x as u32, y as u32, image::Rgb(false_colour(t)));
        }
    }
    let scale = scale_ticks(max, ticks);
    let last = scale.len() - 1;
    let length = (by1 - by0 - 1) as f64;
    // Every tick is drawn, but only every `stride`-th labelled where the bar is too short
    // for all the labels to stand apart (QA of issue #16: at the smallest picture, 160
    // pixels tall, eight labels ran into each other), and the top always; a label is left
    // out where it would touch the top's. (A stride that had to divide the ticks labelled
    // only the ends of a bar of 7 ticks: QA pass 12.)
    // Where each tick stands on the bar, 0 at the bottom and 1 at the top.
    let at = |k: usize| {
        if max > 0.0 {
            scale[k].0 / max
        } else {
            k as f64 / last.max(1) as f64
        }
    };
    let spacing = length * at(1.min(last));
    let need = (5 * LEGEND_FONT + 3) as f64;
    let stride = (1..=last.max(1))
        .find(|&s| spacing * s as f64 >= need)
        .unwrap_or(last.max(1));
    let labelled = |k: usize| k == last || (k % stride == 0 && (1.0 - at(k)) * length >= need);
    for (k, (_, label)) in scale.iter().enumerate() {
        let y = by1 - 1 - (length * at(k)).round() as i64;
        // A short tick, then a gap of 6 px, so that it does not read as a minus sign.
        for x in bx + 18..bx + 21 {
            for dy in 0..2 {
                if y + dy < by1 {
                    img.put_pixel(x as u32, (y + dy) as u32, image::Rgb([0; 3]));
                }
            }
        }
        if labelled(k) {
            let half = 5 * LEGEND_FONT / 2;
            draw_text(img, bx + 27, (y - half).max(0), LEGEND_FONT, label, [0; 3]);
        }
    }
}

/// The illuminance in lux (Y of the bands) on the front of every element of the solution's
/// mesh, for `render --false-colour`. Where the element reflects in every band it is read
/// back from the solution: the irradiance H = (B - E) / rho per band (B the solution's
/// radiosity, of a progressive run the light shot so far, E the surface's own
/// emission), the mean over the element as the solver has it. Where a band's reflectance is
/// 0 the solution holds no trace of the light that arrived, so the illuminance is computed
/// at the element's centroid as [`illuminance`] computes it at a calculation point (direct
/// plus indirect, exact form factors and shadow rays).
pub fn element_illuminance(prepared: &Prepared, solution: &Solution) -> Vec<f64> {
    element_illuminance_with_progress(prepared, solution, &crate::progress::NoProgress)
}

/// [`element_illuminance`], reporting the centroids it computes (the elements that do not
/// reflect in every band) as [`crate::progress::Stage::Illuminance`], one unit a centroid.
pub fn element_illuminance_with_progress(
    prepared: &Prepared,
    solution: &Solution,
    progress: &dyn crate::progress::Progress,
) -> Vec<f64> {
    let scene = &prepared.scene;
    let mesh = &solution.mesh;
    let (_, shown) = reflectance_and_shown(scene, solution);
    let mut out = vec![0.0; mesh.len()];
    let mut black = Vec::new();
    for (i, el) in mesh.elements.iter().enumerate() {
        let surface = &scene.surfaces[el.surface as usize];
        let rho = surface.reflectance;
        if rho.0.iter().all(|&r| r > 0.0) {
            let h = Rgb(std::array::from_fn(|k| {
                (shown[i].0[k] - surface.emission.0[k]) / rho.0[k]
            }));
            out[i] = h.luminance().max(0.0);
        } else {
            black.push(CalcPoint {
                name: String::new(),
                position: el.centroid,
                normal: el.normal,
            });
        }
    }
    if !black.is_empty() {
        let lux = crate::progress::run_stage(
            progress,
            crate::progress::Stage::Illuminance,
            black.len() as u64,
            || illuminance_with_progress(prepared, solution, &black, progress),
        );
        let mut k = 0;
        for (i, el) in mesh.elements.iter().enumerate() {
            if !scene.surfaces[el.surface as usize]
                .reflectance
                .0
                .iter()
                .all(|&r| r > 0.0)
            {
                out[i] = lux[k].total;
                k += 1;
            }
        }
    }
    out
}

/// A scale for `max` that reads at a glance: the smallest top at or above `max` that is
/// n steps of 1, 2, 2.5 or 5 times a power of ten, n from 4 to 8 (150.3 lux: 8 steps of
/// 20 up to 160), and n. `(1, 5)` for a `max` that is not a positive number: a scale of
/// steps where every value is 0 (QA of issue #16: six labels of "0").
pub fn nice_scale(max: f64) -> (f64, usize) {
    if !(max.is_finite() && max > 0.0) {
        return (1.0, 5);
    }
    let e = max.log10().floor() as i32;
    let mut best = (f64::INFINITY, 5);
    for k in e - 2..=e + 1 {
        for m in [1.0, 2.0, 2.5, 5.0] {
            let step = m * 10f64.powi(k);
            for n in 4..=8 {
                let top = step * n as f64;
                if top >= max * (1.0 - 1e-12) && top < best.0 {
                    best = (top, n);
                }
            }
        }
    }
    best
}

/// The least height in pixels of a [`false_colour_picture`], for its scale bar's labels.
pub const FALSE_COLOUR_MIN_HEIGHT: u32 = 200;

/// The width in pixels of the scale bar [`false_colour_picture`] adds on the right.
pub const SCALE_BAR_WIDTH: u32 = 110;

/// A rendered view in false colour: `lux` and `coverage` per pixel (row by row from the
/// top, `width` x `height`), coverage the fraction of the pixel's rays that met a surface
/// (0 for the background, which stays white; edges blend into it). Each pixel's colour is
/// [`false_colour`] of its illuminance over `max`, values above `max` in the top colour;
/// on the right a [`SCALE_BAR_WIDTH`] wide scale bar from 0 to `max` with `ticks` + 1
/// values ([`nice_scale`] gives a `max` and `ticks` that read well) and the unit `lx`.
pub fn false_colour_picture(
    lux: &[f64],
    coverage: &[f64],
    width: u32,
    height: u32,
    max: f64,
    ticks: usize,
) -> image::RgbImage {
    let total_w = width + SCALE_BAR_WIDTH;
    // Tall enough that a scale of up to 8 steps labels every one: 150 px of bar at 18 px a
    // label (QA pass 15 of #16: at 160 px, a 64-pixel view's scale of 7 steps left its
    // sixth unlabelled).
    let total_h = height.max(FALSE_COLOUR_MIN_HEIGHT);
    let mut img = image::RgbImage::from_pixel(total_w, total_h, image::Rgb([255; 3]));
    for y in 0..height {
        for x in 0..width {
            let k = (y * width + x) as usize;
            let c = coverage.get(k).copied().unwrap_or(0.0).clamp(0.0, 1.0);
            if c <= 0.0 {
                continue;
            }
            let v = lux.get(k).copied().unwrap_or(0.0);
            let t = if max > 0.0 { v / max } else { 0.0 };
            let colour = false_colour(t);
            let px = colour.map(|ch| (ch as f64 * c + 255.0 * (1.0 - c)).round() as u8);
            img.put_pixel(x, y, image::Rgb(px));
        }
    }
    draw_scale_bar(
        &mut img,
        width as i64 + 8,
        10,
        total_h as i64 - 16,
        max,
        ticks,
    );
    img
}
