//! A scene as a co-simulation FMU (Functional Mock-up Interface 2.0 or 3.0): the archive
//! `bondmech fmu` writes, and the description of its variables that the FMU's shared library
//! (the `bondmech-fmu` crate of this workspace, `libbondmech_fmu.so`) reads back.
//!
//! The archive holds `modelDescription.xml`, the shared library under the platform folder the
//! standard names (`binaries/x86_64-linux/` for FMI 3.0, `binaries/linux64/` for FMI 2.0), the
//! scene as given (`resources/scene.json`), the variables ([`FmuConfig`],
//! `resources/bondmech-fmu.json`) and `documentation/index.html`. See `docs/fmu.md`.
//!
//! Variables: `time` (value reference 0), then the **parameters** (numeric scene fields named
//! by their `--set` path, `bodies[bar2].mass`, `gravity[1]`, `solve.rtol`; fixed, tunable
//! before initialisation), the **inputs** (the scene's `"inputs"`, held constant over a
//! communication step) and the **outputs** (CSV columns of `bondmech run`; by default every
//! body's position and angle and the requested points), numbered in that order.
//!
//! ```
//! use bondmech::fmu::{describe, ExportOptions, FmiVersion, VariableKind};
//! let text = std::fs::read_to_string("scenes/double_pendulum.json").unwrap();
//! let options = ExportOptions {
//!     parameters: vec!["bodies[bar2].mass".into()],
//!     ..ExportOptions::default()
//! };
//! let config = describe(&text, "double_pendulum", &options).unwrap();
//! assert_eq!(config.fmi_version, FmiVersion::V3);
//! assert_eq!(config.variables[1].name, "bodies[bar2].mass");
//! assert_eq!(config.variables[1].kind, VariableKind::Parameter);
//! assert!(config.variables.iter().any(|v| v.name == "bar2.A.x"));
//! let xml = config.model_description();
//! assert!(xml.contains(r#"fmiVersion="3.0""#));
//! ```

use std::fmt::Write as _;
use std::io::Write as _;

use serde::{Deserialize, Serialize};

use crate::model::Model;
use crate::scene::path::{scene_from_json_with, PathError, ScenePath, Segment};
use crate::scene::{Dimension, Scene, SceneError};

/// The `modelIdentifier` of every bondmech FMU: the shared library is
/// `binaries/<platform>/bondmech_fmu.so`.
pub const MODEL_IDENTIFIER: &str = "bondmech_fmu";

/// The file name of the variables' description under `resources/`.
pub const CONFIG_FILE: &str = "bondmech-fmu.json";

/// The file name of the scene under `resources/`.
pub const SCENE_FILE: &str = "scene.json";

/// Why an FMU cannot be described or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FmuError {
    /// The scene is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A `--parameter` path is malformed or points at nothing.
    #[error("--parameter: {0}")]
    Path(#[from] PathError),
    /// The model cannot be built (or its columns found).
    #[error(transparent)]
    Model(#[from] crate::error::Error),
    /// A `--parameter`, `--input` or `--output` names something the scene does not have.
    #[error("{flag} {name}: {message}")]
    Unknown {
        /// The flag.
        flag: &'static str,
        /// What it named.
        name: String,
        /// What is there instead.
        message: String,
    },
    /// Writing the archive failed.
    #[error("writing the FMU archive: {0}")]
    Zip(#[from] zip::result::ZipError),
    /// Writing the archive failed.
    #[error("writing the FMU archive: {0}")]
    Io(#[from] std::io::Error),
}

/// FMI 2.0 or 3.0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum FmiVersion {
    /// FMI 2.0 (`binaries/linux64/`).
    #[serde(rename = "2.0")]
    V2,
    /// FMI 3.0 (`binaries/x86_64-linux/`), the default.
    #[default]
    #[serde(rename = "3.0")]
    V3,
}

impl FmiVersion {
    /// `"2.0"` or `"3.0"`.
    pub fn as_str(self) -> &'static str {
        match self {
            FmiVersion::V2 => "2.0",
            FmiVersion::V3 => "3.0",
        }
    }

    /// The platform folder of the shared library under `binaries/`.
    pub fn platform_dir(self) -> &'static str {
        match self {
            FmiVersion::V2 => "linux64",
            FmiVersion::V3 => "x86_64-linux",
        }
    }
}

