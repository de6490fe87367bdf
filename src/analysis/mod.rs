//! What the analyses of a mechanism find besides its motion: where it rests
//! ([`equilibrium`]: the search, used by [`crate::Model::equilibrium`] and by a scene's
//! `"start": "equilibrium"`) and the linear model about an operating point
//! ([`linear_model`]: the model, its modes and frequency response, computed by
//! [`crate::linearize`]). Their tables are printed by [`crate::report`].

pub mod equilibrium;
pub mod linear_model;
