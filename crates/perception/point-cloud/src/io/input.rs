//! The input side shared by every reader: a buffered byte source that knows
//! its position and size (for error messages and progress), reads lines of
//! bounded length, and collects points while dropping non-finite ones.

use std::io::{self, BufRead, Read};
use std::path::Path;

use crate::{CloudError, Point};

/// Progress is reported every this many bytes (bytes).
const PROGRESS_STEP: u64 = 1 << 20;

/// A buffered source with position, size, progress and the file's name.
pub(crate) struct Input<'a, R> {
    inner: R,
    pos: u64,
    total: u64,
    next_report: u64,
    progress: &'a mut dyn FnMut(u64, u64),
    path: &'a Path,
}

impl<'a, R: BufRead> Input<'a, R> {
    /// Wraps `inner`, whose size is `total` bytes, read from `path`.
    pub(crate) fn new(
        inner: R,
        total: u64,
        path: &'a Path,
        progress: &'a mut dyn FnMut(u64, u64),
    ) -> Self {
        progress(0, total);
        Self {
            inner,
            pos: 0,
            total,
            next_report: PROGRESS_STEP,
            progress,
            path,
        }
    }

    /// Bytes consumed so far (the offset of the next byte).
    pub(crate) fn pos(&self) -> u64 {
        self.pos
    }

    /// Bytes left according to the size given at construction.
    pub(crate) fn remaining(&self) -> u64 {
        self.total.saturating_sub(self.pos)
    }

    /// Reports completion to the progress callback.
    pub(crate) fn finish(&mut self) {
        (self.progress)(self.total, self.total);
    }

    /// A format error on this file.
    pub(crate) fn format_err(&self, what: impl Into<String>) -> CloudError {
        CloudError::Format {
            path: self.path.to_path_buf(),
            what: what.into(),
        }
    }

    /// An I/O error on this file; an unexpected end of file becomes a
    /// format error naming the offset and what was being read.
    pub(crate) fn io_err(&self, e: io::Error, reading: &str) -> CloudError {
        io_error(self.path, self.pos, e, reading)
    }

    /// Fills `buf` completely or fails with a truncation error naming `what`.
    pub(crate) fn read_exact_or(&mut self, buf: &mut [u8], what: &str) -> crate::Result<()> {
        let mut done = 0;
        while done < buf.len() {
            let n = match self.read(&mut buf[done..]) {
                Ok(0) => {
                    return Err(self.format_err(format!(
                        "file ends at byte {} while reading {what}: {} more bytes were expected",
                        self.pos,
                        buf.len() - done
                    )))
                }
                Ok(n) => n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(self.io_err(e, what)),
            };
            done += n;
        }
        Ok(())
    }

    /// Skips `n` bytes or fails with a truncation error naming `what`.
    pub(crate) fn skip(&mut self, mut n: u64, what: &str) -> crate::Result<()> {
        while n > 0 {
            let avail = match self.inner.fill_buf() {
                Ok(b) => b.len(),
                Err(e) => return Err(io_error(self.path, self.pos, e, what)),
            };
            if avail == 0 {
                return Err(self.format_err(format!(
                    "file ends at byte {} while skipping {what}: {n} more bytes were expected",
                    self.pos
                )));
            }
            let k = avail.min(usize::try_from(n).unwrap_or(usize::MAX));
            self.consume(k);
            n -= k as u64;
        }
        Ok(())
    }

    /// Whether the source is exhausted.
    pub(crate) fn at_eof(&mut self) -> crate::Result<bool> {
        match self.inner.fill_buf() {
            Ok(b) => Ok(b.is_empty()),
            Err(e) => Err(io_error(self.path, self.pos, e, "the end of the data")),
        }
    }

