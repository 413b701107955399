//! The native half of the Python package `autoshovel` (crates/front/py/README.md).
//!
//! Each function here is one library call, as `autoshovel-jobs`
//! makes it for the binary: arguments checked at the edge (naming the
//! argument and what was expected), the GIL released while the library
//! works, the library's own error messages passed on unchanged as
//! `autoshovel.AutoshovelError`, and summaries handed over as the JSON the
//! CLI's `summary.json` holds, which `python/autoshovel` turns into typed
//! objects. Point clouds cross as numpy `(N, 3)` float32 arrays: read in
//! place (the filters take `&[Point]`), and handed back by moving the
//! library's `Vec` into the array, so neither way copies.

use numpy::ndarray::Array2;
use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

mod cloud;
mod jobs;
mod survey;

pyo3::create_exception!(
    _native,
    AutoshovelError,
    pyo3::exceptions::PyException,
    "An error of the autoshovel library, with the message the command line prints."
);

/// The message of a library error and its causes, as the CLI prints them
/// (`error: {e:#}`).
pub(crate) fn message(e: &dyn std::error::Error) -> String {
    autoshovel_core::error_chain(e)
}

/// The library's error as Python's `AutoshovelError` with [`message`].
pub(crate) fn lib_err(e: impl std::error::Error) -> PyErr {
    AutoshovelError::new_err(message(&e))
}

/// A bad argument: `ValueError("{func}(): {what}")`.
pub(crate) fn bad_arg(func: &str, what: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{func}(): {what}"))
}

/// How an object looks, for an error message ("float64 array of shape (10, 2)").
fn describe(obj: &Bound<'_, PyAny>) -> String {
    let attr = |name: &str| {
        obj.getattr(name)
            .ok()
            .and_then(|v| v.str().ok())
            .map(|s| s.to_string())
    };
    match (attr("dtype"), attr("shape")) {
        (Some(dtype), Some(shape)) => format!("a {dtype} array of shape {shape}"),
        _ => obj
            .get_type()
            .name()
            .map(|n| format!("a {n}"))
            .unwrap_or_else(|_| "an object".into()),
    }
}

/// The `(N, 3)` float32 C-contiguous array `obj` (argument `name` of
/// `func`), borrowed read-only; anything else is a `TypeError` or
/// `ValueError` saying what was expected and how to get it.
pub(crate) fn points_arg<'py>(
    func: &str,
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArray2<'py, f32>> {
    const HOW: &str = "np.ascontiguousarray(a, dtype=np.float32).reshape(-1, 3)";
    let array = obj.cast::<PyArray2<f32>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{func}(): {name} must be a float32 numpy array of shape (N, 3), got {}; convert with {HOW}",
            describe(obj)
        ))
    })?;
    if array.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{func}(): {name} must have shape (N, 3), got {:?}",
            array.shape()
        )));
    }
    if !array.is_c_contiguous() {
        return Err(PyValueError::new_err(format!(
            "{func}(): {name} must be C-contiguous (row after row), got a strided view; convert with {HOW}"
        )));
    }
    array
        .try_readonly()
        .map_err(|e| PyValueError::new_err(format!("{func}(): {name} cannot be read: {e}")))
}

/// The points of a checked array, in place.
pub(crate) fn as_points<'a>(array: &'a PyReadonlyArray2<'_, f32>) -> &'a [[f32; 3]] {
    let flat = array.as_slice().expect("checked C-contiguous");
    let (points, rest) = flat.as_chunks::<3>();
    debug_assert!(rest.is_empty());
    points
}

/// Points into a numpy `(N, 3)` float32 array, moving the buffer (no copy).
pub(crate) fn to_numpy(py: Python<'_>, points: Vec<[f32; 3]>) -> Bound<'_, PyArray2<f32>> {
    let n = points.len();
    let flat: Vec<f32> = points.into_flattened();
    let array = Array2::from_shape_vec((n, 3), flat).expect("n × 3 values");
    PyArray2::from_owned_array(py, array)
}

/// Rows of `K` f64 values into a numpy `(N, K)` float64 array (no copy).
pub(crate) fn rows_to_numpy<const K: usize>(
    py: Python<'_>,
    rows: Vec<[f64; K]>,
) -> Bound<'_, PyArray2<f64>> {
    let n = rows.len();
    let array = Array2::from_shape_vec((n, K), rows.into_flattened()).expect("n × K values");
    PyArray2::from_owned_array(py, array)
}

/// A summary as the JSON text of the CLI's `summary.json` (non-finite
/// numbers are `null` there and here).
pub(crate) fn summary_json<S: serde::Serialize>(summary: &S) -> PyResult<String> {
    serde_json::to_string(summary).map_err(lib_err)
}

/// One of `choices` (name, value) by its name, or a `ValueError` listing them.
pub(crate) fn choose<T: Copy>(
    func: &str,
    arg: &str,
    value: &str,
    choices: &[(&str, T)],
) -> PyResult<T> {
    choices
        .iter()
        .find(|(n, _)| *n == value)
        .map(|(_, v)| *v)
        .ok_or_else(|| {
            let names: Vec<&str> = choices.iter().map(|(n, _)| *n).collect();
            bad_arg(
                func,
                format!("{arg} = {value:?}: expected one of {}", names.join(", ")),
            )
        })
}

