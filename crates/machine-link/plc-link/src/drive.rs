//! `autoshovel drive`: the workstation on the link (walking paper §5.1,
//! Fig. 11). It opens a signed-and-encrypted OPC UA session to the PLC
//! with the operator's identity, checks the model and the machine's limits
//! against the scenario, then runs the same [`Workstation`] as `autoshovel
//! track` at the RTK rate: it reads the fix with the receiver's own
//! timestamp and the PLC's clock, decides, and writes both setpoints (and a
//! heartbeat every 50 ms from a task of its own).
//!
//! Safety on this side: a pose older than the timeout or a jump no machine
//! can make zeroes the setpoints at once (the workstation's rules); a lost
//! link is reconnected, but the machine moves again only after the PLC's
//! latched fault is acknowledged by a person (`autoshovel plc-ack`);
//! Ctrl-C, an error or the end of the run leaves zero setpoints on the PLC.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use autoshovel_core::Pose2;
use autoshovel_walk_tracker::sim::{measure, Evaluator, Event, Run, Sample};
use autoshovel_walk_tracker::{Controller, RtkFix, Setup, Status, TrackCommand, Workstation};
use opcua::client::{ClientBuilder, IdentityToken, Session};
use opcua::crypto::SecurityPolicy;
use opcua::types::{
    AttributeId, CallMethodRequest, DataValue, MessageSecurityMode, NodeId, ReadValueId,
    StatusCode, TimestampsToReturn, Variant, WriteValue,
};
use serde::Serialize;
use tokio::time::Instant;

use crate::control::lock_status;
use crate::error::LinkError;
use crate::model::{self, Var, Writer, ACKNOWLEDGE, EXIT_LOCK, INIT_LOCK, NAMESPACE_URI};
use crate::pki::{self, Role};
use autoshovel_run_log::{
    topic, EndMsg, EventMsg, LegMsg, MotorsMsg, PathMsg, RtkMsg, RunLog, TickMsg,
};

/// The run log as the loop writes it: the first error kept (the drive
/// goes on; the error is returned at the end), each control period's
/// messages made durable together ([`RunLog::sync`]), the link's events
/// written as they happen.
struct Logger<'a> {
    log: Option<&'a mut RunLog>,
    error: Option<LinkError>,
    /// Workstation and link events written so far.
    logged: (usize, usize),
}

impl Logger<'_> {
    fn write<T: Serialize>(&mut self, topic: &'static str, t: f64, msg: &T) {
        if let Some(l) = self.log.as_deref_mut() {
            if let Err(e) = l.write(topic, t, msg) {
                self.error.get_or_insert(e.into());
            }
        }
    }

    /// Writes the events not yet written, then makes the log durable.
    fn sync(&mut self, t: f64, ws_events: &[Event], link_events: &[LinkEvent]) {
        for e in &ws_events[self.logged.0.min(ws_events.len())..] {
            self.write(
                topic::EVENT,
                e.t_s,
                &EventMsg {
                    t_s: e.t_s,
                    source: "workstation".into(),
                    kind: e.kind.into(),
                    message: e.message.clone(),
                },
            );
        }
        for e in &link_events[self.logged.1.min(link_events.len())..] {
            self.write(
                topic::EVENT,
                t,
                &EventMsg {
                    t_s: e.wall_s,
                    source: "link".into(),
                    kind: e.kind.into(),
                    message: e.message.clone(),
                },
            );
        }
        self.logged = (ws_events.len(), link_events.len());
        if let Some(l) = self.log.as_deref_mut() {
            if let Err(e) = l.sync() {
                self.error.get_or_insert(e.into());
            }
        }
    }
}

/// The security policy asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Policy {
    /// Basic256Sha256, SignAndEncrypt (the default).
    Basic256Sha256,
    /// Aes256-Sha256-RsaPss, SignAndEncrypt.
    Aes256Sha256RsaPss,
    /// None (needs `insecure`).
    None,
}

impl Policy {
    fn policy(self) -> SecurityPolicy {
        match self {
            Policy::Basic256Sha256 => SecurityPolicy::Basic256Sha256,
            Policy::Aes256Sha256RsaPss => SecurityPolicy::Aes256Sha256RsaPss,
            Policy::None => SecurityPolicy::None,
        }
    }

    fn mode(self) -> MessageSecurityMode {
        match self {
            Policy::None => MessageSecurityMode::None,
            _ => MessageSecurityMode::SignAndEncrypt,
        }
    }
}

/// How to reach and log in to the PLC.
#[derive(Debug, Clone)]
pub struct LinkParams {
    /// `opc.tcp://HOST:PORT/`.
    pub endpoint: String,
    /// PKI root (holding `workstation/`).
    pub pki: PathBuf,
    /// Security policy.
    pub policy: Policy,
    /// Allow security None.
    pub insecure: bool,
    /// User name and password (None: anonymous, which can only read).
    pub user: Option<(String, String)>,
    /// Give up when the link stays down this long.
    pub link_timeout: Duration,
    /// Give up waiting for an acknowledgement after this long.
    pub ack_timeout: Duration,
    /// Seconds to wait for the first answer.
    pub connect_timeout: Duration,
}

impl LinkParams {
    /// Defaults for `endpoint` with the PKI root `pki` and the operator's password file in it.
    pub fn new(endpoint: &str, pki: PathBuf, user: Option<(String, String)>) -> Self {
        Self {
            endpoint: endpoint.to_string(),
            pki,
            policy: Policy::Basic256Sha256,
            insecure: false,
            user,
            link_timeout: Duration::from_secs(30),
            ack_timeout: Duration::from_secs(600),
            connect_timeout: Duration::from_secs(10),
        }
    }
}

/// An open session to a PLC of the model, its node ids resolved.
pub struct Link {
    /// The session.
    pub session: Arc<Session>,
    /// The endpoint URL.
    pub endpoint: String,
    ns: u16,
    /// Whether the PLC has the `Simulator` folder (it is `plc-sim`).
    pub simulator: bool,
    /// The PLC's `Shovel.InstanceId` when the session opened: a PLC that
    /// answers with another is a restarted one, and is not driven.
    pub instance: String,
    event_loop: tokio::task::JoinHandle<StatusCode>,
}

/// What the link saw, in the summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinkEvent {
    /// Wall-clock time since the run started (s).
    pub wall_s: f64,
    /// Kind: `link-lost`, `link-restored`, `plc-fault`, `acknowledged`, `interrupted`, `zeroed`.
    pub kind: &'static str,
    /// Human text.
    pub message: String,
}

