//! Colours and line styles: [`Rgb`] with a named palette, [`Stroke`], and the
//! [`viridis`] colour map used by heat maps.

/// An opaque RGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rgb(pub u8, pub u8, pub u8);

impl Rgb {
    /// Blue (`#1f77b4`), the first colour of the palette.
    pub const BLUE: Rgb = Rgb(31, 119, 180);
    /// Orange (`#ff7f0e`).
    pub const ORANGE: Rgb = Rgb(255, 127, 14);
    /// Green (`#2ca02c`).
    pub const GREEN: Rgb = Rgb(44, 160, 44);
    /// Red (`#d62728`).
    pub const RED: Rgb = Rgb(214, 39, 40);
    /// Purple (`#9467bd`).
    pub const PURPLE: Rgb = Rgb(148, 103, 189);
    /// Brown (`#8c564b`).
    pub const BROWN: Rgb = Rgb(140, 86, 75);
    /// Mid grey (`#7f7f7f`).
    pub const GREY: Rgb = Rgb(127, 127, 127);
    /// Black.
    pub const BLACK: Rgb = Rgb(0, 0, 0);
    /// White (for backgrounds and fills; not part of [`Rgb::PALETTE`]).
    pub const WHITE: Rgb = Rgb(255, 255, 255);

    /// The named colours in the order series should use them; they are
    /// mutually distinguishable (the Tableau 10 hues plus black).
    pub const PALETTE: [Rgb; 8] = [
        Rgb::BLUE,
        Rgb::ORANGE,
        Rgb::GREEN,
        Rgb::RED,
        Rgb::PURPLE,
        Rgb::BROWN,
        Rgb::GREY,
        Rgb::BLACK,
    ];

    /// The `i`-th palette colour, cycling through [`Rgb::PALETTE`].
    pub fn cycle(i: usize) -> Rgb {
        Rgb::PALETTE[i % Rgb::PALETTE.len()]
    }

    /// The colour as a CSS/SVG hex string, e.g. `#1f77b4`.
    pub fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
}

/// How a line or an outline is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Stroke {
    /// Line colour.
    pub color: Rgb,
    /// Line width in pixels; 0 draws nothing, and widths above
    /// [`MAX_STROKE_PX`](crate::MAX_STROKE_PX) are drawn that wide.
    pub width: u32,
    /// Dashed instead of solid.
    pub dashed: bool,
}

impl Stroke {
    /// A solid line.
    pub fn solid(color: Rgb, width: u32) -> Self {
        Self {
            color,
            width,
            dashed: false,
        }
    }

    /// A dashed line.
    pub fn dashed(color: Rgb, width: u32) -> Self {
        Self {
            color,
            width,
            dashed: true,
        }
    }
}

impl Default for Stroke {
    /// A solid black line, 2 px wide.
    fn default() -> Self {
        Self::solid(Rgb::BLACK, 2)
    }
}

/// Control points of the viridis colour map (matplotlib's default), evenly
/// spaced from 0 to 1.
const VIRIDIS: [Rgb; 9] = [
    Rgb(68, 1, 84),
    Rgb(71, 44, 122),
    Rgb(59, 81, 139),
    Rgb(44, 113, 142),
    Rgb(33, 144, 141),
    Rgb(39, 173, 129),
    Rgb(92, 200, 99),
    Rgb(170, 220, 50),
    Rgb(253, 231, 37),
];

/// The viridis colour map: dark purple at `t = 0`, yellow at `t = 1`.
///
/// `t` is clamped to `[0, 1]`; NaN gives the colour for 0.
pub fn viridis(t: f64) -> Rgb {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let pos = t * (VIRIDIS.len() - 1) as f64;
    // `pos` is in [0, 8], so the cast cannot truncate anything that matters.
    let i = (pos.floor() as usize).min(VIRIDIS.len() - 2);
    let f = pos - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * f).round() as u8;
    Rgb(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}
