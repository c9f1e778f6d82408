//! `RayTile`: up to [`TILE_RAYS`] rays from one origin as structure of arrays: their
//! directions and, when they share the watertight test's axes, their shears, lane by lane.
//! What a tile of camera rays is made as ([`crate::camera::RayGen::tile`]) and what the flat
//! list's tile kernels and the tile shading read. A full [`Ray`] is made on demand.

use glam::Vec3;

use super::Ray;

/// Most rays in one tile.
pub const TILE_RAYS: usize = 64;

/// Up to [`TILE_RAYS`] rays from one origin, lane by lane.
///
/// Ray `i` is `Ray::new(origin, dir(i))`, bit for bit ([`RayTile::ray`]); its shear
/// (`shear_lanes()[k][i]`, `k` = `sx`, `sy`, `sz`) is that ray's [`Ray::shear`] when every ray
/// shares one axis order ([`RayTile::axes`] is `Some`), and meaningless otherwise. Lanes from
/// `len` up to the next multiple of 16 repeat ray `len − 1`, so every lane of a packet of eight
/// is a ray of the tile (inside its box of shears).
#[derive(Clone, Debug)]
#[repr(C, align(32))]
pub struct RayTile {
    pub(crate) dir: [[f32; TILE_RAYS]; 3],
    pub(crate) shear: [[f32; TILE_RAYS]; 3],
    pub(crate) origin: Vec3,
    pub(crate) len: usize,
    pub(crate) axes: Option<[usize; 3]>,
    /// The box of the rays' shears: `[min sx, max sx, min sy, max sy, min sz, max sz]` (when
    /// `axes` is some).
    pub(crate) shear_box: [f32; 6],
}

impl Default for RayTile {
    /// No ray.
    fn default() -> RayTile {
        RayTile {
            dir: [[0.0; TILE_RAYS]; 3],
            shear: [[0.0; TILE_RAYS]; 3],
            origin: Vec3::ZERO,
            len: 0,
            axes: None,
            shear_box: [0.0; 6],
        }
    }
}

impl RayTile {
    /// A tile of `rays` (at most [`TILE_RAYS`]), which must share their origin.
    pub fn from_rays(rays: &[Ray]) -> RayTile {
        assert!(
            rays.len() <= TILE_RAYS,
            "a tile holds at most {TILE_RAYS} rays"
        );
        let mut tile = RayTile::default();
        let Some(first) = rays.first() else {
            return tile;
        };
        assert!(
            rays.iter().all(|r| r.origin == first.origin),
            "the rays of a tile share their origin"
        );
        tile.origin = first.origin;
        tile.len = rays.len();
        let axes = first.axes();
        let common = rays.iter().all(|r| r.axes() == axes);
        tile.axes = common.then_some(axes);
        let mut b = [
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for (i, r) in rays.iter().enumerate() {
            let s = r.shear();
            for (k, (d, sh)) in tile.dir.iter_mut().zip(&mut tile.shear).enumerate() {
                d[i] = r.dir[k];
                sh[i] = s[k];
                b[2 * k] = b[2 * k].min(s[k]);
                b[2 * k + 1] = b[2 * k + 1].max(s[k]);
            }
        }
        tile.shear_box.copy_from_slice(&b);
        tile.pad();
        tile
    }

    /// Repeats ray `len − 1` in the lanes up to the next multiple of 16 (the widest lanes).
    pub(crate) fn pad(&mut self) {
        let n = self.len;
        if n == 0 {
            return;
        }
        for row in self.dir.iter_mut().chain(self.shear.iter_mut()) {
            let last = row[n - 1];
            row[n..n.next_multiple_of(16)].fill(last);
        }
    }

    /// How many rays the tile holds.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the tile holds no ray.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The rays' common origin.
    #[inline]
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// Ray `i`'s direction.
    #[inline]
    pub fn dir(&self, i: usize) -> Vec3 {
        debug_assert!(i < self.len);
        Vec3::new(self.dir[0][i], self.dir[1][i], self.dir[2][i])
    }

    /// The directions lane by lane, `[x, y, z][i]` (32-byte aligned; lanes from `len()` on
    /// are meaningless).
    #[inline]
    pub fn dir_lanes(&self) -> &[[f32; TILE_RAYS]; 3] {
        &self.dir
    }

    /// Ray `i`, bit for bit the ray the tile was made of.
    #[inline]
    pub fn ray(&self, i: usize) -> Ray {
        Ray::new(self.origin, self.dir(i))
    }

    /// The axis order ([`Ray::axes`]) every ray of the tile shares, or `None` when they differ.
    #[inline]
    pub fn axes(&self) -> Option<[usize; 3]> {
        self.axes
    }

    /// The shears lane by lane, `[sx, sy, sz][i]` (meaningful when [`RayTile::axes`] is some).
    #[inline]
    pub fn shear_lanes(&self) -> &[[f32; TILE_RAYS]; 3] {
        &self.shear
    }

    /// `[min sx, max sx, min sy, max sy, min sz, max sz]` over the rays (when
    /// [`RayTile::axes`] is some).
    #[inline]
    pub fn shear_box(&self) -> [f32; 6] {
        self.shear_box
    }
}
