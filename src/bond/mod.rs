//! Bond graphs of mechanisms (seed chapter, sections 16.1–16.8).
//!
//! - [`model`]: elements, bonds, parameters, the two-port convention
//!   (TF/MTF `e1 = m·e2, f2 = m·f1`; GY/MGY `e1 = r·f2, e2 = r·f1`; port 1 = bond into the two-port).
//! - [`json`]: the `"bond_graph"` JSON form.
//! - [`validate`](mod@validate): structural checks with JSON paths, all errors collected.
//! - [`causality`]: causality by matching (bipartite max flow on the junction structure), the
//!   numeric rank of the constraint rows ([`rank`]), differential storages, redundant junctions, conflicts,
//!   algebraic loops, degrees of freedom.
//! - [`equations`]: state derivatives, velocity-level constraint rows of differential storages
//!   and algebraic-loop rows from the causal graph, with exact Jacobians.
//! - [`mechanics`]: a bond graph read as a multibody system (coordinates, velocities, `M`,
//!   `K(x) v`, `Q`, the constraint rows of its joints' junctions and their closures).
//! - [`decouple`]: the decoupled twin: each constraint junction opened, a stiff spring put in.
//! - [`dot`]: Graphviz export with half arrows and causal strokes.
//! - [`fragments`]: the chapter's constructions (planar bodies in both frames, the 3D rigid body
//!   with its Euler junction structure, joints, springs, dampers, loads).
pub mod causality;
pub mod decouple;
pub mod dot;
pub mod equations;
pub mod fragments;
pub mod identifiers;
pub mod json;
pub mod mechanics;
pub mod model;
pub mod orient;
pub mod parameter_span;
pub mod rank;
pub mod validate;

pub use causality::{assign_causality, CausalityReport};
pub use json::{BondJsonError, RawBondGraph};
pub use model::{
    Bond, BondGraph, BondId, ConstraintJunction, Displacement, Element, ElementId, ElementKind,
    FlowState, Parameter, SignalDefinition, SignalState,
};
pub use validate::{validate, BondError, ValidationErrors};
