//! Reading any supported file: dispatch on the extension (or a given
//! [`Format`]), progress, and the report.

use std::fmt;
use std::fs::File;
use std::io::{BufRead, BufReader, Cursor};
use std::path::{Path, PathBuf};

use super::input::{Input, Points};
use super::las::{self, LasHeader};
use super::{pcd, ply, xyz, Format};
use crate::{CloudError, PointCloud};

/// Buffer size of file readers (bytes).
const BUFFER: usize = 1 << 20;

/// What [`read`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadReport {
    /// The finite points, in file order.
    pub cloud: PointCloud,
    /// Points dropped because a coordinate was NaN or infinite.
    pub non_finite_dropped: usize,
    /// Columns a text file's header names besides x, y and z (ignored).
    pub ignored_columns: usize,
    /// The format and encoding read, e.g. `"pcd binary_compressed"`,
    /// `"ply binary_big_endian"`, `"laz 1.4"`, `"csv"`.
    pub format: &'static str,
}

impl ReadReport {
    /// Whether no point was kept: valid to read, the caller decides
    /// whether an empty cloud is an error.
    pub fn is_empty(&self) -> bool {
        self.cloud.is_empty()
    }
}

impl fmt::Display for ReadReport {
    /// E.g. `"12345 points (pcd binary), 3 non-finite dropped"` or
    /// `"empty cloud (ply ascii)"`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.cloud.is_empty() {
            write!(f, "empty cloud ({})", self.format)?;
        } else {
            write!(f, "{} points ({})", self.cloud.len(), self.format)?;
        }
        if self.non_finite_dropped > 0 {
            write!(f, ", {} non-finite dropped", self.non_finite_dropped)?;
        }
        Ok(())
    }
}

/// Reads the point cloud in `path`, the format chosen by the extension
/// (`.pcd .ply .las .laz .xyz .csv .txt`, any case).
///
/// `progress(bytes_done, bytes_total)` is called at the start, about every
/// MiB, and at the end, so a caller can draw a bar. Non-finite points are
/// dropped and counted. Every damaged or inconsistent file gives
/// [`CloudError::Format`] naming the line or byte offset; nothing a header
/// merely claims is allocated.
pub fn read(path: &Path, progress: &mut dyn FnMut(u64, u64)) -> crate::Result<ReadReport> {
    let format = Format::from_path(path)?;
    let (file, total) = open(path)?;
    let mut out = Points::default();
    let got = match format {
        Format::Las | Format::Laz => las::read(
            BufReader::with_capacity(BUFFER, file),
            total,
            path,
            progress,
            &mut out,
        )?,
        _ => {
            let mut input = Input::new(
                BufReader::with_capacity(BUFFER, file),
                total,
                path,
                progress,
            );
            plain(read_text_or_binary(format, &mut input, &mut out)?)
        }
    };
    Ok(report(out, got))
}

/// What a reader without attributes or georeference found.
fn plain(name: &'static str) -> las::LasRead {
    las::LasRead {
        name,
        georef: Default::default(),
        attributes: Default::default(),
    }
}

/// What [`read_chunks`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StreamReport {
    /// Finite points handed on.
    pub points: u64,
    /// Points dropped because a coordinate was NaN or infinite.
    pub non_finite_dropped: usize,
    /// The format and encoding read, as [`ReadReport::format`].
    pub format: &'static str,
}

/// Reads `path` as [`read`] does, handing the finite points on in file
/// order, at most `chunk` at a time, to `on_chunk`, whose error stops the
/// read. LAS and LAZ are decoded point by point, so memory stays at one
/// chunk whatever the file's size (a survey of 100 M points); the other
/// formats are read whole first, then handed on. Points come less
/// `origin`, subtracted in f64 before the coordinates become f32: a survey
/// in UTM metres (northings of millions, where f32 steps by 0.5 m) keeps
/// millimetres near an origin of its own. `[0.0; 3]` gives [`read`]'s points.
pub fn read_chunks(
    path: &Path,
    origin: [f64; 3],
    chunk: usize,
    progress: &mut dyn FnMut(u64, u64),
    on_chunk: &mut dyn FnMut(&[crate::Point]) -> crate::Result<()>,
) -> crate::Result<StreamReport> {
    read_chunks_with(path, origin, chunk, false, progress, &mut |points, _| {
        on_chunk(points)
    })
}

/// The receiver of [`read_chunks_with`]'s chunks: the points, and their
/// LAS rows (empty unless asked for); its error stops the read.
pub type ChunkSink<'a> = &'a mut dyn FnMut(&[crate::Point], &[u8]) -> crate::Result<()>;

