//! Errors of dig planning, machine-profile and warm-start pack loading.

use std::path::{Path, PathBuf};

/// Everything that can go wrong when loading a profile or planning a dig.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DigError {
    /// A profile file could not be read, parsed or checked (names the file,
    /// line and key).
    #[error(transparent)]
    Config(#[from] autoshovel_core::config::ConfigError),
    /// The machine cannot put its tooth tip where the plan needs it.
    #[error("unreachable: {0}")]
    Unreachable(String),
    /// The pile surface cannot be used for a dig (too small, not rising, no toe).
    #[error("unusable pile surface: {0}")]
    Surface(String),
    /// The optimiser found no plan meeting every constraint.
    #[error(
        "no feasible dig plan after {evaluations} evaluations; the best plan still violates: {binding}"
    )]
    Infeasible {
        /// The constraints the best plan violates, with their values and limits.
        binding: String,
        /// Objective evaluations spent.
        evaluations: usize,
    },
    /// The optimiser refused its input.
    #[error(transparent)]
    Optim(#[from] autoshovel_optim::OptimError),
    /// A warm-start pack file could not be read.
    #[error("cannot read warm-start pack {}", .path.display())]
    PackRead {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A warm-start pack file could not be written.
    #[error("cannot write warm-start pack {}", .path.display())]
    PackWrite {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A warm-start pack file is not one `write_pack` wrote.
    #[error("{}: {problem}", location(.path, *.line))]
    Pack {
        /// The file.
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is wrong there.
        problem: PackProblem,
    },
    /// A scan whose fitted surface never rises above its floor.
    #[error(
        "{}: the scan does not rise above the floor (z = {floor_height_m:.4} m); no pile to dig",
        .path.display()
    )]
    ScanHasNoPile {
        /// The scan.
        path: PathBuf,
        /// The floor height found by perception (m).
        floor_height_m: f64,
    },
    /// The fitted surface of a scan cannot be cut into a dig profile.
    #[error(
        "{}: cutting the fitted surface along the dig plane y = {dig_plane_y_m:.4} m",
        .path.display()
    )]
    ScanCut {
        /// The scan.
        path: PathBuf,
        /// The dig plane (m).
        dig_plane_y_m: f64,
        /// Why the cut failed.
        source: Box<DigError>,
    },
    /// The machine cannot dig this pile at all (a model of the two cannot be
    /// set up), with the pile's hint when it has one.
    #[error("{pile} pile ({surface_source}): {cause}{}", note(.hint))]
    Pile {
        /// The pile's name ("typical", …, "cloud").
        pile: String,
        /// Where its profile came from.
        surface_source: String,
        /// Why the model refused it (part of this message, so not a
        /// `source` printed again after it).
        cause: Box<DigError>,
        /// Why a plan on this pile may fail (e.g. a full-size scan for a scale model).
        hint: Option<String>,
    },
    /// A setting out of its range (names the field and what it takes).
    #[error("{name} = {value}: expected {expected}")]
    BadParameter {
        /// The field, as `Type.field`.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The range it takes.
        expected: &'static str,
    },
    /// A record file of `validate-dig` (a measured CSV, a plan's
    /// `samples.csv`) could not be read.
    #[error("cannot read {}", .path.display())]
    RecordRead {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A record file could not be written (a simulated measurement).
    #[error("cannot write {}", .path.display())]
    RecordWrite {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A record file is not a usable table (names the file, the line and
    /// the column at fault).
    #[error("{}: {problem}", location(.path, *.line))]
    Record {
        /// The file.
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is wrong there.
        problem: RecordProblem,
    },
    /// A `--plan` folder is not the output of one `plan-dig` plan.
    #[error("{}: {problem}", .dir.display())]
    PlanDir {
        /// The folder.
        dir: PathBuf,
        /// What is wrong with it.
        problem: PlanDirProblem,
    },
    /// The measured record cannot be aligned with the plan: at no offset
    /// within the lag window does it cover enough of the dig.
    #[error(
        "{}: the record ({record_start_s} s to {record_end_s} s) covers less than {min_overlap_pct} % of the {td_s} s dig at every offset within ±{max_lag_s} s of its start; record the whole dig, or widen the window (--max-lag-s)",
        .path.display()
    )]
    NoOverlap {
        /// The measured file.
        path: PathBuf,
        /// Its first time (s).
        record_start_s: f64,
        /// Its last time (s).
        record_end_s: f64,
        /// The planned dig time (s).
        td_s: f64,
        /// The lag window searched, either side of the record's start (s).
        max_lag_s: f64,
        /// The least share of the dig a record must cover (%).
        min_overlap_pct: f64,
    },
}

