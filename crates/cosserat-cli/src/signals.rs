//! SIGINT, SIGTERM and SIGHUP. A cluster scheduler sends SIGTERM before it
//! kills a job, a closed terminal SIGHUP. Commands that work point by point
//! (`continue`, `optimize`, `sweep`) stop at their next point, write what
//! they have as a valid resumable file, say so and exit with
//! [`crate::exit::INTERRUPTED`]. Commands that compute one result (`solve`,
//! `stability`, `plot`, `merge`) have nothing to keep: they stop at once,
//! removing their lock and temporary files, with the same exit code.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// The process-wide stop flag, set by the signal handler.
static STOP: AtomicBool = AtomicBool::new(false);

/// How the handler answers: 0 at once, 1 at the next point.
static MODE: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(0);

/// Files to remove when the process stops at once.
static LITTER: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// How a command answers a stop signal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Set the flag; the command stops at its next point.
    NextPoint,
    /// Remove the registered files and exit now.
    Immediate,
}

/// Installs the handler (once, at start), stopping at once until
/// [`set_mode`] says otherwise: while a command reads its input there is
/// nothing to keep.
pub fn install() {
    // If installing fails the default action stays (the process ends);
    // outputs are written atomically, so no partial file is left even then.
    let _ = ctrlc::set_handler(move || {
        let first = !STOP.swap(true, Ordering::SeqCst);
        let mode = if MODE.load(Ordering::SeqCst) == 1 {
            Mode::NextPoint
        } else {
            Mode::Immediate
        };
        match mode {
            Mode::NextPoint if first => eprintln!(
                "stopping at the next point (finished work is kept; send the signal again to wait no longer)"
            ),
            _ => {
                remove_litter();
                eprintln!("interrupted");
                // _exit, not exit: the main thread may be inside the HDF5
                // library, whose exit-time clean-up must not run under it.
                // SAFETY: _exit only ends the process; no Rust state is
                // touched afterwards.
                unsafe { libc::_exit(i32::from(crate::exit::INTERRUPTED)) }
            }
        }
    });
}

/// How the next signal is answered: a command that keeps finished points
/// switches to [`Mode::NextPoint`] when its work begins.
pub fn set_mode(mode: Mode) {
    MODE.store(u8::from(mode == Mode::NextPoint), Ordering::SeqCst);
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    STOP.load(Ordering::SeqCst)
}

/// The flag itself, for code that takes an `&AtomicBool`.
pub fn flag() -> &'static AtomicBool {
    &STOP
}

/// Registers a file to remove if the process stops at once.
pub fn litter(path: PathBuf) {
    if let Ok(mut l) = LITTER.lock() {
        l.push(path);
    }
}

fn remove_litter() {
    if let Ok(l) = LITTER.lock() {
        for p in l.iter() {
            let _ = std::fs::remove_file(p);
        }
    }
}
