//! VRML97 (`.wrl`, the classic UTF-8 encoding), the format the paper weighed (section 3.2).
//!
//! Written here by hand for the subset that makes geometry, not with the `vrml97` crate
//! (0.1, a port of X_ITE's whole parser): from reading its source, its recursive-descent
//! parser has no limit on nesting (a file of a few hundred thousand nested `Group {
//! children [` overflows the stack and aborts the process, which no error can report), it
//! gunzips compressed files without a size limit (a small file can ask for gigabytes), and
//! its errors do not carry what this program's messages name (the file, line and
//! element). The subset below is small; its parser is bounded in depth and its expansion
//! of `USE` in faces.
//!
//! What is read:
//!
//! * `Transform` (translation, rotation, scale, scaleOrientation, center: `T C R SR S -SR
//!   -C`), `Group`, `Anchor`, `Billboard` and `Collision` (their children, untransformed),
//!   `Switch` (the `whichChoice` child), `LOD` (the first, finest `level`);
//! * `DEF` and `USE` (a node used again is placed again; a `USE` inside the definition it
//!   names, which would make a cycle, is refused, as is a name never defined);
//! * `Shape` with `Appearance` and `Material`: `diffuseColor` is the reflectance (default
//!   0.8; 1 or more is taken as [`MAX_REFLECTANCE`] with a warning), `emissiveColor` the
//!   emission (exitance in the scene's emission units, scale 1: `emissiveColor 1 1 1`
//!   emits 1 per unit area; values above VRML97's range of 0 to 1 are accepted, for lights
//!   brighter than that). A `Shape` without a `Material` gets `Material`'s defaults;
//! * geometry: `IndexedFaceSet` (`coord`, `coordIndex` faces separated by -1, `ccw`), and
//!   the primitives `Box`, `Sphere`, `Cone` and `Cylinder` (with their `side`, `top` and
//!   `bottom` flags), tessellated as the scene format's `BOX`, `SPHERE`, `CYLINDER` and
//!   `CONE` are (fronts facing outwards; [`DEFAULT_SEGMENTS`] round the axis, a sphere in
//!   half as many bands of quads with triangles at the poles, caps one convex polygon);
//! * the first `Viewpoint` (position, orientation, fieldOfView) as the scene's camera.
//!
//! Each `Shape` is one object, named after its `DEF` name, or its nearest `DEF`-named
//! ancestor's, or `Shape N`. Unit: metres (VRML97's unit), times
//! [`super::ImportOptions::scale`].
//!
//! Ignored (with a warning counting them): other geometry (`IndexedLineSet`, `PointSet`,
//! `ElevationGrid`, `Extrusion`, `Text`), `Inline`, and instances of `PROTO`s (whose
//! declarations are skipped); silently: lights, sensors, interpolators, `ROUTE`s,
//! `Script`s, textures, `solid` (every surface is one-sided: its front is the `ccw` side),
//! normals, colours per vertex, `convex` (faces are checked and split anyway). Files
//! compressed with gzip are refused with a message saying to decompress them.

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DQuat, DVec3};

use super::tessellate;
use super::{
    default_settings, scaled_unit, FaceSoup, Format, ImportError, ImportOptions, ImportWarning,
    Imported, SoupFace, SoupMaterial,
};
use crate::io::scene_file::SceneFile;
use crate::light::Rgb;
use crate::scene::CameraHint;

/// The reflectance a `diffuseColor` of 1 or more becomes.
pub const MAX_REFLECTANCE: f64 = 0.99;

/// Segments round the axis of a tessellated `Sphere`, `Cone` or `Cylinder`: the scene
/// format's default `RESOLUTION`, 16 (a sphere of 16 x 8 faces, 3.2% short of its area).
pub const DEFAULT_SEGMENTS: u32 = crate::scene::shape::DEFAULT_RESOLUTION;

/// How deeply nodes may nest in the file.
pub const MAX_DEPTH: usize = 200;

/// The most faces the scene may have once every `USE` is placed.
pub const MAX_FACES: usize = 2_000_000;

/// The most nodes visited once every `USE` is followed: a chain of groups each using the
/// last twice makes 2^k visits from a file of k lines, with no face among them.
pub const MAX_VISITS: usize = 1_000_000;

/// Reads the VRML97 file at `path`.
pub fn read(path: &Path, options: &ImportOptions) -> Result<Imported, ImportError> {
    let file = path.display().to_string();
    crate::io::note_input(path);
    let bytes = std::fs::read(path).map_err(|e| ImportError::Io {
        what: "the scene file",
        file: file.clone(),
        message: e.to_string(),
    })?;
    parse(&file, &bytes, options)
}

