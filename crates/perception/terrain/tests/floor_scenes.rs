//! The floor estimate on scenes it was not shaped for (issue 13, item 6):
//! other sensor heights, a Livox-like rosette pattern beside the even area
//! pattern, every pile shape, and floor shares from 5 % to 60 % made by
//! thinning the floor or the pile of a generated scan. Expectation: the
//! generator's own roll and pitch within 0.02°, and `NoFloor` for a scan
//! with the floor taken out.

use autoshovel_point_cloud::PointCloud;
use autoshovel_terrain::{
    estimate_tilt, generate_pile, level, PileParams, PileShape, ScanPattern, SurfaceError,
    TiltParams,
};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Largest tilt error accepted (deg).
const TOLERANCE_DEG: f64 = 0.02;

/// Which points of a generated scan are floor: levelled with the true angles,
/// within 4σ of the floor height and in front of the toe.
fn floor_mask(scan: &PointCloud, p: &PileParams) -> Vec<bool> {
    let flat = level(scan, p.roll_rad, p.pitch_rad);
    let floor = -p.scale * p.sensor_height_m;
    let band = 4.0 * p.scale * p.range_noise_m + 1e-6;
    flat.points
        .iter()
        .map(|q| {
            let (x, y, z) = (f64::from(q[0]), f64::from(q[1]), f64::from(q[2]));
            (z - floor).abs() <= band && x < p.toe_x_m(y) - 0.05 * p.face_run_m()
        })
        .collect()
}

/// The scan with floor points (or other points) dropped at random so that
/// the floor is `share` of what is left.
fn with_floor_share(scan: &PointCloud, p: &PileParams, share: f64, seed: u64) -> (PointCloud, f64) {
    let mask = floor_mask(scan, p);
    let mut floor: Vec<usize> = (0..scan.len()).filter(|&i| mask[i]).collect();
    let mut rest: Vec<usize> = (0..scan.len()).filter(|&i| !mask[i]).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    floor.shuffle(&mut rng);
    rest.shuffle(&mut rng);
    let natural = floor.len() as f64 / scan.len() as f64;
    if share < natural {
        let keep = (share * rest.len() as f64 / (1.0 - share)).round() as usize;
        floor.truncate(keep);
    } else {
        let keep = (floor.len() as f64 * (1.0 - share) / share).round() as usize;
        rest.truncate(keep);
    }
    let mut idx: Vec<usize> = floor.iter().chain(&rest).copied().collect();
    idx.sort_unstable();
    let got = floor.len() as f64 / idx.len() as f64;
    (
        PointCloud::new(idx.into_iter().map(|i| scan.points[i]).collect()),
        got,
    )
}

fn error_deg(scan: &PointCloud, p: &PileParams) -> Result<(f64, f64), SurfaceError> {
    let est = estimate_tilt(scan, &TiltParams::for_scale(p.scale))?;
    Ok((
        (est.roll_rad - p.roll_rad).to_degrees(),
        (est.pitch_rad - p.pitch_rad).to_degrees(),
    ))
}

#[test]
fn tilt_within_0_02_deg_for_any_floor_share_from_5_percent() {
    let mut worst: f64 = 0.0;
    let mut rows = Vec::new();
    let cases = [
        (ScanPattern::Area, 12.0, PileShape::Typical, 3.0, -2.0),
        (ScanPattern::Rosette, 11.0, PileShape::Typical, -1.5, 4.0),
        (ScanPattern::Rosette, 6.0, PileShape::Concave, 2.0, 1.0),
        (
            ScanPattern::Area,
            15.0,
            PileShape::ConvexConcave,
            -4.0,
            -3.0,
        ),
        (ScanPattern::Rosette, 15.0, PileShape::Convex, 0.5, -6.0),
        (ScanPattern::Area, 4.0, PileShape::Concave, 5.0, 2.5),
    ];
    for (k, (pattern, height, shape, roll, pitch)) in cases.into_iter().enumerate() {
        let p = PileParams {
            pattern,
            shape,
            sensor_height_m: height,
            roll_rad: f64::to_radians(roll),
            pitch_rad: f64::to_radians(pitch),
            points: 200_000,
            seed: 10 + k as u64,
            ..PileParams::default()
        };
        let scan = generate_pile(&p).unwrap();
        for share in [0.05, 0.1, 0.25, 0.6] {
            let (thin, got) = with_floor_share(&scan, &p, share, k as u64);
            let (dr, dp) = error_deg(&thin, &p)
                .unwrap_or_else(|e| panic!("{pattern} h {height} {shape} floor {got:.3}: {e}"));
            rows.push(format!(
                "{pattern:8} h {height:4} {shape:15} floor {got:.3} ({} pts): roll {dr:+.4}° pitch {dp:+.4}°",
                thin.len()
            ));
            worst = worst.max(dr.abs()).max(dp.abs());
        }
    }
    eprintln!("{}", rows.join("\n"));
    assert!(
        worst < TOLERANCE_DEG,
        "worst {worst:.4}°:\n{}",
        rows.join("\n")
    );
}

