//! Form factors F_ij: the fraction of the energy leaving element i that arrives at element j
//! (paper sections 1.2 and 2.3).
//!
//! Properties that hold and are tested: F_ij >= 0; F_ii = 0 for planar elements; each row
//! sums to at most 1 (to 1 in a closed scene); reciprocity A_i F_ij = A_j F_ji.
//!
//! The matrix is written to a file and read back by [`crate::io::form_factor_file`].

pub mod accuracy;
mod area;
pub mod exact;
mod hemicube;
pub(crate) mod kernel;
mod method;
mod montecarlo;
pub mod reference;

/// The form-factor file's error, at the path the command line uses; the file's reader and
/// writer live in [`crate::io::form_factor_file`].
pub use crate::io::form_factor_file::FormFactorFileError;
pub use area::area_integral_pair;
pub use method::{FormFactorMethod, ParseMethodError};

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

use crate::mesh::Mesh;
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::Scene;
use crate::visibility::PolygonBvh;

/// A dense n x n matrix of form factors, stored row by row in f32.
///
/// f32 keeps 7 significant digits, far below the discretisation error of any method here
/// (1e-3 or worse at k = 2), and halves the memory of f64. Sums over rows are taken in f64.
#[derive(Clone, Debug, PartialEq)]
pub struct FormFactorMatrix {
    n: usize,
    data: Vec<f32>,
}

/// Not enough memory for a dense problem. The message states the sizes; what to change (a
/// larger `MAX_PATCH_AREA`, or a solver that keeps no matrix) is the caller's to say.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error(
    "{what} for {n} elements needs {needed_mib:.0} MiB, but only {available_mib:.0} MiB of memory \
     is available; at most {fits} elements would fit"
)]
pub struct OutOfMemory {
    /// What was to be allocated.
    pub what: &'static str,
    /// The element count asked for.
    pub n: usize,
    /// MiB the allocation needs.
    pub needed_mib: f64,
    /// MiB available.
    pub available_mib: f64,
    /// The largest element count whose allocation would fit.
    pub fits: usize,
}

/// A form factor that is not a finite number, or is negative: F_ij is a fraction of
/// energy, in [0, 1]. Found at a stage boundary (after the matrix is computed, before a
/// solve, in each row progressive refinement computes).
#[derive(Clone, Copy, Debug, thiserror::Error, PartialEq)]
#[error(
    "form factor F[{row}][{col}] (from element {row} to element {col}) is {value}, not a \
     number in [0, 1]: the elements' geometry is out of reach of f64 (an area or distance \
     that underflows or overflows, as in a surface 1e-200 thick)"
)]
pub struct NonFiniteFormFactor {
    /// Row i (the element the energy leaves).
    pub row: usize,
    /// Column j (the element it arrives at).
    pub col: usize,
    /// The value found.
    pub value: f64,
}

/// Checks that every entry of `row` (row i of F) is finite and not negative.
pub fn check_row(i: usize, row: impl IntoIterator<Item = f64>) -> Result<(), NonFiniteFormFactor> {
    match row
        .into_iter()
        .enumerate()
        .find(|(_, f)| !(f.is_finite() && *f >= 0.0))
    {
        Some((col, value)) => Err(NonFiniteFormFactor { row: i, col, value }),
        None => Ok(()),
    }
}

/// Memory this process may use, in bytes: the one memory budget every estimate in this
/// library is checked against. The smallest of
///
/// - the memory the system reports available ([`sysinfo`]'s `available_memory`; on Linux
///   `MemAvailable` from /proc/meminfo; 8 GiB where the system reports nothing),
/// - the memory limit of the cgroup when one is set (cgroup v2 `memory.max`, or v1
///   `memory.limit_in_bytes`),
/// - on Linux, what is left of the address-space limit (`ulimit -v`, RLIMIT_AS) and of the
///   data-segment limit (`ulimit -d`, RLIMIT_DATA) after what the process already maps
///   (`VmSize`, `VmData` of /proc/self/status): an allocation past either fails, however
///   much memory is free.
///
/// The limits are read from /proc/self/limits, the same numbers getrlimit gives, so no
/// unsafe code is needed. Elsewhere the resource limits are not seen.
pub fn available_memory_bytes() -> u64 {
    use sysinfo::{MemoryRefreshKind, RefreshKind, System};
    let system = System::new_with_specifics(
        RefreshKind::nothing().with_memory(MemoryRefreshKind::nothing().with_ram()),
    );
    let available = system.available_memory();
    // cgroup_limits asserts that the memory was read (a non-zero total).
    let memory = if available == 0 || system.total_memory() == 0 {
        8 << 30
    } else {
        // The limit's total is min(limit, total memory), so this is min(available, limit).
        match system.cgroup_limits() {
            Some(limits) => available.min(limits.total_memory),
            None => available,
        }
    };
    memory.min(resource_limit_headroom().unwrap_or(u64::MAX))
}

