//! `filter`: one or more filter stages on any cloud, in the order given,
//! as PCL's tools and PDAL pipelines run them (`autoshovel_terrain::chain`);
//! for clouds that are not muck piles, which `perceive` refuses at its
//! floor or fit stage.

use std::path::{Path, PathBuf};

use autoshovel_point_cloud::io::{read, write_named, Encoding, WriteOptions};
use autoshovel_point_cloud::PointCloud;
use autoshovel_terrain::chain::{run_chain, FilterSummary, Stage};

use crate::error::During as _;
use crate::{progress_bar, Job, JobError, OutDir, Result};

/// Writes `cloud` to `path` (format by extension, `encoding` or its
/// default) atomically, never over `inputs`, and over an existing file
/// autoshovel did not write only with `force`; returns the encoding used.
pub fn write_cloud(
    path: &Path,
    inputs: &[PathBuf],
    cloud: &PointCloud,
    encoding: Option<Encoding>,
    force: bool,
) -> Result<Encoding> {
    let encoding = encoding.unwrap_or_else(|| Encoding::default_for(path));
    autoshovel_report::write_file_atomically::<JobError>(
        path,
        inputs,
        (&Default::default(), force),
        |scratch, target| {
            let options = WriteOptions {
                encoding: Some(encoding),
                ..WriteOptions::default()
            };
            write_named(scratch, target, cloud, &options)?;
            Ok(())
        },
    )?;
    Ok(encoding)
}

/// Refuses, before any work, an `--encoding` the output's format does not
/// have (a text file is ascii, LAS/LAZ binary): a writer reports only
/// what it wrote.
fn check_encoding(output: &Path, encoding: Option<Encoding>) -> Result<()> {
    let Some(e) = encoding else { return Ok(()) };
    let format = autoshovel_point_cloud::io::Format::from_path(output)?;
    let has = format.encodings();
    let fixed = match format {
        autoshovel_point_cloud::io::Format::Las | autoshovel_point_cloud::io::Format::Laz => {
            Encoding::Binary
        }
        _ => Encoding::Ascii,
    };
    if has.contains(&e) || (has.is_empty() && e == fixed) {
        return Ok(());
    }
    let choices = if has.is_empty() {
        format!("its one encoding is {fixed}")
    } else {
        let names: Vec<_> = has.iter().map(|e| e.name()).collect();
        format!("use {}", names.join(", "))
    };
    Err(JobError::setting(
        "--encoding",
        e,
        format!(
            "is not an encoding of {} ({}: {choices})",
            output.display(),
            format.extension()
        ),
    ))
}

/// `filter`: `stages` in order on the cloud of `input`, the result written
/// to `output` (never over the input; over a file autoshovel did not write
/// only with `force`), with a progress bar over the read when `progress`.
pub fn filter(
    input: &Path,
    output: &Path,
    stages: &[Stage],
    encoding: Option<Encoding>,
    out: Option<&OutDir>,
    force: bool,
    progress: bool,
) -> Result<Job<FilterSummary>> {
    if stages.is_empty() {
        return Err(JobError::NoStage);
    }
    if same_file(input, output) {
        return Err(JobError::setting(
            "--output",
            output.display(),
            "is the input: write the filtered cloud elsewhere",
        ));
    }
    check_encoding(output, encoding)?;
    let bar = progress_bar(progress, "reading [{bar:40}] {bytes}/{total_bytes} ({eta})");
    let t0 = std::time::Instant::now();
    let got = read(input, &mut |done, total| {
        bar.set_length(total);
        bar.set_position(done);
    })
    .during(|| format!("reading {}", input.display()))?;
    bar.finish_and_clear();
    let read_ms = t0.elapsed().as_secs_f64() * 1e3;
    let (cloud, report) =
        run_chain(&got.cloud, stages).during(|| format!("filtering {}", input.display()))?;
    let filter_ms: f64 = report.iter().map(|r| r.ms).sum();
    let t1 = std::time::Instant::now();
    let encoding = write_cloud(output, &[input.to_path_buf()], &cloud, encoding, force)?;
    let summary = FilterSummary {
        job: "filter",
        success: true,
        input: input.display().to_string(),
        input_format: got.format,
        output: output.display().to_string(),
        output_encoding: encoding.name(),
        points_in: got.cloud.len(),
        non_finite_dropped: got.non_finite_dropped,
        points_out: cloud.len(),
        crs: got.cloud.georef.crs.to_string(),
        origin: got.cloud.origin,
        attributes: got
            .cloud
            .attributes
            .columns()
            .iter()
            .map(|c| c.name.clone())
            .collect(),
        warnings: warnings(&got.cloud),
        stages: report,
        read_ms,
        filter_ms,
        write_ms: t1.elapsed().as_secs_f64() * 1e3,
    };
    let stages_done = summary.stages.clone();
    Job::finish(summary, out, |dir, written| {
        Ok(autoshovel_figures::filter::write(
            dir,
            &stages_done,
            written,
        )?)
    })
}

/// What a user of `cloud` should hear before trusting the output.
fn warnings(cloud: &PointCloud) -> Vec<String> {
    cloud
        .coarser_than_file()
        .into_iter()
        .map(|(axis, held, step)| {
            format!(
                "{axis} is held to {} about the origin, coarser than half the file's step of {}: written back, a coordinate may move by up to {} steps",
                autoshovel_core::config::approx(held),
                autoshovel_core::config::short(step),
                (held / step).ceil()
            )
        })
        .collect()
}

/// Whether `a` and `b` name the same file (`b` need not exist).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}
