//! Point clouds: the readers and writers, every filter, levelling, the
//! synthetic pile scans and `perceive` ([RS eq. 11]–[RS eq. 21]).

use std::path::{Path, PathBuf};

use autoshovel_point_cloud::filter::{
    self, Axis, OutlierSides, PassThroughParams, RadiusOutlierParams, StatisticalOutlierParams,
    VoxelGridParams,
};
use autoshovel_point_cloud::io::Encoding;
use autoshovel_point_cloud::PointCloud;
use autoshovel_terrain::perceive::{PerceiveSummary, Perceived, PerceptionParams};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{
    as_points, bad_arg, choose, finite, lib_err, points_arg, settings, summary_json, to_numpy,
};

/// `read_cloud(path)`: the finite points of a PCD, PLY, LAS, LAZ, XYZ or
/// CSV file, the format read and the count of non-finite points dropped.
#[pyfunction]
fn read_cloud(
    py: Python<'_>,
    path: PathBuf,
) -> PyResult<(Bound<'_, PyArray2<f32>>, &'static str, usize)> {
    let report = py
        .detach(|| autoshovel_point_cloud::io::read(&path, &mut |_, _| {}))
        .map_err(lib_err)?;
    Ok((
        to_numpy(py, world_points(report.cloud)),
        report.format,
        report.non_finite_dropped,
    ))
}

/// The file's coordinates, as the Python API has always returned them: a
/// cloud held about an f64 origin (a UTM survey) has it added back, in
/// f32 as the array is.
fn world_points(c: PointCloud) -> Vec<autoshovel_point_cloud::Point> {
    if c.origin == [0.0; 3] {
        return c.points;
    }
    (0..c.len()).map(|i| c.world(i).map(|v| v as f32)).collect()
}

/// `write_cloud(path, points, encoding, overwrite)`: the points written
/// whole to a file beside `path`, then moved over it (a failed write leaves
/// nothing); an existing file is kept unless `overwrite`.
#[pyfunction]
#[pyo3(signature = (path, points, encoding=None, overwrite=false))]
fn write_cloud(
    py: Python<'_>,
    path: PathBuf,
    points: &Bound<'_, PyAny>,
    encoding: Option<&str>,
    overwrite: bool,
) -> PyResult<()> {
    let array = points_arg("write_cloud", "points", points)?;
    let encoding = match encoding {
        Some(e) => e
            .parse::<Encoding>()
            .map_err(|msg| bad_arg("write_cloud", format!("encoding: {msg}")))?,
        None => Encoding::default_for(&path),
    };
    let cloud = PointCloud::new(as_points(&array).to_vec());
    // The output rule of every job (autoshovel_report::staging): a file
    // beside the target, renamed over it once whole; `overwrite` is --force.
    py.detach(|| {
        autoshovel_report::write_file_atomically::<WriteError>(
            &path,
            &[],
            (&Default::default(), overwrite),
            |scratch, target| {
                let options = autoshovel_point_cloud::io::WriteOptions {
                    encoding: Some(encoding),
                    ..Default::default()
                };
                Ok(autoshovel_point_cloud::io::write_named(
                    scratch, target, &cloud, &options,
                )?)
            },
        )
    })
    .map_err(|e| match e {
        WriteError::Report(e) => lib_err(e),
        WriteError::Cloud(e) => lib_err(e),
    })
}

/// What writing a cloud file can meet: the output rule's refusal, or the writer's error.
enum WriteError {
    Report(autoshovel_report::ReportError),
    Cloud(autoshovel_point_cloud::CloudError),
}

impl From<autoshovel_report::ReportError> for WriteError {
    fn from(e: autoshovel_report::ReportError) -> Self {
        WriteError::Report(e)
    }
}

impl From<autoshovel_point_cloud::CloudError> for WriteError {
    fn from(e: autoshovel_point_cloud::CloudError) -> Self {
        WriteError::Cloud(e)
    }
}

/// PCL's `VoxelGrid`: the centroid of each occupied voxel ([RS eq. 18]–[RS eq. 19]).
#[pyfunction]
fn voxel_grid<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    leaf_m: [f64; 3],
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let array = points_arg("voxel_grid", "points", points)?;
    let pts = as_points(&array);
    let params = VoxelGridParams { leaf_m };
    let out = py
        .detach(|| filter::voxel_grid(pts, &params))
        .map_err(lib_err)?;
    Ok(to_numpy(py, out.points))
}

