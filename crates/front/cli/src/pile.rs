//! `autoshovel generate-pile`: a synthetic LiDAR scan of one of the four
//! pile shapes of the rope-shovel paper's Fig. 7, written in any format.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use autoshovel_point_cloud::io::Encoding;
use autoshovel_terrain::{generate_pile, GeneratePileSummary, PileParams, PileShape, ScanPattern};

use crate::output::print_json;

/// Encoding choice for PCD and PLY.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum EncodingArg {
    /// Text.
    Ascii,
    /// Little-endian binary (the default).
    Binary,
    /// PCD binary_compressed (LZF).
    BinaryCompressed,
    /// PLY binary_big_endian.
    BinaryBigEndian,
}

impl From<EncodingArg> for Encoding {
    fn from(e: EncodingArg) -> Self {
        match e {
            EncodingArg::Ascii => Encoding::Ascii,
            EncodingArg::Binary => Encoding::Binary,
            EncodingArg::BinaryCompressed => Encoding::BinaryCompressed,
            EncodingArg::BinaryBigEndian => Encoding::BinaryBigEndian,
        }
    }
}

/// Arguments of `generate-pile`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Pile shape (Fig. 7).
    #[arg(long, default_value = "typical")]
    pub shape: PileShape,
    /// Number of points.
    #[arg(long, default_value_t = 100_000)]
    pub points: usize,
    /// Sensor roll (deg).
    #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
    pub roll: f64,
    /// Sensor pitch (deg).
    #[arg(long, default_value_t = -2.0, allow_negative_numbers = true)]
    pub pitch: f64,
    /// Scale of the pile: 1 = a 10 m face; 0.0333 = the paper's 1:30 model.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// How the points are spread: area (even over the ground) or rosette (a
    /// Livox-like non-repetitive pattern cast from the sensor).
    #[arg(long, default_value = "area")]
    pub pattern: ScanPattern,
    /// Sensor height above the floor (m at scale 1).
    #[arg(long, default_value_t = 12.0)]
    pub sensor_height: f64,
    /// Full field of view of the rosette pattern (deg).
    #[arg(long, default_value_t = 70.4)]
    pub fov: f64,
    /// Seed of the noise and sampling.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output file; its extension picks the format (.pcd .ply .las .laz .xyz .csv).
    #[arg(long)]
    pub out: PathBuf,
    /// Write a sequence of N frames from the same sensor pose instead of
    /// one scan (seeds SEED, SEED+1, …), named like --out with -0000,
    /// -0001, … before the extension (its folder is made if need be): the
    /// input of `perceive --input FOLDER`.
    #[arg(long, default_value_t = 1)]
    pub frames: usize,
    /// Write a survey of NX × NY scans instead of one (e.g. `10,10`): piles
    /// side by side, each scan shifted by the scan window less 5 % (so
    /// neighbours overlap), all in one frame (tilted by --roll and
    /// --pitch), seeds SEED, SEED+1, …, named like --frames: the input of
    /// `perceive --tiles --input FOLDER`.
    #[arg(long, value_parser = parse_survey)]
    pub survey: Option<[usize; 2]>,
    /// PCD/PLY encoding (default binary).
    #[arg(long, value_enum)]
    pub encoding: Option<EncodingArg>,
    /// Replace an existing file at --out.
    #[arg(long)]
    pub force: bool,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `generate-pile`.
