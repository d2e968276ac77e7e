//! The double area integral (paper figure 4) by the midpoint rule:
//!
//! A_i F_ij = sum over points p of i, q of j of
//!            cos(theta_p) cos(theta_q) / (pi r^2) V(p, q) w_p w_q
//!
//! with k x k points per element (paper 2.8, `INTEGRAL_STEPS`) and V(p, q) in {0, 1} the
//! visibility of q from p by a ray cast (paper 2.3, through a BVH instead of the paper's
//! test against every patch).
//!
//! One change to the paper's integrand: a point pair's term w_q cos cos / (pi r^2) is the
//! form factor from point p to the small area w_q, and when r^2 is not large against w_q
//! (elements that touch, or furniture a centimetre from a wall) it exceeds 1, which no form
//! factor can: in the furnished room example, rows then summed to 7. Each term is therefore
//! the form factor from p to a coaxial disc of that area, w cos cos / (pi r^2 + w)
//! (Wallace, Elmquist and Haines 1989, eq. 7), with w = max(w_p, w_q) so that the kernel stays
//! symmetric and reciprocity exact. It equals the paper's term to first order in w / r^2, so
//! it converges to the same limit (see tests/form_factors.rs), and is never above 1. On the
//! unit-square closed forms at k = 2 it cuts the error from 0.017 to 0.0032 (opposed) and
//! from 0.064 to 0.0088 (sharing an edge).

use std::f64::consts::PI;

use glam::DVec3;

use super::{exact, FormFactorContext, RayCounter};

/// How close, in units of the larger element's size, a pair must be for
/// [`PairKernel::AreaExactNear`] to take the exact value: two elements. Half an element
/// (where the area rule at k = 2 is within about 1 % of the exact value: parallel unit
/// squares half a unit apart, 1.1 %; tests/suite/form_factors.rs) left its small errors
/// over the many pairs a little farther apart adding up: closed rooms escaped 0.29 to
/// 0.63 % of their light; at two elements 0.13 to 0.39 %, and the pixels against the path
/// tracer improved (building_small 5.33 -> 5.06 %, room.scene 4.16 -> 3.92 %), for twice
/// building_small's form-factor time and 1.1 times the Cornell box's (BENCHMARKS.md).
pub(super) const NEAR: f64 = 2.0;

/// Points per axis of each element that judge the visibility of a near pair that
/// something may block ([`PairKernel::AreaExactNear`]): 4 x 4, so 256 point pairs.
pub(super) const NEAR_STEPS: u32 = 4;

/// Points on each element that judge again a near pair that [`NEAR_STEPS`]^2 points found
/// partly hidden: 55 on a rank-1 lattice (see [`sample_polygon`]), so 3,025 point pairs.
const FINE_POINTS: usize = 55;

/// What an element pair's coupling is computed from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum PairKernel {
    /// The double area integral (this module's kernel) with a ray per point pair.
    Area,
    /// As [`PairKernel::Area`], except for pairs of elements closer than [`NEAR`] times the
    /// larger one's size, which take [`PairKernel::Contour`]'s exact value: the area rule's
    /// error is first order where elements meet (2.9 % of a closed box's row sums at k = 2,
    /// 3 % of the emitted power of `examples/room.scene` lost at the junctions of walls,
    /// floor and furniture), and such pairs are few (those along the junctions), so the
    /// exact integral costs little. The `area` method's kernel.
    AreaExactNear,
    /// The exact polygon-to-polygon form factor (`exact::polygon_to_polygon`, the
    /// double contour integral), times the kernel-weighted visible fraction of the point
    /// pairs when occluders may intervene.
    Contour,
    /// Lambert's exact point-to-polygon form factor (`exact::point_to_polygon`) at each
    /// sample point of the receiver i, times the kernel-weighted visible fraction of the
    /// source's sample points seen from it (Wallace, Elmquist and Haines 1989). Not
    /// symmetric in i and j.
    Analytic,
}

