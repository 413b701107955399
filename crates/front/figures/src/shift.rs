//! Figures and tables of the `shift` job, from a [`ShiftRun`]:
//!
//! - `passes.csv` (every loading cycle: stand, swing angle, stage times,
//!   planned / executed / dug volume, fill, energy by drive, wall times),
//!   `stands.csv`, `walks.csv` and `walk_paths.csv` (planned and driven),
//!   `events.csv` (the timeline);
//! - `pit_before` and `pit_after`: the pit's height map at the start and
//!   the end, the stands, every dig path and every walk over it;
//! - `stand_NN`: the height map around stand NN on arrival and on leaving,
//!   with its dig paths (the first eleven stands and the last);
//! - `timeline`: tonnes against time with the walks and the safety
//!   events, and each pass's stage times;
//! - `animation.html`: the shift as a page with a time slider (one
//!   snapshot of the pit every few minutes, the machine on it), self-contained;
//! - `shift.mcap`: the run log in the machine link's format ([`run_log`]).

use std::fmt::Write as _;
use std::path::Path;

use autoshovel_report::{
    format_f64, write_csv, write_csv_cells, write_heatmap, write_panels, Figure, Heatmap, Layer,
    ReportError, Rgb, Stroke, Written,
};
use autoshovel_work_shift::{ShiftRun, World};

use crate::FiguresError;

/// Stands drawn one by one (the first this many less one, and the last).
pub const STAND_MAPS: usize = 12;

/// Writes the job's tables and plots of `run` into `dir`.
pub fn write(dir: &Path, run: &ShiftRun, written: &mut Written) -> Result<(), FiguresError> {
    tables(dir, run, written)?;
    written.plot(
        dir,
        write_heatmap(
            &pit_map(run, &run.before, "The pit at the start", false),
            dir,
            "pit_before",
        )?,
    );
    written.plot(
        dir,
        write_heatmap(
            &pit_map(
                run,
                &run.after,
                "The pit at the end: stands, dig paths and walks",
                true,
            ),
            dir,
            "pit_after",
        )?,
    );
    let n = run.stands.len();
    for (i, stand) in run.stands.iter().enumerate() {
        if i + 1 >= STAND_MAPS && i + 1 != n {
            continue;
        }
        let maps = stand_maps(run, i);
        let name = format!("stand_{:02}", stand.stand);
        written.plot(dir, write_heatmap(&maps.0, dir, &format!("{name}_before"))?);
        written.plot(dir, write_heatmap(&maps.1, dir, &format!("{name}_after"))?);
    }
    written.plot(dir, write_panels(&timeline(run), dir, "timeline")?);
    let page = dir.join("animation.html");
    std::fs::write(&page, animation_html(run)).map_err(|source| ReportError::Io {
        path: page.clone(),
        source,
    })?;
    written.file(dir, &page);
    let log = run_log(&dir.join("shift.mcap"), run)?;
    written.file(dir, &log);
    Ok(())
}

