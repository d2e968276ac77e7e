//! The analytical test cases of CIE 171:2006 (*Test cases to assess the accuracy of lighting
//! computer programs*) that apply to a diffuse program, with reference values recomputed here
//! from first principles.
//!
//! # Sources, and what each number rests on
//!
//! The report itself (CIE 171:2006, 97 pages) was not available to this project; what was
//! read is its public summary (cie.co.at), Ashdown's errata page ("CIE 171:2006 - Errata",
//! lightinganalysts.com: case 5.7's Table 19 is wrong, Dau 2007 found it; case 5.8 is a
//! 4 m cube, S_T = 96 m^2, all surfaces uniform diffusers), and the titles of the cases in
//! the published validations (Dau 2007 for AGi32, Dau 2016 for Iray; Maamari, Fontoynont
//! and Adra 2006). The scenes below follow those titles and the 4 m geometry; where the
//! report's exact dimensions, luminaire data or point positions were not readable, this
//! module states its own, and **every reference value is computed here for exactly the
//! scene written**, from:
//!
//! * a point source: `E = I(theta) cos(theta_p) / d^2` (inverse-square and cosine laws);
//! * a Lambertian area source or an opening under a uniform sky of luminance `L`:
//!   `E = pi L F`, `F` the point-to-polygon form factor by Lambert's contour integral
//!   ([`exact::point_polygon_factor`], checked against the corner formula);
//! * one diffuse reflection (5.6, 5.7): `E(p) = ∫ rho E_dir(x) cos cos / (pi r^2) V dA`
//!   over the one reflecting surface, the region it sees and that the source lights cut out
//!   exactly by polygon clipping, each convex piece by a Gauss-Legendre rule converged to
//!   1e-9 (no published table is used, so the Table 19 erratum cannot affect these numbers;
//!   Dau's corrected values apply to the report's own geometry, not reproduced here);
//! * inter-reflection in the closed cube (5.8): all flux is absorbed, so the area-weighted
//!   mean of the total illuminance is `Phi / ((1 - rho) S_T)` and of the indirect
//!   `Phi / S_T * rho / (1 - rho)`, exactly, for any source inside (energy conservation;
//!   the formula CIE 171 gives for this case).
//!
//! The published tables were not available, so no test compares with them; the tests
//! check each reference against an independent closed form or a limit instead.

use glam::{dvec3, DVec2, DVec3};

use super::exact;

/// A measurement point: where and which way the illuminance meter faces.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Name in the points file.
    pub name: String,
    /// Position, metres.
    pub position: DVec3,
    /// Unit normal of the receiving surface.
    pub normal: DVec3,
}

/// What a case compares.
#[derive(Debug, Clone, PartialEq)]
pub enum Check {
    /// The total illuminance at each point against its reference, lux.
    Points {
        /// Reference total illuminance per point.
        reference_lux: Vec<f64>,
    },
    /// The weighted mean of the indirect illuminance over the points (a quadrature of the
    /// mean over every surface) against one value.
    MeanIndirect {
        /// Quadrature weight per point (areas, m^2; they sum to `S_T`).
        weights: Vec<f64>,
        /// Reference mean indirect illuminance, lux.
        reference_lux: f64,
    },
}

/// One validation case, ready to write and run.
#[derive(Debug, Clone)]
pub struct Case {
    /// CIE 171 section, e.g. "5.2", with a suffix for variants ("5.8 rho=0.5").
    pub id: String,
    /// File stem under `validation/`.
    pub stem: String,
    /// What it tests.
    pub title: &'static str,
    /// The scene file, in the contract syntax.
    pub scene: String,
    /// The measurement points.
    pub points: Vec<Point>,
    /// The reference and how to compare.
    pub check: Check,
    /// The target, percent.
    pub tolerance_percent: f64,
    /// How the reference is computed.
    pub source: &'static str,
    /// Which published description the scene follows, and what of it is this project's own.
    pub scene_from: &'static str,
    /// Where the reference values come from, for the table's last column.
    pub reference_from: ReferenceFrom,
}

/// Where a case's reference values come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReferenceFrom {
    /// Recomputed here from first principles for exactly the scene written (no published
    /// table: CIE 171's own tables are for the report's geometry, which was not available).
    FirstPrinciples,
    /// The closed form CIE 171:2006 gives for the case (5.8's energy balance), evaluated
    /// for the scene written.
    Cie171Formula,
}

