//! `autoshovel plan-dig`: the rope-shovel paper's dig planning (§2 and §4;
//! SPEC §4.2–4.3) on a pile of Fig. 7 at the 1:30 scale or on a scan run
//! through the `perceive` pipeline — `autoshovel_rope_shovel_dig::plan_pile` (a single
//! pile) or `autoshovel_rope_shovel_dig::all_surfaces` (the four piles beside Tables
//! 4–5), written by `autoshovel_figures::dig`.
//!
//! `--out DIR` gets `summary.json`, `samples.csv`, `convergence.csv`, `polish.csv` (the CMA-ES polish, when one ran),
//! `pack.csv`, `surface.csv` and the plots `dig_path`, `speeds`, `forces`
//! and `convergence`; `--all-surfaces` one subfolder per pile, `table.csv`
//! and `paths`. A scan (`--cloud`) is cut into a dig profile by
//! `autoshovel_rope_shovel_dig::scan`'s rule.

use std::path::PathBuf;

use anyhow::{bail, Result};
use autoshovel_figures::dig as figures;
use autoshovel_optim::Init;
use autoshovel_rope_shovel_dig::TomlFile as _;
use autoshovel_rope_shovel_dig::{
    DigSetup, DigSummary, MachineProfile, Pile, SearchSpace, WarmStart, CONSTRAINT_NAMES,
};
use autoshovel_terrain::PileShape;

use autoshovel_terrain::perceive::PerceptionParams;

use crate::output::out_dir;
use crate::output::Report as _;

/// How the optimiser's first pack is placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum InitArg {
    /// The good point set of §4.5 (deterministic; the seed drives the iterations).
    GoodPointSet,
    /// Uniform random wolves (Mirjalili et al. 2014), to show what the good point set buys.
    Random,
}

impl From<InitArg> for Init {
    fn from(a: InitArg) -> Self {
        match a {
            InitArg::GoodPointSet => Init::GoodPointSet,
            InitArg::Random => Init::Random,
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

impl From<SearchArg> for SearchSpace {
    fn from(a: SearchArg) -> Self {
        match a {
            SearchArg::Bends => SearchSpace::Bends,
            SearchArg::Paper => SearchSpace::Paper,
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
    /// After the Grey Wolf Optimizer, polish its best plan by CMA-ES with this
    /// many more evaluations; 0 is the paper's search, GWO alone. The default
    /// lands within 1 % of a long search on every pile (docs/rope-shovel-dig.md).
    #[arg(long, default_value_t = autoshovel_rope_shovel_dig::plan::DEFAULT_POLISH_EVALUATIONS)]
    pub polish: usize,
    /// Start from the final pack of an earlier plan (its `pack.csv`), as the
    /// next dig cycle would: those wolves replace the first of the new pack.
    #[arg(long, conflicts_with = "all_surfaces")]
    pub warm_start: Option<PathBuf>,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// Runs `plan-dig` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    if args.print_profile {
        use std::io::Write as _;
        let text = match &args.profile {
            Some(p) => MachineProfile::load(p)?.to_toml(),
            None => autoshovel_rope_shovel_dig::profile::SCALE_MODEL_TOML.to_string(),
        };
        let _ = write!(std::io::stdout().lock(), "{text}");
        return Ok(());
    }
    let mut setup = match &args.profile {
        Some(p) => DigSetup::new(MachineProfile::load(p)?, p.display().to_string(), args.seed),
        None => DigSetup::scale_model(args.seed),
    };
    setup.polish_evaluations = args.polish;
    setup.gwo.init = args.init.into();
    setup.search = args.search.into();
    if let Some(path) = &args.warm_start {
        setup.warm_start = Some(WarmStart::load(path)?);
    }
    let pipeline = match &args.config {
        Some(p) => PerceptionParams::load(p)?,
        None => PerceptionParams::default(),
    };
    let out = out_dir(
        args.output.out.as_deref(),
        &[
            args.cloud.as_deref(),
            args.config.as_deref(),
            args.profile.as_deref(),
            args.warm_start.as_deref(),
        ],
        args.output.force,
    )?;
    if args.all_surfaces {
        return run_all_surfaces(&setup, out.as_ref(), args.output.json);
    }
    let pile = match &args.cloud {
        Some(path) => {
            autoshovel_jobs::scan_pile(path, &pipeline, &setup.profile, !args.output.json)?
        }
        None => Pile::shape(args.surface.unwrap_or_default(), &setup.profile)?,
    };
    let job = autoshovel_jobs::plan_dig(&pile, &setup, out.as_ref())?;
    job.report(args.output.json, print_human)?;
    match &job.summary.error {
        Some(e) => bail!("{e}"),
        None => Ok(()),
    }
}

/// `--all-surfaces`: the four piles beside Tables 4–5.
fn run_all_surfaces(
    setup: &DigSetup,
    out: Option<&crate::output::OutDir>,
    json: bool,
) -> Result<()> {
    let job = autoshovel_jobs::plan_dig_all_surfaces(setup, out, |s| {
        if !json {
            crate::say!(
                "planned the {} pile: {} ({:.0} ms)",
                s.plan.header.surface,
                if s.plan.error.is_none() {
                    "feasible"
                } else {
                    "NO feasible plan"
                },
                s.plan.plan_time_ms
            );
        }
    })?;
    job.report(json, |s| crate::say!("{}", figures::markdown_table(s)))?;
    match job.summary.error() {
        Some(e) => bail!("{e}"),
        None => Ok(()),
    }
}

/// The human-readable lines of a plan.
fn print_human(s: &DigSummary) {
    let h = &s.header;
    crate::say!(
        "plan-dig {} ({}), profile {}, seed {}, search {}, init {}",
        h.surface,
        h.surface_source,
        h.profile,
        h.seed,
        h.search_space,
        h.init
    );
    let Some(p) = s.plan.as_ref().filter(|_| s.success) else {
        crate::say!("  no feasible plan ({:.0} ms)", s.plan_time_ms);
        return;
    };
    crate::say!(
        "  x = [a_x6 {:.3e} m/s⁶, a_y6 {:.3e} m/s⁶, t_d {:.2} s, g_x {:.4} m, g_y {:.4} m]",
        p.ax6,
        p.ay6,
        p.td_s,
        p.gx_m,
        p.gy_m
    );
    crate::say!(
        "  f {:.3} = {}·f1 + {}·f2, f1 {:.3} J/kg, f2 {:.3} s/kg; m_dig {:.3} kg, fill {:.2} %",
        p.f,
        h.k1,
        h.k2,
        p.f1_j_per_kg,
        p.f2_s_per_kg,
        p.m_dig_kg,
        100.0 * p.fill_factor
    );
    crate::say!(
        "  energy: hoist {:.2} J, crowd {:.2} J; {} evaluations in {:.0} ms",
        p.hoist_energy_j,
        p.crowd_energy_j,
        p.evaluations,
        s.plan_time_ms
    );
    crate::say!("| constraint | measured | bound | limit | units | met |");
    crate::say!("|---|---|---|---|---|---|");
    let f = |v: f64| {
        if v.is_finite() {
            format!("{v:.4}")
        } else {
            "-".into()
        }
    };
    for name in CONSTRAINT_NAMES {
        let Some(c) = p.constraints.get(name) else {
            continue;
        };
        crate::say!(
            "| {name} | {} | {} | {} | {} | {} |",
            f(c.measured),
            c.bound.name(),
            f(c.limit),
            c.units,
            if c.met { "yes" } else { "NO" }
        );
    }
}
