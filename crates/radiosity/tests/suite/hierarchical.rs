//! Hierarchical radiosity against the closed form in a closed cube and against the dense
//! Gauss-Seidel solve on the Cornell box.

use radiosity::compare::compare;
use radiosity::form_factor::occluder_bvh;
use radiosity::light::Rgb as Light;
use radiosity::progress::NoProgress;
use radiosity::scene::{cornell_box, Scene};
use radiosity::solve::{
    solve_hierarchical, HierarchicalSettings, HierarchicalSolution, DEFAULT_HIERARCHICAL_TOLERANCE,
};

use crate::fixtures::{dense_gauss_seidel, lit_closed_cube, prepared_cornell};

/// A closed unit cube, every face facing in, E and rho uniform; one element a face at
/// MAX_PATCH_AREA [`CUBE_AREA`].
fn unit_cube(e: [f64; 3], rho: [f64; 3]) -> Scene {
    lit_closed_cube(|_| e, rho)
}

/// The MAX_PATCH_AREA of [`unit_cube`]: one element a face.
const CUBE_AREA: f64 = 1.0;

/// The built-in Cornell box and its scene file's MAX_PATCH_AREA (1000 mm^2).
fn cornell() -> (Scene, f64) {
    let file = cornell_box();
    (file.scene, file.settings.max_patch_area)
}

/// Settings with the given epsilon and minimum area, the final gather on or off, the
/// default tolerance and no memory limit.
fn settings(epsilon: f64, min_area: f64, final_gather: bool) -> HierarchicalSettings {
    HierarchicalSettings {
        epsilon,
        min_area,
        tolerance: DEFAULT_HIERARCHICAL_TOLERANCE,
        max_memory_bytes: None,
        final_gather,
        gather_points: radiosity::solve::GATHER_POINTS_DEFAULT,
    }
}

/// `scene` by hierarchical radiosity with `settings`, its patches split along the grid of
/// the mesh at MAX_PATCH_AREA `max_area`.
fn solve_with(
    scene: &Scene,
    max_area: f64,
    settings: &HierarchicalSettings,
) -> HierarchicalSolution {
    let bvh = occluder_bvh(scene);
    solve_hierarchical(scene, max_area, &bvh, settings, &NoProgress).unwrap()
}

/// `scene` by hierarchical radiosity with the final gather, its patches split along the
/// grid of the mesh at MAX_PATCH_AREA `max_area`.
fn solve(scene: &Scene, max_area: f64, epsilon: f64, min_area: f64) -> HierarchicalSolution {
    solve_with(scene, max_area, &settings(epsilon, min_area, true))
}

/// Area-weighted mean B of every input surface, per band.
fn per_surface(mesh: &radiosity::mesh::Mesh, b: &radiosity::solve::Radiosity) -> Vec<[f64; 3]> {
    weighted_per_surface(mesh, b, |e| mesh.elements[e].area)
}

/// The area-weighted mean per surface of a solution on `other` projected onto the elements
/// of `reference` (see [`radiosity::compare::project`]), each element weighted by the area
/// of it that `other` covers.
fn per_surface_projected(
    reference: &radiosity::mesh::Mesh,
    other: &radiosity::mesh::Mesh,
    b: &radiosity::solve::Radiosity,
) -> Vec<[f64; 3]> {
    let p = radiosity::compare::project(reference, other, b).unwrap();
    weighted_per_surface(reference, &p.radiosity, |e| p.covered[e])
}

/// The mean of `b` over each input surface of `mesh`, element e weighted by `weight(e)`.
fn weighted_per_surface(
    mesh: &radiosity::mesh::Mesh,
    b: &radiosity::solve::Radiosity,
    weight: impl Fn(usize) -> f64,
) -> Vec<[f64; 3]> {
    mesh.surface_elements
        .iter()
        .map(|range| {
            let mut sum = [0.0; 3];
            let mut total = 0.0;
            for e in range.clone() {
                let w = weight(e as usize);
                total += w;
                for (k, s) in sum.iter_mut().enumerate() {
                    *s += w * b.0[e as usize][k];
                }
            }
            sum.map(|s| s / total)
        })
        .collect()
}

/// The dense reference: Gauss-Seidel on the area-integral form factors (k = 2) of the
/// Cornell box meshed at MAX_PATCH_AREA 2000 mm^2 (about 1000 elements).
struct Dense {
    mesh: std::sync::Arc<radiosity::mesh::Mesh>,
    radiosity: radiosity::solve::Radiosity,
    emission: Vec<Light>,
    per_surface: Vec<[f64; 3]>,
}

fn dense_cornell() -> Dense {
    let prepared = prepared_cornell(2000.0, Some(2));
    let dense = dense_gauss_seidel(&prepared);
    let emission = prepared.light.emission().to_vec();
    Dense {
        per_surface: per_surface(&prepared.mesh, &dense.radiosity),
        mesh: prepared.mesh.clone(),
        radiosity: dense.radiosity,
        emission,
    }
}

