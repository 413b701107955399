//! The rope-shovel paper's Tables 4 (the optimal decision of [RS eq. 24] on each
//! pile of Fig. 7) and 5 (what that plan achieves), as data: one table for
//! the planner's comparison, its tests, examples and the demo; and the four
//! piles rebuilt from them ([`paper_pile`]).

use autoshovel_terrain::{PileParams, PileShape};
use serde::Serialize;

use crate::dig_surface::DigSurface;
use crate::error::{DigError, Result};
use crate::plan::DigModel;
use crate::profile::MachineProfile;
use crate::trajectory::Decision;

/// One row of the paper's Tables 4 and 5. Serialises as the summary's
/// `paper` object (the pile itself is left out: it is the row's key).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PaperRow {
    /// The pile.
    #[serde(skip)]
    pub shape: PileShape,
    /// a_x6 (1e-7 m/s⁶) (Table 4).
    pub ax6_1e7: f64,
    /// a_y6 (1e-7 m/s⁶) (Table 4).
    pub ay6_1e7: f64,
    /// g_x (m) (Table 4).
    pub gx_m: f64,
    /// g_y (m) (Table 4).
    pub gy_m: f64,
    /// t_d (s) (Table 4).
    pub td_s: f64,
    /// f = k1·f1 + k2·f2 (Table 5).
    pub f: f64,
    /// f1 (J/kg) (Table 5).
    pub f1_j_per_kg: f64,
    /// f2 (s/kg) (Table 5).
    pub f2_s_per_kg: f64,
    /// m_dig (kg) (Table 5).
    pub m_dig_kg: f64,
    /// Dipper fill factor (%) (Table 5).
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

/// Lowest and highest face height tried by [`paper_pile`] (m).
const PILE_HEIGHTS_M: (f64, f64) = (0.02, 0.60);
/// Step of [`paper_pile`]'s scan for the fill's crossings (m).
const PILE_SCAN_STEP_M: f64 = 0.005;

/// A pile of Fig. 7 rebuilt from Tables 4–5: the paper prints neither the
/// piles' size nor their position, only the decision planned on each
/// (Table 4) and what it dug (Table 5). With the dig starting at the toe, as
/// [RS §4.1] sets it ("the intersection point of the material surface and
/// the horizontal plane … was set as the excavation starting point (0,0)"),
/// and the profile of [`autoshovel_terrain::PileShape`] at the 40° repose
/// angle, one number is left free per pile, its face height; it is fitted so
/// that Table 4's decision digs Table 5's fill factor (and with it m_dig,
/// since V_cd is one number for all four rows). The fit is geometric: it
/// depends on the dipper's width and capacity, not on the resistance model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaperPile {
    /// The pile.
    #[serde(skip)]
    pub shape: PileShape,
    /// Fitted face height, toe to crest (m).
    pub face_height_m: f64,
    /// Fill factor of Table 4's decision on the fitted pile.
    pub fill_factor: f64,
    /// Table 5's fill factor, the target.
    pub target_fill_factor: f64,
    /// Further face heights that give the same fill, higher up the scan
    /// (the concave profile sags as it grows, so a much taller concave pile
    /// puts as much material above the same path). The fit takes the
    /// lowest: the four piles then stand within a few centimetres of each
    /// other.
    pub other_heights_m: Vec<f64>,
}

impl PaperPile {
    /// The pile's generator parameters (the paper's 1:30 model of
    /// [`PileParams::paper_model`] with the fitted face height).
    pub fn params(&self) -> PileParams {
        let base = PileParams::paper_model();
        PileParams {
            shape: self.shape,
            face_height_m: self.face_height_m / base.scale,
            ..base
        }
    }

    /// The pile as the planner sees it: toe at the dig start, width-averaged
    /// over the dipper width `width_m`.
    pub fn surface(&self, width_m: f64) -> DigSurface {
        let mut s = DigSurface::from_pile(&self.params(), 0.0, width_m);
        s.source = format!(
            "{} pile of Fig. 7 rebuilt from Tables 4-5 (face {:.4} m, toe at the dig start)",
            self.shape.name(),
            self.face_height_m
        );
        s
    }
}

/// Rebuild the pile `shape` of Fig. 7 from Tables 4–5 for the dipper of
/// `profile` ([`PaperPile`]): scan the face height from 2 to 60 cm for
/// where the fill of Table 4's decision crosses Table 5's, then bisect the
/// lowest crossing to 1 µm.
pub fn paper_pile(profile: &MachineProfile, shape: PileShape) -> Result<PaperPile> {
    let row = paper_row(shape);
    let decision = row.decision();
    let target = row.fill_factor();
    let width = profile.dipper.width_m;
    // Fill of Table 4's decision on a pile of face height h; a pile the
    // model refuses as too small holds nothing within reach.
    let fill = |h: f64| -> f64 {
        let pile = PaperPile {
            shape,
            face_height_m: h,
            fill_factor: f64::NAN,
            target_fill_factor: target,
            other_heights_m: Vec::new(),
        };
        DigModel::new(profile, pile.surface(width))
            .map(|m| m.evaluate(&decision).fill_factor)
            .unwrap_or(0.0)
    };
    let (lo, hi) = PILE_HEIGHTS_M;
    let steps = ((hi - lo) / PILE_SCAN_STEP_M).round() as usize;
    let heights: Vec<f64> = (0..=steps)
        .map(|i| lo + i as f64 * PILE_SCAN_STEP_M)
        .collect();
    let residual: Vec<f64> = heights.iter().map(|&h| fill(h) - target).collect();
    let mut roots = Vec::new();
    for i in 0..steps {
        if (residual[i] < 0.0) == (residual[i + 1] < 0.0) {
            continue;
        }
        let (mut a, mut b) = (heights[i], heights[i + 1]);
        let below_at_a = residual[i] < 0.0;
        while b - a > 1e-6 {
            let m = 0.5 * (a + b);
            if (fill(m) < target) == below_at_a {
                a = m;
            } else {
                b = m;
            }
        }
        roots.push(0.5 * (a + b));
    }
    let Some((&first, rest)) = roots.split_first() else {
        return Err(DigError::Surface(format!(
            "no {} pile between {lo} and {hi} m high gives Table 4's decision Table 5's fill \
             {target} with a dipper of {width} m width and {} m³ capacity",
            shape.name(),
            profile.dipper.capacity_m3
        )));
    };
    Ok(PaperPile {
        shape,
        face_height_m: first,
        fill_factor: fill(first),
        target_fill_factor: target,
        other_heights_m: rest.to_vec(),
    })
}
