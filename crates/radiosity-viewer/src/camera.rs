//! The walking camera: keys move the eye, mouse drags turn the view, the wheel changes
//! the speed. A plain struct with no window in it, so that it can be tested.

use glam::DVec3;
use radiosity::render::Camera;

/// Which movement keys are held (W/S or Up/Down, A/D or Left/Right, Q/E or
/// PageUp/PageDown).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MoveKeys {
    /// Along the view direction.
    pub forward: bool,
    /// Against the view direction.
    pub back: bool,
    /// To the left of the view.
    pub left: bool,
    /// To the right of the view.
    pub right: bool,
    /// Along the world's up direction.
    pub up: bool,
    /// Against the world's up direction.
    pub down: bool,
}

impl MoveKeys {
    /// True when any key is held.
    pub fn any(&self) -> bool {
        self.forward || self.back || self.left || self.right || self.up || self.down
    }
}

/// A fly-through camera: an eye, a unit view direction and the world's up direction.
///
/// Movement is at `speed` scene units per second in the direction the held keys add up to
/// (normalised, so two keys at once do not go faster): forward and back along the view
/// direction, left and right along the view's horizontal right vector, up and down along
/// the world's up. Turning: `radians_per_pixel` per pixel dragged, yaw about the world's up,
/// pitch about the right vector, never closer than 1 degree to straight up or down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraController {
    /// Eye position, scene units.
    pub eye: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Unit world up (the scene camera's up).
    pub world_up: DVec3,
    /// Vertical field of view, degrees.
    pub fov_y_degrees: f64,
    /// Scene units per second.
    pub speed: f64,
    /// Turn per pixel of mouse drag, radians.
    pub radians_per_pixel: f64,
}

/// Each wheel step multiplies (or divides) the speed by this.
pub const SPEED_STEP: f64 = 1.25;

impl CameraController {
    /// Starts where `camera` is, with a speed that crosses a scene of diagonal
    /// `scene_diagonal` in 4 seconds.
    pub fn new(camera: &Camera, scene_diagonal: f64) -> CameraController {
        let (forward, _, _) = camera.basis();
        let world_up = camera.up.try_normalize().unwrap_or(DVec3::Y);
        CameraController {
            eye: camera.eye,
            forward,
            world_up,
            fov_y_degrees: camera.fov_y_degrees,
            speed: (scene_diagonal / 4.0).max(1e-6),
            radians_per_pixel: 0.004,
        }
    }

    /// The horizontal unit vector to the right of the view.
    pub fn right(&self) -> DVec3 {
        self.forward
            .cross(self.world_up)
            .try_normalize()
            .unwrap_or_else(|| self.forward.any_orthonormal_vector())
    }

    /// Moves the eye for `dt` seconds with `keys` held.
    pub fn update(&mut self, keys: MoveKeys, dt: f64) {
        let axis = |plus: bool, minus: bool| f64::from(u8::from(plus)) - f64::from(u8::from(minus));
        let dir = self.forward * axis(keys.forward, keys.back)
            + self.right() * axis(keys.right, keys.left)
            + self.world_up * axis(keys.up, keys.down);
        if let Some(dir) = dir.try_normalize() {
            self.eye += dir * (self.speed * dt);
        }
    }

    /// Turns the view by a mouse drag of (`dx`, `dy`) pixels (right and down positive):
    /// dragging right turns right, dragging down looks down.
    pub fn look(&mut self, dx: f64, dy: f64) {
        let yaw = glam::DQuat::from_axis_angle(self.world_up, -dx * self.radians_per_pixel);
        let mut forward = yaw * self.forward;
        let right = forward
            .cross(self.world_up)
            .try_normalize()
            .unwrap_or(self.right());
        let pitched = glam::DQuat::from_axis_angle(right, -dy * self.radians_per_pixel) * forward;
        // Keep away from the poles, where yaw would be undefined.
        if pitched.dot(self.world_up).abs() < 1f64.to_radians().cos() {
            forward = pitched;
        }
        self.forward = forward.normalize();
    }

    /// Changes the speed by `steps` wheel steps (positive: faster).
    pub fn scroll(&mut self, steps: f64) {
        self.speed *= SPEED_STEP.powf(steps);
    }

