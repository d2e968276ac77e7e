//! A procedural building: furnished rooms on one or more floors, joined by doors, lit by
//! ceiling panels and windows.
//!
//! [`building`] makes a deterministic (seeded) scene in metres. Each floor is a grid of
//! `rooms_x` x `rooms_z` square rooms of side `room_size` and height `height`, separated by
//! walls [`WALL_THICKNESS`] thick; floors are stacked with a [`SLAB_THICKNESS`] slab between
//! them (the floors are not connected: there are no stairs).
//!
//! # How the geometry is modelled
//!
//! Every room is a closed shell of one-sided surfaces whose fronts face the room's centre:
//! the floor, the ceiling and four walls. A wall is solid: each of the two rooms a wall
//! separates has its own surface, one wall thickness apart, and an opening through the wall
//! is lined with *reveals* (two jambs, a head and a sill or threshold) that face into the
//! opening, so no view ever reaches the inside of a wall or the back of a surface. Surfaces
//! are planar convex quads, so a wall with an opening is split into the quads around it
//! (left, right, below, above), and no two coplanar surfaces overlap.
//!
//! * Interior walls have a door (0.9 m x 2.1 m, its position along the wall seeded) in every
//!   wall between two rooms, so every room on a floor can be reached from every other.
//! * Exterior walls have a window (sill 0.9 m, head 2.2 m, width seeded). Daylight is
//!   modelled by an emitting quad closing the window at the outer face of the wall, facing
//!   into the room: a little dimmer than the ceiling panels and bluish (a sky, not a sun).
//!   Nothing outside the building is modelled.
//! * Each ceiling has a light panel (1.2 m x 0.6 m) in a hole in its centre, flush with the
//!   ceiling and facing down, like the Cornell box's light; the ceiling is the four quads
//!   around it.
//! * With `furniture`, each room has four pieces, one per quarter of the room, placed at a
//!   seeded position and a seeded rotation (a quarter turn plus up to
//!   [`MAX_JITTER_DEGREES`]) inside its quarter: a table with four chairs, a sofa, a bookcase
//!   with books, and a bed. A cross-shaped aisle 1.1 m wide through the room's centre stays
//!   free, so doors (which open onto the aisle) are never blocked and nothing touches a wall.
//!   Furniture is made of boxes (the box primitive's faces, facing out); a box standing on
//!   another surface leaves out the face it stands on, so no faces coincide.
//!
//! Surface names say what a surface is and which room it belongs to:
//! `F<floor>R<i>-<j> <kind> <part>`, where kind is `shell` (floor, ceiling, walls, light,
//! window: the front faces the room's centre), `opening` (the reveals of a door or window:
//! they face the opening's centre; a door belongs to the room on its lower-coordinate side) or
//! `box` (furniture: the part is `<piece>.<box>.<face>` and the face looks away from its box).
//!
//! Coordinates are rounded to 0.1 mm so that the files stay small.

