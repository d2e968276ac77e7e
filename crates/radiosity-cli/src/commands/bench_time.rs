//! How long `bench`'s repeated runs take: the time limit checked after a configuration's
//! first run, from that run's time, and the progress line while the runs repeat.
//!
//! QA pass 16 of #16: `bench examples/paper196.scene --repeat 1000000` started some 100
//! hours of runs at once and said nothing for a long time. A run's time cannot be known
//! before one is made, so the first run of each configuration is timed, and the rest are
//! refused when they would take longer than [`MAX_BENCH_SECONDS`], saying how many runs
//! fit, as the work budget ([`radiosity::budget`]) refuses a run of hours before it starts.

use std::time::Duration;

use crate::progress_bar::{progress_line_of, seconds_text};

/// Seconds the runs of one configuration may take without `--no-work-limit`: an hour, as
/// the work budget's limits are set at about an hour of the measured rate.
pub const MAX_BENCH_SECONDS: f64 = 3600.0;

/// Checks `repeat` runs of a configuration whose first run took `first_run` against
/// [`MAX_BENCH_SECONDS`]; the error says how long they would take and what would fit.
pub fn check_repeat_time(first_run: Duration, repeat: u32) -> Result<(), String> {
    let each = first_run.as_secs_f64();
    let total = each * repeat as f64;
    if repeat <= 1 || total <= MAX_BENCH_SECONDS {
        return Ok(());
    }
    let most = (MAX_BENCH_SECONDS / each).floor();
    let fits = if most >= 1.0 {
        format!("at most --repeat {most:.0} would fit")
    } else {
        "one run alone takes longer than that: --repeat 1 times it once".to_string()
    };
    Err(format!(
        "--repeat {repeat} at {} a run (the first run, timed) would take about {}, more than \
         the limit of {} for the runs of one configuration; {fits} (or pass --no-work-limit \
         to run them anyway)",
        seconds_text(each),
        seconds_text(total),
        seconds_text(MAX_BENCH_SECONDS)
    ))
}

/// The progress line of the runs so far, as a long stage's: "bench: 25.0 % (250 of 1000
/// runs) after 10 s, about 30 s left".
pub fn repeat_progress_line(done: u32, repeat: u32, elapsed: Duration) -> String {
    progress_line_of(
        "bench",
        Some("runs"),
        done as u64,
        repeat as u64,
        elapsed,
        None,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_million_runs_of_twelve_seconds_are_refused_with_the_runs_that_fit() {
        // 12 s x 1,000,000 = 1.2e7 s, 3333.3 hours; an hour holds 3600 / 12 = 300 runs.
        let err = check_repeat_time(Duration::from_secs(12), 1_000_000).unwrap_err();
        assert!(err.contains("--repeat 1000000 at 12.0 s a run"), "{err}");
        assert!(err.contains("about 3333.3 h"), "{err}");
        assert!(err.contains("at most --repeat 300 would fit"), "{err}");
        assert!(err.contains("--no-work-limit"), "{err}");
        // What it says fits does fit; one more run does not.
        assert!(check_repeat_time(Duration::from_secs(12), 300).is_ok());
        assert!(check_repeat_time(Duration::from_secs(12), 301).is_err());
        // The default five runs of a scene of a few seconds pass.
        assert!(check_repeat_time(Duration::from_secs(3), 5).is_ok());
    }

    #[test]
    fn a_run_longer_than_the_limit_is_timed_once_only() {
        // Two runs of 2 hours: not even one more fits; a single run is never refused (it
        // is already made when its time is known).
        let err = check_repeat_time(Duration::from_secs(7200), 2).unwrap_err();
        assert!(err.contains("--repeat 1 times it once"), "{err}");
        assert!(check_repeat_time(Duration::from_secs(7200), 1).is_ok());
    }

    #[test]
    fn the_progress_line_counts_runs_and_the_time_left() {
        // 250 of 1000 runs in 10 s: 750 more at 0.04 s each, 30 s.
        assert_eq!(
            repeat_progress_line(250, 1000, Duration::from_secs(10)),
            "bench: 25.0 % (250 of 1000 runs) after 10 s, about 30 s left"
        );
    }
}
