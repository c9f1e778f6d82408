//! Where a sample's numbers come from: independent random numbers ([`Rng`]), or an
//! Owen-scrambled Sobol sequence that spreads a pixel's samples evenly over every pair of
//! dimensions a path uses.
//!
//! The Sobol sampler follows Burley's "Practical Hash-based Owen Scrambling" (JCGT 2020): each
//! pair of dimensions (the pixel offset, then each draw of a path: a bounce's direction, a
//! roulette test) is the first two dimensions of the Sobol sequence, a (0,2)-sequence, with the
//! point's index shuffled and each coordinate Owen-scrambled by a hash seeded with (pixel,
//! dimension). So every pair is stratified on its own, pairs are decorrelated from each other,
//! and each number is uniform, as the estimator needs to stay unbiased. The first two pairs a
//! path draws (its first two bounces' directions) are one 4D point instead (Sobol dimensions
//! 0-3 of one shuffled index), so that the light of two-bounce paths, which depends on both at
//! once, is stratified too.
//!
//! Samples of a pixel are points `frame·samples + sample` of one sequence: a frame of N samples
//! continues where the previous frame stopped, so progressive passes (the app's) and one batch
//! draw the same points, and any prefix of a power-of-two length is a well-spread net. Where a
//! path splits into k branches after its first vertex, branch b of point i draws from point
//! `i·k + b` (from its first bounce on), so the branches of N samples spread over kN points.

use crate::rng::{Rng, mix};

/// Which numbers drive a frame's samples (a scene's `sampler`, `raytty render --sampler`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Sampler {
    /// Independent random numbers per (pixel, sample, frame): the bench's references keep
    /// this one, so their cached files stay valid.
    Independent,
    /// Owen-scrambled Sobol points (see the module's doc): lower error at equal samples.
    #[default]
    Sobol,
}

impl Sampler {
    /// Every sampler.
    pub const ALL: [Sampler; 2] = [Sampler::Independent, Sampler::Sobol];

