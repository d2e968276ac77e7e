//! The command line's listener on the library's [`Progress`] interface: a progress bar per
//! stage on a terminal (indicatif); elsewhere (a log file, a pipe, CI) a line on stderr
//! every [`LINE_EVERY`] while a stage runs, so that a long run is never silent for
//! minutes; and a record of each stage's time.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// How often a stage reports when stderr is not a terminal.
pub const LINE_EVERY: Duration = Duration::from_secs(10);

/// The thread that prints a stage's progress lines, and how to stop it.
struct Ticker {
    done: Arc<AtomicU64>,
    stop: Arc<(Mutex<bool>, Condvar)>,
    thread: std::thread::JoinHandle<()>,
}

/// What a stage of unknown length counts, and why it gives no time left: a solver that
/// stops when it has converged cannot say in advance after how many steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Counting {
    /// The steps counted, plural: "sweeps".
    pub unit: &'static str,
    /// One of them: "sweep" (QA of issue #16: "solve: 1 refinement rounds after 10 s").
    pub one: &'static str,
    /// When the steps end: "it sweeps until the change falls below --tolerance".
    pub until: &'static str,
}

impl Counting {
    /// What the solve stage of `solver` counts; `None` for LU, whose total is known.
    pub fn solve(solver: &radiosity::solve::Solver) -> Option<Counting> {
        use radiosity::solve::{DenseSolver, Solver};
        Some(match solver {
            Solver::Dense(DenseSolver::GaussSeidel(_)) => Counting {
                unit: "sweeps",
                one: "sweep",
                until: "Gauss-Seidel sweeps until the change falls below --tolerance",
            },
            Solver::Progressive(_) => Counting {
                unit: "shots",
                one: "shot",
                until: "progressive refinement shoots until the unshot power falls below \
                        --tolerance",
            },
            Solver::Hierarchical(_) => Counting {
                unit: "refinement rounds",
                one: "refinement round",
                until: "hierarchical radiosity refines until a round changes almost no \
                        links (its final gather then counts its points)",
            },
            _ => return None,
        })
    }
}

/// "form factors: 12.5 % (1250 of 10000) after 30 s, about 3.5 min left", or without a
/// total "solve: 1250 steps after 30 s", with what the steps are and why no time left is
/// given when `counting` says so.
pub fn progress_line(
    stage: &str,
    done: u64,
    total: u64,
    elapsed: Duration,
    counting: Option<Counting>,
) -> String {
    progress_line_of(stage, None, done, total, elapsed, counting)
}

/// "12.3 s", "5.0 min", "3416.7 h": a duration in the unit that reads best.
pub fn seconds_text(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.1} s")
    } else if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

/// What a stage's known total counts, where that is not plain (QA of issue #16: the path
/// tracer's progress said "(24 of 64)" of nothing).
pub fn stage_unit(stage: Stage) -> Option<&'static str> {
    match stage {
        Stage::PathTrace | Stage::Render => Some("rows"),
        Stage::Illuminance => Some("points"),
        _ => None,
    }
}

/// [`progress_line`], its total followed by `unit` when given: "(24 of 64 rows)".
pub fn progress_line_of(
    stage: &str,
    unit: Option<&str>,
    done: u64,
    total: u64,
    elapsed: Duration,
    counting: Option<Counting>,
) -> String {
    let secs = elapsed.as_secs_f64();
    if total < 2 {
        return match counting {
            Some(c) => format!(
                "{stage}: {done} {} after {secs:.0} s (no time left can be estimated: {})",
                if done == 1 { c.one } else { c.unit },
                c.until
            ),
            // A stage that reports no steps (meshing, a whole-scene pass) is only said
            // to be running (QA of issue #16: "mesh: 0 steps after 10 s").
            None if done == 0 => format!("{stage}: still running after {secs:.0} s"),
            None => format!(
                "{stage}: {done} {} after {secs:.0} s",
                if done == 1 { "step" } else { "steps" }
            ),
        };
    }
    let fraction = done as f64 / total as f64;
    let left = if done > 0 {
        let s = secs * (1.0 - fraction) / fraction;
        if s < 120.0 {
            format!(", about {s:.0} s left")
        } else {
            format!(", about {} left", seconds_text(s))
        }
    } else {
        String::new()
    };
    let unit = unit.map_or(String::new(), |u| format!(" {u}"));
    format!(
        "{stage}: {:.1} % ({done} of {total}{unit}) after {secs:.0} s{left}",
        100.0 * fraction
    )
}

