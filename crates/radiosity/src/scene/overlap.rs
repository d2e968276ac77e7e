//! Surfaces that lie on others: a rug on a floor, a picture on a wall, a door drawn on a
//! wall, either exactly in its plane or lifted by a hair.
//!
//! Such a pair faces the same way and overlaps. The covered part of the lower surface gets no
//! light and gives none, and a depth buffer cannot tell the two apart there (they flicker
//! through each other: z-fighting). Contact refinement's probe rays do not see a cover that
//! lies in the plane itself (they start above it), nor reliably one a hair above it (the BVH
//! skips boxes a ray leaves within 1e-4 of its origin), so [`lying_on`] finds these pairs by
//! geometry: [`crate::mesh::refine_contacts`] drops the covered pieces of the lower surface,
//! the viewer draws the upper surface slightly towards the eye, and `radiosity check` lists
//! them.
//!
//! Which one is on top: the one in front of the other's plane; in one plane, the smaller
//! (the rug, not the floor), and of two equal ones the later in the file.

use glam::{DVec2, DVec3};

use super::Scene;
use crate::geometry;
use crate::visibility::PolygonBvh;

/// Gaps up to this fraction of the upper surface's size (the square root of its area) count
/// as lying on: 1 %, 17 mm for a 2 x 1.5 m rug (the room's lies 5 mm above its floor); a
/// 1 x 0.5 m light panel hung 5 cm below a ceiling is seven times further. Relative to the
/// surface itself, so a large scene does not make its small things lie on each other.
pub const LYING_ON_GAP: f64 = 1e-2;

/// Gaps up to this fraction of the scene's size count as the same plane: 1e-7, well above the
/// rounding of coordinates (1e-16 relative) and of the reader's flattening, well below any gap
/// anyone models.
pub const SAME_PLANE_GAP: f64 = 1e-7;

/// One surface lying on another.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Overlap {
    /// The covered surface (index into [`Scene::surfaces`]).
    pub lower: u32,
    /// The surface on top.
    pub upper: u32,
    /// How far the upper surface's plane lies in front of the lower's (scene units; 0 in the
    /// same plane).
    pub gap: f64,
    /// The area of the lower surface the upper one covers (scene units squared).
    pub covered_area: f64,
}

impl Overlap {
    /// True when the two lie in one plane (the gap within [`SAME_PLANE_GAP`] of the scene's
    /// size, `scale`).
    pub fn same_plane(&self, scale: f64) -> bool {
        self.gap <= SAME_PLANE_GAP * scale
    }
}

