//! A hostile PLC: a server that speaks just enough OPC UA (Hello,
//! OpenSecureChannel over None, GetEndpoints) to answer the workstation's
//! first request with error details nested deeper than any stack. The
//! workstation must give a named error and live on: async-opcua 0.19
//! decoded nested DiagnosticInfo by unbounded recursion, which the patched
//! copy in `vendor/async-opcua-types` bounds (vendor/README.md).
//!
//! The messages are written byte by byte here (OPC 10000-6 §7.1, §6.7)
//! because the point is to send what no well-behaved stack would. Beside
//! the nesting, a seeded run of responses with bytes overwritten at random
//! (`HOSTILE_CASES`, default 32) must each end in a named error.

use std::time::Duration;

use autoshovel_plc_link::{pki, Link, LinkError, LinkParams};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};

/// The None security policy's URI.
const NONE_URI: &str = "http://opcfoundation.org/UA/SecurityPolicy#None";

/// One message: its three-letter type, its chunk type and its body after
/// the 8-byte header.
async fn read_msg(s: &mut TcpStream) -> std::io::Result<([u8; 3], Vec<u8>)> {
    let mut head = [0u8; 8];
    s.read_exact(&mut head).await?;
    let size = u32::from_le_bytes(head[4..8].try_into().unwrap()) as usize;
    let mut body = vec![0u8; size.saturating_sub(8)];
    s.read_exact(&mut body).await?;
    Ok(([head[0], head[1], head[2]], body))
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

/// Skips an OPC UA String or ByteString at `at`; the offset after it.
fn skip_string(b: &[u8], at: usize) -> usize {
    let n = i32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    at + 4 + n.max(0) as usize
}

/// A response header with `diagnostics` as its ServiceDiagnostics bytes.
fn response_header(request_handle: u32, diagnostics: &[u8]) -> Vec<u8> {
    let mut h = Vec::new();
    h.extend_from_slice(&now_ticks().to_le_bytes()); // Timestamp
    h.extend_from_slice(&request_handle.to_le_bytes());
    h.extend_from_slice(&0u32.to_le_bytes()); // ServiceResult Good
    h.extend_from_slice(diagnostics);
    h.extend_from_slice(&(-1i32).to_le_bytes()); // StringTable: null
    h.extend_from_slice(&[0, 0, 0]); // AdditionalHeader: null ExtensionObject
    h
}

/// Now, in OPC UA DateTime ticks (100 ns since 1601).
fn now_ticks() -> i64 {
    let unix = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap();
    116_444_736_000_000_000 + (unix.as_nanos() / 100) as i64
}

/// A four-byte NodeId in namespace 0.
fn type_id(id: u16) -> [u8; 4] {
    let b = id.to_le_bytes();
    [1, 0, b[0], b[1]]
}

/// What the hostile server answers GetEndpoints with: the response's bytes
/// after its type id, given the request's handle.
type Answer = std::sync::Arc<dyn Fn(u32) -> Vec<u8> + Send + Sync>;

/// A GetEndpoints response whose ServiceDiagnostics nest `depth` deep.
fn nested(depth: usize) -> Answer {
    std::sync::Arc::new(move |handle| {
        let mut diagnostics = vec![0x40u8; depth]; // HasInnerDiagnosticInfo, again and again
        diagnostics.push(0);
        let mut body = response_header(handle, &diagnostics);
        body.extend_from_slice(&0i32.to_le_bytes()); // Endpoints: none
        body
    })
}

/// Serves one workstation: Hello, OpenSecureChannel, then `answer` as the
/// GetEndpoints response, in as many chunks as the client's receive buffer needs.
async fn hostile(mut s: TcpStream, answer: Answer) -> std::io::Result<()> {
    let (kind, hello) = read_msg(&mut s).await?;
    assert_eq!(&kind, b"HEL");
    let receive_buffer = u32_at(&hello, 4) as usize;
    let mut ack = b"ACKF".to_vec();
    ack.extend_from_slice(&28u32.to_le_bytes());
    for v in [0u32, 65_536, 65_536, 0, 0] {
        ack.extend_from_slice(&v.to_le_bytes());
    }
    s.write_all(&ack).await?;
    // OpenSecureChannel (None): channel id, the asymmetric header, sequence, request id.
    let (kind, opn) = read_msg(&mut s).await?;
    assert_eq!(&kind, b"OPN");
    let mut at = skip_string(&opn, 4); // the policy URI
    at = skip_string(&opn, at); // sender certificate
    at = skip_string(&opn, at); // receiver thumbprint
    let request_id = u32_at(&opn, at + 4);
    // Body: type id (4), auth token (2), timestamp (8), request handle.
    let handle = u32_at(&opn, at + 8 + 4 + 2 + 8);
    let mut body = type_id(449).to_vec(); // OpenSecureChannelResponse
    body.extend(response_header(handle, &[0]));
    body.extend_from_slice(&0u32.to_le_bytes()); // ServerProtocolVersion
    body.extend_from_slice(&1u32.to_le_bytes()); // ChannelId
    body.extend_from_slice(&1u32.to_le_bytes()); // TokenId
    body.extend_from_slice(&now_ticks().to_le_bytes()); // CreatedAt
    body.extend_from_slice(&600_000u32.to_le_bytes()); // RevisedLifetime (ms)
    body.extend_from_slice(&(-1i32).to_le_bytes()); // ServerNonce: null
    let mut sec = Vec::new();
    sec.extend_from_slice(&1u32.to_le_bytes()); // SecureChannelId
    sec.extend_from_slice(&(NONE_URI.len() as i32).to_le_bytes());
    sec.extend_from_slice(NONE_URI.as_bytes());
    sec.extend_from_slice(&(-1i32).to_le_bytes());
    sec.extend_from_slice(&(-1i32).to_le_bytes());
    sec.extend_from_slice(&1u32.to_le_bytes()); // SequenceNumber
    sec.extend_from_slice(&request_id.to_le_bytes());
    let mut opn_reply = b"OPNF".to_vec();
    opn_reply.extend_from_slice(&((8 + sec.len() + body.len()) as u32).to_le_bytes());
    opn_reply.extend(sec);
    opn_reply.extend(body);
    s.write_all(&opn_reply).await?;
    // GetEndpoints: channel id, token id, sequence, request id, then the body.
    let (kind, msg) = read_msg(&mut s).await?;
    assert_eq!(&kind, b"MSG");
    let request_id = u32_at(&msg, 12);
    let handle = u32_at(&msg, 16 + 4 + 2 + 8);
    let mut body = type_id(431).to_vec(); // GetEndpointsResponse
    body.extend(answer(handle));
    let room = receive_buffer.max(8192) - 24;
    let chunks: Vec<&[u8]> = body.chunks(room).collect();
    for (i, part) in chunks.iter().enumerate() {
        let last = i + 1 == chunks.len();
        let mut c = if last {
            b"MSGF".to_vec()
        } else {
            b"MSGC".to_vec()
        };
        c.extend_from_slice(&((24 + part.len()) as u32).to_le_bytes());
        c.extend_from_slice(&1u32.to_le_bytes()); // SecureChannelId
        c.extend_from_slice(&1u32.to_le_bytes()); // TokenId
        c.extend_from_slice(&(2 + i as u32).to_le_bytes()); // SequenceNumber
        c.extend_from_slice(&request_id.to_le_bytes());
        c.extend_from_slice(part);
        s.write_all(&c).await?;
    }
    // Hold the connection until the client hangs up.
    let mut sink = [0u8; 1024];
    while s.read(&mut sink).await.unwrap_or(0) > 0 {}
    Ok(())
}

/// The workstation's error from a hostile server answering with `answer`.
fn against(answer: Answer, timeout: Duration) -> LinkError {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("pki");
    pki::init(&root, &[]).unwrap();
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    rt.block_on(async {
        let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
        let endpoint = format!(
            "opc.tcp://127.0.0.1:{}/",
            listener.local_addr().unwrap().port()
        );
        tokio::spawn(async move {
            while let Ok((s, _)) = listener.accept().await {
                tokio::spawn(hostile(s, answer.clone()));
            }
        });
        let mut p = LinkParams::new(
            &endpoint,
            root.clone(),
            Some(("operator".into(), "x".into())),
        );
        p.connect_timeout = timeout;
        Link::open(&p)
            .await
            .err()
            .expect("a hostile server is never a link")
    })
}

#[test]
fn error_details_nested_a_million_deep_are_a_named_error_not_an_abort() {
    // 10^6 levels: more than the client takes in one message.
    let e = against(nested(1_000_000), Duration::from_secs(10));
    assert!(matches!(e, LinkError::Connect { .. }), "{e}");
    assert!(e.to_string().contains("opc.tcp://127.0.0.1:"), "{e}");
    // 300 000 levels fit the client's five 64 KiB chunks and reach the
    // decoder: unbounded, its recursion overflowed the stack and aborted
    // the process; bounded, the depth gauge refuses it.
    let e = against(nested(300_000), Duration::from_secs(10));
    assert!(matches!(e, LinkError::Connect { .. }), "{e}");
    eprintln!("300 000 deep: {}", autoshovel_core::error_chain(&e));
}

#[test]
fn seeded_garbage_in_a_response_is_a_named_error_every_time() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(47);
    let cases = std::env::var("HOSTILE_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(32usize);
    for case in 0..cases {
        // A valid empty response, then bytes of it overwritten at random:
        // lengths, masks and encodings that claim what is not there.
        let mut base = response_header(7, &[0]);
        base.extend_from_slice(&1i32.to_le_bytes()); // one endpoint, then garbage
        let n = rng.gen_range(0..2048);
        base.extend((0..n).map(|_| rng.gen::<u8>()));
        for _ in 0..rng.gen_range(0..8) {
            let at = rng.gen_range(0..base.len());
            base[at] = rng.gen();
        }
        let body = std::sync::Arc::new(base);
        let answer: Answer = std::sync::Arc::new(move |_| body.to_vec());
        let e = against(answer, Duration::from_secs(3));
        assert!(matches!(e, LinkError::Connect { .. }), "case {case}: {e}");
    }
}
