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
    fn centre_ray_looks_forward() {
        let g = Camera::default().rays(500, 500);
        let r = g.ray(250.0, 250.0);
        assert_eq!(r.dir, Vec3::Z);
    }
}
