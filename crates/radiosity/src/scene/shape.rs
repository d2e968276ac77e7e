//! The faces of the box primitive, shared by the scene reader and the building generator.
//! (The checks a polygon must pass are [`crate::geometry::validate_polygon`].)

use glam::{dvec3, DVec3};

use crate::geometry;

/// Which way a box's faces look.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Facing {
    /// Away from the box: a solid object.
    Out,
    /// Into the box: a room.
    In,
}

/// The suffixes of a box's six faces, in the order [`box_faces`] returns them.
pub(crate) const FACE_NAMES: [&str; 6] = ["base", "top", "side0", "side1", "side2", "side3"];

/// The base quad of the axis-aligned box with minimum corner `origin` and extents `size`: its
/// y-min face, wound so that its normal is +y (into the box). The box is this base swept by
/// `size.y`.
pub(crate) fn axis_aligned_base(origin: DVec3, size: DVec3) -> [DVec3; 4] {
    let (x0, y0, z0) = (origin.x, origin.y, origin.z);
    let (x1, z1) = (origin.x + size.x, origin.z + size.z);
    [
        dvec3(x0, y0, z0),
        dvec3(x0, y0, z1),
        dvec3(x1, y0, z1),
        dvec3(x1, y0, z0),
    ]
}

/// The six faces of the prism swept from `base` along its right-hand-rule normal by `height`:
/// base, top, then the side over each base edge `VERTEXk`-`VERTEXk+1`. Every face's front
/// looks away from the prism for [`Facing::Out`] and into it for [`Facing::In`].
pub(crate) fn box_faces(base: &[DVec3; 4], height: f64, facing: Facing) -> [Vec<DVec3>; 6] {
    let normal = geometry::polygon_normal(base).unwrap_or(DVec3::Y);
    let top: [DVec3; 4] = base.map(|b| b + height * normal);
    let side = |i: usize| {
        let j = (i + 1) % 4;
        vec![base[i], base[j], top[j], top[i]]
    };
    // Wound for facing out: the base looks along -normal, the top along +normal, and a side
    // over a counter-clockwise edge e looks along e x normal, which is outwards.
    let mut faces = [
        base.iter().rev().copied().collect(),
        top.to_vec(),
        side(0),
        side(1),
        side(2),
        side(3),
    ];
    for face in &mut faces {
        if facing == Facing::In {
            face.reverse();
        }
        geometry::flatten(face);
    }
    faces
}

/// The largest `RESOLUTION` of a sphere, cylinder or cone: 512 segments round the axis (a
/// sphere of 512 x 256 = 131,072 faces).
pub(crate) const MAX_RESOLUTION: u32 = 512;

/// The `RESOLUTION` of a sphere, cylinder or cone that gives none: 16 segments round the
/// axis (a sphere of 16 x 8 = 128 faces, 3.2 % short of the sphere's area).
pub(crate) const DEFAULT_RESOLUTION: u32 = 16;

/// The point at `angle` round the y axis on the circle of `radius` at height `y` about
/// `centre`: angle 0 is +x, and angles grow from +x towards -z, counter-clockwise seen from
/// +y.
fn on_circle(centre: DVec3, radius: f64, y: f64, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    centre + DVec3::new(radius * c, y, -radius * s)
}

/// Reverses every face for [`Facing::In`] and flattens it (each is planar by construction;
/// this only rounds away what the sines and cosines left).
fn finish(mut faces: Vec<Vec<DVec3>>, facing: Facing) -> Vec<Vec<DVec3>> {
    for face in &mut faces {
        if facing == Facing::In {
            face.reverse();
        }
        geometry::flatten(face);
    }
    faces
}

/// The faces of a sphere: `n` segments round the y axis and `max(2, n / 2)` bands from
/// pole to pole, each of the same angle 2 pi / n (for even `n`); the corners lie on the
/// sphere (it is inscribed). The bands at the poles are triangles, the others quads (each
/// an isosceles trapezoid between two circles of latitude, so planar). In order from the
/// bottom (-y) pole up, each band round from +x; counter-clockwise seen from outside for
/// [`Facing::Out`].
pub(crate) fn sphere_faces(centre: DVec3, radius: f64, n: u32, facing: Facing) -> Vec<Vec<DVec3>> {
    let bands = (n / 2).max(2);
    let point = |band: u32, seg: u32| {
        // Polar angle from the bottom pole.
        let theta = std::f64::consts::PI * f64::from(band) / f64::from(bands);
        let phi = std::f64::consts::TAU * f64::from(seg % n) / f64::from(n);
        let (st, ct) = theta.sin_cos();
        on_circle(centre, radius * st, -radius * ct, phi)
    };
    let mut faces = Vec::with_capacity((n * bands) as usize);
    for band in 0..bands {
        for seg in 0..n {
            // Round (counter-clockwise seen from +y) along the lower circle, up, back along
            // the upper one: counter-clockwise seen from outside, as a cylinder's side.
            let face = if band == 0 {
                vec![
                    centre - DVec3::new(0.0, radius, 0.0),
                    point(1, seg + 1),
                    point(1, seg),
                ]
            } else if band == bands - 1 {
                vec![
                    point(band, seg),
                    point(band, seg + 1),
                    centre + DVec3::new(0.0, radius, 0.0),
                ]
            } else {
                vec![
                    point(band, seg),
                    point(band, seg + 1),
                    point(band + 1, seg + 1),
                    point(band + 1, seg),
                ]
            };
            faces.push(face);
        }
    }
    finish(faces, facing)
}

/// The faces of a cylinder round the y axis: the base disc (centre `centre`, facing -y
/// when out), the top disc at `centre + height y`, then the `n` side quads round from +x.
/// Names: `base`, `top`, `side0` .. `side(n-1)`.
pub(crate) fn cylinder_faces(
    centre: DVec3,
    radius: f64,
    height: f64,
    n: u32,
    facing: Facing,
) -> Vec<Vec<DVec3>> {
    let angle = |k: u32| std::f64::consts::TAU * f64::from(k % n) / f64::from(n);
    let bottom: Vec<DVec3> = (0..n)
        .map(|k| on_circle(centre, radius, 0.0, angle(k)))
        .collect();
    let top: Vec<DVec3> = (0..n)
        .map(|k| on_circle(centre, radius, height, angle(k)))
        .collect();
    let mut faces = vec![bottom.iter().rev().copied().collect(), top.clone()];
    for k in 0..n as usize {
        let j = (k + 1) % n as usize;
        // Counter-clockwise seen from outside: along the bottom edge, then up.
        faces.push(vec![bottom[k], bottom[j], top[j], top[k]]);
    }
    finish(faces, facing)
}

/// The faces of a cone round the y axis: the base disc (centre `centre`, facing -y when
/// out), then the `n` side triangles up to the apex `centre + height y`, round from +x.
/// Names: `base`, `side0` .. `side(n-1)`.
pub(crate) fn cone_faces(
    centre: DVec3,
    radius: f64,
    height: f64,
    n: u32,
    facing: Facing,
) -> Vec<Vec<DVec3>> {
    let angle = |k: u32| std::f64::consts::TAU * f64::from(k % n) / f64::from(n);
    let bottom: Vec<DVec3> = (0..n)
        .map(|k| on_circle(centre, radius, 0.0, angle(k)))
        .collect();
    let apex = centre + DVec3::new(0.0, height, 0.0);
    let mut faces = vec![bottom.iter().rev().copied().collect()];
    for k in 0..n as usize {
        let j = (k + 1) % n as usize;
        faces.push(vec![bottom[k], bottom[j], apex]);
    }
    finish(faces, facing)
}
