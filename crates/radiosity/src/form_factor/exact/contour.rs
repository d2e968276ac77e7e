//! Polygon to polygon: the double contour integral (Stokes' theorem applied twice to the
//! double area integral; Sparrow 1963, "A new and simpler formulation for radiative angle
//! factors", J. Heat Transfer 85; Goral, Torrance, Greenberg and Battaile 1984, "Modeling
//! the interaction of light between diffuse surfaces", SIGGRAPH 84, eq. 9), summed over
//! edge pairs: distant pairs by tensor Gauss-Legendre, parallel and collinear (shared) edges
//! by the closed-form second antiderivative of ln r, the others with the inner integral in
//! closed form and the outer by adaptive Gauss-Kronrod. See the [`super`] documentation
//! for the derivation and the accuracy.

use std::f64::consts::PI;

use glam::DVec3;

use super::clip::clip_front;
use super::quadrature::{adaptive_gk21, GL10, GL6};
use crate::geometry::{area_vector, polygon_normal, vertex_mean};

/// Edges shorter than this (in the same units) are dropped: their contribution
/// is below 1e-15.
const SHORT_EDGE: f64 = 1e-15;

/// Edges whose directions' cross product is shorter than this are parallel (closed form).
/// Treating a pair at angle alpha as parallel changes its distances by about alpha, so
/// 1e-13 is far below the target accuracy.
const PARALLEL_SIN: f64 = 1e-13;

/// The exact unoccluded form factor F_12 from polygon `p1` to polygon `p2`: the fraction of
/// the energy diffusely emitted from the front of `p1` that reaches the front of `p2`.
///
/// Both polygons are planar and convex with corners counter-clockwise seen from the front.
/// Parts of either polygon behind the other's plane exchange nothing and are clipped away,
/// so partly facing pairs are right too; coplanar pairs, pairs facing away and degenerate
/// polygons give 0. Exact (agreeing with the closed forms to about 1e-15 relative) also for
/// polygons that share an edge or a corner; see the [module documentation](super) for the
/// method. For
/// distant pairs the contour sum cancels: expect a relative error of about 3e-17 (d / L)^2
/// for polygons of size L a distance d apart.
pub fn polygon_to_polygon(p1: &[DVec3], p2: &[DVec3]) -> f64 {
    if p1.len() < 3 || p2.len() < 3 {
        return 0.0;
    }
    let (Some(n1), Some(n2)) = (polygon_normal(p1), polygon_normal(p2)) else {
        return 0.0;
    };
    // Measure lengths in units of a typical distance between points of the two polygons
    // (about the root mean square), about the midpoint between them: ln r is then near 0
    // for distant pairs and of order one for close ones, which keeps the terms of the sum,
    // and so its cancellation, small.
    let (m1, m2) = (vertex_mean(p1), vertex_mean(p2));
    let spread = |p: &[DVec3], m: DVec3| {
        p.iter().map(|&v| v.distance_squared(m)).sum::<f64>() / p.len() as f64
    };
    let typical = (m1.distance_squared(m2) + spread(p1, m1) + spread(p2, m2)).sqrt();
    if typical == 0.0 || !typical.is_finite() {
        return 0.0;
    }
    let (shift, inv) = (0.5 * (m1 + m2), 1.0 / typical);
    let Some(q1) = clip_front(p1, n2, m2, shift, inv) else {
        return 0.0;
    };
    let Some(q2) = clip_front(p2, n1, m1, shift, inv) else {
        return 0.0;
    };
    let (q1, q2) = (q1.as_slice(), q2.as_slice());
    if q1.len() < 3 || q2.len() < 3 {
        return 0.0;
    }
    // F_12 is per unit area of the whole of polygon 1, clipped part included: that part
    // emits too, only not towards polygon 2.
    let area1 = area_vector(p1).length() * inv * inv;
    let mut sum = 0.0;
    for i in 0..q1.len() {
        let a = q1[i];
        let ea = q1[(i + 1) % q1.len()] - a;
        for j in 0..q2.len() {
            let b = q2[j];
            let eb = q2[(j + 1) % q2.len()] - b;
            sum += edge_pair(a, ea, b, eb);
        }
    }
    (sum / (2.0 * PI * area1)).max(0.0)
}