/// Everything the area integral precomputes once per matrix: integration points and
/// bounding boxes of the elements, bounding boxes of the surfaces.
pub(super) struct AreaIntegrator<'a> {
    ctx: &'a FormFactorContext<'a>,
    kernel: PairKernel,
    /// k^2 points per element with their area weights.
    per_element: usize,
    points: Vec<(DVec3, f64)>,
    /// For [`PairKernel::AreaExactNear`], [`NEAR_STEPS`]^2 points per element, which judge
    /// the visibility of near pairs that something may block; empty otherwise.
    near_points: Vec<(DVec3, f64)>,
    /// Bounding box (min, max) of each element.
    element_box: Vec<(DVec3, DVec3)>,
    /// Bounding box of each surface (of its elements).
    surface_box: Vec<(DVec3, DVec3)>,
}

/// An element's 3 or 4 corners without a heap allocation.
struct Corners {
    points: [DVec3; 4],
    len: usize,
}

impl Corners {
    fn as_slice(&self) -> &[DVec3] {
        &self.points[..self.len]
    }
}

/// Scratch space for one worker thread, reused across rows.
#[derive(Default)]
pub(super) struct Scratch {
    /// Occluder candidates between the current row's element and the current surface.
    surface_candidates: Vec<u32>,
    /// Those of `surface_candidates` whose boxes meet the current pair's box.
    pair_candidates: Vec<u32>,
}

