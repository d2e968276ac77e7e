//! Every file the library reads or writes, one module per format, so that the rest of the
//! library deals only in its own types: a [`Scene`](crate::scene::Scene), a
//! [`FormFactorMatrix`](crate::form_factor::FormFactorMatrix), a solution, an image.
//!
//! * [`scene_file`]: the paper's Appendix A scene format, reader and writer.
//! * [`form_factor_file`]: the form-factor matrix, written once and read back (paper 2.8).
//! * [`solution`]: the per-element solution as CSV or JSON, for scripts.
//! * [`surface_report`]: the per-surface report (area, mean, min and max radiosity,
//!   luminance) as CSV.
//! * [`path_traced_file`]: a path-traced view (means, standard errors, emitter mask, the
//!   camera and settings) as OpenEXR, so that a reference is traced once.
//! * [`export`]: the solved scene as glTF (vertex colours) and the scene as OBJ + MTL.
//! * [`import`]: scenes from other tools' formats (OBJ + MTL, ...), by the file's
//!   extension, converted to a [`Scene`](crate::scene::Scene) through one shared face-soup
//!   conversion; [`import::read_any_scene`] reads any supported file, `.scene` included.
//! * [`png`]: rendered images as PNG files.
//! * [`exr`]: linear images (radiance, no exposure, clamping or gamma) as OpenEXR files.
//! * [`write_atomically`]: how every writer here replaces a file, so that a reader sees the
//!   old file or the whole new one, never half of one; it never replaces a file that a
//!   reader here has read ([`inputs`]).
//!
//! Importers and exporters of other formats (OBJ, glTF, ...) belong here too, one module
//! each beside [`scene_file`], converting to and from the scene model of [`crate::scene`].

mod atomic_write;
pub mod export;
pub mod exr;
pub mod form_factor_file;
pub mod import;
pub mod inputs;
pub mod path_traced_file;
pub mod png;
pub mod scene_file;
pub mod solution;
pub mod surface_report;

pub use atomic_write::{check_writable, is_same_file, link_target, write_atomically};
pub use inputs::{input_at, note_input, protect_inputs, release_input};
