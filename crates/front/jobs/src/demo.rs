//! The demo: every job on its embedded defaults, one report (`index.html`
//! linking each job's plots and tabulating its summary) and one
//! `summary.json` of them all.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use autoshovel_report::{write_index_html, write_summary, Section};
use autoshovel_walk_planner::study::StudyParams;
use autoshovel_walk_planner::{FieldKind, Scenario};
use serde_json::{json, Value};

use autoshovel_terrain::perceive::PerceptionParams;

use crate::{JobError, OutDir, Result, Written};

/// How the demo runs.
#[derive(Debug, Clone, Copy)]
pub struct DemoOptions {
    /// Replace files in the output folder that autoshovel did not write.
    pub force: bool,
    /// Draw the progress bars of the longer jobs on stderr.
    pub progress: bool,
    /// Set (Ctrl-C) to zero the setpoints of the demo's drive and end it.
    pub stop: &'static AtomicBool,
}

/// Never set: a demo that cannot be stopped by its drive's flag.
static NEVER: AtomicBool = AtomicBool::new(false);

impl Default for DemoOptions {
    fn default() -> Self {
        Self {
            force: false,
            progress: false,
            stop: &NEVER,
        }
    }
}

/// What the demo made.
#[derive(Debug, Clone)]
pub struct Demo {
    /// The report, `index.html`.
    pub index: PathBuf,
    /// Every job's summary, under its key (as `summary.json` holds them).
    pub jobs: Value,
}

/// Runs the demo into `out`; `say` hears one line per job as it ends.
///
/// The demo writes only into its own sub-folders (each job under the output
/// rule of `autoshovel_report::staging`) and its `index.html`,
/// `summary.json` and the two scans it generates, which its summary lists
/// as its own; without `force` a user's file of those names is refused
/// before any work.
pub fn run(out: &Path, options: DemoOptions, say: &mut dyn FnMut(&str)) -> Result<Demo> {
    let DemoOptions {
        force,
        progress,
        stop,
    } = options;
    if out.exists() && !out.is_dir() {
        return Err(JobError::setting(
            "--out",
            out.display(),
            "exists and is not a directory",
        ));
    }
    let ours = autoshovel_report::files_written_before(out);
    for name in [
        autoshovel_report::INDEX_FILE,
        autoshovel_report::SUMMARY_FILE,
    ] {
        let target = out.join(name);
        if let Some(why) = autoshovel_report::refusal(&target, &[], &ours, force) {
            return Err(autoshovel_report::ReportError::Refused { path: target, why }.into());
        }
    }
    std::fs::create_dir_all(out).map_err(|e| JobError::io(out, e))?;
    let mut p = Place {
        out: out.to_path_buf(),
        force,
        progress,
        stop,
        ours,
        say,
    };
    let mut r = Report::default();
    plan_paths(&mut p, &mut r)?;
    tracking(&mut p, &mut r)?;
    drive(&mut p, &mut r)?;
    perception(&mut p, &mut r)?;
    dig(&mut p, &mut r)?;
    excavation(&mut p, &mut r)?;
    shift(&mut p, &mut r)?;
    study(&mut p, &mut r)?;
    let Report {
        mut own,
        sections,
        summaries,
    } = r;
    let out = p.out;
    let all = Value::Object(summaries);
    own.extend([
        autoshovel_report::INDEX_FILE.to_string(),
        autoshovel_report::SUMMARY_FILE.to_string(),
    ]);
    write_summary(&out, &json!({ "job": "demo", "jobs": all, "files": own }))?;
    let index = write_index_html(&out, "autoshovel demo", &sections)?;
    Ok(Demo { index, jobs: all })
}

/// Where the demo writes, by what rule, and who hears of each job.
struct Place<'a> {
    out: PathBuf,
    force: bool,
    progress: bool,
    stop: &'static AtomicBool,
    /// Files autoshovel wrote in `out` before this run.
    ours: std::collections::HashSet<PathBuf>,
    say: &'a mut dyn FnMut(&str),
}

impl Place<'_> {
    /// A job's folder under the demo's.
    fn dir(&self, sub: &str) -> OutDir {
        OutDir {
            dir: self.out.join(sub),
            inputs: Vec::new(),
            force: self.force,
        }
    }

    /// One line about a job that ended.
    fn say(&mut self, line: String) {
        (self.say)(&line)
    }
}

