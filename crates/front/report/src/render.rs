//! Drawing with plotters: figures and stacked panels to SVG and PNG, plus
//! the pieces (title band, axes, layers, legend, file output) that the heat
//! map reuses.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::{DashedPathElement, IntoDynElement};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::clip::{self, Pt, Rect};
use crate::error::ReportError;
use crate::figure::{Figure, Layer};
use crate::font::{self, FAMILY};
use crate::layout::{self, AxisRange};
use crate::style::{Rgb, Stroke};

/// A pixel position on the backend.
type BackendCoord = (i32, i32);

/// Opacity of polygon and circle fills, so that what lies below stays visible.
pub(crate) const FILL_OPACITY: f64 = 0.4;
/// Number of vertices used to draw a circle.
const CIRCLE_VERTICES: usize = 96;
/// Most tick labels per axis.
const MAX_TICKS: usize = 10;
/// Widest line drawn; wider strokes are narrowed to this.
pub const MAX_STROKE_PX: u32 = 50;
/// Largest marker radius drawn; larger markers are shrunk to this.
pub const MAX_MARKER_PX: u32 = 100;

/// The chart type every panel draws on.
pub(crate) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
/// Result of a drawing step on backend `DB`.
pub(crate) type DrawResult<T, DB> =
    Result<T, DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Something drawable at a fixed pixel size, on any plotters backend.
pub(crate) trait Drawing {
    /// Image size in pixels.
    fn size(&self) -> (u32, u32);
    /// Draws everything on `root`, which has [`Drawing::size`].
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<(), DB>;
}

/// Writes `fig` as `<dir>/<stem>.svg` and `<dir>/<stem>.png` and returns
/// both paths, SVG first.
///
/// The directory must exist. Non-finite coordinates are skipped, geometry
/// outside the axes is clipped, and a figure without data shows empty axes
/// under its title.
pub fn write_figure(fig: &Figure, dir: &Path, stem: &str) -> Result<[PathBuf; 2], ReportError> {
    write_panels(std::slice::from_ref(fig), dir, stem)
}

/// Writes several figures stacked vertically, top first, in one image
/// `<dir>/<stem>.svg` / `.png`; returns both paths, SVG first.
///
/// The image is as wide as the widest figure and as tall as all figures'
/// `height_px` together; every panel uses the full width.
pub fn write_panels(figs: &[Figure], dir: &Path, stem: &str) -> Result<[PathBuf; 2], ReportError> {
    let paths = layout::output_paths(dir, stem)?;
    let what = || format!("plot {}", paths[0].display());
    if figs.is_empty() {
        return Err(ReportError::invalid(format!("{}: no panels", what())));
    }
    let width = figs.iter().map(|f| f.width_px).max().unwrap_or(0);
    let mut height = 0u32;
    for fig in figs {
        layout::check_size(fig.width_px, fig.height_px, &what())?;
        height = height.saturating_add(fig.height_px);
    }
    layout::check_size(width, height, &what())?;
    let mut ranges = Vec::with_capacity(figs.len());
    for fig in figs {
        let area = layout::panel_plot_area_px(width, fig.height_px, 0);
        ranges.push(layout::ranges_for_area(fig, area)?);
    }
    let panels = Panels {
        figs,
        ranges,
        size: (width, height),
    };
    write_images(&panels, paths)
}

/// Figures stacked vertically, with their precomputed ranges.
struct Panels<'a> {
    figs: &'a [Figure],
    ranges: Vec<(AxisRange, AxisRange)>,
    size: (u32, u32),
}

impl Drawing for Panels<'_> {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<(), DB> {
        root.fill(&WHITE)?;
        let mut rest = root.clone();
        for (fig, &(x, y)) in self.figs.iter().zip(&self.ranges) {
            let (panel, below) = rest.split_vertically(fig.height_px);
            draw_panel(&panel, fig, x, y)?;
            rest = below;
        }
        Ok(())
    }
}

/// One figure on its own area: title band, axes, layers, legend.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    x: AxisRange,
    y: AxisRange,
) -> DrawResult<(), DB> {
    let body = draw_title(area, &fig.title)?;
    let mut chart = build_chart(&body, x, y)?;
    draw_axes(&mut chart, &fig.x_label, &fig.y_label, x, y)?;
    let px = chart.plotting_area().dim_in_pixel();
    let labelled = draw_layers(&mut chart, &fig.layers, Rect::new(x, y), px)?;
    if labelled {
        draw_legend(&mut chart)?;
    }
    Ok(())
}

