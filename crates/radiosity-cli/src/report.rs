//! Everything the commands print besides their progress notes: the `check` report, the
//! note on computed form factors, the Markdown tables of `bench`, `compare` and
//! `check --compare-methods`, and the summary of `generate building`.

use std::path::Path;

use radiosity::form_factor::{FormFactorMethod, RowSums, ROW_SUM_OVER};
use radiosity::mesh::Mesh;
use radiosity::pathtrace::{FilmComparison, PathTraceSettings, PathTraced};
use radiosity::pipeline::{FormFactorStats, Prepared, Solution, SolutionReport};
use radiosity::scene::{BuildingParams, Scene};
use radiosity::solve::{EnergyBalance, Solver, SolverKind};

use crate::progress_bar::{format_duration, Reporter};

/// Notes what computing the form factors on `mesh` found, with what its figures mean.
pub fn form_factor_stats(
    prepared: &Prepared,
    mesh: &Mesh,
    stats: &FormFactorStats,
    reporter: &Reporter,
) {
    reporter.note(&format!(
        "form factors ({}): {}; row sums min {:.4} mean {:.4} max {:.4}; {}",
        prepared.method(),
        rays_text(prepared.method(), stats),
        stats.row_sums.min,
        stats.row_sums.mean,
        stats.row_sums.max,
        reciprocity_text(prepared.method(), stats),
    ));
    row_sum_notes(prepared, mesh, &stats.row_sums, reporter);
}

/// Notes the rows of form factors that see nothing or sum above 1, with their reasons.
pub fn row_sum_notes(prepared: &Prepared, mesh: &Mesh, rows: &RowSums, reporter: &Reporter) {
    if let Some(text) = zero_rows_text(&prepared.scene, mesh, rows) {
        reporter.note(&text);
    }
    if let Some(text) = over_rows_text(&prepared.scene, mesh, prepared.method(), rows, false) {
        reporter.note(&text);
    }
}

/// "103794791 visibility rays in 18.650 s (5.6 M rays/s)", or for the hemicube, which casts
/// none, what it does instead.
fn rays_text(method: FormFactorMethod, stats: &FormFactorStats) -> String {
    if let FormFactorMethod::Hemicube { .. } = method {
        return format!(
            "{:.3} s, no visibility rays (the hemicube finds what is visible with a depth \
             buffer)",
            stats.seconds
        );
    }
    let mut text = format!(
        "{} visibility rays in {:.3} s ({:.1} M rays/s)",
        stats.rays,
        stats.seconds,
        stats.rays as f64 / stats.seconds.max(1e-9) / 1e6
    );
    if let Some(per_ray) = candidates_per_ray(stats) {
        text.push_str(&format!(
            "; each ray is tested against the occluders whose boxes meet its pair's box, \
             {per_ray:.1} on average{}",
            if per_ray > MANY_CANDIDATES {
                // QA of issue #16: the Cornell box cut into one element a surface was
                // called "cluttered"; large elements' boxes meet many occluders too.
                " (many: in a cluttered scene, or with elements so large that their pairs' \
                 boxes take in most of the scene, rays are that much slower)"
            } else {
                ""
            }
        ));
    }
    text
}

/// Above this many occluder candidates per ray the rays/s figure is said to be low because
/// of them: measured, the Cornell box's rays meet 4.4 on average, building_small's 47.1
/// (its pairs across a room list the furniture between).
const MANY_CANDIDATES: f64 = 10.0;

/// The mean number of occluder candidates listed per ray, where the method lists them.
fn candidates_per_ray(stats: &FormFactorStats) -> Option<f64> {
    (stats.rays > 0 && stats.candidates > 0).then(|| stats.candidates as f64 / stats.rays as f64)
}

/// The reciprocity error, and for the methods that estimate F_ij and F_ji apart, why it is
/// large.
fn reciprocity_text(method: FormFactorMethod, stats: &FormFactorStats) -> String {
    let r = &stats.reciprocity;
    let mut text = format!(
        "reciprocity error {:.1e} largest, {:.1e} of exchanged power",
        r.max_relative, r.total_relative
    );
    if let Some(why) = not_reciprocal(method) {
        if r.max_relative > 1e-3 {
            text.push_str(&format!(" ({why})"));
        }
    }
    text
}

/// Why a method's A_i F_ij and A_j F_ji may differ: `None` for the methods that compute one
/// number per pair.
pub fn not_reciprocal(method: FormFactorMethod) -> Option<&'static str> {
    match method {
        FormFactorMethod::AreaIntegral { .. } | FormFactorMethod::Contour { .. } => None,
        FormFactorMethod::Analytic { .. } => Some(
            "expected: the analytic method integrates each row at its own receiver's points, \
             so F_ij and F_ji come from different points and a partly hidden pair can be seen \
             from one side only",
        ),
        FormFactorMethod::Hemicube { .. } => Some(
            "expected: the hemicube samples each row from its element's centre, so a pair \
             seen by a cell from one side may fall between cells, or be hidden, from the other",
        ),
        FormFactorMethod::MonteCarlo { .. } => Some(
            "expected: Monte Carlo estimates each row with its own random rays, so a small \
             or distant pair hit from one side may be missed from the other",
        ),
    }
}

/// The name of element `e` for a note: `element 12 of surface 3 "Floor"`, numbered within
/// its surface from 0 as the solution CSV's `element` column is (QA of issue #16: notes
/// named the mesh's running index, a different, lit element of the CSV).
fn element_name(scene: &Scene, mesh: &Mesh, e: usize) -> String {
    match mesh.elements.get(e) {
        Some(el) => {
            let s = el.surface as usize;
            let first = mesh.surface_elements.get(s).map_or(0, |r| r.start);
            let k = e.saturating_sub(first as usize);
            match scene.surfaces.get(s).map(|x| x.name.as_str()) {
                Some(name) if !name.is_empty() => format!("element {k} of surface {s} {name:?}"),
                _ => format!("element {k} of surface {s}"),
            }
        }
        None => format!("element {e}"),
    }
}

/// What rows summing to 0 mean, when there are any.
fn zero_rows_text(scene: &Scene, mesh: &Mesh, rows: &RowSums) -> Option<String> {
    if rows.zero == 0 {
        return None;
    }
    if scene.surfaces.len() == 1 {
        // QA of issue #16: a lone triangle got the furniture explanation.
        return Some(format!(
            "row sums: {} no other element: the scene is one flat surface, and a plane \
             does not see itself",
            count(rows.zero as u64, "element") + if rows.zero == 1 { " sees" } else { " see" },
        ));
    }
    // Nothing in front of the first one's surface: it faces open space (QA of issue #16: a
    // triangle facing up over a floor was said to be pressed against another surface).
    if let Some(el) = mesh.elements.get(rows.min_row) {
        if faces_nothing(scene, el.surface as usize) && !faced_in_plane(scene, el.surface as usize)
        {
            return Some(format!(
                "row sums: {} {} no other element (row sum 0; the first is {}): no surface \
                 lies in front of {}, so what they send leaves the scene and nothing \
                 sends light back",
                count(rows.zero as u64, "element"),
                if rows.zero == 1 { "sees" } else { "see" },
                element_name(scene, mesh, rows.min_row),
                if rows.zero == 1 { "it" } else { "the first" },
            ));
        }
    }
    Some(format!(
        "row sums: {} {} no other element (row sum 0; the first is {}): they see no \
         other element's front, most often as faces pressed against another surface (the \
         base of furniture standing on the floor, a side against a wall, or sample points \
         under such furniture, hidden by what touches them), else where only the backs of \
         faces or open space lie in front of them; no light reaches them, so they keep only \
         their own emission",
        count(rows.zero as u64, "element"),
        if rows.zero == 1 { "sees" } else { "see" },
        element_name(scene, mesh, rows.min_row),
    ))
}

/// Above this largest row sum, rows summing above [`ROW_SUM_OVER`] are a warning (or where
/// elements of more than a twentieth of the area have one); below, a note.
const ROW_SUM_WARN: f64 = 1.1;

