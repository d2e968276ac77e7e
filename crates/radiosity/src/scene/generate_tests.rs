use std::collections::HashMap;

use glam::{DVec2, DVec3};

use super::*;
use crate::geometry;
use crate::io::scene_file::{parse_scene, write_scene};

fn small(furniture: bool) -> BuildingParams {
    BuildingParams {
        floors: 1,
        rooms_x: 2,
        rooms_z: 2,
        furniture,
        ..BuildingParams::default()
    }
}

/// The closed-form polygon count, written out independently of `polygon_count`.
fn expected_count(p: &BuildingParams) -> usize {
    let (f, x, z) = (p.floors as usize, p.rooms_x as usize, p.rooms_z as usize);
    let table = 6 + 4 * 4 + 4 * (6 + 4 * 4 + 5);
    let sofa = 4 * 5;
    let bookcase = 2 * 5 + 4 * 6 + 3 * 6 * 5;
    let bed = 4 * 5;
    let per_room = 1
        + 4
        + 1
        + if p.furniture {
            table + sofa + bookcase + bed
        } else {
            0
        };
    let window_walls = 2 * x + 2 * z; // per floor
    let doors = (x - 1) * z + x * (z - 1); // per floor
    f * x * z * per_room + f * (window_walls * (4 + 4 + 1) + doors * (3 + 3 + 4))
}

#[test]
fn polygon_count_has_a_closed_form() {
    for (floors, rx, rz, furniture) in [
        (1, 1, 1, false),
        (1, 1, 1, true),
        (1, 2, 2, true),
        (2, 3, 1, false),
        (3, 2, 4, true),
    ] {
        let p = BuildingParams {
            floors,
            rooms_x: rx,
            rooms_z: rz,
            furniture,
            ..BuildingParams::default()
        };
        let scene = building(&p).scene;
        assert_eq!(scene.surfaces.len(), expected_count(&p), "{p:?}");
        assert_eq!(p.polygon_count() as usize, expected_count(&p));
    }
    // The default: tens of thousands.
    let p = BuildingParams::default();
    assert_eq!(p.polygon_count(), 23_232);
    assert_eq!(expected_count(&p), 23_232);
}

#[test]
fn round_trips_through_the_writer() {
    let file = building(&BuildingParams {
        floors: 2,
        ..small(true)
    });
    let mut text = Vec::new();
    write_scene(&file.scene, file.settings, &mut text).unwrap();
    let back = parse_scene(std::str::from_utf8(&text).unwrap(), "building").unwrap();
    assert_eq!(back, file);
}

#[test]
fn deterministic_for_a_seed() {
    let a = building(&small(true)).scene;
    assert_eq!(a, building(&small(true)).scene);
    let other = building(&BuildingParams {
        seed: 2,
        ..small(true)
    })
    .scene;
    assert_ne!(a, other);
    assert_eq!(a.surfaces.len(), other.surfaces.len());
}

#[test]
fn every_surface_is_a_valid_polygon() {
    let scene = building(&BuildingParams {
        floors: 2,
        rooms_x: 3,
        ..small(true)
    })
    .scene;
    for s in &scene.surfaces {
        let mut v = s.vertices.clone();
        geometry::validate_polygon(&v).unwrap_or_else(|e| panic!("{}: {e}", s.name));
        geometry::flatten(&mut v);
        assert_eq!(v, s.vertices, "{} was not flat", s.name);
        assert!(geometry::polygon_area(&v) > 1e-4, "{}", s.name);
    }
}

/// The interior box of the room a surface's name names.
fn room_of(p: &BuildingParams, name: &str) -> (DVec3, DVec3) {
    let tag = name.split(' ').next().unwrap();
    let (f, rest) = tag[1..].split_once('R').unwrap();
    let (i, j) = rest.split_once('-').unwrap();
    let (f, i, j): (f64, f64, f64) = (f.parse().unwrap(), i.parse().unwrap(), j.parse().unwrap());
    let pitch = p.room_size + WALL_THICKNESS;
    let lo = DVec3::new(
        WALL_THICKNESS + i * pitch,
        f * (p.height + SLAB_THICKNESS),
        WALL_THICKNESS + j * pitch,
    );
    (lo, lo + DVec3::new(p.room_size, p.height, p.room_size))
}

/// The name up to its last '.', the group a face belongs to.
fn group(name: &str) -> &str {
    &name[..name.rfind('.').unwrap()]
}

