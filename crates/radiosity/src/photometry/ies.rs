//! IES LM-63 photometric files: a luminaire's candela table.
//!
//! # What is read
//!
//! The ANSI/IES LM-63 text format in its variants: LM-63-1986 (no first line of version),
//! `IESNA91`, `IESNA:LM-63-1995`, `IESNA:LM-63-2002` and `IES:LM-63-2019`. In order:
//!
//! 1. the version line (absent in 1986 files) and the keyword lines (`[TEST] ...`,
//!    `[MANUFAC] ...`; kept as they stand, see [`IesPhotometry::keywords`]); any line before
//!    `TILT=` that is not a keyword (1986 files have free text) is kept as a label;
//! 2. `TILT=NONE`, or `TILT=INCLUDE` followed by the tilt data (lamp-to-luminaire geometry
//!    1, 2 or 3, the number of tilt angles, the angles in degrees and their multiplying
//!    factors: see [`Tilt`]). `TILT=<file name>` (the tilt data in a separate file, allowed
//!    before 2019) is refused with a message saying to copy the data after `TILT=INCLUDE`;
//! 3. number of lamps, lumens per lamp (-1: absolute photometry, no rated lamp flux), the
//!    candela multiplier, the numbers of vertical and horizontal angles, the photometric type
//!    (1 = C, 2 = B, 3 = A), the units of the dimensions (1 = feet, 2 = metres), and the
//!    luminous opening's width, length and height;
//! 4. the ballast factor, the third factor (1995 and before: the ballast-lamp photometric
//!    factor, applied; 2002: "future use", 2019: the file generation type, both ignored) and
//!    the input watts;
//! 5. the vertical angles, the horizontal angles, and the candela values, one run of
//!    vertical angles per horizontal angle.
//!
//! Numbers are separated by white space or commas and may wrap across lines anywhere.
//! Text that is not UTF-8 is read as Latin-1 (older files write `°` and `µ` that way).
//!
//! # Type C geometry
//!
//! Only type C photometry (the one for building luminaires; types A and B, for floodlights
//! and automotive lamps, are refused with a message). The vertical angle `theta` is measured
//! from the photometric axis (0 = nadir for a downlight); the horizontal angle `phi` turns
//! about that axis. Vertical angles may cover any increasing run within 0 to 180 degrees
//! (the standard's 0-90, 90-180 and 0-180); no light leaves at vertical angles outside the
//! run. The horizontal angles state the symmetry, as the standard says:
//!
//! * one angle: the distribution is the same in every horizontal direction;
//! * 0 to 90: symmetric in each quadrant (about the 0-180 and the 90-270 planes);
//! * 0 to 180: symmetric about the 0-180 plane;
//! * 90 to 270: symmetric about the 90-270 plane (a form older files use);
//! * 0 to 360 (or 0 to a last angle above 180, which then joins angle 0 again at 360): no
//!   symmetry.
//!
//! [`IesPhotometry::candela`] interpolates bilinearly in (vertical, horizontal) angle, and
//! [`IesPhotometry::table_lumens`] integrates exactly that interpolated distribution over
//! the sphere (in closed form per cell), so the flux it reports is the flux a program
//! that uses `candela` emits.
//!
//! # Why not a crate
//!
//! The one Rust crate found that reads IES files with types and errors, `eulumdat`, is
//! AGPL-3.0, which this MIT/Apache project cannot take; no permissively licensed reader was
//! found. The format is a few hundred lines of numbers, written here with each refusal at its
//! line.

use std::fmt;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// Feet to metres, for the luminous dimensions of files in feet (units type 1).
const FOOT_M: f64 = 0.3048;

/// Angles in the file are compared with this slack (degrees) where the standard names a
/// value (0, 90, 180, 270, 360): files print angles to a few decimals.
const ANGLE_SLACK_DEG: f64 = 1e-6;

/// Largest luminous intensity accepted, in candela, after the multiplier and factors: far
/// above any luminaire (a searchlight reaches about 1e9 cd), and low enough that the flux
/// sums over any table stay finite.
pub const MAX_CANDELA: f64 = 1e12;

/// Largest tilt multiplying factor accepted (the factors are near 1: lamp output relative
/// to the photometric position).
const MAX_TILT_FACTOR: f64 = 1e3;

/// The LM-63 variant, from the first line of the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IesVersion {
    /// LM-63-1986: no version line.
    Lm63_1986,
    /// `IESNA91`.
    Lm63_1991,
    /// `IESNA:LM-63-1995`.
    Lm63_1995,
    /// `IESNA:LM-63-2002`.
    Lm63_2002,
    /// `IES:LM-63-2019`.
    Lm63_2019,
}

