//! One FMU instance in safe Rust: variables, modes, communication steps, FMU state.
//!
//! The solve runs on a worker thread per *segment*: one [`bondmech::Model::solve_streaming`]
//! over the communication grid, which hands each row over a channel and then waits until the
//! next step asks for the next row (nothing is computed ahead). While the inputs stay the same
//! and the importer keeps to the grid, every step continues the same integration: the same
//! numbers as `bondmech run` with those output times.
//!
//! A new segment starts when an input changes, when the importer leaves the grid (another step
//! size) and after an FMU state is restored. The first [`REPLAYS`] of them *replay*: the solve
//! from the scene's start time, the inputs' history as piecewise-constant expressions of `t`
//! ([`bondmech::scene::inputs::piecewise_constant`]), rows before the current time skipped —
//! exactly the run of the scene with those inputs written as step functions of `t`, at a cost
//! that grows with the time reached. Later ones *restart from the state*: the scene with every
//! body's position, angle, velocity and angular velocity taken from the last row, its start
//! time moved there, the springs' rest lengths fixed at their initial lengths and the inputs at
//! their new values — a fresh integration whose cost does not grow with time, equal to the
//! continued one within the solver's tolerance. A raw bond graph (no bodies to put the state
//! in) and the decoupled twin (a restart would project its stretched joint springs back onto
//! the joints) always replay.

use std::ops::ControlFlow;
use std::path::Path;
use std::sync::mpsc::{sync_channel, Receiver, RecvError, SyncSender};
use std::thread::JoinHandle;

use bondmech::fmu::{FmuConfig, VariableKind, CONFIG_FILE, SCENE_FILE};
use bondmech::scene::inputs::piecewise_constant;
use bondmech::scene::path::{scene_from_json_with, Assignment, ScenePath};
use bondmech::scene::{output_grid, Dimension, PointRef, Scene};
use bondmech::FormulationKind;
use bondmech::Model;
use serde::{Deserialize, Serialize};

/// How many new segments (input changes, steps off the grid, restored states) replay the
/// solve from the start before they restart from the state instead.
pub const REPLAYS: usize = 8;

/// Why a call failed; the C layer logs the message and returns an error status.
#[derive(Debug, thiserror::Error)]
pub enum SlaveError {
    /// The FMU's resources cannot be read.
    #[error("reading the FMU's resources ({path}): {message}")]
    Resources {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// The importer called something the FMU's mode does not allow, or with bad arguments.
    #[error("{0}")]
    Call(String),
    /// The scene with the parameters set is invalid, or the model cannot be built.
    #[error("{0}")]
    Model(String),
    /// The solve failed (the message names the element and the time).
    #[error("the solve failed: {0}")]
    Solve(String),
}

type Result<T> = std::result::Result<T, SlaveError>;

/// The instance's mode (FMI's states, those bondmech distinguishes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Mode {
    /// Instantiated: parameters and inputs may be set.
    Instantiated,
    /// Initialization mode: parameters and inputs may be set.
    Initialization,
    /// Stepping (FMI 3 step mode, FMI 2 slave initialized).
    Stepping,
    /// After a `stop` event of the scene: the simulation is over.
    Terminated,
    /// After an error: only getters, reset and free.
    Failed,
}

/// What [`Slave::do_step`] reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepOutcome {
    /// The step reached its end.
    Done,
    /// A `stop` event ended the simulation at this time (before or at the step's end).
    Terminated(f64),
}

/// Messages from a segment's worker thread.
enum Msg {
    /// An output row: time and columns.
    Row(f64, Vec<f64>),
    /// The solve ended: successfully (a `stop` event, or the end of the grid), or the error.
    Done(std::result::Result<(), String>),
}

