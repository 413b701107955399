//! `autoshovel plc-sim`: the simulated PLC ([`crate::plc::Plc`]) behind an
//! OPC UA server (async-opcua) on the model of [`crate::model`], with the
//! network relay of [`crate::relay`] in front for link faults.
//!
//! Security: endpoints Basic256Sha256 and Aes256-Sha256-RsaPss, both
//! SignAndEncrypt, with the PLC's application-instance certificate and a
//! trust list (`pki/plc/trusted`); a client certificate not in the list is
//! refused and copied to `pki/plc/rejected`. Security None is offered only
//! with `insecure` (and then logged loudly), and only to anonymous sessions:
//! a password never crosses an unencrypted channel. The operator's user
//! name and password are needed to write and to call methods; an anonymous
//! session may browse and read (an HMI's view), never write. Who may move
//! the machine is [`crate::control`]'s: the one session holding control.

use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use async_trait::async_trait;
use opcua::crypto::{SecurityPolicy, Thumbprint};
use opcua::server::address_space::{AccessLevel, MethodBuilder, VariableBuilder};
use opcua::server::authenticator::{AuthManager, DefaultAuthenticator, Password, UserToken};
use opcua::server::{
    ServerBuilder, ServerEndpoint, ServerHandle, ServerUserToken, ANONYMOUS_USER_TOKEN_ID,
};
use opcua::types::{
    DataTypeId, DataValue, DateTime, Error as UaError, MessageSecurityMode, NodeId, ObjectId,
    QualifiedName, StatusCode, UAString, UserTokenPolicy, Variant,
};
use tokio::net::TcpListener;
use tokio::time::Instant;

use crate::control::{Caller, Refusal};
use crate::error::LinkError;
use crate::model::{
    self, Ty, Var, Writer, ACKNOWLEDGE, BREAK_LOCK, EXIT_LOCK, FOLDERS, INIT_LOCK, INJECT_FAULT,
    NAMESPACE_URI, RENEW_LOCK,
};
use crate::nodes::{shovel_node_manager, ShovelNodeManager};
use crate::pki::{self, Role};
use crate::plc::{FaultKind, Plc, PlcParams};
use autoshovel_run_log::{topic, EventMsg, MotorsMsg, PoseMsg, RtkMsg, RunLog};

/// How `plc-sim` is reached and secured.
#[derive(Debug, Clone)]
pub struct ServeParams {
    /// Host name or address to listen on (and to name in endpoint URLs).
    pub host: String,
    /// Port (0: any free one).
    pub port: u16,
    /// PKI root (holding `plc/` and `workstation/`).
    pub pki: PathBuf,
    /// Also offer security None.
    pub insecure: bool,
    /// User name and password allowed to write.
    pub users: Vec<(String, String)>,
}

/// Ticks of 100 ns per second (OPC UA DateTime).
const TICKS_PER_S: f64 = 1e7;

/// A running `plc-sim`.
pub struct PlcServer {
    /// The PLC.
    pub plc: Arc<Mutex<Plc>>,
    handle: ServerHandle,
    relay: Arc<crate::relay::RelayControl>,
    addr: SocketAddr,
    host: String,
    epoch_ticks: i64,
    instance: String,
    wall0: Instant,
    loop_task: tokio::task::JoinHandle<()>,
    relay_task: tokio::task::JoinHandle<()>,
    log: Arc<Mutex<Option<RunLog>>>,
}

/// A PLC start's identity: its start time (100 ns ticks), its process and
/// its place among the PLCs this process started, so two starts never share one.
fn instance_id(epoch_ticks: i64) -> String {
    static STARTS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = STARTS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    format!("{epoch_ticks}-{}-{n}", std::process::id())
}

fn nid(ns: u16, id: &str) -> NodeId {
    NodeId::new(ns, id)
}

fn lock(plc: &Mutex<Plc>) -> MutexGuard<'_, Plc> {
    // A panic while holding the lock would leave a PLC we cannot trust;
    // its data are still readable, and the next loop zeroes the motors.
    plc.lock().unwrap_or_else(|e| e.into_inner())
}

/// Sessions the server holds at once.
pub const MAX_SESSIONS: usize = 32;

