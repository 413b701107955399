//! TOML configuration files (machine profiles, scenarios) with errors that
//! name the file, the line and the key at fault.
//!
//! One error type and the line-finding helpers, shared by every crate that
//! reads a TOML file: read the text ([`read`]), deserialise it with the
//! span of a syntax or type error turned into `file:line:column` ([`parse`]),
//! then check values and report a bad one at the line of its key
//! ([`invalid`], [`line_of_key`]).

use std::fmt::Display;
use std::path::{Path, PathBuf};

/// What can go wrong with a configuration file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Not valid TOML, or unknown, missing or mistyped keys.
    #[error("{}: {message}", at(file, *line, *column))]
    Parse {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line (0 when unknown).
        line: usize,
        /// 1-based column (0 when unknown).
        column: usize,
        /// The entry at fault as written, under its table
        /// (`[statistical] mean_k = "many"`), when the error is on one.
        entry: Option<String>,
        /// What is wrong.
        message: String,
    },
    /// A value out of range or contradicting another.
    #[error("{}: {key} = {value} is invalid: expected {expected}", at(file, *line, 0))]
    Invalid {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line of the key (0 when unknown).
        line: usize,
        /// `[table] key`, or `key` at the top level.
        key: String,
        /// The value given.
        value: String,
        /// What it should be.
        expected: String,
    },
}

/// A checked configuration read from TOML: implement [`TomlFile::check`]
/// and get loading, parsing and printing that name the file, line and key
/// at fault.
pub trait TomlFile: serde::de::DeserializeOwned + serde::Serialize {
    /// The error of the crate that owns the type.
    type Error: From<ConfigError>;

    /// Check every value once, at the edge; `text` and `file` locate errors
    /// (see [`invalid`]).
    fn check(&self, text: &str, file: &str) -> Result<(), Self::Error>;

    /// Parse and check `text`; `file` names it in errors.
    fn from_toml(text: &str, file: &str) -> Result<Self, Self::Error> {
        let value: Self = parse(text, file)?;
        value.check(text, file)?;
        Ok(value)
    }

    /// Read, parse and check a file.
    fn load(path: &Path) -> Result<Self, Self::Error> {
        let text = read(path)?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// As TOML (without the comments of an embedded file); loads back to an
    /// equal value.
    fn to_toml(&self) -> String {
        toml::to_string_pretty(self).expect("a checked configuration serialises")
    }
}

/// Deserialises an (x, y) point, refusing any other number of coordinates
/// (`#[serde(deserialize_with = "xy")]`): a third coordinate in a 2-D file
/// is a mistake to report, not to drop.
pub fn xy<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let v: Vec<f64> = serde::Deserialize::deserialize(d)?;
    to_xy(&v).map_err(serde::de::Error::custom)
}

/// [`xy`] for a list of points.
pub fn xy_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
    let v: Vec<Vec<f64>> = serde::Deserialize::deserialize(d)?;
    v.iter()
        .enumerate()
        .map(|(i, p)| {
            to_xy(p).map_err(|e| serde::de::Error::custom(format!("point {}: {e}", i + 1)))
        })
        .collect()
}

fn to_xy(v: &[f64]) -> Result<[f64; 2], String> {
    match v {
        [x, y] => Ok([*x, *y]),
        _ => Err(format!(
            "{:?} has {} coordinate(s); expected 2 (x, y) [m]",
            v,
            v.len()
        )),
    }
}

