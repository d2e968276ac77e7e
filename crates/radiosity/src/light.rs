//! Light quantities: one RGB type for radiosity, emission and reflectance, and the checked
//! reflectance and emission of every element.
//!
//! Radiosity B and emission E are exitances per red, green and blue band in the scene's own
//! units (for example W/m^2); reflectance rho is a fraction in [0, 1) per band (paper 1.2:
//! "this matrix is solved three times, each time using separate reflectivity and emissivity
//! information for each of the three color bands"). Every solver reads and writes [`Rgb`]
//! per element, in one layout: a slice with one `Rgb` per element.
//!
//! Photometric reports weigh the bands by [`Rgb::luminance`] (Rec. 709 / sRGB primaries),
//! so a grey scene reports the value of each band.

use std::ops::{Add, AddAssign, Index, IndexMut, Mul, Sub};

/// A triple in linear red, green and blue bands: an exitance per band (radiosity,
/// emission) or a fraction per band (reflectance).
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(transparent)]
pub struct Rgb(pub [f64; 3]);

impl Rgb {
    /// A slice of triples seen as plain arrays (the same memory).
    pub fn as_arrays(v: &[Rgb]) -> &[[f64; 3]] {
        bytemuck::cast_slice(v)
    }

    /// A slice of plain arrays seen as triples (the same memory).
    pub fn from_arrays(v: &[[f64; 3]]) -> &[Rgb] {
        bytemuck::cast_slice(v)
    }

    /// All three bands zero.
    pub const BLACK: Rgb = Rgb([0.0; 3]);

    /// The same value in every band.
    pub const fn splat(v: f64) -> Rgb {
        Rgb([v; 3])
    }

    /// The value of band `b` (0 red, 1 green, 2 blue).
    pub fn band(self, b: usize) -> f64 {
        self.0[b]
    }

    /// The largest of the three bands.
    pub fn max_band(self) -> f64 {
        self.0[0].max(self.0[1]).max(self.0[2])
    }

    /// Each band through `f`.
    pub fn map(self, f: impl Fn(f64) -> f64) -> Rgb {
        Rgb(self.0.map(f))
    }

    /// Band by band, `f(self[b], other[b])`.
    pub fn zip_map(self, other: Rgb, f: impl Fn(f64, f64) -> f64) -> Rgb {
        Rgb(std::array::from_fn(|b| f(self.0[b], other.0[b])))
    }

    /// True when every band is finite.
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|x| x.is_finite())
    }

    /// The luminance-weighted value Y = 0.2126 R + 0.7152 G + 0.0722 B (ITU-R BT.709
    /// primaries; the weights sum to 1, so a grey triple gives its value).
    pub fn luminance(self) -> f64 {
        0.2126 * self.0[0] + 0.7152 * self.0[1] + 0.0722 * self.0[2]
    }
}

impl From<[f64; 3]> for Rgb {
    fn from(v: [f64; 3]) -> Rgb {
        Rgb(v)
    }
}

impl From<Rgb> for [f64; 3] {
    fn from(v: Rgb) -> [f64; 3] {
        v.0
    }
}

impl Index<usize> for Rgb {
    type Output = f64;
    fn index(&self, b: usize) -> &f64 {
        &self.0[b]
    }
}

impl IndexMut<usize> for Rgb {
    fn index_mut(&mut self, b: usize) -> &mut f64 {
        &mut self.0[b]
    }
}

impl Add for Rgb {
    type Output = Rgb;
    fn add(self, o: Rgb) -> Rgb {
        self.zip_map(o, |a, b| a + b)
    }
}

impl AddAssign for Rgb {
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}

impl Sub for Rgb {
    type Output = Rgb;
    fn sub(self, o: Rgb) -> Rgb {
        self.zip_map(o, |a, b| a - b)
    }
}

/// Band by band (reflectance times radiosity).
impl Mul for Rgb {
    type Output = Rgb;
    fn mul(self, o: Rgb) -> Rgb {
        self.zip_map(o, |a, b| a * b)
    }
}

impl Mul<f64> for Rgb {
    type Output = Rgb;
    fn mul(self, s: f64) -> Rgb {
        self.map(|a| a * s)
    }
}

/// A reflectance outside [0, 1) or an emission that is not a finite non-negative number.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("element {element}: {what} {value} in band {band} is {why}")]
pub struct BadLight {
    /// The element (or surface, for [`check_surface`]).
    pub element: usize,
    /// "reflectance" or "emission".
    pub what: &'static str,
    /// The band (0 red, 1 green, 2 blue).
    pub band: usize,
    /// The offending value.
    pub value: f64,
    /// What is wrong with it.
    pub why: &'static str,
}

/// Checks one element's (or surface's) reflectance, in [0, 1), and emission, finite and
/// non-negative.
pub fn check_surface(index: usize, reflectance: Rgb, emission: Rgb) -> Result<(), BadLight> {
    for band in 0..3 {
        let bad = |what, value, why| BadLight {
            element: index,
            what,
            band,
            value,
            why,
        };
        if !(reflectance[band] >= 0.0 && reflectance[band] < 1.0) {
            return Err(bad("reflectance", reflectance[band], "outside [0, 1)"));
        }
        if !(emission[band].is_finite() && emission[band] >= 0.0) {
            return Err(bad(
                "emission",
                emission[band],
                "not a finite non-negative number",
            ));
        }
    }
    Ok(())
}

