//! The dig-planning model of the rope-shovel paper §4: objective
//! ([RS eqs. 25–27]), excavated volume ([RS eq. 28]), the 18 constraints
//! ([RS eqs. 29–35]), the optimisation model ([RS eq. 36]) and its solution
//! by the Grey Wolf Optimizer ([RS eq. 37]).
//!
//! One evaluation samples the trajectory of [RS eq. 22] at `numerics.samples`
//! instants, solves the inverse kinematics ([RS eqs. 7–8]) and the inverse
//! dynamics ([RS eq. 10]) at each, accumulates the material swept ([RS eq. 28]) and the
//! energy of the hoist and crowd ([RS eq. 25]), and returns f and every c_i.
//!
//! # Constraints (value ≤ 0 is satisfied; time-varying ones take the worst instant)
//! | c | eq. | value |
//! |---|---|---|
//! | c1, c2 | 29 | fill_min − V/V_cd, V/V_cd − fill_max |
//! | c3, c4 | 30 | t_min − t_d, t_d − t_max |
//! | c5, c6 | 31 | β_min − min β, max β − β_max (printed with min and max swapped) |
//! | c7, c8 | 32 | −min v_h − 0.001 v_h,max, max v_h − v_h,max |
//! | c9, c10 | 32 | −min v_c − 0.001 v_c,max, max v_c − v_c,max |
//! | c11–c14 | 33 | max F_h − F_h,max, max F_c − F_c,max, max P_h − P_h,max, max P_c − P_c,max |
//! | c15 | 34 | f̄(g_x) − g_y: the tip ends above the surface (H_dm − h) |
//! | c16 | 34 | H_kk + H_cd − g_y: the dipper bottom clears the hopper |
//! | c17 | 35 | max D − L_dg: the handle stroke |
//! | c18 | 35 | max y − H_tl: below the top of the boom point sheave |
//!
//! The digging back angle β is the clearance between the tip velocity and
//! the tooth's back face, which is tilted δ₁ from the handle normal: β = δ₁
//! when the tip moves along the normal, less when the crowd outruns the hoist.
//! For the optimiser the violations are normalised by their limits (fill
//! as is, time by t_max, angles in radians, speeds, forces and powers by
//! their ratings, heights by H_tl, stroke by L_dg) and summed.

use autoshovel_optim::{
    cma_es, minimize, CmaParams, CmaResult, Constraints, Evaluation, GwoParams, GwoResult, Init,
    Problem,
};

use crate::dig_surface::{swept_width, DigSurface};
use crate::dynamics::{inverse_dynamics, Drive, MassModel};
use crate::error::{DigError, Result};
use crate::kinematics::{Joints, RopeShovel};
use crate::profile::MachineProfile;
use crate::trajectory::Decision;

use autoshovel_core::G;

/// Names of c1–c18, as in the summary.
pub const CONSTRAINT_NAMES: [&str; 18] = [
    "c1_fill_min",
    "c2_fill_max",
    "c3_time_min",
    "c4_time_max",
    "c5_back_angle_min",
    "c6_back_angle_max",
    "c7_hoist_speed_positive",
    "c8_hoist_speed_max",
    "c9_crowd_speed_positive",
    "c10_crowd_speed_max",
    "c11_hoist_force_max",
    "c12_crowd_force_max",
    "c13_hoist_power_max",
    "c14_crowd_power_max",
    "c15_leaves_surface",
    "c16_hopper_clearance",
    "c17_handle_stroke",
    "c18_sheave_height",
];

/// c7 and c9 allow a reversal of this share of the rated speed: at the
/// ends of the dig both speeds are zero by [RS eq. 23], and their sign in the
/// last microseconds is rounding, not motion.
pub const SPEED_TOLERANCE: f64 = 1e-3;

/// Units of the constraint values.
pub const CONSTRAINT_UNITS: [&str; 18] = [
    "", "", "s", "s", "rad", "rad", "m/s", "m/s", "m/s", "m/s", "N", "N", "W", "W", "m", "m", "m",
    "m",
];

/// Whether a constraint bounds its quantity from below or from above.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Bound {
    /// The quantity must be at least the limit.
    Min,
    /// The quantity must be at most the limit.
    Max,
}

