//! Control authority: which session may move the machine. The model is
//! OPC UA's own for it, the LockingServices of OPC 10000-100 (Devices,
//! §7: `InitLock`, `RenewLock`, `ExitLock`, `BreakLock`, and the
//! properties `Locked`, `LockingClient`, `LockingUser`,
//! `RemainingLockTime`), on the object `Shovel.Control`:
//!
//! - one session at a time holds control; it claims it with `InitLock`,
//!   bound to its session and to its client's certificate and user;
//! - only the holder's heartbeat, setpoints and lockstep answers count;
//!   anyone else's are refused (`BadLocked`, or `BadRequiresLock` when
//!   nobody holds control) and change nothing on the machine;
//! - the lock ends when the holder releases it (`ExitLock`), when its
//!   heartbeat stops for the watchdog's timeout (the lock's
//!   MaxInactiveLockTime), when its session closes, or when an operator
//!   breaks it at rest (`BreakLock`); each end latches a fault, so a new
//!   claim moves the machine only after a person's acknowledgement at rest;
//! - reading, browsing, discovery, connecting and disconnecting never
//!   touch the machine, whoever does them.
//!
//! Protocol-free, like [`crate::plc`]: the server tells it who calls.

use serde::Serialize;

/// Who calls: a session as the server knows it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Caller {
    /// The server's numeric id of the session.
    pub session: u32,
    /// The user the session logged in as (None: anonymous).
    pub user: Option<String>,
    /// The client application: its URI and its certificate's thumbprint.
    pub client: String,
}

impl Caller {
    /// The caller as events and `LockingUser` / `LockingClient` name it.
    pub fn describe(&self) -> String {
        format!(
            "{} on {} (session {})",
            self.user.as_deref().unwrap_or("anonymous"),
            self.client,
            self.session
        )
    }
}

/// The session holding control, and what it said when it claimed.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Holder {
    /// Who.
    pub caller: Caller,
    /// The `Context` argument of its `InitLock`.
    pub context: String,
}

/// Why a write or call was refused; none of them touches the machine
/// except [`Refusal::OutOfRange`] from the holder (a nonsense command from
/// the controller latches a fault, as a PLC treats one).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Refusal {
    /// Nobody holds control: claim it first (`BadRequiresLock`).
    RequiresLock,
    /// Another session holds control (`BadLocked`).
    Locked {
        /// Who holds it.
        by: String,
    },
    /// A setpoint outside the machine's limits or not finite (`BadOutOfRange`).
    OutOfRange(String),
    /// Not now: the machine is moving under its controller (`BadInvalidState`).
    InvalidState(String),
}

/// The statuses of OPC 10000-100's lock methods (their Int32 outputs).
pub mod lock_status {
    /// The call did what it says.
    pub const OK: i32 = 0;
    /// `InitLock`: another session holds the lock (E_AlreadyLocked).
    pub const ALREADY_LOCKED: i32 = -1;
    /// `RenewLock`, `ExitLock`, `BreakLock`: nobody holds the lock (E_NotLocked).
    pub const NOT_LOCKED: i32 = -1;
}

/// The lock: who holds control, if anyone.
#[derive(Debug, Clone, Default)]
pub struct Control {
    holder: Option<Holder>,
}

impl Control {
    /// The holder, if any.
    pub fn holder(&self) -> Option<&Holder> {
        self.holder.as_ref()
    }

    /// Whether `who` holds control.
    pub fn holds(&self, who: &Caller) -> bool {
        self.holder
            .as_ref()
            .is_some_and(|h| h.caller.session == who.session)
    }

    /// Checks that `who` may command the machine: it holds control.
    pub fn check(&self, who: &Caller) -> Result<(), Refusal> {
        match &self.holder {
            None => Err(Refusal::RequiresLock),
            Some(h) if h.caller.session == who.session => Ok(()),
            Some(h) => Err(Refusal::Locked {
                by: h.caller.describe(),
            }),
        }
    }

    /// `InitLock`: `who` takes control if nobody holds it (a claim by the
    /// holder is renewed). Returns the lock status.
    pub fn claim(&mut self, who: &Caller, context: &str) -> i32 {
        match &self.holder {
            Some(h) if h.caller.session != who.session => lock_status::ALREADY_LOCKED,
            _ => {
                self.holder = Some(Holder {
                    caller: who.clone(),
                    context: context.to_string(),
                });
                lock_status::OK
            }
        }
    }

    /// Ends the lock, whoever holds it; the holder it had.
    pub fn end(&mut self) -> Option<Holder> {
        self.holder.take()
    }
}
