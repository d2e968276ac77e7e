//! Monte Carlo form factors by stratified ray casting (as in Cohen and Wallace, *Radiosity
//! and Realistic Image Synthesis*, 1993, section 4.9).
//!
//! From element i, `samples` rays leave points spread uniformly over its area in
//! cosine-distributed directions; each ray that first hits the front of element j adds
//! 1/samples to F_ij. The estimate is unbiased, occlusion comes free with the closest hit,
//! and rows sum to at most 1 by construction. Points and directions are both stratified: a
//! sqrt(N) x sqrt(N) grid of jittered strata on the element, and an independent shuffled
//! grid of strata on the hemisphere. Each row draws from its own generator, seeded from the
//! user's seed and the row index, so results do not depend on thread scheduling.

use glam::{DVec2, DVec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::mesh::Mesh;
use crate::visibility::PolygonBvh;

use super::RayCounter;

/// Row i of the form-factor matrix by `samples` stratified rays (rounded up to a square).
pub(super) fn row(
    mesh: &Mesh,
    elements: &PolygonBvh,
    i: usize,
    samples: u32,
    seed: u64,
    rays: &RayCounter,
) -> Vec<f64> {
    let mut row = vec![0.0; mesh.len()];
    let e = &mesh.elements[i];
    let corners: Vec<DVec3> = mesh.corner_positions(i).collect();
    // Triangles of the element with their cumulative area fractions, for uniform sampling.
    let triangles: Vec<[DVec3; 3]> = (1..corners.len() - 1)
        .map(|k| [corners[0], corners[k], corners[k + 1]])
        .collect();
    let areas: Vec<f64> = triangles
        .iter()
        .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
        .collect();
    let total: f64 = areas.iter().sum();
    let (u, v) = e.normal.any_orthonormal_pair();
    let m = (samples.max(1) as f64).sqrt().ceil() as usize;
    let n = m * m;
    // Row-specific stream: SplitMix-style mixing of the row index into the seed.
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let mut direction_strata: Vec<usize> = (0..n).collect();
    for k in (1..n).rev() {
        direction_strata.swap(k, rng.random_range(0..=k));
    }
    let scale = mesh_scale(mesh);
    let weight = 1.0 / n as f64;
    rays.add(n as u64);
    for (s, &d) in direction_strata.iter().enumerate() {
        let jitter = |rng: &mut Pcg64Mcg, stratum: usize| {
            DVec2::new(
                ((stratum % m) as f64 + rng.random::<f64>()) / m as f64,
                ((stratum / m) as f64 + rng.random::<f64>()) / m as f64,
            )
        };
        let a = jitter(&mut rng, s);
        let b = jitter(&mut rng, d);
        let origin = point_on(&triangles, &areas, total, a);
        // Cosine-distributed direction (Malley's method: uniform disc, lifted).
        let r = b.x.sqrt();
        let phi = std::f64::consts::TAU * b.y;
        let dir =
            (r * phi.cos()) * u + (r * phi.sin()) * v + (1.0 - b.x).max(0.0).sqrt() * e.normal;
        if let Some(hit) = elements.closest_hit(origin, dir, 1e-7 * scale, f64::INFINITY) {
            let j = hit.id as usize;
            if j != i && mesh.elements[j].normal.dot(dir) < 0.0 {
                row[j] += weight;
            }
        }
    }
    row
}

/// A point on the element: `a.x` picks the triangle by area (and is rescaled within it), then
/// (a.x, a.y) map uniformly onto that triangle.
fn point_on(triangles: &[[DVec3; 3]], areas: &[f64], total: f64, a: DVec2) -> DVec3 {
    let mut x = a.x * total;
    let mut k = 0;
    while k + 1 < triangles.len() && x > areas[k] {
        x -= areas[k];
        k += 1;
    }
    let s = (x / areas[k]).clamp(0.0, 1.0);
    let t = a.y;
    let r = s.sqrt();
    let [p0, p1, p2] = triangles[k];
    (1.0 - r) * p0 + r * (1.0 - t) * p1 + r * t * p2
}

fn mesh_scale(mesh: &Mesh) -> f64 {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for v in &mesh.vertices {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    (hi - lo).length().max(f64::MIN_POSITIVE)
}