/// `(u . v) int int ln |a + s u - b - t v| dt ds` over edge a (from `a` along `ea`) and edge
/// b (from `b` along `eb`), s and t arc lengths.
fn edge_pair(a: DVec3, ea: DVec3, b: DVec3, eb: DVec3) -> f64 {
    let (la, lb) = (ea.length(), eb.length());
    if la < SHORT_EDGE || lb < SHORT_EDGE {
        return 0.0;
    }
    let (u, v) = (ea / la, eb / lb);
    let c = u.dot(v);
    if c == 0.0 {
        return 0.0;
    }
    // Edges apart by more than the longer one: ln r is analytic over both with the nearest
    // singularity at least that far away, so tensor Gauss-Legendre converges geometrically
    // (Bernstein ellipse parameter above 5.8 at 1 x, above 17 at 4 x the length: 10 and 6
    // points per edge leave below 1e-15) and, unlike the closed forms, without cancellation
    // between large antiderivatives when the edges are far apart.
    let longer = la.max(lb);
    let gap = (a + 0.5 * ea).distance(b + 0.5 * eb) - 0.5 * (la + lb);
    if gap >= 4.0 * longer {
        return c * tensor_gauss(a, ea, b, eb, &GL6) * la * lb;
    }
    if gap >= longer {
        return c * tensor_gauss(a, ea, b, eb, &GL10) * la * lb;
    }
    let sin = u.cross(v).length();
    if sin < PARALLEL_SIN {
        c * parallel_pair(a - b, la, lb, u, c)
    } else {
        c * skew_pair(a - b, la, lb, u, v, c)
    }
}

/// The mean of ln |x - y| over x on edge a and y on edge b (each from a corner along an
/// edge vector) by the tensor Gauss-Legendre rule with the symmetric `nodes`.
fn tensor_gauss(a: DVec3, ea: DVec3, b: DVec3, eb: DVec3, nodes: &[(f64, f64)]) -> f64 {
    let (ca, cb) = (a + 0.5 * ea, b + 0.5 * eb);
    let (ha, hb) = (0.5 * ea, 0.5 * eb);
    let mut sum = 0.0;
    for &(xs, ws) in nodes {
        for sign_s in [-1.0, 1.0] {
            let x = ca + ha * (sign_s * xs);
            let mut inner = 0.0;
            for &(xt, wt) in nodes {
                inner += wt
                    * ((x - cb - hb * xt).length_squared().ln()
                        + (x - cb + hb * xt).length_squared().ln());
            }
            sum += ws * inner;
        }
    }
    // Weights sum to 2 per direction, ln |d| = ln |d|^2 / 2.
    sum / 8.0
}

/// The second antiderivative of z -> ln sqrt(z^2 + h^2), less terms linear in z (they cancel
/// in the four-term sum).
fn second_antiderivative(z: f64, h: f64) -> f64 {
    let r2 = z * z + h * h;
    let mut out = -0.75 * z * z;
    if r2 > 0.0 {
        out += 0.25 * (z * z - h * h) * r2.ln();
    }
    if h > 0.0 {
        out += h * z * (z / h).atan();
    }
    out
}

/// `int int ln |d + s u - t v| dt ds` for parallel edges, v = sign(c) u, s in [0, la],
/// t in [0, lb], d = a - b.
fn parallel_pair(d: DVec3, la: f64, lb: f64, u: DVec3, c: f64) -> f64 {
    let along = d.dot(u);
    let h = (d - along * u).length();
    let (x0, x1) = (along, along + la);
    let (y0, y1) = if c > 0.0 { (0.0, lb) } else { (-lb, 0.0) };
    let hh = |z| second_antiderivative(z, h);
    (hh(x1 - y0) - hh(x0 - y0)) - (hh(x1 - y1) - hh(x0 - y1))
}

