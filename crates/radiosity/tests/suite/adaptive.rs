//! Adaptive subdivision ([`radiosity::mesh::mark_steps`] between dense solves) against a
//! closed form: a 4 x 4 floor lit by a small square light 0.3 above one corner. The floor
//! sees only the light (which reflects nothing), so its exact radiosity at a point x is
//! B(x) = rho E F(x -> light), Lambert's point-to-polygon form factor: one bounce, no
//! solve needed.

use glam::{dvec3, DVec3};
use radiosity::form_factor::exact::point_to_polygon;
use radiosity::mesh::{AdaptSettings, MeshSettings};
use radiosity::pipeline::{self, Prepared, Solution, SolveRequest};
use radiosity::progress::NoProgress;
use radiosity::scene::{Rgb, Scene, Surface};
use radiosity::solve::{keep_going, DenseSolver, GaussSeidelSettings, Solver};

const RHO: f64 = 0.5;
const E: f64 = 10.0;

fn light() -> Vec<DVec3> {
    // Facing down (-y), counter-clockwise seen from below.
    vec![
        dvec3(0.4, 0.3, 0.4),
        dvec3(0.8, 0.3, 0.4),
        dvec3(0.8, 0.3, 0.8),
        dvec3(0.4, 0.3, 0.8),
    ]
}

fn scene() -> Scene {
    Scene {
        surfaces: vec![
            Surface {
                name: "floor".into(),
                emission: Rgb::BLACK,
                reflectance: Rgb([RHO; 3]),
                vertices: vec![
                    dvec3(0., 0., 0.),
                    dvec3(0., 0., 4.),
                    dvec3(4., 0., 4.),
                    dvec3(4., 0., 0.),
                ],
                photometry: Default::default(),
            },
            Surface {
                name: "light".into(),
                emission: Rgb([E; 3]),
                reflectance: Rgb::BLACK,
                vertices: light(),
                photometry: Default::default(),
            },
        ],
        camera: None,
        lights: Vec::new(),
    }
}

fn solve(adapt: Option<AdaptSettings>) -> Solution {
    let settings = MeshSettings {
        max_patch_area: 0.25,
        integral_steps: 2,
    };
    let prepared = Prepared::new(scene(), settings, &NoProgress).unwrap();
    let request = SolveRequest {
        adapt,
        ..SolveRequest::new(Solver::Dense(DenseSolver::GaussSeidel(
            GaussSeidelSettings {
                tolerance: 1e-12,
                max_iterations: 1000,
            },
        )))
    };
    pipeline::solve(&prepared, &request, &mut keep_going, &NoProgress).unwrap()
}

/// The RMS over the floor of the piecewise-constant solution's difference from the exact
/// B(x), relative to the floor's mean exact radiosity: 8 x 8 points per element, weighted
/// by area.
fn floor_error(solution: &Solution) -> f64 {
    let mesh = &solution.mesh;
    let (mut sum2, mut sum, mut area) = (0.0, 0.0, 0.0);
    let mut points = Vec::new();
    for e in mesh.surface_elements[0].clone() {
        let e = e as usize;
        let b = solution.radiosity.as_slice()[e].0[0];
        points.clear();
        mesh.integration_points(e, 8, &mut points);
        for &(p, w) in &points {
            let exact = RHO * E * point_to_polygon(p, DVec3::Y, &light());
            sum2 += w * (b - exact).powi(2);
            sum += w * exact;
            area += w;
        }
    }
    (sum2 / area).sqrt() / (sum / area)
}

#[test]
fn adaptive_subdivision_follows_the_light_and_halves_the_error_for_the_same_elements() {
    let coarse = solve(None);
    let adapt = AdaptSettings {
        contrast: 0.3,
        floor: 0.01,
        min_area: 0.25 / 64.0,
        max_elements: 4 * coarse.mesh.len(),
        rounds: 3,
        max_new_pairs: u64::MAX,
    };
    let adapted = solve(Some(adapt));
    let report = adapted.adapt.as_ref().unwrap();
    assert!(!report.rounds.is_empty(), "{report:?}");
    let n = adapted.mesh.len();
    assert!(n <= adapt.max_elements, "{n}");
    // The floor's area is kept: splitting only quarters elements.
    let floor_area: f64 = adapted.mesh.surface_elements[0]
        .clone()
        .map(|e| adapted.mesh.elements[e as usize].area)
        .sum();
    assert!((floor_area - 16.0).abs() < 1e-9, "{floor_area}");
    // A uniform mesh of at least as many elements, for a fair comparison.
    let uniform_area = 16.0 / (n as f64 - 1.0);
    let uniform = {
        let settings = MeshSettings {
            max_patch_area: uniform_area,
            integral_steps: 2,
        };
        let prepared = Prepared::new(scene(), settings, &NoProgress).unwrap();
        let request = SolveRequest::new(Solver::LU);
        pipeline::solve(&prepared, &request, &mut keep_going, &NoProgress).unwrap()
    };
    assert!(uniform.mesh.len() >= n, "{} < {n}", uniform.mesh.len());
    let (e_coarse, e_adapted, e_uniform) = (
        floor_error(&coarse),
        floor_error(&adapted),
        floor_error(&uniform),
    );
    // The light is 0.3 above a 4 x 4 floor: B falls from its peak to a tenth within about
    // 0.6, so the coarse grid of 0.5 x 0.5 elements is far off near the light and nearly
    // right elsewhere. Refining where it steps must beat refining everywhere with as many
    // elements (by a clear margin, 0.7, far outside the rounding of either), and more than
    // halve the coarse error.
    assert!(
        e_adapted < 0.7 * e_uniform && e_adapted < 0.5 * e_coarse,
        "coarse {e_coarse:.4}, adapted {e_adapted:.4} ({n} elements), uniform {e_uniform:.4} ({} elements)",
        uniform.mesh.len()
    );
    // The energy account still closes: what the floor absorbs plus what escapes (the
    // scene is open) is what the light emits.
    assert!(
        adapted.balance.relative_error().abs() < 1e-6,
        "{:?}",
        adapted.balance
    );
}
