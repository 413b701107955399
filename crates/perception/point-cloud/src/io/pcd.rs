//! PCD, the Point Cloud Library's format (v0.7, and the 0.6/0.5 headers
//! before it): a text header (`FIELDS`, `SIZE`, `TYPE`, `COUNT`, `WIDTH`,
//! `HEIGHT`, `VIEWPOINT`, `POINTS`, `DATA`) and then the points as ASCII
//! lines, packed little-endian records (`binary`), or LZF-compressed columns
//! (`binary_compressed`: every field of every point, field after field,
//! preceded by the compressed and uncompressed sizes as two `u32`).
//!
//! x, y and z are read from any layout and type (F4, F8 and the I/U
//! integers, converted); every other field (intensity, rgb, normals, `_`
//! padding) is skipped. Reference: PCL's `pcd_io.cpp` and the "PCD file
//! format" tutorial; defaults for old headers follow PCL (a field without
//! SIZE/TYPE/COUNT is a 4-byte float, a missing HEIGHT is 1).

use std::io::{BufRead, Write};

use super::input::{line_str, Input, Points};
use super::lzf;
use super::scalar::Scalar;
use super::Encoding;
use crate::{Point, Values};

/// Longest header or ASCII data line accepted (bytes).
const MAX_LINE: usize = 1 << 20;
/// Largest point record accepted (bytes): far above any real layout
/// (PCL's largest descriptors are ~1.3 kB) and small enough to buffer.
const MAX_POINT_STEP: usize = 1 << 20;
/// Binary data is read in chunks of about this size (bytes).
const CHUNK: usize = 1 << 20;
/// Zero bytes accepted after binary data (bytes). PCL 1.13 sizes its
/// binary files for memory mapping and leaves up to a page of zeros after
/// the data (its own 7-point test file is 4208 bytes); 64 KiB covers the
/// largest page size in use. Anything else after the data is an error.
const MAX_PADDING: u64 = 1 << 16;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Data {
    Ascii,
    Binary,
    BinaryCompressed,
}

#[derive(Debug, Clone)]
struct Field {
    name: String,
    scalar: Scalar,
    count: usize,
}

/// Where x, y and z are in a record.
#[derive(Debug, Clone, Copy)]
struct Axis {
    /// Byte offset in a binary record.
    offset: usize,
    /// Index among the values of an ASCII line.
    value_index: usize,
    /// Index of the field.
    field: usize,
    scalar: Scalar,
}

/// A field besides x, y and z, carried as a column of the cloud.
#[derive(Debug, Clone)]
struct Extra {
    /// Byte offset in a binary record.
    offset: usize,
    /// Index among the values of an ASCII line.
    value_index: usize,
    /// Index of the field.
    field: usize,
    scalar: Scalar,
    count: usize,
}

struct Header {
    fields: Vec<Field>,
    points: u64,
    data: Data,
    axes: [Axis; 3],
    /// The fields carried as columns (one value a point, or bytes).
    extras: Vec<Extra>,
    point_step: usize,
    values_per_point: usize,
    /// Lines read so far (the DATA line is the last one).
    lines: u64,
    /// The sensor pose `VIEWPOINT` states, where not the identity.
    viewpoint: Option<crate::Viewpoint>,
}

fn parse_u64<R: BufRead>(
    input: &Input<'_, R>,
    word: Option<&str>,
    key: &str,
    line_no: u64,
) -> crate::Result<u64> {
    word.and_then(|w| w.parse::<u64>().ok()).ok_or_else(|| {
        input.format_err(format!(
            "line {line_no}: {key} needs a non-negative integer, found {:?}",
            word.unwrap_or("")
        ))
    })
}

