//! What the analyses of a mechanism find besides its motion: where it rests
//! ([`equilibrium`]: the search, used by [`crate::Model::equilibrium`] and by a scene's
//! `"start": "equilibrium"`) and the linear model about an operating point
//! ([`linear_model`]: the model, its modes and frequency response, computed by
//! [`crate::linearize`]); why a sensitivity run or a fit is refused ([`sensitivity`], the
//! refusals of [`crate::sensitivity`]). Their tables are printed by [`crate::report`].

pub mod equilibrium;
pub mod linear_model;
pub mod sensitivity;
