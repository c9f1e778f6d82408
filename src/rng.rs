//! A small, seedable random number generator. Every sample's stream is derived from
//! (pixel, sample, frame), so images do not depend on the thread count or the order of work.

/// The generator's increment: 2⁶⁴/φ, odd, so the state visits every 64-bit value.
const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// Keeps pixel 0's key away from `mix(0) = 0`; any odd constant unrelated to [`GOLDEN`] will do
/// (the first 64 bits of π's fraction).
const PIXEL_KEY: u64 = 0x243F_6A88_85A3_08D3;

/// SplitMix64 (Steele, Lea and Flood, 2014): tiny, fast, and good enough for sampling.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A generator for one sample of one pixel of one frame.
    ///
    /// The three numbers are hashed into the starting state (each one through the SplitMix64
    /// finaliser, which is a bijection that scrambles every bit), so the streams of
    /// neighbouring pixels, samples and frames start at unrelated points of the sequence. A
    /// start of `pixel·φ` (φ the generator's own increment) would make pixel p's k-th number
    /// pixel p+1's (k−1)-th, and neighbouring pixels' noise correlated.
    pub fn for_sample(pixel: u64, sample: u32, frame: u32) -> Rng {
        let h = mix(pixel ^ PIXEL_KEY);
        let h = mix(h ^ ((u64::from(sample) << 32) | u64::from(frame)));
        Rng { state: mix(h) }
    }

    /// A generator from a plain seed.
    pub fn seeded(seed: u64) -> Rng {
        Rng { state: seed }
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GOLDEN);
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

/// The SplitMix64 finaliser: a bijection of 64 bits that scrambles every bit (also the
/// Sobol sampler's seed hash).
#[inline]
pub(crate) fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first `k` numbers of each of `n` consecutive pixels' streams.
    fn streams(n: u64, k: usize, sample: u32, frame: u32) -> Vec<Vec<f64>> {
        (0..n)
            .map(|p| {
                let mut r = Rng::for_sample(p, sample, frame);
                (0..k).map(|_| r.next_f64()).collect()
            })
            .collect()
    }

    fn correlation(a: &[f64], b: &[f64]) -> f64 {
        let n = a.len() as f64;
        let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
        let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
        let va: f64 = a.iter().map(|x| (x - ma) * (x - ma)).sum();
        let vb: f64 = b.iter().map(|y| (y - mb) * (y - mb)).sum();
        cov / (va * vb).sqrt()
    }

    /// Neighbouring pixels' streams share no number and are uncorrelated at every lag: the
    /// old seeding (`pixel·φ`) made pixel p's draw k+1 equal pixel p+1's draw k (r = 1).
    #[test]
    fn neighbouring_pixels_streams_are_unrelated() {
        const K: usize = 6;
        for (sample, frame) in [(0, 0), (1, 0), (0, 1), (3, 7)] {
            let s = streams(4096, K, sample, frame);
            for p in 0..s.len() - 1 {
                for v in &s[p] {
                    assert!(!s[p + 1].contains(v), "pixel {p} and {} share {v}", p + 1);
                }
            }
            for i in 0..K {
                for j in 0..K {
                    let a: Vec<f64> = s[..s.len() - 1].iter().map(|v| v[i]).collect();
                    let b: Vec<f64> = s[1..].iter().map(|v| v[j]).collect();
                    let r = correlation(&a, &b);
                    // 4095 independent pairs: |r| has a standard deviation of about 0.016.
                    assert!(r.abs() < 0.08, "draw {i} of p vs draw {j} of p+1: r = {r}");
                }
            }
        }
    }

    /// Samples and frames of one pixel get unrelated streams too.
    #[test]
    fn samples_and_frames_of_a_pixel_are_unrelated() {
        let first = |p, s, f| Rng::for_sample(p, s, f).next_u64();
        let mut seen = std::collections::HashSet::new();
        for p in 0..64 {
            for s in 0..16 {
                for f in 0..16 {
                    assert!(seen.insert(first(p, s, f)), "repeat at {p} {s} {f}");
                }
            }
        }
        let a: Vec<f64> = (0..4096)
            .map(|s| Rng::for_sample(7, s, 0).next_f64())
            .collect();
        let b: Vec<f64> = (0..4096)
            .map(|s| Rng::for_sample(7, s + 1, 0).next_f64())
            .collect();
        assert!(correlation(&a, &b).abs() < 0.08);
    }
}