/// What rows summing above [`ROW_SUM_OVER`] mean, when there are any; `in_check` for
/// `check`'s report, where the light counted twice is listed below it (QA of issue #16:
/// "`check` lists it" was said inside `check`).
fn over_rows_text(
    scene: &Scene,
    mesh: &Mesh,
    method: FormFactorMethod,
    rows: &RowSums,
    in_check: bool,
) -> Option<String> {
    if rows.over == 0 {
        return None;
    }
    let cure = match method {
        FormFactorMethod::AreaIntegral { steps }
        | FormFactorMethod::Contour { steps }
        | FormFactorMethod::Analytic { steps } => format!(
            "more points (--steps {}) or a smaller --max-area reduce it",
            (2 * steps).max(4)
        ),
        FormFactorMethod::Hemicube { .. } | FormFactorMethod::MonteCarlo { .. } => {
            "--method contour --steps 4 reduces it".to_string()
        }
    };
    // A warning where the excess can show: a row well above 1, or many of them. A few rows
    // a few per cent over pass on a few per cent too much of a little light (QA of issue
    // #16: the shipped room, 0.19 % of its power counted twice, was warned on every run).
    // By area, not count: the slivers contact refinement cuts along a box's foot are many
    // and small (the shipped room: 81 of 930 elements, 0.20 % of its power counted twice).
    let area: f64 = mesh.elements.iter().map(|e| e.area).sum();
    let serious = rows.max > ROW_SUM_WARN || rows.over_area * 20.0 > area;
    let listed = if in_check {
        "the energy account below takes it off what escaped, as \"counted twice\""
    } else {
        "`check` lists it under \"counted twice by\""
    };
    Some(format!(
        "{}{} {} form-factor rows summing above {ROW_SUM_OVER} (the largest {:.4}, \
         {}): they pass on more light than reaches them, so the solution holds light that \
         was never emitted ({listed}). It comes from pairs much \
         closer than their elements are large (a wall a few cm behind furniture, surfaces \
         meeting at an edge), whose visibility the {method} points cannot resolve; {cure}",
        if serious { "warning: " } else { "" },
        count(rows.over as u64, "element"),
        if rows.over == 1 { "has" } else { "have" },
        rows.max,
        element_name(scene, mesh, rows.max_row),
    ))
}

/// `items` joined as a sentence lists them: "a", "a and b", "a, b and c".
pub fn and_list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// The band the energy account is given in, by every command alike: the one that emits
/// most (the first of equals); `None` when nothing emits.
pub fn energy_band(b: &EnergyBalance) -> Option<usize> {
    (0..3)
        .filter(|&k| b.emitted[k] > 0.0)
        .max_by(|&x, &y| b.emitted[x].total_cmp(&b.emitted[y]).then(y.cmp(&x)))
}

/// The bands' names, as the energy account labels them.
const BAND_NAMES: [&str; 3] = ["R", "G", "B"];

/// Notes where the emitted power went (in the band that emits most, as `check` gives it):
/// absorbed, and escaped (light that reached no element: out of the scene where it is
/// open, into gaps and the backs of faces, or counted twice where negative), so every solve says how far its
/// light can be trusted. `check` prints the same account in full and, for a matrix solve,
/// says through which surfaces the escaped part goes.
pub fn energy_note(
    scene: &Scene,
    solution: &Solution,
    method: FormFactorMethod,
    reporter: &Reporter,
) {
    let b = &solution.balance;
    let Some(band) = energy_band(b) else {
        return;
    };
    let share = |x: f64| 100.0 * x / b.emitted[band];
    let escaped = share(b.escaped[band]);
    // Only a matrix solve's rows say through which surfaces the light escapes.
    let where_ = match solution.report {
        SolutionReport::Matrix(_) => "; `check` says where",
        _ => "",
    };
    let mut text = format!(
        "energy ({}, the band emitting most): of the emitted power {:.2} % absorbed, {:.2} % \
         escaped ({}{where_})",
        BAND_NAMES[band],
        share(b.absorbed[band]),
        escaped,
        escaped_meaning(escaped, &solution.report)
    );
    if let SolutionReport::Progressive(_) = solution.report {
        text.push_str(" (the rest is still unshot)");
    } else if let SolutionReport::Matrix(_) = solution.report {
        // Absorbed is counted where the light arrives, escaped from the rows of the
        // elements that send it; they add up to 100 % only where A_i F_ij = A_j F_ji (QA of
        // issue #16: 100.12 % in all with --method hemicube, and no word why).
        let total = share(b.absorbed[band]) + escaped;
        if (total - 100.0).abs() >= 0.005 {
            let why = match not_reciprocal(method) {
                Some(_) => format!(
                    "{method}'s form factors are not reciprocal (it estimates F_ij and F_ji \
                     apart, so what one element sends and what the other receives differ)"
                ),
                // QA of issue #16: `--tolerance 0.01` blamed the (reciprocal) area method.
                None => UNSOLVED.to_string(),
            };
            text.push_str(&format!(
                "; the two add up to {total:.2} %, not 100 %: {why}"
            ));
        }
    }
    if let Some(openings) = openings_text(scene) {
        text.push_str(&format!("; {openings}"));
    }
    reporter.note(&text);
}

/// The first three of `names` and how many more: "a, b, c, 2 more".
pub fn first_three(names: &[String]) -> String {
    let mut shown: Vec<String> = names.iter().take(3).cloned().collect();
    if names.len() > 3 {
        shown.push(format!("{} more", names.len() - 3));
    }
    shown.join(", ")
}

/// Where a scene has `OPENING` surfaces, that what they take in counts as absorbed (QA of
/// issue #16: the account said light escapes "through openings" while the light into an
/// OPENING, reflectance 0, was in "absorbed").
fn openings_text(scene: &Scene) -> Option<String> {
    let openings: Vec<&str> = scene
        .surfaces
        .iter()
        .filter(|s| s.photometry.opening)
        .map(|s| s.name.as_str())
        .collect();
    if openings.is_empty() {
        return None;
    }
    let named: Vec<String> = openings.iter().map(|n| format!("{n:?}")).collect();
    Some(format!(
        "absorbed includes the light that leaves through the {} ({}): reflectance 0, \
         they take in all that reaches them",
        count(openings.len() as u64, "OPENING surface"),
        first_three(&named)
    ))
}

/// Below this share of the emitted power absorbed, the light is said to reach no surface.
const LIGHT_LOST_ABSORBED: f64 = 0.01;

