//! The FMI 2.0 co-simulation C API (`fmi2Functions.h`), over [`crate::slave::Slave`].
//!
//! Every function takes the importer's pointers on FMI's terms (a component from
//! `fmi2Instantiate`, arrays of the given lengths, NUL-terminated strings); those contracts are
//! the `# Safety` of each function. Each body runs under [`no_panic`].
#![deny(unsafe_op_in_unsafe_fn)]
#![warn(clippy::undocumented_unsafe_blocks)]
#![allow(non_snake_case, clippy::missing_safety_doc)]

use std::ffi::{c_char, c_int, c_uint, c_void, CString};

use crate::ffi::{no_panic, resource_dir, slice, slice_mut, text};
use crate::slave::{Mode, Slave, SlaveError, State, StepOutcome};

type Fmi2Status = c_int;
const OK: Fmi2Status = 0;
const WARNING: Fmi2Status = 1;
const DISCARD: Fmi2Status = 2;
const ERROR: Fmi2Status = 3;
const FATAL: Fmi2Status = 4;

const CO_SIMULATION: c_int = 1;

/// `fmi2StatusKind`.
const DO_STEP_STATUS: c_int = 0;
const LAST_SUCCESSFUL_TIME: c_int = 2;
const TERMINATED: c_int = 3;

type Fmi2Boolean = c_int;
type Fmi2ValueReference = c_uint;

/// `fmi2CallbackLogger` (variadic: the message is a printf format).
type Logger = unsafe extern "C" fn(
    component_environment: *mut c_void,
    instance_name: *const c_char,
    status: Fmi2Status,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    logger: Option<Logger>,
    allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, Fmi2Status)>,
    component_environment: *mut c_void,
}

/// What an `fmi2Component` points at.
struct Instance {
    slave: Slave,
    name: CString,
    logger: Option<Logger>,
    environment: *mut c_void,
    logging_on: bool,
    start_time: f64,
    stop_time: Option<f64>,
    last_status: Fmi2Status,
}

/// Calls the importer's logger (if any) with `message` as text.
fn log_to(
    logger: Option<Logger>,
    environment: *mut c_void,
    name: &CString,
    status: Fmi2Status,
    category: &str,
    message: &str,
) {
    let Some(logger) = logger else { return };
    let category = CString::new(category).unwrap_or_default();
    let message = CString::new(message.replace('\0', " ")).unwrap_or_default();
    // SAFETY: the importer's logger, called with its own environment pointer, valid C strings
    // that outlive the call and the format "%s" consuming exactly one string argument.
    unsafe {
        logger(
            environment,
            name.as_ptr(),
            status,
            category.as_ptr(),
            c"%s".as_ptr(),
            message.as_ptr(),
        )
    };
}

impl Instance {
    fn log(&self, status: Fmi2Status, category: &str, message: &str) {
        if status == OK && !self.logging_on {
            return;
        }
        log_to(
            self.logger,
            self.environment,
            &self.name,
            status,
            category,
            message,
        );
    }
}

/// Runs `f` on the instance behind `c`: errors are logged and returned as `fmi2Error`, a panic
/// as `fmi2Fatal`.
fn with(
    c: *mut c_void,
    f: impl FnOnce(&mut Instance) -> Result<Fmi2Status, SlaveError>,
) -> Fmi2Status {
    if c.is_null() {
        return ERROR;
    }
    // SAFETY: a non-null component is the `Box<Instance>` that `fmi2Instantiate` leaked and
    // `fmi2FreeInstance` has not freed yet (FMI forbids calls after free); FMI calls on one
    // instance are not concurrent, so this is the only reference.
    let inst = unsafe { &mut *(c as *mut Instance) };
    let status = match no_panic(|| f(inst)) {
        Ok(Ok(s)) => s,
        Ok(Err(e)) => {
            inst.log(ERROR, "logStatusError", &e.to_string());
            ERROR
        }
        Err(panic) => {
            inst.log(FATAL, "logStatusError", &panic);
            FATAL
        }
    };
    inst.last_status = status;
    status
}

