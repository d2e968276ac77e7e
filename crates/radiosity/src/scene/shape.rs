//! The polygon checks a scene file's patches must pass, and the faces of the box primitive.

use glam::{dvec3, DVec3};

use crate::geometry;

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

/// Checks a patch polygon and flattens it onto its best-fit plane.
///
/// In order: no repeated corners, non-zero area, planar within [`PLANARITY_TOLERANCE`], convex
/// (every corner turns the same way round the front normal, once round). The message names
/// corners as `VERTEXk`.
pub(crate) fn check_polygon(vertices: &mut [DVec3]) -> Result<(), String> {
    let diameter = geometry::diameter(vertices);
    if let Some((i, j)) = repeated_corner(vertices, diameter) {
        return Err(format!(
            "degenerate polygon: VERTEX{i} and VERTEX{j} are the same point"
        ));
    }
    if geometry::polygon_area(vertices) <= ZERO_AREA * diameter * diameter {
        return Err(
            "degenerate polygon: its area is zero (the vertices are collinear, or \
                    the outline crosses itself)"
                .to_string(),
        );
    }
    check_planar(vertices, diameter)?;
    flatten(vertices);
    check_convex(vertices)
}

/// Projects the corners onto the best-fit plane when they are measurably off it.
pub(super) fn flatten(vertices: &mut [DVec3]) {
    let diameter = geometry::diameter(vertices);
    if geometry::max_plane_deviation(vertices) > FLATTEN_THRESHOLD * diameter {
        geometry::project_to_plane(vertices);
    }
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

/// An error when some corner is too far from the best-fit plane.
fn check_planar(vertices: &[DVec3], diameter: f64) -> Result<(), String> {
    let deviation = geometry::max_plane_deviation(vertices);
    let limit = PLANARITY_TOLERANCE * diameter;
    if deviation <= limit {
        return Ok(());
    }
    Err(format!(
        "the polygon is not planar: a vertex is {} scene units from the best-fit plane, more \
         than the limit of {} scene units (0.2% of the polygon's diameter, {} scene units)",
        significant(deviation),
        significant(limit),
        significant(diameter)
    ))
}

/// An error when the polygon is not convex, naming the first corner that turns the wrong way.
fn check_convex(vertices: &[DVec3]) -> Result<(), String> {
    if geometry::is_convex(vertices) && winds_once(vertices) {
        return Ok(());
    }
    match reflex_corner(vertices) {
        Some(k) => Err(format!(
            "the polygon is not convex: it turns the wrong way at VERTEX{k} (vertices must go \
             counter-clockwise round a convex outline, seen from the front)"
        )),
        None => Err("the polygon is not convex: its outline goes round more than once".into()),
    }
}

/// The first corner whose turn is against the front normal.
fn reflex_corner(vertices: &[DVec3]) -> Option<usize> {
    let normal = geometry::polygon_normal(vertices)?;
    let n = vertices.len();
    let scale = geometry::diameter(vertices).powi(2);
    (0..n).find_map(|i| {
        let (a, b, c) = (vertices[i], vertices[(i + 1) % n], vertices[(i + 2) % n]);
        ((b - a).cross(c - b).dot(normal) < -1e-9 * scale).then_some((i + 1) % n)
    })
}

/// True when every corner lies on the inner side of every edge, which rules out outlines that
/// turn the same way at every corner but go round more than once (a pentagram).
fn winds_once(vertices: &[DVec3]) -> bool {
    let Some(normal) = geometry::polygon_normal(vertices) else {
        return false;
    };
    let n = vertices.len();
    let scale = geometry::diameter(vertices).powi(2);
    (0..n).all(|i| {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        vertices
            .iter()
            .all(|v| (b - a).cross(*v - a).dot(normal) >= -1e-9 * scale)
    })
}

/// `x` with four significant digits, without an exponent for everyday magnitudes.
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor();
    if !(-4.0..=9.0).contains(&magnitude) {
        return format!("{x:.3e}");
    }
    let decimals = (3.0 - magnitude).max(0.0) as usize;
    format!("{x:.decimals$}")
}

/// Which way a box's faces look.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Facing {
    /// Away from the box: a solid object.
    Out,
    /// Into the box: a room.
    In,
}

/// The suffixes of a box's six faces, in the order [`box_faces`] returns them.
pub(crate) const FACE_NAMES: [&str; 6] = ["base", "top", "side0", "side1", "side2", "side3"];

