//! PDAL's range filter (`filters.range`): keep the points whose dimensions
//! fall in given ranges, e.g. `Classification[2:2]` for the ground of a
//! classified survey, `Z[0:100],Intensity(50:]`.
//!
//! The syntax and its logic are PDAL's ("Ranges" in its docs): a dimension
//! name, an optional `!` that negates, then `[MIN:MAX]` with `[`/`]` for a
//! closed end and `(`/`)` for an open one; either end may be left out.
//! Ranges are separated by commas; ranges of one dimension are ORed, of
//! different dimensions ANDed. A name matches a column whatever its case
//! (PDAL's dimension names are case-blind); `X`, `Y` and `Z` are the
//! file's own coordinates (the cloud's origin added back). Written here
//! because no crate reads PDAL's range syntax.

use std::fmt;

use rayon::prelude::*;

use crate::cloud::PointCloud;
use crate::error::{CloudError, Result};
use crate::Values;

/// The filter's name in errors.
const FILTER: &str = "range";

/// One range of one dimension: `Name[lo:hi]`, `Name!(lo:hi]` ...
#[derive(Debug, Clone, PartialEq)]
pub struct Range {
    /// The dimension, as given.
    pub dimension: String,
    /// Lower end (`-inf` when left out).
    pub lo: f64,
    /// Upper end (`inf` when left out).
    pub hi: f64,
    /// Whether `lo` itself is in (`[`).
    pub lo_closed: bool,
    /// Whether `hi` itself is in (`]`).
    pub hi_closed: bool,
    /// `!`: the points outside pass.
    pub negate: bool,
}

impl Range {
    /// Whether `v` passes this range (NaN never lies inside one).
    pub fn passes(&self, v: f64) -> bool {
        let above = if self.lo_closed {
            v >= self.lo
        } else {
            v > self.lo
        };
        let below = if self.hi_closed {
            v <= self.hi
        } else {
            v < self.hi
        };
        (above && below) != self.negate
    }
}

/// A comma-separated list of [`Range`]s: PDAL's `limits` option.
#[derive(Debug, Clone, PartialEq)]
pub struct RangeLimits {
    /// The ranges, in the order given.
    pub ranges: Vec<Range>,
}

impl RangeLimits {
    /// Parses PDAL's syntax; an error says which range is wrong and how.
    ///
    /// ```
    /// use autoshovel_point_cloud::filter::RangeLimits;
    /// let r = RangeLimits::parse("Classification[2:2], Z(:100]").unwrap();
    /// assert_eq!(r.ranges.len(), 2);
    /// assert!(r.ranges[0].passes(2.0) && !r.ranges[0].passes(1.0));
    /// assert!(RangeLimits::parse("Classification[2:").is_err());
    /// ```
    pub fn parse(spec: &str) -> std::result::Result<Self, String> {
        let ranges = split_ranges(spec)?
            .into_iter()
            .map(parse_range)
            .collect::<std::result::Result<Vec<_>, _>>()?;
        if ranges.is_empty() {
            return Err("no range given (e.g. Classification[2:2])".into());
        }
        Ok(Self { ranges })
    }
}

impl fmt::Display for RangeLimits {
    /// The ranges written back in PDAL's syntax.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, r) in self.ranges.iter().enumerate() {
            let end = |v: f64| {
                if v.is_finite() {
                    short(v)
                } else {
                    String::new()
                }
            };
            write!(
                f,
                "{}{}{}{}{}:{}{}",
                if i > 0 { "," } else { "" },
                r.dimension,
                if r.negate { "!" } else { "" },
                if r.lo_closed { '[' } else { '(' },
                end(r.lo),
                end(r.hi),
                if r.hi_closed { ']' } else { ')' },
            )?;
        }
        Ok(())
    }
}

/// `v` as the shortest text that reads back as it.
fn short(v: f64) -> String {
    format!("{v}")
}

