//! The crate's single error type, [`JobError`]: the library crates' own
//! errors as they are (each names its file, node or value), a value outside
//! what a job accepts, and the step a library error happened in.

use std::path::PathBuf;

/// Everything that can stop a job.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum JobError {
    /// A job's setting outside what it accepts, said in the setting's
    /// name as the front end shows it (`--maps`, `maps`).
    #[error("{setting} {value} {rule}")]
    Setting {
        /// The setting at fault.
        setting: String,
        /// Its value.
        value: String,
        /// What it must satisfy.
        rule: String,
    },
    /// Real-time scheduling refused (a priority outside 1–99, or by the
    /// system: not root, no CAP_SYS_NICE).
    #[error("--realtime {priority}: {problem}")]
    Realtime {
        /// The priority asked for.
        priority: u8,
        /// Why it was refused, and what to do.
        problem: String,
    },
    /// `filter` without a stage.
    #[error("no stage given: add one or more of --voxel, --statistical, --radius, --pass, --level (run in the order given)")]
    NoStage,
    /// A folder or file could not be made or read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The path at fault.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A library error, with the step of the job it happened in.
    #[error("{step}")]
    During {
        /// What the job was doing (often naming its input).
        step: String,
        /// What went wrong there.
        #[source]
        source: Box<JobError>,
    },
    /// Writing the output folder or the report.
    #[error(transparent)]
    Report(#[from] autoshovel_report::ReportError),
    /// Writing a job's figures.
    #[error(transparent)]
    Figures(#[from] autoshovel_figures::FiguresError),
    /// Reading a point cloud.
    #[error(transparent)]
    Cloud(#[from] autoshovel_point_cloud::CloudError),
    /// Perception.
    #[error(transparent)]
    Surface(#[from] autoshovel_terrain::SurfaceError),
    /// The rope-shovel dig.
    #[error(transparent)]
    Dig(#[from] autoshovel_rope_shovel_dig::DigError),
    /// The hydraulic excavator.
    #[error(transparent)]
    Excavate(#[from] autoshovel_excavator_dig::ExcavateError),
    /// The walk's planner.
    #[error(transparent)]
    Propel(#[from] autoshovel_walk_planner::PropelError),
    /// Tracking.
    #[error(transparent)]
    Track(#[from] autoshovel_walk_tracker::TrackError),
    /// The machine link.
    #[error(transparent)]
    Link(#[from] autoshovel_plc_link::LinkError),
    /// A run log (written, or read back by `replay`).
    #[error(transparent)]
    RunLog(#[from] autoshovel_run_log::RunLogError),
    /// The whole machine's shift.
    #[error(transparent)]
    Shift(#[from] autoshovel_work_shift::ShiftError),
}

impl JobError {
    /// A setting outside its rule.
    pub fn setting(
        setting: impl Into<String>,
        value: impl std::fmt::Display,
        rule: impl Into<String>,
    ) -> Self {
        Self::Setting {
            setting: setting.into(),
            value: value.to_string(),
            rule: rule.into(),
        }
    }

    /// An I/O error at `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            path: path.into(),
            source,
        }
    }

    /// Whether a drive ended because it was interrupted (Ctrl-C), after
    /// zeroing the setpoints.
    pub fn interrupted(&self) -> bool {
        match self {
            Self::Link(autoshovel_plc_link::LinkError::Interrupted { .. }) => true,
            Self::During { source, .. } => source.interrupted(),
            _ => false,
        }
    }
}

/// `Result` with [`JobError`].
pub type Result<T, E = JobError> = std::result::Result<T, E>;

/// The step a library call belongs to, added to its error.
pub(crate) trait During<T> {
    /// The error, if any, as [`JobError::During`] `step()`.
    fn during(self, step: impl FnOnce() -> String) -> Result<T>;
}

impl<T, E: Into<JobError>> During<T> for std::result::Result<T, E> {
    fn during(self, step: impl FnOnce() -> String) -> Result<T> {
        self.map_err(|e| JobError::During {
            step: step(),
            source: Box::new(e.into()),
        })
    }
}