fn tables(dir: &Path, run: &ShiftRun, written: &mut Written) -> Result<(), ReportError> {
    let passes = dir.join("passes.csv");
    let rows: Vec<Vec<String>> = run
        .passes
        .iter()
        .map(|p| {
            let mut r = vec![p.pass.to_string(), p.stand.to_string(), p.truck.to_string()];
            r.extend(
                [
                    p.t_start_s,
                    p.swing_deg,
                    p.toe_distance_m,
                    p.dig_s,
                    p.swing_s,
                    p.dump_s,
                    p.return_s,
                    p.wait_s,
                    p.planned_m3,
                    p.executed_m3,
                    p.dug_m3,
                    p.dug_t,
                    p.fill_factor,
                    p.hoist_j,
                    p.crowd_j,
                    p.swing_j,
                    p.perceive_ms,
                    p.plan_ms,
                    p.wall_ms,
                ]
                .map(format_f64),
            );
            r
        })
        .collect();
    write_csv_cells(
        &passes,
        &[
            "pass",
            "stand",
            "truck",
            "t_start_s",
            "swing_deg",
            "toe_distance_m",
            "dig_s",
            "swing_s",
            "dump_s",
            "return_s",
            "wait_s",
            "planned_m3",
            "executed_m3",
            "dug_m3",
            "dug_t",
            "fill_factor",
            "hoist_j",
            "crowd_j",
            "swing_j",
            "perceive_ms",
            "plan_ms",
            "wall_ms",
        ],
        &rows,
    )?;
    written.file(dir, &passes);
    let stands = dir.join("stands.csv");
    let rows: Vec<Vec<String>> = run
        .stands
        .iter()
        .map(|s| {
            vec![
                s.stand.to_string(),
                format_f64(s.x_m),
                format_f64(s.y_m),
                format_f64(s.heading_deg),
                format_f64(s.t_arrive_s),
                s.passes.to_string(),
                format_f64(s.dug_t),
                s.left_because.clone(),
            ]
        })
        .collect();
    write_csv_cells(
        &stands,
        &[
            "stand",
            "x_m",
            "y_m",
            "heading_deg",
            "t_arrive_s",
            "passes",
            "dug_t",
            "left_because",
        ],
        &rows,
    )?;
    written.file(dir, &stands);
    let walks = dir.join("walks.csv");
    let rows: Vec<Vec<String>> = run
        .walks
        .iter()
        .map(|w| {
            vec![
                w.from_stand.to_string(),
                w.to_stand.to_string(),
                w.v_move.to_string(),
                format_f64(w.planned_m),
                format_f64(w.travelled_m),
                format_f64(w.time_s),
                format_f64(w.energy_j),
                format_f64(w.final_error_m),
                format_f64(w.max_deviation_m),
            ]
        })
        .collect();
    write_csv_cells(
        &walks,
        &[
            "from_stand",
            "to_stand",
            "v_move",
            "planned_m",
            "travelled_m",
            "time_s",
            "energy_j",
            "final_error_m",
            "max_deviation_m",
        ],
        &rows,
    )?;
    written.file(dir, &walks);
    let paths = dir.join("walk_paths.csv");
    let rows = run.walks.iter().enumerate().flat_map(|(i, w)| {
        let planned = w
            .planned
            .iter()
            .map(move |p| vec![i as f64 + 1.0, 0.0, p[0], p[1]]);
        let driven = w
            .driven
            .iter()
            .map(move |p| vec![i as f64 + 1.0, 1.0, p[0], p[1]]);
        planned.chain(driven)
    });
    write_csv(&paths, &["walk", "driven", "x_m", "y_m"], rows)?;
    written.file(dir, &paths);
    let events = dir.join("events.csv");
    let rows: Vec<Vec<String>> = run
        .events
        .iter()
        .map(|e| {
            vec![
                format_f64(e.t_s),
                e.kind.to_string(),
                e.stand.to_string(),
                e.message.clone(),
            ]
        })
        .collect();
    write_csv_cells(&events, &["t_s", "kind", "stand", "message"], &rows)?;
    written.file(dir, &events);
    Ok(())
}

/// Cells at most in a drawn height map (an SVG draws each as a rectangle).
const MAP_CELLS: usize = 25_000;

/// Sample coordinates and heights by row of `z` (the world's grid) over
/// `window` (default: all), every `k`-th cell each way so that at most
/// [`MAP_CELLS`] are drawn (each the mean of the k × k it stands for).
fn grid(
    world: &World,
    z: &[f64],
    window: Option<([f64; 2], [f64; 2])>,
) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let c = world.cell_m;
    let [nx, ny] = world.size;
    let (lo, hi) = window.unwrap_or((
        world.origin,
        [
            world.origin[0] + nx as f64 * c,
            world.origin[1] + ny as f64 * c,
        ],
    ));
    let i0 = (((lo[0] - world.origin[0]) / c).floor().max(0.0)) as usize;
    let i1 = ((((hi[0] - world.origin[0]) / c).ceil()) as usize).min(nx);
    let j0 = (((lo[1] - world.origin[1]) / c).floor().max(0.0)) as usize;
    let j1 = ((((hi[1] - world.origin[1]) / c).ceil()) as usize).min(ny);
    let cells = (i1 - i0) * (j1 - j0);
    let k = ((cells as f64 / MAP_CELLS as f64).sqrt().ceil() as usize).max(1);
    let centre = |first: usize, last: usize, o: f64| o + 0.5 * (first + last) as f64 * c + 0.5 * c;
    let cols: Vec<(usize, usize)> = (i0..i1).step_by(k).map(|i| (i, (i + k).min(i1))).collect();
    let rows: Vec<(usize, usize)> = (j0..j1).step_by(k).map(|j| (j, (j + k).min(j1))).collect();
    let xs = cols
        .iter()
        .map(|&(a, b)| centre(a, b - 1, world.origin[0]))
        .collect();
    let ys = rows
        .iter()
        .map(|&(a, b)| centre(a, b - 1, world.origin[1]))
        .collect();
    let heights = rows
        .iter()
        .map(|&(ja, jb)| {
            cols.iter()
                .map(|&(ia, ib)| {
                    let n = ((jb - ja) * (ib - ia)) as f64;
                    (ja..jb)
                        .flat_map(|j| (ia..ib).map(move |i| z[j * nx + i]))
                        .sum::<f64>()
                        / n
                })
                .collect()
        })
        .collect();
    (xs, ys, heights)
}

