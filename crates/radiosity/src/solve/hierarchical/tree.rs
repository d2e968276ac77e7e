//! The hierarchy: a quadtree of patches over every input surface (split along the mesh's
//! grid lines where a patch spans several of its cells, else at midpoints) and the binary
//! tree of clusters above their roots, with their nodes and how the leaves under a node are
//! found.

use glam::DVec3;

use super::bins::bin;
use super::link::Link;
use super::solver::{max3, Solver};
use crate::form_factor::kernel::quarter_points;
use crate::geometry;

/// No node index.
pub(super) const NONE: u32 = u32::MAX;
/// Sample points kept per cluster, for visibility and for the geometry of its links (16:
/// against 8, building_small's pixel RMS 6.01 -> 5.49 % and room.scene's 4.16 -> 3.78 %; 32
/// gave 5.40 and 3.92 %, BENCHMARKS.md).
pub(super) const CLUSTER_SAMPLES: usize = 16;

/// A node: a patch of a surface's quadtree, or a cluster.
#[derive(Clone, Debug)]
pub(super) struct Node {
    /// Input surface of a patch; NONE for a cluster.
    pub(super) surface: u32,
    /// Index into `Solver::clusters`; NONE for a patch.
    pub(super) cluster: u32,
    /// Corners of a patch (3 or 4).
    pub(super) count: u8,
    pub(super) children: [u32; 4],
    pub(super) child_count: u8,
    /// The cells of the scene's mesh across a patch (see [`crate::mesh::grid_of`]): [cu, cv]
    /// for a quadrilateral, [m, 0] for a triangle cut into m^2; [0, 0] for a patch smaller
    /// than one cell or off the mesh's lattice.
    pub(super) grid: [u32; 2],
    pub(super) corners: [DVec3; 4],
    pub(super) centre: DVec3,
    pub(super) radius: f64,
    pub(super) area: f64,
    /// The area of a patch less its buried descendants' (see the `contact` module): where
    /// the light its links bring is spread when pushed down (= `area` where nothing under
    /// it is buried, 0 for a buried patch).
    pub(super) open_area: f64,
    pub(super) links: Vec<Link>,
    /// A patch's gathered irradiance.
    pub(super) gathered: [f64; 3],
    /// A patch wholly buried under or inside other surfaces (see the `contact` module): it
    /// carries no light.
    pub(super) buried: bool,
    /// A patch in a cell that is partly buried (the cell and every piece of it): its links'
    /// visibility, sampled from coarser receivers, says little about it, so the final
    /// gather samples it again from the leaf.
    pub(super) straddles: bool,
}

impl Node {
    pub(super) fn polygon(&self) -> &[DVec3] {
        &self.corners[..self.count as usize]
    }
    pub(super) fn is_cluster(&self) -> bool {
        self.cluster != NONE
    }
    pub(super) fn children(&self) -> &[u32] {
        &self.children[..self.child_count as usize]
    }
}

/// What a cluster node keeps beyond [`Node`]: its box, bounds for the oracle, its bins and
/// its sample points.
#[derive(Clone, Debug)]
pub(super) struct Cluster {
    pub(super) lo: DVec3,
    pub(super) hi: DVec3,
    /// Largest reflectance of any band of any patch inside.
    pub(super) rho: f64,
    /// Area bins: sum over its patches of A max(0, ±n_k).
    pub(super) area_bins: [f64; 6],
    /// Power bins per band (see the module documentation of [`super`]).
    pub(super) power: [[f64; 6]; 3],
    /// Largest radiosity (largest band) of its patches (root level): what the oracle uses,
    /// as a cluster's mean hides a small bright light among dark surfaces.
    pub(super) b_max: f64,
    /// Gathered irradiance bins per band.
    pub(super) incident: [[f64; 6]; 3],
    /// Points on surfaces inside, with their normals and the area each stands for, for
    /// visibility ([`ClusterSample`]).
    pub(super) samples: Vec<ClusterSample>,
}

/// A point on a surface inside a cluster, its surface's unit normal, and the area of the
/// cluster it stands for (the cluster's samples' areas sum to the cluster's area).
#[derive(Clone, Copy, Debug)]
pub(super) struct ClusterSample {
    pub(super) point: DVec3,
    pub(super) normal: DVec3,
    pub(super) area: f64,
}

