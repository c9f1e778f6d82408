//! The flat object list, fastest below [`super::BVH_THRESHOLD`] triangles (the Cornell box):
//! each object's triangles in [`Tri4`] blocks, the objects' boxes eight
//! to a [`Box8`]. A closest-hit query slab-tests every box eight at a time, then visits the
//! objects it meets nearest entry first, testing their blocks with the SIMD kernels, and stops
//! once the next object starts beyond the best hit ([`cull_bound`]). An any-hit query stops at
//! the first hit.

use std::mem::MaybeUninit;
use std::ops::Range;

use super::box8::{BOX_LANES, Box8};
use super::hit::{Hit, cull_bound};
use super::tri4::{Best8, Closest, LANES, RayLanes, Tri4, blocks_closest, blocks_occluded};
use crate::simd::{Isa, Kernel, Path};
use glam::Vec3;

use crate::geometry::{Aabb, Ray, RayTile, TILE_RAYS, Triangle};

mod tile;

pub use tile::TileCache;

/// Objects sorted by entry distance on the stack; a list with more is visited in order.
const SORTED_MAX: usize = 64;

/// One object: its blocks.
#[derive(Clone, Debug, PartialEq)]
struct Object {
    first: u32,
    blocks: u32,
}

/// The flat list.
#[derive(Clone, Debug, PartialEq)]
pub struct Flat {
    boxes: Vec<Box8>,
    objects: Vec<Object>,
    blocks: Vec<Tri4>,
    /// Scene index of each lane of `blocks` (`u32::MAX` for padding).
    ids: Vec<u32>,
    /// Every triangle with its scene index, in index order: what a tile is culled over.
    tris: Vec<([Vec3; 3], u32)>,
}