fn read_header<R: BufRead>(input: &mut Input<'_, R>) -> crate::Result<Header> {
    let mut line = Vec::new();
    let mut line_no = 0u64;
    let mut names: Option<Vec<String>> = None;
    let mut sizes: Option<(Vec<usize>, u64)> = None;
    let mut types: Option<(Vec<char>, u64)> = None;
    let mut counts: Option<(Vec<usize>, u64)> = None;
    let mut width: Option<u64> = None;
    let mut viewpoint = None;
    let mut height: Option<u64> = None;
    let mut points: Option<u64> = None;
    let data;
    loop {
        line_no += 1;
        if !input.read_line(&mut line, MAX_LINE, line_no)? {
            return Err(input.format_err(format!(
                "the header ends at line {line_no} without a DATA line (not a PCD file, or truncated)"
            )));
        }
        let text = line_str(input, &line, line_no)?;
        let mut words = text.split_ascii_whitespace();
        let Some(key) = words.next() else { continue };
        if key.starts_with('#') {
            continue;
        }
        let rest: Vec<&str> = words.collect();
        let list_len = |got: usize, what: &str| -> crate::Result<()> {
            match &names {
                None => Err(input.format_err(format!("line {line_no}: {what} before FIELDS"))),
                Some(n) if n.len() != got => Err(input.format_err(format!(
                    "line {line_no}: {what} has {got} entries but FIELDS has {}",
                    n.len()
                ))),
                _ => Ok(()),
            }
        };
        match key.to_ascii_uppercase().as_str() {
            "VERSION" => {
                let v = rest.first().copied().unwrap_or("");
                let v = v.strip_prefix('0').unwrap_or(v);
                if !matches!(v, ".7" | ".6" | ".5" | ".7.0") {
                    return Err(input.format_err(format!(
                        "line {line_no}: unsupported PCD VERSION {:?} (0.5, 0.6 and 0.7 are read)",
                        rest.first().copied().unwrap_or("")
                    )));
                }
            }
            "FIELDS" | "COLUMNS" => {
                if rest.is_empty() {
                    return Err(input.format_err(format!("line {line_no}: FIELDS names no field")));
                }
                names = Some(rest.iter().map(|s| s.to_string()).collect());
            }
            "SIZE" => {
                list_len(rest.len(), "SIZE")?;
                let v = rest
                    .iter()
                    .map(|s| {
                        s.parse::<usize>()
                            .ok()
                            .filter(|n| matches!(n, 1 | 2 | 4 | 8))
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| {
                        input.format_err(format!(
                            "line {line_no}: SIZE entries must be 1, 2, 4 or 8: {text:?}"
                        ))
                    })?;
                sizes = Some((v, line_no));
            }
            "TYPE" => {
                list_len(rest.len(), "TYPE")?;
                let v = rest
                    .iter()
                    .map(|s| match *s {
                        "F" | "I" | "U" => s.chars().next(),
                        _ => None,
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| {
                        input.format_err(format!(
                            "line {line_no}: TYPE entries must be F, I or U: {text:?}"
                        ))
                    })?;
                types = Some((v, line_no));
            }
            "COUNT" => {
                list_len(rest.len(), "COUNT")?;
                let v = rest
                    .iter()
                    .map(|s| s.parse::<usize>().ok().filter(|&n| n <= MAX_POINT_STEP))
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| input.format_err(format!("line {line_no}: COUNT entries must be small non-negative integers: {text:?}")))?;
                counts = Some((v, line_no));
            }
            "WIDTH" => width = Some(parse_u64(input, rest.first().copied(), "WIDTH", line_no)?),
            "HEIGHT" => height = Some(parse_u64(input, rest.first().copied(), "HEIGHT", line_no)?),
            "POINTS" => points = Some(parse_u64(input, rest.first().copied(), "POINTS", line_no)?),
            "VIEWPOINT" => {
                let v: Vec<f64> = rest.iter().filter_map(|s| s.parse::<f64>().ok()).collect();
                let Ok(v) = <[f64; 7]>::try_from(v) else {
                    return Err(input.format_err(format!(
                        "line {line_no}: VIEWPOINT needs 7 numbers (tx ty tz qw qx qy qz): {text:?}"
                    )));
                };
                if rest.len() != 7 {
                    return Err(input.format_err(format!(
                        "line {line_no}: VIEWPOINT needs 7 numbers (tx ty tz qw qx qy qz): {text:?}"
                    )));
                }
                viewpoint = crate::Viewpoint::from_pcd(v);
            }
            "DATA" => {
                data = match rest.first().map(|s| s.to_ascii_lowercase()).as_deref() {
                    Some("ascii") => Data::Ascii,
                    Some("binary") => Data::Binary,
                    Some("binary_compressed") => Data::BinaryCompressed,
                    other => {
                        return Err(input.format_err(format!(
                            "line {line_no}: DATA must be ascii, binary or binary_compressed, found {:?}",
                            other.unwrap_or("")
                        )))
                    }
                };
                break;
            }
            _ => {
                return Err(input.format_err(format!(
                    "line {line_no}: unknown PCD header entry {key:?} (not a PCD file?)"
                )))
            }
        }
    }
    let names = names.ok_or_else(|| input.format_err("the header has no FIELDS line"))?;
    let nf = names.len();
    // FIELDS may be repeated after SIZE/TYPE/COUNT: check the lengths again.
    let agree = |len: usize, at: u64, what: &str| -> crate::Result<()> {
        if len == nf {
            Ok(())
        } else {
            Err(input.format_err(format!(
                "line {at}: {what} has {len} entries but FIELDS has {nf}"
            )))
        }
    };
    if let Some((v, at)) = &sizes {
        agree(v.len(), *at, "SIZE")?;
    }
    if let Some((v, at)) = &types {
        agree(v.len(), *at, "TYPE")?;
    }
    if let Some((v, at)) = &counts {
        agree(v.len(), *at, "COUNT")?;
    }
    let sizes = sizes.map(|s| s.0).unwrap_or_else(|| vec![4; nf]);
    let types = types.map(|t| t.0).unwrap_or_else(|| vec!['F'; nf]);
    let counts = counts.map(|c| c.0).unwrap_or_else(|| vec![1; nf]);
    let mut fields = Vec::with_capacity(nf);
    for i in 0..nf {
        let scalar = Scalar::from_pcd(types[i], sizes[i]).ok_or_else(|| {
            input.format_err(format!(
                "field {:?}: TYPE {} with SIZE {} is not a known type (F4, F8, I1..I8, U1..U8)",
                names[i], types[i], sizes[i]
            ))
        })?;
        fields.push(Field {
            name: names[i].clone(),
            scalar,
            count: counts[i],
        });
    }
    // Layout.
    let mut offset = 0usize;
    let mut value_index = 0usize;
    let mut axes: [Option<Axis>; 3] = [None; 3];
    let mut extras = Vec::new();
    for (k, f) in fields.iter().enumerate() {
        // Any case: PDAL writes its dimensions X, Y and Z.
        let axis = match f.name.as_str() {
            "x" | "X" => Some(0),
            "y" | "Y" => Some(1),
            "z" | "Z" => Some(2),
            _ => None,
        };
        if let Some(a) = axis {
            if f.count == 0 {
                return Err(input.format_err(format!("field {} has COUNT 0", f.name)));
            }
            if axes[a].is_none() {
                axes[a] = Some(Axis {
                    offset,
                    value_index,
                    field: k,
                    scalar: f.scalar,
                });
            }
        } else if f.name != "_" && column_for(f.scalar, f.count).is_some() {
            // PCL's "_" is padding; a field of several non-byte values (a
            // descriptor's histogram) has no column and is skipped.
            extras.push(Extra {
                offset,
                value_index,
                field: k,
                scalar: f.scalar,
                count: f.count,
            });
        }
        offset = f
            .scalar
            .size()
            .checked_mul(f.count)
            .and_then(|b| b.checked_add(offset))
            .filter(|&s| s <= MAX_POINT_STEP)
            .ok_or_else(|| {
                input.format_err(format!(
                    "a point record is larger than {MAX_POINT_STEP} bytes (SIZE × COUNT)"
                ))
            })?;
        value_index += f.count;
    }
    let [Some(x), Some(y), Some(z)] = axes else {
        return Err(input.format_err(format!(
            "no x, y and z among the FIELDS {:?}",
            fields.iter().map(|f| f.name.as_str()).collect::<Vec<_>>()
        )));
    };
    let height = height.unwrap_or(1);
    let n = match (points, width) {
        (Some(p), Some(w)) => {
            let wh = w.checked_mul(height);
            if wh != Some(p) {
                return Err(input.format_err(format!(
                    "POINTS {p} disagrees with WIDTH × HEIGHT = {w} × {height}"
                )));
            }
            p
        }
        (Some(p), None) => p,
        (None, Some(w)) => w.checked_mul(height).ok_or_else(|| {
            input.format_err(format!("WIDTH × HEIGHT = {w} × {height} overflows"))
        })?,
        (None, None) => return Err(input.format_err("the header has neither POINTS nor WIDTH")),
    };
    Ok(Header {
        fields,
        points: n,
        data,
        axes: [x, y, z],
        extras,
        point_step: offset,
        values_per_point: value_index,
        lines: line_no,
        viewpoint,
    })
}

/// Reads a PCD stream into `out`; returns the format's name.
pub(crate) fn read<R: BufRead>(
    input: &mut Input<'_, R>,
    out: &mut Points<'_>,
) -> crate::Result<&'static str> {
    let h = read_header(input)?;
    out.origin_from_first = true;
    out.viewpoint = h.viewpoint;
    let mut cols: Vec<Values> = h
        .extras
        .iter()
        .filter_map(|e| column_for(e.scalar, e.count))
        .collect();
    let name = match h.data {
        Data::Ascii => read_ascii(input, &h, out, &mut cols).map(|()| "pcd ascii"),
        Data::Binary => read_binary(input, &h, out, &mut cols).map(|()| "pcd binary"),
        Data::BinaryCompressed => {
            read_compressed(input, &h, out, &mut cols).map(|()| "pcd binary_compressed")
        }
    }?;
    for (e, values) in h.extras.iter().zip(cols) {
        out.attributes
            .insert(h.fields[e.field].name.clone(), values);
    }
    Ok(name)
}

