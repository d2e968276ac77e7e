//! Geometry and quadrature shared by the exact form factors' tests: the unit floor, walls
//! and ceilings of Howell's catalogue cases, seeded random convex polygons (SplitMix64,
//! Steele, Lea and Flood 2014), and Gauss-Legendre integrals over quadrilaterals (nodes by
//! Newton's method on the Legendre recurrence), plain or graded towards a corner.

use std::f64::consts::PI;

use glam::DVec3;

pub(super) fn rel_err(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

pub(super) fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// Unit square floor z = 0, counter-clockwise from above.
pub(super) fn floor() -> Vec<DVec3> {
    vec![v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)]
}

/// The wall x = 0 over y in [y0, y1], z in [0, h], facing +x (towards the floor).
pub(super) fn wall(y0: f64, y1: f64, h: f64) -> Vec<DVec3> {
    vec![v(0., y0, 0.), v(0., y1, 0.), v(0., y1, h), v(0., y0, h)]
}

/// The rectangle [0, a] x [0, b] at height c, facing down.
pub(super) fn ceiling(a: f64, b: f64, c: f64) -> Vec<DVec3> {
    vec![v(0., 0., c), v(0., b, c), v(a, b, c), v(a, 0., c)]
}

/// A rotation by `angle` about the unit `axis` (Rodrigues).
pub(super) fn rotate(p: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    p * c + axis.cross(p) * s + axis * axis.dot(p) * (1.0 - c)
}

/// SplitMix64, for seeded random geometry without a dependency.
pub(super) struct Rng(pub(super) u64);
impl Rng {
    pub(super) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(super) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    pub(super) fn unit(&mut self) -> DVec3 {
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
    pub(super) fn convex(&mut self, centre: DVec3, normal: DVec3) -> Vec<DVec3> {
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
pub(super) fn quad_integral(q: &[DVec3], n: usize, f: &impl Fn(DVec3) -> f64) -> f64 {
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
pub(super) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
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
pub(super) fn graded_corner_integral(x1: f64, y1: f64, n: usize, f: &impl Fn(DVec3) -> f64) -> f64 {
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
pub(super) const EXACT: f64 = 1e-9;
