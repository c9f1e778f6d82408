//! Acceleration structure: which triangles a ray needs to be tested against.
//!
//! Two kinds, chosen by triangle count ([`AccelKind::for_triangles`]):
//!
//! - [`AccelKind::Flat`]: the scene's objects (the Cornell room, each block, a mesh), each with
//!   a bounding box; a ray is tested against the triangles of every object whose box it meets.
//!   Fastest for a few dozen triangles.
//! - [`AccelKind::Bvh`]: a bounding volume hierarchy (`bvh.rs`).
//!
//! Both answer exactly as testing every triangle would: the closest hit is the one with the
//! smallest `t`, ties going to the lowest triangle index, and a shadow ray is occluded when any
//! triangle has a hit before `t_max`. So a frame is byte-identical whichever is used (see
//! [`crate::accel::bvh`] for how culling keeps to that).
//!
//! Both test triangles four or eight at a time ([`tri4`]) on the widest SIMD path the CPU has
//! ([`Isa::detect`]); every path gives the same hits, bit for bit.

mod box8;
mod bvh;
mod flat;
mod hit;
pub mod shadow;
pub mod tri4;

use std::ops::Range;
use std::time::{Duration, Instant};

use crate::geometry::{Ray, RayTile, Triangle};
use bvh::Bvh;
use flat::Flat;

pub use crate::geometry::TILE_RAYS;
pub use crate::simd::Isa;
pub use bvh::MAX_DEPTH;
pub(crate) use bvh::prefetch_value;
pub use flat::TileCache;
pub use hit::{CULL_SLACK, Hit, cull_bound, shrunk_t_max};

/// Scenes with at least this many triangles get a BVH; smaller ones the flat object list.
///
/// Measured with `cargo run --release --example accel_bench` (one thread's time, camera rays):
/// the Cornell box (30 triangles, 7 objects) traces about twice as fast through the flat list
/// (22-27 against 11 M rays/s; the instruction counts are equal, the BVH's branches are not);
/// the room with a 20·k² icosphere crosses over between 30 triangles (flat 22, BVH 11) and 90
/// (flat 6-7, BVH 11), near 55 by linear interpolation of the flat list's cost.
pub const BVH_THRESHOLD: usize = 64;

/// Which acceleration structure a scene uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AccelKind {
    /// The scene's objects with their bounding boxes, each tested triangle by triangle.
    Flat,
    /// A bounding volume hierarchy over all triangles.
    Bvh,
}

impl AccelKind {
    /// The faster kind for a scene of `triangles` triangles (see [`BVH_THRESHOLD`]).
    pub fn for_triangles(triangles: usize) -> AccelKind {
        if triangles >= BVH_THRESHOLD {
            AccelKind::Bvh
        } else {
            AccelKind::Flat
        }
    }

    /// A short lower-case name ("flat", "bvh").
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Flat => "flat",
            AccelKind::Bvh => "bvh",
        }
    }
}

/// What an acceleration structure holds and what it cost to build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelStats {
    /// Which kind it is.
    pub kind: AccelKind,
    /// Triangles it holds.
    pub triangles: usize,
    /// Boxes: the nodes of the BVH's binary SAH tree (traversal reads it collapsed into
    /// wide nodes of up to eight children, `Bvh::wide_nodes`), or the flat list's objects.
    pub nodes: usize,
    /// Levels of boxes above the triangles: the binary tree's (1 for the flat list, 0 when
    /// empty).
    pub depth: u32,
    /// Wall-clock build time.
    pub build: Duration,
}

/// A scene's acceleration structure.
#[derive(Clone)]
pub struct Accel {
    structure: Structure,
    stats: AccelStats,
    /// The SIMD path queries take: always one the CPU has (checked where it is set).
    isa: Isa,
}

/// Shows the structure but not its build time, so that two builds of one scene print the same.
impl std::fmt::Debug for Accel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Accel")
            .field("structure", &self.structure)
            .field("isa", &self.isa)
            .finish_non_exhaustive()
    }
}

#[derive(Clone, Debug)]
enum Structure {
    Flat(Flat),
    Bvh(Bvh),
}

/// Where a structure reads the triangles' vertices: a scene's list of [`Triangle`]s, or a big
/// model's indexed mesh, which keeps no such list.
pub trait Vertices: Sync {
    /// The number of triangles.
    fn count(&self) -> usize;
    /// Triangle `i`'s vertices.
    fn vertices(&self, i: usize) -> [glam::Vec3; 3];
}

impl Vertices for [Triangle] {
    #[inline]
    fn count(&self) -> usize {
        self.len()
    }

    #[inline]
    fn vertices(&self, i: usize) -> [glam::Vec3; 3] {
        self[i].v
    }
}

impl Default for Accel {
    fn default() -> Accel {
        Accel::build_kind(&[], &[], AccelKind::Flat)
    }
}

impl Accel {
    /// Builds the faster kind for the triangle count ([`AccelKind::for_triangles`]).
    pub fn build(triangles: &[Triangle], objects: &[Range<usize>]) -> Accel {
        Accel::build_kind(
            triangles,
            objects,
            AccelKind::for_triangles(triangles.len()),
        )
    }