/// A running solve on its own thread, paused after each row until asked for the next.
struct Segment {
    rows: Receiver<Msg>,
    /// One message asks for the next row; closing it stops the solve.
    next: Option<SyncSender<()>>,
    /// Whether the worker waits for a request (it has handed over a row).
    paused: bool,
    handle: Option<JoinHandle<()>>,
    /// The grid times still to come (front first).
    grid: std::collections::VecDeque<f64>,
}

impl Segment {
    /// The next message: asks for it first if the worker is paused.
    fn recv(&mut self) -> std::result::Result<Msg, RecvError> {
        if self.paused {
            if let Some(next) = &self.next {
                // an error means the worker has ended: its last message is in `rows`
                let _ = next.send(());
            }
            self.paused = false;
        }
        let m = self.rows.recv()?;
        if matches!(m, Msg::Row(..)) {
            self.paused = true;
        }
        Ok(m)
    }
}

impl Drop for Segment {
    fn drop(&mut self) {
        // closing the request channel stops the solve at its next row (a paused worker at
        // once); wait for it: the library must not be unloaded while one of its threads runs
        self.next = None;
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// Everything a restored FMU state needs (serialised as JSON by `SerializeFMUState`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct State {
    time: f64,
    values: Vec<f64>,
    row: Vec<f64>,
    history: Vec<(f64, Vec<f64>)>,
    step: Option<f64>,
    replays: usize,
    mode: Mode,
    stop_time: Option<f64>,
}

/// One FMU instance.
pub struct Slave {
    config: FmuConfig,
    scene_text: String,
    values: Vec<f64>,
    mode: Mode,
    /// The scene with the parameters set (built at the end of initialisation).
    scene: Option<Scene>,
    /// Column index of each variable that is an output.
    columns: Vec<Option<usize>>,
    /// The names of the run's columns.
    column_names: Vec<String>,
    /// The last row (every column) at `time`: where a restart starts from.
    row: Vec<f64>,
    /// Value references of the inputs, in order.
    inputs: Vec<usize>,
    time: f64,
    stop_time: Option<f64>,
    /// The inputs' values from each time on (first entry: the start time).
    history: Vec<(f64, Vec<f64>)>,
    step: Option<f64>,
    /// New segments that replayed from the start so far (the first [`REPLAYS`] do).
    replays: usize,
    segment: Option<Segment>,
    /// Events met during the last step (name, time), for the log.
    pub events: Vec<(String, f64)>,
}

impl Slave {
    /// An instance reading its scene and variables from the FMU's `resources` directory;
    /// `token` must be the model description's GUID / instantiation token.
    pub fn new(resources: &Path, token: &str) -> Result<Slave> {
        let read = |name: &str| {
            let path = resources.join(name);
            std::fs::read_to_string(&path).map_err(|e| SlaveError::Resources {
                path: path.display().to_string(),
                message: e.to_string(),
            })
        };
        let config_text = read(CONFIG_FILE)?;
        let config: FmuConfig =
            serde_json::from_str(&config_text).map_err(|e| SlaveError::Resources {
                path: resources.join(CONFIG_FILE).display().to_string(),
                message: e.to_string(),
            })?;
        if config.instantiation_token != token {
            return Err(SlaveError::Call(format!(
                "instantiation token {token} does not match the FMU's {}",
                config.instantiation_token
            )));
        }
        let scene_text = read(SCENE_FILE)?;
        Ok(Slave::from_parts(config, scene_text))
    }

    /// An instance of the FMU described by `config` over the scene `scene_text`.
    pub fn from_parts(config: FmuConfig, scene_text: String) -> Slave {
        let inputs = config
            .of_kind(VariableKind::Input)
            .map(|v| v.value_reference as usize)
            .collect();
        let mut slave = Slave {
            values: Vec::new(),
            columns: vec![None; config.variables.len()],
            column_names: Vec::new(),
            row: Vec::new(),
            inputs,
            time: config.start_time,
            mode: Mode::Instantiated,
            scene: None,
            stop_time: None,
            history: Vec::new(),
            step: None,
            replays: 0,
            segment: None,
            events: Vec::new(),
            config,
            scene_text,
        };
        slave.reset();
        slave
    }