fn connect_err(endpoint: &str, why: impl Into<String>) -> LinkError {
    LinkError::Connect {
        endpoint: endpoint.to_string(),
        why: why.into(),
        source: None,
    }
}

/// A session that did not open for the stack's `source`, with the hint
/// [`explain`] finds in its words.
fn connect_failed(
    endpoint: &str,
    source: opcua::types::Error,
    pki_root: &std::path::Path,
) -> LinkError {
    let why = explain(&source.to_string(), pki_root);
    LinkError::Connect {
        endpoint: endpoint.to_string(),
        why,
        source: Some(source),
    }
}

/// A service call that failed in the stack or on the wire.
fn service_err(endpoint: &str, service: &'static str, source: opcua::types::Error) -> LinkError {
    LinkError::Service {
        endpoint: endpoint.to_string(),
        service,
        source,
    }
}

impl Link {
    /// Opens a session: the workstation's certificate (made under
    /// `pki/workstation` if missing), the server's checked against the
    /// trust list, the policy asked for, the user's identity.
    pub async fn open(p: &LinkParams) -> Result<Link, LinkError> {
        if p.policy == Policy::None && !p.insecure {
            return Err(LinkError::InsecureRefused {
                endpoint: p.endpoint.clone(),
            });
        }
        if let (Policy::None, Some((user, _))) = (p.policy, &p.user) {
            return Err(LinkError::PasswordInClear {
                endpoint: p.endpoint.clone(),
                user: user.clone(),
            });
        }
        if p.policy == Policy::None {
            eprintln!(
                "drive: WARNING: security None on {} (--insecure): setpoints travel unsigned and unencrypted",
                p.endpoint
            );
        }
        pki::ensure(&p.pki, Role::Workstation, &[])?;
        let mut client = ClientBuilder::new()
            .application_name(Role::Workstation.application_name())
            .application_uri(Role::Workstation.application_uri())
            .product_uri("urn:autoshovel")
            .pki_dir(pki::role_dir(&p.pki, Role::Workstation))
            .create_sample_keypair(false)
            .trust_server_certs(false)
            .verify_server_certs(true)
            .session_retry_limit(-1)
            .session_retry_initial(Duration::from_millis(100))
            .session_retry_max(Duration::from_millis(500))
            .keep_alive_interval(Duration::from_millis(500))
            .request_timeout(Duration::from_millis(2000))
            .session_timeout(5_000)
            .client()
            .map_err(|e| connect_err(&p.endpoint, e.join("; ")))?;
        let identity = match &p.user {
            Some((u, pw)) => IdentityToken::UserName(u.clone(), pw.clone().into()),
            None => IdentityToken::Anonymous,
        };
        // The endpoint as the server describes it, but reached at the URL
        // the user gave (the server may sit behind a relay, a NAT or a
        // port forward and name an address the workstation cannot use).
        let found = tokio::time::timeout(
            p.connect_timeout,
            client.get_server_endpoints_from_url(p.endpoint.as_str()),
        )
        .await
        .map_err(|_| connect_err(&p.endpoint, "no answer (is plc-sim running there?)"))?
        .map_err(|e| connect_failed(&p.endpoint, e, &p.pki))?;
        let policy_uri = p.policy.policy().to_uri();
        let mut endpoint = found
            .into_iter()
            .find(|e| {
                e.security_policy_uri.as_ref() == policy_uri && e.security_mode == p.policy.mode()
            })
            .ok_or_else(|| {
                connect_err(
                    &p.endpoint,
                    format!(
                        "the server offers no {} {:?} endpoint{}",
                        p.policy.policy(),
                        p.policy.mode(),
                        if p.policy == Policy::None {
                            " (start plc-sim with --insecure)"
                        } else {
                            ""
                        }
                    ),
                )
            })?;
        endpoint.endpoint_url = p.endpoint.as_str().into();
        // Our own check of the PLC's certificate, before any session: pinned
        // to the trust list, named when it fails (the stack would retry
        // until the timeout and say only that the session did not open).
        if p.policy != Policy::None {
            pki::check_peer(
                &p.pki,
                Role::Workstation,
                endpoint.server_certificate.as_ref(),
                &p.endpoint,
            )?;
        }
        let (session, event_loop) = client
            .connect_to_endpoint_directly(endpoint, identity)
            .map_err(|e| connect_failed(&p.endpoint, e, &p.pki))?;
        let event_loop = event_loop.spawn();
        let ok = tokio::time::timeout(p.connect_timeout, session.wait_for_connection())
            .await
            .unwrap_or(false);
        if !ok {
            event_loop.abort();
            // The PLC's certificate is trusted here (checked above), so the
            // likely cause is the other side's trust list, or the identity.
            let own = pki::own_cert(&p.pki, Role::Workstation);
            return Err(connect_err(
                &p.endpoint,
                format!(
                    "the session did not open within {:.0} s: the PLC may not trust this workstation's certificate ({}): on the PLC, `autoshovel pki trust --dir PKI/plc {}` (or move it out of the PLC's rejected/ folder); or the user name or password was refused",
                    p.connect_timeout.as_secs_f64(),
                    own.display(),
                    own.display()
                ),
            ));
        }
        let ns = session
            .get_namespace_index(NAMESPACE_URI)
            .await
            .map_err(|_| LinkError::Model {
                endpoint: p.endpoint.clone(),
                node: "Server.NamespaceArray".into(),
                why: format!("the namespace {NAMESPACE_URI} is not on this server"),
            })?;
        let mut link = Link {
            session,
            endpoint: p.endpoint.clone(),
            ns,
            simulator: false,
            instance: String::new(),
            event_loop,
        };
        link.check_model().await?;
        link.instance = link.read_instance().await?;
        Ok(link)
    }

    /// The node id of `var`.
    pub fn id(&self, var: Var) -> NodeId {
        NodeId::new(self.ns, model::spec(var).id)
    }