    /// Builds a structure of the given kind over `triangles`; `objects` are the flat list's
    /// groups (contiguous ranges of `triangles`).
    pub fn build_kind(triangles: &[Triangle], objects: &[Range<usize>], kind: AccelKind) -> Accel {
        let start = Instant::now();
        let structure = match kind {
            AccelKind::Flat => Structure::Flat(Flat::build(triangles, objects)),
            AccelKind::Bvh => Structure::Bvh(Bvh::build(triangles)),
        };
        let build = start.elapsed();
        let (nodes, depth) = match &structure {
            Structure::Flat(flat) => (flat.objects(), u32::from(flat.objects() > 0)),
            Structure::Bvh(bvh) => (bvh.nodes(), bvh.depth()),
        };
        Accel {
            structure,
            stats: AccelStats {
                kind,
                triangles: triangles.len(),
                nodes,
                depth,
                build,
            },
            isa: Isa::detect(),
        }
    }

    /// The SIMD path its queries take (by default the widest the CPU has).
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// A BVH over the triangles of a big model's `source`, built fast ([`Bvh::build_fast`]).
    pub(crate) fn build_fast(source: &(impl Vertices + ?Sized)) -> Accel {
        let start = Instant::now();
        let bvh = Bvh::build_fast(source);
        let build = start.elapsed();
        Accel {
            stats: AccelStats {
                kind: AccelKind::Bvh,
                triangles: source.count(),
                nodes: bvh.nodes(),
                depth: bvh.depth(),
                build,
            },
            structure: Structure::Bvh(bvh),
            isa: Isa::detect(),
        }
    }

    /// The same structure, queried on path `isa`; `None` if this CPU does not have it. Every
    /// path gives the same hits.
    pub fn with_isa(mut self, isa: Isa) -> Option<Accel> {
        self.isa = isa.available().then_some(isa)?;
        Some(self)
    }

    /// Its kind.
    pub fn kind(&self) -> AccelKind {
        self.stats.kind
    }

    /// What it holds and what it cost to build.
    pub fn stats(&self) -> AccelStats {
        self.stats
    }

    /// The closest hit with `t < t_max` (ties go to the lowest triangle index), or `None`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        match &self.structure {
            Structure::Flat(flat) => flat.intersect(self.isa, ray, t_max),
            Structure::Bvh(bvh) => bvh.intersect_isa(self.isa, ray, t_max),
        }
    }

    /// The closest hits of `tile`'s rays into `hits` (as many), each as [`Accel::intersect`]
    /// gives it. The flat list tests a tile whose rays share their axes (a camera's) eight
    /// rays at a time, keeping what tiles of one camera share in `cache`.
    pub fn intersect_tile(
        &self,
        tile: &RayTile,
        t_max: f32,
        hits: &mut [Option<Hit>],
        cache: &mut TileCache,
    ) {
        self.intersect_tile_with(tile, t_max, hits, cache, |_| {});
    }

    /// [`Accel::intersect_tile`], the hits as lanes: ray `i`'s is lane `i % 8` of
    /// `best[i / 8]` (lanes past the tile's rays are not to be read). The flat list leaves
    /// them there as its kernel makes them; the BVH is asked for [`Hit`]s, which are then put
    /// in lanes. The same hits either way.
    pub fn intersect_tile_best(
        &self,
        tile: &RayTile,
        t_max: f32,
        best: &mut [tri4::Best8; TILE_RAYS / 8],
        cache: &mut TileCache,
    ) {
        if let Structure::Flat(flat) = &self.structure {
            flat.intersect_tile_best(self.isa, tile, t_max, best, cache);
            return;
        }
        let mut hits = [None; TILE_RAYS];
        let hits = &mut hits[..tile.len()];
        self.intersect_tile(tile, t_max, hits, cache);
        for (i, &h) in hits.iter().enumerate() {
            best[i / 8].set(i % 8, h);
        }
    }

    /// [`Accel::intersect_tile`], calling `found(triangle)` as soon as a ray's hit is known
    /// where the structure traces ray by ray (the BVH), so that a caller can prefetch what it
    /// will read for that hit while the tile's other rays are traced.
    pub(crate) fn intersect_tile_with(
        &self,
        tile: &RayTile,
        t_max: f32,
        hits: &mut [Option<Hit>],
        cache: &mut TileCache,
        found: impl Fn(u32),
    ) {
        match &self.structure {
            Structure::Flat(flat) => flat.intersect_tile(self.isa, tile, t_max, hits, cache),
            Structure::Bvh(bvh) => bvh.intersect_tile(self.isa, tile, t_max, hits, found),
        }
    }

    /// [`Accel::occluded`] for each of `rays`, into `out` (as many).
    pub fn occluded_each(&self, rays: &[Ray], t_max: f32, out: &mut [bool]) {
        match &self.structure {
            Structure::Flat(flat) => flat.occluded_each(self.isa, rays, t_max, out),
            Structure::Bvh(bvh) => bvh.occluded_each(self.isa, rays, t_max, out),
        }
    }

    /// Whether any triangle has a hit with `t < t_max` (stops at the first).
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        match &self.structure {
            Structure::Flat(flat) => flat.occluded(self.isa, ray, t_max),
            Structure::Bvh(bvh) => bvh.occluded_isa(self.isa, ray, t_max),
        }
    }
}
