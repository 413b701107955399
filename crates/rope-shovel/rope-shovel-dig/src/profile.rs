//! The machine profile: the geometry of Table 1, masses, the material, the
//! limits of the 18 constraints ([RS eqs. 29–35]), the objective weights (Table 3)
//! and the search box — one TOML file the user can replace.
//!
//! The default is the paper's 1:30 scale model (`profiles/scale-model.toml`,
//! embedded). Every key is required (a missing limit is an error, never a
//! silent default) except `geometry.toe_distance_m`. Values are checked once
//! here: non-finite, non-positive or contradictory values (a minimum above its
//! maximum, a search box outside the dig-time limits) are refused with the
//! file, the line and the key.
//!
//! # Reading of Table 1 (Fig. 2 is missing from the paper; see docs/rope-shovel-dig.md)
//! O is the saddle block (shipper shaft) centre, A the boom foot, B the boom
//! point sheave centre, C the bail pin where the hoist rope meets the dipper,
//! D the tooth tip. With the handle retracted (d₂ = 0), D lies `l_OD` from O
//! at the angle δ₂ from the handle axis, so the paper's l₃ (tip offset normal
//! to the handle) and d₂₀ (initial extension) are
//!
//! ```text
//!     l₃ = l_OD sin δ₂ = 89.3 mm,   d₂₀ = l_OD cos δ₂ = 239.7 mm.
//! ```
//!
//! The dig frame {Oo} has its origin at the toe (SPEC §1), so the paper's l₁, l₂
//! ([RS eq. 3]: the saddle centre's horizontal and vertical offsets from the origin)
//! are `l₁ = −toe_distance`, `l₂ = H`. By default the toe is where the tip
//! meets the floor with the handle retracted, which puts it 65.5 mm in front
//! of O with the handle 5.6° behind the vertical.

use serde::Deserialize;

use autoshovel_core::config::{self, TomlFile};

use crate::error::{DigError, Result};

/// The embedded default profile (the paper's scale model).
pub const SCALE_MODEL_TOML: &str = include_str!("../profiles/scale-model.toml");

/// Table 1 and the placement of the machine.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct GeometrySpec {
    /// R1: boom point sheave radius (m).
    pub sheave_radius_m: f64,
    /// R2: crowd pinion pitch radius (m) (reported as crowd motor speed).
    pub pinion_radius_m: f64,
    /// l_AB: boom length, foot to sheave centre (m).
    pub boom_length_m: f64,
    /// l_OB: saddle centre to sheave centre along the boom (m).
    pub saddle_to_sheave_m: f64,
    /// l_OC: saddle centre to the bail pin on the handle axis, retracted (m).
    pub saddle_to_bail_m: f64,
    /// l_OD: saddle centre to the tooth tip, retracted (m).
    pub saddle_to_tip_m: f64,
    /// H: saddle centre above the floor (m).
    pub saddle_height_m: f64,
    /// α: repose angle of the ideal face (deg).
    pub pile_angle_deg: f64,
    /// β: boom angle to the horizontal (deg).
    pub boom_angle_deg: f64,
    /// δ1: tilt of the tooth back face from the normal to the tooth line OD
    /// (deg) (so δ1 + δ2 from the handle normal; docs/rope-shovel-dig.md).
    pub dipper_pitch_deg: f64,
    /// δ2: angle at O between the handle axis and OD (deg).
    pub tip_angle_deg: f64,
    /// Horizontal distance from O to the toe (m); default: the tip meets the
    /// floor with the handle retracted.
    #[serde(default)]
    pub toe_distance_m: Option<f64>,
}

/// The dipper.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct DipperSpec {
    /// b: width across the dig plane (m).
    pub width_m: f64,
    /// L_c: length from the tip back along the handle (m).
    pub length_m: f64,
    /// H_cd: height from the tip to the bottom (m).
    pub height_m: f64,
    /// V_cd: rated capacity (m³).
    pub capacity_m3: f64,
    /// Empty mass (kg).
    pub mass_kg: f64,
}

/// The handle (dipper stick).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct HandleSpec {
    /// L_d = L_dg: length, which is also the crowd stroke limit of c17 (m).
    pub length_m: f64,
    /// m_d (kg).
    pub mass_kg: f64,
}

/// The material and its digging resistance (SPEC §4.2).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Bank density ρ (kg/m³) (limestone 2540, Table 2).
    pub density_kg_m3: f64,
    /// k_F of F_τ = k_F·b·c (Pa = J/m³).
    pub cutting_resistance_pa: f64,
    /// ψ of F_n = ψ·F_τ.
    pub normal_ratio: f64,
    /// ε of the filling resistance ε·g·m_load: the drag of the material
    /// already in the dipper while it is in the bank.
    pub fill_resistance_ratio: f64,
}