fn pit_map(run: &ShiftRun, world: &World, title: &str, overlays: bool) -> Heatmap {
    let (xs, ys, z) = grid(world, &world.z, None);
    let mut map = Heatmap::new(title, "x (east) [m]", "y (north) [m]", xs, ys, z)
        .z_label("height above the floor [m]")
        .equal_aspect();
    if overlays {
        for p in &run.passes {
            map = map.layer(Layer::line(
                p.path.iter().map(|q| (q[0], q[1])),
                Stroke::solid(Rgb::WHITE, 1),
            ));
        }
        for w in &run.walks {
            map = map.layer(Layer::line(
                w.driven.iter().map(|q| (q[0], q[1])),
                Stroke::solid(Rgb::RED, 2),
            ));
        }
    }
    map.layer(
        Layer::points(run.stands.iter().map(|s| (s.x_m, s.y_m)), Rgb::BLACK, 3)
            .with_label("stands (swing axis)"),
    )
}

fn stand_maps(run: &ShiftRun, i: usize) -> (Heatmap, Heatmap) {
    let s = &run.stands[i];
    let window = ([s.x_m - 8.0, s.y_m - 22.0], [s.x_m + 32.0, s.y_m + 22.0]);
    let world = &run.before;
    let make = |z: &[f64], when: &str| {
        let (xs, ys, rows) = grid(world, z, Some(window));
        Heatmap::new(
            format!(
                "Stand {} {when}: {} passes, {:.0} t",
                s.stand, s.passes, s.dug_t
            ),
            "x (east) [m]",
            "y (north) [m]",
            xs,
            ys,
            rows,
        )
        .z_label("height above the floor [m]")
        .equal_aspect()
        .size(700, 700)
        .layer(Layer::points([(s.x_m, s.y_m)], Rgb::BLACK, 4).with_label("swing axis"))
    };
    let before = make(&s.before, "on arrival");
    let mut after = make(
        if s.after.is_empty() {
            &run.after.z
        } else {
            &s.after
        },
        "on leaving",
    );
    for p in run.passes.iter().filter(|p| p.stand == s.stand) {
        after = after.layer(Layer::line(
            p.path.iter().map(|q| (q[0], q[1])),
            Stroke::solid(Rgb::WHITE, 2),
        ));
    }
    (before, after)
}

/// One stage's time of a pass.
type Stage = fn(&autoshovel_work_shift::PassRecord) -> f64;

