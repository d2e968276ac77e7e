//! Point luminaires: a position, an axis and a luminous intensity distribution, as written
//! in a scene file's `LIGHTBEGIN` ... `LIGHTEND` block ([`crate::io::scene_file`]).
//!
//! # Units
//!
//! Scene lengths are metres (unless the command line's `--scale` said otherwise), so a
//! luminous intensity I in candela gives an illuminance `E = I cos(theta) / d^2` in lux at a
//! distance d in metres, and the radiosity solution's exitances are lm/m^2. Each band of the
//! light is the intensity times its `COLOUR` (1 1 1 unless given): photometric reports weigh
//! the bands by [`crate::light::Rgb::luminance`], so an untinted light reports its own value.
//!
//! # Distributions
//!
//! * `ISOTROPIC`: I in every direction; flux 4 pi I.
//! * `COSINE`: I0 cos(theta) in the hemisphere around the axis, nothing behind it; flux
//!   pi I0 (a Lambertian disc seen from far away).
//! * `IES file.ies`: an IES LM-63 type C table ([`crate::photometry::ies`]).
//!
//! `INTENSITY I` gives the intensity on the axis (for `ISOTROPIC`, in every direction);
//! `FLUX P` gives the lumens emitted in all directions instead, and the intensity follows
//! from the distribution's shape. An IES light takes `FLUX` to scale its table to P lumens,
//! and otherwise its candela values stand as the file gives them.
//!
//! # Angles and the azimuth convention
//!
//! theta is the angle from the axis (`AIM`, default 0 0 -1: -z, straight down in a z-up scene), the photometric
//! axis of type C photometry (theta = 0 is nadir for a downlight). The azimuth phi (the C
//! plane) is measured round the axis from a reference direction `u` towards `v = aim x u`,
//! counter-clockwise seen from behind the light looking along the axis... for the default
//! aim (down) that is: phi = 0 along +x, phi = 90 degrees along +y (counter-clockwise seen
//! from above, as the C planes of LM-63 go). For another aim, (u, v) are +x and +y turned by
//! the smallest rotation that takes 0 0 -1 to the aim, so they change continuously with the
//! aim; an aim straight up (0 0 1) uses the half turn about x (u = +x, v = -y).

use std::f64::consts::PI;

use std::sync::Arc;

use glam::DVec3;

use crate::light::Rgb;
use crate::photometry::ies::IesPhotometry;

/// The default `AIM`: -z (straight down in a z-up scene; horizontal in a y-up one such as
/// the Cornell box, whose downlights need `AIM 0 -1 0`).
pub const DEFAULT_AIM: DVec3 = DVec3::new(0.0, 0.0, -1.0);

/// The shape of a luminaire's intensity distribution.
#[derive(Clone, Debug)]
pub enum Distribution {
    /// The same intensity in every direction.
    Isotropic,
    /// I0 cos(theta) in front of the axis, 0 behind.
    Cosine,
    /// A measured type C table.
    Ies {
        /// The path as written in the scene file (relative to the scene file's folder).
        written: String,
        /// The file's photometry, read when the scene was read.
        photometry: Arc<IesPhotometry>,
    },
}

/// Two IES distributions are the same when the scene names the same file (as written).
impl PartialEq for Distribution {
    fn eq(&self, other: &Distribution) -> bool {
        match (self, other) {
            (Distribution::Isotropic, Distribution::Isotropic)
            | (Distribution::Cosine, Distribution::Cosine) => true,
            (Distribution::Ies { written: a, .. }, Distribution::Ies { written: b, .. }) => a == b,
            _ => false,
        }
    }
}

/// How much light a luminaire gives, as written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Output {
    /// `INTENSITY I`: candela on the axis.
    Intensity(f64),
    /// `FLUX P`: lumens in all directions.
    Flux(f64),
    /// Neither (an IES light whose file's values stand).
    AsTabulated,
}

/// A point light of the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Luminaire {
    /// The block's `#NAME`.
    pub name: String,
    /// Where it is.
    pub position: DVec3,
    /// The axis as written (a direction, not necessarily of unit length).
    pub aim: DVec3,
    /// INTENSITY, FLUX or neither.
    pub output: Output,
    /// The distribution's shape.
    pub distribution: Distribution,
    /// The tint per band (`COLOUR`, default 1 1 1).
    pub colour: Rgb,
}