    /// Back to the instantiated mode with the start values.
    pub fn reset(&mut self) {
        self.segment = None;
        self.values = self
            .config
            .variables
            .iter()
            .map(|v| v.start.unwrap_or(0.0))
            .collect();
        self.values[0] = self.config.start_time;
        self.time = self.config.start_time;
        self.mode = Mode::Instantiated;
        self.scene = None;
        self.stop_time = None;
        self.history.clear();
        self.step = None;
        self.replays = 0;
    }

    /// Ends the simulation: stops the solver thread (the values stay readable).
    pub fn terminate(&mut self) {
        self.segment = None;
        if self.mode == Mode::Stepping {
            self.mode = Mode::Terminated;
        }
    }

    /// The mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The current time.
    pub fn time(&self) -> f64 {
        self.time
    }

    fn fail(&mut self, e: SlaveError) -> SlaveError {
        self.mode = Mode::Failed;
        self.segment = None;
        e
    }

    fn variable_index(&self, vr: u32) -> Result<usize> {
        let i = vr as usize;
        if i < self.config.variables.len() {
            Ok(i)
        } else {
            Err(SlaveError::Call(format!(
                "unknown value reference {vr} (the FMU has {})",
                self.config.variables.len()
            )))
        }
    }

    /// Values by value reference.
    pub fn get(&self, vrs: &[u32], out: &mut [f64]) -> Result<()> {
        if vrs.len() != out.len() {
            return Err(SlaveError::Call(format!(
                "{} value references but room for {} values",
                vrs.len(),
                out.len()
            )));
        }
        for (vr, o) in vrs.iter().zip(out.iter_mut()) {
            let i = self.variable_index(*vr)?;
            *o = if i == 0 { self.time } else { self.values[i] };
        }
        Ok(())
    }

    /// Sets parameters (before the end of initialisation) and inputs.
    pub fn set(&mut self, vrs: &[u32], values: &[f64]) -> Result<()> {
        if vrs.len() != values.len() {
            return Err(SlaveError::Call(format!(
                "{} value references but {} values",
                vrs.len(),
                values.len()
            )));
        }
        for (vr, x) in vrs.iter().zip(values) {
            let i = self.variable_index(*vr)?;
            let v = &self.config.variables[i];
            let settable = match v.kind {
                VariableKind::Parameter => {
                    matches!(self.mode, Mode::Instantiated | Mode::Initialization)
                }
                VariableKind::Input => self.mode != Mode::Failed,
                VariableKind::Time | VariableKind::Output => false,
            };
            if !settable {
                return Err(SlaveError::Call(format!(
                    "'{}' ({:?}) cannot be set in mode {:?}{}",
                    v.name,
                    v.kind,
                    self.mode,
                    if v.kind == VariableKind::Parameter {
                        " (parameters are fixed after initialisation)"
                    } else {
                        ""
                    }
                )));
            }
            if !x.is_finite() {
                return Err(SlaveError::Call(format!(
                    "'{}': not a finite value ({x})",
                    v.name
                )));
            }
            self.values[i] = *x;
        }
        Ok(())
    }

    /// Enters initialisation mode; `start`/`stop` as the importer gives them.
    pub fn enter_initialization(&mut self, start: f64, stop: Option<f64>) -> Result<()> {
        if self.mode != Mode::Instantiated {
            return Err(SlaveError::Call(format!(
                "enter initialisation mode in mode {:?}",
                self.mode
            )));
        }
        if start != self.config.start_time {
            return Err(SlaveError::Call(format!(
                "start time {start}: this FMU starts at the scene's t_start = {} (set solve.t_start as a parameter at export to change it)",
                self.config.start_time
            )));
        }
        self.stop_time = stop.filter(|t| t.is_finite() && *t > start);
        self.mode = Mode::Initialization;
        Ok(())
    }

