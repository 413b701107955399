//! `autoshovel plan-dig`: the rope-shovel paper's dig planning (§2 and §4;
//! SPEC §4.2–4.3) on a pile of Fig. 7 at the 1:30 scale or on a scan run
//! through the `perceive` pipeline: a 6th-order tooth path (eqs. 22–24)
//! minimising f = k1·f1 + k2·f2 (eqs. 25–27) under c1–c18 (eqs. 29–35) with
//! the Grey Wolf Optimizer from a good-point-set start (eq. 37, §4.5).
//!
//! `--out DIR` gets `summary.json`, `samples.csv` (every sample of the
//! planned dig), `convergence.csv`, `surface.csv` (the pile profile in the
//! dig plane) and the plots of Figs. 13–16: `dig_path` (tooth path over the
//! pile, the ideal face and the machine at the start and end of the dig —
//! also our drawing of the paper's missing Fig. 2), `speeds`, `forces`
//! (with the powers) and `convergence`. `--all-surfaces` plans the four
//! piles in Table 5's order, one subfolder each, and writes `table.csv` and
//! `paths` beside Tables 4–5 of the paper.
//!
//! A scan (`--cloud`) is levelled, filtered and fitted exactly as
//! `autoshovel perceive` does. The dig plane is the vertical plane through
//! the middle of the fitted extent in y (the scanner looks along +x at the
//! face); the toe is where the profile first rises [`TOE_RISE_SHARE`] of the
//! face height (the highest of the fit's 8 × 8 grid samples above the floor)
//! — 10 mm on the 1:30 model's 0.33 m face, so the same rule serves a scan at
//! any scale. The profile's machine must fit the pile: a full-size scan
//! (`generate-pile` without `--scale 0.0333`) for the scale model fails with
//! a note saying so.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use autoshovel_dig::TomlFile as _;
use autoshovel_dig::{
    plan_dig, Decision, DigModel, DigOutcome, DigPlan, DigSample, DigSurface, MachineProfile,
    SearchSpace, CONSTRAINT_NAMES,
};
use autoshovel_optim::{GwoParams, Init};
use autoshovel_report::{
    write_csv, write_csv_cells, write_figure, write_panels, Figure, Layer, Rgb, Stroke,
};
use autoshovel_surface::PileShape;
use serde_json::{json, Map, Value};

use crate::output::{num, prepare_dir, print_json, write_job_summary, Written};
use autoshovel_surface::perceive::PerceptionParams as Pipeline;

/// Share of the face height above the floor that marks the toe of a scanned pile.
pub const TOE_RISE_SHARE: f64 = 0.03;

/// How the optimiser's first pack is placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum InitArg {
    /// The good point set of §4.5 (deterministic; the seed drives the iterations).
    GoodPointSet,
    /// Uniform random wolves (Mirjalili et al. 2014), to show what the good point set buys.
    Random,
}

impl InitArg {
    fn init(self) -> Init {
        match self {
            InitArg::GoodPointSet => Init::GoodPointSet,
            InitArg::Random => Init::Random,
        }
    }

    fn name(self) -> &'static str {
        match self {
            InitArg::GoodPointSet => "good-point-set",
            InitArg::Random => "random",
        }
    }
}

/// The optimiser's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SearchArg {
    /// [bend_x, bend_y, t_d, g_x, g_y]: the a₆ as mid-dig bends (well conditioned).
    Bends,
    /// The paper's raw [a_x6, a_y6, t_d, g_x, g_y].
    Paper,
}

impl SearchArg {
    fn space(self) -> SearchSpace {
        match self {
            SearchArg::Bends => SearchSpace::Bends,
            SearchArg::Paper => SearchSpace::Paper,
        }
    }

    fn name(self) -> &'static str {
        match self {
            SearchArg::Bends => "bends",
            SearchArg::Paper => "paper",
        }
    }
}

/// Arguments of `plan-dig`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Pile shape of Fig. 7 at the paper's 1:30 scale: typical, convex, concave, convex-concave [default: typical].
    #[arg(long, conflicts_with_all = ["cloud", "all_surfaces"])]
    pub surface: Option<PileShape>,
    /// A scan of the pile (.pcd .ply .las .laz .xyz .csv), run through the `perceive` pipeline first.
    #[arg(long, conflicts_with = "all_surfaces")]
    pub cloud: Option<PathBuf>,
    /// Pipeline settings for --cloud (TOML, as `autoshovel perceive --print-config` shows).
    #[arg(long, requires = "cloud")]
    pub config: Option<PathBuf>,
    /// Plan all four piles (Table 5's order) and compare with the paper's Tables 4–5.
    #[arg(long)]
    pub all_surfaces: bool,
    /// Machine profile (TOML); default: the paper's 1:30 scale model (`--print-profile` shows it).
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Print the machine profile as TOML and exit (the built-in one, commented, or the checked --profile).
    #[arg(long)]
    pub print_profile: bool,
    /// Seed of the Grey Wolf Optimizer.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Coordinates the optimiser moves in.
    #[arg(long, value_enum, default_value = "bends")]
    pub search: SearchArg,
    /// Placement of the optimiser's first pack.
    #[arg(long, value_enum, default_value = "good-point-set")]
    pub init: InitArg,
    /// Start from the final pack of an earlier plan (its `pack.csv`), as the
    /// next dig cycle would: those wolves replace the first of the new pack.
    #[arg(long, conflicts_with = "all_surfaces")]
    pub warm_start: Option<PathBuf>,
    /// Write summary.json, CSV and plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
}

/// The machine and the optimiser settings of a run.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The checked machine profile.
    pub profile: MachineProfile,
    /// Where it came from: a path or "builtin scale-model".
    pub profile_name: String,
    /// Optimiser settings (the paper's 50 wolves, 100 iterations).
    pub gwo: GwoParams,
    /// Search coordinates.
    pub search: SearchArg,
    /// First-pack placement.
    pub init: InitArg,
    /// Wolves to start from (an earlier plan's final pack) and their file.
    pub warm_start: Option<(PathBuf, Vec<Decision>)>,
}

