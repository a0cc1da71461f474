//! Properties of the load model, the effects, their linearisations and the dataset generator.
// Joint-indexed loops read like the formulas they check.
#![allow(clippy::needless_range_loop)]

mod campaign;
mod coupling;
mod deflection;
mod effects_alone;
mod fixture;
mod generator;
mod gravity;
mod refusals;
mod regressors;
mod robot;
