//! How the scene reader words a [`PolygonError`]: corners named by their `VERTEXk` lines,
//! lengths in scene units with four significant digits.

use crate::geometry::PolygonError;

/// The message, for the file:line:column error at the polygon's `VERTEX0` line.
pub(super) fn message(e: &PolygonError) -> String {
    match *e {
        PolygonError::TooFewVertices { count } => {
            format!("a polygon needs at least 3 vertices, found {count}")
        }
        PolygonError::RepeatedVertex { first, second } => {
            format!("degenerate polygon: VERTEX{first} and VERTEX{second} are the same point")
        }
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
