//! The modeller's data: surface colours and their undo history.
//!
//! Form factors depend only on geometry (paper 1.2), so a reflectance or emission edit
//! needs only a new solve of (I - rho F) B = E: the worker re-solves with the library's
//! Gauss-Seidel on the cached matrix, starting from the previous solution (a warm start:
//! after a small edit the old B is already close, so far fewer sweeps are needed than from
//! B = E). BENCHMARKS.md compares it with refactoring the LU.

use std::path::{Path, PathBuf};

use glam::DVec3;
use radiosity::mesh::Mesh;
use radiosity::scene::{Rgb, Scene};
use radiosity::visibility::PolygonBvh;

/// The colours of one surface: what the modeller edits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceColours {
    /// Reflectance per band, in [0, 1).
    pub reflectance: Rgb,
    /// Emission (exitance) per band, >= 0.
    pub emission: Rgb,
}

/// One undoable change: a surface and its colours before the change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edit {
    /// The surface's index in the scene.
    pub surface: usize,
    /// Its colours before.
    pub before: SurfaceColours,
}

/// A scene being edited, with its undo history.
#[derive(Clone, Debug)]
pub struct Modeller {
    /// The scene as edited.
    pub scene: Scene,
    undo: Vec<Edit>,
    /// The number of edits since the last save.
    pub unsaved: usize,
}

/// The largest reflectance the modeller lets a colour picker set (the scene format
/// requires rho < 1).
pub const MAX_REFLECTANCE: f64 = 0.99;

impl Modeller {
    /// Starts editing `scene`.
    pub fn new(scene: Scene) -> Modeller {
        Modeller {
            scene,
            undo: Vec::new(),
            unsaved: 0,
        }
    }

    /// The colours of surface `s`.
    pub fn colours(&self, s: usize) -> SurfaceColours {
        let surface = &self.scene.surfaces[s];
        SurfaceColours {
            reflectance: surface.reflectance,
            emission: surface.emission,
        }
    }

    /// Sets surface `s`'s colours (reflectance clamped to [0, MAX_REFLECTANCE], emission
    /// to at least 0). `merge` folds the change into the previous edit when that was of the same
    /// surface (one undo step per drag of a colour picker). Returns false when nothing
    /// changed.
    pub fn set(&mut self, s: usize, colours: SurfaceColours, merge: bool) -> bool {
        let clean = SurfaceColours {
            reflectance: Rgb(colours.reflectance.0.map(|x| x.clamp(0.0, MAX_REFLECTANCE))),
            emission: Rgb(colours
                .emission
                .0
                .map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 })),
        };
        let before = self.colours(s);
        if clean == before {
            return false;
        }
        if !(merge && self.undo.last().is_some_and(|e| e.surface == s)) {
            self.undo.push(Edit { surface: s, before });
        }
        let surface = &mut self.scene.surfaces[s];
        surface.reflectance = clean.reflectance;
        surface.emission = clean.emission;
        self.unsaved += 1;
        true
    }

    /// Undoes the last edit; returns the surface it changed.
    pub fn undo(&mut self) -> Option<usize> {
        let edit = self.undo.pop()?;
        let surface = &mut self.scene.surfaces[edit.surface];
        surface.reflectance = edit.before.reflectance;
        surface.emission = edit.before.emission;
        self.unsaved += 1;
        Some(edit.surface)
    }

    /// The number of edits that can be undone.
    pub fn undo_len(&self) -> usize {
        self.undo.len()
    }
}