/// Area-weighted RMS over the surfaces and bands of the difference of the reflected
/// radiosity B - E (the part a solver computes; the light's E would otherwise dominate),
/// relative to the area-weighted RMS of the reference's reflected radiosity.
fn relative_rms(scene: &Scene, got: &[[f64; 3]], want: &[[f64; 3]]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (i, s) in scene.surfaces.iter().enumerate() {
        let a = radiosity::geometry::polygon_area(&s.vertices);
        for k in 0..3 {
            let e = s.emission.0[k];
            num += a * (got[i][k] - want[i][k]).powi(2);
            den += a * (want[i][k] - e).powi(2);
        }
    }
    (num / den).sqrt()
}

const CUBE_E: [f64; 3] = [1.0, 2.0, 0.5];
const CUBE_RHO: [f64; 3] = [0.5, 0.3, 0.7];

/// (area-weighted mean relative error, largest relative error) of B against E / (1 - rho).
fn cube_errors(s: &HierarchicalSolution) -> (f64, f64) {
    let (mut mean, mut worst, mut area) = (0.0, 0.0f64, 0.0);
    for (i, el) in s.mesh.elements.iter().enumerate() {
        for k in 0..3 {
            let exact = CUBE_E[k] / (1.0 - CUBE_RHO[k]);
            let rel = (s.radiosity.0[i][k] - exact).abs() / exact;
            worst = worst.max(rel);
            mean += el.area * rel / 3.0;
        }
        area += el.area;
    }
    (mean / area, worst)
}

#[test]
fn unrefined_closed_cube_is_exact() {
    // Without refinement every face gathers from the five others at the mean of four exact
    // point-to-polygon values, each summing to exactly 1 over the five faces: B = E / (1 - rho)
    // to the solve tolerance (1e-7 of max E per sweep change, amplified by 1 / (1 - rho)).
    let s = solve(&unit_cube(CUBE_E, CUBE_RHO), CUBE_AREA, 10.0, 1.0 / 256.0);
    assert_eq!(s.report.leaves, 6);
    assert_eq!(s.report.links, 30);
    let (mean, worst) = cube_errors(&s);
    assert!(worst < 1e-5, "mean {mean:e} worst {worst:e}");
}

#[test]
fn refined_closed_cube_is_close_to_the_closed_form() {
    // With refinement a leaf gathers through links held by its ancestors, whose form factors
    // are averages over the ancestor, not values at the leaf: leaves near a corner over- or
    // under-estimate their total form factor (measured: up to 1.17 at epsilon 0.01). Area
    // averaged, the sums stay close to 1. Measured at epsilon 0.01: area-weighted mean
    // relative error 3.3e-2, largest 0.19 (a corner leaf); escaped power -0.8 %, -0.4 % and
    // -1.9 % of emitted (red, green, blue: the error of the form-factor sums, amplified by
    // 1 / (1 - rho)). Tolerances: 5 %, 25 % and 3 %. Those figures are without the final
    // gather; with it (evaluating the ancestors' links at each leaf, iterated to the
    // tolerance) measured: mean 2.3e-3, largest 8.2e-3, escaped -0.36 %, -0.26 % and
    // -0.61 % (with two passes of it, as before: 5.7e-3, 3.5e-2, -0.7 %, -0.3 % and
    // -1.8 %); the bounds still hold the
    // hierarchy without it.
    let s = solve(&unit_cube(CUBE_E, CUBE_RHO), CUBE_AREA, 0.01, 1.0 / 256.0);
    let (mean, worst) = cube_errors(&s);
    let b = s.report.balance;
    let escaped: Vec<f64> = (0..3).map(|k| b.escaped[k] / b.emitted[k]).collect();
    eprintln!(
        "cube eps 0.01: leaves {} links {} mean {mean:.3e} worst {worst:.3e} escaped {escaped:?}",
        s.report.leaves, s.report.links
    );
    assert!(s.report.leaves > 6);
    assert!(mean < 0.05, "mean {mean:e}");
    assert!(worst < 0.25, "worst {worst:e}");
    for e in escaped {
        assert!(e.abs() < 0.03, "escaped {e:e}");
    }
    assert!(b.relative_error() < 1e-5, "{b:?}");
}

#[test]
fn closed_room_balances_energy_at_the_defaults() {
    // Issue #11: in a closed room every watt emitted is absorbed, so the energy account's
    // escaped power must be zero (emitted = absorbed). The closed unit cube lit by its
    // ceiling (face5), every face reflecting half, at MAX_PATCH_AREA 0.01 (600 elements)
    // and the defaults. Measured: escaped -0.33 % of emitted in every band (-1.3 % with
    // the two gather passes of before, -3.2 % without the gather: the hierarchy's links
    // from coarse sources send their mean radiosity with their mean form factor, which
    // overshoots where both peak together, near the corners). Bound: the 0.5 %.
    let scene = lit_closed_cube(|i| if i == 5 { [1.0; 3] } else { [0.0; 3] }, [0.5; 3]);
    let max_area = 0.01;
    let s = solve_with(
        &scene,
        max_area,
        &HierarchicalSettings::defaults_for(max_area),
    );
    let b = s.report.balance;
    let escaped: Vec<f64> = (0..3).map(|k| b.escaped[k] / b.emitted[k]).collect();
    eprintln!(
        "closed cube at the defaults: {} leaves, escaped {escaped:?}",
        s.report.leaves
    );
    for e in escaped {
        assert!(e.abs() < 0.005, "escaped {e:e}");
    }
    assert!(b.relative_error() < 1e-5, "{b:?}");
}

