//! LAS and LAZ (ASPRS LAS 1.0–1.4, LASzip compression) through the `las`
//! crate, which returns x, y, z already scaled and offset.
//!
//! # The guard in front of `las`
//! `las` (and `laz` under it) trust header fields when sizing buffers and
//! loops, and a damaged or hostile file can make them allocate gigabytes or
//! overflow. Before a file reaches them, [`check`] reads the public header
//! and refuses:
//! - a point count whose records (count × record length) do not fit in the
//!   bytes after the point-data offset (LAS);
//! - for LAZ, more than [`LAZ_MAX_POINTS_PER_BYTE`] points per byte of
//!   compressed data. The most compressible data there is, 2 M identical
//!   points, takes 13 557 bytes with the `las` writer (148 points a byte,
//!   LAS 1.2; 100 a byte for 1.4's layered format), about 340 bytes per
//!   50 000-point chunk. LASzip's adaptive models cap the probability of a
//!   symbol, so even a crafted stream pays some bits per point; 2000 points
//!   a byte is 13 times the best case measured and still turns a 1 kB file
//!   claiming four billion points into an immediate error;
//! - more variable-length records than fit between the header and the
//!   points, an extended VLR longer than the rest of the file, a point-data
//!   offset past the end;
//! - a LASzip chunk table with more chunks than the compressed bytes could
//!   hold (every chunk starts with one raw point, ≥ 20 bytes; we allow one
//!   chunk per [`LAZ_MIN_CHUNK_BYTES`]), since `laz` reserves the table
//!   from that count;
//! - a layered (LAS 1.4, point formats 6–10) LASzip chunk whose layers add
//!   up to more than the rest of the file, since `laz` zero-fills a buffer
//!   of each announced layer size before reading it; every chunk header is
//!   walked (a few seeks per 50 000 points) before decoding starts, and a
//!   layered file whose chunk table cannot be read is refused (`laz` would
//!   decode from wherever the failed attempt left the stream);
//! - a LASzip record with no items, or variable-size chunks whose table
//!   holds fewer points than the header's count (`laz` would panic: it
//!   indexes the table past its end).
//!
//! `laz` also panics on some malformed streams (fuzzing found an index out
//! of bounds in its arithmetic decoder); the decoding runs under
//! `catch_unwind`, so such a file is a format error (with the default
//! `panic = "unwind"`).
//!
//! Points are then read one at a time (`read_point`, never `read_points`,
//! which reserves the header's count) straight into the cloud's vector.

use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

use super::input::Points;
use super::las_columns::{format_for, unwritable, LasColumns, LasRows};
use crate::attributes::Attributes;
use crate::georef::{las_crs, Georef, LasLayout};
use crate::{CloudError, PointCloud};

/// Most LAZ points accepted per byte of compressed data (see the module
/// docs for the measurement behind it).
pub const LAZ_MAX_POINTS_PER_BYTE: u64 = 2000;
/// Fewest bytes a LASzip chunk is assumed to take (a raw first point alone
/// is 20 or more).
pub const LAZ_MIN_CHUNK_BYTES: u64 = 8;
/// Minimum size of a variable-length record header (bytes).
const VLR_HEADER: u64 = 54;
/// Size of an extended VLR header (bytes).
const EVLR_HEADER: u64 = 60;
/// Progress is reported every this many points.
const PROGRESS_POINTS: u64 = 1 << 16;

/// What the public header says, after checking.
struct Checked {
    /// Bytes to show `las` in place of the file's (see [`Patched`]).
    patch: Option<(u64, [u8; 4])>,
    compressed: bool,
    count: u64,
    minor: u8,
    major: u8,
    offset: u64,
    record_len: u64,
}