/// The surface `--select NAME` picks: of the surfaces whose name starts with `prefix`, one
/// named exactly so, else the first in the file that can be seen, else the first. A surface
/// can be seen when some element of `mesh` (the mesh as solved: buried pieces already left
/// out) has its centre on no other surface: the base of a sofa standing on the floor, or a
/// cupboard's side against a wall, is hidden by what it touches, and selecting it would
/// show nothing. At most the first 64 candidates are tested.
pub fn select_by_name(scene: &Scene, mesh: &Mesh, prefix: &str) -> Option<usize> {
    let candidates: Vec<usize> = scene
        .surfaces
        .iter()
        .enumerate()
        .filter(|(_, s)| s.name.starts_with(prefix))
        .map(|(i, _)| i)
        .collect();
    if let Some(&exact) = candidates
        .iter()
        .find(|&&i| scene.surfaces[i].name == prefix)
    {
        return Some(exact);
    }
    let first = *candidates.first()?;
    let visible = candidates
        .iter()
        .take(64)
        .copied()
        .find(|&s| surface_visible(scene, mesh, s));
    Some(visible.unwrap_or(first))
}

/// True when some element of surface `s` in `mesh` has its centre on no other surface
/// (see [`select_by_name`]).
fn surface_visible(scene: &Scene, mesh: &Mesh, s: usize) -> bool {
    let elements: Vec<_> = mesh
        .elements
        .iter()
        .filter(|e| e.surface as usize == s)
        .collect();
    if elements.is_empty() {
        return false;
    }
    let (polygons, ids): (Vec<&[DVec3]>, Vec<u32>) = scene
        .surfaces
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != s)
        .map(|(i, surface)| (surface.vertices.as_slice(), i as u32))
        .unzip();
    if polygons.is_empty() {
        return true;
    }
    let others = PolygonBvh::new(&polygons, &ids);
    // Touching means at no distance: a millionth of the scene's size covers f64 rounding
    // of coordinates, and no face meant to be seen lies that close to another.
    let tolerance = 1e-6 * others.scale().max(f64::MIN_POSITIVE);
    elements
        .iter()
        .any(|e| others.polygon_at(e.centroid, tolerance).is_none())
}