/// bench/scenes/room_split_walls.scene made a furnace: every surface emits E = 1 and
/// reflects rho = 0.5, so B = E / (1 - rho) = 2 everywhere and nothing escapes (closed
/// form); with its MAX_PATCH_AREA.
fn split_walls_furnace() -> (Scene, f64) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../bench/scenes/room_split_walls.scene"
    );
    let mut file = radiosity::scene::read_scene(std::path::Path::new(path)).unwrap();
    for s in &mut file.scene.surfaces {
        s.emission = Light([1.0; 3]);
        s.reflectance = Light([0.5; 3]);
    }
    (file.scene, file.settings.max_patch_area)
}

/// Asserts a furnace solution of `scene` (B = 2 everywhere): the energy account within
/// `account` of the emitted power, every surface's mean B within `per_surface_bound` of 2.
fn assert_furnace(
    scene: &Scene,
    s: &radiosity::solve::HierarchicalSolution,
    account: f64,
    per_surface_bound: f64,
) {
    let b = s.report.balance;
    for k in 0..3 {
        let escaped = b.escaped[k] / b.emitted[k];
        assert!(
            escaped.abs() < account,
            "escaped {escaped:e} of the emitted"
        );
    }
    for (i, mean) in per_surface(&s.mesh, &s.radiosity).iter().enumerate() {
        let error = mean[0] / 2.0 - 1.0;
        assert!(
            error.abs() < per_surface_bound,
            "{}: mean B {} against 2 ({error:+.3})",
            scene.surfaces[i].name,
            mean[0]
        );
    }
}

#[test]
fn closed_room_of_coplanar_wall_pieces_is_a_furnace_at_the_defaults() {
    // Issue #11: a closed 6 x 2.7 x 6 m room whose walls and ceiling are each several
    // coplanar pieces (as every generated building's are), made a furnace
    // (`split_walls_furnace`). The point model of a cluster (members at its centre, seen
    // along the line between centres) overstated the exchange between clusters that meet
    // at an angle: 7.3 % of the emitted power was counted twice and surfaces' mean B came
    // out up to 16 % high. With cluster links weighed by their members' sample points,
    // measured: escaped +0.06 % (-0.06 % since the gather takes clusters' links at the
    // leaf), surfaces' mean B within 7.8 % (-5.9 % the light panel,
    // +7.8 % a small piece by a corner; they converge as epsilon falls: within 1.4 % at
    // epsilon 0.005). Bounds: the 0.5 % for the account; 10 % per surface, the
    // defaults' coarse links (epsilon 0.05 of the mean B per link) with a little room.
    let (scene, max_area) = split_walls_furnace();
    let s = solve_with(
        &scene,
        max_area,
        &HierarchicalSettings::defaults_for(max_area),
    );
    assert_furnace(&scene, &s, 0.005, 0.10);
}

#[test]
fn a_final_gather_at_coarse_points_keeps_the_furnace() {
    // The furnace of the test above with the final gather held to a quarter as many
    // points as leaves: it then gathers at patches of several leaves, and each leaf adds
    // what the links below its point bring. A link counted twice or left out between the
    // point and the leaf would show in the account by its share of the light (leaving out
    // the links below the points: 16 % escaped). Measured: escaped -0.76 % (counted twice;
    // at every leaf -0.06 %): a coarse point's form factors to middle-distance sources are
    // means over four points of a patch up to four leaves across, accurate to O((R / r)^2)
    // (`patch_form_factor`), so the account is held to 1 % here, twice the 0.5 %
    // for the defaults (which gather at every leaf below 250,000 of them); 10 % per
    // surface as above.
    let (scene, max_area) = split_walls_furnace();
    let defaults = HierarchicalSettings::defaults_for(max_area);
    let every_leaf = solve_with(&scene, max_area, &defaults);
    assert_eq!(every_leaf.report.gather_points, every_leaf.report.leaves);
    let quarter = every_leaf.report.leaves / 4;
    let s = solve_with(
        &scene,
        max_area,
        &HierarchicalSettings {
            gather_points: quarter,
            ..defaults
        },
    );
    assert!(
        s.report.gather_points <= quarter && s.report.gather_points > 0,
        "{} points for {} leaves, at most {quarter} asked",
        s.report.gather_points,
        s.report.leaves
    );
    assert_furnace(&scene, &s, 0.01, 0.10);
}