/// Renders `drawing` to SVG text and to a PNG file at `paths` (`[svg, png]`).
pub(crate) fn write_images(
    drawing: &impl Drawing,
    paths: [PathBuf; 2],
) -> Result<[PathBuf; 2], ReportError> {
    font::ensure_registered()?;
    let [svg_path, png_path] = &paths;
    let size = drawing.size();

    let mut svg = String::new();
    guarded(svg_path, || {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        drawing.draw(&root)?;
        root.present()
    })?;
    std::fs::write(svg_path, svg).map_err(|e| ReportError::io(svg_path, e))?;

    // plotters reports a failed save only as an opaque encoder error; creating
    // the file first turns a missing directory into a proper I/O error.
    std::fs::File::create(png_path).map_err(|e| ReportError::io(png_path, e))?;
    let drawn = guarded(png_path, || {
        let root = BitMapBackend::new(png_path, size).into_drawing_area();
        drawing.draw(&root)?;
        root.present()
    });
    if drawn.is_err() {
        // Best effort: don't leave an empty or truncated image behind.
        let _ = std::fs::remove_file(png_path);
    }
    drawn.map(|()| paths)
}

/// Runs a plotters job, turning its errors, and any panic inside the
/// library, into [`ReportError::Plot`] for `path`.
fn guarded<E: std::fmt::Display>(
    path: &Path,
    job: impl FnOnce() -> Result<(), E>,
) -> Result<(), ReportError> {
    let plot_error = |message: String| ReportError::Plot {
        path: path.to_path_buf(),
        message,
    };
    match catch_unwind(AssertUnwindSafe(job)) {
        Ok(Ok(())) => Ok(()),
        Ok(Err(e)) => Err(plot_error(e.to_string())),
        Err(panic) => {
            let detail = autoshovel_core::panic_message(panic.as_ref())
                .unwrap_or_else(|| "unknown cause".to_string());
            Err(plot_error(format!(
                "the plotting library panicked: {detail}"
            )))
        }
    }
}

/// Replaces control characters (invalid in SVG text) with spaces.
pub(crate) fn printable(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// Draws `title` centred in a band at the top of `area`; returns the area below.
pub(crate) fn draw_title<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
) -> DrawResult<DrawingArea<DB, Shift>, DB> {
    let (band, body) = area.split_vertically(layout::TITLE_BAND_PX);
    let (w, h) = band.dim_in_pixel();
    let style = (FAMILY, 22)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Center));
    band.draw_text(&printable(title), &style, (w as i32 / 2, h as i32 / 2))?;
    Ok(body)
}

/// Cartesian axes on `area`, using the crate's fixed layout so that
/// [`layout::panel_plot_area_px`] gives the plotting area's size.
pub(crate) fn build_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: AxisRange,
    y: AxisRange,
) -> DrawResult<Chart<'a, DB>, DB> {
    ChartBuilder::on(area)
        .margin_left(layout::MARGIN_LEFT_PX)
        .margin_right(layout::MARGIN_RIGHT_PX)
        .margin_top(layout::MARGIN_TOP_PX)
        .margin_bottom(layout::MARGIN_BOTTOM_PX)
        .x_label_area_size(layout::X_LABEL_AREA_PX)
        .y_label_area_size(layout::Y_LABEL_AREA_PX)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
}

/// Grid, ticks and axis descriptions.
pub(crate) fn draw_axes<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    x_label: &str,
    y_label: &str,
    x: AxisRange,
    y: AxisRange,
) -> DrawResult<(), DB> {
    let (x_ticks, y_ticks) = (TickFormat::for_axis(x), TickFormat::for_axis(y));
    let x_fmt = |v: &f64| x_ticks.label(*v);
    let y_fmt = |v: &f64| y_ticks.label(*v);
    let (x_desc, y_desc) = (printable(x_label), printable(y_label));
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_labels(MAX_TICKS)
        .y_labels(MAX_TICKS)
        .max_light_lines(4)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style((FAMILY, 13).into_font().color(&BLACK))
        .axis_desc_style((FAMILY, 16).into_font().color(&BLACK))
        .bold_line_style(RGBColor(215, 215, 215))
        .light_line_style(RGBColor(242, 242, 242))
        .axis_style(BLACK)
        .draw()
}