fn bounds(points: impl Iterator<Item = DVec3>) -> (DVec3, DVec3) {
    points.fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

fn boxes_overlap(a: (DVec3, DVec3), b: (DVec3, DVec3), pad: f64) -> bool {
    a.0.cmple(b.1 + pad).all() && b.0.cmple(a.1 + pad).all()
}

impl<'a> AreaIntegrator<'a> {
    pub fn new(ctx: &'a FormFactorContext<'a>, k: u32, kernel: PairKernel) -> AreaIntegrator<'a> {
        let mesh = ctx.mesh;
        let mut points = Vec::with_capacity(mesh.len() * (k * k) as usize);
        for e in 0..mesh.len() {
            mesh.integration_points(e, k, &mut points);
        }
        let element_box = (0..mesh.len())
            .map(|e| bounds(mesh.corner_positions(e)))
            .collect();
        let surface_box = mesh
            .surface_vertices
            .iter()
            .map(|r| {
                bounds(
                    mesh.vertices[r.start as usize..r.end as usize]
                        .iter()
                        .copied(),
                )
            })
            .collect();
        let mut near_points = Vec::new();
        if kernel == PairKernel::AreaExactNear {
            near_points.reserve(mesh.len() * (NEAR_STEPS * NEAR_STEPS) as usize);
            for e in 0..mesh.len() {
                mesh.integration_points(e, NEAR_STEPS, &mut near_points);
            }
        }
        AreaIntegrator {
            ctx,
            kernel,
            per_element: (k * k) as usize,
            points,
            near_points,
            element_box,
            surface_box,
        }
    }

    fn samples(&self, e: usize) -> &[(DVec3, f64)] {
        &self.points[e * self.per_element..(e + 1) * self.per_element]
    }

    fn near_samples(&self, e: usize) -> &[(DVec3, f64)] {
        let per = (NEAR_STEPS * NEAR_STEPS) as usize;
        &self.near_points[e * per..(e + 1) * per]
    }

    /// G_ij = A_i F_ij for every j in `columns` (0 where j == i).
    pub fn couplings(
        &self,
        i: usize,
        columns: std::ops::Range<usize>,
        rays: &RayCounter,
        scratch: &mut Scratch,
    ) -> Vec<f64> {
        let mesh = self.ctx.mesh;
        let mut out = Vec::with_capacity(columns.len());
        let mut current_surface = u32::MAX;
        for j in columns {
            let s = mesh.elements[j].surface;
            if s != current_surface {
                current_surface = s;
                self.surface_candidates(i, s as usize, &mut scratch.surface_candidates);
            }
            out.push(if i == j {
                0.0
            } else {
                self.coupling(i, j, rays, scratch)
            });
        }
        out
    }

    /// The occluders that could block a segment from element i to any element of surface
    /// s: a BVH box query around both, less the two surfaces themselves (a segment leaves
    /// its plane at once) and surfaces wholly behind the plane of i or of s (segments run
    /// in front of both).
    fn surface_candidates(&self, i: usize, s: usize, out: &mut Vec<u32>) {
        let occ = self.ctx.occluders;
        let ei = &self.ctx.mesh.elements[i];
        let (eb, sb) = (self.element_box[i], self.surface_box[s]);
        out.clear();
        occ.overlapping(eb.0.min(sb.0), eb.1.max(sb.1), out);
        let first = self.ctx.mesh.surface_elements[s].start as usize;
        let (ns, ps) = (
            self.ctx.mesh.elements[first].normal,
            self.ctx.mesh.elements[first].centroid,
        );
        let (ni, pi) = (ei.normal, ei.centroid);
        let tol = 1e-9 * occ.scale();
        out.retain(|&k| {
            let id = occ.id_of(k);
            if id == ei.surface || id as usize == s {
                return false;
            }
            let corners = occ.corners_of(k);
            corners.iter().any(|c| ni.dot(*c - pi) > tol)
                && corners.iter().any(|c| ns.dot(*c - ps) > tol)
        });
    }

    /// A_i F_ij by the midpoint rule over the samples of elements i and j, with occlusion
    /// against `scratch.surface_candidates` (see [`AreaIntegrator::surface_candidates`]).
    /// Emission and reflection are one-sided, so a point pair contributes only when each
    /// point is in front of the other's element.
    fn coupling(&self, i: usize, j: usize, rays: &RayCounter, scratch: &mut Scratch) -> f64 {
        let mesh = self.ctx.mesh;
        let (ei, ej) = (&mesh.elements[i], &mesh.elements[j]);
        // Coplanar elements of one surface exchange nothing.
        if ei.surface == ej.surface {
            return 0.0;
        }
        let (ni, nj) = (ei.normal, ej.normal);
        // Elements wholly behind each other's planes exchange nothing.
        let in_front = |n: DVec3, origin: DVec3, e: usize| {
            mesh.corner_positions(e).any(|c| n.dot(c - origin) > 0.0)
        };
        if !in_front(ni, ei.centroid, j) || !in_front(nj, ej.centroid, i) {
            return 0.0;
        }
        // Of the surface's candidates, keep those whose boxes meet the box around i and j:
        // every segment between the two elements stays inside that box.
        let occ = self.ctx.occluders;
        let pair_box = {
            let (a, b) = (self.element_box[i], self.element_box[j]);
            (a.0.min(b.0), a.1.max(b.1))
        };
        let pad = 1e-6 * occ.scale();
        scratch.pair_candidates.clear();
        for &k in &scratch.surface_candidates {
            if boxes_overlap(occ.box_of(k), pair_box, pad) {
                scratch.pair_candidates.push(k);
            }
        }
        let candidates = &scratch.pair_candidates;

        let mut cast = 0;
        let g = match self.kernel {
            PairKernel::Area => self.area_sum(i, j, candidates, &mut cast),
            PairKernel::AreaExactNear if !self.near(i, j) => {
                self.area_sum(i, j, candidates, &mut cast)
            }
            PairKernel::Contour | PairKernel::AreaExactNear => {
                let (ci, cj) = (self.corners(i), self.corners(j));
                let exact = ei.area * exact::polygon_to_polygon(ci.as_slice(), cj.as_slice());
                if exact <= 0.0 || candidates.is_empty() {
                    exact
                } else {
                    // Exact geometry times the kernel-weighted fraction of point pairs that
                    // see each other: the method's own points for contour, finer ones for
                    // the area method's near pairs (with 2 x 2 points a partly hidden near
                    // pair is often judged wholly visible, and counted twice with what
                    // hides it: row sums up to 1.4 in a furnished building).
                    // Where either element lies partly behind the other's plane, the
                    // points judge the parts that face each other only: clipped to each
                    // other's front, as the exact value is (a shelf's end 2 mm from a
                    // bookcase's side sees the floor element under it through no point
                    // of the floor element's 4 x 4: judged from those the pair would
                    // count as wholly visible).
                    let facing = self.facing_polygons(ci.as_slice(), ni, cj.as_slice(), nj);
                    let (poly_i, poly_j) = match &facing {
                        Some((a, b)) => (a.as_slice(), b.as_slice()),
                        None => (ci.as_slice(), cj.as_slice()),
                    };
                    let clipped = facing.as_ref().map(|_| {
                        let n = (NEAR_STEPS * NEAR_STEPS) as usize;
                        (sample_polygon(poly_i, n), sample_polygon(poly_j, n))
                    });
                    let (points_i, points_j) = match (&clipped, self.kernel) {
                        (Some((a, b)), _) => (a.as_slice(), b.as_slice()),
                        (None, PairKernel::AreaExactNear) => {
                            (self.near_samples(i), self.near_samples(j))
                        }
                        (None, _) => (self.samples(i), self.samples(j)),
                    };
                    let judge = |a: &[(DVec3, f64)], b: &[(DVec3, f64)], cast: &mut u64| {
                        a.iter().fold((0.0, 0.0), |acc, &(p, wp)| {
                            let (v, t) = self.kernel_between(p, wp, ni, nj, b, candidates, cast);
                            (acc.0 + v, acc.1 + t)
                        })
                    };
                    let (mut visible, mut total) = judge(points_i, points_j, &mut cast);
                    // A near pair seen in part: judged again from FINE_POINTS lattice points
                    // on each side (of the parts facing each other), about 12 times the
                    // rays. A partly hidden pair of large elements (the wall behind a
                    // bookcase, seen between two shelves) is where 4 x 4 points miss most.
                    if self.kernel == PairKernel::AreaExactNear && visible > 0.0 && visible < total
                    {
                        let fine_i = sample_polygon(poly_i, FINE_POINTS);
                        let fine_j = sample_polygon(poly_j, FINE_POINTS);
                        let (v, t) = judge(&fine_i, &fine_j, &mut cast);
                        if t > 0.0 {
                            (visible, total) = (v, t);
                        }
                    }
                    if total > 0.0 {
                        exact * visible / total
                    } else {
                        exact
                    }
                }
            }
            PairKernel::Analytic => {
                let cj = self.corners(j);
                self.samples(i)
                    .iter()
                    .map(|&(p, wp)| {
                        let f = exact::point_to_polygon(p, ni, cj.as_slice());
                        if f <= 0.0 || candidates.is_empty() {
                            return wp * f;
                        }
                        let (v, t) = self.kernel_from(p, wp, ni, j, candidates, &mut cast);
                        if t > 0.0 {
                            wp * f * v / t
                        } else {
                            wp * f
                        }
                    })
                    .sum()
            }
        };
        rays.add_tested(cast, candidates.len() as u64);
        g
    }

    /// When polygon `a` (normal `na`) and polygon `b` (normal `nb`) do not lie wholly in
    /// front of each other, the parts that do (each clipped to the other's front
    /// half-space); `None` when nothing needs clipping (or nothing is left).
    fn facing_polygons(
        &self,
        a: &[DVec3],
        na: DVec3,
        b: &[DVec3],
        nb: DVec3,
    ) -> Option<(Vec<DVec3>, Vec<DVec3>)> {
        let tol = 1e-9 * self.ctx.occluders.scale();
        let behind = |p: &[DVec3], n: DVec3, o: DVec3| p.iter().any(|&v| n.dot(v - o) < -tol);
        if !behind(b, na, a[0]) && !behind(a, nb, b[0]) {
            return None;
        }
        let part = |p: &[DVec3], n: DVec3, o: DVec3| {
            exact::clip_front(p, n, o, DVec3::ZERO, 1.0).map(|c| c.as_slice().to_vec())
        };
        let (pa, pb) = (part(a, nb, b[0])?, part(b, na, a[0])?);
        (pa.len() >= 3 && pb.len() >= 3).then_some((pa, pb))
    }

    /// The area kernel summed over all point pairs of elements i and j: A_i F_ij by the
    /// midpoint rule, occluded point pairs left out.
    fn area_sum(&self, i: usize, j: usize, candidates: &[u32], cast: &mut u64) -> f64 {
        let ni = self.ctx.mesh.elements[i].normal;
        self.samples(i)
            .iter()
            .map(|&(p, wp)| self.kernel_from(p, wp, ni, j, candidates, cast).0)
            .sum()
    }

    /// True when elements i and j are closer than [`NEAR`] times the larger one's size
    /// (square root of its area), measured between their bounding boxes: symmetric, so the
    /// matrix stays reciprocal.
    fn near(&self, i: usize, j: usize) -> bool {
        let (a, b) = (self.element_box[i], self.element_box[j]);
        let gap = (a.0 - b.1).max(b.0 - a.1).max(DVec3::ZERO).length();
        let elements = &self.ctx.mesh.elements;
        let size = elements[i].area.max(elements[j].area).sqrt();
        gap < NEAR * size
    }

    /// The corners of element e (3 or 4), on the stack: this runs once per element pair.
    fn corners(&self, e: usize) -> Corners {
        let mut c = Corners {
            points: [DVec3::ZERO; 4],
            len: 0,
        };
        for p in self.ctx.mesh.corner_positions(e) {
            c.points[c.len] = p;
            c.len += 1;
        }
        c
    }

    /// The area kernel from point p (weight `wp`, on an element with normal `np`) to the
    /// samples of element j: (sum over visible samples, sum over all samples) of
    /// cos cos w_p w_q / (r^2 (pi r^2 + w)) with unit cosines (see the module doc).
    /// Visibility is tested against `candidates`, counting the rays cast in `cast`.
    #[inline]
    fn kernel_from(
        &self,
        p: DVec3,
        wp: f64,
        np: DVec3,
        j: usize,
        candidates: &[u32],
        cast: &mut u64,
    ) -> (f64, f64) {
        let nj = self.ctx.mesh.elements[j].normal;
        self.kernel_between(p, wp, np, nj, self.samples(j), candidates, cast)
    }

    /// [`AreaIntegrator::kernel_from`] to the given points `points_j` of an element with
    /// normal `nj`.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn kernel_between(
        &self,
        p: DVec3,
        wp: f64,
        np: DVec3,
        nj: DVec3,
        points_j: &[(DVec3, f64)],
        candidates: &[u32],
        cast: &mut u64,
    ) -> (f64, f64) {
        let occ = self.ctx.occluders;
        let (mut visible, mut total) = (0.0, 0.0);
        for &(q, wq) in points_j {
            let d = q - p;
            let r2 = d.length_squared();
            let cos_p = np.dot(d);
            let cos_q = -nj.dot(d);
            if cos_p <= 0.0 || cos_q <= 0.0 || r2 == 0.0 {
                continue;
            }
            // cos_p and cos_q carry a factor |d| each, hence r^2 twice.
            let k = cos_p * cos_q / (r2 * (PI * r2 + wp.max(wq))) * wp * wq;
            total += k;
            if !candidates.is_empty() {
                *cast += 1;
                // Every visible ray scans the whole list (tens of polygons per pair in a
                // furnished building). Measured on building_small, neither the occluder
                // hierarchy for long lists (17.8 -> 20.4 s of CPU) nor trying the last
                // blocker first was faster.
                if occ.segment_blocked_by(candidates, p, q) {
                    continue;
                }
            }
            visible += k;
        }
        (visible, total)
    }
}

