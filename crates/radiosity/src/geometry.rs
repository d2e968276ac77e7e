//! Planar convex polygons: normal, area, planarity and convexity, and the checks a polygon
//! must pass to be a surface ([`validate_polygon`], with a typed [`PolygonError`]).
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

/// A polygon is accepted as planar when no corner is further than this fraction of its
/// diameter from the best-fit plane (0.2 %).
pub const PLANARITY_TOLERANCE: f64 = 2e-3;

/// Corners are projected onto the best-fit plane only when some corner is further than this
/// fraction of the diameter from it, so that projecting twice changes nothing.
const FLATTEN_THRESHOLD: f64 = 1e-12;

/// Two corners closer than this fraction of the diameter are the same point.
const SAME_POINT: f64 = 1e-9;

/// An area below this fraction of the squared diameter is zero.
const ZERO_AREA: f64 = 1e-9;

/// Why a list of corners is not a usable planar convex polygon ([`validate_polygon`]).
/// Corners are numbered from 0 in the order given.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum PolygonError {
    /// Fewer than 3 corners.
    #[error("a polygon needs at least 3 vertices, found {count}")]
    TooFewVertices {
        /// The number of corners given.
        count: usize,
    },
    /// Two corners coincide (closer than 1e-9 of the diameter).
    #[error("degenerate polygon: vertices {first} and {second} are the same point")]
    RepeatedVertex {
        /// The first of the pair.
        first: usize,
        /// The second of the pair (`first < second`).
        second: usize,
    },
    /// The area is zero (below 1e-9 of the squared diameter): the corners are collinear, or
    /// the outline crosses itself so that its parts cancel.
    #[error("degenerate polygon: its area is zero")]
    ZeroArea,
    /// Some corner is further from the best-fit plane than [`PLANARITY_TOLERANCE`] of the
    /// diameter.
    #[error(
        "the polygon is not planar: vertex {vertex} is {deviation} from the best-fit plane, \
         more than the limit of {limit}"
    )]
    NotPlanar {
        /// The corner furthest from the plane.
        vertex: usize,
        /// Its distance from the plane (scene units).
        deviation: f64,
        /// The largest distance accepted: [`PLANARITY_TOLERANCE`] x `diameter`.
        limit: f64,
        /// The polygon's diameter (scene units).
        diameter: f64,
    },
    /// The outline turns against the front normal at a corner.
    #[error("the polygon is not convex: it turns the wrong way at vertex {vertex}")]
    Reflex {
        /// The first corner that turns the wrong way.
        vertex: usize,
    },
    /// Every corner turns the same way but the outline goes round more than once (a
    /// pentagram).
    #[error("the polygon is not convex: its outline goes round more than once")]
    WindsMoreThanOnce,
}

/// Checks that `vertices` make a usable planar convex polygon, in this order: at least 3
/// corners, no repeated corners, a non-zero area, planar within [`PLANARITY_TOLERANCE`] of
/// the diameter, and convex (every corner turns the same way round the front normal, and
/// the outline goes round once). Convexity is judged on the corners as [`flatten`] would
/// project them, so a polygon that passes stays valid once flattened.
pub fn validate_polygon(vertices: &[DVec3]) -> Result<(), PolygonError> {
    if vertices.len() < 3 {
        return Err(PolygonError::TooFewVertices {
            count: vertices.len(),
        });
    }
    let diameter = diameter(vertices);
    if let Some((first, second)) = repeated_corner(vertices, diameter) {
        return Err(PolygonError::RepeatedVertex { first, second });
    }
    if polygon_area(vertices) <= ZERO_AREA * diameter * diameter {
        return Err(PolygonError::ZeroArea);
    }
    let (vertex, deviation) = furthest_from_plane(vertices);
    let limit = PLANARITY_TOLERANCE * diameter;
    if deviation > limit {
        return Err(PolygonError::NotPlanar {
            vertex,
            deviation,
            limit,
            diameter,
        });
    }
    let mut flat = vertices.to_vec();
    flatten(&mut flat);
    if is_convex(&flat) && winds_once(&flat) {
        return Ok(());
    }
    Err(match reflex_corner(&flat) {
        Some(vertex) => PolygonError::Reflex { vertex },
        None => PolygonError::WindsMoreThanOnce,
    })
}

/// Projects the corners onto the best-fit plane ([`project_to_plane`]) when some corner is
/// measurably off it (more than 1e-12 of the diameter), so that flattening a flattened
/// polygon changes nothing.
pub fn flatten(vertices: &mut [DVec3]) {
    let diameter = diameter(vertices);
    if max_plane_deviation(vertices) > FLATTEN_THRESHOLD * diameter {
        project_to_plane(vertices);
    }
}

/// The corner furthest from the best-fit plane and its distance ([`max_plane_deviation`]).
fn furthest_from_plane(vertices: &[DVec3]) -> (usize, f64) {
    let Some(n) = polygon_normal(vertices) else {
        return (0, 0.0);
    };
    let c = vertex_mean(vertices);
    vertices
        .iter()
        .map(|v| (*v - c).dot(n).abs())
        .enumerate()
        .fold(
            (0, 0.0),
            |best, (i, d)| if d > best.1 { (i, d) } else { best },
        )
}

