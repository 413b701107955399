//! Writing any supported file, atomically: the data goes to a temporary
//! file in the target's directory, which is synced and then renamed over
//! the target, so a crash or an error never leaves a half-written file
//! under the target's name.

use std::fs::{self, File, OpenOptions};
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::{las, pcd, ply, xyz, Encoding, Format, LasVersion};
use crate::{CloudError, PointCloud};

/// Buffer size of file writers (bytes).
const BUFFER: usize = 1 << 20;

/// Options of [`write_with`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WriteOptions {
    /// PCD/PLY encoding; `None` is [`Encoding::default_for`] the path.
    pub encoding: Option<Encoding>,
    /// LAS/LAZ version.
    pub las_version: LasVersion,
}

/// Writes `cloud` to `path` in the format of its extension and, for PCD
/// and PLY, the given encoding (ignored by LAS, LAZ and the text formats).
///
/// Coordinates are written as `f32` (PCD, PLY: exact; text: the shortest
/// decimal that reads back to the same `f32`), or, for LAS/LAZ, as 1 mm
/// integers around a whole-metre offset.
pub fn write(path: &Path, cloud: &PointCloud, encoding: Encoding) -> crate::Result<()> {
    write_with(
        path,
        cloud,
        &WriteOptions {
            encoding: Some(encoding),
            ..WriteOptions::default()
        },
    )
}

/// [`write()`] with every option.
pub fn write_with(path: &Path, cloud: &PointCloud, options: &WriteOptions) -> crate::Result<()> {
    let format = Format::from_path(path)?;
    let encoding = options
        .encoding
        .unwrap_or_else(|| Encoding::default_for(path));
    let bad = |what: String| CloudError::Format {
        path: path.to_path_buf(),
        what,
    };
    match (format, encoding) {
        (Format::Pcd, Encoding::BinaryBigEndian) => {
            return Err(bad("PCD has no binary_big_endian encoding (use ascii, binary or binary_compressed)".into()))
        }
        (Format::Ply, Encoding::BinaryCompressed) => {
            return Err(bad("PLY has no binary_compressed encoding (use ascii, binary_little_endian or binary_big_endian)".into()))
        }
        _ => {}
    }
    let io = |source: std::io::Error| CloudError::Io {
        path: path.to_path_buf(),
        source,
    };
    let (tmp_path, file) = create_temp(path).map_err(io)?;
    let guard = TempFile(Some(tmp_path));
    let points = &cloud.points;
    let mut w = BufWriter::with_capacity(BUFFER, file);
    let file = match format {
        Format::Las | Format::Laz => {
            let w =
                las::write(w, points, format == Format::Laz, options.las_version).map_err(bad)?;
            w.into_inner().map_err(|e| io(e.into_error()))?
        }
        _ => {
            let r = match format {
                Format::Pcd => pcd::write(&mut w, points, encoding),
                Format::Ply => ply::write(&mut w, points, encoding),
                Format::Csv => xyz::write(&mut w, points, b',', Some("x,y,z")),
                _ => xyz::write(&mut w, points, b' ', None),
            };
            match r {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::Other => return Err(bad(e.to_string())),
                Err(e) => return Err(io(e)),
            }
            w.into_inner().map_err(|e| io(e.into_error()))?
        }
    };
    file.sync_all().map_err(io)?;
    drop(file);
    guard.persist(path).map_err(io)
}

/// A temporary file removed on drop unless persisted.
struct TempFile(Option<PathBuf>);

impl TempFile {
    fn persist(mut self, to: &Path) -> std::io::Result<()> {
        let from = self.0.take().expect("persisted once");
        match fs::rename(&from, to) {
            Ok(()) => Ok(()),
            Err(e) => {
                let _ = fs::remove_file(&from);
                Err(e)
            }
        }
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            let _ = fs::remove_file(p);
        }
    }
}

/// Creates `.NAME.PID.N.tmp` beside `path`.
fn create_temp(path: &Path) -> std::io::Result<(PathBuf, File)> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
}