impl ReferenceFrom {
    /// The label in the table.
    pub fn label(self) -> &'static str {
        match self {
            ReferenceFrom::FirstPrinciples => "first principles (recomputed here)",
            ReferenceFrom::Cie171Formula => "CIE 171:2006 5.8 formula",
        }
    }
}

/// What the cases take from the report: its public summary and Ashdown's errata page were
/// read, not the report's tables, figures or dimensions.
pub const GEOMETRY_NOTE: &str = "CIE 171:2006 itself was not available here (its public \
    summary and Ashdown's errata page were read): each case follows the published \
    description named below, the dimensions, sources and points not given there are this \
    project's, and every reference is computed for exactly the scene written \
    (validation/cie171_<case>.scene, as `--write DIR` writes them), so no published table is \
    compared";

impl Case {
    /// Where the case comes from, for the notes under the table: its title, the published
    /// description its scene follows, and where its reference comes from and how.
    pub fn provenance(&self) -> String {
        format!("{}: {}", self.id, self.provenance_text())
    }

    /// [`Self::provenance`] without the id: the same for the cases of one description (the
    /// seven reflectances of 5.8), which are listed once with all their ids.
    pub fn provenance_text(&self) -> String {
        format!(
            "{}. Scene: after {}. Reference: {}: {}.",
            self.title,
            self.scene_from,
            self.reference_from.label(),
            self.source
        )
    }

    /// The points file (`name,x,y,z,nx,ny,nz`).
    pub fn points_csv(&self) -> String {
        let mut text = String::from("name,x,y,z,nx,ny,nz\n");
        for p in &self.points {
            // + 0.0 turns -0 into 0 in the file.
            let (x, n) = (p.position + 0.0, p.normal + 0.0);
            text.push_str(&format!(
                "{},{},{},{},{},{},{}\n",
                p.name, x.x, x.y, x.z, n.x, n.y, n.z
            ));
        }
        text
    }

    /// Compares computed `(direct, indirect)` illuminances, one per point in order, with the
    /// reference: one row per point, or one row for a mean.
    pub fn compare(&self, computed: &[(f64, f64)]) -> Vec<Row> {
        assert_eq!(computed.len(), self.points.len(), "one result per point");
        match &self.check {
            Check::Points { reference_lux } => self
                .points
                .iter()
                .zip(reference_lux)
                .zip(computed)
                .map(|((p, &reference), &(d, i))| Row::new(&self.id, &p.name, reference, d + i))
                .collect(),
            Check::MeanIndirect {
                weights,
                reference_lux,
            } => {
                let total: f64 = weights.iter().sum();
                let mean = weights
                    .iter()
                    .zip(computed)
                    .map(|(w, c)| w * c.1)
                    .sum::<f64>()
                    / total;
                vec![Row::new(&self.id, "mean indirect", *reference_lux, mean)]
            }
        }
    }
}

/// One line of the validation table.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Case id.
    pub case: String,
    /// Point name (or "mean indirect").
    pub point: String,
    /// Reference, lux.
    pub reference: f64,
    /// Computed, lux.
    pub computed: f64,
}

impl Row {
    fn new(case: &str, point: &str, reference: f64, computed: f64) -> Self {
        Self {
            case: case.to_string(),
            point: point.to_string(),
            reference,
            computed,
        }
    }

    /// `100 (computed - reference) / reference`; `None` where the reference is 0 (then the
    /// computed value itself is the error).
    pub fn difference_percent(&self) -> Option<f64> {
        (self.reference != 0.0).then(|| 100.0 * (self.computed - self.reference) / self.reference)
    }

    /// Whether the row is within `tolerance_percent` (for a zero reference: within
    /// `tolerance_percent` hundredths of a lux).
    pub fn passes(&self, tolerance_percent: f64) -> bool {
        match self.difference_percent() {
            Some(d) => d.abs() <= tolerance_percent,
            None => self.computed.abs() <= tolerance_percent * 1e-2,
        }
    }
}

// Geometry shared by the cases -------------------------------------------------------------

/// The room of 5.2 to 5.11: 4 m by 4 m, 3 m high (x, y on the floor, z up).
const W: f64 = 4.0;
const D: f64 = 4.0;
const H: f64 = 3.0;

/// Reflectance of the one reflecting surface of 5.6 and 5.7 (the floor).
pub const FLOOR_REFLECTANCE: f64 = 0.5;

/// The downlight of 5.2, 5.6 and 5.7: `I0 cos(theta)` about straight down, at the room's
/// centre 0.5 m below the ceiling.
pub const DOWNLIGHT_CD: f64 = 1000.0;
const DOWNLIGHT: DVec3 = dvec3(2.0, 2.0, 2.5);