/// An empty column for a field of `count` values of `scalar` (bytes may
/// be several a point; other types one).
fn column_for(scalar: Scalar, count: usize) -> Option<Values> {
    Values::for_pcd(scalar.pcd_kind(), scalar.size(), count)
}

fn read_ascii<R: BufRead>(
    input: &mut Input<'_, R>,
    h: &Header,
    out: &mut Points<'_>,
    cols: &mut [Values],
) -> crate::Result<()> {
    // At least "0 " per value.
    out.reserve_bounded(h.points, input.remaining(), 2 * h.values_per_point as u64);
    let all_f32 = h.axes.iter().all(|a| a.scalar == Scalar::F32);
    let mut line = Vec::new();
    let mut line_no = h.lines;
    let mut done = 0u64;
    loop {
        line_no += 1;
        if !input.read_line(&mut line, MAX_LINE, line_no)? {
            break;
        }
        let text = line_str(input, &line, line_no)?;
        if text.trim().is_empty() {
            continue;
        }
        if done == h.points {
            return Err(input.format_err(format!(
                "line {line_no}: more data than the header's POINTS {}",
                h.points
            )));
        }
        // F4 coordinates are the f32 values the file holds, read as
        // before; any other type (F8, integers) at its own precision (f64),
        // so a survey's northings keep their digits about the origin.
        let mut p = [0.0_f64; 3];
        let words: Vec<&str> = text.split_ascii_whitespace().collect();
        for (i, word) in words.iter().enumerate() {
            for (a, axis) in h.axes.iter().enumerate() {
                if axis.value_index == i {
                    let v = if all_f32 {
                        axis.scalar.parse_f32(word).map(f64::from)
                    } else {
                        axis.scalar.parse_f64(word)
                    };
                    p[a] = v.map_err(|why| {
                        input.format_err(format!(
                            "line {line_no}: {:?} is not a valid {} value ({why})",
                            word, h.fields[axis.field].name
                        ))
                    })?;
                }
            }
        }
        let found = words.len();
        if found != h.values_per_point {
            return Err(input.format_err(format!(
                "line {line_no}: {found} values, the header's fields make {} per point",
                h.values_per_point
            )));
        }
        let kept = if all_f32 {
            out.push(p.map(|v| v as f32))
        } else {
            out.push_f64(p[0], p[1], p[2])
        };
        if kept {
            for (e, col) in h.extras.iter().zip(cols.iter_mut()) {
                col.push_text(&words[e.value_index..e.value_index + e.count])
                    .map_err(|why| {
                        input.format_err(format!(
                            "line {line_no}: field {}: {why}",
                            h.fields[e.field].name
                        ))
                    })?;
            }
        }
        done += 1;
    }
    if done != h.points {
        return Err(input.format_err(format!(
            "the file ends at line {line_no} after {done} of the header's {} points",
            h.points
        )));
    }
    Ok(())
}