/// What a variable is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum VariableKind {
    /// The independent variable `time`.
    Time,
    /// A numeric scene field by its `--set` path, fixed after initialisation.
    Parameter,
    /// A scene input, held constant over a communication step.
    Input,
    /// A column of the run's CSV.
    Output,
}

/// One variable of the FMU.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Variable {
    /// FMI value reference.
    pub value_reference: u32,
    /// Name: `time`, the parameter's path, the input's name or the output column.
    pub name: String,
    /// Parameter, input, output or time.
    pub kind: VariableKind,
    /// Start value (parameters and inputs).
    pub start: Option<f64>,
    /// Unit (`m`, `rad`, `N.m`, …), if any.
    pub unit: Option<String>,
}

/// What `bondmech fmu` exports, beyond the scene.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExportOptions {
    /// FMI version (3.0 by default).
    pub fmi: FmiVersion,
    /// Parameters by `--set` path (none by default).
    pub parameters: Vec<String>,
    /// Inputs by name (`None`: every input of the scene).
    pub inputs: Option<Vec<String>>,
    /// Output columns (`None`: every body's position and angle and the requested points).
    pub outputs: Option<Vec<String>>,
}

/// The description of an FMU's variables, shared by the exporter and the FMU's library
/// (`resources/bondmech-fmu.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FmuConfig {
    /// FMI version.
    pub fmi_version: FmiVersion,
    /// The model's name (the scene's).
    pub model_name: String,
    /// FMI 2.0 `guid`, FMI 3.0 `instantiationToken`: a digest of the scene and the variables.
    pub instantiation_token: String,
    /// The scene's start time.
    pub start_time: f64,
    /// The scene's end time (the default experiment's stop time).
    pub stop_time: f64,
    /// The scene's output interval (the default experiment's step size).
    pub step_size: f64,
    /// The scene's relative tolerance.
    pub tolerance: f64,
    /// The variables, by value reference (`variables[k].value_reference == k`).
    pub variables: Vec<Variable>,
}

/// The unit of an output column, in the FMI spelling (`None`: dimensionless or mixed).
pub fn column_unit(column: &str) -> Option<&'static str> {
    // a driver's effort and power (`motor.torque`, `feed.force`, `motor.power`)
    match column.rsplit('.').next() {
        Some("torque") => return Some("N.m"),
        Some("force") => return Some("N"),
        Some("power") => return Some("W"),
        _ => {}
    }
    match crate::report::timeplot::plot_group(column).unit {
        "m" => Some("m"),
        "rad" => Some("rad"),
        "m/s" => Some("m/s"),
        "rad/s" => Some("rad/s"),
        "J" => Some("J"),
        "N" => Some("N"),
        "N·m" => Some("N.m"),
        _ => None,
    }
}

/// The unit of a numeric scene field, by the last key of its path.
fn parameter_unit(path: &ScenePath) -> Option<&'static str> {
    let keys: Vec<&str> = path
        .segments()
        .iter()
        .filter_map(|s| match s {
            Segment::Key(k) => Some(k.as_str()),
            _ => None,
        })
        .collect();
    Some(match *keys.last()? {
        "mass" => "kg",
        "inertia" => "kg.m2",
        "gravity" => "m/s2",
        "position" | "rest_length" => "m",
        "angle" | "cardan" => "rad",
        "velocity" => "m/s",
        "angular_velocity" => "rad/s",
        "stiffness" | "joint_stiffness" => "N/m",
        "damping" | "joint_damping" => "N.s/m",
        "t_start" | "t_end" | "output_step" | "max_wall_seconds" => "s",
        _ => return None,
    })
}

