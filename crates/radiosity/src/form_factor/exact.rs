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

use std::f64::consts::PI;

use glam::DVec3;

use crate::geometry::{area_vector, polygon_normal, vertex_mean};

/// Polygons of up to this many corners are clipped into a stack buffer (a convex polygon
/// gains at most one corner from a clip); larger ones into a `Vec`.
const STACK_CORNERS: usize = 16;

/// Signed distances from a plane (in units of the typical distance, see the module
/// documentation) below this count as on the plane.
const ON_PLANE: f64 = 1e-12;

/// Edges shorter than this (in the same units) are dropped: their contribution
/// is below 1e-15.
const SHORT_EDGE: f64 = 1e-15;

/// Edges whose directions' cross product is shorter than this are parallel (closed form).
/// Treating a pair at angle alpha as parallel changes its distances by about alpha, so
/// 1e-13 is far below the target accuracy.
const PARALLEL_SIN: f64 = 1e-13;

/// A polygon, copied (scaled and maybe clipped) onto the stack when small, otherwise onto the
/// heap. (The size difference between the variants is the point.)
#[allow(clippy::large_enum_variant)]
enum Corners {
    Stack([DVec3; STACK_CORNERS + 1], usize),
    Heap(Vec<DVec3>),
}

impl Corners {
    fn as_slice(&self) -> &[DVec3] {
        match self {
            Corners::Stack(a, n) => &a[..*n],
            Corners::Heap(v) => v,
        }
    }
}

/// Clips `poly` to the closed half-space `normal . (v - origin) >= 0` (Sutherland-Hodgman),
/// mapping every corner v to (v - `shift`) * `inv_scale`. Returns `None` if no corner lies
/// strictly in front (beyond `ON_PLANE`), so nothing of positive area remains.
fn clip_front(
    poly: &[DVec3],
    normal: DVec3,
    origin: DVec3,
    shift: DVec3,
    inv_scale: f64,
) -> Option<Corners> {
    let dist = |v: DVec3| {
        let d = normal.dot(v - origin) * inv_scale;
        if d.abs() <= ON_PLANE {
            0.0
        } else {
            d
        }
    };
    if !poly.iter().any(|&v| dist(v) > 0.0) {
        return None;
    }
    let n = poly.len();
    let map = |v: DVec3| (v - shift) * inv_scale;
    let emit = |push: &mut dyn FnMut(DVec3)| {
        for k in 0..n {
            let (p, q) = (poly[k], poly[(k + 1) % n]);
            let (dp, dq) = (dist(p), dist(q));
            if dp >= 0.0 {
                push(map(p));
            }
            if (dp > 0.0 && dq < 0.0) || (dp < 0.0 && dq > 0.0) {
                let t = dp / (dp - dq);
                push(map(p + (q - p) * t));
            }
        }
    };
    if n <= STACK_CORNERS {
        let mut buf = [DVec3::ZERO; STACK_CORNERS + 1];
        let mut len = 0;
        // A convex polygon gains at most one corner; a slightly non-convex one could gain
        // more, so stop at the buffer's end rather than overrun it.
        emit(&mut |v| {
            if len < buf.len() {
                buf[len] = v;
                len += 1;
            }
        });
        Some(Corners::Stack(buf, len))
    } else {
        let mut out = Vec::with_capacity(n + 1);
        emit(&mut |v| out.push(v));
        Some(Corners::Heap(out))
    }
}

/// The exact unoccluded form factor F_12 from polygon `p1` to polygon `p2`: the fraction of
/// the energy diffusely emitted from the front of `p1` that reaches the front of `p2`.
///
/// Both polygons are planar and convex with corners counter-clockwise seen from the front.
/// Parts of either polygon behind the other's plane exchange nothing and are clipped away,
/// so partly facing pairs are right too; coplanar pairs, pairs facing away and degenerate
/// polygons give 0. Exact (agreeing with the closed forms to about 1e-15 relative) also for
/// polygons that share an edge or a corner; see the module documentation for the method. For
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