/// What the address-space and data-segment limits leave: min over the two of (soft limit
/// - what is mapped now), `None` when neither is set (or on systems without /proc).
fn resource_limit_headroom() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    headroom_from_proc(&limits, &status)
}

/// [`resource_limit_headroom`] from the texts of /proc/self/limits and /proc/self/status.
fn headroom_from_proc(limits: &str, status: &str) -> Option<u64> {
    // "Max address space   unlimited   unlimited   bytes": the soft limit is the one enforced.
    let soft = |name: &str| -> Option<u64> {
        let line = limits.lines().find(|l| l.starts_with(name))?;
        line[name.len()..].split_whitespace().next()?.parse().ok()
    };
    // "VmSize:	    3896 kB"
    let used = |key: &str| -> u64 {
        status
            .lines()
            .find(|l| l.starts_with(key))
            .and_then(|l| {
                l[key.len()..]
                    .split_whitespace()
                    .next()?
                    .parse::<u64>()
                    .ok()
            })
            .map_or(0, |kib| kib * 1024)
    };
    [
        ("Max address space", "VmSize:"),
        ("Max data size", "VmData:"),
    ]
    .into_iter()
    .filter_map(|(limit, key)| Some(soft(limit)?.saturating_sub(used(key))))
    .min()
}

/// Checks that `bytes_per_entry` x n^2 bytes (plus 10 % headroom) fit in `available` bytes.
pub fn check_dense_fits(
    what: &'static str,
    n: usize,
    bytes_per_entry: f64,
    available: u64,
) -> Result<(), OutOfMemory> {
    let needed = bytes_per_entry * (n as f64).powi(2) * 1.1;
    if needed <= available as f64 {
        return Ok(());
    }
    let fits = ((available as f64 / (1.1 * bytes_per_entry)).sqrt()) as usize;
    Err(OutOfMemory {
        what,
        n,
        needed_mib: needed / (1 << 20) as f64,
        available_mib: available as f64 / (1 << 20) as f64,
        fits,
    })
}

/// Row-sum statistics of a form-factor matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowSums {
    /// Smallest row sum.
    pub min: f64,
    /// Mean row sum.
    pub mean: f64,
    /// Largest row sum.
    pub max: f64,
    /// The row (element) of the smallest sum (the first of equals; 0 for an empty matrix).
    pub min_row: usize,
    /// The row (element) of the largest sum (the first of equals; 0 for an empty matrix).
    pub max_row: usize,
    /// Rows that sum to exactly 0: elements that see no other element (faces pressed
    /// against another surface, or shut in).
    pub zero: usize,
    /// Rows that sum above [`ROW_SUM_OVER`]: elements that send out more light than leaves
    /// them (over-counted near pairs).
    pub over: usize,
    /// The area of those elements (scene units squared): many small ones along a contact
    /// weigh little (the slivers cut along a box's foot), one large wall much.
    pub over_area: f64,
}

/// The row sum above which a row counts as over-counted in [`RowSums::over`]: 1 % above
/// the most a closed surround can give (f32 rounding of a row stays near 1e-6).
pub const ROW_SUM_OVER: f64 = 1.01;

/// `bytes` in MiB (2^20 bytes) as the reports of the dense matrix give them: two decimals
/// below 10 MiB, none above.
pub fn format_mib(bytes: u64) -> String {
    let m = bytes as f64 / (1u64 << 20) as f64;
    if m < 10.0 {
        format!("{m:.2}")
    } else {
        format!("{m:.0}")
    }
}