/// The luminance of the area source of 5.3, cd/m^2.
pub const AREA_LUMINANCE: f64 = 1000.0;

/// The sky luminance of 5.9 and 5.11: an unobstructed horizontal plane under it gets
/// 10 000 lux (`pi L`).
pub const SKY_LUMINANCE: f64 = 10_000.0 / std::f64::consts::PI;

/// The flux of the point source of 5.8, lm.
pub const CUBE_FLUX: f64 = 10_000.0;

/// The reflectances of 5.8.
pub const CUBE_REFLECTANCES: [f64; 7] = [0.0, 0.2, 0.5, 0.7, 0.8, 0.9, 0.95];

/// A rectangle `corner, corner + u, corner + u + v, corner + v`, facing `u x v`.
fn rect(corner: DVec3, u: DVec3, v: DVec3) -> [DVec3; 4] {
    [corner, corner + u, corner + u + v, corner + v]
}

/// A patch of the scene.
struct Patch {
    name: String,
    vertices: [DVec3; 4],
    reflectance: f64,
    luminance: Option<f64>,
    opening: bool,
}

fn patch(name: &str, vertices: [DVec3; 4], reflectance: f64) -> Patch {
    Patch {
        name: name.to_string(),
        vertices,
        reflectance,
        luminance: None,
        opening: false,
    }
}

/// A rectangle `(corner, u, v)` less the hole `[a0, a1] x [b0, b1]` (fractions of `u`, `v`),
/// as up to four rectangles around it.
fn with_hole(
    name: &str,
    corner: DVec3,
    u: DVec3,
    v: DVec3,
    hole: [f64; 4],
    rho: f64,
) -> Vec<Patch> {
    let [a0, a1, b0, b1] = hole;
    let pieces = [
        (0.0, 1.0, 0.0, b0),
        (0.0, 1.0, b1, 1.0),
        (0.0, a0, b0, b1),
        (a1, 1.0, b0, b1),
    ];
    pieces
        .iter()
        .enumerate()
        .filter(|(_, &(u0, u1, v0, v1))| u1 > u0 && v1 > v0)
        .map(|(k, &(u0, u1, v0, v1))| {
            patch(
                &format!("{name}_{}", k + 1),
                rect(corner + u * u0 + v * v0, u * (u1 - u0), v * (v1 - v0)),
                rho,
            )
        })
        .collect()
}

/// The six faces of a `w` x `d` x `h` box from the origin, facing in, each with its
/// reflectance; `hole` cuts a hole in one face (by index: floor, ceiling, x=0, x=w, y=0,
/// y=d) that `fill` fills.
fn room(w: f64, d: f64, h: f64, rho: [f64; 6], hole: Option<(usize, [f64; 4])>) -> Vec<Patch> {
    let faces = [
        ("floor", DVec3::ZERO, dvec3(w, 0., 0.), dvec3(0., d, 0.)),
        (
            "ceiling",
            dvec3(0., 0., h),
            dvec3(0., d, 0.),
            dvec3(w, 0., 0.),
        ),
        ("wall_x0", DVec3::ZERO, dvec3(0., d, 0.), dvec3(0., 0., h)),
        (
            "wall_x1",
            dvec3(w, 0., 0.),
            dvec3(0., 0., h),
            dvec3(0., d, 0.),
        ),
        ("wall_y0", DVec3::ZERO, dvec3(0., 0., h), dvec3(w, 0., 0.)),
        (
            "wall_y1",
            dvec3(0., d, 0.),
            dvec3(w, 0., 0.),
            dvec3(0., 0., h),
        ),
    ];
    let mut patches = Vec::new();
    for (k, &(name, corner, u, v)) in faces.iter().enumerate() {
        match hole {
            Some((face, fractions)) if face == k => {
                patches.extend(with_hole(name, corner, u, v, fractions, rho[k]))
            }
            _ => patches.push(patch(name, rect(corner, u, v), rho[k])),
        }
    }
    patches
}

/// The rectangle that fills `hole` in face `face` of [`room`], facing the same way.
fn hole_rect(w: f64, d: f64, h: f64, face: usize, hole: [f64; 4]) -> [DVec3; 4] {
    let (corner, u, v) = match face {
        1 => (dvec3(0., 0., h), dvec3(0., d, 0.), dvec3(w, 0., 0.)),
        4 => (DVec3::ZERO, dvec3(0., 0., h), dvec3(w, 0., 0.)),
        _ => unreachable!("holes are cut in the ceiling and the y = 0 wall only"),
    };
    let [a0, a1, b0, b1] = hole;
    rect(corner + u * a0 + v * b0, u * (a1 - a0), v * (b1 - b0))
}

