//! The FMI 3.0 co-simulation C API (`fmi3Functions.h`), over [`crate::slave::Slave`].
//!
//! Every function of the standard is exported (importers such as FMPy bind them all); those of
//! model exchange, scheduled execution, clocks and the types this FMU has no variables of
//! return `fmi3Error` with a logged message. The importer's pointers follow FMI's contracts (an
//! instance from `fmi3InstantiateCoSimulation`, arrays of the given lengths, NUL-terminated
//! strings): that is the `# Safety` of each function. Each body runs under [`no_panic`].
#![deny(unsafe_op_in_unsafe_fn)]
#![warn(clippy::undocumented_unsafe_blocks)]
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::too_many_arguments)]

use std::ffi::{c_char, c_int, c_void, CString};

use crate::ffi::{no_panic, resource_dir, slice, slice_mut, text};
use crate::slave::{Slave, SlaveError, State, StepOutcome};

type Fmi3Status = c_int;
const OK: Fmi3Status = 0;
const WARNING: Fmi3Status = 1;
const ERROR: Fmi3Status = 3;
const FATAL: Fmi3Status = 4;

type Vr = u32;

/// `fmi3LogMessageCallback`.
type LogMessage = unsafe extern "C" fn(
    instance_environment: *mut c_void,
    status: Fmi3Status,
    category: *const c_char,
    message: *const c_char,
);

/// `fmi3IntermediateUpdateCallback` (never called: no intermediate updates).
type IntermediateUpdate = unsafe extern "C" fn(
    instance_environment: *mut c_void,
    intermediate_update_time: f64,
    intermediate_variable_set_requested: bool,
    intermediate_variable_get_allowed: bool,
    intermediate_step_finished: bool,
    can_return_early: bool,
    early_return_requested: *mut bool,
    early_return_time: *mut f64,
);

/// What an `fmi3Instance` points at.
struct Instance {
    slave: Slave,
    logger: Option<LogMessage>,
    environment: *mut c_void,
    logging_on: bool,
}

/// Calls the importer's logger (if any).
fn log_to(
    logger: Option<LogMessage>,
    environment: *mut c_void,
    status: Fmi3Status,
    category: &str,
    message: &str,
) {
    let Some(logger) = logger else { return };
    let category = CString::new(category).unwrap_or_default();
    let message = CString::new(message.replace('\0', " ")).unwrap_or_default();
    // SAFETY: the importer's callback with its own environment pointer and C strings that
    // outlive the call.
    unsafe { logger(environment, status, category.as_ptr(), message.as_ptr()) };
}

impl Instance {
    fn log(&self, status: Fmi3Status, category: &str, message: &str) {
        if status == OK && !self.logging_on {
            return;
        }
        log_to(self.logger, self.environment, status, category, message);
    }
}

/// Runs `f` on the instance behind `inst`: errors are logged and returned as `fmi3Error`, a
/// panic as `fmi3Fatal`.
fn with(
    inst: *mut c_void,
    f: impl FnOnce(&mut Instance) -> Result<Fmi3Status, SlaveError>,
) -> Fmi3Status {
    if inst.is_null() {
        return ERROR;
    }
    // SAFETY: a non-null instance is the `Box<Instance>` that fmi3InstantiateCoSimulation
    // leaked and fmi3FreeInstance has not freed (FMI forbids calls after free); FMI calls on
    // one instance are not concurrent, so this is the only reference.
    let inst = unsafe { &mut *(inst as *mut Instance) };
    match no_panic(|| f(inst)) {
        Ok(Ok(s)) => s,
        Ok(Err(e)) => {
            inst.log(ERROR, "logStatusError", &e.to_string());
            ERROR
        }
        Err(panic) => {
            inst.log(FATAL, "logStatusError", &panic);
            FATAL
        }
    }
}

fn bad(what: &str) -> SlaveError {
    SlaveError::Call(format!("{what}: a null pointer where values were expected"))
}