    /// Checks that every node of the model is there with its type (the
    /// `Simulator` folder may be missing).
    async fn check_model(&mut self) -> Result<(), LinkError> {
        let ids: Vec<ReadValueId> = model::VARIABLES
            .iter()
            .map(|v| ReadValueId::new(NodeId::new(self.ns, v.id), AttributeId::DataType))
            .collect();
        let got = self
            .session
            .read(&ids, TimestampsToReturn::Neither, 0.0)
            .await
            .map_err(|e| service_err(&self.endpoint, "read", e))?;
        let mut sim_nodes = 0;
        for (v, dv) in model::VARIABLES.iter().zip(got) {
            let status = dv.status.unwrap_or(StatusCode::Good);
            if status.is_bad() {
                if v.writer == Writer::Simulator || v.var == Var::SimStepAck {
                    continue;
                }
                return Err(LinkError::Model {
                    endpoint: self.endpoint.clone(),
                    node: format!("ns={};s={}", self.ns, v.id),
                    why: format!("missing ({status})"),
                });
            }
            if v.writer == Writer::Simulator {
                sim_nodes += 1;
            }
            let want: NodeId = v.ty.data_type_id().into();
            match dv.value {
                Some(Variant::NodeId(ref t)) if **t == want => {}
                other => {
                    return Err(LinkError::Model {
                        endpoint: self.endpoint.clone(),
                        node: format!("ns={};s={}", self.ns, v.id),
                        why: format!(
                            "data type is {} but the model says {}",
                            other
                                .map(|o| o.to_string())
                                .unwrap_or_else(|| "none".into()),
                            v.ty.name()
                        ),
                    })
                }
            }
        }
        self.simulator = sim_nodes
            == model::VARIABLES
                .iter()
                .filter(|v| v.writer == Writer::Simulator)
                .count();
        Ok(())
    }

    /// Writes both setpoints (and the lockstep answer on a simulator) in one request.
    pub async fn write_setpoints(
        &self,
        cmd: TrackCommand,
        step_ack: Option<u64>,
    ) -> Result<(), LinkError> {
        let mut w = vec![
            write(self.id(Var::LeftSetpoint), Variant::Double(cmd.left_rpm)),
            write(self.id(Var::RightSetpoint), Variant::Double(cmd.right_rpm)),
        ];
        if let (true, Some(s)) = (self.simulator, step_ack) {
            w.push(write(self.id(Var::SimStepAck), Variant::UInt64(s)));
        }
        let res = self
            .session
            .write(&w)
            .await
            .map_err(|e| service_err(&self.endpoint, "write", e))?;
        for (wv, st) in w.iter().zip(res) {
            if st.is_bad() {
                return Err(LinkError::Refused {
                    endpoint: self.endpoint.clone(),
                    what: format!("write of {}", wv.node_id),
                    status: explain_status(st),
                });
            }
        }
        Ok(())
    }

    /// The PLC's `Shovel.InstanceId` now.
    async fn read_instance(&self) -> Result<String, LinkError> {
        let got = self
            .session
            .read(
                &[self.id(Var::InstanceId).into()],
                TimestampsToReturn::Neither,
                0.0,
            )
            .await
            .map_err(|e| service_err(&self.endpoint, "read", e))?;
        let mut r = Reader {
            link: self,
            vals: vec![(Var::InstanceId, got.into_iter().next().unwrap_or_default())],
        };
        r.string(Var::InstanceId)
    }

    /// Calls a method of the model on its object with `args`; its outputs.
    async fn call(&self, method: &str, args: Vec<Variant>) -> Result<Vec<Variant>, LinkError> {
        let object = NodeId::new(self.ns, model::parent(method));
        let req: CallMethodRequest = (object, NodeId::new(self.ns, method), Some(args)).into();
        let r = self
            .session
            .call_one(req)
            .await
            .map_err(|e| service_err(&self.endpoint, "method call", e))?;
        if r.status_code.is_bad() {
            return Err(LinkError::Refused {
                endpoint: self.endpoint.clone(),
                what: model::leaf(method).to_string(),
                status: explain_status(r.status_code),
            });
        }
        Ok(r.output_arguments.unwrap_or_default())
    }

    /// Claims control of the machine for this session (`InitLock`); a
    /// claim by the holder renews it. Another session holding control is
    /// [`LinkError::ControlHeld`].
    pub async fn claim(&self) -> Result<(), LinkError> {
        let out = self
            .call(INIT_LOCK, vec![Variant::from("autoshovel drive")])
            .await?;
        match out.first() {
            Some(Variant::Int32(lock_status::OK)) => Ok(()),
            Some(Variant::Int32(lock_status::ALREADY_LOCKED)) => Err(LinkError::ControlHeld {
                endpoint: self.endpoint.clone(),
                by: self.holder().await,
            }),
            other => Err(LinkError::BadValue {
                endpoint: self.endpoint.clone(),
                node: format!("ns={};s={INIT_LOCK}", self.ns),
                value: format!("{other:?}"),
                why: "InitLockStatus is not 0 or -1".into(),
            }),
        }
    }

    /// Who holds control, as `LockingUser` on `LockingClient` say.
    async fn holder(&self) -> String {
        let ids = [Var::LockingUser, Var::LockingClient];
        let read: Vec<ReadValueId> = ids.iter().map(|v| self.id(*v).into()).collect();
        let Ok(got) = self
            .session
            .read(&read, TimestampsToReturn::Neither, 0.0)
            .await
        else {
            return "another session".into();
        };
        let mut r = Reader {
            link: self,
            vals: ids.into_iter().zip(got).collect(),
        };
        match (r.string(Var::LockingUser), r.string(Var::LockingClient)) {
            (Ok(u), Ok(c)) => format!("{u} on {c}"),
            _ => "another session".into(),
        }
    }

    /// A task writing this session's heartbeat every 50 ms until aborted:
    /// for tools that hold control without a control loop (benchmarks,
    /// tests). `drive` keeps its own, tied to its loop coming round.
    pub fn keep_heartbeat(&self) -> tokio::task::JoinHandle<()> {
        let session = self.session.clone();
        let id = self.id(Var::Heartbeat);
        tokio::spawn(async move {
            let mut n: u32 = 1;
            let mut iv = tokio::time::interval(HEARTBEAT_PERIOD);
            loop {
                iv.tick().await;
                let _ = session
                    .write(&[write(id.clone(), Variant::UInt32(n))])
                    .await;
                n = n.wrapping_add(1);
            }
        })
    }

    /// Releases control (`ExitLock`).
    pub async fn release(&self) -> Result<(), LinkError> {
        self.call(EXIT_LOCK, Vec::new()).await.map(|_| ())
    }

