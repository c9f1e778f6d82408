//! The pinhole camera: where primary rays are shot from, and how the camera moves.

use glam::{Mat3, Vec3};

use crate::geometry::{Ray, RayTile, TILE_RAYS, axes_of, main_axis, shear_of};
use crate::simd::{Isa, Kernel, Lanes, Path};

/// A pinhole camera at `position`, turned by `yaw` about its frame's down axis and tilted by
/// `pitch` about its right axis. In the seed's frame (the identity: x right, y down, z forward,
/// the Cornell box's axes) yaw = pitch = 0 looks along +z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// Rotation about the frame's down axis in radians; positive turns to the right.
    pub yaw: f32,
    /// Rotation about the camera's right axis in radians; positive looks down.
    pub pitch: f32,
    /// The frame yaw and pitch turn within: its columns are the camera's right, down and
    /// forward axes at yaw = pitch = 0, orthonormal with right × down = forward. The identity
    /// for the seed's box; [`Camera::look_at`] makes one whose down axis is the scene's −up.
    pub frame: Mat3,
    /// Vertical field of view in radians, in (0, π); `None` for the seed's rule (focal length
    /// = the shorter image side, 2·atan(½) ≈ 53.13° across it).
    pub fov: Option<f32>,
}

impl Default for Camera {
    /// The seed's camera: at (0, 0, −3) looking along +z.
    fn default() -> Camera {
        Camera {
            position: Vec3::new(0.0, 0.0, -3.0),
            yaw: 0.0,
            pitch: 0.0,
            frame: Mat3::IDENTITY,
            fov: None,
        }
    }
}

/// Smallest and largest vertical field of view accepted, in degrees (`--fov`, file cameras).
pub const FOV_RANGE_DEGREES: (f32, f32) = (1.0, 170.0);

impl Camera {
    /// A camera at `from` looking at `at`, `up` pointing up on screen (yaw 0; the pitch says
    /// how far it looks up or down), with vertical field of view `fov` in radians. Looking
    /// straight along `up`, the screen's up is picked perpendicular to it. `None` when `from`
    /// and `at` are the same point, `up` is zero or any value is not finite.
    pub fn look_at(from: Vec3, at: Vec3, up: Vec3, fov: Option<f32>) -> Option<Camera> {
        let d = (at - from).normalize_or_zero();
        let up = up.normalize_or_zero();
        if d == Vec3::ZERO || up == Vec3::ZERO || !from.is_finite() {
            return None;
        }
        let down = -up;
        // Forward at pitch 0: the view direction flattened onto the plane across `up`.
        let mut flat = (d - up * d.dot(up)).normalize_or_zero();
        if flat == Vec3::ZERO {
            flat = up.any_orthonormal_vector();
        }
        let right = down.cross(flat);
        let pitch = libm::asinf(d.dot(down).clamp(-1.0, 1.0));
        Some(Camera {
            position: from,
            yaw: 0.0,
            pitch,
            frame: Mat3::from_cols(right, down, flat),
            fov,
        })
    }

    /// The camera's rotation: its frame times the seed's yaw R = [[cos θ, 0, sin θ], [0, 1, 0],
    /// [−sin θ, 0, cos θ]] times the pitch (the identity frame is not multiplied: the seed's
    /// rotations stay bit for bit).
    pub fn rotation(&self) -> Mat3 {
        let (s, c) = (libm::sinf(self.yaw), libm::cosf(self.yaw));
        let mut r = Mat3::from_cols(Vec3::new(c, 0.0, -s), Vec3::Y, Vec3::new(s, 0.0, c));
        if self.pitch != 0.0 {
            let (s, c) = (libm::sinf(self.pitch), libm::cosf(self.pitch));
            r *= Mat3::from_cols(Vec3::X, Vec3::new(0.0, c, -s), Vec3::new(0.0, s, c));
        }
        if self.frame != Mat3::IDENTITY {
            r = self.frame * r;
        }
        r
    }

    /// Every value that decides the camera's rays, as bits: equal keys, equal rays.
    pub fn key(&self) -> [u32; 15] {
        let mut k = [0; 15];
        k[..3].copy_from_slice(&self.position.to_array().map(f32::to_bits));
        k[3] = self.yaw.to_bits();
        k[4] = self.pitch.to_bits();
        k[5..14].copy_from_slice(&self.frame.to_cols_array().map(f32::to_bits));
        // No field of view is a NaN's bits: no angle has them.
        k[14] = self.fov.unwrap_or(f32::NAN).to_bits();
        k
    }