    /// Leaves initialisation: builds the model with the parameters and computes the outputs at
    /// the start time.
    pub fn exit_initialization(&mut self) -> Result<()> {
        if self.mode != Mode::Initialization {
            return Err(SlaveError::Call(format!(
                "exit initialisation mode in mode {:?}",
                self.mode
            )));
        }
        match self.initialize() {
            Ok(()) => {
                self.mode = Mode::Stepping;
                Ok(())
            }
            Err(e) => Err(self.fail(e)),
        }
    }

    fn initialize(&mut self) -> Result<()> {
        let mut sets = Vec::new();
        for v in self.config.of_kind(VariableKind::Parameter) {
            let path = ScenePath::parse(&v.name).map_err(|e| SlaveError::Model(e.to_string()))?;
            let x = self.values[v.value_reference as usize];
            let json = if x.fract() == 0.0 && x.abs() < 9.0e15 {
                serde_json::json!(x as i64)
            } else {
                serde_json::json!(x)
            };
            sets.push(Assignment::new(path, json));
        }
        let scene = scene_from_json_with(&self.scene_text, &self.config.model_name, &sets)
            .map_err(|e| SlaveError::Model(e.to_string().replace('\n', "; ")))?;
        self.time = scene.solve.t_start;
        self.history = vec![(self.time, self.input_values())];
        let model = Model::new(&self.scene_with_inputs(&scene))
            .map_err(|e| SlaveError::Model(e.to_string()))?;
        let mut opts = model.default_options();
        opts.output_times = vec![self.time];
        let first = model
            .solve(&opts)
            .map_err(|e| SlaveError::Solve(e.to_string()))?;
        for (i, v) in self.config.variables.iter().enumerate() {
            if v.kind == VariableKind::Output {
                let c = first.columns.iter().position(|c| *c == v.name);
                if c.is_none() {
                    return Err(SlaveError::Model(format!(
                        "output '{}' is not a column of the run",
                        v.name
                    )));
                }
                self.columns[i] = c;
            }
        }
        let row = first
            .rows
            .first()
            .ok_or_else(|| SlaveError::Solve("no row at the start time".into()))?
            .clone();
        self.set_outputs(&row);
        self.row = row;
        self.column_names = first.columns;
        self.scene = Some(scene);
        Ok(())
    }

    fn input_values(&self) -> Vec<f64> {
        self.inputs.iter().map(|&i| self.values[i]).collect()
    }

