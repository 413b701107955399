//! `autoshovel perceive`: the rope-shovel paper's combined filtering process
//! (§3, SPEC §4.1) on a scan file, as `autoshovel_terrain::perceive` runs it;
//! its settings, defaults and stages are documented there.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use autoshovel_terrain::perceive::PerceptionParams;

use crate::output::out_dir;
use crate::output::Report as _;

/// Arguments of `perceive`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The scan (.pcd .ply .las .laz .xyz .csv .txt), or a folder of
    /// frames from one sensor pose, perceived in name order with the
    /// levelling kept between frames (frame mode).
    #[arg(long, required_unless_present = "print_config")]
    pub input: Option<PathBuf>,
    /// Frame mode: search the floor and level again every N frames (0: once).
    #[arg(long, default_value_t = 0)]
    pub relevel_every: usize,
    /// Frame mode: run under real-time scheduling (SCHED_FIFO) at this
    /// priority, 1–99 (10 when given bare), so that other tasks on the
    /// machine wait for a frame rather than a frame for them; needs root or
    /// CAP_SYS_NICE.
    #[arg(long, num_args = 0..=1, default_missing_value = "10", value_name = "PRIORITY")]
    pub realtime: Option<u8>,
    /// Frame mode: cell edge of the running height model (m) (default: 4 × the
    /// point spacing); survey mode: of the survey's height model (default 1 m).
    #[arg(long)]
    pub model_cell: Option<f64>,
    /// Survey mode: perceive a LAS/LAZ survey (a file, or a folder of
    /// files taken as one survey) by tiles with halos, in bounded memory,
    /// with the whole cloud's result; the cleaned tiles go to `--out`'s
    /// `tiles/`. Working files go to the system's temporary folder (some
    /// 30 bytes a point read, at the most) and are removed at the end.
    #[arg(long)]
    pub tiles: bool,
    /// Survey mode: tile side (m) (default: from the memory limit and the
    /// survey's density). Implies --tiles.
    #[arg(long)]
    pub tile_size: Option<f64>,
    /// Survey mode: most working memory of the tiles running at once (a
    /// tile a core while they fit) (GiB).
    #[arg(long, default_value_t = 2.0)]
    pub memory_limit: f64,
    /// Pipeline settings (TOML); defaults otherwise (`autoshovel perceive --print-config` shows them).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Print the pipeline settings (the defaults, or --config's) as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// The settings of `--config`, or the defaults.
pub fn load_params(config: Option<&Path>) -> Result<PerceptionParams> {
    Ok(match config {
        Some(p) => PerceptionParams::load(p)?,
        None => PerceptionParams::default(),
    })
}

