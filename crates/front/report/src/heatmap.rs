//! Heat maps of a function sampled on a regular grid (fuzzy control
//! surfaces, height maps), with a viridis colour bar, written as SVG and PNG.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::clip::Rect;
use crate::error::ReportError;
use crate::figure::{Layer, DEFAULT_HEIGHT_PX, DEFAULT_WIDTH_PX};
use crate::layout::{self, AxisRange};
use crate::render::{self, DrawResult, Drawing, TickFormat};
use crate::style::{viridis, Rgb};

/// Most grid cells a heat map may have (each becomes one SVG rectangle).
pub const MAX_HEATMAP_CELLS: usize = 1_000_000;
/// Colour of cells whose value is not finite.
const MISSING: Rgb = Rgb(220, 220, 220);
/// Number of colour steps in the colour bar.
const BAR_STEPS: usize = 128;

/// Values `z[iy][ix]` sampled at `(xs[ix], ys[iy])`, drawn as cells centred
/// on the samples and coloured by value.
#[derive(Debug, Clone, PartialEq)]
pub struct Heatmap {
    /// Title drawn above the map.
    pub title: String,
    /// X axis description.
    pub x_label: String,
    /// Y axis description.
    pub y_label: String,
    /// Description of the value, written along the colour bar.
    pub z_label: String,
    /// Sample abscissae, finite and strictly increasing.
    pub xs: Vec<f64>,
    /// Sample ordinates, finite and strictly increasing.
    pub ys: Vec<f64>,
    /// One row per y sample, each with one value per x sample. Non-finite
    /// values are drawn light grey and do not count for the colour scale.
    pub z: Vec<Vec<f64>>,
    /// One data unit as long in x as in y (height maps).
    pub equal_aspect: bool,
    /// Drawn over the cells, clipped to the map; labelled layers get a legend.
    pub layers: Vec<Layer>,
    /// Image width in pixels (default 900).
    pub width_px: u32,
    /// Image height in pixels (default 700).
    pub height_px: u32,
}

impl Heatmap {
    /// A heat map of the default size, with an empty colour-bar label.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
        xs: Vec<f64>,
        ys: Vec<f64>,
        z: Vec<Vec<f64>>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            z_label: String::new(),
            xs,
            ys,
            z,
            equal_aspect: false,
            layers: Vec::new(),
            width_px: DEFAULT_WIDTH_PX,
            height_px: DEFAULT_HEIGHT_PX,
        }
    }

    /// Sets the colour-bar label.
    #[must_use]
    pub fn z_label(mut self, label: impl Into<String>) -> Self {
        self.z_label = label.into();
        self
    }

    /// Makes one data unit as long in x as in y.
    #[must_use]
    pub fn equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }

    /// Adds an overlay layer.
    #[must_use]
    pub fn layer(mut self, layer: Layer) -> Self {
        self.layers.push(layer);
        self
    }

    /// Sets the image size in pixels.
    #[must_use]
    pub fn size(mut self, width_px: u32, height_px: u32) -> Self {
        self.width_px = width_px;
        self.height_px = height_px;
        self
    }

    /// The range of the finite values (`(0, 1)` if there are none), widened
    /// if all values are equal. This is the span of the colour bar.
    pub fn z_range(&self) -> Result<AxisRange, ReportError> {
        let mut b: Option<AxisRange> = None;
        for &v in self.z.iter().flatten().filter(|v| v.is_finite()) {
            b = Some(b.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
        }
        let what = format!("value range of heat map {:?}", self.title);
        match b {
            Some((lo, hi)) if lo < hi => layout::axis_range(Some((lo, hi)), None, &what),
            other => layout::axis_range(None, other, &what),
        }
    }
}