fn timeline(run: &ShiftRun) -> Vec<Figure> {
    let hours = |t: f64| t / 3600.0;
    let mut tonnes = Figure::new(
        "Shift timeline: mass dug, walks (grey) and safety events",
        "time [h]",
        "mass dug [t]",
    );
    let mut total = 0.0;
    let mut line = vec![(0.0, 0.0)];
    for p in &run.passes {
        total += p.dug_t;
        line.push((hours(p.t_start_s + p.dig_s), total));
    }
    let top = total.max(1.0);
    let mut t_walk = Vec::new();
    for e in run
        .events
        .iter()
        .filter(|e| matches!(e.kind, "walk" | "back-off"))
    {
        t_walk.push(e.t_s);
    }
    for (w, t_end) in run.walks.iter().zip(&t_walk) {
        let (a, b) = (hours(t_end - w.time_s), hours(*t_end));
        tonnes.layers.push(Layer::polygon(
            [(a, 0.0), (b, 0.0), (b, top), (a, top)],
            Some(Rgb(220, 220, 220)),
            Stroke::solid(Rgb(220, 220, 220), 1),
        ));
    }
    tonnes
        .layers
        .push(Layer::line(line, Stroke::solid(Rgb::BLUE, 2)).with_label("cumulative mass dug"));
    let safety: Vec<(f64, f64)> = run
        .events
        .iter()
        .filter(|e| matches!(e.kind, "overfill" | "over-rating" | "walk-stalled"))
        .map(|e| {
            let done = run
                .passes
                .iter()
                .filter(|p| p.t_start_s <= e.t_s)
                .map(|p| p.dug_t)
                .sum::<f64>();
            (hours(e.t_s), done)
        })
        .collect();
    if !safety.is_empty() {
        tonnes
            .layers
            .push(Layer::points(safety, Rgb::RED, 3).with_label("safety event"));
    }
    let mut stages = Figure::new("Each pass's stages", "pass", "time [s]");
    let series: [(&str, Stage, Rgb); 5] = [
        ("dig", |p| p.dig_s, Rgb::BROWN),
        ("swing", |p| p.swing_s, Rgb::BLUE),
        ("dump", |p| p.dump_s, Rgb::GREEN),
        ("return", |p| p.return_s, Rgb::ORANGE),
        ("wait for a truck", |p| p.wait_s, Rgb::GREY),
    ];
    for (name, f, color) in series {
        stages.layers.push(
            Layer::line(
                run.passes.iter().map(|p| (p.pass as f64, f(p))),
                Stroke::solid(color, 1),
            )
            .with_label(name),
        );
    }
    vec![tonnes, stages]
}