/// The first pair of corners (i < j) that coincide.
fn repeated_corner(vertices: &[DVec3], diameter: f64) -> Option<(usize, usize)> {
    let limit = SAME_POINT * diameter;
    (0..vertices.len()).find_map(|i| {
        (i + 1..vertices.len())
            .find(|&j| vertices[i].distance(vertices[j]) <= limit)
            .map(|j| (i, j))
    })
}

/// The first corner whose turn is against the front normal.
fn reflex_corner(vertices: &[DVec3]) -> Option<usize> {
    let normal = polygon_normal(vertices)?;
    let n = vertices.len();
    let scale = diameter(vertices).powi(2);
    (0..n).find_map(|i| {
        let (a, b, c) = (vertices[i], vertices[(i + 1) % n], vertices[(i + 2) % n]);
        ((b - a).cross(c - b).dot(normal) < -1e-9 * scale).then_some((i + 1) % n)
    })
}

/// True when every corner lies on the inner side of every edge, which rules out outlines that
/// turn the same way at every corner but go round more than once (a pentagram).
fn winds_once(vertices: &[DVec3]) -> bool {
    let Some(normal) = polygon_normal(vertices) else {
        return false;
    };
    let n = vertices.len();
    let scale = diameter(vertices).powi(2);
    (0..n).all(|i| {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        vertices
            .iter()
            .all(|v| (b - a).cross(*v - a).dot(normal) >= -1e-9 * scale)
    })
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
    #[test]
    fn accepts_square_unchanged() {
        let sq = unit_square();
        validate_polygon(&sq).unwrap();
        let mut flat = sq.clone();
        flatten(&mut flat);
        assert_eq!(flat, sq);
    }

    #[test]
    fn planarity_limit_is_two_thousandths_of_the_diameter() {
        // Lifting one corner by h puts every corner h/4 (times the normal's z) off the plane;
        // the diameter is sqrt(2).
        let limit = PLANARITY_TOLERANCE * 2f64.sqrt();
        let mut ok = unit_square();
        ok[2].z = 3.9 * limit;
        validate_polygon(&ok).unwrap();
        flatten(&mut ok);
        assert!(max_plane_deviation(&ok) < 1e-12);
        let mut bad = unit_square();
        bad[2].z = 4.2 * limit;
        let Err(PolygonError::NotPlanar {
            vertex,
            deviation,
            limit: l,
            diameter: d,
        }) = validate_polygon(&bad)
        else {
            panic!("{:?}", validate_polygon(&bad));
        };
        assert_eq!(deviation, max_plane_deviation(&bad));
        assert_eq!(d, diameter(&bad));
        assert_eq!(l, PLANARITY_TOLERANCE * d);
        assert!(deviation > l);
        assert!(vertex < 4);
    }

    #[test]
    fn flattening_is_idempotent() {
        let mut sq = unit_square();
        sq[2].z = 1e-3;
        validate_polygon(&sq).unwrap();
        flatten(&mut sq);
        let once = sq.clone();
        validate_polygon(&sq).unwrap();
        flatten(&mut sq);
        assert_eq!(sq, once);
    }

    #[test]
    fn typed_errors_name_the_vertices() {
        assert_eq!(
            validate_polygon(&unit_square()[..2]),
            Err(PolygonError::TooFewVertices { count: 2 })
        );
        let mut rep = unit_square();
        rep[2] = rep[1];
        assert_eq!(
            validate_polygon(&rep),
            Err(PolygonError::RepeatedVertex {
                first: 1,
                second: 2
            })
        );
        let line = [dvec3(0., 0., 0.), dvec3(1., 0., 0.), dvec3(2., 0., 0.)];
        assert_eq!(validate_polygon(&line), Err(PolygonError::ZeroArea));
        let dart = [
            dvec3(0., 0., 0.),
            dvec3(2., 1., 0.),
            dvec3(0., 2., 0.),
            dvec3(1., 1., 0.),
        ];
        assert_eq!(
            validate_polygon(&dart),
            Err(PolygonError::Reflex { vertex: 3 })
        );
        let star: Vec<DVec3> = (0..5)
            .map(|i| {
                let a = (i * 2) as f64 * std::f64::consts::TAU / 5.0;
                dvec3(a.cos(), a.sin(), 0.0)
            })
            .collect();
        assert_eq!(
            validate_polygon(&star),
            Err(PolygonError::WindsMoreThanOnce)
        );
    }

    #[test]
    fn not_planar_names_the_furthest_corner() {
        // A pentagon with one corner pulled far out of the plane of the others.
        let mut p: Vec<DVec3> = (0..5)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 5.0;
                dvec3(a.cos(), a.sin(), 0.0)
            })
            .collect();
        p[3].z = 0.5;
        let Err(PolygonError::NotPlanar { vertex, .. }) = validate_polygon(&p) else {
            panic!("{:?}", validate_polygon(&p));
        };
        assert_eq!(vertex, 3);
    }
}