/// Where the window's "save scene" (and Ctrl+S) writes unless the user types another
/// path: never over the file opened (a shipped example would be overwritten by one key),
/// but `<stem>-edited.scene` in the current directory; `cornell-edited.scene` for the
/// built-in box. Typing the opened file's own path saves over it.
pub fn default_save_path(opened: Option<&Path>) -> PathBuf {
    let stem = opened
        .and_then(Path::file_stem)
        .map_or("cornell".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from(format!("{stem}-edited.scene"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity::form_factor::FormFactorMatrix;
    use radiosity::pipeline::{
        self, FormFactors, Overrides, Prepared, SolutionReport, SolveRequest,
    };
    use radiosity::progress::NoProgress;
    use radiosity::scene::cornell_box;
    use radiosity::solve::{keep_going, DenseSolver, GaussSeidelSettings, Solver};

    /// Gauss-Seidel to a relative residual of 1e-10 on `f`, from `start` or B = E: B and
    /// the sweeps made.
    fn gauss_seidel(
        prepared: &Prepared,
        f: &FormFactorMatrix,
        start: Option<&[Rgb]>,
    ) -> (Vec<Rgb>, usize) {
        let request = SolveRequest {
            solver: Solver::Dense(DenseSolver::GaussSeidel(GaussSeidelSettings {
                tolerance: 1e-10,
                max_iterations: 10_000,
            })),
            form_factors: FormFactors::Matrix(f),
            start,
            adapt: None,
        };
        let solution = pipeline::solve(prepared, &request, &mut keep_going, &NoProgress).unwrap();
        let SolutionReport::Matrix(report) = solution.report else {
            panic!("a dense solve reports as one")
        };
        (solution.radiosity.0, report.iterations.unwrap())
    }

    #[test]
    fn edits_undo_in_order_and_a_drag_is_one_step() {
        let mut m = Modeller::new(cornell_box().scene);
        let original = m.colours(0);
        let red = SurfaceColours {
            reflectance: Rgb([0.9, 0.1, 0.1]),
            emission: Rgb::BLACK,
        };
        assert!(m.set(0, red, false));
        let mut redder = red;
        redder.reflectance.0[0] = 1.5; // clamped
        assert!(m.set(0, redder, true));
        assert_eq!(m.colours(0).reflectance.0[0], MAX_REFLECTANCE);
        assert_eq!(m.undo_len(), 1, "a drag is one undo step");
        assert!(!m.set(0, m.colours(0), false), "no change, no edit");
        let other = m.colours(1);
        assert!(m.set(1, red, true), "another surface is its own step");
        assert_eq!(m.undo_len(), 2);
        assert_eq!(m.undo(), Some(1));
        assert_eq!(m.colours(1), other);
        assert_eq!(m.undo(), Some(0));
        assert_eq!(m.colours(0), original);
        assert_eq!(m.undo(), None);
    }

    #[test]
    fn saved_edits_read_back_in_the_papers_format() {
        let file = cornell_box();
        let mut m = Modeller::new(file.scene);
        let s = m
            .scene
            .surfaces
            .iter()
            .position(|s| s.name == "Floor")
            .unwrap();
        let colours = SurfaceColours {
            reflectance: Rgb([0.25, 0.5, 0.125]),
            emission: Rgb([1.5, 0.0, 3.25]),
        };
        m.set(s, colours, false);
        let path =
            std::env::temp_dir().join(format!("radiosity-modeller-{}.scene", std::process::id()));
        radiosity::scene::write_scene_file(&m.scene, file.settings, &path).unwrap();
        let back = radiosity::scene::read_scene(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert_eq!(back.settings, file.settings);
        let back = back.scene;
        assert_eq!(back.surfaces[s].reflectance, colours.reflectance);
        assert_eq!(back.surfaces[s].emission, colours.emission);
        assert_eq!(back.surfaces.len(), m.scene.surfaces.len());
    }

    /// The modeller's re-solve after a reflectance change equals a fresh full solve of the
    /// edited scene.
    ///
    /// Both stop at a relative change (or residual) of 1e-10 of max |E|; with rho <= 0.8 and
    /// row sums <= 1 the error of each is at most 1e-10 / (1 - 0.8) = 5e-10 of max |E|, so
    /// they must agree within 1e-9 of max |E| (checked at 2e-9: f32 rows are read the same
    /// way by both, so no other error enters).
    #[test]
    fn resolve_after_a_reflectance_edit_equals_a_fresh_solve() {
        let file = cornell_box();
        let mut scene = file.scene;
        let overrides = Overrides {
            max_patch_area: Some(8000.0),
            integral_steps: Some(2),
        };
        let settings = overrides.apply(file.settings);
        let mut prepared = Prepared::new(scene.clone(), settings, &NoProgress).unwrap();
        let (f, _) = prepared.form_factors(&NoProgress).unwrap();
        let (first, _) = gauss_seidel(&prepared, &f, None);

        // Paint the tall block blue-ish and the floor darker.
        let mut modeller = Modeller::new(prepared.scene.clone());
        let edited: Vec<usize> = modeller
            .scene
            .surfaces
            .iter()
            .enumerate()
            .filter(|(_, s)| {
                s.name.to_lowercase().contains("floor") || s.name.to_lowercase().contains("tall")
            })
            .map(|(i, _)| i)
            .collect();
        assert!(
            !edited.is_empty(),
            "the Cornell box has a floor and a tall block"
        );
        for &s in &edited {
            let mut c = modeller.colours(s);
            c.reflectance = Rgb([0.2, 0.3, 0.75]);
            modeller.set(s, c, false);
        }
        scene.surfaces = modeller.scene.surfaces.clone();
        let colours: Vec<_> = scene
            .surfaces
            .iter()
            .map(|s| (s.reflectance, s.emission))
            .collect();
        prepared.recolour(&colours).unwrap();
        let (b, warm_sweeps) = gauss_seidel(&prepared, &f, Some(&first));

        // A fresh full solve of the edited scene, form factors computed anew.
        let fresh_prepared = Prepared::new(scene, settings, &NoProgress).unwrap();
        let (f2, _) = fresh_prepared.form_factors(&NoProgress).unwrap();
        assert_eq!(
            f2.as_slice(),
            f.as_slice(),
            "form factors do not depend on colours"
        );
        let (fresh, cold_sweeps) = gauss_seidel(&fresh_prepared, &f2, None);
        let max_e = fresh_prepared
            .light
            .emission()
            .iter()
            .fold(0.0f64, |m, e| m.max(e.max_band()));
        // Both stop at a relative residual of 1e-10; with rho <= 0.8 and row sums <= 1 the
        // error of each is at most 1e-10 / (1 - 0.8) = 5e-10 of max |E|, so they agree
        // within 1e-9 of max |E| (checked at 2e-9).
        let mut worst = 0.0f64;
        for (bi, fi) in b.iter().zip(&fresh) {
            for k in 0..3 {
                worst = worst.max((bi[k] - fi[k]).abs() / max_e);
            }
        }
        assert!(
            worst < 2e-9,
            "re-solve vs fresh solve: largest difference {worst:e} of max E \
             ({} elements, {warm_sweeps} sweeps warm)",
            b.len(),
        );
        // And the LU solve agrees too (exact up to rounding).
        let request = SolveRequest {
            form_factors: FormFactors::Matrix(&f2),
            ..SolveRequest::new(Solver::LU)
        };
        let lu = pipeline::solve(&fresh_prepared, &request, &mut keep_going, &NoProgress)
            .unwrap()
            .radiosity;
        for (i, bi) in b.iter().enumerate() {
            for (x, y) in bi.0.iter().zip(lu.element(i).0) {
                assert!(
                    (x - y).abs() / max_e < 2e-9,
                    "element {i}: re-solve {x}, LU {y}"
                );
            }
        }
        // The warm start saves sweeps.
        assert!(
            warm_sweeps <= cold_sweeps,
            "warm {warm_sweeps} vs cold {cold_sweeps}"
        );
    }

    /// The furnished example room, meshed as the window meshes it.
    fn room() -> (Scene, Mesh) {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/room.scene");
        let options = radiosity::io::import::ImportOptions {
            scale: 1.0,
            settings: None,
        };
        let file = radiosity::io::import::read_any_scene(&path, &options)
            .unwrap()
            .file;
        let prepared = Prepared::new(file.scene, file.settings, &NoProgress).unwrap();
        (prepared.scene.clone(), (*prepared.mesh).clone())
    }

    #[test]
    fn select_by_name_picks_a_surface_that_can_be_seen() {
        let (scene, mesh) = room();
        let name = |i: usize| scene.surfaces[i].name.clone();
        let index = |n: &str| scene.surfaces.iter().position(|s| s.name == n).unwrap();
        // The sofa's seat stands on the floor: its base lies on the floor's plane and is
        // hidden; its top is open to the room.
        assert!(!surface_visible(&scene, &mesh, index("Sofa seat.base")));
        assert!(surface_visible(&scene, &mesh, index("Sofa seat.top")));
        assert!(surface_visible(&scene, &mesh, index("Floor")));
        let sofa = select_by_name(&scene, &mesh, "Sofa").unwrap();
        assert!(name(sofa).starts_with("Sofa"), "{}", name(sofa));
        assert!(surface_visible(&scene, &mesh, sofa), "{}", name(sofa));
        assert!(!name(sofa).ends_with(".base"), "{}", name(sofa));
        // An exact name is taken as asked, hidden or not; no match is none.
        assert_eq!(
            select_by_name(&scene, &mesh, "Sofa seat.base"),
            Some(index("Sofa seat.base"))
        );
        assert_eq!(select_by_name(&scene, &mesh, "Piano"), None);
    }

    #[test]
    fn default_save_path_is_never_the_opened_file() {
        let opened = std::path::Path::new("examples/room.scene");
        let save = default_save_path(Some(opened));
        assert_eq!(save, std::path::PathBuf::from("room-edited.scene"));
        assert_ne!(save, opened);
        assert_eq!(
            default_save_path(None),
            std::path::PathBuf::from("cornell-edited.scene")
        );
        // An imported model is saved in the scene format, not over the model.
        assert_eq!(
            default_save_path(Some(std::path::Path::new("model.obj"))),
            std::path::PathBuf::from("model-edited.scene")
        );
    }
}
