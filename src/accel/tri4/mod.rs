//! Triangles four at a time: vertices as structure of arrays ([`Tri4`]), and the watertight
//! test of one ray against a block or two ([`block_hits`]), or of one triangle against a
//! tile's rays ([`rays`]), on any lanes.
//!
//! # Bit-identical to the scalar test, by construction
//!
//! Both run [`crate::geometry::watertight_lanes`], of which the scalar test
//! ([`crate::geometry::intersect_watertight`]) is the one-lane form: so a lane the kernel accepts carries the
//! scalar test's own `t` and barycentrics, bit for bit, and a lane it rejects is one the
//! scalar test rejects. The one exception is a lane whose edge function rounds to exactly 0:
//! the scalar test redoes its edges in `f64`, so the kernel hands that lane back (`redo`) and
//! the search runs [`crate::geometry::intersect_watertight`] on it.

use glam::Vec3;

use super::hit::Hit;
use crate::geometry::{Ray, RayTile, TILE_RAYS, watertight_lanes};
use crate::simd::{Isa, Kernel, Lanes, Path};

mod search;
#[cfg(target_arch = "x86_64")]
pub mod shadow;

pub(crate) use search::{Closest, blocks_closest, blocks_occluded};

/// Triangles per [`Tri4`] block.
pub const LANES: usize = 4;

/// Four triangles' vertices, structure of arrays: `v[vertex][axis][lane]`. Unused lanes hold NaN,
/// which no test accepts (the determinant is NaN).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Tri4 {
    v: [[[f32; LANES]; 3]; 3],
}

/// Equal when every coordinate has the same bits (so the NaN padding compares equal).
impl PartialEq for Tri4 {
    fn eq(&self, o: &Tri4) -> bool {
        self.v
            .as_flattened()
            .as_flattened()
            .iter()
            .map(|x| x.to_bits())
            .eq(o
                .v
                .as_flattened()
                .as_flattened()
                .iter()
                .map(|x| x.to_bits()))
    }
}

impl Tri4 {
    /// A block with no triangle.
    pub const EMPTY: Tri4 = Tri4 {
        v: [[[f32::NAN; LANES]; 3]; 3],
    };

    /// A block of up to [`LANES`] triangles, in order.
    pub fn new(triangles: &[[Vec3; 3]]) -> Tri4 {
        assert!(triangles.len() <= LANES, "a Tri4 holds at most 4 triangles");
        let mut block = Tri4::EMPTY;
        for (lane, t) in triangles.iter().enumerate() {
            for (vertex, p) in t.iter().enumerate() {
                for axis in 0..3 {
                    block.v[vertex][axis][lane] = p[axis];
                }
            }
        }
        block
    }

    /// Blocks holding `triangles` in order, the last one padded.
    pub fn pack(triangles: impl ExactSizeIterator<Item = [Vec3; 3]>) -> Vec<Tri4> {
        let mut blocks = Vec::with_capacity(triangles.len().div_ceil(LANES));
        let mut chunk = Vec::with_capacity(LANES);
        for t in triangles {
            chunk.push(t);
            if chunk.len() == LANES {
                blocks.push(Tri4::new(&chunk));
                chunk.clear();
            }
        }
        if !chunk.is_empty() {
            blocks.push(Tri4::new(&chunk));
        }
        blocks
    }

    /// The vertices in `lane` (NaN for an unused lane).
    #[inline]
    pub fn vertices(&self, lane: usize) -> [Vec3; 3] {
        let v = &self.v;
        [0, 1, 2].map(|i| Vec3::new(v[i][0][lane], v[i][1][lane], v[i][2][lane]))
    }
}

/// A ray's constants as the kernels read them: the origin and each vertex axis in the ray's
/// permuted order (`kx`, `ky`, `kz`), and the shear.
#[derive(Clone, Copy, Debug)]
pub struct RayLanes {
    axes: [usize; 3],
    origin: [f32; 3],
    shear: [f32; 3],
}

