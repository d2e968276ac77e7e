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
use radiosity::pipeline::{choose_dense, Overrides, Prepared};
use radiosity::progress::{Progress, Stage};
use radiosity::scene::{Rgb, Scene};
use radiosity::solve::{element_properties, DEFAULT_PROGRESSIVE_TOLERANCE};
use radiosity::visibility::PolygonBvh;

use crate::model::resolve;

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

/// The most elements [`Strategy::Auto`] computes the dense matrix for: about 5 s of form
/// factors on two cores for the Cornell box (BENCHMARKS.md), more in cluttered scenes, with
/// nothing lit on screen meanwhile. Beyond it progressive refinement shows light at once.
pub const VIEW_DENSE_MAX_ELEMENTS: usize = 6_000;

/// How the worker solves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Strategy {
    /// The dense matrix (cached, so edits are re-solves) when `choose_dense` allows it and
    /// there are at most [`VIEW_DENSE_MAX_ELEMENTS`] elements; progressive refinement
    /// otherwise.
    Auto,
    /// The dense matrix whenever `choose_dense` allows it (up to 20,000 elements and half
    /// the memory), however long the form factors take.
    Dense,
    /// Always progressive refinement (no matrix; edits re-run it).
    Progressive,
    /// Hierarchical radiosity with clustering: the window shows its leaves; edits re-run it
    /// (its links are not kept between solves).
    Hierarchical(radiosity::solve::HierarchicalSettings),
}

