//! LZF, the byte-oriented LZ77 variant of liblzf (Marc Lehmann) that PCL
//! uses for `DATA binary_compressed` PCD files. Written here from the format
//! description rather than bound from C, so that the decoder can be strict
//! about untrusted input.
//!
//! A compressed stream is a sequence of tokens, each starting with a control
//! byte `c`:
//! - `c < 32`: a literal run; the next `c + 1` bytes are copied out.
//! - otherwise a back-reference: length `L = c >> 5` (if `L == 7`, one more
//!   byte is added to it), distance `D = ((c & 31) << 8 | next byte) + 1`;
//!   copy `L + 2` bytes starting `D` bytes back in the output (overlap
//!   allowed, so runs repeat). Hence 3..=264 bytes from at most 8192 back.
//!
//! The decoder streams: it keeps only the last 8 KiB of output (all a
//! back-reference can reach) plus a block, and hands each block to a sink,
//! so a file of tens of millions of points is never held decompressed.
//! Every length and distance is checked; a stream that reaches back before
//! its start, runs past its end, or decodes to a size other than announced
//! is an error, never a panic.

use std::io::BufRead;

use super::input::Input;

/// Largest back-reference distance (bytes).
const MAX_DISTANCE: usize = 1 << 13;
/// Longest literal run (bytes).
const MAX_LITERAL: usize = 32;
/// Longest back-reference (bytes).
const MAX_MATCH: usize = 264;
/// Output is handed to the sink in blocks of about this size (bytes).
const BLOCK: usize = 1 << 16;
/// The most one compressed byte can expand to: a 3-byte back-reference
/// yields at most 264 bytes.
pub(crate) const MAX_RATIO: u64 = 88;
/// log2 of the compressor's hash table size.
const HASH_LOG: u32 = 14;

/// Compresses `input` into LZF (the format liblzf and PCL read).
///
/// Greedy matching with a hash of the next three bytes, every position
/// inserted; output is never more than `len + len / 32 + 1` bytes.
pub fn compress(input: &[u8]) -> Vec<u8> {
    let n = input.len();
    let mut out = Vec::with_capacity(n + n / MAX_LITERAL + 1);
    // Position + 1 of the last occurrence of each 3-byte hash (0: none).
    let mut table = vec![0usize; 1 << HASH_LOG];
    let hash = |i: usize| -> usize {
        let v =
            (u32::from(input[i]) << 16) | (u32::from(input[i + 1]) << 8) | u32::from(input[i + 2]);
        (v.wrapping_mul(2_654_435_761) >> (32 - HASH_LOG)) as usize
    };
    let mut lit_start = 0;
    let mut i = 0;
    while i + 2 < n {
        let h = hash(i);
        let candidate = table[h];
        table[h] = i + 1;
        if candidate > 0 {
            let r = candidate - 1;
            let distance = i - r;
            if distance <= MAX_DISTANCE && input[r..r + 3] == input[i..i + 3] {
                let max_len = MAX_MATCH.min(n - i);
                let mut len = 3;
                while len < max_len && input[r + len] == input[i + len] {
                    len += 1;
                }
                push_literals(&mut out, &input[lit_start..i]);
                let l = len - 2;
                let d = distance - 1;
                if l < 7 {
                    out.push(((l << 5) | (d >> 8)) as u8);
                } else {
                    out.push(((7 << 5) | (d >> 8)) as u8);
                    out.push((l - 7) as u8);
                }
                out.push((d & 0xff) as u8);
                let end = i + len;
                for k in i + 1..end.min(n.saturating_sub(2)) {
                    table[hash(k)] = k + 1;
                }
                i = end;
                lit_start = i;
                continue;
            }
        }
        i += 1;
    }
    push_literals(&mut out, &input[lit_start..]);
    out
}

fn push_literals(out: &mut Vec<u8>, lits: &[u8]) {
    for run in lits.chunks(MAX_LITERAL) {
        out.push((run.len() - 1) as u8);
        out.extend_from_slice(run);
    }
}