impl Setup {
    /// Loads the profile (the built-in one without a path) and sets up the optimiser.
    pub fn new(
        profile: Option<&Path>,
        seed: u64,
        search: SearchArg,
        init: InitArg,
    ) -> Result<Self> {
        let (profile, profile_name) = match profile {
            Some(p) => (MachineProfile::load(p)?, p.display().to_string()),
            None => (
                MachineProfile::scale_model(),
                "builtin scale-model".to_string(),
            ),
        };
        Ok(Self {
            profile,
            profile_name,
            gwo: GwoParams {
                seed,
                init: init.init(),
                ..GwoParams::rope_shovel()
            },
            search,
            init,
            warm_start: None,
        })
    }
}

/// Columns of `pack.csv`: a final wolf as a decision of eq. 24 with its
/// objective and normalised violation, best first.
const PACK_COLUMNS: [&str; 7] = ["ax6", "ay6", "td_s", "gx_m", "gy_m", "f", "violation"];

/// Reads the wolves of a `pack.csv` written by an earlier plan.
fn read_pack(path: &Path) -> Result<Vec<Decision>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read warm-start pack {}", path.display()))?;
    let mut lines = text.lines().enumerate();
    let header: Vec<&str> = match lines.next() {
        Some((_, h)) => h.split(',').map(str::trim).collect(),
        None => bail!(
            "{}: empty file; expected a pack.csv of plan-dig",
            path.display()
        ),
    };
    if header[..] != PACK_COLUMNS[..] {
        bail!(
            "{}:1: header '{}' is not a plan-dig pack (expected {})",
            path.display(),
            header.join(","),
            PACK_COLUMNS.join(",")
        );
    }
    let mut wolves = Vec::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != PACK_COLUMNS.len() {
            bail!(
                "{}:{}: {} values, expected {}",
                path.display(),
                i + 1,
                cells.len(),
                PACK_COLUMNS.len()
            );
        }
        let mut x = [0.0; 5];
        for (k, (cell, v)) in cells.iter().zip(x.iter_mut()).enumerate() {
            *v = cell
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| {
                    format!(
                        "{}:{}: {} = '{cell}' is not a finite number",
                        path.display(),
                        i + 1,
                        PACK_COLUMNS[k]
                    )
                })?;
        }
        if x[2] <= 0.0 {
            bail!("{}:{}: td_s = {} must be > 0", path.display(), i + 1, x[2]);
        }
        wolves.push(Decision::from_slice(&x));
    }
    if wolves.is_empty() {
        bail!("{}: no wolves in the pack", path.display());
    }
    Ok(wolves)
}

/// The pile to dig and where it came from.
#[derive(Debug, Clone)]
pub struct Pile {
    /// The profile in the dig plane.
    pub surface: DigSurface,
    /// "typical", …, or "cloud".
    pub name: String,
    /// Extra summary fields (the scan and what perception made of it).
    pub extra: Map<String, Value>,
    /// Added to errors: why a plan on this pile may fail.
    pub hint: Option<String>,
}

impl Pile {
    /// The noiseless synthetic pile of `shape` at the 1:30 scale.
    pub fn shape(shape: PileShape, profile: &MachineProfile) -> Self {
        Self {
            surface: DigSurface::from_shape(shape, profile.dipper.width_m),
            name: shape.name().to_string(),
            extra: Map::new(),
            hint: None,
        }
    }

    /// A scanned pile: the `perceive` pipeline, then the dig plane through
    /// the middle of the fitted extent (module docs).
    pub fn cloud(
        path: &Path,
        pipeline: &Pipeline,
        profile: &MachineProfile,
        progress: bool,
    ) -> Result<Self> {
        let got = crate::perceive::perceive_with_progress(path, pipeline, progress)?;
        let fit = &got.fit;
        let e = &fit.extent;
        let y_line = 0.5 * (e.y_min_m + e.y_max_m);
        // The face height from the data (the grid samples), not the
        // polynomial, which may overshoot at the edges of its extent.
        let face_m = fit
            .samples
            .iter()
            .map(|s| s.z_m - got.floor_height_m)
            .fold(f64::NEG_INFINITY, f64::max);
        if !(face_m.is_finite() && face_m > 0.0) {
            bail!(
                "{}: the scan does not rise above the floor (z = {:.4} m); no pile to dig",
                path.display(),
                got.floor_height_m
            );
        }
        let toe_rise_m = TOE_RISE_SHARE * face_m;
        let surface = DigSurface::from_fit(
            fit,
            got.floor_height_m,
            y_line,
            profile.dipper.width_m,
            toe_rise_m,
        )
        .with_context(|| {
            format!(
                "{}: cutting the fitted surface along the dig plane y = {y_line:.4} m",
                path.display()
            )
        })?;
        let reach_m = profile.geometry().sheave_top_height;
        let hint = (face_m > 2.0 * reach_m).then(|| {
            format!(
                "{}: the pile's face is {face_m:.2} m high but the machine of the profile reaches \
                 {reach_m:.2} m at most (top of its boom point sheave): a full-size scan for a \
                 scale-model machine? `autoshovel generate-pile --scale 0.0333` writes a pile at \
                 the paper's 1:30 scale",
                path.display()
            )
        });
        let mut extra = Map::new();
        extra.insert("cloud".into(), json!(path.display().to_string()));
        extra.insert(
            "perception".into(),
            json!({
                "format": got.format,
                "input_points": got.input_points,
                "output_points": got.cloud.len(),
                "roll_deg": got.roll_rad.to_degrees(),
                "pitch_deg": got.pitch_rad.to_degrees(),
                "floor_height_m": got.floor_height_m,
                "scale": got.scale,
                "fit_degree": fit.degree,
                "r2": num(fit.r2),
                "extent": fit.extent,
                "dig_plane_y_m": y_line,
                "face_height_m": face_m,
                "toe_rise_m": toe_rise_m,
                "perceive_ms": got.stages.iter().map(|s| s.ms).sum::<f64>(),
            }),
        );
        Ok(Self {
            surface,
            name: "cloud".into(),
            extra,
            hint,
        })
    }
}