/// A finite number argument, or a `ValueError` naming it.
pub(crate) fn finite(func: &str, arg: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        // As Python writes them.
        let v = if v.is_nan() {
            "nan"
        } else if v > 0.0 {
            "inf"
        } else {
            "-inf"
        };
        Err(bad_arg(
            func,
            format!("{arg} = {v}: expected a finite number"),
        ))
    }
}

/// Settings of a TOML settings type from keyword arguments: the library's
/// defaults (or the file `config`), each keyword (a value, or a dict for a
/// table) laid over them, then parsed and checked as a file would be, so
/// an unknown key or a bad value gets the library's message naming it.
pub(crate) fn settings<T>(
    func: &str,
    config: Option<&str>,
    overrides: Option<&Bound<'_, PyDict>>,
    default_toml: impl FnOnce() -> String,
) -> PyResult<T>
where
    T: autoshovel_core::config::TomlFile,
    T::Error: std::error::Error,
{
    let empty = overrides.is_none_or(|d| d.is_empty());
    if let (Some(path), true) = (config, empty) {
        return T::load(std::path::Path::new(path)).map_err(lib_err);
    }
    let base_text = match config {
        Some(path) => autoshovel_core::config::read(std::path::Path::new(path)).map_err(lib_err)?,
        None => default_toml(),
    };
    let mut base: toml::Table = base_text.parse().map_err(|e: toml::de::Error| {
        AutoshovelError::new_err(format!("{}: {e}", config.unwrap_or("the defaults")))
    })?;
    if let Some(d) = overrides {
        overlay(func, "", &mut base, d)?;
    }
    let text = toml::to_string(&base).map_err(lib_err)?;
    let source = match config {
        Some(path) => format!("{path} with {func}()'s keyword arguments"),
        None => format!("{func}()'s keyword arguments"),
    };
    // The merged text is the binding's, never the caller's: errors name
    // the entry at fault by table and key, not by a line of that text
    // (parsed here to read the entry; checked without the text, so that
    // no line is given).
    let value: T = autoshovel_core::config::parse(&text, &source).map_err(|e| match e {
        autoshovel_core::config::ConfigError::Parse {
            entry: Some(entry),
            message,
            ..
        } => AutoshovelError::new_err(format!("{source}: {entry}: {message}")),
        autoshovel_core::config::ConfigError::Parse { message, .. } => {
            AutoshovelError::new_err(format!("{source}: {message}"))
        }
        other => lib_err(other),
    })?;
    value.check("", &source).map_err(lib_err)?;
    Ok(value)
}

/// Lays the keywords of `d` over `table` (a nested dict over a table).
fn overlay(
    func: &str,
    prefix: &str,
    table: &mut toml::Table,
    d: &Bound<'_, PyDict>,
) -> PyResult<()> {
    for (k, v) in d.iter() {
        let key: String = k
            .extract()
            .map_err(|_| bad_arg(func, format!("{prefix}{k}: keys must be strings")))?;
        let path = format!("{prefix}{key}");
        match (table.get_mut(&key), v.cast::<PyDict>()) {
            (Some(toml::Value::Table(inner)), Ok(sub)) => {
                overlay(func, &format!("{path}."), inner, sub)?
            }
            _ => {
                table.insert(key, to_toml(func, &path, &v)?);
            }
        }
    }
    Ok(())
}

/// A Python value as TOML: bool, int, finite float, str, list, tuple, dict.
fn to_toml(func: &str, path: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        let i: i64 = v
            .extract()
            .map_err(|_| bad_arg(func, format!("{path} = {v}: an integer beyond 64 bits")))?;
        return Ok(toml::Value::Integer(i));
    }
    if v.is_instance_of::<PyFloat>() {
        let x: f64 = v.extract()?;
        return Ok(toml::Value::Float(finite(func, path, x)?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: Vec<toml::Value> = v
            .try_iter()?
            .enumerate()
            .map(|(i, item)| to_toml(func, &format!("{path}[{i}]"), &item?))
            .collect::<PyResult<_>>()?;
        return Ok(toml::Value::Array(items));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        overlay(func, &format!("{path}."), &mut t, d)?;
        return Ok(toml::Value::Table(t));
    }
    // numpy scalars and other numbers.
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(finite(func, path, x)?));
    }
    Err(bad_arg(
        func,
        format!(
            "{path} = {}: expected a bool, number, string, list or dict",
            describe(v)
        ),
    ))
}

/// The module `autoshovel._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("AutoshovelError", m.py().get_type::<AutoshovelError>())?;
    m.add(
        "DEFAULT_POLISH_EVALUATIONS",
        autoshovel_rope_shovel_dig::plan::DEFAULT_POLISH_EVALUATIONS,
    )?;
    m.add(
        "DEFAULT_HEADING_TOLERANCE_DEG",
        autoshovel_walk_planner::DEFAULT_HEADING_TOLERANCE_DEG,
    )?;
    cloud::register(m)?;
    jobs::register(m)?;
    survey::register(m)?;
    Ok(())
}