/// A point light block.
struct Light {
    name: &'static str,
    position: DVec3,
    /// `INTENSITY I` with this distribution, or `FLUX` for isotropic.
    text: String,
}

fn write_scene(title: &str, max_patch_area: f64, patches: &[Patch], lights: &[Light]) -> String {
    let mut s = format!(
        "// {title}\n// Written by `radiosity validate cie171 --write` (crates/radiosity/src/validation/cie171.rs); metres, lux.\n"
    );
    s.push_str(&format!(
        "MAX_PATCH_AREA {max_patch_area}\nINTEGRAL_STEPS 2\nSCENEBEGIN\n"
    ));
    for p in patches {
        s.push_str(&format!("PATCHBEGIN\n#{}\nVERTICES 4\n", p.name));
        match p.luminance {
            Some(l) => s.push_str(&format!("LUMINANCE {l}\n")),
            None => s.push_str("Er 0\nEg 0\nEb 0\n"),
        }
        // An opening has no reflectance: OPENING stands where Rr Rg Rb would.
        if p.opening {
            s.push_str("OPENING\n");
        } else {
            let r = p.reflectance;
            s.push_str(&format!("Rr {r}\nRg {r}\nRb {r}\n"));
        }
        for (k, v) in p.vertices.iter().enumerate() {
            s.push_str(&format!("VERTEX{k} {} {} {}\n", v.x, v.y, v.z));
        }
        s.push_str("PATCHEND\n");
    }
    for l in lights {
        let p = l.position;
        s.push_str(&format!(
            "LIGHTBEGIN\n#{}\nPOSITION {} {} {}\n{}LIGHTEND\n",
            l.name, p.x, p.y, p.z, l.text
        ));
    }
    s.push_str("SCENEEND\n");
    s
}

fn downlight() -> Light {
    Light {
        name: "Downlight",
        position: DOWNLIGHT,
        text: format!("AIM 0 0 -1\nINTENSITY {DOWNLIGHT_CD}\nDISTRIBUTION COSINE\n"),
    }
}

/// Direct illuminance from the downlight at `p` facing `n` (unoccluded).
fn downlight_illuminance(p: DVec3, n: DVec3) -> f64 {
    let to_light = DOWNLIGHT - p;
    let r = to_light.length();
    let cos_axis = to_light.z / r; // angle from straight down at the light
    let cos_surface = n.dot(to_light) / r;
    if cos_axis <= 0.0 || cos_surface <= 0.0 {
        return 0.0;
    }
    DOWNLIGHT_CD * cos_axis * cos_surface / (r * r)
}

fn point(name: &str, position: DVec3, normal: DVec3) -> Point {
    Point {
        name: name.to_string(),
        position,
        normal,
    }
}

/// Floor points (a diagonal and an off-diagonal one) and one point per wall at height `z`.
fn room_points(wall_z: f64) -> Vec<Point> {
    vec![
        point("floor_centre", dvec3(2.0, 2.0, 0.0), DVec3::Z),
        point("floor_diag_1", dvec3(1.0, 1.0, 0.0), DVec3::Z),
        point("floor_diag_2", dvec3(0.5, 0.5, 0.0), DVec3::Z),
        point("floor_off", dvec3(3.0, 1.5, 0.0), DVec3::Z),
        point("wall_x0", dvec3(0.0, 2.0, wall_z), DVec3::X),
        point("wall_x1", dvec3(W, 1.0, wall_z), -DVec3::X),
        point("wall_y0", dvec3(3.0, 0.0, wall_z), DVec3::Y),
        point("wall_y1", dvec3(2.0, D, wall_z), -DVec3::Y),
    ]
}

// The cases ----------------------------------------------------------------------------------