/// The text of a configuration file.
pub fn read(path: &Path) -> Result<String, ConfigError> {
    std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// `file:line:column`, `file:line` without a column, `file` alone when the
/// line is unknown (0).
fn at(file: &str, line: usize, column: usize) -> String {
    match (line, column) {
        (0, _) => file.to_string(),
        (_, 0) => format!("{file}:{line}"),
        _ => format!("{file}:{line}:{column}"),
    }
}

/// The entry on the line holding byte `offset` of `text`, under the
/// table it belongs to (`[table] key = value`), if that line is an entry.
fn entry_at(text: &str, offset: usize) -> Option<String> {
    let (line, _) = line_col(text, offset);
    let lines: Vec<&str> = text.lines().collect();
    let own = lines.get(line.checked_sub(1)?)?.trim();
    if own.starts_with('[') || !own.contains('=') {
        return None;
    }
    let table = lines[..line - 1]
        .iter()
        .rev()
        .map(|l| l.trim())
        .find(|l| l.starts_with('['));
    Some(match table {
        Some(t) => format!("{t} {own}"),
        None => own.to_string(),
    })
}

/// Deserialise `text` (named `file` in errors); a TOML error becomes
/// [`ConfigError::Parse`] at the line and column of its span.
pub fn parse<T: serde::de::DeserializeOwned>(text: &str, file: &str) -> Result<T, ConfigError> {
    toml::from_str(text).map_err(|e| {
        let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((0, 0));
        ConfigError::Parse {
            file: file.to_string(),
            line,
            column,
            entry: e.span().and_then(|s| entry_at(text, s.start)),
            message: short_floats(e.message().trim()),
        }
    })
}

/// `message` with every "floating point `…`" of serde's type errors
/// printed short (`1e-300`, not 300 digits).
fn short_floats(message: &str) -> String {
    const TAG: &str = "floating point `";
    let mut out = String::new();
    let mut rest = message;
    while let Some(at) = rest.find(TAG) {
        let (head, tail) = rest.split_at(at + TAG.len());
        out.push_str(head);
        let end = tail.find('`').unwrap_or(tail.len());
        match tail[..end].parse::<f64>() {
            Ok(v) => out.push_str(&short(v)),
            Err(_) => out.push_str(&tail[..end]),
        }
        rest = &tail[end..];
    }
    out.push_str(rest);
    out
}

/// [`ConfigError::Invalid`] for `key` of the `occurrence`-th (0-based)
/// `[table]` / `[[table]]` (the top level when `table` is empty), located
/// with [`line_of_key`].
pub fn invalid(
    text: &str,
    file: &str,
    (table, occurrence): (&str, usize),
    key: &str,
    value: impl Display,
    expected: impl Into<String>,
) -> ConfigError {
    ConfigError::Invalid {
        file: file.to_string(),
        line: line_of_key(text, table, occurrence, key),
        key: if table.is_empty() {
            key.to_string()
        } else {
            format!("[{table}] {key}")
        },
        value: value.to_string(),
        expected: expected.into(),
    }
}

/// Checks every `([table], key, value)` with `ok`; the first that fails is
/// [`invalid`] with `expected` (e.g. [`POSITIVE`]).
pub fn check_each(
    text: &str,
    file: &str,
    values: &[(&str, &str, f64)],
    (ok, expected): (fn(f64) -> bool, &str),
) -> Result<(), ConfigError> {
    for &(table, key, v) in values {
        if !ok(v) {
            return Err(invalid(text, file, (table, 0), key, short(v), expected));
        }
    }
    Ok(())
}

/// A number as a person writes it: plain for ordinary magnitudes, with an
/// exponent for very large or small ones (`1e308`, not 309 digits).
pub fn short(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A setting that sizes work past a ceiling: its `(table, key, value)` and
/// whether restoring its built-in value would bring the work within the
/// ceiling.
pub type WorkSetting<'a> = (&'a str, &'a str, f64, bool);

/// [`ConfigError::Invalid`] for work past a ceiling, at the setting at
/// fault: the first of `settings` whose built-in value would meet the
/// ceiling, else the last. `expected` states the ceiling and the estimate.
pub fn over_ceiling(
    text: &str,
    file: &str,
    settings: &[WorkSetting],
    expected: String,
) -> ConfigError {
    let &(table, key, value, _) = settings
        .iter()
        .find(|s| s.3)
        .or(settings.last())
        .expect("at least one setting");
    invalid(text, file, (table, 0), key, short(value), expected)
}

/// `v` to three significant figures, for estimates in messages:
/// `7.01e9`, `729`, `0.0123`, `7.01e-6`.
pub fn approx(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() {
        format!("{v}")
    } else if (0.01..1e5).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.2e}")
    }
}

/// `bytes` in B, kB, MB, GB, TB or PB (decimal, three significant
/// figures), for work estimates in messages.
pub fn bytes(bytes: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB"];
    let mut v = bytes;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < units.len() {
        v /= 1000.0;
        u += 1;
    }
    if v >= 1000.0 {
        return format!("{v:.1e} PB");
    }
    let digits = if v >= 100.0 || u == 0 {
        0
    } else if v >= 10.0 {
        1
    } else {
        2
    };
    format!("{v:.digits$} {}", units[u])
}

/// A finite length in (0, 1 km] (m), for [`check_each`]: no machine or
/// site part is longer, and geometry beyond it overflows the f32 clouds
/// and the planners' grids.
pub const LENGTH: (fn(f64) -> bool, &str) = (
    |v| v.is_finite() && v > 0.0 && v <= 1e3,
    "a length in (0, 1000] m",
);

/// A finite value > 0, for [`check_each`].
pub const POSITIVE: (fn(f64) -> bool, &str) = (|v| v.is_finite() && v > 0.0, "a finite value > 0");

/// A finite value ≥ 0, for [`check_each`].
pub const NON_NEGATIVE: (fn(f64) -> bool, &str) =
    (|v| v.is_finite() && v >= 0.0, "a finite value >= 0");

/// 1-based line and column of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map_or(offset, |i| offset - i - 1) + 1;
    (line, column)
}