/// A warning when the scene's light reaches none of its surfaces, so every picture is black
/// (QA of issue #16: an emitter facing out of the room, or lying above the ceiling and
/// dropped as buried, gave a black render with only notes): the emitting surfaces that the
/// mesh dropped, or the share that reaches nothing and the likely cause; where at least the
/// emitted power lands ([`light_lands`]), the share lost over many reflections instead.
pub fn light_lost(scene: &Scene, solution: &Solution) -> Option<String> {
    let emitters: Vec<usize> = (0..scene.surfaces.len())
        .filter(|&s| scene.surfaces[s].emission.0.iter().any(|&e| e > 0.0))
        .collect();
    let name = |s: usize| match scene.surfaces[s].name.as_str() {
        "" => format!("surface {s}"),
        n => format!("surface {s} {n:?}"),
    };
    let names = |list: &[usize]| first_three(&list.iter().map(|&s| name(s)).collect::<Vec<_>>());
    let b = &solution.balance;
    let Some(band) = energy_band(b) else {
        // Nothing reached the mesh: emitters dropped whole, or luminaires lighting nothing.
        let meshed: std::collections::HashSet<u32> =
            solution.mesh.elements.iter().map(|e| e.surface).collect();
        let dropped: Vec<usize> = emitters
            .iter()
            .copied()
            .filter(|&s| !meshed.contains(&(s as u32)))
            .collect();
        if !dropped.is_empty() {
            let one = dropped.len() == 1;
            return Some(format!(
                "nothing emits: the {} {} {} dropped whole, lying buried in or behind another \
                 surface (pieces no light can reach or leave are dropped), so pictures are \
                 black; move {} in front of the surface {} behind",
                if one { "emitter" } else { "emitters" },
                names(&dropped),
                if one { "was" } else { "were" },
                if one { "it" } else { "them" },
                if one { "it lies" } else { "they lie" },
            ));
        }
        // Only luminaires that give light (QA of issue #16, review: a FLUX 0 luminaire,
        // already warned of as emitting nothing, was said to be aimed away).
        let lit = scene.lights.iter().any(|l| l.gives_light());
        // Black surfaces take the luminaires' light where it lands and pass none on (QA of
        // issue #16: a room of reflectance 0 was told its lights were aimed away).
        let all_black = scene
            .surfaces
            .iter()
            .all(|s| s.reflectance.max_band() <= 0.0);
        if lit && emitters.is_empty() && all_black {
            return Some(
                "every surface has reflectance 0: the point luminaires' light is absorbed \
                 where it lands and none is reflected, so the solution holds no light and \
                 pictures are black (`illuminance` takes the direct light at each point, and \
                 reads it)"
                    .to_string(),
            );
        }
        if lit && emitters.is_empty() {
            return Some(
                "the point luminaires' light lands on no front of a surface: they are aimed \
                 away from the scene (AIM) or lie outside it, so pictures are black"
                    .to_string(),
            );
        }
        return None;
    };
    // Lost: little absorbed and nearly all escaped (a progressive run that has shot
    // nothing yet has absorbed nothing and escaped nothing: not lost).
    let absorbed = b.absorbed[band] / b.emitted[band];
    let escaped = b.escaped[band] / b.emitted[band];
    if absorbed >= LIGHT_LOST_ABSORBED
        || escaped < 1.0 - 2.0 * LIGHT_LOST_ABSORBED
        || emitters.is_empty()
    {
        return None;
    }
    // Light reflected many times: the surfaces absorb little because they reflect nearly
    // all that lands, not because little lands (QA pass 15 of issue #16: a closed box of
    // reflectance 0.9999 was said to show "only the 0.51 % that lands").
    let landed = landed_power(scene, solution, band) / b.emitted[band];
    if landed >= LANDS_OVER {
        let most = scene
            .surfaces
            .iter()
            .map(|s| s.reflectance.band(band))
            .fold(0.0, f64::max);
        return Some(format!(
            "{:.2} % of the emitted light is lost over many reflections (its surfaces absorb \
             only {} %: with reflectance up to {most} the light lands {} times its emitted \
             power, bouncing until it leaves the scene or meets the back of a face; `check` \
             lists where it goes)",
            100.0 * (1.0 - absorbed),
            significant(100.0 * absorbed, 2),
            significant(landed, 2),
        ));
    }
    // What the pictures show: nothing, or the little that lands, which the automatic
    // exposure brightens (QA of issue #16: "so pictures are black" over a lit picture).
    let pictures = if absorbed > 0.0 {
        format!(
            "pictures show only the {} % that lands, brightened by the automatic exposure",
            significant(100.0 * absorbed, 2)
        )
    } else {
        // The emitters themselves still show (QA of issue #16: a glowing box was said to
        // make black pictures).
        "so nothing is lit: pictures show at most the emitters themselves".to_string()
    };
    // Blame the emitters' orientation only where it is to blame: an emitter with no other
    // surface in front of it (QA of issue #16: a lamp facing a ground 20 m below, and the
    // lamp inside a box whose faces point out, were told to reverse their corners).
    let facing_nothing: Vec<usize> = emitters
        .iter()
        .copied()
        .filter(|&s| faces_nothing(scene, s))
        .collect();
    if !facing_nothing.is_empty() {
        return Some(format!(
            "{:.2} % of the emitted light reaches no surface ({pictures}): {} {} out of the \
             scene, with no surface in front of {} (if that is not meant: a polygon whose \
             corners run clockwise seen from the side to light faces the other way, so reverse \
             their order; a BOX lit from inside takes FACING IN)",
            100.0 * (1.0 - absorbed),
            names(&facing_nothing),
            if facing_nothing.len() == 1 {
                "faces"
            } else {
                "face"
            },
            if facing_nothing.len() == 1 {
                "it"
            } else {
                "them"
            },
        ));
    }
    Some(format!(
        "{:.2} % of the emitted light reaches no surface ({pictures}): it leaves an open \
         scene, or lands on the backs of faces (an emitter behind a wall, above a ceiling or \
         inside furniture, or a room whose faces point out: `check` lists where it goes)",
        100.0 * (1.0 - absorbed),
    ))
}

/// At least this multiple of the emitted power lands on the elements' fronts where light
/// that escapes is said to be lost over many reflections, not to reach no surface.
const LANDS_OVER: f64 = 1.0;

/// Whether at least as much light lands on the elements' fronts as is emitted (in the band
/// that emits most), so the pictures are lit whatever [`light_lost`] says escapes.
pub fn light_lands(scene: &Scene, solution: &Solution) -> bool {
    energy_band(&solution.balance).is_some_and(|band| {
        landed_power(scene, solution, band) >= LANDS_OVER * solution.balance.emitted[band]
    })
}

/// The power arriving at the elements' fronts in `band`, from other elements and point
/// luminaires: A (B - E) / rho summed over the elements of reflectance rho > 1e-6, with E the
/// surface's own emission (B - E = rho x irradiance, luminaires' direct light included).
/// Light reflected many times counts once per landing, so this exceeds the emitted power
/// where the surfaces reflect nearly all of it.
fn landed_power(scene: &Scene, solution: &Solution, band: usize) -> f64 {
    solution
        .mesh
        .elements
        .iter()
        .zip(&solution.radiosity.0)
        .filter_map(|(element, b)| {
            let surface = scene.surfaces.get(element.surface as usize)?;
            let rho = surface.reflectance.band(band);
            // Reflectance near 0 would magnify the rounding of B - E (review).
            (rho > 1e-6)
                .then(|| element.area * (b.band(band) - surface.emission.band(band)).max(0.0) / rho)
        })
        .sum()
}

/// Surface `s`'s unit normal, a point of its plane, and 1e-9 of the scene's size (how far
/// off the plane a corner may lie and still count as in it); `None` for a degenerate one.
fn plane_of(scene: &Scene, s: usize) -> Option<(glam::DVec3, glam::DVec3, f64)> {
    let vertices = &scene.surfaces[s].vertices;
    let normal = radiosity::geometry::polygon_normal(vertices)?;
    let centre = radiosity::geometry::polygon_centroid(vertices);
    let (lo, hi) = scene.bounds();
    Some((
        normal,
        centre,
        1e-9 * (hi - lo).length().max(f64::MIN_POSITIVE),
    ))
}

/// The surfaces of `scene` other than `s`.
fn others(scene: &Scene, s: usize) -> impl Iterator<Item = &radiosity::scene::Surface> {
    scene
        .surfaces
        .iter()
        .enumerate()
        .filter(move |&(k, _)| k != s)
        .map(|(_, other)| other)
}

/// Whether another surface of `scene` lies in surface `s`'s plane facing it (a box's base
/// on the floor): all its corners within 1e-9 of the scene's size of the plane, its normal
/// opposite.
fn faced_in_plane(scene: &Scene, s: usize) -> bool {
    let Some((normal, centre, eps)) = plane_of(scene, s) else {
        return false;
    };
    others(scene, s).any(|other| {
        radiosity::geometry::polygon_normal(&other.vertices).is_some_and(|m| m.dot(normal) < -0.99)
            && other
                .vertices
                .iter()
                .all(|&v| normal.dot(v - centre).abs() <= eps)
    })
}

/// Whether no corner of any other surface of `scene` lies in front of surface `s`'s plane
/// (by more than 1e-9 of the scene's size): its light can only leave the scene.
fn faces_nothing(scene: &Scene, s: usize) -> bool {
    let Some((normal, centre, eps)) = plane_of(scene, s) else {
        return false;
    };
    !others(scene, s)
        .flat_map(|other| other.vertices.iter())
        .any(|&v| normal.dot(v - centre) > eps)
}

/// What an escaped share (percent of the emitted power) means, for the energy notes.
fn escaped_meaning(percent: f64, report: &SolutionReport) -> String {
    if percent < 0.0 && rounds_to_zero(percent) {
        // Below 0 by rounding where the scene is closed (QA pass 17 of #16).
        String::from("none: below 0 by rounding")
    } else if percent < 0.0 && matches!(report, SolutionReport::Hierarchical(_)) {
        // QA of issue #16: hierarchical radiosity has no rows to blame.
        format!("negative: {COUNTED_TWICE_LINKS}")
    } else if percent < 0.0 {
        format!("negative: {COUNTED_TWICE}")
    } else {
        format!("light that reached no element: {ESCAPED}")
    }
}

/// Whether a share in per cent prints as 0.00 at two decimals (a closed scene's escaped
/// power is 0 up to rounding, which can leave it a hair below).
fn rounds_to_zero(percent: f64) -> bool {
    percent.abs() < 0.005
}

