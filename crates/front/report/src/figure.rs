//! The plot description: a [`Figure`] is a titled pair of axes holding
//! [`Layer`]s of plain `(x, y)` data. Nothing here draws; see `render.rs`.

use crate::style::{Rgb, Stroke};

/// One thing drawn on a figure, in data coordinates.
///
/// Non-finite coordinates are skipped (a NaN point in a line leaves a gap).
/// Layers with a `label` get an entry in the figure's legend.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Layer {
    /// A polyline through `points`.
    Line {
        /// Vertices in drawing order.
        points: Vec<(f64, f64)>,
        /// Line style.
        stroke: Stroke,
        /// Legend entry.
        label: Option<String>,
    },
    /// Filled round markers.
    Points {
        /// Marker centres.
        points: Vec<(f64, f64)>,
        /// Marker colour.
        color: Rgb,
        /// Marker radius in pixels (at most [`MAX_MARKER_PX`](crate::MAX_MARKER_PX)).
        size: u32,
        /// Legend entry.
        label: Option<String>,
    },
    /// A circle whose radius is in data units (an ellipse on screen unless the
    /// figure has an equal aspect ratio).
    Circle {
        /// Centre.
        center: (f64, f64),
        /// Radius in data units; negative or non-finite radii draw nothing.
        radius: f64,
        /// Interior colour, drawn semi-transparent; `None` leaves it empty.
        fill: Option<Rgb>,
        /// Outline style.
        stroke: Stroke,
        /// Legend entry.
        label: Option<String>,
    },
    /// A closed polygon (the last vertex joins the first).
    Polygon {
        /// Vertices; the polygon is closed automatically.
        points: Vec<(f64, f64)>,
        /// Interior colour, drawn semi-transparent; `None` leaves it empty.
        fill: Option<Rgb>,
        /// Outline style.
        stroke: Stroke,
        /// Legend entry.
        label: Option<String>,
    },
    /// A straight arrow with a filled head at `to`.
    Arrow {
        /// Tail.
        from: (f64, f64),
        /// Tip (where the head is drawn).
        to: (f64, f64),
        /// Shaft style; the head takes its colour.
        stroke: Stroke,
        /// Legend entry.
        label: Option<String>,
    },
    /// A text annotation whose left edge is vertically centred on `at`.
    Text {
        /// Anchor point.
        at: (f64, f64),
        /// The text.
        text: String,
        /// Text colour.
        color: Rgb,
    },
}

impl Layer {
    /// A polyline without a label.
    pub fn line(points: impl IntoIterator<Item = (f64, f64)>, stroke: Stroke) -> Self {
        Layer::Line {
            points: points.into_iter().collect(),
            stroke,
            label: None,
        }
    }

    /// Markers of radius `size` pixels, without a label.
    pub fn points(points: impl IntoIterator<Item = (f64, f64)>, color: Rgb, size: u32) -> Self {
        Layer::Points {
            points: points.into_iter().collect(),
            color,
            size,
            label: None,
        }
    }

    /// A circle of `radius` data units, without a label.
    pub fn circle(center: (f64, f64), radius: f64, fill: Option<Rgb>, stroke: Stroke) -> Self {
        Layer::Circle {
            center,
            radius,
            fill,
            stroke,
            label: None,
        }
    }

    /// A closed polygon, without a label.
    pub fn polygon(
        points: impl IntoIterator<Item = (f64, f64)>,
        fill: Option<Rgb>,
        stroke: Stroke,
    ) -> Self {
        Layer::Polygon {
            points: points.into_iter().collect(),
            fill,
            stroke,
            label: None,
        }
    }

    /// An arrow from `from` to `to`, without a label.
    pub fn arrow(from: (f64, f64), to: (f64, f64), stroke: Stroke) -> Self {
        Layer::Arrow {
            from,
            to,
            stroke,
            label: None,
        }
    }

