//! mech (placeholder)