/// [`progress_line_of`] of `stage` with where it stands ([`Progress::status`]) after it; a
/// stage of unknown length with a status says that instead of why no time left is given:
/// "solve: 1208 shots after 10 s, unshot power 19.8 % of the emitted (stops below 1.0 %)".
pub fn status_line(
    stage: Stage,
    done: u64,
    total: u64,
    elapsed: Duration,
    counting: Option<Counting>,
    status: Option<&str>,
) -> String {
    match (status, counting) {
        (Some(now), Some(c)) if total < 2 => format!(
            "{}: {done} {} after {:.0} s, {now}",
            stage.name(),
            if done == 1 { c.one } else { c.unit },
            elapsed.as_secs_f64()
        ),
        _ => {
            let line = progress_line_of(
                stage.name(),
                stage_unit(stage),
                done,
                total,
                elapsed,
                counting,
            );
            match status {
                Some(now) => format!("{line}; {now}"),
                None => line,
            }
        }
    }
}

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use radiosity::progress::{Progress, Stage};

/// Draws progress bars (when enabled) and records stage timings.
pub struct Reporter {
    bars_enabled: bool,
    /// Progress lines instead of bars (stderr is not a terminal, not quiet).
    lines_enabled: bool,
    ticker: Mutex<Option<Ticker>>,
    bar: Mutex<Option<ProgressBar>>,
    timings: Mutex<Vec<(Stage, Duration)>>,
    /// What a timed stage worked on, by its index in `timings` ([`Reporter::name_last`]).
    subjects: Mutex<Vec<(usize, String)>>,
    /// What the stages finishing now work for ([`Reporter::stages_for`]).
    purpose: Mutex<Option<String>>,
    quiet: bool,
    /// What the solve stage counts (see [`Reporter::solving_with`]).
    solve_counting: Mutex<Option<Counting>>,
    /// Where the running stage stands ([`Progress::status`]), shown with its progress.
    status: Arc<Mutex<Option<String>>>,
}

impl Reporter {
    /// Bars are drawn only when stderr is a terminal and `quiet` is false.
    pub fn new(quiet: bool) -> Reporter {
        let terminal = std::io::stderr().is_terminal();
        Reporter {
            bars_enabled: !quiet && terminal,
            lines_enabled: !quiet && !terminal,
            ticker: Mutex::new(None),
            bar: Mutex::new(None),
            timings: Mutex::new(Vec::new()),
            subjects: Mutex::new(Vec::new()),
            purpose: Mutex::new(None),
            quiet,
            solve_counting: Mutex::new(None),
            status: Arc::new(Mutex::new(None)),
        }
    }

    /// Progress (bars or lines) unless `quiet`, but no notes or timings: for `check`, which
    /// prints its own report.
    pub fn progress_only(quiet: bool) -> Reporter {
        let terminal = std::io::stderr().is_terminal();
        Reporter {
            bars_enabled: !quiet && terminal,
            lines_enabled: !quiet && !terminal,
            ..Reporter::new(true)
        }
    }

    /// The solve stages from now on are `solver`'s: their progress lines say what they
    /// count and why they give no time left.
    pub fn solving_with(&self, solver: &radiosity::solve::Solver) {
        *self.solve_counting.lock().unwrap() = Counting::solve(solver);
    }

    /// Names what the stage timed last worked on, for its timing label: "write
    /// out-error.png" (QA of issue #16: "write #1, write #2, write #3" did not say which
    /// file took the time).
    pub fn name_last(&self, subject: &str) {
        let count = self.timings.lock().unwrap().len();
        if let Some(last) = count.checked_sub(1) {
            self.subjects
                .lock()
                .unwrap()
                .push((last, subject.to_string()));
        }
    }

