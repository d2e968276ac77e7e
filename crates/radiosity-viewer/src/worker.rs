//! The solve, off the window's thread.
//!
//! One worker thread owns the meshed scene and (for scenes that fit) the dense form-factor
//! matrix. It meshes, computes form factors, solves, and sends the window what it has as
//! it goes: the mesh first (drawn unlit), then a solution after every Gauss-Seidel sweep or
//! every few progressive-refinement shots (the paper's progressive display, section 3.5),
//! then the converged solution. Colour edits arrive as whole sets of surface colours; the
//! worker keeps only the newest one waiting, stops the running solve at its next sweep or
//! shot, and re-solves from the cached matrix, warm-started from the last solution.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use radiosity::form_factor::FormFactorMatrix;
use radiosity::mesh::Mesh;
use radiosity::mesh::MeshSettings;
use radiosity::pipeline::{self, FormFactors, Prepared, SolutionReport, SolveRequest};
use radiosity::progress::{Progress, Stage};
use radiosity::scene::{Rgb, Scene};
use radiosity::solve::{
    choose, DenseSolver, GaussSeidelSettings, HierarchicalSettings, ProgressiveSettings, Solver,
    SolverKind, Step, DEFAULT_PROGRESSIVE_TOLERANCE,
};
use radiosity::visibility::PolygonBvh;

/// The tolerance of the viewer's Gauss-Seidel solves: the largest change in a sweep below
/// 1e-6 of max |E| (far below an 8-bit display level; the CLI's 1e-9 would add sweeps
/// nobody can see).
pub const VIEW_TOLERANCE: f64 = 1e-6;

/// Minimum time between two intermediate solutions sent to the window.
const SNAPSHOT_INTERVAL: Duration = Duration::from_millis(60);

/// What the worker tells the window.
pub enum Update {
    /// The mesh and a BVH of its elements (ids are element indices), for drawing and
    /// picking.
    Mesh(Arc<Mesh>, Arc<PolygonBvh>),
    /// A solution, intermediate (`done` false) or converged.
    Solution {
        /// Radiosity per element (for display: progressive refinement's ambient term added).
        element_b: Vec<[f64; 3]>,
        /// True once converged (or stopped for good).
        done: bool,
        /// What produced it, for the status line.
        note: String,
        /// The edit (by sequence number) it answers, 0 for the first solve.
        edit: u64,
    },
    /// The solve failed; the message says why.
    Error(String),
}

/// A request to the worker: the colours of every surface (reflectance, emission), tagged
/// with a sequence number so the window can time edit-to-picture.
pub struct Recolour {
    /// One (reflectance, emission) per surface.
    pub colours: Vec<(Rgb, Rgb)>,
    /// Increasing sequence number.
    pub edit: u64,
}

/// Progress of the current stage, readable from the window.
#[derive(Default)]
pub struct StageProgress {
    /// The stage's name.
    pub stage: Mutex<&'static str>,
    /// Units done.
    pub done: AtomicU64,
    /// Units expected (0: unknown).
    pub total: AtomicU64,
    /// The last message from the pipeline (for example the dense-or-progressive choice).
    pub message: Mutex<String>,
}

struct Reporter {
    shared: Arc<StageProgress>,
    wake: Arc<dyn Fn() + Send + Sync>,
    last_wake: Mutex<Instant>,
}

impl Progress for Reporter {
    fn start(&self, stage: Stage, total: u64) {
        *self.shared.stage.lock().unwrap() = stage.name();
        self.shared.done.store(0, Ordering::Relaxed);
        self.shared.total.store(total, Ordering::Relaxed);
        (self.wake)();
    }
    fn advance(&self, done: u64) {
        self.shared.done.fetch_add(done, Ordering::Relaxed);
        if let Ok(mut last) = self.last_wake.try_lock() {
            if last.elapsed() > Duration::from_millis(100) {
                *last = Instant::now();
                (self.wake)();
            }
        }
    }
    fn finish(&self, _stage: Stage, _elapsed: Duration) {
        (self.wake)();
    }
    fn message(&self, text: &str) {
        *self.shared.message.lock().unwrap() = text.to_string();
        (self.wake)();
    }
}

/// The most elements the window's `auto` computes the dense matrix for: about 5 s of form
/// factors on two cores for the Cornell box (BENCHMARKS.md), more in cluttered scenes, with
/// nothing lit on screen meanwhile. Beyond it progressive refinement shows light at once.
pub const VIEW_DENSE_MAX_ELEMENTS: usize = 6_000;

