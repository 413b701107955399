//! Surfaces (being written).
