//! The machine profile: link lengths, bucket, joint and speed limits, the
//! attitude range, masses and the digging-force rating of the backhoe — one
//! TOML file the user can replace.
//!
//! The default (`profiles/excavator-15t.toml`, embedded) is the 15 t class
//! machine of SPEC §5: boom 4.6 m, stick 2.5 m, bucket tip radius 1.2 m, boom
//! foot 1.7 m above the ground; bucket 0.6 m³ with opening h_b = 1 m (the
//! paper's JGM 915). Every key is required: a missing limit is an error, never
//! a silent default. Values are checked once here; errors name the file, the
//! line and the key. Angles are in degrees in the file and radians inside.

use serde::{Deserialize, Serialize};

use autoshovel_core::config::{self, ConfigError, TomlFile};

/// Name of the embedded default profile.
pub const EXCAVATOR_15T: &str = "excavator-15t";

/// The embedded default profile (15 t class backhoe).
pub const EXCAVATOR_15T_TOML: &str = include_str!("../profiles/excavator-15t.toml");

/// Link lengths and placement of the boom foot in the dig frame (SPEC §1: x
/// horizontal away from the machine from the slew axis, y up from the ground).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GeometrySpec {
    /// a₁: boom foot pin to stick pin (m).
    pub boom_length_m: f64,
    /// a₂: stick pin to bucket pin (m).
    pub stick_length_m: f64,
    /// a₃: bucket pin to tooth tip (m).
    pub bucket_tip_radius_m: f64,
    /// Horizontal distance of the boom foot pin ahead of the slew axis (m).
    pub boom_foot_x_m: f64,
    /// Height of the boom foot pin above the ground (m).
    pub boom_foot_height_m: f64,
}

/// The bucket.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BucketSpec {
    /// Heaped capacity (m³).
    pub capacity_m3: f64,
    /// h_b: opening width across the dig plane ([HE eq. 2]) (m).
    pub width_m: f64,
}

/// Joint ranges of the D-H joint angles (deg) (see [`crate::kinematics`]).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct JointLimitsSpec {
    /// θ₁ (boom from the horizontal), lower (deg).
    pub boom_min_deg: f64,
    /// θ₁ upper (deg).
    pub boom_max_deg: f64,
    /// θ₂ (stick relative to the boom), lower (deg).
    pub stick_min_deg: f64,
    /// θ₂ upper (deg).
    pub stick_max_deg: f64,
    /// θ₃ (bucket link relative to the stick), lower (deg).
    pub bucket_min_deg: f64,
    /// θ₃ upper (deg).
    pub bucket_max_deg: f64,
    /// Digging attitude angle φ = θ₁ + θ₂ + θ₃, lower (deg).
    pub attitude_min_deg: f64,
    /// φ upper (deg).
    pub attitude_max_deg: f64,
}

/// Joint speed limits (deg/s).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedLimitsSpec {
    /// |θ̇₁| (deg/s).
    pub boom_deg_s: f64,
    /// |θ̇₂| (deg/s).
    pub stick_deg_s: f64,
    /// |θ̇₃| (deg/s).
    pub bucket_deg_s: f64,
}

/// Mass properties of the three links (for the Lagrange dynamics).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MassesSpec {
    /// Boom mass (kg).
    pub boom_kg: f64,
    /// Boom centroid, from the boom foot along the link (m).
    pub boom_centroid_m: f64,
    /// Boom moment of inertia about its centroid (kg·m²).
    pub boom_inertia_kg_m2: f64,
    /// Stick mass (kg).
    pub stick_kg: f64,
    /// Stick centroid, from the stick pin along the link (m).
    pub stick_centroid_m: f64,
    /// Stick moment of inertia about its centroid (kg·m²).
    pub stick_inertia_kg_m2: f64,
    /// Empty bucket mass (kg).
    pub bucket_kg: f64,
    /// Bucket (and load) centroid, from the bucket pin along the link (m).
    pub bucket_centroid_m: f64,
    /// Empty bucket moment of inertia about its centroid (kg·m²).
    pub bucket_inertia_kg_m2: f64,
}