/// Decompresses `compressed_len` bytes of LZF from `input` that must
/// expand to exactly `expected_len` bytes, handing the output in order to
/// `sink(offset, bytes)`. Errors name the byte offset in the file.
pub(crate) fn decompress_stream<R: BufRead>(
    input: &mut Input<'_, R>,
    compressed_len: u64,
    expected_len: u64,
    sink: &mut dyn FnMut(u64, &[u8]),
) -> crate::Result<()> {
    let start = input.pos();
    let end = start + compressed_len;
    let mut buf: Vec<u8> = Vec::with_capacity(BLOCK + MAX_DISTANCE + MAX_MATCH);
    let mut base = 0u64; // output offset of buf[0]
    let mut flushed = 0usize; // buf[..flushed] already given to the sink
    let mut produced = 0u64;
    let mut lit = [0u8; MAX_LITERAL];
    while input.pos() < end {
        let token_at = input.pos();
        let c = next_byte(input, end)?;
        let len = if c < 32 {
            let len = usize::from(c) + 1;
            if input.pos() + len as u64 > end {
                return Err(input.format_err(format!(
                    "LZF literal run of {len} bytes at byte {token_at} runs past the end of the compressed data (byte {end})"
                )));
            }
            input.read_exact_or(&mut lit[..len], "LZF literal run")?;
            check_room(input, produced, len, expected_len, token_at)?;
            buf.extend_from_slice(&lit[..len]);
            len
        } else {
            let mut len = usize::from(c >> 5);
            if len == 7 {
                len += usize::from(next_byte(input, end)?);
            }
            let distance = ((usize::from(c & 31) << 8) | usize::from(next_byte(input, end)?)) + 1;
            len += 2;
            if distance > buf.len() {
                return Err(input.format_err(format!(
                    "LZF back-reference at byte {token_at} reaches {distance} bytes back, before the start of the data (output offset {produced})"
                )));
            }
            check_room(input, produced, len, expected_len, token_at)?;
            let from = buf.len() - distance;
            if distance >= len {
                buf.extend_from_within(from..from + len);
            } else {
                for k in 0..len {
                    let b = buf[from + k];
                    buf.push(b);
                }
            }
            len
        };
        produced += len as u64;
        if buf.len() >= BLOCK + MAX_DISTANCE {
            sink(base + flushed as u64, &buf[flushed..]);
            let drop = buf.len() - MAX_DISTANCE;
            buf.drain(..drop);
            base += drop as u64;
            flushed = buf.len();
        }
    }
    sink(base + flushed as u64, &buf[flushed..]);
    if produced != expected_len {
        return Err(input.format_err(format!(
            "LZF data (bytes {start}..{end}) decompresses to {produced} bytes, the header says {expected_len}"
        )));
    }
    Ok(())
}

fn next_byte<R: BufRead>(input: &mut Input<'_, R>, end: u64) -> crate::Result<u8> {
    if input.pos() >= end {
        return Err(input.format_err(format!(
            "LZF token cut off at the end of the compressed data (byte {end})"
        )));
    }
    let mut b = [0u8; 1];
    input.read_exact_or(&mut b, "LZF data")?;
    Ok(b[0])
}

fn check_room<R: BufRead>(
    input: &Input<'_, R>,
    produced: u64,
    len: usize,
    expected_len: u64,
    token_at: u64,
) -> crate::Result<()> {
    if produced + len as u64 > expected_len {
        return Err(input.format_err(format!(
            "LZF token at byte {token_at} writes past the announced {expected_len} decompressed bytes"
        )));
    }
    Ok(())
}

/// Decompresses a whole LZF buffer that must expand to `expected_len`
/// bytes (tests and tools; readers stream).
pub fn decompress(compressed: &[u8], expected_len: usize) -> crate::Result<Vec<u8>> {
    let path = std::path::Path::new("<lzf buffer>");
    let mut progress = |_: u64, _: u64| {};
    let mut input = Input::new(compressed, compressed.len() as u64, path, &mut progress);
    let mut out =
        Vec::with_capacity(expected_len.min(compressed.len().saturating_mul(MAX_RATIO as usize)));
    decompress_stream(
        &mut input,
        compressed.len() as u64,
        expected_len as u64,
        &mut |_, b| out.extend_from_slice(b),
    )?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_text_runs_and_noise() {
        let mut data = b"the quick brown fox jumps over the lazy dog; the quick brown fox".to_vec();
        data.extend(std::iter::repeat_n(7u8, 5000));
        let mut x = 12345u32;
        for _ in 0..100_000 {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
            data.push((x >> 24) as u8);
        }
        data.extend_from_slice(&data.clone()[..20_000]);
        let c = compress(&data);
        assert!(c.len() < data.len() + data.len() / 32 + 1);
        assert_eq!(decompress(&c, data.len()).unwrap(), data);
    }

    #[test]
    fn known_stream_from_the_format_description() {
        // "aaaaaaaaaa": literal 'a', then a back-reference of 9 bytes, distance 1.
        let c = [0u8, b'a', (7 << 5), 0, 0];
        assert_eq!(decompress(&c, 10).unwrap(), b"aaaaaaaaaa");
        assert_eq!(compress(b"aaaaaaaaaa"), c);
    }

    #[test]
    fn rejects_bad_streams() {
        // back-reference before the start
        assert!(decompress(&[0x20, 0x05], 3).is_err());
        // literal past the end
        assert!(decompress(&[5, 1, 2], 6).is_err());
        // wrong announced size, both ways
        assert!(decompress(&[1, 1, 2], 3).is_err());
        assert!(decompress(&[1, 1, 2], 1).is_err());
        // a cut back-reference
        assert!(decompress(&[0, 1, 0xe0], 20).is_err());
        assert_eq!(decompress(&[], 0).unwrap(), Vec::<u8>::new());
    }
}