impl RayLanes {
    /// The constants of `ray`.
    #[inline]
    pub fn new(ray: &Ray) -> RayLanes {
        let axes = ray.axes();
        RayLanes {
            axes,
            origin: axes.map(|a| ray.origin[a]),
            shear: ray.shear(),
        }
    }
}

/// What a kernel found in one or two blocks (lanes 4-7 from the second).
#[derive(Clone, Copy, Debug)]
pub struct Hits {
    /// Bit `i` set: lane `i` is hit, at `t[i]` with barycentrics `b[..][i]`, exactly as
    /// [`crate::geometry::intersect_watertight`] computes them.
    pub mask: u32,
    /// Bit `i` set: lane `i`'s edge function rounded to 0, so the scalar test redoes it in
    /// `f64`; the kernel says nothing else about it.
    pub redo: u32,
    /// Each hit lane's `t` (meaningless elsewhere).
    pub t: [f32; 2 * LANES],
    /// Each hit lane's barycentric weights of `v0`, `v1`, `v2` (meaningless elsewhere).
    pub b: [[f32; 2 * LANES]; 3],
}

impl Hits {
    /// No lane hit, none to redo.
    pub const NONE: Hits = Hits {
        mask: 0,
        redo: 0,
        t: [0.0; 2 * LANES],
        b: [[0.0; 2 * LANES]; 3],
    };

    /// The masks a kernel returned and the lanes it wrote.
    fn of((mask, redo): (u32, u32), lanes: &LaneHits) -> Hits {
        Hits {
            mask,
            redo,
            t: lanes.t,
            b: lanes.b,
        }
    }
}

/// Where a kernel writes its hit lanes' `t` and barycentrics (lanes 4-7 from a second block):
/// written only when some lane is hit, meaningful only in hit lanes. The masks themselves
/// are returned (in registers), so that a traversal that inlines the kernel tests them
/// without a round trip through memory, and an any-hit query never reads this at all.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneHits {
    pub t: [f32; 2 * LANES],
    pub b: [[f32; 2 * LANES]; 3],
}

impl LaneHits {
    /// Nothing written yet.
    pub const ZERO: LaneHits = LaneHits {
        t: [0.0; 2 * LANES],
        b: [[0.0; 2 * LANES]; 3],
    };
}

/// Each of eight rays' closest hit so far: `t` (∞ for none yet), barycentrics and triangle.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Best8 {
    t: [f32; 2 * LANES],
    b: [[f32; 2 * LANES]; 3],
    id: [u32; 2 * LANES],
}

impl Best8 {
    /// No hit yet.
    pub const NONE: Best8 = Best8 {
        t: [f32::INFINITY; 2 * LANES],
        b: [[0.0; 2 * LANES]; 3],
        id: [u32::MAX; 2 * LANES],
    };

    /// Makes lane `l`'s closest hit `hit` (none: no hit).
    #[inline]
    pub fn set(&mut self, l: usize, hit: Option<Hit>) {
        match hit {
            Some(h) => {
                self.t[l] = h.t;
                for (row, w) in self.b.iter_mut().zip(h.b) {
                    row[l] = w;
                }
                self.id[l] = h.triangle;
            }
            None => {
                self.t[l] = f32::INFINITY;
                for row in &mut self.b {
                    row[l] = 0.0;
                }
                self.id[l] = u32::MAX;
            }
        }
    }

    /// Each lane's triangle, `u32::MAX` for none.
    #[inline]
    pub fn ids(&self) -> &[u32; 2 * LANES] {
        &self.id
    }

    /// Each lane's barycentric weights, by vertex (0 where there is no hit).
    #[inline]
    pub fn barycentrics(&self) -> &[[f32; 2 * LANES]; 3] {
        &self.b
    }

    /// Lane `l`'s closest hit.
    #[inline]
    pub fn hit(&self, l: usize) -> Option<Hit> {
        (self.id[l] != u32::MAX).then(|| Hit {
            t: self.t[l],
            b: [self.b[0][l], self.b[1][l], self.b[2][l]],
            triangle: self.id[l],
        })
    }
}

