//! Adaptive subdivision driven by the solution: elements whose radiosity steps against a
//! neighbour's are split, and the solve goes on on the finer mesh.
//!
//! A uniform grid spends its elements evenly, but the light does not vary evenly: it
//! changes fast at shadow boundaries, under furniture, around a light and in concave
//! corners, and hardly at all across the middle of a wall. After a solve, [`mark_steps`]
//! finds the pairs of touching elements of one surface whose luminances differ by more than
//! a visible step (relative to the larger of the two and to the scene's white), and
//! [`split_marked`] cuts both into four (as contact refinement does). This is the a
//! posteriori refinement of Cohen, Greenberg, Immel and Brock (1986, "An efficient radiosity
//! approach for realistic image synthesis", substructuring by the radiosity gradient) that
//! Lightscape and AGi32 apply between solves, within a budget of elements.
//!
//! Elements touch when they share a vertex of their display polygons (a corner of one on
//! the boundary of the other), so the steps across T-junctions left by earlier splits are
//! seen too.

use glam::DVec3;

use super::contact::quarters;
use super::Mesh;

/// When and how far the mesh is refined between solves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptSettings {
    /// A step is visible when two touching elements' luminances differ by more than this
    /// fraction of the larger of the two ...
    pub contrast: f64,
    /// ... and by more than this fraction of the scene's white (the radiosity that
    /// automatic exposure shows as white), so that steps in the dark, invisible on screen,
    /// do not spend the budget.
    pub floor: f64,
    /// Elements no larger than this (scene units squared) are not split.
    pub min_area: f64,
    /// The refined mesh has at most this many elements: where more are marked, the largest
    /// steps on the largest elements are split first.
    pub max_elements: usize,
    /// Solves after the first, each on a mesh refined from the last solution.
    pub rounds: u32,
    /// At most this many form-factor pairs are integrated in all the rounds together (a
    /// split of one element among n costs about 4 n new pairs): the time the refinement may
    /// take, in units of the first matrix's n (n - 1) / 2 pairs. `u64::MAX` for no limit.
    pub max_new_pairs: u64,
}

/// Steps smaller than this fraction of white are not split by default: they are hard to see
/// and spend the budget inside bookcases and under tables (building_small against the path
/// tracer, two rounds: 5.79 % pixel RMS with a floor of 1 %, 5.61 % with 5 %).
pub const DEFAULT_FLOOR: f64 = 0.05;

/// The default contrast: a step of 30 % of the brighter element.
pub const DEFAULT_CONTRAST: f64 = 0.3;

/// New form-factor pairs the default budget always allows, however small the first mesh:
/// examples/room.scene (907 elements, 0.8 million pairs) takes 1.5 million for its two
/// rounds within twice its elements (4.24 % -> 2.81 % against the path tracer), which a
/// budget of n^2 alone would stop after the first.
pub const MIN_PAIR_BUDGET: u64 = 4_000_000;

/// The most elements the default budget allows: where `--solver auto` turns to hierarchical
/// radiosity.
pub const DEFAULT_MAX_ELEMENTS: usize = 20_000;

impl AdaptSettings {
    /// The defaults for a mesh of `elements` elements cut at `max_patch_area`, `rounds`
    /// rounds: [`DEFAULT_CONTRAST`], [`DEFAULT_FLOOR`], elements down to 1/64 of
    /// `MAX_PATCH_AREA` (three splits), at most twice the elements (and
    /// [`DEFAULT_MAX_ELEMENTS`]), and at most n^2 new pairs (or [`MIN_PAIR_BUDGET`]): about
    /// twice the first matrix's, so the form factors take at most about three times as
    /// long as without it.
    pub fn defaults(elements: usize, max_patch_area: f64, rounds: u32) -> AdaptSettings {
        let n = elements;
        AdaptSettings {
            contrast: DEFAULT_CONTRAST,
            floor: DEFAULT_FLOOR,
            min_area: max_patch_area / 64.0,
            max_elements: (2 * n).min(DEFAULT_MAX_ELEMENTS).max(n),
            rounds,
            max_new_pairs: (n as u64).saturating_mul(n as u64).max(MIN_PAIR_BUDGET),
        }
    }
}

/// How an element of a refined mesh came from the mesh before.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// It is element `i` of the mesh before, unchanged.
    Kept(u32),
    /// It is a quarter of element `i` of the mesh before.
    Child(u32),
}

