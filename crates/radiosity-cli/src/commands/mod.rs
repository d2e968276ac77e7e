//! One file per command, each with its `run` (`generate building`: `generate::building`),
//! and what several of them share: solving a prepared scene, shading and rendering it.

pub mod bench;
pub mod bench_time;
pub mod check;
pub mod compare;
pub mod export;
pub mod formfactors;
pub mod generate;
pub mod illuminance;
pub mod pathtrace;
pub mod render;
pub mod solve;
pub mod validate;
pub mod view;

use std::ops::ControlFlow;
use std::path::Path;

use anyhow::Result;
use image::RgbImage;
use radiosity::mesh::{AdaptSettings, Mesh};
use radiosity::pipeline::{
    self as pipeline, FormFactorStats, FormFactors, Prepared, Solution, SolutionReport,
    SolveRequest,
};
use radiosity::progress::{run_stage, Stage};
use radiosity::render::tonemap::{lit_radiosity_top_mean, AUTO_EXPOSURE_TOP_AREA};
use radiosity::render::{Camera, RenderSettings, Renderer};
use radiosity::shade::{self, Exposure};
use radiosity::solve::{Observer, Solver, Step};

use crate::progress_bar::Reporter;
use crate::report;

/// [`solve_scene`] as the flags say, without an observer: adaptive subdivision where
/// `options` ask for it (or by default), the form factors from `--form-factors` or computed.
pub fn solve_as_asked(
    prepared: &Prepared,
    solver: Solver,
    options: &crate::args::SolveOptions,
    reporter: &Reporter,
) -> Result<Solution> {
    let (solution, _) = solve_scene(
        prepared,
        solver,
        crate::setup::adapt(options, prepared, &solver)?,
        options.form_factors.as_deref(),
        &mut |_| ControlFlow::Continue(()),
        reporter,
    )?;
    Ok(solution)
}

/// Solves with `solver`: the dense solvers on the form factors (read from `file` or
/// computed, then dropped), the others from the scene. Returns the form-factor statistics
/// when they were computed.
pub fn solve_scene(
    prepared: &Prepared,
    solver: Solver,
    adapt: Option<AdaptSettings>,
    file: Option<&Path>,
    observer: &mut Observer,
    reporter: &Reporter,
) -> Result<(Solution, Option<FormFactorStats>)> {
    let form_factors = match file {
        Some(path) => FormFactors::File(path),
        None => FormFactors::Compute,
    };
    if solver.needs_matrix() {
        match form_factors {
            FormFactors::File(path) => {
                reporter.note(&format!("reading form factors from {}", path.display()))
            }
            _ => reporter.note(&format!(
                "form factors by {}; occlusion: {}",
                prepared.method(),
                prepared.method().occlusion()
            )),
        }
    }
    // A dense solve of one mesh computes its form factors here, so that what they found
    // (rays, row sums, the rows that see nothing) is said before the solve's line, not after
    // it (QA of issue #16: "solved ..." came first). Adaptive subdivision makes its own.
    let computed = match (&form_factors, &adapt) {
        (FormFactors::Compute, None) if solver.needs_matrix() => {
            let (f, stats) = prepared.form_factors(reporter)?;
            report::form_factor_stats(prepared, &prepared.mesh, &stats, reporter);
            Some((f, Some(stats)))
        }
        // A matrix read from a file gets the same notes on its rows (QA of issue #16: the
        // rows that see nothing or sum above 1 went unsaid with --form-factors).
        (FormFactors::File(path), None) if solver.needs_matrix() => {
            let f = prepared.load_form_factors(path, reporter)?;
            report::row_sum_notes(
                prepared,
                &prepared.mesh,
                &f.row_sums(&prepared.areas()),
                reporter,
            );
            Some((f, None))
        }
        _ => None,
    };
    let request = SolveRequest {
        form_factors: match &computed {
            Some((f, _)) => FormFactors::Matrix(f),
            None => form_factors,
        },
        adapt,
        ..SolveRequest::new(solver)
    };
    // `--max-shots` caps progressive refinement: the run stops there with what it has shot
    // (and says how far it got) instead of failing; a NaN or divergence is still an error.
    let cap = match solver {
        Solver::Progressive(s) => Some(s),
        _ => None,
    };
    let mut capped = false;
    let mut capping = |step: &Step| {
        let flow = observer(step);
        if let (Some(s), Step::Shot(state)) = (cap, step) {
            if state.shot >= s.max_shots && state.unshot_fraction >= s.tolerance {
                capped = true;
                return ControlFlow::Break(());
            }
        }
        flow
    };
    let mut solution = pipeline::solve(prepared, &request, &mut capping, reporter)?;
    // The matrix is not kept past the solve (as the library's own computation does not).
    let stats_said = match computed {
        Some((f, stats)) => {
            drop(f);
            if stats.is_some() {
                solution.form_factors = stats;
            }
            true
        }
        None => false,
    };
    if let (true, Some(s), SolutionReport::Progressive(r)) = (capped, cap, &solution.report) {
        reporter.note(&shot_cap_note(s.max_shots, s.tolerance, r.unshot_fraction));
    }
    if let (Some(stats), false) = (&solution.form_factors, stats_said) {
        report::form_factor_stats(prepared, &solution.mesh, stats, reporter);
    }
    report::energy_note(&prepared.scene, &solution, prepared.method(), reporter);
    if let Some(warning) = report::light_lost(&prepared.scene, &solution) {
        // Printed even with --quiet: every picture of this solution is black. Once for the
        // same words (QA of issue #16: bench printed it once per run).
        static SAID: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);
        let mut said = SAID.lock().unwrap_or_else(|e| e.into_inner());
        if said.as_deref() != Some(warning.as_str()) {
            errln!("warning: {warning}");
            *said = Some(warning);
        }
    }
    let stats = solution.form_factors;
    Ok((solution, stats))
}

