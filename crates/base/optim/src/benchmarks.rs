//! Classic test functions with the bounds and the published GWO results of
//! Mirjalili, Mirjalili & Lewis 2014 (Tables 1–2 for the functions, Tables
//! 5–6 for the results: 30 dimensions, 30 wolves, 500 iterations, 30 runs):
//!
//! | paper | function | f(x) | bounds | minimum |
//! |---|---|---|---|---|
//! | F1 | sphere | Σ x_i² | [−100, 100]^n | 0 at 0 |
//! | F5 | Rosenbrock | Σ_{i<n} 100 (x_{i+1} − x_i²)² + (x_i − 1)² | [−30, 30]^n | 0 at 1 |
//! | F9 | Rastrigin | Σ x_i² − 10 cos(2π x_i) + 10 | [−5.12, 5.12]^n | 0 at 0 |
//! | F10 | Ackley | −20 exp(−0.2 √(Σ x_i²/n)) − exp(Σ cos(2π x_i)/n) + 20 + e | [−32, 32]^n | 0 at 0 |

use crate::problem::{Evaluation, Problem};

/// One of the four classic functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Benchmark {
    /// F1, unimodal.
    Sphere,
    /// F5, unimodal with a curved valley.
    Rosenbrock,
    /// F9, multimodal (a grid of local minima).
    Rastrigin,
    /// F10, multimodal (a flat outer region with ripples).
    Ackley,
}

/// A published mean and standard deviation over 30 runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Published {
    /// Mean best objective.
    pub mean: f64,
    /// Standard deviation as printed. The paper's std column is not
    /// consistent with its means (e.g. sphere: mean 6.59e−28, std 6.34e−5);
    /// it is quoted, not relied on.
    pub std: f64,
}

impl Benchmark {
    /// The four functions, in the paper's order.
    pub const ALL: [Benchmark; 4] = [
        Benchmark::Sphere,
        Benchmark::Rosenbrock,
        Benchmark::Rastrigin,
        Benchmark::Ackley,
    ];

    /// Short name (`"sphere"`, …).
    pub fn name(self) -> &'static str {
        match self {
            Benchmark::Sphere => "sphere",
            Benchmark::Rosenbrock => "rosenbrock",
            Benchmark::Rastrigin => "rastrigin",
            Benchmark::Ackley => "ackley",
        }
    }

    /// The paper's label (F1, F5, F9, F10).
    pub fn label(self) -> &'static str {
        match self {
            Benchmark::Sphere => "F1",
            Benchmark::Rosenbrock => "F5",
            Benchmark::Rastrigin => "F9",
            Benchmark::Ackley => "F10",
        }
    }

    /// Half-width b of the box [−b, b] in every dimension.
    pub fn half_width(self) -> f64 {
        match self {
            Benchmark::Sphere => 100.0,
            Benchmark::Rosenbrock => 30.0,
            Benchmark::Rastrigin => 5.12,
            Benchmark::Ackley => 32.0,
        }
    }

    /// GWO's published result on 30 dimensions (Mirjalili et al. 2014,
    /// Tables 5–6).
    pub fn published_gwo(self) -> Published {
        let (mean, std) = match self {
            Benchmark::Sphere => (6.59e-28, 6.34e-5),
            Benchmark::Rosenbrock => (26.81258, 69.90499),
            Benchmark::Rastrigin => (0.310521, 47.35612),
            Benchmark::Ackley => (1.06e-13, 0.077835),
        };
        Published { mean, std }
    }

    /// f(x) (see the module table).
    pub fn value(self, x: &[f64]) -> f64 {
        match self {
            Benchmark::Sphere => x.iter().map(|v| v * v).sum(),
            Benchmark::Rosenbrock => x
                .windows(2)
                .map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (w[0] - 1.0).powi(2))
                .sum(),
            Benchmark::Rastrigin => x
                .iter()
                .map(|v| v * v - 10.0 * (std::f64::consts::TAU * v).cos() + 10.0)
                .sum(),
            Benchmark::Ackley => {
                let n = x.len() as f64;
                let sq = x.iter().map(|v| v * v).sum::<f64>() / n;
                let cs = x
                    .iter()
                    .map(|v| (std::f64::consts::TAU * v).cos())
                    .sum::<f64>()
                    / n;
                -20.0 * (-0.2 * sq.sqrt()).exp() - cs.exp() + 20.0 + std::f64::consts::E
            }
        }
    }

    /// The function as a [`Problem`] in `dim` dimensions on its box.
    pub fn problem(self, dim: usize) -> BenchmarkProblem {
        let b = self.half_width();
        BenchmarkProblem {
            function: self,
            bounds: vec![(-b, b); dim],
        }
    }
}

/// A [`Benchmark`] on its standard box, unconstrained.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchmarkProblem {
    /// The function.
    pub function: Benchmark,
    bounds: Vec<(f64, f64)>,
}

impl Problem for BenchmarkProblem {
    fn bounds(&self) -> &[(f64, f64)] {
        &self.bounds
    }

    fn evaluate(&self, x: &[f64]) -> Evaluation {
        Evaluation::feasible(self.function.value(x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn minima() {
        let zero = [0.0; 30];
        let one = [1.0; 30];
        assert_abs_diff_eq!(Benchmark::Sphere.value(&zero), 0.0);
        assert_abs_diff_eq!(Benchmark::Rosenbrock.value(&one), 0.0);
        assert_abs_diff_eq!(Benchmark::Rastrigin.value(&zero), 0.0);
        assert_abs_diff_eq!(Benchmark::Ackley.value(&zero), 0.0, epsilon = 1e-15);
        // Hand values: Rosenbrock at 0 is (n − 1)·1; Rastrigin at 0.5 is 20.25 per dimension.
        assert_abs_diff_eq!(Benchmark::Rosenbrock.value(&zero), 29.0);
        assert_abs_diff_eq!(Benchmark::Rastrigin.value(&[0.5; 2]), 40.5, epsilon = 1e-12);
    }
}
