//! Errors of the machine link, each naming the endpoint, node, file or
//! value at fault.

use std::path::PathBuf;

/// What went wrong on the link.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// A certificate folder or file could not be made or read.
    #[error("{path}: {why}")]
    Pki {
        /// The file or folder.
        path: PathBuf,
        /// What happened.
        why: String,
    },
    /// A run log could not be written or read.
    #[error("{path}: {why}")]
    Log {
        /// The file.
        path: PathBuf,
        /// What happened.
        why: String,
    },
    /// No OPC UA session could be opened.
    #[error("{endpoint}: {why}")]
    Connect {
        /// The endpoint URL.
        endpoint: String,
        /// What happened, with a hint.
        why: String,
    },
    /// Security None asked for without `--insecure`.
    #[error("{endpoint}: security None sends setpoints unsigned and unencrypted; refused without --insecure")]
    InsecureRefused {
        /// The endpoint URL.
        endpoint: String,
    },
    /// A node of the model is missing or of the wrong type.
    #[error("{endpoint}: node {node}: {why}")]
    Model {
        /// The endpoint URL.
        endpoint: String,
        /// The node id.
        node: String,
        /// What is wrong.
        why: String,
    },
    /// The PLC gave a value that cannot be right.
    #[error("{endpoint}: node {node} gave {value}: {why}; setpoints zeroed")]
    BadValue {
        /// The endpoint URL.
        endpoint: String,
        /// The node id.
        node: String,
        /// The value as read.
        value: String,
        /// Why it was refused.
        why: String,
    },
    /// The scenario's machine is not the PLC's.
    #[error("{endpoint}: the scenario's {what} is {scenario} but the PLC's is {plc} ({node}); use a scenario made for this machine")]
    Mismatch {
        /// The endpoint URL.
        endpoint: String,
        /// Which parameter.
        what: &'static str,
        /// The node id.
        node: String,
        /// The scenario's value.
        scenario: String,
        /// The PLC's value.
        plc: String,
    },
    /// The PLC refused a write or a call.
    #[error("{endpoint}: {what} refused: {status}")]
    Refused {
        /// The endpoint URL.
        endpoint: String,
        /// What was asked.
        what: String,
        /// The status code.
        status: String,
    },
    /// The PLC is not in auto.
    #[error(
        "{endpoint}: the PLC is in manual mode (Shovel.Mode = 0); switch it to auto at the machine"
    )]
    Manual {
        /// The endpoint URL.
        endpoint: String,
    },
    /// The server could not start.
    #[error("plc-sim on {addr}: {why}")]
    Serve {
        /// The address asked for.
        addr: String,
        /// What happened.
        why: String,
    },
    /// The link was lost and not restored in time.
    #[error("{endpoint}: link lost for {secs:.1} s (limit {limit_s:.0} s); setpoints zeroed where reachable")]
    LinkLost {
        /// The endpoint URL.
        endpoint: String,
        /// How long.
        secs: f64,
        /// The limit.
        limit_s: f64,
    },
    /// Interrupted by the user (Ctrl-C); setpoints were zeroed.
    #[error("interrupted: setpoints zeroed on {endpoint}")]
    Interrupted {
        /// The endpoint URL.
        endpoint: String,
    },
}
