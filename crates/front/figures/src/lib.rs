//! Each job's figures (SVG + PNG) and CSV tables, built from the typed
//! results of the library crates: one module per job, the shared drawing
//! helpers in `autoshovel-report`. The jobs (`autoshovel-jobs`) call it;
//! it sits at the end of the data flow beside them.
//!
//! Every `write_*` function takes the output folder and a
//! [`Written`](autoshovel_report::Written) that records each file written.

pub mod boulders;
pub mod dig;
pub mod excavate;
pub mod filter;
pub mod frames;
pub mod map;
pub mod perceive;
pub mod shift;
pub mod shovel;
pub mod study;
pub mod tiles;
pub mod track;
pub mod tune;
pub mod validate;

/// What can go wrong while writing a job's files.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FiguresError {
    /// A figure, CSV or summary could not be written (names the file).
    #[error(transparent)]
    Report(#[from] autoshovel_report::ReportError),
    /// A point cloud could not be written (names the file).
    #[error(transparent)]
    Cloud(#[from] autoshovel_point_cloud::CloudError),
    /// A run log (MCAP) could not be written (names the file).
    #[error(transparent)]
    RunLog(#[from] autoshovel_run_log::RunLogError),
    /// A dig file (the warm-start pack) could not be written.
    #[error(transparent)]
    Dig(#[from] autoshovel_rope_shovel_dig::DigError),
    /// An output folder could not be created.
    #[error("cannot create output directory {}", path.display())]
    CreateDir {
        /// The folder.
        path: std::path::PathBuf,
        /// Why.
        source: std::io::Error,
    },
}