    /// Reads one line into `line` (without the `\n` or `\r\n`); `false` at
    /// the end of the file. A line longer than `max_len` bytes is an error,
    /// so a file without line breaks cannot make us allocate its size.
    pub(crate) fn read_line(
        &mut self,
        line: &mut Vec<u8>,
        max_len: usize,
        line_no: u64,
    ) -> crate::Result<bool> {
        line.clear();
        let mut any = false;
        loop {
            let buf = match self.inner.fill_buf() {
                Ok(b) => b,
                Err(e) => return Err(io_error(self.path, self.pos, e, "a line")),
            };
            if buf.is_empty() {
                break;
            }
            any = true;
            let (take, done) = match buf.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (buf.len(), false),
            };
            let body = if done { take - 1 } else { take };
            if line.len() + body > max_len {
                return Err(CloudError::Format {
                    path: self.path.to_path_buf(),
                    what: format!(
                        "line {line_no} (byte {}) is longer than {max_len} bytes",
                        self.pos
                    ),
                });
            }
            line.extend_from_slice(&buf[..body]);
            self.consume(take);
            if done {
                break;
            }
        }
        if line.last() == Some(&b'\r') {
            line.pop();
        }
        Ok(any)
    }

    fn advance(&mut self, n: usize) {
        self.pos += n as u64;
        if self.pos >= self.next_report {
            (self.progress)(self.pos.min(self.total), self.total);
            self.next_report = self.pos + PROGRESS_STEP;
        }
    }
}

/// An I/O error at `pos` of `path`; an unexpected end of file becomes a
/// format error naming the offset and what was being read.
fn io_error(path: &Path, pos: u64, e: io::Error, reading: &str) -> CloudError {
    if e.kind() == io::ErrorKind::UnexpectedEof {
        CloudError::Format {
            path: path.to_path_buf(),
            what: format!("file ends at byte {pos} while reading {reading} (truncated?)"),
        }
    } else {
        CloudError::Io {
            path: path.to_path_buf(),
            source: e,
        }
    }
}

impl<R: BufRead> Read for Input<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.advance(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Input<'_, R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        self.inner.fill_buf()
    }

    fn consume(&mut self, amt: usize) {
        self.inner.consume(amt);
        self.advance(amt);
    }
}

/// The points read so far, with the non-finite ones counted, not kept;
/// when streaming ([`Points::streaming`]), handed on a chunk at a time.
#[derive(Default)]
pub(crate) struct Points<'s> {
    /// The finite points (when streaming, those not yet handed on).
    pub(crate) points: Vec<Point>,
    /// How many non-finite points were dropped.
    pub(crate) non_finite: usize,
    /// Columns of a text header other than x, y and z.
    pub(crate) ignored_columns: usize,
    /// Chunk size and the receiver of full chunks, when streaming.
    sink: Option<(usize, Sink<'s>)>,
    /// Points handed to the sink so far.
    pub(crate) streamed: u64,
    /// Subtracted from LAS/LAZ coordinates in f64, before they become f32.
    pub(crate) origin: [f64; 3],
    /// Set the origin from the first finite point given in f64 (readers
    /// of formats whose header gives no bounds: PCD, PLY, text).
    pub(crate) origin_from_first: bool,
    /// Columns besides x, y and z, a row for every point kept.
    pub(crate) attributes: crate::Attributes,
    /// A PCD file's sensor pose, where not the identity.
    pub(crate) viewpoint: Option<crate::Viewpoint>,
    /// When streaming with rows: each kept point's LAS record, as the
    /// file's point format lays it out (those not yet handed on).
    pub(crate) rows: Option<Vec<u8>>,
}

/// Coordinates within this distance of zero are held about a zero origin
/// when a file's header gives no bounds (f32 resolves 0.24 mm there).
pub(crate) const ORIGIN_FREE: f64 = 4096.0;

/// The receiver of a stream's chunks: the points, and their rows when
/// asked for ([`Points::rows`]; empty otherwise).
pub(crate) type Sink<'s> = super::ChunkSink<'s>;

impl<'s> Points<'s> {
    /// Points that go to `sink` in chunks of `chunk`, not kept.
    pub(crate) fn streaming(chunk: usize, sink: Sink<'s>) -> Self {
        Self {
            sink: Some((chunk.max(1), sink)),
            ..Self::default()
        }
    }

