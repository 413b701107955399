//! Point-cloud files (SPEC §4.1): PCD (ascii, binary, binary_compressed),
//! PLY (ascii, binary little/big endian), LAS/LAZ and XYZ/CSV/TXT.
//!
//! ```no_run
//! use std::path::Path;
//! use autoshovel_point_cloud::io::{read, write, Encoding};
//!
//! let report = read(Path::new("scan.laz"), &mut |done, total| eprint!("\r{done}/{total}"))?;
//! println!("{report}"); // "1234567 points (laz 1.4), 12 non-finite dropped"
//! write(Path::new("scan.pcd"), &report.cloud, Encoding::BinaryCompressed)?;
//! # Ok::<(), autoshovel_point_cloud::CloudError>(())
//! ```
//!
//! Files are untrusted input: readers never allocate what a header merely
//! claims (at most what the bytes left in the file could hold), read
//! binary data in chunks and text line by line (one copy of the points in
//! memory), and turn truncation, headers that disagree with the data,
//! unknown fields or types and absurd counts into
//! [`CloudError::Format`](crate::CloudError::Format) naming the line or
//! byte offset. Writers go through a temporary file and a rename.

mod format;
mod input;
mod las;
pub(crate) mod las_columns;
pub mod lzf;
mod many;
mod pcd;
mod ply;
mod read;
mod scalar;
mod text;
mod write;
mod xyz;

pub use format::{Encoding, Format};
pub use las::{LasHeader, LasVersion, LAS_SCALE_M, LAZ_MAX_POINTS_PER_BYTE, LAZ_MIN_CHUNK_BYTES};
pub use many::{read_files_in_order, FileChunkSink, InOrder};
pub use read::{
    las_header, read, read_chunks, read_chunks_with, read_from_bytes, ChunkSink, ReadReport,
    StreamReport,
};
pub use write::{write, write_named, write_with, WriteOptions};
