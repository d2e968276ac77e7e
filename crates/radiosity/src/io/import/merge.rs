//! Coplanar triangles back into the polygons they were cut from: formats that hold only
//! triangles (glTF) give a quad as two triangles, which would mesh into thin slivers and
//! not the quad's grid. Edge-adjacent triangles of one primitive that lie in one plane
//! (exactly, to the rounding of the file's numbers) and together make a convex polygon are
//! joined, greedily, in file order.

use std::collections::HashMap;

use glam::DVec3;

use crate::geometry;

/// The most corners a joined polygon gets: a fan of many triangles (a disc) stops growing
/// there, which keeps the joining linear in the triangle count.
pub(crate) const MAX_CORNERS: usize = 64;

/// How far from one plane (as a fraction of the polygon's diameter plus its largest
/// coordinate) the corners of a joined polygon may lie: 1e-6, sixteen times single
/// precision's rounding (glTF's positions are `f32`), and far below the 0.2% the scene
/// reader tolerates, so that two triangles of a measured, slightly bent wall (the Cornell
/// box's red wall is 0.1% out of plane) stay two.
const COPLANAR: f64 = 1e-6;

/// Joins the triangles `triangles` (indices into `points`, counter-clockwise seen from the
/// front) into convex polygons where they are coplanar and share an edge (the two
/// triangles running it in opposite directions). Returns the polygons as index lists, in
/// the order of their first triangle. Triangles with a repeated index are passed through
/// alone.
pub(crate) fn join_coplanar(points: &[DVec3], triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let polygons: Vec<Vec<u32>> = triangles.iter().map(|t| t.to_vec()).collect();
    join_coplanar_polygons(points, polygons)
        .into_iter()
        .map(|(_, p)| p)
        .collect()
}

/// [`join_coplanar`] for polygons of any size: a polygon of more than three corners takes
/// part only if it is itself a usable flat convex polygon (others, to be triangulated
/// later, and those with a repeated or out-of-range index pass through alone). Each
/// polygon comes with the index of the input polygon it grew from.
pub(crate) fn join_coplanar_polygons(
    points: &[DVec3],
    polygons: Vec<Vec<u32>>,
) -> Vec<(usize, Vec<u32>)> {
    let mut polygons = polygons;
    let mut alive = vec![true; polygons.len()];
    let mut joinable: Vec<bool> = polygons
        .iter()
        .map(|t| {
            if t.len() < 3
                || t.len() > MAX_CORNERS
                || !t.iter().all(|&i| (i as usize) < points.len())
            {
                return false;
            }
            let mut sorted = t.clone();
            sorted.sort_unstable();
            if sorted.windows(2).any(|w| w[0] == w[1]) {
                return false;
            }
            t.len() == 3 || acceptable(points, t)
        })
        .collect();
    // A polygon given twice (the same corners, turning the same way) joins nothing, and
    // neither does its twin: joined into a neighbour, the first copy would no longer match
    // the second, which the duplicate check after the join then kept (QA of issue #16: an
    // emitting triangle given twice in an OBJ added a sliver of emission, 0.24 % more light).
    let mut seen: HashMap<Vec<u32>, usize> = HashMap::new();
    for p in 0..polygons.len() {
        if !joinable[p] {
            continue;
        }
        let t = &polygons[p];
        let first = (0..t.len()).min_by_key(|&k| t[k]).unwrap_or(0);
        let key: Vec<u32> = (0..t.len()).map(|k| t[(first + k) % t.len()]).collect();
        match seen.get(&key) {
            Some(&q) => {
                joinable[p] = false;
                joinable[q] = false;
            }
            None => {
                seen.insert(key, p);
            }
        }
    }
    let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
    for (p, t) in polygons.iter().enumerate() {
        if joinable[p] {
            let n = t.len();
            for k in 0..n {
                edges.insert((t[k], t[(k + 1) % n]), p);
            }
        }
    }
    for p in 0..polygons.len() {
        if !joinable[p] {
            continue;
        }
        'grow: loop {
            let n = polygons[p].len();
            if n >= MAX_CORNERS {
                break;
            }
            for k in 0..n {
                let (a, b) = (polygons[p][k], polygons[p][(k + 1) % n]);
                let Some(&q) = edges.get(&(b, a)) else {
                    continue;
                };
                if q == p || !alive[q] || !runs(&polygons[q], b, a) {
                    continue;
                }
                let Some(joined) = splice(&polygons[p], k, &polygons[q], b, a) else {
                    continue;
                };
                if joined.len() > MAX_CORNERS || !acceptable(points, &joined) {
                    continue;
                }
                alive[q] = false;
                polygons[q].clear();
                for j in 0..joined.len() {
                    edges.insert((joined[j], joined[(j + 1) % joined.len()]), p);
                }
                polygons[p] = joined;
                continue 'grow;
            }
            break;
        }
    }
    polygons
        .into_iter()
        .zip(alive)
        .enumerate()
        .filter_map(|(i, (poly, a))| a.then_some((i, poly)))
        .collect()
}

