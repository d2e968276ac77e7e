//! Deterministic scenes and queries: a building of furnished rooms (what a radiosity scene
//! meshed into elements looks like) and a worst-case soup of random triangles.

/// A small, fast, seeded generator (xorshift64*), so every run sees the same scene and
/// queries without depending on a `rand` version.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.f64() * n as f64) as usize % n
    }
}

pub type V3 = [f64; 3];
pub type Tri = [[f32; 3]; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn mul(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn len(a: V3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn to_f32(a: V3) -> [f32; 3] {
    [a[0] as f32, a[1] as f32, a[2] as f32]
}

/// Collects triangles, stopping at a fixed count.
struct Builder {
    tris: Vec<Tri>,
    limit: usize,
}

impl Builder {
    fn full(&self) -> bool {
        self.tris.len() >= self.limit
    }
    fn tri(&mut self, a: V3, b: V3, c: V3) {
        if !self.full() {
            self.tris.push([to_f32(a), to_f32(b), to_f32(c)]);
        }
    }
    /// The parallelogram p + s u + t v (s, t in [0, 1]) as an nu x nv grid of quads, two
    /// triangles each, like an element mesh; cells listed in `hole` (cell i, j) are skipped.
    fn quad(&mut self, p: V3, u: V3, v: V3, nu: usize, nv: usize, hole: &dyn Fn(usize, usize) -> bool) {
        for i in 0..nu {
            for j in 0..nv {
                if hole(i, j) {
                    continue;
                }
                let at = |a: usize, b: usize| {
                    add(p, add(mul(u, a as f64 / nu as f64), mul(v, b as f64 / nv as f64)))
                };
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                self.tri(a, b, c);
                self.tri(a, c, d);
            }
        }
    }
    /// A parallelogram meshed into cells of edge about `h`.
    fn patch(&mut self, p: V3, u: V3, v: V3, h: f64) {
        let nu = ((len(u) / h).ceil() as usize).max(1);
        let nv = ((len(v) / h).ceil() as usize).max(1);
        self.quad(p, u, v, nu, nv, &|_, _| false);
    }
    /// A box with corner `p`, size (sx, sy, sz), rotated by `angle` about the vertical
    /// through `p`, each face meshed at edge `h`.
    fn cuboid(&mut self, p: V3, sx: f64, sy: f64, sz: f64, angle: f64, h: f64) {
        let (s, c) = angle.sin_cos();
        let ex = [c * sx, s * sx, 0.0];
        let ey = [-s * sy, c * sy, 0.0];
        let ez = [0.0, 0.0, sz];
        let q = add(add(p, ex), add(ey, ez)); // the opposite corner
        self.patch(p, ey, ex, h); // bottom
        self.patch(p, ex, ez, h);
        self.patch(p, ez, ey, h);
        self.patch(q, mul(ex, -1.0), mul(ey, -1.0), h); // top
        self.patch(q, mul(ez, -1.0), mul(ex, -1.0), h);
        self.patch(q, mul(ey, -1.0), mul(ez, -1.0), h);
    }
}

/// A building: `floors` storeys of nx x ny rooms (5 m x 4 m x 3 m) with walls 0.2 m thick
/// (each room has its own inner wall surfaces), doors between neighbouring rooms and a
/// window per outer wall, walls, floors and ceilings meshed at 0.35 m; then furniture in
/// every room, round-robin, until `n` triangles: axis-aligned and rotated boxes (tables,
/// cabinets, shelves, meshed at 0.25 m) with small objects (books, boxes) on them.
pub fn building(n: usize, seed: u64) -> Vec<Tri> {
    let mut rng = Rng::new(seed);
    let mut b = Builder {
        tris: Vec::with_capacity(n),
        limit: n,
    };
    let (nx, ny, floors) = (4usize, 4usize, 2usize);
    let (rx, ry, rz, wall) = (5.0f64, 4.0f64, 3.0f64, 0.2f64);
    let h = 0.35;
    let mut rooms = Vec::new();
    for f in 0..floors {
        for i in 0..nx {
            for j in 0..ny {
                let lo = [i as f64 * rx + wall / 2.0, j as f64 * ry + wall / 2.0, f as f64 * rz + wall / 2.0];
                let (w, d, t) = (rx - wall, ry - wall, rz - wall);
                rooms.push((lo, w, d, t));
                let cells = |l: f64| ((l / h).ceil() as usize).max(1);
                let (cw, cd, ct) = (cells(w), cells(d), cells(t));
                // Door (inner walls) or window (outer walls): a hole of cells in the middle.
                let door = |nu: usize| move |a: usize, bb: usize| a + 2 >= nu / 2 && a <= nu / 2 + 1 && bb < 7;
                let window = |nu: usize| move |a: usize, bb: usize| a + 2 >= nu / 2 && a <= nu / 2 + 1 && (3..6).contains(&bb);
                let hole_x = |inner: bool, nu: usize| -> Box<dyn Fn(usize, usize) -> bool> {
                    if inner { Box::new(door(nu)) } else { Box::new(window(nu)) }
                };
                // floor and ceiling
                b.quad(lo, [0.0, d, 0.0], [w, 0.0, 0.0], cd, cw, &|_, _| false);
                b.quad(add(lo, [0.0, 0.0, t]), [w, 0.0, 0.0], [0.0, d, 0.0], cw, cd, &|_, _| false);
                // walls at y = lo and y = lo + d (span x), x = lo and x = lo + w (span y)
                b.quad(lo, [w, 0.0, 0.0], [0.0, 0.0, t], cw, ct, &*hole_x(j > 0, cw));
                b.quad(add(lo, [0.0, d, 0.0]), [w, 0.0, 0.0], [0.0, 0.0, t], cw, ct, &*hole_x(j + 1 < ny, cw));
                b.quad(lo, [0.0, d, 0.0], [0.0, 0.0, t], cd, ct, &*hole_x(i > 0, cd));
                b.quad(add(lo, [w, 0.0, 0.0]), [0.0, d, 0.0], [0.0, 0.0, t], cd, ct, &*hole_x(i + 1 < nx, cd));
            }
        }
    }
    let mut k = 0;
    while !b.full() {
        let (lo, w, d, _) = rooms[k % rooms.len()];
        k += 1;
        // A piece of furniture ...
        let (sx, sy, sz) = (rng.range(0.4, 1.6), rng.range(0.4, 1.0), rng.range(0.4, 2.0));
        let angle = if rng.f64() < 0.5 { 0.0 } else { rng.range(0.0, std::f64::consts::PI) };
        let p = [lo[0] + rng.range(0.3, w - 1.8), lo[1] + rng.range(0.3, d - 1.4), lo[2]];
        b.cuboid(p, sx, sy, sz, angle, 0.25);
        // ... with a few small objects on top of it.
        for _ in 0..rng.below(5) {
            let (ox, oy, oz) = (rng.range(0.05, 0.3), rng.range(0.05, 0.3), rng.range(0.02, 0.35));
            let (s, c) = angle.sin_cos();
            let (u, v) = (rng.range(0.0, sx - ox), rng.range(0.0, sy - oy));
            let q = [p[0] + c * u - s * v, p[1] + s * u + c * v, p[2] + sz];
            b.cuboid(q, ox, oy, oz, angle + rng.range(-0.3, 0.3), 1.0);
        }
    }
    b.tris
}

/// Worst case: `n` triangles with uniformly random centres in the unit cube and corners
/// within +-0.025 of the centre, no structure at all.
pub fn soup(n: usize, seed: u64) -> Vec<Tri> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let c = [rng.f64(), rng.f64(), rng.f64()];
            let mut corner = || to_f32(add(c, [rng.range(-0.025, 0.025), rng.range(-0.025, 0.025), rng.range(-0.025, 0.025)]));
            [corner(), corner(), corner()]
        })
        .collect()
}

