//! The four piles of Fig. 7 planned with one setup beside the paper's
//! Tables 4–5 ([`all_surfaces`]): our plan, the paper's plan evaluated on
//! our model of the same pile, and the relative differences. The built-in
//! profile's digging resistance is calibrated on [`CALIBRATION_PILE`]; the
//! other piles are predictions.

use std::time::Instant;

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

use crate::error::Result;
use crate::job::{plan_pile, DigSetup, DigSummary, Pile, PlanFields, PlannedPile};
use crate::paper::{PaperRow, CALIBRATION_PILE, PAPER_TABLES_4_5};
use crate::plan::DigModel;

/// The paper's plan (Table 4's decision) evaluated on our model of its pile.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaperPlanCheck {
    /// f on our model.
    pub f: f64,
    /// m_dig on our model (kg).
    pub m_dig_kg: f64,
    /// Fill factor on our model.
    pub fill_factor: f64,
    /// Whether it meets c1–c18 on our model.
    pub feasible: bool,
    /// The constraints it violates there.
    pub violated: Vec<String>,
}

/// One pile of the comparison: the pile's summary (without the geometry)
/// beside the paper's row.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurfaceComparison {
    /// The pile's plan summary.
    #[serde(flatten)]
    pub plan: DigSummary,
    /// Tables 4–5's row.
    pub paper: PaperRow,
    /// The paper's plan on our model.
    pub paper_plan_on_this_model: PaperPlanCheck,
    /// The pile, rebuilt from Tables 4–5 ([`crate::paper::paper_pile`]).
    pub rebuilt_pile: Option<crate::paper::PaperPile>,
    /// (ours − paper) / paper of m_dig (none without a plan).
    pub m_dig_rel_diff: Option<f64>,
    /// (ours − paper) / paper of f (none without a plan).
    pub f_rel_diff: Option<f64>,
    /// Whether the profile was calibrated on this pile (the others are predictions).
    pub calibrated: bool,
    /// The pile's files, relative to the comparison's folder (set by the writer).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub files: Option<Vec<String>>,
}

/// The summary of `plan-dig --all-surfaces`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AllSurfacesSummary {
    /// Always "plan-dig".
    pub job: &'static str,
    /// Always true.
    pub all_surfaces: bool,
    /// Optimiser seed.
    pub seed: u64,
    /// Search coordinates.
    pub search_space: &'static str,
    /// First-pack placement.
    pub init: &'static str,
    /// The profile's path or "builtin scale-model".
    pub profile: String,
    /// Cutting resistance k_F (Pa).
    pub k_f_pa: f64,
    /// Fill resistance ratio ε.
    pub epsilon: f64,
    /// The piles in Table 5's order.
    pub surfaces: Vec<SurfaceComparison>,
    /// Whether every pile has a feasible plan.
    pub feasible: bool,
    /// Same as `feasible`.
    pub success: bool,
    /// Wall time of the four plans (ms).
    pub plan_time_ms: f64,
}

impl AllSurfacesSummary {
    /// The errors of the piles without a feasible plan, one a line; none when all have one.
    pub fn error(&self) -> Option<String> {
        let failed: Vec<&str> = self
            .surfaces
            .iter()
            .filter_map(|s| s.plan.error.as_deref())
            .collect();
        (!failed.is_empty()).then(|| failed.join("\n"))
    }
}

/// One pile of [`all_surfaces`] with everything needed to draw it.
#[derive(Debug, Clone)]
pub struct ComparedPile {
    /// Tables 4–5's row.
    pub paper: &'static PaperRow,
    /// The pile.
    pub pile: Pile,
    /// Its plan (with the pile's own summary, geometry included).
    pub planned: PlannedPile,
}

/// What [`all_surfaces`] returns.
#[derive(Debug, Clone)]
pub struct AllSurfaces {
    /// The summary.
    pub summary: AllSurfacesSummary,
    /// The piles, in the summary's order.
    pub piles: Vec<ComparedPile>,
}

