//! The scene's surfaces as Wavefront OBJ with a material library (MTL) beside it
//! (`radiosity export SCENE -o out.obj`), for round trips and for modelling tools.
//!
//! What is written: the input surfaces, not the mesh. `out.obj` names `mtllib out.mtl`,
//! then per surface an object `o NAME` (the surface's name; `surfaceK` for an unnamed
//! surface K, counted from 0), its corners as `v x y z` in order, `usemtl`, and one face
//! `f` through all its corners (counter-clockwise from the front, as in the scene). The
//! MTL holds one material per distinct pair of colours, `Kd` the reflectance rho and `Ke`
//! the emission E per band, in the scene's units (both unclamped). Numbers are written in
//! the shortest form that reads back to the same f64, so an importer that reads `Kd` as
//! reflectance and `Ke` as emission gets the same scene back. The meshing settings
//! (`MAX_PATCH_AREA`, `INTEGRAL_STEPS`) are not part of OBJ: they are written as comments.
//! Both files are written atomically ([`crate::io::write_atomically`]), the MTL first.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use crate::mesh::MeshSettings;
use crate::scene::Scene;

/// The material library that goes with the OBJ file `path`: `NAME.mtl` beside `NAME.obj`.
pub fn mtl_path(path: &Path) -> PathBuf {
    path.with_extension("mtl")
}

/// The name an OBJ `o` line gives surface `index` named `name`: the name, or `surfaceK`
/// when it is empty (OBJ statements need a value).
fn object_name(index: usize, name: &str) -> String {
    if name.trim().is_empty() {
        format!("surface{index}")
    } else {
        name.to_string()
    }
}