/// How the window solves: a solver of the library's by kind, and hierarchical radiosity's
/// settings for when that is the kind.
///
/// The window's `auto` differs from the command line's: the dense matrix (cached, so edits
/// are quick re-solves) when [`radiosity::solve::choose`] allows it and there are at most
/// [`VIEW_DENSE_MAX_ELEMENTS`] elements, progressive refinement otherwise (it shows light
/// from the first shot). `gauss-seidel` and `lu` take the dense matrix whenever `choose`
/// allows it, however long the form factors take, and fall back to progressive refinement
/// when it would not fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSolver {
    /// The solver's kind.
    pub kind: SolverKind,
    /// Used when `kind` is hierarchical; `None`: the defaults for the `MAX_PATCH_AREA` the
    /// scene is meshed at ([`HierarchicalSettings::defaults_for`]).
    pub hierarchical: Option<HierarchicalSettings>,
}

impl ViewSolver {
    /// The window's automatic choice.
    pub fn auto() -> ViewSolver {
        ViewSolver {
            kind: SolverKind::Auto,
            hierarchical: None,
        }
    }
}

/// Starts the worker on `scene`, meshed with `settings` (the scene file's with the
/// command line's overrides applied); `wake` is called whenever there is news (the window
/// asks for a repaint).
pub fn spawn(
    scene: Scene,
    settings: MeshSettings,
    solver: ViewSolver,
    wake: Arc<dyn Fn() + Send + Sync>,
) -> (Sender<Recolour>, Receiver<Update>, Arc<StageProgress>) {
    let (edit_tx, edit_rx) = std::sync::mpsc::channel::<Recolour>();
    let (tx, rx) = std::sync::mpsc::channel();
    let shared = Arc::new(StageProgress::default());
    let reporter = Reporter {
        shared: shared.clone(),
        wake: wake.clone(),
        last_wake: Mutex::new(Instant::now()),
    };
    std::thread::Builder::new()
        .name("radiosity solve".into())
        .spawn(move || {
            let send = |u: Update| {
                let _ = tx.send(u);
                wake();
            };
            if let Err(message) = run(scene, settings, solver, &reporter, &edit_rx, &send) {
                send(Update::Error(message));
            }
        })
        .expect("spawning the solve thread");
    (edit_tx, rx, shared)
}

/// The newest waiting edit, if any (older ones are dropped).
fn newest(edits: &Receiver<Recolour>) -> Result<Option<Recolour>, ()> {
    let mut latest = None;
    loop {
        match edits.try_recv() {
            Ok(e) => latest = Some(e),
            Err(TryRecvError::Empty) => return Ok(latest),
            Err(TryRecvError::Disconnected) => return latest.map(Some).ok_or(()),
        }
    }
}

/// The solver the window uses for `n` elements: see [`ViewSolver`]; the reason goes to the
/// status line.
fn decide(prepared: &Prepared, choice: ViewSolver, progress: &Reporter) -> Solver {
    let n = prepared.mesh.len();
    let progressive = Solver::Progressive(ProgressiveSettings {
        tolerance: DEFAULT_PROGRESSIVE_TOLERANCE,
        max_shots: usize::MAX,
    });
    let gauss_seidel = Solver::Dense(DenseSolver::GaussSeidel(GaussSeidelSettings {
        tolerance: VIEW_TOLERANCE,
        max_iterations: 10_000,
    }));
    let dense = match choice.kind {
        SolverKind::Hierarchical => {
            return Solver::Hierarchical(choice.hierarchical.unwrap_or_else(|| {
                HierarchicalSettings::defaults_for(prepared.settings.max_patch_area)
            }))
        }
        SolverKind::Progressive => return progressive,
        SolverKind::Lu => Solver::LU,
        SolverKind::Auto | SolverKind::GaussSeidel => gauss_seidel,
    };
    let auto = choose(n, radiosity::form_factor::available_memory_bytes());
    if !(auto.dense() && prepared.check_memory(Some(&dense)).is_ok()) {
        progress.message(&format!(
            "{}: no dense matrix; progressive refinement",
            auto.estimate()
        ));
        progressive
    } else if choice.kind == SolverKind::Auto && n > VIEW_DENSE_MAX_ELEMENTS {
        progress.message(&format!(
            "{n} elements: more than {VIEW_DENSE_MAX_ELEMENTS}, so progressive refinement \
             shows light at once instead of waiting for every form factor (--dense \
             computes the matrix, for live edits)"
        ));
        progressive
    } else {
        progress.message(&auto.to_string());
        dense
    }
}