impl IesVersion {
    /// The version a first line states, or `None` for a line that states none (1986).
    fn from_first_line(line: &str) -> Option<Self> {
        let line = line.trim().to_ascii_uppercase();
        match line.as_str() {
            "IESNA91" => Some(Self::Lm63_1991),
            "IESNA:LM-63-1995" => Some(Self::Lm63_1995),
            "IESNA:LM-63-2002" => Some(Self::Lm63_2002),
            "IES:LM-63-2019" | "IESNA:LM-63-2019" => Some(Self::Lm63_2019),
            _ => None,
        }
    }

    /// Whether the third number of the ballast line is the ballast-lamp photometric factor
    /// (a multiplier of the candela values): up to 1995; 2002 calls it "future use" and 2019
    /// the file generation type.
    fn third_factor_multiplies(self) -> bool {
        matches!(self, Self::Lm63_1986 | Self::Lm63_1991 | Self::Lm63_1995)
    }
}

impl fmt::Display for IesVersion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Lm63_1986 => "LM-63-1986",
            Self::Lm63_1991 => "LM-63-1991",
            Self::Lm63_1995 => "LM-63-1995",
            Self::Lm63_2002 => "LM-63-2002",
            Self::Lm63_2019 => "LM-63-2019",
        })
    }
}

/// `TILT=INCLUDE` data: how the lamp's output changes as the luminaire is tilted.
#[derive(Debug, Clone, PartialEq)]
pub struct Tilt {
    /// Lamp-to-luminaire geometry: 1 (lamp vertical base up or down when the luminaire
    /// points down), 2 (lamp horizontal, turning in the 0-180 plane), 3 (lamp horizontal,
    /// turning in the 90-270 plane).
    pub geometry: u8,
    /// Tilt angles in degrees, increasing.
    pub angles_deg: Vec<f64>,
    /// Multiplying factor of the candela values at each angle.
    pub factors: Vec<f64>,
}

/// The horizontal symmetry a file's horizontal angles state (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Symmetry {
    /// One horizontal angle.
    Rotational,
    /// 0 to 90.
    Quadrant,
    /// 0 to 180.
    Bilateral0,
    /// 90 to 270.
    Bilateral90,
    /// 0 to a last angle above 180 (360 or less); the last joins angle 0 at 360.
    Full,
}

/// An IES LM-63 type C photometric file, read.
#[derive(Debug, Clone)]
pub struct IesPhotometry {
    path: PathBuf,
    version: IesVersion,
    keywords: Vec<(String, String)>,
    labels: Vec<String>,
    tilt: Option<Tilt>,
    lamps: u32,
    lumens_per_lamp: f64,
    candela_multiplier: f64,
    ballast_factor: f64,
    ballast_lamp_factor: f64,
    input_watts: f64,
    dimensions_m: [f64; 3],
    vertical_deg: Vec<f64>,
    horizontal_deg: Vec<f64>,
    /// Raw candela values, `horizontal_deg.len()` runs of `vertical_deg.len()`.
    values: Vec<f64>,
    /// Multiplier of every raw value: candela multiplier x ballast factor x the ballast-lamp
    /// photometric factor where it applies.
    scale: f64,
    symmetry: Symmetry,
}

