//! Planned against measured ([RS §5], [RS Table 6], [RS Fig. 20]): the
//! measured record aligned with the plan ([`crate::validate::align()`]) and
//! resampled at the plan's sample times, then per force the peaks, the RMS
//! difference, Pearson's r, R² and a fitted gain, and the rows of Table 6
//! (dug mass and dig time, planned and measured, relative deviation).
//!
//! Definitions (docs/rope-shovel-dig.md, "Planned against measured"):
//!
//! - R² is the coefficient of determination of the measurement by the plan,
//!   1 − Σ(m − p)² / Σ(m − m̄)², with the plan as the prediction as it
//!   stands (nothing fitted): 1 only when the two agree, lowered by a
//!   shape, an offset or a gain error. This is the figure set beside
//!   Table 6's "relevant coefficient R²". r² (Pearson's r squared) is also
//!   reported: it forgives offset and gain.
//! - The gain k is the least-squares scale of m ≈ k·p through the origin,
//!   Σ p m / Σ p², which recovers a sensor's gain error.
//! - A relative deviation is |planned − measured| / measured, as Table 6's
//!   numbers are (e.g. 2.053 kg planned, 2.086 kg tested: 1.58 %).
//! - The measured dig time is s · t_d, with s the time scale of the
//!   alignment: how long the measured force pattern takes for the planned
//!   one's t_d. The record's own length is reported beside it.

use serde::Serialize;

use crate::error::Result;
use crate::validate::align::{align, interpolate, AlignParams, Alignment};
use crate::validate::record::{ForceRecord, MeasuredRecord, PlannedRecord};

/// One quantity planned and measured (a row entry of [RS Table 6]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Deviation {
    /// Planned value.
    pub planned: f64,
    /// Measured value.
    pub measured: f64,
    /// measured − planned.
    pub difference: f64,
    /// |planned − measured| / measured (%), Table 6's "relative deviation".
    pub relative_deviation_pct: f64,
}

impl Deviation {
    /// `planned` against `measured`.
    pub fn new(planned: f64, measured: f64) -> Self {
        Self {
            planned,
            measured,
            difference: measured - planned,
            relative_deviation_pct: 100.0 * (planned - measured).abs() / measured.abs(),
        }
    }
}

/// One force planned and measured on the aligned samples ([RS Fig. 20]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ForceComparison {
    /// Largest planned force on the compared samples (N).
    pub peak_planned_n: f64,
    /// Largest measured force on them (N).
    pub peak_measured_n: f64,
    /// Measured minus planned peak (N).
    pub peak_difference_n: f64,
    /// Root mean square of measured − planned (N).
    pub rms_difference_n: f64,
    /// Mean of measured − planned (N).
    pub mean_difference_n: f64,
    /// Pearson's correlation r.
    pub pearson_r: f64,
    /// r².
    pub r2_pearson: f64,
    /// Coefficient of determination of the measurement by the plan,
    /// 1 − SS_res/SS_tot (compared with [RS Table 6]).
    pub r_squared: f64,
    /// Least-squares gain k of measured ≈ k · planned.
    pub gain: f64,
}

impl ForceComparison {
    /// `planned` against `measured`, pair by pair.
    pub fn new(planned: &[f64], measured: &[f64]) -> Self {
        let n = planned.len().min(measured.len()).max(1) as f64;
        let pairs = || planned.iter().zip(measured);
        let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (peak_planned_n, peak_measured_n) = (max(planned), max(measured));
        let ss_res: f64 = pairs().map(|(p, m)| (m - p) * (m - p)).sum();
        let mean_p = planned.iter().sum::<f64>() / n;
        let mean_m = measured.iter().sum::<f64>() / n;
        let ss_tot: f64 = measured.iter().map(|m| (m - mean_m) * (m - mean_m)).sum();
        let ss_p: f64 = planned.iter().map(|p| (p - mean_p) * (p - mean_p)).sum();
        let cov: f64 = pairs().map(|(p, m)| (p - mean_p) * (m - mean_m)).sum();
        let pearson_r = if ss_p > 0.0 && ss_tot > 0.0 {
            cov / (ss_p * ss_tot).sqrt()
        } else {
            f64::NAN
        };
        let pp: f64 = planned.iter().map(|p| p * p).sum();
        let pm: f64 = pairs().map(|(p, m)| p * m).sum();
        Self {
            peak_planned_n,
            peak_measured_n,
            peak_difference_n: peak_measured_n - peak_planned_n,
            rms_difference_n: (ss_res / n).sqrt(),
            mean_difference_n: mean_m - mean_p,
            pearson_r,
            r2_pearson: pearson_r * pearson_r,
            r_squared: if ss_tot > 0.0 {
                1.0 - ss_res / ss_tot
            } else {
                f64::NAN
            },
            gain: if pp > 0.0 { pm / pp } else { f64::NAN },
        }
    }
}