/// 5.2: a point source (a cosine downlight) in a black room: `E = I cos / d^2`.
pub fn point_source() -> Case {
    let patches = room(W, D, H, [0.0; 6], None);
    let points = room_points(1.0);
    let reference = points
        .iter()
        .map(|p| downlight_illuminance(p.position, p.normal))
        .collect();
    Case {
        id: "5.2".into(),
        stem: "cie171_5_2_point_source".into(),
        title: "point source: a cosine downlight in a black 4 x 4 x 3 m room",
        scene: write_scene("CIE 171 5.2 point source", 1.0, &patches, &[downlight()]),
        points,
        check: Check::Points {
            reference_lux: reference,
        },
        tolerance_percent: 1.0,
        source: "E = I0 cos(theta) cos(theta_p) / d^2 (inverse-square and cosine laws)",
        scene_from: "CIE 171:2006 5.2 (light source directional output, point source), by \
                     its title",
        reference_from: ReferenceFrom::FirstPrinciples,
    }
}

/// The 1 m square area source of 5.3, centred in the ceiling (fractions of the ceiling's
/// `u` = y and `v` = x edges).
const AREA_HOLE: [f64; 4] = [0.375, 0.625, 0.375, 0.625];

/// 5.3: a Lambertian area source (1 m^2 in the ceiling) in a black room: `E = pi L F`.
pub fn area_source() -> Case {
    let mut patches = room(W, D, H, [0.0; 6], Some((1, AREA_HOLE)));
    let source = hole_rect(W, D, H, 1, AREA_HOLE);
    patches.push(Patch {
        name: "source".into(),
        vertices: source,
        reflectance: 0.0,
        luminance: Some(AREA_LUMINANCE),
        opening: false,
    });
    let points = room_points(1.0);
    let reference = points
        .iter()
        .map(|p| exact::polygon_illuminance(p.position, p.normal, &source, AREA_LUMINANCE))
        .collect();
    Case {
        id: "5.3".into(),
        stem: "cie171_5_3_area_source".into(),
        title: "area source: a 1 m^2 Lambertian ceiling panel in a black 4 x 4 x 3 m room",
        scene: write_scene("CIE 171 5.3 area source", 1.0, &patches, &[]),
        points,
        check: Check::Points {
            reference_lux: reference,
        },
        tolerance_percent: 1.0,
        source: "E = pi L F, F by Lambert's contour integral (checked against the corner formula)",
        scene_from: "CIE 171:2006 5.3 (light source directional output, area source), by \
                     its title",
        reference_from: ReferenceFrom::FirstPrinciples,
    }
}

/// The black obstruction of 5.7: a vertical panel at x = 3 m, y from 1 to 3 m, from the
/// floor to 1.5 m.
pub fn obstruction() -> [DVec3; 4] {
    rect(
        dvec3(3.0, 1.0, 0.0),
        dvec3(0.0, 0.0, 1.5),
        dvec3(0.0, 2.0, 0.0),
    )
}

/// Points that see the floor from above its obstruction: ceiling points (facing down) and
/// wall points at 2 m.
fn reflection_points() -> Vec<Point> {
    vec![
        point("ceiling_centre", dvec3(2.0, 2.0, H), -DVec3::Z),
        point("ceiling_1", dvec3(1.0, 1.0, H), -DVec3::Z),
        point("ceiling_2", dvec3(3.5, 2.0, H), -DVec3::Z),
        point("ceiling_3", dvec3(3.5, 3.5, H), -DVec3::Z),
        point("wall_x0", dvec3(0.0, 2.0, 2.0), DVec3::X),
        point("wall_x1", dvec3(W, 2.0, 2.0), -DVec3::X),
        point("wall_x1_side", dvec3(W, 0.5, 2.0), -DVec3::X),
        point("wall_y0", dvec3(2.0, 0.0, 2.0), DVec3::Y),
    ]
}

/// Gauss-Legendre points per triangle edge for the reflection integrals: the integrand is
/// smooth on each clipped piece (the points are at least 2 m from the floor), and the
/// result changes by less than 1e-9 relative from 24 to 32 (a test checks it).
const REFLECTION_ORDER: usize = 24;

