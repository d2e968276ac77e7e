//! Closed forms and quadratures for reference illuminances.
//!
//! Conventions: positions in metres, luminance in cd/m^2, intensity in cd, illuminance in
//! lux (lm/m^2). A Lambertian emitter of luminance `L` has exitance `pi L`.

use glam::{DVec2, DVec3};

/// Illuminance at `p` (unit normal `n`) from a Lambertian polygon of luminance `luminance`,
/// unoccluded: `L * pi * F`, with the point-to-polygon form factor `F` from Lambert's
/// contour integral, `F = 1/(2 pi) sum_i beta_i n . unit(R_i x R_(i+1))` (Baum, Rushmeier and
/// Winget 1989, eq. 1; Lambert 1760). The polygon is first clipped to the half-space in front
/// of `p` (`n . (x - p) >= 0`), so a polygon that straddles the point's tangent plane
/// counts only its visible part. Either winding gives the same (positive) value.
pub fn polygon_illuminance(p: DVec3, n: DVec3, polygon: &[DVec3], luminance: f64) -> f64 {
    luminance * std::f64::consts::PI * point_polygon_factor(p, n, polygon)
}

/// The form factor from a differential area at `p` (unit normal `n`) to a polygon: the
/// fraction of the light a Lambertian patch at `p` sends out that lands on the polygon, and
/// `E = pi L F` for a polygon of luminance `L`. See [`polygon_illuminance`].
pub fn point_polygon_factor(p: DVec3, n: DVec3, polygon: &[DVec3]) -> f64 {
    let clipped = clip_to_half_space(polygon, p, n);
    let count = clipped.len();
    if count < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..count {
        let a = clipped[i] - p;
        let b = clipped[(i + 1) % count] - p;
        let cross = a.cross(b);
        let length = cross.length();
        if length == 0.0 {
            continue;
        }
        let angle = length.atan2(a.dot(b));
        sum += angle * n.dot(cross / length);
    }
    let factor = (sum / (2.0 * std::f64::consts::PI)).abs();
    // A polygon seen edge-on (in the point's own plane) has no form factor; the contour sum
    // leaves rounding of about 1e-13 there.
    if factor < 1e-12 {
        0.0
    } else {
        factor
    }
}

/// The polygon's part where `n . (x - p) >= 0` (Sutherland-Hodgman against one plane).
fn clip_to_half_space(polygon: &[DVec3], p: DVec3, n: DVec3) -> Vec<DVec3> {
    let side = |x: DVec3| n.dot(x - p);
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for i in 0..polygon.len() {
        let a = polygon[i];
        let b = polygon[(i + 1) % polygon.len()];
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            out.push(a + (b - a) * (sa / (sa - sb)));
        }
    }
    out
}

/// Form factor from a differential area at a corner of a parallel rectangle `a` by `b` at
/// distance `c`, facing it: the textbook corner formula (Howell, *A catalog of radiation
/// heat transfer configuration factors*, B-3), an independent check of
/// [`point_polygon_factor`].
pub fn corner_parallel_rectangle_factor(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton's method on the Legendre
/// polynomial, Numerical Recipes `gauleg`), exact for polynomials of degree 2n - 1.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut rule = vec![(0.0, 0.0); n];
    let m = n.div_ceil(2);
    for i in 0..m {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            let (mut p1, mut p2) = (1.0, 0.0);
            for j in 0..n {
                let p3 = p2;
                p2 = p1;
                p1 = ((2 * j + 1) as f64 * z * p2 - j as f64 * p3) / (j + 1) as f64;
            }
            derivative = n as f64 * (z * p1 - p2) / (z * z - 1.0);
            let step = p1 / derivative;
            z -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        let weight = 2.0 / ((1.0 - z * z) * derivative * derivative);
        rule[i] = (-z, weight);
        rule[n - 1 - i] = (z, weight);
    }
    rule
}

/// `∫ f` over a convex polygon of the plane (counter-clockwise or not), by a fan of
/// triangles, each by the collapsed-square (Duffy) Gauss-Legendre rule of `n` by `n`
/// points: smooth integrands converge exponentially in `n`.
pub fn integrate_convex(polygon: &[DVec2], n: usize, f: &impl Fn(DVec2) -> f64) -> f64 {
    if polygon.len() < 3 {
        return 0.0;
    }
    let rule = gauss_legendre(n);
    let mut total = 0.0;
    for k in 1..polygon.len() - 1 {
        let (a, b, c) = (polygon[0], polygon[k], polygon[k + 1]);
        let twice_area = ((b - a).perp_dot(c - a)).abs();
        if twice_area == 0.0 {
            continue;
        }
        for &(u, wu) in &rule {
            let s = 0.5 * (u + 1.0);
            for &(v, wv) in &rule {
                let t = 0.5 * (v + 1.0);
                let x = a + (b - a) * s + (c - b) * (s * t);
                // d(x)/d(s, t) = twice_area * s; the two half-interval maps give 1/4.
                total += 0.25 * wu * wv * twice_area * s * f(x);
            }
        }
    }
    total
}

