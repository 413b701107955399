//! The one rule for every file a job writes: nothing the user gave is
//! overwritten or lost. A job writes into a staging folder inside its output
//! folder; [`Staging::commit`] then checks every file against the rule and
//! only when all pass renames them into place (same file system, so each
//! file appears whole).
//!
//! A target is refused when it is one of the job's input files (compared
//! by canonical path and, on Unix, by device and inode, so links are seen
//! through), or when it exists and autoshovel did not write it: the files
//! autoshovel wrote are those the folder's previous `summary.json` lists.
//! `force` lifts the second refusal, never the first.
//!
//! Staging folders are made by [`private_dir`]: `mkdir` under a random
//! name, which fails on any existing entry (a planted link included)
//! rather than going through it, so nothing can steer a job's writes
//! into another folder. Errors name the user's target, never a staging
//! path.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use crate::error::ReportError;
use crate::json::SUMMARY_FILE;
use crate::written::Written;

/// An output folder and what may not be written over.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct OutDir {
    /// The folder (created if missing).
    pub dir: PathBuf,
    /// The job's input files: never written over, even with `force`.
    pub inputs: Vec<PathBuf>,
    /// Replace existing files autoshovel did not write (`--force`).
    pub force: bool,
}

/// A file's identity: canonical path and, on Unix, (device, inode).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct FileId(PathBuf, Option<(u64, u64)>);

fn file_id(p: &Path) -> Option<FileId> {
    let canon = std::fs::canonicalize(p).ok()?;
    #[cfg(unix)]
    let inode = {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(&canon).ok().map(|m| (m.dev(), m.ino()))
    };
    #[cfg(not(unix))]
    let inode = None;
    Some(FileId(canon, inode))
}

fn same_file(a: &FileId, b: &FileId) -> bool {
    a.0 == b.0 || (a.1.is_some() && a.1 == b.1)
}

/// Why `target` may not be written, if it may not: it is an input, or it
/// exists, autoshovel did not write it (not in `ours`) and `force` is off.
pub fn refusal(
    target: &Path,
    inputs: &[PathBuf],
    ours: &HashSet<PathBuf>,
    force: bool,
) -> Option<String> {
    let id = file_id(target)?; // a missing target is free
    if inputs
        .iter()
        .filter_map(|i| file_id(i))
        .any(|i| same_file(&i, &id))
    {
        return Some("it is an input of this job; choose another output".to_string());
    }
    if !force && !ours.contains(&id.0) {
        return Some(
            "it exists and autoshovel did not write it (it is not in the folder's summary.json); \
             give --force to replace it, or choose another output"
                .to_string(),
        );
    }
    None
}

/// The files (canonical paths) that the `summary.json` in `dir` says
/// autoshovel wrote there; none when there is no readable summary.
pub fn files_written_before(dir: &Path) -> HashSet<PathBuf> {
    let Ok(text) = std::fs::read_to_string(dir.join(SUMMARY_FILE)) else {
        return HashSet::new();
    };
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else {
        return HashSet::new();
    };
    let out: HashSet<PathBuf> = v["files"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|f| f.as_str())
        .filter(|f| !f.contains("..") && !Path::new(f).is_absolute())
        .filter_map(|f| std::fs::canonicalize(dir.join(f)).ok())
        .collect();
    out
}

/// A job's files while it writes them: a hidden folder inside the output
/// folder, removed when dropped.
#[derive(Debug)]
pub struct Staging {
    out: OutDir,
    tmp: PathBuf,
}

/// Random characters in a staging folder's name (62 symbols each: 71
/// bits, beyond guessing).
const RANDOM_CHARS: usize = 12;

/// Creates a new folder `.autoshovel-TAG-RANDOM` inside `dir`, readable by
/// its owner only. Made by one `mkdir`, which refuses an existing entry of
/// that name (a file, a folder or a link planted there) instead of going
/// through it, under a name nobody can predict; tempfile retries on a
/// clash. By hand it would be the same loop over `create_dir` and a
/// random source, which tempfile already is.
pub fn private_dir(dir: &Path, tag: &str) -> std::io::Result<PathBuf> {
    let prefix = format!(".autoshovel-{tag}-");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).rand_bytes(RANDOM_CHARS);
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o700));
    autoshovel_core::check_dir(dir)?;
    let made = builder.tempdir_in(dir).map_err(without_path)?;
    Ok(made.keep())
}