#[test]
fn cornell_box_agrees_with_the_dense_solve() {
    const EPS: f64 = 0.01;
    let (scene, max_area) = cornell();
    let dense = dense_cornell();
    let t = std::time::Instant::now();
    let s = solve(&scene, max_area, EPS, 500.0);
    let elapsed = t.elapsed();
    // Per surface over the dense mesh's elements, which leave out the floor under the
    // blocks (contact refinement drops it as buried, and so does the hierarchy).
    let h = per_surface_projected(&dense.mesh, &s.mesh, &s.radiosity);
    let rms = relative_rms(&scene, &h, &dense.per_surface);
    let c = compare(
        &dense.mesh,
        &dense.radiosity,
        &dense.emission,
        &s.mesh,
        &s.radiosity,
    )
    .unwrap();
    for (i, x) in scene.surfaces.iter().enumerate() {
        eprintln!(
            "{:28} dense {:9.4} hier {:9.4}",
            x.name, dense.per_surface[i][0], h[i][0]
        );
    }
    eprintln!(
        "cornell eps {EPS} min 500: {elapsed:?}, {} leaves, {} clusters, {} links, {} rounds, {} sweeps, {} rays; per-surface relative RMS {rms:.3e}; per element {c:?}",
        s.report.leaves, s.report.clusters, s.report.links, s.report.rounds, s.report.iterations, s.report.rays
    );
    // Measured: per-surface relative RMS 6.1e-3; per dense element (the hierarchical
    // solution averaged over each dense element) RMS 1.3e-2, largest 1.44 (a piece along
    // a block's footprint), mean -0.1e-2, 8,178 leaves. Before the hierarchy refined
    // contacts and iterated its final gather: 1.4e-2, 5.0e-2, 0.37 and +0.4e-2. What is
    // left is mostly the dense area k = 2 reference's own error (1.2 % RMS at 2,046
    // elements) and the BF tolerance. The bounds leave 2x margin for the visibility
    // sampling's variation between refinements.
    assert!(rms < 0.012, "per-surface relative RMS {rms:e}");
    assert!(c.rms < 0.026, "per-element relative RMS {:e}", c.rms);
    assert!(c.bias.abs() < 0.01, "mean difference {:e}", c.bias);
    // Energy: emitted = absorbed + escaped to the solve tolerance; the box is open at the
    // front, so much of the power escapes.
    let b = s.report.balance;
    assert!(b.relative_error() < 1e-5, "{b:?}");
    assert!(b.escaped[0] > 0.0);
}

#[test]
fn clustering_makes_linking_about_linear_in_the_surfaces() {
    // Without clusters every pair of facing input surfaces needs a link: links would grow
    // like the square of the surfaces (exponent 2). From 2 x 1 to 4 x 4 furnished rooms the
    // surfaces grow 7.8x; measured with clusters, the links grow 10.1x: exponent 1.13.
    // Bound: 1.4, well below quadratic.
    let links = |rooms_x, rooms_z| {
        let file = radiosity::scene::building(&radiosity::scene::BuildingParams {
            floors: 1,
            rooms_x,
            rooms_z,
            max_patch_area: 4.0,
            ..Default::default()
        });
        let scene = file.scene;
        let s = solve(&scene, file.settings.max_patch_area, 0.5, 1.0);
        eprintln!(
            "{rooms_x} x {rooms_z} rooms: {} surfaces, {} leaves, {} clusters, {} links",
            scene.surfaces.len(),
            s.report.leaves,
            s.report.clusters,
            s.report.links
        );
        (scene.surfaces.len() as f64, s.report.links as f64)
    };
    let (s1, l1) = links(2, 1);
    let (s2, l2) = links(4, 4);
    let exponent = (l2 / l1).ln() / (s2 / s1).ln();
    assert!(s2 / s1 > 4.0, "{s1} -> {s2} surfaces");
    assert!(
        exponent < 1.4,
        "links grew {:.1}x for {:.1}x the surfaces: exponent {exponent:.2}",
        l2 / l1,
        s2 / s1
    );
}

#[test]
fn smaller_epsilon_refines_more() {
    let (scene, max_area) = cornell();
    let coarse = solve(&scene, max_area, 0.5, 250.0);
    let fine = solve(&scene, max_area, 0.1, 250.0);
    assert!(coarse.report.leaves > scene.surfaces.len());
    assert!(fine.report.leaves > coarse.report.leaves);
    assert!(fine.report.links > coarse.report.links);
    assert_eq!(fine.mesh.len(), fine.report.leaves);
    assert_eq!(fine.radiosity.len(), fine.report.leaves);
    // The leaves tile every surface but the pieces buried under the blocks, which contact
    // refinement drops: no more than each surface, and with the buried area, all of them.
    let mut total = 0.0;
    for (i, s) in scene.surfaces.iter().enumerate() {
        let range = fine.mesh.surface_elements[i].clone();
        let area: f64 = range.map(|e| fine.mesh.elements[e as usize].area).sum();
        let want = radiosity::geometry::polygon_area(&s.vertices);
        assert!(area <= want * (1.0 + 1e-9), "surface {i}: {area} vs {want}");
        total += want - area;
    }
    let buried = fine.report.buried_area;
    assert!(buried > 0.0);
    assert!(
        (total - buried).abs() < 1e-9 * buried,
        "{total} vs {buried}"
    );
}

