//! Writing any supported file, atomically: the data goes to a temporary
//! file in the target's directory, which is synced and then renamed over
//! the target, so a crash or an error never leaves a half-written file
//! under the target's name.

use std::io::BufWriter;
use std::path::Path;

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
    write_named(path, path, cloud, options)
}

/// [`write_with`] to `dest`, in the format of `name`'s extension, naming
/// `name` in every error: what a caller writing through a scratch file
/// uses so that errors name the user's target.
pub fn write_named(
    dest: &Path,
    name: &Path,
    cloud: &PointCloud,
    options: &WriteOptions,
) -> crate::Result<()> {
    let path = name;
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
        // What a writer reports is what it wrote: the text formats are
        // text, LAS and LAZ binary, whatever was asked.
        (Format::Xyz | Format::Csv | Format::Txt, e) if e != Encoding::Ascii => {
            return Err(bad(format!("{} is a text format: it has no {e} encoding (use ascii, or write .pcd or .ply)", format.extension())))
        }
        (Format::Las | Format::Laz, e) if e != Encoding::Binary => {
            return Err(bad(format!("{} has one encoding, binary: there is no {e} (use .pcd or .ply for {e})", format.extension())))
        }
        _ => {}
    }
    let io = |source: std::io::Error| CloudError::Io {
        path: path.to_path_buf(),
        source,
    };
    let (file, guard) = create_temp(dest).map_err(io)?.into_parts();
    let mut w = BufWriter::with_capacity(BUFFER, file);
    let file = match format {
        Format::Las | Format::Laz => {
            let w =
                las::write(w, cloud, format == Format::Laz, options.las_version).map_err(bad)?;
            w.into_inner().map_err(|e| io(e.into_error()))?
        }
        _ => {
            let r = match format {
                Format::Pcd => pcd::write_cloud(&mut w, cloud, encoding),
                Format::Ply => ply::write(&mut w, cloud, encoding),
                Format::Csv => xyz::write(&mut w, cloud, b',', Some("x,y,z")),
                _ => xyz::write(&mut w, cloud, b' ', None),
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
    guard.persist(dest).map_err(|e| io(e.error))
}

/// A new file `.NAME.RANDOM.tmp` beside `path`, made exclusively (never
/// through an existing entry) and removed on drop unless persisted.
fn create_temp(path: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // The mode any new file gets (0666 less the umask), not tempfile's
    // private 0600: the temporary file becomes the user's output.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    // tempfile appends the temporary path to its errors: the caller
    // names the user's target instead.
    builder
        .tempfile_in(dir)
        .map_err(|e| match e.raw_os_error() {
            Some(code) => std::io::Error::from_raw_os_error(code),
            None => std::io::Error::from(e.kind()),
        })
}