/// The operating system's error without the path tempfile appends (the
/// caller names the user's target, never the temporary name).
pub fn without_path(e: std::io::Error) -> std::io::Error {
    autoshovel_core::os_error(e)
}

/// Staging folders and temporary files not yet committed or removed, for
/// [`remove_unfinished`].
static UNFINISHED: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn unfinished() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    UNFINISHED.lock().unwrap_or_else(|e| e.into_inner())
}

fn finished(path: &Path) {
    unfinished().retain(|p| p != path);
}

/// Removes every staging folder and temporary file of this process that is
/// not yet committed: what an interrupt handler calls before exiting, so
/// that an interrupted job leaves the output folder as it found it (files
/// already moved into place by a commit stay, whole).
pub fn remove_unfinished() {
    for p in unfinished().drain(..) {
        if p.is_dir() {
            let _ = std::fs::remove_dir_all(&p);
        } else {
            let _ = std::fs::remove_file(&p);
        }
    }
}

impl OutDir {
    /// An output folder with no inputs to protect and no `--force`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self {
            dir: dir.into(),
            ..Self::default()
        }
    }

    /// Creates the folder (if needed) and a staging folder inside it.
    pub fn stage(&self) -> Result<Staging, ReportError> {
        if self.dir.exists() && !self.dir.is_dir() {
            return Err(ReportError::Refused {
                path: self.dir.clone(),
                why: "exists and is not a directory".into(),
            });
        }
        std::fs::create_dir_all(&self.dir).map_err(|e| ReportError::io(&self.dir, e))?;
        let tmp = private_dir(&self.dir, "staging").map_err(|e| ReportError::io(&self.dir, e))?;
        unfinished().push(tmp.clone());
        Ok(Staging {
            out: self.clone(),
            tmp,
        })
    }
}

impl Staging {
    /// Where the job writes its files.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// The output folder the files go to.
    pub fn dir(&self) -> &Path {
        &self.out.dir
    }

    /// Moves every file of `written` into the output folder, after checking
    /// all of them against the rule (module docs); on a refusal nothing is
    /// moved and the staging folder is removed.
    pub fn commit(self, written: &Written) -> Result<(), ReportError> {
        let ours = files_written_before(&self.out.dir);
        let files = written.all();
        for f in &files {
            let target = self.out.dir.join(f);
            if let Some(why) = refusal(&target, &self.out.inputs, &ours, self.out.force) {
                return Err(ReportError::Refused { path: target, why });
            }
        }
        for f in &files {
            let (from, to) = (self.tmp.join(f), self.out.dir.join(f));
            if let Some(parent) = to.parent() {
                std::fs::create_dir_all(parent).map_err(|e| ReportError::io(parent, e))?;
            }
            std::fs::rename(&from, &to).map_err(|e| ReportError::io(&to, e))?;
        }
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.tmp);
        finished(&self.tmp);
    }
}