/// Limits of the constraints c1–c18 ([RS eqs. 29–35]).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    /// c1: least fill factor V/V_cd.
    pub fill_min: f64,
    /// c2: greatest fill factor.
    pub fill_max: f64,
    /// c3: shortest dig (s).
    pub time_min_s: f64,
    /// c4: longest dig (s).
    pub time_max_s: f64,
    /// c5: least digging back (clearance) angle (deg).
    pub back_angle_min_deg: f64,
    /// c6: greatest digging back angle (deg).
    pub back_angle_max_deg: f64,
    /// c8: hoist rope speed limit (m/s).
    pub hoist_speed_max_m_s: f64,
    /// c10: crowd speed limit (m/s).
    pub crowd_speed_max_m_s: f64,
    /// c11: hoist force rating (N).
    pub hoist_force_max_n: f64,
    /// c12: crowd force rating (N).
    pub crowd_force_max_n: f64,
    /// c13: hoist power rating (W).
    pub hoist_power_max_w: f64,
    /// c14: crowd power rating (W).
    pub crowd_power_max_w: f64,
    /// c16: H_kk, hopper height above the floor (m).
    pub hopper_height_m: f64,
}

/// Weights of [RS eq. 27] (Table 3).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectiveSpec {
    /// k1, on f1 (J/kg).
    pub k1: f64,
    /// k2, on f2 (s/kg).
    pub k2: f64,
}

/// Search box of the decision vector x = [a_x6, a_y6, t_d, g_x, g_y]; by
/// default the a₆ are searched as mid-dig bends (see
/// [`crate::Decision::from_bends`]).
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SearchSpec {
    /// Mid-dig bend of the x path (m).
    pub bend_x_m: [f64; 2],
    /// Mid-dig bend of the y path (m).
    pub bend_y_m: [f64; 2],
    /// a_x6 (m/s⁶).
    pub ax6: [f64; 2],
    /// a_y6 (m/s⁶).
    pub ay6: [f64; 2],
    /// t_d (s).
    pub td_s: [f64; 2],
    /// g_x (m).
    pub gx_m: [f64; 2],
    /// g_y (m).
    pub gy_m: [f64; 2],
}

/// Numerical resolution.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct NumericsSpec {
    /// Samples along the dig, ends included (at least 21).
    pub samples: usize,
}

/// A whole machine profile, as read from TOML and checked.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct MachineProfile {
    /// Table 1 and placement.
    pub geometry: GeometrySpec,
    /// The dipper.
    pub dipper: DipperSpec,
    /// The handle.
    pub handle: HandleSpec,
    /// The material.
    pub material: MaterialSpec,
    /// Constraint limits.
    pub limits: LimitsSpec,
    /// Objective weights.
    pub objective: ObjectiveSpec,
    /// Search box.
    pub search: SearchSpec,
    /// Resolution.
    pub numerics: NumericsSpec,
}

impl Default for MachineProfile {
    /// The paper's scale model.
    fn default() -> Self {
        Self::scale_model()
    }
}

impl MachineProfile {
    /// The paper's 1:30 scale model (the embedded `scale-model.toml`).
    pub fn scale_model() -> Self {
        Self::from_toml(SCALE_MODEL_TOML, "<builtin scale-model>")
            .expect("the embedded profile is valid")
    }

