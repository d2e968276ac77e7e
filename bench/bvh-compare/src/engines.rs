//! One adapter per crate: build from triangles, answer any-hit segment and closest-hit ray
//! queries.

use std::time::Duration;

use crate::scene::{Query, Tri};

pub trait Engine: Sync + Send {
    /// True when some triangle meets the ray with tmin <= t <= tmax.
    fn occluded(&self, q: &Query) -> bool;
    /// The nearest triangle (its index in the input) and t.
    fn closest(&self, q: &Query) -> Option<(u32, f32)>;
}

pub struct Maker {
    pub name: &'static str,
    pub version: &'static str,
    pub build: Box<dyn Fn(&[Tri]) -> Box<dyn Engine> + Sync>,
}

pub fn all(threads: usize) -> Vec<Maker> {
    let _ = threads;
    let mut v = vec![
        Maker {
            name: "obvhs",
            version: "0.4.0 CWBVH, Möller-Trumbore",
            build: Box::new(|t| Box::new(Obvhs::new(t, false))),
        },
        Maker {
            name: "obvhs-wt",
            version: "0.4.0 CWBVH, watertight test",
            build: Box::new(|t| Box::new(Obvhs::new(t, true))),
        },
        Maker {
            name: "bvh",
            version: "0.13.0",
            build: Box::new(|t| Box::new(BvhCrate::new(t))),
        },
        Maker {
            name: "parry3d",
            version: "0.31.1",
            build: Box::new(|t| Box::new(Parry::new(t))),
        },
    ];
    #[cfg(feature = "embree")]
    {
        let device = std::sync::Arc::new(
            embree3::Device::with_config(embree3::Config {
                threads: threads as u32,
                ..Default::default()
            })
            .expect("embree device"),
        );
        v.push(Maker {
            name: "embree3",
            version: "0.4.1, Embree 3.13.5",
            build: Box::new(move |t| Box::new(Embree::new(&device, t))),
        });
    }
    v
}

// ---------------------------------------------------------------- leaf tests

use obvhs::{ray::Ray as ORay, triangle::Triangle as OTri};
use glam::Vec3A;

fn v3a(a: [f32; 3]) -> Vec3A {
    // + 0.0 turns -0.0 into +0.0: obvhs picks the octant from sign bits.
    Vec3A::new(a[0] + 0.0, a[1] + 0.0, a[2] + 0.0)
}

fn otri(t: &Tri) -> OTri {
    OTri { v0: v3a(t[0]), v1: v3a(t[1]), v2: v3a(t[2]) }
}

fn oray(q: &Query) -> ORay {
    ORay::new(v3a(q.o), v3a(q.d), q.tmin, q.tmax)
}

/// Per-ray set-up of the watertight test of Woop, Benthin and Wald (JCGT 2013).
#[derive(Clone, Copy)]
struct Wt {
    o: Vec3A,
    k: [usize; 3],
    s: [f32; 3],
}

impl Wt {
    fn new(q: &Query) -> Wt {
        let d = q.d;
        let a = [d[0].abs(), d[1].abs(), d[2].abs()];
        let kz = if a[0] > a[1] { if a[0] > a[2] { 0 } else { 2 } } else if a[1] > a[2] { 1 } else { 2 };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Wt { o: v3a(q.o), k: [kx, ky, kz], s: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]] }
    }

    /// t of the hit, or infinity.
    #[inline]
    fn hit(&self, t: &OTri, tmin: f32, tmax: f32) -> f32 {
        let [kx, ky, kz] = self.k;
        let (a, b, c) = (t.v0 - self.o, t.v1 - self.o, t.v2 - self.o);
        let ax = a[kx] - self.s[0] * a[kz];
        let ay = a[ky] - self.s[1] * a[kz];
        let bx = b[kx] - self.s[0] * b[kz];
        let by = b[ky] - self.s[1] * b[kz];
        let cx = c[kx] - self.s[0] * c[kz];
        let cy = c[ky] - self.s[1] * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Exactly on an edge in f32: decide in f64, as the paper does.
            u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
            v = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
            w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return f32::INFINITY;
        }
        let det = u + v + w;
        if det == 0.0 {
            return f32::INFINITY;
        }
        let tt = (u * a[kz] + v * b[kz] + w * c[kz]) * self.s[2] / det;
        if tt >= tmin && tt <= tmax {
            tt
        } else {
            f32::INFINITY
        }
    }
}

/// The truth for a segment, in f64 over every triangle (Möller-Trumbore without
/// tolerances): used only to judge disagreements.
pub fn brute_f64(tris: &[Tri], q: &Query) -> bool {
    let o = [q.o[0] as f64, q.o[1] as f64, q.o[2] as f64];
    let d = [q.d[0] as f64, q.d[1] as f64, q.d[2] as f64];
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    tris.iter().any(|t| {
        let v = |k: usize| [t[k][0] as f64, t[k][1] as f64, t[k][2] as f64];
        let (e1, e2) = (sub(v(1), v(0)), sub(v(2), v(0)));
        let p = cross(d, e2);
        let det = dot(e1, p);
        if det == 0.0 {
            return false;
        }
        let s = sub(o, v(0));
        let u = dot(s, p) / det;
        if !(0.0..=1.0).contains(&u) {
            return false;
        }
        let qq = cross(s, e1);
        let w = dot(d, qq) / det;
        if w < 0.0 || u + w > 1.0 {
            return false;
        }
        let t = dot(e2, qq) / det;
        t >= q.tmin as f64 && t <= q.tmax as f64
    })
}