/// The report so far: its sections, the jobs' summaries and the files the
/// demo wrote itself.
#[derive(Default)]
struct Report {
    own: Vec<String>,
    sections: Vec<Section>,
    summaries: serde_json::Map<String, Value>,
}

impl Report {
    /// A job's section of the report and its summary under `key`.
    fn add(&mut self, key: &str, section: Section, summary: Value) {
        self.sections.push(section);
        self.summaries.insert(key.to_string(), summary);
    }

    /// [`Report::add`] for a job shown whole under its key, with every
    /// plot and file it wrote.
    fn add_job(
        &mut self,
        key: &str,
        description: &str,
        summary: Value,
        sub: &str,
        written: &Written,
    ) {
        let shown = section(
            key,
            description,
            &summary,
            sub,
            &written.plots,
            &written.files,
        );
        self.add(key, shown, summary);
    }
}

/// Potential-field walks on the built-in scenarios, improved and classic.
fn plan_paths(p: &mut Place, r: &mut Report) -> Result<()> {
    let runs: [(&str, FieldKind, &str); 6] = [
        ("straight", FieldKind::Improved, "Straight travel along a haul road (Fig. 1a)."),
        ("curve", FieldKind::Improved, "Round a parked truck and a stockpile on a bending road (Fig. 1b, Fig. 4a/b)."),
        ("curve", FieldKind::Classic, "The classic field (eqs. 1–5) on the same road, the paper's baseline: it has no heading control and no escape."),
        ("curve-reverse", FieldKind::Improved, "The same road travelled in reverse."),
        ("v-shape", FieldKind::Improved, "V-shaped move: reverse to the midpoint, stop, forward to the new face, arriving square to it (Fig. 1c, Fig. 4c/d)."),
        ("v-shape", FieldKind::Classic, "The classic field on the V-shaped move."),
    ];
    for (name, field, description) in runs {
        let scenario = Scenario::builtin(name).expect("built-in scenario");
        let key = format!("plan-path {name} {}", field.name());
        let sub = format!("plan-path-{name}-{}", field.name());
        let dir = p.dir(&sub);
        let job = crate::plan_path(
            &scenario,
            field,
            autoshovel_walk_planner::DEFAULT_HEADING_TOLERANCE_DEG,
            Some(&dir),
        )?;
        let s = &job.summary;
        let v = |x: Option<f64>| x.unwrap_or(f64::NAN);
        p.say(format!(
            "{key:40} {}",
            if s.success {
                format!(
                    "ok: {:.2} m, heading error {:.2} deg, clearance {:.2} m, {:.2} ms",
                    v(s.length_m),
                    v(s.final_heading_error_deg),
                    v(s.min_clearance_m),
                    v(s.plan_time_ms)
                )
            } else {
                format!("failed: {}", s.error.as_deref().unwrap_or(""))
            }
        ));
        let summary = job.json()?;
        r.add_job(&key, description, summary, &sub, &job.written);
    }
    Ok(())
}

/// Tracking runs of the walking paper's Fig. 9 and §5.3.
fn tracking(p: &mut Place, r: &mut Report) -> Result<()> {
    // Every run uses the fuzzy tracker; the last compares all three. The
    // paths, starts, speeds and noise are said from the scenarios themselves.
    let track_runs: [(&str, bool, &str); 6] = [
        ("fig9a", false, "Fig. 9a"),
        ("fig9b", false, "Fig. 9b"),
        ("straight", false, "§5.3 straight run"),
        ("curve", false, "§5.3 curve round the truck and stockpile"),
        (
            "v-shape",
            false,
            "§5.3 V-shape: reverse, stop at the cusp, forward",
        ),
        (
            "curve",
            true,
            "Every controller on the curve run, same seed (§5.4 compares fuzzy with PID)",
        ),
    ];
    for (name, compare, description) in track_runs {
        let ctl = autoshovel_walk_tracker::ControllerKind::Fuzzy;
        let scenario = autoshovel_walk_tracker::scenario::resolve(name, None, 1)?;
        let key = if compare {
            format!("track {name} --compare")
        } else {
            format!("track {name} fuzzy")
        };
        let sub = if compare {
            format!("track-{name}-compare")
        } else {
            format!("track-{name}-fuzzy")
        };
        let dir = p.dir(&sub);
        let description = format!("{description}: {}.", track_setting(&scenario));
        let description = description.as_str();
        let job = crate::track(&scenario, ctl, compare, Some(&dir))?;
        let m = &job.summary.run.metrics;
        p.say(format!(
            "{key:40} {}: max dev {:.3} m, mean {:.3} m, reached after {:.2} m, final heading error {:.2} deg",
            if job.summary.success { "ok" } else { "FAILED" },
            m.max_centroid_dev_m,
            m.mean_centroid_dev_m,
            m.reached_distance_m,
            m.final_heading_error_deg
        ));
        let summary = job.json()?;
        r.add_job(&key, description, summary, &sub, &job.written);
    }
    Ok(())
}

