//! Reading scene files: the Appendix A grammar, value checks, polygon checks, error recovery.

use std::path::Path;

use glam::DVec3;
use thiserror::Error;

use super::lex::{lex, Keyword, Line, Token};
use super::polygon;
use super::SceneFile;
use crate::geometry;
use crate::light::Rgb;
use crate::luminaire::{Distribution, Luminaire, Output, DEFAULT_AIM};
use crate::mesh::MeshSettings;
use crate::scene::shape::{self, Facing};
use crate::scene::{EmissionGiven, Scene, Surface, SurfacePhotometry};

/// Two surfaces in one plane are the same surface given twice when one covers all but this
/// fraction of the larger's area (module [`Parser::duplicates`]).
const DUPLICATE_TOLERANCE: f64 = 1e-6;

/// After this many errors the reader stops looking for more.
const MAX_ERRORS: usize = 100;

/// One problem in a scene file, at a line and column.
///
/// Displays as `FILE:LINE:COLUMN: error: MESSAGE`. Lines and columns count from 1; a problem
/// with the file as a whole (it cannot be read) has line 0 and displays as
/// `FILE: error: MESSAGE`.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error("{}: error: {message}", location(file, *line, *column))]
pub struct ParseError {
    /// The file name (or other source name) given to the reader.
    pub file: String,
    /// The line, counting from 1; 0 for the file as a whole.
    pub line: usize,
    /// The column in characters, counting from 1; 0 for the whole line or file.
    pub column: usize,
    /// What was found and what was expected.
    pub message: String,
}

/// `FILE:LINE:COLUMN`, `FILE:LINE` or `FILE`, leaving out what is 0.
fn location(file: &str, line: usize, column: usize) -> String {
    match (line, column) {
        (0, _) => file.to_string(),
        (l, 0) => format!("{file}:{l}"),
        (l, c) => format!("{file}:{l}:{c}"),
    }
}

/// Every problem found in a scene file, in file order (at least one).
///
/// Displays as one [`ParseError`] per line, followed by a line with the count where there
/// are several.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error("{}", render(errors))]
pub struct SceneError {
    /// The problems, in the order they occur in the file.
    pub errors: Vec<ParseError>,
}

/// The errors one per line, then `N errors` where there are several (QA of issue #16: a
/// missing file's one line was followed by a stray "1 error").
fn render(errors: &[ParseError]) -> String {
    let lines: Vec<String> = errors.iter().map(|e| e.to_string()).collect();
    let mut text = lines.join("\n");
    if errors.len() > 1 {
        text.push_str(&format!("\n{} errors", errors.len()));
    }
    text
}

impl SceneError {
    /// A scene error made of one problem with the file as a whole.
    fn whole_file(file: &str, message: String) -> SceneError {
        SceneError {
            errors: vec![ParseError {
                file: file.to_string(),
                line: 0,
                column: 0,
                message,
            }],
        }
    }
}

/// Reads and checks the scene file at `path`.
///
/// A file that cannot be read, or is not UTF-8, gives a [`SceneError`] naming the file.
pub fn read_scene(path: &Path) -> Result<SceneFile, SceneError> {
    let name = path.display().to_string();
    crate::io::note_input(path);
    let bytes = std::fs::read(path)
        .map_err(|e| SceneError::whole_file(&name, format!("cannot read the scene file: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = 1 + valid.iter().filter(|&&b| b == b'\n').count();
        SceneError {
            errors: vec![ParseError {
                file: name.clone(),
                line,
                column: 0,
                message: "the file is not valid UTF-8 text".to_string(),
            }],
        }
    })?;
    parse_scene(&text, &name)
}

/// Parses and checks scene text in the Appendix A format (with the box primitive).
///
/// `source_name` is the file name used in error messages. Every error in the text is reported,
/// in order; after an error inside a `PATCHBEGIN` or `BOXBEGIN` block the reader skips to the
/// end of that block and goes on. The scene's `camera` is `None`.
pub fn parse_scene(text: &str, source_name: &str) -> Result<SceneFile, SceneError> {
    let (lines, eof) = lex(text);
    if lines.is_empty() {
        // One error, not one per expected header line (QA of issue #16: four at 1:1).
        return Err(SceneError {
            errors: vec![ParseError {
                file: source_name.to_string(),
                line: 1,
                column: 1,
                message: "the file is empty (or holds only comments): expected MAX_PATCH_AREA, \
                          INTEGRAL_STEPS, then SCENEBEGIN and the blocks (Appendix A)"
                    .to_string(),
            }],
        });
    }
    let mut parser = Parser {
        file: source_name,
        lines,
        pos: 0,
        eof,
        errors: Vec::new(),
        surface_lines: Vec::new(),
        block_line: (0, 0),
        lights: Vec::new(),
        unknown_line: None,
        folder: Path::new(source_name)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default(),
    };
    let settings = parser.header();
    let surfaces = parser.body();
    if parser.errors.is_empty() {
        parser.duplicates(&surfaces);
    }
    match settings {
        Some(settings) if parser.errors.is_empty() => Ok(SceneFile {
            settings,
            scene: Scene {
                surfaces,
                camera: None,
                lights: parser.lights,
            },
        }),
        _ => Err(SceneError {
            errors: parser.errors,
        }),
    }
}

/// Every pair (upper, lower) of surfaces where `upper` lies in the plane of `lower`, facing
/// the same way, and covers all of it while being no larger: the same surface given twice
/// (a second floor quad on the floor), in the order [`crate::scene::lying_on`] finds them.
/// A surface on part of another (a rug on a floor, in its plane or above it) is a model the
/// mesher handles (the covered part is left out); a duplicate leaves nothing of the lower
/// one and is a mistake. The scene reader refuses duplicates; the importers
/// ([`crate::io::import`]) drop the upper one with a warning.
///
/// Exact copies (the same corners in the same cyclic order, bit for bit) are paired with
/// the first of them by hashing, and only that first one goes into the hierarchy: a few
/// hundred identical boxes make obvhs build a tree deeper than its traversal stack (32),
/// which its debug validation refuses with a panic and its release traversal walks wrongly
/// (the DXF fuzz target's crash: an INSERT grid of 256 cells spaced 0).
pub(crate) fn duplicate_surfaces(surfaces: &[Surface]) -> Vec<(usize, usize)> {
    if surfaces.len() < 2 {
        return Vec::new();
    }
    let mut pairs = Vec::new();
    let mut first_of: std::collections::HashMap<Vec<[u64; 3]>, usize> =
        std::collections::HashMap::new();
    let mut kept = Vec::with_capacity(surfaces.len());
    for (i, s) in surfaces.iter().enumerate() {
        let bits: Vec<[u64; 3]> = s
            .vertices
            .iter()
            .map(|v| v.to_array().map(f64::to_bits))
            .collect();
        // The cycle from its smallest corner, so that a copy starting elsewhere matches.
        let start = (0..bits.len()).min_by_key(|&k| bits[k]).unwrap_or(0);
        let key: Vec<[u64; 3]> = (0..bits.len())
            .map(|k| bits[(start + k) % bits.len()])
            .collect();
        match first_of.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => pairs.push((i, *e.get())),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(i);
                kept.push(i);
            }
        }
    }
    let scene = Scene {
        surfaces: kept.iter().map(|&i| surfaces[i].clone()).collect(),
        camera: None,
        lights: Vec::new(),
    };
    let bvh = crate::visibility::PolygonBvh::over_surfaces(&scene);
    for o in crate::scene::lying_on(&scene, &bvh) {
        let (lower, upper) = (kept[o.lower as usize], kept[o.upper as usize]);
        let area = |s: usize| geometry::polygon_area(&surfaces[s].vertices);
        // Covering the whole of the lower surface and no larger than it, to 1e-6 (six
        // significant digits, as scene files are often written).
        let whole = (1.0 - DUPLICATE_TOLERANCE) * area(lower).max(area(upper));
        if o.same_plane(bvh.scale()) && o.covered_area >= whole {
            pairs.push((upper, lower));
        }
    }
    pairs
}