impl FormFactorMatrix {
    /// Bytes of the entries of an `n` x `n` matrix: 4 n^2 (f32). The one figure every
    /// report of the dense matrix's size gives (`auto`'s choice, `compare`).
    pub fn bytes_for(n: usize) -> u64 {
        4 * (n as u64) * (n as u64)
    }

    /// An n x n matrix of zeros, refused with [`OutOfMemory`] if it would not fit.
    pub fn zeros(n: usize) -> Result<FormFactorMatrix, OutOfMemory> {
        check_dense_fits(
            "the form-factor matrix (f32)",
            n,
            4.0,
            available_memory_bytes(),
        )?;
        Ok(FormFactorMatrix {
            n,
            data: vec![0.0; n * n],
        })
    }

    /// Wraps row-major `data` of length n^2.
    ///
    /// # Panics
    /// If `data.len() != n * n`.
    pub fn from_rows(n: usize, data: Vec<f32>) -> FormFactorMatrix {
        assert_eq!(data.len(), n * n);
        FormFactorMatrix { n, data }
    }

    /// The number of rows (and columns).
    pub fn n(&self) -> usize {
        self.n
    }

    /// F_ij.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.data[i * self.n + j] as f64
    }

    /// Row i: F_i0 ... F_i(n-1).
    pub fn row(&self, i: usize) -> &[f32] {
        &self.data[i * self.n..(i + 1) * self.n]
    }

    /// All entries, row by row.
    pub fn as_slice(&self) -> &[f32] {
        &self.data
    }

    /// The sum of row i, in f64.
    pub fn row_sum(&self, i: usize) -> f64 {
        self.row(i).iter().map(|&f| f as f64).sum()
    }

    /// Minimum, mean and maximum row sum; `areas` are the elements' (for
    /// [`RowSums::over_area`]).
    pub fn row_sums(&self, areas: &[f64]) -> RowSums {
        debug_assert_eq!(areas.len(), self.n, "one area per row");
        let sums: Vec<f64> = (0..self.n).map(|i| self.row_sum(i)).collect();
        let (mut min_row, mut max_row) = (0, 0);
        for (i, &s) in sums.iter().enumerate() {
            if s < sums[min_row] {
                min_row = i;
            }
            if s > sums[max_row] {
                max_row = i;
            }
        }
        RowSums {
            min: sums.iter().copied().fold(f64::INFINITY, f64::min),
            mean: sums.iter().sum::<f64>() / self.n.max(1) as f64,
            max: sums.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            min_row,
            max_row,
            zero: sums.iter().filter(|&&s| s == 0.0).count(),
            over: sums.iter().filter(|&&s| s > ROW_SUM_OVER).count(),
            over_area: sums
                .iter()
                .zip(areas)
                .filter(|(&s, _)| s > ROW_SUM_OVER)
                .map(|(_, &a)| a)
                .sum(),
        }
    }

    /// Checks that every entry is finite and not negative ([`check_row`] on every row), in
    /// parallel over rows; the error names the first bad entry of the first bad row.
    pub fn check_entries(&self) -> Result<(), NonFiniteFormFactor> {
        (0..self.n)
            .into_par_iter()
            .map(|i| check_row(i, self.row(i).iter().map(|&f| f as f64)))
            .find_first(Result::is_err)
            .unwrap_or(Ok(()))
    }

    /// The largest sum of |F_ij| over a row (0 for an empty matrix).
    pub fn max_abs_row_sum(&self) -> f64 {
        (0..self.n)
            .into_par_iter()
            .map(|i| self.row(i).iter().map(|&f| (f as f64).abs()).sum::<f64>())
            .reduce(|| 0.0, f64::max)
    }

    /// How far the matrix is from reciprocity A_i F_ij = A_j F_ji.
    ///
    /// Walks the upper triangle in 64 x 64 tiles (so the transposed entries are read from
    /// cache), in parallel over tile rows.
    pub fn reciprocity(&self, areas: &[f64]) -> Reciprocity {
        const TILE: usize = 64;
        let n = self.n;
        let tiles = n.div_ceil(TILE);
        let (worst, diff, total) = (0..tiles)
            .into_par_iter()
            .map(|ti| {
                let (mut worst, mut diff, mut total) = (0.0f64, 0.0f64, 0.0f64);
                for tj in ti..tiles {
                    for i in ti * TILE..((ti + 1) * TILE).min(n) {
                        for j in (tj * TILE).max(i + 1)..((tj + 1) * TILE).min(n) {
                            let (fij, fji) = (self.get(i, j), self.get(j, i));
                            let a = areas[i] * fij;
                            let b = areas[j] * fji;
                            diff += (a - b).abs();
                            total += a + b;
                            if fij.max(fji) > 1e-6 {
                                worst = worst.max((a - b).abs() / a.max(b));
                            }
                        }
                    }
                }
                (worst, diff, total)
            })
            .reduce(
                || (0.0, 0.0, 0.0),
                |x, y| (x.0.max(y.0), x.1 + y.1, x.2 + y.2),
            );
        Reciprocity {
            max_relative: worst,
            total_relative: if total > 0.0 { diff / total } else { 0.0 },
        }
    }

    /// The largest relative reciprocity error; see [`Reciprocity::max_relative`].
    pub fn max_reciprocity_error(&self, areas: &[f64]) -> f64 {
        self.reciprocity(areas).max_relative
    }
}

