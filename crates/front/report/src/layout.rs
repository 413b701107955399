//! Pixel layout of a plot and the data ranges its axes show: fitting the
//! data with a margin, giving degenerate ranges a minimum span, and padding
//! for an equal aspect ratio. Pure arithmetic, no drawing.

use std::path::{Path, PathBuf};

use crate::error::ReportError;
use crate::figure::Figure;

/// An axis range `(lo, hi)` with `lo < hi`.
pub type AxisRange = (f64, f64);

/// Height of the band holding a panel's title.
pub(crate) const TITLE_BAND_PX: u32 = 40;
/// Space between the panel edge and the axes, left.
pub(crate) const MARGIN_LEFT_PX: u32 = 10;
/// Space between the panel edge and the axes, right (room for the last tick label).
pub(crate) const MARGIN_RIGHT_PX: u32 = 25;
/// Space between the title band and the axes.
pub(crate) const MARGIN_TOP_PX: u32 = 10;
/// Space between the axes' labels and the panel's bottom edge.
pub(crate) const MARGIN_BOTTOM_PX: u32 = 10;
/// Height of the x tick labels and description below the axes.
pub(crate) const X_LABEL_AREA_PX: u32 = 50;
/// Width of the y tick labels and description left of the axes.
pub(crate) const Y_LABEL_AREA_PX: u32 = 80;
/// Width reserved on the right of a heat map for its colour bar.
pub(crate) const COLORBAR_AREA_PX: u32 = 150;

/// Smallest accepted image width.
pub const MIN_WIDTH_PX: u32 = 320;
/// Smallest accepted image (or panel) height.
pub const MIN_HEIGHT_PX: u32 = 200;
/// Largest accepted image side.
pub const MAX_SIDE_PX: u32 = 16_384;
/// Largest accepted image area (width times height), to bound memory use.
pub const MAX_AREA_PX: u64 = 40_000_000;

/// Relative fit margin added on each side of the data.
const FIT_MARGIN: f64 = 0.05;
/// Smallest span relative to the magnitude of the range's centre.
const MIN_RELATIVE_SPAN: f64 = 1e-9;
/// Smallest absolute span.
const MIN_ABSOLUTE_SPAN: f64 = 1e-12;
/// Largest magnitude an axis end may have.
const MAX_ABS_COORD: f64 = 1e300;

/// Size in pixels of the plotting area (inside the axes) of a figure drawn
/// alone at `width_px` x `height_px`.
pub fn plot_area_px(width_px: u32, height_px: u32) -> (u32, u32) {
    panel_plot_area_px(width_px, height_px, 0)
}

/// Plotting-area size of a panel `(width, height)` of which `reserved_right`
/// pixels are kept for something else (a colour bar).
pub(crate) fn panel_plot_area_px(width: u32, height: u32, reserved_right: u32) -> (u32, u32) {
    let w = width
        .saturating_sub(reserved_right)
        .saturating_sub(MARGIN_LEFT_PX + MARGIN_RIGHT_PX + Y_LABEL_AREA_PX);
    let h =
        height.saturating_sub(TITLE_BAND_PX + MARGIN_TOP_PX + MARGIN_BOTTOM_PX + X_LABEL_AREA_PX);
    (w.max(1), h.max(1))
}

/// The x and y ranges `fig` will show when drawn alone, after fitting,
/// minimum spans and equal-aspect padding.
///
/// With `equal_aspect`, the returned spans satisfy
/// `x_span / y_span == plot_w / plot_h` where `(plot_w, plot_h)` is
/// [`plot_area_px`]`(fig.width_px, fig.height_px)`. Explicit ranges are then
/// taken as the least region to show.
pub fn data_ranges(fig: &Figure) -> Result<(AxisRange, AxisRange), ReportError> {
    ranges_for_area(fig, plot_area_px(fig.width_px, fig.height_px))
}

/// [`data_ranges`] for a plotting area of `area` pixels.
pub(crate) fn ranges_for_area(
    fig: &Figure,
    area: (u32, u32),
) -> Result<(AxisRange, AxisRange), ReportError> {
    let mut xb: Option<AxisRange> = None;
    let mut yb: Option<AxisRange> = None;
    for layer in &fig.layers {
        layer.for_each_extent_point(&mut |(x, y)| {
            xb = Some(grow(xb, x));
            yb = Some(grow(yb, y));
        });
    }
    let what = |axis: &str| format!("{axis} range of figure {:?}", fig.title);
    let x = axis_range(fig.x_range, xb, &what("x"))?;
    let y = axis_range(fig.y_range, yb, &what("y"))?;
    if fig.equal_aspect {
        equalize(x, y, area, &what("equal-aspect"))
    } else {
        Ok((x, y))
    }
}