    /// Calls the acknowledge method.
    pub async fn acknowledge(&self) -> Result<(), LinkError> {
        self.call(ACKNOWLEDGE, Vec::new()).await.map(|_| ())
    }

    /// Calls the simulator's fault injection.
    pub async fn inject(&self, kind: &str, value: f64) -> Result<(), LinkError> {
        self.call(
            model::INJECT_FAULT,
            vec![Variant::from(kind), Variant::Double(value)],
        )
        .await
        .map(|_| ())
    }

    /// Reads the values the workstation needs, in one request.
    pub async fn read_state(&self) -> Result<PlcState, LinkError> {
        const VARS: &[Var] = &[
            Var::PlcTime,
            Var::RtkEast,
            Var::RtkNorth,
            Var::RtkHeading,
            Var::RtkQuality,
            Var::RtkTime,
            Var::LeftSpeed,
            Var::RightSpeed,
            Var::FaultActive,
            Var::FaultText,
            Var::Mode,
            Var::MaxSpeed,
            Var::MaxAccel,
            Var::LeftFrequency,
            Var::LeftCurrent,
            Var::LeftVoltage,
            Var::RightFrequency,
            Var::RightCurrent,
            Var::RightVoltage,
            Var::InstanceId,
            Var::SimStep,
            Var::SimTrueX,
            Var::SimTrueY,
            Var::SimTrueTheta,
            Var::SimTravelled,
        ];
        // The Simulator folder's five come last.
        let n = if self.simulator {
            VARS.len()
        } else {
            VARS.len() - 5
        };
        let ids: Vec<ReadValueId> = VARS[..n].iter().map(|v| self.id(*v).into()).collect();
        let got = self
            .session
            .read(&ids, TimestampsToReturn::Neither, 0.0)
            .await
            .map_err(|e| service_err(&self.endpoint, "read", e))?;
        let mut r = Reader {
            link: self,
            vals: VARS.iter().copied().zip(got).collect(),
        };
        let instance = r.string(Var::InstanceId)?;
        if instance != self.instance {
            return Err(LinkError::PlcRestarted {
                endpoint: self.endpoint.clone(),
                was: self.instance.clone(),
                now: instance,
            });
        }
        Ok(PlcState {
            clock_ticks: r.ticks(Var::PlcTime)?,
            east_m: r.f64(Var::RtkEast)?,
            north_m: r.f64(Var::RtkNorth)?,
            heading_deg: r.f64(Var::RtkHeading)?,
            quality: r.byte(Var::RtkQuality)?,
            fix_ticks: r.ticks(Var::RtkTime)?,
            left_rpm: r.f64(Var::LeftSpeed)?,
            right_rpm: r.f64(Var::RightSpeed)?,
            fault: r.bool(Var::FaultActive)?,
            fault_text: r.string(Var::FaultText)?,
            mode: r.byte(Var::Mode)?,
            max_rpm: r.f64(Var::MaxSpeed)?,
            max_accel: r.f64(Var::MaxAccel)?,
            motors: [
                [
                    r.f64(Var::LeftFrequency)?,
                    r.f64(Var::LeftCurrent)?,
                    r.f64(Var::LeftVoltage)?,
                ],
                [
                    r.f64(Var::RightFrequency)?,
                    r.f64(Var::RightCurrent)?,
                    r.f64(Var::RightVoltage)?,
                ],
            ],
            step: if self.simulator {
                Some(r.u64(Var::SimStep)?)
            } else {
                None
            },
            truth: if self.simulator {
                Some((
                    Pose2::new(
                        r.f64(Var::SimTrueX)?,
                        r.f64(Var::SimTrueY)?,
                        r.f64(Var::SimTrueTheta)?,
                    ),
                    r.f64(Var::SimTravelled)?,
                ))
            } else {
                None
            },
        })
    }

    /// Closes the session.
    pub async fn close(self) {
        let _ = tokio::time::timeout(Duration::from_secs(2), self.session.disconnect()).await;
        self.event_loop.abort();
    }
}

fn write(node_id: NodeId, v: Variant) -> WriteValue {
    WriteValue {
        node_id,
        attribute_id: AttributeId::Value as u32,
        index_range: Default::default(),
        value: DataValue::value_only(v),
    }
}

fn explain_status(st: StatusCode) -> String {
    let hint = if st == StatusCode::BadLocked {
        " (another session holds control of the machine)"
    } else if st == StatusCode::BadRequiresLock {
        " (this session does not hold control: it was released or lost)"
    } else if st == StatusCode::BadUserAccessDenied || st == StatusCode::BadNotWritable {
        " (the session's identity may not write: log in as the operator)"
    } else if st == StatusCode::BadOutOfRange {
        " (outside the machine's limits; the PLC latched a fault)"
    } else if st == StatusCode::BadInvalidState {
        " (acknowledge only once both motors are at rest)"
    } else {
        ""
    };
    format!("{st}{hint}")
}

fn explain(e: &str, pki_root: &std::path::Path) -> String {
    let lower = e.to_lowercase();
    let hint = if lower.contains("certificate")
        || lower.contains("untrusted")
        || lower.contains("security")
    {
        format!(
            "; if the server's certificate is not trusted yet it is now in {}/rejected: check it and run `autoshovel pki trust --dir {} CERT`",
            pki::role_dir(pki_root, Role::Workstation).display(),
            pki::role_dir(pki_root, Role::Workstation).display()
        )
    } else if lower.contains("identity") || lower.contains("user") {
        "; the user name or password was refused".to_string()
    } else if lower.contains("refused") || lower.contains("connect") {
        "; is plc-sim (or the PLC) running and reachable there?".to_string()
    } else {
        String::new()
    };
    format!("{e}{hint}")
}

/// What one read gives.
#[derive(Debug, Clone, PartialEq)]
pub struct PlcState {
    /// PLC clock (100 ns ticks).
    pub clock_ticks: i64,
    /// Fix east (m).
    pub east_m: f64,
    /// Fix north (m).
    pub north_m: f64,
    /// Fix heading, north clockwise (deg).
    pub heading_deg: f64,
    /// Fix quality (NMEA).
    pub quality: u8,
    /// Fix timestamp (ticks) (0: none yet).
    pub fix_ticks: i64,
    /// Left motor (rpm).
    pub left_rpm: f64,
    /// Right motor (rpm).
    pub right_rpm: f64,
    /// A latched fault.
    pub fault: bool,
    /// Its text.
    pub fault_text: String,
    /// Mode.
    pub mode: u8,
    /// Motor limit (rpm).
    pub max_rpm: f64,
    /// Acceleration limit (rpm/s).
    pub max_accel: f64,
    /// Inverter frequency (Hz), current (A), voltage (V) (left, right).
    pub motors: [[f64; 3]; 2],
    /// Lockstep step (simulator only).
    pub step: Option<u64>,
    /// Truth pose and distance (simulator only).
    pub truth: Option<(Pose2, f64)>,
}