/// Reflected (one bounce off the floor) illuminance at `p` facing `n`, with the floor's
/// direct light from the downlight blocked by `obstacle` (if any) and `p`'s view of the
/// floor blocked by it too.
pub fn floor_reflection(p: DVec3, n: DVec3, obstacle: Option<&[DVec3]>, order: usize) -> f64 {
    let floor = [
        DVec2::new(0., 0.),
        DVec2::new(W, 0.),
        DVec2::new(W, D),
        DVec2::new(0., D),
    ];
    let integrand = |x: DVec2| {
        let x3 = dvec3(x.x, x.y, 0.0);
        let exitance = FLOOR_REFLECTANCE * downlight_illuminance(x3, DVec3::Z);
        let to_p = p - x3;
        let r2 = to_p.length_squared();
        let cos_floor = to_p.z / r2.sqrt();
        let cos_p = -n.dot(to_p) / r2.sqrt();
        if cos_p <= 0.0 {
            return 0.0;
        }
        exitance * cos_floor * cos_p / (std::f64::consts::PI * r2)
    };
    let whole = exact::integrate_convex(&floor, order, &integrand);
    let Some(obstacle) = obstacle else {
        return whole;
    };
    // Inclusion-exclusion over the two shadows (from the light, and from p).
    let from_light = exact::clip_convex(&exact::shadow_on_floor(DOWNLIGHT, obstacle), &floor);
    let from_p = exact::clip_convex(&exact::shadow_on_floor(p, obstacle), &floor);
    let both = exact::clip_convex(&from_light, &from_p);
    whole
        - exact::integrate_convex(&from_light, order, &integrand)
        - exact::integrate_convex(&from_p, order, &integrand)
        + exact::integrate_convex(&both, order, &integrand)
}

fn reflection_case(obstructed: bool) -> Case {
    let mut rho = [0.0; 6];
    rho[0] = FLOOR_REFLECTANCE;
    let mut patches = room(W, D, H, rho, None);
    let panel = obstruction();
    if obstructed {
        patches.push(patch("obstruction", panel, 0.0));
    }
    let points = reflection_points();
    let reference = points
        .iter()
        .map(|p| {
            // The direct light at these points passes above the panel (they are at 2 m or
            // more, the light at 2.5 m, the panel's top at 1.5 m).
            downlight_illuminance(p.position, p.normal)
                + floor_reflection(
                    p.position,
                    p.normal,
                    obstructed.then_some(&panel[..]),
                    REFLECTION_ORDER,
                )
        })
        .collect();
    let scene_from = if obstructed {
        "CIE 171:2006 5.7 (diffuse reflections with internal obstructions), by its title; \
         in the report the case is a configuration factor past an obstruction, given as \
         E / E_v in its Table 19, which is wrong (Dau 2007; Ashdown's errata): neither that \
         table nor Dau's corrected values are used, as they are for the report's geometry; \
         this scene (a floor of reflectance 0.5 lit by a downlight, seen past a black panel) \
         is this project's"
    } else {
        "CIE 171:2006 5.6 (diffuse reflections), by its title; the scene (a floor of \
         reflectance 0.5 lit by a downlight, all else black) is this project's"
    };
    let (id, stem, title, name) = if obstructed {
        (
            "5.7",
            "cie171_5_7_reflection_obstructed",
            "diffuse reflection with an obstruction: floor rho 0.5, a black 2 x 1.5 m panel",
            "CIE 171 5.7 diffuse reflection with an obstruction",
        )
    } else {
        (
            "5.6",
            "cie171_5_6_reflection",
            "diffuse reflection: floor rho 0.5, other surfaces black, a cosine downlight",
            "CIE 171 5.6 diffuse reflection without obstruction",
        )
    };
    Case {
        id: id.into(),
        stem: stem.into(),
        title,
        scene: write_scene(name, 0.04, &patches, &[downlight()]),
        points,
        check: Check::Points {
            reference_lux: reference,
        },
        tolerance_percent: 1.0,
        source: "direct: I cos cos / d^2; reflected: one bounce integrated over the lit, visible \
                 floor (shadows cut exactly), Gauss-Legendre; computed here, not CIE's Table 19",
        scene_from,
        reference_from: ReferenceFrom::FirstPrinciples,
    }
}

/// 5.6: diffuse reflection off the floor, no obstruction.
pub fn reflection() -> Case {
    reflection_case(false)
}

/// 5.7: diffuse reflection off the floor past a black panel.
pub fn reflection_obstructed() -> Case {
    reflection_case(true)
}

/// The cube of 5.8: 4 m, `S_T` = 96 m^2.
pub const CUBE: f64 = 4.0;

/// Gauss-Legendre points per face edge for the mean over the cube's faces.
pub const CUBE_ORDER: usize = 8;