fn grow(b: Option<AxisRange>, v: f64) -> AxisRange {
    match b {
        None => (v, v),
        Some((lo, hi)) => (lo.min(v), hi.max(v)),
    }
}

/// The range of one axis: the explicit one if given (checked), else the
/// data's with a margin, else `(0, 1)`; then widened to a minimum span.
pub(crate) fn axis_range(
    explicit: Option<AxisRange>,
    data: Option<AxisRange>,
    what: &str,
) -> Result<AxisRange, ReportError> {
    let r = match (explicit, data) {
        (Some((lo, hi)), _) => {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(ReportError::invalid(format!(
                    "{what}: ({lo}, {hi}) must be finite with lo < hi"
                )));
            }
            (lo, hi)
        }
        (None, None) => (0.0, 1.0),
        (None, Some((lo, hi))) => {
            let span = hi - lo;
            if span > 0.0 {
                (lo - FIT_MARGIN * span, hi + FIT_MARGIN * span)
            } else {
                let half = if lo == 0.0 {
                    0.5
                } else {
                    FIT_MARGIN * lo.abs()
                };
                (lo - half, hi + half)
            }
        }
    };
    checked(min_span(r), what)
}

/// Widens `r` about its centre so that its span is not negligible next to
/// its magnitude (tick computation needs distinct representable values).
fn min_span((lo, hi): AxisRange) -> AxisRange {
    let c = 0.5 * lo + 0.5 * hi;
    let min = (c.abs() * MIN_RELATIVE_SPAN).max(MIN_ABSOLUTE_SPAN);
    if hi - lo >= min {
        (lo, hi)
    } else {
        (c - 0.5 * min, c + 0.5 * min)
    }
}

fn checked((lo, hi): AxisRange, what: &str) -> Result<AxisRange, ReportError> {
    let ok = lo.is_finite()
        && hi.is_finite()
        && lo < hi
        && lo.abs() <= MAX_ABS_COORD
        && hi.abs() <= MAX_ABS_COORD
        && (hi - lo).is_finite();
    if ok {
        Ok((lo, hi))
    } else {
        Err(ReportError::invalid(format!(
            "{what}: ({lo}, {hi}) cannot be plotted (values must stay within ±{MAX_ABS_COORD:e})"
        )))
    }
}

/// Pads the shorter range so that a data unit spans as many pixels in x as in y.
pub(crate) fn equalize(
    x: AxisRange,
    y: AxisRange,
    (pw, ph): (u32, u32),
    what: &str,
) -> Result<(AxisRange, AxisRange), ReportError> {
    let aspect = f64::from(pw.max(1)) / f64::from(ph.max(1));
    let (xs, ys) = (x.1 - x.0, y.1 - y.0);
    let widen = |(lo, hi): AxisRange, span: f64| {
        let c = 0.5 * lo + 0.5 * hi;
        (c - 0.5 * span, c + 0.5 * span)
    };
    let (x, y) = if xs / ys < aspect {
        (widen(x, ys * aspect), y)
    } else {
        (x, widen(y, xs / aspect))
    };
    Ok((checked(x, what)?, checked(y, what)?))
}

/// Checks an image size against the accepted limits.
pub(crate) fn check_size(width: u32, height: u32, what: &str) -> Result<(), ReportError> {
    let ok = (MIN_WIDTH_PX..=MAX_SIDE_PX).contains(&width)
        && (MIN_HEIGHT_PX..=MAX_SIDE_PX).contains(&height)
        && u64::from(width) * u64::from(height) <= MAX_AREA_PX;
    if ok {
        Ok(())
    } else {
        Err(ReportError::invalid(format!(
            "{what}: size {width} x {height} px is outside {MIN_WIDTH_PX}..={MAX_SIDE_PX} x \
             {MIN_HEIGHT_PX}..={MAX_SIDE_PX} px or above {MAX_AREA_PX} px in all"
        )))
    }
}

/// `<dir>/<stem>.svg` and `<dir>/<stem>.png`, after checking that `stem` is
/// a plain file name.
pub(crate) fn output_paths(dir: &Path, stem: &str) -> Result<[PathBuf; 2], ReportError> {
    let plain = !stem.is_empty()
        && stem != "."
        && stem != ".."
        && !stem.contains(['/', '\\', '\0'])
        && !stem.chars().any(char::is_control);
    if !plain {
        return Err(ReportError::invalid(format!(
            "file stem {stem:?} (in {}) must be a plain, non-empty file name",
            dir.display()
        )));
    }
    Ok([
        dir.join(format!("{stem}.svg")),
        dir.join(format!("{stem}.png")),
    ])
}