fn le16(b: &[u8], at: usize) -> u64 {
    u64::from(u16::from_le_bytes([b[at], b[at + 1]]))
}
fn le32(b: &[u8], at: usize) -> u64 {
    u64::from(u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]))
}
fn le64(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

/// Reads as much of `buf` as the source has.
fn read_up_to<R: Read>(src: &mut R, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match src.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

fn read_at<R: Read + Seek>(src: &mut R, at: u64, buf: &mut [u8]) -> std::io::Result<bool> {
    src.seek(SeekFrom::Start(at))?;
    Ok(read_up_to(src, buf)? == buf.len())
}

/// Checks the header against the file size (see the module docs).
fn check<R: Read + Seek>(src: &mut R, total: u64) -> Result<Checked, String> {
    let io = |e: std::io::Error| format!("reading the header: {e}");
    let mut h = [0u8; 255];
    src.seek(SeekFrom::Start(0)).map_err(io)?;
    let n = read_up_to(src, &mut h).map_err(io)?;
    if n < 4 || &h[..4] != b"LASF" {
        return Err("not a LAS file: it does not start with \"LASF\"".into());
    }
    if n < 227 {
        return Err(format!(
            "a LAS header takes at least 227 bytes, the file has {total}"
        ));
    }
    let (major, minor) = (h[24], h[25]);
    let is14 = major == 1 && minor == 4;
    if is14 && n < 255 {
        return Err(format!(
            "a LAS 1.4 header takes at least 375 bytes, the file has {total}"
        ));
    }
    let header_size = le16(&h, 94);
    let offset = le32(&h, 96);
    let n_vlrs = le32(&h, 100);
    let format = h[104];
    let record_len = le16(&h, 105);
    let legacy = le32(&h, 107);
    // As `las` does: the legacy count unless it is zero (LAS 1.4).
    let count = if legacy > 0 {
        legacy
    } else if is14 {
        le64(&h, 247)
    } else {
        0
    };
    let compressed = format & 0x80 != 0;
    if offset > total {
        return Err(format!(
            "the point data offset {offset} lies past the end of the file ({total} bytes)"
        ));
    }
    // `las` reads the fixed fields of the version, then pads up to
    // `header_size` if that is larger, then the VLRs.
    let (fields, nominal) = match (major, minor) {
        (1, 4) => (375, 375),
        (1, 3) => (235, 235),
        (1, 0..=2) => (227, 227),
        _ => (227, 375),
    };
    // As LAStools does: a header smaller than its version's fields is not a
    // LAS header (`las` would read the fields anyway, from wherever).
    if header_size < fields {
        return Err(format!(
            "the header says it is {header_size} bytes long (byte 94); a LAS {major}.{minor} header takes at least {fields}"
        ));
    }
    let vlr_start = fields + header_size.saturating_sub(nominal);
    if n_vlrs.saturating_mul(VLR_HEADER) > offset.saturating_sub(vlr_start) {
        return Err(format!(
            "{n_vlrs} variable-length records cannot fit between byte {vlr_start} and the point data at byte {offset}"
        ));
    }
    let data_bytes = total - offset;
    if !compressed {
        let need = count.checked_mul(record_len);
        if need.is_none_or(|need| need > data_bytes) {
            return Err(format!(
                "the header claims {count} points × {record_len} bytes, but only {data_bytes} bytes follow the point data offset {offset} (truncated file or a wrong point count)"
            ));
        }
    } else if count > data_bytes.saturating_mul(LAZ_MAX_POINTS_PER_BYTE) {
        return Err(format!(
            "the header claims {count} points, more than {LAZ_MAX_POINTS_PER_BYTE} per byte of the {data_bytes} bytes of compressed data (truncated file or a wrong point count)"
        ));
    }
    if is14 {
        let evlr_start = le64(&h, 235);
        let n_evlrs = le32(&h, 243);
        if evlr_start > 0 && n_evlrs > 0 {
            let mut e = [0u8; EVLR_HEADER as usize];
            if evlr_start.saturating_add(EVLR_HEADER) > total
                || !read_at(src, evlr_start, &mut e).map_err(io)?
            {
                return Err(format!("the extended VLR at byte {evlr_start} lies past the end of the file ({total} bytes)"));
            }
            let len = le64(&e, 20);
            if len > total - evlr_start - EVLR_HEADER {
                return Err(format!(
                    "the extended VLR at byte {evlr_start} claims {len} bytes, more than the rest of the file"
                ));
            }
        }
    }
    let mut c = Checked {
        patch: None,
        compressed,
        count,
        minor,
        major,
        offset,
        record_len,
    };
    if compressed {
        c.patch = check_laz(src, total, vlr_start, n_vlrs, &c)?;
    }
    Ok(c)
}

/// The LASzip checks: items, chunk table, layer sizes. They follow what
/// `las` and `laz` do step by step: where the VLRs start, which VLR is the
/// LASzip one, where decoding starts. Returns the patch a point-wise file
/// needs (see [`Patched`]).
#[cfg(feature = "laz")]
fn check_laz<R: Read + Seek>(
    src: &mut R,
    total: u64,
    vlr_start: u64,
    n_vlrs: u64,
    c: &Checked,
) -> Result<Option<(u64, [u8; 4])>, String> {
    let io = |e: std::io::Error| format!("reading the LASzip records: {e}");
    let mut pos = vlr_start;
    let mut found = None;
    for _ in 0..n_vlrs {
        let mut v = [0u8; VLR_HEADER as usize];
        if !read_at(src, pos, &mut v).map_err(io)? {
            return Ok(None); // `las` reports the truncation
        }
        let len = le16(&v, 20);
        // The user id up to its first NUL, as `las` compares it.
        let id_end = v[2..18].iter().position(|&b| b == 0).map_or(18, |i| i + 2);
        if &v[2..id_end] == b"laszip encoded" && le16(&v, 18) == 22204 {
            found = Some((pos + VLR_HEADER, len));
            break;
        }
        pos += VLR_HEADER + len;
    }
    let Some((at, len)) = found else {
        return Ok(None);
    };
    let mut d = vec![0u8; len as usize];
    if !read_at(src, at, &mut d).map_err(io)? {
        return Ok(None);
    }
    let Ok(vlr) = laz::LazVlr::from_buffer(&d) else {
        return Ok(None); // `las` refuses it the same way
    };
    if vlr.items().is_empty() {
        return Err("the LASzip record lists no items".into());
    }
    let compressor = le16(&d, 0);
    let layered = matches!(vlr.items()[0].version(), 3 | 4);
    let data_start = c.offset;
    // Point-wise LASzip (compressor 1: one stream, no chunks, no table), as
    // LASzip 1.2 wrote it, has 0 in the chunk-size field. `laz` 0.12 reads 0
    // as "variable-size chunks" (LAStools' newer convention) and then panics
    // for want of a chunk table on the first point. Point-wise decoding
    // never uses the chunk size, so `las` is shown a fixed size there.
    let patch = (compressor == 1 && d.len() >= 16 && le32(&d, 12) == 0)
        .then(|| (at + 12, u32::MAX.wrapping_sub(1).to_le_bytes()));
    // How many chunks `laz` decodes for the header's count.
    let mut chunks_decoded = c.count.div_ceil(u64::from(vlr.chunk_size()).max(1));
    if compressor == 1 {
        chunks_decoded = c.count.min(1);
    } else {
        // Chunk table: its offset is the first 8 bytes of the point data,
        // or the last 8 bytes of the file when the writer could not seek.
        let mut b8 = [0u8; 8];
        if !read_at(src, data_start, &mut b8).map_err(io)? {
            return Ok(patch);
        }
        let mut table = i64::from_le_bytes(b8);
        if table <= data_start as i64 && total >= 8 {
            read_at(src, total - 8, &mut b8).map_err(io)?;
            table = i64::from_le_bytes(b8);
        }
        if table > data_start as i64 {
            let table = table as u64;
            if table.saturating_add(8) <= total && read_at(src, table, &mut b8).map_err(io)? {
                let chunks = le32(&b8, 4);
                let bound = (table - data_start) / LAZ_MIN_CHUNK_BYTES + 1;
                if chunks > bound {
                    return Err(format!(
                        "the LASzip chunk table at byte {table} claims {chunks} chunks; {} bytes of compressed points hold at most {bound}",
                        table - data_start
                    ));
                }
            }
        }
        let variable = vlr.uses_variable_size_chunks();
        if layered || variable {
            src.seek(SeekFrom::Start(data_start)).map_err(io)?;
            let table = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                laz::laszip::ChunkTable::read_from(&mut *src, &vlr)
            }));
            let table = match table {
                Ok(t) => t,
                Err(_) => {
                    return Err("the LASzip chunk table is malformed (the decoder failed)".into())
                }
            };
            match table {
                // When the table cannot be read, `laz` goes on decoding from
                // wherever the attempt left the stream: refuse that for
                // layered data, whose chunks announce buffer sizes.
                Err(_) if layered => {
                    return Err(
                        "the LASzip chunk table cannot be read (damaged or truncated file)".into(),
                    )
                }
                Err(_) => {}
                // With variable-size chunks (COPC) `laz` indexes the table
                // by chunk number and panics past its end: the chunks must
                // hold the header's point count.
                Ok(table) if variable => {
                    let mut left = c.count;
                    chunks_decoded = 0;
                    for entry in table.as_ref() {
                        if left == 0 {
                            break;
                        }
                        chunks_decoded += 1;
                        if entry.point_count == 0 || left <= entry.point_count {
                            left = 0;
                            break;
                        }
                        left -= entry.point_count;
                    }
                    if left > 0 {
                        return Err(format!(
                            "the LASzip chunk table's {} chunks hold fewer than the header's {} points",
                            table.len(),
                            c.count
                        ));
                    }
                }
                Ok(_) => {}
            }
        }
    }
    if !layered {
        return Ok(patch);
    }
    // Layered chunks: [first point, raw][u32 count][u32 size per layer]
    // [layers]; `laz` zero-fills a buffer of each size before reading it.
    let mut first_point = 0u64;
    let mut layers = 0u64;
    for item in vlr.items() {
        let (bytes, l) = match item.item_type() {
            laz::LazItemType::Point14 => (30, 9),
            laz::LazItemType::RGB14 => (6, 1),
            laz::LazItemType::RGBNIR14 => (8, 2),
            laz::LazItemType::WavePacket14 => (29, 1),
            laz::LazItemType::Byte14(n) => (u64::from(n), u64::from(n)),
            _ => return Ok(patch), // `laz` refuses it
        };
        first_point += bytes;
        layers += l;
    }
    let mut pos = if compressor == 1 {
        data_start
    } else {
        data_start + 8
    };
    let mut sizes = vec![0u8; 4 + 4 * layers as usize];
    // The chunks `laz` will decode, one after another (it reads the stream
    // in order). Only those: COPC puts the chunk table and its hierarchy
    // records right after the last chunk, and they are not chunks. A count
    // larger than the chunks hold makes `laz` read "chunks" out of whatever
    // follows, so that is walked too, up to the end of the file.
    for _ in 0..chunks_decoded {
        let chunk = pos;
        pos += first_point;
        if pos + sizes.len() as u64 > total || !read_at(src, pos, &mut sizes).map_err(io)? {
            return Ok(patch); // `laz` stops with an end-of-file error here
        }
        pos += sizes.len() as u64;
        let sum: u64 = (0..layers as usize).map(|k| le32(&sizes, 4 + 4 * k)).sum();
        if sum > total - pos {
            return Err(format!(
                "the LASzip chunk at byte {chunk} announces {sum} bytes of layers, more than the rest of the file ({} bytes)",
                total - pos
            ));
        }
        pos += sum;
    }
    Ok(patch)
}