fn run(
    scene: Scene,
    settings: MeshSettings,
    choice: ViewSolver,
    progress: &Reporter,
    edits: &Receiver<Recolour>,
    send: &dyn Fn(Update),
) -> Result<(), String> {
    let mut prepared = Prepared::new(scene, settings, progress).map_err(|e| e.to_string())?;
    send(Update::Mesh(
        prepared.mesh.clone(),
        Arc::new(PolygonBvh::over_elements(&prepared.mesh)),
    ));
    let n = prepared.mesh.len();
    let solver = decide(&prepared, choice, progress);
    // The dense matrix is computed once: edits change colours, not form factors.
    let matrix: Option<FormFactorMatrix> = if solver.needs_matrix() {
        Some(
            prepared
                .form_factors(progress)
                .map_err(|e| e.to_string())?
                .0,
        )
    } else {
        None
    };
    // Gauss-Seidel's warm start: the last solution, converged or not.
    let mut last: Option<Vec<Rgb>> = None;
    let mut pending = Some(0u64);
    loop {
        let Some(edit) = pending.take() else {
            // Idle: wait for the next edit (or the window closing).
            match edits.recv() {
                Ok(r) => {
                    let r = newest(edits).ok().flatten().unwrap_or(r);
                    pending = Some(recoloured(&mut prepared, r, send));
                    continue;
                }
                Err(_) => return Ok(()),
            }
        };
        let mut interrupted: Option<Recolour> = None;
        let mut last_sent = Instant::now() - SNAPSHOT_INTERVAL;
        *progress.shared.stage.lock().unwrap() = match solver {
            Solver::Dense(_) => "solve",
            Solver::Progressive(_) => "progressive",
            Solver::Hierarchical(_) => "hierarchical",
        };
        progress.shared.total.store(0, Ordering::Relaxed);
        let start = Instant::now();
        let mut observer = |step: &Step| {
            if let Ok(Some(r)) = newest(edits) {
                interrupted = Some(r);
                return ControlFlow::Break(());
            }
            if last_sent.elapsed() >= SNAPSHOT_INTERVAL {
                last_sent = Instant::now();
                let (element_b, note) = match step {
                    Step::Sweep {
                        change, radiosity, ..
                    } => (
                        radiosity.to_vec(),
                        format!("Gauss-Seidel: change {change:.1e}"),
                    ),
                    Step::Shot(state) => (
                        state.display_radiosity(),
                        format!(
                            "progressive: shot {}, unshot {:.2} %",
                            state.shot,
                            100.0 * state.unshot_fraction
                        ),
                    ),
                };
                send(Update::Solution {
                    element_b: Rgb::as_arrays(&element_b).to_vec(),
                    done: false,
                    note,
                    edit,
                });
            }
            ControlFlow::Continue(())
        };
        let request = SolveRequest {
            solver,
            form_factors: matrix
                .as_ref()
                .map_or(FormFactors::Compute, FormFactors::Matrix),
            start: last.as_deref(),
            adapt: None,
        };
        let result = pipeline::solve(&prepared, &request, &mut observer, progress);
        if let Some(r) = interrupted {
            if let Ok(solution) = result {
                if solver.needs_matrix() {
                    last = Some(solution.radiosity.0);
                }
            }
            pending = Some(recoloured(&mut prepared, r, send));
            continue;
        }
        let solution = result.map_err(|e| e.to_string())?;
        let seconds = start.elapsed().as_secs_f64();
        let note = match solution.report {
            SolutionReport::Matrix(r) => format!(
                "{n} elements, {} {} sweeps in {:.0} ms (dense form factors cached)",
                if solver == Solver::LU { "LU" } else { "Gauss-Seidel" },
                r.iterations.unwrap_or(0),
                r.elapsed.as_secs_f64() * 1e3
            ),
            SolutionReport::Progressive(r) => format!(
                "{n} elements, progressive refinement: {} shots in {seconds:.1} s (no matrix: edits re-run it)",
                r.shots
            ),
            SolutionReport::Hierarchical(r) => {
                // The window gets the leaves as its mesh (for drawing and picking), then
                // their radiosity.
                send(Update::Mesh(
                    solution.mesh.clone(),
                    Arc::new(PolygonBvh::over_elements(&solution.mesh)),
                ));
                format!(
                    "{} leaves, hierarchical radiosity in {seconds:.1} s (edits re-run it)",
                    r.leaves
                )
            }
        };
        let display = solution.display_radiosity(prepared.light.reflectance());
        send(Update::Solution {
            element_b: Rgb::as_arrays(&display).to_vec(),
            done: true,
            note,
            edit,
        });
        if solver.needs_matrix() {
            last = Some(solution.radiosity.0);
        }
    }
}