    /// The camera for an image of `width` x `height` pixels.
    pub fn camera(&self, width: u32, height: u32) -> Camera {
        Camera {
            eye: self.eye,
            look_at: self.eye + self.forward,
            up: self.world_up,
            fov_y_degrees: self.fov_y_degrees,
            width,
            height,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn controller() -> CameraController {
        let cam = Camera {
            eye: DVec3::new(1.0, 2.0, 3.0),
            look_at: DVec3::new(1.0, 2.0, 10.0),
            up: DVec3::Y,
            fov_y_degrees: 60.0,
            width: 100,
            height: 100,
        };
        let mut c = CameraController::new(&cam, 8.0);
        assert_eq!(c.speed, 2.0, "a diagonal of 8 crossed in 4 s");
        c.speed = 3.0;
        c
    }

    fn moved(keys: MoveKeys, dt: f64) -> DVec3 {
        let mut c = controller();
        c.update(keys, dt);
        c.eye - DVec3::new(1.0, 2.0, 3.0)
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn each_key_moves_speed_times_dt_along_its_axis() {
        let dt = 0.1;
        let k = MoveKeys::default;
        let cases = [
            (
                MoveKeys {
                    forward: true,
                    ..k()
                },
                DVec3::Z,
            ),
            (MoveKeys { back: true, ..k() }, -DVec3::Z),
            // Looking along +z with +y up, right is -x (right = forward x up).
            (MoveKeys { right: true, ..k() }, -DVec3::X),
            (MoveKeys { left: true, ..k() }, DVec3::X),
            (MoveKeys { up: true, ..k() }, DVec3::Y),
            (MoveKeys { down: true, ..k() }, -DVec3::Y),
        ];
        for (keys, dir) in cases {
            let d = moved(keys, dt);
            assert!(
                close(d, dir * 0.3),
                "{keys:?}: moved {d}, expected {}",
                dir * 0.3
            );
        }
    }

    #[test]
    fn two_keys_move_diagonally_at_the_same_speed_and_opposites_cancel() {
        let d = moved(
            MoveKeys {
                forward: true,
                up: true,
                ..Default::default()
            },
            1.0,
        );
        assert!((d.length() - 3.0).abs() < 1e-12, "{d}");
        assert!((d.y - d.z).abs() < 1e-12, "{d}");
        let d = moved(
            MoveKeys {
                forward: true,
                back: true,
                ..Default::default()
            },
            1.0,
        );
        assert_eq!(d, DVec3::ZERO);
    }

    #[test]
    fn starts_where_renders_default_camera_is() {
        let scene = radiosity::scene::cornell_box().scene;
        let cam = Camera::for_scene(&scene, 640, 480);
        let c = CameraController::new(&cam, 1000.0);
        let back = c.camera(640, 480);
        assert_eq!(back.eye, cam.eye);
        assert_eq!(back.fov_y_degrees, cam.fov_y_degrees);
        let (f0, r0, u0) = cam.basis();
        let (f1, r1, u1) = back.basis();
        assert!(close(f0, f1) && close(r0, r1) && close(u0, u1), "{f0} {f1}");
    }

    #[test]
    fn wheel_scales_speed_and_drag_turns() {
        let mut c = controller();
        c.scroll(2.0);
        assert!((c.speed - 3.0 * SPEED_STEP * SPEED_STEP).abs() < 1e-12);
        c.scroll(-2.0);
        assert!((c.speed - 3.0).abs() < 1e-12);
        // A quarter turn to the right: from +z to -x.
        let pixels = std::f64::consts::FRAC_PI_2 / c.radians_per_pixel;
        c.look(pixels, 0.0);
        assert!(
            close(c.forward, -DVec3::X) || (c.forward + DVec3::X).length() < 1e-9,
            "{}",
            c.forward
        );
        // Dragging down looks down.
        c.look(0.0, 10.0);
        assert!(c.forward.y < 0.0);
        // Never over the pole.
        c.look(0.0, -1e6);
        assert!(c.forward.y < 1.0 && c.forward.is_normalized());
        let cam = c.camera(64, 32);
        assert_eq!((cam.width, cam.height), (64, 32));
        assert!(close(cam.look_at - cam.eye, c.forward));
    }
}
