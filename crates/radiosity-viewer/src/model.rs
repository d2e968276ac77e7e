//! The modeller's data: surface colours, their undo history, and the re-solve that turns a
//! colour change into new radiosities from the cached form factors.
//!
//! Form factors depend only on geometry (paper 1.2), so a reflectance or emission edit
//! needs only a new solve of (I - rho F) B = E. [`resolve`] runs Gauss-Seidel sweeps
//! starting from the previous solution (a warm start): after a small edit the old B is
//! already close, so far fewer sweeps are needed than from B = E. BENCHMARKS.md compares
//! it with refactoring the LU.

use std::time::{Duration, Instant};

use radiosity::form_factor::FormFactorMatrix;
use radiosity::scene::{Rgb, Scene};

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

/// How a re-solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResolveReport {
    /// Gauss-Seidel sweeps made.
    pub sweeps: usize,
    /// The last sweep's largest change relative to max |E| (an upper bound on the relative
    /// residual after it; see radiosity's `solve::gauss_seidel`).
    pub change: f64,
    /// Wall-clock time.
    pub elapsed: Duration,
    /// False when it was stopped by `observer` or ran out of sweeps.
    pub converged: bool,
}

/// Gauss-Seidel sweeps B_i <- E_i + rho_i sum_j F_ij B_j over all three bands, in place,
/// starting from the `b` given (the previous solution: a warm start), until the largest
/// change in a sweep relative to max |E| is below `tolerance` or `max_sweeps` sweeps are
/// done. After each sweep `observer` gets the current B and the sweep's change and may stop
/// the solve by returning false (the window shows intermediate solutions this way).
///
/// The change in a sweep bounds the residual after it (radiosity's Gauss-Seidel uses the
/// same test), and the error of B is at most residual / (1 - max rho * max row sum).
///
/// # Panics
/// If the lengths of `reflectance`, `emission` and `b` differ from `f.n()`.
pub fn resolve(
    f: &FormFactorMatrix,
    reflectance: &[[f64; 3]],
    emission: &[[f64; 3]],
    b: &mut [[f64; 3]],
    tolerance: f64,
    max_sweeps: usize,
    mut observer: impl FnMut(&[[f64; 3]], f64) -> bool,
) -> ResolveReport {
    let n = f.n();
    assert!(reflectance.len() == n && emission.len() == n && b.len() == n);
    let start = Instant::now();
    let scale = emission
        .iter()
        .flat_map(|e| e.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 {
        // Nothing emits: B = 0 exactly.
        b.iter_mut().for_each(|x| *x = [0.0; 3]);
        observer(b, 0.0);
        return ResolveReport {
            sweeps: 0,
            change: 0.0,
            elapsed: start.elapsed(),
            converged: true,
        };
    }
    let mut change = f64::INFINITY;
    for sweep in 1..=max_sweeps {
        let mut largest = 0.0f64;
        for i in 0..n {
            let h = row_dot3(f.row(i), b);
            for k in 0..3 {
                let new = emission[i][k] + reflectance[i][k] * h[k];
                largest = largest.max((new - b[i][k]).abs());
                b[i][k] = new;
            }
        }
        change = largest / scale;
        let done = change < tolerance;
        let go_on = observer(b, change);
        if done || !go_on {
            return ResolveReport {
                sweeps: sweep,
                change,
                elapsed: start.elapsed(),
                converged: done,
            };
        }
    }
    ResolveReport {
        sweeps: max_sweeps,
        change,
        elapsed: start.elapsed(),
        converged: false,
    }
}

/// sum_j F_ij B_j for the three bands, with four independent partial sums per band so that
/// the additions do not wait on each other (about twice as fast as one running sum; the
/// rounding differs from it by a few ulps).
fn row_dot3(row: &[f32], b: &[[f64; 3]]) -> [f64; 3] {
    let mut acc = [[0.0f64; 3]; 4];
    let (rows, row_rest) = row.as_chunks::<4>();
    let (bs, b_rest) = b[..row.len()].as_chunks::<4>();
    for (f4, b4) in rows.iter().zip(bs) {
        for l in 0..4 {
            let fij = f4[l] as f64;
            for k in 0..3 {
                acc[l][k] += fij * b4[l][k];
            }
        }
    }
    for (&fij, bj) in row_rest.iter().zip(b_rest) {
        for k in 0..3 {
            acc[0][k] += fij as f64 * bj[k];
        }
    }
    std::array::from_fn(|k| (acc[0][k] + acc[1][k]) + (acc[2][k] + acc[3][k]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity::pipeline::{Overrides, Prepared};
    use radiosity::progress::NoProgress;
    use radiosity::scene::cornell_box;
    use radiosity::solve::{self, element_properties, Solver};

    #[test]
    fn edits_undo_in_order_and_a_drag_is_one_step() {
        let mut m = Modeller::new(cornell_box());
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
        let mut m = Modeller::new(cornell_box());
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
        radiosity::scene::write_scene_file(&m.scene, &path).unwrap();
        let back = radiosity::scene::read_scene(&path).unwrap();
        let _ = std::fs::remove_file(&path);
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
        let mut scene = cornell_box();
        let prepared = Prepared::new(
            scene.clone(),
            Overrides {
                max_patch_area: Some(8000.0),
                integral_steps: Some(2),
            },
            &NoProgress,
        )
        .unwrap();
        let (f, _) = prepared.form_factors(&NoProgress).unwrap();
        let (rho, e) = element_properties(&prepared.mesh, &prepared.scene);
        let mut b = e.clone();
        let first = resolve(&f, &rho, &e, &mut b, 1e-10, 10_000, |_, _| true);
        assert!(first.converged);

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
        let (rho2, e2) = element_properties(&prepared.mesh, &modeller.scene);
        let warm = resolve(&f, &rho2, &e2, &mut b, 1e-10, 10_000, |_, _| true);
        assert!(warm.converged);

        // A fresh full solve of the edited scene, by the library.
        let fresh_prepared = Prepared::new(
            scene,
            Overrides {
                max_patch_area: Some(8000.0),
                integral_steps: Some(2),
            },
            &NoProgress,
        )
        .unwrap();
        let (f2, _) = fresh_prepared.form_factors(&NoProgress).unwrap();
        assert_eq!(
            f2.as_slice(),
            f.as_slice(),
            "form factors do not depend on colours"
        );
        let fresh = fresh_prepared
            .solve(
                &f2,
                Solver::GaussSeidel {
                    tolerance: 1e-10,
                    max_iterations: 10_000,
                },
                &NoProgress,
            )
            .unwrap();
        let max_e = e2.iter().flatten().fold(0.0f64, |m, x| m.max(*x));
        let mut worst = 0.0f64;
        for (i, bi) in b.iter().enumerate() {
            let fi = fresh.radiosity.element(i);
            for k in 0..3 {
                worst = worst.max((bi[k] - fi[k]).abs() / max_e);
            }
        }
        assert!(
            worst < 2e-9,
            "re-solve vs fresh solve: largest difference {worst:e} of max E \
             ({} elements, {} sweeps warm)",
            b.len(),
            warm.sweeps
        );
        // And the LU solve agrees too (exact up to rounding).
        let lu = solve::solve(&f2, &rho2, &e2, Solver::Lu, &NoProgress)
            .unwrap()
            .0;
        for (i, bi) in b.iter().enumerate() {
            for (x, y) in bi.iter().zip(lu.element(i)) {
                assert!(
                    (x - y).abs() / max_e < 2e-9,
                    "element {i}: re-solve {x}, LU {y}"
                );
            }
        }
        // The warm start saves sweeps.
        let mut cold = e2.clone();
        let from_e = resolve(&f, &rho2, &e2, &mut cold, 1e-10, 10_000, |_, _| true);
        assert!(
            warm.sweeps <= from_e.sweeps,
            "warm {} vs cold {}",
            warm.sweeps,
            from_e.sweeps
        );
    }
}
