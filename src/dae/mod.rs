//! dae (placeholder)
