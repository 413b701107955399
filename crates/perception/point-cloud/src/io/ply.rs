//! PLY (Stanford polygon file format, Greg Turk 1994): a text header of
//! elements and their properties, then the data in ASCII or binary of
//! either byte order. Points are the `vertex` element's x, y, z, of any
//! scalar type (char uchar short ushort int uint float double and the
//! int8 ... float64 spellings); the vertex element's other scalar
//! properties are columns ([`crate::Attributes`]), named as PDAL names its
//! dimensions where PDAL has one (`red` → `Red`, `intensity` →
//! `Intensity`; any case), else as the file names them; other elements
//! (faces with list properties, edges, materials) are read past so that a
//! truncated or inconsistent file is still noticed. Writing, the columns
//! follow x, y, z as properties of their own type (colour as `red`,
//! `green`, `blue`, as viewers read it; an extra-bytes column as one
//! `uchar` a byte, `NAME_0` …).
//!
//! Hand-written rather than taken from the `ply-rs` crate: that crate is
//! unmaintained and has a security advisory, it builds every element into
//! a hash map of properties (several copies of a large scan), and it trusts
//! the header's counts when allocating. Here the header is validated once
//! and the data is streamed into the point vector.

use std::io::{BufRead, Write};

use super::input::{line_str, Input, Points};
use super::scalar::Scalar;
use super::text;
use super::Encoding;

/// Longest header or ASCII data line accepted (bytes).
const MAX_LINE: usize = 1 << 20;
/// Binary vertex data is read in chunks of about this size (bytes).
const CHUNK: usize = 1 << 20;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Body {
    Ascii,
    Little,
    Big,
}

#[derive(Debug, Clone)]
enum Prop {
    Scalar {
        name: String,
        ty: Scalar,
    },
    List {
        name: String,
        count: Scalar,
        item: Scalar,
    },
}

impl Prop {
    fn name(&self) -> &str {
        match self {
            Prop::Scalar { name, .. } | Prop::List { name, .. } => name,
        }
    }
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Prop>,
}

impl Element {
    /// Record size if every property is a scalar.
    fn fixed_size(&self) -> Option<usize> {
        self.props
            .iter()
            .map(|p| match p {
                Prop::Scalar { ty, .. } => Some(ty.size()),
                Prop::List { .. } => None,
            })
            .sum()
    }
}

struct Header {
    body: Body,
    elements: Vec<Element>,
    lines: u64,
}

fn read_header<R: BufRead>(input: &mut Input<'_, R>) -> crate::Result<Header> {
    let mut line = Vec::new();
    if !input.read_line(&mut line, MAX_LINE, 1)? || line.as_slice().trim_ascii() != b"ply" {
        return Err(input.format_err("line 1: a PLY file starts with \"ply\""));
    }
    let mut line_no = 1u64;
    let mut body = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        line_no += 1;
        if !input.read_line(&mut line, MAX_LINE, line_no)? {
            return Err(input.format_err(format!(
                "the header ends at line {line_no} without end_header"
            )));
        }
        let text = line_str(input, &line, line_no)?;
        let w: Vec<&str> = text.split_ascii_whitespace().collect();
        let bad =
            |what: &str| input.format_err(format!("line {line_no}: {what}: {:?}", text.trim()));
        match w.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                if body.is_some() {
                    return Err(bad("a second format line"));
                }
                body = Some(match (w.get(1).copied(), w.get(2).copied()) {
                    (Some("ascii"), Some(v)) if v.starts_with('1') => Body::Ascii,
                    (Some("binary_little_endian"), Some(v)) if v.starts_with('1') => Body::Little,
                    (Some("binary_big_endian"), Some(v)) if v.starts_with('1') => Body::Big,
                    _ => return Err(bad("format must be ascii, binary_little_endian or binary_big_endian, version 1.0")),
                });
            }
            Some("element") => {
                let (Some(name), Some(count), None) = (w.get(1), w.get(2), w.get(3)) else {
                    return Err(bad("expected \"element NAME COUNT\""));
                };
                let count = count
                    .parse::<u64>()
                    .map_err(|_| bad("the element count is not a non-negative integer"))?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return Err(bad("property before any element"));
                };
                let prop = match w[1..] {
                    ["list", c, i, name] => {
                        let count = Scalar::from_ply(c).filter(|s| s.is_integer()).ok_or_else(|| bad("a list count must be an integer type"))?;
                        let item = Scalar::from_ply(i).ok_or_else(|| bad("unknown property type"))?;
                        Prop::List { name: name.to_string(), count, item }
                    }
                    [ty, name] => {
                        let ty = Scalar::from_ply(ty).ok_or_else(|| bad("unknown property type"))?;
                        Prop::Scalar { name: name.to_string(), ty }
                    }
                    _ => return Err(bad("expected \"property TYPE NAME\" or \"property list COUNT_TYPE ITEM_TYPE NAME\"")),
                };
                el.props.push(prop);
            }
            Some("end_header") => break,
            Some(_) => return Err(bad("unknown header line")),
        }
    }
    let body = body.ok_or_else(|| input.format_err("the header has no format line"))?;
    Ok(Header {
        body,
        elements,
        lines: line_no,
    })
}

