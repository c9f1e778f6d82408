//! The denoiser's buffers: a frame as planes of `f32` (one per channel of what it holds), the
//! planes of a row side by side, with a border of pixels around the frame that every
//! neighbourhood of every pass reads inside of, and the three-channel lanes its kernels use.

use rayon::prelude::*;

use super::ITERATIONS;
use crate::simd::Lanes;

/// Pixels of border on each side: the widest à-trous step (which also covers the 3×3
/// variance and colour windows and the restore's 5×5).
const PAD: usize = 1 << (ITERATIONS - 1);

/// A row's lanes run past the frame's width to a multiple of this (the widest lanes).
const WIDEST: usize = 16;

/// `k` planes of a `w`×`h` frame and its border. Row `y` holds plane 0's row, then plane
/// 1's, and so on, each `stride` long, so that a pass writes whole rows in parallel.
#[derive(Clone)]
pub(super) struct Planes {
    k: usize,
    w: usize,
    h: usize,
    stride: usize,
    data: Vec<f32>,
}

impl Planes {
    /// `k` planes of zeros.
    pub(super) fn new(k: usize, w: usize, h: usize) -> Planes {
        let stride = PAD + w.next_multiple_of(WIDEST) + PAD;
        Planes {
            k,
            w,
            h,
            stride,
            data: vec![0.0; k * stride * (h + 2 * PAD)],
        }
    }

    /// The frame's width.
    pub(super) fn width(&self) -> usize {
        self.w
    }

    /// The length of one plane's row (the distance between a row's planes).
    pub(super) fn stride(&self) -> usize {
        self.stride
    }

    /// Sets every value of a plane, border included.
    pub(super) fn fill(&mut self, plane: usize, v: f32) {
        let row = self.k * self.stride;
        for r in self.data.chunks_mut(row) {
            r[plane * self.stride..(plane + 1) * self.stride].fill(v);
        }
    }

    /// Where pixel `x` of a plane is in a row (border columns are `x < 0` and `x ≥ w`).
    pub(super) fn in_row(&self, plane: usize, x: isize) -> usize {
        plane * self.stride + (x + PAD as isize) as usize
    }

    /// The frame's rows (`y`, its planes).
    pub(super) fn rows(&self) -> impl IndexedParallelIterator<Item = (usize, &[f32])> {
        self.data
            .par_chunks(self.k * self.stride)
            .skip(PAD)
            .take(self.h)
            .enumerate()
    }

    fn index(&self, plane: usize, x: isize, y: isize) -> usize {
        (y + PAD as isize) as usize * self.k * self.stride + self.in_row(plane, x)
    }

    pub(super) fn get(&self, plane: usize, x: usize, y: usize) -> f32 {
        self.data[self.index(plane, x as isize, y as isize)]
    }

    /// Lanes of a plane from pixel (`x`, `y`) on (`x` up to the border's width outside).
    #[inline(always)]
    pub(super) fn load<L: Lanes>(&self, plane: usize, x: isize, y: isize) -> L {
        L::load(&self.data[self.index(plane, x, y)..])
    }

    /// [`Planes::load`] of three planes from `plane` on.
    #[inline(always)]
    pub(super) fn load3<L: Lanes>(&self, plane: usize, x: isize, y: isize) -> Lane3<L> {
        Lane3 {
            x: self.load(plane, x, y),
            y: self.load(plane + 1, x, y),
            z: self.load(plane + 2, x, y),
        }
    }

    /// The frame's rows (`y`, its planes), for writing in parallel.
    pub(super) fn rows_mut(&mut self) -> impl IndexedParallelIterator<Item = (usize, &mut [f32])> {
        let h = self.h;
        self.data
            .par_chunks_mut(self.k * self.stride)
            .skip(PAD)
            .take(h)
            .enumerate()
    }
}

/// Where pixel `x` (in the frame) of a plane is in a row of planes `stride` long.
pub(super) fn in_row(stride: usize, plane: usize, x: usize) -> usize {
    plane * stride + PAD + x
}