/// The part of convex `subject` inside convex `clip` (Sutherland-Hodgman); both
/// counter-clockwise.
pub fn clip_convex(subject: &[DVec2], clip: &[DVec2]) -> Vec<DVec2> {
    let mut out = subject.to_vec();
    for i in 0..clip.len() {
        if out.is_empty() {
            break;
        }
        let (a, b) = (clip[i], clip[(i + 1) % clip.len()]);
        let inside = |p: DVec2| (b - a).perp_dot(p - a);
        let input = std::mem::take(&mut out);
        for j in 0..input.len() {
            let (p, q) = (input[j], input[(j + 1) % input.len()]);
            let (sp, sq) = (inside(p), inside(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                out.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
    }
    out
}

/// `polygon` made counter-clockwise.
pub fn counter_clockwise(mut polygon: Vec<DVec2>) -> Vec<DVec2> {
    let twice_area: f64 = (0..polygon.len())
        .map(|i| polygon[i].perp_dot(polygon[(i + 1) % polygon.len()]))
        .sum();
    if twice_area < 0.0 {
        polygon.reverse();
    }
    polygon
}

/// The shadow on the plane z = 0 of a convex polygon lit from point `from`: its central
/// projection from `from`, counter-clockwise. Every corner must lie below `from`.
pub fn shadow_on_floor(from: DVec3, polygon: &[DVec3]) -> Vec<DVec2> {
    let projected = polygon
        .iter()
        .map(|&v| {
            assert!(v.z < from.z, "a corner at or above the projection centre");
            let x = from + (v - from) * (from.z / (from.z - v.z));
            DVec2::new(x.x, x.y)
        })
        .collect();
    counter_clockwise(projected)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use std::f64::consts::PI;

    #[test]
    fn lambert_contour_matches_the_corner_formula_and_superposition() {
        // A unit square one unit above a corner point: F = 0.13853 (Howell B-3 tables).
        let square = [
            dvec3(0., 0., 1.),
            dvec3(1., 0., 1.),
            dvec3(1., 1., 1.),
            dvec3(0., 1., 1.),
        ];
        let f = point_polygon_factor(DVec3::ZERO, DVec3::Z, &square);
        assert!(
            (f - corner_parallel_rectangle_factor(1.0, 1.0, 1.0)).abs() < 1e-14,
            "{f}"
        );
        assert!((f - 0.138_53).abs() < 1e-5, "{f}");
        // Below the centre of a 2 x 3 rectangle at height 1.5: four corner rectangles.
        let rect = [
            dvec3(-1., -1.5, 1.5),
            dvec3(1., -1.5, 1.5),
            dvec3(1., 1.5, 1.5),
            dvec3(-1., 1.5, 1.5),
        ];
        let f = point_polygon_factor(DVec3::ZERO, DVec3::Z, &rect);
        let corners = 4.0 * corner_parallel_rectangle_factor(1.0, 1.5, 1.5);
        assert!((f - corners).abs() < 1e-14, "{f} against {corners}");
        // An infinite plane above gives 1; a large one nearly so. A polygon behind gives 0.
        let big = [
            dvec3(-1e6, -1e6, 1.),
            dvec3(1e6, -1e6, 1.),
            dvec3(1e6, 1e6, 1.),
            dvec3(-1e6, 1e6, 1.),
        ];
        assert!((point_polygon_factor(DVec3::ZERO, DVec3::Z, &big) - 1.0).abs() < 1e-5);
        assert_eq!(point_polygon_factor(DVec3::ZERO, -DVec3::Z, &rect), 0.0);
        // Half of the big plane in front of a vertical normal: 1/2 (the half-space clip).
        let f = point_polygon_factor(DVec3::ZERO, DVec3::X, &big);
        assert!((f - 0.5).abs() < 1e-5, "{f}");
        assert!((polygon_illuminance(DVec3::ZERO, DVec3::Z, &big, 1.0) - PI).abs() < 1e-4);
    }

    #[test]
    fn gauss_rules_integrate_polynomials_and_smooth_functions() {
        for n in [1, 2, 5, 12, 24] {
            let rule = gauss_legendre(n);
            let sum: f64 = rule.iter().map(|r| r.1).sum();
            assert!((sum - 2.0).abs() < 1e-13, "n = {n}: weights sum to {sum}");
            let degree = 2 * n - 1;
            let moment: f64 = rule
                .iter()
                .map(|&(x, w)| w * x.powi(degree as i32 - 1))
                .sum();
            let exact = if (degree - 1) % 2 == 0 {
                2.0 / degree as f64
            } else {
                0.0
            };
            assert!((moment - exact).abs() < 1e-12, "n = {n}");
        }
        // x^2 y over the unit square split into a pentagon and a triangle: 1/6 in all.
        let square = [
            DVec2::new(0., 0.),
            DVec2::new(1., 0.),
            DVec2::new(1., 1.),
            DVec2::new(0., 1.),
        ];
        let f = |p: DVec2| p.x * p.x * p.y;
        assert!((integrate_convex(&square, 4, &f) - 1.0 / 6.0).abs() < 1e-14);
        // exp(x + y) over the triangle (0,0),(1,0),(0,1): ∫_0^1 s e^s ds = 1.
        let tri = [DVec2::new(0., 0.), DVec2::new(1., 0.), DVec2::new(0., 1.)];
        let g = |p: DVec2| (p.x + p.y).exp();
        assert!((integrate_convex(&tri, 12, &g) - 1.0).abs() < 1e-13);
    }

    #[test]
    fn clipping_and_shadows() {
        let square = [
            DVec2::new(0., 0.),
            DVec2::new(2., 0.),
            DVec2::new(2., 2.),
            DVec2::new(0., 2.),
        ];
        let shifted: Vec<DVec2> = square.iter().map(|&p| p + DVec2::new(1., 1.)).collect();
        let both = clip_convex(&square, &shifted);
        assert!((integrate_convex(&both, 2, &|_| 1.0) - 1.0).abs() < 1e-14);
        // A unit square at height 1 lit from height 2 above its corner: doubled in size.
        let panel = [
            dvec3(0., 0., 1.),
            dvec3(1., 0., 1.),
            dvec3(1., 1., 1.),
            dvec3(0., 1., 1.),
        ];
        let shadow = shadow_on_floor(dvec3(0., 0., 2.), &panel);
        assert!((integrate_convex(&shadow, 2, &|_| 1.0) - 4.0).abs() < 1e-13);
    }
}
