//! The mesh does not depend on the unit a scene is read in (QA of issue #16: --scale on
//! examples/room.scene gave 899, 917 and 927 elements at 1, 0.001 and 1000, 945 at 0.999).

use radiosity::io::import::{read_any_scene, ImportOptions};
use radiosity::pipeline::Prepared;
use radiosity::progress::NoProgress;

#[test]
fn the_furnished_room_meshes_alike_at_every_scale() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/room.scene");
    let count = |scale: f64| {
        let file = read_any_scene(
            &path,
            &ImportOptions {
                scale,
                settings: None,
            },
        )
        .unwrap()
        .file;
        let prepared = Prepared::new(file.scene, file.settings, &NoProgress).unwrap();
        (prepared.mesh.len(), prepared.contacts.elements)
    };
    let at_one = count(1.0);
    // The grid is the same at any scale (its MAX_PATCH_AREA is scaled by S^2); contact
    // refinement decides by rays and box queries whose tolerances are relative to the
    // scene's size, so it must decide alike too. Powers of two scale exactly, the others
    // round every coordinate: probe points that sat on outlines and faces pressed back to
    // back (a table top on its legs, a sofa's back on its seat) were decided by that
    // rounding, and so was which surfaces a box query returned (every polygon of a BVH
    // leaf whose node box met the query, grouped differently at 7.7).
    for scale in [0.5, 0.999, 1.001, 0.3, 7.7, 13.0, 0.07, 0.001, 1000.0] {
        assert_eq!(count(scale), at_one, "scale {scale}");
    }
}
