//! Damaged files: every reader, on truncated files and flipped bytes,
//! returns Ok or a Format/Io error: never a panic, never a hang.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use autoshovel_point_cloud::io::{
    read_from_bytes, write_with, Encoding, Format, LasVersion, WriteOptions,
};
use autoshovel_point_cloud::{CloudError, PointCloud};
use proptest::prelude::*;

/// (name, format, bytes, every strict truncation must fail)
type Sample = (String, Format, Vec<u8>, bool);

fn samples() -> Vec<Sample> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static CALL: AtomicU64 = AtomicU64::new(0);
    let dir = std::env::temp_dir().join(format!(
        "autoshovel-io-damaged-{}-{}",
        std::process::id(),
        CALL.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let cloud = PointCloud::new(
        (0..40)
            .map(|i| {
                let t = i as f32;
                [t * 0.37 - 3.0, (t * 0.9).cos() * 20.0, t * t * 1e-3]
            })
            .collect(),
    );
    let mut out = Vec::new();
    let written: &[(&str, Encoding, LasVersion, bool)] = &[
        ("pcd", Encoding::Ascii, LasVersion::V1_2, false),
        ("pcd", Encoding::Binary, LasVersion::V1_2, true),
        ("pcd", Encoding::BinaryCompressed, LasVersion::V1_2, true),
        ("ply", Encoding::Ascii, LasVersion::V1_2, false),
        ("ply", Encoding::Binary, LasVersion::V1_2, true),
        ("ply", Encoding::BinaryBigEndian, LasVersion::V1_2, true),
        ("las", Encoding::Binary, LasVersion::V1_2, true),
        ("las", Encoding::Binary, LasVersion::V1_4, true),
        ("laz", Encoding::Binary, LasVersion::V1_2, false),
        ("laz", Encoding::Binary, LasVersion::V1_4, false),
        ("xyz", Encoding::Ascii, LasVersion::V1_2, false),
        ("csv", Encoding::Ascii, LasVersion::V1_2, false),
    ];
    for (i, (ext, enc, ver, strict)) in written.iter().enumerate() {
        let path = dir.join(format!("s{i}.{ext}"));
        write_with(
            &path,
            &cloud,
            &WriteOptions {
                encoding: Some(*enc),
                las_version: *ver,
            },
        )
        .unwrap();
        let f = Format::from_path(&path).unwrap();
        out.push((
            format!("{ext} {enc} {ver:?}"),
            f,
            std::fs::read(&path).unwrap(),
            *strict,
        ));
    }
    let _ = std::fs::remove_dir_all(&dir);
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for name in [
        "pcl_binary.pcd",
        "pcl_binary_compressed.pcd",
        "python_int_fields.pcd",
        "python_mixed_le.ply",
        "python_mixed_be.ply",
        "python_mixed_ascii.ply",
        "vtk_binary.ply",
        "laspy_1_4_format7.laz",
        "laspy_1_2_format3.laz",
        "laspy_1_4_format6.las",
        "lasrs_autzen.copc.laz",
        "pdal_1.2-with-color.copc.laz",
        "pdal_simple-laszip-compressor-version-1.2r0.laz",
    ] {
        let p = data.join(name);
        out.push((
            name.into(),
            Format::from_path(&p).unwrap(),
            std::fs::read(&p).unwrap(),
            false,
        ));
    }
    out
}

/// Reads, turning a panic into a test failure that names the input.
fn check(name: &str, format: Format, bytes: &[u8]) -> Result<usize, String> {
    match catch_unwind(AssertUnwindSafe(|| read_from_bytes(format, bytes))) {
        Err(_) => panic!(
            "{name}: reader panicked on {} bytes: {bytes:?}",
            bytes.len()
        ),
        Ok(Ok(r)) => Ok(r.cloud.len()),
        Ok(Err(CloudError::Format { what, .. })) => Err(what),
        Ok(Err(CloudError::Io { source, .. })) => Err(source.to_string()),
        Ok(Err(e)) => panic!("{name}: unexpected error kind {e:?}"),
    }
}

#[test]
fn every_truncation_is_ok_or_an_error() {
    for (name, format, bytes, strict) in samples() {
        assert!(check(&name, format, &bytes).is_ok(), "{name} reads whole");
        let step = (bytes.len() / 1500).max(1);
        for k in (0..bytes.len()).step_by(step) {
            let r = check(&name, format, &bytes[..k]);
            if strict {
                assert!(
                    r.is_err(),
                    "{name}: cut at byte {k} of {} read as Ok",
                    bytes.len()
                );
            }
        }
    }
}

#[test]
fn truncation_errors_name_the_offset_or_line() {
    for (name, format, bytes, strict) in samples() {
        if !strict {
            continue;
        }
        let cut = &bytes[..bytes.len() - 5];
        let what = check(&name, format, cut).unwrap_err();
        assert!(
            what.contains("byte") || what.contains("line"),
            "{name}: {what}"
        );
    }
}

#[test]
fn text_errors_name_the_line() {
    let bad = b"# comment\nx y z\n1 2 3\n4 five 6\n";
    let what = check("xyz", Format::Xyz, bad).unwrap_err();
    assert!(what.contains("line 4"), "{what}");
    let short = b"1 2 3\n4 5\n";
    assert!(check("xyz", Format::Xyz, short)
        .unwrap_err()
        .contains("line 2"));
    let pcd = b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n1 2\n";
    assert!(check("pcd", Format::Pcd, pcd)
        .unwrap_err()
        .contains("line 11"));
    let ply = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n1 2 q\n";
    assert!(check("ply", Format::Ply, ply)
        .unwrap_err()
        .contains("line 9"));
}

#[test]
fn unknown_fields_types_and_disagreements_are_errors() {
    let head = |fields: &str, size: &str, ty: &str, rest: &str| {
        format!("FIELDS {fields}\nSIZE {size}\nTYPE {ty}\nCOUNT 1 1 1\n{rest}")
    };
    for (case, text) in [
        (
            "F2 type",
            head(
                "x y z",
                "4 4 2",
                "F F F",
                "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
            ),
        ),
        (
            "letter type",
            head(
                "x y z",
                "4 4 4",
                "F F Q",
                "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
            ),
        ),
        (
            "no z",
            head(
                "x y w",
                "4 4 4",
                "F F F",
                "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
            ),
        ),
        (
            "POINTS vs WIDTH",
            head(
                "x y z",
                "4 4 4",
                "F F F",
                "WIDTH 2\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
            ),
        ),
        (
            "extra point",
            head(
                "x y z",
                "4 4 4",
                "F F F",
                "WIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n4 5 6\n",
            ),
        ),
        (
            "missing point",
            head(
                "x y z",
                "4 4 4",
                "F F F",
                "WIDTH 2\nPOINTS 2\nDATA ascii\n1 2 3\n",
            ),
        ),
        (
            "bad DATA",
            head("x y z", "4 4 4", "F F F", "WIDTH 1\nPOINTS 1\nDATA zip\n"),
        ),
        (
            "unknown key",
            head(
                "x y z",
                "4 4 4",
                "F F F",
                "WIDTH 1\nCOLOUR red\nPOINTS 1\nDATA ascii\n1 2 3\n",
            ),
        ),
    ] {
        assert!(check(case, Format::Pcd, text.as_bytes()).is_err(), "{case}");
    }
    // Binary PCD with non-zero bytes after the data (POINTS too small).
    let mut b = b"FIELDS x y z\nWIDTH 1\nPOINTS 1\nDATA binary\n".to_vec();
    b.extend_from_slice(&[0u8; 12]);
    assert_eq!(check("bin", Format::Pcd, &b), Ok(1));
    b.extend_from_slice(&[1u8; 12]);
    assert!(check("bin extra", Format::Pcd, &b)
        .unwrap_err()
        .contains("extra"));
    for (case, text) in [
        ("type", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float16 x\nend_header\n"),
        ("format", "ply\nformat binary_middle_endian 1.0\nelement vertex 0\nend_header\n"),
        ("no vertex", "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int i\nend_header\n"),
        ("float count", "ply\nformat ascii 1.0\nelement f 1\nproperty list float int i\nend_header\n"),
        ("no ply", "plx\nformat ascii 1.0\nend_header\n"),
        ("extra line", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n"),
    ] {
        assert!(check(case, Format::Ply, text.as_bytes()).is_err(), "{case}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, ..ProptestConfig::default() })]

    #[test]
    fn flipped_bytes_never_panic(
        pick in any::<prop::sample::Index>(),
        flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        thread_local!(static SAMPLES: Vec<Sample> = samples());
        SAMPLES.with(|s| {
            let (name, format, bytes, _) = &s[pick.index(s.len())];
            let mut b = bytes.clone();
            for (at, v) in &flips {
                let i = at.index(b.len());
                b[i] = *v;
            }
            let _ = check(name, *format, &b);
        });
    }

    /// The proptest "byte fuzzer": arbitrary bytes behind a valid-looking
    /// start of each format.
    #[test]
    fn arbitrary_bytes_after_a_header_never_panic(
        which in 0usize..4,
        tail in prop::collection::vec(any::<u8>(), 0..600),
    ) {
        let (format, head): (Format, &[u8]) = match which {
            0 => (Format::Pcd, b"FIELDS x y z _\nSIZE 4 8 2 1\nTYPE F F I U\nCOUNT 1 1 1 3\nWIDTH 7\nPOINTS 7\nDATA binary_compressed\n"),
            1 => (Format::Ply, b"ply\nformat binary_big_endian 1.0\nelement vertex 5\nproperty double x\nproperty uchar y\nproperty list uchar int l\nproperty float z\nelement face 3\nproperty list ushort uint v\nend_header\n"),
            2 => (Format::Las, b"LASF"),
            _ => (Format::Csv, b"x,y,z\n"),
        };
        let mut b = head.to_vec();
        b.extend_from_slice(&tail);
        let _ = check("tail", format, &b);
    }
}

/// Regressions found by the fuzzers (fuzz/), each named after what it hit.
#[test]
fn fuzz_regressions() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    // FIELDS repeated with fewer names after SIZE/TYPE/COUNT: indexed past
    // the end of the names.
    let b = std::fs::read(data.join("fuzz_pcd_fields_twice.pcd")).unwrap();
    assert!(check("fields twice", Format::Pcd, &b).is_err());
    // A LAS 1.4 header_size of 256 (below the 375 of the version): `las`
    // still reads the VLRs after byte 375, the guard looked at byte 256,
    // missed the LASzip record, and `laz` zero-filled a 2 GiB layer. Now a
    // header smaller than its version's is refused outright.
    let b = std::fs::read(data.join("fuzz_laz_layer_size_short_header.laz")).unwrap();
    let what = check("short header", Format::Laz, &b).unwrap_err();
    assert!(what.contains("256 bytes long"), "{what}");
    // Variable-size LASzip chunks whose table holds fewer points than the
    // header claims: `laz` indexed its chunk table past the end (a panic).
    let b = std::fs::read(data.join("fuzz_laz_chunk_table_too_short.laz")).unwrap();
    assert!(check("short table", Format::Laz, &b).is_err());
    // A malformed chunk table on which `laz`'s arithmetic decoder indexes
    // past its table (a panic inside `laz`): caught, reported as an error.
    let b = std::fs::read(data.join("fuzz_laz_decoder_index_panic.laz")).unwrap();
    let what = check("decoder panic", Format::Laz, &b).unwrap_err();
    assert!(what.contains("malformed"), "{what}");
    // Point format 6 whose GPS-time stream keeps asking to switch sequence:
    // `laz` 0.12.2 recursed once per switch and overflowed the stack (an
    // abort, not catchable). vendor/laz bounds the switches per point.
    let b = std::fs::read(data.join("fuzz_laz_point6_gps_recursion.laz")).unwrap();
    let what = check("gps recursion", Format::Laz, &b).unwrap_err();
    assert!(what.contains("sequence switches"), "{what}");
}