#[cfg(not(feature = "laz"))]
fn check_laz<R: Read + Seek>(
    _: &mut R,
    _: u64,
    _: u64,
    _: u64,
    _: &Checked,
) -> Result<Option<(u64, [u8; 4])>, String> {
    Ok(None) // `las` refuses compressed data without the feature
}

/// A source that shows `patch.1` at byte `patch.0` in place of the file's
/// four bytes: how a point-wise LASzip record's chunk size reaches `laz`
/// (see `check_laz`) without copying the file. Written by hand: a four-byte
/// overlay on `Read + Seek` is smaller than any crate for it.
struct Patched<R> {
    inner: R,
    pos: u64,
    patch: Option<(u64, [u8; 4])>,
}

impl<R: Read> Read for Patched<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if let Some((at, bytes)) = self.patch {
            let lo = self.pos.max(at);
            let hi = (self.pos + n as u64).min(at + 4);
            for p in lo..hi {
                buf[(p - self.pos) as usize] = bytes[(p - at) as usize];
            }
        }
        self.pos += n as u64;
        Ok(n)
    }
}

impl<R: Seek> Seek for Patched<R> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        self.pos = self.inner.seek(to)?;
        Ok(self.pos)
    }
}

/// Runs `f`, turning a panic (in `las` or `laz`) into a format error.
/// Needs the default `panic = "unwind"`; the panic message still goes to
/// the panic hook (stderr by default).
fn without_panics<T>(path: &Path, f: impl FnOnce() -> crate::Result<T>) -> crate::Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let msg = autoshovel_core::panic_message(payload.as_ref()).unwrap_or_default();
        Err(CloudError::Format {
            path: path.to_path_buf(),
            what: format!("LAS/LAZ decoder failed on malformed data: {msg}"),
        })
    })
}

