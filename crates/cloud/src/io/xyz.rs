//! Plain text clouds (`.xyz`, `.csv`, `.txt`): one point per line, x y z
//! separated by whitespace, commas or semicolons; further columns (intensity,
//! colour, ...) are ignored. `#` starts a comment; one header line of
//! column names is allowed before the first point.

use std::io::{BufRead, Write};

use super::input::{line_str, Input, Points};
use super::text;
use crate::Point;

/// Longest line accepted [bytes].
const MAX_LINE: usize = 1 << 16;
/// Lines sampled before the point vector is sized from the bytes per line.
const SAMPLE_LINES: usize = 4096;

fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| c == ',' || c == ';' || c.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
}

/// Reads a text cloud into `out`.
pub(crate) fn read<R: BufRead>(input: &mut Input<'_, R>, out: &mut Points) -> crate::Result<()> {
    let mut line = Vec::new();
    let mut line_no = 0u64;
    let mut data_lines = 0usize;
    let mut header_seen = false;
    let mut sized = false;
    while input.read_line(&mut line, MAX_LINE, line_no + 1)? {
        line_no += 1;
        let full = line_str(input, &line, line_no)?;
        let text = full.split('#').next().unwrap_or("");
        let mut w = words(text);
        let Some(first) = w.next() else { continue };
        let coords = [Some(first), w.next(), w.next()];
        let parsed: Vec<Option<f32>> = coords
            .iter()
            .map(|c| c.and_then(|s| s.parse::<f32>().ok()))
            .collect();
        if let [Some(x), Some(y), Some(z)] = parsed[..] {
            out.push([x, y, z]);
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
            continue;
        }
        let numeric_first = coords[0].is_some_and(|s| s.parse::<f32>().is_ok());
        if data_lines == 0 && !header_seen && !numeric_first {
            header_seen = true;
            continue;
        }
        let found = coords.iter().flatten().count();
        let what = if found < 3 {
            format!(
                "line {line_no}: needs x, y and z, found {found} value(s): {:?}",
                full.trim()
            )
        } else {
            let bad = coords
                .iter()
                .flatten()
                .find(|s| s.parse::<f32>().is_err())
                .copied()
                .unwrap_or("");
            format!("line {line_no}: {bad:?} is not a number")
        };
        return Err(input.format_err(what));
    }
    Ok(())
}

/// Writes `points` one per line, separated by `sep`, after an optional
/// header line.
pub(crate) fn write<W: Write>(
    w: &mut W,
    points: &[Point],
    sep: u8,
    header: Option<&str>,
) -> std::io::Result<()> {
    if let Some(h) = header {
        writeln!(w, "{h}")?;
    }
    let mut line = Vec::with_capacity(48);
    for p in points {
        text::write_point(w, p, sep, &mut line)?;
    }
    Ok(())
}