struct Reader<'a> {
    link: &'a Link,
    vals: Vec<(Var, DataValue)>,
}

impl Reader<'_> {
    fn get(&mut self, var: Var) -> Result<Variant, LinkError> {
        let i = self.vals.iter().position(|(v, _)| *v == var);
        let dv = i.map(|i| self.vals[i].1.clone()).unwrap_or_default();
        match dv.value {
            Some(v) if dv.status.map(|s| s.is_good()).unwrap_or(true) => Ok(v),
            _ => Err(self.bad(var, "no value".into(), format!("status {:?}", dv.status))),
        }
    }

    fn bad(&self, var: Var, value: String, why: String) -> LinkError {
        LinkError::BadValue {
            endpoint: self.link.endpoint.clone(),
            node: format!("ns={};s={}", self.link.ns, model::spec(var).id),
            value,
            why,
        }
    }

    fn f64(&mut self, var: Var) -> Result<f64, LinkError> {
        match self.get(var)? {
            Variant::Double(x) if x.is_finite() => Ok(x),
            Variant::Double(x) => Err(self.bad(var, x.to_string(), "not a finite number".into())),
            other => Err(self.bad(var, other.to_string(), "not a Double".into())),
        }
    }

    fn byte(&mut self, var: Var) -> Result<u8, LinkError> {
        match self.get(var)? {
            Variant::Byte(x) => Ok(x),
            other => Err(self.bad(var, other.to_string(), "not a Byte".into())),
        }
    }

    fn u64(&mut self, var: Var) -> Result<u64, LinkError> {
        match self.get(var)? {
            Variant::UInt64(x) => Ok(x),
            other => Err(self.bad(var, other.to_string(), "not a UInt64".into())),
        }
    }

    fn bool(&mut self, var: Var) -> Result<bool, LinkError> {
        match self.get(var)? {
            Variant::Boolean(x) => Ok(x),
            other => Err(self.bad(var, other.to_string(), "not a Boolean".into())),
        }
    }

    fn string(&mut self, var: Var) -> Result<String, LinkError> {
        match self.get(var)? {
            Variant::String(x) => Ok(x.as_ref().to_string()),
            other => Err(self.bad(var, other.to_string(), "not a String".into())),
        }
    }

    fn ticks(&mut self, var: Var) -> Result<i64, LinkError> {
        match self.get(var)? {
            Variant::DateTime(x) => Ok(if x.is_null() { 0 } else { x.ticks() }),
            other => Err(self.bad(var, other.to_string(), "not a DateTime".into())),
        }
    }
}

/// A finished drive.
#[derive(Debug, Clone)]
pub struct DriveRun {
    /// Samples, events and metrics, as `autoshovel track` gives them.
    pub run: Run,
    /// What the link saw.
    pub link_events: Vec<LinkEvent>,
    /// Whether the metrics are on the simulator's truth (else on the fixes).
    pub truth: bool,
    /// Round trips of the state read (ms).
    pub read_ms: Vec<f64>,
    /// Round trips of the setpoint write (ms).
    pub write_ms: Vec<f64>,
}

/// Ticks of 100 ns per second.
const TICKS: f64 = 1e7;

/// The heartbeat's period: 50 ms, a fifth of the PLC's timeout
/// ([`crate::HEARTBEAT_TIMEOUT`]).
pub const HEARTBEAT_PERIOD: Duration = Duration::from_millis(50);

/// On the link the workstation treats a pose as stale this much before the
/// scenario's `pose_timeout_s`: the margin covers a poll (5 ms) and the
/// setpoint write's round trip, so the setpoints are zero by the time the
/// pose is `pose_timeout_s` old.
pub const STALE_MARGIN_S: f64 = 0.05;

/// How long a drive may take and wait, and its stop switch.
#[derive(Debug, Clone)]
pub struct DriveOptions {
    /// Give up after this much machine time (s).
    pub t_limit_s: f64,
    /// Give up waiting for a fault's acknowledgement after this long.
    pub ack_timeout: Duration,
    /// Give up when the link stays down this long.
    pub link_timeout: Duration,
    /// Set (by Ctrl-C) to zero the setpoints and end the run.
    pub stop: Arc<AtomicBool>,
}

impl DriveOptions {
    /// The options for `setup` (its time limit) with `params`' timeouts.
    pub fn new(setup: &Setup, params: &LinkParams) -> Self {
        Self {
            t_limit_s: autoshovel_walk_tracker::sim::worst_case(setup).0,
            ack_timeout: params.ack_timeout,
            link_timeout: params.link_timeout,
            stop: Arc::new(AtomicBool::new(false)),
        }
    }
}

/// A whole drive as `autoshovel drive` runs it: the link to `params`
/// opened, the run log begun at `log_path` once it is up (the record of a
/// run, with `metadata`), `setup`'s legs driven with `controller`, then the
/// link closed and the log finished whatever happened (the setpoints are
/// zero at every end of [`drive`]). Returns the run and the log's path.
pub async fn drive_logged(
    params: &LinkParams,
    setup: &Setup,
    controller: &mut dyn Controller,
    opts: &DriveOptions,
    log_path: &std::path::Path,
    metadata: &[(&str, String)],
    overwrite_log: bool,
) -> Result<(DriveRun, PathBuf), LinkError> {
    let link = Link::open(params).await?;
    let mut log = match RunLog::create(log_path, metadata, overwrite_log) {
        Ok(log) => log,
        Err(e) => {
            link.close().await;
            return Err(e.into());
        }
    };
    let run = drive(&link, setup, controller, opts, Some(&mut log)).await;
    link.close().await;
    // Why the run ended, as the log's last event; the log is kept whatever happened.
    let why = match &run {
        Ok(r) if r.run.metrics.completed => "the path was driven to its end".to_string(),
        Ok(r) => format!(
            "stopped before the path's end ({})",
            r.run
                .events
                .last()
                .map(|e| e.message.as_str())
                .unwrap_or("no event")
        ),
        Err(e) => autoshovel_core::error_chain(e),
    };
    let t = log.last_t_s();
    let ended = log.write(
        topic::EVENT,
        t,
        &EventMsg {
            t_s: t,
            source: "link".into(),
            kind: "end".into(),
            message: why,
        },
    );
    let logged = ended.and_then(|()| log.finish());
    Ok((run?, logged?))
}

