//! The two records `validate-dig` compares ([RS §5], Table 6, Fig. 20): the
//! plan (the `--out` folder of `plan-dig`: `summary.json` and
//! `samples.csv`) and the measurement (a CSV with a header naming its
//! columns), both read by names into a [`ForceRecord`] whose times strictly
//! increase; every error names the file, the line and the column.
//!
//! ```text
//! t_s,hoist_force_n,crowd_force_n,rope_length_m,handle_extension_m,mass_kg
//! 0.00,212.4,61.0,0.913,0.000,
//! 0.01,212.9,60.7,0.913,0.000,
//! …
//! 9.50,251.3,12.2,0.655,0.171,2.086
//! ```
//!
//! Required: `t_s`, `hoist_force_n`, `crowd_force_n`. Optional:
//! `rope_length_m`, `handle_extension_m` (the testbed's rope and handle
//! encoders) and `mass_kg` (the dug mass: the last value in the column;
//! other cells of it may be empty). Other columns are ignored; blank lines
//! and lines starting with `#` are skipped.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::error::{DigError, PlanDirProblem, RecordProblem, Result};
use crate::kinematics::{Joints, RopeShovel};
use crate::plan::{DigModel, DigPlan, DigSample};
use crate::profile::Geometry;

/// Columns a measured record must have.
pub const MEASURED_REQUIRED: [&str; 3] = ["t_s", "hoist_force_n", "crowd_force_n"];

/// Columns a measured record may have.
pub const MEASURED_OPTIONAL: [&str; 3] = ["rope_length_m", "handle_extension_m", "mass_kg"];

/// The fewest samples a record may have.
pub const MIN_SAMPLES: usize = 10;

/// Hoist and crowd forces over time, and the rope and handle when known;
/// `t_s` strictly increases and every series is as long as it.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceRecord {
    /// Time (s).
    pub t_s: Vec<f64>,
    /// Hoist rope force F_h (N).
    pub hoist_force_n: Vec<f64>,
    /// Crowd force F_c (N).
    pub crowd_force_n: Vec<f64>,
    /// Free hoist rope length, bail pin to the boom-point sheave (m).
    pub rope_length_m: Option<Vec<f64>>,
    /// Handle extension d₂ (m).
    pub handle_extension_m: Option<Vec<f64>>,
}

impl ForceRecord {
    /// Time of the first and the last sample (s).
    pub fn span_s(&self) -> (f64, f64) {
        (
            self.t_s.first().copied().unwrap_or(0.0),
            self.t_s.last().copied().unwrap_or(0.0),
        )
    }

    /// The median time step (s).
    pub fn median_step_s(&self) -> f64 {
        let mut d: Vec<f64> = self.t_s.windows(2).map(|w| w[1] - w[0]).collect();
        if d.is_empty() {
            return f64::NAN;
        }
        d.sort_by(f64::total_cmp);
        d[d.len() / 2]
    }
}

/// A measured dig: the testbed's record.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredRecord {
    /// The file it came from (for summaries and messages).
    pub source: PathBuf,
    /// The forces (and rope and handle, if recorded).
    pub forces: ForceRecord,
    /// The dug mass, weighed after the dig (kg).
    pub mass_kg: Option<f64>,
}

