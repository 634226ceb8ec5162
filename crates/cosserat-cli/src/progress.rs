//! Meter of a long command: a bar or spinner on a terminal; elsewhere
//! (a cluster log, a pipe) one plain line on stderr every few seconds —
//! done/total, rate, time left — so a log shows the run is alive.
//!
//! The interval is 10 s, or `COSSERAT_PROGRESS_SECONDS` (0: every update).

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// A bar or spinner on a terminal, timed plain lines elsewhere.
pub struct Meter {
    bar: Option<ProgressBar>,
    lines: Mutex<Lines>,
}

struct Lines {
    start: Instant,
    last: Option<Instant>,
    every: Duration,
    total: Option<u64>,
    first: u64,
    position: u64,
    message: String,
}

fn interval() -> Duration {
    let seconds = std::env::var("COSSERAT_PROGRESS_SECONDS")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v >= 0.0)
        .unwrap_or(10.0);
    Duration::from_secs_f64(seconds)
}

impl Meter {
    fn with(bar: Option<ProgressBar>, total: Option<u64>, done: u64) -> Meter {
        Meter {
            bar,
            lines: Mutex::new(Lines {
                start: Instant::now(),
                last: None,
                every: interval(),
                total,
                first: done,
                position: done,
                message: String::new(),
            }),
        }
    }

    /// Work of unknown length (continuation): a spinner with a message.
    pub fn spinner() -> Meter {
        if !std::io::stderr().is_terminal() {
            return Meter::with(None, None, 0);
        }
        let b = ProgressBar::new_spinner();
        b.set_style(
            ProgressStyle::with_template("{spinner} {msg} [{elapsed}]").expect("a valid template"),
        );
        Meter::with(Some(b), None, 0)
    }

    /// `total` points, `done` of them already finished (a resumed run).
    pub fn counted(total: usize, done: usize) -> Meter {
        let (total, done) = (total as u64, done as u64);
        if !std::io::stderr().is_terminal() {
            return Meter::with(None, Some(total), done);
        }
        let bar = ProgressBar::new(total);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} points [{elapsed} < {eta}]")
                .expect("a valid template"),
        );
        bar.set_position(done);
        Meter::with(Some(bar), Some(total), done)
    }

    /// The message of a spinner (and of the plain line).
    pub fn set_message(&self, message: String) {
        if let Some(b) = &self.bar {
            b.set_message(message);
            return;
        }
        self.update(|l| l.message = message);
    }

    /// Redraws a spinner; a plain line if it is due.
    pub fn tick(&self) {
        match &self.bar {
            Some(b) => b.tick(),
            None => self.update(|_| ()),
        }
    }

    /// Points finished so far.
    pub fn set_position(&self, position: u64) {
        match &self.bar {
            Some(b) => b.set_position(position),
            None => self.update(|l| l.position = position),
        }
    }

    /// A line that does not break the bar.
    pub fn println(&self, line: String) {
        match &self.bar {
            Some(b) => b.println(line),
            None => eprintln!("{line}"),
        }
    }

    /// Removes the bar; elsewhere a last line if the run was reported.
    pub fn finish_and_clear(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
            return;
        }
        let lines = self
            .lines
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if lines.last.is_some() {
            eprintln!("{}", lines.line(Instant::now()));
        }
    }

    fn update(&self, change: impl FnOnce(&mut Lines)) {
        let mut lines = self
            .lines
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        change(&mut lines);
        let now = Instant::now();
        let due = lines.last.map_or(now - lines.start, |t| now - t) >= lines.every;
        if due {
            lines.last = Some(now);
            eprintln!("{}", lines.line(now));
        }
    }
}

impl Lines {
    /// "progress  12/40 points, 0.53/s, 53 s left [23 s]" or, without a
    /// total, "progress  <message> [23 s]".
    fn line(&self, now: Instant) -> String {
        let elapsed = (now - self.start).as_secs_f64();
        match self.total {
            Some(total) => {
                let done = self.position.saturating_sub(self.first);
                let rate = done as f64 / elapsed.max(1e-9);
                let left = total.saturating_sub(self.position) as f64;
                let eta = if done > 0 {
                    format!("{:.0} s left", left / rate)
                } else {
                    "time left unknown".into()
                };
                format!(
                    "progress  {}/{total} points, {rate:.3}/s, {eta} [{elapsed:.0} s]",
                    self.position
                )
            }
            None => format!("progress  {} [{elapsed:.0} s]", self.message),
        }
    }
}