/// Writes `map` as `<dir>/<stem>.svg` and `<dir>/<stem>.png` (map on the
/// left, colour bar on the right) and returns both paths, SVG first.
pub fn write_heatmap(map: &Heatmap, dir: &Path, stem: &str) -> Result<[PathBuf; 2], ReportError> {
    let paths = layout::output_paths(dir, stem)?;
    let what = format!("heat map {}", paths[0].display());
    layout::check_size(map.width_px, map.height_px, &what)?;
    let x_edges = cell_edges(&map.xs, &format!("{what}: xs"))?;
    let y_edges = cell_edges(&map.ys, &format!("{what}: ys"))?;
    if map.z.len() != map.ys.len() || map.z.iter().any(|row| row.len() != map.xs.len()) {
        return Err(ReportError::invalid(format!(
            "{what}: z must have {} rows of {} values (one row per y, one value per x)",
            map.ys.len(),
            map.xs.len()
        )));
    }
    if map.xs.len().saturating_mul(map.ys.len()) > MAX_HEATMAP_CELLS {
        return Err(ReportError::invalid(format!(
            "{what}: more than {MAX_HEATMAP_CELLS} cells"
        )));
    }
    let x = (x_edges[0], x_edges[x_edges.len() - 1]);
    let y = (y_edges[0], y_edges[y_edges.len() - 1]);
    let (x, y) = if map.equal_aspect {
        let area =
            layout::panel_plot_area_px(map.width_px, map.height_px, layout::COLORBAR_AREA_PX);
        layout::equalize(x, y, area, &what)?
    } else {
        (
            layout::axis_range(Some(x), None, &what)?,
            layout::axis_range(Some(y), None, &what)?,
        )
    };
    let drawing = HeatmapDrawing {
        map,
        x_edges,
        y_edges,
        x,
        y,
        z: map.z_range()?,
    };
    render::write_images(&drawing, paths)
}

/// Cell boundaries around sample positions: midway between neighbours, and
/// half a spacing beyond the ends (±0.5 for a single sample).
fn cell_edges(s: &[f64], what: &str) -> Result<Vec<f64>, ReportError> {
    let increasing = s
        .windows(2)
        .all(|w| w[0] < w[1] && (w[1] - w[0]).is_finite());
    if s.is_empty() || !increasing || s.iter().any(|v| !v.is_finite()) {
        return Err(ReportError::invalid(format!(
            "{what} must be non-empty, finite and strictly increasing"
        )));
    }
    if s.len() == 1 {
        return Ok(vec![s[0] - 0.5, s[0] + 0.5]);
    }
    let n = s.len();
    let mut edges = Vec::with_capacity(n + 1);
    edges.push(s[0] - 0.5 * (s[1] - s[0]));
    edges.extend(s.windows(2).map(|w| 0.5 * w[0] + 0.5 * w[1]));
    edges.push(s[n - 1] + 0.5 * (s[n - 1] - s[n - 2]));
    if edges.iter().all(|e| e.is_finite()) {
        Ok(edges)
    } else {
        Err(ReportError::invalid(format!("{what}: cell edges overflow")))
    }
}

/// A validated heat map ready to draw.
struct HeatmapDrawing<'a> {
    map: &'a Heatmap,
    x_edges: Vec<f64>,
    y_edges: Vec<f64>,
    x: AxisRange,
    y: AxisRange,
    z: AxisRange,
}