use glam::{dvec3, DVec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::shape::{axis_aligned_base, box_faces, Facing};
use super::{Rgb, Scene, Surface};
use crate::geometry::flatten;
use crate::io::scene_file::SceneFile;
use crate::mesh::MeshSettings;

/// Wall thickness (m).
pub const WALL_THICKNESS: f64 = 0.15;
/// Thickness of the slab between floors (m).
pub const SLAB_THICKNESS: f64 = 0.3;
/// The largest deviation of a piece of furniture from a quarter turn (degrees).
pub const MAX_JITTER_DEGREES: f64 = 8.0;

const DOOR_WIDTH: f64 = 0.9;
const DOOR_HEIGHT: f64 = 2.1;
const WINDOW_SILL: f64 = 0.9;
const WINDOW_HEAD: f64 = 2.2;
const LIGHT_SIZE: (f64, f64) = (1.2, 0.6);
/// Width of the free aisle through each room's centre, along x and along z.
const AISLE: f64 = 1.1;
/// Smallest distance from furniture to a wall.
const WALL_MARGIN: f64 = 0.05;
/// How far a door may sit from the middle of its wall (keeps it on the aisle).
const DOOR_SHIFT: f64 = 0.09;

/// Polygons in one room's shell without its walls: floor, four ceiling quads and the panel.
pub const ROOM_SHELL_POLYGONS: u64 = 6;
/// Polygons of one exterior wall seen from its room: four quads round the window, four
/// reveals and the daylight quad.
pub const WINDOW_WALL_POLYGONS: u64 = 9;
/// Polygons of one interior wall with its door: three quads round the door on each side and
/// four reveals (two jambs, head, threshold).
pub const DOOR_WALL_POLYGONS: u64 = 10;
/// Polygons of one room's furniture: a table with four chairs (130), a sofa (20), a bookcase
/// with 18 books (124) and a bed (20).
pub const FURNITURE_POLYGONS: u64 = 294;

/// The parameters of [`building`].
#[derive(Clone, Debug, PartialEq)]
pub struct BuildingParams {
    /// Storeys, at least 1.
    pub floors: u32,
    /// Rooms along x on every floor, at least 1.
    pub rooms_x: u32,
    /// Rooms along z on every floor, at least 1.
    pub rooms_z: u32,
    /// The inner side of each (square) room (m); at least [`BuildingParams::MIN_ROOM_SIZE`]
    /// with furniture, 2.5 without.
    pub room_size: f64,
    /// Floor-to-ceiling height (m), at least 2.4.
    pub height: f64,
    /// Whether rooms are furnished.
    pub furniture: bool,
    /// Seed of every random choice: door positions, window widths, furniture placement,
    /// colours.
    pub seed: u64,
    /// The scene's `MAX_PATCH_AREA` (m^2).
    pub max_patch_area: f64,
    /// The scene's `INTEGRAL_STEPS`.
    pub integral_steps: u32,
    /// Exitance of the ceiling panels (lm/m^2, as every exitance of the scene format; white
    /// of 1.0, 0.95, 0.85 times this); the windows emit 0.6 times this, tinted 0.75, 0.85,
    /// 1.0.
    pub light: f64,
}

impl Default for BuildingParams {
    /// Two floors of 6 x 6 furnished rooms of 6 m x 6 m x 2.7 m: 23,232 polygons, and with
    /// `MAX_PATCH_AREA` 1 m^2 about 40,000 elements.
    fn default() -> Self {
        BuildingParams {
            floors: 2,
            rooms_x: 6,
            rooms_z: 6,
            room_size: 6.0,
            height: 2.7,
            furniture: true,
            seed: 1,
            max_patch_area: 1.0,
            integral_steps: 2,
            light: 20.0,
        }
    }
}

/// Why [`BuildingParams::check`] refused a building.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BuildingError {
    /// No floors, or no rooms along one axis (the field named).
    #[error("{0} must be at least 1")]
    NoRooms(&'static str),
    /// The room side (m) is not a number, is below what holds the furniture (or 2.5 m
    /// without), or above 100 m.
    #[error(
        "the room size must be between {min} m{} and 100 m, got {size}",
        if *furniture { " (with furniture)" } else { "" }
    )]
    RoomSize {
        /// The side given.
        size: f64,
        /// The smallest allowed.
        min: f64,
        /// Whether the rooms are furnished.
        furniture: bool,
    },
    /// The floor-to-ceiling height (m) is outside 2.4 to 20.
    #[error("the height must be between 2.4 and 20 m, got {0}")]
    Height(f64),
    /// MAX_PATCH_AREA is not a positive number.
    #[error("MAX_PATCH_AREA must be a positive number, got {0}")]
    MaxPatchArea(f64),
    /// INTEGRAL_STEPS is 0.
    #[error("INTEGRAL_STEPS must be at least 1")]
    IntegralSteps,
    /// The panels' exitance is negative or not a number.
    #[error("the light panels' exitance must be a number of at least 0, got {0}")]
    Light(f64),
    /// The panels' exitance is above [`crate::scene::MAX_EMISSION`], which every reader of
    /// the written scene refuses (QA pass 16 of #16: `--light 1e31` wrote a file no other
    /// command would read).
    #[error(
        "the light panels' exitance {0:e} is above the largest the program supports ({max:e})",
        max = crate::scene::MAX_EMISSION
    )]
    LightTooBright(f64),
    /// More rooms than [`BuildingParams::MAX_ROOMS`].
    #[error("{0} rooms is more than the limit of {max}", max = BuildingParams::MAX_ROOMS)]
    TooManyRooms(u64),
}

