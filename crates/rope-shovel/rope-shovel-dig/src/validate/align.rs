//! Aligning a measured record with the plan in time ([RS §5], Fig. 20): the
//! testbed's clock starts when its logger starts, not when the dig does, and
//! a real dig may run a little faster or slower than planned.
//!
//! The measurement is modelled as the plan seen through a clock
//!
//! ```text
//!     t_measured = τ + s · t_plan
//! ```
//!
//! (τ: where plan time 0 falls on the record's clock; s: the time scale, the
//! measured dig taking s · t_d). τ and s maximise the cross-correlation of
//! the two force records: the mean of the Pearson correlations of hoist and
//! crowd force (each mean-removed and normalised on the overlap, so neither
//! force outweighs the other and a gain error does not matter), computed on
//! a grid over [0, t_d] with the measurement linearly interpolated at
//! τ + s·t. τ is searched over the record's start ± `max_lag_s` in steps of
//! the finer of the two sample periods, then s over 1 ± `max_stretch`;
//! the best grid point is refined in both at once on a grid ten times finer,
//! then by parabolic interpolation of the correlation in τ. Offsets at
//! which the record covers
//! less than `min_overlap` of the dig are not considered.

use serde::Serialize;

use crate::error::{DigError, Result};
use crate::validate::record::ForceRecord;

/// How to search the alignment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlignParams {
    /// Offsets searched either side of the record's first sample (s);
    /// `None`: half the planned dig time.
    pub max_lag_s: Option<f64>,
    /// Largest relative deviation of the time scale s from 1 searched
    /// (0.1: the measured dig may take 90 % to 110 % of t_d; 0 fixes s = 1).
    pub max_stretch: f64,
    /// The least share of the dig the record must cover at an offset.
    pub min_overlap: f64,
}

impl Default for AlignParams {
    fn default() -> Self {
        Self {
            max_lag_s: None,
            max_stretch: 0.1,
            min_overlap: 0.5,
        }
    }
}

impl AlignParams {
    /// Check the ranges once, at the edge.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, expected| {
            Err(DigError::BadParameter {
                name,
                value,
                expected,
            })
        };
        if let Some(l) = self.max_lag_s {
            if !(l.is_finite() && (0.0..=3600.0).contains(&l)) {
                return bad("AlignParams.max_lag_s", l, "a time in [0, 3600] s");
            }
        }
        if !(self.max_stretch.is_finite() && (0.0..=0.5).contains(&self.max_stretch)) {
            return bad(
                "AlignParams.max_stretch",
                self.max_stretch,
                "a share in [0, 0.5]",
            );
        }
        if !(self.min_overlap > 0.0 && self.min_overlap <= 1.0) {
            return bad(
                "AlignParams.min_overlap",
                self.min_overlap,
                "a share in (0, 1]",
            );
        }
        Ok(())
    }
}

/// Step of the time-scale grid.
const STRETCH_STEP: f64 = 0.0025;

/// How much finer the refinement's grid is than the search's.
const FINE_STEPS: usize = 10;

/// The most grid points over the dig used in the search.
const MAX_GRID: usize = 400;

/// The clock that maps plan time onto the measured record.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Alignment {
    /// τ: the time on the measured clock at which the plan's t = 0 falls (s).
    pub offset_s: f64,
    /// τ minus the record's first time: how long after the record starts
    /// the dig starts (negative: the record starts after the dig) (s).
    pub delay_s: f64,
    /// s: measured time per planned time (1: as fast as planned).
    pub time_scale: f64,
    /// The mean of the hoist and crowd correlations at the alignment.
    pub correlation: f64,
    /// Offsets searched either side of the record's start (s).
    pub max_lag_s: f64,
    /// Step of the offset grid before refinement (s).
    pub lag_step_s: f64,
    /// Largest deviation of s from 1 searched.
    pub max_stretch: f64,
}

impl Alignment {
    /// The measured-clock time of plan time `t_plan_s` (s).
    pub fn measured_time(&self, t_plan_s: f64) -> f64 {
        self.offset_s + self.time_scale * t_plan_s
    }
}

/// `v` at `t` on the polyline (`t`, `v`), clamped to its ends.
pub fn interpolate(t: &[f64], v: &[f64], x: f64) -> f64 {
    let n = t.len();
    if n == 0 {
        return f64::NAN;
    }
    if x <= t[0] {
        return v[0];
    }
    if x >= t[n - 1] {
        return v[n - 1];
    }
    let i = t.partition_point(|&ti| ti <= x); // t[i-1] <= x < t[i]
    let (t0, t1) = (t[i - 1], t[i]);
    v[i - 1] + (v[i] - v[i - 1]) * (x - t0) / (t1 - t0)
}