/// Reads VRML97 from `bytes` (named `file` in messages).
pub fn parse(file: &str, bytes: &[u8], options: &ImportOptions) -> Result<Imported, ImportError> {
    parse_with(file, bytes, options, DEFAULT_SEGMENTS)
}

/// [`parse`] with `segments` round the axis of each round primitive (at least 3).
pub fn parse_with(
    file: &str,
    bytes: &[u8],
    options: &ImportOptions,
    segments: u32,
) -> Result<Imported, ImportError> {
    let syntax = |line: usize, message: String| ImportError::Syntax {
        file: file.to_string(),
        line,
        message,
    };
    if bytes.starts_with(&[0x1f, 0x8b]) {
        return Err(syntax(
            0,
            "the file is compressed with gzip; decompress it first (gunzip, or rename it \
             .wrl.gz and run gunzip)"
                .into(),
        ));
    }
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        syntax(line, "the file is not UTF-8 text (VRML97 is)".into())
    })?;
    let first = text.lines().next().unwrap_or("");
    if !first.starts_with("#VRML V2.0") {
        let found = if first.starts_with("#VRML V1.0") {
            "a VRML 1.0 file, which this reader does not read".to_string()
        } else {
            format!("\"{}\"", first.chars().take(40).collect::<String>())
        };
        return Err(syntax(
            1,
            format!("expected the VRML97 header \"#VRML V2.0 utf8\", found {found}"),
        ));
    }
    let mut parser = Parser {
        file: file.to_string(),
        lex: Lexer::new(text),
        nodes: Vec::new(),
        defs: HashMap::new(),
        depth: 0,
    };
    let roots = parser.statements(None)?;
    let mut builder = Builder {
        file: file.to_string(),
        nodes: &parser.nodes,
        soup: FaceSoup {
            file: file.to_string(),
            ..FaceSoup::default()
        },
        materials: HashMap::new(),
        ignored: Vec::new(),
        camera: None,
        segments: segments.max(3),
        shapes: 0,
        bright: Vec::new(),
        visits: 0,
    };
    for &r in &roots {
        builder.visit(r, DMat4::IDENTITY, None, 0)?;
    }
    let camera = builder.camera;
    let mut warnings = builder.warnings();
    let soup = builder.soup;
    let (mut scene, mut more) = soup.to_scene(options.scale)?;
    warnings.append(&mut more);
    scene.camera = camera.map(|c| CameraHint {
        eye: c.eye * options.scale,
        look_at: c.look_at * options.scale,
        ..c
    });
    let settings = options.settings.unwrap_or_else(|| default_settings(&scene));
    Ok(Imported {
        file: SceneFile { settings, scene },
        warnings,
        unit: scaled_unit("metres (VRML97's unit)", options.scale),
        format: Format::Vrml,
    })
}

// ---- Lexer

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Open,
    Close,
    LBracket,
    RBracket,
    Str,
    Num(f64),
    Ident(String),
    End,
}

impl Tok {
    fn describe(&self) -> String {
        match self {
            Tok::Open => "'{'".into(),
            Tok::Close => "'}'".into(),
            Tok::LBracket => "'['".into(),
            Tok::RBracket => "']'".into(),
            Tok::Str => "a string".into(),
            Tok::Num(x) => format!("the number {x}"),
            Tok::Ident(s) => format!("\"{s}\""),
            Tok::End => "the end of the file".into(),
        }
    }
}

struct Lexer<'a> {
    text: &'a [u8],
    at: usize,
    line: usize,
    peeked: Option<(Tok, usize)>,
}

