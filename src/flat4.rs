//! The flat object list: each object's triangles in [`Tri4`] blocks, the objects' boxes four
//! to a [`Box4`]. A closest-hit query slab-tests every box four at a time, then visits the
//! objects it meets nearest entry first, testing their blocks with the SIMD kernels, and stops
//! once the next object starts beyond the best hit ([`cull_bound`]). An any-hit query stops at
//! the first confirmed hit.

use std::ops::Range;

use crate::accel::Hit;
use crate::bvh::cull_bound;
use crate::geometry::{Aabb, Ray, Triangle, gamma};
use crate::tri4::{Closest, Isa, Kernel, LANES, Portable, RayLanes, Tri4, any_confirmed};

/// Objects sorted by entry distance on the stack; a list with more is visited in order.
const SORTED_MAX: usize = 64;

/// Four boxes, slab by slab: `min[axis][lane]`, `max[axis][lane]`. Unused lanes are empty
/// boxes (min +∞, max −∞), which no ray meets.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct Box4 {
    min: [[f32; 4]; 3],
    max: [[f32; 4]; 3],
}

impl Box4 {
    /// Up to four boxes.
    pub fn new(boxes: &[Aabb]) -> Box4 {
        assert!(boxes.len() <= 4);
        let mut b = Box4 {
            min: [[f32::INFINITY; 4]; 3],
            max: [[f32::NEG_INFINITY; 4]; 3],
        };
        for (lane, bx) in boxes.iter().enumerate() {
            for axis in 0..3 {
                b.min[axis][lane] = bx.min[axis];
                b.max[axis][lane] = bx.max[axis];
            }
        }
        b
    }

    /// Which boxes the ray meets for some `t` in `[0, t_max]` (bit per lane), and where it
    /// enters each: [`Aabb::hit`]'s robust slab test (the far side widened by 1 + 2γ₃; a NaN
    /// slab distance constrains nothing), one lane at a time.
    #[inline(always)]
    pub fn enter_portable(&self, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        let widen = 1.0 + 2.0 * gamma(3);
        let mut t0 = [0.0f32; 4];
        let mut t1 = [t_max; 4];
        for axis in 0..3 {
            for l in 0..4 {
                let a = (self.min[axis][l] - origin[axis]) * inv_dir[axis];
                let b = (self.max[axis][l] - origin[axis]) * inv_dir[axis];
                let (near, far) = if a > b { (b, a) } else { (a, b) };
                let far = far * widen;
                if near > t0[l] {
                    t0[l] = near;
                }
                if far < t1[l] {
                    t1[l] = far;
                }
            }
        }
        let mut mask = 0;
        for l in 0..4 {
            if t0[l] <= t1[l] {
                mask |= 1 << l;
            }
        }
        (mask, t0)
    }

    /// [`Box4::enter_portable`] with SSE2: the same operations four lanes at a time (SSE's
    /// min/max pick the same operand as the portable comparisons, NaN included).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn enter_sse2(&self, origin: &[f32; 3], inv_dir: &[f32; 3], t_max: f32) -> (u32, [f32; 4]) {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of every x86-64; the loads read whole aligned `[f32; 4]`s.
        unsafe {
            let widen = _mm_set1_ps(1.0 + 2.0 * gamma(3));
            let mut t0 = _mm_setzero_ps();
            let mut t1 = _mm_set1_ps(t_max);
            for axis in 0..3 {
                let o = _mm_set1_ps(origin[axis]);
                let inv = _mm_set1_ps(inv_dir[axis]);
                let a = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(self.min[axis].as_ptr()), o), inv);
                let b = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(self.max[axis].as_ptr()), o), inv);
                let near = _mm_min_ps(b, a);
                let far = _mm_mul_ps(_mm_max_ps(a, b), widen);
                t0 = _mm_max_ps(near, t0);
                t1 = _mm_min_ps(far, t1);
            }
            let mask = _mm_movemask_ps(_mm_cmple_ps(t0, t1)) as u32;
            let mut t = [0f32; 4];
            _mm_storeu_ps(t.as_mut_ptr(), t0);
            (mask, t)
        }
    }
}

/// One object: its blocks.
#[derive(Clone, Debug, PartialEq)]
struct Object {
    first: u32,
    blocks: u32,
}

/// The flat list.
#[derive(Clone, Debug, PartialEq)]
pub struct Flat4 {
    boxes: Vec<Box4>,
    objects: Vec<Object>,
    blocks: Vec<Tri4>,
    /// Scene index of each lane of `blocks` (`u32::MAX` for padding).
    ids: Vec<u32>,
}

impl Flat4 {
    /// The list of `objects` (contiguous ranges of `triangles`; empty ones are dropped).
    pub fn build(triangles: &[Triangle], objects: &[Range<usize>]) -> Flat4 {
        let mut f = Flat4 {
            boxes: vec![],
            objects: vec![],
            blocks: vec![],
            ids: vec![],
        };
        let mut aabbs = vec![];
        for g in objects.iter().filter(|r| !r.is_empty()) {
            let tris = &triangles[g.clone()];
            let first = f.blocks.len();
            f.blocks.extend(Tri4::pack(tris.iter().map(|t| t.v)));
            let n = f.blocks.len() - first;
            f.ids.extend(g.clone().map(|i| i as u32));
            f.ids.resize((first + n) * LANES, u32::MAX);
            f.objects.push(Object {
                first: first as u32,
                blocks: n as u32,
            });
            aabbs.push(
                tris.iter()
                    .fold(Aabb::EMPTY, |b, t| b.union(Aabb::of_triangle(t))),
            );
        }
        f.boxes = aabbs.chunks(4).map(Box4::new).collect();
        f
    }

