//! `autoshovel filter`: one or more filter stages on any cloud, in the order
//! given on the command line, as PCL's tools and PDAL pipelines run them
//! (`autoshovel_terrain::chain`); for clouds that are not muck piles, which
//! `perceive` refuses at its floor or fit stage.

use std::path::PathBuf;

use anyhow::Result;
use autoshovel_terrain::chain::{Stage, StageKind};
use clap::ArgMatches;

use crate::output::out_dir;
use crate::output::Report as _;
use crate::pile::EncodingArg;

/// The stage flags, in no particular order (the command line gives it).
const STAGES: [StageKind; 6] = [
    StageKind::Voxel,
    StageKind::Statistical,
    StageKind::Radius,
    StageKind::Pass,
    StageKind::Range,
    StageKind::Level,
];

/// Arguments of `filter`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The cloud (.pcd .ply .las .laz .xyz .csv .txt).
    #[arg(long)]
    pub input: PathBuf,
    /// Where to write the filtered cloud; its extension picks the format.
    #[arg(long)]
    pub output: PathBuf,
    /// PCD/PLY encoding (default binary).
    #[arg(long, value_enum)]
    pub encoding: Option<EncodingArg>,
    /// Voxel grid to centroids (PCL VoxelGrid): LEAF or LX,LY,LZ (m).
    #[arg(long, value_name = "LEAF", allow_hyphen_values = true)]
    pub voxel: Vec<String>,
    /// Statistical outlier removal (PCL StatisticalOutlierRemoval): K,ALPHA, or K,ALPHA,both for the two-sided rule.
    #[arg(long, value_name = "K,ALPHA", allow_hyphen_values = true)]
    pub statistical: Vec<String>,
    /// Radius outlier removal (PCL RadiusOutlierRemoval): RADIUS,MIN_NEIGHBOURS.
    #[arg(long, value_name = "R,MIN", allow_hyphen_values = true)]
    pub radius: Vec<String>,
    /// Pass-through (PCL PassThrough): AXIS:MIN:MAX keeps MIN ≤ v ≤ MAX; add :outside for the rest; -inf/inf for no limit.
    #[arg(long, value_name = "AXIS:MIN:MAX", allow_hyphen_values = true)]
    pub pass: Vec<String>,
    /// Keep points by dimension ranges (PDAL filters.range): e.g. `Classification[2:2]` for a classified survey's ground; ranges of one dimension ORed, of different ones ANDed; X/Y/Z are the file's coordinates.
    #[arg(long, value_name = "LIMITS", allow_hyphen_values = true)]
    pub range: Vec<String>,
    /// Level the sensor frame: ROLL,PITCH (deg).
    #[arg(long, value_name = "ROLL,PITCH", allow_hyphen_values = true)]
    pub level: Vec<String>,
    #[command(flatten)]
    pub report: crate::output::OutputArgs,
}

/// The stages of `matches` in the order they were given (each flag may be
/// repeated).
pub fn ordered_stages(matches: &ArgMatches) -> Result<Vec<Stage>> {
    let mut given: Vec<(usize, StageKind, String)> = Vec::new();
    for kind in STAGES {
        let (Some(idx), Some(values)) = (
            matches.indices_of(kind.flag()),
            matches.get_many::<String>(kind.flag()),
        ) else {
            continue;
        };
        given.extend(idx.zip(values).map(|(i, v)| (i, kind, v.clone())));
    }
    given.sort_by_key(|(i, _, _)| *i);
    Ok(given
        .into_iter()
        .map(|(_, kind, v)| Stage::parse(kind, &v))
        .collect::<Result<_, _>>()?)
}

/// Runs `filter` with the stages in `matches`' order.
pub fn run(args: &Args, matches: &ArgMatches) -> Result<()> {
    let stages = ordered_stages(matches)?;
    let out = out_dir(
        args.report.out.as_deref(),
        &[Some(&args.input), Some(&args.output)],
        args.report.force,
    )?;
    let job = autoshovel_jobs::filter(
        &args.input,
        &args.output,
        &stages,
        args.encoding.map(Into::into),
        out.as_ref(),
        args.report.force,
        !args.report.json,
    )?;
    job.report(args.report.json, |s| {
        crate::say!(
            "filter {} ({}, {} points, CRS {}{})",
            s.input,
            s.input_format,
            s.points_in,
            s.crs,
            dropped(s.non_finite_dropped)
        );
        for st in &s.stages {
            crate::say!(
                "  --{:<12} {:<16} {:>10} -> {:>10} points  {:>9.1} ms",
                st.stage,
                st.spec,
                st.points_in,
                st.points_out,
                st.ms
            );
        }
        crate::say!(
            "wrote {} points to {} ({})",
            s.points_out,
            s.output,
            s.output_encoding
        );
        for w in &s.warnings {
            eprintln!("warning: {w}");
        }
    })
}

/// ", N non-finite points dropped" when N > 0 (an organised scan's NaN
/// returns): said on the first line, not only in summary.json.
pub(crate) fn dropped(n: usize) -> String {
    if n == 0 {
        String::new()
    } else {
        format!(", {n} non-finite points dropped")
    }
}
