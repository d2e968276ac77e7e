//! Clipping a polygon to the closed half-space in front of a plane, the step both exact
//! form factors take before integrating (one-sided emission and reception): the polygon
//! clipping of Sutherland and Hodgman 1974 ("Reentrant polygon clipping", Communications
//! of the ACM 17), one plane at a time, with the corners scaled on the way.

use glam::DVec3;

/// Polygons of up to this many corners are clipped into a stack buffer (a convex polygon
/// gains at most one corner from a clip); larger ones into a `Vec`.
const STACK_CORNERS: usize = 16;

/// Signed distances from a plane (in units of the typical distance, see the [`super`] module
/// documentation) below this count as on the plane.
pub(super) const ON_PLANE: f64 = 1e-12;

/// A polygon, copied (scaled and maybe clipped) onto the stack when small, otherwise onto the
/// heap. (The size difference between the variants is the point.)
#[allow(clippy::large_enum_variant)]
pub(crate) enum Corners {
    Stack([DVec3; STACK_CORNERS + 1], usize),
    Heap(Vec<DVec3>),
}

impl Corners {
    pub(crate) fn as_slice(&self) -> &[DVec3] {
        match self {
            Corners::Stack(a, n) => &a[..*n],
            Corners::Heap(v) => v,
        }
    }
}

/// Clips `poly` to the closed half-space `normal . (v - origin) >= 0` (Sutherland-Hodgman),
/// mapping every corner v to (v - `shift`) * `inv_scale`. Returns `None` if no corner lies
/// strictly in front (beyond `ON_PLANE`), so nothing of positive area remains.
pub(crate) fn clip_front(
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
