//! The double area integral (paper figure 4) by the midpoint rule:
//!
//! A_i F_ij = sum over points p of i, q of j of
//!            cos(theta_p) cos(theta_q) / (pi r^2) V(p, q) w_p w_q
//!
//! with k x k points per element (paper 2.8, `INTEGRAL_STEPS`) and V(p, q) in {0, 1} the
//! visibility of q from p by a ray cast (paper 2.3, through a BVH instead of the paper's
//! test against every patch).

use std::f64::consts::PI;

use glam::DVec3;

use super::{ElementSamples, FormFactorContext, RayCounter};

/// A_i F_ij by the midpoint rule over the precomputed samples of elements i and j, with
/// occlusion. Emission and reflection are one-sided, so a point pair contributes only when
/// each point is in front of the other's element.
pub(super) fn coupling(
    ctx: &FormFactorContext,
    samples: &ElementSamples,
    i: usize,
    j: usize,
    rays: &RayCounter,
) -> f64 {
    let ei = &ctx.mesh.elements[i];
    let ej = &ctx.mesh.elements[j];
    // Coplanar elements of one surface, or elements that face away from each other
    // entirely, exchange nothing: skip their rays.
    if ei.surface == ej.surface {
        return 0.0;
    }
    let (ni, nj) = (ei.normal, ej.normal);
    let mut sum = 0.0;
    let mut cast = 0;
    for &(p, wp) in samples.of(i) {
        for &(q, wq) in samples.of(j) {
            let d = q - p;
            let r2 = d.length_squared();
            let cos_p = ni.dot(d);
            let cos_q = -nj.dot(d);
            if cos_p <= 0.0 || cos_q <= 0.0 || r2 == 0.0 {
                continue;
            }
            cast += 1;
            if ctx.occluders.segment_blocked(p, q) {
                continue;
            }
            // cos_p and cos_q carry a factor |d| each: divide by r^4 in all.
            sum += cos_p * cos_q / (PI * r2 * r2) * wp * wq;
        }
    }
    rays.add(cast);
    sum
}

/// The unoccluded area-integral form factor F_12 from polygon 1 to polygon 2 (each planar
/// and convex, counter-clockwise from the front), with `k` x `k` points per polygon. For
/// tests and accuracy tables: it meshes nothing and casts no rays.
pub fn area_integral_pair(poly1: &[DVec3], poly2: &[DVec3], k: u32) -> f64 {
    use crate::mesh::mesh_scene;
    use crate::scene::{MeshSettings, Rgb, Scene, Surface};
    let surface = |v: &[DVec3]| Surface {
        name: String::new(),
        emission: Rgb::BLACK,
        reflectance: Rgb::BLACK,
        vertices: v.to_vec(),
    };
    let scene = Scene {
        settings: MeshSettings {
            max_patch_area: f64::MAX,
            integral_steps: k,
        },
        surfaces: vec![surface(poly1), surface(poly2)],
        camera: None,
    };
    let mesh = mesh_scene(&scene, f64::MAX).expect("two polygons always mesh");
    let empty = crate::visibility::PolygonBvh::new::<Vec<DVec3>>(&[], &[]);
    let ctx = FormFactorContext {
        mesh: &mesh,
        occluders: &empty,
    };
    let samples = ElementSamples::new(&mesh, k);
    coupling(&ctx, &samples, 0, 1, &RayCounter::default()) / mesh.elements[0].area
}
