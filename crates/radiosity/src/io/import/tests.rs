//! The shared face-soup conversion and the dispatch by extension.

use glam::{dvec3, DVec3};

use super::*;
use crate::light::Rgb;

const GREY: SoupMaterial = SoupMaterial {
    name: String::new(),
    reflectance: Rgb([0.5, 0.5, 0.5]),
    emission: Rgb([0.0, 0.0, 0.0]),
    defined_at: None,
};

/// A soup of one object per face list given, each face on its own "line" (1, 2, ...).
fn soup(vertices: &[DVec3], objects: &[(&str, &[&[u32]])]) -> FaceSoup {
    let mut s = FaceSoup {
        file: "test.obj".into(),
        vertices: vertices.to_vec(),
        materials: vec![GREY],
        ..FaceSoup::default()
    };
    let mut line = 0;
    for (o, (name, faces)) in objects.iter().enumerate() {
        s.objects.push(name.to_string());
        for face in faces.iter() {
            line += 1;
            s.faces.push(SoupFace {
                object: o as u32,
                material: 0,
                first: s.indices.len(),
                count: face.len() as u32,
                line,
            });
            s.indices.extend_from_slice(face);
        }
    }
    s
}

fn unit_square() -> Vec<DVec3> {
    vec![
        dvec3(0.0, 0.0, 0.0),
        dvec3(1.0, 0.0, 0.0),
        dvec3(1.0, 1.0, 0.0),
        dvec3(0.0, 1.0, 0.0),
    ]
}

#[test]
fn planar_convex_face_is_kept_whole_with_its_object_name() {
    let (scene, warnings) = soup(&unit_square(), &[("Floor", &[&[0, 1, 2, 3]])])
        .to_scene(1.0)
        .unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(scene.surfaces.len(), 1);
    assert_eq!(scene.surfaces[0].name, "Floor");
    assert_eq!(scene.surfaces[0].vertices, unit_square());
    assert_eq!(scene.surfaces[0].reflectance, Rgb([0.5; 3]));
}

#[test]
fn faces_of_one_object_are_numbered_in_file_order() {
    // The second face leans up from the first's edge (coplanar adjacent faces of one
    // object would be joined into one).
    let mut v = unit_square();
    v.push(dvec3(2.0, 0.0, 1.0));
    v.push(dvec3(2.0, 1.0, 1.0));
    let (scene, _) = soup(
        &v,
        &[
            ("Box", &[&[0, 1, 2, 3], &[1, 4, 5, 2]]),
            ("", &[&[4, 5, 2]]),
        ],
    )
    .to_scene(1.0)
    .unwrap();
    let names: Vec<&str> = scene.surfaces.iter().map(|s| s.name.as_str()).collect();
    // The third face lies on part of the second (not the same polygon): kept.
    assert_eq!(names, ["Box.0", "Box.1", "surface"]);
}

#[test]
fn non_convex_face_is_triangulated_covering_its_area() {
    // An L: the 2 x 2 square less its 1 x 1 top-right quarter, area 3, counter-clockwise
    // seen from +z.
    let l = [
        dvec3(0.0, 0.0, 0.0),
        dvec3(2.0, 0.0, 0.0),
        dvec3(2.0, 1.0, 0.0),
        dvec3(1.0, 1.0, 0.0),
        dvec3(1.0, 2.0, 0.0),
        dvec3(0.0, 2.0, 0.0),
    ];
    let (scene, warnings) = soup(&l, &[("L", &[&[0, 1, 2, 3, 4, 5]])])
        .to_scene(1.0)
        .unwrap();
    // A simple hexagon ear-clips into n - 2 = 4 triangles.
    assert_eq!(scene.surfaces.len(), 4);
    let area: f64 = scene
        .surfaces
        .iter()
        .map(|s| geometry::polygon_area(&s.vertices))
        .sum();
    // Sums of products of small integers and halves: exact in f64 up to rounding.
    assert!((area - 3.0).abs() < 1e-12, "area {area}");
    for s in &scene.surfaces {
        assert_eq!(s.vertices.len(), 3);
        // Each triangle faces +z, as the L does.
        assert!(geometry::polygon_normal(&s.vertices).unwrap().z > 0.999_999);
        assert!(
            s.vertices.iter().all(|v| l.contains(v)),
            "corners are the face's own"
        );
    }
    assert_eq!(scene.surfaces[0].name, "L.0");
    assert_eq!(warnings.len(), 1);
    assert!(
        warnings[0]
            .message
            .contains("1 face was not planar and convex")
            && warnings[0].message.contains("into 4 triangles"),
        "{}",
        warnings[0]
    );
}

