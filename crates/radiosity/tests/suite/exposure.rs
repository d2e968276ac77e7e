//! Automatic exposure that does not depend on the mesh (issue #11): the built-in Cornell
//! box meshed at two sizes and solved by hierarchical radiosity gets nearly one exposure
//! scale, where the paper's brightest-element normalisation moves with the mesh.

use radiosity::pipeline::{self, SolveRequest};
use radiosity::progress::NoProgress;
use radiosity::render::tonemap::{lit_radiosity_top_mean, Exposure};
use radiosity::solve::{keep_going, HierarchicalSettings, Solver};

use crate::fixtures::{dense_gauss_seidel, prepared_cornell};

/// The relative spread of `values`: largest / smallest - 1.
fn spread(values: &[f64]) -> f64 {
    let (lo, hi) = values.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    hi / lo - 1.0
}

// The Cornell box at MAX_PATCH_AREA 4000 mm^2 (535 elements) and its own 1000 (2,046
// elements, 4 x finer), dense Gauss-Seidel, and hierarchical radiosity at the command
// line's defaults for 1000 (4,807 leaves). Measured (BENCHMARKS.md, "Automatic exposure"):
// the mean of the brightest 2 % of the lit area, which `auto` makes white, is 1.9595,
// 1.9674 and 1.9487, a spread of 0.96 %; the brightest element, the old `auto`, is 3.2569,
// 3.3862 and 3.4737, a spread of 6.7 %. The bound of 2 % is twice the measured spread (room
// for a change in the solvers' accuracy) and a third of the old statistic's, so the old
// `auto` fails it; the old statistic is held above 5 % so that the test keeps showing the
// difference it was written for.
#[test]
fn issue_11_auto_exposure_agrees_across_meshes_and_solvers() {
    let mut solutions = Vec::new();
    for max_area in [4000.0, 1000.0] {
        let prepared = prepared_cornell(max_area, None);
        let solution = dense_gauss_seidel(&prepared);
        solutions.push((
            format!("dense, MAX_PATCH_AREA {max_area}"),
            prepared,
            solution,
        ));
    }
    let prepared = prepared_cornell(1000.0, None);
    let request = SolveRequest::new(Solver::Hierarchical(HierarchicalSettings::defaults_for(
        1000.0,
    )));
    let hierarchical = pipeline::solve(&prepared, &request, &mut keep_going, &NoProgress).unwrap();
    solutions.push(("hierarchical, defaults".into(), prepared, hierarchical));

    let mut auto = Vec::new();
    let mut brightest = Vec::new();
    for (_, prepared, solution) in &solutions {
        let b = solution.element_rgb();
        auto.push(Exposure::Auto.scale(&prepared.scene, &solution.mesh, b));
        brightest.push(lit_radiosity_top_mean(&prepared.scene, &solution.mesh, b, 0.0).unwrap());
    }
    let report: Vec<String> = solutions
        .iter()
        .zip(auto.iter().zip(&brightest))
        .map(|((name, _, s), (a, m))| {
            format!(
                "{name} ({} elements): auto scale {a}, brightest {m}",
                s.mesh.len()
            )
        })
        .collect();
    let (new, old) = (spread(&auto), spread(&brightest));
    assert!(new < 0.02, "auto exposure spread {new}: {report:#?}");
    assert!(old > 0.05, "brightest-element spread {old}: {report:#?}");
}
