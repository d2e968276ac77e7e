//! Differential area to polygon: Lambert's formula (Lambert 1760; Baum, Rushmeier and
//! Winget 1989, "Improving radiosity solutions through the use of analytically determined
//! form-factors", SIGGRAPH 89, eq. 4), after clipping the polygon to the half-space in
//! front of the point, with the limit along the point's plane where the point lies on the
//! line of an edge. See the [`super`] documentation.

use std::f64::consts::PI;

use glam::DVec3;

use super::clip::{clip_front, ON_PLANE};
use crate::geometry::{polygon_normal, vertex_mean};

/// The form factor from a differential area at `p` with unit front normal `n` to the front of
/// the planar convex polygon `poly` (counter-clockwise from its front), unoccluded:
/// Lambert's formula (see the [module documentation](super)), with the polygon first clipped
/// to the half-space in front of (p, n).
///
/// 0 if nothing of the polygon lies in front of the point or the point lies behind the
/// polygon. A point on the polygon's plane gets the limit from the polygon's front side along
/// its own plane; in particular a point on the line of one of the polygon's edges (a point
/// of a floor on the edge it shares with a wall) is finite and exact.
pub fn point_to_polygon(p: DVec3, n: DVec3, poly: &[DVec3]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let (Some(n), Some(m)) = (n.try_normalize(), polygon_normal(poly)) else {
        return 0.0;
    };
    let size = poly.iter().map(|&v| v.distance(p)).fold(0.0, f64::max);
    if size == 0.0 || !size.is_finite() {
        return 0.0;
    }
    let inv = 1.0 / size;
    // The point must be in front of (or on) the polygon's plane.
    if m.dot(p - vertex_mean(poly)) * inv < -ON_PLANE {
        return 0.0;
    }
    let Some(rel) = clip_front(poly, n, p, p, inv) else {
        return 0.0;
    };
    let rel = rel.as_slice();
    // The direction a point of the receiver's plane approaches from: along the plane,
    // towards the polygon's front.
    let delta = (m - n * m.dot(n)).normalize_or_zero();
    let mut sum = 0.0;
    for k in 0..rel.len() {
        sum += lambert_edge(rel[k], rel[(k + 1) % rel.len()], n, delta);
    }
    (-sum / (2.0 * PI)).max(0.0)
}

/// One edge's term gamma n . unit(ra x rb) of Lambert's formula, ra and rb the corners
/// relative to the point (in units of the polygon's size), with the limits along `delta`
/// where the point lies on the edge's line.
fn lambert_edge(ra: DVec3, rb: DVec3, n: DVec3, delta: DVec3) -> f64 {
    const ON_LINE: f64 = 1e-12;
    let (la, lb) = (ra.length(), rb.length());
    if la <= ON_LINE && lb <= ON_LINE {
        return 0.0;
    }
    let a = if la <= ON_LINE { -delta } else { ra / la };
    let b = if lb <= ON_LINE { -delta } else { rb / lb };
    let cross = a.cross(b);
    let sin = cross.length();
    let cos = a.dot(b);
    if sin > ON_LINE {
        return sin.atan2(cos) * n.dot(cross / sin);
    }
    if cos > 0.0 {
        // The point is on the edge's line beyond its ends: angle 0.
        return 0.0;
    }
    // The point is inside the edge: angle pi about the limiting axis.
    let axis = (rb - ra).cross(delta).normalize_or_zero();
    PI * n.dot(axis)
}

#[cfg(test)]
mod tests {
    use super::super::test_util::*;
    use super::*;
    use crate::form_factor::reference;

