//! Errors of point-cloud input, output and filtering.

use std::path::PathBuf;

/// Everything that can go wrong reading, writing or filtering a cloud.
/// Messages name the file, and the line, byte offset or value at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CloudError {
    /// An I/O error on a file (the cause is the error's source, printed
    /// after the file in an error chain).
    #[error("{path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The file's contents are not what its format says.
    #[error("{path}: {what}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong, with the line or byte offset.
        what: String,
    },
    /// A file extension no reader or writer handles.
    #[error("{path}: unknown point-cloud format '{extension}' (use .pcd, .ply, .las, .laz, .xyz, .csv or .txt)")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// Its extension.
        extension: String,
    },
    /// A filter parameter out of range.
    #[error("{filter}: {what}")]
    BadParameter {
        /// The filter.
        filter: &'static str,
        /// What is wrong, naming the value.
        what: String,
    },
    /// A filter left no points.
    #[error("{filter} removed every point ({input} in, 0 out): {hint}")]
    Emptied {
        /// The filter.
        filter: &'static str,
        /// Points in.
        input: usize,
        /// What to change.
        hint: String,
    },
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, CloudError>;