    /// Labels the stages that finish from now on with what they work for, "(dense
    /// reference)", until called with `None` (QA of issue #16: `compare` printed "solve #1,
    /// solve #2" for the solver tested and its reference).
    pub fn stages_for(&self, purpose: Option<&str>) {
        *self.purpose.lock().unwrap() = purpose.map(|p| format!("({p})"));
    }

    /// Stage timings with distinct labels: a stage named by [`Reporter::name_last`] is
    /// labelled with what it worked on, "write out.png"; a label that still occurs more
    /// than once (the solves of adaptive subdivision) is numbered, "solve #2", "solve
    /// (gauss-seidel, tested) #2".
    pub fn labelled_timings(&self) -> Vec<(String, Duration)> {
        let timings = self.timings();
        let subjects = self.subjects.lock().unwrap().clone();
        let labels: Vec<String> = timings
            .iter()
            .enumerate()
            .map(
                |(i, &(stage, _))| match subjects.iter().rev().find(|s| s.0 == i) {
                    Some((_, subject)) => format!("{} {subject}", stage.name()),
                    None => stage.name().to_string(),
                },
            )
            .collect();
        let mut seen: Vec<(&str, usize)> = Vec::new();
        labels
            .iter()
            .zip(&timings)
            .map(|(label, &(_, d))| {
                let runs = labels.iter().filter(|l| *l == label).count();
                if runs == 1 {
                    return (label.clone(), d);
                }
                let k = match seen.iter_mut().find(|s| s.0 == label) {
                    Some(s) => {
                        s.1 += 1;
                        s.1
                    }
                    None => {
                        seen.push((label, 1));
                        1
                    }
                };
                (format!("{label} #{k}"), d)
            })
            .collect()
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
        let timings = self.labelled_timings();
        let total: Duration = timings.iter().map(|t| t.1).sum();
        let parts: Vec<String> = timings
            .iter()
            .map(|(s, d)| format!("{s} {}", format_duration(*d)))
            .collect();
        errln!(
            "timings: {}; total {}",
            parts.join(", "),
            format_duration(total)
        );
    }
}

impl Reporter {
    /// Starts the thread that prints a line every [`LINE_EVERY`] until the stage finishes
    /// (stages that finish sooner print nothing).
    fn start_ticker(&self, stage: Stage, total: u64) {
        self.stop_ticker();
        let done = Arc::new(AtomicU64::new(0));
        let stop = Arc::new((Mutex::new(false), Condvar::new()));
        let (d, st) = (done.clone(), stop.clone());
        let counting = match stage {
            Stage::Solve => *self.solve_counting.lock().unwrap(),
            _ => None,
        };
        let started = Instant::now();
        let status = self.status.clone();
        let spawned = std::thread::Builder::new()
            .name("progress".into())
            .spawn(move || {
                let (lock, wake) = &*st;
                let mut stopped = lock.lock().unwrap();
                // The flag is read under the lock before each wait, so a stop that came
                // before the first wait is not slept through.
                while !*stopped {
                    let (guard, timeout) = wake.wait_timeout(stopped, LINE_EVERY).unwrap();
                    stopped = guard;
                    if *stopped {
                        return;
                    }
                    if timeout.timed_out() {
                        let line = status_line(
                            stage,
                            d.load(Ordering::Relaxed),
                            total,
                            started.elapsed(),
                            counting,
                            status.lock().unwrap().as_deref(),
                        );
                        errln!("{line}");
                    }
                }
            });
        if let Ok(thread) = spawned {
            *self.ticker.lock().unwrap() = Some(Ticker { done, stop, thread });
        }
    }