/// Sixteen seeds of the hardest case above (a rosette from 15 m, 5 % floor):
/// the spread of the estimate, against the least-squares plane of the true
/// floor points. Slow in a debug build: `cargo test --release -p
/// autoshovel-terrain --test floor_scenes -- --ignored --nocapture`.
#[test]
#[ignore]
fn seed_spread_at_5_percent_floor() {
    let mut worst: f64 = 0.0;
    for seed in 0..16 {
        let p = PileParams {
            pattern: ScanPattern::Rosette,
            shape: PileShape::Convex,
            sensor_height_m: 15.0,
            roll_rad: f64::to_radians(0.5),
            pitch_rad: f64::to_radians(-6.0),
            points: 200_000,
            seed,
            ..PileParams::default()
        };
        let scan = generate_pile(&p).unwrap();
        let (thin, got) = with_floor_share(&scan, &p, 0.05, seed);
        let (dr, dp) = error_deg(&thin, &p).unwrap();
        let mask = floor_mask(&thin, &p);
        let pts: Vec<[f64; 3]> = thin.points.iter().map(|q| q.map(f64::from)).collect();
        let idx: Vec<usize> = (0..pts.len()).filter(|&i| mask[i]).collect();
        let truth = autoshovel_terrain::least_squares_plane(&pts, &idx).unwrap();
        let (r0, p0) = autoshovel_terrain::angles_from_normal(truth.normal).unwrap();
        eprintln!(
            "seed {seed:2} floor {got:.3}: roll {dr:+.4}° pitch {dp:+.4}° (true floor points alone: {:+.4}° {:+.4}°)",
            (r0 - p.roll_rad).to_degrees(),
            (p0 - p.pitch_rad).to_degrees()
        );
        worst = worst.max(dr.abs()).max(dp.abs());
    }
    assert!(worst < TOLERANCE_DEG, "worst {worst:.4}°");
}

#[test]
fn a_scan_without_floor_is_a_clear_error() {
    for (k, (pattern, shape)) in [
        (ScanPattern::Area, PileShape::Typical),
        (ScanPattern::Rosette, PileShape::Concave),
        (ScanPattern::Area, PileShape::ConvexConcave),
        (ScanPattern::Rosette, PileShape::Convex),
    ]
    .into_iter()
    .enumerate()
    {
        let p = PileParams {
            pattern,
            shape,
            points: 40_000,
            seed: 30 + k as u64,
            ..PileParams::default()
        };
        let scan = generate_pile(&p).unwrap();
        // Everything lower than 0.3 m above the floor goes: floor, toe fillet.
        let flat = level(&scan, p.roll_rad, p.pitch_rad);
        let floor = -p.sensor_height_m;
        let kept: Vec<[f32; 3]> = scan
            .points
            .iter()
            .zip(&flat.points)
            .filter(|(_, q)| f64::from(q[2]) > floor + 0.3)
            .map(|(s, _)| *s)
            .collect();
        let pile_only = PointCloud::new(kept);
        let err = estimate_tilt(&pile_only, &TiltParams::default()).unwrap_err();
        assert!(
            matches!(err, SurfaceError::NoFloor { .. }),
            "{pattern} {shape}: {err}"
        );
        let msg = err.to_string();
        assert!(
            msg.contains("mode = \"given\"") && msg.contains("min_floor_share"),
            "{msg}"
        );
    }
}

/// The paper's 1:30 model (a 0.33 m face, 0.67 mm noise) with a small floor:
/// the thresholds scale with it.
#[test]
fn the_paper_model_levels_too() {
    let p = PileParams {
        pattern: ScanPattern::Rosette,
        points: 100_000,
        roll_rad: f64::to_radians(-2.5),
        pitch_rad: f64::to_radians(3.5),
        seed: 41,
        ..PileParams::paper_model()
    };
    let scan = generate_pile(&p).unwrap();
    let (thin, _) = with_floor_share(&scan, &p, 0.08, 41);
    let (dr, dp) = error_deg(&thin, &p).unwrap();
    assert!(dr.abs().max(dp.abs()) < TOLERANCE_DEG, "{dr} {dp}");
}

/// `perceive` reports the floor it levelled by: its share of a scan whose
/// floor share is known.
#[test]
fn perceive_reports_the_floor_share() {
    use autoshovel_terrain::perceive::{perceive, PerceiveSummary, PerceptionParams};
    let p = PileParams {
        points: 60_000,
        seed: 50,
        ..PileParams::default()
    };
    let scan = generate_pile(&p).unwrap();
    let (thin, share) = with_floor_share(&scan, &p, 0.12, 50);
    let got = perceive(&thin, &PerceptionParams::default()).unwrap();
    let s = PerceiveSummary::new(
        std::path::Path::new("thin.pcd"),
        &PerceptionParams::default(),
        &got,
    );
    // The inlier band (5 cm) also holds the toe fillet's foot and a few
    // hovering outliers: a little more than the floor itself.
    assert!(
        s.floor_share >= share && s.floor_share < share + 0.02,
        "{} vs {share}",
        s.floor_share
    );
    assert!(
        s.floor_rms_m > 0.0 && s.floor_rms_m < 0.03,
        "{}",
        s.floor_rms_m
    );
}