fn parse_sides(func: &str, s: &str) -> PyResult<OutlierSides> {
    choose(
        func,
        "sides",
        s,
        &[("above", OutlierSides::Above), ("both", OutlierSides::Both)],
    )
}

/// Statistical outlier removal ([RS eq. 14]–[RS eq. 16]); with `indices`
/// the kept indices instead of the points.
#[pyfunction]
fn statistical_outlier_removal<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    mean_k: usize,
    std_mul: f64,
    sides: &str,
    indices: bool,
) -> PyResult<Bound<'py, PyAny>> {
    const F: &str = "statistical_outlier_removal";
    let array = points_arg(F, "points", points)?;
    let pts = as_points(&array);
    let params = StatisticalOutlierParams {
        mean_k,
        std_mul: finite(F, "std_mul", std_mul)?,
        sides: parse_sides(F, sides)?,
    };
    kept(
        py,
        pts,
        indices,
        |p| filter::statistical_outlier_removal_indices(p, &params),
        |p| filter::statistical_outlier_removal(p, &params),
    )
}

/// Radius outlier removal ([RS eq. 13]).
#[pyfunction]
fn radius_outlier_removal<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    radius_m: f64,
    min_neighbors: usize,
    indices: bool,
) -> PyResult<Bound<'py, PyAny>> {
    const F: &str = "radius_outlier_removal";
    let array = points_arg(F, "points", points)?;
    let pts = as_points(&array);
    let params = RadiusOutlierParams {
        radius_m: finite(F, "radius_m", radius_m)?,
        min_neighbors,
    };
    kept(
        py,
        pts,
        indices,
        |p| filter::radius_outlier_removal_indices(p, &params),
        |p| filter::radius_outlier_removal(p, &params),
    )
}

/// PCL's `PassThrough` on one axis ([RS eq. 17] on z).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn pass_through<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    axis: &str,
    min_m: f64,
    max_m: f64,
    keep_inside: bool,
    indices: bool,
) -> PyResult<Bound<'py, PyAny>> {
    const F: &str = "pass_through";
    let array = points_arg(F, "points", points)?;
    let pts = as_points(&array);
    let axis = choose(
        F,
        "axis",
        axis,
        &[("x", Axis::X), ("y", Axis::Y), ("z", Axis::Z)],
    )?;
    let params = PassThroughParams {
        axis,
        min_m,
        max_m,
        keep_inside,
    };
    kept(
        py,
        pts,
        indices,
        |p| filter::pass_through_indices(p, &params),
        |p| filter::pass_through(p, &params),
    )
}

/// Runs a filter without the GIL: its index form (`indices`, handed back
/// as int64) or its point form (the library's own, as Rust callers get it).
fn kept<'py>(
    py: Python<'py>,
    pts: &[[f32; 3]],
    indices: bool,
    index_form: impl FnOnce(&[[f32; 3]]) -> autoshovel_point_cloud::Result<Vec<usize>> + Send,
    point_form: impl FnOnce(&[[f32; 3]]) -> autoshovel_point_cloud::Result<PointCloud> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    if indices {
        let idx = py
            .detach(|| {
                index_form(pts).map(|k| k.into_iter().map(|i| i as i64).collect::<Vec<i64>>())
            })
            .map_err(lib_err)?;
        Ok(PyArray1::from_vec(py, idx).into_any())
    } else {
        let cloud = py.detach(|| point_form(pts)).map_err(lib_err)?;
        Ok(to_numpy(py, cloud.points).into_any())
    }
}

/// Levels a scan by the sensor's roll and pitch ([RS eq. 11]–[RS eq. 12]).
#[pyfunction]
fn level<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    roll_deg: f64,
    pitch_deg: f64,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    const F: &str = "level";
    let array = points_arg(F, "points", points)?;
    let (roll, pitch) = (
        finite(F, "roll_deg", roll_deg)?.to_radians(),
        finite(F, "pitch_deg", pitch_deg)?.to_radians(),
    );
    let pts = as_points(&array);
    let out = py.detach(|| autoshovel_terrain::level(pts, roll, pitch));
    Ok(to_numpy(py, out.points))
}

