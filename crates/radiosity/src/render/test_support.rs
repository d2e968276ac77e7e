//! Scenes, cameras and pixel look-ups shared by the rendering tests.

use glam::{dvec3, DVec3};
use image::RgbImage;

use super::Camera;
use crate::scene::{Rgb, Scene, Surface};

pub(crate) fn scene(surfaces: Vec<Surface>) -> Scene {
    Scene {
        surfaces,
        camera: None,
        lights: Vec::new(),
    }
}

pub(crate) fn surface(name: &str, emission: f64, vertices: Vec<DVec3>) -> Surface {
    Surface {
        name: name.into(),
        emission: Rgb([emission; 3]),
        reflectance: Rgb([0.5; 3]),
        vertices,
        photometry: Default::default(),
    }
}

/// The rectangle [x0, x1] x [z0, z1] in the plane y, facing +y.
pub(crate) fn facing_up(x0: f64, x1: f64, z0: f64, z1: f64, y: f64) -> Vec<DVec3> {
    vec![
        dvec3(x0, y, z0),
        dvec3(x0, y, z1),
        dvec3(x1, y, z1),
        dvec3(x1, y, z0),
    ]
}

/// The rectangle [x0, x1] x [y0, y1] in the plane z, facing -z.
pub(crate) fn facing_minus_z(x0: f64, x1: f64, y0: f64, y1: f64, z: f64) -> Vec<DVec3> {
    vec![
        dvec3(x0, y0, z),
        dvec3(x0, y1, z),
        dvec3(x1, y1, z),
        dvec3(x1, y0, z),
    ]
}

pub(crate) fn cornell_camera(width: u32, height: u32) -> Camera {
    Camera {
        eye: dvec3(278.0, 273.0, -800.0),
        look_at: dvec3(278.0, 273.0, 0.0),
        up: DVec3::Y,
        fov_y_degrees: 39.3077,
        width,
        height,
    }
}

pub(crate) fn test_image_dir() -> Option<std::path::PathBuf> {
    std::env::var_os("RADIOSITY_TEST_IMAGE_DIR").map(Into::into)
}

pub(crate) fn px(img: &RgbImage, x: u32, y: u32) -> [u8; 3] {
    img.get_pixel(x, y).0
}