/// The plan on the search grid: times and both forces.
struct Resampled {
    t: Vec<f64>,
    hoist: Vec<f64>,
    crowd: Vec<f64>,
}

/// Pearson's r of (a, b) pairs from their sums; 0 when either is constant.
fn pearson(n: f64, [sa, sb, saa, sbb, sab]: [f64; 5]) -> f64 {
    let va = saa - sa * sa / n;
    let vb = sbb - sb * sb / n;
    let cov = sab - sa * sb / n;
    if va <= 0.0 || vb <= 0.0 {
        return 0.0;
    }
    cov / (va * vb).sqrt()
}

/// The search: the plan's grid and the measurement.
struct Search<'a> {
    grid: Resampled,
    measured: &'a ForceRecord,
    min_points: usize,
}

impl Search<'_> {
    /// The mean correlation at offset `tau` and scale `s`; `None` when the
    /// record covers too little of the dig there.
    fn score(&self, tau: f64, s: f64) -> Option<f64> {
        let m = self.measured;
        let (t0, t1) = m.span_s();
        let (mut h, mut c) = ([0.0; 5], [0.0; 5]);
        let mut n = 0usize;
        for (i, &t) in self.grid.t.iter().enumerate() {
            let tm = tau + s * t;
            if tm < t0 || tm > t1 {
                continue;
            }
            n += 1;
            for (acc, p, mv) in [
                (&mut h, self.grid.hoist[i], &m.hoist_force_n),
                (&mut c, self.grid.crowd[i], &m.crowd_force_n),
            ] {
                let q = interpolate(&m.t_s, mv, tm);
                acc[0] += p;
                acc[1] += q;
                acc[2] += p * p;
                acc[3] += q * q;
                acc[4] += p * q;
            }
        }
        if n < self.min_points.max(3) {
            return None;
        }
        Some(0.5 * (pearson(n as f64, h) + pearson(n as f64, c)))
    }
}

/// The vertex offset (in steps, within ±1) of the parabola through
/// (−1, a), (0, b), (1, c); 0 when it opens upwards or a side is missing.
fn parabola_vertex(a: Option<f64>, b: f64, c: Option<f64>) -> f64 {
    let (Some(a), Some(c)) = (a, c) else {
        return 0.0;
    };
    let den = a - 2.0 * b + c;
    if den >= 0.0 {
        return 0.0;
    }
    (0.5 * (a - c) / den).clamp(-1.0, 1.0)
}

