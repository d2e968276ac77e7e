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
///
/// Summed about the first corner, not the origin, so that the result does not depend on
/// where the polygon is: about the origin, a 1 x 1 square at x = 1e9 would be the
/// difference of terms near 1e9, and lose half its digits.
pub fn area_vector(vertices: &[DVec3]) -> DVec3 {
    let n = vertices.len();
    let Some(&o) = vertices.first() else {
        return DVec3::ZERO;
    };
    let mut sum = DVec3::ZERO;
    for i in 1..n.saturating_sub(1) {
        sum += (vertices[i] - o).cross(vertices[i + 1] - o);
    }
    0.5 * sum
}

/// The smallest axis-aligned box holding `points`, as (min, max); (+inf, -inf) for none.
pub fn bounds(points: impl IntoIterator<Item = DVec3>) -> (DVec3, DVec3) {
    points.into_iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

/// Whether the boxes (lo, hi) and (other_lo, other_hi) come within `reach` of each other
/// along every axis.
pub fn boxes_meet(lo: DVec3, hi: DVec3, other_lo: DVec3, other_hi: DVec3, reach: f64) -> bool {
    (other_lo - DVec3::splat(reach)).cmple(hi).all()
        && (other_hi + DVec3::splat(reach)).cmpge(lo).all()
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
///
/// Exact for planar polygons, in O(n log n) time: the corners are projected onto the
/// polygon's plane (Newell normal; for a degenerate polygon, the plane across the smallest
/// extent of its bounding box), their convex hull is found (Andrew's monotone chain), and
/// the diameter is the largest 3D distance over the hull's antipodal pairs (rotating
/// calipers, Shamos 1978; Preparata and Shamos, *Computational Geometry*, 4.2.3). For a
/// polygon out of plane by d, the pair found may miss the true diameter by d^2 / diameter
/// at most: 2e-6 of the diameter at the planarity tolerance (0.2 %). Polygons of up to 8
/// corners compare every pair.
pub fn diameter(vertices: &[DVec3]) -> f64 {
    if vertices.len() <= 8 {
        return brute_force_diameter(vertices);
    }
    let normal = polygon_normal(vertices).unwrap_or_else(|| {
        let (lo, hi) = bounds(vertices.iter().copied());
        let extent = hi - lo;
        if extent.x <= extent.y && extent.x <= extent.z {
            DVec3::X
        } else if extent.y <= extent.z {
            DVec3::Y
        } else {
            DVec3::Z
        }
    });
    let (u, v) = normal.any_orthonormal_pair();
    let flat: Vec<(f64, f64, usize)> = vertices
        .iter()
        .enumerate()
        .map(|(i, p)| (p.dot(u), p.dot(v), i))
        .collect();
    let hull = convex_hull(flat);
    let d3 = |a: usize, b: usize| vertices[hull[a].2].distance(vertices[hull[b].2]);
    let m = hull.len();
    if m < 3 {
        return if m == 2 { d3(0, 1) } else { 0.0 };
    }
    // Twice the area of the triangle (hull[a], hull[b], hull[c]).
    let area = |a: usize, b: usize, c: usize| {
        let (p, q, r) = (hull[a], hull[b], hull[c]);
        (q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0)
    };
    let mut best: f64 = 0.0;
    let mut j = 1;
    for i in 0..m {
        let i1 = (i + 1) % m;
        // The corner furthest from edge i: the area over the edge grows up to it.
        while area(i, i1, (j + 1) % m) > area(i, i1, j) {
            j = (j + 1) % m;
        }
        best = best.max(d3(i, j)).max(d3(i1, j));
    }
    best
}

/// Every pair compared: O(n^2), for small polygons.
fn brute_force_diameter(vertices: &[DVec3]) -> f64 {
    let mut d: f64 = 0.0;
    for (i, a) in vertices.iter().enumerate() {
        for b in &vertices[i + 1..] {
            d = d.max(a.distance(*b));
        }
    }
    d
}

/// The convex hull of 2D points (x, y, tag), counter-clockwise, without collinear points
/// (Andrew 1979, monotone chain).
fn convex_hull(mut points: Vec<(f64, f64, usize)>) -> Vec<(f64, f64, usize)> {
    points.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    points.dedup_by(|a, b| a.0 == b.0 && a.1 == b.1);
    if points.len() < 3 {
        return points;
    }
    let turn = |o: (f64, f64, usize), a: (f64, f64, usize), b: (f64, f64, usize)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64, usize)> = Vec::with_capacity(points.len() + 1);
    for pass in 0..2 {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &(f64, f64, usize)>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in ordered {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        // The last point of each chain is the first of the other.
        hull.pop();
    }
    hull
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

/// A polygon is accepted as planar when no corner is further than this fraction of its
/// diameter from the best-fit plane (0.2 %).
pub const PLANARITY_TOLERANCE: f64 = 2e-3;

/// The largest coordinate magnitude a scene may have (scene units): 1e30.
///
/// Together with [`MIN_POLYGON_SIZE`] this is the range of scales the program supports:
/// sixty orders of magnitude, so any physical unit fits. The limits come from f64 in the
/// form-factor kernel and the solvers: areas reach size^2, the kernel divides by distance^4
/// and multiplies two areas (size^4 over distance^4), all of which stay between 1e-240 and
/// 1e240, far inside f64's 1e-308 .. 1e308. (The ray-query hierarchy, which is in f32,
/// works in its own units: see [`crate::visibility::PolygonBvh`].)
pub const MAX_COORDINATE: f64 = 1e30;

/// The smallest diameter a polygon may have (scene units): 1e-30. See [`MAX_COORDINATE`].
pub const MIN_POLYGON_SIZE: f64 = 1e-30;

/// Corners are projected onto the best-fit plane only when some corner is further than this
/// fraction of the diameter from it, so that projecting twice changes nothing.
const FLATTEN_THRESHOLD: f64 = 1e-12;

/// Two corners closer than this fraction of the diameter are the same point.
const SAME_POINT: f64 = 1e-9;

/// An area below this fraction of the squared diameter is zero.
const ZERO_AREA: f64 = 1e-9;

/// A turn (the cross product of two consecutive edges along the normal) below minus this
/// fraction of the squared diameter turns the wrong way; above it, a corner is straight.
const STRAIGHT_TURN: f64 = 1e-9;

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
    /// A coordinate is infinite or NaN.
    #[error("vertex {vertex} has a coordinate that is not a finite number ({value})")]
    NotFinite {
        /// The corner.
        vertex: usize,
        /// The coordinate.
        value: f64,
    },
    /// A coordinate's magnitude is above [`MAX_COORDINATE`].
    #[error(
        "vertex {vertex} has the coordinate {value:e}, beyond the largest the program \
         supports ({MAX_COORDINATE:e} in magnitude)"
    )]
    OutOfRange {
        /// The corner.
        vertex: usize,
        /// The coordinate.
        value: f64,
    },
    /// Two corners coincide (closer than 1e-9 of the diameter).
    #[error("degenerate polygon: vertices {first} and {second} are the same point")]
    RepeatedVertex {
        /// The first of the pair.
        first: usize,
        /// The second of the pair (`first < second`).
        second: usize,
    },
    /// The diameter is below [`MIN_POLYGON_SIZE`].
    #[error(
        "the polygon is {diameter:e} scene units across, less than the smallest the program \
         supports ({MIN_POLYGON_SIZE:e})"
    )]
    TooSmall {
        /// The polygon's diameter (scene units).
        diameter: f64,
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
/// corners, finite coordinates within [`MAX_COORDINATE`], no repeated corners, a diameter of
/// at least [`MIN_POLYGON_SIZE`], a non-zero area, planar within [`PLANARITY_TOLERANCE`] of
/// the diameter, and convex (every corner turns the same way round the front normal, and
/// the outline goes round once). Convexity is judged on the corners as [`flatten`] would
/// project them, so a polygon that passes stays valid once flattened.
///
/// Every test is relative to the polygon's own size, and is made on a copy moved to its
/// first corner and scaled by a power of two to about unit size: a polygon passes or fails
/// the same at any position and scale within the supported range, and no square or
/// product of coordinates can overflow or underflow. O(n log n) in the corners.
pub fn validate_polygon(vertices: &[DVec3]) -> Result<(), PolygonError> {
    if vertices.len() < 3 {
        return Err(PolygonError::TooFewVertices {
            count: vertices.len(),
        });
    }
    for (vertex, v) in vertices.iter().enumerate() {
        for value in v.to_array() {
            if !value.is_finite() {
                return Err(PolygonError::NotFinite { vertex, value });
            }
            if value.abs() > MAX_COORDINATE {
                return Err(PolygonError::OutOfRange { vertex, value });
            }
        }
    }
    let (local, unit) = normalised(vertices);
    let diameter = self::diameter(&local);
    if let Some((first, second)) = repeated_corner(&local, diameter) {
        return Err(PolygonError::RepeatedVertex { first, second });
    }
    if diameter * unit < MIN_POLYGON_SIZE {
        return Err(PolygonError::TooSmall {
            diameter: diameter * unit,
        });
    }
    if polygon_area(&local) <= ZERO_AREA * diameter * diameter {
        return Err(PolygonError::ZeroArea);
    }
    let (vertex, deviation) = furthest_from_plane(&local);
    let limit = PLANARITY_TOLERANCE * diameter;
    if deviation > limit {
        return Err(PolygonError::NotPlanar {
            vertex,
            deviation: deviation * unit,
            limit: limit * unit,
            diameter: diameter * unit,
        });
    }
    let mut flat = local;
    flatten(&mut flat);
    if is_convex(&flat) && winds_once(&flat) {
        return Ok(());
    }
    Err(match reflex_corner(&flat) {
        Some(vertex) => PolygonError::Reflex { vertex },
        None => PolygonError::WindsMoreThanOnce,
    })
}

/// The corners moved so that the first is at the origin and scaled by powers of two (which
/// is exact) to within a unit of it, and the scale that undoes it: `vertices[i] =
/// vertices[0] + unit * local[i]`. The coordinates are first scaled into [-1, 1], so the
/// differences cannot overflow. Finite coordinates assumed.
fn normalised(vertices: &[DVec3]) -> (Vec<DVec3>, f64) {
    let largest =
        |vs: &mut dyn Iterator<Item = DVec3>| vs.map(|v| v.abs().max_element()).fold(0.0, f64::max);
    let first = power_of_two_at_least(largest(&mut vertices.iter().copied()));
    let o = vertices[0] / first;
    let moved: Vec<DVec3> = vertices.iter().map(|v| *v / first - o).collect();
    let second = power_of_two_at_least(largest(&mut moved.iter().copied()));
    let local = moved.into_iter().map(|v| v / second).collect();
    (local, first * second)
}

/// The smallest power of two at or above `x` (1 for 0).
fn power_of_two_at_least(x: f64) -> f64 {
    if !(x > 0.0) {
        return 1.0;
    }
    let e = x.log2().ceil().clamp(-1000.0, 1000.0) as i32;
    let p = 2f64.powi(e);
    // log2 may round either way; one step fixes it.
    if p < x {
        2.0 * p
    } else {
        p
    }
}

/// True when the polygon is strictly convex with every turn the same way round its normal
/// (collinear corners, with a turn of zero, are allowed). Assumes a non-degenerate polygon.
pub fn is_convex(vertices: &[DVec3]) -> bool {
    polygon_normal(vertices).is_some() && reflex_corner(vertices).is_none()
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

/// The first pair of corners (i < j, by i then j) that lie within 1e-9 of the diameter of
/// each other. Expected O(n): corners are put in cubic cells of that size, and only corners
/// in the 27 cells around each are compared (a cell holds a bounded number of corners that
/// are pairwise further apart than its size).
fn repeated_corner(vertices: &[DVec3], diameter: f64) -> Option<(usize, usize)> {
    let limit = SAME_POINT * diameter;
    if vertices.len() <= 8 || !(limit > 0.0) {
        return (0..vertices.len()).find_map(|i| {
            (i + 1..vertices.len())
                .find(|&j| vertices[i].distance(vertices[j]) <= limit)
                .map(|j| (i, j))
        });
    }
    let (lo, _) = bounds(vertices.iter().copied());
    let cell = |v: DVec3| ((v - lo) / limit).floor().as_i64vec3().to_array();
    let mut cells: std::collections::HashMap<[i64; 3], Vec<usize>> =
        std::collections::HashMap::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        cells.entry(cell(*v)).or_default().push(i);
    }
    let mut first: Option<(usize, usize)> = None;
    for (i, v) in vertices.iter().enumerate() {
        let [x, y, z] = cell(*v);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(near) = cells.get(&[x + dx, y + dy, z + dz]) else {
                        continue;
                    };
                    for &j in near {
                        if j > i
                            && v.distance(vertices[j]) <= limit
                            && first.is_none_or(|f| (i, j) < f)
                        {
                            first = Some((i, j));
                        }
                    }
                }
            }
        }
        if first.is_some_and(|f| f.0 == i) {
            return first;
        }
    }
    first
}

