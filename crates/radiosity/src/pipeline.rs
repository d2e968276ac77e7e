//! The whole pipeline in a few calls, for the command line, benchmarks and tests:
//! scene -> mesh -> form factors (computed or read from a file) -> solve -> shade.
//!
//! Each stage reports through [`Progress`], so its time and progress reach whoever
//! listens (a progress bar, a window, a distributed runner).

use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

use crate::form_factor::{
    self, mesh_fingerprint, read_form_factors, write_form_factors, FormFactorContext,
    FormFactorFileError, FormFactorMatrix, FormFactorMethod, OutOfMemory, RayCounter, Reciprocity,
    RowSums,
};
use crate::mesh::{mesh_scene, Mesh, MeshError};
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::Scene;
use crate::solve::{
    self, energy_balance, EnergyBalance, HierarchicalReport, ProgressiveReport, ProgressiveState,
    Radiosity, SolveError, SolveReport, Solver,
};
use crate::visibility::PolygonBvh;

/// Anything that stops the pipeline.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// Meshing failed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A dense matrix would not fit in memory.
    #[error(transparent)]
    OutOfMemory(#[from] OutOfMemory),
    /// A form-factor file was refused.
    #[error(transparent)]
    FormFactorFile(#[from] FormFactorFileError),
    /// The solve failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The pair methods' integration points (`steps` x `steps` per element) would be more
    /// than [`MAX_INTEGRATION_POINTS`].
    #[error(
        "INTEGRAL_STEPS {steps} on {elements} elements means {points:.2e} integration points \
         (more than {limit:.0e})"
    )]
    TooManyIntegrationPoints {
        /// Points along each axis of each element (1 for the methods that take none).
        steps: u32,
        /// The element count.
        elements: usize,
        /// elements x steps^2.
        points: f64,
        /// [`MAX_INTEGRATION_POINTS`].
        limit: f64,
    },
    /// A setting cannot be honoured.
    #[error("{0}")]
    Settings(String),
    /// Writing an output failed.
    #[error("cannot write {path}")]
    Write {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
}

/// The most integration points (elements x steps^2) [`Prepared::check_memory`] lets the pair
/// methods (area, contour, analytic) hold: 32 bytes each, 1.6 GB at the limit.
pub const MAX_INTEGRATION_POINTS: f64 = 5e7;

/// The most elements `choose_dense` will give the dense solve: its form factors cost
/// O(n^2) (about 5 s at 10,000 elements on two cores, BENCHMARKS.md), so beyond this the
/// hierarchical solver (no matrix) is chosen even when the matrix would fit.
pub const AUTO_DENSE_MAX_ELEMENTS: usize = 20_000;

/// The `auto` solver's decision for `n` elements and `available` bytes of memory: true for
/// the dense solve (Gauss-Seidel on the stored matrix), false for hierarchical radiosity;
/// with the reason, including the memory estimate, to tell the user.
pub fn choose_dense(n: usize, available: u64) -> (bool, String) {
    let matrix = 4.0 * (n as f64).powi(2) * 1.1;
    let mib = |b: f64| b / (1u64 << 20) as f64;
    let estimate = format!(
        "{n} elements; the dense form-factor matrix needs {:.0} MiB of the {:.0} MiB available",
        mib(matrix),
        mib(available as f64)
    );
    if n > AUTO_DENSE_MAX_ELEMENTS {
        (false, format!("{estimate}; more than {AUTO_DENSE_MAX_ELEMENTS} elements: hierarchical radiosity with clustering (no matrix; links, memory about linear in the elements)"))
    } else if matrix > 0.5 * available as f64 {
        (
            false,
            format!(
                "{estimate}, more than half of it: hierarchical radiosity with clustering (no matrix; links, memory about linear in the elements)"
            ),
        )
    } else {
        (
            true,
            format!("{estimate}: Gauss-Seidel on the dense matrix"),
        )
    }
}

/// Settings from the command line that override the scene file's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    /// Replaces `MAX_PATCH_AREA`.
    pub max_patch_area: Option<f64>,
    /// Replaces `INTEGRAL_STEPS`.
    pub integral_steps: Option<u32>,
}

/// A meshed scene with its occluder BVH: everything form factors need.
pub struct Prepared {
    /// The scene, with overrides applied to its settings.
    pub scene: Scene,
    /// Its elements.
    pub mesh: Mesh,
    /// The input surfaces in a BVH, for occlusion.
    pub occluders: PolygonBvh,
    /// How form factors are computed (by default the area integral with the scene's
    /// `INTEGRAL_STEPS`).
    pub method: FormFactorMethod,
}

/// What computing form factors found, besides the matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FormFactorStats {
    /// Visibility segments tested against candidate occluders.
    pub rays: u64,
    /// Wall-clock seconds of the computation.
    pub seconds: f64,
    /// Row sums.
    pub row_sums: RowSums,
    /// Reciprocity errors (see `FormFactorMatrix::reciprocity`).
    pub reciprocity: Reciprocity,
}