/// Every pair of surfaces of `scene` of which one lies on the other (module documentation),
/// ordered by lower then upper surface. `occluders` is the BVH over the scene's surfaces.
pub fn lying_on(scene: &Scene, occluders: &PolygonBvh) -> Vec<Overlap> {
    let scale = occluders.scale();
    let same_plane = SAME_PLANE_GAP * scale;
    let normals: Vec<Option<DVec3>> = scene
        .surfaces
        .iter()
        .map(|s| geometry::polygon_normal(&s.vertices))
        .collect();
    let areas: Vec<f64> = scene
        .surfaces
        .iter()
        .map(|s| geometry::polygon_area(&s.vertices))
        .collect();
    // The largest gap any surface could lie at: that of the largest.
    let max_gap = LYING_ON_GAP * areas.iter().copied().fold(0.0, f64::max).sqrt();
    let mut out = Vec::new();
    let mut candidates = Vec::new();
    for (s, lower) in scene.surfaces.iter().enumerate() {
        let Some(n) = normals[s] else { continue };
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &v in &lower.vertices {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        candidates.clear();
        occluders.overlapping(
            lo - DVec3::splat(max_gap),
            hi + DVec3::splat(max_gap),
            &mut candidates,
        );
        let mut uppers: Vec<u32> = candidates.iter().map(|&k| occluders.id_of(k)).collect();
        uppers.sort_unstable();
        uppers.dedup();
        for t in uppers {
            let tu = t as usize;
            if tu == s || normals[tu].is_none_or(|m| m.dot(n) < 1.0 - 1e-9) {
                continue;
            }
            // Heights of the other surface's corners above this plane: all equal (parallel)
            // and within the gap.
            let origin = lower.vertices[0];
            let heights: Vec<f64> = scene.surfaces[tu]
                .vertices
                .iter()
                .map(|&v| (v - origin).dot(n))
                .collect();
            let gap = heights.iter().sum::<f64>() / heights.len() as f64;
            if heights.iter().any(|h| (h - gap).abs() > same_plane) {
                continue;
            }
            let on_top = if gap.abs() <= same_plane {
                areas[tu] < areas[s] || (areas[tu] == areas[s] && tu > s)
            } else {
                gap > 0.0 && gap <= LYING_ON_GAP * areas[tu].sqrt()
            };
            if !on_top {
                continue;
            }
            let covered = clipped_area(&lower.vertices, &scene.surfaces[tu].vertices, n);
            if covered > 1e-9 * areas[s].min(areas[tu]) {
                out.push(Overlap {
                    lower: s as u32,
                    upper: t,
                    gap: gap.max(0.0),
                    covered_area: covered,
                });
            }
        }
    }
    out
}

/// True when `p`, projected along `normal`, lies strictly inside the convex polygon
/// `polygon` (counter-clockwise about `normal`).
pub fn covers(polygon: &[DVec3], normal: DVec3, p: DVec3) -> bool {
    let k = polygon.len();
    (0..k).all(|i| {
        let (a, b) = (polygon[i], polygon[(i + 1) % k]);
        (b - a).cross(p - a).dot(normal) > 0.0
    })
}

/// The area of the convex polygon `a` that the convex polygon `b` covers, both projected on
/// the plane through the origin with unit normal `normal` and counter-clockwise about it
/// (Sutherland and Hodgman 1974: `a` clipped by each edge of `b`).
fn clipped_area(a: &[DVec3], b: &[DVec3], normal: DVec3) -> f64 {
    let (u, v) = normal.any_orthonormal_pair();
    let flat = |p: &DVec3| DVec2::new(p.dot(u), p.dot(v));
    let mut poly: Vec<DVec2> = a.iter().map(flat).collect();
    let clip: Vec<DVec2> = b.iter().map(flat).collect();
    // (u, v, normal) is right-handed, so counter-clockwise about the normal is
    // counter-clockwise in (u, v).
    let side = |p: DVec2, e0: DVec2, e1: DVec2| (e1 - e0).perp_dot(p - e0);
    for i in 0..clip.len() {
        let (e0, e1) = (clip[i], clip[(i + 1) % clip.len()]);
        let mut next = Vec::with_capacity(poly.len() + 1);
        for j in 0..poly.len() {
            let (p, q) = (poly[j], poly[(j + 1) % poly.len()]);
            let (sp, sq) = (side(p, e0, e1), side(q, e0, e1));
            if sp >= 0.0 {
                next.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                next.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
        poly = next;
        if poly.len() < 3 {
            return 0.0;
        }
    }
    let twice: f64 = (0..poly.len())
        .map(|j| poly[j].perp_dot(poly[(j + 1) % poly.len()]))
        .sum();
    0.5 * twice.abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shape::axis_aligned_base;
    use crate::scene::{Rgb, Surface};
    use glam::dvec3;

    /// A 4 x 4 floor (y = 0, facing +y) and a 2 x 1 rug on it at [1, 3] x [1, 2], `lift` above.
    pub(crate) fn floor_and_rug(lift: f64) -> Scene {
        let surface = |name: &str, vertices: Vec<DVec3>| Surface {
            name: name.into(),
            emission: Rgb::BLACK,
            reflectance: Rgb([0.5; 3]),
            vertices,
            photometry: Default::default(),
        };
        // The rectangle [x0, x1] x [z0, z1] at height y, facing +y.
        let quad = |x0: f64, x1: f64, z0: f64, z1: f64, y: f64| {
            axis_aligned_base(dvec3(x0, y, z0), dvec3(x1 - x0, 0., z1 - z0)).to_vec()
        };
        Scene {
            surfaces: vec![
                surface("floor", quad(0., 4., 0., 4., 0.)),
                surface("rug", quad(1., 3., 1., 2., lift)),
            ],
            camera: None,
            lights: Vec::new(),
        }
    }

    #[test]
    fn a_rug_in_the_floor_or_just_above_it_lies_on_it() {
        for lift in [0.0, 1e-4] {
            let scene = floor_and_rug(lift);
            let bvh = PolygonBvh::over_surfaces(&scene);
            let found = lying_on(&scene, &bvh);
            assert_eq!(found.len(), 1, "lift {lift}: {found:?}");
            let o = found[0];
            assert_eq!((o.lower, o.upper), (0, 1), "lift {lift}");
            // The rug's whole area, 2 x 1, to rounding.
            assert!((o.covered_area - 2.0).abs() < 1e-12, "{o:?}");
            assert!((o.gap - lift).abs() < 1e-12, "{o:?}");
            assert_eq!(o.same_plane(bvh.scale()), lift == 0.0);
        }
    }

    #[test]
    fn far_above_facing_away_or_beside_is_not_lying_on() {
        // 0.1 above (the 2 x 1 rug is some 1.4 across: 7 % of it), facing down, or moved off
        // the floor's edge.
        let mut high = floor_and_rug(0.1);
        let mut flipped = floor_and_rug(0.0);
        flipped.surfaces[1].vertices.reverse();
        let mut beside = floor_and_rug(0.0);
        for v in &mut beside.surfaces[1].vertices {
            v.x += 5.0;
        }
        for scene in [&mut high, &mut flipped, &mut beside] {
            let bvh = PolygonBvh::over_surfaces(scene);
            assert!(lying_on(scene, &bvh).is_empty());
        }
    }

    #[test]
    fn partial_overlap_area_is_the_intersection() {
        // The rug moved to [3, 5] x [1, 2] hangs half over the floor's edge at x = 4.
        let mut scene = floor_and_rug(0.0);
        for v in &mut scene.surfaces[1].vertices {
            v.x += 2.0;
        }
        let bvh = PolygonBvh::over_surfaces(&scene);
        let found = lying_on(&scene, &bvh);
        assert_eq!(found.len(), 1);
        assert!((found[0].covered_area - 1.0).abs() < 1e-12, "{found:?}");
    }
}
