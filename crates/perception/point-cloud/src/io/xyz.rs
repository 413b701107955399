//! Plain text clouds (`.xyz`, `.csv`, `.txt`): one point per line, fields
//! separated by whitespace, commas or semicolons (one separator for the
//! whole file). A header line of column names, if present, picks x, y and z
//! by name in any case and order; its other columns are attributes (f64,
//! named as PDAL names the dimension where it has one, `intensity` →
//! `Intensity`), except one with a value that is not a number, which is
//! ignored and counted. Without a header the first three fields are x, y,
//! z and any others are read past. `#` starts a comment.
//! Decimal commas and mixed separators are refused, not guessed. Written
//! with attributes, a file gets a header line naming them.

use std::io::{BufRead, Write};

use super::input::{line_str, Input, Points};
use super::text;

/// Longest line accepted (bytes).
const MAX_LINE: usize = 1 << 16;
/// Lines sampled before the point vector is sized from the bytes per line.
const SAMPLE_LINES: usize = 4096;

/// How the fields of a line are separated: decided once, on the first
/// line that is not blank or a comment, and held for the whole file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Separator {
    /// Spaces or tabs.
    Whitespace,
    /// `,` (fields may carry spaces around them).
    Comma,
    /// `;` (fields may carry spaces around them).
    Semicolon,
}

impl Separator {
    fn of(line: &str) -> Self {
        if line.contains(';') {
            Separator::Semicolon
        } else if line.contains(',') {
            Separator::Comma
        } else {
            Separator::Whitespace
        }
    }

    fn name(self) -> &'static str {
        match self {
            Separator::Whitespace => "whitespace",
            Separator::Comma => "','",
            Separator::Semicolon => "';'",
        }
    }

    fn split(self, line: &str) -> Vec<&str> {
        match self {
            Separator::Whitespace => line.split_ascii_whitespace().collect(),
            Separator::Comma => line.split(',').map(str::trim).collect(),
            Separator::Semicolon => line.split(';').map(str::trim).collect(),
        }
    }
}

/// Which columns hold x, y and z.
#[derive(Debug, Clone, Copy)]
struct Layout {
    sep: Separator,
    xyz: [usize; 3],
}

/// An attribute column of a text file: its field and rows; `None` once
/// a value was not a number (then the column is dropped and counted).
type TextColumn = (usize, String, Option<Vec<f64>>);

/// The columns of a header line: x, y and z by name (any case, any order,
/// quotes stripped), and the others by field and name (a repeated name
/// after its first is left out).
fn header_layout(
    fields: &[&str],
    sep: Separator,
    full: &str,
) -> Result<(Layout, Vec<TextColumn>), String> {
    let given: Vec<&str> = fields
        .iter()
        .map(|f| f.trim_matches(|c| c == '"' || c == '\''))
        .collect();
    let names: Vec<String> = given.iter().map(|f| f.to_ascii_lowercase()).collect();
    let mut xyz = [0usize; 3];
    for (a, axis) in ["x", "y", "z"].into_iter().enumerate() {
        let at: Vec<usize> = (0..names.len()).filter(|&i| names[i] == axis).collect();
        match at[..] {
            [i] => xyz[a] = i,
            [] => {
                return Err(format!(
                    "line 1: the header {:?} names no {axis:?} column; x, y and z are needed \
                     by name (any case, any order), or no header at all for x y z by position",
                    full.trim()
                ))
            }
            _ => {
                return Err(format!(
                "line 1: the header {:?} names {axis:?} {} times; which one is meant is ambiguous",
                full.trim(),
                at.len()
            ))
            }
        }
    }
    let mut columns: Vec<TextColumn> = Vec::new();
    for (i, name) in given.iter().enumerate() {
        let name = crate::attributes::pdal_name(name);
        if !xyz.contains(&i) && !columns.iter().any(|(_, n, _)| *n == name) {
            columns.push((i, name, Some(Vec::new())));
        }
    }
    Ok((Layout { sep, xyz }, columns))
}