#[test]
fn deterministic() {
    let (scene, max_area) = cornell();
    let a = solve(&scene, max_area, 0.1, 250.0);
    let b = solve(&scene, max_area, 0.1, 250.0);
    assert_eq!(a.radiosity, b.radiosity);
    assert_eq!(a.mesh.vertices, b.mesh.vertices);
    assert_eq!(a.report.links, b.report.links);
}

#[test]
fn refuses_bad_settings() {
    let (scene, max_area) = cornell();
    let bvh = occluder_bvh(&scene);
    for (epsilon, min_area, tolerance) in [
        (0.0, 1.0, 1e-6),
        (f64::NAN, 1.0, 1e-6),
        (0.1, 0.0, 1e-6),
        (0.1, -1.0, 1e-6),
        (0.1, 1.0, 0.0),
        (0.1, 1.0, 1.0),
    ] {
        let settings = HierarchicalSettings {
            epsilon,
            min_area,
            tolerance,
            max_memory_bytes: None,
            final_gather: true,
            gather_points: radiosity::solve::GATHER_POINTS_DEFAULT,
        };
        assert!(solve_hierarchical(&scene, max_area, &bvh, &settings, &NoProgress).is_err());
    }
}

#[test]
fn refuses_to_outgrow_its_memory_limit() {
    // The Cornell box at epsilon 0.01 holds about 340,000 links (over 10 MiB); with a 4 MiB
    // limit refinement must stop with the error that says what to change, not allocate on.
    let (scene, max_area) = cornell();
    let bvh = occluder_bvh(&scene);
    let settings = HierarchicalSettings {
        epsilon: 0.01,
        min_area: 125.0,
        tolerance: DEFAULT_HIERARCHICAL_TOLERANCE,
        max_memory_bytes: Some(4 << 20),
        final_gather: true,
        gather_points: radiosity::solve::GATHER_POINTS_DEFAULT,
    };
    let err = solve_hierarchical(&scene, max_area, &bvh, &settings, &NoProgress).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("larger epsilon or minimum area"), "{text}");
    assert!(
        matches!(
            err,
            radiosity::solve::SolveError::HierarchicalTooBig { limit_mib: 4, .. }
        ),
        "{err:?}"
    );
}

/// The Cornell box meshed at `max_area`, solved densely with exact (contour) form factors
/// and 4 x 4 by 4 x 4 point pairs for visibility (on the 2,046-element mesh this is within
/// 0.23 % RMS of the same solve with 8 x 8, BENCHMARKS.md), and by hierarchical radiosity
/// on the same MAX_PATCH_AREA (so that its leaves nest with the dense elements): the
/// per-element comparison.
fn against_exact_dense(
    max_area: f64,
    settings: &[HierarchicalSettings],
) -> Vec<radiosity::compare::Comparison> {
    // The dense solve on the mesh refined along contacts as the hierarchy refines its
    // leaves (`refine_contacts_as_quadtrees`: the pieces still straddling a block's foot at
    // the quadtrees' last level kept whole, as the hierarchy keeps its leaves, not cut
    // along the foot as `refine_contacts` cuts them), so the two match piece for piece.
    // Against the cut mesh (2,678 elements) the hierarchy's leaves along the feet hold
    // the mean of a lit and a buried part where the dense pieces hold the lit part's:
    // RMS 1.25 % and largest 191 % without the gather, 1.51 % and 193 % at the defaults.
    let prepared = prepared_cornell(max_area, None);
    let grid = radiosity::mesh::mesh_scene(&prepared.scene, max_area).unwrap();
    let (quadtrees, _) = radiosity::mesh::refine_contacts_as_quadtrees(
        &grid,
        &prepared.scene,
        &occluder_bvh(&prepared.scene),
    );
    let mut prepared = prepared.with_mesh(quadtrees).unwrap();
    prepared.method = radiosity::form_factor::FormFactorMethod::Contour { steps: 4 };
    let dense = dense_gauss_seidel(&prepared);
    let emission = prepared.light.emission();
    settings
        .iter()
        .map(|settings| {
            let t = std::time::Instant::now();
            let s = solve_with(&prepared.scene, prepared.settings.max_patch_area, settings);
            let elapsed = t.elapsed();
            let c = compare(
                &prepared.mesh,
                &dense.radiosity,
                emission,
                &s.mesh,
                &s.radiosity,
            )
            .unwrap();
            eprintln!(
                "cornell at {max_area} ({} elements), {settings:?}: {elapsed:?}, {} leaves, {} links; {c:?}",
                prepared.mesh.len(),
                s.report.leaves,
                s.report.links
            );
            c
        })
        .collect()
}

