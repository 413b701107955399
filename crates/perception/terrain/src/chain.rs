//! Filter chains for any cloud, as PCL's command-line tools and PDAL
//! pipelines run them: one or more stages in the order given, each with
//! PCL's semantics ([`autoshovel_point_cloud::filter`]), counted and timed. Unlike
//! [`crate::perceive::perceive`], nothing here assumes a muck pile: no
//! floor to find, no surface to fit.
//!
//! A stage is written as on the command line of `autoshovel filter`
//! (`--voxel 0.05`, `--statistical 50,1.0`, `--radius 0.05,3`,
//! `--pass z:-10.5:-3`, `--range Classification[2:2]`, `--level 3,-2`):
//!
//! ```
//! use autoshovel_terrain::chain::{run_chain, Stage, StageKind};
//! use autoshovel_terrain::{generate_pile, PileParams};
//!
//! let scan = generate_pile(&PileParams { points: 20_000, ..PileParams::default() }).unwrap();
//! let stages = [
//!     Stage::parse(StageKind::Level, "3,-2").unwrap(),
//!     Stage::parse(StageKind::Pass, "z:-11.9:inf").unwrap(),
//!     Stage::parse(StageKind::Voxel, "0.2").unwrap(),
//! ];
//! let (out, report) = run_chain(&scan, &stages).unwrap();
//! assert_eq!(report.len(), 3);
//! assert_eq!(report[2].points_out, out.len());
//! assert!(out.len() < report[1].points_out);
//! ```

use std::time::Instant;

use autoshovel_point_cloud::filter::{
    pass_through_indices, radius_outlier_removal_indices, range_indices,
    statistical_outlier_removal_indices, voxel_grid, voxel_grid_nearest, Axis, OutlierSides,
    PassThroughParams, RadiusOutlierParams, RangeLimits, StatisticalOutlierParams, VoxelGridParams,
};
use autoshovel_point_cloud::{CloudError, PointCloud};
use serde::Serialize;

use autoshovel_core::config::{approx, short};

use crate::calibrate::level;
use crate::error::{Result, SurfaceError};
use crate::perceive::MAX_NEIGHBOUR_VISITS;

/// The kinds of stage, by their command-line flag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageKind {
    /// `--voxel LEAF` or `--voxel LX,LY,LZ` (m): PCL's VoxelGrid ([RS eq. 17]–[RS eq. 18]).
    Voxel,
    /// `--statistical K,ALPHA[,both]`: PCL's StatisticalOutlierRemoval
    /// ([RS eq. 14]–[RS eq. 16]); `both` for the two-sided rule as printed.
    Statistical,
    /// `--radius R,MIN`: PCL's RadiusOutlierRemoval ([RS eq. 13]).
    Radius,
    /// `--pass AXIS:MIN:MAX[:outside]` (m): PCL's PassThrough, keeping
    /// MIN ≤ v ≤ MAX (or the rest with `outside`); `-inf`/`inf` for no limit.
    Pass,
    /// `--range LIMITS`: PDAL's range filter, e.g. `Classification[2:2]`
    /// (a classified survey's ground) or `Z[0:100],Intensity(50:]`.
    Range,
    /// `--level ROLL,PITCH` (deg): rotate the sensor frame level
    /// ([RS eq. 11]–[RS eq. 12]).
    Level,
}

impl StageKind {
    /// The flag's name, without dashes.
    pub fn flag(self) -> &'static str {
        match self {
            StageKind::Voxel => "voxel",
            StageKind::Statistical => "statistical",
            StageKind::Radius => "radius",
            StageKind::Pass => "pass",
            StageKind::Range => "range",
            StageKind::Level => "level",
        }
    }

    /// What a value of this flag looks like.
    pub fn syntax(self) -> &'static str {
        match self {
            StageKind::Voxel => "LEAF or LX,LY,LZ in metres, e.g. 0.05",
            StageKind::Statistical => "K,ALPHA or K,ALPHA,both, e.g. 50,1.0",
            StageKind::Radius => "RADIUS,MIN_NEIGHBOURS, e.g. 0.05,3",
            StageKind::Pass => "AXIS:MIN:MAX or AXIS:MIN:MAX:outside, e.g. z:-10.5:-3",
            StageKind::Range => {
                "PDAL's ranges, Dimension[MIN:MAX] (! negates, ( ) open ends), comma-separated, e.g. Classification[2:2]"
            }
            StageKind::Level => "ROLL,PITCH in degrees, e.g. 3,-2",
        }
    }
}