/// Up to [`CLUSTER_SAMPLES`] samples standing for `candidates` (the two children's
/// samples), drawn in proportion to area by systematic sampling over the candidates'
/// cumulative area: a sample drawn k times stands for k / CLUSTER_SAMPLES of the total. The
/// visible fraction of a cluster link is a mean over its samples weighted by their area
/// (see [`super::Solver::visibility`]); before, each child gave half the samples whatever
/// its area, so a table's legs, hidden under its top, counted as much as the top, and a
/// cluster's links came out dark: a 3 x 3 generated building lost 10.7 % of its emitted
/// power at the default epsilon (a dense solve of it, 0.0 %).
fn draw_samples(candidates: &[ClusterSample]) -> Vec<ClusterSample> {
    if candidates.len() <= CLUSTER_SAMPLES {
        return candidates.to_vec();
    }
    let total: f64 = candidates.iter().map(|s| s.area).sum();
    if !(total > 0.0) {
        return candidates[..CLUSTER_SAMPLES].to_vec();
    }
    let share = total / CLUSTER_SAMPLES as f64;
    let mut out: Vec<ClusterSample> = Vec::with_capacity(CLUSTER_SAMPLES);
    let (mut i, mut reached) = (0, candidates[0].area);
    let mut last = usize::MAX;
    for k in 0..CLUSTER_SAMPLES {
        let target = (k as f64 + 0.5) * share;
        while reached < target && i + 1 < candidates.len() {
            i += 1;
            reached += candidates[i].area;
        }
        if i == last {
            out.last_mut().expect("drawn before").area += share;
        } else {
            out.push(ClusterSample {
                area: share,
                ..candidates[i]
            });
            last = i;
        }
    }
    out
}

/// The midpoint of `a` and `b`.
fn mid(a: DVec3, b: DVec3) -> DVec3 {
    0.5 * (a + b)
}