/// Checks that `need` bytes follow, and at most [`MAX_PADDING`] more;
/// returns how many more.
fn check_data_size<R: BufRead>(
    input: &Input<'_, R>,
    need: Option<u64>,
    h: &Header,
    what: &str,
) -> crate::Result<u64> {
    let need = need.ok_or_else(|| {
        input.format_err(format!(
            "POINTS {} × {} bytes per point overflows",
            h.points, h.point_step
        ))
    })?;
    let left = input.remaining();
    if left < need {
        return Err(input.format_err(format!(
            "{what}: the header's {} points × {} bytes need {need} bytes from byte {}, the file has {left} (truncated, or POINTS is wrong)",
            h.points,
            h.point_step,
            input.pos()
        )));
    }
    if left - need > MAX_PADDING {
        return Err(input.format_err(format!(
            "{what}: {} extra bytes after the header's {} points (from byte {}; POINTS is wrong?)",
            left - need,
            h.points,
            input.pos() + need
        )));
    }
    Ok(left - need)
}

/// Reads the `extra` bytes after the data, which must be zero padding.
fn check_padding<R: BufRead>(input: &mut Input<'_, R>, extra: u64) -> crate::Result<()> {
    let at = input.pos();
    let mut buf = vec![0u8; extra as usize];
    input.read_exact_or(&mut buf, "the padding after the data")?;
    if let Some(i) = buf.iter().position(|&b| b != 0) {
        return Err(input.format_err(format!(
            "{extra} extra bytes after the last point (from byte {at}) are not zero padding (byte {} is {:#04x}; POINTS is wrong?)",
            at + i as u64,
            buf[i]
        )));
    }
    if !input.at_eof()? {
        return Err(input.format_err(format!(
            "data continues past byte {}, the size given at the start",
            input.pos()
        )));
    }
    Ok(())
}

