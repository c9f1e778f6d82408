//! A small, seedable random number generator. Every sample's stream is derived from
//! (pixel, sample, frame), so images do not depend on the thread count or the order of work.

/// SplitMix64 (Steele, Lea and Flood, 2014): tiny, fast, and good enough for sampling.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A generator for one sample of one pixel of one frame.
    pub fn for_sample(pixel: u64, sample: u32, frame: u32) -> Rng {
        let mut r = Rng {
            state: pixel.wrapping_mul(0x9E37_79B9_7F4A_7C15),
        };
        r.state ^= mix((sample as u64) << 32 | frame as u64);
        r.next_u64();
        r
    }

    /// A generator from a plain seed.
    pub fn seeded(seed: u64) -> Rng {
        Rng { state: seed }
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix(self.state)
    }

    /// A uniform `f32` in `[0, 1)`.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// A uniform `f64` in `[0, 1)`.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