/// How the tick labels of one axis are written: the fewest decimals (or
/// significant digits, in scientific notation) that tell its ticks apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TickFormat {
    scientific: bool,
    digits: usize,
    /// Values smaller than this in magnitude are printed as 0.
    zero: f64,
}

impl TickFormat {
    /// The format for the ticks plotters puts on an axis showing `range`
    /// (the same key points the mesh uses).
    pub(crate) fn for_axis((lo, hi): AxisRange) -> Self {
        let ticks = RangedCoordf64::from(lo..hi).key_points(MAX_TICKS);
        let step = ticks
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let step = if step.is_finite() && step > 0.0 {
            step
        } else {
            hi - lo
        };
        let mag = lo.abs().max(hi.abs());
        let scientific = !(1e-4..1e9).contains(&mag);
        let tolerance = step * 1e-3;
        let fits = |digits: usize| {
            ticks.iter().all(|&t| {
                let text = if scientific {
                    format!("{t:.digits$e}")
                } else {
                    format!("{t:.digits$}")
                };
                text.parse::<f64>()
                    .is_ok_and(|back| (back - t).abs() <= tolerance)
            })
        };
        let digits = (0..=15).find(|&d| fits(d)).unwrap_or(15);
        Self {
            scientific,
            digits,
            zero: step * 1e-6,
        }
    }

    /// The label for tick value `v`.
    pub(crate) fn label(&self, v: f64) -> String {
        let v = if v.abs() < self.zero { 0.0 } else { v };
        let digits = self.digits;
        if self.scientific && v == 0.0 {
            "0".to_string()
        } else if self.scientific {
            format!("{v:.digits$e}")
        } else {
            format!("{v:.digits$}")
        }
    }
}

/// How a legend entry looks.
#[derive(Clone, Copy)]
enum Mark {
    Line(Stroke),
    Marker(Rgb, u32),
    Patch(Option<Rgb>, Stroke),
    Arrow(Stroke),
}

/// Plotters colour of an [`Rgb`].
pub(crate) fn color(c: Rgb) -> RGBColor {
    RGBColor(c.0, c.1, c.2)
}

fn line_style(s: Stroke) -> ShapeStyle {
    color(s.color).stroke_width(s.width.min(MAX_STROKE_PX))
}

/// Draws all layers, bottom first, clipped to `r`; `px` is the plotting
/// area's size in pixels. Returns whether any layer has a legend label.
pub(crate) fn draw_layers<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    layers: &[Layer],
    r: Rect,
    px: (u32, u32),
) -> DrawResult<bool, DB> {
    // Data units per pixel, to size arrow heads in pixels.
    let scale = (
        (r.x1 - r.x0) / f64::from(px.0.max(1)),
        (r.y1 - r.y0) / f64::from(px.1.max(1)),
    );
    let mut labelled = false;
    for layer in layers {
        let mark = match layer {
            Layer::Line { points, stroke, .. } => {
                for run in clip::clip_polyline(points, &r) {
                    draw_path(chart, run, *stroke)?;
                }
                Mark::Line(*stroke)
            }
            Layer::Points {
                points,
                color: c,
                size,
                ..
            } => {
                let style = color(*c).filled();
                let visible = points.iter().copied().filter(|p| r.contains(*p));
                let radius = (*size).min(MAX_MARKER_PX);
                chart.draw_series(visible.map(|p| Circle::new(p, radius, style)))?;
                Mark::Marker(*c, *size)
            }
            Layer::Circle {
                center,
                radius,
                fill,
                stroke,
                ..
            } => {
                let ok = center.0.is_finite()
                    && center.1.is_finite()
                    && radius.is_finite()
                    && *radius >= 0.0;
                if ok {
                    let poly = clip::circle_polygon(*center, *radius, CIRCLE_VERTICES);
                    draw_shape(chart, &poly, *fill, *stroke, &r)?;
                }
                Mark::Patch(*fill, *stroke)
            }
            Layer::Polygon {
                points,
                fill,
                stroke,
                ..
            } => {
                draw_shape(chart, points, *fill, *stroke, &r)?;
                Mark::Patch(*fill, *stroke)
            }
            Layer::Arrow {
                from, to, stroke, ..
            } => {
                draw_arrow(chart, *from, *to, *stroke, &r, scale)?;
                Mark::Arrow(*stroke)
            }
            Layer::Text { at, text, color: c } => {
                if r.contains(*at) {
                    let style = (FAMILY, 14)
                        .into_font()
                        .color(&color(*c))
                        .pos(Pos::new(HPos::Left, VPos::Center));
                    let text = printable(text);
                    chart.draw_series(std::iter::once(Text::new(text, *at, style)))?;
                }
                continue;
            }
        };
        if let Some(label) = layer.label() {
            labelled = true;
            add_legend_entry(chart, label, mark)?;
        }
    }
    Ok(labelled)
}