/// About `count` points on the convex polygon `p` with area weights summing to its area,
/// for judging visibility: a quadrilateral gets `count` points of the rank-1 (Fibonacci)
/// lattice u_k = (k + 1/2) / N, v_k = frac(k g / N + 1/2N), g = round(N / phi), mapped
/// bilinearly and weighted by the Jacobian; any other polygon the fan of triangles from its
/// first corner, each with its share of the points on the lattice folded into the triangle
/// ((u, v) -> (1 - u, 1 - v) where u + v > 1). Unlike a k x k grid, whose points share k
/// columns, every point of the lattice has its own u and its own v, so an edge of a shadow
/// along either axis is resolved to 1/N of the polygon instead of 1/k (a 0.3 wide strip
/// hidden by a cover: counted 0.25 wide by an 8 x 8 grid).
fn sample_polygon(p: &[DVec3], count: usize) -> Vec<(DVec3, f64)> {
    let lattice = |n: usize| {
        let g = ((n as f64) / 1.618_033_988_749_895).round().max(1.0);
        (0..n).map(move |k| {
            let u = (k as f64 + 0.5) / n as f64;
            let v = ((k as f64 * g + 0.5) / n as f64).fract();
            (u, v)
        })
    };
    let mut out = Vec::with_capacity(count + 4);
    match p.len() {
        0..=2 => {}
        4 => {
            let start = out.len();
            let mut total = 0.0;
            for (u, v) in lattice(count.max(1)) {
                let w = crate::mesh::bilinear_jacobian(p, u, v);
                total += w;
                out.push((crate::mesh::bilinear(p, u, v), w));
            }
            let area = crate::geometry::polygon_area(p);
            let scale = if total > 0.0 { area / total } else { 0.0 };
            for (_, w) in &mut out[start..] {
                *w *= scale;
            }
        }
        k => {
            let fans = k - 2;
            let per = count.div_ceil(fans).max(1);
            for f in 1..k - 1 {
                let (a, b, c) = (p[0], p[f], p[f + 1]);
                let w = 0.5 * (b - a).cross(c - a).length() / per as f64;
                if w > 0.0 {
                    for (u, v) in lattice(per) {
                        let (u, v) = if u + v > 1.0 {
                            (1.0 - u, 1.0 - v)
                        } else {
                            (u, v)
                        };
                        out.push((a + u * (b - a) + v * (c - a), w));
                    }
                }
            }
        }
    }
    out
}