impl MeasuredRecord {
    /// Reads the measured CSV at `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| DigError::RecordRead {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses the text of a measured CSV; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let table = Table::parse(text, path, &MEASURED_REQUIRED)?;
        let forces = table.forces("rope_length_m", "handle_extension_m")?;
        let mass_kg = match table.column("mass_kg") {
            None => None,
            Some(c) => Some(
                table
                    .optional_numbers(c)?
                    .into_iter()
                    .flatten()
                    .last()
                    .ok_or_else(|| table.fail(None, RecordProblem::NoMass))?,
            ),
        };
        Ok(Self {
            source: path.to_path_buf(),
            forces,
            mass_kg,
        })
    }

    /// Writes the record as a measured CSV that [`MeasuredRecord::load`]
    /// reads back to the same numbers (the mass, if any, on the last row).
    pub fn write(&self, path: &Path) -> Result<()> {
        let f = &self.forces;
        let mut header = MEASURED_REQUIRED.to_vec();
        let mut cols: Vec<&[f64]> = vec![&f.t_s, &f.hoist_force_n, &f.crowd_force_n];
        for (name, v) in [
            ("rope_length_m", &f.rope_length_m),
            ("handle_extension_m", &f.handle_extension_m),
        ] {
            if let Some(v) = v {
                header.push(name);
                cols.push(v);
            }
        }
        if self.mass_kg.is_some() {
            header.push("mass_kg");
        }
        let mut text = header.join(",");
        text.push('\n');
        let n = f.t_s.len();
        for i in 0..n {
            for (j, c) in cols.iter().enumerate() {
                if j > 0 {
                    text.push(',');
                }
                let _ = write!(text, "{}", c[i]);
            }
            if let Some(m) = self.mass_kg {
                text.push(',');
                if i + 1 == n {
                    let _ = write!(text, "{m}");
                }
            }
            text.push('\n');
        }
        std::fs::write(path, text).map_err(|source| DigError::RecordWrite {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// The planned dig: what the plan says the testbed will measure.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedRecord {
    /// The plan's folder, or a name for a plan made in memory.
    pub source: String,
    /// The pile's name.
    pub surface: String,
    /// Planned dug mass m_dig (kg).
    pub m_dig_kg: f64,
    /// Planned dig time t_d (s).
    pub td_s: f64,
    /// Planned forces, rope length and handle extension over [0, t_d].
    pub forces: ForceRecord,
}

/// The fields of a plan's `summary.json` that a comparison needs.
#[derive(Debug, Deserialize)]
struct PlanSummaryFile {
    job: Option<String>,
    surface: Option<String>,
    m_dig_kg: Option<f64>,
    td_s: Option<f64>,
    geometry: Option<Geometry>,
    error: Option<String>,
    surfaces: Option<serde::de::IgnoredAny>,
}

impl PlannedRecord {
    /// Reads the `--out` folder `dir` of one `plan-dig` plan: `summary.json`
    /// (pile, m_dig, t_d, the machine's geometry) and `samples.csv` (the
    /// forces, θ₁ and d₂ over time, [`crate::SAMPLE_COLUMNS`]). The rope
    /// length is the free rope of the plan's joints
    /// ([`PlannedRecord::from_samples`]).
    pub fn load(dir: &Path) -> Result<Self> {
        let bad = |problem| DigError::PlanDir {
            dir: dir.to_path_buf(),
            problem,
        };
        let path = dir.join("summary.json");
        if !path.is_file() {
            return Err(bad(PlanDirProblem::NoSummary));
        }
        let text = std::fs::read_to_string(&path).map_err(|source| DigError::RecordRead {
            path: path.clone(),
            source,
        })?;
        let s: PlanSummaryFile = serde_json::from_str(&text).map_err(|e| {
            bad(PlanDirProblem::Json {
                message: e.to_string(),
            })
        })?;
        match s.job.as_deref() {
            Some("plan-dig") => {}
            Some(job) => {
                return Err(bad(PlanDirProblem::NotPlanDig {
                    job: job.to_string(),
                }))
            }
            None => return Err(bad(PlanDirProblem::MissingField { field: "job" })),
        }
        if s.surfaces.is_some() {
            return Err(bad(PlanDirProblem::AllSurfaces));
        }
        if let Some(error) = s.error {
            return Err(bad(PlanDirProblem::NoPlan { error }));
        }
        let field =
            |v: Option<f64>, field| v.ok_or_else(|| bad(PlanDirProblem::MissingField { field }));
        let m_dig_kg = field(s.m_dig_kg, "m_dig_kg")?;
        let td_s = field(s.td_s, "td_s")?;
        let path = dir.join("samples.csv");
        let text = std::fs::read_to_string(&path).map_err(|source| DigError::RecordRead {
            path: path.clone(),
            source,
        })?;
        let table = Table::parse(
            &text,
            &path,
            &[
                "t_s",
                "theta1_rad",
                "d2_m",
                "hoist_force_n",
                "crowd_force_n",
            ],
        )?;
        let mut forces = table.forces("", "d2_m")?;
        if let Some(g) = s.geometry {
            let theta1 = table.numbers(table.column("theta1_rad").unwrap_or(0))?;
            let d2 = forces.handle_extension_m.clone().unwrap_or_default();
            forces.rope_length_m = rope_lengths(&RopeShovel::new(g), &theta1, &d2);
        }
        Ok(Self {
            source: dir.display().to_string(),
            surface: s.surface.unwrap_or_default(),
            m_dig_kg,
            td_s,
            forces,
        })
    }

    /// The record of a plan made in memory on `model`, named `source`.
    pub fn from_plan(source: &str, surface: &str, model: &DigModel, plan: &DigPlan) -> Self {
        Self::from_samples(
            source,
            surface,
            plan.outcome.m_dig_kg,
            plan.outcome.decision.td_s,
            &plan.samples,
            &model.shovel,
        )
    }

    /// The record of planned `samples`: forces and d₂ as planned, the rope
    /// length as the free rope from the bail pin to the sheave's tangent
    /// point for the joints of each sample ([`RopeShovel::rope`]).
    pub fn from_samples(
        source: &str,
        surface: &str,
        m_dig_kg: f64,
        td_s: f64,
        samples: &[DigSample],
        shovel: &RopeShovel,
    ) -> Self {
        let col = |f: fn(&DigSample) -> f64| samples.iter().map(f).collect::<Vec<f64>>();
        let theta1 = col(|s| s.joints.theta1);
        let d2 = col(|s| s.joints.d2);
        Self {
            source: source.to_string(),
            surface: surface.to_string(),
            m_dig_kg,
            td_s,
            forces: ForceRecord {
                t_s: col(|s| s.t_s),
                hoist_force_n: col(|s| s.drive.hoist_force_n),
                crowd_force_n: col(|s| s.drive.crowd_force_n),
                rope_length_m: rope_lengths(shovel, &theta1, &d2),
                handle_extension_m: Some(d2),
            },
        }
    }
}

/// The free rope length at each (θ₁, d₂); none if the bail is ever inside
/// the sheave.
fn rope_lengths(shovel: &RopeShovel, theta1: &[f64], d2: &[f64]) -> Option<Vec<f64>> {
    theta1
        .iter()
        .zip(d2)
        .map(|(&theta1, &d2)| {
            shovel
                .rope(shovel.bail(Joints { theta1, d2 }))
                .map(|(_, len)| len)
        })
        .collect()
}

/// A CSV read by the names of its header, rows kept with their line numbers.
struct Table<'a> {
    path: &'a Path,
    header: Vec<String>,
    rows: Vec<(usize, Vec<&'a str>)>,
}

impl<'a> Table<'a> {
    /// Splits `text` into a header and rows, checks that `required` are
    /// named, that no column is named twice and that every row is as wide
    /// as the header.
    fn parse(text: &'a str, path: &'a Path, required: &[&'static str]) -> Result<Self> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let fail = |line, problem| DigError::Record {
            path: path.to_path_buf(),
            line,
            problem,
        };
        let Some((header_line, header)) = lines.next() else {
            return Err(fail(
                None,
                RecordProblem::Empty {
                    expected: required.join(","),
                },
            ));
        };
        let header: Vec<String> = header
            .split(',')
            .map(|c| c.trim().trim_matches('"').to_string())
            .collect();
        for (i, c) in header.iter().enumerate() {
            if header[..i].contains(c) {
                return Err(fail(
                    Some(header_line),
                    RecordProblem::DuplicateColumn { column: c.clone() },
                ));
            }
        }
        for &column in required {
            if !header.iter().any(|c| c == column) {
                return Err(fail(
                    Some(header_line),
                    RecordProblem::MissingColumn {
                        column,
                        header: header.join(","),
                        required: required.join(", "),
                    },
                ));
            }
        }
        let mut rows = Vec::new();
        for (line, l) in lines {
            let cells: Vec<&str> = l.split(',').map(str::trim).collect();
            if cells.len() != header.len() {
                return Err(fail(
                    Some(line),
                    RecordProblem::Width {
                        found: cells.len(),
                        expected: header.len(),
                    },
                ));
            }
            rows.push((line, cells));
        }
        if rows.len() < MIN_SAMPLES {
            return Err(fail(
                None,
                RecordProblem::TooFewSamples {
                    found: rows.len(),
                    min: MIN_SAMPLES,
                },
            ));
        }
        Ok(Self { path, header, rows })
    }

    /// The error at `line` of this file.
    fn fail(&self, line: Option<usize>, problem: RecordProblem) -> DigError {
        DigError::Record {
            path: self.path.to_path_buf(),
            line,
            problem,
        }
    }

    /// The index of column `name`.
    fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|c| c == name)
    }

    /// Column `c` as finite numbers, an empty cell allowed (`None`).
    fn optional_numbers(&self, c: usize) -> Result<Vec<Option<f64>>> {
        self.rows
            .iter()
            .map(|(line, cells)| {
                let cell = cells[c].trim_matches('"');
                if cell.is_empty() {
                    return Ok(None);
                }
                cell.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .map(Some)
                    .ok_or_else(|| {
                        self.fail(
                            Some(*line),
                            RecordProblem::NotANumber {
                                column: self.header[c].clone(),
                                cell: cell.to_string(),
                            },
                        )
                    })
            })
            .collect()
    }

    /// Column `c` as finite numbers, every cell filled.
    fn numbers(&self, c: usize) -> Result<Vec<f64>> {
        let v = self.optional_numbers(c)?;
        v.iter()
            .zip(&self.rows)
            .map(|(v, (line, _))| {
                v.ok_or_else(|| {
                    self.fail(
                        Some(*line),
                        RecordProblem::NotANumber {
                            column: self.header[c].clone(),
                            cell: String::new(),
                        },
                    )
                })
            })
            .collect()
    }

    /// The forces, with the rope and handle of columns `rope` and `handle`
    /// when the header names them; checks that time strictly increases.
    fn forces(&self, rope: &str, handle: &str) -> Result<ForceRecord> {
        let req = |name: &str| self.numbers(self.column(name).unwrap_or(0));
        let t_s = req("t_s")?;
        for (k, w) in t_s.windows(2).enumerate() {
            if w[1] <= w[0] {
                return Err(self.fail(
                    Some(self.rows[k + 1].0),
                    RecordProblem::TimeNotIncreasing {
                        t_s: w[1],
                        previous_t_s: w[0],
                    },
                ));
            }
        }
        let opt = |name: &str| {
            self.column(name)
                .filter(|_| !name.is_empty())
                .map(|c| self.numbers(c))
                .transpose()
        };
        Ok(ForceRecord {
            hoist_force_n: req("hoist_force_n")?,
            crowd_force_n: req("crowd_force_n")?,
            rope_length_m: opt(rope)?,
            handle_extension_m: opt(handle)?,
            t_s,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<MeasuredRecord> {
        MeasuredRecord::parse(text, Path::new("m.csv"))
    }

    fn rows(n: usize) -> String {
        (0..n)
            .map(|i| format!("{},{},{}\n", i as f64 * 0.1, 100.0 + i as f64, 50.0))
            .collect()
    }

    #[test]
    fn columns_are_read_by_name_in_any_order_and_unknown_ones_ignored() {
        let mut text = "crowd_force_n,comment,t_s,hoist_force_n,mass_kg\n".to_string();
        for i in 0..12 {
            let mass = if i == 11 { "2.086" } else { "" };
            text.push_str(&format!(
                "{},x,{},{},{mass}\n",
                50 + i,
                i as f64 * 0.01,
                200 + i
            ));
        }
        let m = parse(&text).unwrap();
        assert_eq!(m.forces.t_s.len(), 12);
        assert_eq!(m.forces.hoist_force_n[3], 203.0);
        assert_eq!(m.forces.crowd_force_n[3], 53.0);
        assert_eq!(m.mass_kg, Some(2.086));
        assert!(m.forces.rope_length_m.is_none());
    }

    #[test]
    fn a_missing_column_is_named_with_the_header() {
        let e = parse(&format!("t_s,hoist_force_n\n{}", "0,1\n".repeat(12)))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.csv:1: no column 'crowd_force_n'"), "{e}");
    }

    #[test]
    fn a_bad_number_names_line_and_column() {
        let mut text = format!("t_s,hoist_force_n,crowd_force_n\n{}", rows(12));
        text = text.replacen("105,50", "1O5,50", 1);
        let e = parse(&text).unwrap_err().to_string();
        assert_eq!(
            e,
            "m.csv:7: column hoist_force_n: '1O5' is not a finite number"
        );
    }

    #[test]
    fn time_must_increase_and_rows_must_be_wide_enough() {
        let text = format!("t_s,hoist_force_n,crowd_force_n\n{}", rows(12)).replacen(
            "0.30000000000000004,",
            "0.2,",
            1,
        );
        let e = parse(&text).unwrap_err().to_string();
        assert_eq!(
            e,
            "m.csv:5: t_s = 0.2 does not increase (the line before has 0.2)"
        );
        let text = format!("t_s,hoist_force_n,crowd_force_n\n{}0.9,1\n", rows(12));
        let e = parse(&text).unwrap_err().to_string();
        assert_eq!(e, "m.csv:14: 2 cells, the header has 3");
        let e = parse(&format!("t_s,hoist_force_n,crowd_force_n\n{}", rows(3)))
            .unwrap_err()
            .to_string();
        assert_eq!(e, "m.csv: 3 samples; at least 10 are needed");
        let e = parse("").unwrap_err().to_string();
        assert!(e.starts_with("m.csv: empty file"), "{e}");
    }

    #[test]
    fn written_records_read_back_to_the_same_numbers() {
        let m = parse(&format!("t_s,hoist_force_n,crowd_force_n\n{}", rows(15))).unwrap();
        let mut m = MeasuredRecord {
            mass_kg: Some(2.0 / 3.0),
            ..m
        };
        m.forces.handle_extension_m = Some(m.forces.t_s.iter().map(|t| t / 7.0).collect());
        let dir = std::env::temp_dir().join(format!("validate-record-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("m.csv");
        m.write(&path).unwrap();
        let back = MeasuredRecord::load(&path).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(back.forces, m.forces);
        assert_eq!(back.mass_kg, m.mass_kg);
    }

    #[test]
    fn a_folder_that_is_not_one_plan_says_what_to_pass() {
        let dir = std::env::temp_dir().join(format!("validate-plandir-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let e = PlannedRecord::load(&dir).unwrap_err().to_string();
        assert!(
            e.ends_with("no summary.json here; pass the --out folder of `autoshovel plan-dig`"),
            "{e}"
        );
        std::fs::write(dir.join("summary.json"), r#"{"job": "perceive"}"#).unwrap();
        let e = PlannedRecord::load(&dir).unwrap_err().to_string();
        assert!(
            e.contains("summary.json is of job 'perceive', not plan-dig"),
            "{e}"
        );
        std::fs::write(
            dir.join("summary.json"),
            r#"{"job": "plan-dig", "surfaces": []}"#,
        )
        .unwrap();
        let e = PlannedRecord::load(&dir).unwrap_err().to_string();
        assert!(e.contains("--all-surfaces folder"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
