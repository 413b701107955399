//! Fuzzy inference (being written).