/// Where light that reaches no element goes: one wording for the energy note, `check`'s
/// energy line and its list of surfaces (QA of issue #16: they said it three ways).
// "out of the scene where it is open", not "through openings" (QA of issue #16: light
// into OPENING surfaces is counted as absorbed, and the word read as those).
const ESCAPED: &str =
    "out of the scene where it is open, into gaps and contacts or onto the backs of faces";

/// Why a solve with reciprocal form factors loses part of the account: the relative
/// residual is the largest single element's, over the brightest emission, so thousands
/// of elements each within it can leave much more of the power unsolved (QA of issue #16:
/// `--tolerance 0.01` left a residual of 3.9e-3 and 14 % of the light).
const UNSOLVED: &str = "the form factors are reciprocal, so it is light the solve has not \
                        yet passed on: the relative residual is the largest single \
                        element's, over the brightest emission, and many elements each \
                        within it leave more of the power unsolved; a smaller --tolerance \
                        closes it";

/// What a row of form factors above 1 does, in the same places.
const COUNTED_TWICE: &str = "light counted twice where the form factors' rows sum above 1 \
                             (near pairs' visibility misjudged)";

/// The same for hierarchical radiosity, which has links, not rows.
const COUNTED_TWICE_LINKS: &str = "light counted twice where the estimated form factors of a \
                                   node's links sum above 1 (coarse links near corners and \
                                   contacts)";

/// Prints the note on surfaces lying on others (a rug in or just above a floor's plane):
/// how many pairs, and which, by index and name, with the gap and the area covered.
fn lying_on(prepared: &Prepared) {
    let scene = &prepared.scene;
    let pairs = radiosity::scene::lying_on(scene, &prepared.occluders);
    if pairs.is_empty() {
        return;
    }
    let scale = prepared.occluders.scale();
    let same_plane = pairs.iter().filter(|o| o.same_plane(scale)).count();
    outln!(
        "lying on          {} {} on others ({} in the same plane), their covered parts left \
         out of the mesh:",
        count(pairs.len() as u64, "surface"),
        if pairs.len() == 1 { "lies" } else { "lie" },
        same_plane
    );
    const SHOWN: usize = 10;
    let (length_unit, area_unit) = length_and_area_units();
    for o in pairs.iter().take(SHOWN) {
        let name = |s: u32| &scene.surfaces[s as usize].name;
        outln!(
            "                  surface {} {:?} on surface {} {:?}: gap {} {length_unit}, covering {} {area_unit}",
            o.upper,
            name(o.upper),
            o.lower,
            name(o.lower),
            significant(o.gap, 4),
            significant(o.covered_area, 4)
        );
    }
    if pairs.len() > SHOWN {
        outln!("                  ... and {} more", pairs.len() - SHOWN);
    }
}

/// Below this share of a point luminaire's lumens landing on the fronts of surfaces,
/// `check` warns: a light inside furniture, behind a wall or outside the room (QA: such a
/// typo lost its light without a word). A downlight in an open-sided box still lands most.
const LIGHT_LANDING_WARN: f64 = 0.5;

/// `check`'s lines on the point luminaires: each one's lumens and position, and the share
/// of its lumens that lands on the fronts of surfaces (the rest is in no solution).
fn lights(prepared: &Prepared) {
    let scene = &prepared.scene;
    if scene.lights.is_empty() {
        return;
    }
    let occluders = radiosity::form_factor::occluder_bvh(scene);
    for (i, l) in scene.lights.iter().enumerate() {
        let untinted = l.flux();
        let landing = radiosity::luminaire::landing_flux(&prepared.mesh, l, &occluders);
        let share = if untinted > 0.0 {
            landing / untinted
        } else {
            0.0
        };
        // COLOUR multiplies the output in each band, so the lumens emitted are the untinted
        // lumens times its luminance (QA pass 13 of #16: COLOUR 2 2 2 emitted 2,000 lm
        // where this line said 1,000).
        let tint = l.colour.luminance();
        let flux = untinted * tint;
        let tinted = if l.colour.0 == [1.0; 3] {
            String::new()
        } else {
            format!(
                " ({} lm times COLOUR {} {} {}, luminance {})",
                significant(untinted, 6),
                l.colour.0[0],
                l.colour.0[1],
                l.colour.0[2],
                significant(tint, 4)
            )
        };
        let p = l.position;
        let (length_unit, _) = length_and_area_units();
        outln!(
            "{}{} {:.1} lm{tinted} at ({}, {}, {}) {length_unit}; {:.1} % lands on the fronts of surfaces",
            if i == 0 {
                "point lights      "
            } else {
                "                  "
            },
            l.name,
            flux,
            p.x,
            p.y,
            p.z,
            100.0 * share
        );
        if flux > 0.0 && share < LIGHT_LANDING_WARN {
            // A shaped light at the default aim may simply point the wrong way (QA of issue
            // #16: a COSINE light added to the y-up Cornell box pointed out of its open
            // front, and the warning asked only whether it was inside furniture).
            let aim = if !matches!(
                l.distribution,
                radiosity::luminaire::Distribution::Isotropic
            ) && l.aim == radiosity::luminaire::DEFAULT_AIM
            {
                "; or the light points the wrong way: it has the default AIM 0 0 -1, straight \
                 down in a z-up scene but horizontal in a y-up one, where a downlight takes \
                 AIM 0 -1 0"
            } else {
                ""
            };
            errln!(
                "warning: point luminaire {} at ({}, {}, {}): only {:.1} % of its {:.1} lm lands \
                 on the front of a surface; the rest falls on the backs of faces (is it inside \
                 furniture or behind a wall?) or leaves the scene (is it outside the room?){aim}; \
                 no solution holds it",
                l.name,
                p.x,
                p.y,
                p.z,
                100.0 * share,
                flux
            );
        }
    }
}

/// `n` and the noun, singular for 1 and plural otherwise: "1 point", "2 points", "1 leaf",
/// "3 leaves" (QA of issue #16: "1 points", "1 runs").
pub fn count(n: impl Into<u64>, noun: &str) -> String {
    let n = n.into();
    if n == 1 {
        return format!("1 {noun}");
    }
    let many = match noun {
        "leaf" => "leaves".to_string(),
        _ if noun.ends_with("ch") || noun.ends_with('s') => format!("{noun}es"),
        _ => format!("{noun}s"),
    };
    format!("{n} {many}")
}

