//! Studies: many solves of one scene — the speed-against-error and stiffness sweeps, and
//! parameter sweeps over any scene field, sharded across machines. They build and run
//! [`crate::model::Model`]s; what they produce (data, CSV, JSON, SVG) is [`crate::report`]'s.

pub mod sweep;
pub mod vary;

pub use sweep::{run_sweep, sweep_command};
pub use vary::{vary_command, VarySweep};
