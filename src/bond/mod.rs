//! bond (placeholder)
