//! `Ray`, with the watertight test's per-ray axes and shear, and `RayFrame`: a triangle as
//! that test sees it from the ray.

use glam::Vec3;

use crate::simd::Lanes;

/// A ray `origin + t·dir`, with the per-ray constants of the watertight test precomputed.
///
/// `dir` need not be normalised: `t` is measured in units of `dir`.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Its direction (any non-zero length).
    pub dir: Vec3,
    /// Component-wise `1/dir` for slab tests (±∞ where a component is zero).
    pub inv_dir: Vec3,
    /// The axis along which `dir` is largest in magnitude, and the two others.
    pub(super) kx: usize,
    pub(super) ky: usize,
    pub(super) kz: usize,
    /// Shear that maps `dir` onto +z.
    pub(super) sx: f32,
    pub(super) sy: f32,
    pub(super) sz: f32,
}

impl Ray {
    /// A ray from `origin` along `dir`. `dir` must be finite and non-zero.
    pub fn new(origin: Vec3, dir: Vec3) -> Ray {
        Ray::with_inverse(origin, dir, dir.recip())
    }

    /// [`Ray::new`] with `inv_dir` already computed: it must be `dir.recip()` (each component
    /// `1.0 / dir[i]`), as a batch of rays computes it eight at a time. The same ray, bit for
    /// bit (the shear's `1/dir[kz]` is `inv_dir[kz]`).
    #[inline]
    pub fn with_inverse(origin: Vec3, dir: Vec3, inv_dir: Vec3) -> Ray {
        debug_assert!(origin.is_finite() && dir.is_finite(), "ray {origin} {dir}");
        debug_assert!(dir != Vec3::ZERO, "zero ray direction");
        debug_assert!(
            inv_dir.to_array().map(f32::to_bits) == dir.recip().to_array().map(f32::to_bits)
        );
        let d = dir.to_array();
        let (kz0, kz1) = main_axis::<f32>(d);
        let kz = if kz0 {
            0
        } else if kz1 {
            1
        } else {
            2
        };
        let [kx, ky, kz] = axes_of(kz, dir[kz] < 0.0);
        let [sx, sy, sz] = shear_of::<f32>(d, [kx, ky, kz], inv_dir[kz]);
        Ray {
            origin,
            dir,
            inv_dir,
            kx,
            ky,
            kz,
            sx,
            sy,
            sz,
        }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// A triangle seen from a ray, as the watertight test sees it: the vertices translated to the
/// ray's origin, their axes permuted so that the ray's largest component is the third
/// ([`Ray::axes`]), and sheared so that the ray runs along that axis. The ray passes through
/// the triangle where the origin of the (x, y) plane lies inside the sheared triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayFrame {
    /// Sheared x of each vertex: `(v − o)[kx] + sx·(v − o)[kz]`.
    pub x: [f32; 3],
    /// Sheared y of each vertex: `(v − o)[ky] + sy·(v − o)[kz]`.
    pub y: [f32; 3],
    /// Each vertex's offset along the ray's main axis, `(v − o)[kz]`, not yet scaled by `sz`
    /// into units of `t`.
    pub z: [f32; 3],
}

impl Ray {
    /// The axes `[kx, ky, kz]` of the watertight test: `kz` is the axis along which `dir` is
    /// largest in magnitude (the first one on ties), `kx` and `ky` follow it cyclically, swapped
    /// when `dir[kz] < 0` so that the triangle's winding is kept.
    pub fn axes(&self) -> [usize; 3] {
        [self.kx, self.ky, self.kz]
    }

    /// The shear constants `[sx, sy, sz]`: `sx = −dir[kx]/dir[kz]`, `sy = −dir[ky]/dir[kz]`,
    /// `sz = 1/dir[kz]`, each as rounded in `f32`.
    pub fn shear(&self) -> [f32; 3] {
        [self.sx, self.sy, self.sz]
    }

    /// The triangle `v` in this ray's frame.
    #[inline]
    pub fn frame(&self, v: &[Vec3; 3]) -> RayFrame {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = v[0] - self.origin;
        let b = v[1] - self.origin;
        let c = v[2] - self.origin;
        let (az, bz, cz) = (a[kz], b[kz], c[kz]);
        RayFrame {
            x: [
                a[kx] + self.sx * az,
                b[kx] + self.sx * bz,
                c[kx] + self.sx * cz,
            ],
            y: [
                a[ky] + self.sy * az,
                b[ky] + self.sy * bz,
                c[ky] + self.sy * cz,
            ],
            z: [az, bz, cz],
        }
    }
}

impl RayFrame {
    /// The three edge functions; `e[i]` is the (unnormalised) weight of vertex `i`, the signed
    /// doubled area of the sheared triangle formed by the other two vertices and the ray. When
    /// one rounds to exactly zero in `f32`, all three are recomputed in `f64`, where the products
    /// of `f32` values are exact, so that a ray exactly on an edge gets its sign right.
    #[inline]
    pub fn edge_functions(&self) -> [f32; 3] {
        let (x, y) = (self.x, self.y);
        let e = [
            x[1] * y[2] - y[1] * x[2],
            x[2] * y[0] - y[2] * x[0],
            x[0] * y[1] - y[0] * x[1],
        ];
        if e[0] != 0.0 && e[1] != 0.0 && e[2] != 0.0 {
            return e;
        }
        let (x, y) = (x.map(f64::from), y.map(f64::from));
        [
            (x[1] * y[2] - y[1] * x[2]) as f32,
            (x[2] * y[0] - y[2] * x[0]) as f32,
            (x[0] * y[1] - y[0] * x[1]) as f32,
        ]
    }
}

/// The watertight test's main axis `kz` of each lane's direction `d`: the axis along which it
/// is largest in magnitude, the first one on ties. As masks: the lanes where `kz` is 0, those
/// where it is 1 (else it is 2).
#[inline(always)]
pub(crate) fn main_axis<L: Lanes>(d: [L; 3]) -> (L::Mask, L::Mask) {
    let a = [d[0].abs(), d[1].abs(), d[2].abs()];
    let (xy, xz, yz) = (a[0].gt(a[1]), a[0].gt(a[2]), a[1].gt(a[2]));
    (L::and(xy, xz), L::andnot(xy, yz))
}

/// The axes `[kx, ky, kz]` for main axis `kz` ([`main_axis`]): `kx` and `ky` follow it
/// cyclically, swapped when the direction is `negative` along `kz`, so that a triangle's
/// winding is kept.
#[inline(always)]
pub(crate) fn axes_of(kz: usize, negative: bool) -> [usize; 3] {
    let kx = (kz + 1) % 3;
    let ky = (kx + 1) % 3;
    if negative { [ky, kx, kz] } else { [kx, ky, kz] }
}

/// The shear `[sx, sy, sz]` that maps each lane's direction `d` (axes `[kx, ky, kz]`) onto
/// its `kz` axis: `sz = 1/d[kz]` (given: `inv_kz`), `sx = −d[kx]·sz`, `sy = −d[ky]·sz`.
#[inline(always)]
pub(crate) fn shear_of<L: Lanes>(d: [L; 3], [kx, ky, _]: [usize; 3], inv_kz: L) -> [L; 3] {
    [d[kx].neg().mul(inv_kz), d[ky].neg().mul(inv_kz), inv_kz]
}
