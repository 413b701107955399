//! Shared helpers of the `autoshovel` integration tests: run the built binary
//! with a time limit, make unique temporary paths, read JSON summaries.

#![allow(dead_code)] // each test file uses its own subset

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use serde_json::Value;

/// Time limit of one run of the program.
pub const TIMEOUT: Duration = Duration::from_secs(20);

/// The binary under test.
pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_autoshovel")
}

/// What one run of the program did.
#[derive(Debug)]
pub struct Run {
    /// The command line, for messages.
    pub cmd: String,
    /// Exit status.
    pub status: ExitStatus,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
    /// Wall-clock time.
    pub elapsed: Duration,
}

impl Run {
    /// The exit code (None if killed by a signal).
    pub fn code(&self) -> Option<i32> {
        self.status.code()
    }

    /// Asserts exit code 0 and returns self.
    #[track_caller]
    pub fn ok(self) -> Self {
        assert_eq!(
            self.code(),
            Some(0),
            "`{}` should succeed\nstdout:\n{}\nstderr:\n{}",
            self.cmd,
            self.stdout,
            self.stderr
        );
        self
    }

    /// Asserts exit code 1 (the program's error exit), no panic, and a
    /// one-line-or-more `error: ` message on stderr; returns self.
    #[track_caller]
    pub fn fails(self) -> Self {
        assert_eq!(
            self.code(),
            Some(1),
            "`{}` should fail with exit 1\nstdout:\n{}\nstderr:\n{}",
            self.cmd,
            self.stdout,
            self.stderr
        );
        self.no_panic();
        assert!(
            self.stderr.starts_with("error: "),
            "`{}`: stderr should start with `error: `:\n{}",
            self.cmd,
            self.stderr
        );
        self
    }

    /// Asserts that stderr shows no panic.
    #[track_caller]
    pub fn no_panic(&self) {
        assert!(
            !self.stderr.contains("panicked"),
            "`{}` panicked:\n{}",
            self.cmd,
            self.stderr
        );
    }

    /// The error message on stderr without the `error: ` prefix.
    pub fn error_message(&self) -> &str {
        self.stderr
            .strip_prefix("error: ")
            .unwrap_or(&self.stderr)
            .trim_end()
    }

    /// Stdout parsed as exactly one JSON document (fails the test otherwise).
    #[track_caller]
    pub fn json(&self) -> Value {
        parse_one_json(&self.stdout).unwrap_or_else(|e| {
            panic!(
                "`{}`: stdout is not one JSON document ({e}):\n{}",
                self.cmd, self.stdout
            )
        })
    }
}

/// Parses `text` as exactly one JSON document, nothing before or after it
/// but whitespace.
pub fn parse_one_json(text: &str) -> Result<Value, String> {
    let mut stream = serde_json::Deserializer::from_str(text).into_iter::<Value>();
    let first = match stream.next() {
        Some(Ok(v)) => v,
        Some(Err(e)) => return Err(e.to_string()),
        None => return Err("empty".into()),
    };
    if stream.next().is_some() {
        return Err("more than one document".into());
    }
    Ok(first)
}

/// Runs the program with `args`, failing the test if it does not finish
/// within [`TIMEOUT`] (the child is killed first).
#[track_caller]
pub fn run<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Run {
    run_with_timeout(args, TIMEOUT)
}

/// Like [`run`] with an explicit time limit.
#[track_caller]
pub fn run_with_timeout<S: AsRef<std::ffi::OsStr>>(args: &[S], timeout: Duration) -> Run {
    let cmd = std::iter::once(bin().to_string())
        .chain(
            args.iter()
                .map(|a| a.as_ref().to_string_lossy().into_owned()),
        )
        .collect::<Vec<_>>()
        .join(" ");
    let t0 = Instant::now();
    let mut child = Command::new(bin())
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start `{cmd}`: {e}"));
    // Drain both pipes on threads so a chatty child cannot block on a full pipe.
    let mut out = child.stdout.take().expect("piped stdout");
    let mut err = child.stderr.take().expect("piped stderr");
    let out_t = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = out.read_to_end(&mut s);
        s
    });
    let err_t = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = err.read_to_end(&mut s);
        s
    });
    let status = wait_or_kill(&mut child, timeout, &cmd);
    let elapsed = t0.elapsed();
    let stdout = String::from_utf8_lossy(&out_t.join().expect("stdout reader")).into_owned();
    let stderr = String::from_utf8_lossy(&err_t.join().expect("stderr reader")).into_owned();
    Run {
        cmd,
        status,
        stdout,
        stderr,
        elapsed,
    }
}

