//! The shared library of bondmech's co-simulation FMUs (`libbondmech_fmu.so`, shipped in an
//! FMU as `binaries/<platform>/bondmech_fmu.so` by `bondmech fmu`): the FMI 2.0 and FMI 3.0 C
//! APIs over the bondmech library.
//!
//! [`slave`] is one FMU instance in safe Rust (modes, variables, communication steps, FMU
//! state); `fmi2` and `fmi3` are the C entry points, the only `unsafe` code of the crate: each
//! exported function checks its pointers, runs under [`std::panic::catch_unwind`] (no panic
//! crosses the C boundary; a panic is reported as a fatal status) and logs every error through
//! the importer's logger. See `docs/fmu.md` in the repository.
#![deny(unsafe_code)]
#![deny(missing_docs)]

#[allow(unsafe_code)]
mod ffi;
#[allow(unsafe_code)]
mod fmi2;
#[allow(unsafe_code)]
mod fmi3;
pub mod slave;

pub use slave::{Mode, Slave, SlaveError, State, StepOutcome, REPLAYS};
