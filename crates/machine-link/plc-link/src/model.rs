//! The shovel PLC's information model: one OPC UA namespace
//! ([`NAMESPACE_URI`]) holding, per crawler motor, the speed setpoint the
//! workstation writes and the inverter's readings; the RTK pose as the
//! receiver gives it (walking paper §5.1–5.2, Fig. 11); the workstation's
//! heartbeat; mode, fault and the acknowledge method; the machine's limits.
//! A folder `Simulator` exists only on `autoshovel plc-sim`: the lockstep
//! counters and the simulator's truth, which the workstation logs for
//! evaluation and never feeds to its controller.
//!
//! Node ids are strings in the namespace (`ns=<index of NAMESPACE_URI>;
//! s=Shovel.Rtk.East`); the table [`VARIABLES`] is the one source of the
//! server's address space, the client's checks and `docs/machine-link.md`.

use std::fmt;

/// The namespace URI of the shovel PLC model.
pub const NAMESPACE_URI: &str = "urn:autoshovel:shovel-plc";

/// The data types the model uses (OPC UA built-in types).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ty {
    /// IEEE 754 double.
    Double,
    /// Unsigned 32-bit integer.
    UInt32,
    /// Unsigned 64-bit integer.
    UInt64,
    /// Unsigned byte.
    Byte,
    /// Boolean.
    Boolean,
    /// OPC UA DateTime (100 ns ticks since 1601, UTC).
    DateTime,
    /// UTF-8 string.
    String,
    /// OPC UA Duration: a Double of milliseconds.
    Duration,
}

impl Ty {
    /// The OPC UA data type node of the type.
    pub fn data_type_id(self) -> opcua::types::DataTypeId {
        use opcua::types::DataTypeId as D;
        match self {
            Ty::Double => D::Double,
            Ty::UInt32 => D::UInt32,
            Ty::UInt64 => D::UInt64,
            Ty::Byte => D::Byte,
            Ty::Boolean => D::Boolean,
            Ty::DateTime => D::DateTime,
            Ty::String => D::String,
            Ty::Duration => D::Duration,
        }
    }

    /// The OPC UA name of the type.
    pub fn name(self) -> &'static str {
        match self {
            Ty::Double => "Double",
            Ty::UInt32 => "UInt32",
            Ty::UInt64 => "UInt64",
            Ty::Byte => "Byte",
            Ty::Boolean => "Boolean",
            Ty::DateTime => "DateTime",
            Ty::String => "String",
            Ty::Duration => "Duration",
        }
    }
}

/// Who writes a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Writer {
    /// The workstation (`autoshovel drive`), with a user identity.
    Workstation,
    /// The PLC (its inverters, its receiver, its logic).
    Plc,
    /// The simulator only (`autoshovel plc-sim`; absent on a real PLC).
    Simulator,
}

impl fmt::Display for Writer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Writer::Workstation => "workstation",
            Writer::Plc => "PLC",
            Writer::Simulator => "simulator",
        })
    }
}

/// Every variable of the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[allow(missing_docs)]
pub enum Var {
    LeftSetpoint,
    LeftSpeed,
    LeftFrequency,
    LeftCurrent,
    LeftVoltage,
    RightSetpoint,
    RightSpeed,
    RightFrequency,
    RightCurrent,
    RightVoltage,
    RtkEast,
    RtkNorth,
    RtkHeading,
    RtkQuality,
    RtkTime,
    PlcTime,
    Heartbeat,
    Mode,
    FaultActive,
    FaultCode,
    FaultText,
    MaxSpeed,
    MaxAccel,
    InstanceId,
    Locked,
    LockingClient,
    LockingUser,
    RemainingLockTime,
    SimStep,
    SimStepAck,
    SimTrueX,
    SimTrueY,
    SimTrueTheta,
    SimTravelled,
}

/// One variable of the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VarSpec {
    /// Which.
    pub var: Var,
    /// The node id's string part.
    pub id: &'static str,
    /// Data type.
    pub ty: Ty,
    /// Unit ("" when none).
    pub unit: &'static str,
    /// Who writes it.
    pub writer: Writer,
    /// What it is.
    pub doc: &'static str,
}