/// The closest hits so far of a tile's rays, lane by lane (`t` ∞ and id `u32::MAX`'s bits for
/// none yet): what [`rays`] folds each triangle's hits into, as wide as the path goes.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct BestTile {
    t: [f32; TILE_RAYS],
    b: [[f32; TILE_RAYS]; 3],
    /// Each lane's triangle, as the bits of an `f32` (so that the fold moves it as it moves
    /// the rest).
    id: [f32; TILE_RAYS],
}

impl BestTile {
    /// No hit yet.
    pub const NONE: BestTile = BestTile {
        t: [f32::INFINITY; TILE_RAYS],
        b: [[0.0; TILE_RAYS]; 3],
        id: [f32::from_bits(u32::MAX); TILE_RAYS],
    };

    /// Takes `(t, b)` on triangle `id` for ray `l` if it is nearer than the ray's best.
    /// Triangles are offered in increasing order, so a tie keeps the lower index.
    #[inline(always)]
    pub fn offer(&mut self, l: usize, t: f32, b: [f32; 3], id: u32) {
        self.fold::<f32>(l, t < self.t[l], t, b, id);
    }

    /// The fold into the nearest hit, `L::N` rays from `at` at once: the lanes in `hit` whose
    /// `t` is below their best so far take `t`, `b` and triangle `id`.
    #[inline(always)]
    fn fold<L: Lanes>(&mut self, at: usize, hit: L::Mask, t: L, b: [L; 3], id: u32) {
        let best_t = L::load(&self.t[at..]);
        let take = L::and(hit, t.lt(best_t));
        L::select(take, best_t, t).store_whole(&mut self.t[at..]);
        for (k, w) in b.into_iter().enumerate() {
            let row = &mut self.b[k][at..];
            L::select(take, L::load(row), w).store_whole(row);
        }
        let ids = L::load(&self.id[at..]);
        L::select(take, ids, L::splat(f32::from_bits(id))).store_whole(&mut self.id[at..]);
    }

    /// Makes every ray have no hit yet. (All of them, whatever the tile's size: stores of a
    /// known length, not the calls to `memset` that a tile's own length took.)
    #[inline(always)]
    pub fn clear(&mut self) {
        self.t = [f32::INFINITY; TILE_RAYS];
        self.b = [[0.0; TILE_RAYS]; 3];
        self.id = [f32::from_bits(u32::MAX); TILE_RAYS];
    }

    /// Rays `8·p..8·p + 8` into `out`.
    #[inline(always)]
    pub fn packet_into(&self, p: usize, out: &mut Best8) {
        let at = 8 * p..8 * p + 8;
        out.t.copy_from_slice(&self.t[at.clone()]);
        for (row, b) in out.b.iter_mut().zip(&self.b) {
            row.copy_from_slice(&b[at.clone()]);
        }
        let ids: &[f32; 8] = self.id[at].try_into().expect("eight lanes");
        out.id = ids.map(f32::to_bits);
    }
}

impl Default for BestTile {
    fn default() -> BestTile {
        BestTile::NONE
    }
}

/// The hits of `r` in `blocks` (one or two: lanes 4-7 from the second), `L::N` lanes at a
/// time: `(mask, redo)` as in [`Hits`], and, for lanes some of which are hit, their `t` and
/// barycentrics into `out` (written only then, and meaningful only in hit lanes). The masks
/// are returned in registers, so that a traversal that inlines this tests them without a round
/// trip through memory, and an any-hit query, which never reads `out`, drops the stores.
#[inline(always)]
pub(crate) fn block_hits<L: Lanes>(
    blocks: &[Tri4],
    r: &RayLanes,
    t_max: f32,
    out: &mut LaneHits,
) -> (u32, u32) {
    let origin = splat3(&r.origin);
    let shear = splat3(&r.shear);
    let (mut mask, mut redo) = (0, 0);
    for at in (0..LANES * blocks.len()).step_by(L::N) {
        let rel = [
            vertex(blocks, at, 0, r.axes, origin),
            vertex(blocks, at, 1, r.axes, origin),
            vertex(blocks, at, 2, r.axes, origin),
        ];
        let f = watertight_lanes(rel, shear, L::splat(t_max), false);
        if f.mask != 0 {
            f.t.store(&mut out.t[at..]);
            for (k, b) in f.b.into_iter().enumerate() {
                b.store(&mut out.b[k][at..]);
            }
        }
        mask |= f.mask << at;
        redo |= f.redo << at;
    }
    (mask, redo)
}

