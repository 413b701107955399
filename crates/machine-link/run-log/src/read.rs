//! Reading a run log back, record by record: a fixed-size window of the
//! file at a time (never the whole file), every chunk's CRC checked before
//! any of its messages is used, and the data and summary sections' CRCs
//! checked where the log has them.
//!
//! A log whose writer was killed has no summary and no closing magic: it
//! is read up to its last whole chunk (the writer closes one every control
//! period) and reported [`LogEnd::Cut`]. A log that has its closing magic
//! but does not parse, or any chunk whose CRC differs, is damaged and refused.

use std::collections::HashMap;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};

use crate::error::RunLogError;

/// The MCAP magic that opens and closes a log.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// The largest record read (bytes): a log's chunks are one control period
/// of messages, far below this; a length field beyond it is damage.
pub const RECORD_LIMIT: usize = 64 << 20;

/// How a log ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LogEnd {
    /// Closed by its writer: summary and closing magic present, every CRC good.
    Complete,
    /// Its writer stopped before closing it (killed, power lost): read up
    /// to its last whole chunk.
    Cut {
        /// Bytes of the file that were read as whole records.
        bytes: u64,
    },
}

fn damaged(path: &Path, source: mcap::McapError) -> RunLogError {
    RunLogError::McapRead {
        path: path.to_path_buf(),
        what: "damaged MCAP (a record or CRC does not check)",
        source,
    }
}

fn io(path: &Path, source: std::io::Error) -> RunLogError {
    RunLogError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Whether the file ends with the closing magic (its writer finished it).
fn closed(file: &mut File, path: &Path) -> Result<bool, RunLogError> {
    let len = file.metadata().map_err(|e| io(path, e))?.len();
    if len < 16 {
        return Ok(false);
    }
    let mut tail = [0u8; 8];
    file.seek(SeekFrom::End(-8)).map_err(|e| io(path, e))?;
    file.read_exact(&mut tail).map_err(|e| io(path, e))?;
    file.seek(SeekFrom::Start(0)).map_err(|e| io(path, e))?;
    Ok(&tail == MAGIC)
}

/// Reads every message of the log at `path`, in order, handing each to
/// `on_message(topic, sequence, data)`; how the log ended.
pub fn read_messages(
    path: &Path,
    mut on_message: impl FnMut(&str, u32, &[u8]) -> Result<(), RunLogError>,
) -> Result<LogEnd, RunLogError> {
    let mut file = File::open(path).map_err(|e| io(path, e))?;
    let complete = closed(&mut file, path)?;
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_validate_chunk_crcs(true)
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_record_length_limit(RECORD_LIMIT),
    );
    let mut topics: HashMap<u16, String> = HashMap::new();
    let mut read_bytes = 0u64;
    let mut whole = 0u64;
    let mut messages = 0usize;
    while let Some(event) = reader.next_event() {
        let event = match event {
            Ok(e) => e,
            Err(mcap::McapError::UnexpectedEof) if !complete && messages > 0 => {
                return Ok(LogEnd::Cut { bytes: whole });
            }
            Err(mcap::McapError::UnexpectedEof) if !complete => {
                return Err(RunLogError::Content {
                    path: path.to_path_buf(),
                    why: "cut before its first message: the log holds nothing to replay".into(),
                })
            }
            Err(e) => return Err(damaged(path, e)),
        };
        match event {
            LinearReadEvent::ReadRequest(need) => {
                let n = file.read(reader.insert(need)).map_err(|e| io(path, e))?;
                read_bytes += n as u64;
                reader.notify_read(n);
            }
            LinearReadEvent::Record { opcode, data } => {
                whole = read_bytes;
                match mcap::parse_record(opcode, data).map_err(|e| damaged(path, e))? {
                    mcap::records::Record::Channel(c) => {
                        topics.insert(c.id, c.topic);
                    }
                    mcap::records::Record::Message { header, data } => {
                        let topic =
                            topics
                                .get(&header.channel_id)
                                .ok_or_else(|| RunLogError::Content {
                                    path: path.to_path_buf(),
                                    why: format!(
                                        "message {} on channel {} that no channel record names",
                                        header.sequence, header.channel_id
                                    ),
                                })?;
                        messages += 1;
                        on_message(topic, header.sequence, &data)?;
                    }
                    _ => {}
                }
            }
        }
    }
    Ok(LogEnd::Complete)
}