fn read_binary<R: BufRead>(
    input: &mut Input<'_, R>,
    h: &Header,
    out: &mut Points<'_>,
    cols: &mut [Values],
) -> crate::Result<()> {
    let step = h.point_step;
    let extra = check_data_size(input, h.points.checked_mul(step as u64), h, "binary data")?;
    // The data is there: reserving the count is safe now.
    out.reserve_bounded(h.points, input.remaining(), step as u64);
    let per_chunk = (CHUNK / step.max(1)).max(1) as u64;
    let all_f32 = h.axes.iter().all(|a| a.scalar == Scalar::F32);
    let [ox, oy, oz] = [h.axes[0].offset, h.axes[1].offset, h.axes[2].offset];
    if all_f32 && step == 12 && [ox, oy, oz] == [0, 4, 8] && cfg!(target_endian = "little") {
        // Fields x y z as f32 and nothing else (a sensor's frames, PCL's
        // PointXYZ): the records are the points' own bytes, read straight
        // into their memory (no buffer, no copy, no per-value decoding).
        let mut left = h.points;
        while left > 0 {
            let k = left.min(per_chunk) as usize;
            let base = out.points.len();
            out.points.resize(base + k, [0.0; 3]);
            input.read_exact_or(
                points_as_bytes(&mut out.points[base..]),
                "binary point data",
            )?;
            out.keep_finite_from(base);
            left -= k as u64;
        }
        return check_padding(input, extra);
    }
    let mut buf = vec![0u8; (per_chunk.min(h.points) as usize) * step];
    let mut left = h.points;
    while left > 0 {
        let k = left.min(per_chunk) as usize;
        let chunk = &mut buf[..k * step];
        input.read_exact_or(chunk, "binary point data")?;
        for rec in chunk.chunks_exact(step) {
            let kept = if all_f32 {
                out.push([f32le(&rec[ox..]), f32le(&rec[oy..]), f32le(&rec[oz..])])
            } else {
                // Doubles (PDAL writes X Y Z as F8) about the origin.
                out.push_f64(
                    h.axes[0].scalar.to_f64(&rec[ox..], false),
                    h.axes[1].scalar.to_f64(&rec[oy..], false),
                    h.axes[2].scalar.to_f64(&rec[oz..], false),
                )
            };
            if kept {
                for (e, col) in h.extras.iter().zip(cols.iter_mut()) {
                    col.push_bytes(&rec[e.offset..], false);
                }
            }
        }
        left -= k as u64;
    }
    check_padding(input, extra)
}

/// The bytes of `points`, as a little-endian file lays out x y z as f32.
fn points_as_bytes(points: &mut [Point]) -> &mut [u8] {
    // `[f32; 3]` is plain data: no padding, every bit pattern an f32.
    bytemuck::cast_slice_mut(points)
}

#[inline]
fn f32le(b: &[u8]) -> f32 {
    f32::from_le_bytes([b[0], b[1], b[2], b[3]])
}