fn parse_field<T: std::str::FromStr>(s: &str, sep: Separator) -> Result<T, String> {
    s.parse::<T>().map_err(|_| {
        if sep == Separator::Semicolon
            && s.contains(',')
            && s.replace(',', ".").parse::<f32>().is_ok()
        {
            format!(
                "{s:?} has a decimal comma; write decimals with '.' (the file is read with ';' \
                 between fields and does not guess)"
            )
        } else {
            format!("{s:?} is not a number")
        }
    })
}

/// The origin an axis is held about, from its first value `v` (the word
/// read in f64) and `f` (the same word in f32): its whole units when the
/// word says more than its f32 holds and it is far from zero (a survey's
/// easting), else zero (every f32 a file of f32 values names is kept bit
/// for bit).
fn origin_for(v: f64, f: f32) -> f64 {
    let f32_holds_it = format!("{f}").parse::<f64>().is_ok_and(|back| back == v);
    if f32_holds_it || v.abs() <= super::input::ORIGIN_FREE {
        0.0
    } else {
        v.round()
    }
}

/// Reads a text cloud into `out`: a header line of column names, if there
/// is one, picks x, y and z by name; without one the first three fields are
/// x, y, z. The separator (whitespace, `,` or `;`) is taken from the first
/// line and must hold for every line; decimal commas are refused.
///
/// Coordinates far from zero (a survey's eastings and northings) are read
/// in f64 about an origin taken from the first point; near zero, each is
/// the f32 its word names.
pub(crate) fn read<R: BufRead>(input: &mut Input<'_, R>, out: &mut Points) -> crate::Result<()> {
    out.origin_from_first = true;
    let mut line = Vec::new();
    let mut line_no = 0u64;
    let mut data_lines = 0usize;
    let mut layout: Option<Layout> = None;
    let mut columns: Vec<TextColumn> = Vec::new();
    let mut sized = false;
    while input.read_line(&mut line, MAX_LINE, line_no + 1)? {
        line_no += 1;
        let full = line_str(input, &line, line_no)?;
        let text = full.split('#').next().unwrap_or("");
        if text.trim().is_empty() {
            continue;
        }
        let lay = match layout {
            Some(l) => l,
            None => {
                let sep = Separator::of(text);
                let fields = sep.split(text);
                let numeric = fields
                    .iter()
                    .take(3)
                    .filter(|f| f.parse::<f32>().is_ok())
                    .count();
                if fields.len() >= 3 && numeric == 3 {
                    let l = Layout {
                        sep,
                        xyz: [0, 1, 2],
                    };
                    layout = Some(l);
                    l
                } else if numeric == 0
                    && !fields
                        .iter()
                        .take(3)
                        .any(|f| f.replace(',', ".").parse::<f32>().is_ok())
                {
                    let (l, cols) = header_layout(&fields, sep, full).map_err(|what| {
                        input.format_err(what.replacen("line 1", &format!("line {line_no}"), 1))
                    })?;
                    // Streaming, the points go on without their columns.
                    out.ignored_columns = if out.is_streaming() { cols.len() } else { 0 };
                    if !out.is_streaming() {
                        columns = cols;
                    }
                    layout = Some(l);
                    continue;
                } else {
                    let found = fields.len();
                    let what = if found < 3 {
                        format!(
                            "line {line_no}: needs x, y and z, found {found} value(s) separated by {}: {:?}",
                            sep.name(),
                            full.trim()
                        )
                    } else {
                        let bad = fields
                            .iter()
                            .take(3)
                            .find(|f| f.parse::<f32>().is_err())
                            .copied()
                            .unwrap_or("");
                        format!(
                            "line {line_no}: {}",
                            parse_field::<f64>(bad, sep).err().unwrap_or_default()
                        )
                    };
                    return Err(input.format_err(what));
                }
            }
        };
        let fields = lay.sep.split(text);
        // Once the origin is known to be zero, each word is parsed as the
        // f32 it names, once (the common case, and as fast as before).
        let about_zero = !out.origin_from_first && out.origin == [0.0; 3];
        let mut p = [0f64; 3];
        let mut q = [0f32; 3];
        for (a, &col) in lay.xyz.iter().enumerate() {
            let Some(f) = fields.get(col) else {
                return Err(input.format_err(format!(
                    "line {line_no}: needs {} fields separated by {} (x, y, z in columns {}, {}, {}), found {}: {:?}",
                    lay.xyz.iter().max().unwrap_or(&2) + 1,
                    lay.sep.name(),
                    lay.xyz[0] + 1,
                    lay.xyz[1] + 1,
                    lay.xyz[2] + 1,
                    fields.len(),
                    full.trim()
                )));
            };
            let bad = |e: String| input.format_err(format!("line {line_no}: {e}"));
            if about_zero {
                q[a] = parse_field(f, lay.sep).map_err(bad)?;
            } else {
                p[a] = parse_field(f, lay.sep).map_err(bad)?;
            }
        }
        let kept = if about_zero {
            out.push(q)
        } else {
            // The f32 each word names, not f64 rounded again.
            let word = |a: usize| fields[lay.xyz[a]].parse::<f32>().unwrap_or(f32::NAN);
            if out.origin_from_first && p.iter().all(|v| v.is_finite()) {
                out.origin = [0, 1, 2].map(|a| origin_for(p[a], word(a)));
                out.origin_from_first = false;
            }
            if out.origin == [0.0; 3] {
                out.push([word(0), word(1), word(2)])
            } else {
                out.push_f64(p[0], p[1], p[2])
            }
        };
        if kept {
            for (field, _, rows) in &mut columns {
                let v = fields.get(*field).and_then(|f| f.parse::<f64>().ok());
                match (v, rows.as_mut()) {
                    (Some(v), Some(r)) => r.push(v),
                    _ => *rows = None,
                }
            }
        }
        data_lines += 1;
        if !sized && data_lines == SAMPLE_LINES {
            // Size the vector once from the bytes per line so far,
            // instead of doubling through a large file.
            sized = true;
            let per_line = (input.pos() / line_no).max(1);
            out.reserve_bounded(
                u64::MAX,
                input.remaining() + input.remaining() / 16,
                per_line,
            );
        }
    }
    for (_, name, rows) in columns {
        match rows {
            Some(rows) => out.attributes.insert(name, crate::Values::F64(rows)),
            None => out.ignored_columns += 1,
        }
    }
    Ok(())
}

