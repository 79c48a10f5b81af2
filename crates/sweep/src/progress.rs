//! Progress of a phase whose drops take seconds (a critical search, the orbit drops):
//! a spinner with a count on a terminal, a plain line every few seconds when standard
//! error is not a terminal (a log file, a batch job), and nothing when switched off.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Writes a progress line to standard error; a closed standard error is ignored (progress is
/// not the result, and `eprintln!` would panic).
pub fn progress_line(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// How often a plain progress line is written.
pub(crate) const PLAIN_EVERY: Duration = Duration::from_secs(5);

/// The clock of plain progress lines, shared by the worker threads: a line is due at most
/// once every [`PLAIN_EVERY`].
pub(crate) struct PlainClock(Mutex<Instant>);

impl PlainClock {
    /// A clock whose first line is due [`PLAIN_EVERY`] from now.
    pub(crate) fn new() -> Self {
        Self(Mutex::new(Instant::now()))
    }

    /// Whether a line is due now; if so, the next one is due [`PLAIN_EVERY`] later.
    pub(crate) fn due(&self) -> bool {
        let mut last = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let due = last.elapsed() >= PLAIN_EVERY;
        if due {
            *last = Instant::now();
        }
        due
    }
}

/// Counts finished drops of one phase and reports them; shared by the worker threads.
pub struct Ticker {
    label: String,
    /// Drops known to be coming (a critical search learns its bisections as it goes).
    expected: AtomicUsize,
    done: AtomicUsize,
    bar: Option<ProgressBar>,
    plain: bool,
    start: Instant,
    clock: PlainClock,
}

impl Ticker {
    /// A ticker for `label` (`critical mu 0.25-0.5`) expecting `expected` drops, shown when
    /// `on`: a bar on a terminal, else plain lines.
    pub fn new(label: &str, expected: usize, on: bool) -> Self {
        let tty = std::io::stderr().is_terminal();
        let bar = (on && tty).then(|| {
            let b =
                ProgressBar::with_draw_target(Some(expected as u64), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} drops, ETA {eta}")
                    .expect("valid template")
                    .progress_chars("=> "),
            );
            b.set_message(label.to_string());
            b
        });
        Self {
            label: label.to_string(),
            expected: AtomicUsize::new(expected),
            done: AtomicUsize::new(0),
            bar,
            plain: on && !tty,
            start: Instant::now(),
            clock: PlainClock::new(),
        }
    }

    /// A ticker that shows nothing.
    pub fn off() -> Self {
        Self::new("", 0, false)
    }

    /// `n` more drops are coming than were expected (bisection steps).
    pub fn expect_more(&self, n: usize) {
        let total = self.expected.fetch_add(n, Ordering::Relaxed) + n;
        if let Some(b) = &self.bar {
            b.set_length(total as u64);
        }
    }

    /// `n` of the drops expected will not run after all (answered from memory), though never
    /// fewer than are done.
    pub fn expect_fewer(&self, n: usize) {
        let done = self.done.load(Ordering::Relaxed);
        let update = |e: usize| Some(e.saturating_sub(n).max(done));
        let old = (self.expected)
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, update)
            .expect("the update always gives a value");
        if let Some(b) = &self.bar {
            b.set_length(update(old).unwrap_or(old) as u64);
        }
    }

    /// Drops expected so far.
    pub fn expected(&self) -> usize {
        self.expected.load(Ordering::Relaxed)
    }

    /// One drop is done.
    pub fn tick(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if done > self.expected.load(Ordering::Relaxed) {
            self.expect_more(1);
        }
        if let Some(b) = &self.bar {
            b.inc(1);
        }
        if self.plain && self.clock.due() {
            progress_line(&self.line());
        }
    }

    /// Drops done so far.
    pub fn done(&self) -> usize {
        self.done.load(Ordering::Relaxed)
    }

    /// The plain progress line.
    pub fn line(&self) -> String {
        format!(
            "{}: {} of {} drops, {:.0} s",
            self.label,
            self.done.load(Ordering::Relaxed),
            self.expected.load(Ordering::Relaxed),
            self.start.elapsed().as_secs_f64()
        )
    }

    /// Clears the bar; a plain ticker that ran long enough to print writes its last line.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
        if self.plain && self.start.elapsed() >= PLAIN_EVERY {
            progress_line(&self.line());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_past_the_expected_number_grow_it() {
        let t = Ticker::off();
        t.expect_more(2);
        for _ in 0..3 {
            t.tick();
        }
        assert_eq!(t.done(), 3);
        assert!(t.line().contains("3 of 3 drops"), "{}", t.line());
    }

    #[test]
    fn drops_answered_from_memory_leave_the_total_but_never_below_the_count() {
        let t = Ticker::off();
        t.expect_more(5);
        t.tick();
        t.expect_fewer(2);
        assert_eq!(t.expected(), 3);
        t.expect_fewer(9);
        assert_eq!(t.expected(), 1, "not below the one done");
        assert!(t.line().contains("1 of 1 drops"), "{}", t.line());
    }
}