fn read_compressed<R: BufRead>(
    input: &mut Input<'_, R>,
    h: &Header,
    out: &mut Points<'_>,
    cols: &mut [Values],
) -> crate::Result<()> {
    let at = input.pos();
    let mut sizes = [0u8; 8];
    input.read_exact_or(&mut sizes, "the binary_compressed sizes")?;
    let compressed = u64::from(u32::from_le_bytes([sizes[0], sizes[1], sizes[2], sizes[3]]));
    let uncompressed = u64::from(u32::from_le_bytes([sizes[4], sizes[5], sizes[6], sizes[7]]));
    let need = h.points.checked_mul(h.point_step as u64);
    if need != Some(uncompressed) {
        return Err(input.format_err(format!(
            "byte {at}: uncompressed size {uncompressed} disagrees with the header's {} points × {} bytes",
            h.points, h.point_step
        )));
    }
    let left = input.remaining();
    if compressed > left {
        return Err(input.format_err(format!(
            "byte {at}: compressed size {compressed} but only {left} bytes follow (truncated?)"
        )));
    }
    if left - compressed > MAX_PADDING {
        return Err(input.format_err(format!(
            "{} extra bytes after the {compressed} bytes of compressed data (from byte {})",
            left - compressed,
            input.pos() + compressed
        )));
    }
    if uncompressed > compressed.saturating_mul(lzf::MAX_RATIO) {
        return Err(input.format_err(format!(
            "byte {at}: {compressed} bytes of LZF cannot expand to the announced {uncompressed} bytes"
        )));
    }
    // Column-major: field k of every point, then field k + 1. The points
    // are allocated now (x, y and z arrive in separate columns); their
    // number is bounded by the compressed size times LZF's largest ratio.
    let n = usize::try_from(h.points)
        .map_err(|_| input.format_err("too many points for this machine"))?;
    // Coordinates other than f32 (PDAL's F8) are gathered as raw columns
    // and read in f64 about the origin, as the other encodings read them.
    let doubles = h.axes.iter().any(|a| a.scalar != Scalar::F32);
    let mut points: Vec<Point> = vec![[0.0; 3]; if doubles { 0 } else { n }];
    let mut column_start = 0u64;
    let mut axis_cols = Vec::with_capacity(3);
    for (k, f) in h.fields.iter().enumerate() {
        let stride = (f.scalar.size() * f.count) as u64;
        for (a, axis) in h.axes.iter().enumerate() {
            if axis.field == k {
                axis_cols.push(Column {
                    axis: a,
                    start: column_start,
                    stride,
                    scalar: axis.scalar,
                    partial: [0; 8],
                });
            }
        }
        column_start += stride * h.points;
    }
    // The other fields' columns, their bytes gathered as they stream by.
    let starts: Vec<u64> = h
        .fields
        .iter()
        .scan(0u64, |at, f| {
            let s = *at;
            *at += (f.scalar.size() * f.count) as u64 * h.points;
            Some(s)
        })
        .collect();
    let wanted = h
        .extras
        .iter()
        .map(|e| (e.field, e.scalar.size() * e.count))
        .chain(
            h.axes
                .iter()
                .filter(|_| doubles)
                .map(|a| (a.field, a.scalar.size())),
        );
    let mut raw: Vec<(u64, u64, Vec<u8>)> = wanted
        .map(|(field, width)| {
            let len = width as u64 * h.points;
            (starts[field], len, Vec::with_capacity(len as usize))
        })
        .collect();
    if doubles {
        axis_cols.clear();
    }
    lzf::decompress_stream(input, compressed, uncompressed, &mut |offset, bytes| {
        for c in axis_cols.iter_mut() {
            c.take(offset, bytes, &mut points);
        }
        let end = offset + bytes.len() as u64;
        for (start, len, buf) in raw.iter_mut() {
            let want_end = *start + *len;
            let (lo, hi) = ((*start + buf.len() as u64).max(offset), want_end.min(end));
            if lo < hi {
                buf.extend_from_slice(&bytes[(lo - offset) as usize..(hi - offset) as usize]);
            }
        }
    })?;
    check_padding(input, left - compressed)?;
    if doubles {
        let axes = &raw[h.extras.len()..];
        for i in 0..n {
            let v = |a: usize| {
                let size = h.axes[a].scalar.size();
                h.axes[a].scalar.to_f64(&axes[a].2[i * size..], false)
            };
            if out.push_f64(v(0), v(1), v(2)) {
                for ((e, col), (_, _, buf)) in h.extras.iter().zip(cols.iter_mut()).zip(&raw) {
                    let w = e.scalar.size() * e.count;
                    col.push_bytes(&buf[i * w..(i + 1) * w], false);
                }
            }
        }
        return Ok(());
    }
    let finite: Vec<bool> = points
        .iter()
        .map(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    for ((e, col), (_, _, buf)) in h.extras.iter().zip(cols.iter_mut()).zip(&raw) {
        let w = e.scalar.size() * e.count;
        for (i, _) in finite.iter().enumerate().filter(|(_, &f)| f) {
            col.push_bytes(&buf[i * w..(i + 1) * w], false);
        }
    }
    let before = points.len();
    points.retain(|p| p.iter().all(|v| v.is_finite()));
    out.non_finite += before - points.len();
    if out.points.is_empty() {
        out.points = points;
    } else {
        out.points.extend_from_slice(&points);
    }
    Ok(())
}

/// One coordinate column of a binary_compressed PCD.
struct Column {
    axis: usize,
    start: u64,
    stride: u64,
    scalar: Scalar,
    /// Bytes of a value split across two output blocks.
    partial: [u8; 8],
}

impl Column {
    /// Takes the bytes of this column's values out of the output block
    /// `bytes` that starts at uncompressed offset `offset`.
    fn take(&mut self, offset: u64, bytes: &[u8], points: &mut [Point]) {
        let size = self.scalar.size() as u64;
        let end = offset + bytes.len() as u64;
        let n = points.len() as u64;
        let col_end = self.start + self.stride * n;
        if end <= self.start || offset >= col_end {
            return;
        }
        // First point whose value may overlap the block.
        let mut i = offset.saturating_sub(self.start) / self.stride;
        while i < n {
            let v0 = self.start + i * self.stride;
            if v0 >= end {
                break;
            }
            let v1 = v0 + size;
            if v1 > offset {
                let lo = v0.max(offset);
                let hi = v1.min(end);
                let src = &bytes[(lo - offset) as usize..(hi - offset) as usize];
                let dst = (lo - v0) as usize;
                self.partial[dst..dst + src.len()].copy_from_slice(src);
                if hi == v1 {
                    points[i as usize][self.axis] = self.scalar.to_f32(&self.partial, false);
                }
            }
            i += 1;
        }
    }
}

/// Writes `cloud` as PCD in the given encoding: fields x y z as F4 for a
/// cloud about a zero origin with no attributes (a sensor's frame, PCL's
/// PointXYZ, bit for bit), otherwise [`write_fields`].
///
/// binary_compressed builds the column-major buffer (12 bytes a point) and
/// its LZF image in memory, as PCL does: the sizes precede the data, and
/// LZF compresses one block. Use binary for clouds near the format's
/// 4 GiB uncompressed limit.
pub(crate) fn write_cloud<W: Write>(
    w: &mut W,
    cloud: &crate::PointCloud,
    encoding: Encoding,
) -> std::io::Result<()> {
    if cloud.origin == [0.0; 3] && cloud.attributes.is_empty() && cloud.georef.viewpoint.is_none() {
        write(w, &cloud.points, encoding)
    } else {
        write_fields(w, cloud, encoding)
    }
}

/// A cloud about an origin, or with attributes, as PCD: x y z as F8 (the
/// file's coordinates, origin added, as PDAL writes them) when the origin
/// is not zero, then every column as a field of its own type (bytes as a
/// U1 field of COUNT their width), and the sensor pose read, if any, as
/// VIEWPOINT.
fn write_fields<W: Write>(
    w: &mut W,
    cloud: &crate::PointCloud,
    encoding: Encoding,
) -> std::io::Result<()> {
    let data = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::Binary => "binary",
        Encoding::BinaryCompressed => "binary_compressed",
        Encoding::BinaryBigEndian => {
            return Err(std::io::Error::other("PCD has no big-endian encoding"))
        }
    };
    if let Some((name, len)) = cloud.attributes.mismatch(cloud.len()) {
        return Err(std::io::Error::other(format!(
            "the column {name} has {len} rows for {} points",
            cloud.len()
        )));
    }
    let wide = cloud.origin != [0.0; 3];
    let xyz = if wide { ('F', 8) } else { ('F', 4) };
    let cols = cloud.attributes.columns();
    let mut names = vec!["x".to_string(), "y".into(), "z".into()];
    let mut types = vec![xyz; 3];
    let mut counts = vec![1usize; 3];
    for c in cols {
        let (k, size, count) = c.values.pcd_type();
        names.push(c.name.replace(char::is_whitespace, "_"));
        types.push((k, size));
        counts.push(count);
    }
    let join = |v: Vec<String>| v.join(" ");
    let n = cloud.len();
    let viewpoint = cloud
        .georef
        .viewpoint
        .unwrap_or(crate::Viewpoint::IDENTITY)
        .pcd_words();
    write!(
        w,
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {}\nSIZE {}\nTYPE {}\nCOUNT {}\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT {viewpoint}\nPOINTS {n}\nDATA {data}\n",
        join(names),
        join(types.iter().map(|t| t.1.to_string()).collect()),
        join(types.iter().map(|t| t.0.to_string()).collect()),
        join(counts.iter().map(|c| c.to_string()).collect()),
    )?;
    // One value of field `f` of row `i` as bytes or text.
    let coord = |i: usize, a: usize| cloud.origin[a] + f64::from(cloud.points[i][a]);
    let bytes = |i: usize, f: usize, out: &mut Vec<u8>| match f {
        0..=2 if wide => out.extend_from_slice(&coord(i, f).to_le_bytes()),
        0..=2 => out.extend_from_slice(&cloud.points[i][f].to_le_bytes()),
        _ => cols[f - 3].values.le_bytes_at(i, out),
    };
    let fields = 3 + cols.len();
    match encoding {
        Encoding::Ascii => {
            let mut line = String::new();
            for i in 0..n {
                line.clear();
                for f in 0..fields {
                    if f > 0 {
                        line.push(' ');
                    }
                    match f {
                        0..=2 if wide => line.push_str(&format!("{:?}", coord(i, f))),
                        0..=2 => line.push_str(&format!("{:?}", cloud.points[i][f])),
                        _ => cols[f - 3].values.text_at(i, &mut line),
                    }
                }
                line.push('\n');
                w.write_all(line.as_bytes())?;
            }
        }
        Encoding::Binary => {
            let mut buf = Vec::with_capacity(CHUNK);
            for i in 0..n {
                for f in 0..fields {
                    bytes(i, f, &mut buf);
                }
                if buf.len() >= CHUNK {
                    w.write_all(&buf)?;
                    buf.clear();
                }
            }
            w.write_all(&buf)?;
        }
        Encoding::BinaryCompressed => {
            let mut columns = Vec::new();
            for f in 0..fields {
                for i in 0..n {
                    bytes(i, f, &mut columns);
                }
            }
            write_lzf(w, &columns)?;
        }
        Encoding::BinaryBigEndian => {}
    }
    Ok(())
}

