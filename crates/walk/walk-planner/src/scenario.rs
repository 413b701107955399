//! Travel scenarios: a site map, the machine's footprint, the start, an
//! optional V-shape midpoint and the goal, read from TOML.
//!
//! Validate once at the edge: [`Scenario::from_toml`] checks every number
//! (finite, in range), every polygon (convex) and names the file and line of
//! the table at fault; everything downstream trusts a [`Scenario`].
//!
//! The format (all lengths in metres, headings in degrees from +x,
//! counter-clockwise):
//! ```toml
//! name = "my-bench"
//! footprint_radius_m = 1.0      # at least the machine's half-width
//! direction = "forward"         # or "reverse"; ignored with a midpoint
//! [site]
//! min_m = [0.0, -10.0]
//! max_m = [60.0, 10.0]
//! [start]
//! x_m = 3.0
//! y_m = 0.0
//! heading_deg = 0.0
//! [goal]
//! x_m = 55.0
//! y_m = 0.0
//! heading_deg = 0.0
//! # [midpoint]  (a V-shape: reverse from start to here, then forward to the goal)
//! [[circle]]
//! name = "rock"
//! center_m = [20.0, 1.0]
//! radius_m = 1.5
//! [[polygon]]                   # convex, either winding
//! name = "truck"
//! vertices_m = [[30.0, -6.0], [36.0, -6.0], [36.0, -3.0], [30.0, -3.0]]
//! [[boundary]]                  # a road edge (polyline)
//! name = "left edge"
//! points_m = [[0.0, 8.0], [60.0, 8.0]]
//! ```

use std::path::Path as FsPath;

use autoshovel_core::config::{self, line_col, line_of_key, TomlFile};
use autoshovel_core::{rad, Pose2, Vec2};
use serde::{Deserialize, Serialize};
use toml::Spanned;

use crate::error::{PropelError, Result};
use crate::map::{convex_polygon, Boundary, Map, Obstacle, Shape};
use crate::path::Direction;

/// The built-in scenarios (name, TOML text).
pub const BUILTINS: &[(&str, &str)] = &[
    ("straight", include_str!("../scenarios/straight.toml")),
    (
        "straight-reverse",
        include_str!("../scenarios/straight-reverse.toml"),
    ),
    ("curve", include_str!("../scenarios/curve.toml")),
    (
        "curve-reverse",
        include_str!("../scenarios/curve-reverse.toml"),
    ),
    ("v-shape", include_str!("../scenarios/v-shape.toml")),
];

/// A validated travel scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Name for reports.
    pub name: String,
    /// The site.
    pub map: Map,
    /// Radius of the machine's footprint disc (m).
    pub footprint_radius_m: f64,
    /// Start pose (θ = machine heading).
    pub start: Pose2,
    /// V-shape midpoint: reverse to it, stop, then forward.
    pub midpoint: Option<Pose2>,
    /// Goal pose (θ = required machine heading on arrival).
    pub goal: Pose2,
    /// Direction of a single-leg move.
    pub direction: Direction,
}

impl Scenario {
    /// The legs (from, to, direction): one leg, or reverse-then-forward through the midpoint.
    pub fn legs(&self) -> Vec<(Pose2, Pose2, Direction)> {
        match self.midpoint {
            Some(m) => vec![
                (self.start, m, Direction::Reverse),
                (m, self.goal, Direction::Forward),
            ],
            None => vec![(self.start, self.goal, self.direction)],
        }
    }

    /// A built-in scenario by name.
    pub fn builtin(name: &str) -> Option<Scenario> {
        builtin_text(name).ok().map(|text| {
            Scenario::from_toml(text, &format!("<builtin {name}>"))
                .expect("built-in scenarios are valid")
        })
    }

    /// A built-in name, else a TOML file path.
    pub fn resolve(name_or_path: &str) -> Result<Scenario> {
        if let Some(s) = Scenario::builtin(name_or_path) {
            return Ok(s);
        }
        let path = FsPath::new(name_or_path);
        if path.exists() {
            return Scenario::load(path);
        }
        Err(PropelError::UnknownScenario {
            name: name_or_path.to_string(),
            known: builtin_names(),
        })
    }

    /// Reads a TOML scenario file.
    pub fn load(path: &FsPath) -> Result<Scenario> {
        let text = config::read(path).map_err(|source| PropelError::UnreadableScenario {
            path: path.to_path_buf(),
            source: Box::new(source),
        })?;
        Scenario::from_toml(&text, &path.display().to_string())
    }