impl Flat {
    /// The list of `objects` (contiguous ranges of `triangles`; empty ones are dropped).
    pub fn build(triangles: &[Triangle], objects: &[Range<usize>]) -> Flat {
        let mut f = Flat {
            boxes: vec![],
            objects: vec![],
            blocks: vec![],
            ids: vec![],
            tris: vec![],
        };
        let mut aabbs = vec![];
        for g in objects.iter().filter(|r| !r.is_empty()) {
            let tris = &triangles[g.clone()];
            let first = f.blocks.len();
            f.blocks.extend(Tri4::pack(tris.iter().map(|t| t.v)));
            let n = f.blocks.len() - first;
            f.ids.extend(g.clone().map(|i| i as u32));
            f.tris.extend(g.clone().map(|i| (triangles[i].v, i as u32)));
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
        f.boxes = aabbs.chunks(BOX_LANES).map(Box8::new).collect();
        f.tris.sort_by_key(|&(_, i)| i);
        f
    }

    /// The lanes of box group `g` that hold an object.
    #[inline(always)]
    fn lanes(&self, g: usize) -> u32 {
        let n = (self.objects.len() - BOX_LANES * g).min(BOX_LANES);
        (1 << n) - 1
    }

    /// Number of objects.
    pub fn objects(&self) -> usize {
        self.objects.len()
    }

    /// Closest hit on path `isa` (must be available).
    pub fn intersect(&self, isa: Isa, ray: &Ray, t_max: f32) -> Option<Hit> {
        struct Q<'a>(&'a Flat, &'a Ray, f32);
        impl Kernel for Q<'_> {
            type Output = Option<Hit>;
            #[inline(always)]
            fn run<P: Path>(self) -> Option<Hit> {
                closest::<P>(self.0, self.1, self.2)
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, ray, t_max)) }
    }

    /// The closest hits of `tile`'s rays into `hits` (as many), each as [`Flat::intersect`]
    /// gives it, on path `isa` (must be available). A tile whose rays share their axes (as a
    /// camera's do) is tested as many rays at a time as the path has lanes.
    pub fn intersect_tile(
        &self,
        isa: Isa,
        tile: &RayTile,
        t_max: f32,
        hits: &mut [Option<Hit>],
        cache: &mut TileCache,
    ) {
        struct Q<'a>(
            &'a Flat,
            &'a RayTile,
            f32,
            &'a mut [Option<Hit>],
            &'a mut TileCache,
        );
        impl Kernel for Q<'_> {
            type Output = ();
            const SIXTEEN: bool = true;
            #[inline(always)]
            fn run<P: Path>(self) {
                let Q(f, tile, t_max, hits, cache) = self;
                tile::intersect_tile::<P>(f, tile, t_max, hits, cache, |r| {
                    closest::<P>(f, r, t_max)
                });
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, tile, t_max, hits, cache)) }
    }

    /// [`Flat::intersect_tile`], the hits left as the kernel makes them: ray `i` is lane
    /// `i % 8` of `best[i / 8]`. `isa` must be available.
    pub(crate) fn intersect_tile_best(
        &self,
        isa: Isa,
        tile: &RayTile,
        t_max: f32,
        best: &mut [Best8; TILE_RAYS / 8],
        cache: &mut TileCache,
    ) {
        struct Q<'a>(
            &'a Flat,
            &'a RayTile,
            f32,
            &'a mut [Best8; TILE_RAYS / 8],
            &'a mut TileCache,
        );
        impl Kernel for Q<'_> {
            type Output = ();
            const SIXTEEN: bool = true;
            #[inline(always)]
            fn run<P: Path>(self) {
                let Q(f, tile, t_max, best, cache) = self;
                tile::intersect_tile_best::<P>(f, tile, t_max, best, cache, |r| {
                    closest::<P>(f, r, t_max)
                });
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, tile, t_max, best, cache)) }
    }

    /// [`Flat::occluded`] for each of `rays`, into `out` (as many), on path `isa` (must be
    /// available): the path picked once for them all.
    pub fn occluded_each(&self, isa: Isa, rays: &[Ray], t_max: f32, out: &mut [bool]) {
        struct Q<'a>(&'a Flat, &'a [Ray], f32, &'a mut [bool]);
        impl Kernel for Q<'_> {
            type Output = ();
            #[inline(always)]
            fn run<P: Path>(self) {
                let Q(f, rays, t_max, out) = self;
                for (o, r) in out.iter_mut().zip(rays) {
                    *o = occluded::<P>(f, r, t_max);
                }
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, rays, t_max, out)) }
    }

    /// Any hit on path `isa` (must be available).
    pub fn occluded(&self, isa: Isa, ray: &Ray, t_max: f32) -> bool {
        struct Q<'a>(&'a Flat, &'a Ray, f32);
        impl Kernel for Q<'_> {
            type Output = bool;
            #[inline(always)]
            fn run<P: Path>(self) -> bool {
                occluded::<P>(self.0, self.1, self.2)
            }
        }
        // SAFETY: the caller passes an available path.
        unsafe { isa.run_unchecked(Q(self, ray, t_max)) }
    }

    /// The closest hit among object `o`'s triangles, folded into `c`.
    #[inline(always)]
    fn object_closest<P: Path>(&self, o: usize, ray: &Ray, r: &RayLanes, c: &mut Closest) {
        let obj = &self.objects[o];
        let (b, end) = (obj.first as usize, (obj.first + obj.blocks) as usize);
        blocks_closest::<P>(
            &self.blocks[b..end],
            &self.ids[b * LANES..end * LANES],
            ray,
            r,
            c,
        );
    }

    /// Whether one of object `o`'s triangles has a hit before `t_max`.
    #[inline(always)]
    fn object_occluded<P: Path>(&self, o: usize, ray: &Ray, r: &RayLanes, t_max: f32) -> bool {
        let obj = &self.objects[o];
        let (b, end) = (obj.first as usize, (obj.first + obj.blocks) as usize);
        blocks_occluded::<P>(&self.blocks[b..end], ray, r, t_max)
    }
}