impl Bound {
    /// `min` or `max`, as summaries print it.
    pub fn name(self) -> &'static str {
        match self {
            Bound::Min => "min",
            Bound::Max => "max",
        }
    }
}

/// One constraint's limit.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ConstraintLimit {
    /// Name, as in [`CONSTRAINT_NAMES`].
    pub name: &'static str,
    /// The limit, in SI units.
    pub limit: f64,
    /// Lower or upper bound.
    pub bound: Bound,
    /// Units of the limit and of the constraint value.
    pub units: &'static str,
}

/// The state of the dig at one sample.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DigSample {
    /// Time (s).
    pub t_s: f64,
    /// Tooth tip x, y in the dig frame (m).
    pub tip_m: [f64; 2],
    /// Joint values.
    pub joints: Joints,
    /// Forces and speeds.
    pub drive: Drive,
    /// Cut thickness c normal to the path (m).
    pub cut_thickness_m: f64,
    /// Material in the dipper so far (kg).
    pub load_kg: f64,
    /// Digging back angle β (rad).
    pub back_angle_rad: f64,
}

/// Columns of a plan's `samples.csv`, one per value of [`DigSample::csv_row`]
/// (`plan-dig` writes it, `validate-dig` reads it back).
pub const SAMPLE_COLUMNS: [&str; 17] = [
    "t_s",
    "tip_x_m",
    "tip_y_m",
    "theta1_rad",
    "d2_m",
    "hoist_force_n",
    "crowd_force_n",
    "hoist_speed_m_s",
    "crowd_speed_m_s",
    "hoist_power_w",
    "crowd_power_w",
    "rope_handle_angle_rad",
    "resistance_tangential_n",
    "resistance_normal_n",
    "cut_thickness_m",
    "load_kg",
    "back_angle_rad",
];

impl DigSample {
    /// The sample as one row of `samples.csv` ([`SAMPLE_COLUMNS`]).
    pub fn csv_row(&self) -> [f64; 17] {
        [
            self.t_s,
            self.tip_m[0],
            self.tip_m[1],
            self.joints.theta1,
            self.joints.d2,
            self.drive.hoist_force_n,
            self.drive.crowd_force_n,
            self.drive.hoist_speed_m_s,
            self.drive.crowd_speed_m_s,
            self.drive.hoist_power_w(),
            self.drive.crowd_power_w(),
            self.drive.rope_handle_angle_rad,
            self.drive.resistance_tangential_n,
            self.drive.resistance_normal_n,
            self.cut_thickness_m,
            self.load_kg,
            self.back_angle_rad,
        ]
    }
}

/// Everything one evaluation measures.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DigOutcome {
    /// The decision evaluated.
    pub decision: Decision,
    /// f of [RS eq. 27].
    pub f: f64,
    /// f1 of [RS eq. 25]: energy per kilogram (J/kg).
    pub f1_j_per_kg: f64,
    /// f2 of [RS eq. 26]: time per kilogram (s/kg).
    pub f2_s_per_kg: f64,
    /// ∫ v_h F_h dt (J).
    pub hoist_energy_j: f64,
    /// ∫ v_c F_c dt (J).
    pub crowd_energy_j: f64,
    /// V of [RS eq. 28] (m³).
    pub volume_m3: f64,
    /// m_dig = ρV (kg).
    pub m_dig_kg: f64,
    /// V / V_cd.
    pub fill_factor: f64,
    /// The quantity each of c1–c18 bounds (fill, t_d, worst β, speed, force,
    /// power, end height, stroke, height), in SI units.
    pub measured: [f64; 18],
    /// c1–c18 (≤ 0 satisfied), in SI units: limit − measured for a lower
    /// bound, measured − limit for an upper one.
    pub constraints: [f64; 18],
    /// Normalised total violation (0 when feasible).
    pub violation: f64,
    /// Every sample had an inverse kinematics and a rope with a moment arm.
    pub reachable: bool,
}

impl DigOutcome {
    /// Every constraint met and every sample reachable.
    pub fn feasible(&self) -> bool {
        self.reachable && self.violation == 0.0
    }