    /// The scene with every exported input replaced by its history as a function of `t`.
    fn scene_with_inputs(&self, scene: &Scene) -> Scene {
        let exprs: Vec<(String, String)> = self
            .inputs
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                let h: Vec<(f64, f64)> = self.history.iter().map(|(t, u)| (*t, u[k])).collect();
                (
                    self.config.variables[i].name.clone(),
                    piecewise_constant(&h),
                )
            })
            .collect();
        scene.with_input_expressions(&exprs)
    }

    /// The scene restarted from the last row at `t` (see the module docs), running to at
    /// least `end`, with the inputs at their current values; `None` for a scene that replays.
    fn restarted(&self, base: &Scene, t: f64, end: f64) -> Option<Scene> {
        if base.bond_graph.is_some() || base.solve.formulation == FormulationKind::Decoupled {
            return None;
        }
        let col = |body: &str, c: &str| {
            let name = format!("{body}.{c}");
            let i = self.column_names.iter().position(|n| *n == name)?;
            self.row.get(i).copied()
        };
        let mut s = base.clone();
        for i in 0..s.springs.len() {
            if s.springs[i].rest_length.is_none() {
                s.springs[i].rest_length = Some(initial_length(base, i));
            }
        }
        for b in &mut s.bodies {
            let n = b.name.clone();
            let get = |cs: &[&str]| cs.iter().map(|c| col(&n, c)).collect::<Option<Vec<f64>>>();
            match s.dimension {
                Dimension::Planar => {
                    b.position = get(&["x", "y"])?;
                    b.angle = col(&n, "angle")?;
                    b.velocity = get(&["vx", "vy"])?;
                    b.angular_velocity = get(&["omega"])?;
                }
                Dimension::Spatial => {
                    b.position = get(&["x", "y", "z"])?;
                    let c = get(&["psi", "theta", "phi"])?;
                    b.cardan = [c[0], c[1], c[2]];
                    b.velocity = get(&["vx", "vy", "vz"])?;
                    b.angular_velocity = get(&["wx", "wy", "wz"])?;
                }
            }
        }
        s.solve.t_start = t;
        s.solve.t_end = s.solve.t_end.max(end);
        s.solve.output_times = None;
        s.solve.output_step = None;
        let exprs: Vec<(String, String)> = self
            .inputs
            .iter()
            .map(|&i| {
                let name = self.config.variables[i].name.clone();
                (name, piecewise_constant(&[(t, self.values[i])]))
            })
            .collect();
        Some(s.with_input_expressions(&exprs))
    }

    fn set_outputs(&mut self, row: &[f64]) {
        for (i, c) in self.columns.iter().enumerate() {
            if let Some(c) = c {
                self.values[i] = row[*c];
            }
        }
    }

    /// Tolerance on communication times: a small part of the step.
    fn tol(h: f64, t: f64) -> f64 {
        1e-9 * h.abs().max(1e-12 * t.abs()).max(f64::MIN_POSITIVE)
    }

    /// Starts a solve whose rows come at `t + h`, then on the grid: from the scene's start
    /// (the first segment, or a replay), or restarted from the state at `t`.
    fn start_segment(&mut self, t: f64, h: f64) -> Result<()> {
        self.segment = None;
        let base = self
            .scene
            .as_ref()
            .ok_or_else(|| SlaveError::Call("not initialised".into()))?;
        let t0 = base.solve.t_start;
        let target = t + h;
        let tol = Self::tol(h, target);
        let base_end = self.stop_time.unwrap_or(self.config.stop_time);
        let mut end = if target <= base_end + tol {
            base_end.max(target)
        } else {
            // past the stop time the importer gave: grow the grid geometrically
            t0 + 2.0 * (target - t0)
        };
        end = end.min(t + 1e6 * h);
        let at_start = (t - t0).abs() <= tol;
        let restarted = if at_start || self.replays < REPLAYS {
            None
        } else {
            self.restarted(base, t, end)
        };
        let scene = match restarted {
            Some(s) => s,
            None => {
                if !at_start {
                    self.replays += 1;
                }
                self.scene_with_inputs(base)
            }
        };
        // the run's grid from the start time (the same times as `bondmech run` with
        // output_step = h), or a grid from here when the importer left it
        let mut grid: Vec<f64> = output_grid(t0, end, Some(h))
            .into_iter()
            .filter(|&x| x > t + tol)
            .collect();
        if grid.first().is_none_or(|&x| (x - target).abs() > tol) {
            grid = output_grid(t, end, Some(h)).into_iter().skip(1).collect();
        }
        if grid.is_empty() {
            grid.push(target);
        }
        let model = Model::new(&scene).map_err(|e| SlaveError::Model(e.to_string()))?;
        let mut opts = model.default_options();
        opts.output_times = grid.clone();
        let (row_tx, rows) = sync_channel(1);
        let (next, next_rx) = sync_channel::<()>(1);
        let handle = std::thread::Builder::new()
            .name("bondmech-fmu-solve".into())
            .spawn(move || {
                let mut observer = |row: bondmech::solve::Row<'_>| {
                    if row_tx.send(Msg::Row(row.t, row.values.to_vec())).is_err() {
                        return ControlFlow::Break(());
                    }
                    // paused until the next step asks for the next row
                    match next_rx.recv() {
                        Ok(()) => ControlFlow::Continue(()),
                        Err(_) => ControlFlow::Break(()),
                    }
                };
                let result = model.solve_streaming(&opts, &mut observer);
                let _ = row_tx.send(Msg::Done(result.map(|_| ()).map_err(|e| e.to_string())));
            })
            .map_err(|e| SlaveError::Solve(format!("cannot start the solver thread: {e}")))?;
        self.segment = Some(Segment {
            rows,
            next: Some(next),
            paused: false,
            handle: Some(handle),
            grid: grid.into(),
        });
        Ok(())
    }

    /// One communication step from `t` to `t + h`.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<StepOutcome> {
        self.events.clear();
        match self.mode {
            Mode::Stepping => {}
            Mode::Terminated => return Ok(StepOutcome::Terminated(self.time)),
            m => return Err(SlaveError::Call(format!("doStep in mode {m:?}"))),
        }
        if !(h > 0.0 && h.is_finite() && t.is_finite()) {
            return Err(SlaveError::Call(format!(
                "doStep needs a finite time and a positive step (got t = {t}, h = {h})"
            )));
        }
        if (t - self.time).abs() > Self::tol(h, t) {
            return Err(SlaveError::Call(format!(
                "doStep from t = {t}, but the FMU is at t = {} (restore an FMU state to go back)",
                self.time
            )));
        }
        let target = t + h;
        let tol = Self::tol(h, target);
        let inputs = self.input_values();
        if self.history.last().is_some_and(|(_, u)| *u != inputs) {
            if self
                .history
                .last()
                .is_some_and(|(tl, _)| (*tl - t).abs() <= tol)
            {
                self.history.pop();
            }
            self.history.push((t, inputs));
            self.segment = None;
        }
        let on_grid = self
            .segment
            .as_ref()
            .and_then(|s| s.grid.front())
            .is_some_and(|&x| (x - target).abs() <= tol);
        if !on_grid {
            if let Err(e) = self.start_segment(t, h) {
                return Err(self.fail(e));
            }
        }
        self.step = Some(h);
        let mut event_row: Option<(f64, Vec<f64>)> = None;
        loop {
            let Some(segment) = self.segment.as_mut() else {
                return Err(self.fail(SlaveError::Call("no solve running".into())));
            };
            match segment.recv() {
                Ok(Msg::Row(tr, row)) => {
                    if tr < target - tol {
                        // a row at an event time: inside the step (kept in case a `stop`
                        // event ends the run there), or before it (a replay)
                        if tr > t + tol {
                            self.events.push(("event".into(), tr));
                            event_row = Some((tr, row));
                        }
                        continue;
                    }
                    segment.grid.pop_front();
                    self.set_outputs(&row);
                    self.row = row;
                    self.time = target;
                    return Ok(StepOutcome::Done);
                }
                Ok(Msg::Done(Ok(()))) if segment.grid.is_empty() => {
                    // the end of the grid (the stop time passed): a new segment goes on
                    if let Err(e) = self.start_segment(t, h) {
                        return Err(self.fail(e));
                    }
                }
                Ok(Msg::Done(Ok(()))) => {
                    // the solve ended before the step's end: a `stop` event
                    if let Some((te, row)) = event_row.take() {
                        self.set_outputs(&row);
                        self.row = row;
                        self.time = te;
                    }
                    self.segment = None;
                    self.mode = Mode::Terminated;
                    return Ok(StepOutcome::Terminated(self.time));
                }
                Ok(Msg::Done(Err(message))) => {
                    return Err(self.fail(SlaveError::Solve(message)));
                }
                Err(RecvError) => {
                    return Err(self.fail(SlaveError::Solve(
                        "the solver thread ended without a result (it panicked)".into(),
                    )));
                }
            }
        }
    }

    /// The state to restore later ([`Slave::restore`]).
    pub fn state(&self) -> Result<State> {
        match self.mode {
            Mode::Stepping | Mode::Terminated => Ok(State {
                time: self.time,
                values: self.values.clone(),
                row: self.row.clone(),
                history: self.history.clone(),
                step: self.step,
                replays: self.replays,
                mode: self.mode,
                stop_time: self.stop_time,
            }),
            m => Err(SlaveError::Call(format!(
                "an FMU state can be taken after initialisation (mode {m:?})"
            ))),
        }
    }

    /// Restores a state taken by [`Slave::state`] of an instance of the same FMU with the same
    /// parameters: the next step replays the solve from the scene's start time with the
    /// state's input history, so it continues exactly as the instance did from that state.
    pub fn restore(&mut self, state: &State) -> Result<()> {
        if self.scene.is_none() {
            return Err(SlaveError::Call(
                "an FMU state can be restored after initialisation".into(),
            ));
        }
        if state.values.len() != self.values.len() || state.row.len() != self.row.len() {
            return Err(SlaveError::Call("the FMU state is of another FMU".into()));
        }
        self.segment = None;
        self.time = state.time;
        self.values = state.values.clone();
        self.row = state.row.clone();
        self.history = state.history.clone();
        self.step = state.step;
        self.replays = state.replays;
        self.mode = state.mode;
        self.stop_time = state.stop_time;
        Ok(())
    }
}