/// One stage of a chain.
#[derive(Debug, Clone, PartialEq)]
pub enum Stage {
    /// Voxel-grid down-sampling to centroids.
    Voxel(VoxelGridParams),
    /// Statistical outlier removal.
    Statistical(StatisticalOutlierParams),
    /// Radius outlier removal.
    Radius(RadiusOutlierParams),
    /// Pass-through on one axis.
    Pass(PassThroughParams),
    /// Selection by dimension ranges (PDAL's `filters.range`).
    Range(RangeLimits),
    /// Levelling by roll and pitch, in degrees as given.
    Level {
        /// Sensor roll α (deg).
        roll_deg: f64,
        /// Sensor pitch β (deg).
        pitch_deg: f64,
    },
}

/// What one stage did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageReport {
    /// The flag (`voxel`, `statistical`, `radius`, `pass`, `level`).
    pub stage: &'static str,
    /// Its value as given.
    pub spec: String,
    /// Points in.
    pub points_in: usize,
    /// Points out (kept).
    pub points_out: usize,
    /// Wall time (ms).
    pub ms: f64,
}

impl Stage {
    /// Parse the value `spec` of the flag `kind` (see [`StageKind::syntax`]);
    /// a bad value is [`SurfaceError::BadStage`] naming the flag and the part
    /// at fault. Ranges are checked by the filter when it runs.
    pub fn parse(kind: StageKind, spec: &str) -> Result<Self> {
        let bad = |problem: String| SurfaceError::BadStage {
            flag: kind.flag(),
            spec: spec.to_string(),
            problem,
            syntax: kind.syntax(),
        };
        let number = |part: &str, what: &str| -> Result<f64> {
            let t = part.trim();
            match t {
                "inf" | "+inf" => Ok(f64::INFINITY),
                "-inf" => Ok(f64::NEG_INFINITY),
                _ => t
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(format!("{what} '{t}' is not a number"))),
            }
        };
        let finite = |part: &str, what: &str| -> Result<f64> {
            let v = number(part, what)?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(bad(format!("{what} must be finite")))
            }
        };
        let count = |part: &str, what: &str| -> Result<usize> {
            let t = part.trim();
            t.parse::<usize>()
                .map_err(|_| bad(format!("{what} '{t}' is not a whole number")))
        };
        let parts: Vec<&str> = match kind {
            StageKind::Pass => spec.split(':').collect(),
            _ => spec.split(',').collect(),
        };
        let arity = |allowed: &[usize]| -> Result<()> {
            if allowed.contains(&parts.len()) {
                Ok(())
            } else {
                Err(bad(format!("{} parts", parts.len())))
            }
        };
        Ok(match kind {
            StageKind::Voxel => {
                arity(&[1, 3])?;
                let leaf = if parts.len() == 1 {
                    [finite(parts[0], "leaf")?; 3]
                } else {
                    [
                        finite(parts[0], "leaf x")?,
                        finite(parts[1], "leaf y")?,
                        finite(parts[2], "leaf z")?,
                    ]
                };
                Stage::Voxel(VoxelGridParams { leaf_m: leaf })
            }
            StageKind::Statistical => {
                arity(&[2, 3])?;
                let sides = match parts.get(2).map(|s| s.trim()) {
                    None | Some("above") => OutlierSides::Above,
                    Some("both") => OutlierSides::Both,
                    Some(other) => {
                        return Err(bad(format!("'{other}' is neither 'above' nor 'both'")))
                    }
                };
                Stage::Statistical(StatisticalOutlierParams {
                    mean_k: count(parts[0], "K")?,
                    std_mul: finite(parts[1], "ALPHA")?,
                    sides,
                })
            }
            StageKind::Radius => {
                arity(&[2])?;
                Stage::Radius(RadiusOutlierParams {
                    radius_m: finite(parts[0], "radius")?,
                    min_neighbors: count(parts[1], "MIN_NEIGHBOURS")?,
                })
            }
            StageKind::Pass => {
                arity(&[3, 4])?;
                let axis = match parts[0].trim() {
                    "x" | "X" => Axis::X,
                    "y" | "Y" => Axis::Y,
                    "z" | "Z" => Axis::Z,
                    other => return Err(bad(format!("axis '{other}' is not x, y or z"))),
                };
                let keep_inside = match parts.get(3).map(|s| s.trim()) {
                    None | Some("inside") => true,
                    Some("outside") => false,
                    Some(other) => {
                        return Err(bad(format!("'{other}' is neither 'inside' nor 'outside'")))
                    }
                };
                Stage::Pass(PassThroughParams {
                    axis,
                    min_m: number(parts[1], "MIN")?,
                    max_m: number(parts[2], "MAX")?,
                    keep_inside,
                })
            }
            StageKind::Range => Stage::Range(RangeLimits::parse(spec).map_err(bad)?),
            StageKind::Level => {
                arity(&[2])?;
                Stage::Level {
                    roll_deg: finite(parts[0], "roll")?,
                    pitch_deg: finite(parts[1], "pitch")?,
                }
            }
        })
    }

    /// The kind of this stage.
    pub fn kind(&self) -> StageKind {
        match self {
            Stage::Voxel(_) => StageKind::Voxel,
            Stage::Statistical(_) => StageKind::Statistical,
            Stage::Radius(_) => StageKind::Radius,
            Stage::Pass(_) => StageKind::Pass,
            Stage::Range(_) => StageKind::Range,
            Stage::Level { .. } => StageKind::Level,
        }
    }

    /// Run the stage on `cloud`, after [`Stage::check_work`]; a filter's
    /// refusal is [`SurfaceError::StageFailed`] in the flag's own terms.
    pub fn apply(&self, cloud: &PointCloud) -> Result<PointCloud> {
        self.check_units(cloud)?;
        let scaled = self.in_file_units(cloud);
        scaled.check_work_as(cloud, self)?;
        scaled.run(cloud, self)
    }

    /// Refuses a stage that measures in metres on a cloud whose x and y
    /// are degrees (a geographic CRS such as EPSG:4326): a voxel, a radius,
    /// a neighbour distance or a rotation would mix degrees with metres.
    fn check_units(&self, cloud: &PointCloud) -> Result<()> {
        let crs = &cloud.georef.crs;
        if !crs.is_geographic() || matches!(self, Stage::Pass(_) | Stage::Range(_)) {
            return Ok(());
        }
        Err(SurfaceError::StageFailed {
            flag: self.kind().flag(),
            spec: self.spec(),
            problem: format!(
                "the cloud's x and y are degrees of longitude and latitude ({crs}), not metres: \
                 project it first (e.g. `pdal translate IN OUT reprojection --filters.reprojection.out_srs=EPSG:326NN` \
                 for its UTM zone); only --pass and --range work on degrees"
            ),
        })
    }

    /// The stage with its lengths (a leaf, a radius), given in metres,
    /// in the cloud's own unit (a foot or a US survey foot where its CRS
    /// says so); coordinates (--pass) are the file's own already.
    fn in_file_units(&self, cloud: &PointCloud) -> Stage {
        let crs = &cloud.georef.crs;
        let Some(unit_m) = crs.unit.metres() else {
            return self.clone();
        };
        let z_m = crs.z_unit().metres().unwrap_or(unit_m);
        if unit_m == 1.0 && z_m == 1.0 {
            return self.clone();
        }
        match self {
            // A leaf's z in z's own unit (a compound CRS's vertical one).
            Stage::Voxel(p) => Stage::Voxel(VoxelGridParams {
                leaf_m: [
                    p.leaf_m[0] / unit_m,
                    p.leaf_m[1] / unit_m,
                    p.leaf_m[2] / z_m,
                ],
            }),
            Stage::Radius(p) => Stage::Radius(RadiusOutlierParams {
                radius_m: p.radius_m / unit_m,
                ..*p
            }),
            other => other.clone(),
        }
    }

    /// Runs the stage, its errors naming `shown` (the value as given).
    fn run(&self, cloud: &PointCloud, shown: &Stage) -> Result<PointCloud> {
        let flag = |e| shown.flag_error(e);
        // Removal keeps the same rows of every column; a voxel's centroid
        // takes the attributes of the point nearest it.
        let rows = match self {
            // The nearest points' sort only where there are attributes
            // to take from them.
            Stage::Voxel(p) if cloud.attributes.is_empty() => {
                let centroids = voxel_grid(cloud, p).map_err(flag)?;
                return Ok(cloud.derived(centroids.points, None));
            }
            Stage::Voxel(p) => {
                let (centroids, nearest) = voxel_grid_nearest(cloud, p).map_err(flag)?;
                return Ok(cloud.derived(centroids.points, Some(&nearest)));
            }
            Stage::Statistical(p) => statistical_outlier_removal_indices(cloud, p),
            Stage::Radius(p) => radius_outlier_removal_indices(cloud, p),
            Stage::Range(limits) => range_indices(cloud, limits),
            Stage::Pass(p) => {
                // MIN and MAX are in the file's frame, the points about
                // the cloud's origin.
                let o = cloud.origin[p.axis as usize];
                let relative = PassThroughParams {
                    min_m: p.min_m - o,
                    max_m: p.max_m - o,
                    ..*p
                };
                pass_through_indices(cloud, &relative)
            }
            Stage::Level {
                roll_deg,
                pitch_deg,
            } => {
                // About the origin: the sensor for a scan in its own frame,
                // the middle of the data for a survey (the LAS reader's
                // origin).
                let (roll, pitch) = (roll_deg.to_radians(), pitch_deg.to_radians());
                let turned = level(cloud, roll, pitch);
                let mut out = cloud.clone();
                out.points = turned.points;
                // The sensor's pose turns with its cloud.
                let r = crate::calibrate::level_from_sensor(roll, pitch);
                let rows = std::array::from_fn(|i| std::array::from_fn(|k| r[(i, k)]));
                out.georef.viewpoint = cloud.georef.viewpoint.map(|v| v.turned(rows, cloud.origin));
                return Ok(out);
            }
        };
        Ok(cloud.select(&rows.map_err(flag)?))
    }

    /// Refuses, before any work, a value whose neighbour searches would
    /// cost more than [`MAX_NEIGHBOUR_VISITS`] per point on `cloud` (the
    /// ceiling `perceive` applies to its own filters): K nearest
    /// neighbours, or the neighbours within the radius of a surface at the
    /// cloud's own spacing (its largest face's area over its points).
    pub fn check_work(&self, cloud: &PointCloud) -> Result<()> {
        self.check_work_as(cloud, self)
    }

    /// [`Stage::check_work`], the refusal naming `shown`.
    fn check_work_as(&self, cloud: &PointCloud, shown: &Stage) -> Result<()> {
        let n = cloud.len() as f64;
        let unit = match cloud.georef.crs.unit {
            autoshovel_point_cloud::Unit::Foot => "ft",
            autoshovel_point_cloud::Unit::UsSurveyFoot => "US ft",
            _ => "m",
        };
        let (visits, how) = match self {
            Stage::Statistical(p) => {
                let k = (p.mean_k as f64).min(n);
                (k, format!("{} nearest neighbours a point", approx(k)))
            }
            Stage::Radius(p) => {
                let Some(spacing) = own_spacing(cloud) else {
                    return Ok(());
                };
                let k = (std::f64::consts::PI * (p.radius_m / spacing).powi(2)).min(n);
                (
                    k,
                    format!(
                        "about {} neighbours within {} {unit} of a point at this cloud's spacing of {} {unit}",
                        approx(k),
                        approx(p.radius_m),
                        approx(spacing)
                    ),
                )
            }
            _ => return Ok(()),
        };
        if visits <= MAX_NEIGHBOUR_VISITS {
            return Ok(());
        }
        Err(SurfaceError::StageTooMuchWork {
            flag: shown.kind().flag(),
            spec: shown.spec(),
            estimate: format!(
                "{how}, {} neighbour visits for the {n} points",
                approx(visits * n)
            ),
            ceiling: format!("{} a point", approx(MAX_NEIGHBOUR_VISITS)),
        })
    }

    /// A filter's error in the flag's terms: its parameter names become
    /// the parts of the flag's value, its hint the change to the value.
    fn flag_error(&self, e: CloudError) -> SurfaceError {
        // The filters' parameter names and the flag's parts for them.
        const PARTS: [(&str, &str); 8] = [
            ("mean_k", "K"),
            ("std_mul", "ALPHA"),
            ("radius_m", "RADIUS"),
            ("min_neighbors", "MIN_NEIGHBOURS"),
            ("min_m", "MIN"),
            ("max_m", "MAX"),
            ("keep_inside", "':outside'"),
            ("leaf_m", "LEAF"),
        ];
        let problem = match e {
            CloudError::Emptied { input, .. } => format!(
                "removed every point ({input} in, 0 out): {}",
                match self.kind() {
                    StageKind::Pass => "widen MIN:MAX, check the axis, or add :outside",
                    StageKind::Statistical => "raise ALPHA",
                    StageKind::Radius => "lower MIN_NEIGHBOURS or raise RADIUS",
                    StageKind::Range => "check the ranges against the file's values",
                    _ => "check the previous stage",
                }
            ),
            CloudError::BadParameter { what, .. } => {
                let axes = match self {
                    Stage::Voxel(p) if p.leaf_m[0] == p.leaf_m[1] && p.leaf_m[1] == p.leaf_m[2] => {
                        ["LEAF"; 3]
                    }
                    _ => ["LX", "LY", "LZ"],
                };
                let what = (0..3).fold(what, |w, a| w.replace(&format!("leaf_m[{a}]"), axes[a]));
                PARTS.iter().fold(what, |w, (from, to)| w.replace(from, to))
            }
            other => {
                return SurfaceError::Filter {
                    stage: self.kind().flag(),
                    source: other,
                }
            }
        };
        SurfaceError::StageFailed {
            flag: self.kind().flag(),
            spec: self.spec(),
            problem,
        }
    }
}