#[test]
fn fronts_face_the_room() {
    let p = BuildingParams {
        floors: 2,
        rooms_x: 3,
        ..small(true)
    };
    let scene = building(&p).scene;
    let mut groups: HashMap<&str, (DVec3, usize)> = HashMap::new();
    for s in &scene.surfaces {
        if !s.name.contains(" shell ") {
            let g = groups.entry(group(&s.name)).or_default();
            g.0 += geometry::polygon_centroid(&s.vertices);
            g.1 += 1;
        }
    }
    let (mut shells, mut openings, mut boxes) = (0, 0, 0);
    for s in &scene.surfaces {
        let n = geometry::polygon_normal(&s.vertices).unwrap();
        let c = geometry::polygon_centroid(&s.vertices);
        let (lo, hi) = room_of(&p, &s.name);
        if s.name.contains(" shell ") {
            // Floors, ceilings, walls, lights and windows face the room's centre.
            let to_centre = (0.5 * (lo + hi) - c).normalize();
            assert!(n.dot(to_centre) > 0.3, "{} faces away", s.name);
            shells += 1;
            continue;
        }
        let (sum, count) = groups[group(&s.name)];
        let centre = sum / count as f64;
        if s.name.contains(" opening ") {
            assert!(
                n.dot(centre - c) > 0.0,
                "{} faces away from its opening",
                s.name
            );
            openings += 1;
        } else {
            assert!(s.name.contains(" box "), "{}", s.name);
            assert!(n.dot(c - centre) > 0.0, "{} faces into its box", s.name);
            // Furniture stays inside its room, off the walls and out of the aisle.
            let margin = DVec3::new(WALL_MARGIN, 0.0, WALL_MARGIN) - 1e-3;
            for v in &s.vertices {
                assert!(
                    v.cmpge(lo + margin).all() && v.cmple(hi - margin).all(),
                    "{} leaves its room",
                    s.name
                );
                let local = *v - lo;
                let half = 0.5 * p.room_size;
                for along in [local.x, local.z] {
                    assert!(
                        (along - half).abs() >= 0.5 * AISLE - 1e-3,
                        "{} stands in the aisle",
                        s.name
                    );
                }
            }
            boxes += 1;
        }
    }
    assert!(shells > 0 && openings > 0 && boxes > 0);
}