    /// Check every value; `text` and `file` locate errors.
    fn check_values(&self, text: &str, file: &str) -> Result<()> {
        let bad = |table: &str, key: &str, value: f64, expected: &str| {
            DigError::from(config::invalid(
                text,
                file,
                (table, 0),
                key,
                value,
                expected,
            ))
        };
        let g = &self.geometry;
        let positive: [(&str, &str, f64); 22] = [
            ("geometry", "sheave_radius_m", g.sheave_radius_m),
            ("geometry", "pinion_radius_m", g.pinion_radius_m),
            ("geometry", "boom_length_m", g.boom_length_m),
            ("geometry", "saddle_to_sheave_m", g.saddle_to_sheave_m),
            ("geometry", "saddle_to_bail_m", g.saddle_to_bail_m),
            ("geometry", "saddle_to_tip_m", g.saddle_to_tip_m),
            ("geometry", "saddle_height_m", g.saddle_height_m),
            ("dipper", "width_m", self.dipper.width_m),
            ("dipper", "length_m", self.dipper.length_m),
            ("dipper", "height_m", self.dipper.height_m),
            ("dipper", "capacity_m3", self.dipper.capacity_m3),
            ("dipper", "mass_kg", self.dipper.mass_kg),
            ("handle", "length_m", self.handle.length_m),
            ("handle", "mass_kg", self.handle.mass_kg),
            ("material", "density_kg_m3", self.material.density_kg_m3),
            (
                "limits",
                "hoist_speed_max_m_s",
                self.limits.hoist_speed_max_m_s,
            ),
            (
                "limits",
                "crowd_speed_max_m_s",
                self.limits.crowd_speed_max_m_s,
            ),
            ("limits", "hoist_force_max_n", self.limits.hoist_force_max_n),
            ("limits", "crowd_force_max_n", self.limits.crowd_force_max_n),
            ("limits", "hoist_power_max_w", self.limits.hoist_power_max_w),
            ("limits", "crowd_power_max_w", self.limits.crowd_power_max_w),
            ("limits", "time_min_s", self.limits.time_min_s),
        ];
        config::check_each(text, file, &positive, config::POSITIVE)?;
        // The first ten are the machine's lengths (m).
        config::check_each(text, file, &positive[..10], config::LENGTH)?;
        let non_negative = [
            (
                "material",
                "cutting_resistance_pa",
                self.material.cutting_resistance_pa,
            ),
            ("material", "normal_ratio", self.material.normal_ratio),
            (
                "material",
                "fill_resistance_ratio",
                self.material.fill_resistance_ratio,
            ),
            ("limits", "hopper_height_m", self.limits.hopper_height_m),
            ("limits", "fill_min", self.limits.fill_min),
            ("objective", "k1", self.objective.k1),
            ("objective", "k2", self.objective.k2),
        ];
        config::check_each(text, file, &non_negative, config::NON_NEGATIVE)?;
        if self.objective.k1 + self.objective.k2 == 0.0 {
            return Err(bad("objective", "k2", 0.0, "k1 + k2 > 0"));
        }
        let angles = [
            ("pile_angle_deg", g.pile_angle_deg, 1.0, 89.0),
            ("boom_angle_deg", g.boom_angle_deg, 1.0, 89.0),
            ("dipper_pitch_deg", g.dipper_pitch_deg, -45.0, 45.0),
            ("tip_angle_deg", g.tip_angle_deg, 0.1, 89.0),
        ];
        for (key, v, lo, hi) in angles {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(bad(
                    "geometry",
                    key,
                    v,
                    &format!("an angle in [{lo}°, {hi}°]"),
                ));
            }
        }
        if let Some(t) = g.toe_distance_m {
            if !t.is_finite() {
                return Err(bad("geometry", "toe_distance_m", t, "a finite distance"));
            }
        }
        if g.saddle_to_bail_m >= g.saddle_to_tip_m {
            return Err(bad(
                "geometry",
                "saddle_to_bail_m",
                g.saddle_to_bail_m,
                "less than saddle_to_tip_m (the bail pin is behind the tip)",
            ));
        }
        if g.saddle_to_sheave_m >= g.boom_length_m {
            return Err(bad(
                "geometry",
                "saddle_to_sheave_m",
                g.saddle_to_sheave_m,
                "less than boom_length_m (the saddle is on the boom)",
            ));
        }
        let l = &self.limits;
        let ranges = [
            ("fill_min", l.fill_min, "fill_max", l.fill_max),
            ("time_min_s", l.time_min_s, "time_max_s", l.time_max_s),
            (
                "back_angle_min_deg",
                l.back_angle_min_deg,
                "back_angle_max_deg",
                l.back_angle_max_deg,
            ),
        ];
        for (lo_key, lo, hi_key, hi) in ranges {
            if !hi.is_finite() {
                return Err(bad("limits", hi_key, hi, "a finite value"));
            }
            if !(lo.is_finite() && lo < hi) {
                return Err(bad(
                    "limits",
                    lo_key,
                    lo,
                    &format!("less than {hi_key} = {hi}"),
                ));
            }
        }
        let s = &self.search;
        for (key, [lo, hi]) in [
            ("bend_x_m", s.bend_x_m),
            ("bend_y_m", s.bend_y_m),
            ("ax6", s.ax6),
            ("ay6", s.ay6),
            ("td_s", s.td_s),
            ("gx_m", s.gx_m),
            ("gy_m", s.gy_m),
        ] {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(bad(
                    "search",
                    key,
                    lo,
                    &format!("[lower, upper] with lower < upper (got [{lo}, {hi}])"),
                ));
            }
        }
        if s.td_s[0] <= 0.0 || s.td_s[1] < l.time_min_s || s.td_s[0] > l.time_max_s {
            return Err(bad(
                "search",
                "td_s",
                s.td_s[0],
                &format!(
                    "a positive range overlapping the dig-time limits [{}, {}] s",
                    l.time_min_s, l.time_max_s
                ),
            ));
        }
        if s.gx_m[0] <= 0.0 {
            return Err(bad(
                "search",
                "gx_m",
                s.gx_m[0],
                "a positive range (the tip ends inside the pile's side)",
            ));
        }
        if self.numerics.samples < 21 || self.numerics.samples > 100_000 {
            return Err(bad(
                "numerics",
                "samples",
                self.numerics.samples as f64,
                "between 21 and 100000",
            ));
        }
        // The derived geometry must close (the tip reaches the floor).
        self.geometry_derived().map_err(|why| {
            bad(
                "geometry",
                "toe_distance_m",
                g.toe_distance_m.unwrap_or(f64::NAN),
                &why,
            )
        })?;
        Ok(())
    }

    /// The derived quantities of the reading of Table 1 (module docs).
    pub fn geometry(&self) -> Geometry {
        self.geometry_derived()
            .expect("a checked profile has a consistent geometry")
    }

    fn geometry_derived(&self) -> std::result::Result<Geometry, String> {
        let g = &self.geometry;
        let delta2 = g.tip_angle_deg.to_radians();
        let l3 = g.saddle_to_tip_m * delta2.sin();
        let d20 = g.saddle_to_tip_m * delta2.cos();
        let h = g.saddle_height_m;
        let toe_distance = match g.toe_distance_m {
            Some(t) => t,
            None => {
                // H + l3 sin θ − d20 cos θ = 0 with the handle near the vertical:
                // l_OD sin(θ − atan2(d20, l3)) = −H.
                if h >= g.saddle_to_tip_m {
                    return Err(format!(
                        "a toe distance: with the handle retracted the tip cannot reach \
                         the floor (saddle height {h} m ≥ l_OD {} m), so give toe_distance_m",
                        g.saddle_to_tip_m
                    ));
                }
                let theta = d20.atan2(l3) - (h / g.saddle_to_tip_m).asin();
                l3 * theta.cos() + d20 * theta.sin()
            }
        };
        let boom = g.boom_angle_deg.to_radians();
        let (bc, bs) = (boom.cos(), boom.sin());
        let saddle = [-toe_distance, h];
        let sheave = [
            saddle[0] + g.saddle_to_sheave_m * bc,
            saddle[1] + g.saddle_to_sheave_m * bs,
        ];
        let boom_foot = [
            sheave[0] - g.boom_length_m * bc,
            sheave[1] - g.boom_length_m * bs,
        ];
        Ok(Geometry {
            l1: saddle[0],
            l2: saddle[1],
            l3,
            d20,
            bail_behind_tip: d20 - g.saddle_to_bail_m,
            sheave,
            sheave_radius: g.sheave_radius_m,
            boom_foot,
            sheave_top_height: sheave[1] + g.sheave_radius_m,
            dipper_pitch: g.dipper_pitch_deg.to_radians(),
            back_face_tilt: (g.dipper_pitch_deg + g.tip_angle_deg).to_radians(),
            handle_length: self.handle.length_m,
        })
    }
}

