//! Exact unoccluded form factors between planar convex polygons, and from a differential
//! area to a polygon.
//!
//! # Polygon to polygon: the double contour integral
//!
//! Stokes' theorem applied twice turns the double area integral of the paper (figure 4) into
//! a double integral over the two boundaries (paper 2.3, figure 5; Sparrow 1963, "A new and
//! simpler formulation for radiative angle factors", J. Heat Transfer 85; Goral, Torrance,
//! Greenberg and Battaile 1984, "Modeling the interaction of light between diffuse surfaces",
//! SIGGRAPH 84, eq. 9):
//!
//! ```text
//! A_1 F_12 = 1/(2 pi) sum_{edges i of 1} sum_{edges j of 2} (u_i . v_j) I_ij,
//! I_ij     = int_0^{L_i} int_0^{L_j} ln |a_i + s u_i - b_j - t v_j| dt ds
//! ```
//!
//! with both polygons counter-clockwise about their own front normals, edge i running from
//! a_i along the unit vector u_i for a length L_i (likewise b_j, v_j, L_j for polygon 2). The
//! sign is +: with both polygons counter-clockwise about their own fronts and facing each
//! other the sum is positive, as the opposed unit squares (Howell C-11, +0.1998249) confirm
//! in the tests (facing squares run in opposite senses about a common axis, so parallel
//! edges nearer each other, with the smaller ln r, carry u . v = -1). Because each contour
//! is closed (sum of u_i L_i = 0), adding a constant to ln r changes nothing: lengths are
//! measured in units of a typical distance between the polygons' points (the root of the
//! squared distance between their corner means plus both corner spreads), so that ln r is
//! of order one for close pairs and near zero for distant ones, which keeps the terms, and
//! their cancellation, small.
//!
//! Each edge pair is integrated as follows (the route of the paper's section 2.3, finished):
//!
//! * **Perpendicular edges** (u . v = 0) contribute nothing.
//! * **Edges apart by more than the longer one** by tensor Gauss-Legendre on ln r itself
//!   (10 x 10 points, 6 x 6 beyond four lengths): ln r is analytic over both edges with its
//!   nearest complex singularity at least that far away, so the error is below 1e-15, and
//!   distant edges do not suffer the cancellation of the closed forms below.
//! * **Parallel edges** (including collinear ones: the shared edge of two polygons that touch)
//!   in closed form. With x along the common direction and h the distance between the lines,
//!   `g(z) = ln sqrt(z^2 + h^2)` has the second antiderivative
//!   `H(z) = (z^2 - h^2)/4 ln(z^2 + h^2) - 3 z^2 / 4 + h z atan(z / h)` and
//!   `I = H(x1 - y0) - H(x0 - y0) - H(x1 - y1) + H(x0 - y1)`; for h = 0 (collinear edges)
//!   `H(z) = z^2/2 ln|z| - 3 z^2 / 4`, finite where the edges overlap or touch, so the
//!   logarithmic singularity of a shared edge is integrated exactly.
//! * **Other edges**: the inner integral in closed form,
//!   `int_0^{L_j} ln r dt = G(L_j - tau(s)) - G(-tau(s))` with
//!   `G(z) = z/2 ln(z^2 + h^2) - z + h atan(z / h)`, tau(s) the foot of the point a + s u on
//!   line j and h(s) its distance from that line (the two arc tangents joined into one
//!   atan2); the outer integral over s by adaptive Gauss-Kronrod (10-21 points, QUADPACK's
//!   QK21 rule and error estimate: Piessens, de Doncker-Kapenga, Ueberhuber and Kahaner,
//!   *QUADPACK*, Springer 1983). The inner result is analytic in s except at complex s where
//!   the distance to some point of edge j vanishes: near the point of line i closest to
//!   line j (an |h| kink when the lines meet) and near the points closest to the ends of
//!   edge j (an s ln s singularity when edges share a vertex or coplanar edges cross). Where
//!   such a point comes within a quarter of the edge length, the outer interval is cut
//!   there, and each piece next to a cut is integrated in the variable x of
//!   `s = lo + w x^3 / (x^3 + (1 - x)^3)`, which clusters nodes at both ends and turns an
//!   s ln s singularity at an end into an x^5 ln x one; bisection does the rest.
//!
//! The closed form of Schroeder and Hanrahan 1993 ("On the form factor between two
//! polygons", SIGGRAPH 93), with dilogarithms for the skew edge pairs, is the fully analytic
//! alternative; the inner-closed-form route is simpler and, measured against Howell's closed
//! forms and against Lambert's formula integrated over the emitter in the tests, agrees to
//! about 1e-15 (3e-15 at worst).
//!
//! Distant pairs: the terms are of order A ln r and the result of order A^2 / d^2, so
//! rounding (the relative error of each computed distance) leaves a relative error of about
//! 3e-17 (d / L)^2 for polygons of size L a distance d apart: 3e-13 at d = 100 L, 3e-11 at
//! 1000 L.
//!
//! One-sided emission and reception: a point pair exchanges energy only when each point lies
//! in front of the other polygon's plane, and that region is a product set, so polygon 2 is
//! clipped to the half-space in front of polygon 1 and polygon 1 to the half-space in front
//! of polygon 2 (Sutherland and Hodgman 1974) before integrating. Coplanar polygons, and
//! polygons wholly behind each other, give 0.
//!
//! # Differential area to polygon: Lambert's formula
//!
//! ```text
//! F = -1/(2 pi) sum_e gamma_e n . (R_e x R_{e+1}) / |R_e x R_{e+1}|
//! ```
//!
//! (Lambert 1760; Baum, Rushmeier and Winget 1989, "Improving radiosity solutions through the
//! use of analytically determined form-factors", SIGGRAPH 89, eq. 4), R_e the vector from the
//! point to corner e and gamma_e the angle between R_e and R_{e+1}; the minus sign is for a
//! polygon counter-clockwise from its front, which the point sees. The polygon is first
//! clipped to the half-space in front of the point's plane.
//!
//! The singular case is a point on the line of an edge (a point on the edge shared by a floor
//! and a wall): R_e x R_{e+1} = 0 there. The form factor jumps across the polygon's plane, so
//! the value returned is the limit as the point approaches along its own plane from the
//! polygon's front side (direction delta, the polygon normal less its component along n):
//! for an edge through the point the term tends to angle pi (0 if the point lies beyond the
//! edge's ends) about the axis (R_{e+1} - R_e) x delta, and a corner at the point is replaced
//! by the direction -delta. On the interior of the shared edge of a floor and a wall this
//! gives exactly 1/2, the limit of a point on the floor approaching the wall.

