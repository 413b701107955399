//! Which controller tracks the path ([`ControllerKind`]), and a fresh one
//! of that kind with its gains from a scenario's [`ControllerParams`].

use serde::{Deserialize, Serialize};

use crate::controller::{Controller, ControllerParams, Pid, PurePursuit, Stanley};
use crate::fuzzy_tracker::FuzzyTracker;

/// Which controller tracks the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ControllerKind {
    /// The fuzzy tracker on preview and centroid deviation (§4.3, Table 1).
    Fuzzy,
    /// PID on the lateral error (§5.4).
    Pid,
    /// Pure pursuit (geometric), forward and reverse.
    PurePursuit,
    /// Stanley (geometric, heading and cross-track error).
    Stanley,
}

impl ControllerKind {
    /// Every controller, in report order.
    pub const ALL: [ControllerKind; 4] = [
        ControllerKind::Fuzzy,
        ControllerKind::Pid,
        ControllerKind::PurePursuit,
        ControllerKind::Stanley,
    ];

    /// A fresh controller of this kind with its gains from `params`.
    pub fn build(self, params: &ControllerParams) -> Box<dyn Controller> {
        match self {
            ControllerKind::Fuzzy => Box::new(FuzzyTracker::new(params.fuzzy)),
            ControllerKind::Pid => Box::new(Pid::new(params.pid)),
            ControllerKind::PurePursuit => Box::new(PurePursuit {
                params: params.pure_pursuit,
            }),
            ControllerKind::Stanley => Box::new(Stanley {
                params: params.stanley,
            }),
        }
    }
}
