//! Plots and reports for the autoshovel CLI's jobs, from plain `f64` data.
//!
//! * [`Figure`]s of [`Layer`]s are written as SVG and PNG by [`write_figure`]
//!   (or stacked by [`write_panels`]); [`Heatmap`]s by [`write_heatmap`].
//! * Tables go to CSV with [`write_csv`] / [`write_csv_cells`], job summaries
//!   to `summary.json` with [`write_summary`].
//! * [`write_index_html`] ties a demo run together in one self-contained page.
//!
//! Text is drawn with an embedded DejaVu Sans, so PNGs look the same on
//! machines without system fonts. No function panics on bad input: it returns
//! a [`ReportError`], naming the file at fault. Output directories must exist.
//!
//! ```no_run
//! use autoshovel_report::{write_csv, write_figure, Figure, Layer, Rgb, Stroke};
//! # fn main() -> Result<(), autoshovel_report::ReportError> {
//! let dir = std::path::Path::new("out/follow");
//! let path = vec![(0.0, 0.0), (10.0, 2.0), (20.0, 0.0)];
//! let fig = Figure::new("Path", "east [m]", "north [m]")
//!     .equal_aspect()
//!     .layer(Layer::line(path.clone(), Stroke::solid(Rgb::BLUE, 2)).with_label("planned"))
//!     .layer(Layer::circle((10.0, 0.0), 1.5, Some(Rgb::GREY), Stroke::default()));
//! let [svg, png] = write_figure(&fig, dir, "map")?;
//! write_csv(&dir.join("path.csv"), &["x", "y"], path.iter().map(|&(x, y)| vec![x, y]))?;
//! # let _ = (svg, png);
//! # Ok(())
//! # }
//! ```

mod clip;
mod csv;
mod error;
mod figure;
mod font;
mod heatmap;
mod html;
mod json;
mod layout;
mod panels;
mod render;
mod staging;
mod style;
mod written;

pub use crate::csv::{finite_cell, format_f64, write_csv, write_csv_cells};
pub use crate::error::ReportError;
pub use crate::figure::{Figure, Layer, DEFAULT_HEIGHT_PX, DEFAULT_WIDTH_PX};
pub use crate::heatmap::{write_heatmap, Heatmap, MAX_HEATMAP_CELLS};
pub use crate::html::{write_index_html, Section, INDEX_FILE};
pub use crate::json::{write_summary, SUMMARY_FILE};
pub use crate::layout::{
    data_ranges, plot_area_px, AxisRange, MAX_AREA_PX, MAX_SIDE_PX, MIN_HEIGHT_PX, MIN_WIDTH_PX,
};
pub use crate::panels::{finite_range, markdown_table, rating_line, time_panel, Line};
pub use crate::render::{write_figure, write_panels, MAX_MARKER_PX, MAX_STROKE_PX};
pub use crate::staging::{
    files_written_before, private_dir, refusal, remove_unfinished, without_path,
    write_file_atomically, OutDir, Staging,
};
pub use crate::style::{viridis, Rgb, Stroke};
pub use crate::written::{summary_value, write_job_summary, WithFiles, Written};