/// One plan's result.
#[derive(Debug)]
pub struct Job {
    /// Summary (`success` false and `error` set when no feasible plan was found).
    pub summary: Value,
    /// Files written.
    pub written: Written,
    /// Why no plan came out, if none did.
    pub error: Option<String>,
}

/// Runs `plan-dig` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    if args.print_profile {
        use std::io::Write as _;
        let text = match &args.profile {
            Some(p) => MachineProfile::load(p)?.to_toml(),
            None => autoshovel_dig::profile::SCALE_MODEL_TOML.to_string(),
        };
        let _ = write!(std::io::stdout().lock(), "{text}");
        return Ok(());
    }
    let mut setup = Setup::new(args.profile.as_deref(), args.seed, args.search, args.init)?;
    if let Some(path) = &args.warm_start {
        setup.warm_start = Some((path.clone(), read_pack(path)?));
    }
    let pipeline = match &args.config {
        Some(p) => Pipeline::load(p)?,
        None => Pipeline::default(),
    };
    let out = args.out.as_deref().map(prepare_dir).transpose()?;
    if args.all_surfaces {
        let all = all_surfaces(&setup, out.as_deref(), !args.json)?;
        if args.json {
            print_json(&all.summary)?;
        } else {
            crate::say!("{}", all.table);
            if let Some(dir) = &out {
                crate::say!("wrote {}", dir.display());
            }
        }
        return match all.error {
            Some(e) => bail!("{e}"),
            None => Ok(()),
        };
    }
    let pile = match &args.cloud {
        Some(path) => Pile::cloud(path, &pipeline, &setup.profile, !args.json)?,
        None => Pile::shape(args.surface.unwrap_or_default(), &setup.profile),
    };
    let job = job(&pile, &setup, out.as_deref())?;
    crate::output::report(&job.summary, args.json, out.as_deref(), print_human)?;
    match job.error {
        Some(e) => bail!("{e}"),
        None => Ok(()),
    }
}

/// Plans the dig of `pile`, writing into `out` if given. A pile the machine
/// cannot dig at all is an error; a plan that misses a constraint is a
/// [`Job`] with `error` set (and a summary saying so).
pub fn job(pile: &Pile, setup: &Setup, out: Option<&Path>) -> Result<Job> {
    let profile = &setup.profile;
    let with_hint = |e: String| match &pile.hint {
        Some(h) => format!("{e}\nnote: {h}"),
        None => e,
    };
    let mut model = DigModel::new(profile, pile.surface.clone()).map_err(|e| {
        anyhow::anyhow!(with_hint(format!(
            "{} pile ({}): {e}",
            pile.name, pile.surface.source
        )))
    })?;
    model.set_search_space(setup.search.space());
    let t0 = Instant::now();
    let warm: Vec<Vec<f64>> = match &setup.warm_start {
        Some((_, wolves)) => wolves
            .iter()
            .take(setup.gwo.population)
            .map(|d| model.vector(d))
            .collect(),
        None => Vec::new(),
    };
    let result = plan_dig(&model, &setup.gwo, &warm);
    let plan_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut summary = Value::Object(header(pile, setup));
    let mut written = Written::default();
    let plan = match result {
        Ok(plan) => plan,
        Err(e) => {
            let msg = with_hint(format!("{} pile: {e}", pile.name));
            let o = summary.as_object_mut().expect("object");
            o.insert("feasible".into(), json!(false));
            o.insert("success".into(), json!(false));
            o.insert("error".into(), json!(msg));
            o.insert("plan_time_ms".into(), json!(plan_ms));
            if let Some(dir) = out {
                write_job_summary(dir, &mut summary, &mut written)?;
            }
            return Ok(Job {
                summary,
                written,
                error: Some(msg),
            });
        }
    };
    let o = summary.as_object_mut().expect("object");
    for (k, v) in plan_fields(&model, &plan, plan_ms) {
        o.insert(k, v);
    }
    if let Some(dir) = out {
        write_outputs(dir, pile, &model, &plan, &mut written)?;
        write_job_summary(dir, &mut summary, &mut written)?;
    }
    Ok(Job {
        summary,
        written,
        error: None,
    })
}

/// What every summary of a plan holds, feasible or not.
fn header(pile: &Pile, setup: &Setup) -> Map<String, Value> {
    let p = &setup.profile;
    let mut o = Map::new();
    o.insert("job".into(), json!("plan-dig"));
    o.insert("surface".into(), json!(pile.name));
    o.insert("surface_source".into(), json!(pile.surface.source));
    for (k, v) in &pile.extra {
        o.insert(k.clone(), v.clone());
    }
    o.insert("seed".into(), json!(setup.gwo.seed));
    o.insert("search_space".into(), json!(setup.search.name()));
    o.insert("init".into(), json!(setup.init.name()));
    o.insert("population".into(), json!(setup.gwo.population));
    o.insert("iterations".into(), json!(setup.gwo.iterations));
    o.insert(
        "constraint_handling".into(),
        json!("feasibility rules (Deb 2000)"),
    );
    o.insert("profile".into(), json!(setup.profile_name));
    if let Some((path, wolves)) = &setup.warm_start {
        o.insert(
            "warm_start".into(),
            json!({
                "file": path.display().to_string(),
                "wolves": wolves.len().min(setup.gwo.population),
            }),
        );
    }
    o.insert("k_f_pa".into(), json!(p.material.cutting_resistance_pa));
    o.insert("epsilon".into(), json!(p.material.fill_resistance_ratio));
    o.insert("psi".into(), json!(p.material.normal_ratio));
    o.insert("density_kg_m3".into(), json!(p.material.density_kg_m3));
    o.insert("k1".into(), json!(p.objective.k1));
    o.insert("k2".into(), json!(p.objective.k2));
    o
}

