//! The emitting surfaces as one distribution of points, for next-event estimation: each
//! emitter fanned into triangles, a triangle drawn with probability proportional to its
//! area times its surface's power weight, and a point drawn uniformly in it.
//!
//! The density of a point y on emitter j, per unit area, is then `w_j / W` (w_j the
//! surface's weight, W the sum of area times weight over all emitters), the same all over
//! the surface: [`Lights::area_density`], which the MIS weight of a path that reaches the
//! emitter by a bounce needs as much as the light sample does.

use glam::DVec3;

use crate::scene::Scene;

/// The emitters' triangles with their cumulative probabilities.
#[derive(Clone, Debug, Default)]
pub(super) struct Lights {
    /// Corners of each triangle.
    triangles: Vec<[DVec3; 3]>,
    /// The surface of each triangle.
    surface: Vec<u32>,
    /// Cumulative probability up to and including each triangle (the last is 1).
    cumulative: Vec<f64>,
    /// Per surface of the scene, the area density w_j / W (0 for a surface that does not
    /// emit).
    density: Vec<f64>,
}

/// A point drawn on an emitter.
#[derive(Clone, Copy, Debug)]
pub(super) struct LightPoint {
    pub(super) position: DVec3,
    pub(super) surface: u32,
    /// Its density per unit area.
    pub(super) area_density: f64,
}

impl Lights {
    /// The emitters of `scene` (surfaces with any band of emission above zero), each
    /// weighted by the sum of its bands of E: a surface twice as bright, or twice as
    /// large, gets twice the samples, and a light of one band is still sampled.
    pub(super) fn new(scene: &Scene) -> Lights {
        let mut lights = Lights {
            density: vec![0.0; scene.surfaces.len()],
            ..Lights::default()
        };
        let mut weights = Vec::new();
        for (j, s) in scene.surfaces.iter().enumerate() {
            let w = s.emission.0.iter().sum::<f64>();
            if w.is_nan() || w <= 0.0 {
                continue;
            }
            let v = &s.vertices;
            for k in 1..v.len().saturating_sub(1) {
                let t = [v[0], v[k], v[k + 1]];
                let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
                if area > 0.0 {
                    lights.triangles.push(t);
                    lights.surface.push(j as u32);
                    weights.push(area * w);
                }
            }
        }
        let total: f64 = weights.iter().sum();
        let mut sum = 0.0;
        for w in &weights {
            sum += w;
            lights.cumulative.push(sum / total);
        }
        if let Some(last) = lights.cumulative.last_mut() {
            *last = 1.0;
        }
        for (j, s) in scene.surfaces.iter().enumerate() {
            let w = s.emission.0.iter().sum::<f64>();
            if w > 0.0 && total > 0.0 {
                lights.density[j] = w / total;
            }
        }
        lights
    }

    /// True when the scene has nothing to sample.
    pub(super) fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The density per unit area with which [`Lights::sample`] draws points of surface
    /// `surface` (0 for a surface that does not emit).
    pub(super) fn area_density(&self, surface: u32) -> f64 {
        self.density[surface as usize]
    }

    /// A point from three uniform numbers in [0, 1): `u0` picks the triangle, (u1, u2)
    /// a uniform point in it ([`super::sampling::point_in_triangles`]). `None` when there
    /// are no emitters.
    pub(super) fn sample(&self, u0: f64, u1: f64, u2: f64) -> Option<LightPoint> {
        if self.is_empty() {
            return None;
        }
        let (k, position) =
            super::sampling::point_in_triangles(&self.triangles, &self.cumulative, u0, u1, u2);
        let surface = self.surface[k];
        Some(LightPoint {
            position,
            surface,
            area_density: self.area_density(surface),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Rgb;
    use crate::scene::Surface;
    use glam::dvec3;

    #[test]
    fn points_fall_by_power_and_uniformly() {
        // A 2 x 1 light of E (0.5, 0.25, 0.25) (weight 1) and a 1 x 1 light of E (3, 0, 0)
        // (weight 3): area times weight 2 and 3, so densities 1/5 and 3/5 per unit area,
        // and the second light gets 3/5 of the points. A dark surface between them gets
        // none.
        let rect = |x0: f64, w: f64| {
            vec![
                dvec3(x0, 0., 0.),
                dvec3(x0 + w, 0., 0.),
                dvec3(x0 + w, 1., 0.),
                dvec3(x0, 1., 0.),
            ]
        };
        let surface = |e: Rgb, vertices| Surface {
            name: String::new(),
            emission: e,
            reflectance: Rgb::splat(0.5),
            vertices,
            photometry: Default::default(),
        };
        let scene = Scene {
            surfaces: vec![
                surface(Rgb([0.5, 0.25, 0.25]), rect(0.0, 2.0)),
                surface(Rgb::BLACK, rect(5.0, 1.0)),
                surface(Rgb([3.0, 0.0, 0.0]), rect(10.0, 1.0)),
            ],
            camera: None,
            lights: Vec::new(),
        };
        let lights = Lights::new(&scene);
        assert!((lights.area_density(0) - 0.2).abs() < 1e-15);
        assert_eq!(lights.area_density(1), 0.0);
        assert!((lights.area_density(2) - 0.6).abs() < 1e-15);
        // A 10 x 10 x 10 grid of numbers: the share of each light, and the mean position
        // on the first (its centroid (1, 0.5) up to the grid's discreteness).
        let (mut on_second, mut sum, mut count) = (0, DVec3::ZERO, 0);
        for i in 0..10 {
            for j in 0..10 {
                for k in 0..10 {
                    let f = |n: i32| (n as f64 + 0.5) / 10.0;
                    let p = lights.sample(f(i), f(j), f(k)).unwrap();
                    assert_ne!(p.surface, 1);
                    if p.surface == 2 {
                        on_second += 1;
                        assert!(p.position.x >= 10.0 && p.position.x <= 11.0);
                    } else {
                        sum += p.position;
                        count += 1;
                    }
                }
            }
        }
        assert_eq!(on_second, 600);
        let mean = sum / count as f64;
        assert!((mean - dvec3(1.0, 0.5, 0.0)).length() < 0.02, "{mean}");
        assert!(Lights::new(&Scene {
            surfaces: vec![],
            ..scene
        })
        .sample(0.5, 0.5, 0.5)
        .is_none());
    }
}
