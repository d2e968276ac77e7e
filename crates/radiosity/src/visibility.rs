//! Ray queries against planar convex polygons through a bounding volume hierarchy.
//!
//! One [`PolygonBvh`] answers both queries the pipeline needs: "is the segment from p to q
//! blocked?" (an any-hit query, for form-factor occlusion) and "what does this ray hit
//! first?" (closest hit, for rendering). The hierarchy is obvhs's compressed wide BVH
//! (CWBVH, Ylitie et al. 2017), a maintained pure-Rust crate that needs no system library.
//!
//! The primitives are whole convex polygons, not triangles: obvhs's triangle test is not
//! watertight (a ray through the diagonal shared by two triangles of one quad can pass
//! between them, and form-factor sample points lie on such diagonals by symmetry), so the
//! leaf test here is written by hand: the ray meets the polygon's plane in f64, and the
//! point is inside when it is on the inner side of every edge (edges included).
//!
//! The hierarchy is in f32 and obvhs has absolute constants (a ray skips the boxes it leaves
//! within 1e-4 of its origin), so it is built in its own units: scene coordinates less the
//! centre of the scene's bounding box, times a power of two that makes the scene's diagonal
//! 16 to 32 units long. Scaling by a power of two is exact, so the hierarchy and every
//! answer are the same at any scale (a scene in metres or in light years, within
//! [`crate::geometry::MAX_COORDINATE`]), no f32 box area overflows or underflows, and a scene
//! far from the origin (a room at x = 1e9) keeps f32's precision. The leaf tests stay in
//! scene units, in f64.

use std::time::Duration;

use glam::{DVec3, UVec2, Vec3A};
use obvhs::{
    aabb::Aabb, cwbvh::builder::build_cwbvh, cwbvh::CwBvh, ray::Ray, ray::RayHit, Boundable,
    BvhBuildParams,
};

use crate::mesh::Mesh;
use crate::scene::Scene;

/// A polygon as the BVH builder sees it: its bounding box.
struct Bounds(Aabb);

impl Boundable for Bounds {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// One polygon, ready for ray tests.
#[derive(Clone, Debug)]
struct Polygon {
    /// Unit normal (front side).
    normal: DVec3,
    /// Plane offset: normal . x = offset on the plane.
    offset: f64,
    /// First corner in `PolygonBvh::corners`.
    first: u32,
    /// Number of corners.
    count: u32,
    /// Caller's id.
    id: u32,
    /// Bounding box.
    lo: DVec3,
    hi: DVec3,
}

/// Where obvhs 0.4's CWBVH traversal starts a ray's box tests (its `EPSILON`,
/// cwbvh/node.rs, crate-private), in the BVH's local units: boxes a ray leaves before it
/// are skipped.
const OBVHS_RAY_START_LOCAL: f64 = 1e-4;

/// Planar convex polygons, each tagged with a caller's id (for example the surface or the
/// element it is), in a BVH.
pub struct PolygonBvh {
    bvh: CwBvh,
    /// Polygons in BVH primitive order, so a leaf's primitive index is a direct lookup.
    polygons: Vec<Polygon>,
    corners: Vec<DVec3>,
    /// Per corner of each polygon, the inward unit normal m of the edge that starts there
    /// (in the polygon's plane) and m . (edge start): x is inside when m . x >= offset for
    /// every edge. Precomputed so the inside test is one dot product per edge.
    edge_planes: Vec<(DVec3, f64)>,
    /// Length of the bounding-box diagonal of all polygons, for relative tolerances.
    scale: f64,
    /// The centre of the scene's bounding box and the power of two that take scene units to
    /// the hierarchy's (module documentation).
    centre: DVec3,
    to_local: f64,
}

/// The first thing a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray direction.
    pub t: f64,
    /// The caller's id of the polygon hit.
    pub id: u32,
}

