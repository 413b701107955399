//! The perception jobs (SPEC §3): a scan read and perceived, a folder of
//! live frames, a survey by tiles, and the pile a dig is planned on.

use std::path::Path;

use autoshovel_figures as figures;
use autoshovel_rope_shovel_dig::{MachineProfile, Pile};
use autoshovel_terrain::perceive::{
    perceive_file_with, PerceiveSummary, Perceived, PerceptionParams,
};

use crate::{progress_bar, Job, JobError, OutDir, Result};

/// Reads `input` (with a progress bar when `progress`) and perceives it;
/// errors name the file.
pub fn read_and_perceive(
    input: &Path,
    params: &PerceptionParams,
    progress: bool,
) -> Result<Perceived> {
    let bar = progress_bar(progress, "reading [{bar:40}] {bytes}/{total_bytes} ({eta})");
    let spinner = progress_bar(progress, "{spinner} {msg} ({elapsed})");
    let mut ticking = false;
    let got = perceive_file_with(
        input,
        params,
        &mut |done, total| {
            bar.set_length(total);
            bar.set_position(done);
        },
        &mut |stage| {
            bar.finish_and_clear();
            // Once, and only when shown: each call starts a ticking
            // thread anew, hidden or not.
            if progress && !ticking {
                spinner.enable_steady_tick(std::time::Duration::from_millis(120));
                ticking = true;
            }
            spinner.set_message(match stage {
                "level" => "levelling",
                "ground" => "removing the floor",
                "radius" => "radius outlier removal",
                "statistical" => "statistical outlier removal",
                "voxel" => "voxel grid",
                "smooth" => "bilateral smoothing",
                "fit" => "fitting the surface",
                other => other,
            });
        },
    );
    bar.finish_and_clear();
    spinner.finish_and_clear();
    // A read error names the file itself; the pipeline's do not.
    got.map_err(|e| match e {
        autoshovel_terrain::SurfaceError::Cloud(e) => JobError::from(e),
        e => JobError::During {
            step: input.display().to_string(),
            source: Box::new(e.into()),
        },
    })
}

/// `perceive`: the §3 pipeline on `input`.
pub fn perceive(
    input: &Path,
    params: &PerceptionParams,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<PerceiveSummary>> {
    let got = read_and_perceive(input, params, progress)?;
    let summary = PerceiveSummary::new(input, params, &got);
    Job::finish(summary, out, |dir, written| {
        Ok(figures::perceive::write(dir, &got, written)?)
    })
}

/// `perceive` on a folder of frames (frame mode), with a progress bar
/// over the frames; the memory the first frame will take is mapped first
/// (`process::warm`, by the first file's size).
pub fn perceive_frames(
    dir: &Path,
    params: &PerceptionParams,
    options: autoshovel_terrain::frames::FrameOptions,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<autoshovel_terrain::frames::FramesSummary>> {
    let bar = progress_bar(
        progress,
        "frames [{bar:40}] {pos}/{len} ({per_sec}, {eta}) {msg}",
    );
    let files = autoshovel_terrain::frames::frames_in(dir)?;
    crate::process::warm(std::fs::metadata(&files[0]).map_or(0, |m| m.len()));
    let input = dir.display().to_string();
    let done = autoshovel_terrain::frames::perceive_files(
        &input,
        &files,
        params,
        options,
        &mut |done, total, r| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            bar.set_message(if r.ok {
                format!("{:.0} ms", r.latency_ms)
            } else {
                format!("skipped {}", r.file)
            });
        },
    );
    bar.finish_and_clear();
    let done = done?;
    Job::finish(done.summary.clone(), out, |dir, written| {
        Ok(figures::frames::write(dir, &done, written)?)
    })
}

/// `perceive --tiles`: a survey by tiles, with a progress bar over each
/// pass; the cleaned tiles are written into the output's `tiles/` as LAZ
/// as they come (staged: nothing is left of a failed run).
pub fn perceive_tiles(
    input: &Path,
    params: &PerceptionParams,
    mut options: autoshovel_terrain::tiles::TileOptions,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<autoshovel_terrain::tiles::TiledSummary>> {
    use autoshovel_terrain::tiles::{perceive_tiled, Survey, TiledSummary};
    let survey = Survey::open(&[input.to_path_buf()])?;
    let staging = out.map(OutDir::stage).transpose()?;
    let tiles_dir = staging.as_ref().map(|s| s.path().join("tiles"));
    if let Some(s) = &staging {
        options.work_dir = s.path().to_path_buf();
    }
    // The survey's records are kept only for tiles that are written.
    options.attributes &= tiles_dir.is_some();
    if let Some(d) = &tiles_dir {
        std::fs::create_dir_all(d).map_err(|e| JobError::io(d, e))?;
    }
    let bar = progress_bar(
        progress,
        "{prefix:>18} [{bar:40}] {pos}/{len} ({eta}) {msg}",
    );
    let mut tile_files = Vec::new();
    let got = perceive_tiled(
        &survey,
        params,
        &options,
        &mut |what, done, total| {
            if bar.prefix() != what {
                bar.set_prefix(what.to_string());
                bar.reset();
            }
            bar.set_length(total);
            bar.set_position(done);
        },
        &mut |tile| {
            if let Some(d) = &tiles_dir {
                let f = d.join(tile.file_name());
                autoshovel_point_cloud::io::write(
                    &f,
                    &tile.cloud,
                    autoshovel_point_cloud::io::Encoding::Binary,
                )?;
                tile_files.push(f);
            }
            Ok(())
        },
    );
    bar.finish_and_clear();
    let got = got?;
    let summary = TiledSummary::new(
        &input.display().to_string(),
        &survey,
        params,
        &options,
        &got,
    );
    Job::finish_in(summary.clone(), staging, |dir, written| {
        for f in &tile_files {
            written.file(dir, f);
        }
        Ok(figures::tiles::write(dir, &got, &summary, written)?)
    })
}

/// The pile of a scan for `plan-dig --cloud`: the perception pipeline, then
/// the dig profile cut by the library's rule. The dig planner stands on the
/// paper's polynomial surface ([RS eq. 21]), so its R² gate applies here
/// whatever model `params` names.
pub fn scan_pile(
    path: &Path,
    params: &PerceptionParams,
    profile: &MachineProfile,
    progress: bool,
) -> Result<Pile> {
    let mut params = params.clone();
    params.fit.model = autoshovel_terrain::perceive::SurfaceModel::Polynomial;
    let got = read_and_perceive(path, &params, progress)?;
    Ok(Pile::scan(path, &got, profile)?)
}
