//! The warm-start pack file (`pack.csv`): the optimiser's final wolves as
//! decisions of [RS eq. 24] with their objective and normalised violation, best
//! first, so the next dig cycle can start from them ([RS eq. 37]'s pack).
//!
//! ```text
//! ax6,ay6,td_s,gx_m,gy_m,f,violation
//! -9.1e-7,5.2e-7,11.6,0.34,0.31,13.37,0
//! ```
//!
//! [`write_pack`] and [`read_pack`] are one pair: every number is written
//! in the shortest form that parses back to the same `f64`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use autoshovel_optim::Evaluation;

use crate::error::{DigError, PackProblem, Result};
use crate::plan::DigModel;
use crate::trajectory::Decision;

/// Columns of `pack.csv`.
pub const PACK_COLUMNS: [&str; 7] = ["ax6", "ay6", "td_s", "gx_m", "gy_m", "f", "violation"];

/// Writes the optimiser's final pack (`search.population` of a plan, in the
/// coordinates of `model`) to `path` as decisions, best first.
pub fn write_pack(path: &Path, model: &DigModel, pack: &[(Vec<f64>, Evaluation)]) -> Result<()> {
    let mut text = PACK_COLUMNS.join(",");
    text.push('\n');
    for (x, e) in pack {
        let d = model.decision(x);
        let row = [
            d.ax6,
            d.ay6,
            d.td_s,
            d.gx_m,
            d.gy_m,
            e.objective,
            e.violation,
        ];
        for (j, v) in row.iter().enumerate() {
            if j > 0 {
                text.push(',');
            }
            let _ = write!(text, "{}", Shortest(*v));
        }
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|source| DigError::PackWrite {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads the wolves of a `pack.csv` written by [`write_pack`]; errors name
/// the file and line.
pub fn read_pack(path: &Path) -> Result<Vec<Decision>> {
    let text = std::fs::read_to_string(path).map_err(|source| DigError::PackRead {
        path: path.to_path_buf(),
        source,
    })?;
    parse_pack(&text, path)
}

/// Parses the text of a `pack.csv`; `path` names it in errors.
pub fn parse_pack(text: &str, path: &Path) -> Result<Vec<Decision>> {
    let fail = |line: Option<usize>, problem: PackProblem| DigError::Pack {
        path: PathBuf::from(path),
        line,
        problem,
    };
    let mut lines = text.lines().enumerate();
    let header: Vec<&str> = match lines.next() {
        Some((_, h)) => h.split(',').map(str::trim).collect(),
        None => return Err(fail(None, PackProblem::Empty)),
    };
    if header[..] != PACK_COLUMNS[..] {
        return Err(fail(
            Some(1),
            PackProblem::Header {
                found: header.join(","),
                expected: PACK_COLUMNS.join(","),
            },
        ));
    }
    let mut wolves = Vec::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let at = Some(i + 1);
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != PACK_COLUMNS.len() {
            return Err(fail(
                at,
                PackProblem::Width {
                    found: cells.len(),
                    expected: PACK_COLUMNS.len(),
                },
            ));
        }
        let mut x = [0.0; 5];
        for (k, (cell, v)) in cells.iter().zip(x.iter_mut()).enumerate() {
            *v = cell
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    fail(
                        at,
                        PackProblem::NotANumber {
                            column: PACK_COLUMNS[k],
                            cell: cell.to_string(),
                        },
                    )
                })?;
        }
        if x[2] <= 0.0 {
            return Err(fail(at, PackProblem::DurationNotPositive { td_s: x[2] }));
        }
        wolves.push(Decision::from_slice(&x));
    }
    if wolves.is_empty() {
        return Err(fail(None, PackProblem::NoWolves));
    }
    Ok(wolves)
}

/// The shortest text that parses back to the same `f64` (`{:e}` below 1e-5
/// or from 1e16 in magnitude), as the workspace's CSV writers print numbers.
struct Shortest(f64);

impl std::fmt::Display for Shortest {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if v == 0.0 || !v.is_finite() || (1e-5..1e16).contains(&v.abs()) {
            write!(f, "{v}")
        } else {
            write!(f, "{v:e}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refusals_name_the_line() {
        let p = Path::new("pack.csv");
        let head = PACK_COLUMNS.join(",");
        let msg = |t: &str| parse_pack(t, p).unwrap_err().to_string();
        assert!(msg("").contains("pack.csv: empty"));
        assert!(msg("a,b\n").starts_with("pack.csv:1: header 'a,b'"));
        assert!(msg(&format!("{head}\n1,2,3\n")).starts_with("pack.csv:2: 3 values"));
        assert!(msg(&format!("{head}\n1,2,x,4,5,6,7\n")).contains("pack.csv:2: td_s = 'x'"));
        assert!(msg(&format!("{head}\n1,2,0,4,5,6,7\n")).contains("must be > 0"));
        assert!(msg(&format!("{head}\n\n")).contains("no wolves"));
        let ok = parse_pack(&format!("{head}\n1e-7,2,3,4,5,6,0\n"), p).unwrap();
        assert_eq!(ok.len(), 1);
        assert_eq!(ok[0].td_s, 3.0);
    }

    #[test]
    fn shortest_round_trips() {
        for v in [0.0, 1.0 / 3.0, -9.98e-7, 1e300, 12.5] {
            let s = Shortest(v).to_string();
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
    }
}