/// `int_0^la int_0^lb ln |d + s u - t v| dt ds` for non-parallel edges: the inner integral in
/// closed form, the outer by adaptive Gauss-Kronrod on pieces split at the inner integral's
/// non-smooth points.
fn skew_pair(d: DVec3, la: f64, lb: f64, u: DVec3, v: DVec3, c: f64) -> f64 {
    let tau0 = d.dot(v);
    let perp0 = d - tau0 * v;
    let perp_u = u - c * v;
    // antiderivative(lb - tau, h) - antiderivative(-tau, h), with the two arc tangents
    // joined into one: atan(x) + atan(y) = atan2(x + y, 1 - x y), here with x + y > 0.
    let inner = |s: f64| {
        let tau = tau0 + s * c;
        let h = (perp0 + s * perp_u).length();
        let (z1, z0) = (lb - tau, -tau);
        let (r1, r0) = (z1 * z1 + h * h, z0 * z0 + h * h);
        let mut out = h * (lb * h).atan2(h * h - tau * z1) - lb;
        if r1 > 0.0 {
            out += 0.5 * z1 * r1.ln();
        }
        if r0 > 0.0 {
            out -= 0.5 * z0 * r0.ln();
        }
        out
    };
    // The inner integral is analytic in s except where |a + s u - b - t v| vanishes for
    // some t in [0, lb]: about the point of line a closest to line b (at distance
    // h_min / sin from the real axis) and the points closest to b's two ends (at their
    // distances from line a). Cut the outer interval at those that come nearer than
    // `NEAR` la, so that they lie at piece ends, where bisection converges fast; farther
    // ones leave Gauss-Kronrod a wide enough ellipse of analyticity.
    const NEAR: f64 = 0.25;
    let sin2 = perp_u.length_squared();
    let closest = -perp0.dot(perp_u) / sin2;
    let h_min = (perp0 + closest * perp_u).length();
    let along = -d.dot(u);
    let end_dist = |s: f64, t: f64| (d + s * u - t * v).length();
    let near = |s: f64, dist: f64| {
        if dist <= NEAR * la {
            s
        } else {
            f64::NAN
        }
    };
    // Breakpoints (s, near a singularity): the ends, and the near points clamped into
    // [0, la]; one at an end marks that end.
    let min_piece = 1e-12 * la;
    let mut points = [(0.0, false); 5];
    points[1] = (la, false);
    let mut count = 2;
    let near_points = [
        near(closest, h_min / sin2.sqrt()),
        near(along, end_dist(along, 0.0)),
        near(along + lb * c, end_dist(along + lb * c, lb)),
    ];
    for s in near_points {
        if !s.is_finite() {
            continue;
        }
        let s = s.clamp(0.0, la);
        if s <= min_piece {
            points[0].1 = true;
        } else if s >= la - min_piece {
            points[1].1 = true;
        } else {
            points[count] = (s, true);
            count += 1;
        }
    }
    let points = &mut points[..count];
    points.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let mut total = 0.0;
    for pair in points.windows(2) {
        let ((lo, near_lo), (hi, near_hi)) = (pair[0], pair[1]);
        if hi - lo <= min_piece {
            continue;
        }
        total += if near_lo || near_hi {
            // Grade towards both ends: s = lo + w phi(x), phi(x) = x^3 / (x^3 + (1 - x)^3),
            // analytic on [0, 1] with phi' ~ 3 x^2 at the ends, which turns an s ln s
            // singularity there into one like x^5 ln x that the rule integrates at once.
            let w = hi - lo;
            let graded = |x: f64| {
                let (x3, y3) = (x * x * x, (1.0 - x) * (1.0 - x) * (1.0 - x));
                let den = x3 + y3;
                let dphi = 3.0 * x * x * (1.0 - x) * (1.0 - x) / (den * den);
                inner(lo + w * x3 / den) * w * dphi
            };
            adaptive_gk21(&graded, 0.0, 1.0, lb * w)
        } else {
            adaptive_gk21(&inner, lo, hi, lb)
        };
    }
    total
}

#[cfg(test)]
mod tests {
    use super::super::point_to_polygon;
    use super::super::test_util::*;
    use super::*;
    use crate::form_factor::reference;

    #[test]
    fn exact_opposed_unit_squares() {
        let f = polygon_to_polygon(&floor(), &ceiling(1.0, 1.0, 1.0));
        let want = reference::parallel_rectangles(1.0, 1.0, 1.0);
        eprintln!("opposed squares {f:.16} rel {:e}", rel_err(f, want));
        assert!((want - 0.1998248957).abs() < 1e-10);
        assert!(rel_err(f, want) < EXACT);
    }

    #[test]
    fn exact_opposed_rectangles() {
        let rect = vec![v(0., 0., 0.), v(2., 0., 0.), v(2., 1., 0.), v(0., 1., 0.)];
        let f = polygon_to_polygon(&rect, &ceiling(2.0, 1.0, 0.5));
        let want = reference::parallel_rectangles(2.0, 1.0, 0.5);
        eprintln!("opposed 2x1 at 0.5 {f:.16} rel {:e}", rel_err(f, want));
        assert!(rel_err(f, want) < EXACT);
    }

