//! Two solutions of one scene on different meshes, compared element by element.
//!
//! Hierarchical radiosity returns its own elements (the leaves of its quadtrees), so its
//! solution cannot be compared with a dense solve index by index. [`compare`] projects the
//! other solution onto each reference element: the area-weighted mean of the other
//! solution at the element's 4 x 4 integration points (at each, the element of the other
//! mesh that contains it, found in a BVH of the other mesh's elements of the same input
//! surface, so that a coplanar surface lying on it cannot hide it). Both sides are then area averages over the same element, so an element that
//! straddles a shadow edge is compared with the same straddling average, not with whichever
//! side its centroid falls on. Differences are reported relative to the reference's
//! *reflected* radiosity B - E: the part a solver computes (the emitters' E would otherwise
//! dominate the norms and hide the error).
#![allow(clippy::needless_range_loop)] // bands read best as indices

use glam::DVec3;
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
#[derive(Clone, Debug, Error, PartialEq)]
pub enum CompareError {
    /// More of the reference than [`MAX_UNCOVERED`] lies on no element of the other mesh;
    /// this is the first such element.
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
    let Projection {
        radiosity: projected,
        covered,
    } = project(reference_mesh, other_mesh, other)?;
    let (mut num, mut den, mut sum, mut area, mut max) = (0.0, 0.0, 0.0, 0.0, 0.0f64);
    for (i, &a) in covered.iter().enumerate() {
        if a <= 0.0 {
            continue;
        }
        for k in 0..3 {
            let (r, o) = (reference.0[i][k], projected.0[i][k]);
            num += a * (o - r).powi(2);
            den += a * (r - emission[i][k]).powi(2);
            sum += a * (o - r);
            max = max.max((o - r).abs());
        }
        area += a;
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

/// Another solution averaged over a reference mesh's elements.
#[derive(Clone, Debug, PartialEq)]
pub struct Projection {
    /// Per reference element, the other solution's mean over the part of it that the other
    /// mesh covers (0 where it covers none of it).
    pub radiosity: Radiosity,
    /// Per reference element, the area of it that the other mesh covers (scene units
    /// squared): all of it, except where contact refinement
    /// ([`crate::mesh::refine_contacts`]) dropped buried pieces from one mesh that the
    /// other, refined differently, kept.
    pub covered: Vec<f64>,
}

/// The share of a reference's area that may lie on no element of the other mesh before
/// [`project`] refuses the pair as meshes of different scenes: meshes of one scene differ
/// only in the buried pieces along contacts, a few per cent of the area.
const MAX_UNCOVERED: f64 = 0.25;

/// `other` (on `other_mesh`) averaged over each element of `reference_mesh`: the
/// area-weighted mean at the element's 4 x 4 integration points of the other mesh's
/// element under each point. Each point is looked up among the other mesh's elements of
/// its own input surface only (a BVH per surface, [`PolygonBvh::polygon_at`]), so a
/// surface that lies on it or touches it (a rug on a floor, the bottom of a box standing
/// on it, coplanar with it) cannot hide the element it lies on. A reference element whose
/// 16 points all lie on one element of the other mesh takes that element's value exactly,
/// so a solution compared with itself differs by exactly zero. Points on no element of the
/// other mesh (pieces it dropped as buried) are left out of the mean; more than
/// [`MAX_UNCOVERED`] of the reference's area so left out is refused.
pub fn project(
    reference_mesh: &Mesh,
    other_mesh: &Mesh,
    other: &Radiosity,
) -> Result<Projection, CompareError> {
    let surfaces = SurfaceIndex::new(other_mesh);
    // A point is on an element when within this distance of its plane: far above
    // rounding, far below any element's size.
    let delta = 1e-6 * surfaces.scale;
    let mut out = Vec::with_capacity(reference_mesh.len());
    let mut covered = Vec::with_capacity(reference_mesh.len());
    let mut first_uncovered = None;
    let mut uncovered_area = 0.0;
    let mut points = Vec::new();
    for (i, el) in reference_mesh.elements.iter().enumerate() {
        let not_covered = CompareError::NotCovered {
            element: i,
            surface: el.surface,
        };
        let Some(bvh) = surfaces.of(el.surface) else {
            return Err(not_covered);
        };
        points.clear();
        reference_mesh.integration_points(i, 4, &mut points);
        let mut projected = [0.0; 3];
        let mut weight = 0.0;
        let mut single = Some(None);
        for &(x, w) in &points {
            // The other mesh's element of this surface at x; a point on an outer edge of the
            // surface, which rounding can put just outside it, is nudged towards the
            // element's centroid.
            let found = [0.0, 1e-6, 1e-4]
                .iter()
                .find_map(|&nudge| bvh.polygon_at(x + nudge * (el.centroid - x), delta));
            let Some(hit) = found else {
                first_uncovered.get_or_insert(not_covered.clone());
                uncovered_area += w;
                single = None;
                continue;
            };
            weight += w;
            single = match single {
                Some(None) => Some(Some(hit)),
                Some(Some(id)) if id == hit => single,
                _ => None,
            };
            for k in 0..3 {
                projected[k] += w * other.0[hit as usize][k];
            }
        }
        out.push(match single {
            Some(Some(id)) => other.0[id as usize],
            _ if weight > 0.0 => Rgb(projected.map(|p| p / weight)),
            _ => Rgb::BLACK,
        });
        covered.push(if single.is_some() { el.area } else { weight });
    }
    match first_uncovered {
        Some(e) if uncovered_area > MAX_UNCOVERED * reference_mesh.total_area() => Err(e),
        _ => Ok(Projection {
            radiosity: Radiosity(out),
            covered,
        }),
    }
}

/// A mesh's elements in one BVH per input surface, each element tagged with its index in
/// the mesh.
struct SurfaceIndex {
    /// Per surface, its elements' BVH (`None` for a surface without elements).
    bvhs: Vec<Option<PolygonBvh>>,
    /// The length of the bounding-box diagonal of the whole mesh.
    scale: f64,
}

impl SurfaceIndex {
    fn new(mesh: &Mesh) -> SurfaceIndex {
        let bvhs = mesh
            .surface_elements
            .iter()
            .map(|range| {
                if range.is_empty() {
                    return None;
                }
                let polygons: Vec<Vec<DVec3>> = range
                    .clone()
                    .map(|e| mesh.corner_positions(e as usize).collect())
                    .collect();
                let ids: Vec<u32> = range.clone().collect();
                Some(PolygonBvh::new(&polygons, &ids))
            })
            .collect();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for v in &mesh.vertices {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let scale = if mesh.vertices.is_empty() {
            1.0
        } else {
            (hi - lo).length().max(f64::MIN_POSITIVE)
        };
        SurfaceIndex { bvhs, scale }
    }

    /// The BVH of surface `surface`'s elements, if it has any.
    fn of(&self, surface: u32) -> Option<&PolygonBvh> {
        self.bvhs.get(surface as usize).and_then(Option::as_ref)
    }
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
