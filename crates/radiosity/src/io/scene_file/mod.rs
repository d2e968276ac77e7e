//! The scene file: the paper's Appendix A format, read into a [`SceneFile`] (the meshing
//! settings and the [`Scene`]) and written back.
//!
//! [`read_scene`] and [`parse_scene`] read the format, [`write_scene`] and
//! [`write_scene_file`] write a scene with the settings given beside it. The built-in
//! Cornell box ([`crate::scene::cornell_box`]) is `examples/cornell_box.scene`, compiled in
//! and read by [`parse_scene`].
//!
//! # The scene format
//!
//! The format is the one of De Angelis, *Radiosity: A Study in Photorealistic Rendering*
//! (1998), Appendix A, with two additions, the box primitive the paper proposes in section
//! 3.1 and the sphere, cylinder and cone it wishes for there. Each value stands on its own labelled line, in this order:
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
//! Spheres, cylinders and cones (the primitives the paper wishes for in section 3.1) are
//! blocks like the box, tessellated into planar quads and triangles whose corners lie on
//! the exact shape:
//!
//! ```text
//! SPHEREBEGIN               // NAME.0, NAME.1, ...: n segments round the y axis times
//! #Ball                     // max(2, n/2) bands from the bottom pole up; triangles at the
//! FACING OUT                // poles, quads between
//! Er 0                      // the same six colour lines as a patch
//! Eg 0
//! Eb 0
//! Rr 0.5
//! Rg 0.5
//! Rb 0.5
//! CENTER 0 1 0              // the centre
//! RADIUS 0.5                // > 0
//! RESOLUTION 16             // optional: n, from 3 to 512 (16 when left out)
//! SPHEREEND
//! CYLINDERBEGIN             // NAME.base, NAME.top, NAME.side0 .. side(n-1)
//! ...                       // #NAME, FACING, the colours, as above
//! CENTER 2 0 0              // the centre of the base disc; the axis runs up +y from it
//! RADIUS 0.3
//! HEIGHT 1.2                // > 0
//! RESOLUTION 12             // optional
//! CYLINDEREND
//! CONEBEGIN                 // NAME.base, NAME.side0 .. side(n-1); the apex at CENTER + HEIGHT y
//! ...
//! CONEEND
//! ```
//!
//! # Photometric units, openings and point luminaires
//!
//! Scene lengths are metres (unless `--scale` says otherwise); `Er Eg Eb` are luminous
//! exitances in lm/m^2 per band, and photometric reports give Y = 0.2126 R + 0.7152 G +
//! 0.0722 B ([`crate::light::Rgb::luminance`]). In any block, instead of the three
//! emission lines, `LUMINANCE L` (cd/m^2) makes a Lambertian emitter of exitance pi L in
//! every band, and `FLUX P` (lm) spreads P uniformly over the block's surfaces (exitance P /
//! their area). Instead of the three reflectance lines, `OPENING` makes the block an
//! opening: reflectance 0 in every band, light leaves the room through it; with a
//! `LUMINANCE` it is a uniform sky seen through a window or roof light:
//!
//! ```text
//! PATCHBEGIN
//! #Window
//! VERTICES 4
//! LUMINANCE 3000            // cd/m^2 (a sky); or FLUX 1200 (lm over the patch)
//! OPENING                   // reflectance 0
//! VERTEX0 ...
//! PATCHEND
//! ```
//!
//! The writer gives these keywords back (a `FLUX` spread over several surfaces, a box's or
//! a split patch's, is written as each surface's exitance). Point luminaires are blocks of
//! their own ([`crate::luminaire`]), with `#NAME` first and the other lines in any order:
//!
//! ```text
//! LIGHTBEGIN
//! #Downlight
//! POSITION 2 2 3
//! AIM 0 0 -1              // the axis of the distribution (a direction; default 0 0 -1: -z)
//! INTENSITY 1000          // cd on the axis; or FLUX 10000 (lm in all directions)
//! DISTRIBUTION COSINE     // ISOTROPIC | COSINE (I0 cos theta, nothing above 90 deg) | IES file.ies
//! COLOUR 1 1 1            // optional filter per band, multiplying the output (COLOR is read too)
//! LIGHTEND
//! ```
//!
//! A patch may have any number of vertices (3 or more). One that is planar but not convex,
//! with an outline that does not cross itself (an L, a dart), is split into triangles
//! `NAME.0`, `NAME.1`, ... (ear clipping on its plane); a crossing outline (a bow tie, most
//! likely corners in the wrong order) is an error, as below.
//!
//! `//` starts a comment anywhere on a line, blank lines may go anywhere, and keywords are
//! case-insensitive. Numbers are written as Rust reads an `f64` (`1`, `-0.5`, `.5`, `2.`,
//! `1e-3`), and must be finite. Anything else on a line is an error. Every error in a file is
//! reported with its line and column ([`ParseError`], collected in a [`SceneError`]); after an
//! error inside a block the reader skips to the block's end and carries on. Problems with a
//! polygon's shape ([`crate::geometry::PolygonError`]) are reported at its `VERTEX0` line.
//!
//! # Polygon checks and planarity
//!
//! Every polygon must have distinct corners and a non-zero area, be convex, and be planar: a
//! polygon is accepted when no corner is further from its best-fit plane (Newell normal
//! through the corner mean) than [`PLANARITY_TOLERANCE`](crate::geometry::PLANARITY_TOLERANCE) (0.2 %) of its diameter, and its
//! corners are then projected onto that plane. Measured data needs the tolerance: the
//! Cornell box's red (left) wall is 0.80 mm out of plane over a 783.5 mm diagonal (0.10 %).
//! Flattening it would move each corner 0.80 mm off its neighbours' and open gaps that rays
//! slip through, so the built-in box gives that wall as the two triangles of its measured
//! corners instead (exactly planar, watertight). Corners are only moved when they are more than 1e-12 of the diameter
//! off the plane, so reading a written scene changes nothing and `read(write(scene))`
//! gives back `scene` bit for bit (for scenes whose coordinates are not many thousands of
//! times larger than their polygons).

mod lex;
mod polygon;
mod read;
mod write;

pub(crate) use read::duplicate_surfaces;
pub use read::{parse_scene, read_scene, ParseError, SceneError};
pub use write::{write_scene, write_scene_file};

use crate::mesh::MeshSettings;
use crate::scene::Scene;

/// What a scene file holds: the settings of its first two lines (`MAX_PATCH_AREA`,
/// `INTEGRAL_STEPS`) and the scene between `SCENEBEGIN` and `SCENEEND`. The built-in and
/// generated scenes come the same way ([`crate::scene::cornell_box`],
/// [`crate::scene::building`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFile {
    /// How the file says to mesh and integrate its scene.
    pub settings: MeshSettings,
    /// The surfaces (and, for the built-in box, a camera).
    pub scene: Scene,
}