/// Force rating.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ForceSpec {
    /// Greatest digging force at the tooth tip (N). Soil resisting more is an
    /// error (SPEC §5, out of scope); a boulder stalls the bucket at this force.
    pub max_digging_force_n: f64,
}

/// A whole machine profile, as read from TOML and checked.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MachineProfile {
    /// Links and placement.
    pub geometry: GeometrySpec,
    /// Bucket.
    pub bucket: BucketSpec,
    /// Joint and attitude ranges.
    pub joint_limits: JointLimitsSpec,
    /// Joint speed limits.
    pub speed_limits: SpeedLimitsSpec,
    /// Masses.
    pub masses: MassesSpec,
    /// Force rating.
    pub force: ForceSpec,
}

impl Default for MachineProfile {
    /// The 15 t class machine of SPEC §5.
    fn default() -> Self {
        Self::excavator_15t()
    }
}

impl MachineProfile {
    /// The 15 t class machine (the embedded `excavator-15t.toml`).
    pub fn excavator_15t() -> Self {
        Self::from_toml(EXCAVATOR_15T_TOML, &format!("<builtin {EXCAVATOR_15T}>"))
            .expect("the embedded profile is valid")
    }

    /// Check every value; `text` and `file` locate errors.
    fn check_values(&self, text: &str, file: &str) -> Result<(), ConfigError> {
        let bad = |table: &str, key: &str, value: f64, expected: &str| {
            config::invalid(text, file, (table, 0), key, value, expected)
        };
        let g = &self.geometry;
        let m = &self.masses;
        let positive = [
            ("geometry", "boom_length_m", g.boom_length_m),
            ("geometry", "stick_length_m", g.stick_length_m),
            ("geometry", "bucket_tip_radius_m", g.bucket_tip_radius_m),
            ("geometry", "boom_foot_height_m", g.boom_foot_height_m),
            ("bucket", "capacity_m3", self.bucket.capacity_m3),
            ("bucket", "width_m", self.bucket.width_m),
            ("speed_limits", "boom_deg_s", self.speed_limits.boom_deg_s),
            ("speed_limits", "stick_deg_s", self.speed_limits.stick_deg_s),
            (
                "speed_limits",
                "bucket_deg_s",
                self.speed_limits.bucket_deg_s,
            ),
            ("masses", "boom_kg", m.boom_kg),
            ("masses", "stick_kg", m.stick_kg),
            ("masses", "bucket_kg", m.bucket_kg),
            (
                "force",
                "max_digging_force_n",
                self.force.max_digging_force_n,
            ),
        ];
        config::check_each(text, file, &positive, config::POSITIVE)?;
        let non_negative = [
            ("masses", "boom_inertia_kg_m2", m.boom_inertia_kg_m2),
            ("masses", "stick_inertia_kg_m2", m.stick_inertia_kg_m2),
            ("masses", "bucket_inertia_kg_m2", m.bucket_inertia_kg_m2),
        ];
        config::check_each(text, file, &non_negative, config::NON_NEGATIVE)?;
        if !g.boom_foot_x_m.is_finite() {
            return Err(bad(
                "geometry",
                "boom_foot_x_m",
                g.boom_foot_x_m,
                "a finite value",
            ));
        }
        let centroids = [
            ("boom_centroid_m", m.boom_centroid_m, g.boom_length_m),
            ("stick_centroid_m", m.stick_centroid_m, g.stick_length_m),
            (
                "bucket_centroid_m",
                m.bucket_centroid_m,
                g.bucket_tip_radius_m,
            ),
        ];
        for (key, v, len) in centroids {
            if !(v.is_finite() && (0.0..=len).contains(&v)) {
                return Err(bad(
                    "masses",
                    key,
                    v,
                    &format!("a distance along the link in [0, {len}] m"),
                ));
            }
        }
        let l = &self.joint_limits;
        let ranges = [
            (
                "boom_min_deg",
                l.boom_min_deg,
                "boom_max_deg",
                l.boom_max_deg,
                90.0,
            ),
            (
                "stick_min_deg",
                l.stick_min_deg,
                "stick_max_deg",
                l.stick_max_deg,
                180.0,
            ),
            (
                "bucket_min_deg",
                l.bucket_min_deg,
                "bucket_max_deg",
                l.bucket_max_deg,
                180.0,
            ),
            (
                "attitude_min_deg",
                l.attitude_min_deg,
                "attitude_max_deg",
                l.attitude_max_deg,
                360.0,
            ),
        ];
        for (lo_key, lo, hi_key, hi, bound) in ranges {
            if !(hi.is_finite() && hi.abs() <= bound) {
                return Err(bad(
                    "joint_limits",
                    hi_key,
                    hi,
                    &format!("a finite angle within ±{bound}°"),
                ));
            }
            if !(lo.is_finite() && lo.abs() <= bound && lo < hi) {
                return Err(bad(
                    "joint_limits",
                    lo_key,
                    lo,
                    &format!("an angle within ±{bound}° below {hi_key} = {hi}"),
                ));
            }
        }
        // The inverse kinematics takes the stick-folding branch θ₂ < 0 (module
        // docs of `kinematics`): the stick range must lie on that side.
        if l.stick_max_deg >= 0.0 {
            return Err(bad(
                "joint_limits",
                "stick_max_deg",
                l.stick_max_deg,
                "a negative angle (the stick folds below the boom: θ₂ < 0)",
            ));
        }
        Ok(())
    }
}