/// Turns an error of `las` into ours. `at` is the index of the point being
/// read (None while `las` reads the header and records); an early end of
/// the data is reported as a truncation, with where it happened.
fn las_err(path: &Path, e: las::Error, at: Option<u64>, c: &Checked, total: u64) -> CloudError {
    let eof = match &e {
        las::Error::Io(source) => source.kind() == std::io::ErrorKind::UnexpectedEof,
        #[cfg(feature = "laz")]
        las::Error::LasZipError(laz::LasZipError::IoError(source)) => {
            source.kind() == std::io::ErrorKind::UnexpectedEof
        }
        _ => false,
    };
    let what = match e {
        las::Error::Io(source) if !eof => {
            return CloudError::Io {
                path: path.to_path_buf(),
                source,
            }
        }
        _ if eof => match at {
            None => format!(
                "truncated: the file ({total} bytes) ends inside its header or variable-length records"
            ),
            Some(i) if !c.compressed => format!(
                "truncated: point {} of {} starts at byte {} and runs past the end of the file ({total} bytes)",
                i + 1,
                c.count,
                c.offset + i * c.record_len
            ),
            Some(i) => format!(
                "truncated or damaged compressed data: decoding stopped at point {} of the {} the header claims (the file has {total} bytes)",
                i + 1,
                c.count
            ),
        },
        e => format!("LAS: {e}"),
    };
    CloudError::Format {
        path: path.to_path_buf(),
        what,
    }
}