/// Vertex `i` of `blocks`' lanes `at..at + L::N`, relative to `origin`, in the axis order
/// `[kx, ky, kz]` (the kernels' helpers are functions, not closures, so that they are sure to
/// inline: code left out of line would lose the path's target features).
#[inline(always)]
fn vertex<L: Lanes>(
    blocks: &[Tri4],
    at: usize,
    i: usize,
    [kx, ky, kz]: [usize; 3],
    origin: [L; 3],
) -> [L; 3] {
    let v = |axis: usize| L::load_fours(|k| &blocks[at / LANES + k].v[i][axis], at);
    [
        v(kx).sub(origin[0]),
        v(ky).sub(origin[1]),
        v(kz).sub(origin[2]),
    ]
}

/// Each of `v` in every lane.
#[inline(always)]
fn splat3<L: Lanes>(v: &[f32; 3]) -> [L; 3] {
    [L::splat(v[0]), L::splat(v[1]), L::splat(v[2])]
}

/// One triangle (`rel`: its vertices relative to the rays' common origin, in their axis
/// order) against the rays of `tile` (which share their axes) `L::N` at a time, folded into
/// `best` (lanes that hit it nearer than their best so far take it, as `id`). Returns the rays
/// the caller must test with the scalar test (its `f64` redo); bits from `tile.len()` on are
/// meaningless, as are `best`'s lanes from there.
///
/// `sure`: the caller has proven that every ray of the tile that passes the test's sign
/// and range checks also passes its error-bound checks (`flat/tile.rs`), which are then
/// skipped.
#[inline(always)]
pub(crate) fn rays<L: Lanes>(
    rel: &[[f32; 3]; 3],
    tile: &RayTile,
    t_max: f32,
    id: u32,
    sure: bool,
    best: &mut BestTile,
) -> u64 {
    let rel = [splat3(&rel[0]), splat3(&rel[1]), splat3(&rel[2])];
    let t_max = L::splat(t_max);
    let mut redo = 0;
    // The tile's lanes are padded to a multiple of 16 with its last ray.
    for at in (0..tile.len()).step_by(L::N) {
        let s = &tile.shear;
        let shear = [
            L::load(&s[0][at..]),
            L::load(&s[1][at..]),
            L::load(&s[2][at..]),
        ];
        let f = watertight_lanes(rel, shear, t_max, sure);
        redo |= u64::from(f.redo) << at;
        if f.mask != 0 {
            best.fold(at, f.accepted, f.t, f.b, id);
        }
    }
    redo
}

/// The hits of `ray` in one block on path `isa` (for tests and tools; traversals call
/// [`block_hits`] on their own path). `isa` must be available.
pub fn hits(isa: Isa, block: &Tri4, ray: &Ray, t_max: f32) -> Hits {
    isa.run(Blocks(std::slice::from_ref(block), ray, t_max))
}

/// The hits of `ray` in two blocks on path `isa` (lanes 4-7 from `b`). `isa` must be available.
pub fn hits2(isa: Isa, a: &Tri4, b: &Tri4, ray: &Ray, t_max: f32) -> Hits {
    isa.run(Blocks(&[*a, *b], ray, t_max))
}

/// [`hits`] and [`hits2`] as a kernel.
struct Blocks<'a>(&'a [Tri4], &'a Ray, f32);

impl Kernel for Blocks<'_> {
    type Output = Hits;
    #[inline(always)]
    fn run<P: Path>(self) -> Hits {
        let Blocks(blocks, ray, t_max) = self;
        let r = RayLanes::new(ray);
        let mut out = LaneHits::ZERO;
        let masks = if blocks.len() == 2 {
            block_hits::<P::Eight>(blocks, &r, t_max, &mut out)
        } else {
            block_hits::<P::Four>(blocks, &r, t_max, &mut out)
        };
        Hits::of(masks, &out)
    }
}