/// A solved scene.
pub struct Solution {
    /// Element radiosities.
    pub radiosity: Radiosity,
    /// How the solve went.
    pub report: SolutionReport,
    /// Where the emitted power went. For a matrix solve, from B and the matrix
    /// ([`energy_balance`]); for progressive refinement, from the shots' bookkeeping, where
    /// the power still unshot is neither absorbed nor escaped (so the relative error is the
    /// unshot fraction).
    pub balance: EnergyBalance,
    /// The elements the radiosities belong to when they are not the prepared mesh's: the
    /// leaves of hierarchical radiosity. `None` for every other solver.
    pub mesh: Option<Mesh>,
}

/// How a solve went, by kind of solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolutionReport {
    /// LU or Gauss-Seidel on the form-factor matrix.
    Matrix(SolveReport),
    /// Progressive refinement.
    Progressive(ProgressiveReport),
    /// Hierarchical radiosity.
    Hierarchical(HierarchicalReport),
}

impl Prepared {
    /// Applies `overrides`, meshes the scene and builds the occluder BVH.
    pub fn new(
        mut scene: Scene,
        overrides: Overrides,
        progress: &dyn Progress,
    ) -> Result<Prepared, PipelineError> {
        if let Some(a) = overrides.max_patch_area {
            scene.settings.max_patch_area = a;
        }
        if let Some(k) = overrides.integral_steps {
            scene.settings.integral_steps = k;
        }
        let mesh = run_stage(progress, Stage::Mesh, 0, || {
            mesh_scene(&scene, scene.settings.max_patch_area)
        })?;
        let occluders = run_stage(progress, Stage::Bvh, 0, || {
            form_factor::occluder_bvh(&scene)
        });
        let method = FormFactorMethod::AreaIntegral {
            steps: scene.settings.integral_steps,
        };
        Ok(Prepared {
            scene,
            mesh,
            occluders,
            method,
        })
    }

    /// How form factors are computed.
    pub fn method(&self) -> FormFactorMethod {
        self.method
    }

    /// The fingerprint of the meshed geometry, as stored in form-factor files.
    pub fn fingerprint(&self) -> u64 {
        mesh_fingerprint(&self.mesh)
    }

    /// Element areas.
    pub fn areas(&self) -> Vec<f64> {
        self.mesh.elements.iter().map(|e| e.area).collect()
    }

    /// Refuses, before any work, settings whose form factors and solve would not fit in
    /// memory: the f32 matrix (4 n^2 bytes), plus the f64 LU matrix (8 n^2) for `Solver::Lu`,
    /// plus the integration points (32 k^2 bytes per element). Progressive refinement stores
    /// no matrix, so only the integration points are checked for it.
    pub fn check_memory(&self, solver: Option<Solver>) -> Result<(), PipelineError> {
        let n = self.mesh.len();
        let steps = match self.method {
            FormFactorMethod::AreaIntegral { steps }
            | FormFactorMethod::Contour { steps }
            | FormFactorMethod::Analytic { steps } => steps,
            _ => 1,
        };
        let points = n as f64 * steps as f64 * steps as f64;
        if points > MAX_INTEGRATION_POINTS {
            return Err(PipelineError::TooManyIntegrationPoints {
                steps,
                elements: n,
                points,
                limit: MAX_INTEGRATION_POINTS,
            });
        }
        let per_entry = match solver {
            // No matrix: O(n) vectors and one row.
            Some(Solver::Progressive { .. } | Solver::Hierarchical(_)) => return Ok(()),
            Some(Solver::Lu) => 12.0,
            _ => 4.0,
        };
        let what = if per_entry > 4.0 {
            "the form factors (f32) and the LU matrix (f64)"
        } else {
            "the form-factor matrix (f32)"
        };
        form_factor::check_dense_fits(what, n, per_entry, form_factor::available_memory_bytes())?;
        Ok(())
    }

    /// Computes the form-factor matrix.
    pub fn form_factors(
        &self,
        progress: &dyn Progress,
    ) -> Result<(FormFactorMatrix, FormFactorStats), PipelineError> {
        let ctx = FormFactorContext {
            mesh: &self.mesh,
            occluders: &self.occluders,
        };
        let rays = RayCounter::default();
        let start = Instant::now();
        let matrix = form_factor::compute_matrix(&ctx, self.method(), &rays, progress)?;
        let seconds = start.elapsed().as_secs_f64();
        let stats = FormFactorStats {
            rays: rays.get(),
            seconds,
            row_sums: matrix.row_sums(),
            reciprocity: matrix.reciprocity(&self.areas()),
        };
        Ok((matrix, stats))
    }

    /// Reads form factors from `path`, refusing a file made for another mesh or method.
    pub fn load_form_factors(
        &self,
        path: &Path,
        progress: &dyn Progress,
    ) -> Result<FormFactorMatrix, PipelineError> {
        Ok(run_stage(progress, Stage::FormFactors, 0, || {
            read_form_factors(path, self.fingerprint(), Some(self.method()))
        })?)
    }