/// A planar polygon that is not convex, as triangles, when its outline does not cross
/// itself: the corners flattened onto the best-fit plane and ear-clipped
/// ([`crate::io::import`]'s triangulation), accepted only when every triangle is usable and
/// their areas add up to the polygon's (to 1e-9: rounding), which fails for an outline that
/// crosses itself (a bow tie, whose signed parts cancel) or goes round twice. `None` then:
/// such a patch is more likely corners given in the wrong order than a shape, and stays an
/// error.
fn simple_triangles(corners: &[DVec3]) -> Option<Vec<[DVec3; 3]>> {
    let mut flat = corners.to_vec();
    geometry::project_to_plane(&mut flat);
    let (triangles, lost) = crate::io::import::triangulate(&flat);
    let area = geometry::polygon_area(&flat);
    let sum: f64 = triangles.iter().map(|t| geometry::polygon_area(t)).sum();
    (lost == 0 && !triangles.is_empty() && (sum - area).abs() <= 1e-9 * area).then_some(triangles)
}

/// The keywords that start a block, or end the scene: where recovery after an error stops.
fn is_block_start(k: Keyword) -> bool {
    matches!(
        k,
        Keyword::PatchBegin
            | Keyword::BoxBegin
            | Keyword::SphereBegin
            | Keyword::CylinderBegin
            | Keyword::ConeBegin
            | Keyword::LightBegin
            | Keyword::SceneEnd
    )
}

/// The round primitives.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Round {
    Sphere,
    Cylinder,
    Cone,
}

impl Round {
    fn keywords(self) -> (Keyword, Keyword) {
        match self {
            Round::Sphere => (Keyword::SphereBegin, Keyword::SphereEnd),
            Round::Cylinder => (Keyword::CylinderBegin, Keyword::CylinderEnd),
            Round::Cone => (Keyword::ConeBegin, Keyword::ConeEnd),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Round::Sphere => "sphere",
            Round::Cylinder => "cylinder",
            Round::Cone => "cone",
        }
    }
}

/// A round primitive's geometry as written.
struct RoundShape {
    centre: DVec3,
    radius: f64,
    height: f64,
    resolution: u32,
    /// The `RADIUS` line, where problems with the faces are reported.
    line: usize,
    column: usize,
}

/// Marks a failed step whose error has already been recorded.
struct Reported;

/// The result of a step that records its own errors.
type Step<T> = Result<T, Reported>;

/// A recursive-descent reader over the significant lines.
struct Parser<'a> {
    file: &'a str,
    lines: Vec<Line<'a>>,
    pos: usize,
    eof: (usize, usize),
    errors: Vec<ParseError>,
    /// Where each surface read so far was given (its `VERTEX0` line, or its box's `SIZE` or
    /// `HEIGHT` line), for problems between surfaces.
    surface_lines: Vec<(usize, usize)>,
    /// The line of the block read last.
    block_line: (usize, usize),
    /// The `LIGHTBEGIN` blocks read so far.
    lights: Vec<Luminaire>,
    /// The last line reported as having an unknown keyword: its words are not reported
    /// again (QA pass 16 of #16: `hello world` was an unknown keyword, then "expected a
    /// number after \"hello\", found \"world\""), as whatever the line is, it is not
    /// the line expected there.
    unknown_line: Option<usize>,
    /// The folder that paths in the file (IES files) are relative to: the source name's.
    folder: std::path::PathBuf,
}

/// A patch or box block's name and colours.
struct Head {
    name: String,
    emission: Rgb,
    reflectance: Rgb,
    /// How the emission was given and whether the block is an opening.
    photometry: SurfacePhotometry,
    /// `FLUX P`: the lumens, spread over the block's surfaces once they are known.
    flux: Option<f64>,
}

/// The corners of a polygon and where they were written.
struct Corners {
    vertices: Vec<DVec3>,
    /// The `VERTEX0` line, where polygon errors are reported.
    line: usize,
    column: usize,
}

/// A box block's geometry as written.
enum BoxShape {
    /// `ORIGIN` and `SIZE`.
    Aligned {
        origin: DVec3,
        size: DVec3,
        /// The `SIZE` line, where problems with the faces are reported.
        line: usize,
        column: usize,
    },
    /// `VERTICES 4`, `VERTEX0`..`VERTEX3` and `HEIGHT`.
    Prism {
        base: Corners,
        height: f64,
        /// The `HEIGHT` line, where problems with the other faces are reported.
        line: usize,
        column: usize,
    },
}

impl<'a> Parser<'a> {
    // ----- low-level helpers -----