/// The animation page: the frames as base64 of one byte a cell (height
/// over the pile's top), drawn on a canvas with a time slider.
fn animation_html(run: &ShiftRun) -> String {
    let [nx, ny] = run.frame_size;
    let top = run
        .frames
        .iter()
        .flat_map(|f| f.z.iter().copied())
        .fold(0.0f32, f32::max)
        .max(1e-3);
    let mut frames = String::from("[");
    for (k, f) in run.frames.iter().enumerate() {
        let bytes: Vec<u8> =
            f.z.iter()
                .map(|&z| ((z / top).clamp(0.0, 1.0) * 255.0).round() as u8)
                .collect();
        if k > 0 {
            frames.push(',');
        }
        let _ = write!(
            frames,
            "{{\"t\":{:.0},\"x\":{:.2},\"y\":{:.2},\"h\":{:.4},\"z\":\"{}\"}}",
            f.t_s,
            f.pose.x,
            f.pose.y,
            f.pose.theta,
            base64(&bytes)
        );
    }
    frames.push(']');
    let s = &run.summary;
    format!(
        r#"<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>autoshovel shift: {name}</title>
<style>body{{font-family:sans-serif;margin:1em}}canvas{{border:1px solid #999;image-rendering:pixelated}}#bar{{width:640px}}</style></head>
<body>
<h1>Shift on “{name}”</h1>
<p>{tonnes:.0} t in {hours:.2} h ({tph:.0} t/h), {passes} passes from {stands} stands; the pit seen from above, heights 0–{top:.1} m; the machine in red. Drag the slider or press play.</p>
<canvas id="c" width="{w}" height="{h}"></canvas><br>
<input type="range" id="bar" min="0" max="{last}" value="0"> <button id="play">play</button> <span id="when"></span>
<script>
const F={frames};const NX={nx},NY={ny},S=Math.max(1,Math.floor(Math.min(900/NX,640/NY)));
const c=document.getElementById('c');c.width=NX*S;c.height=NY*S;const g=c.getContext('2d');
const bar=document.getElementById('bar'),when=document.getElementById('when');
function col(v){{const t=v/255;return [Math.round(68+t*185),Math.round(1+t*230),Math.round(84+t*(36-84+255*0.0))];}}
function draw(k){{const f=F[k];const b=atob(f.z);const img=g.createImageData(NX*S,NY*S);
for(let j=0;j<NY;j++)for(let i=0;i<NX;i++){{const v=b.charCodeAt(j*NX+i);const [r,gg,bb]=col(v);
for(let dy=0;dy<S;dy++)for(let dx=0;dx<S;dx++){{const p=(((NY-1-j)*S+dy)*NX*S+i*S+dx)*4;img.data[p]=r;img.data[p+1]=gg;img.data[p+2]=bb;img.data[p+3]=255;}}}}
g.putImageData(img,0,0);const px=(f.x-{x0})/{cell}*S,py=(NY-(f.y-{y0})/{cell})*S;
g.fillStyle='red';g.beginPath();g.arc(px,py,5*S/{cell},0,7);g.fill();g.strokeStyle='red';g.beginPath();g.moveTo(px,py);g.lineTo(px+12*S*Math.cos(f.h)/{cell},py-12*S*Math.sin(f.h)/{cell});g.stroke();
when.textContent=(f.t/3600).toFixed(2)+' h';}}
bar.oninput=()=>draw(+bar.value);let timer=null;
document.getElementById('play').onclick=()=>{{if(timer){{clearInterval(timer);timer=null;return;}}timer=setInterval(()=>{{bar.value=(+bar.value+1)%F.length;draw(+bar.value);}},120);}};
draw(0);
</script></body></html>
"#,
        name = s.scenario,
        tonnes = s.tonnes,
        hours = s.hours,
        tph = s.tonnes_per_hour,
        passes = s.passes,
        stands = s.stands,
        top = top,
        w = nx,
        h = ny,
        last = run.frames.len().saturating_sub(1),
        frames = frames,
        nx = nx,
        ny = ny,
        x0 = run.before.origin[0],
        y0 = run.before.origin[1],
        cell = run.frame_cell_m,
    )
}

/// Standard base64 (RFC 4648) with padding.
fn base64(bytes: &[u8]) -> String {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// The shift as an MCAP run log (the machine link's format and topics,
/// docs/machine-link.md; Foxglove replays it): the machine's true pose at each
/// pass and along every walk, every event, every pass's record, the
/// summary at the end. Times are the shift's.
pub fn run_log(
    path: &Path,
    run: &ShiftRun,
) -> Result<std::path::PathBuf, autoshovel_run_log::RunLogError> {
    use autoshovel_run_log::{topic, EventMsg, PoseMsg};
    let mut log = autoshovel_run_log::RunLog::create(
        path,
        &[
            ("job", "shift".to_string()),
            ("scenario", run.summary.scenario.clone()),
        ],
        true,
    )?;
    // Messages in time order, as MCAP readers expect them.
    enum Msg<'a> {
        Pose(PoseMsg),
        Event(&'a autoshovel_work_shift::Event),
        Pass(&'a autoshovel_work_shift::PassRecord),
    }
    let mut msgs: Vec<(f64, Msg)> = Vec::new();
    for p in &run.passes {
        let s = &run.stands[p.stand - 1];
        let pose = autoshovel_core::Pose2::new(s.x_m, s.y_m, s.heading_deg.to_radians());
        msgs.push((p.t_start_s, Msg::Pose(pose.into())));
        msgs.push((p.t_start_s, Msg::Pass(p)));
    }
    for w in &run.walks {
        for (&[t, theta], q) in w.driven_at.iter().zip(&w.driven) {
            msgs.push((
                t,
                Msg::Pose(PoseMsg {
                    x: q[0],
                    y: q[1],
                    theta,
                }),
            ));
        }
    }
    msgs.extend(run.events.iter().map(|e| (e.t_s, Msg::Event(e))));
    msgs.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (t, msg) in msgs {
        match msg {
            Msg::Pose(pose) => log.write(topic::TRUTH, t, &pose)?,
            Msg::Pass(p) => log.write("/shift/pass", t, p)?,
            Msg::Event(e) => log.write(
                topic::EVENT,
                t,
                &EventMsg {
                    t_s: e.t_s,
                    source: "shift".into(),
                    kind: e.kind.into(),
                    message: e.message.clone(),
                },
            )?,
        }
    }
    let end = run.summary.hours * 3600.0;
    log.write(topic::SUMMARY, end, &run.summary)?;
    log.finish()
}