/// A synthetic LiDAR scan of a Fig. 7 pile, from the generator's
/// settings (`PileParams`) given as keywords.
#[pyfunction]
#[pyo3(signature = (shape, points, scale, roll_deg, pitch_deg, pattern, sensor_height_m, fov_deg, seed))]
#[allow(clippy::too_many_arguments)]
fn generate_pile<'py>(
    py: Python<'py>,
    shape: &str,
    points: usize,
    scale: f64,
    roll_deg: f64,
    pitch_deg: f64,
    pattern: &str,
    sensor_height_m: f64,
    fov_deg: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    const F: &str = "generate_pile";
    let params = autoshovel_terrain::PileParams {
        shape: shape
            .parse()
            .map_err(|e| bad_arg(F, format!("shape: {e}")))?,
        pattern: pattern
            .parse()
            .map_err(|e| bad_arg(F, format!("pattern: {e}")))?,
        points,
        scale: finite(F, "scale", scale)?,
        roll_rad: finite(F, "roll_deg", roll_deg)?.to_radians(),
        pitch_rad: finite(F, "pitch_deg", pitch_deg)?.to_radians(),
        sensor_height_m: finite(F, "sensor_height_m", sensor_height_m)?,
        fov_rad: finite(F, "fov_deg", fov_deg)?.to_radians(),
        seed,
        ..Default::default()
    };
    let cloud = py
        .detach(|| autoshovel_terrain::generate_pile(&params))
        .map_err(|e| match e {
            // The generator names its fields; the caller wrote keywords (in degrees).
            autoshovel_terrain::SurfaceError::BadParameter {
                name,
                value,
                expected,
            } => {
                let (arg, degrees) = match name {
                    "PileParams.points" => ("points", false),
                    "PileParams.scale" => ("scale", false),
                    "PileParams.roll_rad" => ("roll_deg", true),
                    "PileParams.pitch_rad" => ("pitch_deg", true),
                    "PileParams.sensor_height_m" => ("sensor_height_m", false),
                    "PileParams.fov_rad" => ("fov_deg", true),
                    _ => {
                        return lib_err(autoshovel_terrain::SurfaceError::BadParameter {
                            name,
                            value,
                            expected,
                        })
                    }
                };
                let (value, expected) = if degrees {
                    (value.to_degrees(), expected.replace(" [rad]", ""))
                } else {
                    (value, expected.to_string())
                };
                bad_arg(
                    F,
                    format!(
                        "{arg} = {}: expected {expected}",
                        autoshovel_core::config::short(value)
                    ),
                )
            }
            e => lib_err(e),
        })?;
    Ok(to_numpy(py, cloud.points))
}

/// What `perceive` made: the library's `Perceived`, its summary and the
/// name the input goes by (a file, or `<array>`).
#[pyclass(module = "autoshovel._native", frozen)]
pub(crate) struct Perception {
    pub(crate) got: Perceived,
    pub(crate) source: String,
    summary: String,
}

#[pymethods]
impl Perception {
    /// The summary as the JSON of `autoshovel perceive --json`.
    fn summary_json(&self) -> String {
        self.summary.clone()
    }

    /// The cleaned, levelled points (a copy: the perception keeps its own),
    /// in the frame of `surface_height` and `floor_height_m`: about the
    /// scan's origin (`origin` in `summary_json`; zero but for a survey in
    /// map coordinates).
    fn points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        to_numpy(py, self.got.cloud.points.clone())
    }

    /// The fitted surface z = f(x, y) ([RS eq. 21]) at each (x, y).
    fn surface_height<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        y: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (x, y) = (x.as_array(), y.as_array());
        if x.len() != y.len() {
            return Err(bad_arg(
                "surface_height",
                format!("x has {} values, y {}", x.len(), y.len()),
            ));
        }
        let z: Vec<f64> = x
            .iter()
            .zip(y.iter())
            .map(|(&x, &y)| self.got.fit.height(x, y))
            .collect();
        Ok(PyArray1::from_vec(py, z))
    }

    /// The floor height in the levelled frame (m).
    #[getter]
    fn floor_height_m(&self) -> f64 {
        self.got.floor_height_m
    }
}