/// A polyline already clipped to the axes.
fn draw_path<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    run: Vec<Pt>,
    stroke: Stroke,
) -> DrawResult<(), DB> {
    if stroke.width == 0 {
        return Ok(());
    }
    let style = line_style(stroke);
    // Thin the run to a few pixels between vertices: plotters' bitmap backend
    // draws each segment of a wide line on its own, and hundreds of
    // sub-pixel segments come out ragged.
    let min_px = 3i64;
    let mut thinned: Vec<Pt> = Vec::with_capacity(run.len());
    let mut last_px: Option<(i32, i32)> = None;
    for (i, p) in run.iter().enumerate() {
        let px = chart.backend_coord(p);
        let far = match last_px {
            None => true,
            Some(l) => {
                let (dx, dy) = ((px.0 - l.0) as i64, (px.1 - l.1) as i64);
                dx * dx + dy * dy >= min_px * min_px
            }
        };
        if far || i + 1 == run.len() {
            thinned.push(*p);
            last_px = Some(px);
        }
    }
    let run = thinned;
    if stroke.dashed {
        let (dash, gap) = dash_pattern(stroke.width.min(MAX_STROKE_PX));
        chart.draw_series(std::iter::once(DashedPathElement::new(
            run, dash, gap, style,
        )))?;
    } else {
        chart.draw_series(std::iter::once(PathElement::new(run, style)))?;
    }
    Ok(())
}

/// Dash and gap lengths in pixels for a line `width` pixels wide.
fn dash_pattern(width: u32) -> (u32, u32) {
    (8 + 2 * width, 5 + width)
}

/// A closed shape: semi-transparent fill, then outline, both clipped.
fn draw_shape<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    points: &[Pt],
    fill: Option<Rgb>,
    stroke: Stroke,
    r: &Rect,
) -> DrawResult<(), DB> {
    if let Some(f) = fill {
        let visible = clip::clip_polygon(points, r);
        if !visible.is_empty() {
            let style = color(f).mix(FILL_OPACITY).filled();
            chart.draw_series(std::iter::once(Polygon::new(visible, style)))?;
        }
    }
    for run in clip::clip_ring(points, r) {
        draw_path(chart, run, stroke)?;
    }
    Ok(())
}

/// A shaft from `from` to the base of a filled head whose tip is at `to`;
/// the head is sized in pixels using `scale` (data units per pixel).
fn draw_arrow<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    from: Pt,
    to: Pt,
    stroke: Stroke,
    r: &Rect,
    (sx, sy): (f64, f64),
) -> DrawResult<(), DB> {
    let finite = [from.0, from.1, to.0, to.1].iter().all(|v| v.is_finite());
    if !finite {
        return Ok(());
    }
    let (dx, dy) = ((to.0 - from.0) / sx, (to.1 - from.1) / sy);
    let len = dx.hypot(dy);
    if !len.is_finite() || len < 1e-9 {
        return Ok(());
    }
    let (ux, uy) = (dx / len, dy / len);
    let head = (10.0 + 2.0 * f64::from(stroke.width.min(MAX_STROKE_PX))).min(len);
    let half = 0.45 * head;
    let data = |ox: f64, oy: f64| (to.0 + ox * sx, to.1 + oy * sy);
    let left = data(-ux * head - uy * half, -uy * head + ux * half);
    let right = data(-ux * head + uy * half, -uy * head - ux * half);
    // Stop the shaft a little inside the head so that wide lines don't poke out.
    let shaft_end = data(-ux * head * 0.8, -uy * head * 0.8);
    if let Some((p, q)) = clip::clip_segment(from, shaft_end, r) {
        if head < len {
            draw_path(chart, vec![p, q], stroke)?;
        }
    }
    let tri = clip::clip_polygon(&[to, left, right], r);
    if !tri.is_empty() {
        let style = color(stroke.color).filled();
        chart.draw_series(std::iter::once(Polygon::new(tri, style)))?;
    }
    Ok(())
}