/// A vertex property's column name: PDAL's where it has one.
fn column_name(ply: &str) -> String {
    crate::attributes::pdal_name(ply)
}

/// A column's PLY property name: colour in lower case, as viewers read it.
fn property_name(column: &str) -> String {
    match column {
        "Red" | "Green" | "Blue" | "Alpha" => column.to_ascii_lowercase(),
        other => other.to_string(),
    }
}

/// The columns being read: each non-coordinate scalar vertex property's
/// index and rows (none while streaming: the points go on without them).
struct Columns {
    cols: Vec<(usize, String, crate::Values)>,
}

impl Columns {
    fn of(el: &Element, axes: &[(usize, Scalar); 3], streaming: bool) -> Self {
        let cols = el
            .props
            .iter()
            .enumerate()
            .filter(|(k, _)| !streaming && !axes.iter().any(|(a, _)| a == k))
            .filter_map(|(k, p)| match p {
                Prop::Scalar { name, ty } => crate::Values::for_pcd(ty.pcd_kind(), ty.size(), 1)
                    .map(|v| (k, column_name(name), v)),
                Prop::List { .. } => None,
            })
            .collect();
        Self { cols }
    }

    /// Hands the columns to `out` (each as long as its points).
    fn finish(self, out: &mut Points<'_>) {
        for (_, name, values) in self.cols {
            out.attributes.insert(name, values);
        }
    }
}

/// Whether coordinates of type `ty` need f64 to keep them: doubles, and
/// integers past f32's 24-bit mantissa.
fn wide_coordinate(ty: Scalar) -> bool {
    matches!(
        ty,
        Scalar::F64 | Scalar::I32 | Scalar::U32 | Scalar::I64 | Scalar::U64
    )
}

/// Keeps one vertex read as f64: about the origin when the file's
/// coordinates are wide, else as the f32 values a float file holds.
fn push_vertex(out: &mut Points<'_>, axes: &[(usize, Scalar); 3], p: [f64; 3]) -> bool {
    if axes.iter().any(|(_, ty)| wide_coordinate(*ty)) {
        out.push_f64(p[0], p[1], p[2])
    } else {
        out.push(p.map(|v| v as f32))
    }
}

/// x, y, z of the vertex element: the property index and type of each.
fn vertex_axes<R: BufRead>(
    input: &Input<'_, R>,
    el: &Element,
) -> crate::Result<[(usize, Scalar); 3]> {
    let mut axes = [None; 3];
    for (k, p) in el.props.iter().enumerate() {
        // Any case: PDAL writes its dimensions X, Y and Z.
        let a = match p.name() {
            "x" | "X" => 0,
            "y" | "Y" => 1,
            "z" | "Z" => 2,
            _ => continue,
        };
        match p {
            Prop::Scalar { ty, .. } => {
                if axes[a].is_none() {
                    axes[a] = Some((k, *ty));
                }
            }
            Prop::List { name, .. } => {
                return Err(input.format_err(format!(
                    "vertex property {name} is a list, not a coordinate"
                )))
            }
        }
    }
    match axes {
        [Some(x), Some(y), Some(z)] => Ok([x, y, z]),
        _ => Err(input.format_err("the vertex element lacks an x, y or z property")),
    }
}