/// Starts the worker on `scene`; `wake` is called whenever there is news (the window asks
/// for a repaint).
pub fn spawn(
    scene: Scene,
    overrides: Overrides,
    strategy: Strategy,
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
            if let Err(message) = run(scene, overrides, strategy, &reporter, &edit_rx, &send) {
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

fn run(
    scene: Scene,
    overrides: Overrides,
    strategy: Strategy,
    progress: &Reporter,
    edits: &Receiver<Recolour>,
    send: &dyn Fn(Update),
) -> Result<(), String> {
    let mut prepared = Prepared::new(scene, overrides, progress).map_err(|e| e.to_string())?;
    let mesh = Arc::new(prepared.mesh.clone());
    let polygons: Vec<Vec<_>> = (0..mesh.len())
        .map(|e| mesh.corner_positions(e).collect())
        .collect();
    let ids: Vec<u32> = (0..mesh.len() as u32).collect();
    send(Update::Mesh(
        mesh.clone(),
        Arc::new(PolygonBvh::new(&polygons, &ids)),
    ));
    let n = mesh.len();
    let fits = || {
        let (dense, why) = choose_dense(n, radiosity::form_factor::available_memory_bytes());
        if dense && prepared.check_memory(None).is_ok() {
            (true, why)
        } else {
            // choose_dense names the CLI's fallback; the window's is progressive refinement
            // (it shows light from the first shot).
            let estimate = why
                .split([';', ',', ':'])
                .next()
                .unwrap_or_default()
                .to_string();
            (
                false,
                format!("{estimate}: no dense matrix; progressive refinement"),
            )
        }
    };
    let dense = match strategy {
        Strategy::Auto => {
            let (fits, why) = fits();
            if fits && n > VIEW_DENSE_MAX_ELEMENTS {
                progress.message(&format!(
                    "{n} elements: more than {VIEW_DENSE_MAX_ELEMENTS}, so progressive refinement \
                     shows light at once instead of waiting for every form factor (--dense \
                     computes the matrix, for live edits)"
                ));
                false
            } else {
                progress.message(&why);
                fits
            }
        }
        Strategy::Dense => {
            let (fits, why) = fits();
            progress.message(&why);
            fits
        }
        Strategy::Progressive | Strategy::Hierarchical(_) => false,
    };
    let matrix: Option<FormFactorMatrix> = if dense {
        Some(
            prepared
                .form_factors(progress)
                .map_err(|e| e.to_string())?
                .0,
        )
    } else {
        None
    };
    let (reflectance, emission) = element_properties(&prepared.mesh, &prepared.scene);
    let mut b = emission.clone();
    let mut pending = Some((reflectance, emission, 0u64));
    loop {
        let Some((rho, e, edit)) = pending.take() else {
            // Idle: wait for the next edit (or the window closing).
            match edits.recv() {
                Ok(r) => {
                    let r = newest(edits).ok().flatten().unwrap_or(r);
                    pending = Some(recoloured(&mut prepared, r));
                    continue;
                }
                Err(_) => return Ok(()),
            }
        };
        let mut interrupted: Option<Recolour> = None;
        let mut last_sent = Instant::now() - SNAPSHOT_INTERVAL;
        if let Strategy::Hierarchical(settings) = strategy {
            // No intermediate pictures: the leaves are only known at the end. The window
            // gets the leaves as its mesh (for drawing and picking), then their radiosity.
            *progress.shared.stage.lock().unwrap() = "hierarchical";
            progress.shared.total.store(0, Ordering::Relaxed);
            let start = Instant::now();
            let solution = prepared
                .solve_hierarchical(&settings, progress)
                .map_err(|e| e.to_string())?;
            let leaves = Arc::new(solution.mesh(&prepared).clone());
            let polygons: Vec<Vec<_>> = (0..leaves.len())
                .map(|e| leaves.corner_positions(e).collect())
                .collect();
            let ids: Vec<u32> = (0..leaves.len() as u32).collect();
            send(Update::Mesh(
                leaves.clone(),
                Arc::new(PolygonBvh::new(&polygons, &ids)),
            ));
            send(Update::Solution {
                element_b: solution.element_rgb(),
                done: true,
                note: format!(
                    "{} leaves, hierarchical radiosity in {:.1} s (edits re-run it)",
                    leaves.len(),
                    start.elapsed().as_secs_f64()
                ),
                edit,
            });
            continue;
        }
        match &matrix {
            Some(f) => {
                *progress.shared.stage.lock().unwrap() = "solve";
                progress.shared.total.store(0, Ordering::Relaxed);
                let report = resolve(f, &rho, &e, &mut b, VIEW_TOLERANCE, 10_000, |b, change| {
                    if let Ok(Some(r)) = newest(edits) {
                        interrupted = Some(r);
                        return false;
                    }
                    if last_sent.elapsed() >= SNAPSHOT_INTERVAL && change >= VIEW_TOLERANCE {
                        last_sent = Instant::now();
                        send(Update::Solution {
                            element_b: b.to_vec(),
                            done: false,
                            note: format!("Gauss-Seidel: change {change:.1e}"),
                            edit,
                        });
                    }
                    true
                });
                if interrupted.is_none() {
                    send(Update::Solution {
                        element_b: b.clone(),
                        done: true,
                        note: format!(
                            "{n} elements, Gauss-Seidel {} sweeps in {:.0} ms (dense form factors cached)",
                            report.sweeps,
                            report.elapsed.as_secs_f64() * 1e3
                        ),
                        edit,
                    });
                }
            }
            None => {
                *progress.shared.stage.lock().unwrap() = "progressive";
                progress.shared.total.store(0, Ordering::Relaxed);
                let start = Instant::now();
                let mut observer = |state: &radiosity::solve::ProgressiveState| {
                    if let Ok(Some(r)) = newest(edits) {
                        interrupted = Some(r);
                        return ControlFlow::Break(());
                    }
                    if last_sent.elapsed() >= SNAPSHOT_INTERVAL {
                        last_sent = Instant::now();
                        send(Update::Solution {
                            element_b: state.display_radiosity(),
                            done: false,
                            note: format!(
                                "progressive: shot {}, unshot {:.2} %",
                                state.shot,
                                100.0 * state.unshot_fraction
                            ),
                            edit,
                        });
                    }
                    ControlFlow::Continue(())
                };
                let solution = prepared.solve_progressive(
                    DEFAULT_PROGRESSIVE_TOLERANCE,
                    usize::MAX,
                    &mut observer,
                    progress,
                );
                if interrupted.is_none() {
                    let solution = solution.map_err(|e| e.to_string())?;
                    let shots = match solution.report {
                        radiosity::pipeline::SolutionReport::Progressive(r) => r.shots,
                        _ => 0,
                    };
                    let mut display = solution.element_rgb();
                    if let radiosity::pipeline::SolutionReport::Progressive(r) = solution.report {
                        for (d, rho) in display.iter_mut().zip(&rho) {
                            for k in 0..3 {
                                d[k] += rho[k] * r.ambient[k];
                            }
                        }
                    }
                    send(Update::Solution {
                        element_b: display,
                        done: true,
                        note: format!(
                            "{n} elements, progressive refinement: {shots} shots in {:.1} s (no matrix: edits re-run it)",
                            start.elapsed().as_secs_f64()
                        ),
                        edit,
                    });
                }
            }
        }
        if let Some(r) = interrupted {
            pending = Some(recoloured(&mut prepared, r));
        }
    }
}

/// Applies new surface colours to the prepared scene; returns the element properties.
fn recoloured(prepared: &mut Prepared, r: Recolour) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, u64) {
    for (s, (rho, e)) in prepared.scene.surfaces.iter_mut().zip(r.colours) {
        s.reflectance = rho;
        s.emission = e;
    }
    let (rho, e) = element_properties(&prepared.mesh, &prepared.scene);
    (rho, e, r.edit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity::progress::NoProgress;
    use radiosity::scene::cornell_box;
    use radiosity::solve::Solver;

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
        let overrides = Overrides {
            max_patch_area: Some(8000.0),
            integral_steps: Some(2),
        };
        let scene = cornell_box();
        let (edits, updates, _) = spawn(scene.clone(), overrides, Strategy::Auto, Arc::new(|| {}));
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

        let fresh = Prepared::new(edited, overrides, &NoProgress).unwrap();
        let (f, _) = fresh.form_factors(&NoProgress).unwrap();
        let solution = fresh
            .solve(&f, Solver::DEFAULT_GAUSS_SEIDEL, &NoProgress)
            .unwrap();
        let max_e = fresh
            .scene
            .surfaces
            .iter()
            .map(|s| s.emission.max_band())
            .fold(0.0, f64::max);
        for (i, bi) in b.iter().enumerate() {
            for (x, y) in bi.iter().zip(solution.radiosity.element(i)) {
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
        let overrides = Overrides {
            max_patch_area: Some(8000.0),
            integral_steps: Some(2),
        };
        let settings = radiosity::solve::HierarchicalSettings {
            epsilon: 0.2,
            min_area: 2000.0,
            tolerance: 1e-6,
            max_memory_bytes: None,
        };
        let scene = cornell_box();
        let (edits, updates, _) = spawn(
            scene.clone(),
            overrides,
            Strategy::Hierarchical(settings),
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
        let fresh = Prepared::new(edited, overrides, &NoProgress).unwrap();
        let solution = fresh.solve_hierarchical(&settings, &NoProgress).unwrap();
        let leaves = leaves.expect("the leaves are sent");
        assert_eq!(leaves.len(), solution.mesh(&fresh).len());
        assert_eq!(b, solution.element_rgb());
    }
}