macro_rules! var {
    ($v:ident, $id:literal, $ty:ident, $unit:literal, $w:ident, $doc:literal) => {
        VarSpec {
            var: Var::$v,
            id: $id,
            ty: Ty::$ty,
            unit: $unit,
            writer: Writer::$w,
            doc: $doc,
        }
    };
}

/// The model's variables, in the order of the docs' table.
pub const VARIABLES: &[VarSpec] = &[
    var!(LeftSetpoint, "Shovel.Crawler.Left.SpeedSetpoint", Double, "rpm", Workstation,
        "Left track motor speed setpoint; positive drives the machine forward; magnitude ≤ MaxSpeed"),
    var!(LeftSpeed, "Shovel.Crawler.Left.Speed", Double, "rpm", Plc, "Left motor actual speed (inverter)"),
    var!(LeftFrequency, "Shovel.Crawler.Left.Frequency", Double, "Hz", Plc, "Left inverter output frequency"),
    var!(LeftCurrent, "Shovel.Crawler.Left.Current", Double, "A", Plc, "Left motor current"),
    var!(LeftVoltage, "Shovel.Crawler.Left.Voltage", Double, "V", Plc, "Left motor voltage"),
    var!(RightSetpoint, "Shovel.Crawler.Right.SpeedSetpoint", Double, "rpm", Workstation,
        "Right track motor speed setpoint; positive drives the machine forward; magnitude ≤ MaxSpeed"),
    var!(RightSpeed, "Shovel.Crawler.Right.Speed", Double, "rpm", Plc, "Right motor actual speed (inverter)"),
    var!(RightFrequency, "Shovel.Crawler.Right.Frequency", Double, "Hz", Plc, "Right inverter output frequency"),
    var!(RightCurrent, "Shovel.Crawler.Right.Current", Double, "A", Plc, "Right motor current"),
    var!(RightVoltage, "Shovel.Crawler.Right.Voltage", Double, "V", Plc, "Right motor voltage"),
    var!(RtkEast, "Shovel.Rtk.East", Double, "m", Plc, "RTK antenna position, east (local grid)"),
    var!(RtkNorth, "Shovel.Rtk.North", Double, "m", Plc, "RTK position, north (local grid)"),
    var!(RtkHeading, "Shovel.Rtk.Heading", Double, "deg", Plc,
        "RTK heading ϕ from north, clockwise, of the upper works (the receiver's own convention)"),
    var!(RtkQuality, "Shovel.Rtk.FixQuality", Byte, "", Plc,
        "NMEA GGA fix quality: 0 invalid, 1 GNSS, 2 DGNSS, 4 RTK fixed, 5 RTK float"),
    var!(RtkTime, "Shovel.Rtk.Timestamp", DateTime, "", Plc, "The receiver's timestamp of the fix (UTC)"),
    var!(PlcTime, "Shovel.Clock", DateTime, "", Plc, "The PLC's clock (UTC); a pose's age is Clock − Rtk.Timestamp"),
    var!(Heartbeat, "Shovel.Workstation.Heartbeat", UInt32, "", Workstation,
        "Counter the session holding control changes every 50 ms; unchanged for 250 ms: the PLC ramps the motors to zero, latches a fault and ends the lock"),
    var!(Mode, "Shovel.Mode", Byte, "", Plc, "0 manual (setpoints ignored), 1 auto (setpoints obeyed)"),
    var!(FaultActive, "Shovel.Fault.Active", Boolean, "", Plc,
        "A latched fault: motors ramped to zero, setpoints ignored until Acknowledge"),
    var!(FaultCode, "Shovel.Fault.Code", UInt32, "", Plc,
        "0 none, 1 heartbeat lost, 2 controlling session closed, 3 setpoint rejected, 4 injected, 5 control released or broken"),
    var!(FaultText, "Shovel.Fault.Text", String, "", Plc, "What latched the fault"),
    var!(MaxSpeed, "Shovel.Limits.MotorMaxSpeed", Double, "rpm", Plc, "Motor speed limit"),
    var!(MaxAccel, "Shovel.Limits.MotorMaxAcceleration", Double, "rpm/s", Plc, "Motor acceleration limit (the PLC's ramp)"),
    var!(InstanceId, "Shovel.InstanceId", String, "", Plc,
        "This start of the PLC (its start time and process); a workstation drives only the instance it found when it started"),
    var!(Locked, "Shovel.Control.Locked", Boolean, "", Plc,
        "A session holds control of the machine (OPC 10000-100 LockingServices)"),
    var!(LockingClient, "Shovel.Control.LockingClient", String, "", Plc,
        "The controlling client: its application URI and certificate thumbprint, and its session"),
    var!(LockingUser, "Shovel.Control.LockingUser", String, "", Plc, "The user the controlling session logged in as"),
    var!(RemainingLockTime, "Shovel.Control.RemainingLockTime", Duration, "ms", Plc,
        "Time left before the lock lapses unless the holder's heartbeat or RenewLock comes (the heartbeat timeout)"),
    var!(SimStep, "Shovel.Simulator.Step", UInt64, "", Simulator,
        "Lockstep: the control period the simulator waits at (counts up)"),
    var!(SimStepAck, "Shovel.Simulator.StepAck", UInt64, "", Workstation,
        "Lockstep: the step the workstation has answered; the simulator then advances one control period"),
    var!(SimTrueX, "Shovel.Simulator.TrueX", Double, "m", Simulator, "Simulator truth: centroid x (east)"),
    var!(SimTrueY, "Shovel.Simulator.TrueY", Double, "m", Simulator, "Simulator truth: centroid y (north)"),
    var!(SimTrueTheta, "Shovel.Simulator.TrueTheta", Double, "rad", Simulator,
        "Simulator truth: crawler heading θ from east, counter-clockwise"),
    var!(SimTravelled, "Shovel.Simulator.Travelled", Double, "m", Simulator,
        "Simulator truth: distance the centroid travelled"),
];