impl State {
    /// The state as bytes (JSON).
    pub fn to_bytes(&self) -> Vec<u8> {
        serde_json::to_vec(self).unwrap_or_default()
    }

    /// A state from [`State::to_bytes`].
    pub fn from_bytes(bytes: &[u8]) -> Result<State> {
        serde_json::from_slice(bytes)
            .map_err(|e| SlaveError::Call(format!("not a serialised bondmech FMU state: {e}")))
    }
}

/// The initial distance between a spring's two points (its default rest length).
fn initial_length(scene: &Scene, si: usize) -> f64 {
    let s = &scene.springs[si];
    let at = |k: usize| -> Vec<f64> {
        let local: Vec<f64> = match &s.points[k] {
            PointRef::Coords(c) => c.clone(),
            PointRef::Named(n) => scene
                .bodies
                .iter()
                .find(|b| b.name == s.bodies[k])
                .and_then(|b| b.point(n))
                .map(|c| c.to_vec())
                .unwrap_or_default(),
        };
        let c = |i: usize| local.get(i).copied().unwrap_or(0.0);
        let body = scene.bodies.iter().find(|b| b.name == s.bodies[k]);
        match body {
            None => local.clone(),
            Some(b) => {
                let p = |i: usize| b.position.get(i).copied().unwrap_or(0.0);
                match scene.dimension {
                    Dimension::Planar => {
                        let (sn, cs) = b.angle.sin_cos();
                        vec![p(0) + cs * c(0) - sn * c(1), p(1) + sn * c(0) + cs * c(1)]
                    }
                    Dimension::Spatial => {
                        // R = Rz(psi) Ry(theta) Rx(phi), body to global (seed 16.2)
                        let [psi, theta, phi] = b.cardan;
                        let (s1, c1) = psi.sin_cos();
                        let (s2, c2) = theta.sin_cos();
                        let (s3, c3) = phi.sin_cos();
                        let r = [
                            [c1 * c2, c1 * s2 * s3 - s1 * c3, c1 * s2 * c3 + s1 * s3],
                            [s1 * c2, s1 * s2 * s3 + c1 * c3, s1 * s2 * c3 - c1 * s3],
                            [-s2, c2 * s3, c2 * c3],
                        ];
                        (0..3)
                            .map(|i| p(i) + r[i][0] * c(0) + r[i][1] * c(1) + r[i][2] * c(2))
                            .collect()
                    }
                }
            }
        }
    };
    let (a, b) = (at(0), at(1));
    a.iter()
        .zip(&b)
        .map(|(x, y)| (y - x) * (y - x))
        .sum::<f64>()
        .sqrt()
}
