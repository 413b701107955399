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

use autoshovel_core::config::line_col;
use autoshovel_core::{rad, Pose2, Vec2};
use serde::Deserialize;
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
    /// Radius of the machine's footprint disc [m].
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
        BUILTINS.iter().find(|(n, _)| *n == name).map(|(n, text)| {
            Scenario::from_toml(text, &format!("<builtin {n}>"))
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
            known: BUILTINS
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", "),
        })
    }

    /// Reads a TOML scenario file.
    pub fn load(path: &FsPath) -> Result<Scenario> {
        let text = std::fs::read_to_string(path).map_err(|source| PropelError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Scenario::from_toml(&text, &path.display().to_string())
    }

    /// Parses and validates TOML text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Scenario> {
        let raw: ScenarioFile = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((0, 0));
            PropelError::Parse {
                file: file.to_string(),
                line,
                column,
                message: e.message().to_string(),
            }
        })?;
        raw.validate(text, file)
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioFile {
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

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SiteSpec {
    min_m: [f64; 2],
    max_m: [f64; 2],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PoseSpec {
    x_m: f64,
    y_m: f64,
    heading_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CircleSpec {
    name: Option<String>,
    center_m: [f64; 2],
    radius_m: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PolygonSpec {
    name: Option<String>,
    vertices_m: Vec<[f64; 2]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct BoundarySpec {
    name: Option<String>,
    points_m: Vec<[f64; 2]>,
}

/// Default footprint radius: the 1:7 prototype's half-width plus a margin [m].
pub const DEFAULT_FOOTPRINT_RADIUS_M: f64 = 1.0;

impl ScenarioFile {
    fn validate(self, text: &str, file: &str) -> Result<Scenario> {
        let err = |span: std::ops::Range<usize>, what: String| PropelError::Invalid {
            file: file.to_string(),
            line: line_col(text, span.start).0,
            what,
        };
        // The line of `key` inside a table's span (the header's line if not found).
        let key_line = |span: &std::ops::Range<usize>, key: &str| -> usize {
            let start = span.start.min(text.len());
            let end = span.end.min(text.len());
            let body = &text[start..end];
            let mut offset = start;
            for l in body.split_inclusive('\n') {
                let t = l.trim_start();
                if t.starts_with(key) && t[key.len()..].trim_start().starts_with('=') {
                    return line_col(text, offset).0;
                }
                offset += l.len();
            }
            line_col(text, start).0
        };
        // Every number finite and within ±1000 km (a planning site, not a globe).
        let finite =
            |span: &std::ops::Range<usize>, what: &str, vals: &[(&str, f64)]| -> Result<()> {
                match vals.iter().find(|(_, v)| !v.is_finite() || v.abs() > 1e6) {
                    Some((key, v)) => Err(PropelError::Invalid {
                        file: file.to_string(),
                        line: key_line(span, key),
                        what: if v.is_finite() {
                            format!("{what}: {key} has {v:e}, beyond the ±1e6 m a site may span")
                        } else {
                            format!("{what}: {key} has a non-finite number ({v})")
                        },
                    }),
                    None => Ok(()),
                }
            };
        let r_fp = match &self.footprint_radius_m {
            Some(s) => {
                let v = *s.get_ref();
                if !(v.is_finite() && v > 0.0 && v < 1e3) {
                    return Err(err(
                        s.span(),
                        format!("footprint_radius_m = {v} must be a positive number below 1000"),
                    ));
                }
                v
            }
            None => DEFAULT_FOOTPRINT_RADIUS_M,
        };
        let site = self.site.get_ref();
        finite(
            &self.site.span(),
            "[site]",
            &[
                ("min_m", site.min_m[0]),
                ("min_m", site.min_m[1]),
                ("max_m", site.max_m[0]),
                ("max_m", site.max_m[1]),
            ],
        )?;
        if !(site.max_m[0] > site.min_m[0] && site.max_m[1] > site.min_m[1]) {
            return Err(err(
                self.site.span(),
                format!(
                    "[site] max_m {:?} must exceed min_m {:?} in x and y",
                    site.max_m, site.min_m
                ),
            ));
        }
        let extent = (site.max_m[0] - site.min_m[0]).max(site.max_m[1] - site.min_m[1]);
        if extent > 10_000.0 {
            return Err(err(
                self.site.span(),
                format!("[site] spans {extent} m; planning sites are limited to 10 km"),
            ));
        }
        let mut map = Map::new(
            Vec2::new(site.min_m[0], site.min_m[1]),
            Vec2::new(site.max_m[0], site.max_m[1]),
        );
        let pose = |s: &Spanned<PoseSpec>, which: &str| -> Result<Pose2> {
            let p = s.get_ref();
            finite(
                &s.span(),
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
            let what = format!(
                "circle #{} '{}'",
                i + 1,
                spec.name.as_deref().unwrap_or("circle")
            );
            finite(
                &c.span(),
                &what,
                &[
                    ("center_m", spec.center_m[0]),
                    ("center_m", spec.center_m[1]),
                    ("radius_m", spec.radius_m),
                ],
            )?;
            if spec.radius_m <= 0.0 {
                return Err(PropelError::Invalid {
                    file: file.to_string(),
                    line: key_line(&c.span(), "radius_m"),
                    what: format!("{what}: radius_m = {} must be positive", spec.radius_m),
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
            let what = format!(
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
            finite(&p.span(), &what, &flat)?;
            if spec.vertices_m.len() > 1000 {
                return Err(err(
                    p.span(),
                    format!(
                        "{what} has {} vertices; at most 1000",
                        spec.vertices_m.len()
                    ),
                ));
            }
            let verts = spec
                .vertices_m
                .iter()
                .map(|v| Vec2::new(v[0], v[1]))
                .collect();
            let verts =
                convex_polygon(verts).map_err(|fault| err(p.span(), format!("{what} {fault}")))?;
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
            let what = format!(
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
            finite(&b.span(), &what, &flat)?;
            if spec.points_m.len() < 2 {
                return Err(err(
                    b.span(),
                    format!(
                        "{what} has {} points, needs at least 2",
                        spec.points_m.len()
                    ),
                ));
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
            name: self.name.unwrap_or_else(|| file.to_string()),
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