/// Of [`MAX_SESSIONS`], how many anonymous sessions can never take: kept
/// for operators, so readers (HMIs, historians, scanners) cannot lock the
/// operator out of the machine.
pub const OPERATOR_SESSIONS: usize = 4;

/// Anonymous sessions may read and browse, not write or call, and never
/// take the sessions kept for operators.
struct PlcAuth {
    inner: DefaultAuthenticator,
    /// The running server's state (its session count), once it is built.
    info: std::sync::OnceLock<Arc<opcua::server::ServerInfo>>,
}

impl PlcAuth {
    /// Sessions open now (the activating one included).
    fn sessions(&self) -> usize {
        use opcua::types::VariableId::Server_ServerDiagnostics_ServerDiagnosticsSummary_CurrentSessionCount as COUNT;
        self.info
            .get()
            .and_then(|i| i.diagnostics.get(COUNT))
            .and_then(|dv| match dv.value {
                Some(Variant::UInt32(n)) => Some(n as usize),
                _ => None,
            })
            .unwrap_or(0)
    }
}

#[async_trait]
impl AuthManager for PlcAuth {
    async fn authenticate_anonymous_token(&self, endpoint: &ServerEndpoint) -> Result<(), UaError> {
        if self.sessions() > MAX_SESSIONS - OPERATOR_SESSIONS {
            return Err(UaError::new(
                StatusCode::BadTooManySessions,
                format!(
                    "the last {OPERATOR_SESSIONS} of {MAX_SESSIONS} sessions are kept for operators"
                ),
            ));
        }
        self.inner.authenticate_anonymous_token(endpoint).await
    }

    async fn authenticate_username_identity_token(
        &self,
        endpoint: &ServerEndpoint,
        username: &str,
        password: &Password,
    ) -> Result<UserToken, UaError> {
        self.inner
            .authenticate_username_identity_token(endpoint, username, password)
            .await
    }

    async fn authenticate_x509_identity_token(
        &self,
        endpoint: &ServerEndpoint,
        signing_thumbprint: &Thumbprint,
    ) -> Result<UserToken, UaError> {
        self.inner
            .authenticate_x509_identity_token(endpoint, signing_thumbprint)
            .await
    }

    fn effective_user_access_level(
        &self,
        token: &UserToken,
        user_access_level: AccessLevel,
        _node_id: &NodeId,
    ) -> AccessLevel {
        if token.is_anonymous() {
            user_access_level & !AccessLevel::CURRENT_WRITE
        } else {
            user_access_level
        }
    }

    fn is_user_executable(&self, token: &UserToken, _method_id: &NodeId) -> bool {
        !token.is_anonymous()
    }

    fn user_token_policies(&self, endpoint: &ServerEndpoint) -> Vec<UserTokenPolicy> {
        self.inner.user_token_policies(endpoint)
    }
}

fn initial(ty: Ty) -> Variant {
    match ty {
        Ty::Double => Variant::Double(0.0),
        Ty::UInt32 => Variant::UInt32(0),
        Ty::UInt64 => Variant::UInt64(0),
        Ty::Byte => Variant::Byte(0),
        Ty::Boolean => Variant::Boolean(false),
        Ty::DateTime => Variant::DateTime(Box::new(DateTime::null())),
        Ty::String => Variant::String(UAString::from("")),
        Ty::Duration => Variant::Double(0.0),
    }
}

impl PlcServer {
    /// Starts the server and the PLC loop.
    pub async fn start(plc: PlcParams, serve: ServeParams) -> Result<PlcServer, LinkError> {
        Self::start_logged(plc, serve, None).await
    }