/// Drives `setup`'s legs on the PLC behind `link` with `controller`,
/// logging to `log` when given; `opts.stop` set (Ctrl-C) zeroes the
/// setpoints and ends the run.
pub async fn drive(
    link: &Link,
    setup: &Setup,
    controller: &mut dyn Controller,
    opts: &DriveOptions,
    mut log: Option<&mut RunLog>,
) -> Result<DriveRun, LinkError> {
    let (t_limit_s, ack_timeout, link_timeout, stop) = (
        opts.t_limit_s,
        opts.ack_timeout,
        opts.link_timeout,
        opts.stop.clone(),
    );
    let first = match start_checks(link, setup).await {
        Ok(s) => s,
        Err(e) => {
            // Whatever the PLC holds, it holds zero setpoints from us.
            let _ = zero_setpoints(link).await;
            return Err(e);
        }
    };
    // Control of the machine, for this session only, just before the
    // heartbeat that keeps it.
    link.claim().await?;
    if let Some(log) = log.as_deref_mut() {
        log.set_origin_ticks(first.clock_ticks);
        log.write(
            topic::PATH,
            0.0,
            &PathMsg {
                legs: setup.legs.iter().map(LegMsg::of).collect(),
            },
        )?;
    }
    // Heartbeat: its own task, every 50 ms, but it counts on only while
    // the control loop has come round within the last 200 ms: a stalled
    // loop stops the heartbeat, and the PLC the machine.
    let hb_stop = Arc::new(AtomicBool::new(false));
    let alive = Arc::new(AtomicU64::new(0));
    let clock = Instant::now();
    let hb = {
        let session = link.session.clone();
        let id = link.id(Var::Heartbeat);
        let hb_stop = hb_stop.clone();
        let alive = alive.clone();
        tokio::spawn(async move {
            let mut n: u32 = 1;
            let mut iv = tokio::time::interval(HEARTBEAT_PERIOD);
            while !hb_stop.load(Ordering::Relaxed) {
                iv.tick().await;
                let last = alive.load(Ordering::Relaxed);
                let now = clock.elapsed().as_millis() as u64;
                if now.saturating_sub(last) > 200 {
                    continue;
                }
                let _ = session
                    .write(&[write(id.clone(), Variant::UInt32(n))])
                    .await;
                n = n.wrapping_add(1);
            }
        })
    };
    let result = run_loop(
        link,
        setup,
        controller,
        t_limit_s,
        ack_timeout,
        link_timeout,
        &stop,
        first,
        &|| alive.store(clock.elapsed().as_millis() as u64, Ordering::Relaxed),
        log,
    )
    .await;
    // Whatever happened: zero setpoints, stop the heartbeat, release
    // control (the PLC then wants an acknowledgement before the next claim
    // moves the machine; if the release does not arrive, the watchdog ends
    // the lock the same way).
    let zero = zero_setpoints(link).await;
    hb_stop.store(true, Ordering::Relaxed);
    let _ = hb.await;
    let _ = link.release().await;
    let mut run = result?;
    if zero.is_err() {
        run.link_events.push(LinkEvent {
            wall_s: f64::NAN,
            kind: "zeroed",
            message: "could not confirm zero setpoints at the end (link down): the PLC's watchdog stops the machine".into(),
        });
    }
    Ok(run)
}

/// The PLC's state at the start, after checking the machine, the mode and the fault.
async fn start_checks(link: &Link, setup: &Setup) -> Result<PlcState, LinkError> {
    let first = link.read_state().await?;
    plausible(link, &first)?;
    check_machine(link, setup, &first)?;
    if first.mode != model::mode::AUTO {
        return Err(LinkError::Manual {
            endpoint: link.endpoint.clone(),
        });
    }
    if first.fault {
        return Err(LinkError::Refused {
            endpoint: link.endpoint.clone(),
            what: "start".into(),
            status: format!(
                "the PLC has a latched fault ({}); acknowledge it at rest with `autoshovel plc-ack --endpoint {}`",
                first.fault_text, link.endpoint
            ),
        });
    }
    Ok(first)
}

