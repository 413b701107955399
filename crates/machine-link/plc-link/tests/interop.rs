//! Interoperability with two OPC UA stacks nobody here wrote: Python's
//! `asyncua` (PyPI) and `node-opcua` (npm), each as a client of `plc-sim`;
//! asyncua also as a PLC that `drive` runs a scenario against; all over
//! Basic256Sha256 SignAndEncrypt with the operator's identity, under the
//! control-authority model (claims, refusals of a second operator); and
//! the workstation's refusals of a PLC whose model or values are wrong.
//!
//! `.ci/run` installs asyncua in a venv and sets `AUTOSHOVEL_PYTHON`, and
//! node-opcua with npm and sets `AUTOSHOVEL_NODE_MODULES`; with them set
//! (or under CI), a missing peer fails the test. Without, the tests are
//! skipped, saying so.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use autoshovel_plc_link::{drive, Clock, DriveOptions, Link, LinkError};
use autoshovel_walk_tracker::scenario::resolve;
use autoshovel_walk_tracker::{ControllerKind, Noise};

mod peers;
use peers::{node, operator as params, pki_root, python, rt, script};

#[test]
fn python_asyncua_client_browses_reads_and_writes_securely() {
    let Some(py) = python() else { return };
    let (_, root, pw) = pki_root();
    let sc = resolve("curve", Some(Noise::Rtk), 1).unwrap();
    rt().block_on(async {
        let server = peers::plc_sim(&sc.setup, Clock::Scaled(1.0), Vec::new(), 0).await;
        let (py, endpoint, root, pw) = (py.clone(), server.endpoint(), root.clone(), pw.clone());
        let out = tokio::task::spawn_blocking(move || {
            Command::new(py)
                .arg(script("ua_client.py"))
                .arg(endpoint)
                .arg(root)
                .arg(pw)
                .output()
                .unwrap()
        })
        .await
        .unwrap();
        assert!(
            out.status.success(),
            "ua_client.py: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let names = |k: &str| -> Vec<String> {
            v[k].as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_str().unwrap().to_string())
                .collect()
        };
        for f in [
            "Crawler",
            "Rtk",
            "Fault",
            "Limits",
            "Workstation",
            "Mode",
            "Clock",
        ] {
            assert!(names("shovel_children").contains(&f.to_string()), "{v}");
        }
        for f in ["East", "North", "Heading", "FixQuality", "Timestamp"] {
            assert!(names("rtk_children").contains(&f.to_string()), "{v}");
        }
        assert_eq!(v["setpoint_type"], "Double");
        assert_eq!(v["max_rpm"], 3000.0);
        {
            let plc = server.plc.lock().unwrap();
            // The pose it read is the receiver's (at rest: the start fix).
            let fix = plc.fix().unwrap();
            assert_eq!(v["east_m"].as_f64().unwrap(), fix.east_m);
            assert_eq!(v["quality"], 4);
            // Before claiming control the operator's write changes
            // nothing; after InitLock it is taken; the out-of-range one was
            // refused and latched a fault, which zeroed the setpoints.
            assert_eq!(v["write_unclaimed"], "BadRequiresLock", "{v}");
            assert_eq!(v["init_lock"], 0, "{v}");
            assert_eq!(v["locking_user"], "operator", "{v}");
            assert_eq!(v["write_in_range"], "Good");
            // A second operator session neither claims nor commands.
            assert_eq!(v["second_init_lock"], -1, "{v}");
            assert_eq!(v["second_write"], "BadLocked", "{v}");
            assert_eq!(plc.setpoints().left_rpm, 0.0, "cleared by the fault");
            assert_eq!(v["write_out_of_range"], "BadOutOfRange");
            assert_eq!(v["fault_after"], true);
            assert!(plc.events.iter().any(|e| e.kind == "setpoint-rejected"));
            // Anonymous may read, not write.
            assert!(v["anonymous_read_east"].is_number());
            assert_ne!(v["anonymous_write"], "Good", "{v}");
        }
        server.stop().await;
    });
}