impl Origin {
    /// The element of the mesh before that this one is or lies in.
    pub fn parent(self) -> u32 {
        match self {
            Origin::Kept(i) | Origin::Child(i) => i,
        }
    }
}

/// The elements of `mesh` to split: both elements of every touching pair (same surface)
/// whose `luminance` values differ by more than `settings.contrast` of the larger and by
/// more than `settings.floor * white`, unless no larger than `settings.min_area`; at most as
/// many as keep the refined mesh within `settings.max_elements` (each split adds three)
/// and cost at most `pairs_left` new form-factor pairs (about 4 n each), taken in
/// decreasing order of step times the square root of the element's area.
pub fn mark_steps(
    mesh: &Mesh,
    luminance: &[f64],
    white: f64,
    settings: &AdaptSettings,
    pairs_left: u64,
) -> Vec<bool> {
    let n = mesh.len();
    // The largest step each element takes part in, 0 where none is visible.
    let mut step = vec![0.0f64; n];
    for (a, b) in touching_pairs(mesh) {
        let (ya, yb) = (luminance[a as usize], luminance[b as usize]);
        let d = (ya - yb).abs();
        if d.is_finite() && d > settings.contrast * ya.max(yb) && d > settings.floor * white {
            for e in [a as usize, b as usize] {
                step[e] = step[e].max(d);
            }
        }
    }
    let mut candidates: Vec<(f64, usize)> = step
        .iter()
        .enumerate()
        .filter(|&(e, &d)| d > 0.0 && mesh.elements[e].area > settings.min_area)
        .map(|(e, &d)| (d * mesh.elements[e].area.sqrt(), e))
        .collect();
    candidates.sort_unstable_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let room = (settings.max_elements.saturating_sub(n) / 3)
        .min((pairs_left / (4 * n.max(1) as u64)).min(usize::MAX as u64) as usize);
    let mut marks = vec![false; n];
    for &(_, e) in candidates.iter().take(room) {
        marks[e] = true;
    }
    marks
}

/// `mesh` with every marked element cut into four (a quadrilateral at its bilinear
/// midpoints, a triangle at its edge midpoints), and where each new element came from.
/// `surfaces` is the scene's surface count.
pub fn split_marked(mesh: &Mesh, surfaces: usize, marks: &[bool]) -> (Mesh, Vec<Origin>) {
    let pieces: Vec<Option<Vec<Vec<DVec3>>>> = (0..mesh.len())
        .map(|e| {
            marks[e].then(|| {
                let corners: Vec<DVec3> = mesh.corner_positions(e).collect();
                quarters(&corners)
            })
        })
        .collect();
    let refined = mesh.with_pieces(surfaces, &pieces);
    // `with_pieces` keeps surface order and puts each element's pieces in its place.
    let mut origin = Vec::with_capacity(refined.len());
    for range in &mesh.surface_elements {
        for e in range.clone() {
            match &pieces[e as usize] {
                None => origin.push(Origin::Kept(e)),
                Some(p) => origin.extend(std::iter::repeat_n(Origin::Child(e), p.len())),
            }
        }
    }
    debug_assert_eq!(origin.len(), refined.len());
    (refined, origin)
}