    /// Starts the server and the PLC loop, logging the machine (fixes,
    /// truth, setpoints, inverter readings at each fix; every event) to `log`.
    pub async fn start_logged(
        plc: PlcParams,
        serve: ServeParams,
        log: Option<RunLog>,
    ) -> Result<PlcServer, LinkError> {
        let addr_text = format!("{}:{}", serve.host, serve.port);
        let serve_err = |why: String| LinkError::Serve {
            addr: addr_text.clone(),
            why,
        };
        let serve_io = |source: std::io::Error| LinkError::ServeIo {
            addr: addr_text.clone(),
            source,
        };
        pki::ensure(&serve.pki, Role::Plc, std::slice::from_ref(&serve.host))?;
        let public = TcpListener::bind((serve.host.as_str(), serve.port))
            .await
            .map_err(serve_io)?;
        let addr = public.local_addr().map_err(serve_io)?;
        let inner = TcpListener::bind("127.0.0.1:0").await.map_err(serve_io)?;
        let inner_addr = inner.local_addr().map_err(serve_io)?;

        let mut users = BTreeMap::new();
        let mut token_ids: Vec<String> = vec![ANONYMOUS_USER_TOKEN_ID.to_string()];
        for (u, p) in &serve.users {
            users.insert(
                u.clone(),
                ServerUserToken::user_pass(u.as_str(), p.as_str()),
            );
            token_ids.push(u.clone());
        }
        let ids: Vec<&str> = token_ids.iter().map(String::as_str).collect();
        let auth = Arc::new(PlcAuth {
            inner: DefaultAuthenticator::new(users.clone()),
            info: std::sync::OnceLock::new(),
        });
        let mut builder = ServerBuilder::new()
            .application_name(Role::Plc.application_name())
            .application_uri(Role::Plc.application_uri())
            .product_uri("urn:autoshovel")
            .pki_dir(pki::role_dir(&serve.pki, Role::Plc))
            .create_sample_keypair(false)
            .trust_client_certs(false)
            .host(serve.host.clone())
            .port(addr.port())
            .discovery_urls(vec![format!("opc.tcp://{}:{}/", serve.host, addr.port())])
            .with_node_manager(shovel_node_manager(NAMESPACE_URI))
            .with_authenticator(auth.clone())
            .max_sessions(MAX_SESSIONS)
            .diagnostics_enabled(true)
            .add_endpoint(
                "basic256sha256",
                (
                    "/",
                    SecurityPolicy::Basic256Sha256,
                    MessageSecurityMode::SignAndEncrypt,
                    &ids as &[&str],
                ),
            )
            .add_endpoint(
                "aes256sha256rsapss",
                (
                    "/",
                    SecurityPolicy::Aes256Sha256RsaPss,
                    MessageSecurityMode::SignAndEncrypt,
                    &ids as &[&str],
                ),
            )
            .default_endpoint("basic256sha256");
        for (k, v) in users {
            builder = builder.add_user_token(k, v);
        }
        if serve.insecure {
            // Anonymous only: a user's password never crosses an
            // unencrypted channel, so None can read, never command.
            eprintln!(
                "plc-sim: WARNING: security None offered on {addr} (--insecure), for anonymous reading only"
            );
            builder = builder.add_endpoint(
                "none",
                (
                    "/",
                    SecurityPolicy::None,
                    MessageSecurityMode::None,
                    &[ANONYMOUS_USER_TOKEN_ID] as &[&str],
                ),
            );
        }
        let (server, handle) = builder.build().map_err(serve_err)?;
        let _ = auth.info.set(handle.info().clone());
        let manager = handle
            .node_managers()
            .get_of_type::<ShovelNodeManager>()
            .ok_or_else(|| serve_err("node manager missing".into()))?;
        let ns = handle
            .get_namespace_index(NAMESPACE_URI)
            .ok_or_else(|| serve_err("namespace missing".into()))?;

        let plc = Arc::new(Mutex::new(Plc::new(plc)));
        build_address_space(&manager, ns, &plc);

        tokio::spawn(server.run_with(inner));
        // Connections opening and closing tell the PLC nothing: only the
        // controlling session's heartbeat and its session's end count.
        let (relay, relay_task) = crate::relay::spawn(public, inner_addr);

        let epoch_ticks = DateTime::now().ticks();
        let instance = instance_id(epoch_ticks);
        let wall0 = Instant::now();
        let log = Arc::new(Mutex::new(log.map(|mut l| {
            l.set_origin_ticks(epoch_ticks);
            l
        })));
        let loop_task = tokio::spawn(run_loop(
            plc.clone(),
            manager,
            handle.clone(),
            ns,
            relay.clone(),
            (epoch_ticks, instance.clone()),
            wall0,
            log.clone(),
        ));
        Ok(PlcServer {
            plc,
            handle,
            relay,
            addr,
            host: serve.host,
            epoch_ticks,
            instance,
            wall0,
            loop_task,
            relay_task,
            log,
        })
    }