    /// The violated constraints as "name = value unit", worst first.
    pub fn violated(&self) -> Vec<String> {
        let mut v: Vec<(usize, f64)> = self
            .constraints
            .iter()
            .enumerate()
            .filter(|(_, &c)| c > 0.0)
            .map(|(i, &c)| (i, c))
            .collect();
        v.sort_by(|a, b| b.1.total_cmp(&a.1));
        let mut out: Vec<String> = v
            .into_iter()
            .map(|(i, c)| {
                format!(
                    "{} exceeded by {:.4} {}",
                    CONSTRAINT_NAMES[i], c, CONSTRAINT_UNITS[i]
                )
            })
            .collect();
        if !self.reachable {
            out.insert(
                0,
                "reach: part of the path is out of the dipper's reach".to_string(),
            );
        }
        out
    }
}

/// The coordinates the optimiser moves in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SearchSpace {
    /// [bend_x, bend_y, t_d, g_x, g_y]: a₆ as mid-dig bends (default).
    #[default]
    Bends,
    /// The paper's [a_x6, a_y6, t_d, g_x, g_y].
    Paper,
}

impl SearchSpace {
    /// The coordinates' name as summaries print it: `bends` or `paper`.
    pub fn name(self) -> &'static str {
        match self {
            SearchSpace::Bends => "bends",
            SearchSpace::Paper => "paper",
        }
    }
}

impl std::str::FromStr for SearchSpace {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "bends" => Ok(Self::Bends),
            "paper" => Ok(Self::Paper),
            _ => Err(format!("unknown search space '{s}' (use bends or paper)")),
        }
    }
}

/// The planning model of one machine on one pile.
#[derive(Debug, Clone)]
pub struct DigModel {
    /// The machine profile.
    pub profile: MachineProfile,
    /// Its kinematics.
    pub shovel: RopeShovel,
    /// Its mass model.
    pub mass: MassModel,
    /// The pile.
    pub surface: DigSurface,
    space: SearchSpace,
    bounds: Vec<(f64, f64)>,
    scales: [f64; 18],
}

impl DigModel {
    /// Set up a model; refuses a pile whose toe the dipper cannot reach or
    /// whose material could never fill the dipper.
    pub fn new(profile: &MachineProfile, surface: DigSurface) -> Result<Self> {
        let geometry = profile.geometry();
        let shovel = RopeShovel::new(geometry);
        match shovel.inverse([0.0, 0.0]) {
            Some(q) if q.d2 + geometry.d20 <= geometry.handle_length => {}
            _ => {
                return Err(DigError::Unreachable(format!(
                    "the toe (0, 0) is out of the dipper's reach from the saddle at \
                     ({:.3}, {:.3}) m",
                    geometry.l1, geometry.l2
                )))
            }
        }
        // Most material a path inside the search box could take: everything
        // above the floor between the toe and the farthest end point.
        let (_, x_end) = surface.x_range();
        let reach = profile.search.gx_m[1].min(x_end);
        let steps = 400;
        let area: f64 = (0..steps)
            .map(|i| {
                let x = reach * (i as f64 + 0.5) / steps as f64;
                surface.height(x).clamp(0.0, profile.search.gy_m[1])
            })
            .sum::<f64>()
            * reach
            / steps as f64;
        let most = area * profile.dipper.width_m;
        let need = profile.limits.fill_min * profile.dipper.capacity_m3;
        if most < need {
            return Err(DigError::Surface(format!(
                "the pile is too small to fill the dipper: at most {:.3e} m³ lies within \
                 reach (g_x ≤ {:.3} m, g_y ≤ {:.3} m), the fill constraint c1 needs {:.3e} m³",
                most, reach, profile.search.gy_m[1], need
            )));
        }
        let l = &profile.limits;
        let scales = [
            1.0,
            1.0,
            l.time_max_s,
            l.time_max_s,
            1.0,
            1.0,
            l.hoist_speed_max_m_s,
            l.hoist_speed_max_m_s,
            l.crowd_speed_max_m_s,
            l.crowd_speed_max_m_s,
            l.hoist_force_max_n,
            l.crowd_force_max_n,
            l.hoist_power_max_w,
            l.crowd_power_max_w,
            geometry.sheave_top_height,
            geometry.sheave_top_height,
            geometry.handle_length,
            geometry.sheave_top_height,
        ];
        let mut model = Self {
            profile: profile.clone(),
            shovel,
            mass: MassModel::of(profile),
            surface,
            space: SearchSpace::Bends,
            bounds: Vec::new(),
            scales,
        };
        model.set_search_space(SearchSpace::Bends);
        Ok(model)
    }