/// Every pair (a, b), a < b, of elements of one surface that touch: share a vertex of
/// their display polygons ([`Mesh::display`]), which hold each element's corners and the
/// T-vertices on its edges, so a corner of one lying on the boundary of the other counts
/// (vertices are shared by index within a surface, and surfaces share none).
pub(crate) fn touching_pairs(mesh: &Mesh) -> Vec<(u32, u32)> {
    let display = mesh.display();
    let mut at_vertex: Vec<Vec<u32>> = vec![Vec::new(); mesh.vertices.len()];
    for e in 0..mesh.len() {
        for &v in display.polygon(e) {
            at_vertex[v as usize].push(e as u32);
        }
    }
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for elements in &at_vertex {
        for (k, &a) in elements.iter().enumerate() {
            for &b in &elements[k + 1..] {
                pairs.push((a.min(b), a.max(b)));
            }
        }
    }
    // A pair sharing an edge is found at both its ends.
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::scene::{Rgb, Scene, Surface};
    use glam::dvec3;

    /// A 4 x 4 square (facing +z) cut into a 4 x 4 grid of unit elements.
    fn grid() -> (Mesh, usize) {
        let scene = Scene {
            surfaces: vec![Surface {
                name: "square".into(),
                emission: Rgb::BLACK,
                reflectance: Rgb([0.5; 3]),
                vertices: vec![
                    dvec3(0., 0., 0.),
                    dvec3(4., 0., 0.),
                    dvec3(4., 4., 0.),
                    dvec3(0., 4., 0.),
                ],
                photometry: Default::default(),
            }],
            camera: None,
            lights: Vec::new(),
        };
        (mesh_scene(&scene, 1.0).unwrap(), 1)
    }

    fn settings() -> AdaptSettings {
        AdaptSettings {
            contrast: 0.2,
            floor: 0.01,
            min_area: 0.01,
            max_elements: 1000,
            rounds: 1,
            max_new_pairs: u64::MAX,
        }
    }

    #[test]
    fn a_4x4_grid_has_42_touching_pairs() {
        // Edge neighbours: 2 x 4 x 3 = 24; diagonal (corner) neighbours: 2 x 3 x 3 = 18.
        let (mesh, _) = grid();
        assert_eq!(touching_pairs(&mesh).len(), 42);
    }

    #[test]
    fn pieces_of_a_split_element_touch_its_unsplit_neighbours_across_t_junctions() {
        let (mesh, surfaces) = grid();
        let mut marks = vec![false; mesh.len()];
        marks[5] = true; // the cell [1, 2] x [1, 2]
        let (refined, origin) = split_marked(&mesh, surfaces, &marks);
        assert_eq!(refined.len(), 19);
        assert_eq!(origin.iter().filter(|o| **o == Origin::Child(5)).count(), 4);
        assert!((refined.total_area() - 16.0).abs() < 1e-12);
        // Each quarter touches its 3 siblings and the 3 cells around the parent's corner it
        // lies in (two along its outer edges, one at the corner point), across T-junctions.
        let pairs = touching_pairs(&refined);
        let children: Vec<u32> = (0..refined.len() as u32)
            .filter(|&e| origin[e as usize] == Origin::Child(5))
            .collect();
        for &c in &children {
            let touching = pairs.iter().filter(|&&(a, b)| a == c || b == c).count();
            assert_eq!(touching, 3 + 3, "child {c}");
        }
    }

    #[test]
    fn a_step_across_a_line_marks_the_elements_on_both_sides_only() {
        // Left half bright (1.0), right half dark (0.2): columns 1 and 2 step.
        let (mesh, _) = grid();
        let y: Vec<f64> = mesh
            .elements
            .iter()
            .map(|e| if e.centroid.x < 2.0 { 1.0 } else { 0.2 })
            .collect();
        let marks = mark_steps(&mesh, &y, 1.0, &settings(), u64::MAX);
        for (e, el) in mesh.elements.iter().enumerate() {
            let near = (el.centroid.x - 2.0).abs() < 1.0;
            assert_eq!(marks[e], near, "element {e} at {}", el.centroid);
        }
        // A step below the contrast, or below the floor, marks nothing.
        let gentle: Vec<f64> = y.iter().map(|&v| if v < 0.5 { 0.9 } else { 1.0 }).collect();
        assert!(!mark_steps(&mesh, &gentle, 1.0, &settings(), u64::MAX).contains(&true));
        assert!(!mark_steps(&mesh, &y, 1000.0, &settings(), u64::MAX).contains(&true));
    }

    #[test]
    fn the_budget_takes_the_largest_steps_first_and_min_area_stops_splitting() {
        let (mesh, _) = grid();
        // Steps of 0.9 between columns 0 and 1, and of 0.5 between columns 2 and 3.
        let y: Vec<f64> = mesh
            .elements
            .iter()
            .map(|e| match e.centroid.x as u32 {
                0 => 1.0,
                1 => 0.1,
                2 => 0.1,
                _ => 0.6,
            })
            .collect();
        let budget = AdaptSettings {
            max_elements: 16 + 3 * 8,
            ..settings()
        };
        let marks = mark_steps(&mesh, &y, 1.0, &budget, u64::MAX);
        for (e, el) in mesh.elements.iter().enumerate() {
            assert_eq!(marks[e], el.centroid.x < 2.0, "element {e}");
        }
        // The same 8 splits by the pair budget: 8 x 4 x 16 pairs.
        let marks = mark_steps(&mesh, &y, 1.0, &settings(), 8 * 4 * 16);
        for (e, el) in mesh.elements.iter().enumerate() {
            assert_eq!(marks[e], el.centroid.x < 2.0, "element {e}");
        }
        let small = AdaptSettings {
            min_area: 1.0,
            ..settings()
        };
        assert!(!mark_steps(&mesh, &y, 1.0, &small, u64::MAX).contains(&true));
    }
}