    #[test]
    fn exact_point_to_rectangle_corner() {
        for (a, b, c) in [(1.0, 1.0, 1.0), (2.0, 0.5, 0.3), (0.1, 3.0, 2.0)] {
            let f = point_to_polygon(DVec3::ZERO, DVec3::Z, &ceiling(a, b, c));
            let want = reference::differential_to_parallel_rectangle(a, b, c);
            eprintln!(
                "point to rectangle {a} {b} {c}: {f:.16} rel {:e}",
                rel_err(f, want)
            );
            assert!(rel_err(f, want) < EXACT);
        }
        // Under the centre: four corner rectangles.
        let centred: Vec<DVec3> = ceiling(2.0, 2.0, 1.0)
            .into_iter()
            .map(|p| p - v(1., 1., 0.))
            .collect();
        let f = point_to_polygon(DVec3::ZERO, DVec3::Z, &centred);
        let want = 4.0 * reference::differential_to_parallel_rectangle(1.0, 1.0, 1.0);
        assert!(rel_err(f, want) < EXACT);
        // Facing away, or the point behind the polygon: 0.
        assert_eq!(point_to_polygon(DVec3::ZERO, -DVec3::Z, &centred), 0.0);
        assert_eq!(point_to_polygon(v(0., 0., 2.), DVec3::Z, &centred), 0.0);
    }

    // A wall reaching below the receiver's plane counts only above it: the same as the wall
    // cut at the plane, and that in turn is the difference of two corner-under rectangles
    // seen from the side (Howell B-3 turned: a perpendicular rectangle is not in the
    // catalogue here, so compare with the cut polygon and with the integral of the kernel).
    #[test]
    fn exact_point_to_polygon_partly_behind() {
        let tall = vec![
            v(1., -1., -1.),
            v(1., -1., 1.),
            v(1., 1., 1.),
            v(1., 1., -1.),
        ];
        let cut = vec![v(1., -1., 0.), v(1., -1., 1.), v(1., 1., 1.), v(1., 1., 0.)];
        assert!(polygon_normal(&tall).unwrap().dot(-DVec3::X) > 0.99);
        let f = point_to_polygon(DVec3::ZERO, DVec3::Z, &tall);
        let g = point_to_polygon(DVec3::ZERO, DVec3::Z, &cut);
        // The kernel cos cos / (pi r^2) integrated over the cut wall by Gauss-Legendre
        // (smooth there: the point is 1 away).
        let kernel = |q: DVec3| {
            let d = q;
            let r2 = d.length_squared();
            DVec3::Z.dot(d) * d.x / (PI * r2 * r2)
        };
        let want = quad_integral(&cut, 40, &kernel);
        eprintln!("partly behind {f:.16} cut {g:.16} kernel {want:.16}");
        assert!(rel_err(f, g) < 1e-14);
        assert!(rel_err(f, want) < EXACT);
    }

    // A point on the edge a floor shares with a wall: R_e x R_e+1 = 0 for that edge. Along the
    // floor towards the edge the wall fills a quarter of the sphere, a projected solid angle
    // of pi/2 for any wall much larger than the distance: the limit is exactly 1/2 inside the
    // edge and 1/4 at its corner (an eighth of the sphere). Nearby points converge to it.
    #[test]
    fn exact_point_on_shared_edge() {
        let w = wall(0.0, 1.0, 1.0);
        let f = point_to_polygon(v(0., 0.5, 0.), DVec3::Z, &w);
        assert!((f - 0.5).abs() < 1e-15, "{f}");
        let corner = point_to_polygon(v(0., 0., 0.), DVec3::Z, &w);
        assert!((corner - 0.25).abs() < 1e-15, "{corner}");
        for eps in [1e-4, 1e-6, 1e-8] {
            let near = point_to_polygon(v(eps, 0.5, 0.), DVec3::Z, &w);
            // The deficit is the wall's far parts, of order eps.
            assert!(near < 0.5 && 0.5 - near < 2.0 * eps, "{eps}: {near}");
            let near = point_to_polygon(v(eps, 0.0, 0.), DVec3::Z, &w);
            assert!((near - 0.25).abs() < 2.0 * eps, "{eps}: {near}");
        }
        // Integrated over the floor, the point form factor gives the polygon one (the floor's
        // edge at x = 0 is the only non-smooth place; grade towards it from the corner
        // (0, 0) and, by symmetry in y, use twice the half floor).
        let lambert = |p: DVec3| point_to_polygon(p, DVec3::Z, &w);
        let half = graded_corner_integral(1.0, 0.5, 24, &lambert);
        let want = reference::perpendicular_rectangles(1.0, 1.0, 1.0);
        eprintln!("Lambert integrated over the floor {:.16}", 2.0 * half);
        assert!(rel_err(2.0 * half, want) < 1e-6);
    }
}