/// Plans the four piles of Fig. 7 in Table 5's order with `setup` and
/// compares them with Tables 4–5; `on_pile` sees each pile's comparison as
/// it is done (for progress lines).
pub fn all_surfaces(
    setup: &DigSetup,
    mut on_pile: impl FnMut(&SurfaceComparison),
) -> Result<AllSurfaces> {
    let t0 = Instant::now();
    let mut surfaces = Vec::new();
    let mut piles = Vec::new();
    for paper in &PAPER_TABLES_4_5 {
        let pile = Pile::shape(paper.shape, &setup.profile)?;
        let planned = plan_pile(&pile, setup)?;
        let model = DigModel::new(&setup.profile, pile.surface.clone())?;
        let theirs = model.evaluate(&paper.decision());
        let mut plan = planned.summary.clone();
        if let Some(p) = plan.plan.as_mut() {
            p.geometry = None;
        }
        let ours = plan.plan.as_ref();
        let rel =
            |v: Option<f64>, paper: f64| v.filter(|v| v.is_finite()).map(|v| (v - paper) / paper);
        let s = SurfaceComparison {
            m_dig_rel_diff: rel(ours.map(|p| p.m_dig_kg), paper.m_dig_kg),
            f_rel_diff: rel(ours.map(|p| p.f), paper.f),
            plan,
            paper: *paper,
            rebuilt_pile: pile.rebuilt.clone(),
            paper_plan_on_this_model: PaperPlanCheck {
                f: theirs.f,
                m_dig_kg: theirs.m_dig_kg,
                fill_factor: theirs.fill_factor,
                feasible: theirs.feasible(),
                violated: theirs.violated(),
            },
            calibrated: paper.shape == CALIBRATION_PILE,
            files: None,
        };
        on_pile(&s);
        surfaces.push(s);
        piles.push(ComparedPile {
            paper,
            pile,
            planned,
        });
    }
    let feasible = surfaces.iter().all(|s| s.plan.error.is_none());
    let summary = AllSurfacesSummary {
        job: "plan-dig",
        all_surfaces: true,
        seed: setup.gwo.seed,
        search_space: setup.search.name(),
        init: setup.gwo.init.name(),
        profile: setup.profile_name.clone(),
        k_f_pa: setup.profile.material.cutting_resistance_pa,
        epsilon: setup.profile.material.fill_resistance_ratio,
        surfaces,
        feasible,
        success: feasible,
        plan_time_ms: t0.elapsed().as_secs_f64() * 1e3,
    };
    Ok(AllSurfaces { summary, piles })
}

/// One column of the comparison of Tables 4–5.
#[derive(Debug, Clone, Copy)]
pub struct TableColumn {
    /// Label with units.
    pub label: &'static str,
    /// Key in [`TableSummary`] and `table.csv` (`<key>` ours, `<key>_paper` the paper's).
    pub key: &'static str,
    /// Decimals shown in the markdown table.
    pub decimals: usize,
    /// Our value in the table's units.
    pub ours: fn(&PlanFields) -> f64,
    /// The paper's value.
    pub paper: fn(&PaperRow) -> f64,
}

/// The columns of the comparison, in Tables 4–5's units.
pub const TABLE_COLUMNS: [TableColumn; 10] = [
    TableColumn {
        label: "a_x6 [1e-7]",
        key: "ax6_1e7",
        decimals: 2,
        ours: |p| p.ax6 * 1e7,
        paper: |r| r.ax6_1e7,
    },
    TableColumn {
        label: "a_y6 [1e-7]",
        key: "ay6_1e7",
        decimals: 2,
        ours: |p| p.ay6 * 1e7,
        paper: |r| r.ay6_1e7,
    },
    TableColumn {
        label: "g_x [m]",
        key: "gx_m",
        decimals: 4,
        ours: |p| p.gx_m,
        paper: |r| r.gx_m,
    },
    TableColumn {
        label: "g_y [m]",
        key: "gy_m",
        decimals: 4,
        ours: |p| p.gy_m,
        paper: |r| r.gy_m,
    },
    TableColumn {
        label: "t_d [s]",
        key: "td_s",
        decimals: 2,
        ours: |p| p.td_s,
        paper: |r| r.td_s,
    },
    TableColumn {
        label: "f",
        key: "f",
        decimals: 2,
        ours: |p| p.f,
        paper: |r| r.f,
    },
    TableColumn {
        label: "f1 [J/kg]",
        key: "f1_j_per_kg",
        decimals: 2,
        ours: |p| p.f1_j_per_kg,
        paper: |r| r.f1_j_per_kg,
    },
    TableColumn {
        label: "f2 [s/kg]",
        key: "f2_s_per_kg",
        decimals: 3,
        ours: |p| p.f2_s_per_kg,
        paper: |r| r.f2_s_per_kg,
    },
    TableColumn {
        label: "m_dig [kg]",
        key: "m_dig_kg",
        decimals: 3,
        ours: |p| p.m_dig_kg,
        paper: |r| r.m_dig_kg,
    },
    TableColumn {
        label: "fill [%]",
        key: "fill_pct",
        decimals: 2,
        ours: |p| p.fill_factor * 100.0,
        paper: |r| r.fill_pct,
    },
];