    /// The name scene files and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            Sampler::Independent => "independent",
            Sampler::Sobol => "sobol",
        }
    }

    /// Parses a sampler's name.
    pub fn from_name(name: &str) -> Option<Sampler> {
        Sampler::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// A source of uniform numbers in `[0, 1)` for one sample's path: one number, or a pair that
/// is meant to be used together (a direction).
pub trait SampleSource {
    /// The next number.
    fn next_1d(&mut self) -> f32;
    /// The next pair.
    fn next_2d(&mut self) -> [f32; 2];
    /// The numbers of branch `b` of `k` that a path splits into after its first vertex,
    /// from the path's first bounce on.
    fn branch(&self, b: u32, k: u32) -> Self
    where
        Self: Sized;
}

impl SampleSource for Rng {
    /// A generator of its own, seeded from this one's next number and `b`.
    fn branch(&self, b: u32, _k: u32) -> Rng {
        let next = self.clone().next_u64();
        Rng::seeded(mix(next ^ u64::from(b + 1).wrapping_mul(BRANCH_KEY)))
    }

    #[inline]
    fn next_1d(&mut self) -> f32 {
        self.next_f32()
    }

    /// Two numbers in turn, as the path tracer always drew them.
    #[inline]
    fn next_2d(&mut self) -> [f32; 2] {
        let u = self.next_f32();
        [u, self.next_f32()]
    }
}

/// The numbers of one sample of one pixel, from the chosen [`Sampler`].
#[derive(Clone, Debug)]
pub enum Stream {
    /// From [`Sampler::Independent`].
    Independent(Rng),
    /// From [`Sampler::Sobol`].
    Sobol(Sobol),
}

impl Stream {
    /// Sample `sample` of `samples` of `pixel` in frame `frame`.
    pub fn for_sample(
        sampler: Sampler,
        pixel: u64,
        sample: u32,
        samples: u32,
        frame: u32,
    ) -> Stream {
        match sampler {
            Sampler::Independent => Stream::Independent(Rng::for_sample(pixel, sample, frame)),
            Sampler::Sobol => Stream::Sobol(Sobol::new(
                pixel,
                frame.wrapping_mul(samples).wrapping_add(sample),
            )),
        }
    }

    /// Where in its pixel the sample's ray goes, in `[0, 1)²`, or `None` when the render loop
    /// should place it (on its grid, from two numbers of [`Stream::next_2d`]): Sobol points
    /// are already spread evenly over the pixel's samples, in any batch.
    #[inline]
    pub fn pixel_offset(&mut self) -> Option<[f32; 2]> {
        match self {
            Stream::Independent(_) => None,
            Stream::Sobol(s) => Some(s.pair(PIXEL_DIMENSION)),
        }
    }
}

impl SampleSource for Stream {
    fn branch(&self, b: u32, k: u32) -> Stream {
        match self {
            Stream::Independent(r) => Stream::Independent(r.branch(b, k)),
            Stream::Sobol(s) => Stream::Sobol(s.branch(b, k)),
        }
    }

    #[inline]
    fn next_1d(&mut self) -> f32 {
        match self {
            Stream::Independent(r) => r.next_f32(),
            Stream::Sobol(s) => s.next_1d(),
        }
    }

    #[inline]
    fn next_2d(&mut self) -> [f32; 2] {
        match self {
            Stream::Independent(r) => r.next_2d(),
            Stream::Sobol(s) => s.next_2d(),
        }
    }
}

/// Keeps the streams of an independent path's branches apart from each other and from its
/// own (any odd constant: the first 64 bits of √2's fraction, its last bit set).
const BRANCH_KEY: u64 = 0x6A09_E667_F3BC_C909;

/// The Sobol sampler's dimension (pair) of the pixel offset; a path's draws come after it.
const PIXEL_DIMENSION: u32 = 0;

/// One point of a pixel's Owen-scrambled Sobol sequence, handed out a dimension (pair) at a
/// time.
#[derive(Clone, Debug)]
pub struct Sobol {
    /// The pixel's key: seeds every dimension's scrambles.
    key: u64,
    /// The point's index in the pixel's sequence, its bits reversed (every dimension's
    /// shuffle starts from it).
    index_reversed: u32,
    /// The next dimension (pair) to hand out.
    dimension: u32,
}

impl Sobol {
    /// Point `index` of `pixel`'s sequence.
    pub fn new(pixel: u64, index: u32) -> Sobol {
        Sobol {
            key: mix(pixel ^ SOBOL_KEY),
            index_reversed: index.reverse_bits(),
            dimension: PIXEL_DIMENSION + 1,
        }
    }

    /// The seeds of dimension (pair) `dimension`: the index shuffle's, then the first
    /// coordinate's scramble's.
    #[inline]
    fn seeds(&self, dimension: u32) -> (u32, u32) {
        let h = mix(self.key ^ u64::from(dimension).wrapping_mul(DIMENSION_STEP));
        (h as u32, (h >> 32) as u32)
    }

    /// Dimension pair `dimension` of this point: the index shuffled (an Owen scramble of its
    /// reversed bits), the first two Sobol coordinates, each Owen-scrambled; every seed from
    /// (pixel, dimension). Worked in reversed bits, where the Sobol coordinates are the index
    /// itself and [`sobol_1_reversed`], and a scramble is one [`upward_hash`].
    /// [`FOUR_D_SECOND`] takes Sobol dimensions 2 and 3 at the previous pair's shuffled index
    /// instead (with scrambles of its own).
    #[inline]
    fn pair(&self, dimension: u32) -> [f32; 2] {
        let (x, y) = if dimension == FOUR_D_SECOND {
            let (shuffle, _) = self.seeds(FOUR_D_SECOND - 1);
            let (_, sx) = self.seeds(dimension);
            let i = upward_hash(self.index_reversed, shuffle).reverse_bits();
            (
                upward_hash(sobol_reversed(&SOBOL_2, i), sx),
                upward_hash(sobol_reversed(&SOBOL_3, i), second_seed(sx)),
            )
        } else {
            let (shuffle, sx) = self.seeds(dimension);
            let i = upward_hash(self.index_reversed, shuffle).reverse_bits();
            (
                upward_hash(i, sx),
                upward_hash(sobol_1_reversed(i), second_seed(sx)),
            )
        };
        // Both turned back at once: one 64-bit reversal costs what one of 32 bits does.
        let xy = ((u64::from(x) << 32) | u64::from(y)).reverse_bits();
        [unit(xy as u32), unit((xy >> 32) as u32)]
    }
}

impl SampleSource for Sobol {
    /// Point `index·k + b` of the pixel's sequence, from its first draw on: the k branches of
    /// a pixel's N samples are together the first kN points, so each pair a branch draws is
    /// spread over all of them.
    fn branch(&self, b: u32, k: u32) -> Sobol {
        let index = self.index_reversed.reverse_bits();
        Sobol {
            key: self.key,
            index_reversed: index.wrapping_mul(k).wrapping_add(b).reverse_bits(),
            dimension: PIXEL_DIMENSION + 1,
        }
    }

    /// The first coordinate of the next pair (the second is not computed).
    #[inline]
    fn next_1d(&mut self) -> f32 {
        if self.dimension == FOUR_D_SECOND {
            return self.next_2d()[0];
        }
        let (shuffle, sx) = self.seeds(self.dimension);
        self.dimension += 1;
        let i = upward_hash(self.index_reversed, shuffle).reverse_bits();
        unit(upward_hash(i, sx).reverse_bits())
    }

    #[inline]
    fn next_2d(&mut self) -> [f32; 2] {
        let p = self.pair(self.dimension);
        self.dimension += 1;
        p
    }
}

/// The pair drawn second by a path (the second bounce's direction) is Sobol dimensions 2 and 3
/// of the first bounce's shuffled index: the two bounces form one 4D point.
const FOUR_D_SECOND: u32 = PIXEL_DIMENSION + 2;

/// A Sobol dimension's 32 direction numbers (as 32-bit fractions) from its primitive polynomial
/// of degree `s` (inner coefficients `a`, highest first) and initial numbers `m` (Bratley and
/// Fox's recurrence: m_k = 2a₁m_{k−1} ⊕ … ⊕ 2^{s−1}a_{s−1}m_{k−s+1} ⊕ 2^s m_{k−s} ⊕ m_{k−s}).
const fn direction_numbers(s: usize, a: u32, m: [u32; 3]) -> [u32; 32] {
    let mut mk = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        if k < s {
            mk[k] = m[k];
        } else {
            let mut v = mk[k - s] ^ (mk[k - s] << s);
            let mut j = 1;
            while j < s {
                if (a >> (s - 1 - j)) & 1 != 0 {
                    v ^= mk[k - j] << j;
                }
                j += 1;
            }
            mk[k] = v;
        }
        k += 1;
    }
    let mut out = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        out[k] = mk[k] << (31 - k);
        k += 1;
    }
    out
}

