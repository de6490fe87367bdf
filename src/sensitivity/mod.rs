//! Forward sensitivities `∂y/∂p` of a mechanism's run and parameters identified from
//! measurements.
//!
//! * [`parameter`]: a scene path (`bodies[bar2].mass`, as `--set` takes it) and its value.
//! * [`symbols`]: how a parameter enters the equations — the inertias `M`, the generalized
//!   forces `Q`, the initial state — as exact symbolic derivatives `∂M/∂p`, `∂Q/∂p` in the
//!   system's expression graph.
//! * [`run`]: the run with IDAS's forward sensitivities: `F_y s + F_y' s' + ∂F/∂p = 0` alongside
//!   `F(t, y, y') = 0`, from a start consistent with the joints, and the output columns'
//!   sensitivities `d(<column>)/d(<path>)`.
//! * [`mod@fit`]: Levenberg–Marquardt on the exact sensitivities: the parameters that minimise the
//!   squared differences between the run's columns and measured data.
//!
//! ```
//! use bondmech::sensitivity::{sensitivity, SensitivityRequest};
//! let scene = bondmech::Scene::from_path("scenes/double_pendulum.json").unwrap();
//! let req = SensitivityRequest::new(&["bodies[bar2].mass"]).t_end(0.2);
//! let s = sensitivity(&scene, &req).unwrap();
//! let col = s.column("d(bar2.angle)/d(bodies[bar2].mass)").unwrap();
//! assert_eq!(col.len(), s.times.len());
//! assert_eq!(col[0], 0.0); // the start does not depend on the mass
//! ```

pub mod fit;
pub mod parameter;
pub mod run;
pub mod symbols;

pub use crate::analysis::sensitivity::SensitivityError;
pub use fit::{fit, FitData, FitReport, FitRequest};
pub use parameter::SceneParameter;
pub use run::{sensitivity, Sensitivities, SensitivityRequest};
