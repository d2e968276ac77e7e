//! Form factors F_ij: the fraction of the energy leaving element i that arrives at element j
//! (paper sections 1.2 and 2.3).
//!
//! Properties that hold and are tested: F_ij >= 0; F_ii = 0 for planar elements; each row
//! sums to at most 1 (to 1 in a closed scene); reciprocity A_i F_ij = A_j F_ji.

mod area;
pub mod exact;
mod file;
pub mod reference;

pub use area::area_integral_pair;
pub use file::{
    mesh_fingerprint, read_form_factors, write_form_factors, FormFactorFileError,
    FORM_FACTOR_FILE_VERSION, FORM_FACTOR_MAGIC, MAX_METHOD_LEN,
};

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::Mesh;
use crate::progress::{run_stage, Progress, Stage};
use crate::scene::Scene;
use crate::visibility::PolygonBvh;

/// How form factors are computed. Recorded in the form-factor file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormFactorMethod {
    /// The paper's double area integral (figure 4) by the midpoint rule with `steps` x `steps`
    /// points on each element, a disc-regularised kernel (see `area.rs`) and the visibility
    /// of every point pair by a ray cast against candidate occluders.
    AreaIntegral {
        /// k, points along each axis of each element (`INTEGRAL_STEPS`).
        steps: u32,
    },
}

impl std::fmt::Display for FormFactorMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FormFactorMethod::AreaIntegral { steps } => write!(f, "area k={steps}"),
        }
    }
}

/// A dense n x n matrix of form factors, stored row by row in f32.
///
/// f32 keeps 7 significant digits, far below the discretisation error of any method here
/// (1e-3 or worse at k = 2), and halves the memory of f64. Sums over rows are taken in f64.
#[derive(Clone, Debug, PartialEq)]
pub struct FormFactorMatrix {
    n: usize,
    data: Vec<f32>,
}

/// Not enough memory for a dense problem.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error(
    "{what} for {n} elements needs {needed_mib:.0} MiB, but only {available_mib:.0} MiB of memory \
     is available; at most {fits} elements would fit (raise MAX_PATCH_AREA or use --max-area)"
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

/// Memory this process may use, in bytes: `MemAvailable` from /proc/meminfo where there is
/// one, otherwise 8 GiB.
pub fn available_memory_bytes() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("MemAvailable:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map(|kib| kib * 1024)
        .unwrap_or(8 << 30)
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
}

impl FormFactorMatrix {
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

    /// Minimum, mean and maximum row sum.
    pub fn row_sums(&self) -> RowSums {
        let sums: Vec<f64> = (0..self.n).map(|i| self.row_sum(i)).collect();
        RowSums {
            min: sums.iter().copied().fold(f64::INFINITY, f64::min),
            mean: sums.iter().sum::<f64>() / self.n.max(1) as f64,
            max: sums.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    /// The largest reciprocity error |A_i F_ij - A_j F_ji| / max(A_i F_ij, A_j F_ji) over all
    /// pairs where either side exceeds 1e-6 of its row (smaller entries are f32 noise).
    pub fn max_reciprocity_error(&self, areas: &[f64]) -> f64 {
        let mut worst: f64 = 0.0;
        for i in 0..self.n {
            for j in i + 1..self.n {
                let a = areas[i] * self.get(i, j);
                let b = areas[j] * self.get(j, i);
                let big = a.max(b);
                if self.get(i, j).max(self.get(j, i)) > 1e-6 {
                    worst = worst.max((a - b).abs() / big);
                }
            }
        }
        worst
    }
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
    let polygons: Vec<&[DVec3]> = scene
        .surfaces
        .iter()
        .map(|s| s.vertices.as_slice())
        .collect();
    let ids: Vec<u32> = (0..polygons.len() as u32).collect();
    PolygonBvh::new(&polygons, &ids)
}

/// Counts the rays cast, for rays-per-second figures.
#[derive(Debug, Default)]
pub struct RayCounter(AtomicU64);

impl RayCounter {
    /// Adds `n` rays.
    pub fn add(&self, n: u64) {
        self.0.fetch_add(n, Ordering::Relaxed);
    }
    /// The rays counted so far.
    pub fn get(&self) -> u64 {
        self.0.load(Ordering::Relaxed)
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
    let n = ctx.mesh.len();
    let mut matrix = FormFactorMatrix::zeros(n)?;
    let areas: Vec<f64> = ctx.mesh.elements.iter().map(|e| e.area).collect();
    let pairs = (n as u64) * (n as u64).saturating_sub(1) / 2;
    run_stage(progress, Stage::FormFactors, pairs, || {
        let FormFactorMethod::AreaIntegral { steps } = method;
        let integrator = area::AreaIntegrator::new(ctx, steps);
        // Upper triangle, row by row, straight into the matrix: F_ij = G_ij / A_i for j > i.
        matrix
            .data
            .par_chunks_mut(n.max(1))
            .enumerate()
            .for_each_init(area::Scratch::default, |scratch, (i, row)| {
                let g = integrator.couplings(i, i + 1..n, rays, scratch);
                for (f, g) in row[i + 1..].iter_mut().zip(g) {
                    *f = (g / areas[i]) as f32;
                }
                progress.advance((n - i - 1) as u64);
            });
        // Lower triangle by reciprocity: F_ji = A_i F_ij / A_j.
        for i in 0..n {
            for j in i + 1..n {
                let g = matrix.data[i * n + j] as f64 * areas[i];
                matrix.data[j * n + i] = (g / areas[j]) as f32;
            }
        }
    });
    Ok(matrix)
}

/// Computes rows `rows` of the matrix (all n columns each), without using reciprocity, so
/// that blocks can be computed independently (on other threads or machines).
pub fn compute_rows(
    ctx: &FormFactorContext,
    method: FormFactorMethod,
    rows: Range<usize>,
    rays: &RayCounter,
) -> RowBlock {
    let n = ctx.mesh.len();
    let FormFactorMethod::AreaIntegral { steps } = method;
    let integrator = area::AreaIntegrator::new(ctx, steps);
    let data: Vec<f32> = rows
        .clone()
        .into_par_iter()
        .map_init(area::Scratch::default, |scratch, i| {
            let a_i = ctx.mesh.elements[i].area;
            let row = integrator.couplings(i, 0..n, rays, scratch);
            row.into_iter()
                .map(|g| (g / a_i) as f32)
                .collect::<Vec<f32>>()
        })
        .flatten_iter()
        .collect();
    RowBlock { rows, data }
}