/// Byte tables of a dimension's generator: entry `[b][v]` is the XOR of the direction numbers
/// of byte `b`'s set bits when it holds `v`, its bits reversed (as the scrambles take it).
const fn byte_tables(v: [u32; 32]) -> [[u32; 256]; 4] {
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut x = 0;
        while x < 256 {
            let mut acc = 0;
            let mut bit = 0;
            while bit < 8 {
                if (x >> bit) & 1 != 0 {
                    acc ^= v[b * 8 + bit];
                }
                bit += 1;
            }
            t[b][x] = acc.reverse_bits();
            x += 1;
        }
        b += 1;
    }
    t
}

/// Sobol dimension 2: x² + x + 1, m = 1, 3 (Joe and Kuo's table).
static SOBOL_2: [[u32; 256]; 4] = byte_tables(direction_numbers(2, 1, [1, 3, 0]));
/// Sobol dimension 3: x³ + x + 1, m = 1, 3, 1 (Joe and Kuo's table).
static SOBOL_3: [[u32; 256]; 4] = byte_tables(direction_numbers(3, 1, [1, 3, 1]));

/// A Sobol dimension at `index` (a 32-bit fraction, bits reversed) from its byte tables: four
/// lookups.
#[inline]
fn sobol_reversed(t: &[[u32; 256]; 4], i: u32) -> u32 {
    let b = i.to_le_bytes();
    t[0][b[0] as usize] ^ t[1][b[1] as usize] ^ t[2][b[2] as usize] ^ t[3][b[3] as usize]
}