/// A surface's point spacing (m): the square root of the largest face of
/// the cloud's bounding box over its points (a wall or a flat pile alike);
/// `None` for fewer than two points or no extent.
fn own_spacing(cloud: &PointCloud) -> Option<f64> {
    let (lo, hi) = cloud.bounds()?;
    let e = [0, 1, 2].map(|a| f64::from(hi[a]) - f64::from(lo[a]));
    let face = (e[0] * e[1]).max(e[0] * e[2]).max(e[1] * e[2]);
    let s = (face / cloud.len() as f64).sqrt();
    (cloud.len() > 1 && s.is_finite() && s > 0.0).then_some(s)
}

/// Run `stages` on `cloud` in order: the result and what each stage did
/// (its spec written back from the parsed values).
pub fn run_chain(cloud: &PointCloud, stages: &[Stage]) -> Result<(PointCloud, Vec<StageReport>)> {
    let mut current = cloud.clone();
    let mut report = Vec::with_capacity(stages.len());
    for stage in stages {
        let t0 = Instant::now();
        let next = stage.apply(&current)?;
        report.push(StageReport {
            stage: stage.kind().flag(),
            spec: stage.spec(),
            points_in: current.len(),
            points_out: next.len(),
            ms: t0.elapsed().as_secs_f64() * 1e3,
        });
        current = next;
    }
    Ok((current, report))
}

