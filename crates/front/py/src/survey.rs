//! A survey larger than memory, by tiles (`autoshovel_terrain::tiles`),
//! with each stage's tiles run here or by a Python executor (Ray's, in
//! `autoshovel.cluster`), and one tile task run in a worker.

use std::path::{Path, PathBuf};

use autoshovel_point_cloud::io::Encoding;
use autoshovel_terrain::perceive::PerceptionParams;
use autoshovel_terrain::tiles::{
    perceive_tiled_with, run_tile_task as run_task, InProcess, Survey, TileExecutor, TileOptions,
    TileReport, TileTask, TiledSummary,
};
use autoshovel_terrain::SurfaceError;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{bad_arg, finite, lib_err, settings, summary_json, AutoshovelError};

/// A stage's tasks handed to a Python callable `(stage, [task JSON]) ->
/// [report JSON]`; what it raised is kept to be raised again as it was.
struct PyExecutor {
    call: Py<PyAny>,
    raised: Option<PyErr>,
}

impl TileExecutor for PyExecutor {
    fn run(
        &mut self,
        stage: &str,
        tasks: Vec<TileTask>,
        _progress: &mut dyn FnMut(&str, u64, u64),
    ) -> Result<Vec<TileReport>, SurfaceError> {
        let fail = |problem: String| SurfaceError::TileExecutor {
            stage: stage.into(),
            problem,
        };
        let texts = tasks
            .iter()
            .map(serde_json::to_string)
            .collect::<Result<Vec<String>, _>>()
            .map_err(|e| fail(e.to_string()))?;
        let replies: PyResult<Vec<String>> =
            Python::attach(|py| self.call.call1(py, (stage, texts))?.extract(py));
        match replies {
            Ok(replies) => replies
                .iter()
                .map(|r| {
                    serde_json::from_str(r).map_err(|e| {
                        fail(format!("the executor returned {r:.80?}, not a report: {e}"))
                    })
                })
                .collect(),
            Err(e) => {
                let problem = format!("the executor raised {e}");
                self.raised = Some(e);
                Err(fail(problem))
            }
        }
    }
}

/// Where the cleaned tiles go: a folder of `tiles_dir`'s own while the run
/// lasts, moved into `tiles_dir` when it succeeds (removed if it fails).
struct Staged {
    target: PathBuf,
    partial: PathBuf,
    made_target: bool,
    files: Vec<PathBuf>,
}

impl Staged {
    fn new(target: PathBuf) -> PyResult<Self> {
        let made_target = !target.exists();
        std::fs::create_dir_all(&target).map_err(|e| os_err(&target, e))?;
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let partial = target.join(format!(".partial-{}-{stamp}", std::process::id()));
        std::fs::create_dir_all(&partial).map_err(|e| os_err(&partial, e))?;
        Ok(Self {
            target,
            partial,
            made_target,
            files: Vec::new(),
        })
    }

    fn finish(mut self) -> PyResult<Vec<String>> {
        let mut out = Vec::with_capacity(self.files.len());
        for f in std::mem::take(&mut self.files) {
            let to = self.target.join(f.file_name().expect("a file name"));
            std::fs::rename(&f, &to).map_err(|e| os_err(&to, e))?;
            out.push(to.display().to_string());
        }
        let _ = std::fs::remove_dir_all(&self.partial);
        self.made_target = false;
        Ok(out)
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.partial);
        if self.made_target {
            let _ = std::fs::remove_dir(&self.target);
        }
    }
}

fn os_err(path: &Path, e: std::io::Error) -> PyErr {
    AutoshovelError::new_err(format!("{}: {e}", path.display()))
}