    /// This start's identity (`Shovel.InstanceId`).
    pub fn instance_id(&self) -> &str {
        &self.instance
    }

    /// The endpoint URL.
    pub fn endpoint(&self) -> String {
        format!("opc.tcp://{}:{}/", self.host, self.addr.port())
    }

    /// The address listened on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Wall-clock seconds since start.
    pub fn wall_s(&self) -> f64 {
        self.wall0.elapsed().as_secs_f64()
    }

    /// The machine clock's origin as OPC UA DateTime ticks.
    pub fn epoch_ticks(&self) -> i64 {
        self.epoch_ticks
    }

    /// Injects a fault now.
    pub fn inject(&self, fault: FaultKind) {
        lock(&self.plc).inject(fault);
    }

    /// Cuts the network now for `d` (as the `link-cut` fault).
    pub fn cut(&self, d: Duration) {
        self.relay.cut(d);
    }

    /// Stops the server (its port is free again once this returns); finishes the log (its path, or the error that
    /// stopped it) when there is one.
    pub async fn stop(self) -> Option<Result<std::path::PathBuf, LinkError>> {
        self.loop_task.abort();
        let _ = self.loop_task.await;
        self.relay.shut_down();
        let _ = self.relay_task.await;
        self.handle.cancel();
        let log = self.log.lock().unwrap_or_else(|e| e.into_inner()).take();
        log.map(|l| Ok(l.finish()?))
    }
}

/// A write's effect on the PLC: the caller and the value; the status.
type PlcWrite = Box<dyn Fn(&mut Plc, &Caller, &Variant) -> StatusCode + Send + Sync>;
/// A method's effect on the PLC: the caller and the arguments; the outputs or a status.
type PlcCall =
    Box<dyn Fn(&mut Plc, &Caller, &[Variant]) -> Result<Vec<Variant>, StatusCode> + Send + Sync>;

