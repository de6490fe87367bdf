//! sundials (placeholder)
