//! `raytty bench`: what each step of accuracy costs in time, against a cached reference.

pub mod reference;
