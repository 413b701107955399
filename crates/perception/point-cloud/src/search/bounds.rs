//! A search box's bounds in f32: widened past the f32 rounding of a squared
//! distance and rounded outwards, so no point within a cap falls outside
//! the box that gathers candidates (the column grid's heights, the octree's
//! boxes).

/// Relative widening of a search box beyond its radius (`search::columns`,
/// `search::octree`): far above the f32 rounding of a squared distance (below
/// 4e-7), so no point whose f32 squared distance is within a cap lies
/// outside a box of the cap's root widened by it.
pub(crate) const SLACK: f64 = 1e-4;

/// The values within `wide` of `v`, rounded outwards to f32 (so that no
/// f32 value within them falls outside).
pub(crate) fn within_f32(v: f32, wide: f64) -> (f32, f32) {
    let (lo, hi) = (f64::from(v) - wide, f64::from(v) + wide);
    let (mut lo32, mut hi32) = (lo as f32, hi as f32);
    if f64::from(lo32) > lo {
        lo32 = lo32.next_down();
    }
    if f64::from(hi32) < hi {
        hi32 = hi32.next_up();
    }
    (lo32, hi32)
}