/// The §3 pipeline on a file (`path`) or an array, with the settings of
/// `PerceptionParams` (a TOML `config` and/or keyword tables).
#[pyfunction]
#[pyo3(signature = (points=None, path=None, config=None, overrides=None))]
fn perceive(
    py: Python<'_>,
    points: Option<&Bound<'_, PyAny>>,
    path: Option<PathBuf>,
    config: Option<&str>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<Perception> {
    const F: &str = "perceive";
    let params: PerceptionParams = settings(F, config, overrides, || {
        autoshovel_core::config::TomlFile::to_toml(&PerceptionParams::default())
    })?;
    let (got, source) = match (points, path) {
        (Some(obj), None) => {
            let array = points_arg(F, "points", obj)?;
            let cloud = PointCloud::new(as_points(&array).to_vec());
            let got = py
                .detach(|| autoshovel_terrain::perceive::perceive(&cloud, &params))
                .map_err(lib_err)?;
            (got, "<array>".to_string())
        }
        (None, Some(p)) => {
            // A read error names the file; the pipeline's are prefixed
            // with it (the rule of the CLI's jobs).
            let got = py
                .detach(|| {
                    autoshovel_jobs::read_and_perceive(&p, &params, false)
                        .map_err(|e| crate::message(&e))
                })
                .map_err(crate::AutoshovelError::new_err)?;
            (got, p.display().to_string())
        }
        _ => {
            return Err(bad_arg(
                F,
                "give the points (an (N, 3) float32 array) or a path, not both",
            ))
        }
    };
    let summary = summary_json(&PerceiveSummary::new(Path::new(&source), &params, &got))?;
    Ok(Perception {
        got,
        source,
        summary,
    })
}

/// For `crates/front/py/bench/bench_calls.py`: the wall times (s) of `repeats`
/// calls of one library function made from Rust, on the very array the
/// script times from Python (the same data, process and machine state).
/// `kind`: voxel (leaf 0.05 m), statistical (k 50, 1σ), radius (0.05 m, 3),
/// pass (z in [lo, hi]), perceive (defaults).
#[pyfunction]
fn _time_in_rust(
    py: Python<'_>,
    kind: &str,
    points: &Bound<'_, PyAny>,
    repeats: usize,
    lo: f64,
    hi: f64,
) -> PyResult<Vec<f64>> {
    const F: &str = "_time_in_rust";
    let array = points_arg(F, "points", points)?;
    let pts = as_points(&array);
    let cloud = if kind == "perceive" {
        Some(PointCloud::new(pts.to_vec()))
    } else {
        None
    };
    let run = |pts: &[[f32; 3]]| -> Result<usize, String> {
        Ok(match kind {
            "voxel" => filter::voxel_grid(pts, &VoxelGridParams::cube(0.05))
                .map_err(|e| e.to_string())?
                .len(),
            "statistical" => filter::statistical_outlier_removal(
                pts,
                &StatisticalOutlierParams {
                    mean_k: 50,
                    std_mul: 1.0,
                    sides: OutlierSides::Above,
                },
            )
            .map_err(|e| e.to_string())?
            .len(),
            "radius" => filter::radius_outlier_removal(
                pts,
                &RadiusOutlierParams {
                    radius_m: 0.05,
                    min_neighbors: 3,
                },
            )
            .map_err(|e| e.to_string())?
            .len(),
            "pass" => filter::pass_through(
                pts,
                &PassThroughParams {
                    axis: Axis::Z,
                    min_m: lo,
                    max_m: hi,
                    keep_inside: true,
                },
            )
            .map_err(|e| e.to_string())?
            .len(),
            "perceive" => autoshovel_terrain::perceive::perceive(
                cloud.as_ref().expect("made above"),
                &PerceptionParams::default(),
            )
            .map_err(|e| e.to_string())?
            .cloud
            .len(),
            other => {
                return Err(format!(
                    "kind = {other:?}: expected voxel, statistical, radius, pass or perceive"
                ))
            }
        })
    };
    py.detach(|| {
        (0..repeats)
            .map(|_| {
                let t0 = std::time::Instant::now();
                run(pts).map(|_| t0.elapsed().as_secs_f64())
            })
            .collect::<Result<Vec<f64>, String>>()
    })
    .map_err(|e| bad_arg(F, e))
}

/// Adds this module's functions to `m`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Perception>()?;
    m.add_function(wrap_pyfunction!(read_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(write_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(voxel_grid, m)?)?;
    m.add_function(wrap_pyfunction!(statistical_outlier_removal, m)?)?;
    m.add_function(wrap_pyfunction!(radius_outlier_removal, m)?)?;
    m.add_function(wrap_pyfunction!(pass_through, m)?)?;
    m.add_function(wrap_pyfunction!(level, m)?)?;
    m.add_function(wrap_pyfunction!(generate_pile, m)?)?;
    m.add_function(wrap_pyfunction!(perceive, m)?)?;
    m.add_function(wrap_pyfunction!(_time_in_rust, m)?)?;
    Ok(())
}