/// The 1-based line of `key = …` in the `occurrence`-th (0-based) table
/// headed `[table]` or `[[table]]`; a top-level key when `table` is empty.
/// Falls back to the table's header line, and to 0 when the table is absent.
pub fn line_of_key(text: &str, table: &str, occurrence: usize, key: &str) -> usize {
    let mut seen: Option<usize> = if table.is_empty() { Some(0) } else { None };
    let mut active = table.is_empty();
    let mut header_line = 0;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            let name = t.trim_start_matches('[').split(']').next().map(str::trim);
            if !table.is_empty() && name == Some(table) {
                let n = seen.map_or(0, |n| n + 1);
                seen = Some(n);
                active = n == occurrence;
                if active {
                    header_line = i + 1;
                }
            } else {
                active = false;
            }
            continue;
        }
        if active {
            if let Some((k, _)) = t.split_once('=') {
                if k.trim() == key {
                    return i + 1;
                }
            }
        }
    }
    header_line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_found_in_their_table_and_occurrence() {
        let text = "name = \"a\"\n[dig]\nx = 1\n[[obstacle]]\nr = 1\n[[obstacle]]\n# c\nr = 2\n";
        assert_eq!(line_of_key(text, "", 0, "name"), 1);
        assert_eq!(line_of_key(text, "dig", 0, "x"), 3);
        assert_eq!(line_of_key(text, "obstacle", 0, "r"), 5);
        assert_eq!(line_of_key(text, "obstacle", 1, "r"), 8);
        assert_eq!(line_of_key(text, "obstacle", 1, "missing"), 6);
        assert_eq!(line_of_key(text, "nothing", 0, "x"), 0);
        assert_eq!(line_col("ab\ncd", 4), (2, 2));
    }

    #[test]
    fn a_parse_error_names_its_entry_and_table() {
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct S {
            top: u32,
            inner: Inner,
        }
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct Inner {
            k: usize,
        }
        let e = parse::<S>("top = 1\n[inner]\n  k = \"many\"\n", "f.toml").unwrap_err();
        let ConfigError::Parse { line, entry, .. } = &e else {
            panic!("{e}")
        };
        assert_eq!((*line, entry.as_deref()), (3, Some("[inner] k = \"many\"")));
        assert!(e.to_string().starts_with("f.toml:3:"), "{e}");
        let e = parse::<S>("top = -1\n[inner]\nk = 1\n", "f.toml").unwrap_err();
        assert!(matches!(&e, ConfigError::Parse { entry: Some(x), .. } if x == "top = -1"));
        // Unknown location: the file alone.
        let e = ConfigError::Invalid {
            file: "g".into(),
            line: 0,
            key: "[a] b".into(),
            value: "0".into(),
            expected: "more".into(),
        };
        assert_eq!(e.to_string(), "g: [a] b = 0 is invalid: expected more");
        assert_eq!(line_col("é", 1), (1, 1));
    }

    #[test]
    fn parse_errors_name_file_line_and_column() {
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct S {
            a: f64,
        }
        let e = parse::<S>("\n\na = \"x\"\n", "f.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("f.toml:3:5:"), "{e}");
        let e = invalid("[t]\nk = 2\n", "f.toml", ("t", 0), "k", 2.0, "less than 1");
        assert_eq!(
            e.to_string(),
            "f.toml:2: [t] k = 2 is invalid: expected less than 1"
        );
    }
}

#[cfg(test)]
mod xy_tests {
    #[derive(Debug, serde::Deserialize)]
    struct T {
        #[serde(deserialize_with = "super::xy")]
        at: [f64; 2],
        #[serde(deserialize_with = "super::xy_list")]
        ring: Vec<[f64; 2]>,
    }

    #[test]
    fn points_need_exactly_two_coordinates() {
        let t: T = super::parse("at = [1, 2]\nring = [[0, 0], [1, 0.5]]\n", "f").unwrap();
        assert_eq!((t.at, t.ring), ([1.0, 2.0], vec![[0.0, 0.0], [1.0, 0.5]]));
        let e =
            super::parse::<T>("at = [1, 2]\nring = [[0, 0], [1, 2, 3]]\n", "f.toml").unwrap_err();
        let m = e.to_string();
        assert!(
            m.starts_with("f.toml:2:") && m.contains("point 2") && m.contains("3 coordinate"),
            "{m}"
        );
        let e = super::parse::<T>("at = [1]\nring = []\n", "f.toml").unwrap_err();
        assert!(e.to_string().starts_with("f.toml:1:"), "{e}");
    }
}

#[cfg(test)]
mod bytes_tests {
    #[test]
    fn sizes_read_in_decimal_units() {
        assert_eq!(super::bytes(512.0), "512 B");
        assert_eq!(super::bytes(1500.0), "1.50 kB");
        assert_eq!(super::bytes(63e9), "63.0 GB");
        assert_eq!(super::bytes(180e6), "180 MB");
        assert_eq!(super::bytes(2.9e16), "29.0 PB");
        assert_eq!(super::bytes(2.9e21), "2.9e6 PB");
        assert_eq!(super::approx(7.013481971e9), "7.01e9");
        assert_eq!(super::approx(729.27), "729");
        assert_eq!(super::approx(0.012345), "0.0123");
        assert_eq!(super::approx(7.0134819714e-6), "7.01e-6");
        assert_eq!(super::approx(1e7), "1.00e7");
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct N {
            n: usize,
        }
        let e = super::parse::<N>("n = 1e-300\n", "f.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("floating point `1e-300`"), "{e}");
    }
}
