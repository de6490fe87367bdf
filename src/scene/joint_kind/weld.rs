//! `"weld"`: the two bodies fixed together at their initial relative pose
//! (docs/scene-format.md §5).

use super::own_fields::{OwnFields, OwnKey, ReadOwnFields};
use crate::scene::error::Problems;
use crate::scene::fields::Fields;
use crate::scene::space::Dimension;
use crate::scene::tree::Json;

/// The two bodies are fixed together.
#[derive(Debug, Clone, PartialEq)]
pub struct Weld;

impl OwnFields for Weld {
    fn type_name(&self) -> &'static str {
        Self::TYPE
    }

    fn validate(&self, _p: &mut Problems, _dim: Dimension, _path: &str, _bodies: &[String; 2]) {}

    fn write(&self, _e: &mut Vec<(&'static str, Json)>) {}
}

impl ReadOwnFields for Weld {
    const TYPE: &'static str = "weld";
    const KEYS: &'static [OwnKey] = &[];

    fn parse(_p: &mut Problems, _f: &Fields<'_>, _axis: Option<Vec<f64>>) -> Option<Self> {
        Some(Weld)
    }
}
