//! A measurement made from a plan, for trying `validate-dig` without a
//! testbed and for testing it against known errors: the planned forces seen
//! through a logger that starts `delay_s` before the dig, a dig that takes
//! `time_scale` · t_d, force sensors with a gain error and seeded Gaussian
//! noise, noise-free rope and handle encoders, and a weighed mass off by
//! `mass_offset_kg`. Outside the dig the machine is at rest and the forces
//! hold their values at its ends.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::error::{DigError, Result};
use crate::validate::align::interpolate;
use crate::validate::record::{ForceRecord, MeasuredRecord, PlannedRecord};

/// The errors of a simulated measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasurementModel {
    /// Standard deviation of the noise on each force (N).
    pub noise_n: f64,
    /// Time from the logger's start (t = 0) to the dig's start (s).
    pub delay_s: f64,
    /// Measured dig time per planned dig time.
    pub time_scale: f64,
    /// Gain of the hoist force sensor (1: exact).
    pub gain_hoist: f64,
    /// Gain of the crowd force sensor (1: exact).
    pub gain_crowd: f64,
    /// Weighed minus planned mass (kg).
    pub mass_offset_kg: f64,
    /// Logger sample period (s).
    pub sample_period_s: f64,
    /// Recording after the dig ends (s).
    pub tail_s: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for MeasurementModel {
    /// A perfect measurement: no noise, delay, gain or mass error; 100 Hz,
    /// half a second after the dig.
    fn default() -> Self {
        Self {
            noise_n: 0.0,
            delay_s: 0.0,
            time_scale: 1.0,
            gain_hoist: 1.0,
            gain_crowd: 1.0,
            mass_offset_kg: 0.0,
            sample_period_s: 0.01,
            tail_s: 0.5,
            seed: 1,
        }
    }
}

impl MeasurementModel {
    /// The testbed-like errors used in the docs and tests: 0.37 s delay,
    /// hoist sensor +6 %, crowd −5 %, 2 N noise, 33 g more mass, a dig
    /// 0.3 % faster than planned.
    pub fn testbed() -> Self {
        Self {
            noise_n: 2.0,
            delay_s: 0.37,
            time_scale: 0.997,
            gain_hoist: 1.06,
            gain_crowd: 0.95,
            mass_offset_kg: 0.033,
            ..Self::default()
        }
    }

    /// Check the ranges once, at the edge.
    pub fn validate(&self) -> Result<()> {
        for (name, value, lo, hi, expected) in [
            (
                "MeasurementModel.noise_n",
                self.noise_n,
                0.0,
                1e6,
                "a force in [0, 1e6] N",
            ),
            (
                "MeasurementModel.delay_s",
                self.delay_s,
                -60.0,
                60.0,
                "a time in [-60, 60] s",
            ),
            (
                "MeasurementModel.time_scale",
                self.time_scale,
                0.5,
                2.0,
                "a ratio in [0.5, 2]",
            ),
            (
                "MeasurementModel.gain_hoist",
                self.gain_hoist,
                0.01,
                100.0,
                "a gain in [0.01, 100]",
            ),
            (
                "MeasurementModel.gain_crowd",
                self.gain_crowd,
                0.01,
                100.0,
                "a gain in [0.01, 100]",
            ),
            (
                "MeasurementModel.mass_offset_kg",
                self.mass_offset_kg,
                -1e6,
                1e6,
                "a mass in [-1e6, 1e6] kg",
            ),
            (
                "MeasurementModel.sample_period_s",
                self.sample_period_s,
                1e-4,
                1.0,
                "a period in [1e-4, 1] s",
            ),
            (
                "MeasurementModel.tail_s",
                self.tail_s,
                0.0,
                3600.0,
                "a time in [0, 3600] s",
            ),
        ] {
            if !(value.is_finite() && value >= lo && value <= hi) {
                return Err(DigError::BadParameter {
                    name,
                    value,
                    expected,
                });
            }
        }
        Ok(())
    }
}

/// The record the logger of `model` would write for `planned`, named
/// `source`; a model out of range ([`MeasurementModel::validate`]) is an error.
pub fn simulate_measurement(
    planned: &PlannedRecord,
    model: &MeasurementModel,
    source: &std::path::Path,
) -> Result<MeasuredRecord> {
    model.validate()?;
    let p = &planned.forces;
    let period = model.sample_period_s;
    let end = model.delay_s.max(0.0) + model.time_scale * planned.td_s + model.tail_s;
    let n = (end / period).floor() as usize + 1;
    let t_s: Vec<f64> = (0..n).map(|i| i as f64 * period).collect();
    // Plan time at each logger time, clamped to the dig: at rest outside it.
    let t_plan: Vec<f64> = t_s
        .iter()
        .map(|&t| ((t - model.delay_s) / model.time_scale).clamp(0.0, planned.td_s))
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(model.seed);
    let noise = Normal::new(0.0, model.noise_n).expect("a validated σ is finite and ≥ 0");
    let mut sensor = |v: &[f64], gain: f64| -> Vec<f64> {
        t_plan
            .iter()
            .map(|&t| gain * interpolate(&p.t_s, v, t) + noise.sample(&mut rng))
            .collect()
    };
    let hoist_force_n = sensor(&p.hoist_force_n, model.gain_hoist);
    let crowd_force_n = sensor(&p.crowd_force_n, model.gain_crowd);
    let encoder = |v: &Option<Vec<f64>>| {
        v.as_ref()
            .map(|v| t_plan.iter().map(|&t| interpolate(&p.t_s, v, t)).collect())
    };
    Ok(MeasuredRecord {
        source: source.to_path_buf(),
        forces: ForceRecord {
            hoist_force_n,
            crowd_force_n,
            rope_length_m: encoder(&p.rope_length_m),
            handle_extension_m: encoder(&p.handle_extension_m),
            t_s,
        },
        mass_kg: Some(planned.m_dig_kg + model.mass_offset_kg),
    })
}