    // The opposed squares turned 45 degrees about their common axis, then the whole pair
    // turned and moved arbitrarily: no edge is axis-aligned or perpendicular to another, so
    // every edge pair takes the quadrature path; the value is unchanged.
    #[test]
    fn exact_rotated_opposed_squares() {
        let axis = v(1., 2., 3.).normalize();
        let place = |p: DVec3| {
            let p = rotate(p - v(0.5, 0.5, 0.), DVec3::Z, PI / 4.0);
            rotate(p, axis, 0.7) + v(3., -2., 5.)
        };
        let a: Vec<DVec3> = floor().into_iter().map(place).collect();
        let b: Vec<DVec3> = ceiling(1.0, 1.0, 1.0).into_iter().map(place).collect();
        let want = reference::parallel_rectangles(1.0, 1.0, 1.0);
        let f = polygon_to_polygon(&a, &b);
        eprintln!("rotated opposed squares {f:.16} rel {:e}", rel_err(f, want));
        assert!(rel_err(f, want) < EXACT);
        // Only the top turned (by 45 degrees against the bottom): a different, smaller value.
        let twisted: Vec<DVec3> = ceiling(1.0, 1.0, 1.0)
            .into_iter()
            .map(|p| rotate(p - v(0.5, 0.5, 0.), DVec3::Z, PI / 4.0) + v(0.5, 0.5, 0.))
            .collect();
        let g = polygon_to_polygon(&floor(), &twisted);
        assert!(g < f && g > 0.9 * f, "{g}");
    }

    #[test]
    fn exact_perpendicular_squares_sharing_an_edge() {
        let f = polygon_to_polygon(&floor(), &wall(0.0, 1.0, 1.0));
        let want = reference::perpendicular_rectangles(1.0, 1.0, 1.0);
        eprintln!("perpendicular squares {f:.16} rel {:e}", rel_err(f, want));
        assert!((want - 0.2000437761).abs() < 1e-10);
        assert!(rel_err(f, want) < EXACT);
        // And the other way round, which is the same by symmetry.
        let back = polygon_to_polygon(&wall(0.0, 1.0, 1.0), &floor());
        assert!(rel_err(back, want) < EXACT);
    }

    #[test]
    fn exact_perpendicular_rectangles() {
        for (w, h, l) in [(2.0, 0.5, 1.5), (0.3, 4.0, 1.0), (1.0, 1.0, 7.0)] {
            let base = vec![v(0., 0., 0.), v(w, 0., 0.), v(w, l, 0.), v(0., l, 0.)];
            let f = polygon_to_polygon(&base, &wall(0.0, l, h));
            let want = reference::perpendicular_rectangles(w, h, l);
            eprintln!(
                "perpendicular {w} {h} {l}: {f:.16} rel {:e}",
                rel_err(f, want)
            );
            assert!(rel_err(f, want) < EXACT);
            let back = polygon_to_polygon(&wall(0.0, l, h), &base);
            let want = reference::perpendicular_rectangles(h, w, l);
            assert!(rel_err(back, want) < EXACT);
        }
    }

    // Touching at one corner, with collinear edges: the floor [0,1]^2 and the wall over
    // y in [1, 2]. The expected value is Howell's C-14 by superposition: split a 1 x 2 floor
    // and a 1 x 2 wall sharing their long edge into unit squares A1, A2 and W1, W2; then
    // 2 F(1,1,2) = F_A1W1 + F_A1W2 + F_A2W1 + F_A2W2 with F_A1W1 = F_A2W2 = F(1,1,1) and
    // F_A1W2 = F_A2W1 by symmetry, so F_A1W2 = F(1,1,2) - F(1,1,1).
    #[test]
    fn exact_perpendicular_squares_sharing_a_corner() {
        let f = polygon_to_polygon(&floor(), &wall(1.0, 2.0, 1.0));
        let want = reference::perpendicular_rectangles(1.0, 1.0, 2.0)
            - reference::perpendicular_rectangles(1.0, 1.0, 1.0);
        eprintln!("corner, collinear edges {f:.16} rel {:e}", rel_err(f, want));
        assert!(rel_err(f, want) < EXACT);
    }

