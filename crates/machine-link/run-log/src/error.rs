//! Errors of the run log, each naming the file and keeping its cause.

use std::path::PathBuf;

/// What went wrong writing or reading a run log or an RTK track.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunLogError {
    /// The file could not be created, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The log to create exists already (logs are never overwritten unasked).
    #[error("{path}: exists; choose another --log or pass --force")]
    Exists {
        /// The file.
        path: PathBuf,
    },
    /// The MCAP writer failed.
    #[error("{path}: {source}")]
    McapWrite {
        /// The file.
        path: PathBuf,
        /// The MCAP library's error.
        #[source]
        source: mcap::McapError,
    },
    /// The file is not MCAP, or its records are damaged.
    #[error("{path}: {what}: {source}")]
    McapRead {
        /// The file.
        path: PathBuf,
        /// `not an MCAP file` or `damaged MCAP`.
        what: &'static str,
        /// The MCAP library's error.
        #[source]
        source: mcap::McapError,
    },
    /// A message could not be encoded as JSON.
    #[error("{path}: {source}")]
    Encode {
        /// The file.
        path: PathBuf,
        /// The JSON encoder's error.
        #[source]
        source: serde_json::Error,
    },
    /// A message in the log is not what its topic holds.
    #[error("{path}: message {sequence} on {topic}: {source}")]
    Message {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The message's sequence number.
        sequence: u32,
        /// The JSON decoder's error.
        #[source]
        source: serde_json::Error,
    },
    /// The records, read whole, are not a run (no path, a leg out of range,
    /// a CSV line that is not a fix); `why` names the line or topic.
    #[error("{path}: {why}")]
    Content {
        /// The file.
        path: PathBuf,
        /// What is wrong, and where.
        why: String,
    },
}