/// Problems with a luminaire's values (the scene reader reports them at their lines).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LuminaireError {
    /// The aim is the zero vector or not finite.
    #[error("the aim must be a non-zero direction")]
    ZeroAim,
    /// INTENSITY given for an IES distribution.
    #[error("an IES distribution takes FLUX (to scale the table) or neither, not INTENSITY")]
    IntensityWithIes,
    /// Neither INTENSITY nor FLUX for ISOTROPIC or COSINE.
    #[error("an ISOTROPIC or COSINE light needs INTENSITY (cd) or FLUX (lm)")]
    NoOutput,
    /// The IES table emits nothing, so FLUX cannot scale it.
    #[error("the IES table emits no light, so FLUX cannot scale it")]
    DarkTable,
}

impl Luminaire {
    /// Checks the combination of values (the ranges are the reader's).
    pub fn check(&self) -> Result<(), LuminaireError> {
        if !(self.aim.is_finite() && self.aim.length_squared() > 0.0) {
            return Err(LuminaireError::ZeroAim);
        }
        match (&self.distribution, self.output) {
            (Distribution::Ies { .. }, Output::Intensity(_)) => {
                Err(LuminaireError::IntensityWithIes)
            }
            (Distribution::Ies { photometry, .. }, Output::Flux(_))
                if !(photometry.table_lumens() > 0.0) =>
            {
                Err(LuminaireError::DarkTable)
            }
            (Distribution::Isotropic | Distribution::Cosine, Output::AsTabulated) => {
                Err(LuminaireError::NoOutput)
            }
            _ => Ok(()),
        }
    }

    /// The unit axis (theta = 0).
    pub fn axis(&self) -> DVec3 {
        self.aim.normalize()
    }

    /// The frame (u, v, w): w the axis, u the azimuth's zero, v = w x u... see the module
    /// documentation for the convention (phi = 0 along u, phi = 90 degrees along v).
    pub fn frame(&self) -> (DVec3, DVec3, DVec3) {
        let w = self.axis();
        let down = DEFAULT_AIM;
        let c = down.dot(w);
        let u = if c < -1.0 + 1e-6 {
            // Straight up (or within 1e-3 rad of it, where the rotation's axis is lost in
            // rounding): the half turn about x.
            DVec3::X
        } else {
            // Rodrigues' rotation taking `down` to `w`: R x = x c + (k x x) + k (k . x) / (1 + c)
            // with k = down x w (not normalised).
            let k = down.cross(w);
            DVec3::X * c + k.cross(DVec3::X) + k * (k.dot(DVec3::X) / (1.0 + c))
        };
        // Orthonormal to rounding, and right-handed like (x, y, -z).
        let u = (u - w * w.dot(u)).normalize();
        let v = -w.cross(u);
        (u, v, w)
    }

    /// The candela scale applied to the distribution's shape (its value on the axis for
    /// ISOTROPIC and COSINE; the factor on the table for IES).
    fn scale(&self) -> f64 {
        match (&self.distribution, self.output) {
            (_, Output::Intensity(i)) => i,
            (Distribution::Isotropic, Output::Flux(p)) => p / (4.0 * PI),
            (Distribution::Cosine, Output::Flux(p)) => p / PI,
            (Distribution::Ies { photometry, .. }, Output::Flux(p)) => {
                p / photometry.table_lumens()
            }
            (Distribution::Ies { .. }, Output::AsTabulated) => 1.0,
            (_, Output::AsTabulated) => 0.0,
        }
    }

    /// The luminous intensity (cd, untinted) towards the unit direction `d` (from the
    /// light outwards).
    pub fn candela(&self, d: DVec3) -> f64 {
        let (u, v, w) = self.frame();
        let cos_theta = d.dot(w).clamp(-1.0, 1.0);
        let shape = match &self.distribution {
            Distribution::Isotropic => 1.0,
            Distribution::Cosine => cos_theta.max(0.0),
            Distribution::Ies { photometry, .. } => {
                let theta = cos_theta.acos();
                let phi = d.dot(v).atan2(d.dot(u)).rem_euclid(2.0 * PI);
                photometry.candela(theta, phi)
            }
        };
        self.scale() * shape
    }

    /// The intensity per band towards `d` (candela times the colour).
    pub fn intensity(&self, d: DVec3) -> Rgb {
        self.colour * self.candela(d)
    }

    /// Whether it gives any light: lumens above zero and a tint not black in every band.
    pub fn gives_light(&self) -> bool {
        self.flux() > 0.0 && self.colour.0.iter().any(|&c| c > 0.0)
    }