/// Reciprocity errors of a form-factor matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reciprocity {
    /// The largest |A_i F_ij - A_j F_ji| / max(A_i F_ij, A_j F_ji) over the pairs where
    /// either entry exceeds 1e-6 (smaller entries are f32 noise). Exact methods give f32
    /// rounding (~1e-7); sampling methods give up to 1 (an entry estimated as zero in one
    /// direction but not the other).
    pub max_relative: f64,
    /// sum |A_i F_ij - A_j F_ji| / sum (A_i F_ij + A_j F_ji) over all pairs: the fraction of
    /// exchanged power that breaks reciprocity.
    pub total_relative: f64,
}

/// Everything form factors are computed from: the elements, and the occluders (the scene's
/// input surfaces, not the elements, so the BVH stays small).
pub struct FormFactorContext<'a> {
    /// The meshed scene.
    pub mesh: &'a Mesh,
    /// Occluders: the input surfaces, each tagged with its surface index.
    pub occluders: &'a PolygonBvh,
}

/// Builds the occluder BVH of a scene: every input surface, tagged with its surface index.
pub fn occluder_bvh(scene: &Scene) -> PolygonBvh {
    PolygonBvh::over_surfaces(scene)
}

/// Counts the rays cast, for rays-per-second figures, and the occluder candidates they
/// were tested against (where a method tests each ray against a list of candidates).
#[derive(Debug, Default)]
pub struct RayCounter(AtomicU64, AtomicU64);

impl RayCounter {
    /// Adds `n` rays.
    pub fn add(&self, n: u64) {
        self.0.fetch_add(n, Ordering::Relaxed);
    }
    /// Adds `n` rays each tested against a list of `candidates` occluders.
    pub fn add_tested(&self, n: u64, candidates: u64) {
        self.0.fetch_add(n, Ordering::Relaxed);
        self.1.fetch_add(n * candidates, Ordering::Relaxed);
    }
    /// The rays counted so far.
    pub fn get(&self) -> u64 {
        self.0.load(Ordering::Relaxed)
    }
    /// Occluder candidates listed for the rays counted by [`RayCounter::add_tested`]: each
    /// such ray is tested against its list until one blocks it, so this is the most
    /// ray-polygon tests they made (the ray rate falls as it grows).
    pub fn candidates(&self) -> u64 {
        self.1.load(Ordering::Relaxed)
    }
}

/// A block of consecutive rows of the form-factor matrix, as computed by one worker (or one
/// machine): rows `rows`, each of length n, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct RowBlock {
    /// The rows this block holds.
    pub rows: Range<usize>,
    /// Row-major entries, `rows.len()` x n.
    pub data: Vec<f32>,
}

