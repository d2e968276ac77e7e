//! Scenes: surfaces with emission and reflectance, the model that the rest of the library
//! works on.
//!
//! A [`Scene`] is the geometry and materials of a scene file, after parsing and checking: a
//! list of planar convex [`Surface`]s. Each surface is one-sided: it emits and reflects only
//! on its front, the side from which its vertices run counter-clockwise (the right-hand-rule
//! normal points out of the front). Every surface occludes from both sides. The file's
//! meshing and integration settings (`MAX_PATCH_AREA`, `INTEGRAL_STEPS`: [`MeshSettings`])
//! are not part of the scene: they come beside it in a [`SceneFile`], and whoever meshes a
//! scene says with which settings.
//!
//! Scene files (the paper's Appendix A format) are read and written by
//! [`crate::io::scene_file`], which also describes the format and its polygon checks.
//! [`cornell_box`] is the built-in Cornell box (`examples/cornell_box.scene`, compiled in),
//! [`building`] generates furnished buildings of any size (both come with their settings, as
//! a [`SceneFile`]), and the box primitive's faces are made here (module `shape`).
//! [`lying_on`] finds the surfaces that lie on others (a rug on a floor; module `overlap`).

use glam::DVec3;

mod builtin;
pub mod generate;
pub mod overlap;
pub(crate) mod shape;

pub use builtin::cornell_box;

/// The largest emission (exitance per band, in the scene's units), luminance, flux or
/// intensity a scene may give (as written: a LUMINANCE L is an exitance of pi L, a small
/// surface's FLUX a larger exitance, both still far from overflowing): the emitted power, summed over surfaces of up to 1e60 units^2
/// ([`crate::geometry::MAX_COORDINATE`] squared), stays finite (QA of issue #16: an `Er`
/// of 1e308 gave energy lines of "inf %").
pub const MAX_EMISSION: f64 = 1e30;
pub use generate::{building, BuildingError, BuildingParams};
pub use overlap::{lying_on, Overlap};

/// The scene file's reader, writer, contents and error, at the paths the command line and
/// the viewer use; they live in [`crate::io::scene_file`].
pub use crate::io::scene_file::{read_scene, write_scene_file, SceneError, SceneFile};

/// The settings a scene file gives beside its scene: see [`crate::mesh::MeshSettings`].
pub use crate::mesh::MeshSettings;

/// Colours of surfaces: see [`crate::light`].
pub use crate::light::Rgb;

/// One planar convex polygon of the scene, as written in a `PATCHBEGIN` ... `PATCHEND` block.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// The patch's `#NAME` line, without the `#`.
    pub name: String,
    /// Emitted exitance E per band (scene units, >= 0).
    pub emission: Rgb,
    /// Diffuse reflectance rho per band, in [0, 1).
    pub reflectance: Rgb,
    /// The corners, counter-clockwise seen from the front; at least 3, planar and convex.
    pub vertices: Vec<DVec3>,
    /// How the scene file gave the emission, and whether the surface is an opening: kept so
    /// that the writer gives the file back as it was written ([`SurfacePhotometry`]).
    pub photometry: SurfacePhotometry,
}

/// How a surface's light was written in its scene file. The values that the solvers use
/// are [`Surface::emission`] and [`Surface::reflectance`]; this only says where they came
/// from, so that a written scene reads back with the same keywords.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfacePhotometry {
    /// The emission's keywords.
    pub emission: EmissionGiven,
    /// `OPENING`: a hole in the model (a window, a roof light) through which light leaves;
    /// its reflectance is 0. With a luminance it is a uniform sky seen through it.
    pub opening: bool,
}

/// The keywords a surface's emission was written with (scene units: lengths in metres make
/// exitances lm/m^2, see [`crate::io::scene_file`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum EmissionGiven {
    /// `Er Eg Eb`: the exitance per band.
    #[default]
    Exitance,
    /// `LUMINANCE L` (cd/m^2): a Lambertian emitter, exitance pi L in every band.
    Luminance(f64),
    /// `FLUX P` (lm): P spread uniformly over the surface, exitance P / area in every band.
    Flux(f64),
    /// A share of a `FLUX P` block spread over several surfaces (a split patch, a box):
    /// exitance P / (the block's area), written back as `Er Eg Eb`. Kept so that `--scale`
    /// can turn the exitance into lm/m^2 of the scaled lengths, as for [`Self::Flux`].
    FluxShare,
}

/// A checked scene: its surfaces (geometry, emission and reflectance), and the camera it
/// suggests. How finely to mesh it is not the scene's to say: see [`MeshSettings`].
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The surfaces, in file order (a box primitive contributes six).
    pub surfaces: Vec<Surface>,
    /// A suggested camera, for scenes that come with one (the built-in Cornell box).
    pub camera: Option<CameraHint>,
    /// The point luminaires (`LIGHTBEGIN` blocks), in file order.
    pub lights: Vec<crate::luminaire::Luminaire>,
}

/// A camera that a scene suggests for rendering it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraHint {
    /// Eye position.
    pub eye: DVec3,
    /// Point looked at.
    pub look_at: DVec3,
    /// Up direction.
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f64,
}

impl Scene {
    /// The smallest axis-aligned box holding every vertex, as (min, max).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        crate::geometry::bounds(
            self.surfaces
                .iter()
                .flat_map(|s| s.vertices.iter().copied()),
        )
    }

    /// The total area of all surfaces (scene units squared).
    pub fn total_area(&self) -> f64 {
        self.surfaces
            .iter()
            .map(|s| crate::geometry::polygon_area(&s.vertices))
            .sum()
    }
}