fn build_address_space(manager: &Arc<ShovelNodeManager>, ns: u16, plc: &Arc<Mutex<Plc>>) {
    {
        let space = manager.address_space();
        let mut space = space.write();
        for f in FOLDERS {
            let parent = model::parent(f);
            let parent_id = if parent.is_empty() {
                ObjectId::ObjectsFolder.into()
            } else {
                nid(ns, parent)
            };
            space.add_folder(
                &nid(ns, f),
                QualifiedName::new(ns, model::leaf(f)),
                model::leaf(f),
                &parent_id,
            );
        }
        for v in model::VARIABLES {
            let mut b = VariableBuilder::new(
                &nid(ns, v.id),
                QualifiedName::new(ns, model::leaf(v.id)),
                model::leaf(v.id),
            )
            .data_type(v.ty.data_type_id())
            .value(initial(v.ty))
            .description(format!(
                "{}{}",
                v.doc,
                if v.unit.is_empty() {
                    String::new()
                } else {
                    format!(" [{}]", v.unit)
                }
            ))
            .organized_by(nid(ns, model::parent(v.id)));
            if v.writer == Writer::Workstation {
                b = b.writable();
            }
            b.insert(&mut *space);
        }
        MethodBuilder::new(
            &nid(ns, ACKNOWLEDGE),
            QualifiedName::new(ns, "Acknowledge"),
            "Acknowledge",
        )
        .component_of(nid(ns, model::parent(ACKNOWLEDGE)))
        .executable(true)
        .user_executable(true)
        .insert(&mut *space);
        MethodBuilder::new(
            &nid(ns, INJECT_FAULT),
            QualifiedName::new(ns, "InjectFault"),
            "InjectFault",
        )
        .component_of(nid(ns, model::parent(INJECT_FAULT)))
        .executable(true)
        .user_executable(true)
        .input_args(
            &mut *space,
            &nid(ns, "Shovel.Simulator.InjectFault.InputArguments"),
            &[
                ("Kind", DataTypeId::String).into(),
                ("Value", DataTypeId::Double).into(),
            ],
        )
        .insert(&mut *space);
        for (id, _) in model::LOCK_METHODS {
            let name = model::leaf(id);
            let mut b = MethodBuilder::new(&nid(ns, id), QualifiedName::new(ns, name), name)
                .component_of(nid(ns, model::parent(id)))
                .executable(true)
                .user_executable(true);
            if *id == INIT_LOCK {
                b = b.input_args(
                    &mut *space,
                    &nid(ns, &format!("{id}.InputArguments")),
                    &[("Context", DataTypeId::String).into()],
                );
            }
            b.output_args(
                &mut *space,
                &nid(ns, &format!("{id}.OutputArguments")),
                &[(format!("{name}Status").as_str(), DataTypeId::Int32).into()],
            )
            .insert(&mut *space);
        }
    }
    let inner = manager.inner();
    let on_write = |var: Var, f: PlcWrite| {
        let p = plc.clone();
        inner.on_write(
            nid(ns, model::spec(var).id),
            Box::new(move |who, v| f(&mut lock(&p), who, v)),
        );
    };
    for (var, right) in [(Var::LeftSetpoint, false), (Var::RightSetpoint, true)] {
        on_write(
            var,
            Box::new(move |p, who, v| match v {
                Variant::Double(v) => status(p.write_setpoint(who, right, *v)),
                _ => StatusCode::BadTypeMismatch,
            }),
        );
    }
    on_write(
        Var::Heartbeat,
        Box::new(|p, who, v| match v {
            Variant::UInt32(v) => status(p.write_heartbeat(who, *v)),
            _ => StatusCode::BadTypeMismatch,
        }),
    );
    on_write(
        Var::SimStepAck,
        Box::new(|p, who, v| match v {
            Variant::UInt64(v) => status(p.write_step_ack(who, *v)),
            _ => StatusCode::BadTypeMismatch,
        }),
    );
    let on_call = |id: &str, f: PlcCall| {
        let p = plc.clone();
        inner.on_call(
            nid(ns, id),
            Box::new(move |who, args| f(&mut lock(&p), who, args)),
        );
    };
    on_call(
        ACKNOWLEDGE,
        Box::new(|p, who, _| {
            p.acknowledge(who)
                .map(|_| Vec::new())
                .map_err(|_| StatusCode::BadInvalidState)
        }),
    );
    on_call(
        INIT_LOCK,
        Box::new(|p, who, args| match args.first() {
            Some(Variant::String(context)) => {
                Ok(vec![Variant::Int32(p.init_lock(who, context.as_ref()))])
            }
            _ => Err(StatusCode::BadInvalidArgument),
        }),
    );
    type LockCall = fn(&mut Plc, &Caller) -> Result<i32, Refusal>;
    for (id, f) in [
        (RENEW_LOCK, Plc::renew_lock as LockCall),
        (EXIT_LOCK, Plc::exit_lock),
        (BREAK_LOCK, Plc::break_lock),
    ] {
        on_call(
            id,
            Box::new(move |p, who, _| match f(p, who) {
                Ok(s) => Ok(vec![Variant::Int32(s)]),
                Err(e) => Err(status(Err(e))),
            }),
        );
    }
    on_call(
        INJECT_FAULT,
        Box::new(|p, _, args| {
            let (Some(Variant::String(kind)), Some(Variant::Double(v))) =
                (args.first(), args.get(1))
            else {
                return Err(StatusCode::BadInvalidArgument);
            };
            let f =
                FaultKind::parse(kind.as_ref(), *v).map_err(|_| StatusCode::BadInvalidArgument)?;
            p.inject(f);
            Ok(Vec::new())
        }),
    );
}

/// The OPC UA status of a command's outcome.
fn status(r: Result<(), Refusal>) -> StatusCode {
    match r {
        Ok(()) => StatusCode::Good,
        Err(Refusal::RequiresLock) => StatusCode::BadRequiresLock,
        Err(Refusal::Locked { .. }) => StatusCode::BadLocked,
        Err(Refusal::OutOfRange(_)) => StatusCode::BadOutOfRange,
        Err(Refusal::InvalidState(_)) => StatusCode::BadInvalidState,
    }
}

