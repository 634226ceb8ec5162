//! Where a run stands and why a branch ended: values, not strings. They
//! are written to result files as their names (`RunState::name`, the
//! `Display` of `BranchEnd`) and read back by name, so that a resumed run
//! writes the same text an uninterrupted one does.

use std::fmt;

/// How a whole run (a diagram, a sweep, an arm study) stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunState {
    /// Running: what a checkpoint records (resumable).
    InProgress,
    /// Every point asked for is computed.
    Completed,
    /// Stopped by a signal; the finished points are kept (resumable).
    Interrupted,
    /// A merge of shard files that does not hold every point.
    Partial,
}

impl RunState {
    /// The name in result files.
    pub fn name(self) -> &'static str {
        match self {
            RunState::InProgress => "in progress",
            RunState::Completed => "completed",
            RunState::Interrupted => "interrupted",
            RunState::Partial => "partial",
        }
    }

    /// The state of a name; `running` is what sweep files of earlier
    /// versions wrote for a checkpoint.
    pub fn from_name(name: &str) -> Option<RunState> {
        match name {
            "in progress" | "running" => Some(RunState::InProgress),
            "completed" => Some(RunState::Completed),
            "interrupted" => Some(RunState::Interrupted),
            "partial" => Some(RunState::Partial),
            _ => None,
        }
    }

    /// Whether `--resume` has something to do.
    pub fn resumable(self) -> bool {
        matches!(self, RunState::InProgress | RunState::Interrupted)
    }
}

impl fmt::Display for RunState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl PartialEq<&str> for RunState {
    fn eq(&self, other: &&str) -> bool {
        self.name() == *other
    }
}

/// Why a branch ended. Two ends are equal when they say the same thing: a
/// branch end read back from a file ([`BranchEnd::Recorded`]) equals the
/// end it was written from.
#[derive(Debug, Clone)]
pub enum BranchEnd {
    /// Still being followed (what a checkpoint records).
    InProgress,
    /// Stopped by a signal after its last point.
    Interrupted,
    /// A step left the parameter bounds (and could not land on them).
    LeftBounds {
        /// The parameter of the last point.
        parameter: f64,
        /// The bounds.
        bounds: (f64, f64),
    },
    /// The branch landed exactly on a bound.
    ReachedBound(f64),
    /// The branch has the most points allowed.
    MaxPoints(usize),
    /// The tip turned by the angle limit (degrees).
    TipAngle(f64),
    /// A measure reached a stop value (`continuation.stop_at`): landed on
    /// it, or passed it where the shortened step failed.
    ReachedValue {
        /// The measure's name.
        measure: String,
        /// The stop value.
        value: f64,
        /// Whether the last point lies on the value (to the stop's
        /// tolerance) rather than past it.
        landed: bool,
    },
    /// The step fell below the smallest step: the corrector does not
    /// converge there.
    StepTooSmall(f64),
    /// The loads have no potential at the next point (e.g. a dead tip
    /// couple grown from zero on a spatial rod): the second variation no
    /// longer decides stability, so the branch ends at the last point
    /// where it does.
    NotConservative {
        /// The parameter of the point refused.
        parameter: f64,
        /// Why the loads have no potential there.
        reason: String,
    },
    /// The branch came back to its first point, travelling the same way:
    /// a closed branch (a loop), followed once.
    Closed(usize),
    /// A point could not be evaluated.
    Failed(String),
    /// The branch's first point could not be evaluated.
    StartFailed(String),
    /// An ended branch read back from a file, by its text.
    Recorded(String),
}

impl BranchEnd {
    /// Whether the branch goes on when the run is resumed.
    pub fn resumable(&self) -> bool {
        matches!(self, BranchEnd::InProgress | BranchEnd::Interrupted)
    }

    /// The end of a branch from its text in a file.
    pub fn from_text(text: &str) -> BranchEnd {
        match text {
            "in progress" => BranchEnd::InProgress,
            "interrupted" => BranchEnd::Interrupted,
            other => BranchEnd::Recorded(other.to_string()),
        }
    }
}

impl fmt::Display for BranchEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BranchEnd::InProgress => f.write_str("in progress"),
            BranchEnd::Interrupted => f.write_str("interrupted"),
            BranchEnd::LeftBounds {
                parameter,
                bounds: (lo, hi),
            } => write!(f, "parameter {parameter} left [{lo}, {hi}]"),
            BranchEnd::ReachedBound(b) => write!(f, "reached the bound {b}"),
            BranchEnd::MaxPoints(n) => write!(f, "{n} points"),
            BranchEnd::TipAngle(deg) => write!(f, "tip angle {deg:.2}° reached"),
            BranchEnd::ReachedValue {
                measure,
                value,
                landed: true,
            } => write!(f, "reached {measure} = {value}"),
            BranchEnd::ReachedValue {
                measure,
                value,
                landed: false,
            } => write!(
                f,
                "passed {measure} = {value} in its last step, which could not be shortened onto it"
            ),
            BranchEnd::StepTooSmall(min) => write!(
                f,
                "step size below {min:.1e}: the corrector does not converge"
            ),
            BranchEnd::NotConservative { parameter, reason } => write!(
                f,
                "loads not conservative at parameter {parameter}, where stability has no \
                 meaning: {reason}"
            ),
            BranchEnd::Closed(points) => write!(
                f,
                "closed: back at its first point after {points} points (a loop, followed once)"
            ),
            BranchEnd::Failed(e) => write!(f, "stopped: {e}"),
            BranchEnd::StartFailed(e) => write!(f, "start point failed: {e}"),
            BranchEnd::Recorded(text) => f.write_str(text),
        }
    }
}

impl PartialEq for BranchEnd {
    fn eq(&self, other: &BranchEnd) -> bool {
        self.to_string() == other.to_string()
    }
}

impl PartialEq<&str> for BranchEnd {
    fn eq(&self, other: &&str) -> bool {
        let text = self.to_string();
        text.as_str() == *other
    }
}