impl Stage {
    /// The stage written as its flag's value (parses back to the same stage).
    pub fn spec(&self) -> String {
        match self {
            Stage::Voxel(p) if p.leaf_m[0] == p.leaf_m[1] && p.leaf_m[1] == p.leaf_m[2] => {
                short(p.leaf_m[0])
            }
            Stage::Voxel(p) => format!(
                "{},{},{}",
                short(p.leaf_m[0]),
                short(p.leaf_m[1]),
                short(p.leaf_m[2])
            ),
            Stage::Statistical(p) => match p.sides {
                OutlierSides::Above => format!("{},{}", p.mean_k, short(p.std_mul)),
                OutlierSides::Both => format!("{},{},both", p.mean_k, short(p.std_mul)),
            },
            Stage::Radius(p) => format!("{},{}", short(p.radius_m), p.min_neighbors),
            Stage::Pass(p) => {
                let axis = match p.axis {
                    Axis::X => "x",
                    Axis::Y => "y",
                    Axis::Z => "z",
                };
                let side = if p.keep_inside { "" } else { ":outside" };
                format!("{axis}:{}:{}{side}", short(p.min_m), short(p.max_m))
            }
            Stage::Level {
                roll_deg,
                pitch_deg,
            } => format!("{},{}", short(*roll_deg), short(*pitch_deg)),
            Stage::Range(limits) => limits.to_string(),
        }
    }
}