impl HeatmapDrawing<'_> {
    fn cell_color(&self, v: f64) -> RGBColor {
        if v.is_finite() {
            render::color(viridis((v - self.z.0) / (self.z.1 - self.z.0)))
        } else {
            render::color(MISSING)
        }
    }

    fn draw_bar<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<(), DB> {
        let (lo, hi) = self.z;
        let mut bar = ChartBuilder::on(area)
            .margin_top(layout::MARGIN_TOP_PX)
            .margin_bottom(layout::MARGIN_BOTTOM_PX + layout::X_LABEL_AREA_PX)
            .margin_left(20)
            .margin_right(12)
            .right_y_label_area_size(85)
            .build_cartesian_2d(0.0..1.0, lo..hi)?;
        let ticks = TickFormat::for_axis(self.z);
        let fmt = |v: &f64| ticks.label(*v);
        bar.configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .x_labels(0)
            .y_labels(10)
            .y_label_formatter(&fmt)
            .y_desc(render::printable(&self.map.z_label))
            .label_style((crate::font::FAMILY, 13).into_font().color(&BLACK))
            .axis_desc_style((crate::font::FAMILY, 16).into_font().color(&BLACK))
            .axis_style(BLACK)
            .draw()?;
        let step = (hi - lo) / BAR_STEPS as f64;
        // Overlap the next step by a pixel, as the cells do.
        let (_, bar_h) = bar.plotting_area().dim_in_pixel();
        let over = (hi - lo) / f64::from(bar_h.max(1));
        bar.draw_series((0..BAR_STEPS).map(|i| {
            let z0 = lo + step * i as f64;
            let t = (i as f64 + 0.5) / BAR_STEPS as f64;
            Rectangle::new(
                [(0.0, z0), (1.0, (z0 + step + over).min(hi))],
                render::color(viridis(t)).filled(),
            )
        }))?;
        Ok(())
    }
}

impl Drawing for HeatmapDrawing<'_> {
    fn size(&self) -> (u32, u32) {
        (self.map.width_px, self.map.height_px)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<(), DB> {
        root.fill(&WHITE)?;
        let body = render::draw_title(root, &self.map.title)?;
        let (w, _) = body.dim_in_pixel();
        let (main, bar) = body.split_horizontally(w.saturating_sub(layout::COLORBAR_AREA_PX));
        let mut chart = render::build_chart(&main, self.x, self.y)?;
        render::draw_axes(
            &mut chart,
            &self.map.x_label,
            &self.map.y_label,
            self.x,
            self.y,
        )?;
        // Each cell reaches one pixel into its right and upper neighbours (which
        // paint over it), so that SVG viewers show no anti-aliasing seams.
        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let over_x = (self.x.1 - self.x.0) / f64::from(pw.max(1));
        let over_y = (self.y.1 - self.y.0) / f64::from(ph.max(1));
        let (xe, ye) = (&self.x_edges, &self.y_edges);
        let (x_end, y_end) = (self.x.1, self.y.1);
        let cells = self.map.z.iter().enumerate().flat_map(|(iy, row)| {
            row.iter().enumerate().map(move |(ix, &v)| {
                let x1 = (xe[ix + 1] + over_x).min(x_end);
                let y1 = (ye[iy + 1] + over_y).min(y_end);
                Rectangle::new([(xe[ix], ye[iy]), (x1, y1)], self.cell_color(v).filled())
            })
        });
        chart.draw_series(cells)?;
        let px = chart.plotting_area().dim_in_pixel();
        let r = Rect::new(self.x, self.y);
        if render::draw_layers(&mut chart, &self.map.layers, r, px)? {
            render::draw_legend(&mut chart)?;
        }
        self.draw_bar(&bar)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_midway() {
        assert_eq!(
            cell_edges(&[0.0, 1.0, 3.0], "t").unwrap(),
            vec![-0.5, 0.5, 2.0, 4.0]
        );
        assert_eq!(cell_edges(&[2.0], "t").unwrap(), vec![1.5, 2.5]);
        assert!(cell_edges(&[], "t").is_err());
        assert!(cell_edges(&[1.0, 1.0], "t").is_err());
        assert!(cell_edges(&[0.0, f64::NAN], "t").is_err());
    }

    #[test]
    fn z_range_ignores_non_finite_and_widens_constant() {
        let m = Heatmap::new(
            "t",
            "x",
            "y",
            vec![0.0, 1.0],
            vec![0.0],
            vec![vec![2.0, f64::NAN]],
        );
        let (lo, hi) = m.z_range().unwrap();
        assert!(lo < 2.0 && hi > 2.0);
        let m = Heatmap::new(
            "t",
            "x",
            "y",
            vec![0.0, 1.0],
            vec![0.0],
            vec![vec![-1.0, 3.0]],
        );
        assert_eq!(m.z_range().unwrap(), (-1.0, 3.0));
    }
}