    /// Hands the points held to the sink when a chunk is full (or, with
    /// `all`, whatever is held); without a sink, nothing.
    pub(crate) fn hand_on(&mut self, all: bool) -> crate::Result<()> {
        if let Some((chunk, sink)) = &mut self.sink {
            if self.points.len() >= *chunk || (all && !self.points.is_empty()) {
                sink(&self.points, self.rows.as_deref().unwrap_or_default())?;
                self.streamed += self.points.len() as u64;
                self.points.clear();
                if let Some(rows) = &mut self.rows {
                    rows.clear();
                }
            }
        }
        Ok(())
    }

    /// Whether points go to a sink rather than stay.
    pub(crate) fn is_streaming(&self) -> bool {
        self.sink.is_some()
    }

    /// Reserves room for at most `claimed` points, never more than
    /// `bytes_left / min_bytes_per_point`: a header's count is a claim,
    /// the file's size is a fact.
    pub(crate) fn reserve_bounded(
        &mut self,
        claimed: u64,
        bytes_left: u64,
        min_bytes_per_point: u64,
    ) {
        if self.is_streaming() {
            return;
        }
        let possible = bytes_left / min_bytes_per_point.max(1);
        let n = claimed.min(possible);
        if let Ok(n) = usize::try_from(n) {
            // Not populated (`crate::room`): a text file's bound is loose,
            // and the read stage gained nothing measurable from it.
            self.points.reserve(n);
        }
    }

    /// Keeps a finite point given in f64, less the origin; counts a
    /// non-finite one.
    #[inline]
    pub(crate) fn push_f64(&mut self, x: f64, y: f64, z: f64) -> bool {
        self.origin_from([x, y, z]);
        let o = self.origin;
        self.push([(x - o[0]) as f32, (y - o[1]) as f32, (z - o[2]) as f32])
    }

    /// With [`Points::origin_from_first`] set and `p` finite, sets the
    /// origin from `p`: its whole units on each axis far from zero, zero
    /// on the others.
    pub(crate) fn origin_from(&mut self, p: [f64; 3]) {
        if self.origin_from_first && p.iter().all(|v| v.is_finite()) {
            self.origin = p.map(|v| {
                if v.abs() > ORIGIN_FREE {
                    v.round()
                } else {
                    0.0
                }
            });
            self.origin_from_first = false;
        }
    }

    /// Drops the non-finite points from position `base` on (counting
    /// them), keeping the others in order.
    pub(crate) fn keep_finite_from(&mut self, base: usize) {
        let finite = |p: &Point| p[0].is_finite() && p[1].is_finite() && p[2].is_finite();
        // One pass that vectorises, then the compaction only when needed.
        let bad = self.points[base..].iter().filter(|p| !finite(p)).count();
        if bad > 0 {
            let mut kept = base;
            for i in base..self.points.len() {
                let p = self.points[i];
                if finite(&p) {
                    self.points[kept] = p;
                    kept += 1;
                }
            }
            self.points.truncate(kept);
            self.non_finite += bad;
        }
    }

    /// Keeps a finite point (true), counts a non-finite one (false).
    #[inline]
    pub(crate) fn push(&mut self, p: Point) -> bool {
        let finite = p[0].is_finite() && p[1].is_finite() && p[2].is_finite();
        if finite {
            self.points.push(p);
        } else {
            self.non_finite += 1;
        }
        finite
    }
}

/// The whitespace-separated words of an ASCII line, or an error naming the
/// line if it is not UTF-8.
pub(crate) fn line_str<'l, R: BufRead>(
    input: &Input<'_, R>,
    line: &'l [u8],
    line_no: u64,
) -> crate::Result<&'l str> {
    std::str::from_utf8(line)
        .map_err(|_| input.format_err(format!("line {line_no}: not ASCII/UTF-8 text")))
}