    /// Choose the optimiser's coordinates (and with them the box of the
    /// profile's `[search]` table).
    pub fn set_search_space(&mut self, space: SearchSpace) {
        let s = &self.profile.search;
        let (a, b) = match space {
            SearchSpace::Bends => (s.bend_x_m, s.bend_y_m),
            SearchSpace::Paper => (s.ax6, s.ay6),
        };
        self.space = space;
        self.bounds = vec![
            (a[0], a[1]),
            (b[0], b[1]),
            (s.td_s[0], s.td_s[1]),
            (s.gx_m[0], s.gx_m[1]),
            (s.gy_m[0], s.gy_m[1]),
        ];
    }

    /// The optimiser's coordinates.
    pub fn search_space(&self) -> SearchSpace {
        self.space
    }

    /// The decision of an optimiser vector. The optimiser works on the
    /// physical box itself. The Grey Wolf update scales the leaders about the
    /// origin (C·X_α), so it leans towards small coordinates; mapped to
    /// [−1, 1]⁵ it leans to the box centre instead (t_d → 12 s), and on the
    /// four piles, seeds 1–6, that gave f 0.1–0.5 worse than the raw box,
    /// where the lean points at the short digs the objective prefers.
    pub fn decision(&self, x: &[f64]) -> Decision {
        match self.space {
            SearchSpace::Bends => Decision::from_bends(x[0], x[1], x[2], x[3], x[4]),
            SearchSpace::Paper => Decision::from_slice(x),
        }
    }

    /// The optimiser vector of a decision (for warm starts).
    pub fn vector(&self, d: &Decision) -> Vec<f64> {
        match self.space {
            SearchSpace::Bends => {
                let [bx, by] = d.bends();
                vec![bx, by, d.td_s, d.gx_m, d.gy_m]
            }
            SearchSpace::Paper => d.to_vec(),
        }
    }

    /// The limits of c1–c18 ([RS eqs. 29–35]; the table in the module docs); c15's depends on
    /// where the path ends, `gx_m`.
    pub fn constraint_limits(&self, gx_m: f64) -> [ConstraintLimit; 18] {
        use Bound::{Max, Min};
        let p = &self.profile;
        let l = &p.limits;
        let g = &self.shovel.geometry;
        let values = [
            (l.fill_min, Min), // [RS eq. 29]
            (l.fill_max, Max),
            (l.time_min_s, Min), // [RS eq. 30]
            (l.time_max_s, Max),
            (l.back_angle_min_deg.to_radians(), Min), // [RS eq. 31]
            (l.back_angle_max_deg.to_radians(), Max),
            (-SPEED_TOLERANCE * l.hoist_speed_max_m_s, Min), // [RS eq. 32]
            (l.hoist_speed_max_m_s, Max),
            (-SPEED_TOLERANCE * l.crowd_speed_max_m_s, Min),
            (l.crowd_speed_max_m_s, Max),
            (l.hoist_force_max_n, Max), // [RS eq. 33]
            (l.crowd_force_max_n, Max),
            (l.hoist_power_max_w, Max),
            (l.crowd_power_max_w, Max),
            (self.surface.height(gx_m), Min), // [RS eq. 34]
            (l.hopper_height_m + p.dipper.height_m, Min),
            (g.handle_length, Max), // [RS eq. 35]
            (g.sheave_top_height, Max),
        ];
        std::array::from_fn(|i| ConstraintLimit {
            name: CONSTRAINT_NAMES[i],
            limit: values[i].0,
            bound: values[i].1,
            units: CONSTRAINT_UNITS[i],
        })
    }

    /// The scale c_i is divided by in the summed violation.
    pub fn constraint_scale(&self, i: usize) -> f64 {
        self.scales[i]
    }

    /// Evaluate one decision (no curves kept).
    pub fn evaluate(&self, x: &Decision) -> DigOutcome {
        self.run(x, |_| {})
    }

    /// Evaluate one decision and keep every sample (for plots and CSV).
    pub fn simulate(&self, x: &Decision) -> (DigOutcome, Vec<DigSample>) {
        let mut samples = Vec::with_capacity(self.profile.numerics.samples);
        let out = self.run(x, |s| samples.push(*s));
        (out, samples)
    }

