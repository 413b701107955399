//! Damaged scenario files: an error or a dig, never a panic.

use autoshovel_excavator_dig::TomlFile as _;
use autoshovel_excavator_dig::{excavate, MachineProfile, Scenario};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn damaged_scenarios_never_panic(
        which in 0usize..2,
        pos in 0usize..4000,
        byte in 0u8..128,
        cut in proptest::bool::ANY,
    ) {
        let name = ["paper-over", "paper-under"][which];
        let mut bytes = Scenario::builtin_toml(name).unwrap().as_bytes().to_vec();
        let pos = pos % bytes.len();
        if cut {
            bytes.truncate(pos);
        } else {
            bytes[pos] = byte;
        }
        let text = String::from_utf8_lossy(&bytes);
        if let Ok(scenario) = Scenario::from_toml(&text, "damaged.toml") {
            // A changed digit can make any case: a result or a named error.
            let _ = excavate(&scenario, &MachineProfile::default());
        }
    }
}