fn unsupported(what: &str) -> Result<Fmi3Status, SlaveError> {
    Err(SlaveError::Call(format!(
        "{what} is not supported: this is a co-simulation FMU without event mode, clocks or model exchange"
    )))
}

/// Getters and setters of the types the FMU has no variables of: fine for no references.
fn no_variables(kind: &str, n: usize) -> Result<Fmi3Status, SlaveError> {
    if n == 0 {
        Ok(OK)
    } else {
        Err(SlaveError::Call(format!(
            "this FMU has no {kind} variables (all are Float64)"
        )))
    }
}

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    inst: *mut c_void,
    logging_on: bool,
    _n_categories: usize,
    _categories: *const *const c_char,
) -> Fmi3Status {
    with(inst, |i| {
        i.logging_on = logging_on;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: *const c_char,
    instantiation_token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    logging_on: bool,
    _event_mode_used: bool,
    _early_return_allowed: bool,
    _required_intermediate_variables: *const Vr,
    _n_required_intermediate_variables: usize,
    instance_environment: *mut c_void,
    log_message: Option<LogMessage>,
    _intermediate_update: Option<IntermediateUpdate>,
) -> *mut c_void {
    no_panic(|| {
        // SAFETY: FMI passes NUL-terminated strings (or null) valid for the call.
        let (_name, token, path) = unsafe {
            (
                text(instance_name),
                text(instantiation_token),
                text(resource_path),
            )
        };
        let slave = match (token, path) {
            (Some(token), Some(path)) => Slave::new(&resource_dir(&path), &token),
            _ => Err(SlaveError::Call(
                "fmi3InstantiateCoSimulation needs the instantiation token and the resource path"
                    .into(),
            )),
        };
        match slave {
            Ok(slave) => Box::into_raw(Box::new(Instance {
                slave,
                logger: log_message,
                environment: instance_environment,
                logging_on,
            })) as *mut c_void,
            Err(e) => {
                log_to(
                    log_message,
                    instance_environment,
                    ERROR,
                    "logStatusError",
                    &e.to_string(),
                );
                std::ptr::null_mut()
            }
        }
    })
    .unwrap_or(std::ptr::null_mut())
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _instance_name: *const c_char,
    _instantiation_token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    instance_environment: *mut c_void,
    log_message: Option<LogMessage>,
) -> *mut c_void {
    log_to(
        log_message,
        instance_environment,
        ERROR,
        "logStatusError",
        "this FMU supports co-simulation only",
    );
    std::ptr::null_mut()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _instance_name: *const c_char,
    _instantiation_token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    instance_environment: *mut c_void,
    log_message: Option<LogMessage>,
    _clock_update: Option<unsafe extern "C" fn(*mut c_void)>,
    _lock_preemption: Option<unsafe extern "C" fn()>,
    _unlock_preemption: Option<unsafe extern "C" fn()>,
) -> *mut c_void {
    log_to(
        log_message,
        instance_environment,
        ERROR,
        "logStatusError",
        "this FMU supports co-simulation only",
    );
    std::ptr::null_mut()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(inst: *mut c_void) {
    if inst.is_null() {
        return;
    }
    let _ = no_panic(|| {
        // SAFETY: the pointer fmi3InstantiateCoSimulation leaked, freed once (FMI forbids any
        // call after fmi3FreeInstance).
        drop(unsafe { Box::from_raw(inst as *mut Instance) });
    });
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    inst: *mut c_void,
    _tolerance_defined: bool,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: bool,
    stop_time: f64,
) -> Fmi3Status {
    with(inst, |i| {
        i.slave
            .enter_initialization(start_time, stop_time_defined.then_some(stop_time))?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(inst: *mut c_void) -> Fmi3Status {
    with(inst, |i| {
        i.slave.exit_initialization()?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterEventMode(inst: *mut c_void) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3EnterEventMode"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(inst: *mut c_void) -> Fmi3Status {
    with(inst, |i| {
        i.slave.terminate();
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(inst: *mut c_void) -> Fmi3Status {
    with(inst, |i| {
        i.slave.reset();
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    inst: *mut c_void,
    value_references: *const Vr,
    n_value_references: usize,
    values: *mut f64,
    n_values: usize,
) -> Fmi3Status {
    with(inst, |i| {
        // SAFETY: FMI: `value_references` holds `n_value_references` references and `values`
        // has room for `n_values` values.
        let (vr, out) = unsafe {
            (
                slice(value_references, n_value_references),
                slice_mut(values, n_values),
            )
        };
        let (Some(vr), Some(out)) = (vr, out) else {
            return Err(bad("fmi3GetFloat64"));
        };
        i.slave.get(vr, out)?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    inst: *mut c_void,
    value_references: *const Vr,
    n_value_references: usize,
    values: *const f64,
    n_values: usize,
) -> Fmi3Status {
    with(inst, |i| {
        // SAFETY: FMI: the arrays hold `n_value_references` and `n_values` elements.
        let (vr, v) = unsafe {
            (
                slice(value_references, n_value_references),
                slice(values, n_values),
            )
        };
        let (Some(vr), Some(v)) = (vr, v) else {
            return Err(bad("fmi3SetFloat64"));
        };
        i.slave.set(vr, v)?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat32(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut f32,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Float32", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat32(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const f32,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Float32", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt8(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut i8,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Int8", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt8(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const i8,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Int8", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt8(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut u8,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("UInt8", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt8(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const u8,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("UInt8", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt16(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut i16,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Int16", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt16(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const i16,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Int16", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt16(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut u16,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("UInt16", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt16(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const u16,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("UInt16", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut i32,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Int32", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const i32,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Int32", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt32(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut u32,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("UInt32", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt32(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const u32,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("UInt32", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt64(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut i64,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Int64", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt64(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const i64,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Int64", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt64(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut u64,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("UInt64", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt64(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const u64,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("UInt64", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut bool,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Boolean", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const bool,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Boolean", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetString(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut *const c_char,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("String", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetString(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const *const c_char,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("String", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBinary(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _value_sizes: *mut usize,
    _values: *mut *const u8,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Binary", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBinary(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _value_sizes: *const usize,
    _values: *const *const u8,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| no_variables("Binary", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetClock(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *mut bool,
) -> Fmi3Status {
    with(inst, |_| no_variables("Clock", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetClock(
    inst: *mut c_void,
    _value_references: *const Vr,
    n_value_references: usize,
    _values: *const bool,
) -> Fmi3Status {
    with(inst, |_| no_variables("Clock", n_value_references))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
    inst: *mut c_void,
    _value_reference: Vr,
    _n_dependencies: *mut usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetNumberOfVariableDependencies"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    inst: *mut c_void,
    _dependent: Vr,
    _element_indices_of_dependent: *mut usize,
    _independents: *mut Vr,
    _element_indices_of_independents: *mut usize,
    _dependency_kinds: *mut c_int,
    _n_dependencies: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetVariableDependencies"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(inst: *mut c_void, state: *mut *mut c_void) -> Fmi3Status {
    with(inst, |i| {
        if state.is_null() {
            return Err(bad("fmi3GetFMUState"));
        }
        let new = i.slave.state()?;
        // SAFETY: `state` is non-null and points at the importer's fmi3FMUState; a non-null
        // value there is a state this function allocated, which FMI lets us overwrite.
        unsafe {
            if (*state).is_null() {
                *state = Box::into_raw(Box::new(new)) as *mut c_void;
            } else {
                *(*state as *mut State) = new;
            }
        }
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(inst: *mut c_void, state: *mut c_void) -> Fmi3Status {
    with(inst, |i| {
        if state.is_null() {
            return Err(bad("fmi3SetFMUState"));
        }
        // SAFETY: a non-null fmi3FMUState is a `Box<State>` from fmi3GetFMUState or
        // fmi3DeserializeFMUState, not yet freed.
        let s = unsafe { &*(state as *const State) };
        i.slave.restore(s)?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(
    inst: *mut c_void,
    state: *mut *mut c_void,
) -> Fmi3Status {
    with(inst, |_| {
        if state.is_null() {
            return Ok(OK);
        }
        // SAFETY: `state` points at an fmi3FMUState that is null or one of our
        // `Box<State>`s; freed once and set to null as FMI requires.
        unsafe {
            if !(*state).is_null() {
                drop(Box::from_raw(*state as *mut State));
                *state = std::ptr::null_mut();
            }
        }
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    inst: *mut c_void,
    state: *mut c_void,
    size: *mut usize,
) -> Fmi3Status {
    with(inst, |_| {
        if state.is_null() || size.is_null() {
            return Err(bad("fmi3SerializedFMUStateSize"));
        }
        // SAFETY: `state` is one of our `Box<State>`s, `size` a writable size_t.
        unsafe { *size = (*(state as *const State)).to_bytes().len() };
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    inst: *mut c_void,
    state: *mut c_void,
    serialized: *mut u8,
    size: usize,
) -> Fmi3Status {
    with(inst, |_| {
        if state.is_null() {
            return Err(bad("fmi3SerializeFMUState"));
        }
        // SAFETY: `state` is one of our `Box<State>`s.
        let bytes = unsafe { (*(state as *const State)).to_bytes() };
        // SAFETY: FMI: `serialized` has room for `size` bytes.
        let Some(out) = (unsafe { slice_mut(serialized, size) }) else {
            return Err(bad("fmi3SerializeFMUState"));
        };
        if out.len() != bytes.len() {
            return Err(SlaveError::Call(format!(
                "fmi3SerializeFMUState: size {size}, the state needs {} bytes",
                bytes.len()
            )));
        }
        out.copy_from_slice(&bytes);
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    inst: *mut c_void,
    serialized: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Fmi3Status {
    with(inst, |_| {
        // SAFETY: FMI: `serialized` holds `size` bytes.
        let Some(bytes) = (unsafe { slice(serialized, size) }) else {
            return Err(bad("fmi3DeserializeFMUState"));
        };
        if state.is_null() {
            return Err(bad("fmi3DeserializeFMUState"));
        }
        let s = State::from_bytes(bytes)?;
        // SAFETY: `state` is a writable fmi3FMUState: null, or one of our `Box<State>`s that
        // is replaced (and freed) here.
        unsafe {
            if !(*state).is_null() {
                drop(Box::from_raw(*state as *mut State));
            }
            *state = Box::into_raw(Box::new(s)) as *mut c_void;
        }
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    inst: *mut c_void,
    _unknowns: *const Vr,
    _n_unknowns: usize,
    _knowns: *const Vr,
    _n_knowns: usize,
    _seed: *const f64,
    _n_seed: usize,
    _sensitivity: *mut f64,
    _n_sensitivity: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetDirectionalDerivative"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    inst: *mut c_void,
    _unknowns: *const Vr,
    _n_unknowns: usize,
    _knowns: *const Vr,
    _n_knowns: usize,
    _seed: *const f64,
    _n_seed: usize,
    _sensitivity: *mut f64,
    _n_sensitivity: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetAdjointDerivative"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterConfigurationMode(inst: *mut c_void) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3EnterConfigurationMode"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitConfigurationMode(inst: *mut c_void) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3ExitConfigurationMode"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalDecimal(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _intervals: *mut f64,
    _qualifiers: *mut c_int,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetIntervalDecimal"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalFraction(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _counters: *mut u64,
    _resolutions: *mut u64,
    _qualifiers: *mut c_int,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetIntervalFraction"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftDecimal(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _shifts: *mut f64,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetShiftDecimal"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftFraction(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _counters: *mut u64,
    _resolutions: *mut u64,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetShiftFraction"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalDecimal(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _intervals: *const f64,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3SetIntervalDecimal"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalFraction(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _counters: *const u64,
    _resolutions: *const u64,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3SetIntervalFraction"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftDecimal(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _shifts: *const f64,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3SetShiftDecimal"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftFraction(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _counters: *const u64,
    _resolutions: *const u64,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3SetShiftFraction"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(inst: *mut c_void) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3EvaluateDiscreteStates"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    inst: *mut c_void,
    _discrete_states_need_update: *mut bool,
    _terminate_simulation: *mut bool,
    _nominals_of_continuous_states_changed: *mut bool,
    _values_of_continuous_states_changed: *mut bool,
    _next_event_time_defined: *mut bool,
    _next_event_time: *mut f64,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3UpdateDiscreteStates"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(inst: *mut c_void) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3EnterContinuousTimeMode"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
    inst: *mut c_void,
    _no_set_fmu_state_prior_to_current_point: bool,
    _enter_event_mode: *mut bool,
    _terminate_simulation: *mut bool,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3CompletedIntegratorStep"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetTime(inst: *mut c_void, _time: f64) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3SetTime"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetContinuousStates(
    inst: *mut c_void,
    _continuous_states: *const f64,
    _n_continuous_states: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3SetContinuousStates"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
    inst: *mut c_void,
    _derivatives: *mut f64,
    _n_continuous_states: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetContinuousStateDerivatives"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetEventIndicators(
    inst: *mut c_void,
    _event_indicators: *mut f64,
    _n_event_indicators: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetEventIndicators"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStates(
    inst: *mut c_void,
    _continuous_states: *mut f64,
    _n_continuous_states: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetContinuousStates"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
    inst: *mut c_void,
    _nominals: *mut f64,
    _n_continuous_states: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetNominalsOfContinuousStates"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(
    inst: *mut c_void,
    _n_event_indicators: *mut usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetNumberOfEventIndicators"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(
    inst: *mut c_void,
    _n_continuous_states: *mut usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetNumberOfContinuousStates"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(inst: *mut c_void) -> Fmi3Status {
    // the FMU enters step mode when initialisation ends (no event mode)
    with(inst, |_| Ok(OK))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    inst: *mut c_void,
    _value_references: *const Vr,
    _n_value_references: usize,
    _orders: *const i32,
    _values: *mut f64,
    _n_values: usize,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3GetOutputDerivatives"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    inst: *mut c_void,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior_to_current_point: bool,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> Fmi3Status {
    with(inst, |i| {
        let outcome = i
            .slave
            .do_step(current_communication_point, communication_step_size);
        let (terminate, time) = match &outcome {
            Ok(StepOutcome::Done) => (false, i.slave.time()),
            Ok(StepOutcome::Terminated(t)) => (true, *t),
            Err(_) => (false, i.slave.time()),
        };
        // SAFETY: FMI: each out-pointer is null or a writable fmi3Boolean / fmi3Float64.
        unsafe {
            if !event_handling_needed.is_null() {
                *event_handling_needed = false;
            }
            if !terminate_simulation.is_null() {
                *terminate_simulation = terminate;
            }
            if !early_return.is_null() {
                *early_return = terminate;
            }
            if !last_successful_time.is_null() {
                *last_successful_time = time;
            }
        }
        match outcome? {
            StepOutcome::Done => {
                for (name, t) in &i.slave.events {
                    i.log(OK, "logEvents", &format!("{name} at t = {t}"));
                }
                Ok(OK)
            }
            StepOutcome::Terminated(t) => {
                i.log(
                    WARNING,
                    "logEvents",
                    &format!("a stop event of the scene ended the simulation at t = {t}"),
                );
                Ok(OK)
            }
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ActivateModelPartition(
    inst: *mut c_void,
    _clock_reference: Vr,
    _activation_time: f64,
) -> Fmi3Status {
    with(inst, |_| unsupported("fmi3ActivateModelPartition"))
}
