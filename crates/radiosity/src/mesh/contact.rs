//! Contact refinement: no element straddles the outline of an object that stands on it.
//!
//! A box standing on the floor covers part of it; a rug lying on it, a cupboard against a
//! wall, a light panel hanging just below the ceiling do the same. The covered part is
//! **buried**: every direction from it runs into the back of some face (the inside of the
//! box, the underside of the rug), so no light reaches it and none leaves it. An element of
//! the regular grid that is partly buried is wrong twice over: its radiosity is the mean over
//! a lit and a dark part, so the visible part is too dark (the dark strips along furniture),
//! and the light it reflects is spread over its whole area, so the buried part's share is sent
//! into the backs of the faces above it and lost (4.7 % of the emitted power in
//! `examples/room.scene`, 15 % in a generated building).
//!
//! [`refine_contacts`] splits such elements, as a quadtree (quads into four at their bilinear
//! midpoints, triangles into four at their edge midpoints), down to [`CONTACT_DEPTH`] levels,
//! and drops the pieces that are buried entirely. This is contact meshing in the sense of
//! Heckbert (1992) and Lischinski, Tampieri and Greenberg (1992), on the element grid: after
//! three levels the pieces that still straddle the outline (1/8 of an element across) are
//! cut along the edges of the faces that can bury them ([`super::outline_cut`]), and the
//! parts judged again, so no part keeps a buried share where a face edge gives the outline.
//!
//! A point is also buried when a surface lying on its own (a rug in the floor's plane or a
//! hair above it, [`crate::scene::lying_on`]) covers it: the rays start above the plane and
//! cannot see such a cover.
//!
//! On the dense mesh the same step follows the faces hanging just in front of a surface (the
//! back of a sofa 5 cm before a wall, a bookcase's bottom shelf above the floor): a point
//! whose normal meets such a face within the surface's near gap ([`near_gaps`]) is in its
//! shade, and the elements where shade and light meet, inside them or along their edges,
//! are split and cut along the face's projected outline as above, every part kept.
//!
//! A point is buried when all but [`PROBE_SLACK`] of [`PROBE_DIRECTIONS`] rays from it (the
//! normal and six directions 60 degrees from it) first hit the back of a face. Only elements with another
//! surface nearby in front of them are probed (a box query), so the cost is the contacts',
//! not the whole mesh's.

use glam::DVec3;
use rayon::prelude::*;

use super::outline_cut::{crosses, cut_along, runs_along, OutlineEdge};
use super::{bilinear, for_each_subtriangle, Mesh};
use crate::geometry;
use crate::scene::Scene;
use crate::visibility::PolygonBvh;

/// How many times an element straddling a contact is split in four: three levels leave the
/// straddling pieces 1/8 of the element across (1/64 of its area).
pub const CONTACT_DEPTH: u32 = 3;

/// Meshes of more elements than this are left as they are: at that size `--solver auto`
/// takes hierarchical radiosity, which makes its own leaves and does not use them, and the
/// probe of a million-element building took minutes on two shared cores. (Progressive
/// refinement forced onto such a mesh goes without contact refinement; `check` says so.)
pub const CONTACT_MAX_ELEMENTS: usize = 100_000;

/// Rays probed from a point to decide whether it is buried: along the normal and six
/// directions at 60 degrees from it, 60 degrees apart around it.
pub const PROBE_DIRECTIONS: usize = 7;

/// How many probe rays of a buried point may see a front face: two. Where two faces lie in
/// one plane back to back (the top of a sofa's seat and the base of its back standing on it)
/// a ray from inside the seat may report the base, a front face, rather than the top: which
/// of two hits at the same distance comes first is rounding.
pub const PROBE_SLACK: usize = 2;

/// How near another surface must come to an element, in the element's size (the square
/// root of its area), for it to be probed: 0.15. A light panel 5 cm below the ceiling
/// buries the ceiling above it (the rays from there meet the panel's back); at a twentieth,
/// the ceiling's 0.5 m elements in examples/room.scene missed both panels, and its pixel
/// RMS from the path tracer was 4.61 % against 3.72 % (Cornell box and building_small
/// unchanged or better: BENCHMARKS.md, "Contact refinement at any scale").
pub const COVER_REACH: f64 = 0.15;

/// Sample points per element (and per piece) along each axis: 4 x 4.
const PROBE_GRID: u32 = 4;

/// How far the probe points sit from the centres of their cells, in cells (irrational
/// multiples of the golden ratio's: 0.0618 and 0.0382). Centres fall on round coordinates
/// (a leg's outline at z = 0.85 on an element from 0.8 to 1.2): a point exactly on an
/// outline is buried or not by rounding, so the mesh changed with `--scale` (QA of issue
/// #16: examples/room.scene meshed to 899 elements, 945 at `--scale 0.999`).
const PROBE_OFFSET: [f64; 2] = [0.061_803_398_874_989_48, 0.038_196_601_125_010_52];

/// What [`refine_contacts`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactReport {
    /// Elements of the input mesh that lay partly buried and were split.
    pub split: usize,
    /// Elements of the input mesh that lay wholly buried and were dropped.
    pub dropped: usize,
    /// Of the `split` elements, those of which nothing was buried: split only along the
    /// outline of a face hanging just in front of them ([`Probe`]'s near faces).
    pub shaded_split: usize,
    /// Area removed as buried (scene units squared), whole elements and pieces.
    pub buried_area: f64,
    /// Elements in the refined mesh.
    pub elements: usize,
    /// Elements of the input mesh (the grid).
    pub input_elements: usize,
    /// True when the mesh was too large to refine ([`CONTACT_MAX_ELEMENTS`]).
    pub skipped: bool,
}

/// How much of a piece of surface is buried.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Cover {
    Open,
    Partly,
    Buried,
    /// The sample points agree (all buried, all open or all in a near face's shade), but an
    /// outline crosses the piece
    /// between them (a rim left round what stands on it, the foot of a leg or of books
    /// standing on it): cut it along the outline ([`super::outline_cut`]) and judge the
    /// parts.
    Crossed {
        buried: bool,
    },
    /// Nothing buried, but the light changes inside the piece or across one of its edges
    /// where a near face's outline runs ([`Probe`]'s near faces; never for the quadtrees):
    /// split towards the outline as a straddling piece, and cut along it at
    /// [`CONTACT_DEPTH`], every part kept.
    Shade,
}

