//! Running a kernel on a SIMD path: [`Path`] names each path's lane types, [`Kernel`] is a
//! computation written once over them, and [`Isa::run`] compiles and calls it for the path:
//! the two wide paths inside functions compiled for AVX2 or AVX-512 (the only
//! `target_feature` functions the kernels need), the others as they are.

use super::Isa;
use super::lanes::Lanes;
#[cfg(target_arch = "x86_64")]
use super::lanes::{F4, F8, F16};

/// A SIMD path's lanes.
pub(crate) trait Path {
    /// One block of four triangles against one ray: `f32` (a lane at a time) or four lanes.
    type Four: Lanes;
    /// Two blocks (eight triangles) against one ray.
    type Eight: Lanes;
    /// A tile's rays against one triangle, or eight boxes against one ray: as wide as the
    /// path goes.
    type Wide: Lanes;
    /// Whether the CPU has AVX (and AVX2) on this path: the `f64` plane tests of the culls
    /// use it.
    const AVX: bool;
}

/// One lane at a time, on any target.
pub(crate) struct Portable;

impl Path for Portable {
    type Four = f32;
    type Eight = f32;
    type Wide = f32;
    const AVX: bool = false;
}

/// SSE2: four lanes.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Sse2;

#[cfg(target_arch = "x86_64")]
impl Path for Sse2 {
    type Four = F4;
    type Eight = F4;
    type Wide = F4;
    const AVX: bool = false;
}

/// AVX2: eight lanes.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Avx2;

#[cfg(target_arch = "x86_64")]
impl Path for Avx2 {
    type Four = F4;
    type Eight = F8;
    type Wide = F8;
    const AVX: bool = true;
}

/// AVX-512: sixteen lanes for a tile's rays.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Avx512;

#[cfg(target_arch = "x86_64")]
impl Path for Avx512 {
    type Four = F4;
    type Eight = F8;
    type Wide = F16;
    const AVX: bool = true;
}

/// A computation written once for every path ([`Isa::run`] picks the path).
pub(crate) trait Kernel {
    /// What it gives.
    type Output;
    /// Whether it runs AVX-512's sixteen lanes ([`Path::Wide`]) where the path has them. A
    /// kernel that does not (the one-ray traversals) runs AVX2's code on the AVX-512 path:
    /// compiled for AVX-512 too, a GI frame took about 11 % more CPU time (`render --stage gi
    /// --pixels 400x200 --samples 16`, one thread, medians of 9 interleaved runs on a loaded
    /// machine: 0.97 s against 0.86 s).
    const SIXTEEN: bool = false;
    /// It, on path `P`. Implementations are `#[inline(always)]`, and so is everything generic
    /// they call, so that it is compiled into the path's own function.
    fn run<P: Path>(self) -> Self::Output;
}

impl Isa {
    /// Runs `k` on this path.
    ///
    /// # Panics
    /// If this CPU does not have the path.
    #[inline]
    pub(crate) fn run<K: Kernel>(self, k: K) -> K::Output {
        assert!(self.available(), "{} is not available", self.name());
        // SAFETY: checked just above.
        unsafe { self.run_unchecked(k) }
    }

    /// Runs `k` on this path, which the caller knows the CPU has (a scene's path is checked
    /// when it is set).
    ///
    /// # Safety
    /// The CPU must have the path ([`Isa::available`]).
    #[inline(always)]
    pub(crate) unsafe fn run_unchecked<K: Kernel>(self, k: K) -> K::Output {
        debug_assert!(self.available(), "{} is not available", self.name());
        match self {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the caller's contract.
            Isa::Avx512 if K::SIXTEEN => unsafe { run_avx512(k) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the caller's contract (AVX-512 includes AVX2).
            Isa::Avx512 => unsafe { run_avx2(k) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the caller's contract.
            Isa::Avx2 => unsafe { run_avx2(k) },
            #[cfg(target_arch = "x86_64")]
            Isa::Sse2 => run_sse2(k),
            _ => run_portable(k),
        }
    }
}

/// `k` on SSE2, a function of its own as the wider paths' are. Inlined into the dispatch, the
/// narrow paths' code made every caller's frame (registers saved, stack reserved) as heavy as
/// theirs on every path: 30 instructions of each of the flat list's one-ray queries.
#[cfg(target_arch = "x86_64")]
#[inline(never)]
fn run_sse2<K: Kernel>(k: K) -> K::Output {
    k.run::<Sse2>()
}

/// `k` one lane at a time (see [`run_sse2`]).
#[inline(never)]
fn run_portable<K: Kernel>(k: K) -> K::Output {
    k.run::<Portable>()
}

/// `k` compiled for AVX2.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2<K: Kernel>(k: K) -> K::Output {
    k.run::<Avx2>()
}

/// `k` compiled for AVX-512.
///
/// # Safety
/// The CPU must have AVX-512 F, DQ, VL and BW (and AVX2).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
unsafe fn run_avx512<K: Kernel>(k: K) -> K::Output {
    k.run::<Avx512>()
}
