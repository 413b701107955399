//! Printing coordinates as text so that they read back bit for bit.
//!
//! Rust's `{}` and `{:e}` print the shortest decimal that parses back to
//! the same `f32`; plain notation is used for ordinary magnitudes and
//! exponent notation for the very small and very large, which would
//! otherwise print dozens of zeros.

use std::io::{self, Write};

use crate::Point;

/// Appends `v` to `out` in the shortest form that round-trips.
pub(crate) fn push_f32(out: &mut Vec<u8>, v: f32) {
    let a = v.abs();
    // Writing to a Vec cannot fail.
    let _ = if v == 0.0 || (1e-5..1e16).contains(&a) {
        write!(out, "{v}")
    } else {
        write!(out, "{v:e}")
    };
}

/// Writes one point as `x<sep>y<sep>z\n`, using `line` as scratch.
pub(crate) fn write_point<W: Write>(
    w: &mut W,
    p: &Point,
    sep: u8,
    line: &mut Vec<u8>,
) -> io::Result<()> {
    line.clear();
    push_f32(line, p[0]);
    line.push(sep);
    push_f32(line, p[1]);
    line.push(sep);
    push_f32(line, p[2]);
    line.push(b'\n');
    w.write_all(line)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extremes_round_trip_and_stay_short() {
        for v in [
            0.0f32,
            -0.0,
            1.0,
            0.1,
            -123.456,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            1e-45,
            1e-5,
            9.99e15,
            1e16,
            16_777_217.0,
        ] {
            let mut s = Vec::new();
            push_f32(&mut s, v);
            let s = String::from_utf8(s).unwrap();
            assert!(s.len() <= 16, "{s}");
            assert_eq!(s.parse::<f32>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
    }
}