/// The first corner whose turn is against the front normal.
fn reflex_corner(vertices: &[DVec3]) -> Option<usize> {
    let normal = polygon_normal(vertices)?;
    let n = vertices.len();
    let scale = diameter(vertices).powi(2);
    (0..n).find_map(|i| {
        let (a, b, c) = (vertices[i], vertices[(i + 1) % n], vertices[(i + 2) % n]);
        ((b - a).cross(c - b).dot(normal) < -STRAIGHT_TURN * scale).then_some((i + 1) % n)
    })
}

/// True when the outline goes round the normal once, for an outline that turns the same
/// way (or straight on) at every corner: the turning angles (each in (-pi, pi], a
/// reversal counting as pi) add up to 2 pi once round, 4 pi for a pentagram. O(n).
fn winds_once(vertices: &[DVec3]) -> bool {
    let Some(normal) = polygon_normal(vertices) else {
        return false;
    };
    let n = vertices.len();
    let total: f64 = (0..n)
        .map(|i| {
            let (a, b, c) = (vertices[i], vertices[(i + 1) % n], vertices[(i + 2) % n]);
            let (e, f) = (b - a, c - b);
            let angle = e.cross(f).dot(normal).atan2(e.dot(f));
            // A turn of -pi (or a hair less) is a reversal: pi, like +pi.
            if angle < -0.5 * std::f64::consts::PI {
                angle + std::f64::consts::TAU
            } else {
                angle
            }
        })
        .sum();
    (total - std::f64::consts::TAU).abs() < 0.5 * std::f64::consts::PI
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
