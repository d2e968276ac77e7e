//! # radiosity
//!
//! A radiosity renderer after De Angelis, *Radiosity: A Study in Photorealistic Rendering*
//! (1998), built as a library. The pipeline, one module per stage:
//!
//! ```text
//! scene file --io--> Scene + MeshSettings --mesh--> Mesh --form_factor--> FormFactorMatrix
//!   --solve--> element radiosity B (per RGB band) --shade--> vertex radiosity
//!   --render--> image
//! ```
//!
//! * [`scene`]: the scene model: surfaces, the built-in Cornell box, generated buildings
//!   (each with its [`MeshSettings`], as a [`SceneFile`]).
//! * [`geometry`]: planar convex polygon helpers (normal, area, planarity, convexity).
//! * [`mesh`]: area-based subdivision of surfaces into elements (paper 2.4).
//! * [`visibility`]: BVH ray queries over triangles (occlusion and closest hit).
//! * [`form_factor`]: form factors F_ij (paper 1.2, 2.3).
//! * [`light`]: the RGB type of radiosity, emission and reflectance, checked per element.
//! * [`solve`]: (I - rho F) B = E per band: [`Solver`] names every solver with its
//!   settings (dense LU or Gauss-Seidel, paper figure 6; progressive refinement;
//!   hierarchical radiosity).
//! * [`pipeline`]: a meshed scene ([`Prepared`]) and [`pipeline::solve`], the one entry
//!   point that takes any [`Solver`] and returns a [`Solution`] on its own mesh.
//! * [`shade`]: vertex radiosities for smooth shading (paper 2.5).
//! * [`render`]: a CPU ray-cast camera (paper 2.6), exposure and gamma (paper 2.7).
//! * [`render`]: a CPU ray-cast camera (paper 2.6), exposure and gamma (paper 2.7), PNG
//!   images.
//! * [`pathtrace`]: an unbiased diffuse path tracer, the yardstick for radiosity images.
//! * [`photometry`]: luminaire data: IES LM-63 candela tables.
//! * [`validation`]: the CIE 171:2006 analytical cases with references from first principles.
//! * [`progress`]: the one interface long work reports through.
//! * [`io`]: every file read or written: the paper's Appendix A scene format, the
//!   form-factor file (paper 2.8), the per-element solution as CSV or JSON, PNG images.
//!
//! The whole chain, from the built-in Cornell box to an image:
//!
//! ```
//! use radiosity::progress::NoProgress;
//! use radiosity::render::{self, Camera, RenderSettings, Renderer};
//! use radiosity::shade::{self, Exposure};
//! use radiosity::{pipeline, Overrides, Prepared, SolveRequest, Solver};
//!
//! // The box and its file's settings; a coarse mesh keeps the example quick.
//! let file = radiosity::scene::cornell_box();
//! let coarse = Overrides { max_patch_area: Some(20_000.0), integral_steps: Some(1) };
//! let prepared = Prepared::new(file.scene, coarse.apply(file.settings), &NoProgress)?;
//! let request = SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL);
//! let solution = pipeline::solve(&prepared, &request, &mut radiosity::solve::keep_going, &NoProgress)?;
//! // Energy is conserved: what is emitted is absorbed or escapes (the box is closed but
//! // for its open front).
//! assert!(solution.balance.relative_error() < 1e-3);
//!
//! let b = solution.element_rgb();
//! let vertex_b = shade::vertex_radiosity(&solution.mesh, b);
//! let settings = RenderSettings {
//!     exposure_scale: Exposure::Auto.scale(&prepared.scene, &solution.mesh, b),
//!     ..RenderSettings::default()
//! };
//! let camera = Camera::for_scene(&prepared.scene, 64, 64);
//! let image = render::render(&Renderer::new(&solution.mesh), &camera, b, &vertex_b, &settings, &NoProgress);
//! assert_eq!(image.dimensions(), (64, 64));
//! # Ok::<(), radiosity::pipeline::PipelineError>(())
//! ```
//!
//! Conventions used throughout: F_ij is the fraction of the energy leaving element i that
//! arrives at element j; radiosity B and emission E are exitances in the scene's own units
//! (for example W/m^2), per red, green and blue band; reflectance rho is in [0, 1).
#![deny(missing_docs)]

pub mod budget;
pub mod compare;
pub mod form_factor;
pub mod geometry;
pub mod illuminance;
pub mod io;
pub mod light;
pub mod luminaire;
pub mod mesh;
pub mod pathtrace;
pub mod photometry;
pub mod pipeline;
pub mod progress;
pub mod render;
pub mod scene;
pub mod shade;
pub mod solve;
mod splitmix;
pub mod validation;
pub mod visibility;

#[cfg(test)]
mod scale_tests;

/// The solution writer's module at the path the command line uses; it lives in
/// [`io::solution`].
pub use io::solution;

pub use light::{ElementLight, Rgb};
pub use mesh::MeshSettings;
pub use pipeline::{FormFactors, Overrides, PipelineError, Prepared, Solution, SolveRequest};
pub use scene::{Scene, SceneFile};
pub use solve::{DenseSolver, Radiosity, Solver, SolverKind};