/// The per-method machinery, built once per matrix and shared by all rows.
enum Engine<'a> {
    /// Symmetric pair integrals.
    Pairs(area::AreaIntegrator<'a>),
    Hemicube(hemicube::Hemicube),
    MonteCarlo {
        elements: PolygonBvh,
        samples: u32,
        seed: u64,
    },
}

/// Per-thread scratch space of every engine.
#[derive(Default)]
struct Scratch {
    area: area::Scratch,
    hemicube: hemicube::HemicubeScratch,
}

impl<'a> Engine<'a> {
    fn new(ctx: &'a FormFactorContext<'a>, method: FormFactorMethod) -> Engine<'a> {
        match method {
            FormFactorMethod::AreaIntegral { steps } => Engine::Pairs(area::AreaIntegrator::new(
                ctx,
                steps,
                area::PairKernel::AreaExactNear,
            )),
            FormFactorMethod::Contour { steps } => Engine::Pairs(area::AreaIntegrator::new(
                ctx,
                steps,
                area::PairKernel::Contour,
            )),
            FormFactorMethod::Analytic { steps } => Engine::Pairs(area::AreaIntegrator::new(
                ctx,
                steps,
                area::PairKernel::Analytic,
            )),
            FormFactorMethod::Hemicube { resolution } => {
                Engine::Hemicube(hemicube::Hemicube::new(resolution))
            }
            FormFactorMethod::MonteCarlo { samples, seed } => Engine::MonteCarlo {
                elements: PolygonBvh::over_elements(ctx.mesh),
                samples,
                seed,
            },
        }
    }

    /// Row i in full: F_ij for every j.
    fn row(
        &self,
        ctx: &FormFactorContext,
        i: usize,
        rays: &RayCounter,
        scratch: &mut Scratch,
    ) -> Vec<f64> {
        let mesh = ctx.mesh;
        match self {
            Engine::Pairs(integrator) => {
                let a_i = mesh.elements[i].area;
                integrator
                    .couplings(i, 0..mesh.len(), rays, &mut scratch.area)
                    .into_iter()
                    .map(|g| g / a_i)
                    .collect()
            }
            Engine::Hemicube(h) => h.row(mesh, i, &mut scratch.hemicube),
            Engine::MonteCarlo {
                elements,
                samples,
                seed,
            } => montecarlo::row(mesh, elements, i, *samples, *seed, rays),
        }
    }
}

/// Computes single rows of the matrix on demand, building the per-method machinery (the
/// integration points, the hemicube's delta form factors, the element BVH) once: for
/// progressive refinement, which needs one row per shot and never the whole matrix.
///
/// `row(i)` gives the same numbers as row i of [`compute_rows`] (no reciprocity is used),
/// in f64. The pair methods (area, contour, analytic) split the row's columns over the
/// thread pool; the hemicube and Monte Carlo compute it on the calling thread.
pub struct RowComputer<'a> {
    ctx: &'a FormFactorContext<'a>,
    engine: Engine<'a>,
    scratch: Scratch,
}

impl<'a> RowComputer<'a> {
    /// Prepares `method` for the elements and occluders of `ctx`.
    pub fn new(ctx: &'a FormFactorContext<'a>, method: FormFactorMethod) -> RowComputer<'a> {
        RowComputer {
            ctx,
            engine: Engine::new(ctx, method),
            scratch: Scratch::default(),
        }
    }

    /// The number of elements (the length of every row).
    pub fn n(&self) -> usize {
        self.ctx.mesh.len()
    }

    /// Row i: F_ij for every element j, counting visibility rays in `rays`.
    pub fn row(&mut self, i: usize, rays: &RayCounter) -> Vec<f64> {
        const CHUNK: usize = 256;
        let mesh = self.ctx.mesh;
        let n = mesh.len();
        match &self.engine {
            Engine::Pairs(integrator) if n > CHUNK => {
                let a_i = mesh.elements[i].area;
                let chunks: Vec<usize> = (0..n).step_by(CHUNK).collect();
                chunks
                    .into_par_iter()
                    .map_init(Scratch::default, |scratch, start| {
                        integrator.couplings(
                            i,
                            start..(start + CHUNK).min(n),
                            rays,
                            &mut scratch.area,
                        )
                    })
                    .flatten_iter()
                    .map(|g| g / a_i)
                    .collect()
            }
            engine => engine.row(self.ctx, i, rays, &mut self.scratch),
        }
    }
}