impl BuildingParams {
    /// The smallest room side that holds the furniture.
    pub const MIN_ROOM_SIZE: f64 = 5.7;
    /// The most rooms a building may have (floors x rooms along x x rooms along z).
    pub const MAX_ROOMS: u64 = 100_000;

    /// Refuses parameters that cannot make a building, saying which and why.
    pub fn check(&self) -> Result<(), BuildingError> {
        if self.floors == 0 {
            return Err(BuildingError::NoRooms("floors"));
        }
        if self.rooms_x == 0 {
            return Err(BuildingError::NoRooms("rooms along x"));
        }
        if self.rooms_z == 0 {
            return Err(BuildingError::NoRooms("rooms along z"));
        }
        let min = if self.furniture {
            Self::MIN_ROOM_SIZE
        } else {
            2.5
        };
        if !(self.room_size.is_finite() && self.room_size >= min && self.room_size <= 100.0) {
            return Err(BuildingError::RoomSize {
                size: self.room_size,
                min,
                furniture: self.furniture,
            });
        }
        if !(self.height.is_finite() && (2.4..=20.0).contains(&self.height)) {
            return Err(BuildingError::Height(self.height));
        }
        if !(self.max_patch_area.is_finite() && self.max_patch_area > 0.0) {
            return Err(BuildingError::MaxPatchArea(self.max_patch_area));
        }
        if self.integral_steps == 0 {
            return Err(BuildingError::IntegralSteps);
        }
        if !(self.light.is_finite() && self.light >= 0.0) {
            return Err(BuildingError::Light(self.light));
        }
        // The red band is the exitance itself (green and blue are 0.95 and 0.85 of it).
        if self.light > crate::scene::MAX_EMISSION {
            return Err(BuildingError::LightTooBright(self.light));
        }
        let rooms = self.floors as u64 * self.rooms_x as u64 * self.rooms_z as u64;
        if rooms > Self::MAX_ROOMS {
            return Err(BuildingError::TooManyRooms(rooms));
        }
        Ok(())
    }

    /// The number of polygons [`building`] makes, in closed form.
    pub fn polygon_count(&self) -> u64 {
        let (f, x, z) = (self.floors as u64, self.rooms_x as u64, self.rooms_z as u64);
        let furniture = if self.furniture {
            FURNITURE_POLYGONS
        } else {
            0
        };
        let windows = 2 * x + 2 * z;
        let doors = (x - 1) * z + x * (z - 1);
        f * x * z * (ROOM_SHELL_POLYGONS + furniture)
            + f * (windows * WINDOW_WALL_POLYGONS + doors * DOOR_WALL_POLYGONS)
    }
}