/// [`read_chunks`], handing on with each chunk, when `rows` is set, every
/// point's LAS record as the file's point format lays it out
/// ([`crate::LasLayout::record_len`] bytes a point, x, y and z included;
/// [`crate::LasLayout::attributes_of_rows`] makes them columns): a
/// survey's attributes travel beside its points without being decoded into
/// columns on the way. Rows are empty without `rows`, and for formats
/// other than LAS and LAZ.
pub fn read_chunks_with(
    path: &Path,
    origin: [f64; 3],
    chunk: usize,
    rows: bool,
    progress: &mut dyn FnMut(u64, u64),
    on_chunk: ChunkSink<'_>,
) -> crate::Result<StreamReport> {
    let format = Format::from_path(path)?;
    if !matches!(format, Format::Las | Format::Laz) {
        let mut r = read(path, progress)?;
        if origin != [0.0; 3] {
            for p in &mut r.cloud.points {
                *p = [0, 1, 2].map(|a| (f64::from(p[a]) - origin[a]) as f32);
            }
        }
        for c in r.cloud.points.chunks(chunk.max(1)) {
            on_chunk(c, &[])?;
        }
        return Ok(StreamReport {
            points: r.cloud.len() as u64,
            non_finite_dropped: r.non_finite_dropped,
            format: r.format,
        });
    }
    let (file, total) = open(path)?;
    let mut out = Points::streaming(chunk, on_chunk);
    out.origin = origin;
    out.rows = rows.then(Vec::new);
    let got = las::read(
        BufReader::with_capacity(BUFFER, file),
        total,
        path,
        progress,
        &mut out,
    )?;
    Ok(StreamReport {
        points: out.streamed,
        non_finite_dropped: out.non_finite,
        format: got.name,
    })
}

/// The header of the LAS or LAZ file `path` (its count, scale, offset,
/// bounds and coordinate system), checked as [`read`] checks it; no point
/// is decoded.
pub fn las_header(path: &Path) -> crate::Result<LasHeader> {
    match Format::from_path(path)? {
        Format::Las | Format::Laz => {
            let (file, total) = open(path)?;
            las::header(BufReader::with_capacity(1 << 16, file), total, path)
        }
        f => Err(CloudError::Format {
            path: path.to_path_buf(),
            what: format!("not a LAS or LAZ file (a .{} file)", f.extension()),
        }),
    }
}

/// Opens `path` and reads its size.
fn open(path: &Path) -> crate::Result<(File, u64)> {
    let io = |source| CloudError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = File::open(path).map_err(io)?;
    let total = file.metadata().map_err(io)?.len();
    Ok((file, total))
}

/// Reads a cloud from memory, through the same readers as [`read`]
/// (fuzzing, embedded test data, network buffers). Errors name the file
/// as `<memory>.EXT`.
pub fn read_from_bytes(format: Format, bytes: &[u8]) -> crate::Result<ReadReport> {
    let path = PathBuf::from(format!("<memory>.{}", format.extension()));
    let mut progress = |_: u64, _: u64| {};
    let total = bytes.len() as u64;
    let mut out = Points::default();
    let got = match format {
        // `las` wants an owned, seekable source.
        Format::Las | Format::Laz => las::read(
            Cursor::new(bytes.to_vec()),
            total,
            &path,
            &mut progress,
            &mut out,
        )?,
        _ => {
            let mut input = Input::new(bytes, total, &path, &mut progress);
            plain(read_text_or_binary(format, &mut input, &mut out)?)
        }
    };
    Ok(report(out, got))
}

fn read_text_or_binary<R: BufRead>(
    format: Format,
    input: &mut Input<'_, R>,
    out: &mut Points<'_>,
) -> crate::Result<&'static str> {
    let name = match format {
        Format::Pcd => pcd::read(input, out)?,
        Format::Ply => ply::read(input, out)?,
        Format::Xyz | Format::Txt | Format::Csv => {
            xyz::read(input, out)?;
            match format {
                Format::Csv => "csv",
                Format::Txt => "txt",
                _ => "xyz",
            }
        }
        Format::Las | Format::Laz => unreachable!("handled by the callers"),
    };
    input.finish();
    Ok(name)
}

fn report(out: Points<'_>, got: las::LasRead) -> ReadReport {
    let mut points = out.points;
    points.shrink_to_fit();
    ReadReport {
        cloud: PointCloud {
            points,
            origin: out.origin,
            attributes: if got.attributes.is_empty() {
                out.attributes
            } else {
                got.attributes
            },
            georef: crate::Georef {
                viewpoint: out.viewpoint,
                ..got.georef
            },
        },
        non_finite_dropped: out.non_finite,
        ignored_columns: out.ignored_columns,
        format: got.name,
    }
}