/// Polls `child` until it exits; kills it and fails the test after `timeout`.
#[track_caller]
pub fn wait_or_kill(child: &mut std::process::Child, timeout: Duration, cmd: &str) -> ExitStatus {
    let t0 = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) => return status,
            Ok(None) if t0.elapsed() < timeout => std::thread::sleep(Duration::from_millis(5)),
            Ok(None) => {
                let _ = child.kill();
                let _ = child.wait();
                panic!("`{cmd}` did not finish within {timeout:?} (killed)");
            }
            Err(e) => panic!("waiting for `{cmd}`: {e}"),
        }
    }
}

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// A fresh, not yet existing path under the system temp dir, unique to this
/// process and call (`tag` makes it readable).
pub fn unique_path(tag: &str) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    std::env::temp_dir().join(format!(
        "autoshovel-it-{}-{n}-{nanos}-{tag}",
        std::process::id()
    ))
}

/// A temporary directory removed on drop (kept if the test failed, to look at).
pub struct TempDir(pub PathBuf);

impl TempDir {
    /// Creates a fresh empty directory.
    pub fn new(tag: &str) -> Self {
        let p = unique_path(tag);
        std::fs::create_dir_all(&p)
            .unwrap_or_else(|e| panic!("cannot create {}: {e}", p.display()));
        TempDir(p)
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// Writes `text` to `name` inside the directory and returns its path.
    pub fn write(&self, name: &str, text: impl AsRef<[u8]>) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, text).unwrap_or_else(|e| panic!("cannot write {}: {e}", p.display()));
        p
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// The TOML text of a built-in scenario, as `autoshovel scenario NAME` prints it.
#[track_caller]
pub fn builtin_text(name: &str) -> String {
    let r = run(&["scenario", name]).ok();
    assert!(
        r.stdout.contains(&format!("name = \"{name}\"")),
        "`{}` printed:\n{}",
        r.cmd,
        r.stdout
    );
    r.stdout
}

/// Replaces exactly one occurrence of `from` by `to` in `text` (fails the
/// test if `from` is missing or ambiguous, so an edit can never silently miss).
#[track_caller]
pub fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert_eq!(
        text.matches(from).count(),
        1,
        "`{from}` should occur exactly once in:\n{text}"
    );
    text.replacen(from, to, 1)
}

/// 1-based line number of the first line equal to `line` (trimmed).
#[track_caller]
pub fn line_of(text: &str, line: &str) -> usize {
    text.lines()
        .position(|l| l.trim() == line)
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("no line `{line}` in:\n{text}"))
}

/// A number field of a JSON object, failing the test if it is missing or not a number.
#[track_caller]
pub fn f64_field(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("`{key}` should be a number in {v:#}"))
}

/// Removes every object key containing "time" (wall-clock measures), recursively.
pub fn without_timing(v: &Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .filter(|(k, _)| !k.contains("time"))
                .map(|(k, v)| (k.clone(), without_timing(v)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.iter().map(without_timing).collect()),
        other => other.clone(),
    }
}

/// A job's `--out` folder: `summary.json` is the summary printed under
/// `--json`, and each of `files` exists, is listed in the summary's
/// `files`, and is a PNG or SVG where its name says so.
#[allow(dead_code)]
pub fn assert_written(out: &Path, summary: &Value, files: &[&str]) {
    let written: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(&written, summary, "--json prints what summary.json holds");
    let listed: Vec<&str> = summary["files"]
        .as_array()
        .expect("files")
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    for f in files {
        assert!(out.join(f).is_file(), "{f} missing");
        assert!(
            listed.contains(f),
            "summary files should list {f}: {listed:?}"
        );
        let bytes = std::fs::read(out.join(f)).unwrap();
        if f.ends_with(".png") {
            assert!(bytes.starts_with(b"\x89PNG"), "{f} is not a PNG");
        } else if f.ends_with(".svg") {
            assert!(String::from_utf8_lossy(&bytes).contains("<svg"), "{f}");
        }
    }
}