/// Rounds to 0.1 mm.
fn round(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

fn round_vec(v: DVec3) -> DVec3 {
    dvec3(round(v.x), round(v.y), round(v.z))
}

/// The rectangle `o`, `o + u`, `o + u + v`, `o + v`, wound so that its front looks along
/// `facing`, with corners rounded.
fn rect(o: DVec3, u: DVec3, v: DVec3, facing: DVec3) -> Vec<DVec3> {
    let mut q = vec![o, o + u, o + u + v, o + v];
    if u.cross(v).dot(facing) < 0.0 {
        q.reverse();
    }
    q.into_iter().map(round_vec).collect()
}

/// Colours.
const WALL: Rgb = Rgb([0.78, 0.76, 0.72]);
const CEILING: Rgb = Rgb([0.82, 0.82, 0.82]);
const PANEL: Rgb = Rgb([0.8, 0.8, 0.8]);
const WOOD: Rgb = Rgb([0.55, 0.38, 0.22]);
const DARK_WOOD: Rgb = Rgb([0.36, 0.24, 0.15]);
const LINEN: Rgb = Rgb([0.82, 0.81, 0.78]);
const FLOORS: [Rgb; 3] = [
    Rgb([0.52, 0.36, 0.22]),
    Rgb([0.45, 0.45, 0.43]),
    Rgb([0.6, 0.5, 0.38]),
];
const FABRICS: [Rgb; 5] = [
    Rgb([0.55, 0.15, 0.12]),
    Rgb([0.2, 0.3, 0.55]),
    Rgb([0.3, 0.45, 0.25]),
    Rgb([0.6, 0.55, 0.4]),
    Rgb([0.35, 0.35, 0.38]),
];
const BOOKS: [Rgb; 6] = [
    Rgb([0.6, 0.1, 0.1]),
    Rgb([0.1, 0.2, 0.5]),
    Rgb([0.15, 0.4, 0.2]),
    Rgb([0.7, 0.6, 0.2]),
    Rgb([0.2, 0.2, 0.2]),
    Rgb([0.7, 0.7, 0.65]),
];

/// One box of a piece of furniture, in the piece's own frame (x along its width, z along its
/// depth, y up from the floor).
struct Part {
    name: String,
    min: DVec3,
    size: DVec3,
    colour: Rgb,
    /// Leave out the base (the box stands on something).
    no_base: bool,
    /// Leave out the top (something stands on the box).
    no_top: bool,
}

fn part(name: impl Into<String>, min: [f64; 3], size: [f64; 3], colour: Rgb) -> Part {
    Part {
        name: name.into(),
        min: DVec3::from_array(min),
        size: DVec3::from_array(size),
        colour,
        no_base: false,
        no_top: false,
    }
}

impl Part {
    /// Standing on something: no base face.
    fn standing(mut self) -> Part {
        self.no_base = true;
        self
    }

    /// A leg: no base and no top.
    fn leg(mut self) -> Part {
        self.no_base = true;
        self.no_top = true;
        self
    }
}

/// A piece of furniture: its footprint `[0, width] x [0, depth]` and its boxes.
struct Piece {
    name: &'static str,
    width: f64,
    depth: f64,
    parts: Vec<Part>,
}

fn table_with_chairs() -> Piece {
    let (w, table_d, reach) = (1.4, 0.8, 0.36);
    let d = table_d + 2.0 * reach;
    let mut parts = vec![part("top", [0.0, 0.72, reach], [w, 0.04, table_d], WOOD)];
    for (k, (x, z)) in [
        (0.05, reach + 0.05),
        (w - 0.1, reach + 0.05),
        (0.05, reach + table_d - 0.1),
        (w - 0.1, reach + table_d - 0.1),
    ]
    .into_iter()
    .enumerate()
    {
        parts.push(part(format!("leg{k}"), [x, 0.0, z], [0.05, 0.72, 0.05], WOOD).leg());
    }
    // Chairs: seat 0.42 x 0.42 at 0.42-0.46, pushed 0.1 under the table, the back standing
    // on the seat's outer edge.
    let mut c = 0;
    for far in [false, true] {
        for cx in [0.4, 1.0] {
            let x0 = cx - 0.21;
            let seat_z = if far { d - 0.46 } else { 0.04 };
            let back_z = if far { d - 0.08 } else { 0.04 };
            parts.push(part(
                format!("chair{c}-seat"),
                [x0, 0.42, seat_z],
                [0.42, 0.04, 0.42],
                DARK_WOOD,
            ));
            for (k, (lx, lz)) in [(0.0, 0.0), (0.38, 0.0), (0.0, 0.38), (0.38, 0.38)]
                .into_iter()
                .enumerate()
            {
                parts.push(
                    part(
                        format!("chair{c}-leg{k}"),
                        [x0 + lx, 0.0, seat_z + lz],
                        [0.04, 0.42, 0.04],
                        DARK_WOOD,
                    )
                    .leg(),
                );
            }
            parts.push(
                part(
                    format!("chair{c}-back"),
                    [x0, 0.46, back_z],
                    [0.42, 0.44, 0.04],
                    DARK_WOOD,
                )
                .standing(),
            );
            c += 1;
        }
    }
    Piece {
        name: "table",
        width: w,
        depth: d,
        parts,
    }
}

fn sofa(fabric: Rgb) -> Piece {
    let (w, d) = (2.0, 0.9);
    let parts = vec![
        part("base", [0.0, 0.0, 0.0], [w, 0.42, d], fabric).standing(),
        part("back", [0.0, 0.42, 0.7], [w, 0.43, 0.2], fabric).standing(),
        part("arm0", [0.0, 0.42, 0.0], [0.18, 0.2, 0.69], fabric).standing(),
        part("arm1", [w - 0.18, 0.42, 0.0], [0.18, 0.2, 0.69], fabric).standing(),
    ];
    Piece {
        name: "sofa",
        width: w,
        depth: d,
        parts,
    }
}

fn bookcase(rng: &mut Pcg64Mcg) -> Piece {
    let (w, d, h) = (1.0, 0.35, 1.8);
    let mut parts = vec![
        part("side0", [0.0, 0.0, 0.0], [0.03, h, d], WOOD).standing(),
        part("side1", [w - 0.03, 0.0, 0.0], [0.03, h, d], WOOD).standing(),
    ];
    let shelves = [0.05, 0.6, 1.15, 1.7];
    for (k, y) in shelves.into_iter().enumerate() {
        parts.push(part(
            format!("shelf{k}"),
            [0.032, y, 0.0],
            [w - 0.064, 0.02, d],
            WOOD,
        ));
    }
    for (k, y) in shelves[..3].iter().enumerate() {
        let mut x = 0.05;
        for b in 0..6 {
            let thick = round(rng.random_range(0.03..0.07));
            let tall = round(rng.random_range(0.18..0.32));
            let deep = round(rng.random_range(0.18..0.25));
            let colour = BOOKS[rng.random_range(0..BOOKS.len())];
            parts.push(
                part(
                    format!("book{k}-{b}"),
                    [x, y + 0.02, 0.05],
                    [thick, tall, deep],
                    colour,
                )
                .standing(),
            );
            x = round(x + thick + 0.01);
        }
    }
    Piece {
        name: "bookcase",
        width: w,
        depth: d,
        parts,
    }
}

fn bed(cover: Rgb) -> Piece {
    let (w, d) = (0.95, 2.1);
    let parts = vec![
        part("headboard", [0.0, 0.0, 0.0], [w, 0.9, 0.06], WOOD).standing(),
        part("frame", [0.0, 0.0, 0.07], [w, 0.3, d - 0.07], WOOD).standing(),
        part(
            "mattress",
            [0.02, 0.3, 0.09],
            [w - 0.04, 0.2, d - 0.11],
            cover,
        )
        .standing(),
        part("pillow", [0.15, 0.5, 0.15], [w - 0.3, 0.12, 0.35], LINEN).standing(),
    ];
    Piece {
        name: "bed",
        width: w,
        depth: d,
        parts,
    }
}

/// The extents along x and z of a `width` x `depth` footprint turned by `angle` about y.
fn turned_extent(width: f64, depth: f64, angle: f64) -> (f64, f64) {
    let (s, c) = (angle.sin().abs(), angle.cos().abs());
    (width * c + depth * s, width * s + depth * c)
}

/// The side of each quarter of a room that furniture may use.
fn quarter_size(room_size: f64) -> f64 {
    0.5 * (room_size - AISLE) - WALL_MARGIN
}

/// Builds the scene, with the settings of `params` beside it. Panics when `params.check()`
/// fails.
pub fn building(params: &BuildingParams) -> SceneFile {
    if let Err(e) = params.check() {
        panic!("invalid building parameters: {e}");
    }
    let mut b = Builder {
        p: params,
        rng: Pcg64Mcg::seed_from_u64(params.seed ^ 0x05EE_DB01_D1A6_u64),
        surfaces: Vec::with_capacity(params.polygon_count() as usize),
    };
    b.build();
    SceneFile {
        settings: MeshSettings {
            max_patch_area: params.max_patch_area,
            integral_steps: params.integral_steps,
        },
        scene: Scene {
            surfaces: b.surfaces,
            camera: None,
            lights: Vec::new(),
        },
    }
}

/// Which way an opening in a wall goes.
#[derive(Clone, Copy)]
enum Opening {
    /// A door from `h0` to `h1` along the wall.
    Door(f64, f64),
    /// A window from `h0` to `h1` along the wall.
    Window(f64, f64),
}

struct Builder<'a> {
    p: &'a BuildingParams,
    rng: Pcg64Mcg,
    surfaces: Vec<Surface>,
}