/// `x` as the user would type it: Rust's shortest round-trip digits, with an exponent
/// outside 1e-4 to 1e15 (QA of issue #16: `--fov 1e300` was echoed as 301 digits, 1e-6 as
/// 0.000001).
pub fn typed(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `x` in exponent form with `decimals` decimals, "1.5e-9", or "0" for zero (QA of issue
/// #16: "0.0e0").
pub fn exponent(x: f64, decimals: usize) -> String {
    if x == 0.0 {
        "0".to_string()
    } else {
        format!("{x:.decimals$e}")
    }
}

/// `x` with `decimals` decimals and its sign, or none where it rounds to zero: "+0.125",
/// "-1.500", "0.000" (QA of issue #16: `validate` printed "-0.000").
pub fn signed(x: f64, decimals: usize) -> String {
    let text = format!("{x:+.decimals$}");
    if text[1..].bytes().all(|b| b == b'0' || b == b'.') {
        text[1..].to_string()
    } else {
        text
    }
}

/// `x` with `digits` significant digits, without an exponent for everyday magnitudes
/// (1e-4 to 1e9) and without trailing zeros: 0.5080691785954333 -> "0.5081" at 4 (QA of
/// issue #16: the exposure scale came with 16 digits, `check`'s areas as "7.2977e0").
pub fn significant(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor();
    if !(-4.0..=9.0).contains(&magnitude) {
        // Without trailing zeros there too (QA of issue #16: "MAX_PATCH_AREA 1.00000e300").
        let text = format!("{x:.prec$e}", prec = digits.saturating_sub(1));
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let mantissa = if mantissa.contains('.') {
            mantissa.trim_end_matches('0').trim_end_matches('.')
        } else {
            mantissa
        };
        return format!("{mantissa}e{exponent}");
    }
    let decimals = (digits as f64 - 1.0 - magnitude).max(0.0) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// The unit of lengths and of areas of the scene read, short, for figures: `mm` and `mm^2`
/// for the built-in box, `m` for metres (a file read in metres, or scaled to them), else the
/// words of the `unit` line (`inches`, `square inches`).
pub fn length_and_area_units() -> (String, String) {
    let unit = crate::setup::scene_unit();
    if unit.starts_with("millimetres") {
        ("mm".to_string(), "mm^2".to_string())
    } else if unit.starts_with("metres") {
        ("m".to_string(), "m^2".to_string())
    } else {
        // The unit's words before any note in brackets: "inches", "drawing units".
        let words = unit.split(" (").next().unwrap_or(&unit).trim().to_string();
        let area = format!("square {words}");
        (words, area)
    }
}

/// Prints the `check` report of `solution` (the stage times from `reporter`); `stats` are
/// the form factors' statistics when the solve used a matrix.
pub fn check(
    stem: &str,
    prepared: &Prepared,
    solver: &Solver,
    solution: &Solution,
    stats: Option<&FormFactorStats>,
    escaped_by_surface: Option<&[[f64; 3]]>,
    reporter: &Reporter,
) {
    let scene = &prepared.scene;
    outln!("scene             {stem}");
    outln!("unit              {}", crate::setup::scene_unit());
    // check's reporter says no notes: the unit's own note goes under its line.
    if let Some(note) = crate::setup::unit_note() {
        outln!("                  (note: {note})");
    }
    outln!("surfaces          {}", scene.surfaces.len());
    if solution.mesh.len() == prepared.mesh.len() {
        outln!("elements          {}", solution.mesh.len());
    } else {
        // QA of issue #16: the count changed between lines with no word why.
        outln!(
            "elements          {} (hierarchical radiosity's leaves: its patches subdivided \
             where the light varies; the uniform mesh at MAX_PATCH_AREA has {})",
            solution.mesh.len(),
            prepared.mesh.len()
        );
    }
    let (_, area_unit) = length_and_area_units();
    // The elements' area: less than the surfaces' where contact refinement dropped buried
    // pieces or a surface lying on another covers part of it (QA of issue #16: `generate`
    // printed 173 m^2 for a room whose `check` said 167.078).
    let surfaces_area: f64 = scene
        .surfaces
        .iter()
        .map(|s| radiosity::geometry::polygon_area(&s.vertices))
        .sum();
    let elements_area = solution.mesh.total_area();
    outln!(
        "total area        {} {area_unit}{}",
        significant(elements_area, 6),
        if elements_area < surfaces_area * (1.0 - 1e-6) {
            format!(
                " (the elements'; the surfaces' {} less the parts buried under or covered \
                 by other surfaces)",
                significant(surfaces_area, 6)
            )
        } else {
            String::new()
        }
    );
    let contacts = &prepared.contacts;
    if contacts.skipped {
        outln!(
            "contacts          not refined: more than {} elements",
            radiosity::mesh::CONTACT_MAX_ELEMENTS
        );
    } else {
        // One wording with hierarchical radiosity's "leaf contacts" below (QA of issue #16).
        // The elements split for a near face's shade alone, where there are any.
        let shaded = match contacts.shaded_split {
            0 => String::new(),
            n if n == contacts.split => format!(
                " ({} only along a face hanging just in front)",
                if n == 1 { "it" } else { "all" }
            ),
            n => format!(" ({n} of them only along a face hanging just in front)"),
        };
        outln!(
            "contacts          {} of the grid's {} split{shaded}, {} dropped whole; buried and left out: {} {area_unit} (of the grid's elements)",
            count(contacts.split as u64, "element"),
            contacts.input_elements,
            contacts.dropped,
            significant(contacts.buried_area, 4),
        );
    }
    lying_on(prepared);
    lights(prepared);
    outln!(
        "MAX_PATCH_AREA    {}",
        significant(prepared.settings.max_patch_area, 6)
    );
    outln!("INTEGRAL_STEPS    {}", prepared.settings.integral_steps);
    // Hierarchical radiosity estimates each link itself (QA of issue #16: `check
    // --solver hierarchical` named the method it had just said it ignores).
    if matches!(solver, Solver::Hierarchical(_)) {
        outln!("method            hierarchical radiosity's own: exact near pairs, Lambert's point-to-polygon at middle distance, point pairs far");
        outln!("occlusion         point pairs a link (16 between patches, up to 8 for clusters) through the surfaces' BVH");
    } else {
        outln!("method            {}", prepared.method());
        outln!("occlusion         {}", prepared.method().occlusion());
    }
    outln!("solver            {solver}");
    if let Some(stats) = stats {
        outln!(
            "row sums          min {:.6}  mean {:.6}  max {:.6}",
            stats.row_sums.min,
            stats.row_sums.mean,
            stats.row_sums.max
        );
        // Under the "row sums" label, without its own (QA of issue #16).
        if let Some(text) = zero_rows_text(scene, &solution.mesh, &stats.row_sums) {
            let text = text.strip_prefix("row sums: ").unwrap_or(&text);
            outln!("                  {text}");
        }
        if let Some(text) = over_rows_text(
            scene,
            &solution.mesh,
            prepared.method(),
            &stats.row_sums,
            true,
        ) {
            outln!("                  {text}");
        }
        outln!(
            "reciprocity error {:.3e} largest |A_i F_ij - A_j F_ji| / max(A_i F_ij, A_j F_ji); {:.3e} of all exchanged power",
            stats.reciprocity.max_relative, stats.reciprocity.total_relative
        );
        if let (Some(why), true) = (
            not_reciprocal(prepared.method()),
            stats.reciprocity.max_relative > 1e-3,
        ) {
            outln!("                  ({why})");
        }
        if let FormFactorMethod::Hemicube { .. } = prepared.method() {
            outln!(
                "visibility rays   none: the hemicube finds what is visible with a depth buffer"
            );
        } else if stats.rays > 0 {
            outln!(
                "visibility rays   {} ({:.1} M rays/s){}",
                stats.rays,
                stats.rays as f64 / stats.seconds.max(1e-9) / 1e6,
                candidates_per_ray(stats).map_or(String::new(), |c| format!(
                    "; {c:.1} occluder candidates tested per ray on average (the rate falls as \
                     they grow)"
                ))
            );
        }
    }
    match &solution.report {
        SolutionReport::Matrix(report) => {
            let r = report.residual;
            outln!(
                "solve residual    {} / {} / {} (relative, R / G / B)",
                exponent(r[0], 1),
                exponent(r[1], 1),
                exponent(r[2], 1)
            );
        }
        SolutionReport::Hierarchical(report) => {
            outln!(
                "hierarchical      {}, {}, {} ({} before the first solve), about {:.0} MiB, {}, {} (changing power {:.1e} of emitted), {} rays, {:.3} s",
                count(report.leaves as u64, "leaf"),
                count(report.clusters as u64, "cluster"),
                count(report.links as u64, "link"),
                report.initial_links,
                report.memory_bytes as f64 / (1024.0 * 1024.0),
                count(report.rounds as u64, "round"),
                match report.gather_passes {
                    0 => count(report.iterations as u64, "sweep"),
                    g => format!(
                        "{} and the final gather's {}",
                        count((report.iterations - g) as u64, "sweep"),
                        count(g as u64, "pass")
                    ),
                },
                report.residual,
                report.rays,
                report.elapsed.as_secs_f64()
            );
            if report.contacts_skipped {
                outln!(
                    "leaf contacts     not refined: more than {} elements",
                    radiosity::mesh::CONTACT_MAX_ELEMENTS
                );
            } else {
                outln!(
                    "leaf contacts     {} patches (whole cells and pieces) dropped; buried and left out: {} {area_unit}",
                    report.buried_patches,
                    significant(report.buried_area, 4)
                );
            }
        }
        SolutionReport::Progressive(report) => {
            outln!(
                "progressive       {}; unshot power {:.3} % of emitted (the band with the most left); ambient {:.3e} / {:.3e} / {:.3e} (R / G / B: the unshot power's estimated share of every radiosity, added for display, Cohen et al. 1988)",
                count(report.shots as u64, "shot"),
                100.0 * report.unshot_fraction,
                report.ambient[0],
                report.ambient[1],
                report.ambient[2]
            );
        }
    }
    let b = &solution.balance;
    // The band the other commands' energy note gives (R when nothing emits).
    let band = energy_band(b);
    let k = band.unwrap_or(0);
    let share = |x: f64| {
        if band.is_some() {
            format!(" ({:.2} %)", 100.0 * x / b.emitted[k])
        } else {
            String::new()
        }
    };
    // A progressive solve holds the power it has not shot yet: the third term, by
    // difference, in the same band (QA of issue #16: a capped run's "relative error
    // 5.4e-1" was the unshot power, explained lines further down).
    let rest = if let SolutionReport::Progressive(_) = solution.report {
        let unshot = b.emitted[k] - b.absorbed[k] - b.escaped[k];
        format!(
            " + not yet shot {}{} (progressive refinement: the power still to shoot, by \
             difference)",
            significant(unshot, 7),
            share(unshot)
        )
    } else {
        format!(" (relative error {})", exponent(b.relative_error(), 1))
    };
    // A closed scene's escaped power is 0 up to rounding, which can leave it a hair below
    // (QA pass 17 of #16: "escaped -1.307053e-5 (-0.00 %)").
    let escaped_share = match band {
        Some(_) if b.escaped[k] < 0.0 && rounds_to_zero(100.0 * b.escaped[k] / b.emitted[k]) => {
            String::from(" (0.00 %: below 0 by rounding)")
        }
        _ => share(b.escaped[k]),
    };
    outln!(
        "energy ({})        emitted {} = absorbed {}{} + escaped {}{}{rest}",
        BAND_NAMES[k],
        significant(b.emitted[k], 7),
        significant(b.absorbed[k], 7),
        share(b.absorbed[k]),
        significant(b.escaped[k], 7),
        escaped_share,
    );
    if band.is_some() {
        let (length_unit, area_unit) = length_and_area_units();
        // Said for the scene's own unit (QA of issue #16: the built-in box, in millimetres,
        // was told "lengths in metres").
        let watts = match length_unit.as_str() {
            "m" => "W or lm where E is in W/m^2 or lm/m^2".to_string(),
            "mm" => "millionths of a W or lm where E is in W/m^2 or lm/m^2".to_string(),
            _ => format!("W or lm where E is in W/m^2 or lm/m^2 and {length_unit} are metres"),
        };
        outln!(
            "                  (powers: exitance E times {area_unit}, so {watts}; escaped: \
             {}; {} is the band emitting most)",
            escaped_meaning(100.0 * b.escaped[k] / b.emitted[k], &solution.report),
            BAND_NAMES[k]
        );
        if let Some(why) = account_error_reason(prepared.method(), solution) {
            outln!("                  ({why})");
        }
        if let Some(openings) = openings_text(scene) {
            outln!("                  ({openings})");
        }
        if !scene.lights.is_empty() {
            // QA of issue #16: "emitted" did not match the luminaires' lumens, with no word
            // why. The surfaces' own emission, the rest is the luminaires' first bounce.
            let own: f64 = solution
                .mesh
                .elements
                .iter()
                .map(|e| e.area * scene.surfaces[e.surface as usize].emission.0[k])
                .sum();
            outln!(
                "                  (with point luminaires the account starts at their first \
                 bounce: \"emitted\" is the surfaces' own emission, {}, plus the luminaires' \
                 light on them times their reflectance, {}; what the surfaces absorb of the \
                 luminaires' direct light is not in it)",
                significant(own, 7),
                significant(b.emitted[k] - own, 7)
            );
        }
    }
    match (escaped_by_surface, band) {
        (Some(by_surface), Some(k)) => where_escaped(scene, by_surface, b.emitted[k], k),
        (None, Some(_)) => {
            outln!(
                "escaped from      not traced to surfaces: {} keeps no form-factor rows (a \
                 dense solver's `check`, --solver gauss-seidel, lists them)",
                match solution.report {
                    SolutionReport::Progressive(_) => "progressive refinement",
                    _ => "hierarchical radiosity",
                }
            );
        }
        _ => {}
    }
    outln!("stage times:");
    let timings = reporter.labelled_timings();
    // The times in one column, however long a label ("parse room.scene"; QA of issue #16).
    let width = timings.iter().map(|t| t.0.len()).max().unwrap_or(0).max(13);
    for (stage, d) in timings {
        outln!("  {stage:<width$} {}", format_duration(d));
    }
}

/// Above this relative error the energy account gets its reason beside it: where its two
/// shares, printed to 0.01 %, visibly do not add up to 100 % (QA of issue #16: the
/// analytic method's 67.70 % + 32.34 % came without a word at 4.1e-4, below the 1e-3 of
/// before).
const ACCOUNT_ERROR_EXPLAINED: f64 = 5e-5;

/// Why emitted = absorbed + escaped does not hold, where it is off by more than
/// [`ACCOUNT_ERROR_EXPLAINED`] for a reason known: a matrix solve's account weighs each
/// element's incoming power by the other elements' rows (A_i B_i F_ij), the solve by its own
/// row (A_j F_ji B_i), which agree only where the form factors are reciprocal (QA of issue
/// #16: Monte Carlo's 3.5 % came with no reason).
fn account_error_reason(method: FormFactorMethod, solution: &Solution) -> Option<String> {
    if solution.balance.relative_error() <= ACCOUNT_ERROR_EXPLAINED {
        return None;
    }
    match solution.report {
        SolutionReport::Matrix(_) => Some(match not_reciprocal(method) {
            Some(_) => format!(
                "relative error: {method}'s form factors are not reciprocal (A_i F_ij != A_j \
                 F_ji, the reciprocity error above); the account counts the power reaching \
                 each element by the other elements' rows, the solve by the element's own \
                 row, so its two sides differ{}",
                match method {
                    // What lowers it (QA of issue #16: `--samples 1` came with no way out).
                    FormFactorMethod::MonteCarlo { samples, .. } => format!(
                        "; more rays (--samples {}) bring them closer",
                        (4 * samples).max(crate::args::MethodArgs::SAMPLES)
                    ),
                    FormFactorMethod::Hemicube { resolution } => format!(
                        "; a finer hemicube (--resolution {}) brings them closer",
                        2 * resolution
                    ),
                    _ => String::new(),
                }
            ),
            None => format!("relative error: {UNSOLVED} (or it is the f32 matrix's rounding)"),
        }),
        // Progressive: the unshot power, said on its own line; hierarchical: its account
        // is its own (the leaves' B against their gathered irradiance).
        SolutionReport::Progressive(_) | SolutionReport::Hierarchical(_) => None,
    }
}

/// The surfaces through which most power escapes (in `band`, as the energy line), or is
/// counted twice where rows sum above 1: the five largest of each sign (of those of 0.01 %
/// or more), as shares of the emitted power.
fn where_escaped(
    scene: &radiosity::scene::Scene,
    by_surface: &[[f64; 3]],
    emitted: f64,
    band: usize,
) {
    let mut ranked: Vec<(f64, usize)> = by_surface
        .iter()
        .enumerate()
        .map(|(s, e)| (e[band] / emitted, s))
        .filter(|(share, _)| share.abs() >= 1e-4)
        .collect();
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0));
    let name = |s: usize| {
        let n = &scene.surfaces[s].name;
        if n.is_empty() {
            format!("surface {s}")
        } else {
            format!("surface {s} ({n})")
        }
    };
    let lost: Vec<String> = ranked
        .iter()
        .filter(|r| r.0 > 0.0)
        .take(5)
        .map(|&(share, s)| format!("{:.2} % {}", 100.0 * share, name(s)))
        .collect();
    let twice: Vec<String> = ranked
        .iter()
        .rev()
        .filter(|r| r.0 < 0.0)
        .take(5)
        .map(|&(share, s)| format!("{:.2} % {}", -100.0 * share, name(s)))
        .collect();
    // What the lists leave out, so that their shares add up to the energy line's escaped
    // share (QA of issue #16: five shares that did not add up to it, with no word why).
    let (out_total, out_count, in_total, in_count) =
        by_surface
            .iter()
            .fold((0.0, 0usize, 0.0, 0usize), |(o, oc, i, ic), e| {
                let share = e[band] / emitted;
                if share > 0.0 {
                    (o + share, oc + 1, i, ic)
                } else if share < 0.0 {
                    (o, oc, i - share, ic + 1)
                } else {
                    (o, oc, i, ic)
                }
            });
    // Fewer than five are shown when the rest are below 0.01 % each (QA of issue #16: "the
    // 3 largest of 24" beside a README that said five).
    let all = |shown: usize, of: usize, total: f64| {
        if shown == 0 && of > 0 {
            // QA of issue #16: "no surface (the 0 of 4 surfaces with 0.01 % or more ...".
            format!(
                "{} below 0.01 % each, {:.2} % in all",
                count(of as u64, "surface"),
                100.0 * total
            )
        } else if shown == of {
            format!("{:.2} % in all", 100.0 * total)
        } else if shown == 5 {
            format!(
                "the 5 largest of {of} surfaces, {:.2} % in all",
                100.0 * total
            )
        } else {
            format!(
                "the {shown} of {of} surfaces with 0.01 % or more, {:.2} % in all",
                100.0 * total
            )
        }
    };
    outln!(
        "escaped from      {} ({}{}; of emitted, by the surface it left, where its rows of \
         form factors sum below 1: {ESCAPED})",
        if lost.is_empty() && out_count > 0 {
            "no surface of 0.01 % or more".to_string()
        } else if lost.is_empty() {
            "no surface".to_string()
        } else {
            lost.join(", ")
        },
        all(lost.len(), out_count, out_total),
        // "below" only where the line below is printed (QA of issue #16: "less 0.00 %
        // counted twice below" with nothing below); a part too small for that line but
        // large enough to show is still taken off, so the total makes the energy line's.
        if !twice.is_empty() {
            format!(
                ", less {:.2} % counted twice below: {:.2} % escaped",
                100.0 * in_total,
                100.0 * (out_total - in_total)
            )
        } else if in_total >= 0.00005 {
            format!(
                ", less {:.2} % counted twice (by surfaces of under 0.01 % each): {:.2} % \
                 escaped",
                100.0 * in_total,
                100.0 * (out_total - in_total)
            )
        } else {
            String::new()
        }
    );
    if !twice.is_empty() {
        outln!(
            "counted twice by  {} ({}; of emitted; {COUNTED_TWICE})",
            twice.join(", "),
            all(twice.len(), in_count, in_total)
        );
    }
}

/// Prints the accuracy table of `form_factor::accuracy` as Markdown, once every method is
/// measured; meanwhile a line per method on stderr (unless `quiet`), as the whole takes
/// about 8 s on two cores.
pub fn method_accuracy(max_area: f64, quiet: bool) {
    use radiosity::form_factor::accuracy::{measure, standard_methods};
    let methods = standard_methods();
    let start = std::time::Instant::now();
    let rows: Vec<_> = methods
        .iter()
        .enumerate()
        .map(|(i, &method)| {
            if !quiet {
                errln!(
                    "measuring {} of {}: {method} (after {:.0} s)",
                    i + 1,
                    methods.len(),
                    start.elapsed().as_secs_f64()
                );
            }
            measure(method, max_area)
        })
        .collect();
    outln!(
        "Elements of at most {max_area} of a unit of area (a unit square in {} elements; the \
         shapes are measured in units of their own size); relative errors.",
        (1.0 / max_area).round()
    );
    outln!();
    outln!(
        "| method | opposed squares | perpendicular squares | coaxial discs | element to rectangle | mean | closed box max abs(row sum - 1) | reciprocity | time (ms) | mean error x time |"
    );
    outln!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in rows {
        outln!(
            "| {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {} | {} | {:.1} | {:.2e} |",
            r.method,
            r.opposed,
            r.perpendicular,
            r.discs,
            r.differential,
            r.mean_error(),
            exponent(r.closed_box, 2),
            exponent(r.reciprocity, 2),
            r.seconds * 1e3,
            r.mean_error() * r.seconds
        );
    }
}

/// A row of the `compare` table.
pub struct CompareRow<'a> {
    pub stem: &'a str,
    /// Elements of the prepared mesh.
    pub elements: usize,
    /// The solver's short label.
    pub solver: String,
    /// Elements of the solver's solution (the hierarchical solver's leaves).
    pub solver_elements: usize,
    /// Seconds of the solve.
    pub seconds: f64,
    pub peak: Peak,
    /// The dense reference's method; `None` with `--no-reference`.
    pub reference_method: Option<String>,
    /// The dense reference, when it was run.
    pub reference: Option<Reference>,
}