/// Three channels, a pixel a lane: a `Vec3` in lanes, its operations `Vec3`'s, channel by
/// channel in the same order.
#[derive(Clone, Copy)]
pub(super) struct Lane3<L> {
    x: L,
    y: L,
    z: L,
}

impl<L: Lanes> Lane3<L> {
    #[inline(always)]
    pub(super) fn splat(v: L) -> Self {
        Lane3 { x: v, y: v, z: v }
    }

    #[inline(always)]
    fn map(self, f: impl Fn(L) -> L) -> Self {
        Lane3 {
            x: f(self.x),
            y: f(self.y),
            z: f(self.z),
        }
    }

    /// Channel by channel, `f(self, b)`.
    #[inline(always)]
    pub(super) fn zip(self, b: Self, f: impl Fn(L, L) -> L) -> Self {
        Lane3 {
            x: f(self.x, b.x),
            y: f(self.y, b.y),
            z: f(self.z, b.z),
        }
    }

    #[inline(always)]
    pub(super) fn add(self, b: Self) -> Self {
        self.zip(b, L::add)
    }

    #[inline(always)]
    pub(super) fn sub(self, b: Self) -> Self {
        self.zip(b, L::sub)
    }

    #[inline(always)]
    pub(super) fn mul(self, b: Self) -> Self {
        self.zip(b, L::mul)
    }

    #[inline(always)]
    pub(super) fn div3(self, b: Self) -> Self {
        self.zip(b, L::div)
    }

    /// Every channel times `k`.
    #[inline(always)]
    pub(super) fn scale(self, k: L) -> Self {
        self.map(|v| v.mul(k))
    }

    /// Every channel over `k`.
    #[inline(always)]
    pub(super) fn div(self, k: L) -> Self {
        self.map(|v| v.div(k))
    }

    #[inline(always)]
    pub(super) fn abs(self) -> Self {
        self.map(L::abs)
    }

    /// Every channel's `max` with `k` (`Vec3::max` with a splat).
    #[inline(always)]
    pub(super) fn max(self, k: L) -> Self {
        self.map(|v| v.max(k))
    }

    /// `Vec3::dot`: `(x·x' + y·y') + z·z'`.
    #[inline(always)]
    pub(super) fn dot(self, b: Self) -> L {
        self.x.mul(b.x).add(self.y.mul(b.y)).add(self.z.mul(b.z))
    }

    /// `Vec3::max_element`: `max(x, max(y, z))`.
    #[inline(always)]
    pub(super) fn max_element(self) -> L {
        self.x.max(self.y.max(self.z))
    }

    /// [`super::luminance`], a pixel a lane.
    #[inline(always)]
    pub(super) fn luminance(self) -> L {
        L::splat(0.2126)
            .mul(self.x)
            .add(L::splat(0.7152).mul(self.y))
            .add(L::splat(0.0722).mul(self.z))
    }

    /// The lanes in `m`, zero elsewhere: what a neighbour that does not count adds.
    #[inline(always)]
    pub(super) fn counted(self, m: L::Mask) -> Self {
        self.map(|v| L::select(m, L::splat(0.0), v))
    }

    /// `b` in the lanes of `m`, else `a`.
    #[inline(always)]
    pub(super) fn select(m: L::Mask, a: Self, b: Self) -> Self {
        a.zip(b, |a, b| L::select(m, a, b))
    }

    /// Three planes from `at` in a row of planes `stride` apart.
    #[inline(always)]
    pub(super) fn load_row(row: &[f32], at: usize, stride: usize) -> Self {
        Lane3 {
            x: L::load(&row[at..]),
            y: L::load(&row[at + stride..]),
            z: L::load(&row[at + 2 * stride..]),
        }
    }

    /// Into three planes from `at` in a row of planes `stride` apart.
    #[inline(always)]
    pub(super) fn store(self, row: &mut [f32], at: usize, stride: usize) {
        self.x.store(&mut row[at..]);
        self.y.store(&mut row[at + stride..]);
        self.z.store(&mut row[at + 2 * stride..]);
    }
}
