//! The digging simulator: soil with buried boulders the planner does not know.
//!
//! This is the truth's side of the code: the boulders, the soil and the
//! sensor noise live here and in the scenario's `[soil]`, `[sensing]` and
//! `[[obstacle]]`; the planner (`planner.rs`) sees none of them, only the
//! joint torques [`TorqueSensor`] reports.
//!
//! [`SoilSim::advance`] moves the tooth along one planned segment in time steps
//! of dt and reports the first contact with any boulder, met before or not
//! (the planner only estimates where the ones it met are): between
//! two steps it tests the chord against every unknown envelope (so a fast
//! step cannot jump over a rim), then bisects the time of entry to 1e-12 s and
//! puts the contact on the outside of the rim. At the contact the boulder
//! stalls the bucket (the tip stops there) and pushes back with the force of
//! [`Soil::contact_force`] — the jump in the digging resistance of paper §2.2.

use autoshovel_core::Vec2;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::ground::Ground;
use crate::kinematics::Backhoe;
use crate::kinematics::Joints;
use crate::obstacle::Envelope;
use crate::scenario::SensingSpec;
use crate::segment::{MotionState, Segment};
use crate::soil::Soil;

/// The soil and what is buried in it.
#[derive(Debug, Clone, Copy)]
pub struct SoilSim<'a> {
    /// The machine.
    pub machine: &'a Backhoe,
    /// The ground line.
    pub ground: &'a Ground,
    /// Soil parameters.
    pub soil: &'a Soil,
    /// Every boulder, known or not.
    pub obstacles: &'a [Envelope],
    /// h_b (m).
    pub bucket_width_m: f64,
    /// The machine's digging force, which a boulder stalls (N).
    pub max_force_n: f64,
}

/// A boulder met.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Index of the boulder.
    pub obstacle: usize,
    /// Local time in the segment (s).
    pub t_local_s: f64,
    /// The state of the front at the contact.
    pub state: MotionState,
    /// The contact point (on the rim, outside by at most rounding) (m).
    pub point: Vec2,
    /// Outward normal of the envelope there.
    pub normal: Vec2,
    /// V_c: the tip velocity (its direction of motion if at rest) (m/s).
    pub velocity: Vec2,
    /// F_f: the boulder's push on the tooth (N).
    pub force: Vec2,
}

/// What one segment did in the simulator.
#[derive(Debug, Clone)]
pub struct SegmentRun {
    /// (local time (s), state) at every step, from the first step after 0;
    /// ends at the segment's end or at the contact.
    pub states: Vec<(f64, MotionState)>,
    /// The first contact, if any.
    pub contact: Option<Contact>,
}

impl SoilSim<'_> {
    /// The soil's resistance on the tooth at a state (N).
    pub fn resistance(&self, state: &MotionState) -> Vec2 {
        self.soil
            .resistance(self.ground, state.tip, state.direction, self.bucket_width_m)
    }

    /// Advance along `segment` in steps of `dt_s`, up to its end or the first
    /// contact with a boulder.
    pub fn advance(&self, segment: &Segment, dt_s: f64) -> SegmentRun {
        let total = segment.duration_s();
        let steps = (total / dt_s - 1e-9).ceil().max(1.0) as usize;
        let mut states = Vec::with_capacity(steps);
        let mut t_prev = 0.0;
        let mut p_prev = segment.tip(self.machine, 0.0);
        for k in 1..=steps {
            let t = if k == steps { total } else { k as f64 * dt_s };
            let p = segment.tip(self.machine, t);
            if let Some(contact) = self.first_contact(segment, t_prev, p_prev, t, p) {
                states.push((contact.t_local_s, contact.state));
                return SegmentRun {
                    states,
                    contact: Some(contact),
                };
            }
            states.push((t, segment.state(self.machine, t)));
            t_prev = t;
            p_prev = p;
        }
        SegmentRun {
            states,
            contact: None,
        }
    }

    /// The earliest contact between (ta, pa) and (tb, pb): the first time the
    /// tip enters an envelope S of [HE eq. 10].
    fn first_contact(
        &self,
        segment: &Segment,
        ta: f64,
        pa: Vec2,
        tb: f64,
        pb: Vec2,
    ) -> Option<Contact> {
        let mut best: Option<(f64, usize)> = None;
        for (i, e) in self.obstacles.iter().enumerate() {
            if !e.meets_segment(pa, pb) {
                continue;
            }
            // A time inside the envelope ([HE eq. 10]: the tip is in S): the
            // step's end, or a sub-step.
            let inside = if e.contains(pb) {
                Some(tb)
            } else {
                (1..16)
                    .map(|j| ta + (tb - ta) * j as f64 / 16.0)
                    .find(|&t| e.contains(segment.tip(self.machine, t)))
            };
            let Some(mut t_in) = inside else { continue };
            let mut t_out = ta;
            while t_in - t_out > 1e-12 {
                let mid = 0.5 * (t_in + t_out);
                if e.contains(segment.tip(self.machine, mid)) {
                    t_in = mid;
                } else {
                    t_out = mid;
                }
            }
            let earlier = match best {
                Some((b, _)) => t_out < b,
                None => true,
            };
            if earlier {
                best = Some((t_out, i));
            }
        }
        let (t, i) = best?;
        let e = &self.obstacles[i];
        let state = segment.state(self.machine, t);
        let normal = e.outward_normal(state.tip);
        let velocity = if state.tip_velocity.norm() > 1e-9 {
            state.tip_velocity
        } else {
            state.direction
        };
        let force = self.soil.contact_force(normal, velocity, self.max_force_n);
        Some(Contact {
            obstacle: i,
            t_local_s: t,
            state,
            point: state.tip,
            normal,
            velocity,
            force,
        })
    }
}

/// The machine's joint-torque readings: the torques of the dynamics plus
/// independent Gaussian noise per joint, seeded.
#[derive(Debug, Clone)]
pub struct TorqueSensor {
    noise: Option<Normal<f64>>,
    rng: ChaCha8Rng,
}

impl TorqueSensor {
    /// A sensor with the scenario's noise and seed.
    pub fn new(spec: &SensingSpec) -> Self {
        Self {
            noise: (spec.torque_noise_nm > 0.0)
                .then(|| Normal::new(0.0, spec.torque_noise_nm).expect("σ > 0 and finite")),
            rng: ChaCha8Rng::seed_from_u64(spec.seed),
        }
    }

    /// One reading of the torques `tau` (N·m).
    pub fn measure(&mut self, tau: &Joints) -> Joints {
        match &self.noise {
            Some(n) => tau.map(|t| t + n.sample(&mut self.rng)),
            None => *tau,
        }
    }
}