    /// The one loop behind [`DigModel::evaluate`] and [`DigModel::simulate`].
    fn run(&self, x: &Decision, mut sink: impl FnMut(&DigSample)) -> DigOutcome {
        let p = &self.profile;
        let geo = &self.shovel.geometry;
        let traj = x.trajectory();
        let n = p.numerics.samples;
        let dt = x.td_s / (n - 1) as f64;
        let (b, rho) = (p.dipper.width_m, p.material.density_kg_m3);
        let (kf, psi) = (p.material.cutting_resistance_pa, p.material.normal_ratio);
        let eps = p.material.fill_resistance_ratio;
        let (sp, cp) = geo.back_face_tilt.sin_cos();

        let mut reachable = true;
        let (mut v_h_min, mut v_h_max) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut v_c_min, mut v_c_max) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut f_h_max, mut f_c_max) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        let (mut p_h_max, mut p_c_max) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        let (mut beta_min, mut beta_max) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut d_max, mut y_max) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        let (mut e_h, mut e_c) = (0.0, 0.0);
        let mut prev: Option<(f64, f64, f64, [f64; 2])> = None; // (swept, P_h, P_c, tip)
        let mut area = 0.0;

        for i in 0..n {
            let t = i as f64 * dt;
            let tip = traj.at(t); // [RS eq. 22]
            let speed = (tip.v[0] * tip.v[0] + tip.v[1] * tip.v[1]).sqrt();
            // Cut thickness along the left normal; at rest (the ends) the
            // direction of the limit is the direction of the acceleration.
            let dir = if speed > 1e-12 { tip.v } else { tip.a };
            let norm = (dir[0] * dir[0] + dir[1] * dir[1]).sqrt();
            let (c, kappa) = if norm > 0.0 {
                let left = [-dir[1] / norm, dir[0] / norm];
                let kappa = if speed > 1e-12 {
                    (tip.v[0] * tip.a[1] - tip.v[1] * tip.a[0]) / (speed * speed * speed)
                } else {
                    0.0
                };
                (self.surface.cut_thickness(tip.p, left), kappa)
            } else {
                (0.0, 0.0)
            };
            let swept = swept_width(c, kappa).max(0.0);
            if let Some((sw0, _, _, p0)) = prev {
                let ds = ((tip.p[0] - p0[0]).powi(2) + (tip.p[1] - p0[1]).powi(2)).sqrt();
                area += 0.5 * (swept + sw0) * ds; // [RS eq. 28], per unit width
            }
            let load = rho * b * area;
            // [RS eqs. 7–8] and their rates.
            let Some(js) = self.shovel.joint_state(tip.p, tip.v, tip.a) else {
                reachable = false;
                prev = Some((swept, 0.0, 0.0, tip.p));
                continue;
            };
            // Resistance along the path: cutting (k_F·b·c) and, while the
            // dipper is in the bank, dragging its load (ε·g·m_load).
            let f_tau = if c > 0.0 {
                kf * b * c + eps * G * load
            } else {
                0.0
            };
            // [RS eq. 10]: the hoist and crowd forces.
            let Some(drive) =
                inverse_dynamics(&self.shovel, &self.mass, &js, tip.v, f_tau, psi, load)
            else {
                reachable = false;
                prev = Some((swept, 0.0, 0.0, tip.p));
                continue;
            };
            let (ph, pc) = (drive.hoist_power_w(), drive.crowd_power_w());
            if let Some((_, ph0, pc0, _)) = prev {
                e_h += 0.5 * (ph + ph0) * dt; // [RS eq. 25]: ∫ v_h F_h dt
                e_c += 0.5 * (pc + pc0) * dt; // [RS eq. 25]: ∫ v_c F_c dt
            }
            prev = Some((swept, ph, pc, tip.p));

            // Back angle between v and the tooth back face
            // b̂ = cos(δ₁+δ₂) n + sin(δ₁+δ₂) u.
            let (u, nn) = (js.u, js.n);
            let beta = if speed > 1e-12 {
                let bh = [cp * nn[0] + sp * u[0], cp * nn[1] + sp * u[1]];
                let cross = tip.v[0] * bh[1] - tip.v[1] * bh[0];
                let dot = tip.v[0] * bh[0] + tip.v[1] * bh[1];
                let beta = -cross.atan2(dot);
                beta_min = beta_min.min(beta);
                beta_max = beta_max.max(beta);
                beta
            } else {
                f64::NAN
            };
            v_h_min = v_h_min.min(drive.hoist_speed_m_s);
            v_h_max = v_h_max.max(drive.hoist_speed_m_s);
            v_c_min = v_c_min.min(drive.crowd_speed_m_s);
            v_c_max = v_c_max.max(drive.crowd_speed_m_s);
            f_h_max = f_h_max.max(drive.hoist_force_n);
            f_c_max = f_c_max.max(drive.crowd_force_n);
            p_h_max = p_h_max.max(ph);
            p_c_max = p_c_max.max(pc);
            d_max = d_max.max(js.q.d2 + geo.d20);
            y_max = y_max.max(tip.p[1]);
            sink(&DigSample {
                t_s: t,
                tip_m: tip.p,
                joints: js.q,
                drive,
                cut_thickness_m: c,
                load_kg: load,
                back_angle_rad: beta,
            });
        }

        let volume = b * area; // [RS eq. 28]
        let m_dig = rho * volume;
        let fill = volume / p.dipper.capacity_m3; // V/V_cd of [RS eq. 29]
        let measured = [
            fill, fill, x.td_s, x.td_s, beta_min, beta_max, v_h_min, v_h_max, v_c_min, v_c_max,
            f_h_max, f_c_max, p_h_max, p_c_max, x.gy_m, x.gy_m, d_max, y_max,
        ];
        // c1–c18: [RS eq. 29] … [RS eq. 35].
        let limits = self.constraint_limits(x.gx_m);
        let mut constraints = [0.0; 18];
        for (c, (m, lim)) in constraints.iter_mut().zip(measured.iter().zip(&limits)) {
            *c = match lim.bound {
                Bound::Min => lim.limit - m,
                Bound::Max => m - lim.limit,
            };
        }
        let mut violation: f64 = constraints
            .iter()
            .zip(&self.scales)
            .map(|(&c, &s)| if c > 0.0 { c / s } else { 0.0 })
            .sum();
        if !reachable || violation.is_nan() {
            violation = violation.max(0.0) + 100.0;
        }
        let energy = e_h + e_c;
        let (f1, f2, f) = if m_dig > 1e-9 && energy.is_finite() {
            let f1 = energy / m_dig; // [RS eq. 25]
            let f2 = x.td_s / m_dig; // [RS eq. 26]
            (f1, f2, p.objective.k1 * f1 + p.objective.k2 * f2) // [RS eq. 27]
        } else {
            (f64::INFINITY, f64::INFINITY, f64::INFINITY)
        };
        DigOutcome {
            decision: *x,
            f,
            f1_j_per_kg: f1,
            f2_s_per_kg: f2,
            hoist_energy_j: e_h,
            crowd_energy_j: e_c,
            volume_m3: volume,
            m_dig_kg: m_dig,
            fill_factor: fill,
            measured,
            constraints,
            violation,
            reachable,
        }
    }
}

