//! A generic, seeded Grey Wolf Optimizer (Mirjalili, Mirjalili & Lewis
//! 2014, "Grey Wolf Optimizer", Adv. Eng. Softw. 69:46–61) for box-bounded
//! problems with constraints, as the rope-shovel dig planner uses it
//! (rope-shovel paper §4.5: [RS eq. 37] and good-point-set initialisation).
//!
//! ```
//! use autoshovel_optim::{minimize, Evaluation, FnProblem, GwoParams};
//!
//! // min x² + y² subject to x + y ≥ 1: optimum (0.5, 0.5), value 0.5.
//! let p = FnProblem::new(vec![(-2.0, 2.0); 2], |x: &[f64]| {
//!     Evaluation::new(x[0] * x[0] + x[1] * x[1], (1.0 - x[0] - x[1]).max(0.0))
//! });
//! let res = minimize(&p, &GwoParams { seed: 7, ..GwoParams::default() }, &[])?;
//! assert!(res.best_eval.is_feasible());
//! assert!((res.best_eval.objective - 0.5).abs() < 1e-3);
//! # Ok::<(), autoshovel_optim::OptimError>(())
//! ```
//!
//! - [`minimize`] runs [RS eq. 37] with the leader rule and draw order
//!   documented on it; one seeded ChaCha8 stream makes every draw, so
//!   results are bit-identical across runs and with parallel evaluation on
//!   or off. GWO is biased towards the origin: pose variables on a box
//!   centred at 0 (see [`minimize`]).
//! - [`Init::GoodPointSet`] or [`Init::Random`] (the default setting's) places the
//!   initial pack; warm-start wolves replace its first members.
//! - [`Constraints::FeasibilityRules`] (default, Deb 2000) or
//!   [`Constraints::Penalty`] ranks the wolves.
//! - [`cma_es`]: CMA-ES with IPOP restarts under the same ranking rule, on
//!   the box, within an evaluation budget: it learns a narrow valley's shape
//!   where GWO and coordinate polls creep.
//! - [`benchmarks`] holds sphere, Rosenbrock, Rastrigin and Ackley with the
//!   paper's bounds and published results.

pub mod benchmarks;
mod cma_es;
mod constraints;
mod error;
mod good_point_set;
mod gwo;
mod problem;

pub use cma_es::{cma_es, CmaGeneration, CmaParams, CmaResult};
pub use constraints::Constraints;
pub use error::OptimError;
pub use good_point_set::{good_point_set, smallest_prime_at_least, unit_good_point_set};
pub use gwo::{minimize, Generation, GwoParams, GwoResult, Init};
pub use problem::{Evaluation, FnProblem, Problem};