/// What [`read`] found besides the points.
pub(crate) struct LasRead {
    /// E.g. `"laz 1.4"`.
    pub(crate) name: &'static str,
    /// The header read, and the CRS it states.
    pub(crate) georef: Georef,
    /// The points' attributes (none when streaming).
    pub(crate) attributes: Attributes,
}

/// The origin for a LAS file's points, an axis at a time: zero where f32
/// about zero already resolves a quarter of the file's step at the
/// header's largest coordinate (a local scan keeps the frame it was
/// written in), otherwise the middle of the header's bounds on the file's
/// own grid (offset plus whole steps), so the offsets from it are whole
/// steps too. From the header alone: the same data in another container
/// (LAZ, COPC) or in another point order gets the same origin.
fn origin_of(h: &las::Header) -> [f64; 3] {
    let b = h.bounds();
    let t = h.transforms();
    let (lo, hi) = ([b.min.x, b.min.y, b.min.z], [b.max.x, b.max.y, b.max.z]);
    let grid = [t.x, t.y, t.z];
    [0, 1, 2].map(|a| {
        let (scale, offset) = (grid[a].scale, grid[a].offset);
        let far = lo[a].abs().max(hi[a].abs());
        let sane = lo[a].is_finite() && hi[a].is_finite() && lo[a] <= hi[a] && scale > 0.0;
        if !sane || half_ulp(far) <= scale / 4.0 {
            return 0.0;
        }
        offset + (((lo[a] + hi[a]) / 2.0 - offset) / scale).round() * scale
    })
}