/// The dense reference of a `compare` row.
pub struct Reference {
    pub seconds: f64,
    /// Bytes of its f32 form-factor matrix (4 n^2), what the dense solve holds beyond the
    /// prepared scene: computed, not measured, because a resident peak measured after the
    /// first solve depends on what that solve left in the allocator (23 to 256 MiB for
    /// one reference between runs).
    pub matrix_bytes: u64,
    /// The solver's radiosity against the reference's.
    pub difference: radiosity::compare::Comparison,
}

/// Peak resident memory in bytes, where known; `reset`: measured from the start of the
/// solve (else it is the process's peak so far, an upper bound).
pub struct Peak {
    pub bytes: Option<u64>,
    pub reset: bool,
}

/// Prints the `compare` table: its header and `row`.
pub fn compare(row: &CompareRow) {
    let dash = || "-".to_string();
    let (time, peak, rms, max, mean) = match &row.reference {
        Some(r) => (
            format!("{:.2}", r.seconds),
            radiosity::form_factor::format_mib(r.matrix_bytes),
            format!("{:.2}", 100.0 * r.difference.rms),
            format!("{:.1}", 100.0 * r.difference.max),
            signed(100.0 * r.difference.bias, 2),
        ),
        None => (dash(), dash(), dash(), dash(), dash()),
    };
    outln!("| scene | elements | solver | its elements | time (s) | peak (MiB) | dense reference | dense time (s) | dense matrix (MiB) | RMS diff (%) | max diff (%) | mean diff (%) |");
    outln!("| --- | ---: | --- | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: |");
    outln!(
        "| {} | {} | {} | {} | {:.2} | {} | {} | {time} | {peak} | {rms} | {max} | {mean} |",
        row.stem,
        row.elements,
        row.solver,
        row.solver_elements,
        row.seconds,
        mib(&row.peak),
        row.reference_method.clone().unwrap_or_else(dash),
    );
}

