//! The one interface that long work reports progress through.
//!
//! Every long stage (meshing, form factors, solving, rendering) calls a [`Progress`] sink:
//! the command-line program draws a progress bar from it, a window can redraw between calls,
//! and a distributed runner can forward the calls to its coordinator. The library never
//! prints.

use std::time::Duration;

/// A stage of the pipeline, as reported to a [`Progress`] sink.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Reading and checking the scene file.
    Parse,
    /// Subdividing surfaces into elements.
    Mesh,
    /// Building the ray-query acceleration structure.
    Bvh,
    /// Splitting the elements that straddle contacts ([`crate::mesh::refine_contacts`]).
    Contacts,
    /// Computing form factors (work unit: one element pair of the upper triangle).
    FormFactors,
    /// Finding the elements to split between the solves of adaptive subdivision
    /// ([`crate::mesh::mark_steps`]) and splitting them.
    Adapt,
    /// Solving the radiosity system (work unit: one band or one iteration).
    Solve,
    /// Hierarchical radiosity's final gather, after its solve (work unit: one gather
    /// point's terms, see [`crate::solve::HierarchicalSettings::final_gather`]).
    Gather,
    /// Computing vertex radiosities.
    Shade,
    /// Rendering the image (work unit: one image row).
    Render,
    /// Path tracing a view (work unit: one image row), see [`crate::pathtrace`].
    PathTrace,
    /// Illuminance at calculation points (work unit: one point), see
    /// [`crate::illuminance`].
    Illuminance,
    /// Estimating a path-traced view's automatic exposure by paths at points over the
    /// surfaces ([`crate::pathtrace::PathTracer::area_exposure_scale`]).
    Exposure,
    /// Writing output files.
    Write,
}

impl Stage {
    /// A short human-readable name, as printed in timings.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Parse => "parse",
            Stage::Mesh => "mesh",
            Stage::Bvh => "bvh",
            Stage::Contacts => "contacts",
            Stage::FormFactors => "form factors",
            Stage::Adapt => "adapt",
            Stage::Solve => "solve",
            Stage::Gather => "final gather",
            Stage::Shade => "shade",
            Stage::Render => "render",
            Stage::PathTrace => "path trace",
            Stage::Illuminance => "illuminance",
            Stage::Exposure => "exposure",
            Stage::Write => "write",
        }
    }
}

/// Receives progress reports. Implementations must be cheap: `advance` may be called from
/// many threads, once per unit of work (for example once per form-factor row).
pub trait Progress: Sync {
    /// A stage begins; `total` units of work are expected (0 when unknown).
    fn start(&self, stage: Stage, total: u64);
    /// `done` more units of work of the current stage have finished.
    fn advance(&self, done: u64);
    /// The current stage ended after `elapsed` wall-clock time.
    fn finish(&self, stage: Stage, elapsed: Duration);
    /// Where the current stage stands, for a stage whose length is not known in advance:
    /// "unshot power 3.2 % of the emitted (stops below 1 %)". Replaces the last status;
    /// shown with the stage's progress, not printed as a message.
    fn status(&self, _text: &str) {}
    /// An informational message (for example the reciprocity error found).
    fn message(&self, _text: &str) {}
    /// Names the file the stage that just finished read or wrote ("cornell.ff"), for
    /// reports that label stage times.
    fn file(&self, _name: &str) {}
}

/// A sink that ignores every report.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _stage: Stage, _total: u64) {}
    fn advance(&self, _done: u64) {}
    fn finish(&self, _stage: Stage, _elapsed: Duration) {}
}

/// Runs `work` as `stage`, reporting its start and its end (with the elapsed time) to
/// `progress`, and returns its result.
pub fn run_stage<T>(
    progress: &dyn Progress,
    stage: Stage,
    total: u64,
    work: impl FnOnce() -> T,
) -> T {
    let start = std::time::Instant::now();
    progress.start(stage, total);
    let out = work();
    progress.finish(stage, start.elapsed());
    out
}