/// Quantities derived from Table 1 in the dig frame {Oo} (x from the toe into
/// the pile, y up; metres, radians).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, serde::Serialize)]
pub struct Geometry {
    /// l₁: x of the saddle centre O (negative: O is on the machine's side of the toe).
    pub l1: f64,
    /// l₂: y of O.
    pub l2: f64,
    /// l₃: tip offset normal to the handle axis.
    pub l3: f64,
    /// d₂₀: extension from O to the tip's foot on the handle axis, retracted.
    pub d20: f64,
    /// How far the bail pin C sits behind the tip's foot, along the axis.
    pub bail_behind_tip: f64,
    /// Boom point sheave centre B.
    pub sheave: [f64; 2],
    /// R1.
    pub sheave_radius: f64,
    /// Boom foot A.
    pub boom_foot: [f64; 2],
    /// H_tl of c18: top of the sheave.
    pub sheave_top_height: f64,
    /// δ1.
    pub dipper_pitch: f64,
    /// Tilt of the tooth back face from the handle normal, δ1 + δ2: δ1 is
    /// read from the tooth line OD, which is δ2 from the handle axis
    /// (docs/rope-shovel-dig.md, "Our reading of Table 1").
    pub back_face_tilt: f64,
    /// L_dg of c17: the handle length, greatest extension d = d₂ + d₂₀.
    pub handle_length: f64,
}

