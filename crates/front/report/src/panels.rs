//! Shared figure builders of the jobs: panels of lines against time with
//! marks (contact instants, ratings) and the finite range of a series.

use crate::figure::{Figure, Layer};
use crate::style::{Rgb, Stroke};

/// One labelled line of a [`time_panel`]: (t, value) points, colour, label.
pub type Line<'a> = (Vec<(f64, f64)>, Rgb, &'a str);

/// (min, max) of the finite values; (0, 1) when there are none.
pub fn finite_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo <= hi {
        (lo, hi)
    } else {
        (0.0, 1.0)
    }
}

/// A 1000 px wide figure of `lines` against time (s), `height_px` high,
/// with `headroom` of the data's span left free above for the legend and
/// `marks(lo, hi)` (e.g. vertical lines at events, spanning the y range)
/// drawn under the lines.
pub fn time_panel<'a>(
    title: impl Into<String>,
    y_label: &str,
    (height_px, headroom): (u32, f64),
    lines: impl IntoIterator<Item = Line<'a>>,
    marks: impl FnOnce(f64, f64) -> Vec<Layer>,
) -> Figure {
    let lines: Vec<Line<'a>> = lines.into_iter().collect();
    let (lo, hi) = finite_range(lines.iter().flat_map(|(v, ..)| v.iter().map(|p| p.1)));
    let span = (hi - lo).max(1.0);
    let (lo, hi) = (lo - 0.05 * span, hi + headroom * span);
    let mut f = Figure::new(title, "time [s]", y_label)
        .size(1000, height_px)
        .y_range(lo, hi);
    for l in marks(lo, hi) {
        f.push(l);
    }
    for (v, color, label) in lines {
        f.push(Layer::line(v, Stroke::solid(color, 2)).with_label(label));
    }
    f
}

/// A dashed horizontal line at `value` from `t0` to `t1`, labelled (a
/// machine rating or a limit on a time panel).
pub fn rating_line(
    value: f64,
    (t0, t1): (f64, f64),
    color: Rgb,
    label: impl Into<String>,
) -> Layer {
    Layer::line([(t0, value), (t1, value)], Stroke::dashed(color, 1)).with_label(label)
}

/// A markdown table (GitHub style) of `header` and `rows`.
pub fn markdown_table(header: &[&str], rows: impl IntoIterator<Item = Vec<String>>) -> String {
    let mut s = format!(
        "| {} |\n|{}|\n",
        header.join(" | "),
        vec!["---"; header.len()].join("|")
    );
    for r in rows {
        s.push_str(&format!("| {} |\n", r.join(" | ")));
    }
    s
}
