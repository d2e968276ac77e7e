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
