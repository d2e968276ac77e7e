//! The built-in Cornell box, from the scene file `examples/cornell_box.scene`.

use glam::dvec3;

use super::CameraHint;
use crate::io::scene_file::{parse_scene, SceneFile};

/// The text of `examples/cornell_box.scene`, compiled in.
const CORNELL_BOX_SCENE: &str = include_str!("../../../../examples/cornell_box.scene");

/// The Cornell box (Cornell University Program of Computer Graphics measurements, in
/// millimetres), with the Cornell camera: eye at (278, 273, -800) looking along +z, a 35 mm
/// lens on 25 mm film (vertical field of view 2 atan(12.5/35), about 39.31 degrees).
///
/// The scene is `examples/cornell_box.scene`, compiled in, with that file's settings
/// (`MAX_PATCH_AREA` 1000 mm^2, `INTEGRAL_STEPS` 2); a test checks that it parses.
pub fn cornell_box() -> SceneFile {
    let mut file = parse_scene(CORNELL_BOX_SCENE, "examples/cornell_box.scene (built in)")
        .unwrap_or_else(|e| panic!("the built-in Cornell box does not parse:\n{e}"));
    file.scene.camera = Some(CameraHint {
        eye: dvec3(278.0, 273.0, -800.0),
        look_at: dvec3(278.0, 273.0, 0.0),
        up: dvec3(0.0, 1.0, 0.0),
        fov_y_degrees: 2.0 * (12.5f64 / 35.0).atan().to_degrees(),
    });
    file
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{self, polygon_centroid, polygon_normal};
    use crate::scene::Scene;
    use glam::DVec3;

    fn surface<'s>(scene: &'s Scene, name: &str) -> &'s super::super::Surface {
        scene
            .surfaces
            .iter()
            .find(|s| s.name == name)
            .unwrap_or_else(|| panic!("no surface {name}"))
    }

    #[test]
    fn embedded_file_parses() {
        let SceneFile { settings, scene } =
            parse_scene(CORNELL_BOX_SCENE, "cornell_box.scene").unwrap();
        // Light, 4 ceiling pieces, floor, back and green walls, the red wall's two
        // triangles, 5 + 5 block faces.
        assert_eq!(scene.surfaces.len(), 20);
        assert_eq!(settings.max_patch_area, 1000.0);
        assert_eq!(settings.integral_steps, 2);
        assert_eq!(scene.camera, None);
        // The built-in box is that file, with the camera added.
        let built_in = cornell_box();
        assert_eq!(built_in.settings, settings);
        assert_eq!(built_in.scene.surfaces, scene.surfaces);
    }

    #[test]
    fn camera_is_the_cornell_camera() {
        let cam = cornell_box().scene.camera.unwrap();
        assert_eq!(cam.eye, dvec3(278.0, 273.0, -800.0));
        assert_eq!(cam.look_at, dvec3(278.0, 273.0, 0.0));
        assert_eq!(cam.up, DVec3::Y);
        assert!(
            (cam.fov_y_degrees - 39.3076).abs() < 1e-3,
            "{}",
            cam.fov_y_degrees
        );
    }

    #[test]
    fn light_and_colours() {
        let scene = cornell_box().scene;
        let light = surface(&scene, "Light");
        let pi = std::f64::consts::PI;
        assert_eq!(light.emission.0, [17.0 * pi, 12.0 * pi, 4.0 * pi]);
        let emitters = scene
            .surfaces
            .iter()
            .filter(|s| s.emission.max_band() > 0.0);
        assert_eq!(emitters.count(), 1);
        assert_eq!(surface(&scene, "Floor").reflectance.0, [0.725, 0.71, 0.68]);
        assert_eq!(
            surface(&scene, "Left wall (red) lower").reflectance.0,
            [0.63, 0.065, 0.05]
        );
        assert_eq!(
            surface(&scene, "Right wall (green)").reflectance.0,
            [0.14, 0.45, 0.091]
        );
    }

    #[test]
    fn ceiling_has_a_hole_the_size_of_the_light() {
        let scene = cornell_box().scene;
        let ceiling: f64 = scene
            .surfaces
            .iter()
            .filter(|s| s.name.starts_with("Ceiling"))
            .map(|s| geometry::polygon_area(&s.vertices))
            .sum();
        let light = geometry::polygon_area(&surface(&scene, "Light").vertices);
        assert!((light - 130.0 * 105.0).abs() < 1e-9);
        assert!((ceiling + light - 556.0 * 559.2).abs() < 1e-6);
    }

    // The measured red wall is 0.80 mm out of plane; as two triangles of its measured
    // corners it stays watertight with its neighbours (no corner moves).
    #[test]
    fn red_wall_is_two_triangles_of_its_measured_corners() {
        let scene = cornell_box().scene;
        let lower = &surface(&scene, "Left wall (red) lower").vertices;
        let upper = &surface(&scene, "Left wall (red) upper").vertices;
        let measured = [
            dvec3(552.8, 0.0, 0.0),
            dvec3(549.6, 0.0, 559.2),
            dvec3(556.0, 548.8, 559.2),
            dvec3(556.0, 548.8, 0.0),
        ];
        let deviation = geometry::max_plane_deviation(&measured);
        let diameter = geometry::diameter(&measured);
        assert!((deviation - 0.80).abs() < 0.005, "{deviation}");
        assert!((diameter - 783.5).abs() < 0.05, "{diameter}");
        assert_eq!(lower, &vec![measured[0], measured[1], measured[2]]);
        assert_eq!(upper, &vec![measured[0], measured[2], measured[3]]);
        // Together they cover the quad: the same area to the quad's out-of-plane fold
        // (0.8 mm over 556 mm changes the area by far less than 1e-4 of it).
        let quad = geometry::polygon_area(&measured);
        let pair = geometry::polygon_area(lower) + geometry::polygon_area(upper);
        assert!((pair - quad).abs() < 1e-4 * quad, "{pair} vs {quad}");
    }

    #[test]
    fn every_face_looks_into_the_room_or_out_of_its_block() {
        let scene = cornell_box().scene;
        let room_centre = dvec3(278.0, 274.4, 279.6);
        let short_centre = dvec3(185.5, 82.5, 169.0);
        let tall_centre = dvec3(368.5, 165.0, 351.25);
        for s in &scene.surfaces {
            let n = polygon_normal(&s.vertices).unwrap();
            let c = polygon_centroid(&s.vertices);
            let outward = if s.name.starts_with("Short block") {
                (c - short_centre).dot(n)
            } else if s.name.starts_with("Tall block") {
                (c - tall_centre).dot(n)
            } else {
                (room_centre - c).dot(n)
            };
            assert!(outward > 0.0, "{} faces the wrong way", s.name);
            assert!(geometry::is_convex(&s.vertices), "{}", s.name);
        }
        let normal = |name: &str| polygon_normal(&surface(&scene, name).vertices).unwrap();
        let along = |name: &str, axis: DVec3| {
            let d = normal(name).dot(axis);
            assert!(d > 1.0 - 1e-12, "{name}: {d}");
        };
        along("Floor", DVec3::Y);
        along("Light", -DVec3::Y);
        for piece in ["front", "back", "red side", "green side"] {
            along(&format!("Ceiling {piece}"), -DVec3::Y);
        }
        along("Back wall", -DVec3::Z);
        along("Right wall (green)", DVec3::X);
        assert!(normal("Left wall (red) lower").x < -0.999);
        assert!(normal("Left wall (red) upper").x < -0.999);
        along("Short block top", DVec3::Y);
        along("Tall block top", DVec3::Y);
    }

    #[test]
    fn element_count() {
        let SceneFile { settings, scene } = cornell_box();
        let mesh = crate::mesh::mesh_scene(&scene, settings.max_patch_area).unwrap();
        println!(
            "Cornell box at MAX_PATCH_AREA 1000: {} elements",
            mesh.len()
        );
        assert!((1500..3000).contains(&mesh.len()), "{}", mesh.len());
    }
}