/// What is wrong in a record file of `validate-dig`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RecordProblem {
    /// No header line.
    #[error("empty file; expected a header line naming the columns ({expected})")]
    Empty {
        /// The columns a record needs.
        expected: String,
    },
    /// A required column is not in the header.
    #[error("no column '{column}' in the header '{header}' (required: {required})")]
    MissingColumn {
        /// The column missing.
        column: &'static str,
        /// The header found.
        header: String,
        /// Every required column.
        required: String,
    },
    /// A column named twice.
    #[error("column '{column}' appears twice in the header")]
    DuplicateColumn {
        /// The column.
        column: String,
    },
    /// A row with the wrong number of cells.
    #[error("{found} cells, the header has {expected}")]
    Width {
        /// Cells found.
        found: usize,
        /// Cells the header names.
        expected: usize,
    },
    /// A cell that is not a finite number.
    #[error("column {column}: '{cell}' is not a finite number")]
    NotANumber {
        /// Its column.
        column: String,
        /// Its text.
        cell: String,
    },
    /// Time not strictly increasing.
    #[error("t_s = {t_s} does not increase (the line before has {previous_t_s})")]
    TimeNotIncreasing {
        /// The time of this line (s).
        t_s: f64,
        /// The time of the line before (s).
        previous_t_s: f64,
    },
    /// Too few rows to compare.
    #[error("{found} samples; at least {min} are needed")]
    TooFewSamples {
        /// Rows found.
        found: usize,
        /// Rows needed.
        min: usize,
    },
    /// A `mass_kg` column with no value in it.
    #[error(
        "column mass_kg has no value; give the dug mass in at least one row, or drop the column"
    )]
    NoMass,
}

/// What is wrong with a `--plan` folder.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanDirProblem {
    /// No `summary.json` in the folder.
    #[error("no summary.json here; pass the --out folder of `autoshovel plan-dig`")]
    NoSummary,
    /// `summary.json` is not JSON.
    #[error("summary.json is not valid JSON: {message}")]
    Json {
        /// The parser's message.
        message: String,
    },
    /// `summary.json` of another job.
    #[error("summary.json is of job '{job}', not plan-dig; pass the --out folder of `autoshovel plan-dig`")]
    NotPlanDig {
        /// The job named there.
        job: String,
    },
    /// The folder of `plan-dig --all-surfaces`.
    #[error("this is an --all-surfaces folder; pass one pile's folder in it, e.g. its typical/")]
    AllSurfaces,
    /// A summary without a plan.
    #[error("the plan-dig run found no feasible plan: {error}")]
    NoPlan {
        /// Its error.
        error: String,
    },
    /// A field missing from `summary.json`.
    #[error("summary.json has no '{field}'")]
    MissingField {
        /// The field.
        field: &'static str,
    },
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PackProblem {
    /// The file is empty.
    #[error("empty file; expected a pack.csv of plan-dig")]
    Empty,
    /// The header is not the pack's columns.
    #[error("header '{found}' is not a plan-dig pack (expected {expected})")]
    Header {
        /// The header found.
        found: String,
        /// The header a pack has.
        expected: String,
    },
    /// A row with the wrong number of cells.
    #[error("{found} values, expected {expected}")]
    Width {
        /// Cells found.
        found: usize,
        /// Cells a row has.
        expected: usize,
    },
    /// A cell that is not a finite number.
    #[error("{column} = '{cell}' is not a finite number")]
    NotANumber {
        /// Its column.
        column: &'static str,
        /// Its text.
        cell: String,
    },
    /// A dig duration that is not positive.
    #[error("td_s = {td_s} must be > 0")]
    DurationNotPositive {
        /// The duration read (s).
        td_s: f64,
    },
    /// A header and no wolves.
    #[error("no wolves in the pack")]
    NoWolves,
}

/// `path:line` or `path`.
fn location(path: &Path, line: Option<usize>) -> String {
    match line {
        Some(l) => format!("{}:{l}", path.display()),
        None => path.display().to_string(),
    }
}

/// "\nnote: …" for a hint, nothing without one.
fn note(hint: &Option<String>) -> String {
    hint.as_ref()
        .map(|h| format!("\nnote: {h}"))
        .unwrap_or_default()
}

/// Shorthand for results of this crate.
pub type Result<T> = std::result::Result<T, DigError>;