/// Splits the elements of `mesh` (cut from `scene`) that lie partly buried under or inside
/// other surfaces of the scene, and drops the buried pieces (module documentation).
/// `occluders` is the BVH over the scene's surfaces. Returns the mesh unchanged (shared
/// vertices, same element order) when nothing is buried.
pub fn refine_contacts(
    mesh: &Mesh,
    scene: &Scene,
    occluders: &PolygonBvh,
) -> (Mesh, ContactReport) {
    refine(mesh, scene, occluders, true)
}

/// [`refine_contacts`] without the cut along outlines: the pieces still straddling an
/// outline at [`CONTACT_DEPTH`] are kept whole, as hierarchical radiosity's quadtrees keep
/// their leaves (which cannot be cut). The mesh on which a dense solve and hierarchical
/// radiosity are compared piece for piece.
pub fn refine_contacts_as_quadtrees(
    mesh: &Mesh,
    scene: &Scene,
    occluders: &PolygonBvh,
) -> (Mesh, ContactReport) {
    refine(mesh, scene, occluders, false)
}

fn refine(
    mesh: &Mesh,
    scene: &Scene,
    occluders: &PolygonBvh,
    cut_outlines: bool,
) -> (Mesh, ContactReport) {
    if mesh.len() > CONTACT_MAX_ELEMENTS {
        let report = ContactReport {
            elements: mesh.len(),
            input_elements: mesh.len(),
            skipped: true,
            ..ContactReport::default()
        };
        return (mesh.clone(), report);
    }
    let probe = Probe {
        cut_outlines,
        // Only the dense mesh follows near faces: hierarchical radiosity's quadtrees (and
        // the mesh refined as they are) refine their own leaves where the light changes.
        near_gaps: if cut_outlines {
            near_gaps(mesh, scene.surfaces.len())
        } else {
            Vec::new()
        },
        ..Probe::new(scene, occluders)
    };
    // Per element: None where it stays as it is, else the pieces it becomes; and whether
    // it was split for the light of a near face alone (its verdict `Shade`, or crossed by
    // an outline with its samples open).
    let (refined, for_shade): (Vec<Option<Vec<Vec<DVec3>>>>, Vec<bool>) = (0..mesh.len())
        .into_par_iter()
        .map(|e| {
            let corners: Vec<DVec3> = mesh.corner_positions(e).collect();
            let el = &mesh.elements[e];
            if !probe.has_cover_nearby(el.surface, &corners, el.normal) {
                return (None, false);
            }
            let mut pieces = Vec::new();
            let verdict = probe.cover(el.surface, &corners, el.normal);
            let for_shade = matches!(verdict, Cover::Shade | Cover::Crossed { buried: false });
            match verdict {
                Cover::Open => return (None, false),
                Cover::Buried => {}
                Cover::Crossed { .. } if probe.cut_outlines => {
                    probe.cut_along_outlines(el.surface, corners.clone(), el.normal, &mut pieces)
                }
                // As the quadtrees: an open patch crossed by an outline is kept as its
                // samples judge it, a buried one refined as a straddling one.
                Cover::Crossed { buried: false } => return (None, false),
                Cover::Partly | Cover::Shade | Cover::Crossed { buried: true } => {
                    probe.split_into(el.surface, corners.clone(), el.normal, 1, &mut pieces)
                }
            }
            // Cut into parts of which none was buried: the element as it was.
            if pieces.len() == 1 && pieces[0] == corners {
                return (None, false);
            }
            (Some(pieces), for_shade)
        })
        .unzip();

    let mut report = ContactReport {
        input_elements: mesh.len(),
        ..ContactReport::default()
    };
    for (e, r) in refined.iter().enumerate() {
        if let Some(pieces) = r {
            let kept: f64 = pieces.iter().map(|p| geometry::polygon_area(p)).sum();
            let buried = mesh.elements[e].area - kept;
            report.buried_area += buried;
            if pieces.is_empty() {
                report.dropped += 1;
            } else {
                report.split += 1;
                // Pieces tile what is kept to rounding (the cuts' and quarters' corners).
                if for_shade[e] && buried <= 1e-9 * mesh.elements[e].area {
                    report.shaded_split += 1;
                }
            }
        }
    }
    if report.split == 0 && report.dropped == 0 {
        report.elements = mesh.len();
        return (mesh.clone(), report);
    }

    let refined_mesh = mesh.with_pieces(scene.surfaces.len(), &refined);
    report.elements = refined_mesh.len();
    (refined_mesh, report)
}

/// The rays and box queries that decide what is buried (hierarchical radiosity uses it
/// too, on its quadtrees' patches: `solve/hierarchical/contact.rs`).
pub(crate) struct Probe<'a> {
    occluders: &'a PolygonBvh,
    /// Unit front normal of every surface.
    normals: Vec<DVec3>,
    /// Every surface's corners.
    polygons: Vec<&'a [DVec3]>,
    /// How far above a surface the rays start: far below any gap worth resolving, far above
    /// rounding (1e-7 of the scene's size).
    lift: f64,
    /// Per surface, the surfaces that lie on it ([`crate::scene::lying_on`]: in its plane or
    /// a hair above it, where the rays cannot see them): a point under one is buried.
    covers: Vec<Vec<u32>>,
    /// Whether pieces are cut along the outlines that cross them ([`Cover::Crossed`]; at
    /// [`CONTACT_DEPTH`]): true but for [`refine_contacts_as_quadtrees`].
    cut_outlines: bool,
    /// Per surface, how near in front of it a face shades it ([`near_gaps`]): a point whose
    /// normal meets a face within this distance is in its shade, and pieces are split and cut
    /// along such faces' outlines as along buried ones, keeping every part. Empty for the
    /// quadtrees and their comparison mesh (no near faces followed).
    near_gaps: Vec<f64>,
    /// Every surface's size, the square root of its area.
    face_sizes: Vec<f64>,
}

/// Surfaces whose elements are smaller than this fraction of the mesh's largest (in size,
/// the square root of the area) follow no near faces: 1/4. Their elements are already small
/// beside the walls' and floors', and the books of a generated bookcase, standing 1 cm
/// apart, were cut into 30 to 50 pieces each, doubling building_small's elements (3,466 to
/// 7,005) for faces a picture shows a few pixels wide.
const NEAR_MIN_SIZE: f64 = 0.25;

/// Near faces further in front than this fraction of their own size are not followed:
/// 1/4. Their shade is shallow and its edge soft (a chair's seat 45 cm above the floor,
/// 45 cm across), so an outline would cut the surface where the light does not step.
const NEAR_SHARP: f64 = 0.25;

