//! Locating TOML keys by line, so that errors can name `file:line` and the key.

use crate::error::ExcavateError;

/// Parse `text` as `T`, turning a TOML error into [`ExcavateError::Parse`]
/// with the 1-based line and column of its span.
pub(crate) fn parse<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &str,
) -> Result<T, ExcavateError> {
    toml::from_str(text).map_err(|e| {
        let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((0, 0));
        ExcavateError::Parse {
            file: file.to_string(),
            line,
            column,
            message: e.message().trim().to_string(),
        }
    })
}

/// 1-based line and column of a byte offset.
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map_or(offset, |i| offset - i - 1) + 1;
    (line, column)
}

/// The 1-based line of `key = …` in the `occurrence`-th (0-based) table
/// headed `[table]` or `[[table]]`; a top-level key when `table` is empty.
/// Falls back to the table's header line, and to 0 when the table is absent.
pub(crate) fn line_of_key(text: &str, table: &str, occurrence: usize, key: &str) -> usize {
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
}