/// The SI base-unit exponents (`kg`, `m`, `s`, `rad`) of the units bondmech writes.
fn base_units(unit: &str) -> Option<&'static [(&'static str, i32)]> {
    Some(match unit {
        "m" => &[("m", 1)],
        "rad" => &[("rad", 1)],
        "s" => &[("s", 1)],
        "kg" => &[("kg", 1)],
        "m/s" => &[("m", 1), ("s", -1)],
        "m/s2" => &[("m", 1), ("s", -2)],
        "rad/s" => &[("rad", 1), ("s", -1)],
        "J" | "N.m" => &[("kg", 1), ("m", 2), ("s", -2)],
        "N" => &[("kg", 1), ("m", 1), ("s", -2)],
        "W" => &[("kg", 1), ("m", 2), ("s", -3)],
        "kg.m2" => &[("kg", 1), ("m", 2)],
        "N/m" => &[("kg", 1), ("s", -2)],
        "N.s/m" => &[("kg", 1), ("s", -1)],
        _ => return None,
    })
}

/// The value at `path` in a scene's JSON (`None` when the path leads nowhere).
fn value_at<'a>(root: &'a serde_json::Value, path: &ScenePath) -> Option<&'a serde_json::Value> {
    let mut node = root;
    for s in path.segments() {
        node = match s {
            Segment::Key(k) => node.get(k)?,
            Segment::Index(i) => node.get(*i)?,
            Segment::Name(n) => node
                .as_array()?
                .iter()
                .find(|item| item.get("name").and_then(|x| x.as_str()) == Some(n.as_str()))?,
        };
    }
    Some(node)
}

/// The output columns an FMU has by default: every body's position and angle (`b.x`, `b.y`,
/// `b.angle`; in space `b.x`, `b.y`, `b.z`, `b.psi`, `b.theta`, `b.phi`) and the coordinates of
/// the requested points (`b.P.x`, …), and each driver's effort and power (`motor.torque`,
/// `motor.power`); every column for a raw bond graph.
pub fn default_outputs(scene: &Scene, columns: &[String]) -> Vec<String> {
    if scene.bond_graph.is_some() {
        return columns.to_vec();
    }
    let own: &[&str] = match scene.dimension {
        Dimension::Planar => &["x", "y", "angle"],
        Dimension::Spatial => &["x", "y", "z", "psi", "theta", "phi"],
    };
    let mut wanted: Vec<String> = Vec::new();
    for b in &scene.bodies {
        wanted.extend(own.iter().map(|c| format!("{}.{c}", b.name)));
    }
    for o in &scene.outputs {
        if let Some((body, point)) = o.split_once('.') {
            let is_point = scene
                .bodies
                .iter()
                .any(|b| b.name == body && b.point(point).is_some());
            if is_point {
                wanted.extend(["x", "y", "z"].iter().map(|c| format!("{o}.{c}")));
            }
        }
    }
    for d in &scene.drivers {
        wanted.push(format!("{}.{}", d.name, d.kind.effort()));
        wanted.push(format!("{}.power", d.name));
    }
    columns
        .iter()
        .filter(|c| wanted.contains(c))
        .cloned()
        .collect()
}

/// The columns of a model's rows (a raw bond graph's from a solve at its start time).
fn model_columns(model: &Model) -> Result<Vec<String>, crate::error::Error> {
    if let Some(columns) = model.columns() {
        return Ok(columns);
    }
    let mut opts = model.default_options();
    opts.output_times = vec![opts.t_start];
    Ok(model.solve(&opts)?.columns)
}

