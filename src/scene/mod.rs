//! scene (placeholder)
