//! Splitting scene text into lines of tokens, and recognising keywords.
//!
//! `//` starts a comment anywhere on a line; blank and comment-only lines are dropped. Tokens
//! are separated by whitespace and carry their 1-based column (in characters) for messages.

/// One whitespace-separated word of a line.
#[derive(Clone, Copy, Debug)]
pub(super) struct Token<'a> {
    /// The word as written.
    pub text: &'a str,
    /// Its first character's column, counting from 1.
    pub column: usize,
}

/// One line that has something on it besides comments and whitespace.
#[derive(Clone, Debug)]
pub(super) struct Line<'a> {
    /// The line number in the file, counting from 1.
    pub number: usize,
    /// The line without its comment.
    pub code: &'a str,
    /// The words of `code`; never empty.
    pub tokens: Vec<Token<'a>>,
    /// The column just after the last token (where "end of line" is reported).
    pub end_column: usize,
}

impl<'a> Line<'a> {
    /// The first word, which names what the line is.
    pub fn head(&self) -> Token<'a> {
        self.tokens[0]
    }

    /// The keyword the first word spells.
    pub fn keyword(&self) -> Keyword {
        Keyword::of(self.head().text)
    }
}

/// The lines of `text` that carry tokens, and the (line, column) of the end of the file.
pub(super) fn lex(text: &str) -> (Vec<Line<'_>>, (usize, usize)) {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = Vec::new();
    let mut eof = (1, 1);
    for (i, raw) in text.lines().enumerate() {
        eof = (i + 1, raw.chars().count() + 1);
        let code = raw.find("//").map_or(raw, |p| &raw[..p]);
        let tokens = tokens(code);
        if let Some(last) = tokens.last() {
            let end_column = last.column + last.text.chars().count();
            lines.push(Line {
                number: i + 1,
                code,
                tokens,
                end_column,
            });
        }
    }
    (lines, eof)
}

/// The whitespace-separated words of `code`, with their columns.
fn tokens(code: &str) -> Vec<Token<'_>> {
    let mut out = Vec::new();
    let mut start: Option<(usize, usize)> = None;
    for (index, (byte, ch)) in code.char_indices().enumerate() {
        if ch.is_whitespace() {
            if let Some((b, column)) = start.take() {
                out.push(Token {
                    text: &code[b..byte],
                    column,
                });
            }
        } else if start.is_none() {
            start = Some((byte, index + 1));
        }
    }
    if let Some((b, column)) = start {
        out.push(Token {
            text: &code[b..],
            column,
        });
    }
    out
}

/// What the first word of a line says it is. Keywords are case-insensitive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Keyword {
    MaxPatchArea,
    IntegralSteps,
    SceneBegin,
    SceneEnd,
    PatchBegin,
    PatchEnd,
    BoxBegin,
    BoxEnd,
    /// A `#NAME` line.
    Name,
    Vertices,
    Er,
    Eg,
    Eb,
    Rr,
    Rg,
    Rb,
    /// `VERTEXk`; an index too large for `usize` reads as `usize::MAX`.
    Vertex(usize),
    Facing,
    Origin,
    Size,
    Height,
    SphereBegin,
    SphereEnd,
    CylinderBegin,
    CylinderEnd,
    ConeBegin,
    ConeEnd,
    Center,
    Radius,
    Resolution,
    Luminance,
    Flux,
    Opening,
    LightBegin,
    LightEnd,
    Position,
    Aim,
    Intensity,
    Distribution,
    Colour,
    /// Anything else.
    Unknown,
}

