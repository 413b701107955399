//! Small reusable fuzzy inference: membership functions, linguistic
//! variables, rule bases and Mamdani min / max / centroid inference
//! (Mamdani & Assilian 1975, "An experiment in linguistic synthesis with a
//! fuzzy logic controller"), on which autoshovel's crawler
//! trajectory-tracking controller is built (electric-shovel paper §4.3:
//! inputs e (m) and ec, output u (rpm), seven triangular terms each and a
//! 7 × 7 rule table).
//!
//! The crate is generic — any number of inputs, any terms, any rules; the
//! paper's table is only a test fixture and example here.
//!
//! ```
//! use autoshovel_fuzzy::{MamdaniSystem, RuleBase, Variable};
//!
//! let names = ["N", "Z", "P"];
//! let x = Variable::evenly_spaced_triangles("x", -1.0, 1.0, &names)?;
//! let y = Variable::evenly_spaced_triangles("y", -10.0, 10.0, &names)?;
//! let mut rules = RuleBase::new();
//! for t in names {
//!     rules.add(std::slice::from_ref(&x), &y, &[t], t, 1.0)?;
//! }
//! let sys = MamdaniSystem::new(vec![x], y, rules)?;
//! assert!(sys.infer(&[0.0])?.abs() < 1e-9);
//! assert!(sys.infer(&[0.7])? > 0.0);
//! # Ok::<(), autoshovel_fuzzy::FuzzyError>(())
//! ```
//!
//! Definitions are validated once by [`MamdaniSystem::new`]; inference then
//! only checks its arguments, never panics and, on the
//! [`MamdaniSystem::infer`] / [`MamdaniSystem::infer_with`] paths, never
//! allocates.

mod error;
mod mamdani;
mod membership;
pub mod presets;
mod rules;
mod surface;
mod variable;

pub use error::FuzzyError;
pub use mamdani::{MamdaniSystem, Scratch, Trace, DEFAULT_RESOLUTION};
pub use membership::Membership;
pub use rules::{Rule, RuleBase};
pub use surface::Surface;
pub use variable::Variable;
