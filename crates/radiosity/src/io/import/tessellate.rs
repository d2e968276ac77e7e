//! Round primitives as polygons (VRML97's `Box`, `Sphere`, `Cylinder` and `Cone`): each
//! centred on the origin with its axis along y, as VRML places them, and every polygon's
//! front facing outwards.
//!
//! Each body is convex and holds the origin inside it, so a face's outward normal n has
//! n . x > 0 for the points x of the face: [`orient`] winds every polygon that way, which
//! is what "facing outwards" means whatever order the corners were made in.

use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

use glam::DVec3;

use crate::geometry;
use crate::scene::shape::{axis_aligned_base, box_faces, Facing};

/// `poly` wound so that its front faces away from the origin (see the module docs).
fn orient(mut poly: Vec<DVec3>) -> Vec<DVec3> {
    if geometry::area_vector(&poly).dot(geometry::vertex_mean(&poly)) < 0.0 {
        poly.reverse();
    }
    poly
}

/// The box of extents `size` centred on the origin: the scene format's box primitive
/// (its six faces, base first; see [`box_faces`]) at origin `-size / 2`, facing out.
pub(crate) fn cuboid(size: DVec3) -> Vec<Vec<DVec3>> {
    box_faces(&axis_aligned_base(-size / 2.0, size), size.y, Facing::Out).to_vec()
}

/// The point at angle `phi` round the y axis at radius `r` and height `y`.
fn round(r: f64, phi: f64, y: f64) -> DVec3 {
    DVec3::new(r * phi.cos(), y, -r * phi.sin())
}

/// The sphere of radius `r`: `segments` meridians and `segments / 2` (at least 2) bands of
/// latitude; triangles at the poles, quads (planar trapezoids) between.
pub(crate) fn sphere(r: f64, segments: u32) -> Vec<Vec<DVec3>> {
    let n = segments.max(3);
    let m = (n / 2).max(2);
    let at = |i: u32, j: u32| -> DVec3 {
        if i == 0 {
            return DVec3::new(0.0, r, 0.0);
        }
        if i == m {
            return DVec3::new(0.0, -r, 0.0);
        }
        let theta = PI * f64::from(i) / f64::from(m);
        round(
            r * theta.sin(),
            TAU * f64::from(j % n) / f64::from(n),
            r * theta.cos(),
        )
    };
    let mut out = Vec::new();
    for i in 0..m {
        for j in 0..n {
            let poly = if i == 0 {
                vec![at(0, 0), at(1, j), at(1, j + 1)]
            } else if i == m - 1 {
                vec![at(i, j), at(m, 0), at(i, j + 1)]
            } else {
                vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
            };
            out.push(orient(poly));
        }
    }
    out
}

/// The cylinder of radius `r` and height `h`: `segments` quads round its side, each cap a
/// fan of triangles about its centre. `parts`: side, top, bottom.
pub(crate) fn cylinder(r: f64, h: f64, segments: u32, parts: [bool; 3]) -> Vec<Vec<DVec3>> {
    let n = segments.max(3);
    let phi = |j: u32| TAU * f64::from(j % n) / f64::from(n);
    let (top, bottom) = (h / 2.0, -h / 2.0);
    let mut out = Vec::new();
    for j in 0..n {
        if parts[0] {
            out.push(orient(vec![
                round(r, phi(j), bottom),
                round(r, phi(j + 1), bottom),
                round(r, phi(j + 1), top),
                round(r, phi(j), top),
            ]));
        }
        if parts[1] {
            out.push(orient(vec![
                DVec3::new(0.0, top, 0.0),
                round(r, phi(j), top),
                round(r, phi(j + 1), top),
            ]));
        }
        if parts[2] {
            out.push(orient(vec![
                DVec3::new(0.0, bottom, 0.0),
                round(r, phi(j), bottom),
                round(r, phi(j + 1), bottom),
            ]));
        }
    }
    out
}