    /// The focal length in pixels for an image `width`×`height`.
    pub fn focal(&self, width: u32, height: u32) -> f32 {
        match self.fov {
            None => width.min(height).max(1) as f32,
            Some(fov) => height.max(1) as f32 * 0.5 / libm::tanf(fov * 0.5),
        }
    }

    /// The camera's right axis in world space (+x at yaw 0).
    pub fn right(&self) -> Vec3 {
        self.rotation().x_axis
    }

    /// The camera's down axis in world space (+y at pitch 0).
    pub fn down(&self) -> Vec3 {
        self.rotation().y_axis
    }

    /// The camera's forward axis in world space (+z at yaw 0).
    pub fn forward(&self) -> Vec3 {
        self.rotation().z_axis
    }

    /// Maps an offset in camera axes (right, down, forward) to world space.
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        self.rotation() * local
    }

    /// Per-frame ray generator for a `width`×`height` image.
    pub fn rays(&self, width: u32, height: u32) -> RayGen {
        RayGen {
            origin: self.position,
            rotation: self.rotation(),
            half_w: width as f32 * 0.5,
            half_h: height as f32 * 0.5,
            focal: self.focal(width, height),
        }
    }
}

/// Generates primary rays for one frame: by the seed's rule the focal length is the shorter
/// image side in pixels, so the box's front opening fits any aspect ratio (2·atan(½) ≈ 53.13°
/// across the shorter side); a camera with a field of view sets it from the image's height.
#[derive(Clone, Copy, Debug)]
pub struct RayGen {
    origin: Vec3,
    rotation: Mat3,
    half_w: f32,
    half_h: f32,
    focal: f32,
}

impl RayGen {
    /// The ray through image position (`px`, `py`) in pixels; the centre of pixel (x, y) is
    /// (x + ½, y + ½). The direction is normalised.
    #[inline]
    pub fn ray(&self, px: f32, py: f32) -> Ray {
        let d = Vec3::new(px - self.half_w, py - self.half_h, self.focal);
        Ray::new(self.origin, (self.rotation * d).normalize())
    }
}

impl RayGen {
    /// Makes `out` the tile of rays through the centres of pixels `x0..x0 + cols` of rows
    /// `y0..y0 + rows` (`cols`, `rows` ≤ 8), ray `r·cols + c` through pixel (x0 + c, y0 + r):
    /// each is `self.ray(x + 0.5, y + 0.5)` bit for bit, with its shear when the tile's rays
    /// share their axes. Made as many rays at a time as path `isa` (which must be available)
    /// has lanes, up to eight: the same operations in the same order, so the same rounding.
    pub fn tile(
        &self,
        isa: Isa,
        x0: usize,
        y0: usize,
        cols: usize,
        rows: usize,
        out: &mut RayTile,
    ) {
        assert!(
            (1..=8).contains(&cols) && (1..=8).contains(&rows),
            "a tile is 1 to 8 pixels on a side"
        );
        // Columns past the tile's repeat its last one, so that every lane is a ray of the tile.
        let xs = std::array::from_fn(|c| (x0 + c.min(cols - 1)) as f32 + 0.5);
        isa.run(Tile(self, cols, rows, Positions::Centres(xs, y0), out));
    }

    /// Makes `out` the tile of `cols`×`rows` rays (`cols`, `rows` ≤ 8) through image positions
    /// `(px[i], py[i])` in pixels, ray `r·cols + c` being `i = r·cols + c`: each is
    /// `self.ray(px[i], py[i])` bit for bit (an anti-aliased frame's jittered rays), made as
    /// [`RayGen::tile`] makes them. Entries from `rows·cols` on are ignored.
    pub fn tile_at(
        &self,
        isa: Isa,
        cols: usize,
        rows: usize,
        px: &[f32; TILE_RAYS],
        py: &[f32; TILE_RAYS],
        out: &mut RayTile,
    ) {
        assert!(
            (1..=8).contains(&cols) && (1..=8).contains(&rows),
            "a tile is 1 to 8 pixels on a side"
        );
        // The lanes past the last ray repeat it, so that every lane is a ray of the tile.
        let n = rows * cols;
        let (mut x, mut y) = ([px[n - 1]; TILE_RAYS + 8], [py[n - 1]; TILE_RAYS + 8]);
        x[..n].copy_from_slice(&px[..n]);
        y[..n].copy_from_slice(&py[..n]);
        isa.run(Tile(self, cols, rows, Positions::At(&x, &y), out));
    }
}