/// How parallel to a surface a near face must be for its shade to be followed: the cosine
/// of the angle between them at least 0.95 (18 degrees). Its outline is taken from the edges
/// that lie wholly within the gap; a face tilted across the gap has no such outline, and its
/// shade ends where the gap does, not where the light steps.
const NEAR_PARALLEL: f64 = 0.95;

/// Near faces smaller than this fraction of a surface's elements (in size) are not followed
/// on it: 1/3. The light they take is a small part of the element's, and the books standing
/// 2 cm beside a generated bookcase's side cut it into 200 pieces, three fifths of what near
/// faces added to building_small (a book's side is 0.28 of the bookcase side's size; a
/// bookcase's bottom shelf 0.41 of the floor's 1.4 m elements, the sofa's back 1.9 of the
/// room's wall elements).
const NEAR_FACE_MIN: f64 = 1.0 / 3.0;

/// How far in front of a surface, in its elements' size, a face is followed ([`near_gaps`]):
/// half an element. At 0.15 (as [`COVER_REACH`]) the sofa's back 5 cm before the wall of
/// examples/room.scene was followed at the default 0.5 m elements but not at `--max-area
/// 0.1` (0.32 m), where the smoothed wall above it came back 18 % too dark over 30 cm (QA
/// pass 20 of issue #16: a finer mesh made it worse); at a half it is followed down to
/// 0.1 m elements.
pub const NEAR_REACH: f64 = 0.5;

/// Per surface of `mesh`, the gap below which a face standing parallel in front of it is
/// followed: [`NEAR_REACH`] of its largest element's size (25 cm for the 0.5 m elements of
/// examples/room.scene, where the sofa's back stands 5 cm from the wall and the cupboard 2
/// cm), and no more than [`NEAR_SHARP`] of the face's own size (checked per face).
///
/// The light under a face hanging a gap g in front of a surface falls off over about g at
/// its outline (the penumbra of the light from the room, seen past the face's edge), so an
/// element much larger than g that straddles the outline averages a dark and a lit part: the
/// wall above the sofa's back rendered 7-16 % too dark over 30 cm in smooth shading, the floor
/// under a bookcase's bottom shelf (5 cm) twice too bright (QA pass 18 of issue #16). This is
/// discontinuity meshing along the outlines of near occluders (Lischinski, Tampieri and
/// Greenberg 1992, "Discontinuity meshing for accurate radiosity"), for the faces near
/// enough that the outline is the discontinuity; the umbrae of far occluders are left to
/// the grid.
fn near_gaps(mesh: &Mesh, surfaces: usize) -> Vec<f64> {
    let largest = mesh
        .elements
        .iter()
        .map(|e| e.area)
        .fold(0.0, f64::max)
        .sqrt();
    let mut gaps = vec![0.0f64; surfaces];
    for el in &mesh.elements {
        let size = el.area.sqrt();
        if size >= NEAR_MIN_SIZE * largest {
            let gap = &mut gaps[el.surface as usize];
            *gap = gap.max(NEAR_REACH * size);
        }
    }
    gaps
}

/// Which states the sample points of a piece take: under a cover, in the shade of a near
/// face, in the open.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct States {
    buried: bool,
    shaded: bool,
    open: bool,
}

impl States {
    fn mixed(self) -> bool {
        (self.buried as u8 + self.shaded as u8 + self.open as u8) > 1
    }
}

