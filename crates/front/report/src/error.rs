//! The crate's single error type, [`ReportError`].
//!
//! Every variant that concerns a file names the path at fault, so the CLI can
//! print the error as it is.

use std::path::PathBuf;

/// Everything that can go wrong while writing plots, tables and reports.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// A file could not be created or written (a missing output directory ends up here).
    #[error("cannot write {}", path.display())]
    Io {
        /// The file that could not be written.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The plotting library failed while drawing or encoding an image.
    #[error("cannot draw {}: {message}", path.display())]
    Plot {
        /// The image file that was being produced.
        path: PathBuf,
        /// What the plotting library reported.
        message: String,
    },
    /// A file may not be written there: it is an input of the job, or an
    /// existing file autoshovel did not write (without `--force`).
    #[error("refusing to write {}: {why}", path.display())]
    Refused {
        /// The file (or folder) at fault.
        path: PathBuf,
        /// Why, and what to do.
        why: String,
    },
    /// The input cannot be turned into a plot or table (bad range, ragged rows, bad file stem...).
    #[error("invalid report input: {what}")]
    Invalid {
        /// What is wrong, naming the file it was meant for where there is one.
        what: String,
    },
}

impl ReportError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            path: path.into(),
            source,
        }
    }

    pub(crate) fn invalid(what: impl Into<String>) -> Self {
        Self::Invalid { what: what.into() }
    }
}