/// The object folders, parent first.
pub const FOLDERS: &[&str] = &[
    "Shovel",
    "Shovel.Crawler",
    "Shovel.Crawler.Left",
    "Shovel.Crawler.Right",
    "Shovel.Rtk",
    "Shovel.Workstation",
    "Shovel.Fault",
    "Shovel.Limits",
    "Shovel.Control",
    "Shovel.Simulator",
];

/// The acknowledge method (component of `Shovel.Fault`): clears a latched
/// fault once both motors are at rest; needs a user identity.
pub const ACKNOWLEDGE: &str = "Shovel.Fault.Acknowledge";
/// The lock methods of `Shovel.Control` (OPC 10000-100 §7), each with an
/// Int32 status out (0 OK, −1 E_AlreadyLocked / E_NotLocked): `InitLock`
/// (String Context) claims control, `RenewLock` counts as activity,
/// `ExitLock` releases it, `BreakLock` ends another's at rest. Callers
/// need a user identity.
pub const LOCK_METHODS: &[(&str, &str)] = &[
    ("Shovel.Control.InitLock", "Claims control for this session (String Context); Int32 InitLockStatus: 0 OK, −1 E_AlreadyLocked"),
    ("Shovel.Control.RenewLock", "Counts as the holder's activity; Int32 RenewLockStatus: 0 OK, −1 E_NotLocked; BadLocked from another session"),
    ("Shovel.Control.ExitLock", "Releases control (a fault latches: the next claim moves the machine after an acknowledgement at rest); Int32 ExitLockStatus: 0 OK, −1 E_NotLocked"),
    ("Shovel.Control.BreakLock", "Ends another session's control, only with the machine at rest or its heartbeat stopped; Int32 BreakLockStatus: 0 OK, −1 E_NotLocked"),
];
/// `InitLock`.
pub const INIT_LOCK: &str = "Shovel.Control.InitLock";
/// `RenewLock`.
pub const RENEW_LOCK: &str = "Shovel.Control.RenewLock";
/// `ExitLock`.
pub const EXIT_LOCK: &str = "Shovel.Control.ExitLock";
/// `BreakLock`.
pub const BREAK_LOCK: &str = "Shovel.Control.BreakLock";
/// The simulator's fault-injection method (component of
/// `Shovel.Simulator`): arguments kind (String) and duration (s) (Double).
pub const INJECT_FAULT: &str = "Shovel.Simulator.InjectFault";