/// The cone of base radius `r` and height `h` (apex up): `segments` triangles round its
/// side, the base a fan of triangles about its centre. `parts`: side, bottom.
pub(crate) fn cone(r: f64, h: f64, segments: u32, parts: [bool; 2]) -> Vec<Vec<DVec3>> {
    let n = segments.max(3);
    let phi = |j: u32| TAU * f64::from(j % n) / f64::from(n);
    let (top, bottom) = (h / 2.0, -h / 2.0);
    let mut out = Vec::new();
    for j in 0..n {
        if parts[0] {
            out.push(orient(vec![
                DVec3::new(0.0, top, 0.0),
                round(r, phi(j), bottom),
                round(r, phi(j + 1), bottom),
            ]));
        }
        if parts[1] {
            out.push(orient(vec![
                DVec3::new(0.0, bottom, 0.0),
                round(r, phi(j), bottom),
                round(r, phi(j + 1), bottom),
            ]));
        }
    }
    out
}

/// Polygons as one point list (points shared where they are the same) and index lists.
pub(crate) fn indexed(polys: Vec<Vec<DVec3>>) -> (Vec<DVec3>, Vec<Vec<u32>>) {
    let mut points = Vec::new();
    let mut seen: HashMap<[u64; 3], u32> = HashMap::new();
    let faces = polys
        .into_iter()
        .map(|poly| {
            poly.into_iter()
                .map(|p| {
                    *seen
                        .entry(p.to_array().map(f64::to_bits))
                        .or_insert_with(|| {
                            points.push(p);
                            (points.len() - 1) as u32
                        })
                })
                .collect()
        })
        .collect();
    (points, faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every polygon passes the scene's checks and faces away from the origin; the
    /// polygons close up (each directed edge is run once, its reverse once).
    fn closed_and_outward(polys: &[Vec<DVec3>]) {
        let (points, faces) = indexed(polys.to_vec());
        let mut edges = HashMap::new();
        for (poly, face) in polys.iter().zip(&faces) {
            geometry::validate_polygon(poly).unwrap();
            let normal = geometry::polygon_normal(poly).unwrap();
            assert!(normal.dot(geometry::vertex_mean(poly)) > 0.0);
            for k in 0..face.len() {
                *edges
                    .entry((face[k], face[(k + 1) % face.len()]))
                    .or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "edge {a}-{b} run {n} times");
            assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
        }
        assert!(!points.is_empty());
    }

    #[test]
    fn primitives_are_closed_and_face_outwards() {
        closed_and_outward(&cuboid(DVec3::new(1.0, 2.0, 3.0)));
        closed_and_outward(&sphere(1.5, 12));
        closed_and_outward(&sphere(1.0, 3));
        closed_and_outward(&cylinder(1.0, 2.0, 7, [true; 3]));
        closed_and_outward(&cone(1.0, 2.0, 5, [true; 2]));
    }

    #[test]
    fn cylinder_and_cone_areas_are_their_prisms_and_pyramids() {
        // A regular n-gon of circumradius r has area n r^2 sin(2 pi / n) / 2 and side
        // 2 r sin(pi / n).
        let (r, h, n) = (1.5f64, 2.0f64, 16u32);
        let nf = f64::from(n);
        let disc = nf * r * r * (TAU / nf).sin() / 2.0;
        let side = 2.0 * r * (PI / nf).sin();
        let area = |p: &[Vec<DVec3>]| p.iter().map(|q| geometry::polygon_area(q)).sum::<f64>();
        let cyl = area(&cylinder(r, h, n, [true; 3]));
        assert!((cyl - (2.0 * disc + nf * side * h)).abs() < 1e-12);
        // The cone's side triangles: base `side`, slant height to the edge's midpoint.
        let apothem = r * (PI / nf).cos();
        let slant = (h * h + apothem * apothem).sqrt();
        let cone_area = area(&cone(r, h, n, [true; 2]));
        assert!((cone_area - (disc + nf * side * slant / 2.0)).abs() < 1e-12);
        assert_eq!(cylinder(r, h, n, [true, false, false]).len(), n as usize);
    }
}
