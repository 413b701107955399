//! The machine link (walking paper §5.1–5.2, Fig. 11): the shovel PLC's
//! OPC UA information model ([`model`]), the simulated PLC that protects
//! its machine ([`plc`]) behind a secure OPC UA server ([`server`]), the
//! workstation that drives it ([`drive`]), certificates and trust lists
//! ([`pki`]), and the network relay that lets tests pull the cable
//! ([`relay`]). The protocol is async-opcua's; nothing of it is written here.

// Units in brackets ("[m]", "[deg]") are the house style, not intra-doc links.
#![allow(rustdoc::broken_intra_doc_links)]

pub mod drive;
pub mod error;
pub mod log;
pub mod model;
pub mod pki;
pub mod plc;
pub mod relay;
pub mod replay;
pub mod server;

pub use drive::{drive, drive_logged, DriveOptions, DriveRun, Link, LinkEvent, LinkParams, Policy};
pub use error::LinkError;
pub use log::RunLog;
pub use plc::{Clock, FaultKind, Plc, PlcParams, PlcSimSummary, HEARTBEAT_TIMEOUT};
pub use server::{PlcServer, ServeParams};
