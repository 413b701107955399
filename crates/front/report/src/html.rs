//! The demo report page, `index.html`: one self-contained HTML file (inline
//! CSS, no scripts, nothing fetched from elsewhere) with a section per job.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::error::ReportError;

/// Name of the report page inside the report directory.
pub const INDEX_FILE: &str = "index.html";

/// Arrays longer than this are abbreviated in the summary table.
const MAX_INLINE_ITEMS: usize = 10;
/// Longest text shown for an array of objects or arrays.
const MAX_JSON_CHARS: usize = 160;

/// One job's part of the report.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Section {
    /// Heading, e.g. the job name.
    pub title: String,
    /// Plain text; blank lines separate paragraphs.
    pub description: String,
    /// The job's summary, shown as a table of its scalar fields.
    pub summary: Value,
    /// SVG images, as paths relative to the report directory.
    pub plots: Vec<String>,
    /// Other files to link (CSV, JSON...), relative to the report directory.
    pub files: Vec<String>,
}

/// Writes `<dir>/index.html` titled `title` with one section per entry of
/// `sections`, and returns its path.
///
/// Each section shows its description, a table of the summary (nested keys
/// flattened as `a.b`, arrays of scalars inline and abbreviated past ten
/// items, floats to six significant digits with the full value as a
/// tooltip), its plots as images linking to themselves, and links to its
/// files. All text is HTML-escaped and links are percent-encoded.
pub fn write_index_html(
    dir: &Path,
    title: &str,
    sections: &[Section],
) -> Result<PathBuf, ReportError> {
    let path = dir.join(INDEX_FILE);
    std::fs::write(&path, render_page(title, sections)).map_err(|e| ReportError::io(&path, e))?;
    Ok(path)
}