#[test]
fn clockwise_non_convex_face_keeps_its_facing() {
    // The same L wound the other way round faces -z: so must its triangles.
    let l = [
        dvec3(0.0, 2.0, 0.0),
        dvec3(1.0, 2.0, 0.0),
        dvec3(1.0, 1.0, 0.0),
        dvec3(2.0, 1.0, 0.0),
        dvec3(2.0, 0.0, 0.0),
        dvec3(0.0, 0.0, 0.0),
    ];
    let (scene, _) = soup(&l, &[("L", &[&[0, 1, 2, 3, 4, 5]])])
        .to_scene(1.0)
        .unwrap();
    for s in &scene.surfaces {
        assert!(geometry::polygon_normal(&s.vertices).unwrap().z < -0.999_999);
    }
}

#[test]
fn non_planar_quad_is_split_into_two_planar_triangles() {
    // One corner lifted by 0.5 over a unit square: far beyond the 0.2% tolerance.
    let v = [
        dvec3(0.0, 0.0, 0.0),
        dvec3(1.0, 0.0, 0.0),
        dvec3(1.0, 1.0, 0.5),
        dvec3(0.0, 1.0, 0.0),
    ];
    let (scene, _) = soup(&v, &[("Sail", &[&[0, 1, 2, 3]])])
        .to_scene(1.0)
        .unwrap();
    assert_eq!(scene.surfaces.len(), 2);
    let area: f64 = scene
        .surfaces
        .iter()
        .map(|s| geometry::polygon_area(&s.vertices))
        .sum();
    // Split along 0-2: two triangles of area sqrt(1.25)/2 each; along 1-3: 0.5 +
    // sqrt(1.25)/2 (cross products worked by hand).
    let h = 1.25f64.sqrt() / 2.0;
    assert!(
        (area - 2.0 * h).abs() < 1e-12 || (area - (0.5 + h)).abs() < 1e-12,
        "area {area}"
    );
    for s in &scene.surfaces {
        assert!(s.vertices.iter().all(|p| v.contains(p)));
        assert!(geometry::polygon_normal(&s.vertices).unwrap().z > 0.0);
    }
}

#[test]
fn degenerate_faces_are_dropped_and_counted() {
    let mut v = unit_square();
    v.push(dvec3(2.0, 0.0, 0.0)); // 4: collinear with 0 and 1
    let s = soup(
        &v,
        &[(
            "Mixed",
            &[&[0, 1, 2, 3], &[0, 1, 4], &[0, 0, 1], &[2, 2, 2, 2]],
        )],
    );
    let (scene, warnings) = s.to_scene(1.0).unwrap();
    assert_eq!(scene.surfaces.len(), 1);
    assert_eq!(scene.surfaces[0].name, "Mixed");
    assert_eq!(warnings.len(), 1);
    let w = warnings[0].to_string();
    assert!(
        w.starts_with("test.obj: warning: dropped 3 degenerate faces"),
        "{w}"
    );
    assert!(
        w.contains("face 2 of object \"Mixed\" (line 2)")
            && w.contains("face 3 of object \"Mixed\" (line 3)")
            && w.contains("face 4 of object \"Mixed\" (line 4)"),
        "{w}"
    );
}

#[test]
fn only_degenerate_faces_is_an_error() {
    let e = soup(&unit_square(), &[("Line", &[&[0, 1, 1]])])
        .to_scene(1.0)
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "test.obj: error: no usable faces: the file has 1 face, and it is degenerate (zero \
         area or fewer than 3 distinct corners)"
    );
}

#[test]
fn index_out_of_range_names_the_face_and_line() {
    let e = soup(&unit_square(), &[("Box", &[&[0, 1, 2], &[0, 2, 7]])])
        .to_scene(1.0)
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "test.obj:2: error: face 2 of object \"Box\": vertex index 7 is out of range (4 \
         vertices can be named there)"
    );
}

#[test]
fn nan_coordinate_names_the_vertex_and_line() {
    let mut s = soup(&unit_square(), &[("Box", &[&[0, 1, 2]])]);
    s.vertices[2].y = f64::NAN;
    s.vertex_lines = vec![10, 11, 12, 13];
    let e = s.to_scene(1.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "test.obj:12: error: vertex 3: the coordinate NaN is not a finite number"
    );
}