/// c1–c18 as a JSON object: name → value (≤ 0 met), measured quantity,
/// limit, bound, units (the library's table).
fn constraints_json(model: &DigModel, o: &DigOutcome) -> Value {
    let mut m = Map::new();
    let limits = model.constraint_limits(o.decision.gx_m);
    for ((lim, &value), &measured) in limits.iter().zip(&o.constraints).zip(&o.measured) {
        m.insert(
            lim.name.to_string(),
            json!({
                "value": num(value),
                "met": value <= 0.0,
                "measured": num(measured),
                "limit": num(lim.limit),
                "bound": lim.bound,
                "units": lim.units,
            }),
        );
    }
    Value::Object(m)
}

/// The fields of a successful plan.
fn plan_fields(model: &DigModel, plan: &DigPlan, plan_ms: f64) -> Map<String, Value> {
    let o = &plan.outcome;
    let d = &o.decision;
    let [bend_x, bend_y] = d.bends();
    let first_feasible = plan
        .search
        .history
        .iter()
        .find(|g| g.best_violation == 0.0)
        .map(|g| g.iteration);
    let v = json!({
        "ax6": d.ax6,
        "ay6": d.ay6,
        "td_s": d.td_s,
        "gx_m": d.gx_m,
        "gy_m": d.gy_m,
        "bend_x_m": bend_x,
        "bend_y_m": bend_y,
        "f": num(o.f),
        "f1_j_per_kg": num(o.f1_j_per_kg),
        "f2_s_per_kg": num(o.f2_s_per_kg),
        "m_dig_kg": num(o.m_dig_kg),
        "volume_m3": num(o.volume_m3),
        "fill_factor": num(o.fill_factor),
        "hoist_energy_j": num(o.hoist_energy_j),
        "crowd_energy_j": num(o.crowd_energy_j),
        "feasible": o.feasible(),
        "constraints": constraints_json(model, o),
        "evaluations": plan.search.evaluations,
        "first_feasible_iteration": first_feasible,
        "samples": plan.samples.len(),
        "geometry": model.shovel.geometry,
        "plan_time_ms": plan_ms,
        "success": o.feasible(),
    });
    match v {
        Value::Object(m) => m,
        _ => unreachable!("json! of an object"),
    }
}

fn print_human(s: &Value) {
    let g = |k: &str| s[k].as_f64().unwrap_or(f64::NAN);
    crate::say!(
        "plan-dig {} ({}), profile {}, seed {}, search {}, init {}",
        s["surface"].as_str().unwrap_or(""),
        s["surface_source"].as_str().unwrap_or(""),
        s["profile"].as_str().unwrap_or(""),
        s["seed"],
        s["search_space"].as_str().unwrap_or(""),
        s["init"].as_str().unwrap_or("")
    );
    if s["success"] != true {
        crate::say!("  no feasible plan ({:.0} ms)", g("plan_time_ms"));
        return;
    }
    crate::say!(
        "  x = [a_x6 {:.3e} m/s⁶, a_y6 {:.3e} m/s⁶, t_d {:.2} s, g_x {:.4} m, g_y {:.4} m]",
        g("ax6"),
        g("ay6"),
        g("td_s"),
        g("gx_m"),
        g("gy_m")
    );
    crate::say!(
        "  f {:.3} = {}·f1 + {}·f2, f1 {:.3} J/kg, f2 {:.3} s/kg; m_dig {:.3} kg, fill {:.2} %",
        g("f"),
        g("k1"),
        g("k2"),
        g("f1_j_per_kg"),
        g("f2_s_per_kg"),
        g("m_dig_kg"),
        100.0 * g("fill_factor")
    );
    crate::say!(
        "  energy: hoist {:.2} J, crowd {:.2} J; {} evaluations in {:.0} ms",
        g("hoist_energy_j"),
        g("crowd_energy_j"),
        s["evaluations"],
        g("plan_time_ms")
    );
    crate::say!("| constraint | measured | bound | limit | units | met |");
    crate::say!("|---|---|---|---|---|---|");
    let f = |v: &Value| {
        v.as_f64()
            .map(|x| format!("{x:.4}"))
            .unwrap_or_else(|| "-".into())
    };
    for name in CONSTRAINT_NAMES {
        let c = &s["constraints"][name];
        crate::say!(
            "| {name} | {} | {} | {} | {} | {} |",
            f(&c["measured"]),
            c["bound"].as_str().unwrap_or("-"),
            f(&c["limit"]),
            c["units"].as_str().unwrap_or(""),
            if c["met"] == true { "yes" } else { "NO" }
        );
    }
}