impl PolygonBvh {
    /// Builds the hierarchy over `polygons` (each planar and convex, at least 3 corners),
    /// each tagged with the id at the same index of `ids`.
    ///
    /// # Panics
    /// If `polygons` and `ids` differ in length.
    pub fn new<P: AsRef<[DVec3]>>(polygons: &[P], ids: &[u32]) -> PolygonBvh {
        assert_eq!(polygons.len(), ids.len());
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in polygons.iter().flat_map(|p| p.as_ref().iter()) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let scale = if polygons.is_empty() {
            1.0
        } else {
            (hi - lo).length().max(f64::MIN_POSITIVE)
        };
        let to_local = local_unit(scale);
        let centre = if polygons.is_empty() {
            DVec3::ZERO
        } else {
            0.5 * lo + 0.5 * hi
        };
        let local = |v: DVec3| to_f32((v - centre) * to_local);
        // Pad boxes so that flat, axis-aligned polygons get boxes of non-zero thickness and
        // the f32, quantised node boxes of the CWBVH cannot make a ray miss a polygon it
        // meets. With 1e-6 of the scene size, one Monte Carlo ray in 10^5 leaked out of a
        // closed cube near a corner; 1e-5 closes the leak (f32 rounds the hierarchy's
        // coordinates, at most 32 from its centre, by 3.8e-6 units at most: well inside
        // the pad, at least 1.6e-4 units).
        let pad = (1e-5 * scale * to_local) as f32;
        let mut bounds: Vec<Bounds> = polygons
            .iter()
            .map(|p| {
                let pts: Vec<Vec3A> = p.as_ref().iter().map(|v| local(*v)).collect();
                let b = Aabb::from_points(&pts);
                Bounds(Aabb::new(
                    b.min - Vec3A::splat(pad),
                    b.max + Vec3A::splat(pad),
                ))
            })
            .collect();
        spread_identical_boxes(&mut bounds);
        let mut corners = Vec::new();
        let mut edge_planes = Vec::new();
        let mut records = Vec::with_capacity(polygons.len());
        for (p, &id) in polygons.iter().zip(ids) {
            let v = p.as_ref();
            let normal = crate::geometry::polygon_normal(v).unwrap_or(DVec3::Z);
            let offset = normal.dot(crate::geometry::vertex_mean(v));
            let lo = v.iter().fold(DVec3::splat(f64::INFINITY), |a, b| a.min(*b));
            let hi = v
                .iter()
                .fold(DVec3::splat(f64::NEG_INFINITY), |a, b| a.max(*b));
            records.push(Polygon {
                normal,
                offset,
                first: corners.len() as u32,
                count: v.len() as u32,
                id,
                lo,
                hi,
            });
            corners.extend_from_slice(v);
            // The corners run counter-clockwise about the normal, so n x edge points inward.
            for (i, &a) in v.iter().enumerate() {
                let m = normal.cross(v[(i + 1) % v.len()] - a).normalize_or_zero();
                edge_planes.push((m, m.dot(a)));
            }
        }
        if bounds.is_empty() {
            return PolygonBvh {
                bvh: CwBvh::default(),
                polygons: records,
                corners,
                edge_planes,
                scale,
                centre,
                to_local,
            };
        }
        let bvh = build_cwbvh(
            &bounds,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let polygons = bvh
            .primitive_indices
            .iter()
            .map(|&i| records[i as usize].clone())
            .collect();
        PolygonBvh {
            bvh,
            polygons,
            corners,
            edge_planes,
            scale,
            centre,
            to_local,
        }
    }

    /// The hierarchy over every element of `mesh`, each tagged with its element index (the
    /// BVH that rendering, Monte Carlo form factors and solution comparison cast rays into).
    pub fn over_elements(mesh: &Mesh) -> PolygonBvh {
        let polygons: Vec<Vec<DVec3>> = (0..mesh.len())
            .map(|e| mesh.corner_positions(e).collect())
            .collect();
        let ids: Vec<u32> = (0..mesh.len() as u32).collect();
        PolygonBvh::new(&polygons, &ids)
    }

    /// The hierarchy over every input surface of `scene`, each tagged with its surface index
    /// (the occluders of form-factor visibility, and the walls the automatic camera probes).
    pub fn over_surfaces(scene: &Scene) -> PolygonBvh {
        let polygons: Vec<&[DVec3]> = scene
            .surfaces
            .iter()
            .map(|s| s.vertices.as_slice())
            .collect();
        let ids: Vec<u32> = (0..polygons.len() as u32).collect();
        PolygonBvh::new(&polygons, &ids)
    }

    /// A scene point in the hierarchy's units (module documentation).
    fn local(&self, v: DVec3) -> Vec3A {
        to_f32((v - self.centre) * self.to_local)
    }

    /// The number of polygons.
    pub fn len(&self) -> usize {
        self.polygons.len()
    }

    /// True when there are no polygons.
    pub fn is_empty(&self) -> bool {
        self.polygons.is_empty()
    }

    /// The length of the bounding-box diagonal of all polygons.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Where the ray `origin + t dir` meets polygon `k` with `t_min <= t <= t_max`.
    #[inline]
    fn intersect(
        &self,
        k: usize,
        origin: DVec3,
        dir: DVec3,
        t_min: f64,
        t_max: f64,
    ) -> Option<f64> {
        let poly = &self.polygons[k];
        let denom = poly.normal.dot(dir);
        if denom == 0.0 {
            return None;
        }
        let t = (poly.offset - poly.normal.dot(origin)) / denom;
        if !(t >= t_min && t <= t_max) {
            return None;
        }
        let x = origin + t * dir;
        // Inside (edges included, to 1e-9 of the scene size) when on the inner side of
        // every edge.
        let tol = 1e-9 * self.scale;
        let planes = &self.edge_planes[poly.first as usize..(poly.first + poly.count) as usize];
        if planes.iter().all(|&(m, offset)| m.dot(x) >= offset - tol) {
            Some(t)
        } else {
            None
        }
    }

    /// Appends to `out` every polygon (as an index for [`PolygonBvh::segment_blocked_by`])
    /// whose bounding box overlaps the box from `lo` to `hi`: a BVH box query. Together
    /// with the segment test below this gives shaft-style culling: the segments between two
    /// elements stay inside the box around both, so only these polygons can block them.
    pub fn overlapping(&self, lo: DVec3, hi: DVec3, out: &mut Vec<u32>) {
        self.overlapping_where(lo, hi, usize::MAX, |_| true, out);
    }

    /// [`PolygonBvh::overlapping`], keeping only the polygons for which `keep` (given the
    /// index) is true, and stopping once more than `limit` are kept: false then (`out`
    /// holds `limit + 1` of them), true when all are in `out`. A caller that scans a short
    /// list and traverses the hierarchy for a long one need not find the whole long one.
    pub fn overlapping_where(
        &self,
        lo: DVec3,
        hi: DVec3,
        limit: usize,
        mut keep: impl FnMut(u32) -> bool,
        out: &mut Vec<u32>,
    ) -> bool {
        if self.polygons.is_empty() {
            return true;
        }
        let pad = 1e-6 * self.scale;
        let query = Aabb::new(
            self.local(lo - DVec3::splat(pad)),
            self.local(hi + DVec3::splat(pad)),
        );
        let bvh = &self.bvh;
        let mut state = bvh.new_traversal(Vec3A::ZERO);
        let mut node;
        // The traversal gives every polygon of a leaf whose node box meets the query; each
        // is kept only when its own box (in f64) does. Without this the answer depended on
        // how the hierarchy grouped its leaves, which rounding changes with the scene's
        // scale (QA of issue #16: the ceiling over a light panel was contact-refined at
        // `--scale 1` and not at 7.7).
        let (lo, hi) = (lo - DVec3::splat(pad), hi + DVec3::splat(pad));
        let mut found = 0usize;
        obvhs::traverse!(
            bvh,
            node,
            state,
            node.intersect_aabb(&query, state.oct_inv4),
            {
                let poly = &self.polygons[state.primitive_id as usize];
                if poly.lo.cmple(hi).all() && poly.hi.cmpge(lo).all() && keep(state.primitive_id) {
                    out.push(state.primitive_id);
                    found += 1;
                    if found > limit {
                        // Ends the traversal: nothing left in this leaf, this node or the
                        // stack.
                        state.primitive_group = UVec2::ZERO;
                        state.current_group = UVec2::ZERO;
                        while state.stack.pop().is_some() {}
                    }
                }
            }
        );
        found <= limit
    }

    /// The bounding box (min, max) of polygon `index` (an index from
    /// [`PolygonBvh::overlapping`]).
    pub fn box_of(&self, index: u32) -> (DVec3, DVec3) {
        let poly = &self.polygons[index as usize];
        (poly.lo, poly.hi)
    }

    /// The caller's id of polygon `index` (an index from [`PolygonBvh::overlapping`]).
    pub fn id_of(&self, index: u32) -> u32 {
        self.polygons[index as usize].id
    }

    /// The corners of polygon `index` (an index from [`PolygonBvh::overlapping`]).
    pub fn corners_of(&self, index: u32) -> &[DVec3] {
        let poly = &self.polygons[index as usize];
        &self.corners[poly.first as usize..(poly.first + poly.count) as usize]
    }

    /// The unit direction, length and end trim (1e-7 of the scene's diagonal) of the segment
    /// from `p` to `q`; `None` where it is no longer than the two trims.
    #[inline]
    fn trimmed(&self, p: DVec3, q: DVec3) -> Option<(DVec3, f64, f64)> {
        let d = q - p;
        let len = d.length();
        let eps = 1e-7 * self.scale;
        (len > 2.0 * eps).then(|| (d / len, len, eps))
    }

    /// The BVH ray (local f32 coordinates) along a segment of [`PolygonBvh::trimmed`], a
    /// little longer than the segment so that f32 rounding cannot cut it short.
    fn segment_ray(&self, p: DVec3, dir: DVec3, len: f64, eps: f64) -> Ray {
        Ray::new(
            self.local(p),
            to_f32(dir),
            0.0,
            ((len * 1.001 + eps) * self.to_local) as f32,
        )
    }

    /// True when one of the polygons `candidates` (indices from [`PolygonBvh::overlapping`])
    /// crosses the open segment from `p` to `q`, trimmed as in [`PolygonBvh::segment_blocked`].
    #[inline]
    pub fn segment_blocked_by(&self, candidates: &[u32], p: DVec3, q: DVec3) -> bool {
        let Some((dir, len, eps)) = self.trimmed(p, q) else {
            return false;
        };
        candidates
            .iter()
            .any(|&k| self.intersect(k as usize, p, dir, eps, len - eps).is_some())
    }

    /// [`PolygonBvh::segment_blocked_by`], moving the candidate that blocks to the front of
    /// `candidates`: segments between the same two patches are mostly blocked by the same
    /// occluder, which the next segment then tests first (a shadow cache, Haines and
    /// Greenberg 1986). The answer is the same; only the order of the tests changes.
    #[inline]
    pub fn segment_blocked_by_first(&self, candidates: &mut [u32], p: DVec3, q: DVec3) -> bool {
        let Some((dir, len, eps)) = self.trimmed(p, q) else {
            return false;
        };
        match candidates
            .iter()
            .position(|&k| self.intersect(k as usize, p, dir, eps, len - eps).is_some())
        {
            Some(i) => {
                candidates.swap(0, i);
                true
            }
            None => false,
        }
    }

    /// [`PolygonBvh::segment_blocked`], testing polygon `*last` (an index as from
    /// [`PolygonBvh::overlapping`]) before the hierarchy, and setting it to the polygon that
    /// blocks this segment, if any: a shadow cache (Haines and Greenberg 1986) for a run of
    /// segments between the same two patches, where one test then stands for a traversal.
    /// The answer is the same as without the cache.
    pub fn segment_blocked_cached(&self, p: DVec3, q: DVec3, last: &mut Option<u32>) -> bool {
        if self.polygons.is_empty() {
            return false;
        }
        let Some((dir, len, eps)) = self.trimmed(p, q) else {
            return false;
        };
        if let Some(k) = *last {
            // Trusted only clear of the segment's start: obvhs's traversal skips boxes a
            // ray leaves within its EPSILON (1e-4 local units) of the origin, so a hit as
            // near is left to the traversal, whose answer this must be (review of #11: a
            // hit between the trim and that distance blocked through the cache only).
            let near = 10.0 * OBVHS_RAY_START_LOCAL / self.to_local;
            if (k as usize) < self.polygons.len()
                && self
                    .intersect(k as usize, p, dir, eps, len - eps)
                    .is_some_and(|t| t > near)
            {
                return true;
            }
        }
        let to_local = self.to_local;
        let ray = self.segment_ray(p, dir, len, eps);
        let mut blocker = None;
        let missed = self.bvh.ray_traverse_miss(ray, |_, k| {
            match self.intersect(k, p, dir, eps, len - eps) {
                Some(t) => {
                    blocker = Some(k as u32);
                    (t * to_local) as f32
                }
                None => f32::INFINITY,
            }
        });
        if !missed {
            *last = blocker;
        }
        !missed
    }

    /// True when some polygon crosses the open segment from `p` to `q`.
    ///
    /// The segment's ends are trimmed by 1e-7 of the scene's diagonal, so surfaces that
    /// `p` and `q` lie on, and surfaces that meet them at a shared edge, do not block it.
    pub fn segment_blocked(&self, p: DVec3, q: DVec3) -> bool {
        self.segment_blocked_except(p, q, u32::MAX)
    }

    /// [`PolygonBvh::segment_blocked`], not counting the polygons whose caller's id is
    /// `ignored`: the surface a segment ends on, which a planar convex surface can only
    /// cross there, but which rounding makes it cross earlier where the segment runs
    /// along its plane (a point on the edge where two walls meet, QA of issue #16).
    pub fn segment_blocked_except(&self, p: DVec3, q: DVec3, ignored: u32) -> bool {
        if self.polygons.is_empty() {
            return false;
        }
        let Some((dir, len, eps)) = self.trimmed(p, q) else {
            return false;
        };
        let to_local = self.to_local;
        let ray = self.segment_ray(p, dir, len, eps);
        !self.bvh.ray_traverse_miss(ray, |_, k| {
            if self.polygons[k].id == ignored {
                return f32::INFINITY;
            }
            match self.intersect(k, p, dir, eps, len - eps) {
                Some(t) => (t * to_local) as f32,
                None => f32::INFINITY,
            }
        })
    }

    /// The caller's id of a polygon that contains the point `p`: `p` lies within
    /// `tolerance` of the polygon's plane and its projection onto the plane is inside the
    /// polygon (edges included, to the tolerance of ray hits). Where several do (a point on
    /// a shared edge, overlapping polygons), the first in BVH order.
    ///
    /// A box query and the inside test, not a ray: obvhs's ray traversal skips every box
    /// that a ray leaves within 1e-4 of its origin (an absolute distance in the hierarchy's
    /// units, its `EPSILON`, which stands in for the ray's own t_min; about 1e-7 of the
    /// scene's diagonal), so a short enough ray through a point on a polygon finds nothing.
    pub fn polygon_at(&self, p: DVec3, tolerance: f64) -> Option<u32> {
        self.polygons_containing(p, tolerance)
            .first()
            .map(|&k| self.polygons[k as usize].id)
    }

    /// The polygons (as indices) that contain `p` to `tolerance`, in BVH order: those whose
    /// boxes meet the point's and whose plane, crossed along the normal within the
    /// tolerance, is met inside the polygon.
    fn polygons_containing(&self, p: DVec3, tolerance: f64) -> Vec<u32> {
        let mut candidates = Vec::new();
        self.overlapping(
            p - DVec3::splat(tolerance),
            p + DVec3::splat(tolerance),
            &mut candidates,
        );
        candidates.retain(|&k| {
            let poly = &self.polygons[k as usize];
            let origin = p + tolerance * poly.normal;
            self.intersect(k as usize, origin, -poly.normal, 0.0, 2.0 * tolerance)
                .is_some()
        });
        candidates
    }

    /// Whether a polygon whose back faces along `dir` (normal . dir > 0) contains the point
    /// `p`, to `tolerance` ([`PolygonBvh::polygon_at`]'s test). Where two faces lie back to
    /// back in one plane (a box's base on the floor) a ray meets both at the same distance
    /// and which [`PolygonBvh::closest_hit`] reports is rounding; this finds the back one.
    ///
    /// `accept` is given each such polygon's caller's id and decides whether it counts (a
    /// caller leaves out the back half of a two-sided wall, the same polygon facing the
    /// other way, which is no box standing on anything).
    pub fn back_face_at(
        &self,
        p: DVec3,
        dir: DVec3,
        tolerance: f64,
        accept: impl Fn(u32) -> bool,
    ) -> bool {
        self.polygons_containing(p, tolerance).into_iter().any(|k| {
            let poly = &self.polygons[k as usize];
            poly.normal.dot(dir) > 0.0 && accept(poly.id)
        })
    }

    /// The first polygon hit by the ray from `origin` along unit `dir`, with `t_min <= t <= t_max`.
    pub fn closest_hit(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64) -> Option<Hit> {
        if self.polygons.is_empty() {
            return None;
        }
        let to_local = self.to_local;
        let ray = Ray::new(
            self.local(origin),
            to_f32(dir),
            0.0,
            (t_max * 1.001 * to_local) as f32,
        );
        let mut hit = RayHit::none();
        let mut best: Option<(f64, u32)> = None;
        self.bvh.ray_traverse(ray, &mut hit, |_, k| {
            let limit = best.map_or(t_max, |b| b.0);
            match self.intersect(k, origin, dir, t_min, limit) {
                Some(t) => {
                    best = Some((t, self.polygons[k].id));
                    // Report a t just inside the f32 ray's range so the traversal keeps
                    // shrinking its interval; the exact t is kept in f64 in `best`.
                    (t * to_local) as f32
                }
                None => f32::INFINITY,
            }
        });
        best.map(|(t, id)| Hit { t, id })
    }
}

/// The shortest diagonal of the scene in the hierarchy's units (module documentation): 16,
/// so that obvhs's absolute constants are small against the scene (its rays skip boxes
/// they leave within 1e-4 of their origin: 6e-6 of the diagonal at most) and large against
/// f32's rounding there (the ulp at 32 is 3.8e-6, below the 1e-5 its debug validation of a
/// built hierarchy allows; at 1024 to 2048 units, the ulp of 1.2e-4 failed that validation
/// on two ordinary boxes, found by the fuzzer).
const LOCAL_DIAGONAL: f64 = 16.0;

/// Makes boxes that are the same (bit for bit) different, each still holding its own:
/// the k-th of n equal boxes grows by (n - 1 - k) steps below and k steps above (a step
/// two units in the last place of its largest coordinate), so the n boxes are the same
/// size and slide apart. obvhs's builder chains equal boxes into a tree deeper than its
/// traversal stack (32): a few hundred copies of one polygon, or many small polygons far
/// from the rest whose boxes round to the same `f32`s (found by the VRML and DXF fuzz
/// targets), failed its debug validation with a panic and would be walked wrongly in a
/// release build. Growing a box only adds candidates to test, never loses a hit.
fn spread_identical_boxes(bounds: &mut [Bounds]) {
    let key = |b: &Bounds| {
        let (lo, hi) = (b.0.min, b.0.max);
        [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z].map(f32::to_bits)
    };
    let mut groups: std::collections::HashMap<[u32; 6], (usize, usize)> =
        std::collections::HashMap::new();
    for b in bounds.iter() {
        groups.entry(key(b)).or_insert((0, 0)).0 += 1;
    }
    if groups.len() == bounds.len() {
        return;
    }
    for b in bounds.iter_mut() {
        let Some((n, next)) = groups.get_mut(&key(b)) else {
            continue;
        };
        if *n < 2 {
            continue;
        }
        let k = *next;
        *next += 1;
        let reach = b.0.min.abs().max(b.0.max.abs()).max_element();
        let step = 2.0 * f32::EPSILON * (reach + 1.0);
        b.0.min -= Vec3A::splat((*n - 1 - k) as f32 * step);
        b.0.max += Vec3A::splat(k as f32 * step);
    }
}

/// The power of two that makes a scene of diagonal `scale` [`LOCAL_DIAGONAL`] to twice that
/// of the hierarchy's units long (module documentation).
fn local_unit(scale: f64) -> f64 {
    let e = (LOCAL_DIAGONAL / scale)
        .log2()
        .floor()
        .clamp(-1000.0, 1000.0) as i32;
    let unit = 2f64.powi(e);
    // log2 may round either way; one step fixes it.
    if scale * unit < LOCAL_DIAGONAL {
        2.0 * unit
    } else if scale * unit >= 2.0 * LOCAL_DIAGONAL {
        0.5 * unit
    } else {
        unit
    }
}

/// Converts to f32, turning -0.0 into +0.0: obvhs picks the traversal octant from the sign
/// bits of the direction, and a -0.0 component makes its slab tests miss (found by the unit
/// test `closest_hit_reports_nearest_id`, which shoots along -Z).
fn to_f32(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32 + 0.0, v.y as f32 + 0.0, v.z as f32 + 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    #[test]
    fn hundreds_of_polygons_with_one_box_pass_obvhs_validation() {
        // 300 copies of a triangle (the DXF fuzz target's zero-spaced INSERT grid), and
        // 300 different small triangles far from a large one, whose boxes round to the
        // same f32s in the hierarchy's units (the VRML fuzz target's far-off Transform):
        // obvhs chained equal boxes deeper than its traversal stack and its validation
        // (debug assertions, as in this test) panicked. Every copy is still found.
        let tri = vec![
            dvec3(-1.0, 0.0, 0.0),
            dvec3(-1.1, 0.0, 0.0),
            dvec3(-1.0, 0.0, -1.0),
        ];
        let polygons = vec![tri; 300];
        let ids: Vec<u32> = (0..300).collect();
        let bvh = PolygonBvh::new(&polygons, &ids);
        let mut found = Vec::new();
        bvh.overlapping(
            dvec3(-1.05, -0.1, -0.2),
            dvec3(-1.04, 0.1, -0.1),
            &mut found,
        );
        found.sort_unstable();
        assert_eq!(found, (0..300).collect::<Vec<u32>>());
        let mut polygons: Vec<Vec<DVec3>> = (0..300)
            .map(|k| {
                let d = k as f64 * 1e-14;
                vec![
                    dvec3(d, 0.0, 0.0),
                    dvec3(d + 1e-12, 0.0, 0.0),
                    dvec3(d, 1e-12, 0.0),
                ]
            })
            .collect();
        polygons.push(vec![
            dvec3(0.0, 1e17, 0.0),
            dvec3(1e17, 1e17, 0.0),
            dvec3(0.0, 1e17, 1e17),
        ]);
        let ids: Vec<u32> = (0..301).collect();
        let bvh = PolygonBvh::new(&polygons, &ids);
        let mut found = Vec::new();
        bvh.overlapping(dvec3(-1.0, -1.0, -1.0), dvec3(1.0, 1.0, 1.0), &mut found);
        assert_eq!(found.len(), 300);
    }

    #[test]
    fn a_box_query_returns_exactly_the_polygons_whose_boxes_meet_it() {
        // 400 small squares on a 20 x 20 lattice of pitch 1 (0.4 wide); queries of every
        // size: the answer is the brute-force list, not every polygon of a leaf that the
        // hierarchy happened to group with one that meets the query (QA of issue #16).
        let mut polygons = Vec::new();
        for j in 0..20 {
            for i in 0..20 {
                let (x, z) = (i as f64, j as f64);
                polygons.push(vec![
                    dvec3(x, 0.0, z),
                    dvec3(x, 0.0, z + 0.4),
                    dvec3(x + 0.4, 0.0, z + 0.4),
                    dvec3(x + 0.4, 0.0, z),
                ]);
            }
        }
        let ids: Vec<u32> = (0..polygons.len() as u32).collect();
        let bvh = PolygonBvh::new(&polygons, &ids);
        let pad = 1e-6 * bvh.scale();
        for (k, size) in [0.05, 0.3, 0.7, 2.5].into_iter().enumerate() {
            for q in 0..25 {
                let lo = dvec3(
                    0.37 * q as f64 + 0.11 * k as f64,
                    -0.1,
                    0.53 * q as f64 + 0.07,
                );
                let hi = lo + dvec3(size, 0.2, size);
                let mut found = Vec::new();
                bvh.overlapping(lo, hi, &mut found);
                let mut found: Vec<u32> = found.into_iter().map(|f| bvh.id_of(f)).collect();
                found.sort_unstable();
                let expected: Vec<u32> = (0..polygons.len())
                    .filter(|&p| {
                        let (plo, phi) = (polygons[p][0], polygons[p][2]);
                        plo.cmple(hi + DVec3::splat(pad)).all()
                            && phi.cmpge(lo - DVec3::splat(pad)).all()
                    })
                    .map(|p| p as u32)
                    .collect();
                assert_eq!(found, expected, "query {lo} .. {hi}");
                // Filtered and limited: the same polygons the filter keeps, all of them
                // (true) up to the limit, else limit + 1 of them (false), the traversal
                // ended early.
                let keep = |k: u32| bvh.id_of(k) % 3 != 0;
                let kept: Vec<u32> = expected.iter().copied().filter(|id| id % 3 != 0).collect();
                for limit in [0, 1, 5, 32, usize::MAX] {
                    let mut out = Vec::new();
                    let all = bvh.overlapping_where(lo, hi, limit, keep, &mut out);
                    let mut out: Vec<u32> = out.into_iter().map(|f| bvh.id_of(f)).collect();
                    out.sort_unstable();
                    assert_eq!(all, kept.len() <= limit, "limit {limit}");
                    if all {
                        assert_eq!(out, kept, "limit {limit}");
                    } else {
                        assert_eq!(out.len(), limit + 1, "limit {limit}");
                        assert!(out.iter().all(|id| kept.contains(id)), "limit {limit}");
                    }
                }
            }
        }
    }

    /// A segment that ends on a surface and runs along its plane is not blocked by that
    /// surface where it is ignored (review of issue #16: a point on the edge where two
    /// walls meet had its shadow rays to the other wall blocked by rounding).
    #[test]
    fn a_segment_is_not_blocked_by_the_surface_it_ignores() {
        // A wall in the plane z = 0, id 7 (no polygon has id 8).
        let wall = vec![
            dvec3(0.0, 0.0, 0.0),
            dvec3(1.0, 0.0, 0.0),
            dvec3(1.0, 1.0, 0.0),
            dvec3(0.0, 1.0, 0.0),
        ];
        let bvh = PolygonBvh::new(&[wall], &[7]);
        // Crossing the wall's middle: blocked unless the wall is ignored.
        let (p, q) = (dvec3(0.5, 0.5, -1.0), dvec3(0.5, 0.5, 1.0));
        assert!(bvh.segment_blocked(p, q));
        assert!(bvh.segment_blocked_except(p, q, 8));
        assert!(!bvh.segment_blocked_except(p, q, 7));
    }

    /// The shadow caches change only the order of the tests: across runs of segments, some
    /// blocked by the square tried first and some not, the answers are those of a
    /// brute-force test (vertical segments against horizontal squares: blocked where a
    /// square between the ends holds the segment's (x, y)), and the cache names a square
    /// that does block.
    #[test]
    fn shadow_caches_give_the_brute_force_answers() {
        // 60 unit squares at heights 0.5, 1.5, ..., offset over a 10 x 6 area.
        let squares: Vec<(f64, f64, f64)> = (0..60)
            .map(|k| {
                let (x, y) = crate::splitmix::jitter(17, k);
                (9.0 * x, 5.0 * y, 0.5 + (k % 7) as f64)
            })
            .collect();
        let polygons: Vec<Vec<DVec3>> = squares
            .iter()
            .map(|&(x, y, z)| {
                vec![
                    dvec3(x, y, z),
                    dvec3(x + 1.0, y, z),
                    dvec3(x + 1.0, y + 1.0, z),
                    dvec3(x, y + 1.0, z),
                ]
            })
            .collect();
        let ids: Vec<u32> = (0..60).collect();
        let bvh = PolygonBvh::new(&polygons, &ids);
        let mut last = None;
        let (mut blocked_count, mut cached_hits) = (0, 0);
        for k in 0..400 {
            let (u, v) = crate::splitmix::jitter(99, k);
            // Runs of eight segments near one another, as a link's point pairs are.
            let (a, b) = crate::splitmix::jitter(5, k / 8);
            let (x, y) = (10.0 * a + 0.3 * u, 6.0 * b + 0.3 * v);
            let (z0, z1) = ((k % 5) as f64, 7.5 - (k % 3) as f64);
            let (p, q) = (dvec3(x, y, z0), dvec3(x, y, z1));
            let blocking: Vec<u32> = squares
                .iter()
                .enumerate()
                .filter(|(_, &(sx, sy, sz))| {
                    sz > z0 && sz < z1 && x >= sx && x <= sx + 1.0 && y >= sy && y <= sy + 1.0
                })
                .map(|(i, _)| i as u32)
                .collect();
            let expected = !blocking.is_empty();
            let before = last;
            assert_eq!(
                bvh.segment_blocked_cached(p, q, &mut last),
                expected,
                "{p} {q}"
            );
            if expected {
                blocked_count += 1;
                let id = bvh.id_of(last.expect("a blocked segment names its blocker"));
                assert!(
                    blocking.contains(&id),
                    "cached square {id} does not block {p} {q}"
                );
                cached_hits += usize::from(before == last);
            }
            let mut candidates = Vec::new();
            bvh.overlapping(p.min(q), p.max(q), &mut candidates);
            candidates.reverse();
            assert_eq!(
                bvh.segment_blocked_by_first(&mut candidates, p, q),
                expected
            );
            if expected {
                assert!(blocking.contains(&bvh.id_of(candidates[0])));
            }
        }
        // The test must exercise both: blocked segments, and blockers found in the cache.
        assert!(
            blocked_count > 50 && cached_hits > 20,
            "{blocked_count} {cached_hits}"
        );
        // A cached blocker nearer the segment's start than the traversal looks (review of
        // #11): the answer is still the traversal's, at every distance from the trim (1e-7
        // of the diagonal) out.
        let (sx, sy, sz) = squares[0];
        let centre = dvec3(sx + 0.5, sy + 0.5, sz);
        let mut found = Vec::new();
        bvh.overlapping(
            centre - DVec3::splat(1e-3),
            centre + DVec3::splat(1e-3),
            &mut found,
        );
        let index = *found.iter().find(|&&k| bvh.id_of(k) == 0).unwrap();
        for gap in [2e-6, 5e-6, 1e-5, 3e-5, 1e-4, 1e-3] {
            let (p, q) = (centre - DVec3::Z * gap, centre + DVec3::Z * 0.4);
            let mut last = Some(index);
            assert_eq!(
                bvh.segment_blocked_cached(p, q, &mut last),
                bvh.segment_blocked(p, q),
                "gap {gap}"
            );
        }
    }

    #[test]
    fn hierarchy_of_two_ordinary_boxes_passes_obvhs_validation() {
        // Found by the scene fuzzer (fuzz/corpus/scene_file/bvh_units_two_boxes.scene): in
        // units of a 1024 to 2048 long diagonal, f32's rounding (1.2e-4) broke obvhs's own
        // validation of the built hierarchy (node origins within 1e-5 of their parent's
        // box), which runs when debug assertions are on, as in this test. The faces of two
        // rooms, 0..5 x 0..3 x 0..4 and 7..11 x 1..4 x 0..4, facing in.
        let text = "MAX_PATCH_AREA 0.05
INTEGRAL_STEPS 2
SCENEBEGIN
BOXBEGIN
#A
FACING IN
Er 0
Eg 0
Eb 0
Rr 0.7
Rg 0.7
Rb 0.7
ORIGIN 0 0 0
SIZE 5 3 4
BOXEND
BOXBEGIN
#B
FACING IN
Er 0
Eg 0
Eb 0
Rr 0.7
Rg 0.7
Rb 0.7
ORIGIN 7 1 0
SIZE 4 3 4
BOXEND
SCENEEND
";
        let file = crate::io::scene_file::parse_scene(text, "two_boxes.scene").unwrap();
        let bvh = PolygonBvh::over_surfaces(&file.scene);
        // And it answers: a ray across room A from its floor hits its ceiling.
        let hit = bvh
            .closest_hit(dvec3(2.5, 0.0, 2.0), DVec3::Y, 1e-9, 10.0)
            .expect("the ceiling");
        assert!((hit.t - 3.0).abs() < 1e-9, "{}", hit.t);
    }

    fn square_at_z(z: f64, id: u32) -> (Vec<Vec<DVec3>>, Vec<u32>) {
        let (a, b, c, d) = (
            dvec3(0., 0., z),
            dvec3(1., 0., z),
            dvec3(1., 1., z),
            dvec3(0., 1., z),
        );
        (vec![vec![a, b, c, d]], vec![id])
    }

    #[test]
    fn segment_through_square_is_blocked() {
        let (t, ids) = square_at_z(1.0, 7);
        let bvh = PolygonBvh::new(&t, &ids);
        assert!(bvh.segment_blocked(dvec3(0.5, 0.5, 0.0), dvec3(0.5, 0.5, 2.0)));
        assert!(!bvh.segment_blocked(dvec3(0.5, 0.5, 0.0), dvec3(0.5, 0.5, 0.9)));
        assert!(!bvh.segment_blocked(dvec3(1.5, 0.5, 0.0), dvec3(1.5, 0.5, 2.0)));
        // The square's centre and edges block too (no gaps between pieces).
        assert!(bvh.segment_blocked(dvec3(0.5, 0.5, 0.0), dvec3(0.5, 0.5, 2.0)));
        assert!(bvh.segment_blocked(dvec3(1.0, 0.5, 0.0), dvec3(1.0, 0.5, 2.0)));
        // A segment that ends on the square itself is not blocked by it.
        assert!(!bvh.segment_blocked(dvec3(0.5, 0.5, 0.0), dvec3(0.3, 0.3, 1.0)));
    }

    #[test]
    fn closest_hit_reports_nearest_id() {
        let (mut t, mut ids) = square_at_z(1.0, 1);
        let (t2, ids2) = square_at_z(2.0, 2);
        t.extend(t2);
        ids.extend(ids2);
        let bvh = PolygonBvh::new(&t, &ids);
        let hit = bvh
            .closest_hit(dvec3(0.25, 0.5, 3.0), -DVec3::Z, 0.0, 10.0)
            .unwrap();
        assert_eq!(hit.id, 2);
        assert!((hit.t - 1.0).abs() < 1e-6);
        assert!(bvh
            .closest_hit(dvec3(5.0, 0.5, 3.0), -DVec3::Z, 0.0, 10.0)
            .is_none());
    }

    #[test]
    fn polygon_at_finds_points_on_polygons_however_close_the_tolerance() {
        // The unit square at z = 1 (id 1) and one at z = 1 + 1e-3 (id 2) above it.
        let (mut t, mut ids) = square_at_z(1.0, 1);
        let (t2, ids2) = square_at_z(1.0 + 1e-3, 2);
        t.extend(t2);
        ids.extend(ids2);
        let bvh = PolygonBvh::new(&t, &ids);
        let p = dvec3(0.3, 0.6, 1.0);
        assert_eq!(bvh.polygon_at(p, 1e-6), Some(1));
        assert_eq!(bvh.polygon_at(p + 1e-3 * DVec3::Z, 1e-6), Some(2));
        // Off both planes, and off the squares' side.
        assert_eq!(bvh.polygon_at(p + 5e-4 * DVec3::Z, 1e-6), None);
        assert_eq!(bvh.polygon_at(dvec3(1.5, 0.5, 1.0), 1e-6), None);
        // An edge belongs to the square.
        assert_eq!(bvh.polygon_at(dvec3(1.0, 0.5, 1.0), 1e-6), Some(1));
        // What polygon_at replaces: obvhs skips the boxes a ray leaves within 1e-4 of its
        // origin, in the hierarchy's units (the diagonal, sqrt(2 + 1e-6), is 16 of them
        // times sqrt 2: a square far from these units would see the same). A ray of 2e-4
        // scene units (3.2e-3 units of the hierarchy) finds the square; one of 2e-8 (3.2e-7
        // units, below 1e-4) finds nothing. If the second starts to pass, obvhs has changed
        // and the note at polygon_at can go.
        assert_eq!(
            bvh.closest_hit(p + 1e-4 * DVec3::Z, -DVec3::Z, 0.0, 2e-4)
                .map(|h| h.id),
            Some(1)
        );
        assert_eq!(
            bvh.closest_hit(p + 1e-8 * DVec3::Z, -DVec3::Z, 0.0, 2e-8),
            None
        );
    }

    #[test]
    fn element_and_surface_hierarchies_carry_their_indices() {
        use crate::scene::{Rgb, Surface};
        // Two unit squares facing -z at z = 1 and z = 2, the second cut into 4 elements.
        let surface = |name: &str, z: f64| Surface {
            name: name.into(),
            emission: Rgb([0.0; 3]),
            reflectance: Rgb([0.5; 3]),
            vertices: square_at_z(z, 0).0.remove(0).into_iter().rev().collect(),
            photometry: Default::default(),
        };
        let scene = Scene {
            surfaces: vec![surface("near", 1.0), surface("far", 2.0)],
            camera: None,
            lights: Vec::new(),
        };
        let surfaces = PolygonBvh::over_surfaces(&scene);
        assert_eq!(surfaces.len(), 2);
        let hit = surfaces
            .closest_hit(dvec3(0.25, 0.5, 1.5), DVec3::Z, 0.0, 10.0)
            .unwrap();
        assert_eq!(hit.id, 1);
        let mesh = crate::mesh::mesh_scene(&scene, 0.3).unwrap();
        let elements = PolygonBvh::over_elements(&mesh);
        assert_eq!(elements.len(), mesh.len());
        for (e, el) in mesh.elements.iter().enumerate() {
            let origin = el.centroid - 0.5 * DVec3::Z;
            let hit = elements.closest_hit(origin, DVec3::Z, 0.0, 10.0).unwrap();
            assert_eq!(hit.id as usize, e);
        }
    }
}