/// What is wrong at a place in an IES file.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum IesProblem {
    /// The file is empty.
    #[error("the file is empty: an IES LM-63 file starts with a line such as IESNA:LM-63-2002")]
    Empty,
    /// No `TILT=` line.
    #[error(
        "no TILT= line: an IES LM-63 file gives TILT=NONE (or TILT=INCLUDE and the tilt data) \
         after its keyword lines, before the numbers"
    )]
    NoTilt,
    /// `TILT=<file>`.
    #[error(
        "TILT={0} names a separate tilt file, which is not read: copy its numbers into this \
         file after a line TILT=INCLUDE, or write TILT=NONE"
    )]
    TiltFile(String),
    /// A token that is not a finite number where one was expected.
    #[error("expected {expected}, found `{found}`")]
    NotANumber {
        /// What the number would have been.
        expected: String,
        /// The text found.
        found: String,
    },
    /// The numbers end early.
    #[error("the file ends where {expected} was expected")]
    UnexpectedEnd {
        /// What was expected next.
        expected: String,
    },
    /// A number outside what the standard allows.
    #[error("{what} is {value}; {allowed}")]
    OutOfRange {
        /// The quantity.
        what: String,
        /// The value read.
        value: f64,
        /// What would work.
        allowed: String,
    },
    /// Photometric type A or B.
    #[error(
        "photometric type {0} (type {name}) is not read: only type C (1), the photometry of \
         building luminaires, is",
        name = if *.0 == 2 { "B" } else { "A" }
    )]
    UnsupportedType(u32),
    /// Angles that do not increase.
    #[error(
        "{what} angle {index} is {value} degrees, not above the one before it ({previous}): \
         angles must increase"
    )]
    NotIncreasing {
        /// "vertical", "horizontal" or "tilt".
        what: &'static str,
        /// 1-based position in its list.
        index: usize,
        /// The previous angle.
        previous: f64,
        /// This angle.
        value: f64,
    },
    /// An angle list that stops increasing at the first number of a line, in a file that
    /// holds fewer numbers than its counts need: the declared count is likely larger than
    /// the angles given, and the list has run onto the next one.
    #[error(
        "this line declares {count} {what} angles, but {given_on} {given}: {what} angle \
         {index} would be the {value} that starts line {value_line}, not above the {previous} \
         before it, and the file holds fewer numbers than its counts need, so line \
         {value_line} likely begins the {next} (give the count of angles listed, or the \
         missing angle)",
        index = given + 1
    )]
    CountTooLarge {
        /// "vertical", "horizontal" or "tilt".
        what: &'static str,
        /// The count declared.
        count: usize,
        /// The angles given before the line that breaks the order.
        given: usize,
        /// "line 6 gives", or "lines 6 to 8 give".
        given_on: String,
        /// The angle after them, which is not above the one before it.
        value: f64,
        /// Its line.
        value_line: usize,
        /// The last angle given.
        previous: f64,
        /// What follows the list in the file: "horizontal angles" and so on.
        next: &'static str,
    },
    /// A lamp or ballast line with more numbers than it takes, found where a later number
    /// is refused and the file holds exactly that many numbers too many.
    #[error(
        "this line has {found} numbers, where the {name} takes {expected} ({names}): {moved}, \
         and line {then_line} then reads: {then}",
        moved = match found - expected {
            1 => "the extra one moves every number after it one place on".to_string(),
            n => format!("the {n} extra move every number after them {n} places on"),
        }
    )]
    ExtraNumbers {
        /// "lamp line" or "ballast line".
        name: &'static str,
        /// The numbers on the line.
        found: usize,
        /// The numbers the line takes.
        expected: usize,
        /// What they are.
        names: &'static str,
        /// The line of the later problem.
        then_line: usize,
        /// The later problem.
        then: Box<IesProblem>,
    },
    /// Horizontal angles that state none of the standard's symmetries.
    #[error(
        "the horizontal angles run from {first} to {last} degrees; type C files give one \
         angle, or 0 to 90, 0 to 180, 90 to 270 or 0 to 360"
    )]
    HorizontalRange {
        /// The first horizontal angle.
        first: f64,
        /// The last horizontal angle.
        last: f64,
    },
    /// Numbers after the candela table.
    #[error(
        "`{0}` follows the last candela value: the counts of angles on the lamp line may be \
         too small"
    )]
    TrailingData(String),
}

/// An IES file that cannot be read.
#[derive(Debug, Error)]
pub enum IesError {
    /// The file cannot be opened or read.
    #[error("{}: error: cannot read the IES file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a valid IES LM-63 type C file.
    #[error("{}:{line}: error: {problem}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// 1-based line of the problem (the last line for a file that ends early).
        line: usize,
        /// What is wrong and what would work.
        problem: IesProblem,
    },
}

impl IesError {
    /// The problem and its line, for a file that was read but is not valid.
    pub fn problem(&self) -> Option<(usize, &IesProblem)> {
        match self {
            Self::Invalid { line, problem, .. } => Some((*line, problem)),
            Self::Io { .. } => None,
        }
    }
}

/// Numbers of the file after the `TILT=` line, each with its line.
struct Numbers<'a> {
    tokens: Vec<(usize, &'a str)>,
    next: usize,
    last_line: usize,
    path: &'a Path,
}