impl TomlFile for MachineProfile {
    type Error = ConfigError;

    fn check(&self, text: &str, file: &str) -> Result<(), ConfigError> {
        self.check_values(text, file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(replace: &str, by: &str) -> String {
        assert!(EXCAVATOR_15T_TOML.contains(replace), "{replace}");
        EXCAVATOR_15T_TOML.replacen(replace, by, 1)
    }

    fn line_of(text: &str, start: &str) -> usize {
        text.lines().position(|l| l.starts_with(start)).unwrap() + 1
    }

    #[test]
    fn the_embedded_profile_is_spec_section_5() {
        let p = MachineProfile::excavator_15t();
        assert_eq!(p.geometry.boom_length_m, 4.6);
        assert_eq!(p.geometry.stick_length_m, 2.5);
        assert_eq!(p.geometry.bucket_tip_radius_m, 1.2);
        assert_eq!(p.geometry.boom_foot_height_m, 1.7);
        assert_eq!(p.bucket.capacity_m3, 0.6);
        assert_eq!(p.bucket.width_m, 1.0);
    }

    #[test]
    fn a_missing_key_is_named_with_the_file() {
        let text = with("stick_kg = ", "# stick_kg = ");
        let err = MachineProfile::from_toml(&text, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("m.toml:") && err.contains("stick_kg"),
            "{err}"
        );
    }

    #[test]
    fn bad_values_are_named_with_file_line_and_key() {
        let text = with("boom_length_m = 4.6", "boom_length_m = -4.6");
        let err = MachineProfile::from_toml(&text, "m.toml")
            .unwrap_err()
            .to_string();
        let line = line_of(&text, "boom_length_m");
        assert!(err.contains(&format!("m.toml:{line}:")), "{err}");
        assert!(err.contains("[geometry] boom_length_m = -4.6"), "{err}");

        let text = with("stick_min_deg = ", "stick_min_deg = 10.0 #");
        let err = MachineProfile::from_toml(&text, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("stick_min_deg") && err.contains("stick_max_deg"),
            "{err}"
        );

        let text = with("bucket_centroid_m = ", "bucket_centroid_m = 2.0 #");
        let err = MachineProfile::from_toml(&text, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("bucket_centroid_m = 2"), "{err}");

        let text = with("[force]", "[force]\nbogus = 1");
        let err = MachineProfile::from_toml(&text, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("bogus"), "{err}");
    }

    #[test]
    fn the_profile_round_trips_through_toml() {
        let p = MachineProfile::excavator_15t();
        let back = MachineProfile::from_toml(&p.to_toml(), "x").unwrap();
        assert_eq!(p, back);
    }
}