/// A ray or segment: origin, unit direction, and the range of t that counts.
#[derive(Clone, Copy, Debug)]
pub struct Query {
    pub o: [f32; 3],
    pub d: [f32; 3],
    pub tmin: f32,
    pub tmax: f32,
}

fn point_on(rng: &mut Rng, t: &Tri) -> V3 {
    let (mut a, mut b) = (rng.f64(), rng.f64());
    if a + b > 1.0 {
        a = 1.0 - a;
        b = 1.0 - b;
    }
    let v = |k: usize| [t[k][0] as f64, t[k][1] as f64, t[k][2] as f64];
    add(v(0), add(mul(sub(v(1), v(0)), a), mul(sub(v(2), v(0)), b)))
}

/// Cosine between a triangle's normal and the unit vector `d`.
fn cos_to(t: &Tri, d: V3) -> f64 {
    let v = |k: usize| [t[k][0] as f64, t[k][1] as f64, t[k][2] as f64];
    let (a, b) = (sub(v(1), v(0)), sub(v(2), v(0)));
    let n = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let l = len(n);
    if l == 0.0 { 0.0 } else { (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / l }
}

/// The diagonal of the scene's bounding box.
pub fn diagonal(tris: &[Tri]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in tris.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k] as f64);
            hi[k] = hi[k].max(v[k] as f64);
        }
    }
    len(sub(hi, lo))
}

/// Form-factor visibility: segments between uniform random points on two random triangles
/// (pairs that see each other edge-on skipped), trimmed by `eps` at both ends (so the triangles they start and end on do not count).
pub fn segments(tris: &[Tri], n: usize, eps: f64, seed: u64) -> Vec<Query> {
    let mut rng = Rng::new(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let (i, j) = (rng.below(tris.len()), rng.below(tris.len()));
        let p = point_on(&mut rng, &tris[i]);
        let q = point_on(&mut rng, &tris[j]);
        let l = len(sub(q, p));
        if l <= 4.0 * eps {
            continue;
        }
        // A pair whose segment grazes either triangle (|cos| < 0.01) has a zero form
        // factor and is never asked; coplanar pairs (two cells of one floor) are the bulk.
        let dir = mul(sub(q, p), 1.0 / l);
        if cos_to(&tris[i], dir).abs() < 0.01 || cos_to(&tris[j], dir).abs() < 0.01 {
            continue;
        }
        out.push(Query { o: to_f32(p), d: to_f32(mul(sub(q, p), 1.0 / l)), tmin: eps as f32, tmax: (l - eps) as f32 });
    }
    out
}

/// Rendering-style incoherent rays: from a uniform random point on a random triangle in a
/// uniformly random direction, unbounded; closest hit wanted.
pub fn rays(tris: &[Tri], n: usize, eps: f64, seed: u64) -> Vec<Query> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let i = rng.below(tris.len());
            let p = point_on(&mut rng, &tris[i]);
            let z = rng.range(-1.0, 1.0);
            let phi = rng.range(0.0, 2.0 * std::f64::consts::PI);
            let r = (1.0 - z * z).sqrt();
            Query { o: to_f32(p), d: to_f32([r * phi.cos(), r * phi.sin(), z]), tmin: eps as f32, tmax: f32::INFINITY }
        })
        .collect()
}