/// Writes zero setpoints, three tries.
pub async fn zero_setpoints(link: &Link) -> Result<(), LinkError> {
    let mut last = Ok(());
    for _ in 0..3 {
        last = link.write_setpoints(TrackCommand::STOP, None).await;
        if last.is_ok() {
            return last;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    last
}

fn check_machine(link: &Link, setup: &Setup, s: &PlcState) -> Result<(), LinkError> {
    let c = &setup.crawler;
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * a.abs().max(b.abs()).max(1.0);
    if !close(c.motor_max_rpm, s.max_rpm) {
        return Err(LinkError::Mismatch {
            endpoint: link.endpoint.clone(),
            what: "motor speed limit [rpm]",
            node: model::spec(Var::MaxSpeed).id.into(),
            scenario: c.motor_max_rpm.to_string(),
            plc: s.max_rpm.to_string(),
        });
    }
    if !close(c.motor_max_accel_rpm_per_s, s.max_accel) {
        return Err(LinkError::Mismatch {
            endpoint: link.endpoint.clone(),
            what: "motor acceleration limit [rpm/s]",
            node: model::spec(Var::MaxAccel).id.into(),
            scenario: c.motor_max_accel_rpm_per_s.to_string(),
            plc: s.max_accel.to_string(),
        });
    }
    Ok(())
}

fn plausible(link: &Link, s: &PlcState) -> Result<(), LinkError> {
    for (var, v) in [(Var::LeftSpeed, s.left_rpm), (Var::RightSpeed, s.right_rpm)] {
        if v.abs() > 1.5 * s.max_rpm {
            return Err(LinkError::BadValue {
                endpoint: link.endpoint.clone(),
                node: format!("ns={};s={}", link.ns, model::spec(var).id),
                value: v.to_string(),
                why: format!("beyond 1.5 × the motor limit {} rpm", s.max_rpm),
            });
        }
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
async fn run_loop(
    link: &Link,
    setup: &Setup,
    controller: &mut dyn Controller,
    t_limit_s: f64,
    ack_timeout: Duration,
    link_timeout: Duration,
    stop: &AtomicBool,
    first: PlcState,
    alive: &dyn Fn(),
    mut log: Option<&mut RunLog>,
) -> Result<DriveRun, LinkError> {
    let mut logger = Logger {
        log: log.take(),
        error: None,
        logged: (0, 0),
    };
    let wall0 = Instant::now();
    let wall = || wall0.elapsed().as_secs_f64();
    let origin = first.clock_ticks;
    let secs = |ticks: i64| (ticks - origin) as f64 / TICKS;
    let mut sp = setup.sim;
    sp.pose_timeout_s = (sp.pose_timeout_s - STALE_MARGIN_S).max(0.0);
    let mut ws = Workstation::new(&setup.legs, setup.crawler, sp, controller, t_limit_s);
    let mut eval = Evaluator::new();
    let mut samples: Vec<Sample> = Vec::new();
    let mut link_events = Vec::new();
    let mut read_ms = Vec::new();
    let mut write_ms = Vec::new();
    let control_dt = 1.0 / setup.sim.control_rate_hz;
    let mut last_fix_ticks = 0i64;
    let mut last_step: Option<u64> = None;
    let mut last_tick_t = f64::NEG_INFINITY;
    let mut lost_since: Option<f64> = None;
    let mut faulted_since: Option<f64> = None;
    let mut travelled_measured = 0.0;
    let mut last_measured: Option<Pose2> = None;
    let mut state = first;
    let mut fresh = true;
    let mut stopped_wait: Option<f64> = None;
    let status = loop {
        alive();
        logger.sync(secs(state.clock_ticks), &ws.events, &link_events);
        if stop.load(Ordering::Relaxed) {
            link_events.push(LinkEvent {
                wall_s: wall(),
                kind: "interrupted",
                message: "Ctrl-C: setpoints zeroed".into(),
            });
            return Err(LinkError::Interrupted {
                endpoint: link.endpoint.clone(),
            });
        }
        if !fresh {
            let t0 = Instant::now();
            match link.read_state().await {
                Ok(s) => {
                    read_ms.push(t0.elapsed().as_secs_f64() * 1e3);
                    if let Some(since) = lost_since.take() {
                        link_events.push(LinkEvent {
                            wall_s: wall(),
                            kind: "link-restored",
                            message: format!("link back after {:.2} s", wall() - since),
                        });
                    }
                    state = s;
                }
                // A value that cannot be right, or another PLC: never retried.
                Err(
                    e @ (LinkError::BadValue { .. }
                    | LinkError::Model { .. }
                    | LinkError::PlcRestarted { .. }),
                ) => return Err(e),
                Err(e) => {
                    match lost_since {
                        None => {
                            lost_since = Some(wall());
                            link_events.push(LinkEvent {
                                wall_s: wall(),
                                kind: "link-lost",
                                message: format!(
                                    "{}; reconnecting (the PLC stops the machine on its own watchdog)",
                                    autoshovel_core::error_chain(&e)
                                ),
                            });
                            ws.halt();
                        }
                        Some(since) if wall() - since > link_timeout.as_secs_f64() => {
                            return Err(LinkError::LinkLost {
                                endpoint: link.endpoint.clone(),
                                secs: wall() - since,
                                limit_s: link_timeout.as_secs_f64(),
                            })
                        }
                        _ => {}
                    }
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                }
            }
        }
        fresh = false;
        plausible(link, &state)?;
        let t = secs(state.clock_ticks);
        if state.fault {
            if faulted_since.is_none() {
                faulted_since = Some(wall());
                ws.halt();
                link_events.push(LinkEvent {
                    wall_s: wall(),
                    kind: "plc-fault",
                    message: format!(
                        "PLC fault latched: {}; waiting for an acknowledgement (autoshovel plc-ack --endpoint {})",
                        state.fault_text, link.endpoint
                    ),
                });
                eprintln!(
                    "drive: PLC fault latched: {}; the machine stays stopped until acknowledged: autoshovel plc-ack --endpoint {}",
                    state.fault_text, link.endpoint
                );
            } else if let Some(since) = faulted_since {
                if wall() - since > ack_timeout.as_secs_f64() {
                    return Err(LinkError::Refused {
                        endpoint: link.endpoint.clone(),
                        what: "resume".into(),
                        status: format!(
                            "no acknowledgement of the fault ({}) within {:.0} s",
                            state.fault_text,
                            ack_timeout.as_secs_f64()
                        ),
                    });
                }
            }
            // Hold control again if the fault took it (a claim by the
            // holder only renews it); another session holding it ends the
            // run. Keep the setpoints at zero (the PLC ignores them anyway)
            // and answer lockstep steps so the machine's own stop runs.
            if let Err(e @ LinkError::ControlHeld { .. }) = link.claim().await {
                return Err(e);
            }
            let _ = link.write_setpoints(TrackCommand::STOP, state.step).await;
            tokio::time::sleep(Duration::from_millis(20)).await;
            continue;
        }
        if let Some(since) = faulted_since.take() {
            link_events.push(LinkEvent {
                wall_s: wall(),
                kind: "acknowledged",
                message: format!("fault acknowledged after {:.1} s; resuming", wall() - since),
            });
        }
        if let Some(until) = stopped_wait {
            // After a safety stop: zero setpoints until the motors are at rest.
            let _ = link.write_setpoints(TrackCommand::STOP, state.step).await;
            let at_rest = state.left_rpm.abs() < autoshovel_walk_tracker::workstation::AT_REST_RPM
                && state.right_rpm.abs() < autoshovel_walk_tracker::workstation::AT_REST_RPM;
            if at_rest || wall() > until {
                break Status::Stopped;
            }
            tokio::time::sleep(Duration::from_millis(5)).await;
            continue;
        }
        let new_fix = state.fix_ticks != 0
            && state.fix_ticks != last_fix_ticks
            && matches!(state.quality, 4 | 5);
        let new_step = state.step.is_some() && state.step != last_step;
        let overdue = t - last_tick_t >= 1.5 * control_dt - 1e-9;
        // A pose older than the timeout zeroes the setpoints at once, not
        // at the next control period.
        let last_fix_t = secs(last_fix_ticks);
        let goes_stale = last_fix_ticks != 0
            && t - last_fix_t > sp.pose_timeout_s + 1e-6
            && last_tick_t - last_fix_t <= sp.pose_timeout_s + 1e-6;
        if !(new_fix || new_step || overdue || goes_stale) {
            tokio::time::sleep(Duration::from_millis(if state.step.is_some() {
                1
            } else {
                5
            }))
            .await;
            continue;
        }
        let fix = new_fix.then(|| {
            last_fix_ticks = state.fix_ticks;
            RtkFix {
                time_s: secs(state.fix_ticks),
                east_m: state.east_m,
                north_m: state.north_m,
                heading_north_cw_rad: state.heading_deg.to_radians(),
            }
        });
        last_step = state.step;
        last_tick_t = t;
        if let Some(f) = fix {
            logger.write(
                topic::RTK,
                f.time_s,
                &RtkMsg {
                    t_s: f.time_s,
                    east_m: state.east_m,
                    north_m: state.north_m,
                    heading_deg: state.heading_deg,
                    quality: state.quality,
                },
            );
        }
        logger.write(
            topic::MOTORS,
            t,
            &MotorsMsg {
                t_s: t,
                left: [
                    state.left_rpm,
                    state.motors[0][0],
                    state.motors[0][1],
                    state.motors[0][2],
                ],
                right: [
                    state.right_rpm,
                    state.motors[1][0],
                    state.motors[1][1],
                    state.motors[1][2],
                ],
            },
        );
        let tick = ws.tick(t, fix, (state.left_rpm, state.right_rpm));
        for d in &tick.decisions {
            if let Some(p) = last_measured {
                travelled_measured += (d.measured.position() - p.position()).norm();
            }
            last_measured = Some(d.measured);
            let (truth, travelled) = state.truth.unwrap_or((d.measured, travelled_measured));
            samples.push(eval.sample(&setup.legs, d, t, truth, travelled));
            logger.write(
                topic::TICK,
                t,
                &TickMsg {
                    t_s: t,
                    leg: d.leg,
                    measured: d.measured.into(),
                    truth: state.truth.map(|(p, _)| p.into()),
                    travelled_m: travelled,
                    d_m: d.dev.d_m,
                    d0_m: d.dev.d0_m,
                    speed_ref_mps: d.speed_ref_mps,
                    steer_rpm: d.steer_rpm,
                    left_rpm: d.command.left_rpm,
                    right_rpm: d.command.right_rpm,
                },
            );
        }
        let t0 = Instant::now();
        let ack = if tick.status == Status::Running {
            state.step
        } else {
            None
        };
        link.write_setpoints(tick.command(), ack).await?;
        write_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        match tick.status {
            Status::Running => {}
            Status::Stopped => stopped_wait = Some(wall() + 30.0),
            s => break s,
        }
    };
    // The end as the last tick saw it; after a safety stop, once at rest.
    let last = if status == Status::Stopped {
        link.read_state().await.unwrap_or(state)
    } else {
        state
    };
    let t_end = secs(last.clock_ticks);
    let (end, travelled) = last.truth.unwrap_or((
        last_measured.unwrap_or_else(|| {
            RtkFix {
                time_s: 0.0,
                east_m: last.east_m,
                north_m: last.north_m,
                heading_north_cw_rad: last.heading_deg.to_radians(),
            }
            .to_pose()
        }),
        travelled_measured,
    ));
    let completed = status == Status::Finished;
    let metrics = measure(&samples, setup, end, travelled, t_end, completed);
    logger.sync(t_end, &ws.events, &link_events);
    logger.write(
        topic::SUMMARY,
        t_end,
        &EndMsg {
            t_s: t_end,
            end: end.into(),
            travelled_m: travelled,
            completed,
            metrics,
        },
    );
    logger.sync(t_end, &ws.events, &link_events);
    if let Some(e) = logger.error {
        return Err(e);
    }
    let mut events: Vec<Event> = ws.events;
    events.sort_by(|a, b| {
        a.t_s
            .partial_cmp(&b.t_s)
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    Ok(DriveRun {
        run: Run {
            samples,
            events,
            metrics,
        },
        link_events,
        truth: last.truth.is_some(),
        read_ms,
        write_ms,
    })
}

/// Quantiles of a set of round trips (ms).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Quantiles {
    /// Count.
    pub n: usize,
    /// Median.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Largest.
    pub max: f64,
}

impl Quantiles {
    /// Of `xs` (NaN when empty).
    pub fn of(xs: &[f64]) -> Self {
        let mut v: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        let q = |p: f64| {
            if v.is_empty() {
                f64::NAN
            } else {
                v[((p * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)]
            }
        };
        Self {
            n: v.len(),
            p50: q(0.5),
            p99: q(0.99),
            max: v.last().copied().unwrap_or(f64::NAN),
        }
    }
}

/// The link's part of the `drive` summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinkSummary {
    /// The endpoint URL.
    pub endpoint: String,
    /// The security policy (SignAndEncrypt unless `none`).
    pub policy: Policy,
    /// The user name the session ran as.
    pub user: Option<String>,
    /// The PLC is `plc-sim` (it has the Simulator folder).
    pub simulator: bool,
    /// What the metrics are measured on: `simulator truth` or `rtk fixes`.
    pub metrics_on: &'static str,
    /// Link events (lost, restored, PLC faults, acknowledgements).
    pub events: Vec<LinkEvent>,
    /// Round trip of the state read (ms).
    pub read_ms: Quantiles,
    /// Round trip of the setpoint write (ms).
    pub write_ms: Quantiles,
    /// The MCAP run log.
    pub log: Option<String>,
}

impl LinkSummary {
    /// The summary of `run` over `params`' link.
    pub fn of(run: &DriveRun, params: &LinkParams) -> Self {
        Self {
            endpoint: params.endpoint.clone(),
            policy: params.policy,
            user: params.user.as_ref().map(|u| u.0.clone()),
            simulator: run.truth,
            metrics_on: if run.truth {
                "simulator truth"
            } else {
                "rtk fixes"
            },
            events: run.link_events.clone(),
            read_ms: Quantiles::of(&run.read_ms),
            write_ms: Quantiles::of(&run.write_ms),
            log: None,
        }
    }
}

/// The `drive` job's summary: the same fields as `track`'s (`job` =
/// `"drive"`), and the link's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriveSummary {
    /// The tracking summary, as `autoshovel track` writes it.
    #[serde(flatten)]
    pub track: autoshovel_walk_tracker::TrackSummary,
    /// The link.
    pub link: LinkSummary,
}