/// Reads a PLY stream into `out`; returns the format's name.
pub(crate) fn read<R: BufRead>(
    input: &mut Input<'_, R>,
    out: &mut Points<'_>,
) -> crate::Result<&'static str> {
    let h = read_header(input)?;
    let vertex = h.elements.iter().position(|e| e.name == "vertex");
    let Some(vertex) = vertex else {
        return Err(input.format_err("no vertex element in the header"));
    };
    let axes = vertex_axes(input, &h.elements[vertex])?;
    // Doubles and wide integers (a georeferenced PLY) are read in f64
    // about an origin; float coordinates stay the f32 values the file holds.
    let wide = axes.iter().any(|(_, ty)| wide_coordinate(*ty));
    out.origin_from_first = wide;
    match h.body {
        Body::Ascii => {
            read_ascii(input, &h, vertex, axes, out)?;
            Ok("ply ascii")
        }
        Body::Little | Body::Big => {
            let big = h.body == Body::Big;
            for (k, el) in h.elements.iter().enumerate() {
                read_binary_element(input, el, big, (k == vertex).then_some((axes, &mut *out)))?;
            }
            if !input.at_eof()? {
                return Err(input.format_err(format!(
                    "{} extra bytes after the last element (from byte {})",
                    input.remaining(),
                    input.pos()
                )));
            }
            Ok(if big {
                "ply binary_big_endian"
            } else {
                "ply binary_little_endian"
            })
        }
    }
}