mod clip;
mod contour;
mod lambert;
mod quadrature;
#[cfg(test)]
mod test_util;

pub(crate) use clip::clip_front;
pub use contour::polygon_to_polygon;
pub use lambert::point_to_polygon;

#[cfg(test)]
mod tests {
    use super::test_util::*;
    use super::*;
    use glam::DVec3;

    // Speed, not correctness: `cargo test --release -p radiosity --lib exact_timing --
    // --ignored --nocapture` prints nanoseconds per polygon pair.
    #[test]
    #[ignore]
    fn exact_timing() {
        let twisted: Vec<DVec3> = ceiling(1.0, 1.0, 1.0)
            .into_iter()
            .map(|p| rotate(p - v(0.5, 0.5, 0.), DVec3::Z, 0.3) + v(0.5, 0.5, 0.))
            .collect();
        let far: Vec<DVec3> = ceiling(1.0, 1.0, 10.0);
        let q1 = vec![
            v(0., 0., 0.),
            v(2., 0., 0.),
            v(1.5, 1., 0.),
            v(0.3, 1.2, 0.),
        ];
        let q2: Vec<DVec3> = [
            v(0., 0., 0.),
            v(1., 0.2, 0.),
            v(1.3, 1.1, 0.),
            v(-0.2, 0.8, 0.),
        ]
        .iter()
        .rev()
        .map(|&p| rotate(p, v(1., 1., 0.).normalize(), 0.5) + v(0.4, 0.2, 0.9))
        .collect();
        let d = v(-1., 1., 0.) / 2f64.sqrt();
        let angled = vec![v(0., 0., 0.), d, d + v(0., 0., 1.), v(0., 0., 1.)];
        let cases: [(&str, &[DVec3], &[DVec3]); 6] = [
            (
                "perpendicular, shared corner at an angle",
                &floor(),
                &angled,
            ),
            ("opposed squares", &floor(), &ceiling(1.0, 1.0, 1.0)),
            ("opposed, one turned 0.3 rad", &floor(), &twisted),
            ("perpendicular, shared edge", &floor(), &wall(0.0, 1.0, 1.0)),
            ("general quads", &q1, &q2),
            ("squares 10 apart", &floor(), &far),
        ];
        for (name, a, b) in cases {
            let n = 20_000;
            let start = std::time::Instant::now();
            let mut sink = 0.0;
            for _ in 0..n {
                sink += polygon_to_polygon(std::hint::black_box(a), std::hint::black_box(b));
            }
            let ns = start.elapsed().as_nanos() as f64 / n as f64;
            eprintln!("{name}: {ns:.0} ns per pair ({:.12})", sink / n as f64);
        }
        let w = wall(0.0, 1.0, 1.0);
        let n = 1_000_000;
        let start = std::time::Instant::now();
        let mut sink = 0.0;
        for k in 0..n {
            let p = v(0.5, (k % 1000) as f64 * 1e-3, 0.0);
            sink += point_to_polygon(std::hint::black_box(p), DVec3::Z, &w);
        }
        let ns = start.elapsed().as_nanos() as f64 / n as f64;
        eprintln!("point to polygon: {ns:.0} ns ({sink})");
    }
}