/// The data of a binary_compressed PCD: the compressed and uncompressed
/// sizes, then the LZF image of the column-major `columns`.
fn write_lzf<W: Write>(w: &mut W, columns: &[u8]) -> std::io::Result<()> {
    let packed = lzf::compress(columns);
    let (Ok(c), Ok(u)) = (u32::try_from(packed.len()), u32::try_from(columns.len())) else {
        return Err(std::io::Error::other(
            "binary_compressed PCD holds at most 4 GiB of uncompressed data (357 913 941 x y z points); use binary",
        ));
    };
    w.write_all(&c.to_le_bytes())?;
    w.write_all(&u.to_le_bytes())?;
    w.write_all(&packed)
}

/// Writes `points` as PCD (fields x y z, F4) in the given encoding.
pub(crate) fn write<W: Write>(
    w: &mut W,
    points: &[Point],
    encoding: Encoding,
) -> std::io::Result<()> {
    let data = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::Binary => "binary",
        Encoding::BinaryCompressed => "binary_compressed",
        Encoding::BinaryBigEndian => {
            return Err(std::io::Error::other("PCD has no big-endian encoding"))
        }
    };
    let n = points.len();
    write!(
        w,
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n"
    )?;
    match encoding {
        Encoding::Ascii => {
            let mut line = Vec::new();
            for p in points {
                super::text::write_point(w, p, b' ', &mut line)?;
            }
        }
        Encoding::Binary => {
            let mut buf = Vec::with_capacity(CHUNK);
            for chunk in points.chunks(CHUNK / 12) {
                buf.clear();
                for p in chunk {
                    for v in p {
                        buf.extend_from_slice(&v.to_le_bytes());
                    }
                }
                w.write_all(&buf)?;
            }
        }
        Encoding::BinaryCompressed => {
            let mut columns = Vec::with_capacity(12 * n);
            for a in 0..3 {
                for p in points {
                    columns.extend_from_slice(&p[a].to_le_bytes());
                }
            }
            write_lzf(w, &columns)?;
        }
        Encoding::BinaryBigEndian => {}
    }
    Ok(())
}