#[inline(always)]
fn closest<P: Path>(f: &Flat, ray: &Ray, t_max: f32) -> Option<Hit> {
    let r = RayLanes::new(ray);
    let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
    let mut c = Closest::new(t_max);
    let mut bound = cull_bound(t_max);
    if f.objects.len() > SORTED_MAX {
        for (g, bx) in f.boxes.iter().enumerate() {
            let (mut mask, t) = bx.enter_lanes::<P::Eight>(&o, &inv, bound);
            mask &= f.lanes(g);
            while mask != 0 {
                let l = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if t[l] <= bound {
                    f.object_closest::<P>(BOX_LANES * g + l, ray, &r, &mut c);
                    if let Some(h) = c.best {
                        bound = cull_bound(h.t);
                    }
                }
            }
        }
        return c.best;
    }
    // The objects the ray meets, by entry distance (insertion sort: a handful). Entries `..n`
    // are written before they are read; the rest is left uninitialised, as zeroing its 512
    // bytes cost 17 of the 640 instructions a closest-hit query took in the area-lit box.
    let mut order = [MaybeUninit::<(f32, u32)>::uninit(); SORTED_MAX];
    let mut n = 0;
    for (g, bx) in f.boxes.iter().enumerate() {
        let (mut mask, t) = bx.enter_lanes::<P::Eight>(&o, &inv, bound);
        mask &= f.lanes(g);
        while mask != 0 {
            let l = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let mut i = n;
            // SAFETY: entries `..n` have been written.
            while i > 0 && unsafe { order[i - 1].assume_init() }.0 > t[l] {
                order[i] = order[i - 1];
                i -= 1;
            }
            order[i] = MaybeUninit::new((t[l], (BOX_LANES * g + l) as u32));
            n += 1;
        }
    }
    for e in &order[..n] {
        // SAFETY: entries `..n` have been written.
        let (t_enter, obj) = unsafe { e.assume_init() };
        if !(t_enter <= bound) {
            break;
        }
        f.object_closest::<P>(obj as usize, ray, &r, &mut c);
        if let Some(h) = c.best {
            bound = cull_bound(h.t);
        }
    }
    c.best
}

#[inline(always)]
fn occluded<P: Path>(f: &Flat, ray: &Ray, t_max: f32) -> bool {
    let r = RayLanes::new(ray);
    let (o, inv) = (ray.origin.to_array(), ray.inv_dir.to_array());
    let bound = cull_bound(t_max);
    for (g, bx) in f.boxes.iter().enumerate() {
        let (mut mask, _) = bx.enter_lanes::<P::Eight>(&o, &inv, bound);
        mask &= f.lanes(g);
        while mask != 0 {
            let l = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if f.object_occluded::<P>(BOX_LANES * g + l, ray, &r, t_max) {
                return true;
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::Hit;
    use crate::geometry::intersect_watertight;

    /// Random soups split into objects of one to five triangles: one box group, several (a
    /// last one partly filled), and more objects than are sorted ([`SORTED_MAX`]). Every
    /// closest hit and occlusion, on every path, is the brute-force loop's, bit for bit.
    #[test]
    fn every_grouping_of_objects_matches_brute_force() {
        let mut rng = crate::rng::Rng::seeded(11);
        for n_objects in [1, 7, 8, 9, 17, SORTED_MAX + 6] {
            let mut tris = vec![];
            let mut objects = vec![];
            for o in 0..n_objects {
                let start = tris.len();
                let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
                while tris.len() < start + 1 + o % 5 {
                    let mut corner = || {
                        c + (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 0.6
                    };
                    if let Ok(t) = Triangle::new(corner(), corner(), corner(), 0) {
                        tris.push(t);
                    }
                }
                objects.push(start..tris.len());
            }
            let flat = Flat::build(&tris, &objects);
            let mut hits = 0;
            for i in 0..300 {
                let mut p = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                let origin = (p() * 2.0 - 1.0) * 2.5;
                // Two rays in three aimed at a vertex, where neighbouring triangles may tie.
                let target = if i % 3 == 0 {
                    p() * 2.0 - 1.0
                } else {
                    tris[i * 7 % tris.len()].v[i % 3]
                };
                let ray = Ray::new(origin, target - origin);
                let t_max = if i % 4 == 0 { 1.5 } else { f32::INFINITY };
                let mut want: Option<Hit> = None;
                for (k, t) in tris.iter().enumerate() {
                    if let Some(h) = intersect_watertight(&ray, &t.v, t_max)
                        && want.is_none_or(|b| h.t < b.t)
                    {
                        want = Some(Hit {
                            t: h.t,
                            b: h.b,
                            triangle: k as u32,
                        });
                    }
                }
                hits += usize::from(want.is_some());
                for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
                    let context = format!("{n_objects} objects, ray {i} on {isa:?}");
                    let got = flat.intersect(isa, &ray, t_max);
                    assert_eq!(got, want, "{context}");
                    assert_eq!(
                        got.map(|h| h.t.to_bits()),
                        want.map(|h| h.t.to_bits()),
                        "{context}"
                    );
                    assert_eq!(flat.occluded(isa, &ray, t_max), want.is_some(), "{context}");
                }
            }
            assert!(hits > 100, "{n_objects} objects: only {hits} rays hit");
        }
    }
}
