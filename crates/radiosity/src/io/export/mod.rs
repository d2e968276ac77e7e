//! Exporters: the scene and its solution written for other tools.
//!
//! * [`gltf`]: the solved mesh with the radiosity baked into vertex colours, as glTF 2.0
//!   (`.glb`, or `.gltf` with a `.bin` buffer beside it).
//! * [`obj`]: the scene's surfaces (not the mesh) as Wavefront OBJ with an MTL file
//!   (`Kd` reflectance, `Ke` emission), which reads back as the same scene.

pub mod gltf;
pub mod obj;