/// Computes the full matrix with `method`, in parallel over rows, reporting progress in
/// element pairs (n (n - 1) / 2 in all) as each row of the upper triangle finishes.
///
/// The area integral is symmetric in i and j up to the 1/A_i factor, so only the upper
/// triangle G_ij = A_i F_ij (j > i) is integrated and both F_ij = G_ij / A_i and
/// F_ji = G_ij / A_j are filled from it (paper 1.2, property 1): half the work, and
/// reciprocity holds to f32 rounding.
pub fn compute_matrix(
    ctx: &FormFactorContext,
    method: FormFactorMethod,
    rays: &RayCounter,
    progress: &dyn Progress,
) -> Result<FormFactorMatrix, OutOfMemory> {
    compute_matrix_reusing(ctx, method, None, rays, progress)
}

/// A matrix computed before on a mesh that shares elements with the one at hand: after
/// adaptive subdivision most elements are unchanged, and so are the form factors between
/// them.
#[derive(Clone, Copy, Debug)]
pub struct Reuse<'a> {
    /// The matrix on the mesh before, computed by the same method.
    pub matrix: &'a FormFactorMatrix,
    /// For each element of the mesh at hand, its index in the mesh before where it is the
    /// same element (same corners, same surface), else `None`.
    pub kept: &'a [Option<u32>],
}

/// [`compute_matrix`], taking from `reuse` the entries between elements that both were in
/// the mesh before, for the reciprocal pair methods (area, contour, analytic: each entry
/// depends on its two elements and the scene's occluders alone, so the copy is bit for bit
/// what integrating again would give). The other methods, whose rows depend on the whole
/// mesh, compute everything. Progress counts the pairs integrated.
pub fn compute_matrix_reusing(
    ctx: &FormFactorContext,
    method: FormFactorMethod,
    reuse: Option<Reuse>,
    rays: &RayCounter,
    progress: &dyn Progress,
) -> Result<FormFactorMatrix, OutOfMemory> {
    let n = ctx.mesh.len();
    let mut matrix = FormFactorMatrix::zeros(n)?;
    let areas: Vec<f64> = ctx.mesh.elements.iter().map(|e| e.area).collect();
    let engine = Engine::new(ctx, method);
    if let (true, Engine::Pairs(integrator)) = (method.is_reciprocal(), &engine) {
        let kept = |i: usize| reuse.and_then(|r| r.kept.get(i).copied().flatten());
        let fresh: Vec<bool> = (0..n).map(|i| kept(i).is_none()).collect();
        // Pairs to integrate: j > i with i or j fresh.
        let fresh_after: Vec<u64> = {
            let mut after = vec![0u64; n + 1];
            for i in (0..n).rev() {
                after[i] = after[i + 1] + fresh[i] as u64;
            }
            after
        };
        let pairs: u64 = (0..n)
            .map(|i| {
                if fresh[i] {
                    (n - i - 1) as u64
                } else {
                    fresh_after[i + 1]
                }
            })
            .sum();
        run_stage(progress, Stage::FormFactors, pairs, || {
            // Upper triangle, row by row, straight into the matrix: F_ij = G_ij / A_i, j > i.
            matrix
                .data
                .par_chunks_mut(n.max(1))
                .enumerate()
                .for_each_init(Scratch::default, |scratch, (i, row)| {
                    let mut done = 0u64;
                    let mut j = i + 1;
                    while j < n {
                        if let (Some(oi), Some(oj), Some(r)) = (kept(i), kept(j), reuse) {
                            row[j] = r.matrix.data[oi as usize * r.matrix.n + oj as usize];
                            j += 1;
                            continue;
                        }
                        // The run of columns from j that must be integrated.
                        let end = if fresh[i] {
                            n
                        } else {
                            (j..n).find(|&c| !fresh[c]).unwrap_or(n)
                        };
                        let g = integrator.couplings(i, j..end, rays, &mut scratch.area);
                        for (f, g) in row[j..end].iter_mut().zip(g) {
                            *f = upper_entry(g, areas[i]);
                        }
                        done += (end - j) as u64;
                        j = end;
                    }
                    progress.advance(done);
                });
            // Lower triangle by reciprocity: F_ji = A_i F_ij / A_j.
            for i in 0..n {
                for j in i + 1..n {
                    matrix.data[j * n + i] =
                        mirrored_entry(matrix.data[i * n + j], areas[i], areas[j]);
                }
            }
        });
    } else {
        let pairs = (n as u64) * (n as u64).saturating_sub(1);
        run_stage(progress, Stage::FormFactors, pairs, || {
            matrix
                .data
                .par_chunks_mut(n.max(1))
                .enumerate()
                .for_each_init(Scratch::default, |scratch, (i, row)| {
                    for (f, v) in row.iter_mut().zip(engine.row(ctx, i, rays, scratch)) {
                        *f = v as f32;
                    }
                    progress.advance(n.saturating_sub(1) as u64);
                });
        });
    }
    Ok(matrix)
}