/// Describes the FMU of the scene `text` (named `default_name` unless it has a `name`): its
/// variables and default experiment. Fails when the scene is invalid, or a parameter, input
/// or output names nothing in it.
pub fn describe(
    text: &str,
    default_name: &str,
    options: &ExportOptions,
) -> Result<FmuConfig, FmuError> {
    let scene = scene_from_json_with(text, default_name, &[])?;
    let model = Model::new(&scene)?;
    let columns = model_columns(&model)?;
    let full: serde_json::Value =
        serde_json::from_str(&scene.to_json_string()).map_err(|e| FmuError::Unknown {
            flag: "scene",
            name: scene.name.clone(),
            message: e.to_string(),
        })?;
    let mut variables = vec![Variable {
        value_reference: 0,
        name: "time".into(),
        kind: VariableKind::Time,
        start: None,
        unit: Some("s".into()),
    }];
    let mut push = |name: String, kind, start, unit: Option<String>| {
        if variables.iter().any(|v| v.name == name) {
            return false;
        }
        let value_reference = variables.len() as u32;
        variables.push(Variable {
            value_reference,
            name,
            kind,
            start,
            unit,
        });
        true
    };
    for p in &options.parameters {
        let path = ScenePath::parse(p)?;
        let value = value_at(&full, &path).and_then(|v| v.as_f64());
        let Some(value) = value else {
            return Err(FmuError::Unknown {
                flag: "--parameter",
                name: p.clone(),
                message: "is not a number in the scene (name one numeric field, as --set does: bodies[bar2].mass, gravity[1], solve.rtol)".into(),
            });
        };
        let unit = parameter_unit(&path).map(String::from);
        push(p.clone(), VariableKind::Parameter, Some(value), unit);
    }
    let inputs: Vec<String> = match &options.inputs {
        Some(names) => names.clone(),
        None => scene.inputs.iter().map(|u| u.name.clone()).collect(),
    };
    for name in inputs {
        let Some(u) = scene.inputs.iter().find(|u| u.name == name) else {
            let known: Vec<&str> = scene.inputs.iter().map(|u| u.name.as_str()).collect();
            return Err(FmuError::Unknown {
                flag: "--input",
                name,
                message: format!("the scene's inputs are [{}]", known.join(", ")),
            });
        };
        push(
            name.clone(),
            VariableKind::Input,
            Some(u.start),
            u.unit.clone(),
        );
    }
    let outputs = match &options.outputs {
        Some(o) => o.clone(),
        None => default_outputs(&scene, &columns),
    };
    for name in outputs {
        if !columns.contains(&name) {
            return Err(FmuError::Unknown {
                flag: "--output",
                name,
                message: format!(
                    "is not a column of the run; the columns are [{}]",
                    columns.join(", ")
                ),
            });
        }
        let unit = column_unit(&name).map(String::from);
        push(name, VariableKind::Output, None, unit);
    }
    let s = &scene.solve;
    let times = scene.output_times();
    let step_size = match s.output_step {
        Some(h) => h,
        None if times.len() > 1 => times[1] - times[0],
        None => s.t_end - s.t_start,
    };
    let mut config = FmuConfig {
        fmi_version: options.fmi,
        model_name: scene.name.clone(),
        instantiation_token: String::new(),
        start_time: s.t_start,
        stop_time: s.t_end,
        step_size,
        tolerance: s.rtol,
        variables,
    };
    config.instantiation_token = token(text, &config);
    Ok(config)
}

/// A UUID-shaped digest (FNV-1a, 128 bits) of the scene text and the variables.
fn token(text: &str, config: &FmuConfig) -> String {
    let described = serde_json::to_string(config).unwrap_or_default();
    let mut h: u128 = 0x6c62272e07bb014262b821756295c58d;
    for b in text.bytes().chain(described.bytes()) {
        h ^= b as u128;
        h = h.wrapping_mul(0x0000000001000000000000000000013B);
    }
    let x = format!("{h:032x}");
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &x[0..8],
        &x[8..12],
        &x[12..16],
        &x[16..20],
        &x[20..32]
    )
}