    /// A text annotation.
    pub fn text(at: (f64, f64), text: impl Into<String>, color: Rgb) -> Self {
        Layer::Text {
            at,
            text: text.into(),
            color,
        }
    }

    /// Sets the legend label (ignored by [`Layer::Text`], which has none).
    #[must_use]
    pub fn with_label(mut self, text: impl Into<String>) -> Self {
        match &mut self {
            Layer::Line { label, .. }
            | Layer::Points { label, .. }
            | Layer::Circle { label, .. }
            | Layer::Polygon { label, .. }
            | Layer::Arrow { label, .. } => *label = Some(text.into()),
            Layer::Text { .. } => {}
        }
        self
    }

    /// The legend label, if any.
    pub fn label(&self) -> Option<&str> {
        match self {
            Layer::Line { label, .. }
            | Layer::Points { label, .. }
            | Layer::Circle { label, .. }
            | Layer::Polygon { label, .. }
            | Layer::Arrow { label, .. } => label.as_deref(),
            Layer::Text { .. } => None,
        }
    }

    /// Calls `f` with every finite point that should be inside the axes
    /// (circle extremes included).
    pub(crate) fn for_each_extent_point(&self, f: &mut impl FnMut((f64, f64))) {
        let mut finite = |p: (f64, f64)| {
            if p.0.is_finite() && p.1.is_finite() {
                f(p);
            }
        };
        match self {
            Layer::Line { points, .. }
            | Layer::Points { points, .. }
            | Layer::Polygon { points, .. } => points.iter().copied().for_each(&mut finite),
            Layer::Circle { center, radius, .. } => {
                if radius.is_finite() && *radius >= 0.0 {
                    finite((center.0 - radius, center.1 - radius));
                    finite((center.0 + radius, center.1 + radius));
                }
            }
            Layer::Arrow { from, to, .. } => {
                finite(*from);
                finite(*to);
            }
            Layer::Text { at, .. } => finite(*at),
        }
    }
}

/// Default image width in pixels.
pub const DEFAULT_WIDTH_PX: u32 = 900;
/// Default image height in pixels.
pub const DEFAULT_HEIGHT_PX: u32 = 700;

/// A titled x/y plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title drawn above the axes.
    pub title: String,
    /// X axis description.
    pub x_label: String,
    /// Y axis description.
    pub y_label: String,
    /// For maps: one data unit spans as many pixels in x as in y. The shorter
    /// range is widened (about its centre) to achieve it.
    pub equal_aspect: bool,
    /// X range shown; `None` fits the data with a 5 % margin.
    pub x_range: Option<(f64, f64)>,
    /// Y range shown; `None` fits the data with a 5 % margin.
    pub y_range: Option<(f64, f64)>,
    /// What is drawn, bottom layer first.
    pub layers: Vec<Layer>,
    /// Image width in pixels (default 900).
    pub width_px: u32,
    /// Image height in pixels (default 700).
    pub height_px: u32,
}

impl Figure {
    /// An empty figure of the default size with automatic ranges.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            equal_aspect: false,
            x_range: None,
            y_range: None,
            layers: Vec::new(),
            width_px: DEFAULT_WIDTH_PX,
            height_px: DEFAULT_HEIGHT_PX,
        }
    }

    /// Makes one data unit as long in x as in y (for maps).
    #[must_use]
    pub fn equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }

    /// Fixes the x range instead of fitting the data.
    #[must_use]
    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    /// Fixes the y range instead of fitting the data.
    #[must_use]
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Sets the image size in pixels.
    #[must_use]
    pub fn size(mut self, width_px: u32, height_px: u32) -> Self {
        self.width_px = width_px;
        self.height_px = height_px;
        self
    }

    /// Adds a layer on top of the existing ones.
    #[must_use]
    pub fn layer(mut self, layer: Layer) -> Self {
        self.layers.push(layer);
        self
    }

    /// Adds a layer on top of the existing ones, in place.
    pub fn push(&mut self, layer: Layer) {
        self.layers.push(layer);
    }
}
