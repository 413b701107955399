//! A shift scenario: the world (a pit floor, a muck pile along a bench,
//! boulders and stockpiles), the machine at full size, the trucks and the
//! shift's length — one TOML file (`scenarios/bench.toml` is the built-in,
//! with every key commented).

use serde::{Deserialize, Serialize};

use autoshovel_core::config::{self, check_each, invalid, TomlFile, NON_NEGATIVE, POSITIVE};
use autoshovel_terrain::PileShape;

use crate::error::{Result, ShiftError};

/// Most cells of the pit's height grid (two grids of 80 MB: the pit and
/// the machine's model; a 1.5 km square pit at 0.5 m).
pub const MAX_CELLS: f64 = 1e7;

/// Highest pile, heap or vehicle (m).
pub const MAX_HEIGHT_M: f64 = 1000.0;

/// The built-in scenario's text.
pub const BENCH_TOML: &str = include_str!("../scenarios/bench.toml");

/// The names of the built-in scenarios.
pub const BUILTINS: &[(&str, &str)] = &[("bench", BENCH_TOML)];

/// The world's extent and resolution.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Lower-left corner (x, y) (m).
    #[serde(deserialize_with = "config::xy")]
    pub min_m: [f64; 2],
    /// Upper-right corner (m).
    #[serde(deserialize_with = "config::xy")]
    pub max_m: [f64; 2],
    /// Edge of a cell of the height grid (m).
    pub cell_m: f64,
}

/// The muck pile: a face along y with its toe at x = `toe_x_m`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PileSpec {
    /// The face's profile (the generator's shapes, Fig. 7).
    pub shape: PileShape,
    /// x of the toe line (m).
    pub toe_x_m: f64,
    /// The face runs along y between these (m).
    #[serde(deserialize_with = "config::xy")]
    pub y_m: [f64; 2],
    /// Toe to crest (m).
    pub face_height_m: f64,
    /// Mean slope of the face and of the sides (deg).
    pub repose_deg: f64,
    /// Flat top behind the crest (m).
    pub top_depth_m: f64,
}

/// A heap on the floor: a boulder or a stockpile (a flat-topped cone).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeapSpec {
    /// Centre (x, y) (m).
    #[serde(deserialize_with = "config::xy")]
    pub center_m: [f64; 2],
    /// Radius at the floor (m).
    pub radius_m: f64,
    /// Height (m).
    pub height_m: f64,
}

/// A parked vehicle (a haul truck waiting, a water truck, a dozer): a box
/// on the floor, in the pit's height grid, so scans see it and walks go
/// round it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParkedSpec {
    /// Centre (x, y) (m).
    #[serde(deserialize_with = "config::xy")]
    pub center_m: [f64; 2],
    /// Length and width (m).
    #[serde(deserialize_with = "config::xy")]
    pub size_m: [f64; 2],
    /// Heading of its length (deg from +x).
    pub heading_deg: f64,
    /// Height (m).
    pub height_m: f64,
}

/// The machine at full size.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineSpec {
    /// The swing axis at the start, on the floor (x, y) (m).
    #[serde(deserialize_with = "config::xy")]
    pub start_m: [f64; 2],
    /// Heading at the start [deg from +x, counter-clockwise].
    pub heading_deg: f64,
    /// λ: the dig planner's 1:30 model is scaled this many times
    /// ([`autoshovel_rope_shovel_dig::Similarity`]).
    pub lambda: f64,
    /// The saddle block O ahead of the swing axis (m).
    pub saddle_ahead_m: f64,
    /// Radius of the crawlers' footprint disc, for walking (m).
    pub footprint_radius_m: f64,
    /// The LiDAR's height above the floor, on the swing axis (m).
    pub sensor_height_m: f64,
    /// Largest swing speed (deg/s).
    pub swing_speed_deg_s: f64,
    /// Swing acceleration and braking (deg/s²).
    pub swing_accel_deg_s2: f64,
    /// Inertia of the upper works and boom about the swing axis (kg·m²).
    pub upper_inertia_kg_m2: f64,
    /// Radius at which the load swings (m).
    pub dipper_radius_m: f64,
    /// Dumping: the door opens and the load falls (s).
    pub dump_s: f64,
    /// Mass of the whole machine (t).
    pub mass_t: f64,
    /// Propel force over weight on the pit floor.
    pub rolling_resistance: f64,
    /// Walking speed (m/s).
    pub walk_speed_mps: f64,
}

/// The trucks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruckSpec {
    /// Swing angle at which a truck stands, from the machine's heading (deg).
    pub swing_deg: f64,
    /// Payload (t).
    pub capacity_t: f64,
    /// A full truck leaves and the next is spotted in this time (s).
    pub exchange_s: f64,
}