fn read_binary_element<R: BufRead>(
    input: &mut Input<'_, R>,
    el: &Element,
    big: bool,
    vertex: Option<([(usize, Scalar); 3], &mut Points<'_>)>,
) -> crate::Result<()> {
    if let Some(size) = el.fixed_size() {
        let total = el.count.checked_mul(size as u64).ok_or_else(|| {
            input.format_err(format!(
                "element {}: {} × {size} bytes overflows",
                el.name, el.count
            ))
        })?;
        if total > input.remaining() {
            return Err(input.format_err(format!(
                "element {}: {} instances × {size} bytes need {total} bytes from byte {}, the file has {} (truncated, or the count is wrong)",
                el.name,
                el.count,
                input.pos(),
                input.remaining()
            )));
        }
        let Some((axes, out)) = vertex else {
            return input.skip(total, "an element");
        };
        // Byte offset of each coordinate in the record.
        let offsets: Vec<usize> = el
            .props
            .iter()
            .scan(0usize, |o, p| {
                let at = *o;
                if let Prop::Scalar { ty, .. } = p {
                    *o += ty.size();
                }
                Some(at)
            })
            .collect();
        let at = [offsets[axes[0].0], offsets[axes[1].0], offsets[axes[2].0]];
        let mut columns = Columns::of(el, &axes, out.is_streaming());
        out.reserve_bounded(el.count, input.remaining(), size as u64);
        let per_chunk = (CHUNK / size).max(1) as u64;
        let mut buf = vec![0u8; per_chunk.min(el.count) as usize * size];
        let mut left = el.count;
        while left > 0 {
            let k = left.min(per_chunk) as usize;
            let chunk = &mut buf[..k * size];
            input.read_exact_or(chunk, "vertex data")?;
            for rec in chunk.chunks_exact(size) {
                let get = |a: usize| axes[a].1.to_f64(&rec[at[a]..], big);
                let kept = if out.origin_from_first || out.origin != [0.0; 3] {
                    out.push_f64(get(0), get(1), get(2))
                } else {
                    out.push([
                        axes[0].1.to_f32(&rec[at[0]..], big),
                        axes[1].1.to_f32(&rec[at[1]..], big),
                        axes[2].1.to_f32(&rec[at[2]..], big),
                    ])
                };
                if kept {
                    for (k, _, col) in &mut columns.cols {
                        col.push_bytes(&rec[offsets[*k]..], big);
                    }
                }
            }
            left -= k as u64;
        }
        columns.finish(out);
        return Ok(());
    }
    // Elements with list properties: instance by instance. Every instance
    // holds at least one list count, so the loop ends with the file.
    let mut vertex = vertex;
    let mut columns = None;
    if let Some((axes, out)) = vertex.as_mut() {
        out.reserve_bounded(el.count, input.remaining(), 1);
        columns = Some(Columns::of(el, axes, out.is_streaming()));
    }
    let mut scratch = [0u8; 8];
    // Each scalar property's bytes of the instance, for the columns.
    let mut held = vec![[0u8; 8]; el.props.len()];
    for i in 0..el.count {
        let mut p = [0.0f64; 3];
        for (k, prop) in el.props.iter().enumerate() {
            match prop {
                Prop::Scalar { ty, .. } => {
                    let b = &mut scratch[..ty.size()];
                    input.read_exact_or(b, "element data")?;
                    held[k][..b.len()].copy_from_slice(b);
                    if let Some((axes, _)) = &vertex {
                        for (a, (idx, _)) in axes.iter().enumerate() {
                            if *idx == k {
                                p[a] = ty.to_f64(b, big);
                            }
                        }
                    }
                }
                Prop::List { name, count, item } => {
                    let at = input.pos();
                    let b = &mut scratch[..count.size()];
                    input.read_exact_or(b, "a list length")?;
                    let n = count.to_count(b, big).ok_or_else(|| {
                        input.format_err(format!(
                            "byte {at}: negative list length in {} {i} ({name})",
                            el.name
                        ))
                    })?;
                    let bytes = n.checked_mul(item.size() as u64).ok_or_else(|| {
                        input.format_err(format!("byte {at}: list length {n} overflows"))
                    })?;
                    if bytes > input.remaining() {
                        return Err(input.format_err(format!(
                            "byte {at}: list {name} of {} {i} claims {n} items, more than the file holds",
                            el.name
                        )));
                    }
                    input.skip(bytes, "list items")?;
                }
            }
        }
        if let (Some((axes, out)), Some(columns)) = (vertex.as_mut(), columns.as_mut()) {
            if push_vertex(out, axes, p) {
                for (k, _, col) in &mut columns.cols {
                    col.push_bytes(&held[*k], big);
                }
            }
        }
    }
    if let (Some((_, out)), Some(columns)) = (vertex, columns) {
        columns.finish(out);
    }
    Ok(())
}

fn read_ascii<R: BufRead>(
    input: &mut Input<'_, R>,
    h: &Header,
    vertex: usize,
    axes: [(usize, Scalar); 3],
    out: &mut Points<'_>,
) -> crate::Result<()> {
    let mut line = Vec::new();
    let mut line_no = h.lines;
    for (k, el) in h.elements.iter().enumerate() {
        if el.props.is_empty() {
            continue;
        }
        let is_vertex = k == vertex;
        if is_vertex {
            out.reserve_bounded(el.count, input.remaining(), 2 * el.props.len() as u64);
        }
        let mut columns = Columns::of(el, &axes, !is_vertex || out.is_streaming());
        let mut i = 0u64;
        while i < el.count {
            line_no += 1;
            if !input.read_line(&mut line, MAX_LINE, line_no)? {
                return Err(input.format_err(format!(
                    "the file ends at line {line_no} after {i} of {} {} instances",
                    el.count, el.name
                )));
            }
            let text = line_str(input, &line, line_no)?;
            let mut words = text.split_ascii_whitespace().peekable();
            if words.peek().is_none() {
                continue;
            }
            let mut p = [0.0f64; 3];
            let mut words_of: Vec<&str> = Vec::with_capacity(el.props.len());
            for (pk, prop) in el.props.iter().enumerate() {
                let missing = || {
                    input.format_err(format!(
                        "line {line_no}: {} {i} is missing property {}",
                        el.name,
                        prop.name()
                    ))
                };
                match prop {
                    Prop::Scalar { ty, name } => {
                        let word = words.next().ok_or_else(missing)?;
                        words_of.push(word);
                        let is_axis = is_vertex && axes.iter().any(|(idx, _)| *idx == pk);
                        if is_axis {
                            // A float file's words parse to f32 directly (no
                            // double rounding through f64).
                            let v = if wide_coordinate(*ty) {
                                ty.parse_f64(word)
                            } else {
                                ty.parse_f32(word).map(f64::from)
                            };
                            let v = v.map_err(|why| {
                                input.format_err(format!(
                                    "line {line_no}: {word:?} is not a valid {name} ({why})"
                                ))
                            })?;
                            for (a, (idx, _)) in axes.iter().enumerate() {
                                if *idx == pk {
                                    p[a] = v;
                                }
                            }
                        }
                    }
                    Prop::List { count, name, .. } => {
                        let word = words.next().ok_or_else(missing)?;
                        words_of.push("");
                        let n = count.parse_count(word).ok_or_else(|| {
                            input.format_err(format!(
                                "line {line_no}: list length {word:?} of {name} is not a count"
                            ))
                        })?;
                        for _ in 0..n {
                            words.next().ok_or_else(|| {
                                input.format_err(format!(
                                    "line {line_no}: list {name} has fewer than its {n} items"
                                ))
                            })?;
                        }
                    }
                }
            }
            if words.next().is_some() {
                return Err(input.format_err(format!(
                    "line {line_no}: more values than the {} properties of {}",
                    el.props.len(),
                    el.name
                )));
            }
            if is_vertex && push_vertex(out, &axes, p) {
                for (k, name, col) in &mut columns.cols {
                    col.push_text(&[words_of[*k]]).map_err(|why| {
                        input.format_err(format!("line {line_no}: property {name}: {why}"))
                    })?;
                }
            }
            i += 1;
        }
        columns.finish(out);
    }
    loop {
        line_no += 1;
        if !input.read_line(&mut line, MAX_LINE, line_no)? {
            return Ok(());
        }
        if !line.trim_ascii().is_empty() {
            return Err(input.format_err(format!("line {line_no}: data after the last element")));
        }
    }
}

/// A column's PLY type name; `None` for extra bytes (one `uchar` a byte).
fn ply_type(v: &crate::Values) -> Option<&'static str> {
    use crate::Values as V;
    Some(match v {
        V::U8(_) => "uchar",
        V::I8(_) => "char",
        V::U16(_) => "ushort",
        V::I16(_) => "short",
        V::U32(_) => "uint",
        V::I32(_) => "int",
        V::F32(_) => "float",
        // PLY has no 64-bit integers: double, as PDAL's writer does.
        V::U64(_) | V::I64(_) | V::F64(_) => "double",
        V::Bytes { .. } => return None,
    })
}

