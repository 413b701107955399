//! Output conventions shared by every job (SPEC §6): `--out DIR` gets
//! `summary.json`, CSV and SVG+PNG plots; `--json` prints the summary alone
//! on stdout; human-readable lines go to stdout only without `--json`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// Makes sure `dir` is a directory we may write into, creating it if needed.
/// An existing directory is used as it is: only the files a job names are
/// written, nothing else in it is touched.
pub fn prepare_dir(dir: &Path) -> Result<PathBuf> {
    if dir.exists() && !dir.is_dir() {
        bail!("--out {}: exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create output directory {}", dir.display()))?;
    Ok(dir.to_path_buf())
}

/// Prints the summary as pretty JSON on stdout.
pub fn print_json(summary: &serde_json::Value) -> Result<()> {
    crate::say!("{}", serde_json::to_string_pretty(summary)?);
    Ok(())
}

/// Reports a finished job: the summary alone on stdout under `--json`,
/// otherwise the `human` report and the folder written to.
pub fn report(
    summary: &serde_json::Value,
    json: bool,
    out: Option<&std::path::Path>,
    human: impl FnOnce(&serde_json::Value),
) -> Result<()> {
    if json {
        print_json(summary)?;
    } else {
        human(summary);
        if let Some(dir) = out {
            crate::say!("wrote {}", dir.display());
        }
    }
    Ok(())
}

/// A finite f64 or JSON null (JSON has no NaN).
pub fn num(v: f64) -> serde_json::Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        serde_json::Value::Null
    }
}

/// Files a job wrote, relative to its output folder.
#[derive(Debug, Default, Clone)]
pub struct Written {
    /// SVG plots.
    pub plots: Vec<String>,
    /// Everything else (CSV, JSON, PNG).
    pub files: Vec<String>,
}

impl Written {
    /// Records a plot pair [svg, png] written under `base`.
    pub fn plot(&mut self, base: &Path, pair: [PathBuf; 2]) {
        let [svg, png] = pair;
        self.plots.push(rel(base, &svg));
        self.files.push(rel(base, &png));
    }

    /// Records a data file written under `base`.
    pub fn file(&mut self, base: &Path, path: &Path) {
        self.files.push(rel(base, path));
    }
}

fn rel(base: &Path, p: &Path) -> String {
    p.strip_prefix(base)
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}

/// Lists every file a job wrote in its summary (`files`) and writes
/// `summary.json` into `dir`.
pub fn write_job_summary(
    dir: &Path,
    summary: &mut serde_json::Value,
    written: &mut Written,
) -> Result<()> {
    written.file(dir, &dir.join(autoshovel_report::SUMMARY_FILE));
    summary["files"] = serde_json::json!(written
        .files
        .iter()
        .chain(written.plots.iter())
        .collect::<Vec<_>>());
    autoshovel_report::write_summary(dir, summary)?;
    Ok(())
}
