//! Damaged and extreme machine profiles: an error or a plan, never a panic.

use autoshovel_rope_shovel_dig::profile::SCALE_MODEL_TOML;
use autoshovel_rope_shovel_dig::{DigModel, DigSurface, MachineProfile, TomlFile};
use autoshovel_terrain::PileShape;
use proptest::prelude::*;

/// The profile with the `k`-th number scaled by `factor` (or negated).
fn scale_number(k: usize, factor: f64) -> String {
    let mut seen = 0;
    SCALE_MODEL_TOML
        .lines()
        .map(|line| {
            let Some((key, rest)) = line.split_once('=') else {
                return line.to_string();
            };
            let value = rest.split('#').next().unwrap_or("").trim();
            match value.parse::<f64>() {
                Ok(v) if !key.trim().starts_with('#') => {
                    seen += 1;
                    if seen - 1 == k {
                        format!("{key}= {:?}", v * factor)
                    } else {
                        line.to_string()
                    }
                }
                _ => line.to_string(),
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn damaged_profile_text_never_panics(pos in 0usize..4000, byte in 0u8..128, cut in proptest::bool::ANY) {
        let mut bytes = SCALE_MODEL_TOML.as_bytes().to_vec();
        let pos = pos % bytes.len();
        if cut {
            bytes.truncate(pos);
        } else {
            bytes[pos] = byte;
        }
        let text = String::from_utf8_lossy(&bytes);
        let _ = MachineProfile::from_toml(&text, "damaged.toml");
    }

    /// Any number of the profile scaled by up to 10⁴ either way, or negated:
    /// refused with an error, or a model whose evaluation returns numbers.
    #[test]
    fn extreme_profile_values_are_refused_or_planned(
        k in 0usize..60,
        exp in -4.0f64..4.0,
        negate in proptest::bool::ANY,
    ) {
        let factor = 10f64.powf(exp) * if negate { -1.0 } else { 1.0 };
        let text = scale_number(k, factor);
        let Ok(p) = MachineProfile::from_toml(&text, "extreme.toml") else {
            return Ok(());
        };
        let Ok(model) = DigModel::new(&p, DigSurface::from_shape(PileShape::Typical, p.dipper.width_m)) else {
            return Ok(());
        };
        let mid: Vec<f64> = autoshovel_optim::Problem::bounds(&model)
            .iter()
            .map(|&(lo, hi)| 0.5 * (lo + hi))
            .collect();
        let out = model.evaluate(&model.decision(&mid));
        prop_assert!(!out.violation.is_nan());
        prop_assert!(!out.f.is_nan());
    }
}
