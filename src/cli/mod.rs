//! The command line's parts below `main.rs`: its grammar, reading scenes and writing outputs,
//! signals and failures, and the commands that are more than a call into the library.

pub(crate) mod animate;
pub(crate) mod args;
pub(crate) mod failure;
pub(crate) mod fmu;
pub(crate) mod graph;
pub(crate) mod output;
pub(crate) mod run;
pub(crate) mod scene_input;
pub(crate) mod sensitivity;
pub(crate) mod signals;
pub(crate) mod sweep;