// ---------------------------------------------------------------- obvhs

use obvhs::{cwbvh::builder::build_cwbvh_from_tris, cwbvh::CwBvh, ray::RayHit, BvhBuildParams};

/// obvhs's compressed wide BVH, built as the library builds it (`medium_build`, single
/// thread: the `parallel` feature is off), triangles stored in BVH order.
struct Obvhs {
    bvh: CwBvh,
    tris: Vec<OTri>,
    ids: Vec<u32>,
    watertight: bool,
}

impl Obvhs {
    fn new(tris: &[Tri], watertight: bool) -> Obvhs {
        let ot: Vec<OTri> = tris.iter().map(otri).collect();
        let bvh = build_cwbvh_from_tris(&ot, BvhBuildParams::medium_build(), &mut Duration::default());
        let ids = bvh.primitive_indices.clone();
        let tris = ids.iter().map(|&i| ot[i as usize]).collect();
        Obvhs { bvh, tris, ids, watertight }
    }
}

impl Engine for Obvhs {
    fn occluded(&self, q: &Query) -> bool {
        let ray = oray(q);
        if self.watertight {
            let wt = Wt::new(q);
            !self.bvh.ray_traverse_miss(ray, |r, k| wt.hit(&self.tris[k], r.tmin, r.tmax))
        } else {
            !self.bvh.ray_traverse_miss(ray, |r, k| self.tris[k].intersect(r))
        }
    }
    fn closest(&self, q: &Query) -> Option<(u32, f32)> {
        let ray = oray(q);
        let mut hit = RayHit::none();
        let found = if self.watertight {
            let wt = Wt::new(q);
            self.bvh.ray_traverse(ray, &mut hit, |r, k| wt.hit(&self.tris[k], r.tmin, r.tmax))
        } else {
            self.bvh.ray_traverse(ray, &mut hit, |r, k| self.tris[k].intersect(r))
        };
        found.then(|| (self.ids[hit.primitive_id as usize], hit.t))
    }
}

// ---------------------------------------------------------------- bvh

use bvh::aabb::{Aabb as BAabb, Bounded, IntersectsAabb};
use bvh::bounding_hierarchy::{BHShape, BoundingHierarchy};
use nalgebra::Point3;
use std::cell::Cell;

struct BShape {
    aabb: BAabb<f32, 3>,
    node: usize,
}

impl Bounded<f32, 3> for BShape {
    fn aabb(&self) -> BAabb<f32, 3> {
        self.aabb
    }
}