/// The unoccluded area-integral form factor F_12 from polygon 1 to polygon 2 (each planar
/// and convex, counter-clockwise from the front), with `k` x `k` points per polygon. For
/// tests and accuracy tables: it meshes nothing and casts no rays.
pub fn area_integral_pair(poly1: &[DVec3], poly2: &[DVec3], k: u32) -> f64 {
    use crate::mesh::mesh_scene;
    use crate::scene::{Rgb, Scene, Surface};
    let surface = |v: &[DVec3]| Surface {
        name: String::new(),
        emission: Rgb::BLACK,
        reflectance: Rgb::BLACK,
        vertices: v.to_vec(),
        photometry: Default::default(),
    };
    let scene = Scene {
        surfaces: vec![surface(poly1), surface(poly2)],
        camera: None,
        lights: Vec::new(),
    };
    let mesh = mesh_scene(&scene, f64::MAX).expect("two polygons always mesh");
    let empty = crate::visibility::PolygonBvh::new::<Vec<DVec3>>(&[], &[]);
    let ctx = FormFactorContext {
        mesh: &mesh,
        occluders: &empty,
    };
    let integrator = AreaIntegrator::new(&ctx, k, PairKernel::Area);
    integrator.couplings(0, 1..2, &RayCounter::default(), &mut Scratch::default())[0]
        / mesh.elements[0].area
}
