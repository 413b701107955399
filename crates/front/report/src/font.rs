//! The embedded DejaVu Sans font (see `assets/DejaVuSans-LICENSE.txt`),
//! registered once with plotters as the "sans-serif" family so that text
//! renders identically on machines without system fonts.

use std::sync::OnceLock;

use crate::error::ReportError;

/// The family every text in this crate is drawn with.
pub(crate) const FAMILY: &str = "sans-serif";

/// DejaVu Sans, Bitstream Vera licence.
static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

static REGISTERED: OnceLock<bool> = OnceLock::new();

/// Registers the embedded font with plotters (once per process).
pub(crate) fn ensure_registered() -> Result<(), ReportError> {
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FAMILY, plotters::style::FontStyle::Normal, DEJAVU_SANS)
            .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(ReportError::invalid(
            "the embedded DejaVu Sans font could not be loaded",
        ))
    }
}