/// One pile's row of the comparison: ours and the paper's value of each of
/// [`TABLE_COLUMNS`]. Serialises flat: `<key>`, `<key>_paper`, …,
/// `m_dig_rel_diff`, `f_rel_diff`, `feasible`.
#[derive(Debug, Clone, PartialEq)]
pub struct TableRow {
    /// The pile's name.
    pub surface: String,
    /// Our values (none without a plan or when not finite).
    pub ours: [Option<f64>; 10],
    /// The paper's values.
    pub paper: [f64; 10],
    /// (ours − paper) / paper of m_dig.
    pub m_dig_rel_diff: Option<f64>,
    /// (ours − paper) / paper of f.
    pub f_rel_diff: Option<f64>,
    /// Whether our plan is feasible.
    pub feasible: bool,
    /// Whether the profile was calibrated on this pile.
    pub calibrated: bool,
}

impl TableRow {
    /// The row of one pile of the comparison.
    pub fn new(s: &SurfaceComparison) -> Self {
        Self {
            surface: s.plan.header.surface.clone(),
            ours: TABLE_COLUMNS.map(|c| {
                s.plan
                    .plan
                    .as_ref()
                    .map(|p| (c.ours)(p))
                    .filter(|v| v.is_finite())
            }),
            paper: TABLE_COLUMNS.map(|c| (c.paper)(&s.paper)),
            m_dig_rel_diff: s.m_dig_rel_diff,
            f_rel_diff: s.f_rel_diff,
            feasible: s.plan.feasible,
            calibrated: s.calibrated,
        }
    }
}

impl Serialize for TableRow {
    fn serialize<S: Serializer>(&self, ser: S) -> std::result::Result<S::Ok, S::Error> {
        let mut m = ser.serialize_map(Some(2 * TABLE_COLUMNS.len() + 4))?;
        for ((c, ours), paper) in TABLE_COLUMNS.iter().zip(&self.ours).zip(&self.paper) {
            m.serialize_entry(c.key, ours)?;
            m.serialize_entry(&format!("{}_paper", c.key), paper)?;
        }
        m.serialize_entry("m_dig_rel_diff", &self.m_dig_rel_diff)?;
        m.serialize_entry("f_rel_diff", &self.f_rel_diff)?;
        m.serialize_entry("feasible", &self.feasible)?;
        m.serialize_entry("calibrated", &self.calibrated)?;
        m.end()
    }
}

/// A flat view of an `--all-surfaces` summary for a report table: the
/// setting, then pile → ours and the paper's value of each column.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableSummary {
    /// Optimiser seed.
    pub seed: u64,
    /// Search coordinates.
    pub search_space: &'static str,
    /// First-pack placement.
    pub init: &'static str,
    /// The profile.
    pub profile: String,
    /// Cutting resistance k_F (Pa).
    pub k_f_pa: f64,
    /// Fill resistance ratio ε.
    pub epsilon: f64,
    /// Whether every pile has a feasible plan.
    pub success: bool,
    /// Wall time (ms).
    pub plan_time_ms: f64,
    /// One row per pile, keyed by its name.
    #[serde(flatten)]
    pub rows: std::collections::BTreeMap<String, TableRow>,
}

/// The [`TableSummary`] of `all`.
pub fn table_summary(all: &AllSurfacesSummary) -> TableSummary {
    TableSummary {
        seed: all.seed,
        search_space: all.search_space,
        init: all.init,
        profile: all.profile.clone(),
        k_f_pa: all.k_f_pa,
        epsilon: all.epsilon,
        success: all.success,
        plan_time_ms: all.plan_time_ms,
        rows: all
            .surfaces
            .iter()
            .map(|s| (s.plan.header.surface.clone(), TableRow::new(s)))
            .collect(),
    }
}