/// Writes one file at `target` through a private folder beside it
/// ([`private_dir`]) and a rename, after checking `target` against the rule
/// (module docs); `ours` are the files autoshovel wrote before and may
/// replace. `write(scratch, target)` writes the file at `scratch` (the
/// target's name, so format-by-extension writers work) and names `target`
/// in its errors; every error names `target`, never the scratch path.
pub fn write_file_atomically<E: From<ReportError>>(
    target: &Path,
    inputs: &[PathBuf],
    (ours, force): (&HashSet<PathBuf>, bool),
    write: impl FnOnce(&Path, &Path) -> Result<(), E>,
) -> Result<(), E> {
    if let Some(why) = refusal(target, inputs, ours, force) {
        return Err(ReportError::Refused {
            path: target.to_path_buf(),
            why,
        }
        .into());
    }
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    // A missing or unwritable folder is the target's error.
    let scratch = private_dir(parent, "write").map_err(|e| ReportError::io(target, e))?;
    unfinished().push(scratch.clone());
    let name = target.file_name().unwrap_or(target.as_os_str());
    let result = write(&scratch.join(name), target).and_then(|()| {
        std::fs::rename(scratch.join(name), target).map_err(|e| ReportError::io(target, e).into())
    });
    let _ = std::fs::remove_dir_all(&scratch);
    finished(&scratch);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmpdir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("as-staging-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn stage_one(out: &OutDir, name: &str, text: &str) -> Result<(), ReportError> {
        let s = out.stage()?;
        std::fs::write(s.path().join(name), text).unwrap();
        let mut w = Written::default();
        w.file(s.path(), &s.path().join(name));
        w.file(s.path(), &s.path().join(SUMMARY_FILE));
        std::fs::write(
            s.path().join(SUMMARY_FILE),
            format!("{{\"files\": [\"{name}\", \"summary.json\"]}}"),
        )
        .unwrap();
        s.commit(&w)
    }

    #[test]
    fn a_users_file_is_kept_unless_forced_and_an_input_always() {
        let d = tmpdir("rule");
        std::fs::write(d.join("index.html"), "mine").unwrap();
        let out = OutDir::new(&d);
        let e = stage_one(&out, "index.html", "ours").unwrap_err();
        assert!(e.to_string().contains("--force"), "{e}");
        assert_eq!(
            std::fs::read_to_string(d.join("index.html")).unwrap(),
            "mine"
        );
        assert!(!d.join(SUMMARY_FILE).exists(), "nothing moved on a refusal");
        // Our own earlier output may be replaced: it is in summary.json.
        stage_one(&out, "a.csv", "1").unwrap();
        stage_one(&out, "a.csv", "2").unwrap();
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "2");
        // An input never, even with --force, and through a link too.
        let forced = OutDir {
            inputs: vec![d.join("a.csv")],
            force: true,
            ..OutDir::new(&d)
        };
        let e = stage_one(&forced, "a.csv", "3").unwrap_err();
        assert!(e.to_string().contains("is an input"), "{e}");
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "2");
        // --force replaces the user's file.
        let forced = OutDir {
            force: true,
            ..OutDir::new(&d)
        };
        stage_one(&forced, "index.html", "ours").unwrap();
        assert_eq!(
            std::fs::read_to_string(d.join("index.html")).unwrap(),
            "ours"
        );
        // No staging folder is left behind.
        let left: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().starts_with(".autoshovel"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn staging_folders_are_new_private_folders_under_random_names() {
        let d = tmpdir("private");
        let out = OutDir::new(&d);
        let (a, b) = (out.stage().unwrap(), out.stage().unwrap());
        for s in [&a, &b] {
            let meta = std::fs::symlink_metadata(s.path()).unwrap();
            assert!(meta.is_dir() && !meta.file_type().is_symlink());
            #[cfg(unix)]
            {
                use std::os::unix::fs::PermissionsExt;
                assert_eq!(meta.permissions().mode() & 0o077, 0, "owner only");
            }
            let name = s.path().file_name().unwrap().to_string_lossy().into_owned();
            let random = name.trim_start_matches(".autoshovel-staging-");
            assert_eq!(random.len(), RANDOM_CHARS, "{name}");
            assert!(!random.contains(&std::process::id().to_string()), "{name}");
        }
        assert_ne!(a.path(), b.path());
        drop((a, b));
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_failed_write_names_the_target_not_the_scratch_file() {
        let d = tmpdir("names");
        std::fs::write(d.join("file"), "x").unwrap();
        // Its folder is a file: nothing can be made beside the target.
        let target = d.join("file").join("out.pcd");
        let e =
            write_file_atomically::<ReportError>(&target, &[], (&HashSet::new(), false), |_, _| {
                Ok(())
            })
            .unwrap_err();
        let chain = format!("{e}: {}", std::error::Error::source(&e).unwrap());
        assert!(
            chain.starts_with(&format!("cannot write {}", target.display())),
            "{chain}"
        );
        assert!(!chain.contains(".autoshovel"), "{chain}");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_lone_file_is_written_whole_or_not_at_all() {
        let d = tmpdir("lone");
        let f = d.join("pile.pcd");
        write_file_atomically::<ReportError>(&f, &[], (&HashSet::new(), false), |p, _| {
            std::fs::write(p, "1").map_err(|e| ReportError::io(p, e))
        })
        .unwrap();
        let e = write_file_atomically::<ReportError>(&f, &[], (&HashSet::new(), false), |p, _| {
            std::fs::write(p, "2").map_err(|e| ReportError::io(p, e))
        })
        .unwrap_err();
        assert!(e.to_string().contains("--force"), "{e}");
        assert_eq!(std::fs::read_to_string(&f).unwrap(), "1");
        let e = write_file_atomically::<ReportError>(&f, &[], (&HashSet::new(), true), |_, _| {
            Err(ReportError::invalid("failed half-way"))
        })
        .unwrap_err();
        assert!(e.to_string().contains("half-way"));
        assert_eq!(std::fs::read_to_string(&f).unwrap(), "1");
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            1,
            "no temporary left"
        );
        let _ = std::fs::remove_dir_all(&d);
    }
}
