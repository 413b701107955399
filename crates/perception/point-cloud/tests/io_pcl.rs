//! PCL reads what we write: our PCD (all three encodings) and PLY (all
//! three) go through PCL 1.13's own converters and come back bit for bit.
//! Needs Debian's `pcl-tools`, so it is ignored by default; the commands
//! and results are in tests/data/README.md. Run with
//! `cargo test -p autoshovel-point-cloud --test io_pcl -- --ignored --nocapture`.

use std::path::Path;
use std::process::Command;

use autoshovel_point_cloud::io::{read, write, Encoding};
use autoshovel_point_cloud::{Point, PointCloud};

fn bits(points: &[Point]) -> Vec<[u32; 3]> {
    points.iter().map(|p| p.map(f32::to_bits)).collect()
}

fn pcl(tool: &str, args: &[&Path], extra: &[&str]) {
    let mut c = Command::new(tool);
    for e in extra.iter().take_while(|e| e.starts_with('-')) {
        c.arg(e);
    }
    c.args(args);
    for e in extra.iter().skip_while(|e| e.starts_with('-')) {
        c.arg(e);
    }
    let out = c
        .output()
        .unwrap_or_else(|e| panic!("{tool}: {e} (apt-get install pcl-tools)"));
    assert!(
        out.status.success(),
        "{tool} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
#[ignore = "needs PCL's command-line tools (Debian pcl-tools)"]
fn pcl_reads_our_pcd_and_ply_files() {
    let dir = std::env::temp_dir().join(format!("autoshovel-io-pcl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut points: Vec<Point> = vec![
        [0.0, -0.0, 1.0],
        [1.5, -2.25, 3.125],
        [123456.79, -0.000123, 42.0],
        [3.4028235e38, -3.4028235e38, 1e-7],
        [1.1754944e-38, 0.1, 0.3],
        [1e-45, -1e-40, 16_777_217.0],
    ];
    let mut s = 1u32;
    for _ in 0..5000 {
        let mut p = [0.0f32; 3];
        for v in &mut p {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            *v = (s >> 8) as f32 / 16_777_216.0 * 200.0 - 100.0;
        }
        points.push(p);
    }
    let cloud = PointCloud::new(points);
    for enc in [
        Encoding::Ascii,
        Encoding::Binary,
        Encoding::BinaryCompressed,
    ] {
        let ours = dir.join(format!("ours_{enc}.pcd"));
        write(&ours, &cloud, enc).unwrap();
        for (mode, name) in [("0", "ascii"), ("1", "binary")] {
            let theirs = dir.join(format!("pcl_{enc}_to_{name}.pcd"));
            pcl(
                "pcl_convert_pcd_ascii_binary",
                &[&ours, &theirs],
                &[mode, "9"],
            );
            let r = read(&theirs, &mut |_, _| {}).unwrap();
            assert_eq!(
                bits(&r.cloud.points),
                bits(&cloud.points),
                "PCD {enc} -> PCL {name}"
            );
            println!(
                "PCD {enc:<17} -> PCL -> {name:<6}: {} points identical",
                r.cloud.len()
            );
        }
    }
    for enc in [Encoding::Ascii, Encoding::Binary, Encoding::BinaryBigEndian] {
        let ours = dir.join(format!("ours_{enc}.ply"));
        write(&ours, &cloud, enc).unwrap();
        let theirs = dir.join(format!("pcl_from_{enc}.pcd"));
        pcl("pcl_ply2pcd", &[&ours, &theirs], &["-format", "1"]);
        let r = read(&theirs, &mut |_, _| {}).unwrap();
        assert_eq!(
            bits(&r.cloud.points),
            bits(&cloud.points),
            "PLY {enc} -> PCL"
        );
        println!(
            "PLY {enc:<17} -> pcl_ply2pcd -> binary PCD: {} points identical",
            r.cloud.len()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