/// The quadrature points of 5.8: `CUBE_ORDER^2` Gauss-Legendre points per face, with their
/// areas as weights (summing to 96 m^2).
pub fn cube_points() -> (Vec<Point>, Vec<f64>) {
    let rule = exact::gauss_legendre(CUBE_ORDER);
    let half = CUBE / 2.0;
    let c = DVec3::splat(half);
    let faces = [
        ("floor", DVec3::Z, DVec3::X, DVec3::Y),
        ("ceiling", -DVec3::Z, DVec3::X, DVec3::Y),
        ("wall_x0", DVec3::X, DVec3::Y, DVec3::Z),
        ("wall_x1", -DVec3::X, DVec3::Y, DVec3::Z),
        ("wall_y0", DVec3::Y, DVec3::X, DVec3::Z),
        ("wall_y1", -DVec3::Y, DVec3::X, DVec3::Z),
    ];
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for (name, normal, u, v) in faces {
        for (i, &(a, wa)) in rule.iter().enumerate() {
            for (j, &(b, wb)) in rule.iter().enumerate() {
                let position = c - normal * half + u * (a * half) + v * (b * half);
                points.push(point(&format!("{name}_{i}_{j}"), position, normal));
                weights.push(wa * wb * half * half);
            }
        }
    }
    (points, weights)
}

/// 5.8: inter-reflection in the 4 m cube, all surfaces of reflectance `rho`, an isotropic
/// source of [`CUBE_FLUX`] at the centre: mean indirect `Phi / S_T * rho / (1 - rho)`.
pub fn cube(rho: f64) -> Case {
    let patches = room(CUBE, CUBE, CUBE, [rho; 6], None);
    let light = Light {
        name: "Lamp",
        position: DVec3::splat(CUBE / 2.0),
        text: format!("FLUX {CUBE_FLUX}\nDISTRIBUTION ISOTROPIC\n"),
    };
    let (points, weights) = cube_points();
    let area = 6.0 * CUBE * CUBE;
    Case {
        id: format!("5.8 rho={rho}"),
        stem: format!("cie171_5_8_cube_rho_{:03}", (rho * 100.0).round() as u32),
        title: "inter-reflection in a 4 m cube, all surfaces of one reflectance",
        scene: write_scene(
            &format!("CIE 171 5.8 cube, reflectance {rho}"),
            0.25,
            &patches,
            &[light],
        ),
        points,
        check: Check::MeanIndirect {
            weights,
            reference_lux: CUBE_FLUX / area * rho / (1.0 - rho),
        },
        tolerance_percent: 0.5,
        source: "energy conservation: mean indirect = Phi / S_T * rho / (1 - rho) (CIE 171 5.8)",
        scene_from: "CIE 171:2006 5.8 (diffuse inter-reflections) as Ashdown's errata page \
                     describes it: a 4 m cube, S_T = 96 m^2, uniform diffusers, reflectances 0 \
                     to 0.95; the 10 000 lm isotropic source at the centre and the quadrature \
                     points are this project's",
        reference_from: ReferenceFrom::Cie171Formula,
    }
}

/// The roof opening of 5.9: 2 m by 1 m in the ceiling (fractions of `u` = y and `v` = x).
const ROOF_HOLE: [f64; 4] = [0.375, 0.625, 0.25, 0.75];

/// The window of 5.11: 2 m wide, 1.5 m high, sill at 1 m, in the y = 0 wall (fractions of
/// `u` = z and `v` = x).
const WINDOW_HOLE: [f64; 4] = [1.0 / 3.0, 2.5 / 3.0, 0.25, 0.75];

fn opening_case(
    face: usize,
    hole: [f64; 4],
    id: &str,
    stem: &str,
    title: &'static str,
    scene_from: &'static str,
) -> Case {
    let mut patches = room(W, D, H, [0.0; 6], Some((face, hole)));
    let opening = hole_rect(W, D, H, face, hole);
    patches.push(Patch {
        name: "opening".into(),
        vertices: opening,
        reflectance: 0.0,
        luminance: Some(SKY_LUMINANCE),
        opening: true,
    });
    // Points below the window's sill see only sky through it (no ground).
    let points = room_points(0.5);
    let reference = points
        .iter()
        .map(|p| exact::polygon_illuminance(p.position, p.normal, &opening, SKY_LUMINANCE))
        .collect();
    Case {
        id: id.into(),
        stem: stem.into(),
        title,
        scene: write_scene(&format!("CIE 171 {id} {title}"), 1.0, &patches, &[]),
        points,
        check: Check::Points {
            reference_lux: reference,
        },
        tolerance_percent: 1.0,
        source: "a uniform sky of luminance L seen through an opening is a Lambertian emitter: \
                 E = pi L F, F by Lambert's contour integral",
        scene_from,
        reference_from: ReferenceFrom::FirstPrinciples,
    }
}

