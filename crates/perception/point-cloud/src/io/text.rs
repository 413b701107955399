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

/// How a cloud's coordinates are printed: about a zero origin each as the
/// shortest text of its f32 (read back bit for bit); about a non-zero one,
/// the file's coordinate (origin added, in f64) to the decimals of the
/// cloud's own step: the LAS scale where it came from LAS, else f32's
/// step about the origin (a power of two, printed exactly).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Printed {
    origin: [f64; 3],
    decimals: [usize; 3],
}

/// Most decimals printed (a step finer than 1e-12 is printed to 1e-12).
const MAX_DECIMALS: usize = 12;

impl Printed {
    /// The printing of `cloud`'s coordinates.
    pub(crate) fn of(cloud: &crate::PointCloud) -> Self {
        let step = match &cloud.georef.las {
            Some(las) => las.scale(),
            None => cloud.precision_axes().map(|h| 2.0 * h),
        };
        let decimals = step.map(|s| {
            (0..=MAX_DECIMALS)
                .find(|&d| {
                    let k = s * 10f64.powi(d as i32);
                    (k - k.round()).abs() <= 1e-6 * k.abs().max(1.0)
                })
                .unwrap_or(MAX_DECIMALS)
        });
        Self {
            origin: cloud.origin,
            decimals,
        }
    }

    /// Whether every coordinate is printed as its own f32.
    pub(crate) fn is_plain(&self) -> bool {
        self.origin == [0.0; 3]
    }

    /// Puts point `p` in `line` as `x<sep>y<sep>z`, no newline.
    pub(crate) fn fill(&self, p: &Point, sep: u8, line: &mut Vec<u8>) {
        line.clear();
        for (a, (&v, (&o, &d))) in p
            .iter()
            .zip(self.origin.iter().zip(&self.decimals))
            .enumerate()
        {
            if a > 0 {
                line.push(sep);
            }
            if o == 0.0 {
                push_f32(line, v);
            } else {
                // Writing to a Vec cannot fail.
                let _ = write!(line, "{:.*}", d, o + f64::from(v));
            }
        }
    }
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

    #[test]
    fn about_an_origin_the_files_coordinates_print_to_its_step() {
        let mut c = crate::PointCloud::new(vec![[-65.67, -667.74, 131.57], [0.25, 0.5, 1.0]]);
        c.origin = [637_012.0, 849_000.0, 0.0];
        let printed = Printed::of(&c);
        let mut out = Vec::new();
        let mut line = Vec::new();
        for p in &c.points {
            printed.fill(p, b' ', &mut line);
            line.push(b'\n');
            out.extend_from_slice(&line);
        }
        let text = String::from_utf8(out).unwrap();
        for (i, row) in text.lines().enumerate() {
            let w = c.world(i);
            let words: Vec<&str> = row.split(' ').collect();
            for a in 0..2 {
                // f32 about the origin, printed to its step: exact.
                assert_eq!(words[a].parse::<f64>().unwrap(), w[a], "{text}");
            }
            // About a zero origin, the f32 itself.
            assert_eq!(words[2].parse::<f32>().unwrap(), c.points[i][2], "{text}");
        }
        assert!(text.starts_with("636946.") && !printed.is_plain(), "{text}");
    }
}