const STYLE: &str = "\
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,'DejaVu Sans',sans-serif;\
margin:0 auto;max-width:1150px;padding:1rem 1.5rem 3rem;color:#1d1d1f;line-height:1.45}
h1{font-size:1.8rem;margin:.5rem 0 1rem}
h2{font-size:1.35rem;margin:0 0 .5rem;padding-top:.5rem;border-top:2px solid #d0d7de}
section{margin:2rem 0}
nav ol{columns:2;margin:0 0 1rem}
table{border-collapse:collapse;margin:.75rem 0;font-size:.92rem}
th,td{border:1px solid #d0d7de;padding:.25rem .6rem;text-align:left;vertical-align:top}
th{background:#f3f5f7}
td.key{font-family:ui-monospace,'DejaVu Sans Mono',monospace;white-space:nowrap}
td.value{font-variant-numeric:tabular-nums;word-break:break-word}
.plots{display:flex;flex-wrap:wrap;gap:1rem}
figure{margin:0;flex:1 1 480px;max-width:min(100%,900px)}
figure img{width:100%;height:auto;border:1px solid #d0d7de;background:#fff}
figcaption{font-size:.85rem;color:#57606a}
ul.files{padding-left:1.2rem}
.empty{color:#57606a;font-style:italic}
";

/// The whole page as text.
pub(crate) fn render_page(title: &str, sections: &[Section]) -> String {
    let mut h = String::new();
    let t = escape(title);
    // Writing to a String cannot fail; the results are ignored on purpose.
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{t}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n<header>\n<h1>{t}</h1>\n"
    );
    if !sections.is_empty() {
        h.push_str("<nav><ol>\n");
        for (i, s) in sections.iter().enumerate() {
            let _ = writeln!(
                h,
                "<li><a href=\"#job-{}\">{}</a></li>",
                i + 1,
                escape(&s.title)
            );
        }
        h.push_str("</ol></nav>\n");
    }
    h.push_str("</header>\n");
    for (i, s) in sections.iter().enumerate() {
        render_section(&mut h, i + 1, s);
    }
    h.push_str("</body>\n</html>\n");
    h
}

fn render_section(h: &mut String, number: usize, s: &Section) {
    let _ = writeln!(
        h,
        "<section id=\"job-{number}\">\n<h2>{}</h2>",
        escape(&s.title)
    );
    for para in s
        .description
        .split("\n\n")
        .map(str::trim)
        .filter(|p| !p.is_empty())
    {
        let _ = writeln!(h, "<p>{}</p>", escape(para).replace('\n', "<br>\n"));
    }
    let rows = flatten(&s.summary);
    if rows.is_empty() {
        h.push_str("<p class=\"empty\">No summary values.</p>\n");
    } else {
        h.push_str("<table class=\"summary\">\n<thead><tr><th>quantity</th><th>value</th></tr></thead>\n<tbody>\n");
        for row in &rows {
            let tip = match &row.full {
                Some(full) => format!(" title=\"{}\"", escape(full)),
                None => String::new(),
            };
            let _ = writeln!(
                h,
                "<tr><td class=\"key\">{}</td><td class=\"value\"{tip}>{}</td></tr>",
                escape(&row.key),
                escape(&row.shown)
            );
        }
        h.push_str("</tbody>\n</table>\n");
    }
    if !s.plots.is_empty() {
        h.push_str("<div class=\"plots\">\n");
        for plot in &s.plots {
            let href = url(plot);
            let name = escape(plot);
            let _ = writeln!(
                h,
                "<figure><a href=\"{href}\"><img src=\"{href}\" alt=\"{name}\" loading=\"lazy\"></a>\
                 <figcaption>{name}</figcaption></figure>"
            );
        }
        h.push_str("</div>\n");
    }
    if !s.files.is_empty() {
        h.push_str("<ul class=\"files\">\n");
        for file in &s.files {
            let _ = writeln!(h, "<li><a href=\"{}\">{}</a></li>", url(file), escape(file));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("</section>\n");
}

/// One line of the summary table.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Row {
    /// Dotted path, e.g. `a.b`; `(value)` for a summary that is not an object.
    pub key: String,
    /// What the table shows.
    pub shown: String,
    /// The exact value, when `shown` rounds it.
    pub full: Option<String>,
}

/// The summary's fields as table rows: nested objects flattened as `a.b`,
/// arrays of scalars inline (abbreviated when long), other arrays as
/// shortened JSON.
pub(crate) fn flatten(summary: &Value) -> Vec<Row> {
    let mut rows = Vec::new();
    walk("", summary, &mut rows);
    rows
}

fn walk(prefix: &str, v: &Value, rows: &mut Vec<Row>) {
    let key = || {
        if prefix.is_empty() {
            "(value)".to_string()
        } else {
            prefix.to_string()
        }
    };
    match v {
        Value::Object(map) if !map.is_empty() => {
            for (k, child) in map {
                let path = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                walk(&path, child, rows);
            }
        }
        Value::Object(_) => {
            if !prefix.is_empty() {
                rows.push(Row {
                    key: key(),
                    shown: "{}".to_string(),
                    full: None,
                });
            }
        }
        Value::Null if prefix.is_empty() => {}
        Value::Array(items) => rows.push(array_row(key(), items)),
        scalar => {
            let (shown, full) = scalar_text(scalar);
            rows.push(Row {
                key: key(),
                shown,
                full,
            });
        }
    }
}

fn array_row(key: String, items: &[Value]) -> Row {
    let n = items.len();
    if items.iter().all(|i| !i.is_array() && !i.is_object()) {
        let text = |i: &Value| scalar_text(i).0;
        let shown = if n > MAX_INLINE_ITEMS {
            let head: Vec<String> = items[..5].iter().map(text).collect();
            let tail: Vec<String> = items[n - 2..].iter().map(text).collect();
            format!("[{}, …, {}] ({n} items)", head.join(", "), tail.join(", "))
        } else {
            let all: Vec<String> = items.iter().map(text).collect();
            format!("[{}]", all.join(", "))
        };
        Row {
            key,
            shown,
            full: None,
        }
    } else {
        let json = Value::Array(items.to_vec()).to_string();
        let shown = if json.chars().count() > MAX_JSON_CHARS {
            let cut: String = json.chars().take(MAX_JSON_CHARS).collect();
            format!("{cut}… ({n} items)")
        } else {
            json
        };
        Row {
            key,
            shown,
            full: None,
        }
    }
}

/// How a scalar is shown, and its exact text if that differs.
fn scalar_text(v: &Value) -> (String, Option<String>) {
    match v {
        Value::String(s) => (s.clone(), None),
        Value::Number(n) if n.is_f64() => {
            let exact = n.to_string();
            let short = n.as_f64().map_or_else(|| exact.clone(), short_float);
            if short == exact {
                (short, None)
            } else {
                (short, Some(exact))
            }
        }
        other => (other.to_string(), None),
    }
}

/// `v` to six significant digits, without trailing zeros.
pub(crate) fn short_float(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let exp = v.abs().log10().floor();
    if (-4.0..9.0).contains(&exp) {
        let decimals = (5.0 - exp).max(0.0) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let s = format!("{v:.5e}");
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        }
    }
}

/// Escapes text for HTML content and attribute values.
pub(crate) fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A relative path as a URL: every byte but unreserved characters and `/`
/// percent-encoded (so no path can become a `javascript:` or other scheme).
pub(crate) fn url(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for b in path.bytes() {
        if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'.' | b'_' | b'~' | b'/') {
            out.push(char::from(b));
        } else {
            let _ = write!(out, "%{b:02X}");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn short_floats() {
        assert_eq!(short_float(0.1 + 0.2), "0.3");
        assert_eq!(short_float(12.345678901), "12.3457");
        assert_eq!(short_float(1234567.0), "1234567");
        assert_eq!(short_float(2.5e-7), "2.5e-7");
        assert_eq!(short_float(-3.0e12), "-3e12");
    }

    #[test]
    fn flattening() {
        let rows = flatten(&json!({
            "a": {"b": 1, "c": {"d": "x"}},
            "v": [1, 2, 3],
            "long": (0..20).collect::<Vec<i32>>(),
            "pts": [[0.0, 1.0], [2.0, 3.0]],
            "empty": {},
            "none": null
        }));
        let get = |k: &str| rows.iter().find(|r| r.key == k).map(|r| r.shown.clone());
        assert_eq!(get("a.b").as_deref(), Some("1"));
        assert_eq!(get("a.c.d").as_deref(), Some("x"));
        assert_eq!(get("v").as_deref(), Some("[1, 2, 3]"));
        assert_eq!(
            get("long").as_deref(),
            Some("[0, 1, 2, 3, 4, …, 18, 19] (20 items)")
        );
        assert_eq!(get("pts").as_deref(), Some("[[0.0,1.0],[2.0,3.0]]"));
        assert_eq!(get("empty").as_deref(), Some("{}"));
        assert_eq!(get("none").as_deref(), Some("null"));
        assert_eq!(flatten(&json!(3))[0].key, "(value)");
        assert!(flatten(&Value::Null).is_empty());
    }

    #[test]
    fn urls_are_encoded() {
        assert_eq!(url("plots/map 1.svg"), "plots/map%201.svg");
        assert_eq!(url("javascript:alert(1)"), "javascript%3Aalert%281%29");
        assert_eq!(url("a\"b<c>"), "a%22b%3Cc%3E");
    }
}