/// The rope length or the handle extension planned and measured.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TravelComparison {
    /// Root mean square of measured − planned (m).
    pub rms_difference_m: f64,
    /// Mean of measured − planned: an encoder's zero offset (m).
    pub mean_difference_m: f64,
    /// Root mean square of measured − planned after removing the mean (m).
    pub rms_difference_zeroed_m: f64,
    /// Largest |measured − planned| (m).
    pub max_abs_difference_m: f64,
}

impl TravelComparison {
    /// `planned` against `measured`, pair by pair.
    pub fn new(planned: &[f64], measured: &[f64]) -> Self {
        let d: Vec<f64> = planned.iter().zip(measured).map(|(p, m)| m - p).collect();
        let n = d.len().max(1) as f64;
        let mean = d.iter().sum::<f64>() / n;
        Self {
            rms_difference_m: (d.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
            mean_difference_m: mean,
            rms_difference_zeroed_m: (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt(),
            max_abs_difference_m: d.iter().fold(0.0, |a, x| a.max(x.abs())),
        }
    }
}

/// The summary of one `validate-dig` job.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ValidateSummary {
    /// Always "validate-dig".
    pub job: &'static str,
    /// The plan's folder.
    pub plan: String,
    /// The measured file.
    pub measured: String,
    /// The pile the plan is for.
    pub surface: String,
    /// Samples of the plan.
    pub planned_samples: usize,
    /// Samples of the measured record.
    pub measured_samples: usize,
    /// Plan samples inside the measured record after alignment (compared).
    pub compared_samples: usize,
    /// The measured record's first and last time (s).
    pub record_span_s: [f64; 2],
    /// The clock that maps the plan onto the record.
    pub alignment: Alignment,
    /// Dug mass (kg), when the record has `mass_kg` ([RS Table 6]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<Deviation>,
    /// Dig time (s): t_d against s · t_d ([RS Table 6]).
    pub dig_time_s: Deviation,
    /// Hoist force ([RS Fig. 20], [RS Table 6]).
    pub hoist_force: ForceComparison,
    /// Crowd force ([RS Fig. 20], [RS Table 6]).
    pub crowd_force: ForceComparison,
    /// Free rope length, when the record has `rope_length_m`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rope_length: Option<TravelComparison>,
    /// Handle extension, when the record has `handle_extension_m`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub handle_extension: Option<TravelComparison>,
}

/// A series planned and measured at the compared samples.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Paired {
    /// Planned values.
    pub planned: Vec<f64>,
    /// Measured values, interpolated at the aligned times.
    pub measured: Vec<f64>,
}

/// The compared samples: the plan's times inside the aligned record.
#[derive(Debug, Clone, PartialEq)]
pub struct AlignedSeries {
    /// Plan time (s).
    pub t_plan_s: Vec<f64>,
    /// The same instants on the measured clock (s).
    pub t_measured_s: Vec<f64>,
    /// Hoist force (N).
    pub hoist_force_n: Paired,
    /// Crowd force (N).
    pub crowd_force_n: Paired,
    /// Rope length (m), when both sides have it.
    pub rope_length_m: Option<Paired>,
    /// Handle extension (m), when both sides have it.
    pub handle_extension_m: Option<Paired>,
}

/// A finished comparison: its summary and the aligned series it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Validation {
    /// The job's summary.
    pub summary: ValidateSummary,
    /// The compared samples.
    pub aligned: AlignedSeries,
    /// The whole measured record with its times moved onto the plan's
    /// clock, (t − τ)/s (for plots like [RS Fig. 20]).
    pub measured_on_plan_clock: ForceRecord,
}