/// The ranges of `spec`: split at the commas between them (a range's own
/// text holds none).
fn split_ranges(spec: &str) -> std::result::Result<Vec<&str>, String> {
    let parts: Vec<&str> = spec.split(',').map(str::trim).collect();
    if let Some(i) = parts.iter().position(|p| p.is_empty()) {
        if parts.len() > 1 {
            return Err(format!("range {} is empty (a stray comma?)", i + 1));
        }
    }
    Ok(parts.into_iter().filter(|p| !p.is_empty()).collect())
}

/// One `Name[!](lo:hi)` range.
fn parse_range(text: &str) -> std::result::Result<Range, String> {
    let open = text
        .find(['[', '('])
        .ok_or_else(|| format!("'{text}': no '[' or '(' after the dimension's name"))?;
    let (head, body) = text.split_at(open);
    let (dimension, negate) = match head.trim().strip_suffix('!') {
        Some(name) => (name.trim(), true),
        None => (head.trim(), false),
    };
    if dimension.is_empty() || !dimension.chars().all(|c| c.is_alphanumeric() || c == '_') {
        return Err(format!("'{text}': '{dimension}' is not a dimension's name"));
    }
    let lo_closed = body.starts_with('[');
    let hi_closed = match body.chars().last() {
        Some(']') => true,
        Some(')') => false,
        _ => return Err(format!("'{text}': no ']' or ')' at the end")),
    };
    let inner = &body[1..body.len() - 1];
    let (lo, hi) = inner
        .split_once(':')
        .ok_or_else(|| format!("'{text}': no ':' between the ends"))?;
    let end = |t: &str, missing: f64| -> std::result::Result<f64, String> {
        let t = t.trim();
        if t.is_empty() {
            return Ok(missing);
        }
        t.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{text}': '{t}' is not a number"))
    };
    let (lo, hi) = (end(lo, f64::NEG_INFINITY)?, end(hi, f64::INFINITY)?);
    if lo > hi {
        return Err(format!("'{text}': the start {lo} is past the end {hi}"));
    }
    Ok(Range {
        dimension: dimension.to_string(),
        lo,
        hi,
        lo_closed,
        hi_closed,
        negate,
    })
}

/// Where a dimension's values come from: a coordinate (file frame) or a
/// column.
enum Source<'a> {
    Axis(usize),
    Column(&'a Values),
}

/// The rows of `cloud` that pass `limits`, in input order: for each
/// dimension named, some range of it passes (OR); every dimension named
/// passes (AND). A dimension the cloud lacks is an error naming the ones
/// it has; no row passing is [`CloudError::Emptied`].
pub fn range_indices(cloud: &PointCloud, limits: &RangeLimits) -> Result<Vec<usize>> {
    // The dimensions in first-named order, each with its ranges.
    let mut groups: Vec<(Source, Vec<&Range>)> = Vec::new();
    let mut names: Vec<String> = Vec::new();
    for r in &limits.ranges {
        let key = r.dimension.to_ascii_lowercase();
        if let Some(i) = names.iter().position(|n| *n == key) {
            groups[i].1.push(r);
            continue;
        }
        groups.push((source(cloud, &r.dimension)?, vec![r]));
        names.push(key);
    }
    let passes = |i: usize| {
        groups.iter().all(|(src, ranges)| {
            let v = match src {
                Source::Axis(a) => cloud.origin[*a] + f64::from(cloud.points[i][*a]),
                Source::Column(values) => values.f64_at(i),
            };
            ranges.iter().any(|r| r.passes(v))
        })
    };
    let kept: Vec<usize> = (0..cloud.len())
        .into_par_iter()
        .filter(|&i| passes(i))
        .collect();
    if kept.is_empty() {
        return Err(CloudError::Emptied {
            filter: FILTER,
            input: cloud.len(),
            hint: "check the ranges against the file's values (e.g. `pdal info --stats`)".into(),
        });
    }
    Ok(kept)
}