    /// The lumens it emits in all directions (untinted): 4 pi I, pi I0, or the table's
    /// lumens times the scale.
    pub fn flux(&self) -> f64 {
        match &self.distribution {
            Distribution::Isotropic => 4.0 * PI * self.scale(),
            Distribution::Cosine => PI * self.scale(),
            Distribution::Ies { photometry, .. } => photometry.table_lumens() * self.scale(),
        }
    }

    /// The illuminance per band at `x` on a surface with unit normal `n`, unoccluded:
    /// I(d) cos / r^2 (0 behind the surface).
    pub fn irradiance_unoccluded(&self, x: DVec3, n: DVec3) -> Rgb {
        let to_light = self.position - x;
        let r2 = to_light.length_squared();
        if r2 <= 0.0 {
            return Rgb::BLACK;
        }
        let l = to_light / r2.sqrt();
        let cos = n.dot(l);
        if cos <= 0.0 {
            return Rgb::BLACK;
        }
        self.intensity(-l) * (cos / r2)
    }
}

/// The signed solid angle of triangle (a, b, c) seen from the origin (Van Oosterom and
/// Strackee 1983): positive when the corners run counter-clockwise seen from the origin.
pub fn triangle_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

/// The power per band that `light` sends onto the front of the planar convex polygon
/// `poly` (counter-clockwise from its front), divided by nothing: the integral of I over the
/// solid angle the polygon subtends, with visibility. The polygon is fanned from corner 0
/// and each triangle cut into `k` x `k` sub-triangles; a sub-triangle that subtends more
/// than [`MAX_PIECE_SOLID_ANGLE`] is split in four at its edges' midpoints until it does not
/// (at most [`MAX_WIDE_PIECE_DEPTH`] times), and each piece's exact solid angle is weighted
/// by the mean intensity at its edges' midpoints ([`mean_intensity`]) and by whether the
/// segment from its centroid to the light is clear (`blocked`). For an isotropic light and
/// no occluder this is exact (the solid angles add up), so a closed room receives every
/// lumen to rounding. A piece whose
/// corners' intensities jump (by [`INTENSITY_JUMP`], where [`JUMP_FLUX`] of the lumens is
/// at stake) is split further, to [`MIN_PIECE_SOLID_ANGLE`]. For any other
/// distribution the pieces are small seen from the light, so a surface a few centimetres
/// from it is not short-changed (QA of issue #16: a COSINE light 5 cm below a ceiling put
/// only 82 % of its lumens on the default mesh, the pieces above it seen from the light
/// spanning a steradian and weighted by the intensity at their centroids). 0 when the
/// light is behind the polygon's front.
pub fn power_onto(
    light: &Luminaire,
    poly: &[DVec3],
    k: u32,
    blocked: impl Fn(DVec3, DVec3) -> bool,
) -> Rgb {
    let Some(normal) = crate::geometry::polygon_normal(poly) else {
        return Rgb::BLACK;
    };
    let p = light.position;
    if normal.dot(p - poly[0]) <= 0.0 {
        return Rgb::BLACK;
    }
    let flux = light.flux();
    let mut sum = Rgb::BLACK;
    let mut stack: Vec<([DVec3; 3], u32)> = Vec::new();
    for i in 1..poly.len() - 1 {
        let t = [poly[0], poly[i], poly[i + 1]];
        crate::mesh::for_each_subtriangle(t, k, |s| {
            stack.push((s, 0));
            while let Some((s, depth)) = stack.pop() {
                // Seen from the light, a front-facing triangle runs clockwise: the solid
                // angle comes out negative.
                let omega = -triangle_solid_angle(s[0] - p, s[1] - p, s[2] - p);
                if omega <= 0.0 {
                    continue;
                }
                // Split where the piece is wide, or where the intensity jumps across it (a
                // table that ends at 90 degrees: the piece straddling the horizon took all
                // or nothing from its centroid, and 101.4 % of a light's lumens landed in
                // a closed room; QA pass 15 of issue #16).
                // Only where the light at stake counts: the noisy back of a measured table
                // (0.3, 0, 1.2 cd) or a downlight's dim tail would otherwise split to the
                // smallest pieces for a fraction of a lumen (review).
                let jumps = || intensity_jumps(light, &s, omega, || flux);
                // A wide piece splits until it is not, however close the light (QA pass 16
                // of #16: a COSINE light 0.1 mm under a ceiling put 17 % of its lumens on
                // it, the piece at its foot stopped at MAX_PIECE_DEPTH while it still
                // spanned most of the hemisphere, weighted by the intensity 80 degrees off
                // its aim).
                let wide = omega > MAX_PIECE_SOLID_ANGLE && depth < MAX_WIDE_PIECE_DEPTH;
                if wide || (depth < MAX_PIECE_DEPTH && omega > MIN_PIECE_SOLID_ANGLE && jumps()) {
                    let m = [
                        (s[0] + s[1]) * 0.5,
                        (s[1] + s[2]) * 0.5,
                        (s[2] + s[0]) * 0.5,
                    ];
                    for piece in [
                        [s[0], m[0], m[2]],
                        [m[0], s[1], m[1]],
                        [m[2], m[1], s[2]],
                        [m[0], m[1], m[2]],
                    ] {
                        stack.push((piece, depth + 1));
                    }
                    continue;
                }
                let centroid = (s[0] + s[1] + s[2]) / 3.0;
                if blocked(centroid, p) {
                    continue;
                }
                sum += mean_intensity(light, s.map(|c| (c - p).normalize_or_zero())) * omega;
            }
        });
    }
    sum
}