/// Half the f32 spacing at `v`.
fn half_ulp(v: f64) -> f64 {
    let f = v.abs() as f32;
    f64::from(f32::from_bits(f.to_bits() + 1) - f) / 2.0
}

/// Reads a LAS or LAZ stream of `total` bytes into `out`, its points less
/// the origin of the header ([`origin_of`]) unless streaming (then
/// `out.origin` as given), the attributes as columns unless streaming.
pub(crate) fn read<R: Read + Seek + Send + Sync + 'static>(
    mut src: R,
    total: u64,
    path: &Path,
    progress: &mut dyn FnMut(u64, u64),
    out: &mut Points<'_>,
) -> crate::Result<LasRead> {
    progress(0, total);
    let c = check(&mut src, total).map_err(|what| CloudError::Format {
        path: path.to_path_buf(),
        what,
    })?;
    src.seek(SeekFrom::Start(0))
        .map_err(|source| CloudError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    // `laz` 0.12 panics on some malformed streams (an index out of bounds
    // in its arithmetic decoder, found by fuzzing): decoding runs under
    // catch_unwind so that such a file is a format error, not a crash.
    let src = Patched {
        inner: src,
        pos: 0,
        patch: c.patch,
    };
    without_panics(path, || {
        let mut reader = las::Reader::new(src).map_err(|e| las_err(path, e, None, &c, total))?;
        if !c.compressed {
            out.reserve_bounded(c.count, total - c.offset, c.record_len.max(1));
        }
        let header = reader.header().clone();
        let mut columns = (!out.is_streaming()).then(|| {
            out.origin = origin_of(&header);
            LasColumns::for_format(header.point_format())
        });
        let (format, transforms) = (*header.point_format(), *header.transforms());
        let mut i = 0u64;
        while let Some(p) = reader
            .read_point()
            .map_err(|e| las_err(path, e, Some(i), &c, total))?
        {
            if out.push_f64(p.x, p.y, p.z) {
                if let Some(cols) = &mut columns {
                    cols.push(&p);
                }
                if let Some(rows) = &mut out.rows {
                    p.into_raw(&transforms)
                        .and_then(|raw| raw.write_to(rows, &format))
                        .map_err(|e| las_err(path, e, Some(i), &c, total))?;
                }
            }
            out.hand_on(false)?;
            i += 1;
            if i.is_multiple_of(PROGRESS_POINTS) {
                let done = if c.compressed {
                    (total as f64 * i as f64 / c.count.max(1) as f64) as u64
                } else {
                    c.offset + i * c.record_len
                };
                progress(done.min(total), total);
            }
        }
        out.hand_on(true)?;
        Ok(LasRead {
            name: version_name(c.compressed, c.major, c.minor),
            georef: Georef {
                crs: las_crs(&header),
                las: Some(LasLayout(header)),
                viewpoint: None,
            },
            attributes: columns.map(LasColumns::into_attributes).unwrap_or_default(),
        })
    })
    .inspect(|_| progress(total, total))
}

/// What a LAS or LAZ file's header says: enough to lay tiles over a
/// survey and to check that its files agree, without reading a point.
#[derive(Debug, Clone, PartialEq)]
pub struct LasHeader {
    /// E.g. `"laz 1.4"`.
    pub format: &'static str,
    /// The point count of the header.
    pub points: u64,
    /// Scale factor per axis (m per step).
    pub scale: [f64; 3],
    /// Offset per axis (m).
    pub offset: [f64; 3],
    /// The header's bounds (m).
    pub min: [f64; 3],
    /// The header's bounds (m).
    pub max: [f64; 3],
    /// The coordinate system records (`LASF_Projection`: GeoTIFF keys
    /// 34735–34737, WKT 2111–2112), as (record id, bytes), in record-id
    /// order; empty when the file states none.
    pub crs: Vec<(u16, Vec<u8>)>,
    /// The CRS and the header itself, as a cloud read from the file would
    /// carry them: what a cloud made from the file's points (a survey's
    /// cleaned tile) is written back with.
    pub georef: crate::Georef,
}

/// Reads the header of the LAS or LAZ stream `src` of `total` bytes (after
/// the same checks as [`read`]).
pub(crate) fn header<R: Read + Seek + Send + Sync + 'static>(
    mut src: R,
    total: u64,
    path: &Path,
) -> crate::Result<LasHeader> {
    let c = check(&mut src, total).map_err(|what| CloudError::Format {
        path: path.to_path_buf(),
        what,
    })?;
    src.seek(SeekFrom::Start(0))
        .map_err(|source| CloudError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    let src = Patched {
        inner: src,
        pos: 0,
        patch: c.patch,
    };
    without_panics(path, || {
        let reader = las::Reader::new(src).map_err(|e| las_err(path, e, None, &c, total))?;
        let h = reader.header();
        let t = h.transforms();
        let b = h.bounds();
        let georef = Georef {
            crs: las_crs(h),
            las: Some(LasLayout(h.clone())),
            viewpoint: None,
        };
        let mut crs: Vec<(u16, Vec<u8>)> = h
            .all_vlrs()
            .filter(|v| v.user_id == "LASF_Projection")
            .map(|v| (v.record_id, v.data.clone()))
            .collect();
        crs.sort();
        Ok(LasHeader {
            format: version_name(c.compressed, c.major, c.minor),
            points: c.count,
            scale: [t.x.scale, t.y.scale, t.z.scale],
            offset: [t.x.offset, t.y.offset, t.z.offset],
            min: [b.min.x, b.min.y, b.min.z],
            max: [b.max.x, b.max.y, b.max.z],
            crs,
            georef,
        })
    })
}

/// The name of a LAS version, e.g. `"laz 1.4"`.
fn version_name(compressed: bool, major: u8, minor: u8) -> &'static str {
    match (compressed, major, minor) {
        (false, 1, 0) => "las 1.0",
        (false, 1, 1) => "las 1.1",
        (false, 1, 2) => "las 1.2",
        (false, 1, 3) => "las 1.3",
        (false, 1, 4) => "las 1.4",
        (false, _, _) => "las",
        (true, 1, 0) => "laz 1.0",
        (true, 1, 1) => "laz 1.1",
        (true, 1, 2) => "laz 1.2",
        (true, 1, 3) => "laz 1.3",
        (true, 1, 4) => "laz 1.4",
        (true, _, _) => "laz",
    }
}