#[allow(clippy::excessive_precision)]
/// Positive Gauss-Legendre nodes on [-1, 1] and their weights, 6 points.
const GL6: [(f64, f64); 3] = [
    (0.238_619_186_083_196_9, 0.467_913_934_572_691_0),
    (0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
    (0.932_469_514_203_152_1, 0.171_324_492_379_170_4),
];
#[allow(clippy::excessive_precision)]
/// Positive Gauss-Legendre nodes on [-1, 1] and their weights, 10 points.
const GL10: [(f64, f64); 5] = [
    (0.148_874_338_981_631_2, 0.295_524_224_714_752_9),
    (0.433_395_394_129_247_2, 0.269_266_719_309_996_3),
    (0.679_409_568_299_024_4, 0.219_086_362_515_982_0),
    (0.865_063_366_688_984_5, 0.149_451_349_150_580_6),
    (0.973_906_528_517_171_7, 0.066_671_344_308_688_1),
];

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

#[allow(clippy::excessive_precision)]
/// QUADPACK's QK21 rule on [-1, 1]: the positive Kronrod nodes with their Kronrod weights
/// and, for the 10 Gauss nodes among them, their Gauss weights (0 for the others); the
/// centre, a Kronrod node only, is `WGK_CENTRE`.
const GK21: [(f64, f64, f64); 10] = [
    (
        0.995_657_163_025_808_080_735_527_280_689_003,
        0.011_694_638_867_371_874_278_064_396_062_192,
        0.0,
    ),
    (
        0.973_906_528_517_171_720_077_964_012_084_452,
        0.032_558_162_307_964_727_478_818_972_459_390,
        0.066_671_344_308_688_137_593_568_809_893_332,
    ),
    (
        0.930_157_491_355_708_226_001_207_180_059_508,
        0.054_755_896_574_351_996_031_381_300_244_580,
        0.0,
    ),
    (
        0.865_063_366_688_984_510_732_096_688_423_493,
        0.075_039_674_810_919_952_767_043_140_916_190,
        0.149_451_349_150_580_593_145_776_339_657_697,
    ),
    (
        0.780_817_726_586_416_897_063_717_578_345_042,
        0.093_125_454_583_697_605_535_065_465_083_366,
        0.0,
    ),
    (
        0.679_409_568_299_024_406_234_327_365_114_874,
        0.109_387_158_802_297_641_899_210_590_325_805,
        0.219_086_362_515_982_043_995_534_934_228_163,
    ),
    (
        0.562_757_134_668_604_683_339_000_099_272_694,
        0.123_491_976_262_065_851_077_958_109_831_074,
        0.0,
    ),
    (
        0.433_395_394_129_247_190_799_265_943_165_784,
        0.134_709_217_311_473_325_928_054_001_771_707,
        0.269_266_719_309_996_355_091_226_921_569_469,
    ),
    (
        0.294_392_862_701_460_198_131_126_603_103_866,
        0.142_775_938_577_060_080_797_094_273_138_717,
        0.0,
    ),
    (
        0.148_874_338_981_631_210_884_826_001_129_720,
        0.147_739_104_901_338_491_374_841_515_972_068,
        0.295_524_224_714_752_870_173_892_994_651_338,
    ),
];
#[allow(clippy::excessive_precision)]
/// The Kronrod weight of the centre in QK21.
const WGK_CENTRE: f64 = 0.149_445_554_002_916_905_664_936_468_389_821;

/// The 21-point Kronrod estimate of the integral of `f` over [lo, hi] and QUADPACK's error
/// estimate for it (from the 10-point Gauss rule on the same nodes).
fn gk21(f: &impl Fn(f64) -> f64, lo: f64, hi: f64) -> (f64, f64) {
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let mut fv = [(0.0, 0.0); 10];
    let f_centre = f(centre);
    let mut kron = WGK_CENTRE * f_centre;
    let mut gauss = 0.0;
    for (k, &(x, wk, wg)) in GK21.iter().enumerate() {
        fv[k] = (f(centre - half * x), f(centre + half * x));
        let pair = fv[k].0 + fv[k].1;
        kron += wk * pair;
        gauss += wg * pair;
    }
    let mean = 0.5 * kron;
    let mut asc = WGK_CENTRE * (f_centre - mean).abs();
    for (k, &(_, wk, _)) in GK21.iter().enumerate() {
        asc += wk * ((fv[k].0 - mean).abs() + (fv[k].1 - mean).abs());
    }
    let asc = asc * half.abs();
    let mut err = ((kron - gauss) * half).abs();
    if asc != 0.0 && err != 0.0 {
        err = asc * (200.0 * err / asc).powf(1.5).min(1.0);
    }
    (kron * half, err)
}

/// The integral of `f` over [lo, hi] by adaptive bisection with `gk21`. `scale` is the size of
/// f (here the inner edge length, times the piece length for a graded piece): an interval is
/// accepted when its error estimate is below 1e-13 scale per unit of length, or below
/// 2e-15 scale in all (so that the few intervals at a singularity need not shrink to
/// nothing), or when it is 1e-13 of the whole. QUADPACK's estimate is pessimistic for
/// analytic integrands by orders of magnitude: the results agree with the closed forms to
/// about 1e-15.
fn adaptive_gk21(f: &impl Fn(f64) -> f64, lo: f64, hi: f64, scale: f64) -> f64 {
    const DEPTH: usize = 64;
    let per_length = 1e-13 * scale;
    let floor = 2e-15 * scale;
    let min_width = 1e-13 * (hi - lo);
    let mut stack = [(0.0, 0.0); DEPTH];
    let mut top = 0;
    let mut total = 0.0;
    let (mut a, mut b) = (lo, hi);
    loop {
        let (value, err) = gk21(f, a, b);
        let width = b - a;
        if err <= per_length * width || err <= floor || width <= min_width || top == DEPTH {
            total += value;
            if top == 0 {
                return total;
            }
            top -= 1;
            (a, b) = stack[top];
        } else {
            let mid = 0.5 * (a + b);
            stack[top] = (mid, b);
            top += 1;
            b = mid;
        }
    }
}

/// The form factor from a differential area at `p` with unit front normal `n` to the front of
/// the planar convex polygon `poly` (counter-clockwise from its front), unoccluded:
/// Lambert's formula (see the module documentation), with the polygon first clipped to the
/// half-space in front of (p, n).
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
    use super::*;
    use crate::form_factor::reference;

    fn rel_err(got: f64, want: f64) -> f64 {
        (got - want).abs() / want.abs()
    }

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    /// Unit square floor z = 0, counter-clockwise from above.
    fn floor() -> Vec<DVec3> {
        vec![v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)]
    }

    // The Kronrod rule integrates polynomials up to degree 31 exactly, the Gauss rule up to
    // 19: a check on the transcribed constants (to rounding).
    #[test]
    fn exact_gk21_weights() {
        for k in 0..=31 {
            let want = if k % 2 == 0 {
                2.0 / (k + 1) as f64
            } else {
                0.0
            };
            let (got, _) = gk21(&|x: f64| x.powi(k), -1.0, 1.0);
            assert!((got - want).abs() < 1e-15, "degree {k}: {got} vs {want}");
        }
        for k in (0..=18).step_by(2) {
            let got: f64 = GK21.iter().map(|(x, _, w)| 2.0 * w * x.powi(k)).sum();
            assert!((got - 2.0 / (k + 1) as f64).abs() < 1e-15, "Gauss {k}");
        }
        // Gauss-Legendre with n points: exact to degree 2n - 1.
        for (rule, n) in [(&GL6[..], 6), (&GL10[..], 10)] {
            for k in (0..2 * n).step_by(2) {
                let got: f64 = rule.iter().map(|(x, w)| 2.0 * w * x.powi(k)).sum();
                assert!((got - 2.0 / (k + 1) as f64).abs() < 1e-15, "{n} {k}");
            }
        }
    }

    /// The wall x = 0 over y in [y0, y1], z in [0, h], facing +x (towards the floor).
    fn wall(y0: f64, y1: f64, h: f64) -> Vec<DVec3> {
        vec![v(0., y0, 0.), v(0., y1, 0.), v(0., y1, h), v(0., y0, h)]
    }

    /// The rectangle [0, a] x [0, b] at height c, facing down.
    fn ceiling(a: f64, b: f64, c: f64) -> Vec<DVec3> {
        vec![v(0., 0., c), v(0., b, c), v(a, b, c), v(a, 0., c)]
    }

    /// A rotation by `angle` about the unit `axis` (Rodrigues).
    fn rotate(p: DVec3, axis: DVec3, angle: f64) -> DVec3 {
        let (s, c) = angle.sin_cos();
        p * c + axis.cross(p) * s + axis * axis.dot(p) * (1.0 - c)
    }

    /// SplitMix64, for seeded random geometry without a dependency.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
        fn unit(&mut self) -> DVec3 {
            loop {
                let p = v(
                    self.range(-1., 1.),
                    self.range(-1., 1.),
                    self.range(-1., 1.),
                );
                if p.length_squared() > 0.01 && p.length_squared() <= 1.0 {
                    return p.normalize();
                }
            }
        }
        /// A convex polygon of 3 to 7 corners on an ellipse about `centre`, counter-clockwise
        /// about `normal`.
        fn convex(&mut self, centre: DVec3, normal: DVec3) -> Vec<DVec3> {
            let (e1, e2) = normal.any_orthonormal_pair();
            let (r1, r2) = (self.range(0.3, 1.5), self.range(0.3, 1.5));
            let k = 3 + (self.next() * 5.0) as usize;
            let mut angles: Vec<f64> = (0..k).map(|_| self.range(0.0, 2.0 * PI)).collect();
            angles.sort_by(f64::total_cmp);
            angles
                .iter()
                .map(|t| centre + r1 * t.cos() * e1 + r2 * t.sin() * e2)
                .collect()
        }
    }

    /// The integral of `f` over the planar convex quadrilateral `q` by Gauss-Legendre with
    /// `n` x `n` points on the bilinear map from the unit square (exact for a planar quad's
    /// Jacobian, which is bilinear).
    fn quad_integral(q: &[DVec3], n: usize, f: &impl Fn(DVec3) -> f64) -> f64 {
        let (x, w) = gauss_legendre(n);
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let (s, t) = (0.5 * (1.0 + x[i]), 0.5 * (1.0 + x[j]));
                let p = q[0] * (1. - s) * (1. - t)
                    + q[1] * s * (1. - t)
                    + q[2] * s * t
                    + q[3] * (1. - s) * t;
                let ds = (q[1] - q[0]) * (1. - t) + (q[2] - q[3]) * t;
                let dt = (q[3] - q[0]) * (1. - s) + (q[2] - q[1]) * s;
                sum += 0.25 * w[i] * w[j] * ds.cross(dt).length() * f(p);
            }
        }
        sum
    }

    /// Gauss-Legendre nodes and weights on [-1, 1] (Newton on the Legendre recurrence).
    fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
        let (mut x, mut w) = (vec![0.0; n], vec![0.0; n]);
        for i in 0..n {
            let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            loop {
                let (mut p0, mut p1) = (1.0, z);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                    (p0, p1) = (p1, p2);
                }
                let dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
                let dz = p1 / dp;
                z -= dz;
                if dz.abs() < 1e-16 {
                    // One more Newton step's derivative for the weight.
                    x[i] = z;
                    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
                    break;
                }
            }
        }
        (x, w)
    }

    /// The integral over the axis-aligned rectangle [x0, x1] x [y0, y1] of the plane z = 0 of
    /// `f`, with rectangles graded geometrically towards the corner (x0, y0) (40 levels, each
    /// an L of two rectangles with `n` x `n` Gauss points): for integrands that are smooth
    /// except at that corner.
    fn graded_corner_integral(x1: f64, y1: f64, n: usize, f: &impl Fn(DVec3) -> f64) -> f64 {
        let rect = |a: f64, b: f64, c: f64, d: f64| {
            quad_integral(&[v(a, c, 0.), v(b, c, 0.), v(b, d, 0.), v(a, d, 0.)], n, f)
        };
        let mut sum = 0.0;
        let mut s = 1.0;
        for _ in 0..40 {
            let h = 0.5 * s;
            sum += rect(h * x1, s * x1, 0.0, s * y1) + rect(0.0, h * x1, h * y1, s * y1);
            s = h;
        }
        sum
    }

    // Accuracy target for the closed-form cases: 1e-9 relative, as asked of an exact method
    // (measured: 0 to 3e-15, see the eprintln! output with --nocapture).
    const EXACT: f64 = 1e-9;

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