/// Applies new surface colours to the prepared scene (a refusal goes to the window, and
/// the colours stay as they were); returns the edit's number.
fn recoloured(prepared: &mut Prepared, r: Recolour, send: &dyn Fn(Update)) -> u64 {
    if let Err(e) = prepared.recolour(&r.colours) {
        send(Update::Error(e.to_string()));
    }
    r.edit
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity::progress::NoProgress;
    use radiosity::scene::cornell_box;
    use radiosity::solve::keep_going;

    /// Asks the worker for the colours of `scene`, as edit number `edit`.
    fn send_colours(edits: &Sender<Recolour>, scene: &Scene, edit: u64) {
        let colours = scene
            .surfaces
            .iter()
            .map(|s| (s.reflectance, s.emission))
            .collect();
        edits.send(Recolour { colours, edit }).unwrap();
    }

    /// Waits for the converged solution answering `edit`.
    fn converged(updates: &Receiver<Update>, edit: u64) -> Vec<[f64; 3]> {
        loop {
            match updates
                .recv_timeout(Duration::from_secs(120))
                .expect("worker answers")
            {
                Update::Solution {
                    element_b,
                    done: true,
                    edit: e,
                    ..
                } if e == edit => return element_b,
                Update::Error(m) => panic!("worker failed: {m}"),
                _ => {}
            }
        }
    }

    /// The window's path: the worker solves, gets new colours, re-solves from its cached
    /// matrix; the result equals a fresh solve of the edited scene within the viewer's
    /// tolerance (largest sweep change 1e-6 of max E, so an error of at most
    /// 1e-6 / (1 - 0.8) = 5e-6 of max E with rho <= 0.8; checked at 1e-5).
    #[test]
    fn worker_resolves_an_edit_like_a_fresh_solve() {
        let meshing = MeshSettings {
            max_patch_area: 8000.0,
            integral_steps: 2,
        };
        let scene = cornell_box().scene;
        let (edits, updates, _) =
            spawn(scene.clone(), meshing, ViewSolver::auto(), Arc::new(|| {}));
        converged(&updates, 0);
        let mut edited = scene.clone();
        for s in edited
            .surfaces
            .iter_mut()
            .filter(|s| s.name.starts_with("Tall block"))
        {
            s.reflectance = Rgb([0.2, 0.3, 0.75]);
        }
        send_colours(&edits, &edited, 1);
        let b = converged(&updates, 1);

        let fresh = Prepared::new(edited, meshing, &NoProgress).unwrap();
        let solution = pipeline::solve(
            &fresh,
            &SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL),
            &mut keep_going,
            &NoProgress,
        )
        .unwrap();
        let max_e = fresh
            .scene
            .surfaces
            .iter()
            .map(|s| s.emission.max_band())
            .fold(0.0, f64::max);
        for (i, bi) in b.iter().enumerate() {
            for (x, y) in bi.iter().zip(solution.radiosity.element(i).0) {
                assert!(
                    (x - y).abs() < 1e-5 * max_e,
                    "element {i}: worker {x}, fresh solve {y} (max E {max_e})"
                );
            }
        }
    }

    /// With hierarchical radiosity the worker sends the leaves as the mesh, then their
    /// radiosity; after an edit, the leaves and radiosity of a fresh hierarchical solve of
    /// the edited scene (the solve is deterministic, so they are equal).
    #[test]
    fn worker_resolves_hierarchically_like_a_fresh_solve() {
        let meshing = MeshSettings {
            max_patch_area: 8000.0,
            integral_steps: 2,
        };
        let settings = radiosity::solve::HierarchicalSettings {
            epsilon: 0.2,
            min_area: 2000.0,
            tolerance: 1e-6,
            max_memory_bytes: None,
            final_gather: true,
            gather_points: radiosity::solve::GATHER_POINTS_DEFAULT,
        };
        let scene = cornell_box().scene;
        let (edits, updates, _) = spawn(
            scene.clone(),
            meshing,
            ViewSolver {
                kind: SolverKind::Hierarchical,
                hierarchical: Some(settings),
            },
            Arc::new(|| {}),
        );
        converged(&updates, 0);
        let mut edited = scene.clone();
        for s in edited.surfaces.iter_mut().filter(|s| s.name == "Floor") {
            s.reflectance = Rgb([0.7, 0.2, 0.2]);
        }
        send_colours(&edits, &edited, 1);
        // The leaves come before the solution that answers the edit.
        let mut leaves = None;
        let b = loop {
            match updates
                .recv_timeout(Duration::from_secs(120))
                .expect("worker answers")
            {
                Update::Mesh(mesh, _) => leaves = Some(mesh),
                Update::Solution {
                    element_b,
                    done: true,
                    edit: 1,
                    ..
                } => break element_b,
                Update::Error(m) => panic!("worker failed: {m}"),
                _ => {}
            }
        };
        let fresh = Prepared::new(edited, meshing, &NoProgress).unwrap();
        let solution = pipeline::solve(
            &fresh,
            &SolveRequest::new(Solver::Hierarchical(settings)),
            &mut keep_going,
            &NoProgress,
        )
        .unwrap();
        let leaves = leaves.expect("the leaves are sent");
        assert_eq!(leaves.len(), solution.mesh.len());
        assert_eq!(b, solution.element_rgb());
    }
}