/// What a progressive run stopped by `--max-shots` says: how far it got against the
/// tolerance, and what its output holds.
pub fn shot_cap_note(max_shots: usize, tolerance: f64, unshot: f64) -> String {
    format!(
        "progressive refinement stopped at --max-shots {max_shots}: the unshot power is \
         {:.3} % of the emitted power, not yet below the tolerance {} %; the output holds \
         the light shot so far (the unshot part is left out, where --snapshots pictures \
         add it as the paper's ambient term for display, so they look brighter; \
         --max-shots or --tolerance takes it further)",
        100.0 * unshot,
        crate::report::significant(100.0 * tolerance, 4)
    )
}

/// Vertex radiosities (the shade stage), then the image with radiosities multiplied by
/// `exposure_scale` (the render stage).
pub fn shade_and_render(
    prepared: &Prepared,
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    camera: &Camera,
    settings: RenderSettings,
    exposure_scale: f64,
    reporter: &Reporter,
) -> Result<RgbImage, radiosity::render::NonFiniteImage> {
    let vertex_b = run_stage(reporter, Stage::Shade, 0, || {
        let mut vertex_b = shade::vertex_radiosity(mesh, element_b);
        shade::smooth_objects(&prepared.scene, mesh, &mut vertex_b);
        vertex_b
    });
    let settings = RenderSettings {
        exposure_scale,
        ..settings
    };
    let renderer = Renderer::for_settings(mesh, &prepared.scene, &settings);
    radiosity::render::try_render(&renderer, camera, element_b, &vertex_b, &settings, reporter)
}

/// Vertex radiosities (the shade stage), then the linear image (the render stage): each
/// pixel the mean of its samples' radiosity, no exposure, clamping or gamma. `None` for a
/// wireframe, which has no light to give.
pub fn shade_and_render_linear(
    prepared: &Prepared,
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    camera: &Camera,
    settings: RenderSettings,
    reporter: &Reporter,
) -> Result<Option<Vec<[f64; 3]>>, radiosity::render::NonFiniteImage> {
    let vertex_b = run_stage(reporter, Stage::Shade, 0, || {
        let mut vertex_b = shade::vertex_radiosity(mesh, element_b);
        shade::smooth_objects(&prepared.scene, mesh, &mut vertex_b);
        vertex_b
    });
    let renderer = Renderer::for_settings(mesh, &prepared.scene, &settings);
    radiosity::render::render_linear(&renderer, camera, element_b, &vertex_b, &settings, reporter)
}

/// What `render` says about the exposure `scale` it used: for `auto`, the radiosity it
/// made white and how bright the brightest non-emitting element is against it.
pub fn exposure_note(
    prepared: &Prepared,
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    exposure: Exposure,
    scale: f64,
) -> String {
    if let Exposure::Fixed(_) = exposure {
        return format!("exposure scale {scale}");
    }
    let brightest = lit_radiosity_top_mean(&prepared.scene, mesh, element_b, 0.0).unwrap_or(0.0);
    let white = lit_radiosity_top_mean(&prepared.scene, mesh, element_b, AUTO_EXPOSURE_TOP_AREA);
    if !white.is_some_and(|w| w > 0.0 && (1.0 / w).is_finite()) {
        // Exposure::scale's fallback (QA of issue #16: "auto 1.0000 is the mean" for a scene
        // with no light, where 1 is no mean at all).
        return format!(
            "exposure scale {} (auto: nothing is lit, the brightest {} % of the non-emitting \
             area has radiosity 0, so there is nothing to expose for; scale 1 is the fallback)",
            crate::report::significant(scale, 4),
            100.0 * AUTO_EXPOSURE_TOP_AREA,
        );
    }
    let any_unlit = mesh.elements.iter().any(|el| {
        prepared
            .scene
            .surfaces
            .get(el.surface as usize)
            .is_some_and(|s| s.emission.max_band() <= 0.0)
    });
    if !any_unlit {
        // The rule's fallback, said as such (QA of issue #16: a lone emitting triangle was
        // given "the brightest non-emitting element").
        return format!(
            "exposure scale {} (auto: every surface emits, so the mean radiosity of the \
             brightest {} % of the whole area, {}, is white)",
            crate::report::significant(scale, 4),
            100.0 * AUTO_EXPOSURE_TOP_AREA,
            crate::report::significant(1.0 / scale, 5),
        );
    }
    format!(
        // Significant figures, not four decimals (QA of issue #16: a dim scene's white
        // read 0.0000, a bright one's 31 digits).
        "exposure scale {} (auto: {}, the mean radiosity of the brightest {} % of \
         the non-emitting area, is white; the brightest non-emitting element is {}, \
         {:.2} x white)",
        crate::report::significant(scale, 4),
        crate::report::significant(1.0 / scale, 5),
        100.0 * AUTO_EXPOSURE_TOP_AREA,
        crate::report::significant(brightest, 5),
        brightest * scale,
    )
}