/// The reflectance and emission of every element, checked once when built: every solver
/// takes this, so none checks again.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementLight {
    reflectance: Vec<Rgb>,
    emission: Vec<Rgb>,
}

/// Two per-element vectors of different lengths.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LightError {
    /// A value is out of range.
    #[error(transparent)]
    Bad(#[from] BadLight),
    /// The vectors differ in length.
    #[error("{reflectance} reflectances but {emission} emissions")]
    Lengths {
        /// Reflectances given.
        reflectance: usize,
        /// Emissions given.
        emission: usize,
    },
}

impl ElementLight {
    /// Checks rho in [0, 1) and finite E >= 0 for every element.
    pub fn new(reflectance: Vec<Rgb>, emission: Vec<Rgb>) -> Result<ElementLight, LightError> {
        if reflectance.len() != emission.len() {
            return Err(LightError::Lengths {
                reflectance: reflectance.len(),
                emission: emission.len(),
            });
        }
        for (i, (&rho, &e)) in reflectance.iter().zip(&emission).enumerate() {
            check_surface(i, rho, e)?;
        }
        Ok(ElementLight {
            reflectance,
            emission,
        })
    }

    /// [`ElementLight::new`] from arrays, for tests and callers that hold plain triples.
    pub fn from_arrays(
        reflectance: &[[f64; 3]],
        emission: &[[f64; 3]],
    ) -> Result<ElementLight, LightError> {
        ElementLight::new(
            reflectance.iter().map(|&r| Rgb(r)).collect(),
            emission.iter().map(|&e| Rgb(e)).collect(),
        )
    }

    /// Each element gets the reflectance and emission of the scene surface it belongs to.
    ///
    /// With point luminaires in the scene, their direct light is the first bounce: each
    /// element's average illuminance from them, with occlusion by the scene's surfaces
    /// ([`crate::luminaire::element_irradiance`]), times its reflectance, is added to its
    /// emission. Every solver then carries it on unchanged; the element's own emission is
    /// still its surface's ([`crate::scene::Surface::emission`]), which is what reports of
    /// direct and indirect light separate.
    pub fn of_mesh(
        mesh: &crate::mesh::Mesh,
        scene: &crate::scene::Scene,
    ) -> Result<ElementLight, LightError> {
        let (reflectance, mut emission): (Vec<Rgb>, Vec<Rgb>) = mesh
            .elements
            .iter()
            .map(|e| {
                let s = &scene.surfaces[e.surface as usize];
                (s.reflectance, s.emission)
            })
            .unzip();
        if !scene.lights.is_empty() {
            let occluders = crate::visibility::PolygonBvh::over_surfaces(scene);
            let direct = crate::luminaire::element_irradiance(mesh, &scene.lights, &occluders);
            for ((e, rho), d) in emission.iter_mut().zip(&reflectance).zip(direct) {
                *e += *rho * d;
            }
        }
        ElementLight::new(reflectance, emission)
    }

    /// The number of elements.
    pub fn len(&self) -> usize {
        self.emission.len()
    }

    /// True when there are no elements.
    pub fn is_empty(&self) -> bool {
        self.emission.is_empty()
    }

    /// rho per element.
    pub fn reflectance(&self) -> &[Rgb] {
        &self.reflectance
    }

    /// E per element.
    pub fn emission(&self) -> &[Rgb] {
        &self.emission
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_band_by_band() {
        let a = Rgb([1.0, 2.0, 3.0]);
        let b = Rgb([0.5, 0.25, 2.0]);
        assert_eq!(a + b, Rgb([1.5, 2.25, 5.0]));
        assert_eq!(a - b, Rgb([0.5, 1.75, 1.0]));
        assert_eq!(a * b, Rgb([0.5, 0.5, 6.0]));
        assert_eq!(a * 2.0, Rgb([2.0, 4.0, 6.0]));
        assert_eq!(a[2], 3.0);
        // BT.709 weights sum to one: grey keeps its value.
        assert!((Rgb::splat(0.7).luminance() - 0.7).abs() < 1e-15);
    }

    #[test]
    fn bad_values_are_refused_once() {
        let ok = ElementLight::from_arrays(&[[0.5; 3]; 2], &[[1.0; 3], [0.0; 3]]).unwrap();
        assert_eq!(ok.len(), 2);
        let err =
            ElementLight::from_arrays(&[[0.5; 3], [0.5, 1.0, 0.5]], &[[0.0; 3]; 2]).unwrap_err();
        assert_eq!(
            err,
            LightError::Bad(BadLight {
                element: 1,
                what: "reflectance",
                band: 1,
                value: 1.0,
                why: "outside [0, 1)"
            })
        );
        let err = ElementLight::from_arrays(&[[0.5; 3]], &[[f64::NAN, 0.0, 0.0]]).unwrap_err();
        assert!(err.to_string().contains("emission NaN in band 0"), "{err}");
        assert!(matches!(
            ElementLight::from_arrays(&[[0.5; 3]], &[]),
            Err(LightError::Lengths { .. })
        ));
    }
}