/// The pipeline on a LAS/LAZ survey by tiles (`autoshovel perceive
/// --tiles`): its summary (JSON), the height model (rows y, columns x; NaN
/// where no point), the model's lower corner, and the cleaned tiles'
/// files (when `tiles_dir` is given). `executor(stage, tasks) -> reports`
/// runs each stage's tasks (JSON text) elsewhere; none: in this process.
#[pyfunction]
#[pyo3(signature = (inputs, config=None, overrides=None, tile_m=None, memory_limit=2 << 30, sample_points=2_000_000, model_cell_m=1.0, work_dir=None, tiles_dir=None, executor=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn perceive_survey<'py>(
    py: Python<'py>,
    inputs: Vec<PathBuf>,
    config: Option<&str>,
    overrides: Option<&Bound<'py, PyDict>>,
    tile_m: Option<f64>,
    memory_limit: u64,
    sample_points: usize,
    model_cell_m: f64,
    work_dir: Option<PathBuf>,
    tiles_dir: Option<PathBuf>,
    executor: Option<Py<PyAny>>,
) -> PyResult<(String, Bound<'py, PyArray2<f64>>, (f64, f64), Vec<String>)> {
    const F: &str = "perceive_survey";
    let params: PerceptionParams = settings(F, config, overrides, || {
        autoshovel_core::config::TomlFile::to_toml(&PerceptionParams::default())
    })?;
    if let Some(t) = tile_m {
        if finite(F, "tile_m", t)? <= 0.0 {
            return Err(bad_arg(
                F,
                format!("tile_m = {t}: expected a length > 0 [m]"),
            ));
        }
    }
    if memory_limit == 0 {
        return Err(bad_arg(F, "memory_limit = 0: expected bytes > 0"));
    }
    if sample_points == 0 {
        return Err(bad_arg(F, "sample_points = 0: expected at least 1"));
    }
    if finite(F, "model_cell_m", model_cell_m)? <= 0.0 {
        return Err(bad_arg(
            F,
            format!("model_cell_m = {model_cell_m}: expected a length > 0 [m]"),
        ));
    }
    let defaults = TileOptions::default();
    let options = TileOptions {
        tile_m,
        memory_limit,
        sample_points,
        model_cell_m,
        work_dir: work_dir.unwrap_or(defaults.work_dir),
        // The records are kept only for tiles that are written.
        attributes: tiles_dir.is_some(),
    };
    let survey = Survey::open(&inputs).map_err(lib_err)?;
    let mut staged = tiles_dir.map(Staged::new).transpose()?;
    let mut py_exec = executor.map(|call| PyExecutor { call, raised: None });
    let mut here = InProcess;
    let got = py.detach(|| {
        let exec: &mut dyn TileExecutor = match py_exec.as_mut() {
            Some(e) => e,
            None => &mut here,
        };
        perceive_tiled_with(
            &survey,
            &params,
            &options,
            exec,
            &mut |_, _, _| {},
            &mut |tile| {
                if let Some(s) = staged.as_mut() {
                    let f = s.partial.join(tile.file_name());
                    autoshovel_point_cloud::io::write(&f, &tile.cloud, Encoding::Binary)?;
                    s.files.push(f);
                }
                Ok(())
            },
        )
    });
    let got = match got {
        Ok(got) => got,
        Err(e) => {
            return Err(match py_exec.and_then(|x| x.raised) {
                Some(raised) => raised,
                None => lib_err(e),
            })
        }
    };
    let input = inputs
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let summary = TiledSummary::new(&input, &survey, &params, &options, &got);
    let files = staged
        .take()
        .map(Staged::finish)
        .transpose()?
        .unwrap_or_default();
    let m = &got.model;
    let z = numpy::ndarray::Array2::from_shape_vec((m.size[1], m.size[0]), m.z.clone())
        .map_err(lib_err)?;
    Ok((
        summary_json(&summary)?,
        PyArray2::from_owned_array(py, z),
        (m.origin[0], m.origin[1]),
        files,
    ))
}

/// One tile's work of one stage (`TileTask` as JSON, as an executor
/// receives it), run here on `threads` threads (default: every core); its
/// report as JSON.
#[pyfunction]
#[pyo3(signature = (task, threads=None))]
fn run_tile_task(py: Python<'_>, task: &str, threads: Option<usize>) -> PyResult<String> {
    let task = parse_task("run_tile_task", task)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(lib_err)?;
    let report = py
        .detach(|| pool.install(|| run_task(&task)))
        .map_err(lib_err)?;
    serde_json::to_string(&report).map_err(lib_err)
}

/// Points a tile task loads (its tile and halo): what its time follows,
/// for an executor that balances tasks.
#[pyfunction]
fn tile_task_points(task: &str) -> PyResult<u64> {
    Ok(parse_task("tile_task_points", task)?.points())
}

/// A `TileTask` from its JSON text, or a `ValueError` naming `func`.
fn parse_task(func: &str, text: &str) -> PyResult<TileTask> {
    serde_json::from_str(text)
        .map_err(|e| bad_arg(func, format!("task {text:.80?} is not a tile task: {e}")))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(perceive_survey, m)?)?;
    m.add_function(wrap_pyfunction!(run_tile_task, m)?)?;
    m.add_function(wrap_pyfunction!(tile_task_points, m)?)?;
    Ok(())
}