/// Characters that end an identifier or number (besides white space and controls).
fn is_delimiter(c: u8) -> bool {
    matches!(
        c,
        b'"' | b'#' | b'\'' | b',' | b'[' | b'\\' | b']' | b'{' | b'}'
    ) || c <= b' '
        || c == 0x7f
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str) -> Self {
        Lexer {
            text: text.as_bytes(),
            at: 0,
            line: 1,
            peeked: None,
        }
    }

    /// The next token and its line, or a message (with its line) for a bad one.
    fn next(&mut self) -> Result<(Tok, usize), (usize, String)> {
        if let Some(p) = self.peeked.take() {
            return Ok(p);
        }
        self.scan()
    }

    fn peek(&mut self) -> Result<&(Tok, usize), (usize, String)> {
        if self.peeked.is_none() {
            let t = self.scan()?;
            self.peeked = Some(t);
        }
        Ok(self.peeked.as_ref().expect("just set"))
    }

    fn scan(&mut self) -> Result<(Tok, usize), (usize, String)> {
        let t = self.text;
        loop {
            match t.get(self.at) {
                None => return Ok((Tok::End, self.line)),
                Some(b'\n') => {
                    self.line += 1;
                    self.at += 1;
                }
                Some(b'#') => {
                    while t.get(self.at).is_some_and(|&c| c != b'\n') {
                        self.at += 1;
                    }
                }
                Some(&c) if c <= b' ' || c == b',' => self.at += 1,
                Some(_) => break,
            }
        }
        let line = self.line;
        let c = t[self.at];
        let single = match c {
            b'{' => Some(Tok::Open),
            b'}' => Some(Tok::Close),
            b'[' => Some(Tok::LBracket),
            b']' => Some(Tok::RBracket),
            _ => None,
        };
        if let Some(tok) = single {
            self.at += 1;
            return Ok((tok, line));
        }
        if c == b'"' {
            self.at += 1;
            loop {
                match t.get(self.at) {
                    None => return Err((line, "a string that is never closed (\")".into())),
                    Some(b'\\') => self.at += 2,
                    Some(b'"') => {
                        self.at += 1;
                        return Ok((Tok::Str, line));
                    }
                    Some(b'\n') => {
                        self.line += 1;
                        self.at += 1;
                    }
                    Some(_) => self.at += 1,
                }
            }
        }
        let start = self.at;
        while t.get(self.at).is_some_and(|&c| !is_delimiter(c)) {
            self.at += 1;
        }
        if self.at == start {
            self.at += 1;
            return Err((line, format!("unexpected character '{}'", char::from(c))));
        }
        let word = std::str::from_utf8(&t[start..self.at]).unwrap_or("?");
        if c.is_ascii_digit() || matches!(c, b'+' | b'-' | b'.') {
            let value = if let Some(hex) = word.strip_prefix("0x").or(word.strip_prefix("0X")) {
                i64::from_str_radix(hex, 16).ok().map(|v| v as f64)
            } else {
                word.parse::<f64>().ok()
            };
            return match value {
                Some(v) if v.is_finite() => Ok((Tok::Num(v), line)),
                Some(v) => Err((line, format!("\"{word}\" is not a finite number ({v})"))),
                None => Err((line, format!("\"{word}\" is not a number"))),
            };
        }
        // NaN and infinities spelt as words (QA of issue #16: `1 0 nan` read as a node type
        // named "nan", and the error spoke of a missing '{'). No VRML identifier is meant so.
        if ["nan", "inf", "infinity"]
            .iter()
            .any(|w| word.eq_ignore_ascii_case(w))
        {
            return Err((line, format!("\"{word}\" is not a finite number")));
        }
        Ok((Tok::Ident(word.to_string()), line))
    }
}

// ---- Parser: nodes and their fields, untyped (a field's value is whatever follows it).

struct Node {
    kind: String,
    line: usize,
    def: Option<String>,
    fields: Vec<Field>,
}

#[derive(Default)]
struct Field {
    name: String,
    line: usize,
    nums: Vec<f64>,
    bools: Vec<bool>,
    nodes: Vec<usize>,
}

impl Node {
    fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().rev().find(|f| f.name == name)
    }
}

struct Parser<'a> {
    file: String,
    lex: Lexer<'a>,
    nodes: Vec<Node>,
    /// Name -> node; `None` while the node it names is being read.
    defs: HashMap<String, Option<usize>>,
    depth: usize,
}