impl Solver<'_> {
    pub(super) fn new_patch(
        &mut self,
        surface: u32,
        poly: &[DVec3],
        grid: [u32; 2],
        b: [f64; 3],
    ) -> u32 {
        let mut corners = [DVec3::ZERO; 4];
        corners[..poly.len()].copy_from_slice(poly);
        let centre = geometry::vertex_mean(poly);
        let radius = poly.iter().map(|v| v.distance(centre)).fold(0.0, f64::max);
        self.nodes.push(Node {
            surface,
            cluster: NONE,
            count: poly.len() as u8,
            children: [NONE; 4],
            child_count: 0,
            grid,
            corners,
            centre,
            radius,
            area: geometry::polygon_area(poly),
            open_area: geometry::polygon_area(poly),
            links: Vec::new(),
            gathered: [0.0; 3],
            buried: false,
            straddles: false,
        });
        let b = if self.lights.is_empty() {
            b
        } else {
            let d = self.point_light_bounce(surface, poly);
            self.direct.push(d);
            std::array::from_fn(|k| b[k] + d[k])
        };
        self.b.push(b);
        self.b_span.push((max3(b), max3(b)));
        self.cluster_of.push(NONE);
        self.nodes.len() as u32 - 1
    }

    /// The first bounce of the point luminaires on the piece `poly` of `surface`: its
    /// reflectance times its mean illuminance from them, with shadow rays through the
    /// scene's surfaces (the same quadrature as the dense solvers' elements,
    /// [`crate::luminaire::power_onto`] at [`crate::luminaire::ELEMENT_SUBDIVISION`]).
    pub(super) fn point_light_bounce(&mut self, surface: u32, poly: &[DVec3]) -> [f64; 3] {
        let area = geometry::polygon_area(poly);
        if area <= 0.0 {
            return [0.0; 3];
        }
        let occ = self.occluders;
        let rays = std::cell::Cell::new(0u64);
        let mut power = crate::light::Rgb::BLACK;
        for l in self.lights {
            power += crate::luminaire::power_onto(
                l,
                poly,
                crate::luminaire::ELEMENT_SUBDIVISION,
                |x, y| {
                    rays.set(rays.get() + 1);
                    occ.segment_blocked(x, y)
                },
            );
        }
        self.rays += rays.get();
        let rho = self.rho[surface as usize];
        std::array::from_fn(|k| rho[k] * power.0[k] / area)
    }

    /// Builds the cluster tree over `items` (patch roots); returns its top node.
    pub(super) fn build_clusters(&mut self, items: &mut [u32]) -> u32 {
        if items.len() == 1 {
            return items[0];
        }
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &i in items.iter() {
            let c = self.nodes[i as usize].centre;
            lo = lo.min(c);
            hi = hi.max(c);
        }
        let axis = (hi - lo).max_position();
        let half = items.len() / 2;
        items.select_nth_unstable_by(half, |&a, &b| {
            let (ca, cb) = (
                self.nodes[a as usize].centre[axis],
                self.nodes[b as usize].centre[axis],
            );
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
        let (left, right) = items.split_at_mut(half);
        let a = self.build_clusters(left);
        let b = self.build_clusters(right);
        // The cluster's box, area, reflectance and sample points from its two children.
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let mut rho: f64 = 0.0;
        let mut area = 0.0;
        // The two children's samples, interleaved so that the draw below spreads over both.
        let mut per_child: Vec<Vec<ClusterSample>> = Vec::new();
        let mut area_bins = [0.0; 6];
        for c in [a, b] {
            let n = &self.nodes[c as usize];
            area += n.area;
            if n.is_cluster() {
                let cl = &self.clusters[n.cluster as usize];
                for k in 0..6 {
                    area_bins[k] += cl.area_bins[k];
                }
                lo = lo.min(cl.lo);
                hi = hi.max(cl.hi);
                rho = rho.max(cl.rho);
                per_child.push(cl.samples.clone());
            } else {
                for &v in n.polygon() {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                rho = rho.max(max3(self.rho[n.surface as usize]));
                let m = self.normal[n.surface as usize];
                for k in 0..3 {
                    area_bins[bin(k, m[k])] += n.area * m[k].abs();
                }
                // The quarter points, not the centre: the centre of a large patch may lie
                // under something standing on it (the Cornell box's floor centre is under
                // the tall block), which would hide the whole cluster.
                let m = self.normal[n.surface as usize];
                let area = 0.25 * n.area;
                per_child.push(
                    quarter_points(n.polygon())
                        .map(|point| ClusterSample {
                            point,
                            normal: m,
                            area,
                        })
                        .to_vec(),
                );
            }
        }
        let longest = per_child[0].len().max(per_child[1].len());
        let candidates: Vec<ClusterSample> = (0..2 * longest)
            .filter_map(|k| per_child[k % 2].get(k / 2).copied())
            .collect();
        let samples = draw_samples(&candidates);
        let centre = 0.5 * (lo + hi);
        self.clusters.push(Cluster {
            lo,
            hi,
            rho,
            area_bins,
            b_max: 0.0,
            power: [[0.0; 6]; 3],
            incident: [[0.0; 6]; 3],
            samples,
        });
        self.nodes.push(Node {
            surface: NONE,
            cluster: self.clusters.len() as u32 - 1,
            count: 0,
            children: [a, b, NONE, NONE],
            child_count: 2,
            grid: [0, 0],
            corners: [DVec3::ZERO; 4],
            centre,
            radius: 0.5 * (hi - lo).length(),
            area,
            open_area: area,
            links: Vec::new(),
            gathered: [0.0; 3],
            buried: false,
            straddles: false,
        });
        self.b.push([0.0; 3]);
        if !self.lights.is_empty() {
            self.direct.push([0.0; 3]);
        }
        self.b_span.push((0.0, 0.0));
        self.cluster_of.push(self.clusters.len() as u32 - 1);
        self.nodes.len() as u32 - 1
    }

    /// The children of patch `n`, made on first use (they start with the parent's B).
    ///
    /// A patch that spans several cells of the scene's mesh splits along the grid lines
    /// nearest its middle (four children; two, across its length, when it is twice as
    /// many cells long as wide), so that every element of the mesh is a node of the
    /// quadtree and the leaves nest with the mesh's elements (a leaf is a union of elements
    /// or a piece of one); a triangle of m^2 cells with m even splits at its edge midpoints
    /// into four of (m/2)^2. Below one cell, or off the lattice (a triangle of odd m), a
    /// quadrilateral splits at its bilinear midpoints and a triangle at its edge midpoints.
    pub(super) fn split_patch(&mut self, n: u32) -> Vec<u32> {
        let node = &self.nodes[n as usize];
        if node.child_count > 0 {
            return node.children().to_vec();
        }
        // Children start with the parent's B, less the parent's own first bounce of the
        // point luminaires (each adds its own).
        let (surface, mut b) = (node.surface, self.b[n as usize]);
        if let Some(d) = self.direct.get(n as usize) {
            b = std::array::from_fn(|k| b[k] - d[k]);
        }
        let p = node.corners;
        let [cu, cv] = node.grid;
        // (corners, grid) of each child.
        let mut made: Vec<([DVec3; 4], [u32; 2])> = Vec::with_capacity(4);
        if node.count == 4 {
            let aligned = cu > 1 || cv > 1;
            // Cuts in u and v: (parameter, cells before it) for each piece boundary. The
            // mesh's cells are near square, so a patch twice as many cells long as wide is
            // cut across its length only: children stay near square (an elongated patch
            // has a large bounding sphere for its area, which the oracle and the near-pair
            // test pay for).
            let (split_u, split_v) = if cu >= 2 * cv {
                (true, false)
            } else if cv >= 2 * cu {
                (false, true)
            } else {
                (cu > 1, cv > 1)
            };
            let cuts = |c: u32, split: bool| -> Vec<(f64, u32)> {
                if !aligned {
                    vec![(0.0, 0), (0.5, 0), (1.0, 0)]
                } else if split {
                    let h = c / 2;
                    vec![(0.0, 0), (h as f64 / c as f64, h), (1.0, c)]
                } else {
                    vec![(0.0, 0), (1.0, c)]
                }
            };
            let (us, vs) = (cuts(cu, split_u), cuts(cv, split_v));
            for j in 0..vs.len() - 1 {
                for i in 0..us.len() - 1 {
                    let (u0, u1, v0, v1) = (us[i].0, us[i + 1].0, vs[j].0, vs[j + 1].0);
                    let q = |u: f64, v: f64| crate::mesh::bilinear(&p, u, v);
                    let grid = if aligned {
                        [us[i + 1].1 - us[i].1, vs[j + 1].1 - vs[j].1]
                    } else {
                        [0, 0]
                    };
                    made.push(([q(u0, v0), q(u1, v0), q(u1, v1), q(u0, v1)], grid));
                }
            }
        } else {
            let (m01, m12, m20) = (mid(p[0], p[1]), mid(p[1], p[2]), mid(p[2], p[0]));
            let z = DVec3::ZERO;
            let grid = if cu >= 2 && cu % 2 == 0 {
                [cu / 2, 0]
            } else {
                [0, 0]
            };
            for t in [
                [p[0], m01, m20, z],
                [m01, p[1], m12, z],
                [m20, m12, p[2], z],
                [m01, m12, m20, z],
            ] {
                made.push((t, grid));
            }
        }
        let count = node.count as usize;
        let straddles = node.straddles;
        let children: Vec<u32> = made
            .iter()
            .map(|(poly, grid)| {
                let c = self.new_patch(surface, &poly[..count], *grid, b);
                self.nodes[c as usize].straddles = straddles;
                c
            })
            .collect();
        let node = &mut self.nodes[n as usize];
        node.children[..children.len()].copy_from_slice(&children);
        node.child_count = children.len() as u8;
        children
    }

    /// Roots are made first, surface by surface, before any cluster or child.
    pub(super) fn is_root(&self, n: u32) -> bool {
        (n as usize) < self.root_count
    }

    /// The leaves under `n` that are not buried (the elements a solve returns).
    pub(super) fn leaves_of(&self, n: u32, out: &mut Vec<u32>) {
        let node = &self.nodes[n as usize];
        if node.buried {
            return;
        }
        if node.child_count == 0 {
            out.push(n);
        } else {
            for &k in node.children() {
                self.leaves_of(k, out);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(x: f64, area: f64) -> ClusterSample {
        ClusterSample {
            point: DVec3::new(x, 0.0, 0.0),
            normal: DVec3::Y,
            area,
        }
    }

    #[test]
    fn cluster_samples_are_drawn_in_proportion_to_area() {
        // A table top of area 8 among eight legs of area 1 each: of the total 16 the top
        // stands for half, so half of the CLUSTER_SAMPLES = 16 draws (targets 0.5, 1.5,
        // ..., 7.5 of the cumulative area 0..16, shares of 1) fall on it and merge into
        // one sample of area 8; the other eight land one on each leg (targets 8.5 ...
        // 15.5), area 1 each. Drawn by count, the top would have stood for 1/9.
        let mut candidates = vec![sample(0.0, 8.0)];
        candidates.extend((1..=8).map(|k| sample(k as f64, 1.0)));
        let drawn = draw_samples(&candidates);
        let got: Vec<(f64, f64)> = drawn.iter().map(|s| (s.point.x, s.area)).collect();
        let mut want = vec![(0.0, 8.0)];
        want.extend((1..=8).map(|k| (k as f64, 1.0)));
        assert_eq!(got, want);
        // Eighteen legs of area 1 and a top of 14 (total 32, shares of 2): the top takes
        // seven draws (targets 1, 3, ..., 13), and the legs every other one (targets 15,
        // ..., 31 fall on legs 1, 3, ..., 17), area 2 each.
        let mut candidates = vec![sample(0.0, 14.0)];
        candidates.extend((1..=18).map(|k| sample(k as f64, 1.0)));
        let drawn = draw_samples(&candidates);
        let got: Vec<(f64, f64)> = drawn.iter().map(|s| (s.point.x, s.area)).collect();
        let mut want = vec![(0.0, 14.0)];
        want.extend((0..9).map(|k| ((2 * k + 1) as f64, 2.0)));
        assert_eq!(got, want);
        // The areas still sum to the cluster's (exactly: shares of 2 added).
        assert_eq!(drawn.iter().map(|s| s.area).sum::<f64>(), 32.0);
    }

    #[test]
    fn few_cluster_samples_are_kept_as_they_are() {
        let candidates: Vec<ClusterSample> = (0..CLUSTER_SAMPLES)
            .map(|k| sample(k as f64, 1.0 + k as f64))
            .collect();
        let drawn = draw_samples(&candidates);
        assert_eq!(drawn.len(), CLUSTER_SAMPLES);
        for (a, b) in drawn.iter().zip(&candidates) {
            assert_eq!((a.point, a.area), (b.point, b.area));
        }
    }
}