impl<'a> Probe<'a> {
    pub(crate) fn new(scene: &'a Scene, occluders: &'a PolygonBvh) -> Probe<'a> {
        Probe {
            occluders,
            normals: scene
                .surfaces
                .iter()
                .map(|s| geometry::polygon_normal(&s.vertices).unwrap_or(DVec3::Z))
                .collect(),
            polygons: scene
                .surfaces
                .iter()
                .map(|s| s.vertices.as_slice())
                .collect(),
            lift: 1e-7 * occluders.scale(),
            covers: {
                let mut covers = vec![Vec::new(); scene.surfaces.len()];
                for o in crate::scene::lying_on(scene, occluders) {
                    covers[o.lower as usize].push(o.upper);
                }
                covers
            },
            cut_outlines: true,
            near_gaps: Vec::new(),
            face_sizes: scene
                .surfaces
                .iter()
                .map(|s| geometry::polygon_area(&s.vertices).sqrt())
                .collect(),
        }
    }

    /// Whether `surface` follows the outline of the near face `face`: not its twin, and not
    /// much smaller than its elements ([`NEAR_FACE_MIN`]).
    fn follows(&self, surface: u32, face: u32) -> bool {
        let element = self.near_gaps.get(surface as usize).copied().unwrap_or(0.0) / NEAR_REACH;
        self.face_sizes[face as usize] >= NEAR_FACE_MIN * element && !self.twins(face, surface)
    }

    /// Whether the point `p` of `surface` (front normal `n`), not buried, is in the shade of
    /// a face within the surface's near gap in front of it ([`near_gaps`]).
    fn shaded(&self, surface: u32, p: DVec3, n: DVec3) -> bool {
        let gap = self.near_gaps.get(surface as usize).copied().unwrap_or(0.0);
        gap > 0.0
            && self
                .occluders
                .closest_hit(p + self.lift * n, n, 0.0, gap)
                .is_some_and(|hit| {
                    hit.t <= gap
                        && hit.t <= NEAR_SHARP * self.face_sizes[hit.id as usize]
                        && self.normals[hit.id as usize].dot(n).abs() >= NEAR_PARALLEL
                        && self.follows(surface, hit.id)
                })
    }

    /// True when a surface lying on `surface` covers the point `p` of it.
    fn under_cover(&self, surface: u32, p: DVec3) -> bool {
        let n = self.normals[surface as usize];
        self.covers[surface as usize]
            .iter()
            .any(|&t| crate::scene::overlap::covers(self.polygons[t as usize], n, p))
    }

    /// True when another surface reaches within [`COVER_REACH`] of the element's size of
    /// it (or the surface's near gap, [`near_gaps`], where that is wider) and has some part
    /// in front of its plane, or is pressed against it face to face:
    /// only then can part of it be buried. (A surface wholly behind the plane, or lying in
    /// it, cannot cover it; a cover standing further off, such as the top of a bottomless
    /// box whose sides are far from this element, is missed: the scenes' boxes have all six
    /// faces.)
    pub(crate) fn has_cover_nearby(&self, surface: u32, corners: &[DVec3], normal: DVec3) -> bool {
        let size = geometry::polygon_area(corners).sqrt();
        let near = self.near_gaps.get(surface as usize).copied().unwrap_or(0.0);
        let reach = (COVER_REACH * size).max(near) + self.lift;
        let (lo, hi) = geometry::bounds(corners.iter().copied());
        let mut candidates = Vec::new();
        self.occluders.overlapping(
            lo - DVec3::splat(reach),
            hi + DVec3::splat(reach),
            &mut candidates,
        );
        // A surface lying on this one, whose box reaches the element's.
        let covered = self.covers[surface as usize].iter().any(|&t| {
            let (clo, chi) = geometry::bounds(self.polygons[t as usize].iter().copied());
            geometry::boxes_meet(lo, hi, clo, chi, reach)
        });
        if covered {
            return true;
        }
        // Another surface with a corner in front of the plane, or one pressed face to face
        // against it (the base of a table top on a leg's top: in the same plane, facing the
        // other way; missed before where rounding put its corners exactly in the plane, so
        // the mesh changed with `--scale`, QA of issue #16).
        let origin = corners[0];
        candidates.into_iter().any(|k| {
            let s = self.occluders.id_of(k);
            let corners = self.polygons[s as usize];
            s != surface
                && (corners
                    .iter()
                    .any(|&v| (v - origin).dot(normal) > self.lift)
                    || (self.normals[s as usize].dot(normal) < -1.0 + 1e-9
                        && corners
                            .iter()
                            .all(|&v| (v - origin).dot(normal).abs() <= self.lift)
                        && !self.twins(s, surface)))
        })
    }

    /// Whether surfaces `a` and `b` are one polygon given twice (a two-sided wall: the same
    /// corners, one copy facing each way), to the probe's lift.
    fn twins(&self, a: u32, b: u32) -> bool {
        let (pa, pb) = (self.polygons[a as usize], self.polygons[b as usize]);
        pa.len() == pb.len()
            && pa
                .iter()
                .all(|&v| pb.iter().any(|&w| (v - w).length() <= self.lift))
    }

    /// Whether the point `p` of a surface with front normal `n` is buried: every probe ray
    /// but [`PROBE_SLACK`] hits the back of a face.
    fn buried(&self, p: DVec3, n: DVec3) -> bool {
        let origin = p + self.lift * n;
        let (t1, t2) = n.any_orthonormal_pair();
        let (sin, cos) = (60f64.to_radians().sin(), 60f64.to_radians().cos());
        // Stop at the first ray past the slack that does not hit a back face: most points
        // are open, and they cost PROBE_SLACK + 1 rays.
        let mut misses = 0;
        (0..PROBE_DIRECTIONS).all(|i| {
            let dir = if i == 0 {
                n
            } else {
                let phi = (i - 1) as f64 * std::f64::consts::TAU / (PROBE_DIRECTIONS - 1) as f64;
                (cos * n + sin * (phi.cos() * t1 + phi.sin() * t2)).normalize()
            };
            // A front face hit where a back face lies in the same plane (a box standing on
            // the floor: the ray from inside it meets its base and the floor together)
            // counts as the back face: which of the two comes first is rounding, and it
            // changed the mesh with `--scale` (QA of issue #16).
            let back = match self.occluders.closest_hit(origin, dir, 0.0, f64::INFINITY) {
                Some(hit) => {
                    self.normals[hit.id as usize].dot(dir) > 0.0
                        || self.occluders.back_face_at(
                            origin + hit.t * dir,
                            dir,
                            self.lift,
                            |back| !self.twins(hit.id, back),
                        )
                }
                None => false,
            };
            if !back {
                misses += 1;
            }
            misses <= PROBE_SLACK
        })
    }

    /// How much of the piece `corners` (3 or 4 corners) of `surface` is buried, judged at
    /// its 4 x 4 sample points: under a surface lying on it, or by the probe rays.
    pub(crate) fn cover(&self, surface: u32, corners: &[DVec3], normal: DVec3) -> Cover {
        let points = sample_points(corners);
        let states = self.states(surface, &points, normal);
        if states.mixed() {
            return if states.buried {
                Cover::Partly
            } else {
                Cover::Shade
            };
        }
        let buried = states.buried;
        // The samples agree, but an outline may cross the piece between them: an open rim
        // round what stands on it (QA pass 18 of #16: the 2 cm of a bed's frame round its
        // mattress was dropped whole, a black line round every bed), or a buried foot (of a
        // leg, of books on a shelf) whose share of the piece would send and take light.
        if crosses(
            corners,
            normal,
            &self.outline_edges(surface, corners, normal),
        ) {
            Cover::Crossed { buried }
        } else if buried {
            Cover::Buried
        } else if self.shade_changes_along(surface, corners, normal, states.shaded) {
            Cover::Shade
        } else {
            Cover::Open
        }
    }

    /// Whether a near face's outline runs along an edge of the piece (not buried; in the
    /// shade of near faces where `shaded`) with the light changing across it: the point
    /// 1/16 of the piece's size beyond the stretch's middle, on the surface, is shaded where
    /// the piece is not or the other way round. Such a piece is split towards the outline as
    /// one it crosses, so that smooth shading, which shares a vertex's value between the
    /// elements round it, blends the two sides over a narrow row of pieces, not over whole
    /// elements (the wall above the sofa's back in examples/room.scene, 7-16 % too dark over
    /// 30 cm: QA pass 18 of issue #16).
    fn shade_changes_along(
        &self,
        surface: u32,
        corners: &[DVec3],
        normal: DVec3,
        shaded: bool,
    ) -> bool {
        if self.near_gaps.is_empty() {
            return false;
        }
        let edges = self.near_edges(surface, corners, normal);
        if edges.is_empty() {
            return false;
        }
        let step = geometry::polygon_area(corners).sqrt() / 16.0;
        let polygon = self.polygons[surface as usize];
        runs_along(corners, normal, &edges)
            .into_iter()
            .any(|(middle, outward)| {
                let beyond = middle + step * outward;
                crate::scene::overlap::covers(polygon, normal, beyond)
                    && !self.under_cover(surface, beyond)
                    && !self.buried(beyond, normal)
                    && self.shaded(surface, beyond, normal) != shaded
            })
    }

    /// The states `points` of `surface` take, stopping at the second.
    fn states(&self, surface: u32, points: &[DVec3], normal: DVec3) -> States {
        let mut states = States::default();
        for &p in points {
            if self.under_cover(surface, p) || self.buried(p, normal) {
                states.buried = true;
            } else if self.shaded(surface, p, normal) {
                states.shaded = true;
            } else {
                states.open = true;
            }
            if states.mixed() {
                break;
            }
        }
        states
    }

    /// Splits a partly buried piece (or one a near face's shade parts, [`Cover::Shade`]) in
    /// four, at `level` (1 for the element's children), and appends to `out` the pieces not
    /// buried: a child is split again while it is partly buried or parted by the shade and
    /// `level` is below [`CONTACT_DEPTH`].
    fn split_into(
        &self,
        surface: u32,
        corners: Vec<DVec3>,
        normal: DVec3,
        level: u32,
        out: &mut Vec<Vec<DVec3>>,
    ) {
        for child in quarters(&corners) {
            match self.cover(surface, &child, normal) {
                Cover::Open => out.push(child),
                Cover::Buried => {}
                // Cut along the outline where it crosses a child between its samples, or
                // where the quadtree stops.
                Cover::Crossed { .. } if self.cut_outlines => {
                    self.cut_along_outlines(surface, child, normal, out)
                }
                Cover::Partly | Cover::Shade if level >= CONTACT_DEPTH && self.cut_outlines => {
                    self.cut_along_outlines(surface, child, normal, out)
                }
                // As the quadtrees (`solve/hierarchical/contact.rs`): an open child crossed
                // by an outline kept, a straddling one kept at the last level, a buried one
                // crossed by an outline kept there where some part of it is open.
                Cover::Crossed { buried: false } => out.push(child),
                Cover::Partly | Cover::Shade if level >= CONTACT_DEPTH => out.push(child),
                Cover::Crossed { buried: true } if level >= CONTACT_DEPTH => {
                    if self.has_open_part(surface, &child, normal) {
                        out.push(child)
                    }
                }
                Cover::Partly | Cover::Shade | Cover::Crossed { buried: true } => {
                    self.split_into(surface, child, normal, level + 1, out)
                }
            }
        }
    }
}