#[test]
fn scale_multiplies_coordinates_and_is_range_checked() {
    let s = soup(&unit_square(), &[("Floor", &[&[0, 1, 2, 3]])]);
    let (scene, _) = s.to_scene(0.001).unwrap();
    assert_eq!(scene.surfaces[0].vertices[2], dvec3(0.001, 0.001, 0.0));
    // 1 x 2e30 is beyond the 1e30 limit.
    let e = s.to_scene(2e30).unwrap_err();
    assert!(
        matches!(e, ImportError::OutOfRange { value, .. } if value == 2e30),
        "{e}"
    );
    assert!(matches!(s.to_scene(0.0), Err(ImportError::BadScale { .. })));
    assert!(matches!(
        s.to_scene(f64::NAN),
        Err(ImportError::BadScale { .. })
    ));
}

#[test]
fn reflectance_of_one_or_more_is_refused_naming_the_material() {
    let mut s = soup(&unit_square(), &[("Floor", &[&[0, 1, 2, 3]])]);
    s.materials[0].name = "white".into();
    s.materials[0].reflectance = Rgb([0.5, 1.0, 0.5]);
    s.materials[0].defined_at = Some(("test.mtl".into(), 4));
    let e = s.to_scene(1.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "test.mtl:4: error: material \"white\": the green reflectance is 1; reflectance must \
         be at least 0 and below 1 (a surface cannot reflect all the light it receives, or \
         more)"
    );
    s.materials[0].reflectance = Rgb([0.5; 3]);
    s.materials[0].emission = Rgb([0.0, 0.0, -1.0]);
    assert!(s
        .to_scene(1.0)
        .unwrap_err()
        .to_string()
        .contains("the blue emission is -1"));
}

#[test]
fn a_triangle_given_twice_beside_its_neighbour_is_dropped_not_joined() {
    // Two triangles of a unit square and the first again (QA of issue #16: the first was
    // joined with its neighbour into the square, the copy then matched nothing and stayed:
    // 1.0024 m^2 where the square is 1).
    let (scene, warnings) = soup(
        &unit_square(),
        &[("A", &[&[0, 1, 2], &[0, 2, 3], &[0, 1, 2]])],
    )
    .to_scene(1.0)
    .unwrap();
    let area: f64 = scene
        .surfaces
        .iter()
        .map(|s| crate::geometry::polygon_area(&s.vertices))
        .sum();
    // Exact up to rounding: the two halves of a unit square.
    assert!((area - 1.0).abs() < 1e-12, "area {area}");
    assert!(
        warnings
            .iter()
            .any(|w| w.message.starts_with("dropped 1 face given twice")),
        "{warnings:?}"
    );
}

#[test]
fn a_face_given_twice_is_dropped_with_a_warning() {
    let (scene, warnings) = soup(
        &unit_square(),
        &[("A", &[&[0, 1, 2, 3]]), ("B", &[&[1, 2, 3, 0]])],
    )
    .to_scene(1.0)
    .unwrap();
    assert_eq!(scene.surfaces.len(), 1);
    assert_eq!(warnings.len(), 1);
    // Named by face, as the degenerate faces are (QA of issue #16).
    assert_eq!(
        warnings[0].message,
        "dropped 1 face given twice (the same polygon facing the same way): \"B\" (face 2 of \
         object \"B\", line 2; the same as \"A\", face 1 of object \"A\", line 1)",
        "{}",
        warnings[0]
    );
    // Facing the other way, it is another surface (the back of the first): kept.
    let (scene, warnings) = soup(
        &unit_square(),
        &[("A", &[&[0, 1, 2, 3]]), ("B", &[&[3, 2, 1, 0]])],
    )
    .to_scene(1.0)
    .unwrap();
    assert_eq!(scene.surfaces.len(), 2);
    assert!(warnings.is_empty());
}

#[test]
fn dispatch_by_extension() {
    let o = ImportOptions::default();
    let e = read_any_scene(Path::new("model.stl"), &o).unwrap_err();
    assert_eq!(
        e.to_string(),
        "model.stl: error: cannot tell the scene format from the extension \".stl\": expected \
         .scene, .obj, .gltf, .glb, .dxf or .wrl"
    );
    assert!(matches!(
        read_any_scene(Path::new("noext"), &o),
        Err(ImportError::UnknownFormat { extension, .. }) if extension.is_empty()
    ));
    assert_eq!(Format::of_path(Path::new("A.OBJ")), Some(Format::Obj));
    assert_eq!(Format::of_path(Path::new("a.Glb")), Some(Format::Glb));
    assert_eq!(Format::of_path(Path::new("a.wrl")), Some(Format::Vrml));
    let e = read_any_scene(
        Path::new("x.scene"),
        &ImportOptions {
            scale: -1.0,
            settings: None,
        },
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "error: the scale must be a positive finite number, found -1"
    );
}

