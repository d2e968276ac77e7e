//! [`FormFactorMethod`], how form factors are computed, and its text form: the `Display`
//! written into the form-factor file (`area k=2`, `hemicube resolution=128`, ...) and the
//! `FromStr` that reads it back, accepting exactly what `Display` writes.

use std::num::ParseIntError;
use std::str::FromStr;

/// How form factors are computed. Recorded in the form-factor file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormFactorMethod {
    /// The paper's double area integral (figure 4) by the midpoint rule with `steps` x `steps`
    /// points on each element, a disc-regularised kernel (see `area.rs`) and the visibility
    /// of every point pair by a ray cast against candidate occluders.
    AreaIntegral {
        /// k, points along each axis of each element (`INTEGRAL_STEPS`).
        steps: u32,
    },
    /// The exact form factor between the two elements (the paper's double contour integral,
    /// figure 5, with the shared-edge and shared-vertex cases in closed form; see
    /// `exact/`). Exact for unoccluded pairs; where an occluder may intervene it is
    /// multiplied by the visible fraction of `steps` x `steps` by `steps` x `steps` point
    /// pairs, weighted by the area kernel.
    Contour {
        /// Points along each axis of each element for the visibility estimate.
        steps: u32,
    },
    /// Lambert's exact point-to-polygon form factor at `steps` x `steps` points on the
    /// receiving element, each times the visible fraction of `steps` x `steps` points on
    /// the source (Wallace, Elmquist and Haines 1989). Accurate at shared edges.
    Analytic {
        /// Points along each axis of each element.
        steps: u32,
    },
    /// The hemicube (Cohen and Greenberg 1985): each element's view rasterised on the CPU
    /// onto a half cube of `resolution` x `resolution` cells on top.
    Hemicube {
        /// Cells across the top face (even).
        resolution: u32,
    },
    /// Stratified Monte Carlo ray casting: `samples` cosine-distributed rays per element,
    /// from a seeded generator (deterministic).
    MonteCarlo {
        /// Rays per element (rounded up to a square).
        samples: u32,
        /// Generator seed.
        seed: u64,
    },
}

impl FormFactorMethod {
    /// True when the method's estimate is symmetric (A_i F_ij = A_j F_ji exactly), so only
    /// the upper triangle need be computed.
    pub fn is_reciprocal(&self) -> bool {
        matches!(
            self,
            FormFactorMethod::AreaIntegral { .. } | FormFactorMethod::Contour { .. }
        )
    }

    /// How the method handles occlusion, for the command line's help and notes.
    pub fn occlusion(&self) -> &'static str {
        match self {
            FormFactorMethod::AreaIntegral { .. } => "ray cast per point pair",
            FormFactorMethod::Contour { .. } => {
                "exact when unoccluded; pairs with a possible occluder are scaled by the visible fraction of their point pairs"
            }
            FormFactorMethod::Analytic { .. } => "rays from each receiver point to the source's points",
            FormFactorMethod::Hemicube { .. } => "depth buffer",
            FormFactorMethod::MonteCarlo { .. } => "closest hit of each ray",
        }
    }
}

impl std::fmt::Display for FormFactorMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FormFactorMethod::AreaIntegral { steps } => write!(f, "area k={steps}"),
            FormFactorMethod::Contour { steps } => write!(f, "contour k={steps}"),
            FormFactorMethod::Analytic { steps } => write!(f, "analytic k={steps}"),
            FormFactorMethod::Hemicube { resolution } => {
                write!(f, "hemicube resolution={resolution}")
            }
            FormFactorMethod::MonteCarlo { samples, seed } => {
                write!(f, "montecarlo samples={samples} seed={seed}")
            }
        }
    }
}

/// A text that is not a [`FormFactorMethod`] as its `Display` writes it. Each variant holds
/// the whole text.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParseMethodError {
    /// The first word names no method.
    #[error(
        "`{text}` is not a form-factor method: it does not start with area, contour, analytic, \
         hemicube or montecarlo"
    )]
    UnknownName {
        /// The text.
        text: String,
    },
    /// The method is known, but the settings after its name are not the ones it takes.
    #[error("`{text}` is not a form-factor method: {name} takes `{expected}`")]
    Settings {
        /// The text.
        text: String,
        /// The method's name.
        name: &'static str,
        /// Its settings as written, with placeholders (`k=<steps>`).
        expected: &'static str,
    },
    /// A setting's value is not a number of its type.
    #[error("`{text}` is not a form-factor method: {key}={value} is not a valid {key} ({source})")]
    Number {
        /// The text.
        text: String,
        /// The setting.
        key: &'static str,
        /// Its value as written.
        value: String,
        /// Why it does not parse.
        source: ParseIntError,
    },
    /// The text reads as a method but is not how `Display` writes it (a leading `+` or zero
    /// in a number, say), so it would not round-trip.
    #[error("`{text}` is not a form-factor method as written; it would be `{canonical}`")]
    NotCanonical {
        /// The text.
        text: String,
        /// How `Display` writes the method it reads as.
        canonical: String,
    },
}

impl FromStr for FormFactorMethod {
    type Err = ParseMethodError;

