//! CSV output (RFC 4180 quoting, `\n` line ends): numeric tables written at
//! full precision, and tables of arbitrary text cells.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::error::ReportError;

/// Writes a header line and rows of numbers to `path`.
///
/// Every value is written in the shortest form that parses back to the same
/// `f64` (`{}` formatting; `{:e}` below 1e-5 or from 1e16 in magnitude, to
/// avoid hundreds of zeros). NaN and infinities are written as `NaN`, `inf`
/// and `-inf`. A row whose length differs from the header's is an error
/// (the lines before it are already written).
pub fn write_csv(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<f64>>,
) -> Result<(), ReportError> {
    let mut out = CsvWriter::create(path)?;
    out.record(header.iter().copied())?;
    let mut line = String::new();
    for (i, row) in rows.into_iter().enumerate() {
        out.check_len(i, row.len(), header.len())?;
        line.clear();
        for (j, v) in row.iter().enumerate() {
            if j > 0 {
                line.push(',');
            }
            line.push_str(&format_f64(*v));
        }
        line.push('\n');
        out.write(line.as_bytes())?;
    }
    out.finish()
}

/// Writes a header line and rows of text cells to `path`, quoting cells that
/// contain commas, quotes or line breaks. Every row must be as long as the
/// header.
pub fn write_csv_cells(
    path: &Path,
    header: &[&str],
    rows: &[Vec<String>],
) -> Result<(), ReportError> {
    let mut out = CsvWriter::create(path)?;
    for (i, row) in rows.iter().enumerate() {
        out.check_len(i, row.len(), header.len())?;
    }
    out.record(header.iter().copied())?;
    for row in rows {
        out.record(row.iter().map(String::as_str))?;
    }
    out.finish()
}

/// Shortest round-trip text of `v`, as the CSV writers print numbers (for
/// callers mixing text and numbers in [`write_csv_cells`]).
pub fn format_f64(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-5..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A number for a CSV cell: [`format_f64`] when finite, an empty cell
/// otherwise (NaN and ±inf mean "none" in the tables that use it).
pub fn finite_cell(v: f64) -> String {
    if v.is_finite() {
        format_f64(v)
    } else {
        String::new()
    }
}

/// `cell`, quoted if it has to be.
fn quote(cell: &str) -> std::borrow::Cow<'_, str> {
    if cell.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", cell.replace('"', "\"\"")).into()
    } else {
        cell.into()
    }
}

/// A buffered file that reports errors with its path.
struct CsvWriter<'a> {
    path: &'a Path,
    out: BufWriter<File>,
}

impl<'a> CsvWriter<'a> {
    fn create(path: &'a Path) -> Result<Self, ReportError> {
        let file = File::create(path).map_err(|e| ReportError::io(path, e))?;
        Ok(Self {
            path,
            out: BufWriter::new(file),
        })
    }

    fn check_len(&self, row: usize, len: usize, want: usize) -> Result<(), ReportError> {
        if len == want {
            Ok(())
        } else {
            Err(ReportError::invalid(format!(
                "{}: row {row} has {len} cells but the header has {want}",
                self.path.display()
            )))
        }
    }

    fn write(&mut self, bytes: &[u8]) -> Result<(), ReportError> {
        self.out
            .write_all(bytes)
            .map_err(|e| ReportError::io(self.path, e))
    }

    fn record<'c>(&mut self, cells: impl Iterator<Item = &'c str>) -> Result<(), ReportError> {
        let mut line = String::new();
        for (j, cell) in cells.enumerate() {
            if j > 0 {
                line.push(',');
            }
            line.push_str(&quote(cell));
        }
        line.push('\n');
        self.write(line.as_bytes())
    }

    fn finish(mut self) -> Result<(), ReportError> {
        self.out.flush().map_err(|e| ReportError::io(self.path, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_round_trip_and_stay_short() {
        for v in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1.0 / 3.0,
            1e-7,
            1e300,
            -2.5e-300,
            12345.678,
        ] {
            let s = format_f64(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
            assert!(s.len() < 26, "{s}");
        }
        assert_eq!(format_f64(1.0), "1");
        assert_eq!(format_f64(f64::NAN), "NaN");
        assert_eq!(format_f64(f64::NEG_INFINITY), "-inf");
    }

    #[test]
    fn quoting() {
        assert_eq!(quote("plain"), "plain");
        assert_eq!(quote("a,b"), "\"a,b\"");
        assert_eq!(quote("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(quote("two\nlines"), "\"two\nlines\"");
    }
}