/// Finds the clock τ + s·t that best aligns `measured` with `planned` (a
/// plan of duration `td_s`); [`DigError::NoOverlap`] naming `source` when no
/// offset in the window covers enough of the dig.
pub fn align(
    planned: &ForceRecord,
    td_s: f64,
    measured: &ForceRecord,
    source: &std::path::Path,
    params: &AlignParams,
) -> Result<Alignment> {
    params.validate()?;
    let max_lag_s = params.max_lag_s.unwrap_or(0.5 * td_s);
    let max_stretch = params.max_stretch;
    let h = planned
        .median_step_s()
        .min(measured.median_step_s())
        .max(td_s / 1e5);
    let step_g = h.max(td_s / MAX_GRID as f64);
    let n_g = (td_s / step_g).round().max(2.0) as usize;
    let t: Vec<f64> = (0..=n_g).map(|i| td_s * i as f64 / n_g as f64).collect();
    let grid = Resampled {
        hoist: t
            .iter()
            .map(|&x| interpolate(&planned.t_s, &planned.hoist_force_n, x))
            .collect(),
        crowd: t
            .iter()
            .map(|&x| interpolate(&planned.t_s, &planned.crowd_force_n, x))
            .collect(),
        t,
    };
    let search = Search {
        min_points: (params.min_overlap * (n_g + 1) as f64).ceil() as usize,
        grid,
        measured,
    };
    let (t0, t1) = measured.span_s();
    let k_max = (max_lag_s / h).ceil() as i64;
    let tau_of = |k: i64| t0 + k as f64 * h;
    let no_overlap = || DigError::NoOverlap {
        path: source.to_path_buf(),
        record_start_s: t0,
        record_end_s: t1,
        td_s,
        max_lag_s,
        min_overlap_pct: 100.0 * params.min_overlap,
    };
    // Offsets at s = 1.
    let best_k = |s: f64, ks: std::ops::RangeInclusive<i64>| {
        ks.filter_map(|k| search.score(tau_of(k), s).map(|r| (k, r)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    };
    let (mut k, mut best) = best_k(1.0, -k_max..=k_max).ok_or_else(no_overlap)?;
    // Then scales, each with the offsets it can shift the best one by.
    let mut s = 1.0;
    if max_stretch > 0.0 {
        let j_max = (max_stretch / STRETCH_STEP).round() as i64;
        let k1 = k;
        for j in -j_max..=j_max {
            let sj = 1.0 + j as f64 * STRETCH_STEP;
            let w = ((sj - 1.0).abs() * td_s / h).ceil() as i64 + 2;
            let lo = (k1 - w).max(-k_max);
            let hi = (k1 + w).min(k_max);
            if let Some((kj, r)) = best_k(sj, lo..=hi) {
                if r > best {
                    (k, s, best) = (kj, sj, r);
                }
            }
        }
    }
    // Refinement between grid points: τ and s trade off along a ridge (a
    // longer clock and an earlier start look alike), so both at once, on a
    // grid ten times finer round the best (±2 offset steps, ±1 scale step),
    // then the parabola in τ. Kept only if it correlates better than the
    // grid's best.
    let (tau_grid, s_grid) = (tau_of(k), s);
    let ds = STRETCH_STEP;
    let fine = FINE_STEPS as i64;
    let scales: Vec<f64> = if max_stretch > 0.0 {
        (-fine..=fine)
            .map(|j| s_grid + j as f64 * ds / fine as f64)
            .filter(|sj| (sj - 1.0).abs() <= max_stretch + 1e-12)
            .collect()
    } else {
        vec![s_grid]
    };
    let (mut tau, mut s, mut fine_best) = (tau_grid, s_grid, best);
    for &sj in &scales {
        for i in -2 * fine..=2 * fine {
            let ti = tau_grid + i as f64 * h / fine as f64;
            if let Some(r) = search.score(ti, sj) {
                if r > fine_best {
                    (tau, s, fine_best) = (ti, sj, r);
                }
            }
        }
    }
    let hf = h / fine as f64;
    tau += parabola_vertex(
        search.score(tau - hf, s),
        fine_best,
        search.score(tau + hf, s),
    ) * hf;
    let correlation = match search.score(tau, s) {
        Some(r) if r > best => r,
        _ => {
            (tau, s) = (tau_grid, s_grid);
            best
        }
    };
    Ok(Alignment {
        offset_s: tau,
        delay_s: tau - t0,
        time_scale: s,
        correlation,
        max_lag_s,
        lag_step_s: h,
        max_stretch,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn interpolation_is_linear_inside_and_clamped_outside() {
        let t = [0.0, 1.0, 3.0];
        let v = [0.0, 10.0, 30.0];
        assert_relative_eq!(interpolate(&t, &v, 0.25), 2.5);
        assert_relative_eq!(interpolate(&t, &v, 2.0), 20.0);
        assert_relative_eq!(interpolate(&t, &v, 1.0), 10.0);
        assert_relative_eq!(interpolate(&t, &v, -1.0), 0.0);
        assert_relative_eq!(interpolate(&t, &v, 9.0), 30.0);
    }

    #[test]
    fn the_parabola_vertex_of_a_sampled_parabola_is_exact() {
        // y = −(x − 0.3)², sampled at −1, 0, 1.
        let y = |x: f64| -(x - 0.3) * (x - 0.3);
        assert_relative_eq!(
            parabola_vertex(Some(y(-1.0)), y(0.0), Some(y(1.0))),
            0.3,
            epsilon = 1e-12
        );
        assert_eq!(parabola_vertex(None, 1.0, Some(0.0)), 0.0);
    }

    /// Two smooth bumps at different times, as hoist and crowd.
    fn record(t: Vec<f64>, shift: f64, scale: f64) -> ForceRecord {
        let f = |t: f64, c: f64| (-(t - c).powi(2) / 0.5).exp();
        let u = |t: f64| (t - shift) / scale;
        ForceRecord {
            hoist_force_n: t.iter().map(|&t| 100.0 + 50.0 * f(u(t), 3.0)).collect(),
            crowd_force_n: t.iter().map(|&t| 20.0 - 10.0 * f(u(t), 6.0)).collect(),
            t_s: t,
            rope_length_m: None,
            handle_extension_m: None,
        }
    }

    #[test]
    fn a_known_offset_and_time_scale_are_found_between_grid_points() {
        let planned = record((0..=120).map(|i| i as f64 * 0.075).collect(), 0.0, 1.0);
        let measured = record(
            (0..1000).map(|i| 5.0 + i as f64 * 0.01).collect(),
            5.0 + 0.374,
            0.992,
        );
        let a = align(
            &planned,
            9.0,
            &measured,
            std::path::Path::new("m.csv"),
            &AlignParams::default(),
        )
        .unwrap();
        assert_relative_eq!(a.delay_s, 0.374, epsilon = 2e-3);
        assert_relative_eq!(a.offset_s, 5.374, epsilon = 2e-3);
        assert_relative_eq!(a.time_scale, 0.992, epsilon = 5e-4);
        assert!(a.correlation > 0.999, "{a:?}");
    }
}
