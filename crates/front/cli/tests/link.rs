//! The machine link from the command line, as a new user runs it:
//! `plc-sim` in one process, `drive` in another, `replay` of the log;
//! pulling the plug and Ctrl-C; and the refusals a user meets first.

mod common;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use common::*;

/// Starts `plc-sim` on a free port with `args`; returns it and its endpoint.
fn plc_sim(pki: &Path, args: &[&str]) -> (Child, String) {
    let log = pki.with_file_name(format!(
        "plc-{}.mcap",
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_nanos()
    ));
    let mut child = Command::new(bin())
        .args(["plc-sim", "--port", "0", "--pki"])
        .arg(pki)
        .arg("--log")
        .arg(log)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("plc-sim starts");
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut endpoint = None;
    let mut seen = String::new();
    for _ in 0..5 {
        let mut line = String::new();
        if err.read_line(&mut line).unwrap_or(0) == 0 {
            break;
        }
        seen.push_str(&line);
        if let Some(i) = line.find("opc.tcp://") {
            endpoint = line[i..].split_whitespace().next().map(str::to_string);
            break;
        }
    }
    // Keep draining stderr so the child never blocks on a full pipe.
    std::thread::spawn(move || {
        let mut rest = String::new();
        while err.read_line(&mut rest).unwrap_or(0) > 0 {
            rest.clear();
        }
    });
    let endpoint = endpoint.unwrap_or_else(|| panic!("plc-sim printed no endpoint:\n{seen}"));
    (child, endpoint)
}

fn finish(mut child: Child) -> String {
    let status = wait_or_kill(&mut child, Duration::from_secs(120), "plc-sim");
    assert!(status.success(), "plc-sim exit {status:?}");
    let mut s = String::new();
    use std::io::Read;
    child.stdout.take().unwrap().read_to_string(&mut s).unwrap();
    s
}

