//! Scenes: surfaces with emission and reflectance, in the paper's Appendix A format.
//!
//! A [`Scene`] is what a scene file says, after parsing and checking: meshing settings and a
//! list of planar convex [`Surface`]s. Each surface is one-sided: it emits and reflects only
//! on its front, the side from which its vertices run counter-clockwise (the right-hand-rule
//! normal points out of the front). Every surface occludes from both sides.
//!
//! [`read_scene`] and [`parse_scene`] read the format, [`write_scene`] and
//! [`write_scene_file`] write it, and [`cornell_box`] is the built-in Cornell box
//! (`examples/cornell_box.scene`, compiled in).
//!
//! # The scene format
//!
//! The format is the one of De Angelis, *Radiosity: A Study in Photorealistic Rendering*
//! (1998), Appendix A, with one addition, the box primitive the paper proposes in section
//! 3.1. Each value stands on its own labelled line, in this order:
//!
//! ```text
//! MAX_PATCH_AREA 100        // meshing threshold, scene units squared; > 0, may be decimal
//! INTEGRAL_STEPS 2          // k >= 1, a whole number ("2" or "2.0")
//! SCENEBEGIN
//! PATCHBEGIN
//! #Floor                    // the name: the rest of the line after '#', trimmed
//! VERTICES 4                // n >= 3
//! Er 0.0                    // emission (exitance) per band, >= 0
//! Eg 0.0
//! Eb 0.0
//! Rr 0.5                    // reflectance per band, in [0, 1)
//! Rg 0.5
//! Rb 0.5
//! VERTEX0 0 0 0             // VERTEX0 .. VERTEX(n-1), in order: x y z
//! VERTEX1 1 0 0
//! VERTEX2 1 1 0
//! VERTEX3 0 1 0
//! PATCHEND
//! BOXBEGIN                  // six 4-vertex surfaces NAME.base, NAME.top, NAME.side0..3
//! #Table
//! FACING OUT                // OUT: fronts look away from the box (an object); IN: into it
//! Er 0                      // the same six colour lines as a patch
//! Eg 0
//! Eb 0
//! Rr 0.5
//! Rg 0.5
//! Rb 0.5
//! ORIGIN 1 0 2              // axis-aligned: the minimum corner ...
//! SIZE 2 0.8 1              // ... and the extents (> 0); base = the y-min face
//! BOXEND
//! SCENEEND
//! ```
//!
//! Instead of `ORIGIN` and `SIZE` a box may be given as one face and a height:
//! `VERTICES 4`, `VERTEX0` .. `VERTEX3` (a planar convex quad, the base) and `HEIGHT h`
//! (h > 0); the box is the prism swept from the base along its right-hand-rule normal by h.
//!
//! `//` starts a comment anywhere on a line, blank lines may go anywhere, and keywords are
//! case-insensitive. Numbers are written as Rust reads an `f64` (`1`, `-0.5`, `.5`, `2.`,
//! `1e-3`), and must be finite. Anything else on a line is an error. Every error in a file is
//! reported with its line and column ([`ParseError`], collected in a [`SceneError`]); after an
//! error inside a block the reader skips to the block's end and carries on. Problems with a
//! polygon's shape are reported at its `VERTEX0` line.
//!
//! # Polygon checks and planarity
//!
//! Every polygon must have distinct corners and a non-zero area, be convex, and be planar: a
//! polygon is accepted when no corner is further from its best-fit plane (Newell normal
//! through the corner mean) than [`PLANARITY_TOLERANCE`] (0.2 %) of its diameter, and its
//! corners are then projected onto that plane. Measured data needs the tolerance: the
//! Cornell box's red (left) wall is 0.80 mm out of plane over a 783.5 mm diagonal (0.10 %).
//! Flattening it would move each corner 0.80 mm off its neighbours' and open gaps that rays
//! slip through, so the built-in box gives that wall as the two triangles of its measured
//! corners instead (exactly planar, watertight). Corners are only moved when they are more than 1e-12 of the diameter
//! off the plane, so reading a written scene changes nothing and `read(write(scene))`
//! gives back `scene` bit for bit (for scenes whose coordinates are not many thousands of
//! times larger than their polygons).

use glam::DVec3;

mod builtin;
pub mod generate;
mod lex;
mod parse;
mod shape;
mod write;

pub use builtin::cornell_box;
pub use generate::{building, BuildingParams};
pub use parse::{parse_scene, read_scene, ParseError, SceneError};
pub use shape::PLANARITY_TOLERANCE;
pub use write::{write_scene, write_scene_file};

/// Colours of surfaces: see [`crate::light`].
pub use crate::light::Rgb;

/// The meshing and integration settings at the top of a scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSettings {
    /// `MAX_PATCH_AREA`: surfaces larger than this (scene units squared) are subdivided into
    /// elements of at most this area.
    pub max_patch_area: f64,
    /// `INTEGRAL_STEPS`: k, the number of sample points along each axis of each element in
    /// the double area integral (paper 2.8; 1 means one point per element).
    pub integral_steps: u32,
}

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
}

/// A checked scene: settings and surfaces.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Meshing and integration settings.
    pub settings: MeshSettings,
    /// The surfaces, in file order (a box primitive contributes six).
    pub surfaces: Vec<Surface>,
    /// A suggested camera, for scenes that come with one (the built-in Cornell box).
    pub camera: Option<CameraHint>,
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
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in self.surfaces.iter().flat_map(|s| s.vertices.iter()) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        (lo, hi)
    }

    /// The total area of all surfaces (scene units squared).
    pub fn total_area(&self) -> f64 {
        self.surfaces
            .iter()
            .map(|s| crate::geometry::polygon_area(&s.vertices))
            .sum()
    }
}
