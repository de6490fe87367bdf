//! expr (placeholder)