/// Starts `drive` on the straight scenario against `endpoint`, logging to
/// `log`, its stderr piped; the process.
fn spawn_drive(endpoint: &str, pki: &Path, log: &Path) -> Child {
    Command::new(bin())
        .args([
            "drive",
            "--endpoint",
            endpoint,
            "--scenario",
            "straight",
            "--pki",
        ])
        .arg(pki)
        .arg("--log")
        .arg(log)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn plc_sim_and_drive_run_the_loop_and_replay_gives_its_metrics() {
    let d = TempDir::new("link-loop");
    let pki = d.path().join("pki");
    let (sim, endpoint) = plc_sim(
        &pki,
        &["--scenario", "fig9a", "--lockstep", "--duration", "60"],
    );
    let out = d.path().join("out");
    let drive = run_with_timeout(
        &[
            "drive".as_ref(),
            "--endpoint".as_ref(),
            endpoint.as_str().as_ref(),
            "--scenario".as_ref(),
            "fig9a".as_ref(),
            "--pki".as_ref(),
            pki.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--json".as_ref(),
        ],
        Duration::from_secs(120),
    )
    .ok();
    let dj = drive.json();
    assert_eq!(dj["job"], "drive");
    assert_eq!(dj["link"]["metrics_on"], "simulator truth");
    assert_eq!(dj["link"]["policy"], "basic256-sha256");
    assert!(out.join("drive.mcap").exists() && out.join("track_path.svg").exists());
    let replay = run(&[
        "replay".as_ref(),
        out.join("drive.mcap").as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    let track = run(&["track", "--scenario", "fig9a", "--json"]).ok().json();
    for k in [
        "max_centroid_dev_m",
        "mean_centroid_dev_m",
        "final_position_error_m",
    ] {
        let (a, b, c) = (
            dj[k].as_f64().unwrap(),
            replay[k].as_f64().unwrap(),
            track[k].as_f64().unwrap(),
        );
        assert_eq!(a, b, "{k}: replay gives the drive's figure");
        assert!((a - c).abs() < 1e-6, "{k}: lockstep drive {a} vs track {c}");
    }
    // A real machine's record: the run's track as a CSV of receiver fixes
    // (heading north-clockwise, columns in another order, one extra column)
    // replayed against the planned path gives the same deviations.
    let text = std::fs::read_to_string(out.join("track.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (ct, cx, cy, ch) = (col("t_s"), col("x_m"), col("y_m"), col("heading_deg"));
    let mut csv = String::from("heading_deg,north_m,east_m,quality,t_s\n");
    let mut last_t = f64::NEG_INFINITY;
    for l in lines {
        let c: Vec<&str> = l.split(',').collect();
        let t: f64 = c[ct].parse().unwrap();
        if t <= last_t {
            continue; // a leg's end and the next leg's start share a tick
        }
        last_t = t;
        let phi = (90.0 - c[ch].parse::<f64>().unwrap()).rem_euclid(360.0);
        csv.push_str(&format!("{phi},{},{},4,{t}\n", c[cy], c[cx]));
    }
    let fixes = out.with_file_name("fixes.csv");
    std::fs::write(&fixes, csv).unwrap();
    let from_csv = run(&[
        "replay".as_ref(),
        fixes.as_os_str(),
        "--path".as_ref(),
        "fig9a".as_ref(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    assert_eq!(from_csv["measured_on"], "rtk fixes");
    for k in ["max_centroid_dev_m", "mean_centroid_dev_m"] {
        let (a, b) = (dj[k].as_f64().unwrap(), from_csv[k].as_f64().unwrap());
        assert!((a - b).abs() < 1e-6, "{k}: drive {a} vs CSV replay {b}");
    }
    // plc-sim is still up: stop it by its own clock.
    let mut sim = sim;
    let _ = sim.kill();
    let _ = sim.wait();
}

#[test]
fn killing_drive_stops_the_machine_and_it_stays_stopped_until_acknowledged() {
    let d = TempDir::new("link-kill");
    let pki = d.path().join("pki");
    let (sim, endpoint) = plc_sim(
        &pki,
        &["--scenario", "straight", "--duration", "8", "--json"],
    );
    let mut drive = spawn_drive(&endpoint, &pki, &d.path().join("d.mcap"));
    std::thread::sleep(Duration::from_millis(3000));
    drive.kill().unwrap(); // SIGKILL: no chance to say goodbye
    let _ = drive.wait();
    let s = parse_one_json(&finish(sim)).unwrap();
    assert_eq!(s["moved_while_faulted"], false);
    assert_eq!(s["faults_latched"], 1, "{s}");
    let fault = s["fault"]
        .as_str()
        .expect("still latched at the end: no self-restart");
    assert!(
        fault.contains("dropped") || fault.contains("heartbeat"),
        "{fault}"
    );
    assert!(
        s["travelled_m"].as_f64().unwrap() > 0.1,
        "it had moved: {s}"
    );
    // The killed drive's log: every control period up to the kill, and
    // replay says it was cut.
    let r = run(&[
        "replay".as_ref(),
        d.path().join("d.mcap").as_os_str(),
        "--json".as_ref(),
    ]);
    let j = parse_one_json(&r.stdout).unwrap_or_else(|e| panic!("{e}: {}", r.stderr));
    assert_eq!(j["cut"], true, "{j}");
    assert!(j["max_centroid_dev_m"].as_f64().unwrap().is_finite(), "{j}");
}

#[test]
fn sigterm_and_ctrl_c_zero_the_setpoints_and_leave_a_log_that_says_why() {
    for signal in ["-TERM", "-INT", "-HUP"] {
        let d = TempDir::new("link-int");
        let pki = d.path().join("pki");
        let (sim, endpoint) = plc_sim(
            &pki,
            &["--scenario", "straight", "--duration", "8", "--json"],
        );
        let mut drive = spawn_drive(&endpoint, &pki, &d.path().join("d.mcap"));
        std::thread::sleep(Duration::from_millis(3000));
        let ok = Command::new("kill")
            .args([signal, &drive.id().to_string()])
            .status()
            .unwrap();
        assert!(ok.success());
        let status = wait_or_kill(&mut drive, Duration::from_secs(20), "drive");
        let mut err = String::new();
        use std::io::Read;
        drive
            .stderr
            .take()
            .unwrap()
            .read_to_string(&mut err)
            .unwrap();
        assert_eq!(status.code(), Some(130), "{signal}: {err}");
        assert!(err.contains("setpoints zeroed"), "{signal}: {err}");
        let s = parse_one_json(&finish(sim)).unwrap();
        // The workstation's own zeroing reached the PLC, then its release.
        assert!(
            !s["setpoints_zeroed_at_s"].as_array().unwrap().is_empty(),
            "{signal}: {s}"
        );
        assert!(
            s["events"]
                .as_array()
                .unwrap()
                .iter()
                .any(|e| e["kind"] == "control-released"),
            "{signal}: {s}"
        );
        // The log is whole (closed by drive itself) and its last event says why.
        let r = run(&[
            "replay".as_ref(),
            d.path().join("d.mcap").as_os_str(),
            "--json".as_ref(),
        ]);
        let j = parse_one_json(&r.stdout).unwrap_or_else(|e| panic!("{e}: {}", r.stderr));
        assert_eq!(j["cut"], false, "{signal}: {j}");
        let why = j["ended"].as_str().unwrap_or_default();
        assert!(why.contains("interrupted"), "{signal}: {why}");
    }
}

#[test]
fn the_link_refuses_what_it_must_and_names_it() {
    let d = TempDir::new("link-bad");
    let pki = d.path().join("pki");
    run(&[
        "pki".as_ref(),
        "init".as_ref(),
        "--dir".as_ref(),
        pki.as_os_str(),
    ])
    .ok();
    let log = d.path().join("x.mcap");
    // Unreachable endpoint: named, no log left behind.
    let r = run(&[
        "drive".as_ref(),
        "--endpoint".as_ref(),
        "opc.tcp://127.0.0.1:9/".as_ref(),
        "--pki".as_ref(),
        pki.as_os_str(),
        "--log".as_ref(),
        log.as_os_str(),
    ])
    .fails();
    assert!(
        r.error_message().contains("opc.tcp://127.0.0.1:9/"),
        "{}",
        r.stderr
    );
    assert!(!log.exists());
    // Security None only with --insecure.
    let r = run(&[
        "drive".as_ref(),
        "--policy".as_ref(),
        "none".as_ref(),
        "--pki".as_ref(),
        pki.as_os_str(),
    ])
    .fails();
    assert!(r.error_message().contains("--insecure"), "{}", r.stderr);
    // ... and even then, never with a password.
    let r = run(&[
        "drive".as_ref(),
        "--policy".as_ref(),
        "none".as_ref(),
        "--insecure".as_ref(),
        "--pki".as_ref(),
        pki.as_os_str(),
    ])
    .fails();
    assert!(r.error_message().contains("in clear"), "{}", r.stderr);
    // A track that is not of this path, and a fix no grid has.
    let track = d.write(
        "far.csv",
        "t_s,east_m,north_m,heading_deg\n0,500,500,90\n0.1,500.1,500,90\n",
    );
    let r = run(&[
        "replay".as_ref(),
        track.as_os_str(),
        "--path".as_ref(),
        "fig9a".as_ref(),
    ])
    .fails();
    assert!(
        r.error_message().contains("from the path's start"),
        "{}",
        r.stderr
    );
    let huge = d.write(
        "huge.csv",
        "t_s,east_m,north_m,heading_deg\n0,0,0,90\n0.1,1e308,0,90\n",
    );
    let r = run(&[
        "replay".as_ref(),
        huge.as_os_str(),
        "--path".as_ref(),
        "fig9a".as_ref(),
    ])
    .fails();
    assert!(r.error_message().contains("line 3"), "{}", r.stderr);
    // Faults and time scales plc-sim cannot run.
    for (args, want) in [
        (vec!["--fault", "warp@1"], "unknown fault"),
        (vec!["--fault", "rtk-jump@-1"], "rtk-jump@-1"),
        (vec!["--fault", "link-cut@2:1e9"], "link-cut@2:1e9"),
        (vec!["--time-scale", "0"], "--time-scale 0"),
    ] {
        let pki_s = pki.to_str().unwrap();
        let log_s = d.path().join("p.mcap");
        let log_s = log_s.to_str().unwrap();
        let mut a = vec![
            "plc-sim",
            "--port",
            "0",
            "--duration",
            "1",
            "--pki",
            pki_s,
            "--log",
            log_s,
        ];
        a.extend(args);
        let r = run(&a).fails();
        assert!(r.error_message().contains(want), "{}", r.stderr);
    }
    // A server whose certificate this workstation does not trust, and a wrong password.
    let (sim, endpoint) = plc_sim(&pki, &["--scenario", "straight", "--duration", "30"]);
    let other = d.path().join("other-pki");
    run(&[
        "pki".as_ref(),
        "init".as_ref(),
        "--dir".as_ref(),
        other.as_os_str(),
    ])
    .ok();
    let r = run(&[
        "drive".as_ref(),
        "--endpoint".as_ref(),
        endpoint.as_str().as_ref(),
        "--pki".as_ref(),
        other.as_os_str(),
    ])
    .fails();
    let msg = r.error_message();
    assert!(msg.contains(&endpoint), "{}", r.stderr);
    // Named: whose certificate, where it was saved, the command that trusts it.
    assert!(msg.contains("the PLC's certificate"), "{msg}");
    assert!(msg.contains("autoshovel pki trust --dir"), "{msg}");
    let saved = std::fs::read_dir(other.join("workstation/rejected"))
        .unwrap()
        .count();
    assert_eq!(
        saved, 1,
        "the PLC's certificate saved for a person to check"
    );
    // That command, run, makes the next drive get past the certificate
    // (to the PLC's own refusal of this workstation, named as such).
    let rejected = std::fs::read_dir(other.join("workstation/rejected"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    run(&[
        "pki".as_ref(),
        "trust".as_ref(),
        "--dir".as_ref(),
        other.join("workstation").as_os_str(),
        rejected.as_os_str(),
    ])
    .ok();
    let r = run(&[
        "drive".as_ref(),
        "--endpoint".as_ref(),
        endpoint.as_str().as_ref(),
        "--pki".as_ref(),
        other.as_os_str(),
    ])
    .fails();
    assert!(
        r.error_message()
            .contains("may not trust this workstation's certificate"),
        "{}",
        r.stderr
    );
    let wrong = d.write("wrong.password", "not-the-password\n");
    let r = run(&[
        "drive".as_ref(),
        "--endpoint".as_ref(),
        endpoint.as_str().as_ref(),
        "--pki".as_ref(),
        pki.as_os_str(),
        "--password-file".as_ref(),
        wrong.as_os_str(),
    ])
    .fails();
    assert!(r.error_message().contains(&endpoint), "{}", r.stderr);
    let mut sim = sim;
    let _ = sim.kill();
    let _ = sim.wait();
}
