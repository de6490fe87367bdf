//! `--shard i/n`: one slice of a parameter sweep's points (parsed by the sweep's
//! [`Shard::parse`](super::vary)).

use serde::{Deserialize, Serialize};

/// `--shard i/n`: the `i`-th (from 1) of `n` slices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which slice, 1 ..= count.
    pub index: usize,
    /// How many slices.
    pub count: usize,
}

impl Shard {
    /// Whether point `k` (from 0) belongs to this shard.
    pub fn owns(&self, k: usize) -> bool {
        k % self.count == self.index - 1
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}
