//! Planned against measured: the rope-shovel paper's testbed validation
//! ([RS §5], [RS Table 6], [RS Fig. 20]) as a job, `validate-dig`. A plan's
//! folder and a measured record ([`record`]), aligned in time by
//! cross-correlation of the forces ([`align()`]), compared force by force and
//! in dug mass and dig time ([`compare`], [`ValidateSummary`]); and a
//! measurement simulated from a plan with known errors ([`simulate`]).

pub mod align;
pub mod compare;
pub mod record;
pub mod simulate;

pub use align::{align, interpolate, AlignParams, Alignment};
pub use compare::{
    validate, AlignedSeries, Deviation, ForceComparison, Paired, TravelComparison, ValidateSummary,
    Validation,
};
pub use record::{
    ForceRecord, MeasuredRecord, PlannedRecord, MEASURED_OPTIONAL, MEASURED_REQUIRED, MIN_SAMPLES,
};
pub use simulate::{simulate_measurement, MeasurementModel};