    /// Writes form factors to `path` (atomically) with this mesh's fingerprint and method.
    pub fn save_form_factors(
        &self,
        path: &Path,
        matrix: &FormFactorMatrix,
        progress: &dyn Progress,
    ) -> Result<(), PipelineError> {
        run_stage(progress, Stage::Write, 0, || {
            write_form_factors(path, matrix, self.fingerprint(), &self.method().to_string())
        })
        .map_err(|source| PipelineError::Write {
            path: path.display().to_string(),
            source,
        })
    }

    /// Solves for element radiosities with `solver`.
    pub fn solve(
        &self,
        f: &FormFactorMatrix,
        solver: Solver,
        progress: &dyn Progress,
    ) -> Result<Solution, PipelineError> {
        let (reflectance, emission) = solve::element_properties(&self.mesh, &self.scene);
        let (radiosity, report) = solve::solve(f, &reflectance, &emission, solver, progress)?;
        let balance = energy_balance(f, &self.areas(), &reflectance, &emission, &radiosity);
        Ok(Solution {
            radiosity,
            report: SolutionReport::Matrix(report),
            balance,
            mesh: None,
        })
    }

    /// Solves by progressive refinement (see [`solve::solve_progressive`]) with this
    /// scene's method, without any form-factor matrix. `observer` is called after every
    /// shot (for snapshots or a viewer) and may stop the solve.
    pub fn solve_progressive(
        &self,
        tolerance: f64,
        max_shots: usize,
        observer: &mut dyn FnMut(&ProgressiveState) -> ControlFlow<()>,
        progress: &dyn Progress,
    ) -> Result<Solution, PipelineError> {
        let (reflectance, emission) = solve::element_properties(&self.mesh, &self.scene);
        let ctx = FormFactorContext {
            mesh: &self.mesh,
            occluders: &self.occluders,
        };
        let (radiosity, report) = solve::solve_progressive(
            &ctx,
            self.method(),
            &reflectance,
            &emission,
            tolerance,
            max_shots,
            observer,
            progress,
        )?;
        Ok(Solution {
            radiosity,
            balance: report.balance,
            report: SolutionReport::Progressive(report),
            mesh: None,
        })
    }

    /// Solves by hierarchical radiosity (see [`solve::solve_hierarchical`]): no matrix; the
    /// solution carries its own elements (the leaves) in [`Solution::mesh`].
    pub fn solve_hierarchical(
        &self,
        settings: &solve::HierarchicalSettings,
        progress: &dyn Progress,
    ) -> Result<Solution, PipelineError> {
        let h = solve::solve_hierarchical(&self.scene, &self.occluders, settings, progress)?;
        Ok(Solution {
            radiosity: h.radiosity,
            balance: h.report.balance,
            report: SolutionReport::Hierarchical(h.report),
            mesh: Some(h.mesh),
        })
    }
}

impl Solution {
    /// The elements the radiosities belong to: [`Solution::mesh`] when set, else `prepared`'s.
    pub fn mesh<'a>(&'a self, prepared: &'a Prepared) -> &'a Mesh {
        self.mesh.as_ref().unwrap_or(&prepared.mesh)
    }

    /// B per element as RGB triples.
    pub fn element_rgb(&self) -> Vec<[f64; 3]> {
        (0..self.radiosity.len())
            .map(|i| self.radiosity.element(i))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;

    #[test]
    fn auto_picks_dense_only_when_small_and_comfortable() {
        let gib = 1u64 << 30;
        assert!(choose_dense(2_000, 16 * gib).0);
        // 20,000 elements need 1.64 GiB with headroom: dense with 16 GiB, not with 2 GiB
        // (more than half of it).
        assert!(choose_dense(20_000, 16 * gib).0);
        assert!(!choose_dense(20_000, 2 * gib).0);
        assert!(!choose_dense(20_001, 1 << 50).0);
        assert!(
            choose_dense(9_805, 16 * gib).1.contains("MiB"),
            "the reason states the estimate"
        );
    }

    #[test]
    fn too_many_integration_points_are_refused_with_the_numbers() {
        let overrides = Overrides {
            max_patch_area: Some(20_000.0),
            integral_steps: Some(1000),
        };
        let prepared = Prepared::new(crate::scene::cornell_box(), overrides, &NoProgress).unwrap();
        let n = prepared.mesh.len();
        let err = prepared.check_memory(None).unwrap_err();
        let PipelineError::TooManyIntegrationPoints {
            steps,
            elements,
            points,
            limit,
        } = err
        else {
            panic!("{err}")
        };
        assert_eq!((steps, elements), (1000, n));
        assert_eq!((points, limit), (n as f64 * 1e6, MAX_INTEGRATION_POINTS));
        let text = err.to_string();
        let want = format!("INTEGRAL_STEPS 1000 on {n} elements means {points:.2e} integration");
        assert!(text.contains(&want), "{text}");
        assert!(text.ends_with("(more than 5e7)"), "{text}");
        // The hemicube holds no integration points: the same mesh passes.
        let mut hemicube = prepared;
        hemicube.method = FormFactorMethod::Hemicube { resolution: 8 };
        assert!(hemicube.check_memory(None).is_ok());
    }
}