impl BHShape<f32, 3> for BShape {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// A finite segment as a bvh traversal query (the crate's own `Ray` is infinite); `tmax`
/// shrinks as closer hits are found.
struct Seg {
    o: [f32; 3],
    inv: [f32; 3],
    tmin: f32,
    tmax: Cell<f32>,
}

impl IntersectsAabb<f32, 3> for Seg {
    #[inline]
    fn intersects_aabb(&self, b: &BAabb<f32, 3>) -> bool {
        let (mut lo, mut hi) = (self.tmin, self.tmax.get());
        for k in 0..3 {
            if self.inv[k].is_infinite() {
                // Parallel to this slab: in it or not (avoids 0 * inf = NaN).
                if self.o[k] < b.min[k] || self.o[k] > b.max[k] {
                    return false;
                }
                continue;
            }
            let t0 = (b.min[k] - self.o[k]) * self.inv[k];
            let t1 = (b.max[k] - self.o[k]) * self.inv[k];
            lo = lo.max(t0.min(t1));
            hi = hi.min(t0.max(t1));
        }
        lo <= hi
    }
}

/// The `bvh` crate: binary SAH BVH built with its rayon executor (`build_par`), traversed
/// with `traverse_iterator` and a finite-segment query, the same Möller-Trumbore leaf test
/// as obvhs.
struct BvhCrate {
    bvh: bvh::bvh::Bvh<f32, 3>,
    shapes: Vec<BShape>,
    tris: Vec<OTri>,
}

impl BvhCrate {
    fn new(tris: &[Tri]) -> BvhCrate {
        let ot: Vec<OTri> = tris.iter().map(otri).collect();
        let mut shapes: Vec<BShape> = tris
            .iter()
            .map(|t| {
                let p = |v: [f32; 3]| Point3::new(v[0], v[1], v[2]);
                let aabb = BAabb::with_bounds(p(t[0]), p(t[0])).grow(&p(t[1])).grow(&p(t[2]));
                BShape { aabb, node: 0 }
            })
            .collect();
        let bvh = bvh::bvh::Bvh::build_par(&mut shapes);
        BvhCrate { bvh, shapes, tris: ot }
    }
    fn seg(q: &Query) -> Seg {
        Seg { o: q.o, inv: [1.0 / q.d[0], 1.0 / q.d[1], 1.0 / q.d[2]], tmin: q.tmin, tmax: Cell::new(q.tmax) }
    }
    fn index(&self, s: &BShape) -> usize {
        (s as *const BShape as usize - self.shapes.as_ptr() as usize) / std::mem::size_of::<BShape>()
    }
}

impl Engine for BvhCrate {
    fn occluded(&self, q: &Query) -> bool {
        let seg = Self::seg(q);
        let ray = oray(q);
        self.bvh
            .traverse_iterator(&seg, &self.shapes)
            .any(|s| self.tris[self.index(s)].intersect(&ray) < f32::INFINITY)
    }
    fn closest(&self, q: &Query) -> Option<(u32, f32)> {
        let seg = Self::seg(q);
        let mut ray = oray(q);
        let mut best = None;
        for s in self.bvh.traverse_iterator(&seg, &self.shapes) {
            let i = self.index(s);
            let t = self.tris[i].intersect(&ray);
            if t < f32::INFINITY {
                best = Some((i as u32, t));
                ray.tmax = t;
                seg.tmax.set(t);
            }
        }
        best
    }
}

// ---------------------------------------------------------------- parry3d

use parry3d::math::Vector as PVec;
use parry3d::query::{Ray as PRay, RayCast};
use parry3d::shape::{CompositeShapeRef, TriMesh};

/// parry3d's `TriMesh` (its own BVH); no tmin, so the ray starts at tmin.
struct Parry {
    mesh: TriMesh,
}

impl Parry {
    fn new(tris: &[Tri]) -> Parry {
        let vertices = tris.iter().flatten().map(|v| PVec::new(v[0], v[1], v[2])).collect();
        let indices = (0..tris.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        Parry { mesh: TriMesh::new(vertices, indices).expect("trimesh") }
    }
    fn ray(q: &Query) -> (PRay, f32) {
        let d = PVec::new(q.d[0], q.d[1], q.d[2]);
        let o = PVec::new(q.o[0], q.o[1], q.o[2]) + d * q.tmin;
        (PRay::new(o, d), (q.tmax - q.tmin).min(f32::MAX))
    }
}

impl Engine for Parry {
    fn occluded(&self, q: &Query) -> bool {
        let (ray, max) = Self::ray(q);
        self.mesh.intersects_local_ray(&ray, max)
    }
    fn closest(&self, q: &Query) -> Option<(u32, f32)> {
        let (ray, max) = Self::ray(q);
        CompositeShapeRef(&self.mesh)
            .cast_local_ray(&ray, max, false)
            .map(|(i, t)| (i, t + q.tmin))
    }
}

// ---------------------------------------------------------------- embree3

#[cfg(feature = "embree")]
struct Embree {
    scene: embree3::Scene<'static>,
    _geometry: embree3::Geometry<'static>,
}

#[cfg(feature = "embree")]
impl Embree {
    /// One triangle geometry, default (medium) build quality, committed with the device's
    /// threads.
    fn new(device: &embree3::Device, tris: &[Tri]) -> Embree {
        use embree3::{BufferUsage, Format, GeometryKind};
        let mut scene = device.create_scene().expect("scene");
        let mut g = device.create_geometry(GeometryKind::TRIANGLE).expect("geometry");
        g.set_new_buffer::<[f32; 3]>(BufferUsage::VERTEX, 0, Format::FLOAT3, 12, 3 * tris.len())
            .expect("vertex buffer")
            .copy_from_slice(&tris.iter().flatten().copied().collect::<Vec<_>>());
        g.set_new_buffer::<[u32; 3]>(BufferUsage::INDEX, 0, Format::UINT3, 12, tris.len())
            .expect("index buffer")
            .copy_from_slice(
                &(0..tris.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect::<Vec<_>>(),
            );
        let g = g.commit();
        scene.attach_geometry(&g);
        scene.commit();
        Embree { scene, _geometry: g }
    }
}

#[cfg(feature = "embree")]
impl Engine for Embree {
    fn occluded(&self, q: &Query) -> bool {
        let mut ctx = embree3::IntersectContext::incoherent();
        let mut ray = embree3::Ray::segment(q.o, q.d, q.tmin, q.tmax);
        self.scene.occluded(&mut ctx, &mut ray)
    }
    fn closest(&self, q: &Query) -> Option<(u32, f32)> {
        let mut ctx = embree3::IntersectContext::incoherent();
        let mut rh = embree3::RayHit::from_ray(embree3::Ray::segment(q.o, q.d, q.tmin, q.tmax));
        self.scene.intersect(&mut ctx, &mut rh);
        rh.hit.is_valid().then(|| (rh.hit.primID, rh.ray.tfar))
    }
}