impl Probe<'_> {
    /// A piece still partly buried at [`CONTACT_DEPTH`], or crossed by an outline between
    /// its samples, cut along the outlines that cross it ([`super::outline_cut`]); appends
    /// to `out` the parts not buried, or the piece whole where no part is buried and no near
    /// face's shade parts them (a cut that buries nothing only makes elements: a panel
    /// standing on the floor). A part that is
    /// still partly buried (an outline no surface edge gives, such as a sofa's curved foot)
    /// is kept, as the whole piece was before.
    fn cut_along_outlines(
        &self,
        surface: u32,
        piece: Vec<DVec3>,
        normal: DVec3,
        out: &mut Vec<Vec<DVec3>>,
    ) {
        match self.open_parts(surface, &piece, normal) {
            None => out.push(piece),
            Some(parts) => out.extend(parts),
        }
    }

    /// The parts of `piece` not buried once it is cut along the outlines that cross it, or
    /// `None` where none is buried and the parts not buried all lie alike in a near face's
    /// shade or out of it (or nothing crosses it).
    fn open_parts(&self, surface: u32, piece: &[DVec3], normal: DVec3) -> Option<Vec<Vec<DVec3>>> {
        let edges = self.outline_edges(surface, piece, normal);
        let parts = cut_along(piece, normal, &edges);
        if parts.len() < 2 {
            return None;
        }
        let count = parts.len();
        let open: Vec<Vec<DVec3>> = parts
            .into_iter()
            .filter(|part| {
                !matches!(
                    self.cover(surface, part, normal),
                    Cover::Buried | Cover::Crossed { buried: true }
                )
            })
            .collect();
        if open.len() < count {
            return Some(open);
        }
        // Nothing buried: the cut is kept where it parts shade from light under a near face
        // (the parts' samples differ), the piece whole otherwise.
        if self.near_gaps.is_empty() {
            return None;
        }
        // Parts still partly buried (an outline no edge gives) are no matter here: before
        // near faces were followed such a cut was undone, and it still is.
        let lit: Vec<States> = open
            .iter()
            .map(|part| self.states(surface, &sample_points(part), normal))
            .filter(|s| !s.buried)
            .collect();
        let apart = lit
            .iter()
            .any(|s| (s.shaded && s.open) || s.shaded != lit[0].shaded);
        apart.then_some(open)
    }

    /// Whether some part of a piece whose samples are all buried, cut along the outlines
    /// that cross it, is open (hierarchical radiosity keeps such a patch at its last level
    /// and buries it otherwise: it cannot cut it).
    pub(crate) fn has_open_part(&self, surface: u32, piece: &[DVec3], normal: DVec3) -> bool {
        match self.open_parts(surface, piece, normal) {
            Some(open) => !open.is_empty(),
            // Nothing buried once cut: its samples said otherwise; keep it.
            None => true,
        }
    }

    /// The edges along which a piece of `surface` may be buried: those of the surfaces lying
    /// on it (projected onto its plane) and those of other surfaces that lie in its plane,
    /// to the probe's lift (the foot of a box standing on it, the base of one pressed against
    /// it), near the piece.
    fn outline_edges(&self, surface: u32, piece: &[DVec3], normal: DVec3) -> Vec<OutlineEdge> {
        let origin = piece[0];
        let onto = |p: DVec3| p - (p - origin).dot(normal) * normal;
        let (lo, hi) = geometry::bounds(piece.iter().copied());
        let mut edges = Vec::new();
        let mut push_edges = |polygon: &[DVec3], in_plane_only: bool| {
            let k = polygon.len();
            for i in 0..k {
                let (a, b) = (polygon[i], polygon[(i + 1) % k]);
                let in_plane = (a - origin).dot(normal).abs() <= self.lift
                    && (b - origin).dot(normal).abs() <= self.lift;
                if !in_plane_only || in_plane {
                    edges.push((onto(a), onto(b)));
                }
            }
        };
        // The covers whose box (projected, so their gap above the plane is no matter)
        // reaches the piece's: a floor under many rugs asks only the near ones.
        for &t in &self.covers[surface as usize] {
            let cover = self.polygons[t as usize];
            let (clo, chi) = geometry::bounds(cover.iter().map(|&v| onto(v)));
            if geometry::boxes_meet(lo, hi, clo, chi, self.lift) {
                push_edges(cover, false);
            }
        }
        let mut candidates = Vec::new();
        let reach = DVec3::splat(self.lift);
        self.occluders
            .overlapping(lo - reach, hi + reach, &mut candidates);
        let mut near: Vec<u32> = candidates
            .into_iter()
            .map(|k| self.occluders.id_of(k))
            .filter(|&s| s != surface && !self.covers[surface as usize].contains(&s))
            .collect();
        near.sort_unstable();
        near.dedup();
        for s in near {
            if !self.twins(s, surface) {
                push_edges(self.polygons[s as usize], true);
            }
        }
        edges.extend(self.near_edges(surface, piece, normal));
        edges
    }

    /// The edges of faces hanging within `surface`'s near gap in front of the plane of
    /// `piece` (both ends between the lift and the gap), projected onto it: the outlines of
    /// their shade ([`near_gaps`]). None where near faces are not followed.
    fn near_edges(&self, surface: u32, piece: &[DVec3], normal: DVec3) -> Vec<OutlineEdge> {
        let origin = piece[0];
        let onto = |p: DVec3| p - (p - origin).dot(normal) * normal;
        let (lo, hi) = geometry::bounds(piece.iter().copied());
        let mut edges = Vec::new();
        let gap = self.near_gaps.get(surface as usize).copied().unwrap_or(0.0);
        if gap > 0.0 {
            let mut candidates = Vec::new();
            let reach = DVec3::splat(gap);
            self.occluders
                .overlapping(lo - reach, hi + reach, &mut candidates);
            let mut near: Vec<u32> = candidates
                .into_iter()
                .map(|k| self.occluders.id_of(k))
                .filter(|&s| s != surface)
                .collect();
            near.sort_unstable();
            near.dedup();
            let within = |p: DVec3, sharp: f64| {
                let h = (p - origin).dot(normal);
                h > self.lift && h <= gap && h <= sharp
            };
            for s in near {
                if !self.follows(surface, s) {
                    continue;
                }
                let polygon = self.polygons[s as usize];
                let sharp = NEAR_SHARP * self.face_sizes[s as usize];
                let k = polygon.len();
                for i in 0..k {
                    let (a, b) = (polygon[i], polygon[(i + 1) % k]);
                    if within(a, sharp) && within(b, sharp) {
                        edges.push((onto(a), onto(b)));
                    }
                }
            }
        }
        edges
    }
}