/// The base quad of the axis-aligned box with minimum corner `origin` and extents `size`: its
/// y-min face, wound so that its normal is +y (into the box). The box is this base swept by
/// `size.y`.
pub(crate) fn axis_aligned_base(origin: DVec3, size: DVec3) -> [DVec3; 4] {
    let (x0, y0, z0) = (origin.x, origin.y, origin.z);
    let (x1, z1) = (origin.x + size.x, origin.z + size.z);
    [
        dvec3(x0, y0, z0),
        dvec3(x0, y0, z1),
        dvec3(x1, y0, z1),
        dvec3(x1, y0, z0),
    ]
}

/// The six faces of the prism swept from `base` along its right-hand-rule normal by `height`:
/// base, top, then the side over each base edge `VERTEXk`-`VERTEXk+1`. Every face's front
/// looks away from the prism for [`Facing::Out`] and into it for [`Facing::In`].
pub(crate) fn box_faces(base: &[DVec3; 4], height: f64, facing: Facing) -> [Vec<DVec3>; 6] {
    let normal = geometry::polygon_normal(base).unwrap_or(DVec3::Y);
    let top: [DVec3; 4] = base.map(|b| b + height * normal);
    let side = |i: usize| {
        let j = (i + 1) % 4;
        vec![base[i], base[j], top[j], top[i]]
    };
    // Wound for facing out: the base looks along -normal, the top along +normal, and a side
    // over a counter-clockwise edge e looks along e x normal, which is outwards.
    let mut faces = [
        base.iter().rev().copied().collect(),
        top.to_vec(),
        side(0),
        side(1),
        side(2),
        side(3),
    ];
    for face in &mut faces {
        if facing == Facing::In {
            face.reverse();
        }
        flatten(face);
    }
    faces
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Vec<DVec3> {
        vec![
            dvec3(0., 0., 0.),
            dvec3(1., 0., 0.),
            dvec3(1., 1., 0.),
            dvec3(0., 1., 0.),
        ]
    }

    #[test]
    fn accepts_square_unchanged() {
        let mut sq = square();
        check_polygon(&mut sq).unwrap();
        assert_eq!(sq, square());
    }

    #[test]
    fn planarity_limit_is_two_thousandths_of_the_diameter() {
        // Lifting one corner by h puts every corner h/4 (times the normal's z) off the plane;
        // the diameter is sqrt(2).
        let limit = PLANARITY_TOLERANCE * 2f64.sqrt();
        let mut ok = square();
        ok[2].z = 3.9 * limit;
        check_polygon(&mut ok).unwrap();
        assert!(geometry::max_plane_deviation(&ok) < 1e-12);
        let mut bad = square();
        bad[2].z = 4.2 * limit;
        let e = check_polygon(&mut bad).unwrap_err();
        assert!(e.contains("not planar"), "{e}");
        assert!(e.contains("scene units"), "{e}");
    }

    #[test]
    fn flattening_is_idempotent() {
        let mut sq = square();
        sq[2].z = 1e-3;
        check_polygon(&mut sq).unwrap();
        let once = sq.clone();
        check_polygon(&mut sq).unwrap();
        assert_eq!(sq, once);
    }

    #[test]
    fn degenerate_and_concave_and_star() {
        let mut rep = square();
        rep[2] = rep[1];
        assert!(check_polygon(&mut rep)
            .unwrap_err()
            .contains("VERTEX1 and VERTEX2"));
        let mut line = vec![dvec3(0., 0., 0.), dvec3(1., 0., 0.), dvec3(2., 0., 0.)];
        assert!(check_polygon(&mut line)
            .unwrap_err()
            .contains("area is zero"));
        let mut dart = vec![
            dvec3(0., 0., 0.),
            dvec3(2., 1., 0.),
            dvec3(0., 2., 0.),
            dvec3(1., 1., 0.),
        ];
        assert!(check_polygon(&mut dart).unwrap_err().contains("VERTEX3"));
        let star: Vec<DVec3> = (0..5)
            .map(|i| {
                let a = (i * 2) as f64 * std::f64::consts::TAU / 5.0;
                dvec3(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let mut star = star;
        assert!(check_polygon(&mut star)
            .unwrap_err()
            .contains("more than once"));
    }

    #[test]
    fn significant_digits() {
        assert_eq!(significant(0.80123), "0.8012");
        assert_eq!(significant(1.567), "1.567");
        assert_eq!(significant(783.456), "783.5");
        assert_eq!(significant(12345.6), "12346");
    }
}
