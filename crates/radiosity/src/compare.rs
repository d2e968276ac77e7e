//! Two solutions of one scene on different meshes, compared element by element.
//!
//! Hierarchical radiosity returns its own elements (the leaves of its quadtrees), so its
//! solution cannot be compared with a dense solve index by index. [`compare`] projects the
//! other solution onto each reference element: the area-weighted mean of the other
//! solution at the element's 4 x 4 integration points (at each, the element of the other
//! mesh that contains it, found by a ray along the surface normal through a BVH of the
//! other mesh). Both sides are then area averages over the same element, so an element that
//! straddles a shadow edge is compared with the same straddling average, not with whichever
//! side its centroid falls on. Differences are reported relative to the reference's
//! *reflected* radiosity B - E: the part a solver computes (the emitters' E would otherwise
//! dominate the norms and hide the error).
#![allow(clippy::needless_range_loop)] // bands read best as indices

use thiserror::Error;

use crate::light::Rgb;
use crate::mesh::Mesh;
use crate::solve::Radiosity;
use crate::visibility::PolygonBvh;

/// Differences of a solution from a reference, relative to the reference's reflected
/// radiosity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// Reference elements compared.
    pub elements: usize,
    /// Area-weighted RMS over the reference elements and the three bands of the difference
    /// B_other - B_reference, divided by the area-weighted RMS of B_reference - E.
    pub rms: f64,
    /// Largest |B_other - B_reference| over elements and bands, divided by the same RMS.
    pub max: f64,
    /// Area-weighted mean of B_other - B_reference over elements and bands, divided by the
    /// same RMS (negative: the other solution is darker).
    pub bias: f64,
}

/// Why two solutions could not be compared.
#[derive(Debug, Error, PartialEq)]
pub enum CompareError {
    /// A reference element's centroid lies on no element of the other mesh.
    #[error("reference element {element} (surface {surface}) lies on no element of the other mesh: the meshes are not of one scene")]
    NotCovered {
        /// The reference element.
        element: usize,
        /// Its input surface.
        surface: u32,
    },
    /// The reference has no reflected radiosity to compare with.
    #[error("the reference solution reflects no light: nothing to compare")]
    Dark,
}

/// Compares `other` (on `other_mesh`) with `reference` (on `reference_mesh`) over the
/// reference's elements (see [`project`]); `emission` is E per reference element.
pub fn compare(
    reference_mesh: &Mesh,
    reference: &Radiosity,
    emission: &[Rgb],
    other_mesh: &Mesh,
    other: &Radiosity,
) -> Result<Comparison, CompareError> {
    let projected = project(reference_mesh, other_mesh, other)?;
    let (mut num, mut den, mut sum, mut area, mut max) = (0.0, 0.0, 0.0, 0.0, 0.0f64);
    for (i, el) in reference_mesh.elements.iter().enumerate() {
        for k in 0..3 {
            let (r, o) = (reference.0[i][k], projected.0[i][k]);
            num += el.area * (o - r).powi(2);
            den += el.area * (r - emission[i][k]).powi(2);
            sum += el.area * (o - r);
            max = max.max((o - r).abs());
        }
        area += el.area;
    }
    if den <= 0.0 {
        return Err(CompareError::Dark);
    }
    let scale = (den / (3.0 * area)).sqrt();
    Ok(Comparison {
        elements: reference_mesh.len(),
        rms: (num / den).sqrt(),
        max: max / scale,
        bias: sum / (3.0 * area) / scale,
    })
}

/// `other` (on `other_mesh`) averaged over each element of `reference_mesh`: the
/// area-weighted mean at the element's 4 x 4 integration points of the other mesh's
/// element under each point (found by a ray along the surface normal through a BVH of the
/// other mesh).
pub fn project(
    reference_mesh: &Mesh,
    other_mesh: &Mesh,
    other: &Radiosity,
) -> Result<Radiosity, CompareError> {
    let bvh = PolygonBvh::over_elements(other_mesh);
    let delta = 1e-6 * bvh.scale();
    let mut out = Vec::with_capacity(reference_mesh.len());
    let mut points = Vec::new();
    for (i, el) in reference_mesh.elements.iter().enumerate() {
        points.clear();
        reference_mesh.integration_points(i, 4, &mut points);
        let mut projected = [0.0; 3];
        for &(x, w) in &points {
            // The other mesh's element under x (a ray down the normal, from just in front);
            // a point on an edge of the other mesh is nudged towards the centroid.
            let found = [0.0, 1e-6, 1e-4].iter().find_map(|&nudge| {
                let c = x + nudge * (el.centroid - x);
                bvh.closest_hit(c + delta * el.normal, -el.normal, 0.0, 2.0 * delta)
                    .filter(|h| other_mesh.elements[h.id as usize].surface == el.surface)
            });
            let Some(hit) = found else {
                return Err(CompareError::NotCovered {
                    element: i,
                    surface: el.surface,
                });
            };
            for k in 0..3 {
                projected[k] += w * other.0[hit.id as usize][k];
            }
        }
        out.push(Rgb(projected.map(|p| p / el.area)));
    }
    Ok(Radiosity(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::scene::cornell_box;

    fn uniform(mesh: &Mesh, f: impl Fn(usize) -> [f64; 3]) -> Radiosity {
        Radiosity((0..mesh.len()).map(|e| Rgb(f(e))).collect())
    }

    #[test]
    fn a_solution_on_a_finer_mesh_of_the_same_field() {
        // B = 1 + surface index on every element of both meshes: identical fields, so
        // zero difference whatever the meshes; B = 2 (1 + index) doubles the reflected part
        // (E = 0): relative RMS and mean exactly 1.
        let scene = cornell_box().scene;
        let coarse = mesh_scene(&scene, 20_000.0).unwrap();
        let fine = mesh_scene(&scene, 2_000.0).unwrap();
        assert!(fine.len() > 4 * coarse.len());
        let field = |m: &Mesh, scale: f64| {
            uniform(m, |e| [scale * (1.0 + m.elements[e].surface as f64); 3])
        };
        let e = vec![Rgb::BLACK; coarse.len()];
        let same = compare(&coarse, &field(&coarse, 1.0), &e, &fine, &field(&fine, 1.0)).unwrap();
        // Zero up to the rounding of the 16-point weighted means.
        assert!(same.rms < 1e-12 && same.max < 1e-12, "{same:?}");
        let double = compare(&coarse, &field(&coarse, 1.0), &e, &fine, &field(&fine, 2.0)).unwrap();
        assert!((double.rms - 1.0).abs() < 1e-12, "{double:?}");
        assert!(double.bias > 0.0);
    }

    #[test]
    fn meshes_of_other_scenes_are_refused() {
        let a = cornell_box().scene;
        let mut b = cornell_box().scene;
        b.surfaces.truncate(5);
        let (ma, mb) = (
            mesh_scene(&a, 20_000.0).unwrap(),
            mesh_scene(&b, 20_000.0).unwrap(),
        );
        let e = vec![Rgb::BLACK; ma.len()];
        let one = |m: &Mesh| uniform(m, |_| [1.0; 3]);
        assert!(matches!(
            compare(&ma, &one(&ma), &e, &mb, &one(&mb)),
            Err(CompareError::NotCovered { .. })
        ));
    }
}