impl Parser<'_> {
    fn error(&self, line: usize, message: String) -> ImportError {
        ImportError::Syntax {
            file: self.file.clone(),
            line,
            message,
        }
    }

    fn next(&mut self) -> Result<(Tok, usize), ImportError> {
        self.lex.next().map_err(|(l, m)| self.error(l, m))
    }

    fn peek(&mut self) -> Result<(Tok, usize), ImportError> {
        match self.lex.peek() {
            Ok(t) => Ok(t.clone()),
            Err((l, m)) => Err(self.error(l, m)),
        }
    }

    /// Statements up to `end` (or the end of the file when `None`): the nodes among them.
    fn statements(&mut self, end: Option<Tok>) -> Result<Vec<usize>, ImportError> {
        let mut out = Vec::new();
        loop {
            let (tok, line) = self.peek()?;
            if Some(&tok) == end.as_ref() {
                self.next()?;
                return Ok(out);
            }
            match tok {
                Tok::End => {
                    return match end {
                        None => Ok(out),
                        Some(e) => Err(self.error(
                            line,
                            format!("the file ends before the closing {}", e.describe()),
                        )),
                    }
                }
                Tok::Ident(ref w) if self.skip_statement(w)? => {}
                Tok::Ident(_) => {
                    if let Some(n) = self.node_value()? {
                        out.push(n);
                    }
                }
                other => {
                    return Err(
                        self.error(line, format!("expected a node, found {}", other.describe()))
                    )
                }
            }
        }
    }

    /// Skips `PROTO`, `EXTERNPROTO` and `ROUTE` statements; false for anything else.
    fn skip_statement(&mut self, word: &str) -> Result<bool, ImportError> {
        match word {
            "PROTO" => {
                self.next()?;
                self.next()?; // its name
                self.skip_balanced(Tok::LBracket, Tok::RBracket)?;
                self.skip_balanced(Tok::Open, Tok::Close)?;
            }
            "EXTERNPROTO" => {
                self.next()?;
                self.next()?;
                self.skip_balanced(Tok::LBracket, Tok::RBracket)?;
                if self.peek()?.0 == Tok::LBracket {
                    self.skip_balanced(Tok::LBracket, Tok::RBracket)?;
                } else {
                    self.next()?;
                }
            }
            "ROUTE" => {
                for _ in 0..4 {
                    self.next()?; // from.event TO to.event
                }
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// Skips `open` ... `close`, nesting counted.
    fn skip_balanced(&mut self, open: Tok, close: Tok) -> Result<(), ImportError> {
        let (t, line) = self.next()?;
        if t != open {
            return Err(self.error(
                line,
                format!("expected {}, found {}", open.describe(), t.describe()),
            ));
        }
        let mut depth = 1usize;
        while depth > 0 {
            let (t, l) = self.next()?;
            match t {
                Tok::End => {
                    return Err(self.error(
                        l,
                        format!(
                            "the file ends before the {} that closes the {} of line {line}",
                            close.describe(),
                            open.describe()
                        ),
                    ))
                }
                t if t == open => depth += 1,
                t if t == close => depth -= 1,
                _ => {}
            }
        }
        Ok(())
    }

    /// A node where a value is expected: `DEF name Type { ... }`, `USE name`, `NULL` (no
    /// node), or `Type { ... }`.
    fn node_value(&mut self) -> Result<Option<usize>, ImportError> {
        let (tok, line) = self.next()?;
        let Tok::Ident(word) = tok else {
            return Err(self.error(line, format!("expected a node, found {}", tok.describe())));
        };
        match word.as_str() {
            "NULL" => Ok(None),
            "USE" => {
                let (t, l) = self.next()?;
                let Tok::Ident(name) = t else {
                    return Err(self.error(
                        l,
                        format!("expected a name after USE, found {}", t.describe()),
                    ));
                };
                match self.defs.get(&name) {
                    Some(Some(n)) => Ok(Some(*n)),
                    Some(None) => Err(self.error(
                        l,
                        format!(
                            "USE {name} inside the definition of {name} itself: the node would \
                             contain itself (a cycle)"
                        ),
                    )),
                    None => Err(self.error(
                        l,
                        format!("USE {name}: no node named {name} is defined (DEF) before it"),
                    )),
                }
            }
            "DEF" => {
                let (t, l) = self.next()?;
                let Tok::Ident(name) = t else {
                    return Err(self.error(
                        l,
                        format!("expected a name after DEF, found {}", t.describe()),
                    ));
                };
                let before = self.defs.insert(name.clone(), None);
                let (t, l2) = self.next()?;
                let Tok::Ident(kind) = t else {
                    return Err(self.error(
                        l2,
                        format!(
                            "expected a node type after DEF {name}, found {}",
                            t.describe()
                        ),
                    ));
                };
                let n = self.node_body(kind, l2, Some(name.clone()))?;
                let _ = before;
                self.defs.insert(name, Some(n));
                Ok(Some(n))
            }
            _ => self.node_body(word, line, None).map(Some),
        }
    }

    /// `{ fields }` of a node of type `kind`.
    fn node_body(
        &mut self,
        kind: String,
        line: usize,
        def: Option<String>,
    ) -> Result<usize, ImportError> {
        let (t, l) = self.next()?;
        if t != Tok::Open {
            return Err(self.error(
                l,
                format!(
                    "expected '{{' after the node type {kind}, found {}",
                    t.describe()
                ),
            ));
        }
        if kind == "Script" {
            // Its interface declarations are not fields; nothing in it makes geometry.
            self.skip_rest(line)?;
            self.nodes.push(Node {
                kind,
                line,
                def,
                fields: Vec::new(),
            });
            return Ok(self.nodes.len() - 1);
        }
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error(
                line,
                format!("nodes nested more than {MAX_DEPTH} deep (the {kind} here)"),
            ));
        }
        let mut fields = Vec::new();
        loop {
            let (t, fl) = self.next()?;
            match t {
                Tok::Close => break,
                Tok::Ident(w) if matches!(w.as_str(), "ROUTE" | "PROTO" | "EXTERNPROTO") => {
                    self.lex.peeked = Some((Tok::Ident(w.clone()), fl));
                    self.skip_statement(&w)?;
                }
                Tok::Ident(name) => {
                    let f = self.field_value(name, fl)?;
                    fields.push(f);
                }
                Tok::End => {
                    return Err(self.error(
                        fl,
                        format!(
                        "the file ends inside the {kind} node of line {line} (a '}}' is missing)"
                    ),
                    ))
                }
                other => {
                    return Err(self.error(
                        fl,
                        format!(
                        "expected a field name or '}}' in the {kind} node of line {line}, found {}",
                        other.describe()
                    ),
                    ))
                }
            }
        }
        self.depth -= 1;
        self.nodes.push(Node {
            kind,
            line,
            def,
            fields,
        });
        Ok(self.nodes.len() - 1)
    }

    /// Skips to the '}' that closes a body already opened.
    fn skip_rest(&mut self, line: usize) -> Result<(), ImportError> {
        let mut depth = 1usize;
        while depth > 0 {
            let (t, l) = self.next()?;
            match t {
                Tok::Open => depth += 1,
                Tok::Close => depth -= 1,
                Tok::End => {
                    return Err(
                        self.error(l, format!("the file ends inside the node of line {line}"))
                    )
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// A field's value: numbers, a string, TRUE/FALSE, a node, `IS name`, or a `[ ]` list
    /// of any of them.
    fn field_value(&mut self, name: String, line: usize) -> Result<Field, ImportError> {
        let mut f = Field {
            name,
            line,
            ..Field::default()
        };
        let (t, l) = self.peek()?;
        match t {
            Tok::LBracket => {
                self.next()?;
                loop {
                    let (t, l) = self.peek()?;
                    match t {
                        Tok::RBracket => {
                            self.next()?;
                            break;
                        }
                        Tok::End => {
                            return Err(self.error(
                                l,
                                format!("the file ends inside the list of the field {} of line {line} (a ']' is missing)", f.name),
                            ))
                        }
                        _ => self.single_value(&mut f)?,
                    }
                }
            }
            Tok::Num(_) => {
                while let (Tok::Num(x), _) = self.peek()? {
                    f.nums.push(x);
                    self.next()?;
                }
            }
            Tok::End | Tok::Close | Tok::RBracket | Tok::Open => {
                return Err(self.error(
                    l,
                    format!(
                        "expected a value for the field {}, found {}",
                        f.name,
                        t.describe()
                    ),
                ))
            }
            _ => self.single_value(&mut f)?,
        }
        Ok(f)
    }

    fn single_value(&mut self, f: &mut Field) -> Result<(), ImportError> {
        let (t, l) = self.peek()?;
        match t {
            Tok::Num(x) => {
                self.next()?;
                f.nums.push(x);
            }
            Tok::Str => {
                self.next()?;
            }
            Tok::Ident(ref w) if w == "TRUE" || w == "FALSE" => {
                self.next()?;
                f.bools.push(w == "TRUE");
            }
            Tok::Ident(ref w) if w == "IS" => {
                self.next()?;
                self.next()?;
            }
            Tok::Ident(_) => {
                if let Some(n) = self.node_value()? {
                    f.nodes.push(n);
                }
            }
            other => {
                self.next()?;
                return Err(self.error(
                    l,
                    format!(
                        "expected a value for the field {}, found {}",
                        f.name,
                        other.describe()
                    ),
                ));
            }
        }
        Ok(())
    }
}

// ---- From the nodes to the face soup.

struct Builder<'a> {
    file: String,
    nodes: &'a [Node],
    soup: FaceSoup,
    /// (reflectance, emission) bits -> material index.
    materials: HashMap<[u64; 6], u32>,
    /// Node kinds left out, with counts.
    ignored: Vec<(String, usize)>,
    camera: Option<CameraHint>,
    segments: u32,
    shapes: usize,
    /// Materials whose diffuseColor was 1 or more (line).
    bright: Vec<usize>,
    /// Nodes visited so far.
    visits: usize,
}

impl Builder<'_> {
    fn error(&self, line: usize, message: String) -> ImportError {
        ImportError::Syntax {
            file: self.file.clone(),
            line,
            message,
        }
    }

    fn ignore(&mut self, kind: &str) {
        match self.ignored.iter_mut().find(|(k, _)| k == kind) {
            Some((_, n)) => *n += 1,
            None => self.ignored.push((kind.to_string(), 1)),
        }
    }

    fn warnings(&self) -> Vec<ImportWarning> {
        let mut out = Vec::new();
        if !self.ignored.is_empty() {
            let list: Vec<String> = self
                .ignored
                .iter()
                .map(|(k, n)| format!("{n} {k}"))
                .collect();
            out.push(ImportWarning {
                file: self.file.clone(),
                line: 0,
                message: format!("left out (no surfaces made of them): {}", list.join(", ")),
            });
        }
        if let Some(&line) = self.bright.first() {
            // Counted by where they are written: a Material used again (USE) is one
            // (QA of issue #16: "2 Materials" for one used twice).
            let written: std::collections::BTreeSet<usize> = self.bright.iter().copied().collect();
            out.push(ImportWarning {
                file: self.file.clone(),
                line,
                message: format!(
                    "{} Material{} with a diffuseColor of 1 or more taken as reflectance {MAX_REFLECTANCE} (a surface cannot reflect all the light it receives)",
                    written.len(),
                    if written.len() == 1 { "" } else { "s" }
                ),
            });
        }
        out
    }

    /// Numbers of a field, checked to be `n` (or a default when absent).
    fn vec<const N: usize>(
        &self,
        node: &Node,
        name: &str,
        default: [f64; N],
    ) -> Result<[f64; N], ImportError> {
        match node.field(name) {
            None => Ok(default),
            Some(f) if f.nums.len() == N => {
                let mut out = [0.0; N];
                out.copy_from_slice(&f.nums);
                Ok(out)
            }
            Some(f) => Err(self.error(
                f.line,
                format!(
                    "{}.{name} needs {N} number{}, found {}",
                    node.kind,
                    if N == 1 { "" } else { "s" },
                    f.nums.len()
                ),
            )),
        }
    }

    fn flag(&self, node: &Node, name: &str, default: bool) -> bool {
        node.field(name)
            .and_then(|f| f.bools.first().copied())
            .unwrap_or(default)
    }

    fn rotation(&self, node: &Node, name: &str, default: [f64; 4]) -> Result<DQuat, ImportError> {
        let [x, y, z, angle] = self.vec(node, name, default)?;
        let axis = DVec3::new(x, y, z);
        if angle == 0.0 {
            return Ok(DQuat::IDENTITY);
        }
        let len = axis.length();
        if !(len > 0.0 && len.is_finite()) {
            let line = node.field(name).map_or(node.line, |f| f.line);
            return Err(self.error(
                line,
                format!(
                    "{}.{name}: the rotation axis ({x} {y} {z}) has no direction",
                    node.kind
                ),
            ));
        }
        Ok(DQuat::from_axis_angle(axis / len, angle))
    }

    /// A Transform's matrix: T C R SR S -SR -C.
    fn transform(&self, node: &Node) -> Result<DMat4, ImportError> {
        let t = DVec3::from(self.vec(node, "translation", [0.0; 3])?);
        let c = DVec3::from(self.vec(node, "center", [0.0; 3])?);
        let s = DVec3::from(self.vec(node, "scale", [1.0; 3])?);
        let r = self.rotation(node, "rotation", [0.0, 0.0, 1.0, 0.0])?;
        let sr = self.rotation(node, "scaleOrientation", [0.0, 0.0, 1.0, 0.0])?;
        Ok(DMat4::from_translation(t + c)
            * DMat4::from_quat(r)
            * DMat4::from_quat(sr)
            * DMat4::from_scale(s)
            * DMat4::from_quat(sr.inverse())
            * DMat4::from_translation(-c))
    }

    fn children(&self, node: &Node, field: &str) -> Vec<usize> {
        node.field(field).map_or_else(Vec::new, |f| f.nodes.clone())
    }

    fn visit(
        &mut self,
        id: usize,
        m: DMat4,
        name: Option<&str>,
        depth: usize,
    ) -> Result<(), ImportError> {
        let node = &self.nodes[id];
        self.visits += 1;
        if self.visits > MAX_VISITS {
            return Err(self.error(
                node.line,
                format!(
                    "more than {MAX_VISITS} nodes to visit once every USE is followed (USE \
                     nested in USE multiplies; the {} here)",
                    node.kind
                ),
            ));
        }
        if depth > MAX_DEPTH {
            return Err(self.error(
                node.line,
                format!(
                    "nodes nested more than {MAX_DEPTH} deep once USE is followed (the {} here)",
                    node.kind
                ),
            ));
        }
        let name = node.def.as_deref().or(name);
        match node.kind.as_str() {
            "Transform" => {
                let local = self.transform(node)?;
                let m = m * local;
                if !m.is_finite() {
                    return Err(self.error(
                        node.line,
                        "the Transform's matrix is not finite (a scale or translation too large)"
                            .into(),
                    ));
                }
                for c in self.children(node, "children") {
                    self.visit(c, m, name, depth + 1)?;
                }
            }
            "Group" | "Anchor" | "Billboard" | "Collision" => {
                for c in self.children(node, "children") {
                    self.visit(c, m, name, depth + 1)?;
                }
            }
            "Switch" => {
                let which = self.vec(node, "whichChoice", [-1.0])?[0];
                let choice = self.children(node, "choice");
                if which >= 0.0 {
                    if let Some(&c) = choice.get(which as usize) {
                        self.visit(c, m, name, depth + 1)?;
                    }
                }
            }
            "LOD" => {
                if let Some(&c) = self.children(node, "level").first() {
                    self.visit(c, m, name, depth + 1)?;
                }
            }
            "Shape" => self.shape(id, m, name)?,
            "Viewpoint" => {
                if self.camera.is_none() {
                    let p = DVec3::from(self.vec(node, "position", [0.0, 0.0, 10.0])?);
                    let q = self.rotation(node, "orientation", [0.0, 0.0, 1.0, 0.0])?;
                    let fov = self.vec(node, "fieldOfView", [std::f64::consts::FRAC_PI_4])?[0];
                    let eye = m.transform_point3(p);
                    let look = m.transform_vector3(q * DVec3::NEG_Z);
                    let up = m.transform_vector3(q * DVec3::Y);
                    if eye.is_finite() && look.length() > 0.0 && up.length() > 0.0 {
                        self.camera = Some(CameraHint {
                            eye,
                            look_at: eye + look.normalize(),
                            up: up.normalize(),
                            fov_y_degrees: fov.to_degrees().clamp(1.0, 179.0),
                        });
                    }
                }
            }
            "Inline" => self.ignore("Inline (not loaded)"),
            "Script"
            | "WorldInfo"
            | "NavigationInfo"
            | "Background"
            | "Fog"
            | "Sound"
            | "AudioClip"
            | "DirectionalLight"
            | "PointLight"
            | "SpotLight"
            | "TimeSensor"
            | "TouchSensor"
            | "PlaneSensor"
            | "SphereSensor"
            | "CylinderSensor"
            | "ProximitySensor"
            | "VisibilitySensor"
            | "PositionInterpolator"
            | "OrientationInterpolator"
            | "ColorInterpolator"
            | "ScalarInterpolator"
            | "CoordinateInterpolator"
            | "NormalInterpolator" => {}
            other => {
                let kind = format!("{other} node");
                self.ignore(&kind);
            }
        }
        Ok(())
    }

    fn material(&mut self, shape: &Node) -> Result<u32, ImportError> {
        let nodes = self.nodes;
        let material = shape
            .field("appearance")
            .and_then(|f| f.nodes.first())
            .map(|&a| &nodes[a])
            .and_then(|a| a.field("material"))
            .and_then(|f| f.nodes.first())
            .map(|&m| &nodes[m]);
        let (mut diffuse, emissive, line) = match material {
            Some(m) => (
                self.vec(m, "diffuseColor", [0.8; 3])?,
                self.vec(m, "emissiveColor", [0.0; 3])?,
                m.line,
            ),
            None => ([0.8; 3], [0.0; 3], shape.line),
        };
        for (what, c) in [("diffuseColor", diffuse), ("emissiveColor", emissive)] {
            if c.iter().any(|&x| x < 0.0) {
                return Err(self.error(
                    line,
                    format!(
                        "Material.{what} ({} {} {}) is negative; colours are at least 0",
                        c[0], c[1], c[2]
                    ),
                ));
            }
        }
        if diffuse.iter().any(|&x| x >= 1.0) {
            self.bright.push(line);
            diffuse = diffuse.map(|x| x.min(MAX_REFLECTANCE));
        }
        let mut key = [0u64; 6];
        for k in 0..3 {
            key[k] = diffuse[k].to_bits();
            key[k + 3] = emissive[k].to_bits();
        }
        if let Some(&i) = self.materials.get(&key) {
            return Ok(i);
        }
        let i = self.soup.materials.len() as u32;
        self.soup.materials.push(SoupMaterial {
            name: format!("Material of line {line}"),
            reflectance: Rgb(diffuse),
            emission: Rgb(emissive),
            defined_at: Some((self.file.clone(), line)),
        });
        self.materials.insert(key, i);
        Ok(i)
    }

    fn shape(&mut self, id: usize, m: DMat4, name: Option<&str>) -> Result<(), ImportError> {
        let nodes = self.nodes;
        let shape = &nodes[id];
        self.shapes += 1;
        let Some(&g) = shape.field("geometry").and_then(|f| f.nodes.first()) else {
            return Ok(());
        };
        let geometry = &nodes[g];
        let material = self.material(shape)?;
        let object = self.soup.objects.len() as u32;
        let object_name = name.map_or_else(|| format!("Shape {}", self.shapes), str::to_string);
        // Faces in local coordinates: corners, and index lists into them.
        let (points, faces): (Vec<DVec3>, Vec<Vec<u32>>) = match geometry.kind.as_str() {
            "IndexedFaceSet" => self.indexed_face_set(geometry)?,
            "Box" => {
                let size = DVec3::from(self.vec(geometry, "size", [2.0; 3])?);
                if size.min_element() <= 0.0 {
                    return Err(
                        self.error(geometry.line, format!("Box.size ({size}) must be positive"))
                    );
                }
                tessellate::indexed(tessellate::cuboid(size))
            }
            "Sphere" => {
                let r = self.positive(geometry, "radius", 1.0)?;
                tessellate::indexed(tessellate::sphere(r, self.segments))
            }
            "Cylinder" => {
                let r = self.positive(geometry, "radius", 1.0)?;
                let h = self.positive(geometry, "height", 2.0)?;
                tessellate::indexed(tessellate::cylinder(
                    r,
                    h,
                    self.segments,
                    [
                        self.flag(geometry, "side", true),
                        self.flag(geometry, "top", true),
                        self.flag(geometry, "bottom", true),
                    ],
                ))
            }
            "Cone" => {
                let r = self.positive(geometry, "bottomRadius", 1.0)?;
                let h = self.positive(geometry, "height", 2.0)?;
                tessellate::indexed(tessellate::cone(
                    r,
                    h,
                    self.segments,
                    [
                        self.flag(geometry, "side", true),
                        self.flag(geometry, "bottom", true),
                    ],
                ))
            }
            other => {
                let kind = format!("{other} geometry");
                self.ignore(&kind);
                return Ok(());
            }
        };
        let corners: usize = faces.iter().map(Vec::len).sum();
        if self.soup.faces.len() + faces.len() > MAX_FACES
            || self.soup.indices.len() + corners > 4 * MAX_FACES
        {
            return Err(self.error(
                shape.line,
                format!("the scene would have more than {MAX_FACES} faces once every USE is placed (this Shape is placed again and again); simplify it"),
            ));
        }
        self.soup.objects.push(object_name);
        let base = self.soup.vertices.len() as u32;
        for p in &points {
            self.soup.vertices.push(m.transform_point3(*p));
            self.soup.vertex_lines.push(geometry.line);
        }
        let mirrored = m.determinant() < 0.0;
        for face in faces {
            self.soup.faces.push(SoupFace {
                object,
                material,
                first: self.soup.indices.len(),
                count: face.len() as u32,
                line: geometry.line,
            });
            if mirrored {
                self.soup
                    .indices
                    .extend(face.iter().rev().map(|&i| base + i));
            } else {
                self.soup.indices.extend(face.iter().map(|&i| base + i));
            }
        }
        Ok(())
    }

    fn positive(&self, node: &Node, name: &str, default: f64) -> Result<f64, ImportError> {
        let v = self.vec(node, name, [default])?[0];
        if v > 0.0 {
            Ok(v)
        } else {
            let line = node.field(name).map_or(node.line, |f| f.line);
            Err(self.error(
                line,
                format!("{}.{name} is {v}; it must be positive", node.kind),
            ))
        }
    }

    fn indexed_face_set(&self, ifs: &Node) -> Result<(Vec<DVec3>, Vec<Vec<u32>>), ImportError> {
        let coord = ifs
            .field("coord")
            .and_then(|f| f.nodes.first())
            .map(|&c| &self.nodes[c]);
        let points: Vec<DVec3> = match coord {
            None => Vec::new(),
            Some(c) => {
                let Some(f) = c.field("point") else {
                    return Ok((Vec::new(), Vec::new()));
                };
                if f.nums.len() % 3 != 0 {
                    return Err(self.error(
                        f.line,
                        format!(
                            "Coordinate.point has {} numbers, not a whole number of x y z triples",
                            f.nums.len()
                        ),
                    ));
                }
                f.nums
                    .chunks_exact(3)
                    .map(|p| DVec3::new(p[0], p[1], p[2]))
                    .collect()
            }
        };
        let ccw = self.flag(ifs, "ccw", true);
        let mut faces = Vec::new();
        let mut face = Vec::new();
        if let Some(f) = ifs.field("coordIndex") {
            for (k, &i) in f.nums.iter().enumerate() {
                if i == -1.0 {
                    faces.push(std::mem::take(&mut face));
                    continue;
                }
                if !(i >= 0.0 && i.fract() == 0.0 && (i as usize) < points.len()) {
                    return Err(ImportError::BadIndex {
                        file: self.file.clone(),
                        line: f.line,
                        element: format!(
                            "IndexedFaceSet of line {}, coordIndex entry {k} (face {})",
                            ifs.line,
                            faces.len() + 1
                        ),
                        index: i as i64,
                        count: points.len(),
                    });
                }
                face.push(i as u32);
            }
            if !face.is_empty() {
                faces.push(face);
            }
        }
        faces.retain(|f| !f.is_empty());
        if !ccw {
            for f in &mut faces {
                f.reverse();
            }
        }
        Ok((points, faces))
    }
}

#[cfg(test)]
#[path = "vrml_tests.rs"]
mod tests;
