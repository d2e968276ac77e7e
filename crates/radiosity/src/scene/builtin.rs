//! The built-in Cornell box, from the scene file `examples/cornell_box.scene`.

use glam::dvec3;

use super::{parse_scene, CameraHint, Scene};

/// The text of `examples/cornell_box.scene`, compiled in.
const CORNELL_BOX_SCENE: &str = include_str!("../../../../examples/cornell_box.scene");

/// The Cornell box (Cornell University Program of Computer Graphics measurements, in
/// millimetres), with the Cornell camera: eye at (278, 273, -800) looking along +z, a 35 mm
/// lens on 25 mm film (vertical field of view 2 atan(12.5/35), about 39.31 degrees).
///
/// The scene is `examples/cornell_box.scene`, compiled in; a test checks that it parses.
pub fn cornell_box() -> Scene {
    let mut scene = parse_scene(CORNELL_BOX_SCENE, "examples/cornell_box.scene (built in)")
        .unwrap_or_else(|e| panic!("the built-in Cornell box does not parse:\n{e}"));
    scene.camera = Some(CameraHint {
        eye: dvec3(278.0, 273.0, -800.0),
        look_at: dvec3(278.0, 273.0, 0.0),
        up: dvec3(0.0, 1.0, 0.0),
        fov_y_degrees: 2.0 * (12.5f64 / 35.0).atan().to_degrees(),
    });
    scene
}
