//! The pinhole camera: where primary rays are shot from, and how the camera moves.

use glam::{Mat3, Vec3};

use crate::geometry::Ray;

/// A pinhole camera at `position`, turned by `yaw` about the y axis (y points down) and tilted
/// by `pitch` about its right axis. With yaw = pitch = 0 it looks along +z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// Rotation about y in radians; positive turns towards +x (to the right).
    pub yaw: f32,
    /// Rotation about the camera's right axis in radians; positive looks down (+y).
    pub pitch: f32,
}

impl Default for Camera {
    /// The seed's camera: at (0, 0, −3) looking along +z.
    fn default() -> Camera {
        Camera {
            position: Vec3::new(0.0, 0.0, -3.0),
            yaw: 0.0,
            pitch: 0.0,
        }
    }
}

impl Camera {
    /// The seed's rotation R = [[cos θ, 0, sin θ], [0, 1, 0], [−sin θ, 0, cos θ]] times the pitch.
    pub fn rotation(&self) -> Mat3 {
        let (s, c) = (libm::sinf(self.yaw), libm::cosf(self.yaw));
        let yaw = Mat3::from_cols(Vec3::new(c, 0.0, -s), Vec3::Y, Vec3::new(s, 0.0, c));
        if self.pitch == 0.0 {
            return yaw;
        }
        let (s, c) = (libm::sinf(self.pitch), libm::cosf(self.pitch));
        let pitch = Mat3::from_cols(Vec3::X, Vec3::new(0.0, c, -s), Vec3::new(0.0, s, c));
        yaw * pitch
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
            focal: width.min(height).max(1) as f32,
        }
    }
}

/// Generates primary rays for one frame: focal length = the shorter image side in pixels, so
/// the box's front opening fits any aspect ratio (2·atan(½) ≈ 53.13° across the shorter side).
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
    /// Appends the rays through the centres of pixels `x0..x0 + n` of row `y` to `out`: each
    /// is `self.ray(x + 0.5, y + 0.5)` bit for bit, made eight at a time with AVX2 where the CPU
    /// has it (the same operations in the same order, so the same rounding).
    pub fn row(&self, x0: usize, n: usize, y: usize, out: &mut Vec<Ray>) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            let mut x = x0;
            while x < x0 + n {
                let k = (x0 + n - x).min(8);
                // SAFETY: the CPU has AVX2 (checked above).
                unsafe { self.row8_avx2(x, k, y, out) };
                x += k;
            }
            return;
        }
        self.row_scalar(x0, n, y, out);
    }

    /// [`RayGen::row`] one ray at a time.
    pub fn row_scalar(&self, x0: usize, n: usize, y: usize, out: &mut Vec<Ray>) {
        out.extend((x0..x0 + n).map(|x| self.ray(x as f32 + 0.5, y as f32 + 0.5)));
    }

    /// Up to eight rays of [`RayGen::row`] at once.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn row8_avx2(&self, x0: usize, n: usize, y: usize, out: &mut Vec<Ray>) {
        use std::arch::x86_64::*;
        debug_assert!(n <= 8);
        let xs: [f32; 8] = std::array::from_fn(|i| (x0 + i.min(n - 1)) as f32 + 0.5);
        let splat = |v: f32| _mm256_set1_ps(v);
        // SAFETY: reads eight `f32`s.
        let dx = _mm256_sub_ps(unsafe { _mm256_loadu_ps(xs.as_ptr()) }, splat(self.half_w));
        let dy = splat((y as f32 + 0.5) - self.half_h);
        let dz = splat(self.focal);
        let m = &self.rotation;
        // `Mat3 * Vec3`: x_axis·d.x + y_axis·d.y + z_axis·d.z, in that order.
        let axis = |x: f32, y: f32, z: f32| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(splat(x), dx), _mm256_mul_ps(splat(y), dy)),
                _mm256_mul_ps(splat(z), dz),
            )
        };
        let rx = axis(m.x_axis.x, m.y_axis.x, m.z_axis.x);
        let ry = axis(m.x_axis.y, m.y_axis.y, m.z_axis.y);
        let rz = axis(m.x_axis.z, m.y_axis.z, m.z_axis.z);
        // `normalize`: times 1 / sqrt(x·x + y·y + z·z).
        let len2 = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(rx, rx), _mm256_mul_ps(ry, ry)),
            _mm256_mul_ps(rz, rz),
        );
        let one = splat(1.0);
        let rcp = _mm256_div_ps(one, _mm256_sqrt_ps(len2));
        let d = [rx, ry, rz].map(|r| _mm256_mul_ps(r, rcp));
        let inv = d.map(|c| _mm256_div_ps(one, c));
        let mut dir = [[0f32; 8]; 3];
        let mut inv_dir = [[0f32; 8]; 3];
        for k in 0..3 {
            // SAFETY: each store writes eight `f32`s.
            unsafe {
                _mm256_storeu_ps(dir[k].as_mut_ptr(), d[k]);
                _mm256_storeu_ps(inv_dir[k].as_mut_ptr(), inv[k]);
            }
        }
        for l in 0..n {
            let dir = Vec3::new(dir[0][l], dir[1][l], dir[2][l]);
            let inv = Vec3::new(inv_dir[0][l], inv_dir[1][l], inv_dir[2][l]);
            out.push(Ray::with_inverse(self.origin, dir, inv));
        }
    }
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

    #[test]
    fn rows_of_rays_are_single_rays_bit_for_bit() {
        let bits = |r: &Ray| {
            let v = [r.origin, r.dir, r.inv_dir].map(|v| v.to_array().map(f32::to_bits));
            (v, r.axes(), r.shear().map(f32::to_bits))
        };
        for (i, (w, h)) in [(500, 500), (37, 91), (1920, 1080), (3, 1)]
            .into_iter()
            .enumerate()
        {
            let cam = Camera {
                position: Vec3::new(0.3 * i as f32, -0.2, -3.0 + i as f32),
                yaw: 0.7 * i as f32 - 1.4,
                pitch: 0.3 * i as f32 - 0.5,
            };
            let g = cam.rays(w, h);
            for y in [0, h as usize / 2, h as usize - 1] {
                let (mut fast, mut slow) = (vec![], vec![]);
                g.row(0, w as usize, y, &mut fast);
                g.row_scalar(0, w as usize, y, &mut slow);
                let one: Vec<Ray> = (0..w as usize)
                    .map(|x| g.ray(x as f32 + 0.5, y as f32 + 0.5))
                    .collect();
                assert_eq!(fast.len(), one.len());
                for x in 0..one.len() {
                    assert_eq!(
                        bits(&fast[x]),
                        bits(&one[x]),
                        "{w}x{h} camera {i}: ({x}, {y})"
                    );
                    assert_eq!(
                        bits(&slow[x]),
                        bits(&one[x]),
                        "{w}x{h} camera {i}: ({x}, {y})"
                    );
                }
            }
        }
    }

    #[test]
    fn centre_ray_looks_forward() {
        let g = Camera::default().rays(500, 500);
        let r = g.ray(250.0, 250.0);
        assert_eq!(r.dir, Vec3::Z);
    }
}