#[test]
fn scene_file_scaled_meshes_the_same() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cornell_box.scene");
    let plain = read_any_scene(&path, &ImportOptions::default()).unwrap();
    assert_eq!(
        plain.unit,
        "metres (a .scene file states no unit; metres assumed)"
    );
    assert_eq!(plain.file, read_scene(&path).unwrap());
    let o = ImportOptions {
        scale: 0.5,
        settings: None,
    };
    let half = read_any_scene(&path, &o).unwrap();
    assert_eq!(
        half.unit,
        "metres = the file's numbers x 0.5; unscaled, metres (a .scene file states no \
         unit; metres assumed)"
    );
    // Halving is exact in binary: every coordinate exactly half, the area a quarter.
    assert_eq!(
        half.file.settings.max_patch_area,
        plain.file.settings.max_patch_area / 4.0
    );
    for (a, b) in plain
        .file
        .scene
        .surfaces
        .iter()
        .zip(&half.file.scene.surfaces)
    {
        let halved: Vec<DVec3> = a.vertices.iter().map(|v| *v * 0.5).collect();
        assert_eq!(b.vertices, halved);
    }
    let e = read_any_scene(
        &path,
        &ImportOptions {
            scale: 1e29,
            settings: None,
        },
    )
    .unwrap_err();
    assert!(matches!(e, ImportError::OutOfRange { .. }), "{e}");
    assert!(e.to_string().contains("(after scaling)"), "{e}");
}

#[test]
fn counts_beyond_the_file_are_refused() {
    assert!(check_count("a.glb", 0, "accessor 3", 10, 12, 120).is_ok());
    let e = check_count("a.glb", 0, "accessor 3", 11, 12, 120).unwrap_err();
    assert_eq!(
        e.to_string(),
        "a.glb: error: accessor 3 says 11 items, more than the 120 bytes left in the file can \
         hold (the file is truncated or corrupt)"
    );
    assert!(check_count("a.glb", 0, "x", u64::MAX, u64::MAX, u64::MAX - 1).is_err());
}

#[test]
fn default_settings_give_about_a_thousand_elements() {
    let (scene, _) = soup(&unit_square(), &[("Floor", &[&[0, 1, 2, 3]])])
        .to_scene(1.0)
        .unwrap();
    let s = default_settings(&scene);
    assert_eq!(s.max_patch_area, 1.0 / 1000.0);
    assert_eq!(s.integral_steps, 2);
}

/// Regression (obj fuzz target): a quad with one corner 1e8 times further off than the
/// others passes the polygon checks, but flattened onto its plane two corners fall within
/// the same-point distance (1e-9 of its diameter): it must be dropped as degenerate, not
/// kept as an unusable surface.
#[test]
fn sliver_that_flattening_makes_degenerate_is_dropped() {
    let v = [
        dvec3(213.0, 548.8, 227.0),
        dvec3(213.0, 548.8, 332.0),
        dvec3(0.0, 548.8e8, 332.0),
        dvec3(0.0, 548.8, 227.0),
        dvec3(0.0, 0.0, 0.0),
        dvec3(1.0, 0.0, 0.0),
        dvec3(0.0, 1.0, 0.0),
    ];
    let (scene, _) = soup(&v, &[("Sliver", &[&[0, 1, 2, 3], &[4, 5, 6]])])
        .to_scene(1.0)
        .unwrap();
    for s in &scene.surfaces {
        assert_eq!(
            geometry::validate_polygon(&s.vertices),
            Ok(()),
            "{}",
            s.name
        );
    }
}

#[test]
fn coplanar_adjacent_faces_of_one_object_are_joined_before_meshing() {
    // A unit square given as two triangles (the diagonal 0-2 run both ways): one quad,
    // named after the object alone since it is its only surface.
    let (scene, warnings) = soup(&unit_square(), &[("Quad", &[&[0, 1, 2], &[0, 2, 3]])])
        .to_scene(1.0)
        .unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(scene.surfaces.len(), 1);
    assert_eq!(scene.surfaces[0].name, "Quad");
    assert_eq!(scene.surfaces[0].vertices, unit_square());

    // As a DXF gives them: each triangle with its own copies of the corners (found by
    // position).
    let mut v = unit_square();
    v.extend([unit_square()[0], unit_square()[2]]);
    let (scene, _) = soup(&v, &[("Quad", &[&[0, 1, 2], &[4, 5, 3]])])
        .to_scene(1.0)
        .unwrap();
    assert_eq!(scene.surfaces.len(), 1);
    assert!((crate::geometry::polygon_area(&scene.surfaces[0].vertices) - 1.0).abs() < 1e-15);
}