/// LAS version written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LasVersion {
    /// LAS 1.2, point format 0: read by every LAS tool.
    #[default]
    V1_2,
    /// LAS 1.4, point format 6.
    V1_4,
}

/// Coordinate resolution written (m).
pub const LAS_SCALE_M: f64 = 0.001;

/// Scale and offset of one axis: the offset is the middle of the data
/// rounded to a whole metre, the scale 1 mm unless the extent needs
/// coarser steps to fit LAS's 32-bit integers (then 1 cm, 1 dm, ...; a
/// cloud spanning more than ±2000 km is not a LiDAR scan).
fn transform(lo: f64, hi: f64) -> las::Transform {
    if lo > hi {
        return las::Transform {
            scale: LAS_SCALE_M,
            offset: 0.0,
        };
    }
    let offset = ((lo + hi) / 2.0).round();
    let half = (hi - offset).abs().max((lo - offset).abs());
    let mut scale = LAS_SCALE_M;
    while half / scale > f64::from(i32::MAX - 1) {
        scale *= 10.0;
    }
    las::Transform { scale, offset }
}

/// User ids of the records a LAS writer makes itself (LASzip's) or that
/// describe a layout the copy does not have (COPC's octree): dropped from
/// a header read before it is written again.
const NOT_COPIED: [&str; 2] = ["laszip encoded", "copc"];