#[test]
fn node_opcua_client_reads_claims_and_is_refused_as_a_second_operator() {
    let Some((node, modules)) = node() else {
        return;
    };
    let (_, root, pw) = pki_root();
    let sc = resolve("curve", Some(Noise::Rtk), 1).unwrap();
    rt().block_on(async {
        let server = peers::plc_sim(&sc.setup, Clock::Scaled(1.0), Vec::new(), 0).await;
        let (endpoint, root, pw) = (server.endpoint(), root.clone(), pw.clone());
        let out = tokio::task::spawn_blocking(move || {
            Command::new(node)
                .arg(script("node/client.js"))
                .arg(endpoint)
                .arg(root)
                .arg(pw)
                .env("NODE_PATH", modules)
                .output()
                .unwrap()
        })
        .await
        .unwrap();
        assert!(
            out.status.success(),
            "client.js: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        // node-opcua prints notices of its own: the JSON is the line that is an object.
        let stdout = String::from_utf8_lossy(&out.stdout);
        let last = stdout
            .lines()
            .find(|l| l.starts_with('{'))
            .unwrap_or_default();
        let v: serde_json::Value =
            serde_json::from_str(last).unwrap_or_else(|e| panic!("{e}: {stdout}"));
        {
            let p = server.plc.lock().unwrap();
            assert_eq!(
                v["east_m"].as_f64().unwrap(),
                p.fix().unwrap().east_m,
                "{v}"
            );
            assert_eq!(v["instance"], server.instance_id(), "{v}");
            assert_eq!(v["write_unclaimed"], "BadRequiresLock", "{v}");
            assert_eq!(v["init_lock"], 0, "{v}");
            assert_eq!(v["locking_user"], "operator", "{v}");
            assert_eq!(v["write_claimed"], "Good", "{v}");
            assert_eq!(v["second_init_lock"], -1, "{v}");
            assert_eq!(v["second_write"], "BadLocked", "{v}");
            assert!(v["anonymous_read_east"].is_number(), "{v}");
            assert_ne!(v["anonymous_write"], "Good", "{v}");
            assert_eq!(v["exit_lock"], 0, "{v}");
            // The claimed write was obeyed as a setpoint; the release latched.
            assert!(p.control.holder().is_none());
            assert_eq!(
                p.fault.as_ref().map(|f| f.0),
                Some(autoshovel_plc_link::model::fault_code::CONTROL_ENDED)
            );
        }
        server.stop().await;
    });
}

/// A python asyncua PLC on a free port, started at `pose`, with `extra` args.
struct PyPlc {
    child: Child,
    endpoint: String,
}

impl PyPlc {
    fn start(py: &str, pose: (f64, f64, f64), extra: &[&str]) -> PyPlc {
        let (_, root, pw) = pki_root();
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let mut child = Command::new(py)
            .arg(script("ua_plc.py"))
            .arg(port.to_string())
            .arg(root)
            .arg(pw)
            .args([pose.0.to_string(), pose.1.to_string(), pose.2.to_string()])
            .args(extra)
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        assert_eq!(line.trim(), "ready", "ua_plc.py did not start");
        PyPlc {
            child,
            endpoint: format!("opc.tcp://127.0.0.1:{port}/"),
        }
    }
}

impl Drop for PyPlc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn drive_runs_a_scenario_against_a_python_asyncua_plc() {
    let Some(py) = python() else { return };
    let sc = resolve("fig9a", Some(Noise::Off), 1).unwrap();
    let s = sc.setup.start;
    let plc = PyPlc::start(&py, (s.x, s.y, s.theta), &[]);
    let p = params(&plc.endpoint);
    let run = rt().block_on(async {
        let link = Link::open(&p).await.unwrap();
        assert!(!link.simulator, "a PLC, not plc-sim");
        let mut ctl = ControllerKind::Fuzzy.build(&sc.controllers);
        let opts = DriveOptions::new(&sc.setup, &p);
        let r = drive(&link, &sc.setup, ctl.as_mut(), &opts, None).await;
        link.close().await;
        r.unwrap()
    });
    let m = &run.run.metrics;
    assert!(!run.truth, "measured on the fixes");
    assert!(m.completed, "{m:?} {:?}", run.run.events);
    // An ideal crawler at 10 ms steps: the same tracker keeps it within
    // a few centimetres once on the path (fig9a in process: 4.4 cm).
    assert!(m.max_centroid_dev_m < 0.10, "{m:?}");
    assert!(m.final_position_error_m < 0.10, "{m:?}");
}

/// A node-opcua PLC on a free port, started at `pose`.
struct NodePlc {
    child: Child,
    endpoint: String,
}

impl NodePlc {
    fn start(node: &str, modules: &Path, pose: (f64, f64, f64)) -> NodePlc {
        let (_, root, pw) = pki_root();
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let mut child = Command::new(node)
            .arg(script("node/plc.js"))
            .arg(port.to_string())
            .arg(root)
            .arg(pw)
            .args([pose.0.to_string(), pose.1.to_string(), pose.2.to_string()])
            .env("NODE_PATH", modules)
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        // node-opcua may print notices of its own before "ready".
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut seen = String::new();
        loop {
            let mut line = String::new();
            if out.read_line(&mut line).unwrap_or(0) == 0 {
                panic!("plc.js ended before it was ready:\n{seen}");
            }
            if line.trim() == "ready" {
                break;
            }
            seen.push_str(&line);
        }
        std::thread::spawn(move || {
            let mut rest = String::new();
            while out.read_line(&mut rest).unwrap_or(0) > 0 {
                rest.clear();
            }
        });
        NodePlc {
            child,
            endpoint: format!("opc.tcp://127.0.0.1:{port}/"),
        }
    }
}

impl Drop for NodePlc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn drive_runs_a_scenario_against_a_node_opcua_plc() {
    let Some((node, modules)) = node() else {
        return;
    };
    let sc = resolve("fig9a", Some(Noise::Off), 1).unwrap();
    let s = sc.setup.start;
    let plc = NodePlc::start(&node, &modules, (s.x, s.y, s.theta));
    let p = params(&plc.endpoint);
    let run = rt().block_on(async {
        let link = Link::open(&p).await.unwrap();
        assert!(!link.simulator, "a PLC, not plc-sim");
        assert!(link.instance.starts_with("node-"), "{}", link.instance);
        // Another session cannot claim the machine this drive holds.
        let other = Link::open(&p).await.unwrap();
        let mut ctl = ControllerKind::Fuzzy.build(&sc.controllers);
        let opts = DriveOptions::new(&sc.setup, &p);
        let driving = drive(&link, &sc.setup, ctl.as_mut(), &opts, None);
        let probing = async {
            tokio::time::sleep(Duration::from_secs(2)).await;
            let claim = other.claim().await;
            assert!(
                matches!(claim, Err(LinkError::ControlHeld { .. })),
                "{claim:?}"
            );
        };
        let (r, ()) = tokio::join!(driving, probing);
        other.close().await;
        link.close().await;
        r.unwrap()
    });
    let m = &run.run.metrics;
    assert!(!run.truth, "measured on the fixes");
    assert!(m.completed, "{m:?} {:?}", run.run.events);
    // The same ideal crawler as the asyncua PLC's, stepped by node's timers.
    assert!(m.max_centroid_dev_m < 0.10, "{m:?}");
    assert!(m.final_position_error_m < 0.10, "{m:?}");
}

#[test]
fn a_plc_with_a_wrong_type_a_nan_or_other_limits_is_refused_by_node() {
    let Some(py) = python() else { return };
    let sc = resolve("fig9a", Some(Noise::Off), 1).unwrap();
    let s = sc.setup.start;
    let pose = (s.x, s.y, s.theta);
    {
        let plc = PyPlc::start(&py, pose, &["--wrong-type", "Shovel.Rtk.East"]);
        let p = params(&plc.endpoint);
        let e = rt().block_on(Link::open(&p)).err().expect("refused");
        match &e {
            LinkError::Model { node, why, .. } => {
                assert!(node.ends_with("Shovel.Rtk.East"), "{e}");
                assert!(why.contains("Double"), "{e}");
            }
            other => panic!("{other}"),
        }
    }
    {
        let plc = PyPlc::start(&py, pose, &["--nan", "Shovel.Crawler.Left.Speed"]);
        let p = params(&plc.endpoint);
        rt().block_on(async {
            let link = Link::open(&p).await.unwrap();
            let mut ctl = ControllerKind::Fuzzy.build(&sc.controllers);
            let opts = DriveOptions::new(&sc.setup, &p);
            let e = drive(&link, &sc.setup, ctl.as_mut(), &opts, None)
                .await
                .expect_err("refused");
            assert!(
                matches!(&e, LinkError::BadValue { node, .. } if node.ends_with("Shovel.Crawler.Left.Speed")),
                "{e}"
            );
            assert!(e.to_string().contains("NaN"), "{e}");
            link.close().await;
        });
    }
    {
        // The scenario's machine is not this PLC's.
        let plc = PyPlc::start(&py, pose, &[]);
        let p = params(&plc.endpoint);
        let mut setup = sc.setup.clone();
        setup.crawler.motor_max_rpm = 1500.0;
        rt().block_on(async {
            let link = Link::open(&p).await.unwrap();
            let mut ctl = ControllerKind::Fuzzy.build(&sc.controllers);
            let opts = DriveOptions::new(&setup, &p);
            let e = drive(&link, &setup, ctl.as_mut(), &opts, None)
                .await
                .expect_err("refused");
            assert!(matches!(e, LinkError::Mismatch { .. }), "{e}");
            assert!(e.to_string().contains("MotorMaxSpeed"), "{e}");
            link.close().await;
        });
    }
}