fn bad(what: &str) -> SlaveError {
    SlaveError::Call(format!("{what}: a null pointer where values were expected"))
}

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    logging_on: Fmi2Boolean,
    _n_categories: usize,
    _categories: *const *const c_char,
) -> Fmi2Status {
    with(c, |inst| {
        inst.logging_on = logging_on != 0;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    fmu_guid: *const c_char,
    fmu_resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: Fmi2Boolean,
    logging_on: Fmi2Boolean,
) -> *mut c_void {
    no_panic(|| {
        // SAFETY: FMI passes NUL-terminated strings (or null) valid for the call.
        let (name, guid, location) = unsafe {
            (
                text(instance_name).unwrap_or_default(),
                text(fmu_guid),
                text(fmu_resource_location),
            )
        };
        let (logger, environment) = if functions.is_null() {
            (None, std::ptr::null_mut())
        } else {
            // SAFETY: non-null, points at the importer's fmi2CallbackFunctions (FMI 2.0 §2.1.5).
            let f = unsafe { &*functions };
            (f.logger, f.component_environment)
        };
        let name = CString::new(name.replace('\0', " ")).unwrap_or_default();
        let slave = if fmu_type != CO_SIMULATION {
            Err(SlaveError::Call(
                "this FMU supports co-simulation only (fmi2CoSimulation)".into(),
            ))
        } else {
            match (guid, location) {
                (Some(guid), Some(location)) => Slave::new(&resource_dir(&location), &guid),
                _ => Err(SlaveError::Call(
                    "fmi2Instantiate needs the GUID and the resource location".into(),
                )),
            }
        };
        match slave {
            Ok(slave) => {
                let inst = Instance {
                    start_time: slave.time(),
                    slave,
                    name,
                    logger,
                    environment,
                    logging_on: logging_on != 0,
                    stop_time: None,
                    last_status: OK,
                };
                Box::into_raw(Box::new(inst)) as *mut c_void
            }
            Err(e) => {
                log_to(
                    logger,
                    environment,
                    &name,
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
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if c.is_null() {
        return;
    }
    let _ = no_panic(|| {
        // SAFETY: the pointer `fmi2Instantiate` leaked, freed once (FMI forbids any call after
        // fmi2FreeInstance).
        drop(unsafe { Box::from_raw(c as *mut Instance) });
    });
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tolerance_defined: Fmi2Boolean,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: Fmi2Boolean,
    stop_time: f64,
) -> Fmi2Status {
    with(c, |inst| {
        inst.start_time = start_time;
        inst.stop_time = (stop_time_defined != 0).then_some(stop_time);
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Fmi2Status {
    with(c, |inst| {
        let (start, stop) = (inst.start_time, inst.stop_time);
        inst.slave.enter_initialization(start, stop)?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Fmi2Status {
    with(c, |inst| {
        inst.slave.exit_initialization()?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> Fmi2Status {
    with(c, |inst| {
        inst.slave.terminate();
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> Fmi2Status {
    with(c, |inst| {
        inst.slave.reset();
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut f64,
) -> Fmi2Status {
    with(c, |inst| {
        // SAFETY: FMI: `vr` holds `nvr` references and `value` has room for `nvr` values.
        let (vr, out) = unsafe { (slice(vr, nvr), slice_mut(value, nvr)) };
        let (Some(vr), Some(out)) = (vr, out) else {
            return Err(bad("fmi2GetReal"));
        };
        inst.slave.get(vr, out)?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const f64,
) -> Fmi2Status {
    with(c, |inst| {
        // SAFETY: FMI: `vr` and `value` hold `nvr` elements each.
        let (vr, values) = unsafe { (slice(vr, nvr), slice(value, nvr)) };
        let (Some(vr), Some(values)) = (vr, values) else {
            return Err(bad("fmi2SetReal"));
        };
        inst.slave.set(vr, values)?;
        Ok(OK)
    })
}

/// Getters and setters of the types the FMU has no variables of: fine for no references.
fn no_variables(kind: &str, nvr: usize) -> Result<Fmi2Status, SlaveError> {
    if nvr == 0 {
        Ok(OK)
    } else {
        Err(SlaveError::Call(format!(
            "this FMU has no {kind} variables (all are Real)"
        )))
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: *mut c_void,
    _vr: *const Fmi2ValueReference,
    nvr: usize,
    _value: *mut c_int,
) -> Fmi2Status {
    with(c, |_| no_variables("Integer", nvr))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: *mut c_void,
    _vr: *const Fmi2ValueReference,
    nvr: usize,
    _value: *mut Fmi2Boolean,
) -> Fmi2Status {
    with(c, |_| no_variables("Boolean", nvr))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: *mut c_void,
    _vr: *const Fmi2ValueReference,
    nvr: usize,
    _value: *mut *const c_char,
) -> Fmi2Status {
    with(c, |_| no_variables("String", nvr))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: *mut c_void,
    _vr: *const Fmi2ValueReference,
    nvr: usize,
    _value: *const c_int,
) -> Fmi2Status {
    with(c, |_| no_variables("Integer", nvr))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: *mut c_void,
    _vr: *const Fmi2ValueReference,
    nvr: usize,
    _value: *const Fmi2Boolean,
) -> Fmi2Status {
    with(c, |_| no_variables("Boolean", nvr))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: *mut c_void,
    _vr: *const Fmi2ValueReference,
    nvr: usize,
    _value: *const *const c_char,
) -> Fmi2Status {
    with(c, |_| no_variables("String", nvr))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: *mut c_void, state: *mut *mut c_void) -> Fmi2Status {
    with(c, |inst| {
        if state.is_null() {
            return Err(bad("fmi2GetFMUstate"));
        }
        let new = inst.slave.state()?;
        // SAFETY: `state` is non-null and points at the importer's fmi2FMUstate; a non-null
        // value there is a state this function allocated, which FMI lets us overwrite in place.
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
pub unsafe extern "C" fn fmi2SetFMUstate(c: *mut c_void, state: *mut c_void) -> Fmi2Status {
    with(c, |inst| {
        if state.is_null() {
            return Err(bad("fmi2SetFMUstate"));
        }
        // SAFETY: a non-null fmi2FMUstate is a `Box<State>` from fmi2GetFMUstate or
        // fmi2DeSerializeFMUstate, not yet freed.
        let s = unsafe { &*(state as *const State) };
        inst.slave.restore(s)?;
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: *mut c_void, state: *mut *mut c_void) -> Fmi2Status {
    with(c, |_| {
        if state.is_null() {
            return Ok(OK);
        }
        // SAFETY: `state` points at an fmi2FMUstate that is null or a `Box<State>` of ours;
        // it is freed once and set to null as FMI requires.
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
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: *mut c_void,
    state: *mut c_void,
    size: *mut usize,
) -> Fmi2Status {
    with(c, |_| {
        if state.is_null() || size.is_null() {
            return Err(bad("fmi2SerializedFMUstateSize"));
        }
        // SAFETY: `state` is one of our `Box<State>`s, `size` a writable size_t.
        unsafe { *size = (*(state as *const State)).to_bytes().len() };
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: *mut c_void,
    state: *mut c_void,
    serialized: *mut c_char,
    size: usize,
) -> Fmi2Status {
    with(c, |_| {
        if state.is_null() {
            return Err(bad("fmi2SerializeFMUstate"));
        }
        // SAFETY: `state` is one of our `Box<State>`s.
        let bytes = unsafe { (*(state as *const State)).to_bytes() };
        // SAFETY: FMI: `serialized` has room for `size` bytes.
        let Some(out) = (unsafe { slice_mut(serialized as *mut u8, size) }) else {
            return Err(bad("fmi2SerializeFMUstate"));
        };
        if out.len() != bytes.len() {
            return Err(SlaveError::Call(format!(
                "fmi2SerializeFMUstate: size {size}, the state needs {} bytes",
                bytes.len()
            )));
        }
        out.copy_from_slice(&bytes);
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: *mut c_void,
    serialized: *const c_char,
    size: usize,
    state: *mut *mut c_void,
) -> Fmi2Status {
    with(c, |_| {
        // SAFETY: FMI: `serialized` holds `size` bytes.
        let Some(bytes) = (unsafe { slice(serialized as *const u8, size) }) else {
            return Err(bad("fmi2DeSerializeFMUstate"));
        };
        if state.is_null() {
            return Err(bad("fmi2DeSerializeFMUstate"));
        }
        let s = State::from_bytes(bytes)?;
        // SAFETY: `state` is a writable fmi2FMUstate: null, or a `Box<State>` of ours that is
        // replaced (and freed) here.
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
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: *mut c_void,
    _unknown: *const Fmi2ValueReference,
    _n_unknown: usize,
    _known: *const Fmi2ValueReference,
    _n_known: usize,
    _dv_known: *const f64,
    _dv_unknown: *mut f64,
) -> Fmi2Status {
    with(c, |_| {
        Err(SlaveError::Call(
            "directional derivatives are not provided".into(),
        ))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    _vr: *const Fmi2ValueReference,
    _nvr: usize,
    _order: *const c_int,
    _value: *const f64,
) -> Fmi2Status {
    with(c, |_| {
        Err(SlaveError::Call(
            "input derivatives are not used (inputs are held constant over a step)".into(),
        ))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: *mut c_void,
    _vr: *const Fmi2ValueReference,
    _nvr: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> Fmi2Status {
    with(c, |_| {
        Err(SlaveError::Call(
            "output derivatives are not provided".into(),
        ))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior_to_current_point: Fmi2Boolean,
) -> Fmi2Status {
    with(c, |inst| {
        match inst
            .slave
            .do_step(current_communication_point, communication_step_size)?
        {
            StepOutcome::Done => {
                for (name, t) in &inst.slave.events {
                    inst.log(OK, "logEvents", &format!("{name} at t = {t}"));
                }
                Ok(OK)
            }
            StepOutcome::Terminated(t) => {
                inst.log(
                    WARNING,
                    "logEvents",
                    &format!("a stop event of the scene ended the simulation at t = {t}"),
                );
                Ok(DISCARD)
            }
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: *mut c_void) -> Fmi2Status {
    with(c, |_| {
        Err(SlaveError::Call(
            "fmi2CancelStep: doStep never returns fmi2Pending".into(),
        ))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: *mut c_void,
    kind: c_int,
    value: *mut Fmi2Status,
) -> Fmi2Status {
    with(c, |inst| {
        if value.is_null() || kind != DO_STEP_STATUS {
            return Err(SlaveError::Call(format!(
                "fmi2GetStatus: status kind {kind} is not available"
            )));
        }
        // SAFETY: non-null, a writable fmi2Status.
        unsafe { *value = inst.last_status };
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: *mut c_void,
    kind: c_int,
    value: *mut f64,
) -> Fmi2Status {
    with(c, |inst| {
        if value.is_null() || kind != LAST_SUCCESSFUL_TIME {
            return Err(SlaveError::Call(format!(
                "fmi2GetRealStatus: status kind {kind} is not available"
            )));
        }
        // SAFETY: non-null, a writable fmi2Real.
        unsafe { *value = inst.slave.time() };
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: *mut c_void,
    kind: c_int,
    _value: *mut c_int,
) -> Fmi2Status {
    with(c, |_| {
        Err(SlaveError::Call(format!(
            "fmi2GetIntegerStatus: status kind {kind} is not available"
        )))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: *mut c_void,
    kind: c_int,
    value: *mut Fmi2Boolean,
) -> Fmi2Status {
    with(c, |inst| {
        if value.is_null() || kind != TERMINATED {
            return Err(SlaveError::Call(format!(
                "fmi2GetBooleanStatus: status kind {kind} is not available"
            )));
        }
        // SAFETY: non-null, a writable fmi2Boolean.
        unsafe { *value = Fmi2Boolean::from(inst.slave.mode() == Mode::Terminated) };
        Ok(OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: *mut c_void,
    kind: c_int,
    _value: *mut *const c_char,
) -> Fmi2Status {
    with(c, |_| {
        Err(SlaveError::Call(format!(
            "fmi2GetStringStatus: status kind {kind} is not available"
        )))
    })
}