/// Runs `perceive`.
pub fn run(args: &Args) -> Result<()> {
    let params = load_params(args.config.as_deref())?;
    if args.print_config {
        crate::say!("{}", params.to_toml());
        return Ok(());
    }
    let input = args.input.as_deref().context("--input is required")?;
    let out = out_dir(
        args.output.out.as_deref(),
        &[Some(input), args.config.as_deref()],
        args.output.force,
    )?;
    if args.tiles || args.tile_size.is_some() {
        if args.relevel_every != 0 || args.realtime.is_some() {
            anyhow::bail!("--relevel-every and --realtime are for a folder of frames, not --tiles");
        }
        if !(args.memory_limit.is_finite() && args.memory_limit > 0.0) {
            anyhow::bail!(
                "--memory-limit {}: expected a size > 0 in GiB",
                args.memory_limit
            );
        }
        let defaults = autoshovel_terrain::tiles::TileOptions::default();
        let options = autoshovel_terrain::tiles::TileOptions {
            tile_m: args.tile_size,
            memory_limit: (args.memory_limit * f64::from(1u32 << 30)) as u64,
            model_cell_m: args.model_cell.unwrap_or(defaults.model_cell_m),
            ..defaults
        };
        let job = autoshovel_jobs::perceive_tiles(
            input,
            &params,
            options,
            out.as_ref(),
            !args.output.json,
        )?;
        return job.report(args.output.json, |s| {
            crate::say!(
                "perceive {} by tiles: {} file(s), {} points in {} tiles of {:.1} m (halo {:.2} m)",
                s.input,
                s.files.len(),
                s.input_points,
                s.tiles_used,
                s.tile_m,
                s.halo_m
            );
            for st in &s.stages {
                crate::say!("  {:<12} {:>11} points  {:>10.1} ms", st.stage, st.points, st.ms);
            }
            crate::say!(
                "  {:.2} M points/s; largest tile {} points with its halo; peak memory {}; {} outlier(s) searched past the halo",
                s.points_per_s / 1e6,
                s.largest_tile_points,
                s.peak_memory_bytes
                    .map_or("unknown".into(), |b| format!("{:.2} GiB", b as f64 / f64::from(1u32 << 30))),
                s.statistical_researched
            );
            crate::say!(
                "  roll {:.3} deg, pitch {:.3} deg from a sample of {} points; fit {}",
                s.roll_deg,
                s.pitch_deg,
                s.sample_points,
                s.fit.as_ref().map_or("none".into(), |f| format!("degree {}, R² {:.4}", f.degree, f.r2))
            );
            if let Some(note) = &s.fit_note {
                crate::say!("  {note}");
            }
            for w in &s.warnings {
                eprintln!("warning: {w}");
            }
        });
    }
    if input.is_dir() {
        if let Some(priority) = args.realtime {
            autoshovel_jobs::process::realtime(priority)?;
        }
        let options = autoshovel_terrain::frames::FrameOptions {
            relevel_every: args.relevel_every,
            model_cell_m: args.model_cell,
            realtime_priority: args.realtime,
        };
        let job = autoshovel_jobs::perceive_frames(
            input,
            &params,
            options,
            out.as_ref(),
            !args.output.json,
        )?;
        return job.report(args.output.json, |s| {
            crate::say!(
                "perceive {} frames of {}: {} perceived, {} skipped",
                s.frames,
                s.input,
                s.frames_ok,
                s.frames_skipped
            );
            for k in &s.skipped {
                crate::say!("  skipped frame {} ({}): {}", k.index, k.file, k.reason);
            }
            crate::say!(
                "  latency: first {:.1} ms, then median {:.1} ms, 95 % {:.1} ms, max {:.1} ms ({:.1} frames/s{})",
                s.latency.first_ms,
                s.latency.median_ms,
                s.latency.p95_ms,
                s.latency.max_ms,
                s.frames_per_s,
                s.realtime_priority
                    .map_or(String::new(), |p| format!(", SCHED_FIFO priority {p}"))
            );
            for stage in autoshovel_terrain::perceive::STAGES {
                if let Some(ms) = s.timings_ms.get(stage) {
                    crate::say!("  {stage:<12} median {ms:>9.1} ms");
                }
            }
            crate::say!(
                "  roll {:.3} deg, pitch {:.3} deg; height model {} × {} cells of {:.2} m, {:.0} % seen, median change {:.1} mm a frame",
                s.roll_deg,
                s.pitch_deg,
                s.model_size[0],
                s.model_size[1],
                s.model_cell_m,
                100.0 * s.model_coverage,
                1e3 * s.model_change_rms_m
            );
        });
    }
    if args.relevel_every != 0 || args.model_cell.is_some() || args.realtime.is_some() {
        anyhow::bail!(
            "--relevel-every, --model-cell and --realtime are for a folder of frames; {} is a file",
            input.display()
        );
    }
    let job = autoshovel_jobs::perceive(input, &params, out.as_ref(), !args.output.json)?;
    job.report(args.output.json, |s| {
        crate::say!(
            "perceive {} ({} points{})",
            s.input,
            s.input_points,
            crate::filter::dropped(s.non_finite_dropped)
        );
        for st in &s.stages {
            crate::say!(
                "  {:<12} {:>10} points  {:>9.1} ms",
                st.stage,
                st.points,
                st.ms
            );
        }
        crate::say!(
            "  level {}, ground {}: roll {:.3} deg, pitch {:.3} deg from a floor of {} points ({:.1} % of the scan, RMS {:.1} mm), fit degree {}, R² {:.4} (all points {:.4})",
            s.level_mode,
            s.ground_mode,
            s.roll_deg,
            s.pitch_deg,
            s.floor_points,
            100.0 * s.floor_share,
            1e3 * s.floor_rms_m,
            s.fit.degree,
            s.r2,
            s.fit.r2_all_points
        );
        let m = &s.height_model;
        crate::say!(
            "  height model {} × {} cells of {:.3} m ({:.1} % holes), residual RMS {:.1} mm; volume {:.1} m³ above z = {:.3} m",
            m.size[0],
            m.size[1],
            m.cell_m,
            100.0 * m.hole_share,
            1e3 * m.rms_residual_m,
            s.volume_m3,
            s.volume_base_m
        );
        if let Some(note) = &s.ground_note {
            crate::say!("  {note}");
        }
        for w in &s.warnings {
            eprintln!("warning: {w}");
        }
    })
}