    fn current(&self) -> Option<Line<'a>> {
        self.lines.get(self.pos).cloned()
    }

    fn current_keyword(&self) -> Option<Keyword> {
        self.lines.get(self.pos).map(Line::keyword)
    }

    fn error(&mut self, line: usize, column: usize, message: impl Into<String>) -> Reported {
        self.errors.push(ParseError {
            file: self.file.to_string(),
            line,
            column,
            message: message.into(),
        });
        Reported
    }

    /// An error at a word of `line`; none on a line already reported as having an unknown
    /// keyword ([`Parser::unknown_line`]).
    fn error_at(&mut self, token: Token, line: &Line, message: impl Into<String>) -> Reported {
        if self.unknown_line == Some(line.number) {
            return Reported;
        }
        self.error(line.number, token.column, message)
    }

    /// Takes the current line if it starts with `keyword`; otherwise reports what was found.
    fn expect(&mut self, keyword: Keyword) -> Step<Line<'a>> {
        self.expect_either(keyword, &keyword.spelling())
    }

    /// Like [`Self::expect`], with `wanted` describing the expectation in the message.
    ///
    /// A line with an unknown keyword is reported and does not end the block, so that one
    /// run shows every mistake in it: when the expected line follows it (and any other
    /// unknown lines) it was an extra line and is passed over; otherwise it is taken as the
    /// expected line misspelt, and its values are still read and checked.
    fn expect_either(&mut self, keyword: Keyword, wanted: &str) -> Step<Line<'a>> {
        if self.skip_unknown_before(wanted, |k| k == keyword) {
            return self.expect_either(keyword, wanted);
        }
        match self.current() {
            Some(line) if line.keyword() == keyword => {
                self.pos += 1;
                Ok(line)
            }
            Some(line) if line.keyword() == Keyword::Unknown => {
                // Reported once, as a misspelling of the expected line.
                self.unexpected(wanted);
                self.pos += 1;
                Ok(line)
            }
            _ => Err(self.unexpected(wanted)),
        }
    }

    /// When the current line and any after it have unknown keywords and the next known
    /// line is one that `accept` takes: reports each unknown line (once, as not `wanted`)
    /// and moves past them, returning true. Otherwise takes nothing and returns false.
    fn skip_unknown_before(&mut self, wanted: &str, accept: impl Fn(Keyword) -> bool) -> bool {
        let mut next = self.pos;
        while self.lines.get(next).map(Line::keyword) == Some(Keyword::Unknown) {
            next += 1;
        }
        let found = self.lines.get(next).map(Line::keyword);
        if next == self.pos || !found.is_some_and(accept) {
            return false;
        }
        while self.pos < next {
            self.unexpected(wanted);
            self.pos += 1;
        }
        true
    }

    /// Reports the current line (or the end of the file) where `wanted` should be.
    fn unexpected(&mut self, wanted: &str) -> Reported {
        let Some(line) = self.current() else {
            let (l, c) = self.eof;
            return self.error(l, c, format!("expected {wanted}, found end of file"));
        };
        let head = line.head();
        if line.keyword() == Keyword::Unknown {
            let msg = format!("unknown keyword \"{}\"; expected {wanted}", head.text);
            let reported = self.error_at(head, &line, msg);
            self.unknown_line = Some(line.number);
            return reported;
        }
        let msg = format!("expected {wanted}, found \"{}\"", head.text);
        self.error_at(head, &line, msg)
    }

    /// Reports words after the first `used` ones on `line` (the line is still understood).
    fn line_end(&mut self, line: &Line, used: usize) {
        let Some(extra) = line.tokens.get(used) else {
            return;
        };
        let what = match used {
            1 => format!("\"{}\"", line.head().text),
            2 => format!("the value of \"{}\"", line.head().text),
            n => format!("the {} values of \"{}\"", n - 1, line.head().text),
        };
        self.error_at(
            *extra,
            line,
            format!(
                "expected end of line after {what}, found \"{}\"",
                extra.text
            ),
        );
    }

    /// The finite number in word `index` of `line`; `what` names it in messages.
    fn number(&mut self, line: &Line<'a>, index: usize, what: &str) -> Step<(f64, Token<'a>)> {
        let key = line.head().text;
        let Some(token) = line.tokens.get(index).copied() else {
            if self.unknown_line == Some(line.number) {
                return Err(Reported);
            }
            return Err(self.error(
                line.number,
                line.end_column,
                format!("expected {what} after \"{key}\", found end of line"),
            ));
        };
        let message = match token.text.parse::<f64>() {
            Ok(v) if v.is_finite() => return Ok((v, token)),
            // "a number (the y size)" becomes "a finite number (the y size)".
            Ok(_) => format!(
                "expected a finite {} after \"{key}\", found \"{}\"",
                what.strip_prefix("a ").unwrap_or(what),
                token.text
            ),
            Err(_) => format!("expected {what} after \"{key}\", found \"{}\"", token.text),
        };
        Err(self.error_at(token, line, message))
    }

    /// Records an error when the coordinate `v` (word `token` of `line`) is beyond
    /// [`geometry::MAX_COORDINATE`] in magnitude.
    fn check_range(&mut self, v: f64, token: Token<'a>, line: &Line<'a>) {
        if v.abs() > geometry::MAX_COORDINATE {
            let msg = format!(
                "the coordinate \"{}\" is beyond the largest the program supports ({:e} in \
                 magnitude); rescale the scene (for instance to metres)",
                token.text,
                geometry::MAX_COORDINATE
            );
            self.error_at(token, line, msg);
        }
    }

    /// A `KEYWORD value` line.
    fn value(&mut self, keyword: Keyword) -> Step<(f64, Token<'a>, Line<'a>)> {
        let line = self.expect(keyword)?;
        let (v, token) = self.number(&line, 1, "a number")?;
        self.line_end(&line, 2);
        Ok((v, token, line))
    }

    /// A `KEYWORD value` line whose bad number is recorded but does not stop the block:
    /// the block is dropped at its end (it has errors), and the lines after it are still
    /// read and checked, so one file shows all its mistakes. The value is then 0.
    fn value_or_recorded(&mut self, keyword: Keyword) -> Step<(f64, Option<Token<'a>>, Line<'a>)> {
        let line = self.expect(keyword)?;
        let found = self.number(&line, 1, "a number").ok();
        self.line_end(&line, 2);
        Ok((found.map_or(0.0, |f| f.0), found.map(|f| f.1), line))
    }

    /// A `KEYWORD x y z` line; `what` names the three numbers ("coordinate", "size"). Each
    /// number comes with its word, `None` from the first one that could not be read (that
    /// one is recorded, and the block will be dropped at its end; the rest of the line would
    /// only repeat the complaint).
    #[allow(clippy::type_complexity)]
    fn triple_read(
        &mut self,
        keyword: Keyword,
        what: &str,
    ) -> Step<([Option<(f64, Token<'a>)>; 3], Line<'a>)> {
        let line = self.expect(keyword)?;
        let mut xyz = [None; 3];
        // A colour's three numbers are its bands (QA pass 13 of #16: "the z band").
        let names = if keyword == Keyword::Colour {
            ["red", "green", "blue"]
        } else {
            ["x", "y", "z"]
        };
        for (i, axis) in names.iter().enumerate() {
            match self.number(&line, i + 1, &format!("a number (the {axis} {what})")) {
                Ok(found) => xyz[i] = Some(found),
                Err(Reported) => return Ok((xyz, line)),
            }
        }
        self.line_end(&line, 4);
        Ok((xyz, line))
    }

    /// A whole number written as an integer or with a zero fraction ("2", "2.0").
    fn whole(v: f64) -> Option<u64> {
        (v.fract() == 0.0 && (0.0..=9.007_199_254_740_992e15).contains(&v)).then_some(v as u64)
    }

    // ----- file structure -----

    /// `MAX_PATCH_AREA`, `INTEGRAL_STEPS` and `SCENEBEGIN`. The two values swapped, or one
    /// given twice, is one error, not one for every line after it (QA of issue #16).
    fn header(&mut self) -> Option<MeshSettings> {
        let next_keyword = |p: &Self| p.lines.get(p.pos + 1).map(|l| l.keyword());
        let swapped = self.current_keyword() == Some(Keyword::IntegralSteps)
            && next_keyword(self) == Some(Keyword::MaxPatchArea);
        let (area, steps) = if swapped {
            let line = self.current().expect("checked above");
            let head = line.head();
            self.error_at(
                head,
                &line,
                "expected MAX_PATCH_AREA, found \"INTEGRAL_STEPS\": the file starts with \
                 MAX_PATCH_AREA, then INTEGRAL_STEPS (Appendix A); swap the two lines",
            );
            let steps = self.steps_line();
            (self.area_line(), steps)
        } else {
            let area = self.area_line();
            self.repeated_header_lines(&[Keyword::MaxPatchArea]);
            (area, self.steps_line())
        };
        self.repeated_header_lines(&[Keyword::MaxPatchArea, Keyword::IntegralSteps]);
        let _ =
            self.skip_unless_known(|p| p.expect(Keyword::SceneBegin).map(|l| p.line_end(&l, 1)));
        Some(MeshSettings {
            max_patch_area: area?,
            integral_steps: steps?,
        })
    }

    /// Reports and passes over header lines of `keywords` already read.
    fn repeated_header_lines(&mut self, keywords: &[Keyword]) {
        while let Some(k) = self.current_keyword().filter(|k| keywords.contains(k)) {
            let line = self.current().expect("a keyword was read");
            let head = line.head();
            self.error_at(
                head,
                &line,
                format!(
                    "{} is given twice; remove this line (the first is used)",
                    k.spelling()
                ),
            );
            self.pos += 1;
        }
    }

    /// The `MAX_PATCH_AREA` line's value, checked.
    fn area_line(&mut self) -> Option<f64> {
        self.header_value(Keyword::MaxPatchArea)
            .and_then(|(v, t, l)| {
                if v > 0.0 {
                    return Some(v);
                }
                let msg = format!(
                    "MAX_PATCH_AREA must be greater than 0, found \"{}\"",
                    t.text
                );
                self.error_at(t, &l, msg);
                None
            })
    }

    /// The `INTEGRAL_STEPS` line's value, checked.
    fn steps_line(&mut self) -> Option<u32> {
        self.header_value(Keyword::IntegralSteps)
            .and_then(
                |(v, t, l)| match Self::whole(v).and_then(|k| u32::try_from(k).ok()) {
                    Some(k) if k >= 1 => Some(k),
                    _ => {
                        let msg = format!(
                        "INTEGRAL_STEPS must be a whole number of at least 1 (and at most {}), \
                         found \"{}\"",
                        u32::MAX,
                        t.text
                    );
                        self.error_at(t, &l, msg);
                        None
                    }
                },
            )
    }

    /// A header line; a line with an unknown keyword in its place is taken as a misspelling.
    fn header_value(&mut self, keyword: Keyword) -> Option<(f64, Token<'a>, Line<'a>)> {
        self.skip_unless_known(|p| p.value(keyword)).ok()
    }

    /// Runs `step`; when it fails without taking a line and the line has an unknown keyword,
    /// takes that line (so one misspelt line gives one error, not one per expectation).
    fn skip_unless_known<T>(&mut self, step: impl FnOnce(&mut Self) -> Step<T>) -> Step<T> {
        let before = self.pos;
        let result = step(self);
        if result.is_err() && self.pos == before && self.current_keyword() == Some(Keyword::Unknown)
        {
            self.pos += 1;
        }
        result
    }

    /// The blocks up to and including `SCENEEND`, then a check that nothing follows.
    fn body(&mut self) -> Vec<Surface> {
        let mut surfaces = Vec::new();
        let mut blocks = 0usize;
        loop {
            if self.errors.len() >= MAX_ERRORS {
                let (l, _) = self.current().map_or(self.eof, |l| (l.number, 0));
                self.error(l, 0, "too many errors; stopped reading here");
                return surfaces;
            }
            match self.current_keyword() {
                None => {
                    let (l, c) = self.eof;
                    let msg = if blocks == 0 {
                        "no patches: expected PATCHBEGIN, BOXBEGIN, SPHEREBEGIN, CYLINDERBEGIN \
                         or CONEBEGIN after SCENEBEGIN, found end of file"
                    } else {
                        "expected SCENEEND, found end of file"
                    };
                    self.error(l, c, msg);
                    return surfaces;
                }
                Some(Keyword::PatchBegin) => {
                    blocks += 1;
                    surfaces.extend(self.patch().into_iter().flatten());
                    self.surface_lines.resize(surfaces.len(), self.block_line);
                }
                Some(Keyword::BoxBegin) => {
                    blocks += 1;
                    surfaces.extend(self.box_block().into_iter().flatten());
                    self.surface_lines.resize(surfaces.len(), self.block_line);
                }
                Some(k @ (Keyword::SphereBegin | Keyword::CylinderBegin | Keyword::ConeBegin)) => {
                    blocks += 1;
                    let kind = match k {
                        Keyword::SphereBegin => Round::Sphere,
                        Keyword::CylinderBegin => Round::Cylinder,
                        _ => Round::Cone,
                    };
                    surfaces.extend(self.round_block(kind).into_iter().flatten());
                    self.surface_lines.resize(surfaces.len(), self.block_line);
                }
                Some(Keyword::LightBegin) => {
                    // Not counted: a scene needs surfaces, and lights alone are "no patches".
                    if let Some(light) = self.light_block() {
                        self.lights.push(light);
                    }
                }
                Some(Keyword::SceneEnd) => {
                    self.scene_end(blocks);
                    return surfaces;
                }
                Some(_) => {
                    // Counted so that an unreadable block is not also reported as "no patches".
                    blocks += 1;
                    self.stray_line();
                }
            }
        }
    }

    /// Reports every surface that lies in the plane of another, facing the same way, and
    /// covers all of it while being no larger: the same surface given twice (a second floor
    /// quad on the floor). A surface on part of another (a rug on a floor, in its plane or
    /// above it) is a model the mesher handles ([`crate::scene::lying_on`]: the covered
    /// part is left out); a duplicate leaves nothing of the lower one and is a mistake.
    fn duplicates(&mut self, surfaces: &[Surface]) {
        for (upper, lower) in duplicate_surfaces(surfaces) {
            let (line, column) = self.surface_lines[upper];
            let (lower_line, _) = self.surface_lines[lower];
            let msg = format!(
                "surface \"{}\" lies exactly on surface \"{}\" (line {lower_line}): the same \
                 polygon facing the same way, given twice; remove one (a surface lying on \
                 another must cover only part of it, like a rug on a floor)",
                surfaces[upper].name, surfaces[lower].name
            );
            self.error(line, column, msg);
        }
    }

    /// Takes `SCENEEND` and reports an empty scene or anything after it.
    fn scene_end(&mut self, blocks: usize) {
        let Ok(line) = self.expect(Keyword::SceneEnd) else {
            return;
        };
        self.line_end(&line, 1);
        if blocks == 0 {
            let head = line.head();
            self.error_at(
                head,
                &line,
                "no patches: expected PATCHBEGIN, BOXBEGIN, SPHEREBEGIN, CYLINDERBEGIN or \
                 CONEBEGIN after SCENEBEGIN, found \"SCENEEND\"",
            );
        }
        if let Some(after) = self.current() {
            let head = after.head();
            self.error_at(
                head,
                &after,
                format!(
                    "expected end of file after SCENEEND, found \"{}\"",
                    head.text
                ),
            );
        }
    }

    /// Reports a line where a block should start and skips to the next block.
    fn stray_line(&mut self) {
        self.unexpected(
            "PATCHBEGIN, BOXBEGIN, SPHEREBEGIN, CYLINDERBEGIN, CONEBEGIN, LIGHTBEGIN or SCENEEND",
        );
        self.pos += 1;
        while let Some(k) = self.current_keyword() {
            if is_block_start(k) {
                break;
            }
            self.pos += 1;
        }
    }

    /// After an error inside a block: skips past its `end` line, or up to the start of the
    /// next block or of `SCENEEND` when `end` is missing.
    fn skip_block(&mut self, end: Keyword) {
        while let Some(k) = self.current_keyword() {
            if k == end {
                self.pos += 1;
                return;
            }
            if is_block_start(k) {
                return;
            }
            self.pos += 1;
        }
    }

    /// Runs `fields` inside a `begin` ... `end` block; on a failure skips the rest of it.
    /// `None` when anything in the block was wrong.
    fn block<T>(
        &mut self,
        begin: Keyword,
        end: Keyword,
        fields: impl FnOnce(&mut Self) -> Step<T>,
    ) -> Option<T> {
        let errors_before = self.errors.len();
        let result = self.expect(begin).and_then(|line| {
            self.line_end(&line, 1);
            let value = fields(self)?;
            let end_line = self.expect_end(end)?;
            self.line_end(&end_line, 1);
            Ok(value)
        });
        match result {
            Ok(value) if self.errors.len() == errors_before => Some(value),
            Ok(_) => None,
            Err(Reported) => {
                self.skip_block(end);
                None
            }
        }
    }

    /// The block's `end` line; a further `VERTEXk` gets its own message.
    fn expect_end(&mut self, end: Keyword) -> Step<Line<'a>> {
        if let Some(line) = self.current() {
            if let Keyword::Vertex(_) = line.keyword() {
                let head = line.head();
                let msg = format!(
                    "expected {}, found \"{}\": there are more VERTEX lines than VERTICES says",
                    end.spelling(),
                    head.text
                );
                return Err(self.error_at(head, &line, msg));
            }
        }
        self.expect(end)
    }

    // ----- patches -----

    /// A `PATCHBEGIN` block as a checked surface; a planar patch that is not convex but
    /// whose outline does not cross itself (an L, a dart) as its triangles `NAME.0`,
    /// `NAME.1`, ... ([`simple_triangles`]).
    fn patch(&mut self) -> Option<Vec<Surface>> {
        let (head, mut corners) = self.block(Keyword::PatchBegin, Keyword::PatchEnd, |p| {
            let name = p.name_line()?;
            let count = p.vertex_count(3, "a patch")?;
            let head = p.colours(name)?;
            Ok((head, p.vertex_lines(count)?))
        })?;
        self.block_line = (corners.line, corners.column);
        if let Err(geometry::PolygonError::Reflex { .. }) =
            geometry::validate_polygon(&corners.vertices)
        {
            if let Some(triangles) = simple_triangles(&corners.vertices) {
                let mut surfaces: Vec<Surface> = triangles
                    .into_iter()
                    .enumerate()
                    .map(|(k, t)| Surface {
                        name: format!("{}.{k}", head.name),
                        emission: head.emission,
                        reflectance: head.reflectance,
                        vertices: t.to_vec(),
                        photometry: head.photometry,
                    })
                    .collect();
                Self::spread_flux(&head, &mut surfaces);
                return Some(surfaces);
            }
            // Not convex and no simple outline: it crosses itself or winds twice (QA of issue
            // #16: "not convex" read as if non-convex outlines were refused, which an L is
            // not).
            self.error(
                corners.line,
                corners.column,
                "the outline crosses itself or goes round more than once (a bow tie: corners \
                 in the wrong order); list the corners once round the outline, \
                 counter-clockwise seen from the front (a non-convex outline such as an L is \
                 split into triangles)"
                    .to_string(),
            );
            return None;
        }
        self.check_polygon(&mut corners)?;
        let mut surfaces = vec![Surface {
            name: head.name.clone(),
            emission: head.emission,
            reflectance: head.reflectance,
            vertices: corners.vertices,
            photometry: head.photometry,
        }];
        Self::spread_flux(&head, &mut surfaces);
        Some(surfaces)
    }

    /// Checks and flattens a polygon ([`geometry::validate_polygon`], [`geometry::flatten`]),
    /// reporting a problem at its `VERTEX0` line.
    fn check_polygon(&mut self, corners: &mut Corners) -> Option<()> {
        // Checked again once flattened: flattening can bring two corners of a sliver within
        // the same-point distance of each other (found by the obj fuzz target).
        let checked = geometry::validate_polygon(&corners.vertices).and_then(|()| {
            geometry::flatten(&mut corners.vertices);
            geometry::validate_polygon(&corners.vertices)
        });
        match checked {
            Ok(()) => Some(()),
            Err(e) => {
                self.error(corners.line, corners.column, polygon::message(&e));
                None
            }
        }
    }

    /// The `#NAME` line: the rest of the line after `#`, trimmed.
    fn name_line(&mut self) -> Step<String> {
        let line = self.expect(Keyword::Name)?;
        let after_hash = line.code.split_once('#').map_or("", |(_, rest)| rest);
        Ok(after_hash.trim().to_string())
    }

    /// `Er`, `Eg`, `Eb` (or `LUMINANCE L`, or `FLUX P`), then `Rr`, `Rg`, `Rb` (or
    /// `OPENING`), in that order, range-checked.
    fn colours(&mut self, name: String) -> Step<Head> {
        let mut emission = [0.0; 3];
        let mut photometry = SurfacePhotometry::default();
        let mut flux = None;
        self.skip_unknown_before("Er (or LUMINANCE L, or FLUX P)", |k| {
            matches!(k, Keyword::Er | Keyword::Luminance | Keyword::Flux)
        });
        match self.current_keyword() {
            Some(k @ (Keyword::Luminance | Keyword::Flux)) => {
                let (v, token, line) = self.value_or_recorded(k)?;
                if let (true, Some(token)) = (v < 0.0, token) {
                    let what = if k == Keyword::Luminance {
                        "LUMINANCE (cd/m^2)"
                    } else {
                        "FLUX (lm)"
                    };
                    let msg = format!("{what} must not be negative, found \"{}\"", token.text);
                    self.error_at(token, &line, msg);
                }
                if let (true, Some(token)) = (v > crate::scene::MAX_EMISSION, token) {
                    let what = if k == Keyword::Luminance {
                        "LUMINANCE"
                    } else {
                        "FLUX"
                    };
                    self.error_at(token, &line, too_bright(what, token.text));
                }
                if k == Keyword::Luminance {
                    emission = [std::f64::consts::PI * v; 3];
                    photometry.emission = EmissionGiven::Luminance(v);
                } else {
                    flux = Some(v);
                    photometry.emission = EmissionGiven::Flux(v);
                }
            }
            _ => {
                for (i, k) in [Keyword::Er, Keyword::Eg, Keyword::Eb]
                    .into_iter()
                    .enumerate()
                {
                    let wanted = if i == 0 {
                        "Er (or LUMINANCE L, or FLUX P)".to_string()
                    } else {
                        k.spelling()
                    };
                    let line = self.expect_either(k, &wanted)?;
                    let found = self.number(&line, 1, "a number").ok();
                    self.line_end(&line, 2);
                    let (v, token) = (found.map_or(0.0, |f| f.0), found.map(|f| f.1));
                    if let (true, Some(token)) = (v < 0.0, token) {
                        let msg =
                            format!("emission must not be negative, found \"{}\"", token.text);
                        self.error_at(token, &line, msg);
                    }
                    if let (true, Some(token)) = (v > crate::scene::MAX_EMISSION, token) {
                        self.error_at(token, &line, too_bright("emission", token.text));
                    }
                    emission[i] = v;
                }
            }
        }
        let mut reflectance = [0.0; 3];
        self.skip_unknown_before("Rr (or OPENING)", |k| {
            matches!(k, Keyword::Rr | Keyword::Opening)
        });
        if self.current_keyword() == Some(Keyword::Opening) {
            let line = self.expect(Keyword::Opening)?;
            self.line_end(&line, 1);
            photometry.opening = true;
            if let Some(next) = self.current() {
                if matches!(next.keyword(), Keyword::Rr | Keyword::Rg | Keyword::Rb) {
                    let head = next.head();
                    let msg = format!(
                        "expected the block's shape after OPENING, found \"{}\": an opening \
                         has reflectance 0 (light leaves through it), so it takes no Rr, Rg, Rb",
                        head.text
                    );
                    return Err(self.error_at(head, &next, msg));
                }
            }
        } else {
            for (i, k) in [Keyword::Rr, Keyword::Rg, Keyword::Rb]
                .into_iter()
                .enumerate()
            {
                let wanted = if i == 0 {
                    "Rr (or OPENING)".to_string()
                } else {
                    k.spelling()
                };
                let line = self.expect_either(k, &wanted)?;
                let found = self.number(&line, 1, "a number").ok();
                self.line_end(&line, 2);
                let (v, token) = (found.map_or(0.0, |f| f.0), found.map(|f| f.1));
                if let (false, Some(token)) = ((0.0..1.0).contains(&v), token) {
                    let msg = format!(
                        "reflectance must be at least 0 and below 1, found \"{}\"",
                        token.text
                    );
                    self.error_at(token, &line, msg);
                }
                reflectance[i] = v;
            }
        }
        Ok(Head {
            name,
            emission: Rgb(emission),
            reflectance: Rgb(reflectance),
            photometry,
            flux,
        })
    }

    /// A block's `FLUX P` spread over its surfaces: exitance P / (their total area) on
    /// each. A block of one surface keeps the keyword for the writer; the pieces of a
    /// split patch or a primitive are written back as their exitance.
    fn spread_flux(head: &Head, surfaces: &mut [Surface]) {
        let Some(p) = head.flux else { return };
        let area: f64 = surfaces
            .iter()
            .map(|s| geometry::polygon_area(&s.vertices))
            .sum();
        let exitance = if area > 0.0 { p / area } else { 0.0 };
        let single = surfaces.len() == 1;
        for s in surfaces {
            s.emission = Rgb::splat(exitance);
            if !single {
                s.photometry.emission = EmissionGiven::FluxShare;
            }
        }
    }

    /// `VERTICES n` with a whole `n` of at least `min`.
    fn vertex_count(&mut self, min: u64, what: &str) -> Step<usize> {
        let (v, token, line) = self.value(Keyword::Vertices)?;
        match Self::whole(v) {
            Some(n) if n >= min => Ok(usize::try_from(n).unwrap_or(usize::MAX)),
            _ => Err(self.error_at(
                token,
                &line,
                format!(
                    "{what} needs a whole number of at least {min} after \"VERTICES\", \
                     found \"{}\"",
                    token.text
                ),
            )),
        }
    }

    /// `VERTEX0` .. `VERTEX(count-1)`, in order.
    fn vertex_lines(&mut self, count: usize) -> Step<Corners> {
        let mut vertices = Vec::new();
        let (mut first_line, mut first_column) = (0, 0);
        for k in 0..count {
            let keyword = Keyword::Vertex(k);
            let found = self.current_keyword();
            if k > 0 && !matches!(found, Some(Keyword::Vertex(_) | Keyword::Unknown)) {
                let wanted = format!(
                    "{} (VERTICES says {count} vertices, but only {k} are given)",
                    keyword.spelling()
                );
                return Err(self.unexpected(&wanted));
            }
            let (read, line) = self.triple_read(keyword, "coordinate")?;
            if k == 0 {
                (first_line, first_column) = (line.number, line.head().column);
            }
            for (v, token) in read.iter().flatten() {
                self.check_range(*v, *token, &line);
            }
            vertices.push(read.map(|t| t.map_or(0.0, |t| t.0)).into());
        }
        Ok(Corners {
            vertices,
            line: first_line,
            column: first_column,
        })
    }

    // ----- point luminaires -----

    /// A `LIGHTBEGIN` block: `#NAME`, then `POSITION x y z`, `AIM x y z` (optional),
    /// `INTENSITY I` or `FLUX P`, `DISTRIBUTION ISOTROPIC | COSINE | IES file.ies`, `COLOUR r g b`
    /// (optional), in any order, each at most once.
    fn light_block(&mut self) -> Option<Luminaire> {
        let begin = self
            .current()
            .map_or((0, 0), |l| (l.number, l.head().column));
        let light = self.block(Keyword::LightBegin, Keyword::LightEnd, |p| {
            let name = p.name_line()?;
            p.light_fields(name, begin)
        })?;
        Some(light)
    }

    /// The lines of a light block after its name, up to (not including) `LIGHTEND`.
    fn light_fields(&mut self, name: String, begin: (usize, usize)) -> Step<Luminaire> {
        let mut position = None;
        let mut aim = None;
        let mut output = None;
        let mut distribution = None;
        let mut colour = None;
        let mut bad_distribution = false;
        let mut seen: Vec<(Keyword, usize)> = Vec::new();
        let errors_before = self.errors.len();
        loop {
            let Some(line) = self.current() else {
                return Err(self.unexpected("LIGHTEND"));
            };
            let k = line.keyword();
            if k == Keyword::LightEnd || is_block_start(k) {
                break;
            }
            let key = match k {
                Keyword::Flux => Keyword::Intensity,
                other => other,
            };
            if let Some((_, first)) = seen.iter().find(|(s, _)| *s == key) {
                let head = line.head();
                let what = if key == Keyword::Intensity {
                    "INTENSITY or FLUX".to_string()
                } else {
                    key.spelling()
                };
                let msg = format!(
                    "{what} is given twice in this light (first on line {first}); give it once"
                );
                return Err(self.error_at(head, &line, msg));
            }
            seen.push((key, line.number));
            match k {
                Keyword::Position => {
                    let (read, l) = self.triple_read(Keyword::Position, "coordinate")?;
                    for (v, token) in read.iter().flatten() {
                        self.check_range(*v, *token, &l);
                    }
                    position = Some(DVec3::from(read.map(|t| t.map_or(0.0, |t| t.0))));
                }
                Keyword::Aim => {
                    let (read, l) = self.triple_read(Keyword::Aim, "component")?;
                    let v = DVec3::from(read.map(|t| t.map_or(0.0, |t| t.0)));
                    if read.iter().all(Option::is_some) && v.length_squared() == 0.0 {
                        let head = l.head();
                        self.error_at(
                            head,
                            &l,
                            "AIM must be a direction (not 0 0 0): the axis of the light, \
                             for example 0 0 -1 for straight down in a z-up scene, 0 -1 0 in a y-up one",
                        );
                    }
                    aim = Some(v);
                }
                Keyword::Intensity | Keyword::Flux => {
                    let (v, token, l) = self.value_or_recorded(k)?;
                    if let (true, Some(token)) = (v < 0.0, token) {
                        let msg = format!(
                            "{} must not be negative, found \"{}\"",
                            k.spelling(),
                            token.text
                        );
                        self.error_at(token, &l, msg);
                    }
                    // Review of issue #16: a light's FLUX or INTENSITY of 1e308 made
                    // "inf lm" and "NaN %".
                    if let (true, Some(token)) = (v > crate::scene::MAX_EMISSION, token) {
                        let what = k.spelling();
                        self.error_at(token, &l, too_bright(&what, token.text));
                    }
                    output = Some(if k == Keyword::Intensity {
                        Output::Intensity(v)
                    } else {
                        Output::Flux(v)
                    });
                }
                Keyword::Distribution => {
                    self.pos += 1;
                    // Reported, and the rest of the block still read (QA pass 14 of #16:
                    // a missing IES file hid the COLOUR and AIM errors after it).
                    match self.distribution_line(&line) {
                        Ok(d) => distribution = Some(d),
                        Err(Reported) => bad_distribution = true,
                    }
                }
                Keyword::Colour => {
                    let (read, l) = self.triple_read(Keyword::Colour, "band")?;
                    for (v, token) in read.iter().flatten() {
                        if *v < 0.0 {
                            let msg =
                                format!("COLOUR must not be negative, found \"{}\"", token.text);
                            self.error_at(*token, &l, msg);
                        }
                    }
                    let c = Rgb(read.map(|t| t.map_or(0.0, |t| t.0)));
                    // QA pass 13 of #16: a black light passed, and `check` then said that
                    // nothing in the scene emits light and that the lamp was inside
                    // furniture.
                    if read.iter().all(Option::is_some) && c.0.iter().all(|&v| v == 0.0) {
                        let head = l.head();
                        self.error_at(
                            head,
                            &l,
                            "COLOUR 0 0 0 makes the light emit nothing: COLOUR multiplies its \
                             output in each band (1 1 1 for white); leave the light out to \
                             switch it off",
                        );
                    }
                    colour = Some(c);
                }
                _ => {
                    // Reported, and the rest of the block still read: the light is
                    // dropped at its end.
                    self.unexpected(
                        "POSITION, AIM, INTENSITY, FLUX, DISTRIBUTION, COLOUR or LIGHTEND",
                    );
                    self.pos += 1;
                }
            }
        }
        let (line, column) = begin;
        let Some(position) = position else {
            return Err(self.error(
                line,
                column,
                format!("the light \"{name}\" has no POSITION x y z (where it is, in scene units)"),
            ));
        };
        let Some(distribution) = distribution else {
            if bad_distribution {
                return Err(Reported);
            }
            return Err(self.error(
                line,
                column,
                format!(
                    "the light \"{name}\" has no DISTRIBUTION line: expected ISOTROPIC, COSINE \
                     or IES file.ies"
                ),
            ));
        };
        let light = Luminaire {
            name,
            position,
            aim: aim.unwrap_or(DEFAULT_AIM),
            output: output.unwrap_or(Output::AsTabulated),
            distribution,
            colour: colour.unwrap_or(Rgb::splat(1.0)),
        };
        if self.errors.len() > errors_before {
            // A light with a bad line is dropped; its own check would report the same line
            // again (AIM 0 0 0 as a zero aim).
            return Err(Reported);
        }
        if let Err(e) = light.check() {
            return Err(self.error(line, column, format!("the light \"{}\": {e}", light.name)));
        }
        Ok(light)
    }

    /// The `DISTRIBUTION` line's value (the line is already taken).
    fn distribution_line(&mut self, line: &Line<'a>) -> Step<Distribution> {
        let Some(word) = line.tokens.get(1).copied() else {
            let msg = "expected ISOTROPIC, COSINE or IES file.ies after \"DISTRIBUTION\", \
                       found end of line";
            return Err(self.error(line.number, line.end_column, msg));
        };
        let upper = word.text.to_ascii_uppercase();
        match upper.as_str() {
            "ISOTROPIC" | "COSINE" => {
                self.line_end(line, 2);
                Ok(if upper == "ISOTROPIC" {
                    Distribution::Isotropic
                } else {
                    Distribution::Cosine
                })
            }
            "IES" => self.ies_distribution(line, word),
            _ => {
                let msg = format!(
                    "expected ISOTROPIC, COSINE or IES file.ies after \"DISTRIBUTION\", found \"{}\"",
                    word.text
                );
                Err(self.error_at(word, line, msg))
            }
        }
    }

    /// `DISTRIBUTION IES file.ies`: the rest of the line (trimmed) is the path, relative to
    /// the scene file's folder.
    fn ies_distribution(&mut self, line: &Line<'a>, word: Token<'a>) -> Step<Distribution> {
        // The rest of the line after the word IES: a path may hold spaces.
        let start = line
            .code
            .char_indices()
            .nth(word.column - 1)
            .map_or(line.code.len(), |(b, _)| b + word.text.len());
        let written = line.code.get(start..).unwrap_or("").trim().to_string();
        if written.is_empty() {
            let msg = "expected the IES file's path after \"IES\" (relative to the scene \
                       file), found end of line";
            return Err(self.error(line.number, line.end_column, msg));
        }
        let path = self.folder.join(&written);
        match crate::photometry::ies::IesPhotometry::read(&path) {
            Ok(photometry) => Ok(Distribution::Ies {
                written,
                photometry: std::sync::Arc::new(photometry),
            }),
            Err(e) => {
                let column = line.tokens.get(2).map_or(word.column, |t| t.column);
                // The file is named once, here (QA of issue #16: the IES error's own
                // "file:line: error:" repeated it).
                let msg = match (&e, e.problem()) {
                    (crate::photometry::ies::IesError::Io { source, .. }, _) => format!(
                        "the light's IES file \"{written}\" (relative to the scene file's \
                         folder): cannot read it: {source}"
                    ),
                    (_, Some((ies_line, problem))) => format!(
                        "the light's IES file \"{written}\" (relative to the scene file's \
                         folder) cannot be used: its line {ies_line}: {problem}"
                    ),
                    (_, None) => format!(
                        "the light's IES file \"{written}\" (relative to the scene file's \
                         folder) cannot be used: {e}"
                    ),
                };
                Err(self.error(line.number, column, msg))
            }
        }
    }

    // ----- boxes -----

    /// A `BOXBEGIN` block as its six checked faces.
    fn box_block(&mut self) -> Option<Vec<Surface>> {
        let (head, facing, shape) = self.block(Keyword::BoxBegin, Keyword::BoxEnd, |p| {
            let name = p.name_line()?;
            let facing = p.facing()?;
            let head = p.colours(name)?;
            let shape = p.box_shape()?;
            Ok((head, facing, shape))
        })?;
        let (base, height, line, column) = match shape {
            BoxShape::Aligned {
                origin,
                size,
                line,
                column,
            } => (shape::axis_aligned_base(origin, size), size.y, line, column),
            BoxShape::Prism {
                mut base,
                height,
                line,
                column,
            } => {
                self.check_polygon(&mut base)?;
                let quad = [0, 1, 2, 3].map(|i| base.vertices.get(i).copied().unwrap_or_default());
                (quad, height, line, column)
            }
        };
        self.block_line = (line, column);
        // Each face passes the polygon checks, as a patch would: a box too thin for its
        // position or its other sizes, too small, or too large is refused here, not met by
        // the mesher as a face of zero area.
        let faces = shape::box_faces(&base, height, facing);
        for (suffix, face) in shape::FACE_NAMES.iter().zip(&faces) {
            if let Err(e) = geometry::validate_polygon(face) {
                let name = format!("{}.{suffix}", head.name);
                self.error(line, column, polygon::box_face_message(&name, &e));
                return None;
            }
        }
        let mut surfaces: Vec<Surface> = shape::FACE_NAMES
            .iter()
            .zip(faces)
            .map(|(suffix, vertices)| Surface {
                name: format!("{}.{suffix}", head.name),
                emission: head.emission,
                reflectance: head.reflectance,
                vertices,
                photometry: head.photometry,
            })
            .collect();
        Self::spread_flux(&head, &mut surfaces);
        Some(surfaces)
    }

    /// A `SPHEREBEGIN`, `CYLINDERBEGIN` or `CONEBEGIN` block as its checked faces.
    fn round_block(&mut self, kind: Round) -> Option<Vec<Surface>> {
        let (begin, end) = kind.keywords();
        let (head, facing, shape) = self.block(begin, end, |p| {
            let name = p.name_line()?;
            let facing = p.facing()?;
            let head = p.colours(name)?;
            let shape = p.round_shape(kind)?;
            Ok((head, facing, shape))
        })?;
        self.block_line = (shape.line, shape.column);
        let RoundShape {
            centre,
            radius,
            height,
            resolution: n,
            ..
        } = shape;
        let (faces, names): (Vec<Vec<DVec3>>, Vec<String>) = match kind {
            Round::Sphere => {
                let faces = shape::sphere_faces(centre, radius, n, facing);
                let names = (0..faces.len()).map(|k| k.to_string()).collect();
                (faces, names)
            }
            Round::Cylinder => {
                let faces = shape::cylinder_faces(centre, radius, height, n, facing);
                let names = ["base".to_string(), "top".to_string()]
                    .into_iter()
                    .chain((0..n).map(|k| format!("side{k}")))
                    .collect();
                (faces, names)
            }
            Round::Cone => {
                let faces = shape::cone_faces(centre, radius, height, n, facing);
                let names = std::iter::once("base".to_string())
                    .chain((0..n).map(|k| format!("side{k}")))
                    .collect();
                (faces, names)
            }
        };
        let mut surfaces = Vec::with_capacity(faces.len());
        for (suffix, vertices) in names.into_iter().zip(faces) {
            let name = format!("{}.{suffix}", head.name);
            if let Err(e) = geometry::validate_polygon(&vertices) {
                let msg = format!(
                    "the {}'s face \"{name}\" is not a usable polygon: {e} (the {} is too small \
                     or too thin for its position, or too large; rescale the scene or change \
                     RESOLUTION)",
                    kind.name(),
                    kind.name()
                );
                self.error(shape.line, shape.column, msg);
                return None;
            }
            surfaces.push(Surface {
                name,
                emission: head.emission,
                reflectance: head.reflectance,
                vertices,
                photometry: head.photometry,
            });
        }
        Self::spread_flux(&head, &mut surfaces);
        Some(surfaces)
    }

    /// `CENTER`, `RADIUS`, `HEIGHT` (not for a sphere) and an optional `RESOLUTION`.
    fn round_shape(&mut self, kind: Round) -> Step<RoundShape> {
        let (read, centre_line) = self.triple_read(Keyword::Center, "coordinate")?;
        let mut centre = [0.0; 3];
        for (i, found) in read.iter().enumerate() {
            let Some((v, token)) = *found else { break };
            centre[i] = v;
            self.check_range(v, token, &centre_line);
        }
        let (radius, token, line) = self.value(Keyword::Radius)?;
        if radius <= 0.0 {
            let msg = format!("RADIUS must be greater than 0, found \"{}\"", token.text);
            self.error_at(token, &line, msg);
        }
        let (shape_line, shape_column) = (line.number, line.head().column);
        let mut height = 0.0;
        if kind != Round::Sphere {
            let (h, token, line) = self.value(Keyword::Height)?;
            if h <= 0.0 {
                let msg = format!("HEIGHT must be greater than 0, found \"{}\"", token.text);
                self.error_at(token, &line, msg);
            }
            height = h;
        }
        let mut resolution = shape::DEFAULT_RESOLUTION;
        self.skip_unknown_before("RESOLUTION or the block's end", |k| {
            k == Keyword::Resolution
        });
        if self.current_keyword() == Some(Keyword::Resolution) {
            let (v, token, line) = self.value(Keyword::Resolution)?;
            match Self::whole(v) {
                Some(n) if (3..=u64::from(shape::MAX_RESOLUTION)).contains(&n) => {
                    resolution = n as u32;
                }
                _ => {
                    let msg = format!(
                        "RESOLUTION must be a whole number from 3 to {} (the segments round the \
                         axis), found \"{}\"",
                        shape::MAX_RESOLUTION,
                        token.text
                    );
                    self.error_at(token, &line, msg);
                }
            }
        }
        Ok(RoundShape {
            centre: centre.into(),
            radius,
            height,
            resolution,
            line: shape_line,
            column: shape_column,
        })
    }

    /// `FACING OUT` or `FACING IN`.
    fn facing(&mut self) -> Step<Facing> {
        let line = self.expect(Keyword::Facing)?;
        let word = line.tokens.get(1).copied();
        let facing = match word.map(|t| t.text.to_ascii_uppercase()) {
            Some(w) if w == "OUT" => Facing::Out,
            Some(w) if w == "IN" => Facing::In,
            _ => {
                let (column, found) = word.map_or((line.end_column, "end of line".into()), |t| {
                    (t.column, format!("\"{}\"", t.text))
                });
                let msg = format!("expected OUT or IN after \"FACING\", found {found}");
                return Err(self.error(line.number, column, msg));
            }
        };
        self.line_end(&line, 2);
        Ok(facing)
    }

    /// `ORIGIN` + `SIZE`, or `VERTICES 4` + `VERTEX0..3` + `HEIGHT`.
    fn box_shape(&mut self) -> Step<BoxShape> {
        self.skip_unknown_before("ORIGIN or VERTICES", |k| {
            matches!(k, Keyword::Vertices | Keyword::Origin)
        });
        if self.current_keyword() == Some(Keyword::Vertices) {
            return self.prism_shape();
        }
        if self.current_keyword() != Some(Keyword::Origin) {
            return Err(self.unexpected("ORIGIN or VERTICES"));
        }
        let (origin_read, origin_line) = self.triple_read(Keyword::Origin, "coordinate")?;
        let mut origin = [0.0; 3];
        for (i, found) in origin_read.iter().enumerate() {
            let Some((v, token)) = *found else { break };
            origin[i] = v;
            self.check_range(v, token, &origin_line);
        }
        let (read, line) = self.triple_read(Keyword::Size, "size")?;
        // Only the numbers that were read are checked: a missing or unreadable one has been
        // reported already, at its own column.
        let mut size = [0.0; 3];
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let Some((v, token)) = read[i] else { break };
            size[i] = v;
            if v <= 0.0 {
                let msg = format!(
                    "box sizes must be greater than 0, found \"{}\" for {axis}",
                    token.text
                );
                self.error_at(token, &line, msg);
            } else if (origin[i] + v).abs() > geometry::MAX_COORDINATE {
                let msg = format!(
                    "the box reaches {axis} = {:e} (ORIGIN plus SIZE), beyond the largest \
                     coordinate the program supports ({:e} in magnitude); rescale the scene \
                     (for instance to metres)",
                    origin[i] + v,
                    geometry::MAX_COORDINATE
                );
                self.error_at(token, &line, msg);
            }
        }
        Ok(BoxShape::Aligned {
            origin: origin.into(),
            size: size.into(),
            line: line.number,
            column: line.head().column,
        })
    }

    /// The base quad and `HEIGHT` of a box given as one face plus a height.
    fn prism_shape(&mut self) -> Step<BoxShape> {
        let (v, token, line) = self.value(Keyword::Vertices)?;
        if v != 4.0 {
            let msg = format!(
                "a box's base needs exactly 4 vertices after \"VERTICES\", found \"{}\"",
                token.text
            );
            return Err(self.error_at(token, &line, msg));
        }
        let base = self.vertex_lines(4)?;
        let (height, token, line) = self.value(Keyword::Height)?;
        if height <= 0.0 {
            let msg = format!("HEIGHT must be greater than 0, found \"{}\"", token.text);
            self.error_at(token, &line, msg);
        }
        Ok(BoxShape::Prism {
            base,
            height,
            line: line.number,
            column: line.head().column,
        })
    }
}

#[cfg(test)]
#[path = "read_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "round_tests.rs"]
mod round_tests;

#[cfg(test)]
#[path = "photometric_tests.rs"]
mod photometric_tests;

/// The error for an emission, LUMINANCE or FLUX (`what`) given as `text`, past
/// [`crate::scene::MAX_EMISSION`].
fn too_bright(what: &str, text: &str) -> String {
    format!(
        "{what} \"{text}\" is above the largest the program supports ({:e}): the power \
         summed over the scene would overflow",
        crate::scene::MAX_EMISSION
    )
}
