//! The simulated network in front of `plc-sim`: a TCP relay between the
//! public port and the OPC UA server's own, which can cut the link for a
//! while (pulling the cable: nothing passes either way and nobody is told;
//! bytes sent meanwhile arrive after, as TCP's retransmissions deliver them
//! once the cable is back) or hold back the server's replies (a slow link). It passes bytes and knows nothing of the
//! protocol, and tells the PLC nothing: a connection opening or closing is
//! no command (a scanner, an HMI or a discovery probe does so all day).

use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::watch;
use tokio::time::Instant;

/// The relay's switches, shared with the PLC.
#[derive(Debug)]
pub struct RelayControl {
    /// Connections are refused and cut until this instant.
    cut_until: watch::Sender<Option<Instant>>,
    /// Server → client bytes are held this long (µs).
    delay_us: AtomicU64,
    /// Number of connections that have ended (either side, or cut).
    pub closed: AtomicU64,
    /// Set once: the relay stops listening and drops every connection.
    shutdown: watch::Sender<bool>,
}

impl RelayControl {
    fn new() -> Self {
        Self {
            cut_until: watch::channel(None).0,
            delay_us: AtomicU64::new(0),
            closed: AtomicU64::new(0),
            shutdown: watch::channel(false).0,
        }
    }

    /// Stops listening and drops every connection (the PLC is gone).
    pub fn shut_down(&self) {
        self.shutdown.send_replace(true);
    }

    async fn until_shut_down(&self) {
        let mut rx = self.shutdown.subscribe();
        let _ = rx.wait_for(|down| *down).await;
    }

    /// Cuts the link now for `d`: nothing passes either way until then.
    pub fn cut(&self, d: Duration) {
        self.cut_until.send_replace(Some(Instant::now() + d));
    }

    /// Holds the server's replies back by `d` (zero: no delay).
    pub fn delay(&self, d: Duration) {
        self.delay_us.store(
            d.as_micros().min(u64::MAX as u128) as u64,
            Ordering::Relaxed,
        );
    }

    /// Sleeps until the cut (if any) is over.
    async fn wait_while_cut(&self) {
        loop {
            let until = *self.cut_until.borrow();
            match until {
                Some(t) if Instant::now() < t => tokio::time::sleep_until(t).await,
                _ => return,
            }
        }
    }
}

/// Starts a relay from `listener` to `upstream`; its switches, and the
/// task that listens (done once [`RelayControl::shut_down`] has freed the port).
pub fn spawn(
    listener: TcpListener,
    upstream: SocketAddr,
) -> (Arc<RelayControl>, tokio::task::JoinHandle<()>) {
    let control = Arc::new(RelayControl::new());
    let ctl = control.clone();
    let task = tokio::spawn(async move {
        loop {
            let accepted = tokio::select! {
                a = listener.accept() => a,
                () = ctl.until_shut_down() => return,
            };
            let Ok((client, _)) = accepted else {
                continue;
            };
            let ctl = ctl.clone();
            tokio::spawn(async move {
                let relayed = async {
                    ctl.wait_while_cut().await;
                    if let Ok(server) = TcpStream::connect(upstream).await {
                        pipe(client, server, &ctl).await;
                    }
                };
                tokio::select! {
                    () = relayed => {}
                    () = ctl.until_shut_down() => {}
                }
                ctl.closed.fetch_add(1, Ordering::Relaxed);
            });
        }
    });
    (control, task)
}

async fn pipe(client: TcpStream, server: TcpStream, ctl: &RelayControl) {
    let _ = client.set_nodelay(true);
    let _ = server.set_nodelay(true);
    let (mut cr, mut cw) = client.into_split();
    let (mut sr, mut sw) = server.into_split();
    let up = async {
        let mut buf = vec![0u8; 64 * 1024];
        loop {
            match cr.read(&mut buf).await {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    ctl.wait_while_cut().await;
                    if sw.write_all(&buf[..n]).await.is_err() {
                        break;
                    }
                }
            }
        }
    };
    let down = async {
        let mut buf = vec![0u8; 64 * 1024];
        loop {
            match sr.read(&mut buf).await {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    let d = ctl.delay_us.load(Ordering::Relaxed);
                    if d > 0 {
                        tokio::time::sleep(Duration::from_micros(d)).await;
                    }
                    ctl.wait_while_cut().await;
                    if cw.write_all(&buf[..n]).await.is_err() {
                        break;
                    }
                }
            }
        }
    };
    tokio::select! {
        _ = up => {}
        _ = down => {}
    }
}
