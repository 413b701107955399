//! Headers that lie about sizes: every reader refuses them quickly and
//! without a large allocation. A tracking global allocator records the
//! largest single allocation made on the test's thread.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::{Duration, Instant};

use autoshovel_point_cloud::io::{
    read_from_bytes, write_with, Encoding, Format, LasVersion, WriteOptions,
};
use autoshovel_point_cloud::{CloudError, PointCloud};

struct Tracking;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(n: usize) {
    let _ = LARGEST.try_with(|c| {
        if n > c.get() {
            c.set(n)
        }
    });
}

// SAFETY: forwards to the system allocator; only records sizes.
unsafe impl GlobalAlloc for Tracking {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        note(l.size());
        // SAFETY: same contract as our caller's.
        unsafe { System.alloc(l) }
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        note(l.size());
        // SAFETY: same contract as our caller's.
        unsafe { System.alloc_zeroed(l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        note(new);
        // SAFETY: same contract as our caller's.
        unsafe { System.realloc(p, l, new) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: same contract as our caller's.
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static ALLOC: Tracking = Tracking;

/// Largest allocation a lying file may cause (bytes): the 1 MiB read
/// buffers and a little more, nowhere near what the headers claim.
const LIMIT: usize = 4 << 20;

/// Reads `bytes`, expects a Format error mentioning `hint`, fast and small.
fn refuses(case: &str, format: Format, bytes: &[u8], hint: &str) {
    LARGEST.with(|c| c.set(0));
    let t = Instant::now();
    let r = read_from_bytes(format, bytes);
    let dt = t.elapsed();
    let largest = LARGEST.with(|c| c.get());
    match r {
        Err(CloudError::Format { what, .. }) => {
            assert!(what.contains(hint), "{case}: error {what:?} lacks {hint:?}")
        }
        other => panic!("{case}: expected a format error, got {other:?}"),
    }
    assert!(dt < Duration::from_secs(1), "{case}: took {dt:?}");
    assert!(largest < LIMIT, "{case}: allocated {largest} bytes at once");
}

fn pcd(rest: &str) -> Vec<u8> {
    format!("# lies\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n{rest}")
        .into_bytes()
}

#[test]
fn pcd_claiming_four_billion_points_in_200_bytes() {
    for data in ["ascii", "binary", "binary_compressed"] {
        let mut b = pcd(&format!(
            "WIDTH 4000000000\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4000000000\nDATA {data}\n"
        ));
        b.resize(200, b'1');
        let hint = match data {
            "ascii" => "line",
            "binary" => "need 48000000000 bytes",
            _ => "uncompressed size",
        };
        refuses(data, Format::Pcd, &b, hint);
    }
}

#[test]
fn pcd_other_lies() {
    // A consistent binary_compressed header whose 100 compressed bytes
    // cannot expand to 3.6 GB.
    let mut b = pcd("WIDTH 300000000\nPOINTS 300000000\nDATA binary_compressed\n");
    b.extend_from_slice(&100u32.to_le_bytes());
    b.extend_from_slice(&3_600_000_000u32.to_le_bytes());
    b.extend_from_slice(&[0u8; 100]);
    refuses("lzf ratio", Format::Pcd, &b, "cannot expand");
    // Compressed size larger than the file.
    let mut b = pcd("WIDTH 2\nPOINTS 2\nDATA binary_compressed\n");
    b.extend_from_slice(&4_000_000_000u32.to_le_bytes());
    b.extend_from_slice(&24u32.to_le_bytes());
    refuses("compressed size", Format::Pcd, &b, "truncated");
    // A huge COUNT makes an absurd record.
    let b = b"FIELDS x y z\nCOUNT 1 1 4000000000\nWIDTH 1\nPOINTS 1\nDATA binary\n".to_vec();
    refuses("count", Format::Pcd, &b, "COUNT");
    let b = b"FIELDS x y z w\nCOUNT 1 1 1 900000\nWIDTH 1\nPOINTS 1\nDATA binary\n".to_vec();
    refuses("record", Format::Pcd, &b, "larger than");
    // WIDTH × HEIGHT overflowing u64.
    let b = pcd("WIDTH 18446744073709551615\nHEIGHT 3\nDATA binary\n");
    refuses("overflow", Format::Pcd, &b, "overflows");
    // A 10 MB line without a line break is refused, not buffered whole.
    let mut b = pcd("WIDTH 1\nPOINTS 1\nDATA ascii\n");
    b.extend(std::iter::repeat_n(b'7', 10 << 20));
    refuses("long line", Format::Pcd, &b, "longer than");
}

#[test]
fn ply_lies() {
    let head = |body: &str, n: &str| {
        format!("ply\nformat {body} 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n")
    };
    let mut b = head("binary_little_endian", "4000000000").into_bytes();
    b.extend_from_slice(&[0u8; 100]);
    refuses("binary vertex", Format::Ply, &b, "need 48000000000 bytes");
    let mut b = head("ascii", "4000000000").into_bytes();
    b.extend_from_slice(b"1 2 3\n");
    refuses("ascii vertex", Format::Ply, &b, "after 1 of 4000000000");
    let mut b = head("binary_big_endian", "18446744073709551615").into_bytes();
    b.extend_from_slice(&[0u8; 100]);
    refuses("overflow", Format::Ply, &b, "overflows");
    // A face list claiming 4 billion indices.
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uint int v\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec();
    b.extend_from_slice(&4_000_000_000u32.to_le_bytes());
    b.extend_from_slice(&[0u8; 64]);
    refuses("list", Format::Ply, &b, "more than the file holds");
    // Ten million faces of zero bytes... are a list each, so at least one
    // byte each: a 100-byte file runs out quickly.
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 10000000000\nproperty list uchar int v\nend_header\n".to_vec();
    b.extend_from_slice(&[0u8; 100]);
    refuses("many faces", Format::Ply, &b, "file ends");
}

fn las_bytes(compressed: bool, version: LasVersion, n: usize) -> Vec<u8> {
    let dir = std::env::temp_dir().join(format!(
        "autoshovel-io-lies-{}-{compressed}-{version:?}-{n}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(if compressed { "a.laz" } else { "a.las" });
    let cloud = PointCloud::new((0..n).map(|i| [i as f32, (i % 7) as f32, 0.5]).collect());
    write_with(
        &path,
        &cloud,
        &WriteOptions {
            encoding: Some(Encoding::Binary),
            las_version: version,
        },
    )
    .unwrap();
    let b = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    b
}

fn put_u32(b: &mut [u8], at: usize, v: u32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}
fn put_u64(b: &mut [u8], at: usize, v: u64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}
fn get_u32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

#[test]
fn las_lies() {
    // Legacy point count 4e9 in a file of 10 points.
    let mut b = las_bytes(false, LasVersion::V1_2, 10);
    put_u32(&mut b, 107, 4_000_000_000);
    refuses("legacy count", Format::Las, &b, "claims 4000000000 points");
    // LAS 1.4: the 64-bit count, legacy field zero.
    let mut b = las_bytes(false, LasVersion::V1_4, 10);
    put_u32(&mut b, 107, 0);
    put_u64(&mut b, 247, 1 << 50);
    refuses(
        "large count",
        Format::Las,
        &b,
        "claims 1125899906842624 points",
    );
    // 4e9 variable-length records.
    let mut b = las_bytes(false, LasVersion::V1_2, 10);
    put_u32(&mut b, 100, 4_000_000_000);
    refuses("vlrs", Format::Las, &b, "variable-length records");
    // An extended VLR of 1 TiB.
    let mut b = las_bytes(false, LasVersion::V1_4, 10);
    let at = b.len() as u64;
    let mut evlr = vec![0u8; 60];
    put_u64(&mut evlr, 20, 1 << 40);
    b.extend_from_slice(&evlr);
    put_u64(&mut b, 235, at);
    put_u32(&mut b, 243, 1);
    refuses("evlr", Format::Las, &b, "extended VLR");
    // Point data offset past the end.
    let mut b = las_bytes(false, LasVersion::V1_2, 10);
    put_u32(&mut b, 96, 1 << 30);
    refuses("offset", Format::Las, &b, "past the end");
    // A header_size smaller than the version's header (0, and 1.4's 256).
    for (version, size) in [
        (LasVersion::V1_2, 0u16),
        (LasVersion::V1_4, 0),
        (LasVersion::V1_4, 256),
    ] {
        let mut b = las_bytes(false, version, 10);
        b[94..96].copy_from_slice(&size.to_le_bytes());
        refuses(
            "header size",
            Format::Las,
            &b,
            &format!("says it is {size} bytes long"),
        );
    }
    // Not LAS at all.
    refuses("signature", Format::Las, b"LASX and more", "LASF");
}

#[test]
fn laz_lies() {
    // 4e9 points in a few hundred bytes.
    let mut b = las_bytes(true, LasVersion::V1_2, 10);
    put_u32(&mut b, 107, 4_000_000_000);
    refuses("count", Format::Laz, &b, "per byte");
    // A chunk table claiming 4e9 chunks (laz would reserve 64 GB).
    let mut b = las_bytes(true, LasVersion::V1_4, 10);
    let data = get_u32(&b, 96) as usize;
    let table = u64::from_le_bytes(b[data..data + 8].try_into().unwrap()) as usize;
    put_u32(&mut b, table + 4, u32::MAX);
    refuses("chunk table", Format::Laz, &b, "chunk table");
    // A layered chunk announcing a 4 GB layer (laz would zero-fill it).
    let mut b = las_bytes(true, LasVersion::V1_4, 10);
    let data = get_u32(&b, 96) as usize;
    // 8 bytes of table offset, a raw 30-byte first point, the point count.
    put_u32(&mut b, data + 8 + 30 + 4, 0xFFFF_FFF0);
    refuses("layer", Format::Laz, &b, "bytes of layers");
    // A LASzip record listing no items (laz would panic).
    let mut b = las_bytes(true, LasVersion::V1_2, 10);
    let pos = b.windows(14).position(|w| w == b"laszip encoded").unwrap() - 2;
    put_u32(&mut b, pos + 54 + 32, 0); // num_items (u16) and the next item's type
    refuses("no items", Format::Laz, &b, "no items");
}

#[test]
fn laz_of_identical_points_passes_the_guard() {
    // The guard's bound assumes at most LAZ_MAX_POINTS_PER_BYTE points per
    // compressed byte; the most compressible real data must stay below it.
    for version in [LasVersion::V1_2, LasVersion::V1_4] {
        let dir = std::env::temp_dir().join(format!(
            "autoshovel-io-same-{}-{version:?}",
            std::process::id()
        ));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("same.laz");
        let n = 400_000;
        let cloud = PointCloud::new(vec![[1.0, 2.0, 3.0]; n]);
        write_with(
            &path,
            &cloud,
            &WriteOptions {
                encoding: None,
                las_version: version,
            },
        )
        .unwrap();
        let size = std::fs::metadata(&path).unwrap().len();
        let r = autoshovel_point_cloud::io::read(&path, &mut |_, _| {}).unwrap();
        assert_eq!(r.cloud.len(), n);
        let per_byte = n as f64 / size as f64;
        assert!(
            per_byte * 5.0 < autoshovel_point_cloud::io::LAZ_MAX_POINTS_PER_BYTE as f64,
            "{version:?}: {per_byte:.1} points per byte is too close to the guard"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