/// Whether `light`'s intensity towards the corners of `piece` (a triangle it sees across
/// `omega` sr) differs by more than [`INTENSITY_JUMP`] of the largest, where that difference
/// over the piece is more than [`JUMP_FLUX`] of the light's `flux` (lumens, asked for only
/// then: an IES table's is a sum over the table): a cut-off or a steep flank crosses it,
/// and it is worth splitting. Never for an isotropic or a COSINE light, whose intensity is
/// smooth: [`mean_intensity`] takes its variation across a piece (splitting a COSINE
/// light's dim tail made `illuminance` on the README's downlight grid 63 % slower for 0.04 %
/// of its indirect lux).
pub(crate) fn intensity_jumps(
    light: &Luminaire,
    piece: &[DVec3; 3],
    omega: f64,
    flux: impl FnOnce() -> f64,
) -> bool {
    if matches!(
        light.distribution,
        Distribution::Isotropic | Distribution::Cosine
    ) {
        return false;
    }
    let p = light.position;
    let i = piece.map(|c| light.candela((c - p).normalize_or_zero()));
    let (lo, hi) = (i[0].min(i[1]).min(i[2]), i[0].max(i[1]).max(i[2]));
    hi - lo > INTENSITY_JUMP * hi && (hi - lo) * omega > JUMP_FLUX * flux()
}

/// The mean intensity of `light` over the small spherical triangle of directions `d` (unit
/// vectors): the mean at its edges' midpoints, a rule exact for an intensity quadratic in
/// the direction over a flat triangle (Strang and Fix 1973, the three-point midpoint rule),
/// so that a COSINE light's pieces are not weighed high by the curvature of cos (the centroid
/// alone put 100.07 % of a downlight's lumens on a closed room: QA pass 16 of #16). An
/// isotropic light needs one look.
pub(crate) fn mean_intensity(light: &Luminaire, d: [DVec3; 3]) -> Rgb {
    if matches!(light.distribution, Distribution::Isotropic) {
        return light.intensity(d[0]);
    }
    let mid = |a: DVec3, b: DVec3| (a + b).normalize_or_zero();
    (light.intensity(mid(d[0], d[1]))
        + light.intensity(mid(d[1], d[2]))
        + light.intensity(mid(d[2], d[0])))
        * (1.0 / 3.0)
}

/// The largest solid angle (sr) over which [`power_onto`] takes a light's intensity and
/// visibility as constant: 0.01 sr is a cone of about 3.2 degrees half-angle, over which a
/// COSINE light's intensity varies by at most 5.6 % of its axial value (the mean at the
/// piece's edges' midpoints, [`mean_intensity`], is exact for a quadratic: its error is
/// fourth order, far less), and a light's whole sphere holds at most some 1,300
/// such pieces, so the splitting costs at most a few thousand shadow rays a light (more
/// along a cut-off: see [`MIN_PIECE_SOLID_ANGLE`]).
pub const MAX_PIECE_SOLID_ANGLE: f64 = 0.01;

/// The smallest solid angle (sr) to which [`power_onto`] splits a piece whose corners'
/// intensities differ by more than [`INTENSITY_JUMP`] of the largest: a cone of 0.32 degrees
/// half-angle, so that the band of pieces straddling a cut-off (a table ending at 90
/// degrees) is a tenth of the width it was at [`MAX_PIECE_SOLID_ANGLE`].
pub const MIN_PIECE_SOLID_ANGLE: f64 = 1e-4;

