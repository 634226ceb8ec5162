//! Running a case under the limits and judging what it did and left.

use super::*;

/// The directory's files (names, with symlinks and special files) and
/// their contents where regular.
pub(crate) fn snapshot(dir: &Path) -> BTreeMap<String, Option<Vec<u8>>> {
    let mut out = BTreeMap::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let meta = std::fs::symlink_metadata(e.path()).unwrap();
        let content = meta
            .is_file()
            .then(|| std::fs::read(e.path()).unwrap_or_default());
        out.insert(name, content);
    }
    out
}

pub(crate) fn prepare(dir: &Path, case: &Case) {
    for p in &case.prepared {
        match p {
            Prepared::File(n, b) => std::fs::write(dir.join(n), b).unwrap(),
            Prepared::Directory(n) => std::fs::create_dir_all(dir.join(n)).unwrap(),
            Prepared::Symlink(n, t) => std::os::unix::fs::symlink(t, dir.join(n)).unwrap(),
            Prepared::Fifo(n) => {
                let ok = Command::new("mkfifo").arg(dir.join(n)).status().unwrap();
                assert!(ok.success());
            }
        }
    }
}

/// Runs one case; Err(reason) when it breaks a rule.
pub(crate) fn run_case(
    work: &Path,
    logs: &Path,
    case: &Case,
    limit: Duration,
) -> Result<i32, String> {
    let dir = work.join(format!("case{}", case.id));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    prepare(&dir, case);
    let before = snapshot(&dir);
    let (out_log, err_log) = (
        logs.join(format!("{}.out", case.id)),
        logs.join(format!("{}.err", case.id)),
    );
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_KIB}; exec \"$0\" \"$@\""))
        .arg(BIN)
        .args(&case.args)
        .current_dir(&dir)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_log).unwrap())
        .stderr(std::fs::File::create(&err_log).unwrap())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let mut signalled = false;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        let elapsed = start.elapsed();
        if !signalled && elapsed > limit {
            let _ = Command::new("kill")
                .args(["-TERM", &child.id().to_string()])
                .status();
            signalled = true;
        }
        if elapsed > limit + GRACE {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("did not stop within {GRACE:?} of SIGTERM"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stderr = std::fs::read_to_string(&err_log).unwrap_or_default();
    let verdict = judge(case, status, signalled, &stderr, &dir, &before);
    if verdict.is_ok() || std::env::var("COSSERAT_HOSTILE_KEEP").is_err() {
        let _ = std::fs::remove_dir_all(&dir);
        let _ = std::fs::remove_file(&out_log);
        let _ = std::fs::remove_file(&err_log);
    }
    verdict
}

pub(crate) fn judge(
    case: &Case,
    status: std::process::ExitStatus,
    signalled: bool,
    stderr: &str,
    dir: &Path,
    before: &BTreeMap<String, Option<Vec<u8>>>,
) -> Result<i32, String> {
    let tail: String = stderr
        .chars()
        .rev()
        .take(600)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    if let Some(sig) = status.signal() {
        return Err(format!("killed by signal {sig}: {tail}"));
    }
    let code = status.code().unwrap_or(-1);
    if stderr.contains("panicked at") || code == 101 {
        return Err(format!("panic (exit {code}): {tail}"));
    }
    if stderr.contains("memory allocation of") {
        return Err(format!("allocation failure: {tail}"));
    }
    if !CODES.contains(&code) {
        return Err(format!("exit code {code} outside the table: {tail}"));
    }
    if code == 130 && !signalled {
        return Err(format!("exit 130 without a signal: {tail}"));
    }
    if matches!(code, 1..=3) && !stderr.contains("error:") {
        return Err(format!("exit {code} without an error line: {tail}"));
    }
    if stderr.len() > 20_000 {
        return Err(format!("{} bytes on stderr", stderr.len()));
    }
    let after = snapshot(dir);
    for (name, content) in &after {
        let declared = case.outputs.iter().any(|o| o == name);
        match before.get(name) {
            None if !declared => return Err(format!("left behind: {name:?} (exit {code})")),
            None if !matches!(code, 0 | 1 | 130) => {
                return Err(format!(
                    "output {name:?} written by a failed run (exit {code})"
                ))
            }
            Some(old) if old != content && !(declared && matches!(code, 0 | 1 | 130)) => {
                return Err(format!("{name:?} changed by a run that exits {code}"))
            }
            _ => {}
        }
    }
    for name in before.keys() {
        if !after.contains_key(name) {
            return Err(format!("{name:?} was removed (exit {code})"));
        }
    }
    if code == 0 {
        // Success means the asked outputs exist (an output path the case
        // declared but the command may skip, e.g. a chart of an
        // interrupted run, is not required).
        if let Some(o) = case.outputs.first() {
            if case.args.iter().any(|a| a == "-o") && !after.contains_key(o) {
                let resumed_complete = case.args.iter().any(|a| a == "--resume");
                if !resumed_complete {
                    return Err(format!("exit 0 but {o:?} is missing"));
                }
            }
        }
    }
    Ok(code)
}