/// The fixed keywords and their canonical spelling.
const WORDS: [(&str, Keyword); 40] = [
    ("MAX_PATCH_AREA", Keyword::MaxPatchArea),
    ("INTEGRAL_STEPS", Keyword::IntegralSteps),
    ("SCENEBEGIN", Keyword::SceneBegin),
    ("SCENEEND", Keyword::SceneEnd),
    ("PATCHBEGIN", Keyword::PatchBegin),
    ("PATCHEND", Keyword::PatchEnd),
    ("BOXBEGIN", Keyword::BoxBegin),
    ("BOXEND", Keyword::BoxEnd),
    ("#NAME", Keyword::Name),
    ("VERTICES", Keyword::Vertices),
    ("Er", Keyword::Er),
    ("Eg", Keyword::Eg),
    ("Eb", Keyword::Eb),
    ("Rr", Keyword::Rr),
    ("Rg", Keyword::Rg),
    ("Rb", Keyword::Rb),
    ("FACING", Keyword::Facing),
    ("ORIGIN", Keyword::Origin),
    ("SIZE", Keyword::Size),
    ("HEIGHT", Keyword::Height),
    ("SPHEREBEGIN", Keyword::SphereBegin),
    ("SPHEREEND", Keyword::SphereEnd),
    ("CYLINDERBEGIN", Keyword::CylinderBegin),
    ("CYLINDEREND", Keyword::CylinderEnd),
    ("CONEBEGIN", Keyword::ConeBegin),
    ("CONEEND", Keyword::ConeEnd),
    ("CENTER", Keyword::Center),
    ("RADIUS", Keyword::Radius),
    ("RESOLUTION", Keyword::Resolution),
    ("LUMINANCE", Keyword::Luminance),
    ("FLUX", Keyword::Flux),
    ("OPENING", Keyword::Opening),
    ("LIGHTBEGIN", Keyword::LightBegin),
    ("LIGHTEND", Keyword::LightEnd),
    ("POSITION", Keyword::Position),
    ("AIM", Keyword::Aim),
    ("INTENSITY", Keyword::Intensity),
    ("DISTRIBUTION", Keyword::Distribution),
    ("COLOUR", Keyword::Colour),
    // The American spelling reads as the same keyword (written back as COLOUR).
    ("COLOR", Keyword::Colour),
];

impl Keyword {
    /// The keyword that `word` spells (ignoring case), or [`Keyword::Unknown`].
    pub fn of(word: &str) -> Keyword {
        if word.starts_with('#') {
            return Keyword::Name;
        }
        if let Some((_, k)) = WORDS.iter().find(|(w, _)| w.eq_ignore_ascii_case(word)) {
            return *k;
        }
        vertex_index(word).map_or(Keyword::Unknown, Keyword::Vertex)
    }

    /// How the keyword is written in messages.
    pub fn spelling(self) -> String {
        match self {
            Keyword::Vertex(k) => format!("VERTEX{k}"),
            Keyword::Name => "a \"#NAME\" line".to_string(),
            Keyword::Unknown => "an unknown keyword".to_string(),
            other => WORDS
                .iter()
                .find(|(_, k)| *k == other)
                .map_or_else(String::new, |(w, _)| (*w).to_string()),
        }
    }
}

/// `k` for a word `VERTEXk` (any case, `k` all decimal digits).
fn vertex_index(word: &str) -> Option<usize> {
    let prefix = word.get(..6)?;
    let digits = &word[6..];
    if !prefix.eq_ignore_ascii_case("vertex")
        || digits.is_empty()
        || !digits.bytes().all(|b| b.is_ascii_digit())
    {
        return None;
    }
    Some(digits.parse().unwrap_or(usize::MAX))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_blank_lines_and_columns() {
        let (lines, eof) = lex("// header\n\n  Er  0.5 // c\n\t#Floor // n\nx");
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0].number, 3);
        assert_eq!(lines[0].tokens[0].column, 3);
        assert_eq!(lines[0].tokens[1].column, 7);
        assert_eq!(lines[0].tokens[1].text, "0.5");
        assert_eq!(lines[0].end_column, 10);
        assert_eq!(lines[1].keyword(), Keyword::Name);
        assert_eq!(eof, (5, 2));
    }

    #[test]
    fn keywords_ignore_case() {
        assert_eq!(Keyword::of("patchBegin"), Keyword::PatchBegin);
        assert_eq!(Keyword::of("RG"), Keyword::Rg);
        assert_eq!(Keyword::of("vertex12"), Keyword::Vertex(12));
        assert_eq!(Keyword::of("VERTEXO"), Keyword::Unknown);
        assert_eq!(Keyword::of("VERTEX"), Keyword::Unknown);
        assert_eq!(Keyword::of("vértex1"), Keyword::Unknown);
        assert_eq!(
            Keyword::of("VERTEX99999999999999999999999"),
            Keyword::Vertex(usize::MAX)
        );
    }
}