    // Touching at one corner, no two edges collinear or perpendicular at it: the floor and a
    // unit square wall through the z axis along (-1, 1, 0) / sqrt 2, facing (1, 1, 0) / sqrt 2.
    // No closed form; the expected value integrates Lambert's formula (`point_to_polygon`,
    // an independent formula) over the floor with Gauss-Legendre on rectangles graded towards
    // the touching corner, where alone the integrand is not smooth. The graded rule agrees
    // with itself to about 1e-15 between 16 and 24 points per direction (asserted: 1e-11),
    // so the 1e-9 target is checked with room to spare.
    #[test]
    fn exact_perpendicular_squares_sharing_a_corner_at_an_angle() {
        let d = v(-1., 1., 0.) / 2f64.sqrt();
        let w = vec![v(0., 0., 0.), d, d + v(0., 0., 1.), v(0., 0., 1.)];
        let n = polygon_normal(&w).unwrap();
        assert!((n - v(1., 1., 0.) / 2f64.sqrt()).length() < 1e-15);
        let f = polygon_to_polygon(&floor(), &w);
        let lambert = |p: DVec3| point_to_polygon(p, DVec3::Z, &w);
        let want = graded_corner_integral(1.0, 1.0, 24, &lambert);
        let coarser = graded_corner_integral(1.0, 1.0, 16, &lambert);
        eprintln!(
            "corner at an angle {f:.16} Lambert {want:.16} rel {:e} (quadrature {:e})",
            rel_err(f, want),
            rel_err(coarser, want)
        );
        assert!(rel_err(coarser, want) < 1e-11);
        assert!(rel_err(f, want) < EXACT);
        // Reciprocity across the singular corner.
        let back = polygon_to_polygon(&w, &floor());
        assert!((f - back).abs() < 1e-12 * f);
    }

