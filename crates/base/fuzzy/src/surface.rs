//! Control surfaces: the crisp output of a two-input system over a regular
//! grid of its input universes, z[iy][ix] = f(xs[ix], ys[iy]) — the 3-D
//! surface / heat map drawn for a fuzzy controller (the paper's §4.3 uses
//! it for u(e, ec); inference is Mamdani & Assilian 1975, see
//! [`crate::MamdaniSystem`]).

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::mamdani::linspace;
use crate::{FuzzyError, MamdaniSystem};

/// A control surface sampled on a regular grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Surface {
    /// Name of the first input (x axis, e.g. `"e"`).
    pub x_name: String,
    /// Name of the second input (y axis, e.g. `"ec"`).
    pub y_name: String,
    /// Name of the output (e.g. `"u"`).
    pub z_name: String,
    /// Grid along the first input: `nx` evenly spaced points of its universe.
    pub xs: Vec<f64>,
    /// Grid along the second input: `ny` evenly spaced points of its universe.
    pub ys: Vec<f64>,
    /// Outputs, row-major by the second input: `z[iy][ix] = f(xs[ix], ys[iy])`.
    pub z: Vec<Vec<f64>>,
}

impl Surface {
    /// Long-format CSV: a header `x_name,y_name,z_name`, then one line per
    /// grid point, x varying fastest, values in shortest round-trip form.
    pub fn to_csv(&self) -> String {
        let mut out = format!("{},{},{}\n", self.x_name, self.y_name, self.z_name);
        for (y, row) in self.ys.iter().zip(&self.z) {
            for (x, z) in self.xs.iter().zip(row) {
                // Writing to a String cannot fail.
                let _ = writeln!(out, "{x},{y},{z}");
            }
        }
        out
    }
}

impl MamdaniSystem {
    /// The control surface of a two-input system on an `nx × ny` grid
    /// spanning both input universes, ends included ([`crate::Variable::sample`]).
    ///
    /// Errors: [`FuzzyError::NotTwoInputs`] unless the system has exactly
    /// two inputs, [`FuzzyError::BadGrid`] if `nx < 2` or `ny < 2`.
    pub fn surface(&self, nx: usize, ny: usize) -> Result<Surface, FuzzyError> {
        let [xv, yv] = self.inputs() else {
            return Err(FuzzyError::NotTwoInputs {
                inputs: self.inputs().len(),
            });
        };
        if nx < 2 || ny < 2 {
            return Err(FuzzyError::BadGrid { nx, ny });
        }
        let xs = linspace(xv.min, xv.max, nx);
        let ys = linspace(yv.min, yv.max, ny);
        let mut scratch = self.scratch();
        let z = ys
            .iter()
            .map(|&y| {
                xs.iter()
                    .map(|&x| self.infer_with(&[x, y], &mut scratch))
                    .collect::<Result<Vec<f64>, _>>()
            })
            .collect::<Result<_, _>>()?;
        Ok(Surface {
            x_name: xv.name.clone(),
            y_name: yv.name.clone(),
            z_name: self.output().name.clone(),
            xs,
            ys,
            z,
        })
    }
}
