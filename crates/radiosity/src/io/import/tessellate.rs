//! VRML97's primitives (`Box`, `Sphere`, `Cylinder`, `Cone`) as polygons, each centred on
//! the origin with its axis along y as VRML places them, every front facing outwards.
//! They are the scene format's primitives (module `crate::scene::shape`), so that a VRML
//! sphere and a scene file's `SPHERE` of the same resolution are the same polygons: a
//! sphere of `n` segments round the axis and `n / 2` bands (triangles at the poles, quads
//! between), a cylinder's and a cone's side of `n` quads or triangles, their caps one
//! convex `n`-gon each.

use std::collections::HashMap;

use glam::DVec3;

use crate::scene::shape::{
    axis_aligned_base, box_faces, cone_faces, cylinder_faces, sphere_faces, Facing,
};

/// The box of extents `size` centred on the origin: the scene format's box primitive
/// (its six faces, base first; see [`box_faces`]) at origin `-size / 2`, facing out.
pub(crate) fn cuboid(size: DVec3) -> Vec<Vec<DVec3>> {
    box_faces(&axis_aligned_base(-size / 2.0, size), size.y, Facing::Out).to_vec()
}

/// The sphere of radius `r` about the origin with `segments` round the axis.
pub(crate) fn sphere(r: f64, segments: u32) -> Vec<Vec<DVec3>> {
    sphere_faces(DVec3::ZERO, r, segments.max(3), Facing::Out)
}

/// The cylinder of radius `r` and height `h` centred on the origin; `parts`: side, top,
/// bottom (VRML's flags).
pub(crate) fn cylinder(r: f64, h: f64, segments: u32, parts: [bool; 3]) -> Vec<Vec<DVec3>> {
    let faces = cylinder_faces(
        DVec3::new(0.0, -h / 2.0, 0.0),
        r,
        h,
        segments.max(3),
        Facing::Out,
    );
    // base, top, then the sides.
    faces
        .into_iter()
        .enumerate()
        .filter(|(k, _)| match k {
            0 => parts[2],
            1 => parts[1],
            _ => parts[0],
        })
        .map(|(_, f)| f)
        .collect()
}

/// The cone of base radius `r` and height `h` (apex up) centred on the origin; `parts`:
/// side, bottom (VRML's flags).
pub(crate) fn cone(r: f64, h: f64, segments: u32, parts: [bool; 2]) -> Vec<Vec<DVec3>> {
    let faces = cone_faces(
        DVec3::new(0.0, -h / 2.0, 0.0),
        r,
        h,
        segments.max(3),
        Facing::Out,
    );
    // base, then the sides.
    faces
        .into_iter()
        .enumerate()
        .filter(|(k, _)| if *k == 0 { parts[1] } else { parts[0] })
        .map(|(_, f)| f)
        .collect()
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
    use crate::geometry;

    /// Every polygon passes the scene's checks and faces away from the centre (each body
    /// is convex about it, so a face's outward normal n has n . x > 0 on the face); the
    /// polygons close up (each directed edge is run once, its reverse once).
    fn closed_and_outward(polys: &[Vec<DVec3>]) {
        let (_, faces) = indexed(polys.to_vec());
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
    }

    #[test]
    fn primitives_are_closed_centred_and_face_outwards() {
        closed_and_outward(&cuboid(DVec3::new(1.0, 2.0, 3.0)));
        closed_and_outward(&sphere(1.5, 12));
        closed_and_outward(&sphere(1.0, 3));
        closed_and_outward(&cylinder(1.0, 2.0, 7, [true; 3]));
        closed_and_outward(&cone(1.0, 2.0, 5, [true; 2]));
        let c = cylinder(1.0, 2.0, 8, [true; 3]);
        let ys = c.iter().flatten().map(|p| p.y);
        assert_eq!(ys.clone().fold(f64::INFINITY, f64::min), -1.0);
        assert_eq!(ys.fold(f64::NEG_INFINITY, f64::max), 1.0);
        assert_eq!(cylinder(1.0, 2.0, 8, [true, false, false]).len(), 8);
        assert_eq!(cylinder(1.0, 2.0, 8, [false, true, true]).len(), 2);
        assert_eq!(cone(1.0, 2.0, 8, [false, true]).len(), 1);
    }
}