impl Problem for DigModel {
    fn bounds(&self) -> &[(f64, f64)] {
        &self.bounds
    }

    /// f(x) under c_i ≤ 0 of [RS eq. 36], the violations normalised and summed.
    fn evaluate(&self, x: &[f64]) -> Evaluation {
        // [RS eq. 36]
        let out = DigModel::evaluate(self, &self.decision(x));
        Evaluation::new(out.f, out.violation)
    }
}

/// The rope-shovel paper's Grey Wolf Optimizer setting (§4.6): 50 wolves,
/// 100 iterations, good-point-set start (§4.5), feasibility rules, seed 0,
/// parallel evaluation — 5050 evaluations. The planner's default search is
/// [`search_preset`], which spends the same budget differently.
pub fn gwo_preset() -> GwoParams {
    GwoParams {
        population: 50,
        iterations: 100,
        init: Init::GoodPointSet,
        constraints: Constraints::FeasibilityRules,
        seed: 0,
        parallel: true,
    }
}

/// How a dig is searched: the Grey Wolf Optimizer ([RS eq. 37]), then a
/// CMA-ES polish of its best point ([`autoshovel_optim::cma_es`]) with the
/// same ranking rule and seed.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DigSearch {
    /// The Grey Wolf Optimizer.
    pub gwo: GwoParams,
    /// Evaluations of the polish after GWO (0: none).
    pub polish_evaluations: usize,
    /// The polish's first step, as a share of each coordinate's range.
    pub polish_step: f64,
}

