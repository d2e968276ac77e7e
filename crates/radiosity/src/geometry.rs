//! Planar convex polygons: normal, area, planarity and convexity.
//!
//! Polygons are lists of corners in order; the front is the side from which they run
//! counter-clockwise. Normals use Newell's method (Sutherland, Sproull and Schumacker 1974,
//! as in Foley et al., *Computer Graphics*, 2nd ed., 11.1.3), which is exact for planar
//! polygons and a best-fit direction for slightly non-planar ones.

use glam::DVec3;

/// Newell's area vector: its direction is the front normal and its length is the area of a
/// planar polygon.
pub fn area_vector(vertices: &[DVec3]) -> DVec3 {
    let n = vertices.len();
    let mut sum = DVec3::ZERO;
    for i in 0..n {
        let a = vertices[i];
        let b = vertices[(i + 1) % n];
        sum += a.cross(b);
    }
    0.5 * sum
}

/// The area of a planar polygon (scene units squared).
pub fn polygon_area(vertices: &[DVec3]) -> f64 {
    area_vector(vertices).length()
}

/// The unit front normal, or `None` for a degenerate (zero-area) polygon.
pub fn polygon_normal(vertices: &[DVec3]) -> Option<DVec3> {
    area_vector(vertices).try_normalize()
}

/// The mean of the corners.
pub fn vertex_mean(vertices: &[DVec3]) -> DVec3 {
    vertices.iter().copied().sum::<DVec3>() / vertices.len() as f64
}

/// The area centroid of a planar polygon (fan triangulation from the first corner).
pub fn polygon_centroid(vertices: &[DVec3]) -> DVec3 {
    let mut weighted = DVec3::ZERO;
    let mut total = 0.0;
    for i in 1..vertices.len().saturating_sub(1) {
        let (a, b, c) = (vertices[0], vertices[i], vertices[i + 1]);
        let w = 0.5 * (b - a).cross(c - a).length();
        weighted += w * (a + b + c) / 3.0;
        total += w;
    }
    if total > 0.0 {
        weighted / total
    } else {
        vertex_mean(vertices)
    }
}

/// The largest distance of any corner from the best-fit plane (Newell normal through the
/// corner mean), in scene units. Zero for triangles and for exactly planar polygons.
pub fn max_plane_deviation(vertices: &[DVec3]) -> f64 {
    let Some(n) = polygon_normal(vertices) else {
        return 0.0;
    };
    let c = vertex_mean(vertices);
    vertices
        .iter()
        .map(|v| (*v - c).dot(n).abs())
        .fold(0.0, f64::max)
}

/// The largest distance between two corners (the polygon's diameter).
pub fn diameter(vertices: &[DVec3]) -> f64 {
    let mut d: f64 = 0.0;
    for (i, a) in vertices.iter().enumerate() {
        for b in &vertices[i + 1..] {
            d = d.max(a.distance(*b));
        }
    }
    d
}

/// Moves every corner onto the best-fit plane (Newell normal through the corner mean).
pub fn project_to_plane(vertices: &mut [DVec3]) {
    if let Some(n) = polygon_normal(vertices) {
        let c = vertex_mean(vertices);
        for v in vertices.iter_mut() {
            *v -= (*v - c).dot(n) * n;
        }
    }
}

/// True when the polygon is strictly convex with every turn the same way round its normal
/// (collinear corners, with a turn of zero, are allowed). Assumes a non-degenerate polygon.
pub fn is_convex(vertices: &[DVec3]) -> bool {
    let Some(n) = polygon_normal(vertices) else {
        return false;
    };
    let k = vertices.len();
    let scale = diameter(vertices).powi(2);
    for i in 0..k {
        let a = vertices[i];
        let b = vertices[(i + 1) % k];
        let c = vertices[(i + 2) % k];
        let turn = (b - a).cross(c - b).dot(n);
        // Relative tolerance: a turn this small is a straight (collinear) corner.
        if turn < -1e-9 * scale {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    fn unit_square() -> Vec<DVec3> {
        vec![
            dvec3(0., 0., 0.),
            dvec3(1., 0., 0.),
            dvec3(1., 1., 0.),
            dvec3(0., 1., 0.),
        ]
    }

    #[test]
    fn square_area_normal_centroid() {
        let sq = unit_square();
        assert!((polygon_area(&sq) - 1.0).abs() < 1e-15);
        assert_eq!(polygon_normal(&sq).unwrap(), DVec3::Z);
        assert!((polygon_centroid(&sq) - dvec3(0.5, 0.5, 0.0)).length() < 1e-15);
        assert!(is_convex(&sq));
        assert_eq!(max_plane_deviation(&sq), 0.0);
    }

    #[test]
    fn clockwise_square_faces_down() {
        let mut sq = unit_square();
        sq.reverse();
        assert_eq!(polygon_normal(&sq).unwrap(), -DVec3::Z);
    }

    #[test]
    fn dart_is_not_convex() {
        let dart = vec![
            dvec3(0., 0., 0.),
            dvec3(2., 1., 0.),
            dvec3(0., 2., 0.),
            dvec3(1., 1., 0.),
        ];
        assert!(!is_convex(&dart));
    }

    #[test]
    fn lifted_corner_deviation() {
        let mut sq = unit_square();
        sq[2].z = 0.1;
        // Newell normal is tilted; every corner is 0.025 from the fitted plane by symmetry of
        // the alternating +/- pattern (0.1 / 4 along z, scaled by n.z).
        let d = max_plane_deviation(&sq);
        let n = polygon_normal(&sq).unwrap();
        assert!((d - 0.025 * n.z).abs() < 1e-12, "{d}");
        project_to_plane(&mut sq);
        assert!(max_plane_deviation(&sq) < 1e-15);
    }
}