/// Keeps the Sobol sampler's pixel keys apart from [`Rng`]'s (any odd constant: the first
/// 64 bits of e's fraction).
const SOBOL_KEY: u64 = 0xB7E1_5162_8AED_2A6B;

/// Dimensions are spread over the key by this odd step (2⁶⁴/φ), so each gets its own seeds.
const DIMENSION_STEP: u64 = 0x9E37_79B9_7F4A_7C15;

/// The top 24 bits of `x` as an `f32` in `[0, 1)` (exact: every such value is an `f32`).
#[inline]
fn unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The second dimension of the Sobol sequence at `index`, as a 32-bit fraction with its bits
/// reversed (bit 0 is the 2⁻¹ digit): the XOR of the direction numbers of the index's set
/// bits. Its direction numbers (primitive polynomial x + 1) start at 2⁻¹ and follow
/// `v ← v ⊕ (v ≫ 1)`; reversed, index bit k's is `(1 + X)ᵏ` over GF(2), whose bit i is the
/// binomial C(k, i) mod 2, which is 1 exactly when i's bits are a subset of k's (Lucas). So
/// bit i of the result is the XOR of the index bits k ⊇ i: a superset sum over the five bits
/// of a bit position, one shift, mask and XOR per bit. (The first dimension is the bit
/// reversal of the index, the van der Corput sequence: reversed, the index itself.)
#[inline]
fn sobol_1_reversed(index: u32) -> u32 {
    let mut x = index;
    x ^= (x >> 1) & 0x5555_5555;
    x ^= (x >> 2) & 0x3333_3333;
    x ^= (x >> 4) & 0x0F0F_0F0F;
    x ^= (x >> 8) & 0x00FF_00FF;
    x ^ (x >> 16)
}

/// A hash of 32 bits in which output bit k depends only on `seed` and input bits 0..=k, and
/// which is a bijection for any seed. On a fraction's reversed bits (digit 2⁻¹ at bit 0) it is
/// a nested uniform (Owen) scramble: whether a digit flips depends only on the seed and the
/// digits above it, so points sharing their first k digits still share them (nets stay nets),
/// and each output is uniform over seeds. Laine and Karras's construction as Burley uses it,
/// with the constants of Vegdahl's better-mixing variant (2021): an addition, a product by an
/// odd number, and XORs with products by even ones, each of which carries only upwards.
#[inline]
fn upward_hash(mut v: u32, seed: u32) -> u32 {
    v ^= v.wrapping_mul(0x3D20_ADEA);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6C56);
    v ^= v.wrapping_mul(0x53A2_2864);
    v
}

/// The second coordinate's scramble seed, from the first's: a 32-bit finaliser (Wellons's
/// "lowbias32"), so the two coordinates are scrambled independently.
#[inline]
fn second_seed(mut s: u32) -> u32 {
    s ^= 0x5851_F42D;
    s ^= s >> 16;
    s = s.wrapping_mul(0x7FEB_352D);
    s ^= s >> 15;
    s = s.wrapping_mul(0x846C_A68B);
    s ^ (s >> 16)
}

#[cfg(test)]
mod tests;
