//! Progress of a long run on standard error: an `indicatif` bar on a terminal, a plain
//! line now and then when standard error is a file or a pipe (a log), nothing with
//! `--quiet`. Nothing at all for a run shorter than about a second.
//!
//! Workers only bump atomic counters ([`Progress::made`], ...); one reporting thread
//! reads them, so the hot path never touches the terminal.

use std::io::IsTerminal as _;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// How long a run goes before its progress is shown, and how often a plain line is
/// printed after that (the bar redraws ten times a second). `MJCF_FORGE_PROGRESS_SECONDS`
/// sets the period of the plain lines (and shortens the first wait to it when shorter):
/// the tests use it to see lines from a short run.
const FIRST_AFTER: Duration = Duration::from_secs(1);
const LINE_EVERY: Duration = Duration::from_secs(5);
const BAR_EVERY: Duration = Duration::from_millis(100);

/// The counts of a run, bumped by its workers.
#[derive(Default)]
pub struct Progress {
    /// Items made (variants drawn and written as text).
    pub made: AtomicU64,
    /// Items checked by MuJoCo (with `--validate`).
    pub validated: AtomicU64,
    /// Items in the output.
    pub written: AtomicU64,
    /// Items that failed.
    pub failed: AtomicU64,
}

/// How progress is shown.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Show {
    /// Nothing (`--quiet`).
    Nothing,
    /// A bar when standard error is a terminal, else plain lines.
    Auto,
}

impl Progress {
    /// Adds one to `counter`.
    pub fn bump(counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    /// Runs `work` while a reporting thread shows the counts of `total` items; the
    /// reporting stops (the bar is cleared) before this returns.
    pub fn run<T>(&self, total: u64, validating: bool, show: Show, work: impl FnOnce() -> T) -> T {
        if show == Show::Nothing {
            return work();
        }
        let (stop, stopped) = mpsc::channel::<()>();
        std::thread::scope(|s| {
            s.spawn(move || self.report(total, validating, &stopped));
            let result = work();
            drop(stop);
            result
        })
    }

    /// The reporting thread: waits for the first show, then draws until `stopped` closes.
    fn report(&self, total: u64, validating: bool, stopped: &mpsc::Receiver<()>) {
        let started = Instant::now();
        let line_every = std::env::var("MJCF_FORGE_PROGRESS_SECONDS")
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s > 0.0)
            .map_or(LINE_EVERY, Duration::from_secs_f64);
        let first = FIRST_AFTER.min(line_every);
        if stopped.recv_timeout(first) != Err(mpsc::RecvTimeoutError::Timeout) {
            return;
        }
        if std::io::stderr().is_terminal() {
            self.draw_bar(total, validating, started, stopped);
        } else {
            loop {
                eprintln!("{}", self.line(total, validating, started.elapsed()));
                if stopped.recv_timeout(line_every) != Err(mpsc::RecvTimeoutError::Timeout) {
                    return;
                }
            }
        }
    }

    /// The bar; its rate and time left are ours (those of the plain lines), not
    /// indicatif's, whose estimate starts from the first draw, a second into the run.
    fn draw_bar(
        &self,
        total: u64,
        validating: bool,
        started: Instant,
        stopped: &mpsc::Receiver<()>,
    ) {
        let bar = indicatif::ProgressBar::new(total);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} written {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        loop {
            // Counts read after `written`, and the message set first: never fewer made
            // than written on screen.
            let written = self.written.load(Ordering::Relaxed);
            let (rate, left) = rate_and_left(written, total, started.elapsed());
            bar.set_message(format!(
                "({}), {rate:.0}/s, {left}",
                self.counts(validating)
            ));
            bar.set_position(written);
            if stopped.recv_timeout(BAR_EVERY) != Err(mpsc::RecvTimeoutError::Timeout) {
                break;
            }
        }
        bar.finish_and_clear();
    }

    /// `made M, validated V, failed F` (the parts that apply).
    fn counts(&self, validating: bool) -> String {
        let mut s = format!("made {}", self.made.load(Ordering::Relaxed));
        if validating {
            s.push_str(&format!(
                ", validated {}",
                self.validated.load(Ordering::Relaxed)
            ));
        }
        let failed = self.failed.load(Ordering::Relaxed);
        if failed > 0 {
            s.push_str(&format!(", failed {failed}"));
        }
        s
    }

    /// One plain line: `generate: 1200/5000 written (made 1234, validated 1200), 830/s,
    /// about 4.6 s left`.
    fn line(&self, total: u64, validating: bool, elapsed: Duration) -> String {
        let written = self.written.load(Ordering::Relaxed);
        let (rate, left) = rate_and_left(written, total, elapsed);
        format!(
            "generate: {written}/{total} written ({}), {rate:.0}/s, {left}",
            self.counts(validating)
        )
    }
}

/// Items written per second so far, and the time left at that rate, in words.
fn rate_and_left(written: u64, total: u64, elapsed: Duration) -> (f64, String) {
    let rate = written as f64 / elapsed.as_secs_f64().max(1e-9);
    let left = if written == 0 {
        "time left unknown".to_owned()
    } else {
        format!(
            "about {:.1} s left",
            total.saturating_sub(written) as f64 / rate
        )
    };
    (rate, left)
}
