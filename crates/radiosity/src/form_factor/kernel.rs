//! Form-factor kernels evaluated at a few points of a patch, for estimates that need neither
//! a mesh nor a ray: the four quarter points of a triangle or quadrilateral, and the mean
//! over them of Lambert's point-to-polygon form factor, of the point-to-point kernel, and of
//! the cosine over r^2 towards a point. The hierarchical solver
//! ([`crate::solve::solve_hierarchical`]) estimates its links with them.

use glam::DVec3;

use super::exact::point_to_polygon;

/// Four points of a triangle or a planar convex quadrilateral, the centres of its four
/// quarters (at its bilinear or edge midpoints: equal areas, an equal-weight quadrature).
pub(crate) fn quarter_points(p: &[DVec3]) -> [DVec3; 4] {
    if p.len() == 4 {
        [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75)]
            .map(|(u, v)| crate::mesh::bilinear(p, u, v))
    } else {
        [
            (4.0 * p[0] + p[1] + p[2]) / 6.0,
            (p[0] + 4.0 * p[1] + p[2]) / 6.0,
            (p[0] + p[1] + 4.0 * p[2]) / 6.0,
            (p[0] + p[1] + p[2]) / 3.0,
        ]
    }
}

/// The mean of Lambert's point-to-polygon form factor from the four quarter points of
/// `receiver` to `source`: an estimate of the area-averaged F of the receiver. The point
/// value is Lambert's formula ([`super::exact::point_to_polygon`]; Lambert 1760; Baum,
/// Rushmeier and Winget 1989, eq. 4).
pub(crate) fn mean_point_to_polygon(receiver: &[DVec3], normal: DVec3, source: &[DVec3]) -> f64 {
    quarter_points(receiver)
        .iter()
        .map(|&x| point_to_polygon(x, normal, source))
        .sum::<f64>()
        / 4.0
}

/// The mean over the quarter points x of `receiver` (normal `n`) of the form factor to
/// `source` (normal `m`, area `area`) by the point-to-point kernel from its four quarter
/// points y, each standing for a quarter of its area: sum_y (A / 4) cos+ cos+ / (pi r^2)
/// (the midpoint rule on both patches). For pairs more than three times the sum of their
/// radii apart it is within a few parts in a thousand of the exact value, at a fraction of
/// the cost of Lambert's formula (no arc tangents). One point for the source (the
/// point-to-disc formula at its centre, used before) was biased low: where the source
/// straddles the receiver's plane its centre may lie behind it, and the Cornell box's
/// tilted block faces came out 8 % dark (0.5 % of all power lost). The kernel is the
/// integrand of the double area integral (paper figure 4; Goral, Torrance, Greenberg and
/// Battaile 1984), the differential form factor cos cos dA / (pi r^2) between two points.
pub(crate) fn mean_point_pairs(
    receiver: &[DVec3],
    n: DVec3,
    source: &[DVec3],
    m: DVec3,
    area: f64,
) -> f64 {
    let ys = quarter_points(source);
    let weight = area / (4.0 * std::f64::consts::PI);
    let sum: f64 = quarter_points(receiver)
        .iter()
        .flat_map(|&x| ys.iter().map(move |&y| (x, y)))
        .map(|(x, y)| {
            let v = y - x;
            let r2 = v.length_squared();
            // cos_p cos_q / r^2 with both cosines from the unnormalised v.
            let cos_p = n.dot(v).max(0.0);
            let cos_q = (-m.dot(v)).max(0.0);
            weight * cos_p * cos_q / (r2 * r2)
        })
        .sum();
    sum / 4.0
}

/// The mean over the quarter points x of `poly` of cos+(n, c - x) / |c - x|^2: the
/// irradiance at a patch from a point source of unit intensity at `c`, I cos / r^2 (Lambert's
/// inverse-square cosine law), as a cluster treated as a point lights a patch (Smits, Arvo
/// and Greenberg 1994; Sillion 1995).
pub(crate) fn mean_cos_over_r2(poly: &[DVec3], n: DVec3, c: DVec3) -> f64 {
    quarter_points(poly)
        .iter()
        .map(|&x| {
            let v = c - x;
            let r2 = v.length_squared();
            if r2 == 0.0 {
                0.0
            } else {
                n.dot(v).max(0.0) / (r2 * r2.sqrt())
            }
        })
        .sum::<f64>()
        / 4.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry;

    #[test]
    fn far_estimate_against_the_exact_form_factor() {
        use crate::form_factor::exact::polygon_to_polygon;
        let v = DVec3::new;
        // Receiver: the unit square in the plane x = 0, facing +x.
        let p = [v(0., 0., 0.), v(0., 1., 0.), v(0., 1., 1.), v(0., 0., 1.)];
        let np = DVec3::X;
        let quad = |c: DVec3, a: DVec3, b: DVec3| [c - a - b, c + a - b, c + a + b, c - a + b];
        let cases = [
            // Facing, 5 units in front: the midpoint rule's error, O((R / r)^2), is
            // measured at 6.4e-3.
            (
                quad(v(5., 0.5, 0.5), v(0., 0., 0.5), v(0., 0.5, 0.)),
                -DVec3::X,
                0.01,
            ),
            // Perpendicular, above and in front: measured 3.9e-3.
            (
                quad(v(3., 4., 0.5), v(0.5, 0., 0.), v(0., 0., 0.5)),
                -DVec3::Y,
                0.01,
            ),
            // Straddling the receiver's plane (half of it behind): its centre lies in the
            // plane, where a one-point source (the point-to-disc formula used before)
            // gives 0; two of its four quarter points are in front: measured 4.2e-3.
            (
                quad(v(0., 5., 0.5), v(0.5, 0., 0.), v(0., 0., 0.5)),
                -DVec3::Y,
                0.01,
            ),
        ];
        for (q, nq, tol) in cases {
            // Counter-clockwise about its normal, as the exact formula wants.
            let q: Vec<DVec3> = if geometry::polygon_normal(&q).unwrap().dot(nq) > 0.0 {
                q.to_vec()
            } else {
                q.iter().rev().copied().collect()
            };
            let r = geometry::vertex_mean(&q).distance(geometry::vertex_mean(&p));
            assert!(r > 3.0 * 2.0 * 0.5f64.sqrt(), "not a far pair: {r}");
            let exact = polygon_to_polygon(&p, &q);
            let got = mean_point_pairs(&p, np, &q, nq, 1.0);
            let rel = (got - exact).abs() / exact;
            eprintln!("exact {exact:.6e} estimate {got:.6e} relative error {rel:.2e}");
            assert!(rel < tol, "exact {exact:e} estimate {got:e}");
        }
    }
}