/// The coordinate or column named `name` (any case).
fn source<'a>(cloud: &'a PointCloud, name: &str) -> Result<Source<'a>> {
    if let Some(a) = ["x", "y", "z"]
        .iter()
        .position(|n| n.eq_ignore_ascii_case(name))
    {
        return Ok(Source::Axis(a));
    }
    let column = cloud
        .attributes
        .columns()
        .iter()
        .find(|c| c.name.eq_ignore_ascii_case(name));
    match column {
        Some(c) if matches!(c.values, Values::Bytes { .. }) => Err(CloudError::BadParameter {
            filter: FILTER,
            what: format!("dimension '{name}' is opaque extra bytes, with no value to compare"),
        }),
        Some(c) => Ok(Source::Column(&c.values)),
        None => {
            let have: Vec<&str> = std::iter::once("X, Y, Z")
                .chain(cloud.attributes.columns().iter().map(|c| c.name.as_str()))
                .collect();
            Err(CloudError::BadParameter {
                filter: FILTER,
                what: format!(
                    "the cloud has no dimension '{name}' (it has {})",
                    have.join(", ")
                ),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud() -> PointCloud {
        let mut c = PointCloud::new(vec![
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 2.0],
            [2.0, 0.0, 3.0],
            [3.0, 0.0, 4.0],
        ]);
        c.origin = [500_000.0, 4_000_000.0, 100.0];
        c.attributes
            .insert("Classification", Values::U8(vec![1, 2, 2, 7]));
        c.attributes
            .insert("Intensity", Values::U16(vec![10, 20, 30, 40]));
        c
    }

    fn kept(spec: &str) -> Vec<usize> {
        range_indices(&cloud(), &RangeLimits::parse(spec).unwrap()).unwrap()
    }

    #[test]
    fn pdals_examples_select_as_its_docs_say() {
        assert_eq!(kept("Classification[2:2]"), [1, 2]);
        // Same dimension ORed, different dimensions ANDed.
        assert_eq!(kept("Classification[1:1],Classification[7:7]"), [0, 3]);
        assert_eq!(kept("Classification[1:2], Intensity[15:]"), [1, 2]);
        // Open ends and negation.
        assert_eq!(kept("Intensity(10:40)"), [1, 2]);
        assert_eq!(kept("Intensity!(20:40]"), [0, 1]);
        assert_eq!(kept("Intensity![25:25]"), [0, 1, 2, 3]);
        assert_eq!(kept("Intensity[:20)"), [0]);
        // Coordinates in the file's frame, names in any case.
        assert_eq!(kept("z[102:103]"), [1, 2]);
        assert_eq!(kept("X[500001:],classification[2:2]"), [1, 2]);
    }

    #[test]
    fn bad_ranges_and_missing_dimensions_say_what_is_wrong() {
        for (spec, says) in [
            ("Classification[2:", "no ']' or ')'"),
            ("Classification 2:2", "no '[' or '('"),
            ("[2:2]", "not a dimension's name"),
            ("Intensity[a:2]", "'a' is not a number"),
            ("Intensity[5:2]", "past the end"),
            ("Intensity[2]", "no ':'"),
            ("Z[0:1],,Z[3:4]", "range 2 is empty"),
            ("", "no range given"),
        ] {
            let e = RangeLimits::parse(spec).unwrap_err();
            assert!(e.contains(says), "{spec}: {e}");
        }
        let e = range_indices(&cloud(), &RangeLimits::parse("GpsTime[0:1]").unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no dimension 'GpsTime'") && e.contains("Intensity"),
            "{e}"
        );
        let e = range_indices(
            &cloud(),
            &RangeLimits::parse("Classification[9:9]").unwrap(),
        )
        .unwrap_err();
        assert!(matches!(e, CloudError::Emptied { input: 4, .. }), "{e}");
    }

    #[test]
    fn written_back_it_reads_the_same() {
        for spec in [
            "Classification[2:2]",
            "Intensity!(20:40],Z[:100.5)",
            "X(1:]",
        ] {
            let r = RangeLimits::parse(spec).unwrap();
            assert_eq!(r.to_string(), spec);
            assert_eq!(RangeLimits::parse(&r.to_string()).unwrap(), r);
        }
    }
}
