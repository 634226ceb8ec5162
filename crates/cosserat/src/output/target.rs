//! Output files claimed before any work: every path a command will write
//! is checked when the command starts (so a mistyped directory costs
//! nothing), locked against a second process writing the same file, and
//! only ever replaces a regular file that is not one of the command's
//! inputs.
//!
//! A claim holds an advisory lock (`flock`) on a lock file beside the
//! output, `.<name>.lock`; the kernel releases it when the process dies, so
//! a killed run never blocks the next one, and the lock file is removed
//! when the claim is dropped. Temporary files of an earlier killed run
//! (`.<name>.*.tmp`) are removed when the output is claimed: under the lock
//! no other process can be writing them.

use std::fs::{File, OpenOptions};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// Why an output cannot be claimed.
#[derive(Debug, thiserror::Error)]
pub enum ClaimError {
    /// The path exists and neither `--force` nor `--resume` was given.
    #[error("{0} exists; pass --force to overwrite it")]
    Exists(String),
    /// The path exists and is not a regular file (a directory, a device
    /// such as /dev/null, a FIFO, a symbolic link).
    #[error("{path} is {what}, not a regular file; cosserat only ever replaces regular files")]
    NotRegular {
        /// The output path.
        path: String,
        /// What it is instead ("a directory", "a symbolic link", …).
        what: &'static str,
    },
    /// The path is an input of the same command.
    #[error("{path} is also an input of this command ({input}); write the result elsewhere")]
    IsInput {
        /// The output path.
        path: String,
        /// The input it names (as given).
        input: String,
    },
    /// Two outputs of one command are the same file.
    #[error("{path} is named twice as an output of this command")]
    Twice {
        /// The output path named twice.
        path: String,
    },
    /// The directory does not exist or cannot be written.
    #[error("cannot write {path}: {reason}")]
    Directory {
        /// The output path.
        path: String,
        /// Why its directory cannot be written.
        reason: String,
    },
    /// Another process holds the lock.
    #[error(
        "another cosserat process is writing {path} (its lock {lock} is held); \
         wait for it or write elsewhere"
    )]
    Locked {
        /// The output path.
        path: String,
        /// The lock file held by the other process.
        lock: String,
    },
}

/// What a command reads, to be sure it never overwrites it.
pub type Inputs<'a> = &'a [&'a Path];

/// An output path checked and locked for this process. Dropping it releases
/// the lock and removes the lock file.
#[derive(Debug)]
pub struct Claim {
    path: PathBuf,
    lock_path: PathBuf,
    _lock: File,
}

impl Claim {
    /// The claimed path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The lock file and this process's temporary file: what to remove if
    /// the process has to stop without unwinding.
    pub fn scratch_files(&self) -> Vec<PathBuf> {
        vec![self.lock_path.clone(), temporary_path(&self.path)]
    }
}

impl Drop for Claim {
    fn drop(&mut self) {
        // Unlinked while still locked, so a process that opens the path
        // after this creates a new lock file (see `lock`).
        let _ = std::fs::remove_file(&self.lock_path);
    }
}

/// A description of a file type that is not a regular file.
fn kind_of(meta: &std::fs::Metadata) -> Option<&'static str> {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_file() {
        None
    } else if t.is_dir() {
        Some("a directory")
    } else if t.is_symlink() {
        Some("a symbolic link")
    } else if t.is_char_device() || t.is_block_device() {
        Some("a device")
    } else if t.is_fifo() {
        Some("a FIFO")
    } else if t.is_socket() {
        Some("a socket")
    } else {
        Some("not a file")
    }
}

/// Fails unless `path` is absent or a regular file (not followed through a
/// symbolic link).
pub fn ensure_replaceable(path: &Path) -> Result<(), ClaimError> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) => match kind_of(&meta) {
            Some(what) => Err(ClaimError::NotRegular {
                path: path.display().to_string(),
                what,
            }),
            None => Ok(()),
        },
        Err(_) => Ok(()),
    }
}

/// The same file: equal device and inode (both must exist).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

/// The directory that will hold `path` ("." for a bare file name).
fn directory_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// `.<name>.<suffix>` beside `path`.
pub(crate) fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    directory_of(path).join(format!(".{name}.{suffix}"))
}

