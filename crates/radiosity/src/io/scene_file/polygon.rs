//! How the scene reader words a [`PolygonError`]: corners named by their `VERTEXk` lines,
//! lengths in scene units with four significant digits.

use crate::geometry::{self, PolygonError};

/// The message, for the file:line:column error at the polygon's `VERTEX0` line.
pub(super) fn message(e: &PolygonError) -> String {
    match *e {
        PolygonError::TooFewVertices { count } => {
            format!("a polygon needs at least 3 vertices, found {count}")
        }
        PolygonError::RepeatedVertex { first, second } => {
            format!("degenerate polygon: VERTEX{first} and VERTEX{second} are the same point")
        }
        PolygonError::NotFinite { vertex, value } => {
            format!("VERTEX{vertex} has a coordinate that is not a finite number ({value})")
        }
        PolygonError::OutOfRange { vertex, value } => format!(
            "VERTEX{vertex} has the coordinate {value:e}, beyond the largest the program \
             supports ({:e} in magnitude); rescale the scene (for instance to metres)",
            geometry::MAX_COORDINATE
        ),
        PolygonError::TooSmall { diameter } => format!(
            "the polygon is {} scene units across, less than the smallest the program \
             supports ({:e}); rescale the scene (for instance to millimetres)",
            significant(diameter),
            geometry::MIN_POLYGON_SIZE
        ),
        PolygonError::ZeroArea => "degenerate polygon: its area is zero (the vertices are \
                                   collinear, or the outline crosses itself)"
            .to_string(),
        PolygonError::NotPlanar {
            deviation,
            limit,
            diameter,
            ..
        } => format!(
            "the polygon is not planar: a vertex is {} scene units from the best-fit plane, \
             more than the limit of {} scene units (0.2% of the polygon's diameter, {} scene \
             units)",
            significant(deviation),
            significant(limit),
            significant(diameter)
        ),
        PolygonError::Reflex { vertex } => format!(
            "the polygon is not convex: it turns the wrong way at VERTEX{vertex} (vertices must \
             go counter-clockwise round a convex outline, seen from the front)"
        ),
        PolygonError::WindsMoreThanOnce => {
            "the polygon is not convex: its outline goes round more than once".to_string()
        }
    }
}

/// The message for a box whose face `face` (its full name, `Table.side0`) fails the
/// polygon checks, at the box's `SIZE` or `HEIGHT` line. A face's corners are not written
/// in the file, so the message speaks of the box's sizes, not of `VERTEXk` lines.
pub(super) fn box_face_message(face: &str, e: &PolygonError) -> String {
    let why = match *e {
        PolygonError::RepeatedVertex { .. } => "two of its corners are the same point: a size \
             is too small to register beside the box's coordinates or its other sizes (less \
             than a billionth of them)"
            .to_string(),
        PolygonError::ZeroArea => {
            "its area is zero: one size is less than a billionth of another".to_string()
        }
        PolygonError::TooSmall { diameter } => format!(
            "it is {} scene units across, less than the smallest the program supports ({:e}); \
             rescale the scene (for instance to millimetres)",
            significant(diameter),
            geometry::MIN_POLYGON_SIZE
        ),
        PolygonError::OutOfRange { value, .. } => format!(
            "it reaches the coordinate {value:e}, beyond the largest the program supports \
             ({:e} in magnitude); rescale the scene (for instance to metres)",
            geometry::MAX_COORDINATE
        ),
        PolygonError::NotFinite { .. } => {
            "a corner's coordinate is not a finite number (the box reaches past the largest \
             number)"
                .to_string()
        }
        _ => message(e),
    };
    format!("the box's face \"{face}\" is not a usable polygon: {why}")
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(significant(0.80123), "0.8012");
        assert_eq!(significant(1.567), "1.567");
        assert_eq!(significant(783.456), "783.5");
        assert_eq!(significant(12345.6), "12346");
    }

    #[test]
    fn messages_name_vertex_lines() {
        let m = message(&PolygonError::RepeatedVertex {
            first: 1,
            second: 2,
        });
        assert_eq!(
            m,
            "degenerate polygon: VERTEX1 and VERTEX2 are the same point"
        );
        let m = message(&PolygonError::NotPlanar {
            vertex: 2,
            deviation: 0.024_94,
            limit: 0.002_835,
            diameter: 1.418,
        });
        assert_eq!(
            m,
            "the polygon is not planar: a vertex is 0.02494 scene units from the best-fit \
             plane, more than the limit of 0.002835 scene units (0.2% of the polygon's \
             diameter, 1.418 scene units)"
        );
        assert!(message(&PolygonError::Reflex { vertex: 3 }).contains("at VERTEX3 ("));
    }
}
