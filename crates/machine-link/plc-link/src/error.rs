//! Errors of the machine link, each naming the endpoint, node, file or
//! value at fault, with the cause kept as the error's source (printed after
//! it in an error chain: `error: {e:#}`, `autoshovel_core::error_chain`).

use std::path::PathBuf;

use autoshovel_run_log::RunLogError;

/// What went wrong on the link.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LinkError {
    /// A certificate folder or file could not be made or read.
    #[error("{path}: {why}")]
    Pki {
        /// The file or folder.
        path: PathBuf,
        /// What happened.
        why: String,
    },
    /// A certificate folder or file could not be made, read or written.
    #[error("{path}")]
    PkiIo {
        /// The file or folder.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A file is not an X.509 certificate, or one could not be encoded.
    #[error("{path}: {what}")]
    Certificate {
        /// The file.
        path: PathBuf,
        /// What was being done: `not an X.509 certificate (DER or PEM)`.
        what: &'static str,
        /// The certificate library's error.
        #[source]
        source: opcua::crypto::X509Error,
    },
    /// A run log could not be written or read.
    #[error(transparent)]
    RunLog(#[from] RunLogError),
    /// No OPC UA session could be opened.
    #[error("{endpoint}: {why}")]
    Connect {
        /// The endpoint URL.
        endpoint: String,
        /// What happened, with a hint.
        why: String,
        /// The OPC UA stack's error, where it gave one.
        #[source]
        source: Option<opcua::types::Error>,
    },
    /// A service call (read, write, method call) on an open session failed
    /// in the stack or on the wire (the PLC's own refusals are `Refused`).
    #[error("{endpoint}: the {service} failed")]
    Service {
        /// The endpoint URL.
        endpoint: String,
        /// Which call: `read`, `write`, `method call`.
        service: &'static str,
        /// The OPC UA stack's error.
        #[source]
        source: opcua::types::Error,
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
    /// The server's address could not be bound or read.
    #[error("plc-sim on {addr}")]
    ServeIo {
        /// The address asked for.
        addr: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
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
    /// The peer presented a certificate this side does not trust.
    #[error("{endpoint}: the {side}'s certificate ({certificate}) is not in this side's trust list; saved to {saved}; {fix}", saved = saved.display())]
    Untrusted {
        /// The endpoint URL.
        endpoint: String,
        /// Whose certificate: `PLC` or `workstation`.
        side: &'static str,
        /// Its subject and SHA-1 thumbprint.
        certificate: String,
        /// Where it was saved for a person to check.
        saved: PathBuf,
        /// The command that trusts it.
        fix: String,
    },
    /// Another session holds control of the machine.
    #[error("{endpoint}: control of the machine is held by {by}; it moves only for that session (it releases control, or an operator breaks it at rest with the machine stopped)")]
    ControlHeld {
        /// The endpoint URL.
        endpoint: String,
        /// Who holds it (`Shovel.Control.LockingUser` on `LockingClient`).
        by: String,
    },
    /// The PLC on the endpoint is not the one the run started with.
    #[error("{endpoint}: the PLC restarted (Shovel.InstanceId was {was}, now {now}); this run will not drive a new instance: check the machine, acknowledge, and start a new drive")]
    PlcRestarted {
        /// The endpoint URL.
        endpoint: String,
        /// The instance at the start.
        was: String,
        /// The instance now.
        now: String,
    },
    /// A user password asked to travel over a channel without encryption.
    #[error("{endpoint}: security None would send the password of {user} in clear; a user identity is only sent over SignAndEncrypt (drop --policy none, or read anonymously)")]
    PasswordInClear {
        /// The endpoint URL.
        endpoint: String,
        /// The user.
        user: String,
    },
    /// Interrupted by the user (Ctrl-C) or a signal (SIGTERM, SIGHUP);
    /// setpoints were zeroed.
    #[error("interrupted: setpoints zeroed on {endpoint}")]
    Interrupted {
        /// The endpoint URL.
        endpoint: String,
    },
}
