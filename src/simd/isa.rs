//! Which SIMD path the kernels take, picked at run time.

/// The SIMD instruction set a kernel uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Isa {
    /// One lane at a time, in plain Rust (any target).
    Portable,
    /// Four lanes (x86-64's baseline).
    Sse2,
    /// Eight lanes, two blocks at a time (x86-64 CPUs from 2013 on; detected at run time).
    Avx2,
    /// AVX2's lanes, with sixteen where it pays: a tile's rays sixteen at a time against a
    /// triangle, the tile's shading compiled for AVX-512, and an anti-aliased sample's random
    /// numbers eight pixels at a time (AVX-512 F, DQ, VL and BW: x86-64 server CPUs from 2017
    /// on, AMD's from Zen 4; detected at run time).
    Avx512,
}

impl Isa {
    /// Every path, narrowest first.
    pub const ALL: [Isa; 4] = [Isa::Portable, Isa::Sse2, Isa::Avx2, Isa::Avx512];

    /// The widest path this CPU runs.
    pub fn detect() -> Isa {
        if Isa::Avx512.available() {
            Isa::Avx512
        } else if Isa::Avx2.available() {
            Isa::Avx2
        } else if Isa::Sse2.available() {
            Isa::Sse2
        } else {
            Isa::Portable
        }
    }

    /// Whether this CPU runs the path.
    pub fn available(self) -> bool {
        match self {
            Isa::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Sse2 => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => std::is_x86_feature_detected!("avx2"),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                std::is_x86_feature_detected!("avx2")
                    && std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512dq")
                    && std::is_x86_feature_detected!("avx512vl")
                    && std::is_x86_feature_detected!("avx512bw")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// A short lower-case name ("portable", "sse2", "avx2", "avx512").
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "portable",
            Isa::Sse2 => "sse2",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }
}
