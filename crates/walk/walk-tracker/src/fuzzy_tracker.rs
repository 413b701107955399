//! The fuzzy tracker of the electric-shovel paper §4.3: inputs the lateral
//! error e = d + α·d0 [W eq. 23] and its rate ec, output the speed difference u
//! between the track motors; seven evenly spaced triangular terms
//! NB…PB on e ∈ [−0.45, 0.45], ec ∈ [−30, 30], u ∈ [−2700, 2700] rpm;
//! Mamdani min / max / centroid; the rule base of Table 1 (rows ec, columns e).
//!
//! Variable universe [W eq. 24]: the controller maps the physical inputs into
//! the fuzzy universes with scaling factors, e_f = k1·e, ec_f = k2·ec, and the
//! output back with u = k3·u_f. Values beyond a universe saturate at its edge.
//!
//! Sign (SPEC §3): e is positive left of the path; Table 1 gives a positive u
//! for a large positive e, which must turn the machine right, back towards the
//! path, so the controller commands n_right − n_left = −u.

use autoshovel_fuzzy::{FuzzyError, MamdaniSystem, Scratch};

pub use crate::controller::FuzzyParams;
use crate::controller::{ControlInput, Controller, Gains, Universe, CURVATURE_WINDOW_M};

/// The edge of the rule base's e and ec universes (Table 1's terms).
const E_EDGE: f64 = 0.45;
const EC_EDGE: f64 = 30.0;

pub use autoshovel_fuzzy::presets::shovel_table1::{TABLE1, TERMS};

/// Builds the Table 1 Mamdani system (inputs [e, ec], output u).
pub fn table1_system() -> Result<MamdaniSystem, FuzzyError> {
    autoshovel_fuzzy::presets::shovel_table1::system()
}

/// The fuzzy tracker.
#[derive(Debug, Clone)]
pub struct FuzzyTracker {
    /// Parameters.
    pub params: FuzzyParams,
    system: MamdaniSystem,
    scratch: Scratch,
    prev_e: Option<f64>,
    ec_filtered: f64,
    /// Last inputs fed to the rule base (e_f, ec_f) and its output u_f.
    pub last: (f64, f64, f64),
}

impl FuzzyTracker {
    /// The tracker on Table 1.
    pub fn new(params: FuzzyParams) -> Self {
        let system = table1_system().expect("Table 1 is a valid rule base");
        let scratch = system.scratch();
        Self {
            params,
            system,
            scratch,
            prev_e: None,
            ec_filtered: 0.0,
            last: (0.0, 0.0, 0.0),
        }
    }

    /// The rule base.
    pub fn system(&self) -> &MamdaniSystem {
        &self.system
    }
}

impl Controller for FuzzyTracker {
    fn name(&self) -> &'static str {
        "fuzzy"
    }

    fn reset(&mut self) {
        self.prev_e = None;
        self.ec_filtered = 0.0;
    }

    fn gains(&self) -> Gains {
        Gains::Fuzzy(self.params)
    }

    /// One tick: e = d + α·d0 [W eq. 23], its filtered rate ec, the
    /// variable universe e_f = k1·e, ec_f = k2·ec, u = k3·u_f [W eq. 24],
    /// and Table 1's Mamdani inference.
    fn step(&mut self, input: &ControlInput) -> f64 {
        let p = self.params;
        // α related to the path's curvature [W eq. 23]
        let alpha = if p.alpha_curvature_m > 0.0 {
            let kappa = input.leg.curvature_at(input.dev.s_a_m, CURVATURE_WINDOW_M);
            p.alpha + p.alpha_curvature_m * kappa.abs()
        } else {
            p.alpha
        };
        // e = d + α·d0 [W eq. 23]
        let e = input.dev.d_m + alpha * input.dev.d0_m;
        let raw = match self.prev_e {
            Some(prev) if input.dt_s > 0.0 => (e - prev) / input.dt_s,
            _ => 0.0,
        };
        self.prev_e = Some(e);
        let a = if p.ec_filter_s > 0.0 {
            input.dt_s / (p.ec_filter_s + input.dt_s)
        } else {
            1.0
        };
        self.ec_filtered += a * (raw - self.ec_filtered);
        let ec = self.ec_filtered;
        // e_f = k1·e, ec_f = k2·ec [W eq. 24]; with a variable universe the
        // physical universes E = edge/k contract by α(x) = (|x|/E)^τ + ε.
        let (ae, aec) = match p.universe {
            Universe::Fixed => (1.0, 1.0),
            Universe::Variable => {
                let factor =
                    |x: f64, edge: f64| ((x.abs() / edge).powf(p.vu_tau) + p.vu_epsilon).min(1.0);
                (factor(p.k1 * e, E_EDGE), factor(p.k2 * ec, EC_EDGE))
            }
        };
        let x = [p.k1 * e / ae, p.k2 * ec / aec];
        let u_f = if x.iter().all(|v| v.is_finite()) {
            self.system.infer_with(&x, &mut self.scratch).unwrap_or(0.0)
        } else {
            0.0
        };
        self.last = (x[0], x[1], u_f);
        // u = β·k3·u_f [W eq. 24] (β = α(e), 1 for fixed universes); n_r − n_l = −u
        -(ae * p.k3 * u_f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn table1_steers_back_towards_the_path() {
        let s = table1_system().unwrap();
        // Large positive e (PB, left of the path), ec = ZE → PM: u at PM's peak,
        // and the tracker turns right (negative n_r − n_l).
        let u = s.infer(&[0.45, 0.0]).unwrap();
        assert_relative_eq!(u, 1800.0, epsilon = 60.0);
        assert_relative_eq!(s.infer(&[0.0, 0.0]).unwrap(), 0.0, epsilon = 1e-9);
        // Odd symmetry of the table.
        assert_relative_eq!(
            s.infer(&[-0.2, 7.0]).unwrap(),
            -s.infer(&[0.2, -7.0]).unwrap(),
            epsilon = 1e-9
        );
    }
}