pub fn run(args: &Args) -> Result<()> {
    if args.points > 200_000_000 {
        anyhow::bail!(
            "--points {} is more than the 200,000,000 a scan file should hold",
            args.points
        );
    }
    let params = PileParams {
        shape: args.shape,
        points: args.points,
        scale: args.scale,
        roll_rad: args.roll.to_radians(),
        pitch_rad: args.pitch.to_radians(),
        seed: args.seed,
        pattern: args.pattern,
        sensor_height_m: args.sensor_height,
        fov_rad: args.fov.to_radians(),
        ..PileParams::default()
    };
    if !(1..=100_000).contains(&args.frames) {
        anyhow::bail!("--frames {}: expected 1 to 100000", args.frames);
    }
    if args.survey.is_some() && args.frames > 1 {
        anyhow::bail!("--survey and --frames: give one or the other");
    }
    let files = args.survey.map_or(args.frames, |[nx, ny]| nx * ny);
    let step = params.survey_step_m();
    let paths = autoshovel_terrain::frames::sequence_paths(&args.out, files);
    if let Some(parent) = paths[0].parent().filter(|p| !p.as_os_str().is_empty()) {
        if files > 1 {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("cannot create the folder {}", parent.display()))?;
        }
    }
    // Frames are independent (each its own seed, each file written whole):
    // made on all cores, the same files as one by one; an error stops the run.
    use rayon::prelude::*;
    let summaries: Vec<GeneratePileSummary> = paths
        .par_iter()
        .enumerate()
        .map(|(i, path)| {
            let params = params.nth_scan(i, args.survey.map(|[nx, _]| nx));
            generate_one(&params, path, args)
        })
        .collect::<Result<_>>()?;
    let mut summary = summaries.into_iter().last().expect("at least one frame");
    summary.frames = paths.len();
    summary.file = paths[0].display().to_string();
    summary.seed = args.seed;
    if args.json {
        print_json(&summary)?;
    } else if let Some([nx, ny]) = args.survey {
        crate::say!(
            "wrote a survey of {nx} × {ny} scans of {} points each ({} piles side by side every {:.1} m × {:.1} m, roll {} deg, pitch {} deg, seeds {}–{}): {} … {}",
            summary.points,
            summary.shape,
            step[0],
            step[1],
            args.roll,
            args.pitch,
            args.seed,
            args.seed.wrapping_add(summary.frames as u64 - 1),
            summary.file,
            summary.last_file
        );
    } else if summary.frames > 1 {
        crate::say!(
            "wrote {} frames of {} points of a {} pile (roll {} deg, pitch {} deg, seeds {}–{}): {} … {}",
            summary.frames,
            summary.points,
            summary.shape,
            args.roll,
            args.pitch,
            args.seed,
            args.seed.wrapping_add(summary.frames as u64 - 1),
            summary.file,
            summary.last_file
        );
    } else {
        crate::say!(
            "wrote {} points of a {} pile (roll {} deg, pitch {} deg, seed {}) to {}",
            summary.points,
            summary.shape,
            args.roll,
            args.pitch,
            summary.seed,
            summary.file
        );
    }
    Ok(())
}

/// `NX,NY` of `--survey`.
fn parse_survey(s: &str) -> std::result::Result<[usize; 2], String> {
    let bad =
        || format!("{s}: expected NX,NY, two whole numbers of scans from 1 to 1000, e.g. 10,10");
    let (a, b) = s.split_once(',').ok_or_else(bad)?;
    let n = |v: &str| {
        v.trim()
            .parse::<usize>()
            .ok()
            .filter(|n| (1..=1000).contains(n))
    };
    match (n(a), n(b)) {
        (Some(x), Some(y)) => Ok([x, y]),
        _ => Err(bad()),
    }
}

/// Generates one scan with `params` and writes it to `path`.
fn generate_one(params: &PileParams, path: &Path, args: &Args) -> Result<GeneratePileSummary> {
    let t0 = std::time::Instant::now();
    // The library names its fields; the user wrote flags.
    let cloud = generate_pile(params).map_err(|e| match e {
        autoshovel_terrain::SurfaceError::BadParameter {
            name,
            value,
            expected,
        } => {
            let flag = match name {
                "PileParams.scale" => "--scale",
                "PileParams.points" => "--points",
                "PileParams.roll_rad" => "--roll",
                "PileParams.pitch_rad" => "--pitch",
                "PileParams.sensor_height_m" => "--sensor-height",
                "PileParams.fov_rad" => "--fov",
                other => other,
            };
            let (value, expected) = match flag {
                "--roll" | "--pitch" | "--fov" => {
                    (value.to_degrees(), expected.replace(" [rad]", ""))
                }
                _ => (value, expected.to_string()),
            };
            anyhow::anyhow!(
                "{flag} {}: expected {expected}",
                autoshovel_core::config::short(value)
            )
        }
        e => e.into(),
    })?;
    let gen_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t1 = std::time::Instant::now();
    let encoding =
        autoshovel_jobs::write_cloud(path, &[], &cloud, args.encoding.map(Into::into), args.force)?;
    Ok(GeneratePileSummary::new(
        params,
        cloud.len(),
        path,
        encoding.name(),
        (gen_ms, t1.elapsed().as_secs_f64() * 1e3),
    ))
}