/// Fig. 9a driven over OPC UA against a simulated PLC.
fn drive(p: &mut Place, r: &mut Report) -> Result<()> {
    // The machine link: a simulated PLC in lockstep on loopback, the
    // workstation driving it over Basic256Sha256 SignAndEncrypt; a PKI made
    // for the run in a temporary folder and removed after.
    {
        use autoshovel_plc_link::{pki, Clock, LinkParams, PlcParams, PlcServer, ServeParams};
        let key = "drive fig9a over OPC UA".to_string();
        let sub = "drive-fig9a";
        let dir = p.dir(sub);
        let scenario = autoshovel_walk_tracker::scenario::resolve("fig9a", None, 1)?;
        let pki_dir =
            std::env::temp_dir().join(format!("autoshovel-demo-pki-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&pki_dir);
        pki::init(&pki_dir, &[])?;
        let pw = pki::read_password(&pki_dir.join(pki::PASSWORD_FILE))?;
        let rt = crate::runtime()?;
        let job = (|| {
            let server = rt.block_on(PlcServer::start(
                PlcParams {
                    setup: scenario.setup.clone(),
                    clock: Clock::Lockstep,
                    heartbeat_timeout: autoshovel_plc_link::HEARTBEAT_TIMEOUT,
                    auto: true,
                    schedule: Vec::new(),
                },
                ServeParams {
                    host: "127.0.0.1".into(),
                    port: 0,
                    pki: pki_dir.clone(),
                    insecure: false,
                    users: vec![(pki::OPERATOR.into(), pw.clone())],
                },
            ))?;
            let params = LinkParams::new(
                &server.endpoint(),
                pki_dir.clone(),
                Some((pki::OPERATOR.into(), pw.clone())),
            );
            let log = dir.dir.join("drive.mcap");
            let overwrite = p.force || p.ours.contains(&log);
            let job = crate::drive(
                &rt,
                &scenario,
                autoshovel_walk_tracker::ControllerKind::Fuzzy,
                &params,
                &log,
                overwrite,
                Some(&dir),
                p.stop,
            );
            rt.block_on(server.stop());
            job
        })();
        let _ = std::fs::remove_dir_all(&pki_dir);
        let job = job?;
        r.own.push(format!("{sub}/drive.mcap"));
        let m = &job.summary.track.run.metrics;
        p.say(format!(
            "{key:40} {}: max dev {:.3} m, mean {:.3} m, setpoint write p50 {:.2} ms (plc-sim in lockstep, metrics on {})",
            if job.summary.track.success { "ok" } else { "FAILED" },
            m.max_centroid_dev_m,
            m.mean_centroid_dev_m,
            job.summary.link.write_ms.p50,
            job.summary.link.metrics_on
        ));
        let summary = job.json()?;
        let mut files = job.written.files.clone();
        files.push("drive.mcap".into());
        r.add(&key, section(
            &key,
            "The walking paper's system (§5.1, Fig. 11) over a real network connection: `autoshovel plc-sim` (the crawler plant, RTK and a PLC's watchdog behind a secure OPC UA server, here in lockstep) driven by `autoshovel drive` on Fig. 9a's path. Lockstep makes the run repeat the in-process `track fig9a` exactly; `drive.mcap` is the run log (Foxglove opens it; `autoshovel replay drive-fig9a/drive.mcap` recomputes the metrics).",
            &summary,
            sub,
            &job.written.plots,
            &files,
        ), summary);
    }
    Ok(())
}

/// The §3 pipeline on a synthetic scan of two pile shapes.
fn perception(p: &mut Place, r: &mut Report) -> Result<()> {
    // Perception: a synthetic scan of each pile shape, levelled, filtered and fitted.
    for shape in [
        autoshovel_terrain::PileShape::Typical,
        autoshovel_terrain::PileShape::ConvexConcave,
    ] {
        let sub = format!("perceive-{}", shape.name());
        let dir = p.dir(&sub);
        let scan = dir.dir.join("scan.pcd");
        let params = autoshovel_terrain::PileParams {
            shape,
            points: 200_000,
            ..Default::default()
        };
        let cloud = autoshovel_terrain::generate_pile(&params)?;
        std::fs::create_dir_all(&dir.dir).map_err(|e| JobError::io(&dir.dir, e))?;
        autoshovel_report::write_file_atomically::<JobError>(
            &scan,
            &[],
            (&p.ours, p.force),
            |scratch, target| {
                let options = autoshovel_point_cloud::io::WriteOptions {
                    encoding: Some(autoshovel_point_cloud::io::Encoding::Binary),
                    ..Default::default()
                };
                autoshovel_point_cloud::io::write_named(scratch, target, &cloud, &options)?;
                Ok(())
            },
        )?;
        r.own.push(format!("{sub}/scan.pcd"));
        let job = crate::perceive(&scan, &PerceptionParams::default(), Some(&dir), false)?;
        let mut written = job.written.clone();
        written.file(&dir.dir, &scan);
        let key = format!("perceive {} pile", shape.name());
        let s = &job.summary;
        p.say(format!(
            "{key:40} roll {:.3} deg (true {:.3}), pitch {:.3} deg (true {:.3}), R² {:.4}, {} → {} points in {:.0} ms",
            s.roll_deg,
            params.roll_rad.to_degrees(),
            s.pitch_deg,
            params.pitch_rad.to_degrees(),
            s.r2,
            s.input_points,
            s.output_points,
            s.total_ms
        ));
        let summary = job.json()?;
        let description = format!(
            "A synthetic {}-point scan of a {} pile (Fig. 7) tilted by roll {:.1}°, pitch {:.1}°, then the §3 pipeline.",
            params.points,
            shape.name(),
            params.roll_rad.to_degrees(),
            params.pitch_rad.to_degrees()
        );
        r.add_job(&key, &description, summary, &sub, &written);
    }
    Ok(())
}

/// The rope-shovel dig plan on the typical pile and on all four.
fn dig(p: &mut Place, r: &mut Report) -> Result<()> {
    // Dig planning: the typical pile, then all four beside the paper's Tables 4–5.
    let setup = autoshovel_rope_shovel_dig::DigSetup::scale_model(1);
    let sub = "plan-dig-typical";
    let dir = p.dir(sub);
    let typical = autoshovel_rope_shovel_dig::paper_row(autoshovel_terrain::PileShape::Typical);
    let pile = autoshovel_rope_shovel_dig::Pile::shape(typical.shape, &setup.profile)?;
    let job = crate::plan_dig(&pile, &setup, Some(&dir))?;
    let key = "plan-dig typical";
    let s = &job.summary;
    match (&s.error, &s.plan) {
        (None, Some(plan)) => p.say(format!(
            "{key:40} ok: m_dig {:.3} kg (paper {}), fill {:.1} %, t_d {:.2} s, f {:.2} (paper {}), {:.0} ms",
            plan.m_dig_kg,
            typical.m_dig_kg,
            100.0 * plan.fill_factor,
            plan.td_s,
            plan.f,
            typical.f,
            s.plan_time_ms
        )),
        (e, _) => p.say(format!("{key:40} FAILED: {}", e.as_deref().unwrap_or("no plan"))),
    }
    let summary = job.json()?;
    let mut shown = summary.clone();
    if let Some(o) = shown.as_object_mut() {
        o.remove("geometry");
        if let Some(cs) = o.get_mut("constraints").and_then(Value::as_object_mut) {
            for c in cs.values_mut() {
                *c = c["value"].clone();
            }
        }
    }
    r.add(key, section(
        key,
        &format!("The rope-shovel paper's §4 on its typical 40° pile at the 1:30 scale: a 6th-order tooth path chosen by the Grey Wolf Optimizer ({} wolves, {} iterations, {} start) to minimise {}·f1 + {}·f2 under c1–c18 (constraint values shown: ≤ 0 is met). The first plot draws the machine at the start and end of the dig: our reading of the paper's missing Fig. 2.", setup.gwo.population, setup.gwo.iterations, setup.gwo.init.name(), setup.profile.objective.k1, setup.profile.objective.k2),
        &shown,
        sub,
        &job.written.plots,
        &job.written.files,
    ), summary);
    let sub = "plan-dig-all-surfaces";
    let dir = p.dir(sub);
    let job = crate::plan_dig_all_surfaces(&setup, Some(&dir), |_| {})?;
    let key = "plan-dig --all-surfaces";
    p.say(autoshovel_figures::dig::markdown_table(&job.summary));
    if let Some(e) = job.summary.error() {
        p.say(format!("{key:40} FAILED: {e}"));
    }
    let calibrated: Vec<&str> = autoshovel_rope_shovel_dig::PAPER_TABLES_4_5
        .iter()
        .filter(|r| r.calibrated())
        .map(|r| r.shape.name())
        .collect();
    let description = format!(
        "The four piles of Fig. 7 in Table 5's order, each planned with the same profile and seed, beside the paper's Tables 4–5 (paper values and the relative difference of m_dig and f). The profile's digging resistance is calibrated on the {} pile (SPEC §4.2); the other three piles are predictions. Each pile's full outputs are in its own folder.",
        calibrated.join(", ")
    );
    r.add(
        key,
        section(
            key,
            &description,
            &autoshovel_report::summary_value(&autoshovel_rope_shovel_dig::table_summary(
                &job.summary,
            ))?,
            sub,
            // The comparison and each pile's path; the other plots are in the pile folders.
            &job.written
                .plots
                .iter()
                .filter(|p| p.ends_with("paths.svg") || p.ends_with("dig_path.svg"))
                .cloned()
                .collect::<Vec<_>>(),
            &job.written
                .files
                .iter()
                .filter(|f| !f.contains('/') || f.ends_with("summary.json"))
                .cloned()
                .collect::<Vec<_>>(),
        ),
        job.json()?,
    );
    Ok(())
}

/// The hydraulic-excavator cases of its paper's §3 and two boulders.
fn excavation(p: &mut Place, r: &mut Report) -> Result<()> {
    // Hydraulic excavator: the paper's §3 case passed over and under, then two boulders in one dig.
    let excavate_runs: [(&str, &str); 3] = [
        ("paper-over", "The hydraulic-excavator paper's §3 case (Fig. 5): 0.9 m³ from (7, 0) at 0.7 m depth; the descending tooth meets a 0.5 m boulder it did not know about on its upper part, γ ∈ (0°, 180°), so it passes over; the boulder counts as dug and the rest is re-planned."),
        ("paper-under", "The same case with the boulder met on its lower part, γ ∈ (180°, 360°): the bucket passes under it."),
        ("two-boulders", "Two boulders in one dig: the first passed over while descending, the second met while lifting out after the re-plan; each contact repeats preimage decision, forward search and re-plan."),
    ];
    for (name, description) in excavate_runs {
        let setup = autoshovel_excavator_dig::Setup::load(name, None)?;
        let description = match autoshovel_excavator_dig::paper_case(name) {
            Some(c) => format!(
                "{description} ({}; paper: {} m³, contacts at {} s)",
                c.figure,
                c.volume_m3,
                c.contacts_text()
            ),
            None => description.to_string(),
        };
        let sub = format!("plan-excavate-{name}");
        let dir = p.dir(&sub);
        let job = crate::plan_excavate(&setup, Some(&dir))?;
        let key = format!("plan-excavate {name}");
        let s = &job.summary;
        let contacts: Vec<String> = s
            .plan
            .contacts
            .iter()
            .map(|c| format!("{:.2} s γ {:.0}° {}", c.t_s, c.gamma_deg, c.decision))
            .collect();
        p.say(format!(
            "{key:40} ok: {:.3} m³ of {:.3} m³ ({:+.2} %), contacts: {}, dig {:.1} s, {:.1} ms",
            s.plan.achieved_volume_m3,
            s.plan.target_volume_m3,
            s.volume_error_pct,
            if contacts.is_empty() {
                "none".to_string()
            } else {
                contacts.join("; ")
            },
            s.plan.duration_s,
            s.plan.plan_time_ms
        ));
        let summary = job.json()?;
        let mut shown = summary.clone();
        if let Some(o) = shown.as_object_mut() {
            o.remove("segments");
        }
        r.add(
            &key,
            section(
                &key,
                &description,
                &shown,
                &sub,
                &job.written.plots,
                &job.written.files,
            ),
            summary,
        );
    }
    Ok(())
}

/// A 45-minute shift of the whole machine on the built-in bench.
fn shift(p: &mut Place, r: &mut Report) -> Result<()> {
    // The whole machine: a short shift on the built-in bench.
    let scenario = autoshovel_work_shift::ShiftScenario::bench();
    let options = autoshovel_work_shift::ShiftOptions {
        hours: Some(0.75),
        ..Default::default()
    };
    let sub = "shift";
    let dir = p.dir(sub);
    let job = crate::shift(
        &scenario,
        &autoshovel_rope_shovel_dig::MachineProfile::scale_model(),
        &options,
        Some(&dir),
        false,
    )?;
    let s = &job.summary;
    p.say(format!(
        "{:40} ok: {:.0} t in {:.2} h ({:.0} t/h), {} passes from {} stands, {} walks; mass balance {}",
        "shift (45 min)",
        s.tonnes,
        s.hours,
        s.tonnes_per_hour,
        s.passes,
        s.stands,
        s.walks,
        if s.mass_balance.closes { "closes" } else { "DOES NOT CLOSE" }
    ));
    let summary = job.json()?;
    let shown_plots: Vec<String> = job
        .written
        .plots
        .iter()
        .filter(|p| {
            !p.starts_with("stand_") || p.starts_with("stand_01") || p.starts_with("stand_02")
        })
        .cloned()
        .collect();
    r.add("shift", section(
        "shift (45 minutes of the built-in bench)",
        "The whole machine (SPEC §9): the rope shovel at full size (the paper's 1:30 model by Froude similarity, λ = 30) scans the face, perceives it, plans each dig with the warm start of the last, digs, swings, dumps into a truck and returns; when no feasible dig remains it chooses the next stand from its scans, plans the walk on a map built from them (a V-move to the side) and drives it with slip and RTK noise. The pit is a height grid the dipper cuts; the mass balance compares its loss with the trucks' load. animation.html replays the shift. The full shift: autoshovel shift --out DIR.",
        &summary,
        sub,
        &shown_plots,
        &job.written.files,
    ), summary);
    Ok(())
}

/// The random-road study on 100 maps.
fn study(p: &mut Place, r: &mut Report) -> Result<()> {
    let params = StudyParams {
        maps: 100,
        ..Default::default()
    };
    let sub = "study-paths";
    let dir = p.dir(sub);
    let job = crate::study(&params, Some(&dir), p.progress)?;
    p.say(autoshovel_figures::study::markdown_table(&job.summary));
    let summary = job.json()?;
    r.add("study-paths", section(
        "study-paths (100 maps)",
        "Seeded random haul roads with 3–12 obstacles: classic APF, improved APF and the Theta* reference. The full study: autoshovel study-paths --maps 500.",
        &summary,
        sub,
        &job.written.plots,
        &job.written.files,
    ), summary);
    Ok(())
}

/// A tracking scenario's path, start, speed and noise, from its values.
fn track_setting(scenario: &autoshovel_walk_tracker::scenario::TrackScenario) -> String {
    let setup = &scenario.setup;
    let xy = |p: autoshovel_core::Vec2| format!("({:.0}, {:.0})", p.x, p.y);
    let path = match (
        setup.legs.first().and_then(|l| l.points.first()),
        setup.legs.last().and_then(|l| l.points.last()),
    ) {
        (Some(&a), Some(&b)) => format!("path {} → {}", xy(a), xy(b)),
        _ => "no path".to_string(),
    };
    format!(
        "{path} in {} leg(s), start {} at {} m/s, noise {}",
        setup.legs.len(),
        xy(autoshovel_core::Vec2::new(setup.start.x, setup.start.y)),
        autoshovel_core::config::short(setup.sim.speed_mps),
        scenario.noise.name()
    )
}

fn section(
    title: &str,
    description: &str,
    summary: &Value,
    sub: &str,
    plots: &[String],
    files: &[String],
) -> Section {
    let mut s = summary.clone();
    if let Some(o) = s.as_object_mut() {
        o.remove("params");
        o.remove("files");
        o.remove("events");
        o.remove("pipeline");
        o.remove("stages");
    }
    Section {
        title: title.to_string(),
        description: description.to_string(),
        summary: s,
        plots: plots.iter().map(|p| format!("{sub}/{p}")).collect(),
        files: files.iter().map(|p| format!("{sub}/{p}")).collect(),
    }
}
