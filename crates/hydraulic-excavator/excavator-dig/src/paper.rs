//! The hydraulic-excavator paper's reported results for its §3 case (0.9 m³
//! from (7, 0) at 0.7 m depth, step 0.05 m), as data: used by the example,
//! the demo and the docs, typed nowhere else.

use crate::preimage::AvoidSide;

/// One case the paper reports (Figs. 5–6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperCase {
    /// Our built-in scenario of the case.
    pub scenario: &'static str,
    /// The paper's figure.
    pub figure: &'static str,
    /// The side the bucket passes the boulder.
    pub side: AvoidSide,
    /// The volume the paper's dig achieved (m³).
    pub volume_m3: f64,
    /// The contact times the paper reports (s).
    pub contacts_s: &'static [f64],
}

/// The paper's two cases: over (Fig. 5) and under (Fig. 6).
pub const PAPER_CASES: [PaperCase; 2] = [
    PaperCase {
        scenario: "paper-over",
        figure: "Fig. 5",
        side: AvoidSide::Over,
        volume_m3: 0.909,
        contacts_s: &[1.6],
    },
    PaperCase {
        scenario: "paper-under",
        figure: "Fig. 6",
        side: AvoidSide::Under,
        volume_m3: 0.915,
        contacts_s: &[2.8, 5.3],
    },
];

/// The paper's case of a built-in scenario, if it has one.
pub fn paper_case(scenario: &str) -> Option<&'static PaperCase> {
    PAPER_CASES.iter().find(|c| c.scenario == scenario)
}

impl PaperCase {
    /// The contact times as the paper prints them, e.g. "2.8, 5.3".
    pub fn contacts_text(&self) -> String {
        self.contacts_s
            .iter()
            .map(|t| format!("{t}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}