#[test]
fn faces_of_two_objects_or_two_materials_or_a_bend_stay_apart() {
    // Two objects.
    let (scene, _) = soup(
        &unit_square(),
        &[("A", &[&[0, 1, 2]]), ("B", &[&[0, 2, 3]])],
    )
    .to_scene(1.0)
    .unwrap();
    assert_eq!(scene.surfaces.len(), 2);
    // Two materials.
    let mut s = soup(&unit_square(), &[("A", &[&[0, 1, 2], &[0, 2, 3]])]);
    s.materials.push(SoupMaterial {
        name: "red".into(),
        reflectance: Rgb([0.6, 0.1, 0.1]),
        ..GREY
    });
    s.faces[1].material = 1;
    let (scene, _) = s.to_scene(1.0).unwrap();
    assert_eq!(scene.surfaces.len(), 2);
    assert_eq!(scene.surfaces[1].reflectance, Rgb([0.6, 0.1, 0.1]));
    // A fold of 1 % of the diagonal: two planes.
    let mut bent = unit_square();
    bent[3].z = 0.01;
    let (scene, _) = soup(&bent, &[("A", &[&[0, 1, 2], &[0, 2, 3]])])
        .to_scene(1.0)
        .unwrap();
    assert_eq!(scene.surfaces.len(), 2);
}

#[test]
fn a_scene_in_millimetres_scaled_to_metres_keeps_its_lights_and_lumens() {
    // A 2000 x 1000 mm FLUX 600 panel, a FLUX 1200 box of 1000 mm sides (six faces of
    // 1 m^2), and a point light at (1000, 2000, 3000) mm, read with --scale 0.001.
    let text = "MAX_PATCH_AREA 250000\nINTEGRAL_STEPS 2\nSCENEBEGIN\nPATCHBEGIN\n#Panel\n\
                VERTICES 4\nFLUX 600\nRr 0\nRg 0\nRb 0\nVERTEX0 0 0 0\nVERTEX1 2000 0 0\n\
                VERTEX2 2000 1000 0\nVERTEX3 0 1000 0\nPATCHEND\nBOXBEGIN\n#Lamp\nFACING OUT\n\
                FLUX 1200\nRr 0\nRg 0\nRb 0\nORIGIN 5000 0 0\nSIZE 1000 1000 1000\nBOXEND\n\
                LIGHTBEGIN\n#Down\nPOSITION 1000 2000 3000\nINTENSITY 100\n\
                DISTRIBUTION ISOTROPIC\nLIGHTEND\nSCENEEND\n";
    let dir = std::env::temp_dir().join(format!("radiosity-mm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("mm.scene");
    std::fs::write(&path, text).unwrap();
    let read = |scale: f64| {
        read_any_scene(
            &path,
            &ImportOptions {
                scale,
                settings: None,
            },
        )
        .unwrap()
        .file
    };
    let metres = read(0.001);
    let scene = &metres.scene;
    // The light stands at the scaled position (before: left at 1000, 2000, 3000 "metres").
    assert!((scene.lights[0].position - dvec3(1.0, 2.0, 3.0)).length() < 1e-12);
    // The panel's 600 lm over its 2 m^2: 300 lm/m^2 (before: 600 / 2e6 mm^2).
    assert!((scene.surfaces[0].emission.luminance() - 300.0).abs() < 1e-9);
    // The box's 1200 lm over 6 m^2: 200 lm/m^2 on each face.
    for s in &scene.surfaces[1..] {
        assert!(
            (s.emission.luminance() - 200.0).abs() < 1e-9,
            "{}: {:?}",
            s.name,
            s.emission
        );
    }
    // The lumens emitted are those of the file, at either scale.
    let lumens = |file: &crate::io::scene_file::SceneFile| -> f64 {
        file.scene
            .surfaces
            .iter()
            .map(|s| s.emission.luminance() * geometry::polygon_area(&s.vertices))
            .sum()
    };
    assert!((lumens(&metres) - 1800.0).abs() < 1e-9);
    assert!((lumens(&read(1.0)) - 1800.0).abs() < 1e-9);
    assert!((metres.settings.max_patch_area - 0.25).abs() < 1e-12);
    std::fs::remove_dir_all(&dir).unwrap();
}