#[test]
fn cornell_box_element_by_element_against_an_exact_dense_solve() {
    // The hierarchy itself, without the final gather (held with it by the next test), on
    // the contact-refined mesh (2,484 elements; the hierarchy refines its leaves along the
    // blocks' footprints the same way); leaves down to a quarter of an element. Measured:
    // RMS 0.63 %, mean -0.18 %, largest 24.8 % (a piece 1/64 of an element along a
    // footprint, where the two solves' sixteen visibility samples differ most). Before the
    // hierarchy refined contacts: 2.4 % RMS against this mesh (0.66 % against the plain
    // grid). The bound is the target of issue #4 (1 % RMS; 1.6x the measured value, for
    // the visibility samples' variation between refinements); the mean bound is 2x the
    // measured one, the largest 1.4x. The largest difference was 29 % (at 1,638
    // elements, against contour k = 8) when pairs that sixteen sample pairs called hidden
    // were dropped instead of refined (a footprint element lost the light its uncovered
    // part sees).
    let [c, coarse] = against_exact_dense(
        1000.0,
        &[settings(3e-4, 250.0, false), settings(0.05, 250.0, false)],
    )[..] else {
        unreachable!()
    };
    // 2,590 elements since a piece whose probe points are all buried while a block's foot
    // crosses it (a rim outside the foot) is refined as a straddling one, by the hierarchy
    // and this mesh alike (2,500 before; 2,484 before the contact probes decided alike at
    // any scale, issue #16): the figures above were measured at 2,484; at 2,590 (review of
    // #11) RMS 0.50 %, largest 34 %, mean -0.03 % here, 0.98 %, 45 % and +0.05 % at the
    // defaults below; coarse 8.4 %, 88 %, -0.44 %.
    assert_eq!(c.elements, 2590);
    assert!(c.rms < 0.01, "{c:?}");
    assert!(c.bias.abs() < 0.004, "{c:?}");
    // The largest: 1.4x the 34 % measured at 2,590 elements (24.8 % at 2,484).
    assert!(c.max < 0.48, "{c:?}");
    // The CLI's default epsilon, 0.05: measured RMS 8.4 %, largest 87 %, mean -0.86 %
    // (8.8 %, 89 % and -0.15 % on the plain grid before contacts were refined). Before a
    // cluster's oracle counted the directions its members see the other node from,
    // 12.8 %, 177 % and -1.6 % (a triangle of the red wall at 15 % of its radiosity); the
    // RMS and largest bounds (1.3x, 1.4x) are between the two, the mean's 1.4x the
    // measured one.
    assert!(coarse.rms < 0.11, "{coarse:?}");
    assert!(coarse.max < 1.2, "{coarse:?}");
    assert!(coarse.bias.abs() < 0.012, "{coarse:?}");
}

#[test]
fn default_settings_within_two_percent_of_an_exact_dense_solve() {
    // Issue #11: hierarchical radiosity at its defaults (epsilon 0.05, minimum area
    // MAX_PATCH_AREA / 16, the final gather iterated to the tolerance), as `--solver auto`
    // runs it above 20,000 elements, within 2 % RMS element by element of the exact dense
    // solve on the contact-refined mesh, here at 2,484 elements. Measured (BENCHMARKS.md):
    // RMS 1.20 %, largest 41.9 %, mean +0.21 %; before the hierarchy refined contacts
    // 2.94 %, 159 % and -0.03 % (1.58 % RMS against the plain grid). The largest
    // differences are at pieces 1/64 of an element along the blocks' footprints, where the
    // two solves' sixteen visibility samples differ. Bounds: the 2 % (1.7x the
    // measured RMS, for the visibility samples' variation between refinements); the
    // largest difference 0.6, 1.4x the measured one and well below the 1.59 before
    // contacts were refined; the mean 1 %, 5x the measured one.
    let max_area = 1000.0;
    let [c] = against_exact_dense(max_area, &[HierarchicalSettings::defaults_for(max_area)])[..]
    else {
        unreachable!()
    };
    // 2,590 elements since a piece whose probe points are all buried while a block's foot
    // crosses it (a rim outside the foot) is refined as a straddling one, by the hierarchy
    // and this mesh alike (2,500 before; 2,484 before the contact probes decided alike at
    // any scale, issue #16): the figures above were measured at 2,484; at 2,590 (review of
    // #11) RMS 0.50 %, largest 34 %, mean -0.03 % here, 0.98 %, 45 % and +0.05 % at the
    // defaults below; coarse 8.4 %, 88 %, -0.44 %.
    assert_eq!(c.elements, 2590);
    assert!(c.rms < 0.02, "{c:?}");
    assert!(c.max < 0.6, "{c:?}");
    assert!(c.bias.abs() < 0.01, "{c:?}");
}

