//! The rope-shovel paper's Tables 4 (the optimal decision of [RS eq. 24] on each
//! pile of Fig. 7) and 5 (what that plan achieves), as data: one table for
//! the planner's comparison, its tests, examples and the demo.

use autoshovel_surface::PileShape;
use serde::Serialize;

use crate::trajectory::Decision;

/// One row of the paper's Tables 4 and 5. Serialises as the summary's
/// `paper` object (the pile itself is left out: it is the row's key).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PaperRow {
    /// The pile.
    #[serde(skip)]
    pub shape: PileShape,
    /// a_x6 [1e-7 m/s⁶] (Table 4).
    pub ax6_1e7: f64,
    /// a_y6 [1e-7 m/s⁶] (Table 4).
    pub ay6_1e7: f64,
    /// g_x [m] (Table 4).
    pub gx_m: f64,
    /// g_y [m] (Table 4).
    pub gy_m: f64,
    /// t_d [s] (Table 4).
    pub td_s: f64,
    /// f = k1·f1 + k2·f2 (Table 5).
    pub f: f64,
    /// f1 [J/kg] (Table 5).
    pub f1_j_per_kg: f64,
    /// f2 [s/kg] (Table 5).
    pub f2_s_per_kg: f64,
    /// m_dig [kg] (Table 5).
    pub m_dig_kg: f64,
    /// Dipper fill factor [%] (Table 5).
    pub fill_pct: f64,
}

impl PaperRow {
    /// Table 4's decision in SI units.
    pub fn decision(&self) -> Decision {
        Decision {
            ax6: self.ax6_1e7 * 1e-7,
            ay6: self.ay6_1e7 * 1e-7,
            td_s: self.td_s,
            gx_m: self.gx_m,
            gy_m: self.gy_m,
        }
    }

    /// Table 5's fill factor as a ratio V/V_cd.
    pub fn fill_factor(&self) -> f64 {
        self.fill_pct / 100.0
    }

    /// Whether the built-in profile's digging resistance was calibrated on
    /// this pile ([`CALIBRATION_PILE`]); the other piles are predictions.
    pub fn calibrated(&self) -> bool {
        self.shape == CALIBRATION_PILE
    }
}

/// The pile on which the built-in profile's k_F and ε are calibrated
/// (SPEC §4.2; [`crate::calibrate`]): Table 5's typical pile.
pub const CALIBRATION_PILE: PileShape = PileShape::Typical;

/// Tables 4 (decision) and 5 (results) of the rope-shovel paper, in Table 5's
/// order: typical, concave, convex, convex–concave.
pub const PAPER_TABLES_4_5: [PaperRow; 4] = [
    PaperRow {
        shape: PileShape::Typical,
        ax6_1e7: -9.98,
        ay6_1e7: 5.41,
        gx_m: 0.3489,
        gy_m: 0.3159,
        td_s: 11.85,
        f: 13.76,
        f1_j_per_kg: 17.19,
        f2_s_per_kg: 5.771,
        m_dig_kg: 2.053,
        fill_pct: 99.72,
    },
    PaperRow {
        shape: PileShape::Concave,
        ax6_1e7: -17.05,
        ay6_1e7: 9.73,
        gx_m: 0.3605,
        gy_m: 0.2943,
        td_s: 11.81,
        f: 13.83,
        f1_j_per_kg: 17.22,
        f2_s_per_kg: 5.925,
        m_dig_kg: 1.991,
        fill_pct: 96.71,
    },
    PaperRow {
        shape: PileShape::Convex,
        ax6_1e7: -5.52,
        ay6_1e7: 11.33,
        gx_m: 0.2413,
        gy_m: 0.2796,
        td_s: 11.57,
        f: 13.87,
        f1_j_per_kg: 17.51,
        f2_s_per_kg: 5.367,
        m_dig_kg: 2.156,
        fill_pct: 104.7,
    },
    PaperRow {
        shape: PileShape::ConvexConcave,
        ax6_1e7: -9.71,
        ay6_1e7: 4.15,
        gx_m: 0.2825,
        gy_m: 0.2352,
        td_s: 11.49,
        f: 12.57,
        f1_j_per_kg: 15.55,
        f2_s_per_kg: 5.625,
        m_dig_kg: 2.045,
        fill_pct: 99.29,
    },
];

/// The row of Tables 4–5 for `shape`.
pub fn paper_row(shape: PileShape) -> &'static PaperRow {
    PAPER_TABLES_4_5
        .iter()
        .find(|r| r.shape == shape)
        .expect("Tables 4-5 hold every pile of Fig. 7")
}