impl From<GwoParams> for DigSearch {
    /// GWO alone, no polish.
    fn from(gwo: GwoParams) -> Self {
        Self {
            gwo,
            polish_evaluations: 0,
            polish_step: 0.05,
        }
    }
}

impl DigSearch {
    /// Evaluations of the whole search (without warm starts' own).
    pub fn evaluations(&self) -> usize {
        self.gwo.population * (self.gwo.iterations + 1) + self.polish_evaluations
    }
}

/// Evaluations of the default search's CMA-ES polish ([`search_preset`]).
pub const DEFAULT_POLISH_EVALUATIONS: usize = 20_000;

/// The planner's default search: the paper's GWO setting ([`gwo_preset`],
/// 5050 evaluations) and a CMA-ES polish of [`DEFAULT_POLISH_EVALUATIONS`]
/// of its best wolf. The best plans sit where several constraints meet
/// (t_d, c16, c5, c9); GWO alone stops short of that corner, by up to a few
/// per cent, and GWO alone with the same 25 050 evaluations does too
/// (docs/rope-shovel-dig.md, "Does the planner find its own optimum?"). With
/// `polish_evaluations = 0` it is the paper's search.
pub fn search_preset() -> DigSearch {
    DigSearch {
        polish_evaluations: DEFAULT_POLISH_EVALUATIONS,
        ..gwo_preset().into()
    }
}

/// A finished plan.
#[derive(Debug, Clone)]
pub struct DigPlan {
    /// The best decision and everything measured on it.
    pub outcome: DigOutcome,
    /// The samples along the planned dig.
    pub samples: Vec<DigSample>,
    /// The optimiser's record (convergence history, final pack for warm
    /// starts, led by the polished best when the polish improved on it).
    pub search: GwoResult,
    /// The polish, if one ran.
    pub polish: Option<CmaResult>,
}

impl DigPlan {
    /// Evaluations of the objective made by the search and the polish.
    pub fn evaluations(&self) -> usize {
        self.search.evaluations + self.polish.as_ref().map_or(0, |p| p.evaluations)
    }
}

/// Plan a dig ([RS eq. 36] solved by [RS eq. 37]): minimise f over the
/// search box with the Grey Wolf Optimizer, starting from `warm_start`
/// wolves (e.g. the previous cycle's `search.population`) plus the initial
/// pack of `search.gwo`, then polish its best by CMA-ES if
/// `search.polish_evaluations > 0`. A best plan that still violates a
/// constraint is an error naming the binding constraints.
pub fn plan_dig(model: &DigModel, search: &DigSearch, warm_start: &[Vec<f64>]) -> Result<DigPlan> {
    let mut found = minimize(model, &search.gwo, warm_start)?; // [RS eq. 37]
    let polish = if search.polish_evaluations > 0 {
        let p = cma_es(
            model,
            &found.best,
            found.best_eval,
            &CmaParams {
                evaluations: search.polish_evaluations,
                initial_step: search.polish_step,
                constraints: search.gwo.constraints,
                seed: search.gwo.seed,
                parallel: search.gwo.parallel,
                ..CmaParams::default()
            },
        )?;
        if p.best != found.best {
            found.best.clone_from(&p.best);
            found.best_eval = p.best_eval;
            found.population.pop();
            found.population.insert(0, (p.best.clone(), p.best_eval));
        }
        Some(p)
    } else {
        None
    };
    let decision = model.decision(&found.best);
    let (outcome, samples) = model.simulate(&decision);
    let evaluations = found.evaluations + polish.as_ref().map_or(0, |p| p.evaluations);
    if !outcome.feasible() {
        return Err(DigError::Infeasible {
            binding: outcome.violated().join("; "),
            evaluations,
        });
    }
    Ok(DigPlan {
        outcome,
        samples,
        search: found,
        polish,
    })
}