/// True when `x` lies in the convex polygon `poly` (normal `n`), up to `tol` outside.
fn inside(poly: &[glam::DVec3], n: glam::DVec3, x: glam::DVec3, tol: f64) -> bool {
    (0..poly.len()).all(|i| {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        (b - a).cross(x - a).dot(n) >= -tol * (b - a).length()
    })
}

#[test]
fn leaves_nest_with_the_mesh_elements() {
    // Every leaf on a quadrilateral surface lies within one element of the mesh made at the
    // solve's MAX_PATCH_AREA, or is the union of whole elements: the hierarchy splits along
    // the mesh's grid lines. (The Cornell box at 1000 mm^2: 18 x 18 and 17 x 18 grids and
    // the like, none a power of two, so bisection alone would not nest.)
    let scene = cornell_box().scene;
    let mesh = radiosity::mesh::mesh_scene(&scene, 1000.0).unwrap();
    // Without the final gather, which splits every leaf larger than an element down to
    // elements (no unions would be left to check).
    let s = solve_with(&scene, 1000.0, &settings(0.03, 250.0, false));
    let corners = |m: &radiosity::mesh::Mesh, e: usize| -> Vec<glam::DVec3> {
        m.corner_positions(e).collect()
    };
    let tol = 1e-6;
    let (mut within, mut unions) = (0, 0);
    for (surface, x) in scene.surfaces.iter().enumerate() {
        if x.vertices.len() != 4 {
            continue;
        }
        let elements: Vec<usize> = mesh.surface_elements[surface]
            .clone()
            .map(|e| e as usize)
            .collect();
        let leaves: Vec<usize> = s.mesh.surface_elements[surface]
            .clone()
            .map(|e| e as usize)
            .collect();
        for &l in &leaves {
            let leaf = &s.mesh.elements[l];
            let lp = corners(&s.mesh, l);
            // An element that holds the leaf's centroid and all its corners.
            let host = elements.iter().copied().find(|&e| {
                let ep = corners(&mesh, e);
                inside(&ep, leaf.normal, leaf.centroid, tol)
                    && lp.iter().all(|&c| inside(&ep, leaf.normal, c, tol))
            });
            if host.is_some() {
                within += 1;
            } else {
                // The elements whose centroids it holds lie inside it and fill it.
                let held: Vec<usize> = elements
                    .iter()
                    .copied()
                    .filter(|&e| inside(&lp, leaf.normal, mesh.elements[e].centroid, -tol))
                    .collect();
                let area: f64 = held.iter().map(|&e| mesh.elements[e].area).sum();
                for &e in &held {
                    let ep = corners(&mesh, e);
                    assert!(ep.iter().all(|&c| inside(&lp, leaf.normal, c, tol)));
                }
                assert!(
                    (area - leaf.area).abs() < 1e-9 * leaf.area,
                    "{}: leaf {l}",
                    x.name
                );
                unions += 1;
            }
        }
    }
    eprintln!("{within} leaves within an element, {unions} unions of elements");
    assert!(within > 0 && unions > 0);
}

/// A regular `n`-gon of radius 1 on the floor, lit by a square above it.
fn polygon_under_a_light(n: usize) -> Scene {
    use glam::dvec3;
    use radiosity::scene::Surface;
    let polygon = (0..n)
        .map(|i| {
            let a = -std::f64::consts::TAU * i as f64 / n as f64;
            dvec3(a.cos(), 0.0, a.sin())
        })
        .collect();
    let light = vec![
        dvec3(-0.2, 1.0, -0.2),
        dvec3(0.2, 1.0, -0.2),
        dvec3(0.2, 1.0, 0.2),
        dvec3(-0.2, 1.0, 0.2),
    ];
    let surface = |name: &str, vertices, e: f64| Surface {
        name: name.into(),
        emission: Light([e; 3]),
        reflectance: Light([0.5; 3]),
        vertices,
        photometry: Default::default(),
    };
    Scene {
        surfaces: vec![
            surface("floor", polygon, 0.0),
            surface("light", light, 10.0),
        ],
        camera: None,
        lights: Vec::new(),
    }
}

#[test]
fn memory_estimate_counts_the_refinement_frontier_of_a_many_sided_polygon() {
    // A 2,000-gon becomes 2,000 coplanar fan triangles: their clusters are all too close
    // for cluster links, so refinement expands them pair by pair (at 5,000 sides, 8.7
    // million pairs at once, 573 MB peak where the nodes and links held 10 MiB). The
    // nodes alone are 2 x 2,000 x about 300 bytes, 1.2 MB: a 16 MiB limit lets them
    // through, and must stop the frontier (about 0.35 n^2 = 1.4 million pairs of at least
    // 48 bytes, 67 MB) before it is allocated.
    let scene = polygon_under_a_light(2_000);
    let bvh = occluder_bvh(&scene);
    let settings = HierarchicalSettings {
        max_memory_bytes: Some(16 << 20),
        ..settings(0.05, 0.05 / 16.0, false)
    };
    let err = solve_hierarchical(&scene, 0.05, &bvh, &settings, &NoProgress).unwrap_err();
    assert!(
        matches!(
            err,
            radiosity::solve::SolveError::HierarchicalTooBig { limit_mib: 16, .. }
        ),
        "{err:?}"
    );
}