/// The header to write `cloud` with: the one it was read with (version,
/// point format, scale, offset, CRS and every other record), or, for a
/// cloud from another format, LAS `version` with a point format holding
/// its columns, 1 mm steps about whole-unit offsets.
fn header_for(
    cloud: &PointCloud,
    lo: [f64; 3],
    hi: [f64; 3],
    version: LasVersion,
) -> Result<las::Builder, String> {
    let Some(layout) = &cloud.georef.las else {
        let mut builder = match version {
            LasVersion::V1_2 => las::Builder::from((1, 2)),
            LasVersion::V1_4 => las::Builder::from((1, 4)),
        };
        let format = format_for(&cloud.attributes, version == LasVersion::V1_4);
        builder.point_format = las::point::Format::new(format).map_err(|e| e.to_string())?;
        builder.generating_software = "autoshovel".into();
        builder.transforms = las::Vector {
            x: transform(lo[0], hi[0]),
            y: transform(lo[1], hi[1]),
            z: transform(lo[2], hi[2]),
        };
        return Ok(builder);
    };
    let mut builder = las::Builder::from(layout.0.clone());
    if builder.point_format.has_waveform {
        return Err(format!(
            "point format {} carries waveform packets, which are not kept: write .pcd or .ply, or convert the file first",
            layout.point_format()
        ));
    }
    builder
        .vlrs
        .retain(|v| !NOT_COPIED.contains(&v.user_id.as_str()));
    builder
        .evlrs
        .retain(|v| !NOT_COPIED.contains(&v.user_id.as_str()));
    // The file's scale is kept; its offset too unless a point moved out
    // of the integers' reach (a levelled cloud), then re-centred.
    let t = &mut builder.transforms;
    for (a, t) in [&mut t.x, &mut t.y, &mut t.z].into_iter().enumerate() {
        if lo[a] <= hi[a] && (t.inverse(lo[a]).is_err() || t.inverse(hi[a]).is_err()) {
            let scale = t.scale;
            *t = transform(lo[a], hi[a]);
            t.scale = t.scale.max(scale);
        }
    }
    Ok(builder)
}

/// Writes `cloud` as LAS (or LAZ when `compressed`) into `w`: its points
/// at `origin + point` in f64, its columns into the point records' fields
/// ([`super::las_columns`]).
pub(crate) fn write<W: Write + Seek + Send + Sync + 'static>(
    w: W,
    cloud: &PointCloud,
    compressed: bool,
    version: LasVersion,
) -> Result<W, String> {
    if let Some((name, len)) = cloud.attributes.mismatch(cloud.len()) {
        return Err(format!(
            "the column {name} has {len} rows for {} points",
            cloud.len()
        ));
    }
    let lost = unwritable(&cloud.attributes);
    if !lost.is_empty() {
        return Err(format!(
            "LAS has no field for the column(s) {}: write .pcd or .ply to keep them",
            lost.join(", ")
        ));
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for i in 0..cloud.len() {
        let p = cloud.world(i);
        for k in 0..3 {
            if !p[k].is_finite() {
                return Err(format!(
                    "LAS cannot store the non-finite coordinate {}",
                    p[k]
                ));
            }
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let mut builder = header_for(cloud, lo, hi, version)?;
    builder.point_format.is_compressed = compressed;
    let format = builder.point_format;
    let header = builder.into_header().map_err(|e| e.to_string())?;
    let rows = LasRows::new(&cloud.attributes, format);
    let mut writer = las::Writer::new(w, header).map_err(|e| e.to_string())?;
    for i in 0..cloud.len() {
        writer
            .write_point(rows.point(i, cloud.world(i)))
            .map_err(|e| e.to_string())?;
    }
    writer.into_inner().map_err(|e| e.to_string())
}