/// F_ij = G_ij / A_i as stored (f32), from the coupling G_ij = A_i F_ij of the upper
/// triangle: the one place this rounding is written, shared by [`compute_matrix`] and
/// [`BlockComputer`].
fn upper_entry(g: f64, a_i: f64) -> f32 {
    (g / a_i) as f32
}

/// F_ji = A_i F_ij / A_j as stored (f32), from the stored (f32) upper-triangle entry F_ij:
/// how [`compute_matrix`] fills the lower triangle of a reciprocal method, and how a writer
/// of [`BlockComputer`]'s upper-triangle blocks must fill it to give the same bytes.
pub fn mirrored_entry(f_ij: f32, a_i: f64, a_j: f64) -> f32 {
    ((f_ij as f64 * a_i) / a_j) as f32
}

/// True when [`compute_matrix`] integrates only the upper triangle with `method` and fills
/// the lower one by reciprocity ([`mirrored_entry`]): the area integral and the contour
/// integral. Then [`BlockComputer`] gives only the entries j > i of each row.
pub fn fills_lower_by_reciprocity(method: FormFactorMethod) -> bool {
    // Both are pair methods (Engine::Pairs), the condition compute_matrix tests.
    method.is_reciprocal()
}

/// Computes blocks of rows of the matrix exactly as [`compute_matrix`] does (the same
/// arithmetic, so the same f32 bits), for a matrix split over processes or machines that
/// each compute some blocks: the per-method machinery is built once, and each block is
/// computed in parallel over its rows.
///
/// Where [`fills_lower_by_reciprocity`] holds for the method, a block holds only the upper
/// triangle: row i's entries j > i, the others 0 (the diagonal is 0 in the matrix too);
/// whoever assembles the matrix fills F_ji from F_ij with [`mirrored_entry`]. So each pair
/// is integrated once over all blocks. Otherwise each row is complete.
pub struct BlockComputer<'a> {
    ctx: &'a FormFactorContext<'a>,
    engine: Engine<'a>,
    upper_only: bool,
}

impl<'a> BlockComputer<'a> {
    /// Prepares `method` for the elements and occluders of `ctx`.
    pub fn new(ctx: &'a FormFactorContext<'a>, method: FormFactorMethod) -> BlockComputer<'a> {
        let engine = Engine::new(ctx, method);
        let upper_only = fills_lower_by_reciprocity(method) && matches!(engine, Engine::Pairs(_));
        BlockComputer {
            ctx,
            engine,
            upper_only,
        }
    }

    /// True when blocks hold the upper triangle only (see the type's documentation).
    pub fn upper_only(&self) -> bool {
        self.upper_only
    }

    /// The number of elements (the length of every row).
    pub fn n(&self) -> usize {
        self.ctx.mesh.len()
    }

    /// Rows `rows` (n entries each, row-major), counting visibility rays in `rays`.
    pub fn block(&self, rows: Range<usize>, rays: &RayCounter) -> RowBlock {
        let n = self.n();
        let mesh = self.ctx.mesh;
        let mut data = vec![0.0f32; rows.len() * n];
        data.par_chunks_mut(n.max(1))
            .zip(rows.clone().into_par_iter())
            .for_each_init(Scratch::default, |scratch, (row, i)| match &self.engine {
                Engine::Pairs(integrator) if self.upper_only => {
                    // As compute_matrix: one call for the columns after i.
                    let a_i = mesh.elements[i].area;
                    let g = integrator.couplings(i, i + 1..n, rays, &mut scratch.area);
                    for (f, g) in row[i + 1..].iter_mut().zip(g) {
                        *f = upper_entry(g, a_i);
                    }
                }
                engine => {
                    for (f, v) in row.iter_mut().zip(engine.row(self.ctx, i, rays, scratch)) {
                        *f = v as f32;
                    }
                }
            });
        RowBlock { rows, data }
    }
}

