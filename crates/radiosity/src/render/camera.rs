//! The pinhole camera of the walkthrough (paper section 2.6, "Walkthrough Ability"): an eye,
//! a point to look at, an up direction and a vertical field of view, and the image it
//! makes. [`Camera::basis`] gives its frame, [`Camera::ray_direction`] the ray through an
//! image point and [`Camera::project`] the way back from a scene point to the image. Where
//! to put the camera when the user gives none ([`Camera::for_scene`]) is in `camera/auto.rs`.

use glam::DVec3;

use crate::scene::CameraHint;

mod auto;

pub use auto::{in_top_quarter, z_is_up, DEFAULT_FOV_Y_DEGREES};

/// A pinhole camera (right-handed): `forward = normalize(look_at - eye)`,
/// `right = normalize(forward x up)`, `true_up = right x forward`. Image pixel (x, y) has
/// y = 0 at the top row and x = 0 at the left column.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: DVec3,
    /// The point at the centre of the image.
    pub look_at: DVec3,
    /// Up direction; need not be perpendicular to the view direction (nor unit).
    pub up: DVec3,
    /// Vertical field of view, degrees (in (0, 180)).
    pub fov_y_degrees: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// The camera a scene suggests, at the given image size.
    pub fn from_hint(hint: &CameraHint, width: u32, height: u32) -> Camera {
        Camera {
            eye: hint.eye,
            look_at: hint.look_at,
            up: hint.up,
            fov_y_degrees: hint.fov_y_degrees,
            width,
            height,
        }
    }

    /// The unit vectors (forward, right, true_up) of the camera frame. When `up` is parallel
    /// to the view direction another up (+z, or +x) is used.
    pub fn basis(&self) -> (DVec3, DVec3, DVec3) {
        let forward = (self.look_at - self.eye)
            .try_normalize()
            .unwrap_or(DVec3::Z);
        let mut right = forward.cross(self.up);
        if right.length_squared() < 1e-20 * self.up.length_squared().max(1e-300) {
            let alt = if forward.z.abs() < 0.9 {
                DVec3::Z
            } else {
                DVec3::X
            };
            right = forward.cross(alt);
        }
        let right = right.normalize();
        (forward, right, right.cross(forward))
    }

    /// tan of half the vertical field of view.
    fn tan_half(&self) -> f64 {
        (0.5 * self.fov_y_degrees.to_radians()).tan()
    }

    fn aspect(&self) -> f64 {
        self.width.max(1) as f64 / self.height.max(1) as f64
    }

    /// The unit direction of the ray through image point (x, y), in pixels from the image's
    /// top-left corner (the centre of pixel (i, j) is (i + 0.5, j + 0.5)).
    pub fn ray_direction(&self, x: f64, y: f64) -> DVec3 {
        self.direction_in(self.screen(), x, y)
    }

    /// The camera frame scaled to the image plane at distance 1: (forward, the right edge's
    /// offset, the top edge's offset), computed once per image rather than per ray.
    pub(in crate::render) fn screen(&self) -> (DVec3, DVec3, DVec3) {
        let (forward, right, up) = self.basis();
        let t = self.tan_half();
        (forward, right * (t * self.aspect()), up * t)
    }

    pub(in crate::render) fn direction_in(
        &self,
        (forward, right, up): (DVec3, DVec3, DVec3),
        x: f64,
        y: f64,
    ) -> DVec3 {
        let sx = 2.0 * x / self.width.max(1) as f64 - 1.0;
        let sy = 1.0 - 2.0 * y / self.height.max(1) as f64;
        (forward + sx * right + sy * up).normalize()
    }

    /// Where `p` appears in the image, as (x, y) in pixels from the top-left corner, or
    /// `None` when it is not in front of the eye.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let (forward, right, up) = self.basis();
        let d = p - self.eye;
        let z = d.dot(forward);
        if z <= 0.0 {
            return None;
        }
        let t = self.tan_half();
        let sx = d.dot(right) / (z * t * self.aspect());
        let sy = d.dot(up) / (z * t);
        Some((
            0.5 * (sx + 1.0) * self.width as f64,
            0.5 * (1.0 - sy) * self.height as f64,
        ))
    }

    /// The angle one pixel subtends (vertically, at the image centre), radians.
    pub fn pixel_angle(&self) -> f64 {
        2.0 * self.tan_half() / self.height.max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::test_support::cornell_camera;
    use glam::dvec3;

    #[test]
    fn cornell_camera_orientation() {
        let cam = cornell_camera(200, 100);
        let (f, r, u) = cam.basis();
        assert!((f - DVec3::Z).length() < 1e-15);
        assert!((r + DVec3::X).length() < 1e-15); // image right is scene -x
        assert!((u - DVec3::Y).length() < 1e-15);
        // The look-at point is the image centre.
        let (x, y) = cam.project(cam.look_at).unwrap();
        assert!((x - 100.0).abs() < 1e-9 && (y - 50.0).abs() < 1e-9);
        // The red wall (x = 556) is on the left, the green wall (x = 0) on the right.
        let (red_x, _) = cam.project(dvec3(556.0, 273.0, 0.0)).unwrap();
        let (green_x, _) = cam.project(dvec3(0.0, 273.0, 0.0)).unwrap();
        assert!(red_x < 100.0 && green_x > 100.0);
        // Larger y is nearer the top (smaller row index).
        let (_, high) = cam.project(dvec3(278.0, 500.0, 0.0)).unwrap();
        let (_, low) = cam.project(dvec3(278.0, 50.0, 0.0)).unwrap();
        assert!(high < 50.0 && low > 50.0);
        assert!(cam.project(dvec3(278.0, 273.0, -900.0)).is_none());
        // The ray through a projected point leads back to it.
        let p = dvec3(400.0, 100.0, 300.0);
        let (x, y) = cam.project(p).unwrap();
        let d = cam.ray_direction(x, y);
        assert!((d - (p - cam.eye).normalize()).length() < 1e-12);
    }
}