    // A wall reaching below the floor's plane: only its upper half sees the floor, so
    // F_floor,wall is Howell's C-14 for the upper half, and F_wall,floor is half of C-14
    // (the lower half emits too, only not towards the floor). Exercises both clips.
    #[test]
    fn exact_partly_facing_wall() {
        let deep = vec![v(0., 0., -1.), v(0., 1., -1.), v(0., 1., 1.), v(0., 0., 1.)];
        let want = reference::perpendicular_rectangles(1.0, 1.0, 1.0);
        let f = polygon_to_polygon(&floor(), &deep);
        let back = polygon_to_polygon(&deep, &floor());
        eprintln!("partly facing {f:.16} {back:.16}");
        assert!(rel_err(f, want) < EXACT);
        assert!(rel_err(back, 0.5 * want) < EXACT);
        // The floor extended behind the wall (x < 0): the same again.
        let wide = vec![v(-1., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(-1., 1., 0.)];
        let upper = wall(0.0, 1.0, 1.0);
        assert!(rel_err(polygon_to_polygon(&wide, &upper), 0.5 * want) < EXACT);
        assert!(rel_err(polygon_to_polygon(&upper, &wide), want) < EXACT);
    }

    // Nearly touching: the wall lifted by a small gap, or moved off the floor's edge, and
    // a tilted triangle whose corner touches the floor's edge mid-way (a T contact,
    // checked against Lambert's formula integrated over the floor as above). These
    // put near-singularities inside the outer intervals. F must approach the touching
    // value continuously (the gap changes it by O(gap ln gap)) and stay reciprocal.
    #[test]
    fn exact_nearly_touching() {
        let want = reference::perpendicular_rectangles(1.0, 1.0, 1.0);
        for gap in [1e-3, 1e-6, 1e-9] {
            for offset in [v(0., 0., gap), v(-gap, 0., 0.), v(-gap, 0.3, gap)] {
                let w: Vec<DVec3> = wall(0.0, 1.0, 1.0).iter().map(|&p| p + offset).collect();
                let f = polygon_to_polygon(&floor(), &w);
                let back = polygon_to_polygon(&w, &floor());
                assert!((f - back).abs() < 1e-13 * f, "{gap} {offset}: {f} {back}");
                let bound = if offset.y == 0.0 {
                    20.0 * gap * (1.0 - gap.ln())
                } else {
                    0.1
                };
                assert!(f < want && want - f < bound, "{gap} {offset}: {f}");
            }
        }
        // In the plane 0.8 y + 0.5 z = 0, which holds the floor's edge y = 0: the whole floor
        // is in front of it and it is above the floor.
        let tri = vec![v(0.5, 0., 0.), v(0.1, -0.5, 0.8), v(0.9, -0.5, 0.8)];
        let n = polygon_normal(&tri).unwrap();
        assert!((n - v(0., 0.8, 0.5).normalize()).length() < 1e-15);
        let (a_tri, a_floor) = (area_vector(&tri).length(), 1.0);
        let f = polygon_to_polygon(&floor(), &tri);
        let back = polygon_to_polygon(&tri, &floor());
        assert!(
            f > 0.0 && (a_floor * f - a_tri * back).abs() < 1e-13 * f,
            "{f} {back}"
        );
        let lambert = |p: DVec3| point_to_polygon(p, DVec3::Z, &tri);
        // Graded towards the contact at (0.5, 0): two halves of the floor, each graded
        // towards its corner there.
        let right = graded_corner_integral(0.5, 1.0, 24, &|p| lambert(v(0.5 + p.x, p.y, 0.)));
        let left = graded_corner_integral(0.5, 1.0, 24, &|p| lambert(v(0.5 - p.x, p.y, 0.)));
        eprintln!("T contact {f:.16} Lambert {:.16}", left + right);
        assert!(rel_err(f, left + right) < EXACT);
    }

    #[test]
    fn exact_coplanar_is_zero() {
        let beside: Vec<DVec3> = floor().into_iter().map(|p| p + v(1., 0., 0.)).collect();
        assert_eq!(polygon_to_polygon(&floor(), &beside), 0.0);
        let overlapping: Vec<DVec3> = floor().into_iter().map(|p| p + v(0.5, 0.3, 0.)).collect();
        assert_eq!(polygon_to_polygon(&floor(), &overlapping), 0.0);
        assert_eq!(polygon_to_polygon(&floor(), &floor()), 0.0);
        // Facing away (the ceiling turned to face up) and wholly behind.
        let up: Vec<DVec3> = ceiling(1.0, 1.0, 1.0).into_iter().rev().collect();
        assert_eq!(polygon_to_polygon(&floor(), &up), 0.0);
        let below: Vec<DVec3> = ceiling(1.0, 1.0, -1.0);
        assert_eq!(polygon_to_polygon(&floor(), &below), 0.0);
    }

    // Regular 256-gons are not discs, but the coupling A_1 F_12 only grows with either
    // polygon, so it lies between the couplings of the inscribed and circumscribed coaxial
    // discs (Howell C-41): a bracket of relative width about 2 (pi/256)^2 = 3e-4.
    #[test]
    fn exact_coaxial_256_gons_between_discs() {
        let n = 256;
        let (r, h) = (1.0, 1.0);
        let gon = |z: f64, sense: f64| -> Vec<DVec3> {
            (0..n)
                .map(|k| {
                    let t = sense * 2.0 * PI * k as f64 / n as f64;
                    v(r * t.cos(), r * t.sin(), z)
                })
                .collect()
        };
        let (bottom, top) = (gon(0.0, 1.0), gon(h, -1.0));
        let coupling = polygon_to_polygon(&bottom, &top) * area_vector(&bottom).length();
        let disc = |rr: f64| PI * rr * rr * reference::coaxial_discs(rr, rr, h);
        let (inner, outer) = (disc(r * (PI / n as f64).cos()), disc(r));
        eprintln!("256-gons: {inner:.12} <= {coupling:.12} <= {outer:.12}");
        assert!(inner < coupling && coupling < outer);
    }

    // Reciprocity A_1 F_12 = A_2 F_21 for random convex pairs, many only partly facing (so
    // both clips are exercised): the edge-pair sum is symmetric, but the outer quadrature runs
    // over polygon 1's edges one way and over polygon 2's the other, so this checks the
    // quadrature. Tolerance: 1e-12 relative, plus 1e-15 of the smaller area absolute. The
    // terms of the contour sum are of the order of the areas whatever F is, so rounding
    // leaves an absolute error of about 1e-16 A (measured: below 1e-16 here); only couplings
    // below 1e-4 A, from pairs clipped to slivers, need the absolute part.
    #[test]
    fn exact_reciprocity_random_pairs() {
        let mut rng = Rng(20240611);
        let mut substantial = 0;
        for _ in 0..200 {
            let n1 = rng.unit();
            let p1 = rng.convex(DVec3::ZERO, n1);
            let c2 = n1 * rng.range(-0.5, 2.0) + rng.unit() * rng.range(0.0, 2.0);
            let n2 = rng.unit();
            let p2 = rng.convex(c2, n2);
            let (a1, a2) = (area_vector(&p1).length(), area_vector(&p2).length());
            let g12 = polygon_to_polygon(&p1, &p2) * a1;
            let g21 = polygon_to_polygon(&p2, &p1) * a2;
            let big = g12.max(g21);
            if big > 1e-4 * a1.min(a2) {
                substantial += 1;
            }
            assert!(
                (g12 - g21).abs() <= 1e-12 * big + 1e-15 * a1.min(a2),
                "{g12} {g21}\n{p1:?}\n{p2:?}"
            );
        }
        assert!(substantial > 50, "{substantial}");
    }

    // Distant pairs: the contour sum cancels (terms of order A ln r, result of order
    // A^2 / d^2), so accuracy falls with the distance d over the size L, as about
    // 3e-17 (d / L)^2 (measured: 1e-15 at d = 10, 3e-13 at 100, 3e-11 at 1000). Against
    // Lambert's formula integrated over the emitter by 32 x 32 Gauss-Legendre (smooth).
    #[test]
    fn exact_distant_pairs() {
        let a = vec![v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0.2, 1., 0.)];
        for (d, tol) in [(1.0, EXACT), (10.0, EXACT), (100.0, EXACT), (1000.0, 1e-8)] {
            let b: Vec<DVec3> = [v(0., 0., d), v(0., 1., d), v(1.2, 1., d), v(1., 0., d)]
                .iter()
                .map(|&p| p + v(0.3 * d, 0.1 * d, 0.))
                .collect();
            let f = polygon_to_polygon(&a, &b);
            let lambert = |p: DVec3| point_to_polygon(p, DVec3::Z, &b);
            let want = quad_integral(&a, 32, &lambert) / area_vector(&a).length();
            eprintln!("distant d = {d}: {f:e} rel {:e}", rel_err(f, want));
            assert!(rel_err(f, want) < tol);
        }
    }