impl<'a> Numbers<'a> {
    fn new(lines: &[&'a str], first_line: usize, path: &'a Path) -> Self {
        let mut tokens = Vec::new();
        for (offset, line) in lines.iter().enumerate() {
            let number = first_line + offset;
            for token in line.split(|c: char| c.is_whitespace() || c == ',') {
                if !token.is_empty() {
                    tokens.push((number, token));
                }
            }
        }
        let last_line = (first_line + lines.len()).saturating_sub(1).max(1);
        Self {
            tokens,
            next: 0,
            last_line,
            path,
        }
    }

    fn error(&self, line: usize, problem: IesProblem) -> IesError {
        IesError::Invalid {
            path: self.path.to_path_buf(),
            line,
            problem,
        }
    }

    /// The numbers on the line of token `start`, where that token is the first on its line
    /// (`None` where a number before it shares the line, or past the end).
    fn on_line_from(&self, start: usize) -> Option<usize> {
        let &(line, _) = self.tokens.get(start)?;
        if start > 0 && self.tokens[start - 1].0 == line {
            return None;
        }
        Some(
            self.tokens[start..]
                .iter()
                .take_while(|t| t.0 == line)
                .count(),
        )
    }

    /// The next number and its line.
    fn number(&mut self, expected: &str) -> Result<(f64, usize), IesError> {
        let Some(&(line, token)) = self.tokens.get(self.next) else {
            return Err(self.error(
                self.last_line,
                IesProblem::UnexpectedEnd {
                    expected: expected.to_string(),
                },
            ));
        };
        self.next += 1;
        match token.parse::<f64>() {
            Ok(value) if value.is_finite() => Ok((value, line)),
            _ => Err(self.error(
                line,
                IesProblem::NotANumber {
                    expected: expected.to_string(),
                    found: token.to_string(),
                },
            )),
        }
    }

    /// The next number, which must be a whole number in `range`.
    fn whole(
        &mut self,
        expected: &str,
        range: std::ops::RangeInclusive<u32>,
    ) -> Result<(u32, usize), IesError> {
        let (value, line) = self.number(expected)?;
        if value.fract() != 0.0
            || value < f64::from(*range.start())
            || value > f64::from(*range.end())
        {
            return Err(self.error(
                line,
                IesProblem::OutOfRange {
                    what: expected.to_string(),
                    value,
                    allowed: format!(
                        "a whole number from {} to {} is expected",
                        range.start(),
                        range.end()
                    ),
                },
            ));
        }
        Ok((value as u32, line))
    }

    /// The next number, which must be positive.
    fn positive(&mut self, expected: &str) -> Result<f64, IesError> {
        let (value, line) = self.number(expected)?;
        if value <= 0.0 {
            return Err(self.error(
                line,
                IesProblem::OutOfRange {
                    what: expected.to_string(),
                    value,
                    allowed: "a number above 0 is expected".to_string(),
                },
            ));
        }
        Ok(value)
    }

    /// `count` increasing angles within `[lo, hi]` degrees. `count_line` is the line that
    /// declares `count`, `needed` the numbers the file needs from the first angle to its
    /// end, and `next` what follows the list: an angle that stops the order at the start of
    /// a line in a file short of numbers is refused as a count too large
    /// ([`IesProblem::CountTooLarge`]), since lists may wrap across lines.
    fn angles(
        &mut self,
        what: &'static str,
        count: usize,
        lo: f64,
        hi: f64,
        (count_line, needed, next): (usize, usize, &'static str),
    ) -> Result<Vec<f64>, IesError> {
        let start = self.next;
        let mut angles: Vec<f64> = Vec::new();
        for index in 1..=count {
            let (value, line) = self.number(&format!("{what} angle {index} of {count}"))?;
            if value < lo - ANGLE_SLACK_DEG || value > hi + ANGLE_SLACK_DEG {
                return Err(self.error(
                    line,
                    IesProblem::OutOfRange {
                        what: format!("{what} angle {index}"),
                        value,
                        allowed: format!("{what} angles of type C lie from {lo} to {hi} degrees"),
                    },
                ));
            }
            if let Some(&previous) = angles.last() {
                let before = self.tokens[self.next - 2].0;
                let available = self.tokens.len() - start;
                if value <= previous && before != line && available < needed {
                    let first = self.tokens[start].0;
                    let given_on = if first == before {
                        format!("line {first} gives")
                    } else {
                        format!("lines {first} to {before} give")
                    };
                    return Err(self.error(
                        count_line,
                        IesProblem::CountTooLarge {
                            what,
                            count,
                            given: index - 1,
                            given_on,
                            value,
                            value_line: line,
                            previous,
                            next,
                        },
                    ));
                }
                if value <= previous {
                    return Err(self.error(
                        line,
                        IesProblem::NotIncreasing {
                            what,
                            index,
                            previous,
                            value,
                        },
                    ));
                }
            }
            angles.push(value);
        }
        Ok(angles)
    }
}

impl IesPhotometry {
    /// Reads an IES LM-63 file. See the module docs for what is read and refused.
    pub fn read(path: &Path) -> Result<IesPhotometry, IesError> {
        let bytes = std::fs::read(path).map_err(|source| IesError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let text = match String::from_utf8(bytes) {
            Ok(text) => text,
            // Latin-1: each byte is the code point of the same number.
            Err(error) => error.into_bytes().iter().map(|&b| char::from(b)).collect(),
        };
        Self::parse(&text, path)
    }

    /// Parses the text of an IES LM-63 file; `path` names it in errors and
    /// [`IesPhotometry::path`].
    pub fn parse(text: &str, path: &Path) -> Result<IesPhotometry, IesError> {
        let error = |line: usize, problem| IesError::Invalid {
            path: path.to_path_buf(),
            line,
            problem,
        };
        let lines: Vec<&str> = text.lines().collect();
        if lines.iter().all(|line| line.trim().is_empty()) {
            return Err(error(1, IesProblem::Empty));
        }

        // Version line, keywords and labels, up to TILT=
        let first = lines[0].trim_start_matches('\u{feff}');
        let version = IesVersion::from_first_line(first);
        let mut keywords = Vec::new();
        let mut labels = Vec::new();
        let mut tilt_line = None;
        let start = usize::from(version.is_some());
        for (index, raw) in lines.iter().enumerate().skip(start) {
            let line = if index == 0 { first } else { raw }.trim();
            // `get`: the first five bytes may end inside a character (Latin-1 text read
            // as UTF-8 code points); found by the fuzz target.
            if line
                .get(..5)
                .is_some_and(|start| start.eq_ignore_ascii_case("TILT="))
            {
                tilt_line = Some(index);
                break;
            }
            if let Some(rest) = line.strip_prefix('[') {
                if let Some((key, value)) = rest.split_once(']') {
                    keywords.push((key.trim().to_string(), value.trim().to_string()));
                    continue;
                }
            }
            if !line.is_empty() {
                labels.push(line.to_string());
            }
        }
        let Some(tilt_index) = tilt_line else {
            return Err(error(lines.len(), IesProblem::NoTilt));
        };
        let version = version.unwrap_or(IesVersion::Lm63_1986);
        let tilt_value = lines[tilt_index].trim()[5..].trim();
        let mut numbers = Numbers::new(&lines[tilt_index + 1..], tilt_index + 2, path);

        // Tilt data
        let tilt = if tilt_value.eq_ignore_ascii_case("NONE") {
            None
        } else if tilt_value.eq_ignore_ascii_case("INCLUDE") {
            let (geometry, _) =
                numbers.whole("the lamp-to-luminaire geometry (1, 2 or 3)", 1..=3)?;
            let (count, count_line) = numbers.whole("the number of tilt angles", 1..=u32::MAX)?;
            let count = count as usize;
            // The factors, then at least the lamp and ballast lines and a table of 2 x 1.
            let needed = count.saturating_mul(2).saturating_add(10 + 3 + 5);
            let angles_deg = numbers.angles(
                "tilt",
                count,
                0.0,
                180.0,
                (count_line, needed, "tilt multiplying factors"),
            )?;
            let mut factors = Vec::new();
            for index in 1..=count {
                let (value, line) =
                    numbers.number(&format!("tilt multiplying factor {index} of {count}"))?;
                if !(0.0..=MAX_TILT_FACTOR).contains(&value) {
                    return Err(error(
                        line,
                        IesProblem::OutOfRange {
                            what: format!("tilt multiplying factor {index}"),
                            value,
                            allowed: format!("factors from 0 to {MAX_TILT_FACTOR} are expected"),
                        },
                    ));
                }
                factors.push(value);
            }
            Some(Tilt {
                geometry: geometry as u8,
                angles_deg,
                factors,
            })
        } else {
            return Err(error(
                tilt_index + 1,
                IesProblem::TiltFile(tilt_value.to_string()),
            ));
        };

        // The lamp line
        let lamp_start = numbers.next;
        let (lamps, _) = numbers.whole("the number of lamps", 1..=u32::MAX)?;
        let (lumens_per_lamp, line) = numbers.number("the lumens per lamp")?;
        if lumens_per_lamp <= 0.0 && lumens_per_lamp != -1.0 {
            return Err(error(
                line,
                IesProblem::OutOfRange {
                    what: "the lumens per lamp".to_string(),
                    value: lumens_per_lamp,
                    allowed: "a number above 0 is expected, or -1 for absolute photometry"
                        .to_string(),
                },
            ));
        }
        let candela_multiplier = numbers.positive("the candela multiplier")?;
        let (vertical_count, counts_line) =
            numbers.whole("the number of vertical angles", 2..=u32::MAX)?;
        let (horizontal_count, horizontal_count_line) =
            numbers.whole("the number of horizontal angles", 1..=u32::MAX)?;
        let (photometric_type, line) =
            numbers.whole("the photometric type (1 = C, 2 = B, 3 = A)", 1..=3)?;
        if photometric_type != 1 {
            return Err(error(line, IesProblem::UnsupportedType(photometric_type)));
        }
        let (units, _) = numbers.whole("the units type (1 = feet, 2 = metres)", 1..=2)?;
        let unit_m = if units == 1 { FOOT_M } else { 1.0 };
        let mut dimensions_m = [0.0; 3];
        for (dimension, name) in dimensions_m.iter_mut().zip(["width", "length", "height"]) {
            *dimension = numbers.number(&format!("the luminous opening's {name}"))?.0 * unit_m;
        }

        // The ballast line
        let ballast_start = numbers.next;
        let ballast_factor = numbers.positive("the ballast factor")?;
        let (third, line) = numbers.number(match version {
            IesVersion::Lm63_2019 => "the file generation type",
            IesVersion::Lm63_2002 => "the future-use number (1)",
            _ => "the ballast-lamp photometric factor",
        })?;
        let ballast_lamp_factor = if version.third_factor_multiplies() {
            if third <= 0.0 {
                return Err(error(
                    line,
                    IesProblem::OutOfRange {
                        what: "the ballast-lamp photometric factor".to_string(),
                        value: third,
                        allowed: "a number above 0 is expected".to_string(),
                    },
                ));
            }
            third
        } else {
            1.0
        };
        let scale = candela_multiplier * ballast_factor * ballast_lamp_factor;
        if scale > MAX_CANDELA {
            return Err(error(
                line,
                IesProblem::OutOfRange {
                    what: "the candela multiplier times the ballast factors".to_string(),
                    value: scale,
                    allowed: format!("at most {MAX_CANDELA:e} is accepted"),
                },
            ));
        }
        let (input_watts, _) = numbers.number("the input watts")?;

        // A lamp or ballast line with as many numbers too many as the file holds blames
        // what goes wrong later on that line (QA pass 15 of issue #16: a fourth number on
        // the ballast line was read as the first vertical angle, and the error named the
        // next line).
        let rest = numbers.tokens.len() - numbers.next;
        let needed = (vertical_count as usize)
            .saturating_mul(horizontal_count as usize)
            .saturating_add(vertical_count as usize)
            .saturating_add(horizontal_count as usize);
        let overlong = [
            (
                ballast_start,
                "ballast line",
                3,
                "the ballast factor, the third factor and the input watts",
            ),
            (
                lamp_start,
                "lamp line",
                10,
                "the lamps, lumens, multiplier, two counts, type, units and three dimensions",
            ),
        ]
        .into_iter()
        .find_map(|(start, name, expected, names)| {
            let found = numbers.on_line_from(start)?;
            (rest > needed && found == expected + (rest - needed)).then_some((
                numbers.tokens[start].0,
                name,
                found,
                expected,
                names,
            ))
        });
        let table = (|| -> Result<(Vec<f64>, Vec<f64>, Symmetry, Vec<f64>), IesError> {
            // Angles
            let (v, h) = (vertical_count as usize, horizontal_count as usize);
            let values_needed = v.saturating_mul(h);
            let vertical_deg = numbers.angles(
                "vertical",
                v,
                0.0,
                180.0,
                (
                    counts_line,
                    values_needed.saturating_add(v).saturating_add(h),
                    "horizontal angles",
                ),
            )?;
            let horizontal_line = numbers
                .tokens
                .get(numbers.next)
                .map_or(numbers.last_line, |t| t.0);
            let horizontal_deg = numbers.angles(
                "horizontal",
                h,
                0.0,
                360.0,
                (
                    horizontal_count_line,
                    values_needed.saturating_add(h),
                    "candela values",
                ),
            )?;
            let near = |a: f64, b: f64| (a - b).abs() <= ANGLE_SLACK_DEG;
            let first = horizontal_deg[0];
            let last = *horizontal_deg.last().unwrap_or(&first);
            let symmetry = if horizontal_deg.len() == 1 {
                Symmetry::Rotational
            } else if near(first, 0.0) && near(last, 90.0) {
                Symmetry::Quadrant
            } else if near(first, 0.0) && near(last, 180.0) {
                Symmetry::Bilateral0
            } else if near(first, 90.0) && near(last, 270.0) {
                Symmetry::Bilateral90
            } else if near(first, 0.0) && last > 180.0 {
                Symmetry::Full
            } else {
                return Err(error(
                    horizontal_line,
                    IesProblem::HorizontalRange { first, last },
                ));
            };

            // Candela values
            let mut values = Vec::new();
            for &horizontal in &horizontal_deg {
                for &vertical in &vertical_deg {
                    let (value, line) = numbers.number(&format!(
                        "the candela value at vertical angle {} and horizontal angle {}",
                        vertical, horizontal
                    ))?;
                    if value < 0.0 {
                        return Err(error(
                            line,
                            IesProblem::OutOfRange {
                                what: format!(
                                    "the candela value at vertical angle {} and horizontal angle {}",
                                    vertical, horizontal
                                ),
                                value,
                                allowed: "intensities must be 0 or more".to_string(),
                            },
                        ));
                    }
                    if value * scale > MAX_CANDELA {
                        return Err(error(
                            line,
                            IesProblem::OutOfRange {
                                what: format!(
                                    "the candela value at vertical angle {} and horizontal angle {}, \
                                     times the candela multiplier and ballast factors,",
                                    vertical, horizontal
                                ),
                                value: value * scale,
                                allowed: format!("at most {MAX_CANDELA:e} cd is accepted"),
                            },
                        ));
                    }
                    values.push(value);
                }
            }
            if let Some(&(line, token)) = numbers.tokens.get(numbers.next) {
                return Err(error(line, IesProblem::TrailingData(token.to_string())));
            }
            Ok((vertical_deg, horizontal_deg, symmetry, values))
        })();
        let (vertical_deg, horizontal_deg, symmetry, values) = match (table, overlong) {
            (Ok(table), _) => table,
            (
                Err(IesError::Invalid {
                    line: then_line,
                    problem,
                    ..
                }),
                Some((line, name, found, expected, names)),
            ) => {
                return Err(error(
                    line,
                    IesProblem::ExtraNumbers {
                        name,
                        found,
                        expected,
                        names,
                        then_line,
                        then: Box::new(problem),
                    },
                ))
            }
            (Err(e), _) => return Err(e),
        };

        Ok(IesPhotometry {
            path: path.to_path_buf(),
            version,
            keywords,
            labels,
            tilt,
            lamps,
            lumens_per_lamp,
            candela_multiplier,
            ballast_factor,
            ballast_lamp_factor,
            input_watts,
            dimensions_m,
            vertical_deg,
            horizontal_deg,
            values,
            scale,
            symmetry,
        })
    }

    /// The file this was read from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The LM-63 variant.
    pub fn version(&self) -> IesVersion {
        self.version
    }

    /// The keyword lines, as `(keyword, value)` in file order (`("MANUFAC", "Acme")`).
    pub fn keywords(&self) -> &[(String, String)] {
        &self.keywords
    }

    /// Lines before `TILT=` that are neither the version nor keywords (1986 files' text).
    pub fn labels(&self) -> &[String] {
        &self.labels
    }

    /// The `TILT=INCLUDE` data, if any.
    pub fn tilt(&self) -> Option<&Tilt> {
        self.tilt.as_ref()
    }

    /// The tilt multiplying factor at a lamp tilt of `tilt_rad` from the photometric
    /// position, interpolated linearly in the tilt table and held at its ends; 1 for a file
    /// with `TILT=NONE`. [`IesPhotometry::candela`] does not apply it: the caller knows how
    /// the luminaire is turned.
    pub fn tilt_factor(&self, tilt_rad: f64) -> f64 {
        match &self.tilt {
            None => 1.0,
            Some(tilt) => interpolate(&tilt.angles_deg, &tilt.factors, tilt_rad.to_degrees()),
        }
    }

    /// Number of lamps.
    pub fn lamps(&self) -> u32 {
        self.lamps
    }

    /// The candela multiplier.
    pub fn candela_multiplier(&self) -> f64 {
        self.candela_multiplier
    }

    /// The ballast factor.
    pub fn ballast_factor(&self) -> f64 {
        self.ballast_factor
    }

    /// The ballast-lamp photometric factor (LM-63-1995 and before; 1 for later files,
    /// where the number in its place is not a factor).
    pub fn ballast_lamp_factor(&self) -> f64 {
        self.ballast_lamp_factor
    }

    /// The input watts.
    pub fn input_watts(&self) -> f64 {
        self.input_watts
    }

    /// Width, length and height of the luminous opening in metres (converted from feet
    /// where the file says so; 0 for a point, negative for round shapes as LM-63 codes them).
    pub fn dimensions_m(&self) -> [f64; 3] {
        self.dimensions_m
    }

    /// The vertical angles of the table, degrees.
    pub fn vertical_angles_deg(&self) -> &[f64] {
        &self.vertical_deg
    }

    /// The horizontal angles of the table, degrees.
    pub fn horizontal_angles_deg(&self) -> &[f64] {
        &self.horizontal_deg
    }

    /// The rated flux the file states: lumens per lamp times lamps, or `None` for absolute
    /// photometry (lumens per lamp -1, as LED luminaires are measured).
    pub fn stated_lumens(&self) -> Option<f64> {
        (self.lumens_per_lamp > 0.0).then(|| self.lumens_per_lamp * f64::from(self.lamps))
    }

    /// Luminous intensity in candela in the direction at vertical angle `theta_rad` from the
    /// photometric axis (0 = along it, nadir for a downlight) and horizontal angle `phi_rad`
    /// about it, interpolated bilinearly in the table, with the symmetry the horizontal
    /// angles state, times the candela multiplier and the ballast factor (and, up to
    /// LM-63-1995, the ballast-lamp photometric factor). 0 outside the table's vertical
    /// angles and for a direction that is not a number.
    pub fn candela(&self, theta_rad: f64, phi_rad: f64) -> f64 {
        let theta = theta_rad.to_degrees();
        let phi = phi_rad.to_degrees();
        if !theta.is_finite() || !phi.is_finite() {
            return 0.0;
        }
        let first = self.vertical_deg[0];
        let last = self.vertical_deg[self.vertical_deg.len() - 1];
        if theta < first - ANGLE_SLACK_DEG || theta > last + ANGLE_SLACK_DEG {
            return 0.0;
        }
        let column = |h: usize| self.column_at(h, theta);
        let (h0, h1, t) = self.horizontal_weights(phi);
        let raw = if t == 0.0 {
            column(h0)
        } else {
            column(h0) * (1.0 - t) + column(h1) * t
        };
        raw * self.scale
    }

    /// The raw value of horizontal column `h` at vertical angle `theta` (degrees, within
    /// the table's range).
    fn column_at(&self, h: usize, theta: f64) -> f64 {
        let n = self.vertical_deg.len();
        interpolate(&self.vertical_deg, &self.values[h * n..(h + 1) * n], theta)
    }

    /// The two horizontal columns about `phi` (degrees, any value) and the weight of the
    /// second, after folding `phi` into the table's range by its symmetry.
    fn horizontal_weights(&self, phi: f64) -> (usize, usize, f64) {
        let mut p = phi.rem_euclid(360.0);
        match self.symmetry {
            Symmetry::Rotational => return (0, 0, 0.0),
            Symmetry::Quadrant => {
                if p > 180.0 {
                    p = 360.0 - p;
                }
                if p > 90.0 {
                    p = 180.0 - p;
                }
            }
            Symmetry::Bilateral0 => {
                if p > 180.0 {
                    p = 360.0 - p;
                }
            }
            Symmetry::Bilateral90 => {
                if p < 90.0 {
                    p = 180.0 - p;
                } else if p > 270.0 {
                    p = 540.0 - p;
                }
            }
            Symmetry::Full => {
                let n = self.horizontal_deg.len();
                let last = self.horizontal_deg[n - 1];
                if p >= last {
                    // Between the last angle and 360 (= the first column again).
                    let span = 360.0 - last;
                    let t = if span > 0.0 {
                        ((p - last) / span).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    return (n - 1, 0, t);
                }
            }
        }
        let angles = &self.horizontal_deg;
        let upper = angles.partition_point(|&a| a <= p);
        if upper == 0 {
            return (0, 0, 0.0);
        }
        if upper >= angles.len() {
            return (angles.len() - 1, angles.len() - 1, 0.0);
        }
        let (a0, a1) = (angles[upper - 1], angles[upper]);
        (upper - 1, upper, ((p - a0) / (a1 - a0)).clamp(0.0, 1.0))
    }

    /// The luminous flux in lumens of the distribution [`IesPhotometry::candela`] gives,
    /// integrated over the sphere: exact for the bilinear interpolation (per vertical
    /// segment in closed form, `∫ (a + b t) sin t dt`, and per horizontal segment by the
    /// trapezoid rule, exact for a linear function), with the multiplier and factors applied.
    /// For a bare lamp, or a luminaire with a light output ratio of 1, it equals
    /// [`IesPhotometry::stated_lumens`] up to the table's resolution.
    pub fn table_lumens(&self) -> f64 {
        let n = self.vertical_deg.len();
        // ∫ I(theta) sin(theta) dtheta for column h, I linear between the vertical angles.
        let column_integral = |h: usize| -> f64 {
            let values = &self.values[h * n..(h + 1) * n];
            let mut sum = 0.0;
            for k in 0..n - 1 {
                let a = self.vertical_deg[k].to_radians();
                let b = self.vertical_deg[k + 1].to_radians();
                let width = b - a;
                let (ya, yb) = (values[k], values[k + 1]);
                // ∫_a^b (t - a) sin t dt = sin b - sin a - (b - a) cos b
                let ramp = (b.sin() - a.sin() - width * b.cos()) / width;
                sum += ya * (a.cos() - b.cos()) + (yb - ya) * ramp;
            }
            sum
        };
        let columns: Vec<f64> = (0..self.horizontal_deg.len())
            .map(column_integral)
            .collect();
        let trapezoid = |from: usize, to: usize| -> f64 {
            (from..to)
                .map(|h| {
                    let width = (self.horizontal_deg[h + 1] - self.horizontal_deg[h]).to_radians();
                    0.5 * (columns[h] + columns[h + 1]) * width
                })
                .sum()
        };
        let last = columns.len() - 1;
        let raw = match self.symmetry {
            Symmetry::Rotational => std::f64::consts::TAU * columns[0],
            Symmetry::Quadrant => 4.0 * trapezoid(0, last),
            Symmetry::Bilateral0 | Symmetry::Bilateral90 => 2.0 * trapezoid(0, last),
            Symmetry::Full => {
                let wrap = (360.0 - self.horizontal_deg[last]).to_radians();
                trapezoid(0, last) + 0.5 * (columns[last] + columns[0]) * wrap
            }
        };
        raw * self.scale
    }
}

/// Linear interpolation of `values` at `x` over increasing `knots`; outside the knots the end
/// values are held.
fn interpolate(knots: &[f64], values: &[f64], x: f64) -> f64 {
    let upper = knots.partition_point(|&k| k <= x);
    if upper == 0 {
        return values[0];
    }
    if upper >= knots.len() {
        return values[knots.len() - 1];
    }
    let (k0, k1) = (knots[upper - 1], knots[upper]);
    let t = ((x - k0) / (k1 - k0)).clamp(0.0, 1.0);
    values[upper - 1] * (1.0 - t) + values[upper] * t
}

#[cfg(test)]
mod tests;
