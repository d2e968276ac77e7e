//! The hemicube (Cohen and Greenberg, "The Hemi-Cube: A Radiosity Solution for Complex
//! Environments", SIGGRAPH 1985), named in paper section 3.5.
//!
//! Around the centroid of element i stands half a cube: a top face of `resolution` x
//! `resolution` cells facing along the element's normal and four side faces of
//! `resolution` x `resolution / 2` cells above its plane. Every other element is projected
//! onto each face and rasterised on the CPU with a depth buffer, so each cell ends up
//! holding the nearest element seen through it. A cell's delta form factor is the form
//! factor from the element's centre to that cell (top face at height 1, cell area dA):
//!
//!   top:  dF = dA / (pi (x^2 + y^2 + 1)^2)
//!   side: dF = z dA / (pi (y^2 + z^2 + 1)^2)
//!
//! and F_ij is the sum of the delta form factors of the cells that see element j's front.
//! The deltas of a whole hemicube sum to 1 (to O(1/resolution^2)); they are rescaled to
//! sum to exactly 1, so a closed scene's rows sum to 1 to rounding.
//!
//! Occlusion comes from the depth buffer: every element occludes, from both sides. A cell
//! that sees the back of an element contributes to no one (that light falls on a back face,
//! which absorbs it). The method is a point-to-area approximation from the element's centre,
//! so it is least accurate for elements close to each other compared with their size, and it
//! aliases small distant elements (the "resolution problems" the paper mentions).

use glam::DVec3;

use crate::mesh::Mesh;

/// Delta form factors of a hemicube, and the depth buffers it rasterises into.
pub(super) struct Hemicube {
    resolution: usize,
    /// Delta form factors of the top face, row-major, resolution x resolution.
    top: Vec<f64>,
    /// Delta form factors of one side face, row-major: resolution / 2 rows (height z from
    /// 0 at row 0 to 1) of resolution cells.
    side: Vec<f64>,
}

/// Per-thread buffers of one hemicube face.
#[derive(Default)]
pub(super) struct HemicubeScratch {
    depth: Vec<f64>,
    owner: Vec<u32>,
    corners: Vec<DVec3>,
}

/// No element seen through a cell.
const EMPTY: u32 = u32::MAX;
/// The back of an element seen through a cell (the high bit marks a back face).
const BACK: u32 = 1 << 31;

impl Hemicube {
    /// A hemicube with `resolution` cells across the top face (rounded up to even, at least 2).
    pub fn new(resolution: u32) -> Hemicube {
        let (resolution, mut top, mut side) = raw_deltas(resolution);
        // Normalise: the analytic total is exactly 1.
        let total: f64 = top.iter().sum::<f64>() + 4.0 * side.iter().sum::<f64>();
        for d in top.iter_mut().chain(side.iter_mut()) {
            *d /= total;
        }
        Hemicube {
            resolution,
            top,
            side,
        }
    }

    /// The sum of all normalised delta form factors (1 up to rounding).
    #[cfg(test)]
    pub fn delta_sum(&self) -> f64 {
        self.top.iter().sum::<f64>() + 4.0 * self.side.iter().sum::<f64>()
    }

    /// Row i of the form-factor matrix: F_ij for every element j.
    pub fn row(&self, mesh: &Mesh, i: usize, scratch: &mut HemicubeScratch) -> Vec<f64> {
        let mut row = vec![0.0; mesh.len()];
        let e = &mesh.elements[i];
        let n = e.normal;
        // An orthonormal frame (u, v, n) at the centroid (Duff et al. 2017, "Building an
        // Orthonormal Basis, Revisited").
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let u = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let v = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        let centre = e.centroid;
        // Faces as (depth axis, horizontal axis, vertical axis, rows, deltas).
        let faces: [(DVec3, DVec3, DVec3, usize, &[f64]); 5] = [
            (n, u, v, self.resolution, &self.top),
            (u, v, n, self.resolution / 2, &self.side),
            (-u, -v, n, self.resolution / 2, &self.side),
            (v, -u, n, self.resolution / 2, &self.side),
            (-v, u, n, self.resolution / 2, &self.side),
        ];
        for (depth_axis, h_axis, v_axis, rows, deltas) in faces {
            self.rasterise_face(mesh, i, centre, depth_axis, h_axis, v_axis, rows, scratch);
            for (cell, &owner) in scratch.owner.iter().enumerate() {
                if owner != EMPTY && owner & BACK == 0 {
                    row[owner as usize] += deltas[cell];
                }
            }
        }
        row
    }