/// The header lines of `cloud`'s columns.
fn column_properties(cloud: &crate::PointCloud) -> String {
    let mut out = String::new();
    for c in cloud.attributes.columns() {
        let name = property_name(&c.name);
        match (ply_type(&c.values), &c.values) {
            (Some(ty), _) => out += &format!("property {ty} {name}\n"),
            (None, crate::Values::Bytes { width, .. }) => {
                for k in 0..*width {
                    out += &format!("property uchar {name}_{k}\n");
                }
            }
            (None, _) => {}
        }
    }
    out
}

/// Appends row `i` of column `v` in the byte order asked.
fn column_bytes(v: &crate::Values, i: usize, big: bool, out: &mut Vec<u8>) {
    use crate::Values as V;
    let at = out.len();
    match v {
        V::U64(x) => out.extend_from_slice(&(x[i] as f64).to_le_bytes()),
        V::I64(x) => out.extend_from_slice(&(x[i] as f64).to_le_bytes()),
        other => other.le_bytes_at(i, out),
    }
    if big && !matches!(v, V::Bytes { .. }) {
        out[at..].reverse();
    }
}

/// Writes `cloud` as PLY with one vertex element: float x, y, z about a
/// zero origin; about another, the file's coordinates (origin added) as
/// double x, y, z, as PDAL writes its X, Y and Z; then its columns.
pub(crate) fn write<W: Write>(
    w: &mut W,
    cloud: &crate::PointCloud,
    encoding: Encoding,
) -> std::io::Result<()> {
    let format = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::Binary => "binary_little_endian",
        Encoding::BinaryBigEndian => "binary_big_endian",
        Encoding::BinaryCompressed => {
            return Err(std::io::Error::other("PLY has no compressed encoding"))
        }
    };
    let points = &cloud.points;
    let columns = cloud.attributes.columns();
    let printed = text::Printed::of(cloud);
    let ty = if printed.is_plain() {
        "float"
    } else {
        "double"
    };
    write!(
        w,
        "ply\nformat {format} 1.0\ncomment written by autoshovel\nelement vertex {}\nproperty {ty} x\nproperty {ty} y\nproperty {ty} z\n{}end_header\n",
        points.len(),
        column_properties(cloud)
    )?;
    if encoding == Encoding::Ascii {
        let mut line = Vec::with_capacity(48);
        let mut words = String::new();
        for (i, p) in points.iter().enumerate() {
            printed.fill(p, b' ', &mut line);
            words.clear();
            for c in columns {
                words.push(' ');
                c.values.text_at(i, &mut words);
            }
            line.extend_from_slice(words.as_bytes());
            line.push(b'\n');
            w.write_all(&line)?;
        }
        return Ok(());
    }
    let big = encoding == Encoding::BinaryBigEndian;
    let mut buf = Vec::with_capacity(CHUNK);
    let per_chunk = CHUNK / 24;
    for (k, chunk) in points.chunks(per_chunk).enumerate() {
        buf.clear();
        for (j, p) in chunk.iter().enumerate() {
            let i = k * per_chunk + j;
            if printed.is_plain() {
                for v in p {
                    buf.extend_from_slice(&if big {
                        v.to_be_bytes()
                    } else {
                        v.to_le_bytes()
                    });
                }
            } else {
                for v in cloud.world(i) {
                    buf.extend_from_slice(&if big {
                        v.to_be_bytes()
                    } else {
                        v.to_le_bytes()
                    });
                }
            }
            for c in columns {
                column_bytes(&c.values, i, big, &mut buf);
            }
        }
        w.write_all(&buf)?;
    }
    Ok(())
}
