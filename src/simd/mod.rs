//! SIMD: which path the kernels take ([`Isa`], detected once per scene and forced by tests),
//! and the lane operations the kernels are written in.
//!
//! Every CPU check of the library goes through [`Isa`]: a kernel asks the scene's (or its
//! caller's) path, never the CPU, so a test that forces a path runs that path's code.

mod isa;

pub use isa::Isa;