/// MiB; "<= N" where the peak could not be reset before the solve, "?" where unknown.
fn mib(peak: &Peak) -> String {
    match peak.bytes {
        Some(b) if peak.reset => format!("{:.0}", b as f64 / (1024.0 * 1024.0)),
        Some(b) => format!("<= {:.0}", b as f64 / (1024.0 * 1024.0)),
        None => "?".into(),
    }
}

/// What the `bench` table's "other" column holds: the work of a run outside the stages it
/// lists (QA of issue #16: the column was unexplained).
pub const BENCH_OTHER: &str = "contact refinement, the memory and work checks, the exposure, \
                               and the renderer's own BVH built before the render";

/// Prints the note (stderr, unless `quiet`) and the header of the `bench` table.
pub fn bench_header(
    repeat: usize,
    (width, height): (u32, u32),
    rays: &radiosity::render::RenderSettings,
    solver: SolverKind,
    quiet: bool,
) {
    let solver_name = match solver {
        SolverKind::Auto => {
            "auto (dense Gauss-Seidel up to 20,000 elements when the matrix fits in half the \
             memory, else hierarchical)"
        }
        SolverKind::Lu => "LU",
        SolverKind::GaussSeidel => "Gauss-Seidel",
        SolverKind::Progressive => "progressive (form factors computed within the solve)",
        SolverKind::Hierarchical => "hierarchical (links computed within the solve)",
    };
    let n = rays.supersample.max(1);
    // Adaptive antialiasing takes an even N above 2 (`setup::ray_settings`).
    let pixel_rays = match rays.adaptive_contrast {
        Some(_) if n > 2 && n % 2 == 0 => format!("4 to {} rays a pixel (adaptive)", n * n),
        _ if n == 1 => "1 ray a pixel".to_string(),
        _ => format!("{n}x{n} rays a pixel"),
    };
    let rays_text = match rays.direct_light {
        true => format!("{pixel_rays}, direct light gathered per ray (as `render`)"),
        false => format!("{pixel_rays}, shading from the mesh alone (the paper's)"),
    };
    if !quiet {
        errln!(
            "median of {0}; times in ms; render {1}x{2}, {rays_text}; solver {solver_name}; \
             other: end to end less the stages listed ({BENCH_OTHER}); rays/s: visibility rays \
             over the form-factor stage, or over the solve stage where the solver computes its \
             form factors within the solve, - where none is cast (the hemicube's depth \
             buffer)",
            count(repeat as u64, "run"),
            width,
            height
        );
    }
    outln!(
        // The unit in the header too: with -q the note that says "times in ms" is not
        // printed (QA of issue #16).
        "| scene | max area | elements | method | parse (ms) | mesh (ms) | bvh (ms) | form factors (ms) | solve (ms) | shade (ms) | render (ms) | other (ms) | end to end (ms) | end to end less render (ms) | visibility rays | rays/s |"
    );
    outln!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
}