    // A general pair of quads (a trapezoid and a skewed quad, tilted and offset, partly
    // facing nothing in particular): against reciprocity, against Lambert's formula integrated
    // over quad 1 by 32 x 32 Gauss-Legendre (smooth: the quads are apart; agrees with 24 x 24
    // to 1e-14), and against the brute-force area integral, whose midpoint rule with a
    // disc-regularised kernel converges as 1/k^2: the difference between k = 64 and k = 128 is
    // three times the k = 128 error, so the exact value must lie within that difference.
    #[test]
    fn exact_general_quads() {
        let q1 = vec![
            v(0., 0., 0.),
            v(2., 0., 0.),
            v(1.5, 1., 0.),
            v(0.3, 1.2, 0.),
        ];
        let q2 = {
            let base = [
                v(0., 0., 0.),
                v(1., 0.2, 0.),
                v(1.3, 1.1, 0.),
                v(-0.2, 0.8, 0.),
            ];
            base.iter()
                .rev()
                .map(|&p| rotate(p, v(1., 1., 0.).normalize(), 0.5) + v(0.4, 0.2, 0.9))
                .collect::<Vec<_>>()
        };
        let (a1, a2) = (area_vector(&q1).length(), area_vector(&q2).length());
        let f = polygon_to_polygon(&q1, &q2);
        let back = polygon_to_polygon(&q2, &q1);
        assert!((a1 * f - a2 * back).abs() < 1e-13 * a1 * f);
        let lambert = |p: DVec3| point_to_polygon(p, DVec3::Z, &q2);
        let want = quad_integral(&q1, 32, &lambert) / a1;
        let coarser = quad_integral(&q1, 24, &lambert) / a1;
        let k64 = crate::form_factor::area_integral_pair(&q1, &q2, 64);
        let k128 = crate::form_factor::area_integral_pair(&q1, &q2, 128);
        eprintln!(
            "general quads {f:.16} Lambert {want:.16} rel {:e} (quadrature {:e}); area k=64 \
             {k64:.10} k=128 {k128:.10}",
            rel_err(f, want),
            rel_err(coarser, want)
        );
        assert!(rel_err(coarser, want) < 1e-12);
        assert!(rel_err(f, want) < EXACT);
        assert!((f - k128).abs() < (k128 - k64).abs());
    }
}