// The loop's eight inputs are the server's parts it publishes; a struct
// holding them would only be unpacked again here.
#[allow(clippy::too_many_arguments)]
async fn run_loop(
    plc: Arc<Mutex<Plc>>,
    manager: Arc<ShovelNodeManager>,
    handle: ServerHandle,
    ns: u16,
    relay: Arc<crate::relay::RelayControl>,
    (epoch_ticks, instance): (i64, String),
    wall0: Instant,
    log: Arc<Mutex<Option<RunLog>>>,
) {
    let mut logged_events = 0usize;
    let mut iv = tokio::time::interval(Duration::from_millis(1));
    iv.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let stamp = |t_s: f64| DateTime::from(epoch_ticks + (t_s * TICKS_PER_S).round() as i64);
    let ids: BTreeMap<Var, NodeId> = model::VARIABLES
        .iter()
        .map(|v| (v.var, nid(ns, v.id)))
        .collect();
    let mut published_once = false;
    loop {
        iv.tick().await;
        let mut values: Vec<(Var, Variant)> = Vec::with_capacity(32);
        let network;
        {
            let mut p = lock(&plc);
            // The controlling session closed or timed out: the machine stops.
            if let Some(h) = p.control.holder().map(|h| h.caller.session) {
                if manager.inner().session_open(h) == Some(false) {
                    p.session_closed(h);
                }
            }
            p.run_to(wall0.elapsed().as_secs_f64());
            network = std::mem::take(&mut p.network);
            let t = p.machine.time_s();
            let r = p.readings();
            let sp = p.setpoints();
            values.extend([
                (Var::PlcTime, Variant::DateTime(Box::new(stamp(t)))),
                (Var::LeftSpeed, Variant::Double(r[0].speed_rpm)),
                (Var::LeftFrequency, Variant::Double(r[0].frequency_hz)),
                (Var::LeftCurrent, Variant::Double(r[0].current_a)),
                (Var::LeftVoltage, Variant::Double(r[0].voltage_v)),
                (Var::RightSpeed, Variant::Double(r[1].speed_rpm)),
                (Var::RightFrequency, Variant::Double(r[1].frequency_hz)),
                (Var::RightCurrent, Variant::Double(r[1].current_a)),
                (Var::RightVoltage, Variant::Double(r[1].voltage_v)),
                (Var::LeftSetpoint, Variant::Double(sp.left_rpm)),
                (Var::RightSetpoint, Variant::Double(sp.right_rpm)),
                (Var::Mode, Variant::Byte(p.mode())),
                (Var::FaultActive, Variant::Boolean(p.fault.is_some())),
                (
                    Var::FaultCode,
                    Variant::UInt32(p.fault.as_ref().map(|f| f.0).unwrap_or(0)),
                ),
                (
                    Var::FaultText,
                    Variant::String(UAString::from(
                        p.fault.as_ref().map(|f| f.1.as_str()).unwrap_or(""),
                    )),
                ),
                (Var::SimStep, Variant::UInt64(p.step())),
            ]);
            values.extend(control_values(&p));
            let (truth, travelled) = p.truth();
            values.extend([
                (Var::SimTrueX, Variant::Double(truth.x)),
                (Var::SimTrueY, Variant::Double(truth.y)),
                (Var::SimTrueTheta, Variant::Double(truth.theta)),
                (Var::SimTravelled, Variant::Double(travelled)),
            ]);
            if !published_once {
                let c = p.params.setup.crawler;
                values.push((Var::MaxSpeed, Variant::Double(c.motor_max_rpm)));
                values.push((Var::MaxAccel, Variant::Double(c.motor_max_accel_rpm_per_s)));
                values.push((
                    Var::InstanceId,
                    Variant::String(UAString::from(instance.as_str())),
                ));
                published_once = true;
            }
            let fix_changed = p.take_fix_changed();
            let mut guard = log.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(l) = guard.as_mut() {
                // A log that fails stops logging, never the PLC.
                if let Err(e) = log_machine(l, &p, fix_changed, &mut logged_events) {
                    eprintln!("plc-sim: the run log stopped: {e}");
                    *guard = None;
                }
            }
            drop(guard);
            if fix_changed {
                if let Some(f) = p.fix() {
                    values.extend([
                        (Var::RtkEast, Variant::Double(f.east_m)),
                        (Var::RtkNorth, Variant::Double(f.north_m)),
                        (
                            Var::RtkHeading,
                            Variant::Double(f.heading_north_cw_rad.to_degrees()),
                        ),
                        (Var::RtkQuality, Variant::Byte(4)),
                        (Var::RtkTime, Variant::DateTime(Box::new(stamp(f.time_s)))),
                    ]);
                }
            }
        }
        for f in network {
            match f {
                FaultKind::LinkCut { duration_s } => {
                    relay.cut(Duration::from_secs_f64(duration_s));
                }
                FaultKind::Delay {
                    delay_s,
                    duration_s,
                } => {
                    relay.delay(Duration::from_secs_f64(delay_s));
                    let r = relay.clone();
                    tokio::spawn(async move {
                        tokio::time::sleep(Duration::from_secs_f64(duration_s)).await;
                        r.delay(Duration::ZERO);
                    });
                }
                _ => {}
            }
        }
        let now = DateTime::now();
        let _ = manager.set_values(
            handle.subscriptions(),
            values.into_iter().map(|(v, val)| {
                let mut dv = DataValue::new_at(val, now);
                dv.source_timestamp = Some(now);
                (&ids[&v], None, dv)
            }),
        );
    }
}