/// Whether `poly` runs the edge a -> b.
fn runs(poly: &[u32], a: u32, b: u32) -> bool {
    let n = poly.len();
    (0..n).any(|k| poly[k] == a && poly[(k + 1) % n] == b)
}

/// `p` (whose edge `k` runs a -> b) and `q` (which runs b -> a) as one outline: p from b
/// round to a, then q's corners between a and b. `None` when a corner would repeat (the
/// two touch elsewhere too).
fn splice(p: &[u32], k: usize, q: &[u32], b: u32, a: u32) -> Option<Vec<u32>> {
    let n = p.len();
    let mut out: Vec<u32> = (0..n).map(|j| p[(k + 1 + j) % n]).collect(); // b ... a
    let m = q.len();
    let start = (0..m).find(|&j| q[j] == a)?; // q runs b -> a, so after a comes the rest
    for j in 1..m - 1 {
        let c = q[(start + j) % m];
        if out.contains(&c) {
            return None;
        }
        out.push(c);
    }
    debug_assert_eq!(out.first(), Some(&b));
    Some(out)
}

/// A joined outline passes the scene's polygon checks and is flat to [`COPLANAR`].
fn acceptable(points: &[DVec3], poly: &[u32]) -> bool {
    let corners: Vec<DVec3> = poly.iter().map(|&i| points[i as usize]).collect();
    if geometry::validate_polygon(&corners).is_err() {
        return false;
    }
    let reach = corners
        .iter()
        .map(|c| c.abs().max_element())
        .fold(0.0, f64::max);
    geometry::max_plane_deviation(&corners) <= COPLANAR * (geometry::diameter(&corners) + reach)
}

#[cfg(test)]
mod tests {
    use glam::dvec3;

    use super::*;

    fn square() -> Vec<DVec3> {
        vec![
            dvec3(0.0, 0.0, 0.0),
            dvec3(1.0, 0.0, 0.0),
            dvec3(1.0, 1.0, 0.0),
            dvec3(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn a_fan_of_two_triangles_is_its_quad_from_the_same_corner() {
        let joined = join_coplanar(&square(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(joined, vec![vec![0, 1, 2, 3]]);
    }

    #[test]
    fn triangles_that_bend_stay_apart() {
        // The fourth corner 0.01 above the plane of the first three: 0.7% of the
        // diagonal, far more than the 1e-6 allowed.
        let mut p = square();
        p[3].z = 0.01;
        let joined = join_coplanar(&p, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(joined.len(), 2);
    }

    #[test]
    fn a_non_convex_union_stays_apart() {
        // An L of three unit squares' triangles: the squares join pairwise but never into
        // the L (not convex).
        let p = vec![
            dvec3(0.0, 0.0, 0.0),
            dvec3(1.0, 0.0, 0.0),
            dvec3(2.0, 0.0, 0.0),
            dvec3(0.0, 1.0, 0.0),
            dvec3(1.0, 1.0, 0.0),
            dvec3(2.0, 1.0, 0.0),
            dvec3(0.0, 2.0, 0.0),
            dvec3(1.0, 2.0, 0.0),
        ];
        let tris = [
            [0, 1, 4],
            [0, 4, 3],
            [1, 2, 5],
            [1, 5, 4],
            [3, 4, 7],
            [3, 7, 6],
        ];
        let joined = join_coplanar(&p, &tris);
        let area: f64 = joined
            .iter()
            .map(|poly| {
                let c: Vec<DVec3> = poly.iter().map(|&i| p[i as usize]).collect();
                assert!(geometry::is_convex(&c), "{poly:?}");
                geometry::polygon_area(&c)
            })
            .sum();
        assert!(joined.len() < tris.len() && joined.len() >= 2, "{joined:?}");
        assert!((area - 3.0).abs() < 1e-12);
    }

    #[test]
    fn opposite_facing_triangles_are_not_joined() {
        // The second triangle runs 0 -> 2 too (faces the other way): no shared edge in
        // opposite directions.
        let joined = join_coplanar(&square(), &[[0, 1, 2], [0, 3, 2]]);
        assert_eq!(joined.len(), 2);
    }

    #[test]
    fn degenerate_triangles_pass_through() {
        let joined = join_coplanar(&square(), &[[0, 0, 1], [0, 1, 2], [0, 2, 3]]);
        assert_eq!(joined, vec![vec![0, 0, 1], vec![0, 1, 2, 3]]);
    }
}
