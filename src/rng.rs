//! A small, seedable random number generator. Every sample's stream is derived from
//! (pixel, sample, frame), so images do not depend on the thread count or the order of work.

use crate::simd::Isa;

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

/// The first two numbers of sample `sample` of rows of eight pixels in frame `frame`: for row
/// `r`, `Rng::for_sample(pixels[r][l], sample, frame)`'s first two `next_f32`s in lane `l` of
/// `out[r][0]` and `out[r][1]`, bit for bit. On the AVX-512 path (its 64-bit multiply) eight
/// lanes at a time, the rows' hashes in flight together; else one pixel after the other.
/// `isa` must be available.
pub fn first_two8(
    isa: Isa,
    pixels: &[[u64; 8]],
    sample: u32,
    frame: u32,
    out: &mut [[[f32; 8]; 2]],
) {
    assert_eq!(pixels.len(), out.len());
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx512 {
        assert!(isa.available(), "{} is not available", isa.name());
        // SAFETY: the CPU has AVX-512 (checked above).
        unsafe { first_two8_avx512(pixels, sample, frame, out) };
        return;
    }
    for (row, out) in pixels.iter().zip(out) {
        for (l, &p) in row.iter().enumerate() {
            let mut r = Rng::for_sample(p, sample, frame);
            out[0][l] = r.next_f32();
            out[1][l] = r.next_f32();
        }
    }
}

/// [`first_two8`] with AVX-512: [`Rng::for_sample`]'s hashes and two steps of the generator,
/// lane by lane, in the same wrapping 64-bit arithmetic.
///
/// # Safety
/// The CPU must have AVX-512 F, DQ, VL and BW.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
unsafe fn first_two8_avx512(
    pixels: &[[u64; 8]],
    sample: u32,
    frame: u32,
    out: &mut [[[f32; 8]; 2]],
) {
    use std::arch::x86_64::*;
    let k = |c: u64| _mm512_set1_epi64(c as i64);
    // `mix`, lane by lane.
    let mix8 = |z: __m512i| {
        let z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64::<30>(z)), k(MIX_1));
        let z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64::<27>(z)), k(MIX_2));
        _mm512_xor_si512(z, _mm512_srli_epi64::<31>(z))
    };
    // `next_f32`: the top 24 bits of the next number, times 2⁻²⁴ (both exact).
    let scale = _mm256_set1_ps(1.0 / (1u64 << 24) as f32);
    let draw = |state: __m512i| {
        let top = _mm512_srli_epi64::<40>(mix8(state));
        _mm256_mul_ps(_mm512_cvtepi64_ps(top), scale)
    };
    let seed = k((u64::from(sample) << 32) | u64::from(frame));
    for (row, out) in pixels.iter().zip(out) {
        // SAFETY: reads eight `u64`s.
        let p = unsafe { _mm512_loadu_si512(row.as_ptr().cast()) };
        let h = mix8(_mm512_xor_si512(p, k(PIXEL_KEY)));
        let state = mix8(_mm512_xor_si512(h, seed));
        let state = mix8(state);
        let first = _mm512_add_epi64(state, k(GOLDEN));
        let second = _mm512_add_epi64(first, k(GOLDEN));
        // SAFETY: each writes eight `f32`s.
        unsafe {
            _mm256_storeu_ps(out[0].as_mut_ptr(), draw(first));
            _mm256_storeu_ps(out[1].as_mut_ptr(), draw(second));
        }
    }
}

/// The SplitMix64 finaliser: a bijection of 64 bits that scrambles every bit (also the
/// Sobol sampler's seed hash).
#[inline]
pub(crate) fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(MIX_1);
    z = (z ^ (z >> 27)).wrapping_mul(MIX_2);
    z ^ (z >> 31)
}

/// [`mix`]'s two multipliers (SplitMix64's own).
const MIX_1: u64 = 0xBF58_476D_1CE4_E5B9;
const MIX_2: u64 = 0x94D0_49BB_1331_11EB;

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

    /// Rows of eight pixels' first two numbers at once are each pixel's own, bit for bit (on
    /// every path this CPU has), for pixels, samples and frames across the whole range of their
    /// bits.
    #[test]
    fn first_two_numbers_of_eight_pixels_are_each_ones() {
        let mut seeds = Rng::seeded(9);
        for case in 0..2000 {
            let pixels: [u64; 8] = std::array::from_fn(|l| match case % 3 {
                0 => case * 8 + l as u64,
                1 => seeds.next_u64(),
                _ => u64::MAX - l as u64,
            });
            let (sample, frame) = (seeds.next_u64() as u32, (case % 7) as u32);
            // One to eight rows, the last one these pixels.
            let rows = 1 + case as usize % 8;
            let mut all = vec![[0; 8]; rows];
            for (r, row) in all.iter_mut().enumerate() {
                *row = pixels.map(|p| p.wrapping_add(r as u64 * 1000));
            }
            for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
                let mut got = vec![[[0.0; 8]; 2]; rows];
                first_two8(isa, &all, sample, frame, &mut got);
                for (row, got) in all.iter().zip(&got) {
                    for (l, &p) in row.iter().enumerate() {
                        let mut r = Rng::for_sample(p, sample, frame);
                        let want = [r.next_f32(), r.next_f32()];
                        assert_eq!(
                            [got[0][l].to_bits(), got[1][l].to_bits()],
                            want.map(f32::to_bits),
                            "{}: pixel {p}, sample {sample}, frame {frame}",
                            isa.name()
                        );
                    }
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