/// Where a tile's rays go through the image, in pixels.
#[derive(Clone, Copy)]
enum Positions<'a> {
    /// The centres of row `y0 + r`'s pixels: the `x` of a row's eight lanes, and `y0`.
    Centres([f32; 8], usize),
    /// Ray `i` through `(x[i], y[i])`, rows of eight lanes from `r·cols` (padded).
    At(&'a [f32; TILE_RAYS + 8], &'a [f32; TILE_RAYS + 8]),
}

/// [`RayGen::tile`] as a kernel: `cols`×`rows` rays through `Positions`, into the tile.
struct Tile<'a>(&'a RayGen, usize, usize, Positions<'a>, &'a mut RayTile);

impl Kernel for Tile<'_> {
    type Output = ();

    #[inline(always)]
    fn run<P: Path>(self) {
        let Tile(g, cols, rows, at, out) = self;
        tile_lanes::<P::Eight>(g, cols, rows, at, out);
    }
}

/// [`RayGen::tile`], `L::N` rays at a time: [`RayGen::ray`]'s operations, then the axes
/// ([`crate::geometry::Ray::axes`]) and shear of each lane, kept when every lane shares
/// them.
#[inline(always)]
fn tile_lanes<L: Lanes>(
    g: &RayGen,
    cols: usize,
    rows: usize,
    positions: Positions,
    out: &mut RayTile,
) {
    let splat = L::splat;
    let m = &g.rotation;
    let rows_of_m = [0, 1, 2].map(|i| m.row(i).to_array());
    // What every row shares, worked out once (written out: a closure would not inline the
    // path's lane operations): the matrix's columns for x and y, its z column times the
    // focal length (the product `Mat3 * Vec3` takes lane by lane, so the same bits), and the
    // image's centre.
    let [m0, m1, m2] = rows_of_m;
    let m_x = [splat(m0[0]), splat(m1[0]), splat(m2[0])];
    let m_y = [splat(m0[1]), splat(m1[1]), splat(m2[1])];
    let focal = splat(g.focal);
    let m_z = [
        splat(m0[2]).mul(focal),
        splat(m1[2]).mul(focal),
        splat(m2[2]).mul(focal),
    ];
    let (half_w, half_h) = (splat(g.half_w), g.half_h);
    let zero = splat(0.0);
    let full = (1u32 << L::N).wrapping_sub(1);
    // The main axis and its sign shared by every lane so far (`None` until the first row),
    // `mixed` once a lane differs.
    let mut common: Option<(usize, bool)> = None;
    let mut mixed = false;
    let (mut lo, mut hi) = ([splat(f32::INFINITY); 3], [splat(f32::NEG_INFINITY); 3]);
    for r in 0..rows {
        for at in (r * cols..r * cols + 8).step_by(L::N) {
            let (dx, dy) = match positions {
                Positions::Centres(xs, y0) => (
                    L::load(&xs[at - r * cols..]).sub(half_w),
                    splat((y0 + r) as f32 + 0.5 - half_h),
                ),
                Positions::At(px, py) => (
                    L::load(&px[at..]).sub(half_w),
                    L::load(&py[at..]).sub(splat(half_h)),
                ),
            };
            // `Mat3 * Vec3`: x_axis·d.x + y_axis·d.y + z_axis·d.z, in that order.
            let d = [
                m_x[0].mul(dx).add(m_y[0].mul(dy)).add(m_z[0]),
                m_x[1].mul(dx).add(m_y[1].mul(dy)).add(m_z[1]),
                m_x[2].mul(dx).add(m_y[2].mul(dy)).add(m_z[2]),
            ];
            // `normalize`: times 1 / sqrt(x·x + y·y + z·z).
            let len2 = d[0].mul(d[0]).add(d[1].mul(d[1])).add(d[2].mul(d[2]));
            let rcp = splat(1.0).div(len2.sqrt());
            let d = [d[0].mul(rcp), d[1].mul(rcp), d[2].mul(rcp)];
            for (k, c) in d.into_iter().enumerate() {
                c.store(&mut out.dir[k][at..]);
            }
            if mixed {
                continue;
            }
            let (kz0, kz1) = main_axis(d);
            let kz = match (L::bits(kz0), L::bits(kz1)) {
                (b, 0) if b == full => 0,
                (0, b) if b == full => 1,
                (0, 0) => 2,
                _ => {
                    mixed = true;
                    continue;
                }
            };
            let negative = match L::bits(d[kz].lt(zero)) {
                0 => false,
                b if b == full => true,
                _ => {
                    mixed = true;
                    continue;
                }
            };
            if *common.get_or_insert((kz, negative)) != (kz, negative) {
                mixed = true;
                continue;
            }
            let shear = shear_of(d, axes_of(kz, negative), splat(1.0).div(d[kz]));
            for (k, s) in shear.into_iter().enumerate() {
                s.store(&mut out.shear[k][at..]);
                lo[k] = lo[k].min(s);
                hi[k] = hi[k].max(s);
            }
        }
    }
    out.origin = g.origin;
    out.len = rows * cols;
    out.axes = common
        .filter(|_| !mixed)
        .map(|(kz, negative)| axes_of(kz, negative));
    let fold = |v: L, f: fn(f32, f32) -> f32| {
        let mut a = [0.0; 16];
        v.store(&mut a);
        a[..L::N].iter().copied().reduce(f).unwrap_or(0.0)
    };
    out.shear_box = [
        fold(lo[0], f32::min),
        fold(hi[0], f32::max),
        fold(lo[1], f32::min),
        fold(hi[1], f32::max),
        fold(lo[2], f32::min),
        fold(hi[2], f32::max),
    ];
    out.pad();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_follow_the_seed_rotation() {
        let cam = Camera {
            yaw: std::f32::consts::FRAC_PI_2,
            ..Camera::default()
        };
        assert!((cam.forward() - Vec3::X).length() < 1e-6);
        assert!((cam.right() + Vec3::Z).length() < 1e-6);
        assert_eq!(cam.down(), Vec3::Y);
    }

    /// Asserts that tile `t` holds rays `one` bit for bit: directions, axes, and where they are
    /// shared the shears, their box and the padding lanes. Returns whether they share axes.
    fn assert_tile_is(t: &RayTile, one: &[Ray], origin: Vec3, what: &str) -> bool {
        let axes = one.iter().all(|r| r.axes() == one[0].axes());
        assert_eq!(t.len(), one.len());
        assert_eq!(t.origin(), origin);
        assert_eq!(t.axes(), axes.then(|| one[0].axes()), "{what}");
        let mut b = [f32::INFINITY, f32::NEG_INFINITY].repeat(3);
        for (j, r) in one.iter().enumerate() {
            let at = format!("{what}: ray {j}");
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            assert_eq!(bits(t.dir(j)), bits(r.dir), "{at}");
            let tr = t.ray(j);
            assert_eq!(bits(tr.inv_dir), bits(r.inv_dir), "{at}");
            assert_eq!(tr.shear().map(f32::to_bits), r.shear().map(f32::to_bits));
            if axes {
                let s = t.shear_lanes();
                let s = [s[0][j], s[1][j], s[2][j]];
                assert_eq!(s.map(f32::to_bits), r.shear().map(f32::to_bits), "{at}");
                for k in 0..3 {
                    b[2 * k] = b[2 * k].min(s[k]);
                    b[2 * k + 1] = b[2 * k + 1].max(s[k]);
                }
            }
        }
        if axes {
            assert_eq!(t.shear_box()[..], b, "{what}");
            // The lanes past the last ray repeat it.
            let (n, s) = (t.len(), t.shear_lanes());
            for l in n..n.next_multiple_of(16) {
                assert_eq!(s[0][l].to_bits(), s[0][n - 1].to_bits());
                assert_eq!(s[2][l].to_bits(), s[2][n - 1].to_bits());
            }
        }
        axes
    }

    /// Every ray of tiles of four cameras and image sizes equals `RayGen::ray` bit for bit
    /// (direction, and axes and shear when shared), on every path this CPU has: through pixel
    /// centres, and through jittered positions (`tile_at`, as
    /// anti-aliased frames make them).
    #[test]
    fn tiles_of_rays_are_single_rays_bit_for_bit() {
        let mut tiles = 0;
        let mut shared = 0;
        let mut rng = crate::rng::Rng::seeded(3);
        for (i, (w, h)) in [(500, 500), (37, 91), (1920, 1080), (3, 1)]
            .into_iter()
            .enumerate()
        {
            let cam = Camera {
                position: Vec3::new(0.3 * i as f32, -0.2, -3.0 + i as f32),
                yaw: 0.7 * i as f32 - 1.4,
                pitch: 0.3 * i as f32 - 0.5,
                ..Camera::default()
            };
            let g = cam.rays(w, h);
            let (w, h) = (w as usize, h as usize);
            let (mut tile, mut jittered) = (RayTile::default(), RayTile::default());
            for y0 in (0..h).step_by(8).filter(|y| y % 24 == 0 || y + 8 >= h) {
                for x0 in (0..w).step_by(8) {
                    let (cols, rows) = ((w - x0).min(8), (h - y0).min(8));
                    tiles += 1;
                    let pixel = |j: usize| (x0 + j % cols, y0 + j / cols);
                    let one: Vec<Ray> = (0..rows * cols)
                        .map(|j| {
                            let (x, y) = pixel(j);
                            g.ray(x as f32 + 0.5, y as f32 + 0.5)
                        })
                        .collect();
                    for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
                        let what = format!("{isa:?}, {w}x{h} camera {i}: tile ({x0}, {y0})");
                        g.tile(isa, x0, y0, cols, rows, &mut tile);
                        let s = assert_tile_is(&tile, &one, cam.position, &what);
                        shared += (s && isa == Isa::Portable) as usize;
                    }
                    // Jittered anywhere in their pixels, corners included.
                    let (mut px, mut py) = ([0.0; TILE_RAYS], [0.0; TILE_RAYS]);
                    for j in 0..rows * cols {
                        let (x, y) = pixel(j);
                        let jitter = |rng: &mut crate::rng::Rng| match rng.next_u64() % 4 {
                            0 => 0.0,
                            1 => 0.999_999_94,
                            _ => (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32,
                        };
                        px[j] = x as f32 + jitter(&mut rng);
                        py[j] = y as f32 + jitter(&mut rng);
                    }
                    let one: Vec<Ray> = (0..rows * cols).map(|j| g.ray(px[j], py[j])).collect();
                    for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
                        let what = format!("{isa:?}, {w}x{h} camera {i}: tile ({x0}, {y0})");
                        g.tile_at(isa, cols, rows, &px, &py, &mut jittered);
                        assert_tile_is(&jittered, &one, cam.position, &what);
                    }
                }
            }
        }
        // Both kinds of tiles were seen.
        assert!(
            shared > 100 && shared < tiles,
            "{shared} of {tiles} tiles share axes"
        );
    }

    /// `look_at` looks where it is told, keeps `up` up on screen, and its field of view spans
    /// the image's height.
    #[test]
    fn look_at_points_the_camera() {
        let mut rng = crate::rng::Rng::seeded(11);
        let unit = |rng: &mut crate::rng::Rng| {
            let v = Vec3::new(
                (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32 - 0.5,
                (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32 - 0.5,
                (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32 - 0.5,
            );
            v * 10.0
        };
        for _ in 0..500 {
            let (from, at, up) = (unit(&mut rng), unit(&mut rng), unit(&mut rng));
            let Some(c) = Camera::look_at(from, at, up, Some(0.8)) else {
                continue;
            };
            let d = (at - from).normalize();
            assert!((c.forward() - d).length() < 1e-4, "{from} {at} {up}");
            // The screen's up is on the side of `up`, and the right axis is level.
            assert!(c.right().dot(up).abs() < 1e-3 * up.length());
            assert!(-c.down().dot(up) >= -1e-4);
            let r = c.rotation();
            assert!((r.x_axis.cross(r.y_axis) - r.z_axis).length() < 1e-4);
            let g = c.rays(200, 100);
            let top = g.ray(100.0, 0.0).dir;
            let bottom = g.ray(100.0, 100.0).dir;
            assert!((top.angle_between(bottom) - 0.8).abs() < 1e-4);
        }
        assert_eq!(Camera::look_at(Vec3::ONE, Vec3::ONE, Vec3::Y, None), None);
        // Straight down still gives a camera.
        let c = Camera::look_at(Vec3::Y, Vec3::ZERO, Vec3::Y, None).unwrap();
        assert!((c.forward() + Vec3::Y).length() < 1e-5);
    }

    #[test]
    fn centre_ray_looks_forward() {
        let g = Camera::default().rays(500, 500);
        let r = g.ray(250.0, 250.0);
        assert_eq!(r.dir, Vec3::Z);
    }
}
