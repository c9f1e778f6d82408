//! SIMD, in one place: which path the kernels take ([`Isa`], detected once per scene and
//! forced by tests), the lane type the kernels are written in (`Lanes`: `f32` is one lane,
//! then SSE2's four, AVX2's eight and AVX-512's sixteen), and the one dispatch that compiles a
//! kernel for each path (`Path`, `Kernel`, `Isa::run`).
//!
//! A kernel is written once, generic over its lanes, and never asks the CPU what it has: the
//! scene's (or its caller's) [`Isa`] decides, so a test that forces a path runs that path's
//! code. Every lane operation is one IEEE operation (no fused multiply-add), so every path
//! gives the same bits.
//!
//! Why our own small trait rather than a crate such as `pulp` or `multiversion`: the kernels
//! need exactly SSE2's, AVX's and AVX-512's comparison and min/max semantics (which lane wins
//! on NaN) to stay bit for bit with the one-lane form, a plain SSE2 path, and AVX-512's
//! 16-lane form with bit masks; the trait is some 400 lines of one-line operations that say
//! exactly that, and adds no dependency.

mod isa;
mod lanes;
mod path;

pub use isa::Isa;
#[cfg(target_arch = "x86_64")]
pub(crate) use lanes::F8;
pub(crate) use lanes::Lanes;
pub(crate) use path::{Kernel, Path};
