//! Which format a file is in (by extension) and how it is encoded.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use crate::CloudError;

/// A point-cloud file format, chosen by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Format {
    /// PCL's PCD (`.pcd`).
    Pcd,
    /// Stanford PLY (`.ply`).
    Ply,
    /// ASPRS LAS (`.las`); reading also accepts LAZ content.
    Las,
    /// LASzip-compressed LAS (`.laz`).
    Laz,
    /// Text, whitespace separated (`.xyz`).
    Xyz,
    /// Text, comma separated with a header line (`.csv`).
    Csv,
    /// Text, whitespace separated (`.txt`).
    Txt,
}

impl Format {
    /// The format for an extension (without the dot, any case).
    pub fn from_extension(ext: &str) -> Option<Format> {
        Some(match ext.to_ascii_lowercase().as_str() {
            "pcd" => Format::Pcd,
            "ply" => Format::Ply,
            "las" => Format::Las,
            "laz" => Format::Laz,
            "xyz" => Format::Xyz,
            "csv" => Format::Csv,
            "txt" => Format::Txt,
            _ => return None,
        })
    }

    /// The format of `path` by its extension.
    pub fn from_path(path: &Path) -> crate::Result<Format> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        Format::from_extension(ext).ok_or_else(|| CloudError::UnknownFormat {
            path: path.to_path_buf(),
            extension: ext.to_string(),
        })
    }

    /// The usual extension.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Pcd => "pcd",
            Format::Ply => "ply",
            Format::Las => "las",
            Format::Laz => "laz",
            Format::Xyz => "xyz",
            Format::Csv => "csv",
            Format::Txt => "txt",
        }
    }

    /// The encodings this format can be written in (the first is the
    /// default); empty for formats with a single fixed encoding.
    pub fn encodings(self) -> &'static [Encoding] {
        match self {
            Format::Pcd => &[
                Encoding::Binary,
                Encoding::Ascii,
                Encoding::BinaryCompressed,
            ],
            Format::Ply => &[Encoding::Binary, Encoding::Ascii, Encoding::BinaryBigEndian],
            _ => &[],
        }
    }
}

/// How a PCD or PLY file is encoded; LAS, LAZ and the text formats ignore
/// it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// Text (PCD `ascii`, PLY `ascii`).
    Ascii,
    /// Little-endian binary (PCD `binary`, PLY `binary_little_endian`).
    Binary,
    /// LZF-compressed columns (PCD `binary_compressed`; PCD only).
    BinaryCompressed,
    /// Big-endian binary (PLY `binary_big_endian`; PLY only).
    BinaryBigEndian,
}

impl Encoding {
    /// The default for a path: binary for PCD and PLY (the compact,
    /// exact choice), ASCII for the text formats, binary otherwise.
    pub fn default_for(path: &Path) -> Encoding {
        match Format::from_path(path) {
            Ok(Format::Xyz | Format::Csv | Format::Txt) => Encoding::Ascii,
            _ => Encoding::Binary,
        }
    }

    /// The name as the file formats spell it.
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Ascii => "ascii",
            Encoding::Binary => "binary",
            Encoding::BinaryCompressed => "binary_compressed",
            Encoding::BinaryBigEndian => "binary_big_endian",
        }
    }
}

impl fmt::Display for Encoding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Encoding {
    type Err = String;

    /// `ascii`, `binary` (or `binary_little_endian`), `binary_compressed`,
    /// `binary_big_endian`; any case, `-` for `_`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.to_ascii_lowercase().replace('-', "_").as_str() {
            "ascii" => Encoding::Ascii,
            "binary" | "binary_little_endian" => Encoding::Binary,
            "binary_compressed" => Encoding::BinaryCompressed,
            "binary_big_endian" => Encoding::BinaryBigEndian,
            _ => {
                return Err(format!(
                    "unknown encoding {s:?} (ascii, binary, binary_compressed, binary_little_endian, binary_big_endian)"
                ))
            }
        })
    }
}