    fn stop_ticker(&self) {
        if let Some(ticker) = self.ticker.lock().unwrap().take() {
            let (lock, wake) = &*ticker.stop;
            *lock.lock().unwrap() = true;
            wake.notify_all();
            let _ = ticker.thread.join();
        }
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
    fn file(&self, name: &str) {
        self.name_last(name);
    }

    fn start(&self, stage: Stage, total: u64) {
        *self.status.lock().unwrap() = None;
        if self.lines_enabled {
            self.start_ticker(stage, total);
        }
        if !self.bars_enabled {
            return;
        }
        if total < 2 {
            // A solve of unknown length shows a spinner with its count and status (QA pass
            // 15 of #16: a terminal showed nothing while progressive refinement shot).
            let counting = match stage {
                Stage::Solve => *self.solve_counting.lock().unwrap(),
                _ => None,
            };
            if let Some(c) = counting {
                let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
                let template = format!(
                    "{{prefix:>13}} {{spinner}} {{pos}} {} {{elapsed_precise}} {{msg}}",
                    c.unit
                );
                bar.set_style(
                    ProgressStyle::with_template(&template)
                        .unwrap_or_else(|_| ProgressStyle::default_spinner()),
                );
                bar.set_prefix(stage.name());
                bar.enable_steady_tick(Duration::from_millis(250));
                *self.bar.lock().unwrap() = Some(bar);
            }
            return;
        }
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        let template = match stage_unit(stage) {
            Some(unit) => format!(
                "{{prefix:>13}} [{{bar:40}}] {{percent:>3}}% ({{pos}} of {{len}} {unit}) \
                 {{elapsed_precise}} eta {{eta}}"
            ),
            None => "{prefix:>13} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}".into(),
        };
        bar.set_style(
            ProgressStyle::with_template(&template)
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.set_prefix(stage.name());
        *self.bar.lock().unwrap() = Some(bar);
    }

    fn advance(&self, done: u64) {
        if let Some(ticker) = self.ticker.lock().unwrap().as_ref() {
            ticker.done.fetch_add(done, Ordering::Relaxed);
        }
        if let Some(bar) = self.bar.lock().unwrap().as_ref() {
            bar.inc(done);
        }
    }

    fn finish(&self, stage: Stage, elapsed: Duration) {
        self.stop_ticker();
        if let Some(bar) = self.bar.lock().unwrap().take() {
            bar.finish_and_clear();
        }
        let mut timings = self.timings.lock().unwrap();
        timings.push((stage, elapsed));
        if let Some(purpose) = self.purpose.lock().unwrap().clone() {
            self.subjects
                .lock()
                .unwrap()
                .push((timings.len() - 1, purpose));
        }
    }

    fn message(&self, text: &str) {
        self.note(text);
    }

    fn status(&self, text: &str) {
        *self.status.lock().unwrap() = Some(text.to_string());
        if let Some(bar) = self.bar.lock().unwrap().as_ref() {
            bar.set_message(text.to_string());
        }
    }
}

/// Runs `work` as `stage` of `reporter`, its timing labelled with the file it reads or
/// writes ([`Reporter::name_last`]): "write out.png", "parse room.scene".
pub fn run_file_stage<T>(
    reporter: &Reporter,
    stage: Stage,
    path: &std::path::Path,
    work: impl FnOnce() -> T,
) -> T {
    let out = radiosity::progress::run_stage(reporter, stage, 0, work);
    let name = path.file_name().unwrap_or(path.as_os_str());
    reporter.name_last(&name.to_string_lossy());
    out
}

#[cfg(test)]
mod tests {

    #[test]
    fn a_stage_without_steps_is_said_to_be_running() {
        // QA of issue #16: meshing printed "mesh: 0 steps after 10 s".
        let line = progress_line("mesh", 0, 0, Duration::from_secs(10), None);
        assert_eq!(line, "mesh: still running after 10 s");
        let line = progress_line("solve", 3, 0, Duration::from_secs(10), None);
        assert_eq!(line, "solve: 3 steps after 10 s");
    }
    use super::*;

    #[test]
    fn progress_lines_say_how_far_and_how_long_is_left() {
        // A quarter done after 30 s: 90 s left at the same rate.
        assert_eq!(
            progress_line("form factors", 250, 1000, Duration::from_secs(30), None),
            "form factors: 25.0 % (250 of 1000) after 30 s, about 90 s left"
        );
        // 1 % after 60 s: 99 minutes left.
        assert_eq!(
            progress_line("render", 1, 100, Duration::from_secs(60), None),
            "render: 1.0 % (1 of 100) after 60 s, about 99.0 min left"
        );
        assert_eq!(
            progress_line("solve", 17, 0, Duration::from_secs(10), None),
            "solve: 17 steps after 10 s"
        );
        // The path tracer's total is rows of the image (QA of issue #16).
        assert_eq!(
            progress_line_of(
                Stage::PathTrace.name(),
                stage_unit(Stage::PathTrace),
                16,
                64,
                Duration::from_secs(10),
                None
            ),
            "path trace: 25.0 % (16 of 64 rows) after 10 s, about 30 s left"
        );
    }

    #[test]
    fn a_solve_of_unknown_length_says_what_it_counts_and_why_no_time_left() {
        // QA of issue #16: hierarchical radiosity's "solve: 17 steps after 30 s" said
        // neither what a step is nor why no time left was given.
        let hierarchical = radiosity::solve::Solver::Hierarchical(
            radiosity::solve::HierarchicalSettings::defaults_for(1.0),
        );
        let line = progress_line(
            "solve",
            17,
            0,
            Duration::from_secs(30),
            Counting::solve(&hierarchical),
        );
        assert!(
            line.starts_with(
                "solve: 17 refinement rounds after 30 s (no time left can be estimated: "
            ),
            "{line}"
        );
        // One of them is one.
        let line = progress_line(
            "solve",
            1,
            0,
            Duration::from_secs(10),
            Counting::solve(&hierarchical),
        );
        assert!(
            line.starts_with("solve: 1 refinement round after 10 s"),
            "{line}"
        );
        // LU knows its total: it gets the percentage and the time left instead.
        assert_eq!(Counting::solve(&radiosity::solve::Solver::LU), None);
    }

    #[test]
    fn a_status_stands_in_for_why_no_time_left() {
        // QA pass 15 of #16: progressive refinement's lines counted shots and said nothing
        // of how far the solve was from its end.
        let progressive =
            radiosity::solve::Solver::Progressive(radiosity::solve::ProgressiveSettings {
                tolerance: 0.01,
                max_shots: 1000,
            });
        let status = "unshot power 19.8 % of the emitted (stops below 1.0 %)";
        let line = status_line(
            Stage::Solve,
            1208,
            0,
            Duration::from_secs(10),
            Counting::solve(&progressive),
            Some(status),
        );
        assert_eq!(line, format!("solve: 1208 shots after 10 s, {status}"));
        // Without a status, the reason; a stage with a total keeps its time left.
        let line = status_line(
            Stage::Solve,
            1208,
            0,
            Duration::from_secs(10),
            Counting::solve(&progressive),
            None,
        );
        assert!(line.contains("(no time left can be estimated: "), "{line}");
        let line = status_line(
            Stage::Solve,
            5,
            10,
            Duration::from_secs(10),
            None,
            Some("status"),
        );
        assert_eq!(
            line,
            "solve: 50.0 % (5 of 10) after 10 s, about 10 s left; status"
        );
    }

    #[test]
    fn checks_reporter_shows_progress_but_no_notes() {
        // QA of issue #16: `check` reported through a quiet reporter, so its 40 s
        // form-factor stage on building_small printed no progress at all.
        let r = Reporter::progress_only(false);
        assert!(r.bars_enabled || r.lines_enabled);
        assert!(r.quiet, "its notes are in the report");
        let q = Reporter::progress_only(true);
        assert!(!q.bars_enabled && !q.lines_enabled);
    }

    #[test]
    fn repeated_stages_get_distinct_labels() {
        // QA of issue #16: the timings of adaptive subdivision read "solve 1 s, ..., solve
        // 2 s", of pathtrace --compare "write ..., write ...".
        let reporter = Reporter::new(true);
        for stage in [
            Stage::Parse,
            Stage::Solve,
            Stage::Adapt,
            Stage::Solve,
            Stage::Write,
        ] {
            reporter.finish(stage, Duration::from_millis(1));
        }
        let labels: Vec<String> = reporter
            .labelled_timings()
            .into_iter()
            .map(|t| t.0)
            .collect();
        assert_eq!(labels, ["parse", "solve #1", "adapt", "solve #2", "write"]);
    }
}