/// Claims `path` for writing: it must not be an input, must be absent or a
/// regular file (and then `replace` — `--force` or `--resume` — must be
/// given), its directory must exist and be writable, and no other process
/// may hold it.
pub fn claim(path: &Path, inputs: Inputs, replace: bool) -> Result<Claim, ClaimError> {
    let shown = path.display().to_string();
    if path.as_os_str().is_empty() || path.file_name().is_none() {
        return Err(ClaimError::Directory {
            path: shown,
            reason: "the path names no file".into(),
        });
    }
    for input in inputs {
        if same_file(path, input) {
            return Err(ClaimError::IsInput {
                path: shown,
                input: input.display().to_string(),
            });
        }
    }
    ensure_replaceable(path)?;
    if path.exists() && !replace {
        return Err(ClaimError::Exists(shown));
    }
    let dir = directory_of(path);
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(ClaimError::Directory {
                path: shown,
                reason: format!("{} is not a directory", dir.display()),
            })
        }
        Err(e) => {
            return Err(ClaimError::Directory {
                path: shown,
                reason: format!("the directory {}: {e}", dir.display()),
            })
        }
    }
    let (lock_path, lock) = lock(path)?;
    remove_stale_temporaries(path);
    Ok(Claim {
        path: path.to_path_buf(),
        lock_path,
        _lock: lock,
    })
}

/// Claims every output of a command at once; an output named twice is an
/// error.
pub fn claim_all(paths: &[&Path], inputs: Inputs, replace: bool) -> Result<Vec<Claim>, ClaimError> {
    let mut claims: Vec<Claim> = Vec::with_capacity(paths.len());
    for (i, p) in paths.iter().enumerate() {
        let twice =
            paths[..i].iter().any(|q| q == p) || claims.iter().any(|c| same_file(c.path(), p));
        if twice {
            return Err(ClaimError::Twice {
                path: p.display().to_string(),
            });
        }
        claims.push(claim(p, inputs, replace)?);
    }
    Ok(claims)
}

/// Creates and locks `.<name>.lock`; retries when the file it locked was
/// unlinked meanwhile by the previous holder.
fn lock(path: &Path) -> Result<(PathBuf, File), ClaimError> {
    let lock_path = sibling(path, "lock");
    let denied = |e: std::io::Error| ClaimError::Directory {
        path: path.display().to_string(),
        reason: format!("cannot create {}: {e}", lock_path.display()),
    };
    for _ in 0..16 {
        ensure_replaceable(&lock_path).map_err(|_| ClaimError::Directory {
            path: path.display().to_string(),
            reason: format!("{} exists and is not a regular file", lock_path.display()),
        })?;
        let file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&lock_path)
            .map_err(denied)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(ClaimError::Locked {
                    path: path.display().to_string(),
                    lock: lock_path.display().to_string(),
                })
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(denied(e)),
        }
        // The lock is ours only if the path still names the locked file.
        let held = file.metadata().map_err(denied)?;
        match std::fs::metadata(&lock_path) {
            Ok(now) if now.ino() == held.ino() && now.dev() == held.dev() => {
                return Ok((lock_path, file))
            }
            _ => {}
        }
    }
    Err(ClaimError::Locked {
        path: path.display().to_string(),
        lock: lock_path.display().to_string(),
    })
}

/// Removes `.<name>.*.tmp` beside `path` (left by a killed run).
fn remove_stale_temporaries(path: &Path) {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return;
    };
    let prefix = format!(".{name}.");
    let Ok(entries) = std::fs::read_dir(directory_of(path)) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        let temporary = file
            .strip_prefix(&prefix)
            .and_then(|rest| rest.split_once(".tmp"))
            .is_some_and(|(pid, _)| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()));
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        if temporary && regular {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The temporary name a result is written under before it is renamed into
/// place: `.<name>.<pid>.tmp`, keeping the extension last so that writers
/// that choose a format by extension (images) still see it.
pub fn temporary_path(path: &Path) -> PathBuf {
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    sibling(path, &format!("{}.tmp{ext}", std::process::id()))
}

/// Writes a file through `write` (given the temporary path) and renames it
/// onto `path`, which must be absent or a regular file; the temporary is
/// removed on any failure, so nothing partial is ever left at `path`.
pub fn replace_atomically<E: std::fmt::Display>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), String> {
    ensure_replaceable(path).map_err(|e| e.to_string())?;
    let tmp = temporary_path(path);
    if let Err(e) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(format!("writing {}: {e}", path.display()));
    }
    if let Err(e) = ensure_replaceable(path) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e.to_string());
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("moving the result to {}: {e}", path.display())
    })
}