    /// Parses exactly what `Display` writes: the method's name, then its settings as
    /// `key=value`, each after one space, in `Display`'s order, with numbers as `Display`
    /// writes them.
    fn from_str(text: &str) -> Result<FormFactorMethod, ParseMethodError> {
        let mut words = text.split(' ');
        let name = words.next().unwrap_or_default();
        let settings: Vec<&str> = words.collect();
        // The values of `keys`, which must be all the settings, each `key=value`, in order.
        let values = |name: &'static str, keys: &[&str], expected: &'static str| {
            let found: Option<Vec<&str>> = if settings.len() == keys.len() {
                settings
                    .iter()
                    .zip(keys)
                    .map(|(setting, key)| setting.strip_prefix(key)?.strip_prefix('='))
                    .collect()
            } else {
                None
            };
            found.ok_or_else(|| ParseMethodError::Settings {
                text: text.to_string(),
                name,
                expected,
            })
        };
        // The one setting `k=<steps>` of the pair methods.
        let steps = |name: &'static str| {
            let v = values(name, &["k"], "k=<steps>")?;
            number(text, "k", v[0])
        };
        let method = match name {
            "area" => FormFactorMethod::AreaIntegral {
                steps: steps("area")?,
            },
            "contour" => FormFactorMethod::Contour {
                steps: steps("contour")?,
            },
            "analytic" => FormFactorMethod::Analytic {
                steps: steps("analytic")?,
            },
            "hemicube" => {
                let v = values("hemicube", &["resolution"], "resolution=<cells>")?;
                FormFactorMethod::Hemicube {
                    resolution: number(text, "resolution", v[0])?,
                }
            }
            "montecarlo" => {
                let keys = ["samples", "seed"];
                let v = values("montecarlo", &keys, "samples=<rays> seed=<seed>")?;
                FormFactorMethod::MonteCarlo {
                    samples: number(text, "samples", v[0])?,
                    seed: number(text, "seed", v[1])?,
                }
            }
            _ => {
                return Err(ParseMethodError::UnknownName {
                    text: text.to_string(),
                })
            }
        };
        // Rust's integers also read `+2` and `02`, which `Display` never writes.
        let canonical = method.to_string();
        if canonical != text {
            return Err(ParseMethodError::NotCanonical {
                text: text.to_string(),
                canonical,
            });
        }
        Ok(method)
    }
}

/// The setting `key=value` of the method `text` as an integer.
fn number<T: FromStr<Err = ParseIntError>>(
    text: &str,
    key: &'static str,
    value: &str,
) -> Result<T, ParseMethodError> {
    value.parse().map_err(|source| ParseMethodError::Number {
        text: text.to_string(),
        key,
        value: value.to_string(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every variant, at the edges of its settings' ranges and at ordinary values.
    fn methods() -> Vec<FormFactorMethod> {
        use FormFactorMethod::*;
        let mut out = Vec::new();
        for k in [0, 1, 2, 4, 17, u32::MAX] {
            out.extend([
                AreaIntegral { steps: k },
                Contour { steps: k },
                Analytic { steps: k },
                Hemicube { resolution: k },
            ]);
        }
        for (samples, seed) in [(1, 0), (1024, 1), (u32::MAX, u64::MAX), (7, 1 << 40)] {
            out.push(MonteCarlo { samples, seed });
        }
        out
    }

    #[test]
    fn display_round_trips_through_from_str() {
        let all = methods();
        // Every variant is in the list.
        for name in ["area", "contour", "analytic", "hemicube", "montecarlo"] {
            assert!(
                all.iter().any(|m| m.to_string().starts_with(name)),
                "{name}"
            );
        }
        for m in all {
            let text = m.to_string();
            assert_eq!(text.parse::<FormFactorMethod>(), Ok(m), "{text}");
        }
    }

    #[test]
    fn display_is_the_file_format() {
        // These texts are in form-factor files on disk: they must not change.
        use FormFactorMethod::*;
        for (m, text) in [
            (AreaIntegral { steps: 2 }, "area k=2"),
            (Contour { steps: 4 }, "contour k=4"),
            (Analytic { steps: 3 }, "analytic k=3"),
            (Hemicube { resolution: 128 }, "hemicube resolution=128"),
            (
                MonteCarlo {
                    samples: 1024,
                    seed: 1,
                },
                "montecarlo samples=1024 seed=1",
            ),
        ] {
            assert_eq!(m.to_string(), text);
            assert_eq!(text.parse::<FormFactorMethod>(), Ok(m));
        }
    }

    #[test]
    fn anything_else_is_refused() {
        let parse = |s: &str| s.parse::<FormFactorMethod>().unwrap_err();
        for s in [
            "",
            "radiosity k=2",
            "Area k=2",
            "hemicube-gpu resolution=8",
            " area k=2",
        ] {
            assert_eq!(parse(s), ParseMethodError::UnknownName { text: s.into() });
        }
        for s in [
            "area",
            "area k=",
            "area steps=2",
            "area k=2 k=2",
            "area  k=2",
            "area k=2 ",
            "hemicube k=2",
            "montecarlo samples=4",
            "montecarlo seed=1 samples=4",
            "montecarlo samples=4 seed=1 extra=0",
        ] {
            let err = parse(s);
            assert!(
                matches!(err, ParseMethodError::Settings { ref text, .. } if text == s)
                    || matches!(err, ParseMethodError::Number { ref text, .. } if text == s),
                "{s}: {err:?}"
            );
        }
        let err = parse("area k=two");
        let ParseMethodError::Number { key, value, .. } = &err else {
            panic!("{err:?}")
        };
        assert_eq!((*key, value.as_str()), ("k", "two"));
        assert!(err.to_string().contains("area k=two"), "{err}");
        for s in [
            "area k=-1",
            "area k=4294967296",
            "montecarlo samples=1 seed=18446744073709551616",
        ] {
            assert!(matches!(parse(s), ParseMethodError::Number { .. }), "{s}");
        }
        assert_eq!(
            parse("contour k=+4"),
            ParseMethodError::NotCanonical {
                text: "contour k=+4".into(),
                canonical: "contour k=4".into()
            }
        );
        assert!(matches!(
            parse("hemicube resolution=064"),
            ParseMethodError::NotCanonical { .. }
        ));
    }
}