/// Compares `measured` with `planned` ([RS §5]): aligns the two in time
/// ([`align`] with `params`), resamples the measurement at the plan's
/// times inside the record, and reports the forces, the travels and the
/// rows of [RS Table 6].
pub fn validate(
    planned: &PlannedRecord,
    measured: &MeasuredRecord,
    params: &AlignParams,
) -> Result<Validation> {
    let (p, m) = (&planned.forces, &measured.forces);
    let alignment = align(p, planned.td_s, m, &measured.source, params)?;
    let (t0, t1) = m.span_s();
    let mut t_plan_s = Vec::new();
    let mut t_measured_s = Vec::new();
    let mut index = Vec::new();
    for (i, &t) in p.t_s.iter().enumerate() {
        let tm = alignment.measured_time(t);
        if tm >= t0 && tm <= t1 {
            t_plan_s.push(t);
            t_measured_s.push(tm);
            index.push(i);
        }
    }
    let pair = |pv: &[f64], mv: &[f64]| Paired {
        planned: index.iter().map(|&i| pv[i]).collect(),
        measured: t_measured_s
            .iter()
            .map(|&tm| interpolate(&m.t_s, mv, tm))
            .collect(),
    };
    let both = |a: &Option<Vec<f64>>, b: &Option<Vec<f64>>| match (a, b) {
        (Some(a), Some(b)) => Some(pair(a, b)),
        _ => None,
    };
    let aligned = AlignedSeries {
        hoist_force_n: pair(&p.hoist_force_n, &m.hoist_force_n),
        crowd_force_n: pair(&p.crowd_force_n, &m.crowd_force_n),
        rope_length_m: both(&p.rope_length_m, &m.rope_length_m),
        handle_extension_m: both(&p.handle_extension_m, &m.handle_extension_m),
        t_plan_s,
        t_measured_s,
    };
    let force = |s: &Paired| ForceComparison::new(&s.planned, &s.measured);
    let travel = |s: &Option<Paired>| {
        s.as_ref()
            .map(|s| TravelComparison::new(&s.planned, &s.measured))
    };
    let summary = ValidateSummary {
        job: "validate-dig",
        plan: planned.source.clone(),
        measured: measured.source.display().to_string(),
        surface: planned.surface.clone(),
        planned_samples: p.t_s.len(),
        measured_samples: m.t_s.len(),
        compared_samples: aligned.t_plan_s.len(),
        record_span_s: [t0, t1],
        mass_kg: measured
            .mass_kg
            .map(|mk| Deviation::new(planned.m_dig_kg, mk)),
        dig_time_s: Deviation::new(planned.td_s, alignment.time_scale * planned.td_s),
        hoist_force: force(&aligned.hoist_force_n),
        crowd_force: force(&aligned.crowd_force_n),
        rope_length: travel(&aligned.rope_length_m),
        handle_extension: travel(&aligned.handle_extension_m),
        alignment,
    };
    let mut measured_on_plan_clock = m.clone();
    for t in &mut measured_on_plan_clock.t_s {
        *t = (*t - alignment.offset_s) / alignment.time_scale;
    }
    Ok(Validation {
        summary,
        aligned,
        measured_on_plan_clock,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// [RS Table 6]: planned and tested mass and time, and the relative
    /// deviations the paper prints (its "relative deviation" is relative
    /// to the test result).
    #[test]
    fn relative_deviations_reproduce_table_6() {
        let rows = [
            (2.053, 2.086, 1.58, 11.85, 11.81, 0.34),
            (1.991, 2.079, 4.23, 11.81, 11.72, 0.77),
            (2.156, 2.245, 3.96, 11.57, 11.49, 0.70),
            (2.045, 2.174, 5.93, 11.49, 11.43, 0.52),
        ];
        for (mp, mt, dm, tp, tt, dt) in rows {
            let m = Deviation::new(mp, mt);
            let t = Deviation::new(tp, tt);
            assert_relative_eq!(m.relative_deviation_pct, dm, epsilon = 0.005);
            assert_relative_eq!(t.relative_deviation_pct, dt, epsilon = 0.005);
        }
    }

    #[test]
    fn a_pure_gain_error_gives_the_gain_r_one_and_r_squared_below_one() {
        let p: Vec<f64> = (0..100)
            .map(|i| 200.0 + (i as f64 * 0.1).sin() * 50.0)
            .collect();
        let m: Vec<f64> = p.iter().map(|x| 1.06 * x).collect();
        let c = ForceComparison::new(&p, &m);
        assert_relative_eq!(c.gain, 1.06, epsilon = 1e-12);
        assert_relative_eq!(c.pearson_r, 1.0, epsilon = 1e-12);
        assert!(c.r_squared < 1.0);
        let same = ForceComparison::new(&p, &p);
        assert_relative_eq!(same.r_squared, 1.0);
        assert_relative_eq!(same.rms_difference_n, 0.0);
        assert_relative_eq!(same.gain, 1.0);
    }
}
