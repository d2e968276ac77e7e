//! Solutions compared across meshes (`radiosity::compare`) on a scene whose surfaces lie on
//! or touch one another (`contact.scene`): the case where `radiosity compare` used to stop
//! with "lies on no element of the other mesh" (issue #11), because the ray that looked
//! for a floor point's element first met the coplanar bottom of a box standing there (or a
//! rug lying in the floor's plane) and then refused it as another surface.

use radiosity::compare::compare;
use radiosity::light::Rgb;
use radiosity::mesh::{mesh_scene, Mesh};
use radiosity::pipeline::{self, Overrides, Prepared, SolveRequest};
use radiosity::progress::NoProgress;
use radiosity::solve::{keep_going, HierarchicalSettings, Radiosity, Solver};

use crate::fixtures::{contact_scene, dense_gauss_seidel};

fn prepared(max_area: f64) -> Prepared {
    let file = contact_scene();
    let overrides = Overrides {
        max_patch_area: Some(max_area),
        integral_steps: None,
    };
    Prepared::new(file.scene, overrides.apply(file.settings), &NoProgress).unwrap()
}

/// `contact.scene` in millimetres: the ray that looked for a point's element was then long
/// enough for the BVH's traversal (see `PolygonBvh::polygon_at`), and failed only where a
/// coplanar surface of another name lay on the point.
fn in_millimetres(max_area_m2: f64) -> Prepared {
    let file = contact_scene();
    let mut scene = file.scene;
    for s in &mut scene.surfaces {
        for v in &mut s.vertices {
            *v *= 1000.0;
        }
    }
    let overrides = Overrides {
        max_patch_area: Some(max_area_m2 * 1e6),
        integral_steps: None,
    };
    Prepared::new(scene, overrides.apply(file.settings), &NoProgress).unwrap()
}

#[test]
fn a_solution_compared_with_itself_differs_by_exactly_zero() {
    for p in [prepared(0.1), in_millimetres(0.1)] {
        self_comparison_is_zero(&p);
    }
}

fn self_comparison_is_zero(p: &Prepared) {
    let s = dense_gauss_seidel(p);
    let c = compare(
        &p.mesh,
        &s.radiosity,
        p.light.emission(),
        &s.mesh,
        &s.radiosity,
    )
    .unwrap();
    assert_eq!((c.rms, c.max, c.bias), (0.0, 0.0, 0.0), "{c:?}");
    assert_eq!(c.elements, p.mesh.len());
}

#[test]
fn a_field_of_surface_values_is_the_same_on_any_mesh() {
    // B = 1 + surface index on both meshes: wherever a point of one mesh falls, the other
    // mesh's element there is of the same surface, so the difference is zero but for the
    // rounding of the 16-point means. Taking the rug's, the stool's or the block's value
    // for the floor's would put it near 1.
    let scene = contact_scene().scene;
    let (coarse, fine) = (
        mesh_scene(&scene, 0.1).unwrap(),
        mesh_scene(&scene, 0.1 / 3.0).unwrap(),
    );
    assert!(fine.len() > 2 * coarse.len());
    let field = |m: &Mesh| {
        Radiosity(
            m.elements
                .iter()
                .map(|e| Rgb::splat(1.0 + e.surface as f64))
                .collect(),
        )
    };
    let e = vec![Rgb::BLACK; coarse.len()];
    let c = compare(&coarse, &field(&coarse), &e, &fine, &field(&fine)).unwrap();
    assert!(c.rms < 1e-12 && c.max < 1e-12, "{c:?}");
    let (coarse_mm, fine_mm) = (in_millimetres(0.1).mesh, in_millimetres(0.1 / 3.0).mesh);
    // Contact refinement may split a piece at a footprint's edge in one unit and not in the
    // other (a probe point that lies on the edge is judged by rounding): the meshes need
    // not have equal counts.
    let e = vec![Rgb::BLACK; coarse_mm.len()];
    let c = compare(
        &coarse_mm,
        &field(&coarse_mm),
        &e,
        &fine_mm,
        &field(&fine_mm),
    )
    .unwrap();
    assert!(c.rms < 1e-12 && c.max < 1e-12, "{c:?}");
    let e = vec![Rgb::BLACK; fine.len()];
    let back = compare(&fine, &field(&fine), &e, &coarse, &field(&coarse)).unwrap();
    assert!(back.rms < 1e-12 && back.max < 1e-12, "{back:?}");
}

#[test]
fn two_meshes_and_two_solvers_of_one_scene_differ_by_their_discretisation() {
    // The dense solve at 0.1 m^2 against itself at a quarter of the area, and against
    // hierarchical radiosity (which makes its own leaves) refined finely: the differences
    // of element radiosity are the meshes' (a few per cent), not a failed projection (order
    // 1) or a refusal.
    let reference = prepared(0.1);
    let dense = dense_gauss_seidel(&reference);
    let emission = reference.light.emission();
    let finer = prepared(0.025);
    let fine = dense_gauss_seidel(&finer);
    let c = compare(
        &reference.mesh,
        &dense.radiosity,
        emission,
        &fine.mesh,
        &fine.radiosity,
    )
    .unwrap();
    eprintln!("dense 0.1 against dense 0.025: {c:?}");
    assert!(c.rms > 0.0 && c.rms < 0.1, "{c:?}");
    let hierarchical = pipeline::solve(
        &reference,
        &SolveRequest::new(Solver::Hierarchical(HierarchicalSettings {
            epsilon: 0.001,
            min_area: 0.1 / 4.0,
            tolerance: 1e-6,
            max_memory_bytes: None,
            final_gather: true,
            gather_points: radiosity::solve::GATHER_POINTS_DEFAULT,
        })),
        &mut keep_going,
        &NoProgress,
    )
    .unwrap();
    assert_ne!(hierarchical.mesh.len(), reference.mesh.len());
    let h = compare(
        &reference.mesh,
        &dense.radiosity,
        emission,
        &hierarchical.mesh,
        &hierarchical.radiosity,
    )
    .unwrap();
    eprintln!("dense 0.1 against hierarchical: {h:?}");
    assert!(h.rms > 0.0 && h.rms < 0.1, "{h:?}");
}