fn write_outputs(
    dir: &Path,
    pile: &Pile,
    model: &DigModel,
    plan: &DigPlan,
    written: &mut Written,
) -> Result<()> {
    let samples = dir.join("samples.csv");
    write_samples_csv(&samples, &plan.samples)?;
    written.file(dir, &samples);
    let conv = dir.join("convergence.csv");
    write_csv(
        &conv,
        &[
            "iteration",
            "best_objective",
            "best_violation",
            "mean_objective",
            "feasible_share",
        ],
        plan.search.history.iter().map(|g| {
            vec![
                g.iteration as f64,
                g.best_objective,
                g.best_violation,
                g.mean_objective,
                g.feasible_share,
            ]
        }),
    )?;
    written.file(dir, &conv);
    let pack = dir.join("pack.csv");
    write_csv(
        &pack,
        &PACK_COLUMNS,
        plan.search.population.iter().map(|(x, e)| {
            let d = model.decision(x);
            vec![
                d.ax6,
                d.ay6,
                d.td_s,
                d.gx_m,
                d.gy_m,
                e.objective,
                e.violation,
            ]
        }),
    )?;
    written.file(dir, &pack);
    let (x0, x1) = view_x_range(model, &plan.outcome.decision);
    let surface = dir.join("surface.csv");
    write_csv(
        &surface,
        &["x_m", "y_m"],
        model
            .surface
            .polyline(x0, x1, 0.001)
            .into_iter()
            .map(|p| p.to_vec()),
    )?;
    written.file(dir, &surface);
    written.plot(
        dir,
        write_figure(&dig_path_figure(pile, model, plan), dir, "dig_path")
            .context("dig path plot")?,
    );
    let l = &model.profile.limits;
    let td = plan.outcome.decision.td_s;
    let limit = |v: f64, label: &str| {
        Layer::line([(0.0, v), (td, v)], Stroke::dashed(Rgb::GREY, 1)).with_label(label)
    };
    let series = |f: fn(&DigSample) -> f64| -> Vec<(f64, f64)> {
        plan.samples.iter().map(|s| (s.t_s, f(s))).collect()
    };
    let title = |what: &str| format!("{what} during the dig ({} pile)", pile.name);
    let mut speeds = Figure::new(title("Hoist and crowd speeds"), "time [s]", "speed [m/s]");
    speeds.push(
        Layer::line(
            series(|s| s.drive.hoist_speed_m_s),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("hoist rope speed v_h"),
    );
    speeds.push(
        Layer::line(
            series(|s| s.drive.crowd_speed_m_s),
            Stroke::solid(Rgb::RED, 2),
        )
        .with_label("crowd speed v_c"),
    );
    if (l.hoist_speed_max_m_s - l.crowd_speed_max_m_s).abs() < 1e-12 {
        speeds.push(limit(l.hoist_speed_max_m_s, "speed limit (c8, c10)"));
    } else {
        speeds.push(limit(l.hoist_speed_max_m_s, "hoist speed limit (c8)"));
        speeds.push(limit(l.crowd_speed_max_m_s, "crowd speed limit (c10)"));
    }
    written.plot(
        dir,
        write_figure(&speeds, dir, "speeds").context("speed plot")?,
    );
    let mut forces =
        Figure::new(title("Hoist and crowd forces"), "time [s]", "force [N]").size(900, 520);
    forces.push(
        Layer::line(
            series(|s| s.drive.hoist_force_n),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("hoist rope force F_h"),
    );
    forces.push(
        Layer::line(
            series(|s| s.drive.crowd_force_n),
            Stroke::solid(Rgb::RED, 2),
        )
        .with_label("crowd force F_c"),
    );
    forces.push(limit(l.hoist_force_max_n, "hoist force rating (c11)"));
    forces.push(limit(l.crowd_force_max_n, "crowd force rating (c12)"));
    forces.push(
        Layer::line(
            series(|s| s.drive.resistance_tangential_n),
            Stroke::dashed(Rgb::BROWN, 2),
        )
        .with_label("digging resistance F_τ"),
    );
    let mut powers =
        Figure::new(title("Hoist and crowd powers"), "time [s]", "power [W]").size(900, 420);
    powers.push(
        Layer::line(
            series(|s| s.drive.hoist_power_w()),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("hoist P_h"),
    );
    powers.push(
        Layer::line(
            series(|s| s.drive.crowd_power_w()),
            Stroke::solid(Rgb::RED, 2),
        )
        .with_label("crowd P_c"),
    );
    if (l.hoist_power_max_w - l.crowd_power_max_w).abs() < 1e-12 {
        powers.push(limit(l.hoist_power_max_w, "power rating (c13, c14)"));
    } else {
        powers.push(limit(l.hoist_power_max_w, "hoist power rating (c13)"));
        powers.push(limit(l.crowd_power_max_w, "crowd power rating (c14)"));
    }
    written.plot(
        dir,
        write_panels(&[forces, powers], dir, "forces").context("force plot")?,
    );
    written.plot(
        dir,
        write_panels(&convergence_figures(plan, &pile.name), dir, "convergence")
            .context("convergence plot")?,
    );
    Ok(())
}

fn write_samples_csv(path: &Path, samples: &[DigSample]) -> Result<()> {
    write_csv(
        path,
        &[
            "t_s",
            "tip_x_m",
            "tip_y_m",
            "theta1_rad",
            "d2_m",
            "hoist_force_n",
            "crowd_force_n",
            "hoist_speed_m_s",
            "crowd_speed_m_s",
            "hoist_power_w",
            "crowd_power_w",
            "rope_handle_angle_rad",
            "resistance_tangential_n",
            "resistance_normal_n",
            "cut_thickness_m",
            "load_kg",
            "back_angle_rad",
        ],
        samples.iter().map(|s| {
            vec![
                s.t_s,
                s.tip_m[0],
                s.tip_m[1],
                s.joints.theta1,
                s.joints.d2,
                s.drive.hoist_force_n,
                s.drive.crowd_force_n,
                s.drive.hoist_speed_m_s,
                s.drive.crowd_speed_m_s,
                s.drive.hoist_power_w(),
                s.drive.crowd_power_w(),
                s.drive.rope_handle_angle_rad,
                s.drive.resistance_tangential_n,
                s.drive.resistance_normal_n,
                s.cut_thickness_m,
                s.load_kg,
                s.back_angle_rad,
            ]
        }),
    )?;
    Ok(())
}

/// The x range worth drawing: the machine behind the toe to a little past
/// the end of the dig and the top of the ideal face.
fn view_x_range(model: &DigModel, d: &Decision) -> (f64, f64) {
    let g = &model.shovel.geometry;
    let (lo, hi) = model.surface.x_range();
    let alpha = model.profile.geometry.pile_angle_deg.to_radians();
    let x0 = (g.boom_foot[0].min(g.l1) - 0.05).min(lo);
    let want = d.gx_m.max(model.surface.top() / alpha.tan()) + 0.15;
    (x0, want.min(hi).max(d.gx_m))
}

/// Fig. 13–16 (a) with our reading of Fig. 2: the tooth path over the pile
/// and the machine at the start and end of the dig.
fn dig_path_figure(pile: &Pile, model: &DigModel, plan: &DigPlan) -> Figure {
    let p = &model.profile;
    let d = &plan.outcome.decision;
    let (x0, x1) = view_x_range(model, d);
    let mut fig = Figure::new(
        format!(
            "Tooth path and the machine at the start and end of the dig ({} pile)",
            pile.name
        ),
        "x from the toe [m]",
        "y above the floor [m]",
    )
    .equal_aspect()
    .size(1100, 800);
    for l in
        autoshovel_figures::shovel::pile_layers(&model.surface, x0, x1, p.geometry.pile_angle_deg)
    {
        fig.push(l);
    }
    let h = p.limits.hopper_height_m + p.dipper.height_m;
    fig.push(
        Layer::line([(x0, h), (x1, h)], Stroke::dashed(Rgb::GREY, 1))
            .with_label("c16: end height H_kk + H_cd"),
    );
    for l in autoshovel_figures::shovel::shovel_frame_layers(&model.shovel) {
        fig.push(l);
    }
    let (first, last) = (plan.samples.first(), plan.samples.last());
    for (s, color, label, names) in [
        (first, Rgb::BLUE, "start", true),
        (last, Rgb::ORANGE, "end", false),
    ] {
        if let Some(s) = s {
            for l in autoshovel_figures::shovel::shovel_pose_layers(
                &model.shovel,
                p,
                s.joints,
                color,
                label,
                names,
            ) {
                fig.push(l);
            }
        }
    }
    fig.push(
        Layer::line(
            plan.samples.iter().map(|s| (s.tip_m[0], s.tip_m[1])),
            Stroke::solid(Rgb::RED, 3),
        )
        .with_label(format!(
            "tooth path, t_d = {:.2} s, m_dig = {:.3} kg",
            d.td_s, plan.outcome.m_dig_kg
        )),
    );
    fig
}

fn convergence_figures(plan: &DigPlan, name: &str) -> Vec<Figure> {
    let h = &plan.search.history;
    let mut best = Figure::new(
        format!("Grey Wolf Optimizer convergence ({name} pile)"),
        "iteration",
        "best objective f",
    )
    .size(900, 520);
    best.push(
        Layer::line(
            h.iter().map(|g| {
                (
                    g.iteration as f64,
                    if g.best_violation == 0.0 {
                        g.best_objective
                    } else {
                        f64::NAN
                    },
                )
            }),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("best feasible f (α wolf)"),
    );
    let infeasible: Vec<(f64, f64)> = h
        .iter()
        .filter(|g| g.best_violation > 0.0 && g.best_objective.is_finite())
        .map(|g| (g.iteration as f64, g.best_objective))
        .collect();
    if !infeasible.is_empty() {
        best.push(Layer::points(infeasible, Rgb::RED, 4).with_label("best still infeasible"));
    }
    let mut share = Figure::new("Share of feasible wolves", "iteration", "feasible share")
        .size(900, 360)
        .y_range(0.0, 1.05);
    share.push(
        Layer::line(
            h.iter().map(|g| (g.iteration as f64, g.feasible_share)),
            Stroke::solid(Rgb::GREEN, 2),
        )
        .with_label("feasible share"),
    );
    vec![best, share]
}

/// One row of the paper's Tables 4 and 5.
#[derive(Debug, Clone, Copy)]
pub struct PaperRow {
    /// The pile.
    pub shape: PileShape,
    /// a_x6 [1e-7 m/s⁶].
    pub ax6_1e7: f64,
    /// a_y6 [1e-7 m/s⁶].
    pub ay6_1e7: f64,
    /// g_x [m].
    pub gx_m: f64,
    /// g_y [m].
    pub gy_m: f64,
    /// t_d [s].
    pub td_s: f64,
    /// f.
    pub f: f64,
    /// f1 [J/kg].
    pub f1_j_per_kg: f64,
    /// f2 [s/kg].
    pub f2_s_per_kg: f64,
    /// m_dig [kg].
    pub m_dig_kg: f64,
    /// Bucket fill factor [%].
    pub fill_pct: f64,
}

impl PaperRow {
    fn decision(&self) -> Decision {
        Decision {
            ax6: self.ax6_1e7 * 1e-7,
            ay6: self.ay6_1e7 * 1e-7,
            td_s: self.td_s,
            gx_m: self.gx_m,
            gy_m: self.gy_m,
        }
    }
}

/// Tables 4 (decision) and 5 (results) of the rope-shovel paper, in Table 5's order.
pub const PAPER_TABLES_4_5: [PaperRow; 4] = [
    PaperRow {
        shape: PileShape::Typical,
        ax6_1e7: -9.98,
        ay6_1e7: 5.41,
        gx_m: 0.3489,
        gy_m: 0.3159,
        td_s: 11.85,
        f: 13.76,
        f1_j_per_kg: 17.19,
        f2_s_per_kg: 5.771,
        m_dig_kg: 2.053,
        fill_pct: 99.72,
    },
    PaperRow {
        shape: PileShape::Concave,
        ax6_1e7: -17.05,
        ay6_1e7: 9.73,
        gx_m: 0.3605,
        gy_m: 0.2943,
        td_s: 11.81,
        f: 13.83,
        f1_j_per_kg: 17.22,
        f2_s_per_kg: 5.925,
        m_dig_kg: 1.991,
        fill_pct: 96.71,
    },
    PaperRow {
        shape: PileShape::Convex,
        ax6_1e7: -5.52,
        ay6_1e7: 11.33,
        gx_m: 0.2413,
        gy_m: 0.2796,
        td_s: 11.57,
        f: 13.87,
        f1_j_per_kg: 17.51,
        f2_s_per_kg: 5.367,
        m_dig_kg: 2.156,
        fill_pct: 104.7,
    },
    PaperRow {
        shape: PileShape::ConvexConcave,
        ax6_1e7: -9.71,
        ay6_1e7: 4.15,
        gx_m: 0.2825,
        gy_m: 0.2352,
        td_s: 11.49,
        f: 12.57,
        f1_j_per_kg: 15.55,
        f2_s_per_kg: 5.625,
        m_dig_kg: 2.045,
        fill_pct: 99.29,
    },
];

/// The result of `--all-surfaces`.
#[derive(Debug)]
pub struct AllSurfaces {
    /// Combined summary (`surfaces`: one summary per pile, with the paper's values).
    pub summary: Value,
    /// Files written, relative to the output folder.
    pub written: Written,
    /// The comparison table (markdown).
    pub table: String,
    /// The piles without a feasible plan, if any.
    pub error: Option<String>,
}

/// The columns of the comparison: label, summary key, scale into the table's units, decimals.
const TABLE_COLUMNS: [(&str, &str, &str, f64, usize); 10] = [
    ("a_x6 [1e-7]", "ax6", "ax6_1e7", 1e7, 2),
    ("a_y6 [1e-7]", "ay6", "ay6_1e7", 1e7, 2),
    ("g_x [m]", "gx_m", "gx_m", 1.0, 4),
    ("g_y [m]", "gy_m", "gy_m", 1.0, 4),
    ("t_d [s]", "td_s", "td_s", 1.0, 2),
    ("f", "f", "f", 1.0, 2),
    ("f1 [J/kg]", "f1_j_per_kg", "f1_j_per_kg", 1.0, 2),
    ("f2 [s/kg]", "f2_s_per_kg", "f2_s_per_kg", 1.0, 3),
    ("m_dig [kg]", "m_dig_kg", "m_dig_kg", 1.0, 3),
    ("fill [%]", "fill_factor", "fill_pct", 100.0, 2),
];

fn paper_json(r: &PaperRow) -> Value {
    json!({
        "ax6_1e7": r.ax6_1e7, "ay6_1e7": r.ay6_1e7, "gx_m": r.gx_m, "gy_m": r.gy_m,
        "td_s": r.td_s, "f": r.f, "f1_j_per_kg": r.f1_j_per_kg, "f2_s_per_kg": r.f2_s_per_kg,
        "m_dig_kg": r.m_dig_kg, "fill_pct": r.fill_pct,
    })
}

/// Plans all four piles of Fig. 7 (Table 5's order) into `out/<shape>/`
/// and compares them with Tables 4–5; `progress` prints a line per pile.
pub fn all_surfaces(setup: &Setup, out: Option<&Path>, progress: bool) -> Result<AllSurfaces> {
    let t0 = Instant::now();
    let mut rows = Vec::new();
    let mut written = Written::default();
    let mut failed = Vec::new();
    let mut panels = Vec::new();
    for paper in &PAPER_TABLES_4_5 {
        let pile = Pile::shape(paper.shape, &setup.profile);
        let sub = out
            .map(|d| prepare_dir(&d.join(paper.shape.name())))
            .transpose()?;
        let job = job(&pile, setup, sub.as_deref())?;
        let mut s = job.summary;
        if let Some(e) = &job.error {
            failed.push(e.clone());
        }
        if progress {
            crate::say!(
                "planned the {} pile: {} ({:.0} ms)",
                paper.shape.name(),
                if job.error.is_none() {
                    "feasible"
                } else {
                    "NO feasible plan"
                },
                s["plan_time_ms"].as_f64().unwrap_or(f64::NAN)
            );
        }
        // The paper's own plan, evaluated on our model of the same pile.
        let model = DigModel::new(&setup.profile, pile.surface.clone())?;
        let theirs = model.evaluate(&paper.decision());
        s["paper"] = paper_json(paper);
        s["paper_plan_on_this_model"] = json!({
            "f": num(theirs.f),
            "m_dig_kg": num(theirs.m_dig_kg),
            "fill_factor": num(theirs.fill_factor),
            "feasible": theirs.feasible(),
            "violated": theirs.violated(),
        });
        let rel = |ours: &Value, theirs: f64| ours.as_f64().map(|v| (v - theirs) / theirs);
        s["m_dig_rel_diff"] = json!(rel(&s["m_dig_kg"], paper.m_dig_kg));
        s["f_rel_diff"] = json!(rel(&s["f"], paper.f));
        if let Some(o) = s.as_object_mut() {
            if let Some(files) = o.get_mut("files").and_then(Value::as_array_mut) {
                for f in files.iter_mut() {
                    *f = json!(format!(
                        "{}/{}",
                        paper.shape.name(),
                        f.as_str().unwrap_or("")
                    ));
                }
            }
            o.remove("geometry");
        }
        written.plots.extend(
            job.written
                .plots
                .iter()
                .map(|p| format!("{}/{p}", paper.shape.name())),
        );
        written.files.extend(
            job.written
                .files
                .iter()
                .map(|p| format!("{}/{p}", paper.shape.name())),
        );
        if out.is_some() {
            panels.push(comparison_panel(&model, &s, paper));
        }
        rows.push((paper, s));
    }
    let table = markdown_table(&rows);
    let error = (!failed.is_empty()).then(|| failed.join("\n"));
    let mut summary = json!({
        "job": "plan-dig",
        "all_surfaces": true,
        "seed": setup.gwo.seed,
        "search_space": setup.search.name(),
        "init": setup.init.name(),
        "profile": setup.profile_name,
        "k_f_pa": setup.profile.material.cutting_resistance_pa,
        "epsilon": setup.profile.material.fill_resistance_ratio,
        "surfaces": rows.iter().map(|(_, s)| s.clone()).collect::<Vec<_>>(),
        "feasible": error.is_none(),
        "success": error.is_none(),
        "plan_time_ms": t0.elapsed().as_secs_f64() * 1e3,
    });
    if let Some(dir) = out {
        let path = dir.join("table.csv");
        write_table_csv(&path, &rows)?;
        written.file(dir, &path);
        written.plot(
            dir,
            write_panels(&panels, dir, "paths").context("comparison plot")?,
        );
        write_job_summary(dir, &mut summary, &mut written)?;
    }
    Ok(AllSurfaces {
        summary,
        written,
        table,
        error,
    })
}

/// A flat view of an `--all-surfaces` summary for a report table:
/// pile → ours and the paper's value of each column of Tables 4–5.
pub fn table_summary(all: &Value) -> Value {
    let mut m = Map::new();
    for key in [
        "seed",
        "search_space",
        "init",
        "profile",
        "k_f_pa",
        "epsilon",
        "success",
        "plan_time_ms",
    ] {
        m.insert(key.into(), all[key].clone());
    }
    for s in all["surfaces"].as_array().into_iter().flatten() {
        let mut row = Map::new();
        for (_, key, pkey, scale, _) in TABLE_COLUMNS {
            row.insert(pkey.into(), json!(s[key].as_f64().map(|v| v * scale)));
            row.insert(format!("{pkey}_paper"), s["paper"][pkey].clone());
        }
        for key in ["m_dig_rel_diff", "f_rel_diff", "feasible"] {
            row.insert(key.into(), s[key].clone());
        }
        m.insert(
            s["surface"].as_str().unwrap_or("?").to_string(),
            Value::Object(row),
        );
    }
    Value::Object(m)
}

fn cell(v: Option<f64>, decimals: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.decimals$}"),
        _ => "-".into(),
    }
}

fn pct(v: &Value) -> String {
    match v.as_f64() {
        Some(x) if x.is_finite() => format!("{:+.1} %", 100.0 * x),
        _ => "-".into(),
    }
}

fn markdown_table(rows: &[(&PaperRow, Value)]) -> String {
    let mut t = String::from("| surface | |");
    for (label, ..) in TABLE_COLUMNS {
        t.push_str(&format!(" {label} |"));
    }
    t.push_str(" Δm_dig | Δf |\n|---|---|");
    t.push_str(&"---|".repeat(TABLE_COLUMNS.len() + 2));
    t.push('\n');
    for (paper, s) in rows {
        let p = paper_json(paper);
        t.push_str(&format!("| {} | ours |", paper.shape.name()));
        for (_, key, _, scale, dec) in TABLE_COLUMNS {
            t.push_str(&format!(
                " {} |",
                cell(s[key].as_f64().map(|v| v * scale), dec)
            ));
        }
        t.push_str(&format!(
            " {} | {} |\n| | paper |",
            pct(&s["m_dig_rel_diff"]),
            pct(&s["f_rel_diff"])
        ));
        for (_, _, pkey, _, dec) in TABLE_COLUMNS {
            t.push_str(&format!(" {} |", cell(p[pkey].as_f64(), dec)));
        }
        t.push_str(" | |\n");
    }
    t.pop();
    t
}

fn write_table_csv(path: &Path, rows: &[(&PaperRow, Value)]) -> Result<()> {
    let mut header = vec!["surface".to_string()];
    for (_, _, pkey, ..) in TABLE_COLUMNS {
        header.push(pkey.to_string());
        header.push(format!("{pkey}_paper"));
    }
    header.extend(["m_dig_rel_diff", "f_rel_diff", "feasible"].map(String::from));
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|(paper, s)| {
            let p = paper_json(paper);
            let mut row = vec![paper.shape.name().to_string()];
            for (_, key, pkey, scale, _) in TABLE_COLUMNS {
                row.push(
                    s[key]
                        .as_f64()
                        .map(|v| format!("{}", v * scale))
                        .unwrap_or_default(),
                );
                row.push(format!("{}", p[pkey].as_f64().unwrap_or(f64::NAN)));
            }
            for k in ["m_dig_rel_diff", "f_rel_diff"] {
                row.push(s[k].as_f64().map(|v| format!("{v}")).unwrap_or_default());
            }
            row.push((s["feasible"] == true).to_string());
            row
        })
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    write_csv_cells(path, &header, &cells)?;
    Ok(())
}

/// One pile of the comparison: our tooth path and the paper's (Table 4's
/// decision drawn on our pile).
fn comparison_panel(model: &DigModel, s: &Value, paper: &PaperRow) -> Figure {
    let ours = Decision {
        ax6: s["ax6"].as_f64().unwrap_or(f64::NAN),
        ay6: s["ay6"].as_f64().unwrap_or(f64::NAN),
        td_s: s["td_s"].as_f64().unwrap_or(f64::NAN),
        gx_m: s["gx_m"].as_f64().unwrap_or(f64::NAN),
        gy_m: s["gy_m"].as_f64().unwrap_or(f64::NAN),
    };
    let theirs = paper.decision();
    let x1 = (model.surface.top() / model.profile.geometry.pile_angle_deg.to_radians().tan())
        .max(paper.gx_m)
        + 0.1;
    let x1 = x1.min(model.surface.x_range().1);
    let mut fig = Figure::new(
        format!(
            "{} pile: planned tooth path and the paper's (Table 4)",
            paper.shape.name()
        ),
        "x from the toe [m]",
        "y above the floor [m]",
    )
    .equal_aspect()
    .size(900, 480);
    for l in autoshovel_figures::shovel::pile_layers(
        &model.surface,
        -0.05,
        x1,
        model.profile.geometry.pile_angle_deg,
    ) {
        fig.push(l);
    }
    let path = |d: &Decision| -> Vec<(f64, f64)> {
        if !(d.td_s.is_finite() && d.td_s > 0.0) {
            return Vec::new();
        }
        let tr = d.trajectory();
        (0..=200)
            .map(|i| {
                let p = tr.at(d.td_s * i as f64 / 200.0).p;
                (p[0], p[1])
            })
            .collect()
    };
    fig.push(
        Layer::line(path(&ours), Stroke::solid(Rgb::RED, 3)).with_label(format!(
            "planned: m_dig {} kg, f {}",
            cell(s["m_dig_kg"].as_f64(), 3),
            cell(s["f"].as_f64(), 2)
        )),
    );
    fig.push(
        Layer::line(path(&theirs), Stroke::dashed(Rgb::BLACK, 2)).with_label(format!(
            "paper's path: m_dig {} kg, f {} (Table 5); on this model m_dig {} kg",
            paper.m_dig_kg,
            paper.f,
            cell(s["paper_plan_on_this_model"]["m_dig_kg"].as_f64(), 3)
        )),
    );
    fig
}