    /// The lanes of box group `g` that hold an object.
    #[inline(always)]
    fn lanes(&self, g: usize) -> u32 {
        let n = (self.objects.len() - 4 * g).min(4);
        (1 << n) - 1
    }

    /// Number of objects.
    pub fn objects(&self) -> usize {
        self.objects.len()
    }

    /// Closest hit on path `isa` (must be available).
    pub fn intersect(&self, isa: Isa, ray: &Ray, t_max: f32) -> Option<Hit> {
        match isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the caller passes an available path.
            Isa::Avx2 => unsafe { closest_avx2(self, ray, t_max) },
            #[cfg(target_arch = "x86_64")]
            Isa::Sse2 => closest::<crate::tri4::Sse2>(self, ray, t_max),
            _ => closest::<Portable>(self, ray, t_max),
        }
    }

    /// Any hit on path `isa` (must be available).
    pub fn occluded(&self, isa: Isa, ray: &Ray, t_max: f32) -> bool {
        match isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the caller passes an available path.
            Isa::Avx2 => unsafe { occluded_avx2(self, ray, t_max) },
            #[cfg(target_arch = "x86_64")]
            Isa::Sse2 => occluded::<crate::tri4::Sse2>(self, ray, t_max),
            _ => occluded::<Portable>(self, ray, t_max),
        }
    }

    /// The closest hit among object `o`'s triangles, folded into `c`.
    #[inline(always)]
    fn object_closest<K: Kernel>(&self, o: usize, ray: &Ray, r: &RayLanes, c: &mut Closest) {
        let obj = &self.objects[o];
        let (mut b, end) = (obj.first as usize, (obj.first + obj.blocks) as usize);
        let blocks = &self.blocks;
        while b < end {
            let (cand, n) = if b + 1 < end {
                (K::two(&blocks[b], &blocks[b + 1], r, c.tri_t_max), 2)
            } else {
                (K::one(&blocks[b], r, c.tri_t_max), 1)
            };
            if cand.mask != 0 {
                c.take(
                    ray,
                    cand,
                    |l| blocks[b + l / LANES].vertices(l % LANES),
                    |l| self.ids[b * LANES + l],
                );
            }
            b += n;
        }
    }

    /// Whether one of object `o`'s triangles has a hit before `t_max`.
    #[inline(always)]
    fn object_occluded<K: Kernel>(&self, o: usize, ray: &Ray, r: &RayLanes, t_max: f32) -> bool {
        let obj = &self.objects[o];
        let (mut b, end) = (obj.first as usize, (obj.first + obj.blocks) as usize);
        let blocks = &self.blocks;
        while b < end {
            let (cand, n) = if b + 1 < end {
                (K::two(&blocks[b], &blocks[b + 1], r, t_max), 2)
            } else {
                (K::one(&blocks[b], r, t_max), 1)
            };
            if cand.mask != 0
                && any_confirmed(ray, cand, t_max, |l| {
                    blocks[b + l / LANES].vertices(l % LANES)
                })
            {
                return true;
            }
            b += n;
        }
        false
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn closest_avx2(f: &Flat4, ray: &Ray, t_max: f32) -> Option<Hit> {
    closest::<crate::tri4::Avx2>(f, ray, t_max)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn occluded_avx2(f: &Flat4, ray: &Ray, t_max: f32) -> bool {
    occluded::<crate::tri4::Avx2>(f, ray, t_max)
}

#[inline(always)]
fn closest<K: Kernel>(f: &Flat4, ray: &Ray, t_max: f32) -> Option<Hit> {
    let r = RayLanes::new(ray);
    let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
    let mut c = Closest::new(t_max);
    let mut bound = cull_bound(t_max);
    if f.objects.len() > SORTED_MAX {
        for (g, bx) in f.boxes.iter().enumerate() {
            let (mut mask, t) = K::boxes(bx, &o, &inv, bound);
            mask &= f.lanes(g);
            while mask != 0 {
                let l = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if t[l] <= bound {
                    f.object_closest::<K>(4 * g + l, ray, &r, &mut c);
                    if let Some(h) = c.best {
                        bound = cull_bound(h.t);
                    }
                }
            }
        }
        return c.best;
    }
    // The objects the ray meets, by entry distance (insertion sort: a handful).
    let mut order = [(0f32, 0u32); SORTED_MAX];
    let mut n = 0;
    for (g, bx) in f.boxes.iter().enumerate() {
        let (mut mask, t) = K::boxes(bx, &o, &inv, bound);
            mask &= f.lanes(g);
        while mask != 0 {
            let l = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let mut i = n;
            while i > 0 && order[i - 1].0 > t[l] {
                order[i] = order[i - 1];
                i -= 1;
            }
            order[i] = (t[l], (4 * g + l) as u32);
            n += 1;
        }
    }
    for &(t_enter, obj) in &order[..n] {
        if !(t_enter <= bound) {
            break;
        }
        f.object_closest::<K>(obj as usize, ray, &r, &mut c);
        if let Some(h) = c.best {
            bound = cull_bound(h.t);
        }
    }
    c.best
}

#[inline(always)]
fn occluded<K: Kernel>(f: &Flat4, ray: &Ray, t_max: f32) -> bool {
    let r = RayLanes::new(ray);
    let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
    let bound = cull_bound(t_max);
    for (g, bx) in f.boxes.iter().enumerate() {
        let (mut mask, _) = K::boxes(bx, &o, &inv, bound);
        mask &= f.lanes(g);
        while mask != 0 {
            let l = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if f.object_occluded::<K>(4 * g + l, ray, &r, t_max) {
                return true;
            }
        }
    }
    false
}