/// A row of the `bench` table: medians over the runs of one configuration, in seconds.
pub struct BenchRow {
    pub elements: usize,
    /// The form-factor method and its setting, as `check` names it ("area k=2",
    /// "hemicube resolution=128").
    pub method: String,
    /// Each stage, in the table's order (parse to render).
    pub stages: Vec<f64>,
    /// The form-factor stage (also in `stages`), for the ray rate.
    pub form_factors: f64,
    /// The solve stage (also in `stages`): the ray rate's time where the solver computes
    /// its form factors within it.
    pub solve: f64,
    /// End to end less the stages.
    pub other: f64,
    pub total: f64,
    /// End to end less the render stage.
    pub no_render: f64,
    pub rays: u64,
}

/// Prints a `bench` table row for `scene` at MAX_PATCH_AREA `max_area` (`None`: the
/// scene's own).
pub fn bench_row(scene: &str, max_area: Option<f64>, row: &BenchRow) {
    let area = max_area.map_or("scene's".to_string(), |a| a.to_string());
    let stages: Vec<String> = row.stages.iter().map(|s| ms(*s)).collect();
    outln!(
        "| {scene} | {area} | {} | {} | {} | {} | {} | {} | {} | {} |",
        row.elements,
        row.method,
        stages.join(" | "),
        ms(row.other),
        ms(row.total),
        ms(row.no_render),
        row.rays,
        rays_per_second(row),
    );
}

/// The rays/s column: rays over the stage that cast them (QA of issue #16: hierarchical
/// radiosity's rays over its 0 ms form-factor stage gave "5145996000.00 M").
fn rays_per_second(row: &BenchRow) -> String {
    let time = if row.form_factors > 0.0 {
        row.form_factors
    } else {
        row.solve
    };
    if row.rays == 0 || time <= 0.0 {
        "-".to_string()
    } else {
        format!("{:.2} M", row.rays as f64 / time / 1e6)
    }
}

/// Milliseconds with three significant digits or so.
fn ms(seconds: f64) -> String {
    let ms = seconds * 1e3;
    if ms >= 100.0 {
        format!("{ms:.0}")
    } else if ms >= 10.0 {
        format!("{ms:.1}")
    } else {
        format!("{ms:.2}")
    }
}

/// Prints what `generate building` wrote to `output`; `elements` is its element count.
pub fn building(output: &Path, params: &BuildingParams, built: &Scene, elements: &str) {
    let (lo, hi) = built.bounds();
    let size = hi - lo;
    let rooms = params.floors * params.rooms_x * params.rooms_z;
    outln!(
        "{}: {} room{}, {} surfaces of {:.0} m^2 in all, {:.1} x {:.1} x {:.1} m across; MAX_PATCH_AREA {}: {}",
        output.display(),
        rooms,
        if rooms == 1 { "" } else { "s" },
        built.surfaces.len(),
        built.total_area(),
        size.x,
        size.y,
        size.z,
        params.max_patch_area,
        elements
    );
}

/// Prints how a path-traced view was made and its noise: the RMS over the pixels that show
/// no emitter of the standard error of luminance, relative to their mean luminance.
pub fn path_traced(view: &PathTraced, settings: &PathTraceSettings) {
    let noise = view.noise();
    let pixels = view.width() * view.height();
    outln!(
        "paths             {} a pixel, seed {}, at most {}, roulette after {}, light sampling {}",
        view.samples_per_pixel(),
        settings.seed,
        count(settings.max_bounces, "bounce"),
        count(settings.roulette_after_bounces, "bounce"),
        if settings.next_event_estimation {
            "on"
        } else {
            "off"
        }
    );
    let pixels_counted = format!(
        "{}, {} showing an emitter left out",
        count(noise.pixels as u64, "pixel"),
        pixels - noise.pixels
    );
    if noise.relative().is_finite() {
        outln!(
            "noise             {:.2} % (RMS standard error of luminance over the mean luminance \
             {}; mean standard error {}; {pixels_counted})",
            100.0 * noise.relative(),
            significant(noise.mean_luminance, 4),
            significant(noise.mean_standard_error, 4),
        );
    } else {
        // QA of issue #16: `--max-bounces 0` printed "NaN %".
        outln!(
            "noise             none to measure: the pixels that show no emitter are black \
             ({pixels_counted}; {})",
            if settings.max_bounces == 0 {
                "--max-bounces 0 shows the emitters only"
            } else {
                // QA of issue #16: asked whether anything emits of a scene whose lamp lay
                // outside the room.
                "no light reaches what the view shows: nothing in the scene emits, or its \
                 light does not reach what the camera sees (a lamp outside the room or \
                 facing away; `check` says how much of each light lands)"
            }
        );
    }
}

/// Prints a radiosity render's difference from the path-traced view: RMS, mean and largest
/// difference of pixel luminance, and the path tracer's own noise on the same scale, all
/// relative to the path-traced view's RMS luminance.
pub fn path_trace_comparison(c: &FilmComparison, elements: usize) {
    // QA pass 18 of #16: a room of emitting walls read "0 showing an emitter left out".
    let left_out = if c.all_emitters {
        "every one showing an emitter: none left out, the emitters compared".to_string()
    } else {
        format!("{} showing an emitter left out", c.excluded)
    };
    outln!(
        "compared          the radiosity render ({elements} elements) with the path-traced \
         view on luminance: {} pixels ({left_out}), relative to the path tracer's RMS \
         luminance {}",
        c.pixels,
        significant(c.reference_rms_luminance, 4)
    );
    outln!("rms               {:.2} %", 100.0 * c.rms);
    outln!("bias              {} %", signed(100.0 * c.bias, 2));
    outln!("max               {:.2} %", 100.0 * c.max);
    if let Some(noise) = c.reference_noise {
        outln!(
            "reference noise   {:.2} % (the path tracer's RMS standard error over its RMS \
             luminance, as the lines above, where `noise` divides it by the mean luminance: \
             the rms a render equal to the true image would show)",
            100.0 * noise
        );
        // Within the reference's noise the difference is not measured (QA of issue #16:
        // "0.00 %" read as perfect agreement).
        if c.rms <= noise {
            outln!(
                "rms less noise    not measured: the rms is within the reference's noise (the \
                 render agrees with the path tracer as far as its noise shows); more --paths \
                 lower the noise"
            );
        } else if c.rms < 2.0 * noise {
            outln!(
                "rms less noise    {:.2} % (uncertain: the rms is under twice the reference's \
                 noise; more --paths sharpen it)",
                100.0 * c.rms_less_noise()
            );
        } else {
            outln!("rms less noise    {:.2} %", 100.0 * c.rms_less_noise());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{signed, significant};

    #[test]
    fn significant_figures_read_as_plain_numbers() {
        assert_eq!(significant(0.5080691785954333, 4), "0.5081");
        assert_eq!(significant(7.2977, 4), "7.298");
        assert_eq!(significant(20.0, 7), "20");
        assert_eq!(significant(19.898112, 7), "19.89811");
        assert_eq!(significant(0.1018865, 7), "0.1018865");
        assert_eq!(significant(0.005, 4), "0.005");
        assert_eq!(significant(106.83529, 6), "106.835");
        assert_eq!(significant(123456.7, 4), "123457");
        assert_eq!(significant(-2.5, 4), "-2.5");
        // Outside everyday magnitudes: an exponent, with the figures asked for and no
        // trailing zeros.
        assert_eq!(significant(1.5e-7, 4), "1.5e-7");
        assert_eq!(significant(1.23456e-7, 4), "1.235e-7");
        assert_eq!(significant(1e300, 6), "1e300");
        assert_eq!(signed(-0.0001, 3), "0.000");
        assert_eq!(signed(0.0004, 3), "0.000");
        assert_eq!(signed(-0.0006, 3), "-0.001");
        assert_eq!(signed(2.5, 2), "+2.50");
        assert_eq!(significant(0.0, 4), "0");
    }
}