/// A progress sink that records each stage's start (with its total), its advances and its
/// end, in order.
#[derive(Default)]
struct Recorder {
    events: std::sync::Mutex<Vec<(radiosity::progress::Stage, &'static str, u64)>>,
    current: std::sync::Mutex<Option<radiosity::progress::Stage>>,
}

impl radiosity::progress::Progress for Recorder {
    fn start(&self, stage: radiosity::progress::Stage, total: u64) {
        *self.current.lock().unwrap() = Some(stage);
        self.events.lock().unwrap().push((stage, "start", total));
    }
    fn advance(&self, done: u64) {
        let stage = self
            .current
            .lock()
            .unwrap()
            .expect("advance inside a stage");
        self.events.lock().unwrap().push((stage, "advance", done));
    }
    fn finish(&self, stage: radiosity::progress::Stage, _elapsed: std::time::Duration) {
        assert_eq!(
            *self.current.lock().unwrap(),
            Some(stage),
            "stages do not nest"
        );
        *self.current.lock().unwrap() = None;
        self.events.lock().unwrap().push((stage, "finish", 0));
    }
}

#[test]
fn the_final_gather_is_a_stage_that_counts_its_points() {
    // QA of issue #16: the final gather ran inside the solve stage, whose progress lines
    // counted refinement rounds that no longer changed, for a minute on large scenes. It is
    // now its own stage after the solve, announced with its number of gather points and
    // advanced once per point, so a progress line can give how far it is and the time left.
    use radiosity::progress::Stage;
    let (scene, max_area) = cornell();
    let bvh = occluder_bvh(&scene);
    let recorder = Recorder::default();
    let s = solve_hierarchical(
        &scene,
        max_area,
        &bvh,
        &HierarchicalSettings::defaults_for(max_area),
        &recorder,
    )
    .unwrap();
    let events = recorder.events.into_inner().unwrap();
    let starts: Vec<_> = events.iter().filter(|e| e.1 == "start").collect();
    assert_eq!(
        starts.iter().map(|e| e.0).collect::<Vec<_>>(),
        [Stage::Solve, Stage::Gather],
        "{starts:?}"
    );
    let points = s.report.gather_points as u64;
    assert!(points > 0);
    assert_eq!(
        starts[1].2, points,
        "the stage's total is its gather points"
    );
    let advanced: u64 = events
        .iter()
        .filter(|e| e.0 == Stage::Gather && e.1 == "advance")
        .map(|e| e.2)
        .sum();
    assert_eq!(advanced, points, "each point counted once");

    // Without the final gather there is no such stage.
    let recorder = Recorder::default();
    solve_hierarchical(
        &scene,
        max_area,
        &bvh,
        &HierarchicalSettings {
            final_gather: false,
            ..HierarchicalSettings::defaults_for(max_area)
        },
        &recorder,
    )
    .unwrap();
    let events = recorder.events.into_inner().unwrap();
    assert!(events.iter().all(|e| e.0 != Stage::Gather), "{events:?}");
}

#[test]
fn light_that_grows_is_refused_with_its_reason_and_a_converging_furnace_is_not() {
    // QA of issue #16: a closed 2 m box, every face emitting 1 and reflecting 0.97, at
    // MAX_PATCH_AREA 0.25 and the defaults: the links' estimated form factors sum a little
    // above 1 (1.5 % too bright at rho 0.9), and at 0.97 the light grew for 234 sweeps
    // until "diverged ... (rows summing far above 1?)". Now growth is named within
    // RISING_SWEEPS (20) sweeps. At rho 0.9 the same box converges (B = 10 in the closed
    // form; the links' 1.5 % is an accuracy of their own, left to the bound below).
    let boxed = |rho: f64| {
        let mut s = unit_cube([1.0; 3], [rho; 3]);
        for surface in &mut s.surfaces {
            for v in &mut surface.vertices {
                *v *= 2.0;
            }
        }
        s
    };
    let bvh = occluder_bvh(&boxed(0.97));
    let err = solve_hierarchical(
        &boxed(0.97),
        0.25,
        &bvh,
        &HierarchicalSettings::defaults_for(0.25),
        &NoProgress,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            radiosity::solve::SolveError::HierarchicalGrowing { rising: 20, .. }
        ),
        "{err:?}"
    );
    let s = solve_with(&boxed(0.9), 0.25, &HierarchicalSettings::defaults_for(0.25));
    let per = per_surface(&s.mesh, &s.radiosity);
    let mean = per.iter().map(|b| b[0]).sum::<f64>() / per.len() as f64;
    // 3 % bound: twice the links' 1.5 % measured at this size.
    assert!((mean / 10.0 - 1.0).abs() < 0.03, "{mean}");
}
