//! What motor rating do the paper's dig times imply? (issue 13, item 4.)
//! Table 4's digs take 11.5–11.9 s where ours, with nothing binding but the
//! 9 s bound of c3, take 9 s. For each rating the paper leaves out (hoist
//! or crowd speed, hoist or crowd power), this study lowers it until the
//! typical pile's plan ends at Table 5's 11.85 s — k_F and ε recalibrated
//! on that pile at every step, as the built-in profile's are — and then
//! predicts the dig time on the other three piles. It also measures what
//! the paper's own plans (Table 4's decisions on the rebuilt piles) need of
//! the same rating: a rating that explains the dig times must let all four
//! of them run.
//!
//! It prints the table of docs/rope-shovel-dig.md and checks its finding: every
//! rating calibrated this way is below what one of the paper's plans
//! needs, so no single rating explains the four dig times on our model.
//!
//! Slow (several minutes in release): `cargo test --release -p
//! autoshovel-rope-shovel-dig --test rating_study -- --ignored --nocapture`.

use autoshovel_optim::GwoParams;
use autoshovel_rope_shovel_dig::calibrate::{calibrate, CalibrationTarget};
use autoshovel_rope_shovel_dig::{
    paper_pile, paper_row, plan_dig, search_preset, DigModel, DigSearch, DigSurface,
    MachineProfile, PAPER_TABLES_4_5,
};
use autoshovel_terrain::PileShape;

/// The ratings tried: name, index in `DigOutcome::measured`, bisection range.
const RATINGS: [(&str, usize, f64, f64); 4] = [
    ("hoist speed [m/s]", 7, 0.005, 0.1),
    ("crowd speed [m/s]", 9, 0.005, 0.1),
    ("hoist power [W]", 12, 1.0, 15.0),
    ("crowd power [W]", 13, 1.0, 15.0),
];

fn set(p: &mut MachineProfile, index: usize, v: f64) {
    match index {
        7 => p.limits.hoist_speed_max_m_s = v,
        9 => p.limits.crowd_speed_max_m_s = v,
        12 => p.limits.hoist_power_max_w = v,
        _ => p.limits.crowd_power_max_w = v,
    }
}

fn search() -> DigSearch {
    let preset = search_preset();
    DigSearch {
        gwo: GwoParams {
            seed: 1,
            ..preset.gwo
        },
        ..preset
    }
}

/// `p` with k_F and ε recalibrated on `typical`, and its plan's t_d there
/// (None when no feasible plan or calibration exists).
fn calibrated(p: &MachineProfile, typical: &DigSurface) -> Option<(MachineProfile, f64)> {
    let c = calibrate(p, typical, CalibrationTarget::table5_typical(), &search()).ok()?;
    let mut p = p.clone();
    p.material.cutting_resistance_pa = c.cutting_resistance_pa;
    p.material.fill_resistance_ratio = c.fill_resistance_ratio;
    let plan = plan_dig(&DigModel::new(&p, typical.clone()).ok()?, &search(), &[]).ok()?;
    Some((p, plan.outcome.decision.td_s))
}

#[test]
#[ignore]
fn one_rating_calibrated_on_the_typical_pile() {
    let base = MachineProfile::scale_model();
    let surfaces: Vec<DigSurface> = PAPER_TABLES_4_5
        .iter()
        .map(|r| {
            paper_pile(&base, r.shape)
                .unwrap()
                .surface(base.dipper.width_m)
        })
        .collect();
    let target = paper_row(PileShape::Typical).td_s;
    eprintln!("| rating | calibrated on typical (t_d) | k_F Pa, ε | predicted t_d: concave, convex, convex–concave (paper 11.81, 11.57, 11.49) | Table 4's plans need (typical, concave, convex, convex–concave) |");
    for (name, index, lo, hi) in RATINGS {
        // Bisect the rating on a log scale: a lower rating, a longer dig.
        let (mut lo, mut hi) = (lo, hi);
        let mut last = None;
        for _ in 0..10 {
            let mid = (lo * hi).sqrt();
            let mut p = base.clone();
            set(&mut p, index, mid);
            match calibrated(&p, &surfaces[0]) {
                Some((p, td)) if td <= target => {
                    hi = mid;
                    last = Some((p, td, mid));
                }
                _ => lo = mid,
            }
        }
        let Some((p, td, rating)) = last else {
            eprintln!("| {name} | no feasible plan | | | |");
            continue;
        };
        let predicted: Vec<String> = surfaces[1..]
            .iter()
            .map(
                |s| match plan_dig(&DigModel::new(&p, s.clone()).unwrap(), &search(), &[]) {
                    Ok(plan) => format!("{:.2}", plan.outcome.decision.td_s),
                    Err(_) => "infeasible".to_string(),
                },
            )
            .collect();
        let needs: Vec<f64> = PAPER_TABLES_4_5
            .iter()
            .zip(&surfaces)
            .map(|(r, s)| {
                DigModel::new(&p, s.clone())
                    .unwrap()
                    .evaluate(&r.decision())
                    .measured[index]
            })
            .collect();
        eprintln!(
            "| {name} | {rating:.4} ({td:.2} s) | {:.0}, {:.2} | {} | {} |",
            p.material.cutting_resistance_pa,
            p.material.fill_resistance_ratio,
            predicted.join(", "),
            needs
                .iter()
                .map(|v| format!("{v:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        // A rating that stretches the typical dig to the paper's time does
        // not let the paper's own plans run on every pile.
        let most = needs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        assert!(
            rating < most,
            "{name}: {rating} lets every Table 4 plan run"
        );
    }
}