/// How much a piece's corners' intensities may differ, as a fraction of the largest, before
/// [`power_onto`] splits it further (to [`MIN_PIECE_SOLID_ANGLE`]): a quarter, far above
/// what a smooth distribution changes across a piece of [`MAX_PIECE_SOLID_ANGLE`] (a
/// COSINE light's 5.6 %), so that jumps and steep flanks are split, and only where the
/// difference times the piece's solid angle is above [`JUMP_FLUX`] of the light's lumens.
pub const INTENSITY_JUMP: f64 = 0.25;

/// The share of a light's lumens below which a piece's intensity jump is not worth
/// splitting for ([`INTENSITY_JUMP`]): 1e-5, so a piece straddling a 159 cd horizon (0.6 lm
/// of 1,000 at 0.004 sr) splits, and the back of a measured table (a candela or so of
/// noise) does not.
pub const JUMP_FLUX: f64 = 1e-5;

/// How many times [`power_onto`] may halve a piece's edges for an intensity jump (4^7 =
/// 16,384 pieces from one sub-triangle at most).
pub const MAX_PIECE_DEPTH: u32 = 7;

/// How many times [`power_onto`] may halve the edges of a piece wider than
/// [`MAX_PIECE_SOLID_ANGLE`], so that a surface through the light itself cannot split
/// without end. Only the pieces at the foot of a light stay wide as they shrink (a piece of
/// size s at a distance D >= s from the foot of a light h above its plane subtends about
/// s^2 h / D^3 sr), a handful a level, so a light h above a surface splits about
/// log2(10 s / h) levels there (until the foot's piece is a tenth of h across): 40 levels
/// reach a trillionth of a sub-triangle's size, a light 1e-11 of it from the surface. The
/// wide pieces of one level subtend 2 pi sr at most, so no more than about 630 split at any
/// level; a light near a surface makes some thousands of pieces on the element at its foot.
pub const MAX_WIDE_PIECE_DEPTH: u32 = 40;

/// The sub-triangles per fan triangle edge used for elements' first bounce
/// ([`power_onto`]): 4 x 4 = 16 shadow rays per triangle at least (more where a light
/// sees a piece wider than [`MAX_PIECE_SOLID_ANGLE`]).
pub const ELEMENT_SUBDIVISION: u32 = 4;

/// Each element's average illuminance from the point lights of `scene` (per band,
/// lm/m^2), with the scene's surfaces as occluders: [`power_onto`] over the element divided
/// by its area. Times rho, it is the first bounce that the solvers add to the emission.
pub fn element_irradiance(
    mesh: &crate::mesh::Mesh,
    lights: &[Luminaire],
    occluders: &crate::visibility::PolygonBvh,
) -> Vec<Rgb> {
    use rayon::prelude::*;
    (0..mesh.len())
        .into_par_iter()
        .map(|e| {
            let el = &mesh.elements[e];
            if lights.is_empty() || el.area <= 0.0 {
                return Rgb::BLACK;
            }
            let poly: Vec<DVec3> = mesh.corner_positions(e).collect();
            let mut sum = Rgb::BLACK;
            for l in lights {
                sum += power_onto(l, &poly, ELEMENT_SUBDIVISION, |x, y| {
                    occluders.segment_blocked(x, y)
                });
            }
            sum * (1.0 / el.area)
        })
        .collect()
}

/// The lumens of `light` that land on the fronts of `mesh`'s elements, with occlusion by
/// the scene's surfaces (`occluders`): [`power_onto`] over every element, as the first
/// bounce takes it, in lumens of the untinted light (the tint's luminance divided out).
/// The rest of [`Luminaire::flux`] lands on the backs of faces (a light inside furniture
/// or behind a wall) or leaves the scene (a light outside the room, an open side), and
/// none of it is in the solution; `check` reports the share.
pub fn landing_flux(
    mesh: &crate::mesh::Mesh,
    light: &Luminaire,
    occluders: &crate::visibility::PolygonBvh,
) -> f64 {
    use rayon::prelude::*;
    let tint = light.colour.luminance();
    if tint <= 0.0 {
        return 0.0;
    }
    // Summed in element order, whatever the threads (the same figure every run).
    let per_element: Vec<f64> = (0..mesh.len())
        .into_par_iter()
        .map(|e| {
            let poly: Vec<DVec3> = mesh.corner_positions(e).collect();
            power_onto(light, &poly, ELEMENT_SUBDIVISION, |x, y| {
                occluders.segment_blocked(x, y)
            })
            .luminance()
        })
        .collect();
    per_element.iter().sum::<f64>() / tint
}

#[cfg(test)]
#[path = "luminaire_tests.rs"]
mod tests;
