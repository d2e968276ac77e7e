//! The most leaves a minimum area lets the hierarchy make, checked against the element
//! budget before any refinement.
//!
//! QA pass 16 of #16: `check --solver hierarchical --min-area 1e-9` was accepted and
//! refined for minutes, its memory growing, until the memory limit stopped it. A patch is
//! split while its area exceeds the minimum, so where the refinement goes all the way the
//! leaves are at most the minimum area: the scene's surfaces cut at that area, about the
//! scene's area over it. That count is held to [`crate::mesh::MAX_ELEMENTS`], the budget
//! that `MAX_PATCH_AREA` is held to, except at or above the default minimum area
//! (`MAX_PATCH_AREA / 16`, [`super::HierarchicalSettings::defaults_for`]), with which the
//! million-element scenes of BENCHMARKS.md are solved (the refinement oracle keeps them far
//! from the bound, and the memory limit still holds).

use crate::mesh::{largest_area_that_fits, planned_elements, MAX_ELEMENTS};
use crate::scene::Scene;

use crate::solve::SolveError;

/// Refuses a `min_area` below `max_patch_area / 16` at which `scene`'s surfaces, cut to
/// that area, would make more than [`MAX_ELEMENTS`] leaves; the error says the smallest
/// minimum area that fits.
pub fn check_min_area(scene: &Scene, max_patch_area: f64, min_area: f64) -> Result<(), SolveError> {
    let default = max_patch_area / 16.0;
    if !(min_area < default) {
        return Ok(());
    }
    // A patch splits in four while its area is above the minimum, so its leaves are
    // between a quarter of it and it: as many as the surfaces cut at a quarter of it (the
    // review: cut at the minimum itself, the count was up to 4 times short).
    let leaves = planned_elements(scene, min_area / 4.0);
    if leaves <= MAX_ELEMENTS as f64 {
        return Ok(());
    }
    Err(SolveError::MinAreaTooSmall {
        min_area,
        leaves,
        limit: MAX_ELEMENTS,
        fits: largest_area_that_fits(scene, MAX_ELEMENTS).map(|a| (4.0 * a).min(default)),
        default,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Rgb;
    use crate::scene::Surface;
    use glam::DVec3;

    /// One `side` x `side` square.
    fn square(side: f64) -> Scene {
        let v = |x: f64, z: f64| DVec3::new(x, 0.0, z);
        Scene {
            surfaces: vec![Surface {
                name: "floor".into(),
                vertices: vec![v(0.0, 0.0), v(side, 0.0), v(side, side), v(0.0, side)],
                reflectance: Rgb([0.5; 3]),
                emission: Rgb::BLACK,
                photometry: Default::default(),
            }],
            camera: None,
            lights: Vec::new(),
        }
    }

    #[test]
    fn a_minimum_area_of_more_leaves_than_the_budget_is_refused_with_what_fits() {
        // A 100 m square at MAX_PATCH_AREA 100 (100 elements): leaves of 1e-9 m^2 down to a
        // quarter of that would be up to 1e4 / 2.5e-10 = 4e13 of them, past the 8e6
        // budget; 8e6 square leaves of the square are 1e4 / 8e6 = 1.25e-3 m^2 each (a
        // 2828 x 2828 grid, 7,997,584 of them, is the largest square grid within it:
        // 1e4 / 2828^2 = 1.2504e-3), the quarter of a minimum area 4 times that.
        let scene = square(100.0);
        match check_min_area(&scene, 100.0, 1e-9) {
            Err(SolveError::MinAreaTooSmall {
                leaves,
                limit,
                fits: Some(fits),
                default,
                ..
            }) => {
                assert!((leaves - 4e13).abs() < 4e13 * 1e-6, "{leaves}");
                assert_eq!(limit, 8_000_000);
                assert_eq!(default, 100.0 / 16.0);
                assert!(
                    fits >= 5e-3 && fits <= 4e4 / 2828f64.powi(2) * 1.000001,
                    "{fits}"
                );
                // What it says fits does fit.
                assert_eq!(check_min_area(&scene, 100.0, fits), Ok(()));
            }
            other => panic!("{other:?}"),
        }
        let text = check_min_area(&scene, 100.0, 1e-9).unwrap_err().to_string();
        assert!(text.contains("a minimum element area of 1e-9"), "{text}");
        assert!(text.contains("more than the limit of 8000000"), "{text}");
        assert!(text.contains("0.005002 or more fits"), "{text}");
    }

    #[test]
    fn the_default_minimum_area_and_coarser_ones_are_never_refused() {
        // A 10 km square at MAX_PATCH_AREA 100: its mesh has 1e6 elements, and the default
        // minimum area, 100 / 16, would cut it into 1.6e7 leaves, past the budget: the
        // default is what the million-element scenes run with, and passes.
        let scene = square(10_000.0);
        assert_eq!(check_min_area(&scene, 100.0, 100.0 / 16.0), Ok(()));
        assert_eq!(check_min_area(&scene, 100.0, 50.0), Ok(()));
        // Below it, the smallest that fits is the default itself (1e8 / 8e6 = 12.5 m^2 is
        // coarser).
        match check_min_area(&scene, 100.0, 1.0) {
            Err(SolveError::MinAreaTooSmall { fits, .. }) => assert_eq!(fits, Some(6.25)),
            other => panic!("{other:?}"),
        }
        // A fine minimum on a small scene is fine: 1 m^2 at 1e-3 is 1e3 leaves.
        assert_eq!(check_min_area(&square(1.0), 1.0, 1e-3), Ok(()));
    }
}