/// 5.9: a roof opening under a uniform sky.
pub fn roof_opening() -> Case {
    opening_case(
        1,
        ROOF_HOLE,
        "5.9",
        "cie171_5_9_roof_opening",
        "roof opening (2 x 1 m) under a uniform sky of 10 000 lux, black room",
        "CIE 171:2006 5.9 (sky component for a roof unglazed opening), by its title, under \
         a uniform sky (the CIE general sky of uniform luminance)",
    )
}

/// 5.11: a façade opening under a uniform sky.
pub fn facade_opening() -> Case {
    opening_case(
        4,
        WINDOW_HOLE,
        "5.11",
        "cie171_5_11_facade_opening",
        "facade opening (2 x 1.5 m, sill 1 m) under a uniform sky of 10 000 lux, black room",
        "CIE 171:2006 5.11 (sky component for a facade unglazed opening), by its title, \
         under a uniform sky (the CIE general sky of uniform luminance)",
    )
}

/// Every case, in the report's order (5.8 once per reflectance).
pub fn cases() -> Vec<Case> {
    let mut all = vec![
        point_source(),
        area_source(),
        reflection(),
        reflection_obstructed(),
    ];
    all.extend(CUBE_REFLECTANCES.iter().map(|&rho| cube(rho)));
    all.push(roof_opening());
    all.push(facade_opening());
    all
}

/// Runs `case` through the program: parses its scene, meshes it, computes the form factors
/// by the exact contour integral ([`crate::form_factor::FormFactorMethod::Contour`], with
/// the scene's `INTEGRAL_STEPS` for the visibility of occluded pairs: a closed room's rows
/// then sum to 1 to rounding, which the cube at reflectance 0.95 needs, as any leak is
/// multiplied by 1 / (1 - rho)), solves with `solver` (point lights are the first bounce)
/// and returns `(direct, indirect)` lux at each point by
/// [`crate::illuminance::illuminance`], the calculation `radiosity illuminance` makes.
pub fn compute(case: &Case, solver: crate::Solver) -> Result<Vec<(f64, f64)>, ComputeError> {
    compute_with(case, solver, crate::Overrides::default())
}

/// [`compute`] with the scene's meshing settings overridden (a finer `MAX_PATCH_AREA`).
pub fn compute_with(
    case: &Case,
    solver: crate::Solver,
    overrides: crate::Overrides,
) -> Result<Vec<(f64, f64)>, ComputeError> {
    use crate::progress::NoProgress;
    let file = crate::io::scene_file::parse_scene(&case.scene, &case.stem)
        .map_err(|e| ComputeError(e.to_string()))?;
    let settings = overrides.apply(file.settings);
    let mut prepared = crate::Prepared::new(file.scene, settings, &NoProgress)
        .map_err(|e| ComputeError(e.to_string()))?;
    prepared.method = crate::form_factor::FormFactorMethod::Contour {
        steps: settings.integral_steps,
    };
    let request = crate::SolveRequest::new(solver);
    let solution = crate::pipeline::solve(
        &prepared,
        &request,
        &mut crate::solve::keep_going,
        &NoProgress,
    )
    .map_err(|e| ComputeError(e.to_string()))?;
    let points: Vec<crate::illuminance::CalcPoint> = case
        .points
        .iter()
        .map(|p| crate::illuminance::CalcPoint {
            name: p.name.clone(),
            position: p.position,
            normal: p.normal,
        })
        .collect();
    Ok(
        crate::illuminance::illuminance(&prepared, &solution, &points)
            .into_iter()
            .map(|lux| (lux.direct, lux.indirect))
            .collect(),
    )
}

/// A case that could not be run: the scene, the mesh or the solve refused, with why.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ComputeError(pub String);

/// Writes every case's scene and points file into `dir` (`<stem>.scene`,
/// `<stem>.points.csv`), returning the paths written.
pub fn write_files(dir: &std::path::Path) -> std::io::Result<Vec<std::path::PathBuf>> {
    write_case_files(dir, &cases())
}

/// Writes the scene and points file of each of `cases` into `dir`, as [`write_files`]
/// does for all of them, returning the paths written.
pub fn write_case_files(
    dir: &std::path::Path,
    cases: &[Case],
) -> std::io::Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    for case in cases {
        for (name, text) in [
            (format!("{}.scene", case.stem), case.scene.clone()),
            (format!("{}.points.csv", case.stem), case.points_csv()),
        ] {
            let path = dir.join(name);
            std::fs::write(&path, text)?;
            written.push(path);
        }
    }
    Ok(written)
}

#[cfg(test)]
mod tests;