/// Area of the intersection of two convex polygons in a common plane with unit normal `n`.
fn overlap_area(a: &[DVec3], b: &[DVec3], n: DVec3) -> f64 {
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let project = |p: &[DVec3]| -> Vec<DVec2> {
        let mut q: Vec<DVec2> = p.iter().map(|x| DVec2::new(x.dot(u), x.dot(v))).collect();
        if signed_area(&q) < 0.0 {
            q.reverse();
        }
        q
    };
    let mut clipped = project(a);
    let b = project(b);
    for k in 0..b.len() {
        let (e0, e1) = (b[k], b[(k + 1) % b.len()]);
        let side = |p: DVec2| (e1 - e0).perp_dot(p - e0);
        let mut out = Vec::new();
        for m in 0..clipped.len() {
            let (p, q) = (clipped[m], clipped[(m + 1) % clipped.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                out.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
        clipped = out;
        if clipped.len() < 3 {
            return 0.0;
        }
    }
    signed_area(&clipped).abs()
}

fn signed_area(p: &[DVec2]) -> f64 {
    0.5 * (0..p.len())
        .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
        .sum::<f64>()
}

#[test]
fn overlap_area_of_squares() {
    let sq = |x: f64| {
        vec![
            DVec3::new(x, 0.0, 0.0),
            DVec3::new(x + 1.0, 0.0, 0.0),
            DVec3::new(x + 1.0, 1.0, 0.0),
            DVec3::new(x, 1.0, 0.0),
        ]
    };
    assert!((overlap_area(&sq(0.0), &sq(0.5), DVec3::Z) - 0.5).abs() < 1e-12);
    assert!(overlap_area(&sq(0.0), &sq(1.0), DVec3::Z) < 1e-12);
}

#[test]
fn no_coplanar_surfaces_overlap() {
    let scene = building(&BuildingParams {
        floors: 2,
        rooms_x: 3,
        ..small(true)
    })
    .scene;
    let info: Vec<(DVec3, f64, DVec3, DVec3)> = scene
        .surfaces
        .iter()
        .map(|s| {
            let n = geometry::polygon_normal(&s.vertices).unwrap();
            let c = geometry::polygon_centroid(&s.vertices);
            let lo = s.vertices.iter().fold(DVec3::INFINITY, |a, v| a.min(*v));
            let hi = s
                .vertices
                .iter()
                .fold(DVec3::NEG_INFINITY, |a, v| a.max(*v));
            (n, n.dot(c), lo, hi)
        })
        .collect();
    let mut checked = 0;
    for i in 0..info.len() {
        for j in i + 1..info.len() {
            let (ni, di, loi, hii) = info[i];
            let (nj, dj, loj, hij) = info[j];
            let sign = ni.dot(nj);
            if sign.abs() < 1.0 - 1e-6 || (di - sign * dj).abs() > 1e-4 {
                continue;
            }
            if (loi - 1e-6).cmpgt(hij).any() || (loj - 1e-6).cmpgt(hii).any() {
                continue;
            }
            checked += 1;
            let area = overlap_area(&scene.surfaces[i].vertices, &scene.surfaces[j].vertices, ni);
            assert!(
                area < 1e-6,
                "{} and {} overlap by {area} m^2",
                scene.surfaces[i].name,
                scene.surfaces[j].name
            );
        }
    }
    assert!(checked > 100, "only {checked} coplanar neighbours");
}

#[test]
fn bad_parameters_are_refused() {
    assert_eq!(
        BuildingParams {
            floors: 0,
            ..BuildingParams::default()
        }
        .check(),
        Err(BuildingError::NoRooms("floors"))
    );
    assert_eq!(
        BuildingParams {
            room_size: 4.0,
            ..BuildingParams::default()
        }
        .check(),
        Err(BuildingError::RoomSize {
            size: 4.0,
            min: BuildingParams::MIN_ROOM_SIZE,
            furniture: true
        })
    );
    // QA pass 16 of #16: a light past the largest emission the readers take was written.
    // 1e30 itself is the largest they read, so it passes; the next double up does not.
    let light = |light: f64| {
        BuildingParams {
            light,
            ..BuildingParams::default()
        }
        .check()
    };
    assert_eq!(light(1e30), Ok(()));
    let above = f64::from_bits(1e30_f64.to_bits() + 1);
    assert_eq!(light(above), Err(BuildingError::LightTooBright(above)));
    assert_eq!(light(1e300), Err(BuildingError::LightTooBright(1e300)));
    let bare = BuildingParams {
        room_size: 2.5,
        furniture: false,
        ..BuildingParams::default()
    };
    bare.check().unwrap();
    assert_eq!(building(&bare).scene.surfaces.len(), expected_count(&bare));
}

#[test]
fn furniture_fits_the_smallest_room() {
    let q = quarter_size(BuildingParams::MIN_ROOM_SIZE);
    let j = MAX_JITTER_DEGREES.to_radians();
    for piece in [
        table_with_chairs(),
        sofa(WOOD),
        bookcase(&mut Pcg64Mcg::seed_from_u64(1)),
        bed(WOOD),
    ] {
        let (ex, ez) = turned_extent(piece.width, piece.depth, j);
        assert!(ex <= q && ez <= q, "{} does not fit", piece.name);
    }
}

#[test]
fn element_counts_at_the_default_and_the_million_setting() {
    use crate::mesh::{mesh_scene, MeshError, MAX_ELEMENTS};
    let SceneFile { settings, scene } = building(&BuildingParams::default());
    let mesh = mesh_scene(&scene, settings.max_patch_area).unwrap();
    assert!((30_000..40_000).contains(&mesh.len()), "{}", mesh.len());
    // The million setting meshes (the help of --max-area promises about a million).
    let million = mesh_scene(&scene, 0.0125).unwrap();
    assert!(
        (950_000..1_100_000).contains(&million.len()),
        "{}",
        million.len()
    );
    // Far past the limit, the refusal says how many elements it would have made.
    match mesh_scene(&scene, 1e-6) {
        Err(MeshError::TooManyElements { count, limit, .. }) => {
            assert_eq!(limit, MAX_ELEMENTS);
            assert!(count > MAX_ELEMENTS, "{count}");
        }
        other => panic!("expected a refusal, got {:?}", other.map(|m| m.len())),
    }
}