/// The lock's state as `Shovel.Control` publishes it (OPC 10000-100).
fn control_values(p: &Plc) -> [(Var, Variant); 4] {
    let holder = p.control.holder();
    [
        (Var::Locked, Variant::Boolean(holder.is_some())),
        (
            Var::LockingClient,
            Variant::String(UAString::from(
                holder
                    .map(|h| format!("{} (session {})", h.caller.client, h.caller.session))
                    .unwrap_or_default(),
            )),
        ),
        (
            Var::LockingUser,
            Variant::String(UAString::from(
                holder
                    .and_then(|h| h.caller.user.clone())
                    .unwrap_or_default(),
            )),
        ),
        (
            Var::RemainingLockTime,
            Variant::Double(p.lock_remaining_s().unwrap_or(0.0) * 1e3),
        ),
    ]
}

fn log_machine(
    l: &mut RunLog,
    p: &Plc,
    fix_changed: bool,
    logged_events: &mut usize,
) -> Result<(), LinkError> {
    let t = p.machine.time_s();
    for e in &p.events[*logged_events..] {
        l.write(
            topic::EVENT,
            e.t_s,
            &EventMsg {
                t_s: e.t_s,
                source: "plc".into(),
                kind: e.kind.into(),
                message: e.message.clone(),
            },
        )?;
    }
    let new_events = *logged_events < p.events.len();
    *logged_events = p.events.len();
    if !fix_changed {
        if new_events {
            l.sync()?;
        }
        return Ok(());
    }
    if let Some(f) = p.fix() {
        l.write(
            topic::RTK,
            t,
            &RtkMsg {
                t_s: f.time_s,
                east_m: f.east_m,
                north_m: f.north_m,
                heading_deg: f.heading_north_cw_rad.to_degrees(),
                quality: 4,
            },
        )?;
    }
    let (truth, travelled) = p.truth();
    l.write(
        topic::TRUTH,
        t,
        &serde_json::json!({ "t_s": t, "pose": PoseMsg::from(truth), "travelled_m": travelled }),
    )?;
    let sp = p.setpoints();
    l.write(
        topic::SETPOINTS,
        t,
        &serde_json::json!({ "t_s": t, "left_rpm": sp.left_rpm, "right_rpm": sp.right_rpm, "obeyed": p.effective_command() == sp }),
    )?;
    let r = p.readings();
    l.write(
        topic::MOTORS,
        t,
        &MotorsMsg {
            t_s: t,
            left: [
                r[0].speed_rpm,
                r[0].frequency_hz,
                r[0].current_a,
                r[0].voltage_v,
            ],
            right: [
                r[1].speed_rpm,
                r[1].frequency_hz,
                r[1].current_a,
                r[1].voltage_v,
            ],
        },
    )?;
    // Durable each fix: a killed plc-sim leaves its log readable.
    l.sync()?;
    Ok(())
}