impl Builder<'_> {
    fn pitch(&self) -> f64 {
        self.p.room_size + WALL_THICKNESS
    }

    /// The minimum corner of room (f, i, j)'s interior.
    fn room_origin(&self, f: u32, i: u32, j: u32) -> DVec3 {
        dvec3(
            round(WALL_THICKNESS + i as f64 * self.pitch()),
            round(f as f64 * (self.p.height + SLAB_THICKNESS)),
            round(WALL_THICKNESS + j as f64 * self.pitch()),
        )
    }

    fn add(&mut self, name: String, vertices: Vec<DVec3>, emission: Rgb, reflectance: Rgb) {
        let mut vertices = vertices;
        flatten(&mut vertices);
        self.surfaces.push(Surface {
            name,
            emission,
            reflectance,
            vertices,
            photometry: Default::default(),
        });
    }

    fn build(&mut self) {
        let p = self.p;
        let s = p.room_size;
        // Door positions (start along the wall) per floor, in a fixed order: walls crossing
        // x (between rooms i and i+1), then walls crossing z.
        let door = |rng: &mut Pcg64Mcg| {
            let shift = rng.random_range(-DOOR_SHIFT..DOOR_SHIFT);
            let h0 = round(0.5 * (s - DOOR_WIDTH) + shift);
            (h0, round(h0 + DOOR_WIDTH))
        };
        let window = |rng: &mut Pcg64Mcg| {
            let width = rng.random_range(1.2..(s - 1.0).min(2.4));
            let h0 = round(0.5 * (s - width));
            (h0, round(s - h0))
        };
        let (nx, nz) = (p.rooms_x as usize, p.rooms_z as usize);
        for f in 0..p.floors {
            let mut doors_x = vec![(0.0, 0.0); nx * nz];
            let mut doors_z = vec![(0.0, 0.0); nx * nz];
            let mut windows = vec![[(0.0, 0.0); 4]; nx * nz];
            for k in 0..nx * nz {
                doors_x[k] = door(&mut self.rng);
                doors_z[k] = door(&mut self.rng);
                for w in &mut windows[k] {
                    *w = window(&mut self.rng);
                }
            }
            for i in 0..nx {
                for j in 0..nz {
                    let k = i * nz + j;
                    let sides = [
                        // xmin, xmax, zmin, zmax
                        if i == 0 {
                            Opening::Window(windows[k][0].0, windows[k][0].1)
                        } else {
                            let d = doors_x[(i - 1) * nz + j];
                            Opening::Door(d.0, d.1)
                        },
                        if i + 1 == nx {
                            Opening::Window(windows[k][1].0, windows[k][1].1)
                        } else {
                            Opening::Door(doors_x[k].0, doors_x[k].1)
                        },
                        if j == 0 {
                            Opening::Window(windows[k][2].0, windows[k][2].1)
                        } else {
                            let d = doors_z[i * nz + j - 1];
                            Opening::Door(d.0, d.1)
                        },
                        if j + 1 == nz {
                            Opening::Window(windows[k][3].0, windows[k][3].1)
                        } else {
                            Opening::Door(doors_z[k].0, doors_z[k].1)
                        },
                    ];
                    self.room(f, i as u32, j as u32, sides);
                }
            }
        }
    }

    fn room(&mut self, f: u32, i: u32, j: u32, sides: [Opening; 4]) {
        let p = self.p;
        let (s, h) = (p.room_size, p.height);
        let o = self.room_origin(f, i, j);
        let tag = format!("F{f}R{i}-{j}");
        let floor_colour = FLOORS[self.rng.random_range(0..FLOORS.len())];
        let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);

        // Floor and ceiling.
        self.add(
            format!("{tag} shell floor"),
            rect(o, x * s, z * s, y),
            Rgb::BLACK,
            floor_colour,
        );
        let top = o + y * h;
        let (lw, ld) = LIGHT_SIZE;
        let (a0, a1) = (round(0.5 * (s - lw)), round(0.5 * (s + lw)));
        let (b0, b1) = (round(0.5 * (s - ld)), round(0.5 * (s + ld)));
        let pieces = [
            (0.0, a0, 0.0, s),
            (a1, s, 0.0, s),
            (a0, a1, 0.0, b0),
            (a0, a1, b1, s),
        ];
        for (k, (x0, x1, z0, z1)) in pieces.into_iter().enumerate() {
            self.add(
                format!("{tag} shell ceiling{k}"),
                rect(top + x * x0 + z * z0, x * (x1 - x0), z * (z1 - z0), -y),
                Rgb::BLACK,
                CEILING,
            );
        }
        let e = p.light;
        self.add(
            format!("{tag} shell light"),
            rect(top + x * a0 + z * b0, x * (a1 - a0), z * (b1 - b0), -y),
            Rgb([e, 0.95 * e, 0.85 * e]),
            PANEL,
        );

        // Walls: (name, a point at along = 0 on the floor, along, inward normal).
        let walls = [
            ("xmin", o, z, x),
            ("xmax", o + x * s, z, -x),
            ("zmin", o, x, z),
            ("zmax", o + z * s, x, -z),
        ];
        for ((name, w0, along, n), opening) in walls.into_iter().zip(sides) {
            let (h0, h1, v0, v1) = match opening {
                Opening::Door(h0, h1) => (h0, h1, 0.0, DOOR_HEIGHT),
                Opening::Window(h0, h1) => (h0, h1, WINDOW_SILL, WINDOW_HEAD),
            };
            let mut quads = vec![(0.0, h0, 0.0, h)];
            if h1 < s {
                quads.push((h1, s, 0.0, h));
            }
            if v0 > 0.0 {
                quads.push((h0, h1, 0.0, v0));
            }
            if v1 < h {
                quads.push((h0, h1, v1, h));
            }
            for (k, (s0, s1, t0, t1)) in quads.into_iter().enumerate() {
                self.add(
                    format!("{tag} shell {name}{k}"),
                    rect(
                        w0 + along * s0 + y * t0,
                        along * (s1 - s0),
                        y * (t1 - t0),
                        n,
                    ),
                    Rgb::BLACK,
                    WALL,
                );
            }
            // Reveals: a door's belong to the room on its lower side (xmax, zmax), a
            // window's to its room.
            let depth = -n * WALL_THICKNESS;
            let lined = match opening {
                Opening::Door(..) if name == "xmax" || name == "zmax" => Some("door"),
                Opening::Door(..) => None,
                Opening::Window(..) => Some("window"),
            };
            if let Some(kind) = lined {
                let c = w0 + along * h0 + y * v0;
                let reveals = [
                    ("jamb0", rect(c, y * (v1 - v0), depth, along)),
                    (
                        "jamb1",
                        rect(c + along * (h1 - h0), y * (v1 - v0), depth, -along),
                    ),
                    (
                        "head",
                        rect(c + y * (v1 - v0), along * (h1 - h0), depth, -y),
                    ),
                    ("sill", rect(c, along * (h1 - h0), depth, y)),
                ];
                for (part, q) in reveals {
                    let colour = if kind == "door" && part == "sill" {
                        floor_colour
                    } else {
                        WALL
                    };
                    self.add(
                        format!("{tag} opening {kind}-{name}.{part}"),
                        q,
                        Rgb::BLACK,
                        colour,
                    );
                }
            }
            if let Opening::Window(..) = opening {
                let d = 0.6 * e;
                self.add(
                    format!("{tag} shell window-{name}"),
                    rect(
                        w0 + depth + along * h0 + y * v0,
                        along * (h1 - h0),
                        y * (v1 - v0),
                        n,
                    ),
                    Rgb([0.75 * d, 0.85 * d, d]),
                    PANEL,
                );
            }
        }

        if p.furniture {
            self.furnish(&tag, o);
        }
    }

    /// Puts a table with chairs, a sofa, a bookcase and a bed in the four quarters of the
    /// room with minimum corner `o`, in a seeded order, each at a seeded position and turn.
    fn furnish(&mut self, tag: &str, o: DVec3) {
        let s = self.p.room_size;
        let q = quarter_size(s);
        let fabric = FABRICS[self.rng.random_range(0..FABRICS.len())];
        let cover = FABRICS[self.rng.random_range(0..FABRICS.len())];
        let mut pieces = vec![
            table_with_chairs(),
            sofa(fabric),
            bookcase(&mut self.rng),
            bed(cover),
        ];
        // A seeded permutation (Fisher-Yates).
        for k in (1..pieces.len()).rev() {
            let m = self.rng.random_range(0..=k);
            pieces.swap(k, m);
        }
        let quarters = [
            (WALL_MARGIN, WALL_MARGIN),
            (0.5 * (s + AISLE), WALL_MARGIN),
            (WALL_MARGIN, 0.5 * (s + AISLE)),
            (0.5 * (s + AISLE), 0.5 * (s + AISLE)),
        ];
        for (piece, (qx, qz)) in pieces.into_iter().zip(quarters) {
            let turns = self.rng.random_range(0..4) as f64;
            let jitter = self
                .rng
                .random_range(-MAX_JITTER_DEGREES..MAX_JITTER_DEGREES);
            let angle = (turns * 90.0 + jitter).to_radians();
            let (ex, ez) = turned_extent(piece.width, piece.depth, angle);
            let cx = qx + 0.5 * ex + self.rng.random_range(0.0..1.0) * (q - ex).max(0.0);
            let cz = qz + 0.5 * ez + self.rng.random_range(0.0..1.0) * (q - ez).max(0.0);
            let centre = o + dvec3(cx, 0.0, cz);
            let local_centre = dvec3(0.5 * piece.width, 0.0, 0.5 * piece.depth);
            let (sin, cos) = angle.sin_cos();
            let place = |v: DVec3| {
                let d = v - local_centre;
                round_vec(centre + dvec3(cos * d.x + sin * d.z, d.y, -sin * d.x + cos * d.z))
            };
            for part in &piece.parts {
                let base = axis_aligned_base(part.min, part.size).map(place);
                let faces = box_faces(&base, part.size.y, Facing::Out);
                for (k, face) in faces.into_iter().enumerate() {
                    if (k == 0 && part.no_base) || (k == 1 && part.no_top) {
                        continue;
                    }
                    let face = face.into_iter().map(round_vec).collect();
                    self.add(
                        format!(
                            "{tag} box {}.{}.{}",
                            piece.name,
                            part.name,
                            super::shape::FACE_NAMES[k]
                        ),
                        face,
                        Rgb::BLACK,
                        part.colour,
                    );
                }
            }
        }
    }
}

#[cfg(test)]
#[path = "generate_tests.rs"]
mod tests;
