//! A run's inputs: the checked scenario and machine profile, each with where
//! it came from (a built-in by name, or a TOML file), and the run itself.

use std::path::Path;

use autoshovel_core::config::TomlFile;

use crate::error::Result;
use crate::excavation::{excavate, Excavation};
use crate::profile::{MachineProfile, EXCAVATOR_15T, EXCAVATOR_15T_TOML};
use crate::scenario::Scenario;

/// What a built-in scenario's source is called in summaries.
pub const BUILTIN_SOURCE: &str = "builtin";

/// The dig and the machine of a run, and where they came from.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The checked scenario.
    pub scenario: Scenario,
    /// `builtin` or the scenario file's path.
    pub scenario_source: String,
    /// The checked machine profile.
    pub profile: MachineProfile,
    /// `builtin excavator-15t` or the profile file's path.
    pub profile_name: String,
}

impl Setup {
    /// Loads the scenario (a built-in name or a TOML file) and the profile
    /// (the built-in 15 t machine without a path); errors name the file,
    /// line and key.
    pub fn load(scenario: &str, profile: Option<&Path>) -> Result<Self> {
        let scenario_source = if Scenario::builtin_toml(scenario).is_some() {
            BUILTIN_SOURCE.to_string()
        } else {
            scenario.to_string()
        };
        let scenario = Scenario::from_name_or_file(scenario)?;
        let (profile, profile_name) = match profile {
            Some(p) => (MachineProfile::load(p)?, p.display().to_string()),
            None => (
                MachineProfile::excavator_15t(),
                format!("{BUILTIN_SOURCE} {EXCAVATOR_15T}"),
            ),
        };
        Ok(Self {
            scenario,
            scenario_source,
            profile,
            profile_name,
        })
    }

    /// Plans and executes the dig ([`excavate`]).
    pub fn run(&self) -> Result<Excavation> {
        excavate(&self.scenario, &self.profile)
    }

    /// The scenario as TOML: a built-in's commented text, or the checked
    /// file printed back.
    pub fn scenario_toml(scenario: &str) -> Result<String> {
        Ok(match Scenario::builtin_toml(scenario) {
            Some(text) => text.to_string(),
            None => Scenario::from_name_or_file(scenario)?.to_toml(),
        })
    }

    /// The machine profile as TOML: the built-in one's commented text
    /// without a path, or the checked file printed back.
    pub fn profile_toml(profile: Option<&Path>) -> Result<String> {
        Ok(match profile {
            Some(p) => MachineProfile::load(p)?.to_toml(),
            None => EXCAVATOR_15T_TOML.to_string(),
        })
    }
}