    /// Fills `scratch.owner` with the nearest element through each cell of one face. The
    /// face looks along `depth_axis`; cell columns run along `h_axis` over [-1, 1] and rows
    /// along `v_axis` over [-1, 1] (top face, `rows` = resolution) or [0, 1] (side faces).
    #[allow(clippy::too_many_arguments)]
    fn rasterise_face(
        &self,
        mesh: &Mesh,
        i: usize,
        centre: DVec3,
        depth_axis: DVec3,
        h_axis: DVec3,
        v_axis: DVec3,
        rows: usize,
        scratch: &mut HemicubeScratch,
    ) {
        let cols = self.resolution;
        let cells = rows * cols;
        scratch.depth.clear();
        scratch.depth.resize(cells, f64::INFINITY);
        scratch.owner.clear();
        scratch.owner.resize(cells, EMPTY);
        let cell = 2.0 / cols as f64;
        let v_min = if rows == cols { -1.0 } else { 0.0 };
        let surface_i = mesh.elements[i].surface;
        // Geometry closer than this along the depth axis is behind the eye.
        let near = 1e-9 * (mesh.elements[i].area.sqrt() + 1.0);
        for (j, ej) in mesh.elements.iter().enumerate() {
            // Elements of i's own surface lie in its plane: never seen.
            if j == i || ej.surface == surface_i {
                continue;
            }
            // Corners in face coordinates (h, v, depth), clipped to depth >= near.
            scratch.corners.clear();
            let corners = mesh.corner_positions(j).map(|p| {
                let d = p - centre;
                DVec3::new(d.dot(h_axis), d.dot(v_axis), d.dot(depth_axis))
            });
            clip_near(corners, near, &mut scratch.corners);
            if scratch.corners.len() < 3 {
                continue;
            }
            // Project onto the face plane at depth 1, in cell units.
            let to_cell = |p: DVec3| ((p.x / p.z + 1.0) / cell, (p.y / p.z - v_min) / cell);
            let projected: Vec<(f64, f64)> = scratch.corners.iter().map(|&p| to_cell(p)).collect();
            let (mut c0, mut c1, mut r0, mut r1) = (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            );
            for &(x, y) in &projected {
                c0 = c0.min(x);
                c1 = c1.max(x);
                r0 = r0.min(y);
                r1 = r1.max(y);
            }
            if c1 < 0.0 || r1 < 0.0 || c0 > cols as f64 || r0 > rows as f64 {
                continue;
            }
            let col_range = (c0.floor().max(0.0) as usize)..(c1.ceil().min(cols as f64) as usize);
            let row_range = (r0.floor().max(0.0) as usize)..(r1.ceil().min(rows as f64) as usize);
            // The element's plane in face coordinates: the ray t (x, y, 1) meets it at
            // t = offset / (normal . (x, y, 1)).
            let nj = DVec3::new(
                ej.normal.dot(h_axis),
                ej.normal.dot(v_axis),
                ej.normal.dot(depth_axis),
            );
            let pj = scratch.corners[0];
            let offset = nj.dot(pj);
            // Seen from the eye, is this the element's front? (The eye is at the origin.)
            let back = offset >= 0.0;
            let id = j as u32 | if back { BACK } else { 0 };
            // Orientation of the projected polygon, for the inside test.
            let area2: f64 = (0..projected.len())
                .map(|k| {
                    let (a, b) = (projected[k], projected[(k + 1) % projected.len()]);
                    a.0 * b.1 - b.0 * a.1
                })
                .sum();
            if area2 == 0.0 {
                continue;
            }
            let orient = area2.signum();
            for r in row_range {
                let y = r as f64 + 0.5;
                for c in col_range.clone() {
                    let x = c as f64 + 0.5;
                    // Inside when on the inner side of every edge (edges included).
                    let inside = (0..projected.len()).all(|k| {
                        let (a, b) = (projected[k], projected[(k + 1) % projected.len()]);
                        orient * ((b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0)) >= 0.0
                    });
                    if !inside {
                        continue;
                    }
                    let dir = DVec3::new(x * cell - 1.0, y * cell + v_min, 1.0);
                    let denom = nj.dot(dir);
                    let t = if denom != 0.0 {
                        offset / denom
                    } else {
                        f64::INFINITY
                    };
                    let k = r * cols + c;
                    if t > 0.0 && t < scratch.depth[k] {
                        scratch.depth[k] = t;
                        scratch.owner[k] = id;
                    }
                }
            }
        }
    }
}

/// The delta form factors before normalisation: (resolution rounded up to even, top face,
/// one side face).
fn raw_deltas(resolution: u32) -> (usize, Vec<f64>, Vec<f64>) {
    let res = (resolution.max(2) as usize).div_ceil(2) * 2;
    let cell = 2.0 / res as f64;
    let da = cell * cell;
    let centre = |k: usize| -1.0 + (k as f64 + 0.5) * cell;
    let pi = std::f64::consts::PI;
    let mut top = Vec::with_capacity(res * res);
    for r in 0..res {
        for c in 0..res {
            let (x, y) = (centre(c), centre(r));
            top.push(da / (pi * (x * x + y * y + 1.0).powi(2)));
        }
    }
    let mut side = Vec::with_capacity(res * res / 2);
    for r in 0..res / 2 {
        let z = (r as f64 + 0.5) * cell;
        for c in 0..res {
            let y = centre(c);
            side.push(z * da / (pi * (y * y + z * z + 1.0).powi(2)));
        }
    }
    (res, top, side)
}

/// Sutherland-Hodgman: the part of the convex polygon `corners` with z >= `near`.
fn clip_near(corners: impl ExactSizeIterator<Item = DVec3>, near: f64, out: &mut Vec<DVec3>) {
    let pts: Vec<DVec3> = corners.collect();
    let k = pts.len();
    for idx in 0..k {
        let (a, b) = (pts[idx], pts[(idx + 1) % k]);
        let (ina, inb) = (a.z >= near, b.z >= near);
        if ina {
            out.push(a);
        }
        if ina != inb {
            let t = (near - a.z) / (b.z - a.z);
            out.push(a + t * (b - a));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The analytic total of the delta form factors is 1; the midpoint sums converge to it
    // as O(1/res^2) (the integrands are smooth on each face). The constant is 0.55
    // (raw sum 1.0086 at res 8), so the bound 1/res^2 leaves 80 % headroom.
    #[test]
    fn delta_form_factors_sum_to_one() {
        for res in [8u32, 32, 128, 512] {
            let (_, top, side) = raw_deltas(res);
            let raw = top.iter().sum::<f64>() + 4.0 * side.iter().sum::<f64>();
            let bound = 1.0 / (res as f64).powi(2);
            assert!(
                (raw - 1.0).abs() < bound,
                "res {res}: raw sum {raw}, |error| above {bound}"
            );
            assert!((Hemicube::new(res).delta_sum() - 1.0).abs() < 1e-12);
        }
    }
}
