//! The command line's listener on the library's [`Progress`] interface: a progress bar per
//! stage on a terminal (indicatif), silence otherwise, and a record of each stage's time.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use radiosity::progress::{Progress, Stage};

/// Draws progress bars (when enabled) and records stage timings.
pub struct Reporter {
    bars_enabled: bool,
    bar: Mutex<Option<ProgressBar>>,
    timings: Mutex<Vec<(Stage, Duration)>>,
    quiet: bool,
}

impl Reporter {
    /// Bars are drawn only when stderr is a terminal and `quiet` is false.
    pub fn new(quiet: bool) -> Reporter {
        Reporter {
            bars_enabled: !quiet && std::io::stderr().is_terminal(),
            bar: Mutex::new(None),
            timings: Mutex::new(Vec::new()),
            quiet,
        }
    }

    /// Stage timings in the order the stages finished.
    pub fn timings(&self) -> Vec<(Stage, Duration)> {
        self.timings.lock().unwrap().clone()
    }

    /// Prints a line to stderr unless quiet.
    pub fn note(&self, text: &str) {
        if !self.quiet {
            match self.bar.lock().unwrap().as_ref() {
                Some(bar) => bar.println(text),
                None => errln!("{text}"),
            }
        }
    }

    /// Prints the time of each stage and the total to stderr unless quiet.
    pub fn print_timings(&self) {
        if self.quiet {
            return;
        }
        let timings = self.timings();
        let total: Duration = timings.iter().map(|t| t.1).sum();
        let parts: Vec<String> = timings
            .iter()
            .map(|(s, d)| format!("{} {}", s.name(), format_duration(*d)))
            .collect();
        errln!(
            "timings: {}; total {}",
            parts.join(", "),
            format_duration(total)
        );
    }
}

/// Milliseconds below 1 s, seconds above.
pub fn format_duration(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s < 1.0 {
        format!("{:.1} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

impl Progress for Reporter {
    fn start(&self, stage: Stage, total: u64) {
        if !self.bars_enabled || total < 2 {
            return;
        }
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix:>13} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar.set_prefix(stage.name());
        *self.bar.lock().unwrap() = Some(bar);
    }

    fn advance(&self, done: u64) {
        if let Some(bar) = self.bar.lock().unwrap().as_ref() {
            bar.inc(done);
        }
    }

    fn finish(&self, stage: Stage, elapsed: Duration) {
        if let Some(bar) = self.bar.lock().unwrap().take() {
            bar.finish_and_clear();
        }
        self.timings.lock().unwrap().push((stage, elapsed));
    }

    fn message(&self, text: &str) {
        self.note(text);
    }
}