    /// Parses and validates TOML text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Scenario> {
        let raw: ScenarioFile = config::parse(text, file)?;
        raw.to_scenario(text, file)
    }
}

/// The names of the built-in scenarios, in [`BUILTINS`] order.
pub fn builtin_names() -> Vec<&'static str> {
    BUILTINS.iter().map(|(n, _)| *n).collect()
}

/// The TOML text of a built-in scenario (with its comments), to print and
/// edit; an unknown name is [`PropelError::UnknownBuiltin`] listing the names.
pub fn builtin_text(name: &str) -> Result<&'static str> {
    BUILTINS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
        .ok_or_else(|| PropelError::UnknownBuiltin {
            name: name.to_string(),
            known: builtin_names(),
        })
}

/// A scenario file as written (the raw layer): deserialised with spans so
/// that [`ScenarioFile::to_scenario`] can name the line of a bad value.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    name: Option<String>,
    footprint_radius_m: Option<Spanned<f64>>,
    direction: Option<Direction>,
    site: Spanned<SiteSpec>,
    start: Spanned<PoseSpec>,
    goal: Spanned<PoseSpec>,
    midpoint: Option<Spanned<PoseSpec>>,
    #[serde(default)]
    circle: Vec<Spanned<CircleSpec>>,
    #[serde(default)]
    polygon: Vec<Spanned<PolygonSpec>>,
    #[serde(default)]
    boundary: Vec<Spanned<BoundarySpec>>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct SiteSpec {
    #[serde(deserialize_with = "config::xy")]
    min_m: [f64; 2],
    #[serde(deserialize_with = "config::xy")]
    max_m: [f64; 2],
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct PoseSpec {
    x_m: f64,
    y_m: f64,
    heading_deg: f64,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct CircleSpec {
    name: Option<String>,
    #[serde(deserialize_with = "config::xy")]
    center_m: [f64; 2],
    radius_m: f64,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct PolygonSpec {
    name: Option<String>,
    #[serde(deserialize_with = "config::xy_list")]
    vertices_m: Vec<[f64; 2]>,
}

#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct BoundarySpec {
    name: Option<String>,
    #[serde(deserialize_with = "config::xy_list")]
    points_m: Vec<[f64; 2]>,
}

/// Default footprint radius: the 1:7 prototype's half-width plus a margin (m).
pub const DEFAULT_FOOTPRINT_RADIUS_M: f64 = 1.0;

impl TomlFile for ScenarioFile {
    type Error = PropelError;

    fn check(&self, text: &str, file: &str) -> Result<()> {
        self.to_scenario(text, file).map(drop)
    }
}

/// Largest |coordinate| a site may have (m) (a planning site, not a globe).
const MAX_COORDINATE_M: f64 = 1e6;
/// Largest side of a site (m).
const MAX_SITE_EXTENT_M: f64 = 10_000.0;
/// Most vertices of a polygon obstacle.
const MAX_POLYGON_VERTICES: usize = 1000;

impl ScenarioFile {
    /// Checks every number (finite, in range) and polygon (convex) and
    /// builds the scenario; `text` and `file` locate a bad value.
    pub fn to_scenario(&self, text: &str, file: &str) -> Result<Scenario> {
        // The line a span starts on (a table's header, a top-level value).
        let line_at = |span: std::ops::Range<usize>| line_col(text, span.start).0;
        // Every number finite and within ±1000 km; `table` and `occurrence`
        // locate the key, `item` names the element in the message.
        let finite = |(table, occurrence): (&str, usize),
                      item: &str,
                      vals: &[(&'static str, f64)]|
         -> Result<()> {
            match vals
                .iter()
                .find(|(_, v)| !v.is_finite() || v.abs() > MAX_COORDINATE_M)
            {
                Some(&(key, value)) => {
                    let line = line_of_key(text, table, occurrence, key);
                    let (file, key) = (file.to_string(), format!("{item}: {key}"));
                    Err(if value.is_finite() {
                        PropelError::BeyondSite {
                            file,
                            line,
                            key,
                            value,
                        }
                    } else {
                        PropelError::NonFinite {
                            file,
                            line,
                            key,
                            value,
                        }
                    })
                }
                None => Ok(()),
            }
        };
        let r_fp = match &self.footprint_radius_m {
            Some(s) => {
                let v = *s.get_ref();
                if !(v.is_finite() && v > 0.0 && v < 1e3) {
                    return Err(PropelError::OutOfRange {
                        file: file.to_string(),
                        line: line_at(s.span()),
                        key: "footprint_radius_m".into(),
                        value: v,
                        expected: "a positive number below 1000",
                    });
                }
                v
            }
            None => DEFAULT_FOOTPRINT_RADIUS_M,
        };
        let site = self.site.get_ref();
        finite(
            ("site", 0),
            "[site]",
            &[
                ("min_m", site.min_m[0]),
                ("min_m", site.min_m[1]),
                ("max_m", site.max_m[0]),
                ("max_m", site.max_m[1]),
            ],
        )?;
        if !(site.max_m[0] > site.min_m[0] && site.max_m[1] > site.min_m[1]) {
            return Err(PropelError::SiteInverted {
                file: file.to_string(),
                line: line_at(self.site.span()),
                min_m: site.min_m,
                max_m: site.max_m,
            });
        }
        let extent = (site.max_m[0] - site.min_m[0]).max(site.max_m[1] - site.min_m[1]);
        if extent > MAX_SITE_EXTENT_M {
            return Err(PropelError::SiteTooLarge {
                file: file.to_string(),
                line: line_at(self.site.span()),
                extent_m: extent,
                limit_m: MAX_SITE_EXTENT_M,
            });
        }
        let mut map = Map::new(
            Vec2::new(site.min_m[0], site.min_m[1]),
            Vec2::new(site.max_m[0], site.max_m[1]),
        );
        let pose = |s: &Spanned<PoseSpec>, which: &str| -> Result<Pose2> {
            let p = s.get_ref();
            finite(
                (which, 0),
                &format!("[{which}]"),
                &[
                    ("x_m", p.x_m),
                    ("y_m", p.y_m),
                    ("heading_deg", p.heading_deg),
                ],
            )?;
            Ok(Pose2::new(p.x_m, p.y_m, rad(p.heading_deg)))
        };
        let start = pose(&self.start, "start")?;
        let goal = pose(&self.goal, "goal")?;
        let midpoint = match &self.midpoint {
            Some(m) => Some(pose(m, "midpoint")?),
            None => None,
        };
        for (i, c) in self.circle.iter().enumerate() {
            let spec = c.get_ref();
            let item = format!(
                "circle #{} '{}'",
                i + 1,
                spec.name.as_deref().unwrap_or("circle")
            );
            finite(
                ("circle", i),
                &item,
                &[
                    ("center_m", spec.center_m[0]),
                    ("center_m", spec.center_m[1]),
                    ("radius_m", spec.radius_m),
                ],
            )?;
            if spec.radius_m <= 0.0 {
                return Err(PropelError::OutOfRange {
                    file: file.to_string(),
                    line: line_of_key(text, "circle", i, "radius_m"),
                    key: format!("{item}: radius_m"),
                    value: spec.radius_m,
                    expected: "positive",
                });
            }
            map.obstacles.push(Obstacle {
                name: spec
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("circle {}", i + 1)),
                shape: Shape::Circle {
                    center: Vec2::new(spec.center_m[0], spec.center_m[1]),
                    radius: spec.radius_m,
                },
            });
        }
        for (i, p) in self.polygon.iter().enumerate() {
            let spec = p.get_ref();
            let item = format!(
                "polygon #{} '{}'",
                i + 1,
                spec.name.as_deref().unwrap_or("polygon")
            );
            let flat: Vec<(&str, f64)> = spec
                .vertices_m
                .iter()
                .flatten()
                .map(|v| ("vertices_m", *v))
                .collect();
            finite(("polygon", i), &item, &flat)?;
            if spec.vertices_m.len() > MAX_POLYGON_VERTICES {
                return Err(PropelError::PointCount {
                    file: file.to_string(),
                    line: line_at(p.span()),
                    item,
                    count: spec.vertices_m.len(),
                    what: "vertices",
                    limit: "at most 1000",
                });
            }
            let verts = spec
                .vertices_m
                .iter()
                .map(|v| Vec2::new(v[0], v[1]))
                .collect();
            let verts = match convex_polygon(verts) {
                Ok(v) => v,
                Err(fault) => {
                    return Err(PropelError::BadPolygon {
                        file: file.to_string(),
                        line: line_at(p.span()),
                        item,
                        fault,
                    })
                }
            };
            map.obstacles.push(Obstacle {
                name: spec
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("polygon {}", i + 1)),
                shape: Shape::Polygon { vertices: verts },
            });
        }
        for (i, b) in self.boundary.iter().enumerate() {
            let spec = b.get_ref();
            let item = format!(
                "boundary #{} '{}'",
                i + 1,
                spec.name.as_deref().unwrap_or("boundary")
            );
            let flat: Vec<(&str, f64)> = spec
                .points_m
                .iter()
                .flatten()
                .map(|v| ("points_m", *v))
                .collect();
            finite(("boundary", i), &item, &flat)?;
            if spec.points_m.len() < 2 {
                return Err(PropelError::PointCount {
                    file: file.to_string(),
                    line: line_at(b.span()),
                    item,
                    count: spec.points_m.len(),
                    what: "points",
                    limit: "needs at least 2",
                });
            }
            map.boundaries.push(Boundary {
                name: spec
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("boundary {}", i + 1)),
                points: spec
                    .points_m
                    .iter()
                    .map(|v| Vec2::new(v[0], v[1]))
                    .collect(),
            });
        }
        Ok(Scenario {
            name: self.name.clone().unwrap_or_else(|| file.to_string()),
            map,
            footprint_radius_m: r_fp,
            start,
            midpoint,
            goal,
            direction: self.direction.unwrap_or(Direction::Forward),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_parses() {
        for (name, _) in BUILTINS {
            let s = Scenario::builtin(name).unwrap();
            assert!(
                !s.map.obstacles.is_empty() || name.starts_with("straight"),
                "{name}"
            );
        }
    }

    fn base() -> String {
        "[site]\nmin_m = [0.0, 0.0]\nmax_m = [50.0, 20.0]\n[start]\nx_m = 2.0\ny_m = 10.0\nheading_deg = 0.0\n[goal]\nx_m = 45.0\ny_m = 10.0\nheading_deg = 0.0\n".to_string()
    }

    #[test]
    fn a_minimal_file_parses_with_defaults() {
        let s = Scenario::from_toml(&base(), "t.toml").unwrap();
        assert_eq!(s.direction, Direction::Forward);
        assert_eq!(s.footprint_radius_m, DEFAULT_FOOTPRINT_RADIUS_M);
        assert_eq!(s.legs().len(), 1);
    }

    #[test]
    fn malformed_toml_names_file_and_line() {
        let text = base() + "[[circle]]\ncenter_m = [1.0, 2.0\n";
        let e = Scenario::from_toml(&text, "bad.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("bad.toml:14:"), "{e}");
    }

    #[test]
    fn nan_and_non_convex_polygons_are_refused_with_their_line() {
        let text = base() + "[[circle]]\nname = \"rock\"\ncenter_m = [nan, 2.0]\nradius_m = 1.0\n";
        let e = Scenario::from_toml(&text, "n.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("n.toml:14") && e.contains("rock") && e.contains("NaN"),
            "{e}"
        );
        let text = base() + "\n[[polygon]]\nname = \"dart\"\nvertices_m = [[0.0, 0.0], [2.0, 1.0], [4.0, 0.0], [2.0, 3.0]]\n";
        let e = Scenario::from_toml(&text, "p.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("p.toml:13") && e.contains("not convex"), "{e}");
    }

    #[test]
    fn unknown_fields_and_names_are_refused() {
        let text = base() + "speed = 3\n";
        assert!(Scenario::from_toml(&text, "u.toml")
            .unwrap_err()
            .to_string()
            .contains("speed"));
        let e = Scenario::resolve("no-such-scenario")
            .unwrap_err()
            .to_string();
        assert!(e.contains("curve") && e.contains("no-such-scenario"), "{e}");
    }

    proptest::proptest! {
        // Untrusted input: any text, and any byte-level damage to a valid
        // file, gives a scenario or an error, never a panic.
        #[test]
        fn arbitrary_text_never_panics(text in ".{0,400}") {
            let _ = Scenario::from_toml(&text, "fuzz.toml");
        }

        #[test]
        fn damaged_builtins_never_panic(which in 0usize..5, pos in 0usize..2000, byte in 0u8..128, cut in proptest::bool::ANY) {
            let text = BUILTINS[which % BUILTINS.len()].1;
            let mut bytes = text.as_bytes().to_vec();
            let pos = pos % bytes.len();
            if cut { bytes.truncate(pos) } else { bytes[pos] = byte }
            if let Ok(t) = String::from_utf8(bytes) {
                if let Ok(s) = Scenario::from_toml(&t, "fuzz.toml") {
                    // Whatever parses plans or fails cleanly.
                    let _ = crate::plan_path(&s, &crate::PlanOptions::new(crate::FieldKind::Improved));
                }
            }
        }
    }
}