/// Writes `points` one per line, separated by `sep`, after an optional
/// header line: the file's coordinates, the cloud's origin added
/// ([`text::Printed`]).
pub(crate) fn write<W: Write>(
    w: &mut W,
    cloud: &crate::PointCloud,
    sep: u8,
    header: Option<&str>,
) -> std::io::Result<()> {
    let columns = cloud.attributes.columns();
    let s = char::from(sep);
    if columns.is_empty() {
        if let Some(h) = header {
            writeln!(w, "{h}")?;
        }
    } else {
        // x, y, z and the columns by name; a column of extra bytes as one
        // field a byte (NAME_0 …).
        let mut names = vec!["x".to_string(), "y".into(), "z".into()];
        for c in columns {
            match &c.values {
                crate::Values::Bytes { width, .. } => {
                    names.extend((0..*width).map(|k| format!("{}_{k}", c.name)));
                }
                _ => names.push(c.name.clone()),
            }
        }
        writeln!(w, "{}", names.join(&s.to_string()))?;
    }
    let printed = text::Printed::of(cloud);
    let mut line = Vec::with_capacity(48);
    let mut words = String::new();
    for (i, p) in cloud.points.iter().enumerate() {
        printed.fill(p, sep, &mut line);
        for c in columns {
            words.clear();
            c.values.text_at(i, &mut words);
            line.push(sep);
            if matches!(c.values, crate::Values::Bytes { .. }) {
                // One field a byte: the row's bytes by the separator.
                line.extend_from_slice(words.replace(' ', &s.to_string()).as_bytes());
            } else {
                line.extend_from_slice(words.as_bytes());
            }
        }
        line.push(b'\n');
        w.write_all(&line)?;
    }
    Ok(())
}