/// The 4 x 4 sample points of a piece (3 or 4 corners): the centres of the cells of its
/// bilinear grid, or of its 16 subtriangles, moved by [`PROBE_OFFSET`].
fn sample_points(corners: &[DVec3]) -> Vec<DVec3> {
    let k = PROBE_GRID;
    let mut points = Vec::with_capacity((k * k) as usize);
    if corners.len() == 4 {
        for j in 0..k {
            for i in 0..k {
                let (u, v) = (
                    (i as f64 + 0.5 + PROBE_OFFSET[0]) / k as f64,
                    (j as f64 + 0.5 + PROBE_OFFSET[1]) / k as f64,
                );
                points.push(bilinear(corners, u, v));
            }
        }
    } else {
        let [a, b] = PROBE_OFFSET;
        for_each_subtriangle([corners[0], corners[1], corners[2]], k, |t| {
            points
                .push((1.0 / 3.0 + a) * t[0] + (1.0 / 3.0 + b) * t[1] + (1.0 / 3.0 - a - b) * t[2])
        });
    }
    points
}

/// The four children of a quadrilateral (at its bilinear midpoints) or a triangle (at its
/// edge midpoints), wound as the parent. Edge midpoints are computed from the edge's two
/// ends alone, so neighbouring pieces compute bit-identical shared corners.
pub(super) fn quarters(c: &[DVec3]) -> Vec<Vec<DVec3>> {
    let mid = |a: DVec3, b: DVec3| 0.5 * (a + b);
    if c.len() == 4 {
        let (a, b, cc, d) = (c[0], c[1], c[2], c[3]);
        let (ab, bc, cd, da) = (mid(a, b), mid(b, cc), mid(cc, d), mid(d, a));
        let m = bilinear(c, 0.5, 0.5);
        vec![
            vec![a, ab, m, da],
            vec![ab, b, bc, m],
            vec![m, bc, cc, cd],
            vec![da, m, cd, d],
        ]
    } else {
        let (a, b, cc) = (c[0], c[1], c[2]);
        let (ab, bc, ca) = (mid(a, b), mid(b, cc), mid(cc, a));
        vec![
            vec![a, ab, ca],
            vec![ab, b, bc],
            vec![ca, bc, cc],
            vec![ab, bc, ca],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::mesh_scene;
    use crate::scene::shape::{axis_aligned_base, box_faces, Facing};
    use crate::scene::{Rgb, Surface};
    use crate::visibility::PolygonBvh;
    use glam::dvec3;

    fn surface(name: &str, vertices: Vec<DVec3>) -> Surface {
        Surface {
            name: name.to_string(),
            emission: Rgb::BLACK,
            reflectance: Rgb([0.5; 3]),
            vertices,
            photometry: Default::default(),
        }
    }

    /// A 4 x 4 floor (facing +y) cut into 1 x 1 elements, with a closed box standing on it
    /// whose footprint is [x0, x1] x [z0, z1].
    fn floor_with_box(x0: f64, x1: f64, z0: f64, z1: f64) -> Scene {
        let mut surfaces = vec![surface(
            "floor",
            vec![
                dvec3(0., 0., 0.),
                dvec3(0., 0., 4.),
                dvec3(4., 0., 4.),
                dvec3(4., 0., 0.),
            ],
        )];
        let base = axis_aligned_base(dvec3(x0, 0., z0), dvec3(x1 - x0, 0.5, z1 - z0));
        for (k, face) in box_faces(&base, 0.5, Facing::Out).into_iter().enumerate() {
            surfaces.push(surface(&format!("box{k}"), face));
        }
        Scene {
            surfaces,
            camera: None,
            lights: Vec::new(),
        }
    }

    fn refine(scene: &Scene) -> (Mesh, ContactReport) {
        let grid = mesh_scene(scene, 1.0).unwrap();
        let bvh = PolygonBvh::over_surfaces(scene);
        refine_contacts(&grid, scene, &bvh)
    }

    fn floor_area(mesh: &Mesh) -> f64 {
        mesh.surface_elements[0]
            .clone()
            .map(|e| mesh.elements[e as usize].area)
            .sum()
    }

    #[test]
    fn a_room_of_two_sided_walls_keeps_every_element() {
        // A 3 x 2 x 4 room whose six faces are each given twice, facing in and facing out
        // (as CAD and OBJ exports often give walls). A probe ray from a wall meets the
        // opposite wall's two copies at one distance; the outer copy is a back face there,
        // but a two-sided wall buries nothing: every element stays (review of issue #16:
        // counting it as a box's base on the floor dropped whole rooms).
        let base = axis_aligned_base(dvec3(0., 0., 0.), dvec3(3., 2., 4.));
        let mut surfaces = Vec::new();
        for facing in [Facing::In, Facing::Out] {
            for (k, face) in box_faces(&base, 2.0, facing).into_iter().enumerate() {
                surfaces.push(surface(&format!("wall{k}"), face));
            }
        }
        let scene = Scene {
            surfaces,
            camera: None,
            lights: Vec::new(),
        };
        let grid = mesh_scene(&scene, 1.0).unwrap();
        let (mesh, report) = refine(&scene);
        assert_eq!(report.dropped, 0, "{report:?}");
        assert_eq!(report.split, 0, "{report:?}");
        assert_eq!(mesh.len(), grid.len());
    }

    #[test]
    fn a_box_on_grid_lines_drops_its_footprint_exactly() {
        // The footprint [1, 3] x [1, 2] covers two whole elements and touches others only
        // along their edges: they are dropped, nothing is split.
        let scene = floor_with_box(1., 3., 1., 2.);
        let (mesh, report) = refine(&scene);
        assert_eq!(report.dropped, 2, "{report:?}");
        assert_eq!(report.split, 0, "{report:?}");
        assert!(
            (floor_area(&mesh) - 14.0).abs() < 1e-12,
            "{}",
            floor_area(&mesh)
        );
    }

    #[test]
    fn a_box_across_elements_is_cut_along_its_outline() {
        // The footprint [0.5, 2.5] x [0.5, 1.5] (2 m^2) lies on dyadic lines of the 1 x 1
        // grid at level 1, so the refinement recovers it exactly: 4 m^2 of the floor... of
        // which 2 m^2 are buried.
        let scene = floor_with_box(0.5, 2.5, 0.5, 1.5);
        let (mesh, report) = refine(&scene);
        assert!((report.buried_area - 2.0).abs() < 1e-9, "{report:?}");
        assert!(
            (floor_area(&mesh) - 14.0).abs() < 1e-9,
            "{}",
            floor_area(&mesh)
        );
        // A footprint off the dyadic lines, [0.3, 2.3] x [0.3, 1.3]: the pieces still
        // straddling its outline at 1/8 x 1/8 are cut along the box's bottom edges, so the
        // floor kept is the exact 14 m^2 (to rounding; before the cut it was up to one row of
        // such pieces along the 6 m outline more).
        let scene = floor_with_box(0.3, 2.3, 0.3, 1.3);
        let (mesh, report) = refine(&scene);
        let kept = floor_area(&mesh);
        assert!((kept - 14.0).abs() < 1e-9, "{kept}");
        // Split for the box standing on it, none for a near face's shade alone (review:
        // elements whose straddling pieces were all kept counted as such), on the cut mesh
        // and on the quadtrees' comparison mesh.
        assert!(report.split > 0 && report.shaded_split == 0, "{report:?}");
        let grid = mesh_scene(&scene, 1.0).unwrap();
        let bvh = PolygonBvh::over_surfaces(&scene);
        let (_, report) = refine_contacts_as_quadtrees(&grid, &scene, &bvh);
        assert!(report.split > 0 && report.shaded_split == 0, "{report:?}");
        assert_eq!(report.input_elements, grid.len());
    }

    #[test]
    fn a_rug_in_the_floors_plane_or_a_hair_above_it_buries_what_it_covers() {
        // Floor [0, 4]^2 (1 x 1 elements) and a rug over [0.5, 2.5] x [1, 2], exactly in the
        // floor's plane or 1e-4 above it (there the probe rays' BVH skips boxes a ray leaves
        // within 1e-4 of its origin). The rug covers 2 m^2, on dyadic lines of the grid at
        // level 1: the floor keeps exactly 16 - 2 = 14 m^2.
        for lift in [0.0, 1e-4] {
            // The rectangle [x0, x1] x [z0, z1] at height y, facing +y.
            let quad = |x0: f64, x1: f64, z0: f64, z1: f64, y: f64| {
                axis_aligned_base(dvec3(x0, y, z0), dvec3(x1 - x0, 0., z1 - z0)).to_vec()
            };
            let scene = Scene {
                surfaces: vec![
                    surface("floor", quad(0., 4., 0., 4., 0.)),
                    surface("rug", quad(0.5, 2.5, 1., 2., lift)),
                ],
                camera: None,
                lights: Vec::new(),
            };
            let (mesh, report) = refine(&scene);
            assert!(
                (floor_area(&mesh) - 14.0).abs() < 1e-9,
                "lift {lift}: floor {} ({report:?})",
                floor_area(&mesh)
            );
            // The rug itself is whole.
            let rug: f64 = mesh.surface_elements[1]
                .clone()
                .map(|e| mesh.elements[e as usize].area)
                .sum();
            assert!((rug - 2.0).abs() < 1e-12, "lift {lift}: rug {rug}");
        }
    }

    #[test]
    fn a_bottomless_box_or_a_rug_off_the_grid_lines_is_cut_along_its_outline() {
        // A box without its base, [0.3, 2.3] x [0.3, 1.3]: the outline is its sides' bottom
        // edges, which lie in the floor's plane. The floor keeps 16 - 2 m^2 to rounding.
        let mut scene = floor_with_box(0.3, 2.3, 0.3, 1.3);
        scene.surfaces.remove(1);
        let (mesh, _) = refine(&scene);
        assert!(
            (floor_area(&mesh) - 14.0).abs() < 1e-9,
            "{}",
            floor_area(&mesh)
        );
        // A rug over [0.3, 2.3] x [1.1, 1.95], in the floor's plane or 5 mm above it (the
        // room's): its edges projected onto the floor. It covers 1.7 m^2. (The element
        // [1, 2] x [1, 2] has all its probe points under it and is cut along both edges.)
        for lift in [0.0, 0.005] {
            let rug = axis_aligned_base(dvec3(0.3, lift, 1.1), dvec3(2.0, 0., 0.85)).to_vec();
            let mut scene = floor_with_box(0.3, 2.3, 0.3, 1.3);
            scene.surfaces.truncate(1);
            scene.surfaces.push(surface("rug", rug));
            let (mesh, _) = refine(&scene);
            let kept = floor_area(&mesh);
            assert!((kept - (16.0 - 1.7)).abs() < 1e-9, "lift {lift}: {kept}");
            // No floor element lies partly under the rug: each one's centroid decides.
            for e in mesh.surface_elements[0].clone() {
                let el = &mesh.elements[e as usize];
                let c = el.centroid;
                let inside = c.x > 0.3 && c.x < 2.3 && c.z > 1.1 && c.z < 1.95;
                assert!(!inside, "element {e} at {c} under the rug");
            }
        }
    }

    #[test]
    fn a_rim_between_the_probe_points_is_kept() {
        // A box over [0.02, 0.98]^2 on the floor element [0, 1]^2 covers all 16 of its
        // probe points and leaves a 2 cm rim (a bed's frame round its mattress, QA pass 18 of
        // #16: dropped whole). The rim, 1 - 0.96^2 = 0.0784 m^2, is kept.
        let scene = floor_with_box(0.02, 0.98, 0.02, 0.98);
        let (mesh, report) = refine(&scene);
        assert_eq!(report.dropped, 0, "{report:?}");
        let kept = floor_area(&mesh);
        assert!((kept - (16.0 - 0.96 * 0.96)).abs() < 1e-9, "{kept}");
    }

    #[test]
    fn a_shelf_just_above_the_floor_cuts_it_along_its_outline_and_buries_nothing() {
        // A box hovering 5 cm above the floor (a bookcase's bottom shelf), its footprint
        // [0.3, 2.3] x [0.3, 1.3] off the grid's dyadic lines: within the near gap of the
        // 1 x 1 elements (0.15), so the floor is split and cut along the outline, and
        // nothing is dropped (light reaches under it through the gap).
        let mut scene = floor_with_box(0.3, 2.3, 0.3, 1.3);
        for s in &mut scene.surfaces[1..] {
            for v in &mut s.vertices {
                v.y += 0.05;
            }
        }
        let (mesh, report) = refine(&scene);
        assert_eq!(report.dropped, 0, "{report:?}");
        assert!(
            report.split > 0 && report.shaded_split == report.split,
            "{report:?}"
        );
        // The pieces tile the floor: its 16 m^2 to rounding.
        assert!(
            (floor_area(&mesh) - 16.0).abs() < 1e-9,
            "{}",
            floor_area(&mesh)
        );
        // No floor element straddles the outline: an element whose centroid lies under the
        // footprint has every corner in it (closed, to 1e-9: the cut's corners are computed
        // on the lines), any other has none strictly inside it.
        let within = |p: DVec3, eps: f64| {
            p.x > 0.3 + eps && p.x < 2.3 - eps && p.z > 0.3 + eps && p.z < 1.3 - eps
        };
        for e in mesh.surface_elements[0].clone() {
            let corners: Vec<DVec3> = mesh.corner_positions(e as usize).collect();
            let under = within(mesh.elements[e as usize].centroid, 0.0);
            let straddles = if under {
                corners.iter().any(|&p| !within(p, -1e-9))
            } else {
                corners.iter().any(|&p| within(p, 1e-9))
            };
            assert!(!straddles, "element {e} straddles the outline: {corners:?}");
        }
        // The hierarchy's comparison mesh follows no near faces.
        let grid = mesh_scene(&scene, 1.0).unwrap();
        let bvh = PolygonBvh::over_surfaces(&scene);
        let (quadtrees, report) = refine_contacts_as_quadtrees(&grid, &scene, &bvh);
        assert_eq!((report.split, report.dropped), (0, 0), "{report:?}");
        assert_eq!(quadtrees.elements, grid.elements);
    }

    #[test]
    fn a_shelf_outline_on_the_grid_lines_refines_the_elements_along_it() {
        // The shelf's footprint [1, 3] x [1, 2], 5 cm up, on the grid's lines: no element
        // straddles it, but the light changes across it, so the elements on both sides are
        // split towards it and those touching it are 1/8 of an element across (smooth
        // shading blends the two sides over them only).
        let mut scene = floor_with_box(1., 3., 1., 2.);
        for s in &mut scene.surfaces[1..] {
            for v in &mut s.vertices {
                v.y += 0.05;
            }
        }
        let (mesh, report) = refine(&scene);
        assert_eq!(report.dropped, 0, "{report:?}");
        assert!(report.split > 0, "{report:?}");
        assert!(
            (floor_area(&mesh) - 16.0).abs() < 1e-9,
            "{}",
            floor_area(&mesh)
        );
        let on_outline = |p: DVec3| {
            let (x, z) = (p.x, p.z);
            let on = |a: f64, b: f64| (a - b).abs() < 1e-9;
            ((on(x, 1.) || on(x, 3.)) && (1.0..=2.0).contains(&z))
                || ((on(z, 1.) || on(z, 2.)) && (1.0..=3.0).contains(&x))
        };
        let mut touching = 0;
        for e in mesh.surface_elements[0].clone() {
            let el = &mesh.elements[e as usize];
            if mesh
                .corner_positions(e as usize)
                .filter(|&p| on_outline(p))
                .count()
                >= 2
            {
                touching += 1;
                assert!(el.area <= 1.0 / 64.0 + 1e-12, "element {e}: {}", el.area);
            }
        }
        // 6 m of outline, 8 pieces a metre on each side: 48 outside, 48 inside less the 4
        // inside corners' pieces, which touch two sides.
        assert_eq!(touching, 92);
    }

    #[test]
    fn nothing_buried_or_near_leaves_the_mesh_as_it_was() {
        // A box hovering 0.6 above the floor buries nothing (light passes under it) and
        // stands beyond the near gap of the floor's 1 x 1 elements (NEAR_REACH: 0.5; not
        // COVER_REACH, 0.15) and a quarter of its base's size (NEAR_SHARP: 0.35).
        let mut scene = floor_with_box(0.5, 2.5, 0.5, 1.5);
        for s in &mut scene.surfaces[1..] {
            for v in &mut s.vertices {
                v.y += 0.6;
            }
        }
        let grid = mesh_scene(&scene, 1.0).unwrap();
        let (mesh, report) = refine(&scene);
        assert_eq!((report.split, report.dropped), (0, 0), "{report:?}");
        assert_eq!(mesh.elements, grid.elements);
    }
}
