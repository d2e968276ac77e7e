//! Validation cases with answers computed here from first principles.
//!
//! * [`cie171`]: the analytical cases of CIE 171:2006 that apply to a diffuse program, as
//!   scene files in the contract syntax, measurement points, and reference illuminances.
//! * [`exact`]: the closed forms and quadratures the references are computed with
//!   (point-to-polygon form factors by Lambert's contour integral, convex polygon clipping,
//!   Gauss-Legendre rules), each tested against an independent closed form.

pub mod cie171;
pub mod exact;