/// `s` with XML's special characters escaped for an attribute value.
fn xml(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// A number as an XML attribute (shortest text that reads back exactly).
fn num(x: f64) -> String {
    format!("{x:?}")
}

impl FmuConfig {
    /// The variables of one kind.
    pub fn of_kind(&self, kind: VariableKind) -> impl Iterator<Item = &Variable> {
        self.variables.iter().filter(move |v| v.kind == kind)
    }

    /// `modelDescription.xml` for the FMI version of the configuration.
    pub fn model_description(&self) -> String {
        let v3 = self.fmi_version == FmiVersion::V3;
        let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let tool = format!("bondmech {}", env!("CARGO_PKG_VERSION"));
        let description = format!(
            "bondmech scene '{}' as a co-simulation FMU (its own solver, SUNDIALS, integrates each communication step)",
            self.model_name
        );
        let _ = writeln!(
            s,
            "<fmiModelDescription fmiVersion=\"{}\" modelName=\"{}\" {}=\"{}\" description=\"{}\" generationTool=\"{}\" variableNamingConvention=\"flat\"{}>",
            self.fmi_version.as_str(),
            xml(&self.model_name),
            if v3 { "instantiationToken" } else { "guid" },
            self.instantiation_token,
            xml(&description),
            xml(&tool),
            if v3 { "" } else { " numberOfEventIndicators=\"0\"" }
        );
        if v3 {
            let _ = writeln!(
                s,
                "  <CoSimulation modelIdentifier=\"{MODEL_IDENTIFIER}\" canHandleVariableCommunicationStepSize=\"true\" canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\" hasEventMode=\"false\" providesIntermediateUpdate=\"false\" canReturnEarlyAfterIntermediateUpdate=\"false\"/>"
            );
        } else {
            let _ = writeln!(
                s,
                "  <CoSimulation modelIdentifier=\"{MODEL_IDENTIFIER}\" canHandleVariableCommunicationStepSize=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\"/>"
            );
        }
        let mut units: Vec<&str> = self
            .variables
            .iter()
            .filter_map(|v| v.unit.as_deref())
            .collect();
        units.sort_unstable();
        units.dedup();
        if !units.is_empty() {
            s.push_str("  <UnitDefinitions>\n");
            for u in units {
                match base_units(u) {
                    Some(base) => {
                        let attrs: String =
                            base.iter().map(|(k, e)| format!(" {k}=\"{e}\"")).collect();
                        let _ =
                            writeln!(s, "    <Unit name=\"{}\"><BaseUnit{attrs}/></Unit>", xml(u));
                    }
                    None => {
                        let _ = writeln!(s, "    <Unit name=\"{}\"/>", xml(u));
                    }
                }
            }
            s.push_str("  </UnitDefinitions>\n");
        }
        s.push_str("  <LogCategories>\n");
        for (name, what) in [
            (
                "logStatusError",
                "errors: a failed solve (element and time), a bad call",
            ),
            (
                "logStatusWarning",
                "warnings of the model (redundant joints, …)",
            ),
            ("logEvents", "the scene's events met during a step"),
        ] {
            let _ = writeln!(
                s,
                "    <Category name=\"{name}\" description=\"{}\"/>",
                xml(what)
            );
        }
        s.push_str("  </LogCategories>\n");
        let _ = writeln!(
            s,
            "  <DefaultExperiment startTime=\"{}\" stopTime=\"{}\" tolerance=\"{}\" stepSize=\"{}\"/>",
            num(self.start_time),
            num(self.stop_time),
            num(self.tolerance),
            num(self.step_size)
        );
        s.push_str("  <ModelVariables>\n");
        for v in &self.variables {
            let (causality, variability, initial) = match v.kind {
                VariableKind::Time => ("independent", "continuous", None),
                VariableKind::Parameter => ("parameter", "fixed", Some("exact")),
                VariableKind::Input => ("input", "continuous", None),
                VariableKind::Output => ("output", "continuous", Some("calculated")),
            };
            let mut attrs = String::new();
            if let Some(x) = v.start {
                let _ = write!(attrs, " start=\"{}\"", num(x));
            }
            if let Some(u) = &v.unit {
                let _ = write!(attrs, " unit=\"{}\"", xml(u));
            }
            let initial = initial
                .map(|i| format!(" initial=\"{i}\""))
                .unwrap_or_default();
            if v3 {
                let _ = writeln!(
                    s,
                    "    <Float64 name=\"{}\" valueReference=\"{}\" causality=\"{causality}\" variability=\"{variability}\"{initial}{attrs}/>",
                    xml(&v.name),
                    v.value_reference
                );
            } else {
                let _ = writeln!(
                    s,
                    "    <ScalarVariable name=\"{}\" valueReference=\"{}\" causality=\"{causality}\" variability=\"{variability}\"{initial}><Real{attrs}/></ScalarVariable>",
                    xml(&v.name),
                    v.value_reference
                );
            }
        }
        s.push_str("  </ModelVariables>\n  <ModelStructure>\n");
        let outputs: Vec<&Variable> = self.of_kind(VariableKind::Output).collect();
        if v3 {
            for v in &outputs {
                let _ = writeln!(s, "    <Output valueReference=\"{}\"/>", v.value_reference);
            }
            for v in &outputs {
                let _ = writeln!(
                    s,
                    "    <InitialUnknown valueReference=\"{}\"/>",
                    v.value_reference
                );
            }
        } else if !outputs.is_empty() {
            // FMI 2.0 refers to variables by their 1-based position in ModelVariables, which
            // is the value reference + 1 here
            s.push_str("    <Outputs>\n");
            for v in &outputs {
                let _ = writeln!(s, "      <Unknown index=\"{}\"/>", v.value_reference + 1);
            }
            s.push_str("    </Outputs>\n    <InitialUnknowns>\n");
            for v in &outputs {
                let _ = writeln!(s, "      <Unknown index=\"{}\"/>", v.value_reference + 1);
            }
            s.push_str("    </InitialUnknowns>\n");
        }
        s.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
        s
    }

    /// `documentation/index.html`: what the FMU is and what it needs.
    fn documentation(&self) -> String {
        let mut rows = String::new();
        for v in &self.variables {
            let _ = writeln!(
                rows,
                "<tr><td>{}</td><td>{}</td><td>{:?}</td><td>{}</td><td>{}</td></tr>",
                v.value_reference,
                xml(&v.name),
                v.kind,
                v.start.map(num).unwrap_or_default(),
                xml(v.unit.as_deref().unwrap_or(""))
            );
        }
        format!(
            "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title></head><body>\n\
             <h1>{name}: a bondmech co-simulation FMU (FMI {version})</h1>\n\
             <p>The scene is <code>resources/{SCENE_FILE}</code>; the FMU solves it with the \
             formulation and tolerances of its <code>solve</code> section (the solver of \
             <code>bondmech run</code>), integrating to the end of each communication step. \
             Inputs are held constant over a communication step; parameters are fixed after \
             initialisation.</p>\n\
             <p>Requirements: Linux x86-64 and the SUNDIALS 6 shared libraries it was built \
             against, linked dynamically (Debian 12: <code>apt-get install libsundials-dev</code>, \
             or the runtime packages <code>libsundials-idas5 libsundials-cvodes6 \
             libsundials-arkode5 libsundials-sunlinsol3 libsundials-sunmatrix4</code>).</p>\n\
             <table><tr><th>value reference</th><th>name</th><th>kind</th><th>start</th><th>unit</th></tr>\n{rows}</table>\n\
             </body></html>\n",
            name = xml(&self.model_name),
            version = self.fmi_version.as_str(),
        )
    }

    /// The FMU archive: model description, the shared library `library` (the bytes of
    /// `libbondmech_fmu.so`) under the platform folder, the scene text, this description and
    /// the documentation.
    pub fn archive(&self, scene_text: &str, library: &[u8]) -> Result<Vec<u8>, FmuError> {
        let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let deflated = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        let files: [(String, Vec<u8>); 5] = [
            (
                "modelDescription.xml".into(),
                self.model_description().into_bytes(),
            ),
            (
                format!(
                    "binaries/{}/{MODEL_IDENTIFIER}.so",
                    self.fmi_version.platform_dir()
                ),
                library.to_vec(),
            ),
            (
                format!("resources/{SCENE_FILE}"),
                scene_text.as_bytes().to_vec(),
            ),
            (
                format!("resources/{CONFIG_FILE}"),
                serde_json::to_string_pretty(self)
                    .unwrap_or_default()
                    .into_bytes(),
            ),
            (
                "documentation/index.html".into(),
                self.documentation().into_bytes(),
            ),
        ];
        for (name, bytes) in files {
            // the shared library is most of the archive: compressed fast (measured on a debug
            // build's library: level 1 gives 17.5 MB in 0.16 s of CPU, the default 12.2 MB in
            // 0.55 s)
            let options = if name.starts_with("binaries/") {
                deflated.compression_level(Some(1))
            } else {
                deflated
            };
            zip.start_file(name, options)?;
            zip.write_all(&bytes)?;
        }
        Ok(zip.finish()?.into_inner())
    }
}
