//! Illuminance at calculation points: what a lighting designer's light meter would read at
//! a point with a given normal, split into the direct and the indirect light.
//!
//! * **Direct**: the light that arrives straight from emission: each emitting surface's
//!   own exitance times Lambert's exact point-to-polygon form factor times the visible
//!   fraction (shadow rays, [`crate::render::DirectLight`]), plus each point luminaire's
//!   I cos / d^2 where its segment is clear.
//! * **Indirect**: the light that arrives from reflected light: every element's reflected
//!   exitance (its radiosity less its surface's own emission; progressive refinement's
//!   ambient term included) times the exact point-to-polygon form factor to the element
//!   times the visible fraction of the element (kernel-weighted shadow rays to 3 x 3 points
//!   of it; an element seen whole needs no more).
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

/// The illuminance at each of `points` for the scene of `prepared` solved as `solution`
/// (any solver's: its mesh may be the prepared one, adaptive subdivision's or hierarchical
/// radiosity's leaves). Points run in parallel; the result is in the order of `points` and
/// does not depend on threads.
pub fn illuminance(prepared: &Prepared, solution: &Solution, points: &[CalcPoint]) -> Vec<Lux> {
    let scene = &prepared.scene;
    let direct = DirectLight::new(scene);
    let mesh = &solution.mesh;
    let reflectance: Vec<Rgb> = mesh
        .elements
        .iter()
        .map(|e| scene.surfaces[e.surface as usize].reflectance)
        .collect();
    let shown = solution.display_radiosity(&reflectance);
    // Each element's reflected exitance (Y) and corners; the elements that reflect nothing
    // are left out.
    let reflecting: Vec<(usize, f64, Vec<DVec3>)> = mesh
        .elements
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let own = scene.surfaces[e.surface as usize].emission;
            let r = (shown[i] - own).luminance();
            (r > 0.0).then(|| (i, r, mesh.corner_positions(i).collect()))
        })
        .collect();
    let occluders = &prepared.occluders;
    points
        .par_iter()
        .enumerate()
        .map(|(k, p)| {
            let n = p.normal.normalize_or_zero();
            if n == DVec3::ZERO {
                return Lux::default();
            }
            let salt = 0x5eed_0000_0000_0000 ^ k as u64;
            let d = direct.irradiance(p.position, n, salt).luminance();
            let mut ind = 0.0;
            let mut samples = Vec::with_capacity((ELEMENT_POINTS * ELEMENT_POINTS) as usize);
            for (e, r, poly) in &reflecting {
                let f = point_to_polygon(p.position, n, poly);
                if f <= 0.0 {
                    continue;
                }
                samples.clear();
                mesh.integration_points(*e, ELEMENT_POINTS, &mut samples);
                let normal = mesh.elements[*e].normal;
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
                // All points behind the meter's plane while Lambert sees a sliver: seen.
                let fraction = if total > 0.0 { seen / total } else { 1.0 };
                ind += r * f * fraction;
            }
            Lux {
                direct: d,
                indirect: ind,
                total: d + ind,
            }
        })
        .collect()
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
                p[axis] = a[axis] + (b[axis] - a[axis]).signum() * k * spacing;
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