/// Writes `scene`'s surfaces to `path` and its materials to [`mtl_path`]`(path)` (module
/// documentation).
pub fn write_obj(path: &Path, scene: &Scene, settings: Option<MeshSettings>) -> io::Result<()> {
    let mtl = mtl_path(path);
    let mtl_name = mtl
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| io::Error::other("the output has no file name"))?;
    // One material per distinct (reflectance, emission), by exact value.
    let mut materials: Vec<([f64; 3], [f64; 3])> = Vec::new();
    let material_of: Vec<usize> = scene
        .surfaces
        .iter()
        .map(|s| {
            let key = (s.reflectance.0, s.emission.0);
            let bits = |k: &([f64; 3], [f64; 3])| {
                k.0.map(f64::to_bits) == key.0.map(f64::to_bits)
                    && k.1.map(f64::to_bits) == key.1.map(f64::to_bits)
            };
            materials.iter().position(bits).unwrap_or_else(|| {
                materials.push(key);
                materials.len() - 1
            })
        })
        .collect();
    let header = concat!("# radiosity ", env!("CARGO_PKG_VERSION"));
    crate::io::write_atomically(&mtl, |w| {
        writeln!(
            w,
            "{header}: Kd is the reflectance, Ke the emission (exitance) per band"
        )?;
        for (m, (rho, e)) in materials.iter().enumerate() {
            writeln!(w, "\nnewmtl m{m}")?;
            writeln!(w, "Kd {} {} {}", rho[0], rho[1], rho[2])?;
            writeln!(w, "Ke {} {} {}", e[0], e[1], e[2])?;
        }
        Ok(())
    })?;
    crate::io::write_atomically(path, |w| {
        writeln!(
            w,
            "{header}: {} surfaces, one face each",
            scene.surfaces.len()
        )?;
        if let Some(s) = settings {
            writeln!(w, "# MAX_PATCH_AREA {}", s.max_patch_area)?;
            writeln!(w, "# INTEGRAL_STEPS {}", s.integral_steps)?;
        }
        writeln!(w, "mtllib {mtl_name}")?;
        let mut next = 1usize;
        for (i, s) in scene.surfaces.iter().enumerate() {
            writeln!(w, "\no {}", object_name(i, &s.name))?;
            for v in &s.vertices {
                writeln!(w, "v {} {} {}", v.x, v.y, v.z)?;
            }
            writeln!(w, "usemtl m{}", material_of[i])?;
            write!(w, "f")?;
            for k in 0..s.vertices.len() {
                write!(w, " {}", next + k)?;
            }
            writeln!(w)?;
            next += s.vertices.len();
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Rgb, Surface};
    use glam::dvec3;

    #[test]
    fn tobj_reads_back_the_surfaces_and_their_colours() {
        // The built-in Cornell box: quads, a triangle pair, named surfaces, one light.
        let scene = crate::scene::cornell_box().scene;
        let mut scene = scene;
        // An unnamed pentagon with a colour no other surface has.
        scene.surfaces.push(Surface {
            name: String::new(),
            emission: Rgb([0.1, 0.2, 0.3]),
            reflectance: Rgb([0.25, 0.5, 0.125]),
            vertices: vec![
                dvec3(0., 0., -1.),
                dvec3(1., 0., -1.),
                dvec3(1.5, 1., -1.),
                dvec3(0.5, 2., -1.),
                dvec3(-0.5, 1., -1.),
            ],
            photometry: Default::default(),
        });
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("box.obj");
        write_obj(&path, &scene, None).unwrap();
        assert!(dir.path().join("box.mtl").exists());
        let (models, materials) = tobj::load_obj(&path, &tobj::LoadOptions::default()).unwrap();
        let materials = materials.unwrap();
        assert_eq!(models.len(), scene.surfaces.len());
        for (i, (model, surface)) in models.iter().zip(&scene.surfaces).enumerate() {
            let want_name = if surface.name.is_empty() {
                format!("surface{i}")
            } else {
                surface.name.clone()
            };
            assert_eq!(model.name, want_name);
            let m = &model.mesh;
            // One face through all the corners, in order.
            assert_eq!(m.face_arities.len().max(1), 1, "{}", model.name);
            assert_eq!(m.positions.len(), 3 * surface.vertices.len());
            for (k, v) in surface.vertices.iter().enumerate() {
                for a in 0..3 {
                    // tobj reads f32: the scene's f64 to f32 rounding.
                    assert_eq!(m.positions[3 * m.indices[k] as usize + a], v[a] as f32);
                }
            }
            let mat = &materials[m.material_id.unwrap()];
            assert_eq!(
                mat.diffuse.unwrap(),
                surface.reflectance.0.map(|x| x as f32)
            );
            assert_eq!(mat.emissive.unwrap(), surface.emission.0.map(|x| x as f32));
        }
        // The Cornell box's surfaces share few colour pairs: materials are not repeated.
        assert!(materials.len() < scene.surfaces.len());
    }
}

#[cfg(test)]
mod round_trip {
    use super::*;
    use crate::io::import::{read_any_scene, ImportOptions};

    #[test]
    fn scene_to_obj_to_scene_gives_the_same_surfaces() {
        // The built-in Cornell box (quads, a wall given as two triangles, a light) and the
        // committed furnished room: every surface comes back with its name, its corners in
        // order, bit for bit (the writer's numbers are the shortest exact form) and its
        // colours.
        let room = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/room.scene");
        let scenes = [
            crate::scene::cornell_box().scene,
            crate::scene::read_scene(&room).unwrap().scene,
        ];
        let dir = tempfile::tempdir().unwrap();
        for (k, scene) in scenes.iter().enumerate() {
            let path = dir.path().join(format!("scene{k}.obj"));
            write_obj(&path, scene, None).unwrap();
            let back = read_any_scene(&path, &ImportOptions::default()).unwrap();
            assert!(back.warnings.is_empty(), "{:?}", back.warnings);
            let got = &back.file.scene.surfaces;
            assert_eq!(got.len(), scene.surfaces.len(), "scene {k}");
            for (a, b) in scene.surfaces.iter().zip(got) {
                assert_eq!(a.name, b.name);
                assert_eq!(a.vertices, b.vertices, "{}", a.name);
                assert_eq!(a.reflectance, b.reflectance, "{}", a.name);
                assert_eq!(a.emission, b.emission, "{}", a.name);
            }
        }
    }
}
