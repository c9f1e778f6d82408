//! Which SIMD path the triangle and box kernels take, picked at run time.

/// The SIMD instruction set a kernel uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Isa {
    /// One lane at a time, in plain Rust (any target).
    Portable,
    /// Four lanes (x86-64's baseline).
    Sse2,
    /// Eight lanes, two blocks at a time (x86-64 CPUs from 2013 on; detected at run time).
    Avx2,
}

impl Isa {
    /// Every path, narrowest first.
    pub const ALL: [Isa; 3] = [Isa::Portable, Isa::Sse2, Isa::Avx2];

    /// The widest path this CPU runs.
    pub fn detect() -> Isa {
        if Isa::Avx2.available() {
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
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// A short lower-case name ("portable", "sse2", "avx2").
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "portable",
            Isa::Sse2 => "sse2",
            Isa::Avx2 => "avx2",
        }
    }
}