/// Computes rows `rows` of the matrix (all n columns each), without using reciprocity, so
/// that blocks can be computed independently (on other threads or machines).
pub fn compute_rows(
    ctx: &FormFactorContext,
    method: FormFactorMethod,
    rows: Range<usize>,
    rays: &RayCounter,
) -> RowBlock {
    let engine = Engine::new(ctx, method);
    let data: Vec<f32> = rows
        .clone()
        .into_par_iter()
        .map_init(Scratch::default, |scratch, i| {
            engine
                .row(ctx, i, rays, scratch)
                .into_iter()
                .map(|f| f as f32)
                .collect::<Vec<f32>>()
        })
        .flatten_iter()
        .collect();
    RowBlock { rows, data }
}

#[cfg(test)]
mod tests {
    /// `ulimit -v` and `ulimit -d` count: what they leave after the mapped memory is the
    /// budget, the smaller of the two; "unlimited" sets nothing.
    #[test]
    fn memory_budget_honours_ulimit_v_and_ulimit_d() {
        let limits = "Limit                     Soft Limit           Hard Limit           Units\n\
                      Max data size             3221225472           unlimited            bytes\n\
                      Max address space         2147483648           4294967296           bytes\n";
        let status = "Name:\tradiosity\nVmSize:\t  1048576 kB\nVmData:\t   524288 kB\n";
        // 2 GiB - 1 GiB mapped = 1 GiB; 3 GiB - 0.5 GiB = 2.5 GiB.
        assert_eq!(super::headroom_from_proc(limits, status), Some(1 << 30));
        let unlimited = "Max data size             unlimited            unlimited            bytes\n\
                         Max address space         unlimited            unlimited            bytes\n";
        assert_eq!(super::headroom_from_proc(unlimited, status), None);
        // A limit below what is already mapped leaves nothing.
        let tight = "Max address space         1024                 unlimited            bytes\n";
        assert_eq!(super::headroom_from_proc(tight, status), Some(0));
    }

    /// `MemAvailable` read by hand, capped by a cgroup limit read by hand (and by the
    /// resource limits), matches
    /// [`super::available_memory_bytes`] up to what other processes change in between.
    #[cfg(target_os = "linux")]
    #[test]
    fn available_memory_is_mem_available_capped_by_the_cgroup() {
        let read = |path: &str| std::fs::read_to_string(path).ok();
        let Some(meminfo) = read("/proc/meminfo") else {
            return;
        };
        let kib = |key: &str| {
            meminfo
                .lines()
                .find(|l| l.starts_with(key))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
                .map(|k| k * 1024)
        };
        let (Some(available), Some(total)) = (kib("MemAvailable:"), kib("MemTotal:")) else {
            return;
        };
        let limit = [
            "/sys/fs/cgroup/memory.max",
            "/sys/fs/cgroup/memory/memory.limit_in_bytes",
        ]
        .iter()
        .find_map(|p| read(p)?.trim().parse::<u64>().ok())
        .unwrap_or(u64::MAX);
        let rlimit = super::resource_limit_headroom().unwrap_or(u64::MAX);
        let by_hand = available.min(limit).min(rlimit) as f64;
        let got = super::available_memory_bytes();
        assert!(got <= total.min(limit), "{got} > {total} or {limit}");
        let slack = (0.1 * by_hand).max((256 << 20) as f64);
        assert!((got as f64 - by_hand).abs() <= slack, "{got} vs {by_hand}");
    }
}