/// The summary of `autoshovel filter` (SPEC §6: `job`, `success`, then the
/// chain's own fields).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FilterSummary {
    /// Always "filter".
    pub job: &'static str,
    /// Always true (a failed chain is an error, not a summary).
    pub success: bool,
    /// The cloud read.
    pub input: String,
    /// Its format, as the reader names it.
    pub input_format: &'static str,
    /// The cloud written.
    pub output: String,
    /// Its encoding.
    pub output_encoding: &'static str,
    /// Finite points read.
    pub points_in: usize,
    /// Points dropped on reading for a non-finite coordinate.
    pub non_finite_dropped: usize,
    /// Points written.
    pub points_out: usize,
    /// The coordinate system the input states (`EPSG:26910 (metre)`,
    /// `none stated`), written back with the output.
    pub crs: String,
    /// The f64 origin the points were held about (the file's frame).
    pub origin: [f64; 3],
    /// The attribute columns carried through, as PDAL names them.
    pub attributes: Vec<String>,
    /// What the user should know: coordinates the f32 points cannot hold
    /// to the file's own step, and the like.
    pub warnings: Vec<String>,
    /// Each stage, in the order run.
    pub stages: Vec<StageReport>,
    /// Reading (ms).
    pub read_ms: f64,
    /// The stages together (ms).
    pub filter_ms: f64,
    /// Writing (ms).
    pub write_ms: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use autoshovel_point_cloud::filter::{
        pass_through_indices, radius_outlier_removal_indices, statistical_outlier_removal_indices,
    };

    #[test]
    fn a_pcd_viewpoint_is_kept_and_turned_with_the_cloud() {
        // PCL's VIEWPOINT, through a file: a quarter turn about z at
        // (1.5, 2, 3); a pass keeps it, levelling by a pitch of 90° turns
        // it as the points turn (T(0, β) of [RS eq. 11]: (x, y, z) →
        // (−z, y, x)).
        let dir = std::env::temp_dir().join(format!("autoshovel-vp-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("vp.pcd");
        std::fs::write(
            &path,
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n\
             VIEWPOINT 1.5 2 3 0.5 0.5 0.5 0.5\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n",
        )
        .unwrap();
        let read = |p: &std::path::Path| {
            autoshovel_point_cloud::io::read(p, &mut |_, _| {})
                .unwrap()
                .cloud
        };
        let c = read(&path);
        let vp = c.georef.viewpoint.expect("the file's viewpoint");
        assert_eq!(vp.position, [1.5, 2.0, 3.0]);
        let (kept, _) =
            run_chain(&c, &[Stage::parse(StageKind::Pass, "z:-inf:inf").unwrap()]).unwrap();
        let out = dir.join("out.pcd");
        autoshovel_point_cloud::io::write(&out, &kept, autoshovel_point_cloud::io::Encoding::Ascii)
            .unwrap();
        assert_eq!(
            read(&out).georef.viewpoint,
            Some(vp),
            "written back as read"
        );
        let (turned, _) =
            run_chain(&c, &[Stage::parse(StageKind::Level, "0,90").unwrap()]).unwrap();
        let t = turned.georef.viewpoint.unwrap();
        let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9);
        assert!(close(&t.position, &[-3.0, 2.0, 1.5]), "{t:?}");
        // The first point turned the same way.
        let p = turned.points[0];
        assert!(
            close(
                &[f64::from(p[0]), f64::from(p[1]), f64::from(p[2])],
                &[-3.0, 2.0, 1.0]
            ),
            "{p:?}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    fn cloud() -> PointCloud {
        // A jittered 40 × 40 grid with a few far points.
        let mut pts: Vec<[f32; 3]> = (0..1600)
            .map(|i| {
                let (x, y) = ((i % 40) as f32 * 0.1, (i / 40) as f32 * 0.1);
                [x, y, 0.01 * ((i * 7919) % 13) as f32]
            })
            .collect();
        pts.extend([[10.0, 10.0, 5.0], [-8.0, 3.0, 2.0], [2.0, -9.0, -4.0]]);
        PointCloud::new(pts)
    }

    #[test]
    fn every_spec_parses_back_to_its_stage() {
        for (kind, spec) in [
            (StageKind::Voxel, "0.05"),
            (StageKind::Voxel, "0.1,0.2,0.3"),
            (StageKind::Statistical, "50,1"),
            (StageKind::Statistical, "8,0.5,both"),
            (StageKind::Radius, "0.05,3"),
            (StageKind::Pass, "z:-10.5:-3"),
            (StageKind::Pass, "x:-inf:2:outside"),
            (StageKind::Level, "3,-2"),
        ] {
            let s = Stage::parse(kind, spec).unwrap();
            assert_eq!(Stage::parse(kind, &s.spec()).unwrap(), s, "{spec}");
        }
    }

    #[test]
    fn bad_values_name_the_flag_and_the_part() {
        for (kind, spec, needle) in [
            (StageKind::Voxel, "abc", "leaf 'abc'"),
            (StageKind::Voxel, "0.1,0.2", "2 parts"),
            (StageKind::Statistical, "50", "1 parts"),
            (StageKind::Statistical, "x,1", "K 'x'"),
            (StageKind::Statistical, "50,1,left", "'left'"),
            (StageKind::Radius, "0.05,-3", "MIN_NEIGHBOURS '-3'"),
            (StageKind::Pass, "w:0:1", "axis 'w'"),
            (StageKind::Pass, "z:0:NaN", "MAX 'NaN'"),
            (StageKind::Level, "3", "1 parts"),
            (StageKind::Level, "inf,0", "roll must be finite"),
        ] {
            let e = Stage::parse(kind, spec).unwrap_err().to_string();
            assert!(
                e.contains(&format!("--{}", kind.flag())) && e.contains(needle),
                "{spec}: {e}"
            );
        }
        // Ranges are the filter's: a zero leaf is refused when it runs.
        let s = Stage::parse(StageKind::Voxel, "0").unwrap();
        let e = run_chain(&cloud(), &[s]).unwrap_err().to_string();
        assert!(e.contains("voxel"), "{e}");
    }

    #[test]
    fn a_chain_is_its_filters_applied_in_order() {
        let c = cloud();
        let stages = [
            Stage::parse(StageKind::Pass, "z:-1:1").unwrap(),
            Stage::parse(StageKind::Radius, "0.15,3").unwrap(),
            Stage::parse(StageKind::Statistical, "8,1").unwrap(),
        ];
        let (out, report) = run_chain(&c, &stages).unwrap();
        // The same by hand, through the filters' own index functions.
        let Stage::Pass(p) = stages[0] else {
            unreachable!()
        };
        let Stage::Radius(r) = stages[1] else {
            unreachable!()
        };
        let Stage::Statistical(st) = stages[2] else {
            unreachable!()
        };
        let pick = |c: &PointCloud, idx: Vec<usize>| {
            PointCloud::new(idx.into_iter().map(|i| c.points[i]).collect())
        };
        let a = pick(&c, pass_through_indices(&c, &p).unwrap());
        let b = pick(&a, radius_outlier_removal_indices(&a, &r).unwrap());
        let d = pick(&b, statistical_outlier_removal_indices(&b, &st).unwrap());
        assert_eq!(out.points, d.points);
        assert_eq!(
            report
                .iter()
                .map(|r| (r.points_in, r.points_out))
                .collect::<Vec<_>>(),
            vec![(c.len(), a.len()), (a.len(), b.len()), (b.len(), d.len())]
        );
        // The three far points, all beyond z ±1, went at the first stage.
        assert_eq!(a.len(), c.len() - 3);
    }
}