/// The shift.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShiftSpec {
    /// Length of the shift (h).
    pub hours: f64,
    /// Seed of every random process of the run.
    pub seed: u64,
    /// Points of each scan.
    pub scan_points: usize,
    /// Swing angles at which the machine may dig from a stand (deg).
    pub dig_angles_deg: Vec<f64>,
    /// A new stand along the face is this far to the side (m).
    pub lateral_step_m: f64,
}

/// A whole shift scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShiftScenario {
    /// Name for reports.
    pub name: String,
    /// The world's extent.
    pub world: WorldSpec,
    /// The muck pile.
    pub pile: PileSpec,
    /// Boulders on the floor.
    #[serde(default)]
    pub boulder: Vec<HeapSpec>,
    /// Stockpiles on the floor.
    #[serde(default)]
    pub stockpile: Vec<HeapSpec>,
    /// Parked vehicles.
    #[serde(default)]
    pub parked: Vec<ParkedSpec>,
    /// The machine.
    pub machine: MachineSpec,
    /// The trucks.
    pub truck: TruckSpec,
    /// The shift.
    pub shift: ShiftSpec,
}

impl ShiftScenario {
    /// A built-in scenario by name, else a TOML file.
    pub fn resolve(name_or_path: &str) -> Result<Self> {
        if let Some((name, text)) = BUILTINS.iter().find(|(n, _)| *n == name_or_path) {
            return Self::from_toml(text, &format!("<builtin {name}>"));
        }
        let path = std::path::Path::new(name_or_path);
        if !path.exists() {
            return Err(ShiftError::UnknownScenario {
                name: name_or_path.to_string(),
                known: BUILTINS
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        Self::load(path)
    }

    /// The built-in bench.
    pub fn bench() -> Self {
        Self::from_toml(BENCH_TOML, "<builtin bench>").expect("the built-in scenario is valid")
    }
}

impl TomlFile for ShiftScenario {
    type Error = ShiftError;

    fn check(&self, text: &str, file: &str) -> Result<()> {
        let (w, p, m, t, s) = (
            &self.world,
            &self.pile,
            &self.machine,
            &self.truck,
            &self.shift,
        );
        check_each(
            text,
            file,
            &[
                ("world", "cell_m", w.cell_m),
                ("pile", "face_height_m", p.face_height_m),
                ("pile", "repose_deg", p.repose_deg),
                ("machine", "lambda", m.lambda),
                ("machine", "saddle_ahead_m", m.saddle_ahead_m),
                ("machine", "footprint_radius_m", m.footprint_radius_m),
                ("machine", "sensor_height_m", m.sensor_height_m),
                ("machine", "swing_speed_deg_s", m.swing_speed_deg_s),
                ("machine", "swing_accel_deg_s2", m.swing_accel_deg_s2),
                ("machine", "upper_inertia_kg_m2", m.upper_inertia_kg_m2),
                ("machine", "dipper_radius_m", m.dipper_radius_m),
                ("machine", "mass_t", m.mass_t),
                ("machine", "walk_speed_mps", m.walk_speed_mps),
                ("truck", "capacity_t", t.capacity_t),
                ("shift", "hours", s.hours),
                ("shift", "lateral_step_m", s.lateral_step_m),
            ],
            POSITIVE,
        )?;
        check_each(
            text,
            file,
            &[
                ("pile", "top_depth_m", p.top_depth_m),
                ("machine", "dump_s", m.dump_s),
                ("machine", "rolling_resistance", m.rolling_resistance),
                ("truck", "exchange_s", t.exchange_s),
            ],
            NON_NEGATIVE,
        )?;
        let bad = |table: &str, key: &str, value: String, expected: &str| {
            ShiftError::from(invalid(text, file, (table, 0), key, value, expected))
        };
        for a in 0..2 {
            if !(w.min_m[a].is_finite() && w.max_m[a].is_finite() && w.max_m[a] > w.min_m[a]) {
                return Err(bad(
                    "world",
                    "max_m",
                    format!("{:?}", w.max_m),
                    "finite and above min_m on both axes",
                ));
            }
        }
        let cells = ((w.max_m[0] - w.min_m[0]) / w.cell_m) * ((w.max_m[1] - w.min_m[1]) / w.cell_m);
        if cells > MAX_CELLS {
            return Err(bad(
                "world",
                "cell_m",
                config::short(w.cell_m),
                &format!(
                    "a cell coarse enough for at most {} cells over the world ({} asked)",
                    config::approx(MAX_CELLS),
                    config::approx(cells)
                ),
            ));
        }
        if m.lambda > 1000.0 {
            return Err(bad(
                "machine",
                "lambda",
                config::short(m.lambda),
                "at most 1000 (the 1:30 model at 30 is a full-size shovel)",
            ));
        }
        if p.face_height_m > MAX_HEIGHT_M {
            return Err(bad(
                "pile",
                "face_height_m",
                config::short(p.face_height_m),
                "at most 1000 m",
            ));
        }
        if p.repose_deg >= 80.0 {
            return Err(bad(
                "pile",
                "repose_deg",
                config::short(p.repose_deg),
                "below 80°",
            ));
        }
        if !p.y_m.iter().all(|v| v.is_finite()) || p.y_m[1] <= p.y_m[0] {
            return Err(bad(
                "pile",
                "y_m",
                format!("{:?}", p.y_m),
                "[south end, north end]",
            ));
        }
        let inside = |x: f64, y: f64| {
            (w.min_m[0]..=w.max_m[0]).contains(&x) && (w.min_m[1]..=w.max_m[1]).contains(&y)
        };
        if !inside(p.toe_x_m, p.y_m[0]) || !inside(p.toe_x_m, p.y_m[1]) {
            return Err(bad(
                "pile",
                "toe_x_m",
                config::short(p.toe_x_m),
                "inside the world",
            ));
        }
        if !inside(m.start_m[0], m.start_m[1]) {
            return Err(bad(
                "machine",
                "start_m",
                format!("{:?}", m.start_m),
                "inside the world",
            ));
        }
        for (table, heaps) in [("boulder", &self.boulder), ("stockpile", &self.stockpile)] {
            for (i, h) in heaps.iter().enumerate() {
                let ok = h.radius_m.is_finite()
                    && h.radius_m > 0.0
                    && h.height_m.is_finite()
                    && h.height_m > 0.0
                    && h.height_m <= MAX_HEIGHT_M
                    && inside(h.center_m[0], h.center_m[1]);
                if !ok {
                    return Err(ShiftError::from(invalid(
                        text,
                        file,
                        (table, i),
                        "radius_m",
                        format!("{:?} / {:?}", h.radius_m, h.height_m),
                        "a heap inside the world with radius > 0 and height in (0, 1000] m",
                    )));
                }
            }
        }
        for (i, v) in self.parked.iter().enumerate() {
            let ok = v.size_m.iter().all(|d| d.is_finite() && *d > 0.0)
                && v.height_m.is_finite()
                && v.height_m > 0.0
                && v.height_m <= MAX_HEIGHT_M
                && v.heading_deg.is_finite()
                && inside(v.center_m[0], v.center_m[1]);
            if !ok {
                return Err(ShiftError::from(invalid(
                    text,
                    file,
                    ("parked", i),
                    "size_m",
                    format!("{:?}, height {:?}", v.size_m, v.height_m),
                    "a box inside the world with length and width > 0 and height in (0, 1000] m",
                )));
            }
        }
        if s.scan_points < 1000 || s.scan_points > 2_000_000 {
            return Err(bad(
                "shift",
                "scan_points",
                s.scan_points.to_string(),
                "1000 to 2 000 000",
            ));
        }
        if s.dig_angles_deg.is_empty()
            || s.dig_angles_deg
                .iter()
                .any(|a| !(a.is_finite() && a.abs() <= 90.0))
        {
            return Err(bad(
                "shift",
                "dig_angles_deg",
                format!("{:?}", s.dig_angles_deg),
                "one or more angles within ±90°",
            ));
        }
        if !(m.heading_deg.is_finite() && t.swing_deg.is_finite() && t.swing_deg.abs() <= 180.0) {
            return Err(bad(
                "truck",
                "swing_deg",
                config::short(t.swing_deg),
                "within ±180°",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_loads_and_bad_values_name_their_line() {
        let s = ShiftScenario::bench();
        assert_eq!(s.name, "bench");
        assert_eq!(s.boulder.len(), 2);
        let text = BENCH_TOML.replace("face_height_m = 4.5", "face_height_m = -1.0");
        let e = ShiftScenario::from_toml(&text, "f.toml")
            .unwrap_err()
            .to_string();
        let line = BENCH_TOML
            .lines()
            .position(|l| l.starts_with("face_height_m"))
            .unwrap()
            + 1;
        assert!(e.contains(&format!("f.toml:{line}")), "{e}");
        assert!(e.contains("face_height_m"), "{e}");
        let text = BENCH_TOML.replace("scan_points = 30000", "scan_points = 3");
        assert!(ShiftScenario::from_toml(&text, "f.toml").is_err());
        // A round trip through TOML keeps every value.
        assert_eq!(ShiftScenario::from_toml(&s.to_toml(), "again").unwrap(), s);
    }
}