/// Fault codes of `Shovel.Fault.Code`.
pub mod fault_code {
    /// No fault.
    pub const NONE: u32 = 0;
    /// The workstation's heartbeat did not change for the timeout.
    pub const HEARTBEAT_LOST: u32 = 1;
    /// The controlling session closed (or the server timed it out).
    pub const LINK_DROPPED: u32 = 2;
    /// A setpoint out of range or not finite was written.
    pub const SETPOINT_REJECTED: u32 = 3;
    /// Injected by the simulator.
    pub const INJECTED: u32 = 4;
    /// Control was released (`ExitLock`) or broken (`BreakLock`): the
    /// next claim moves the machine only after an acknowledgement at rest.
    pub const CONTROL_ENDED: u32 = 5;
}

/// The mode values of `Shovel.Mode`.
pub mod mode {
    /// Setpoints ignored.
    pub const MANUAL: u8 = 0;
    /// Setpoints obeyed.
    pub const AUTO: u8 = 1;
}

/// The spec of `var`.
pub fn spec(var: Var) -> &'static VarSpec {
    VARIABLES
        .iter()
        .find(|s| s.var == var)
        .expect("every Var is in VARIABLES")
}

/// The folder a node id sits in.
pub fn parent(id: &str) -> &str {
    id.rsplit_once('.').map(|(p, _)| p).unwrap_or("")
}

/// The node id's last part (its browse name).
pub fn leaf(id: &str) -> &str {
    id.rsplit_once('.').map(|(_, l)| l).unwrap_or(id)
}

/// The model as a Markdown table (node id, type, unit, writer, meaning),
/// as `docs/machine-link.md` shows it.
pub fn markdown_table() -> String {
    let mut s = String::from(
        "| node id (`ns=…;s=`) | type | unit | written by | meaning |\n|---|---|---|---|---|\n",
    );
    for v in VARIABLES {
        s.push_str(&format!(
            "| `{}` | {} | {} | {} | {} |\n",
            v.id,
            v.ty.name(),
            if v.unit.is_empty() { "–" } else { v.unit },
            v.writer,
            v.doc
        ));
    }
    s.push_str(&format!(
        "| `{ACKNOWLEDGE}` | method () | – | operator (any session) | Clears a latched fault once both motors are at rest |\n"
    ));
    for (id, doc) in LOCK_METHODS {
        let args = if *id == INIT_LOCK {
            "String Context"
        } else {
            ""
        };
        s.push_str(&format!(
            "| `{id}` | method ({args}) → Int32 | – | operator | {doc} |\n"
        ));
    }
    s.push_str(&format!(
        "| `{INJECT_FAULT}` | method (String kind, Double duration_s) | – | test harness | Simulator only: injects a fault (see plc-sim) |\n"
    ));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_docs_show_the_model_as_it_is() {
        let doc = include_str!("../../../../docs/machine-link.md");
        assert!(
            doc.contains(&markdown_table()),
            "docs/machine-link.md's table differs from model::VARIABLES; paste:\n{}",
            markdown_table()
        );
    }

    #[test]
    fn every_variable_sits_in_a_folder_and_ids_are_unique() {
        let mut ids: Vec<&str> = VARIABLES.iter().map(|v| v.id).collect();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), VARIABLES.len());
        for v in VARIABLES {
            assert!(FOLDERS.contains(&parent(v.id)), "{}", v.id);
        }
        let lock_ids = LOCK_METHODS.iter().map(|m| m.0);
        assert_eq!(
            lock_ids.clone().collect::<Vec<_>>(),
            [INIT_LOCK, RENEW_LOCK, EXIT_LOCK, BREAK_LOCK]
        );
        for m in [ACKNOWLEDGE, INJECT_FAULT].into_iter().chain(lock_ids) {
            assert!(FOLDERS.contains(&parent(m)), "{m}");
        }
        for f in FOLDERS.iter().skip(1) {
            assert!(FOLDERS.contains(&parent(f)), "{f}");
        }
    }
}