impl TomlFile for MachineProfile {
    type Error = DigError;

    fn check(&self, text: &str, file: &str) -> Result<()> {
        self.check_values(text, file)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The scale model without its toe distance: the toe where the retracted
    /// tip meets the floor.
    pub(crate) fn retracted_start() -> MachineProfile {
        let mut p = MachineProfile::scale_model();
        p.geometry.toe_distance_m = None;
        p
    }

    #[test]
    fn the_embedded_profile_gives_the_documented_derived_geometry() {
        assert_relative_eq!(MachineProfile::scale_model().geometry().l1, -0.0875);
        let g = retracted_start().geometry();
        assert_relative_eq!(g.l3, 0.2558 * 20.43f64.to_radians().sin(), epsilon = 1e-12);
        assert_relative_eq!(g.l3, 0.08929, epsilon = 1e-4);
        assert_relative_eq!(g.d20, 0.23974, epsilon = 1e-4);
        assert_relative_eq!(g.l2, 0.2473, epsilon = 1e-12);
        assert_relative_eq!(g.l1, -0.0655, epsilon = 5e-4);
        // Boom: foot to sheave is l_AB long at 45°.
        let (dx, dy) = (g.sheave[0] - g.boom_foot[0], g.sheave[1] - g.boom_foot[1]);
        assert_relative_eq!(dx.hypot(dy), 0.450, epsilon = 1e-12);
        assert_relative_eq!(dy.atan2(dx).to_degrees(), 45.0, epsilon = 1e-9);
    }

    fn with(replace: &str, by: &str) -> String {
        assert!(SCALE_MODEL_TOML.contains(replace), "{replace}");
        SCALE_MODEL_TOML.replacen(replace, by, 1)
    }

    #[test]
    fn missing_and_contradictory_limits_are_named_with_their_line() {
        let text = with("hoist_force_max_n = 400.0   # c11\n", "");
        let err = MachineProfile::from_toml(&text, "p.toml")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("p.toml") && err.contains("hoist_force_max_n"),
            "{err}"
        );

        let text = with("fill_min = 0.9 ", "fill_min = 1.2 ");
        let err = MachineProfile::from_toml(&text, "p.toml")
            .unwrap_err()
            .to_string();
        let line = text
            .lines()
            .position(|l| l.starts_with("fill_min"))
            .unwrap()
            + 1;
        assert!(err.contains(&format!("p.toml:{line}:")), "{err}");
        assert!(err.contains("fill_max"), "{err}");

        let text = with("crowd_power_max_w = 15.0", "crowd_power_max_w = -1");
        let err = MachineProfile::from_toml(&text, "p.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("[limits] crowd_power_max_w = -1"), "{err}");

        let text = with("td_s = [9.0, 15.0]", "td_s = [20.0, 30.0]");
        let err = MachineProfile::from_toml(&text, "p.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("td_s") && err.contains("dig-time"), "{err}");

        // Issue 11: a length no machine has is refused, printed short.
        let text = with("boom_length_m = 0.450", "boom_length_m = 1e308");
        let err = MachineProfile::from_toml(&text, "p.toml")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(
                "p.toml:10: [geometry] boom_length_m = 1e308 is invalid: expected a length"
            ),
            "{err}"
        );

        let text = with("[numerics]", "[numerics]\nbogus = 1");
        let err = MachineProfile::from_toml(&text, "p.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("bogus"), "{err}");
    }

    #[test]
    fn a_saddle_too_high_to_reach_the_floor_needs_a_toe_distance() {
        let text = with("saddle_height_m = 0.2473", "saddle_height_m = 0.3");
        let no_toe = text.replacen("toe_distance_m = 0.0875", "", 1);
        let err = MachineProfile::from_toml(&no_toe, "p.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("toe_distance_m"), "{err}");
        let p = MachineProfile::from_toml(&text, "p.toml").unwrap();
        assert_relative_eq!(p.geometry().l1, -0.0875);
    }

    #[test]
    fn the_profile_round_trips_through_toml() {
        let p = MachineProfile::scale_model();
        let back = MachineProfile::from_toml(&p.to_toml(), "x").unwrap();
        assert_eq!(p, back);
    }
}