/// Attaches a legend entry (drawn by [`draw_legend`]) to the chart.
fn add_legend_entry<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    label: &str,
    mark: Mark,
) -> DrawResult<(), DB> {
    chart
        .draw_series(std::iter::empty::<PathElement<Pt>>())?
        .label(printable(label))
        .legend(move |at| legend_mark(mark, at));
    Ok(())
}

/// The little sample drawn left of a legend label, `at` its left middle.
///
/// Every mark is the same composition of shapes (so that one concrete type
/// serves all); the parts a mark does not use are transparent, and
/// transparent shapes are skipped by both backends.
fn legend_mark<'a, DB: DrawingBackend + 'a>(
    mark: Mark,
    at: BackendCoord,
) -> impl IntoDynElement<'a, DB, BackendCoord> {
    let none = || ShapeStyle::from(TRANSPARENT);
    let thin = |s: Stroke| {
        line_style(Stroke {
            width: s.width.min(4),
            ..s
        })
    };
    let (mut fill, mut outline, mut first, mut second, mut head, mut dot) =
        (none(), none(), none(), none(), none(), none());
    let (mut first_end, mut second_start) = (22, 22);
    let mut dot_r = 0;
    match mark {
        Mark::Line(s) => {
            first = thin(s);
            if s.dashed {
                (first_end, second_start) = (8, 13);
                second = thin(s);
            }
        }
        Mark::Marker(c, size) => {
            dot = color(c).filled();
            dot_r = size.clamp(2, 6);
        }
        Mark::Patch(f, s) => {
            if let Some(f) = f {
                fill = color(f).mix(FILL_OPACITY).filled();
            }
            outline = color(s.color).stroke_width(s.width.clamp(1, 3));
        }
        Mark::Arrow(s) => {
            first = thin(s);
            first_end = 14;
            head = color(s.color).filled();
        }
    }
    let patch = [(2, -7), (20, 7)];
    EmptyElement::at(at)
        + Rectangle::new(patch, fill)
        + Rectangle::new(patch, outline)
        + PathElement::new(vec![(0, 0), (first_end, 0)], first)
        + PathElement::new(vec![(second_start, 0), (22, 0)], second)
        + Polygon::new(vec![(22, 0), (13, -5), (13, 5)], head)
        + Circle::new((11, 0), dot_r, dot)
}

/// The legend box in the upper right corner of the axes.
pub(crate) fn draw_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
) -> DrawResult<(), DB> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .label_font((FAMILY, 14).into_font().color(&BLACK))
        .legend_area_size(28)
        .draw()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fixed layout of `layout.rs` is what plotters actually produces,
    /// so that equal-aspect padding uses the true plotting-area size.
    #[test]
    fn layout_matches_plotters_plotting_area() {
        font::ensure_registered().unwrap();
        for &(w, h) in &[(900, 700), (320, 200), (1600, 400), (777, 1234)] {
            for reserved in [0, layout::COLORBAR_AREA_PX] {
                let mut svg = String::new();
                let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
                let body = draw_title(&root, "t").unwrap();
                let (bw, _) = body.dim_in_pixel();
                let (main, _) = body.split_horizontally(bw - reserved);
                let chart = build_chart(&main, (0.0, 1.0), (0.0, 1.0)).unwrap();
                assert_eq!(
                    chart.plotting_area().dim_in_pixel(),
                    layout::panel_plot_area_px(w, h, reserved),
                    "{w} x {h}, reserved {reserved}"
                );
            }
        }
    }

    #[test]
    fn tick_labels_use_the_needed_decimals() {
        let f = TickFormat::for_axis((-0.22, 0.32));
        assert_eq!(f.label(0.1), "0.1");
        assert_eq!(f.label(-1e-17), "0.0");
        let f = TickFormat::for_axis((0.00095, 0.00255));
        assert_eq!(f.label(0.0012), "0.0012");
        let f = TickFormat::for_axis((0.0, 100.0));
        assert_eq!(f.label(20.0), "20");
        let f = TickFormat::for_axis((1e12, 5e12));
        assert_eq!(f.label(2e12), "2.0e12");
        let f = TickFormat::for_axis((0.0, 2e-6));
        assert!(f.label(1e-6).contains('e'));
    }
}
