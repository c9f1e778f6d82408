//! Where a model is seen from: the file's camera, or one framed on the model's bounds at a
//! three-quarter view; the user's `--look-from`, `--look-at`, `--fov` and `--up` over either.
//! And the default light rig for a model whose file has no light.

use glam::Vec3;

use crate::camera::{Camera, FOV_RANGE_DEGREES};
use crate::scene::PointLight;

use super::ModelCamera;

/// Vertical field of view of a framed camera, in degrees (a common viewer's default).
pub const DEFAULT_FOV_DEGREES: f32 = 45.0;

/// From the model's centre, where a framed camera stands: front-right and above (a
/// three-quarter view; +y up, the model's front facing +z as glTF's is).
const THREE_QUARTER: Vec3 = Vec3::new(1.0, 0.6, 1.4);

/// The view the user asks for; every field unset gives the file's or the framed camera.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct View {
    /// Which of the file's cameras (0-based); `None`: the first, if it has any.
    pub camera_index: Option<usize>,
    /// Eye position.
    pub look_from: Option<Vec3>,
    /// The point looked at.
    pub look_at: Option<Vec3>,
    /// Up on screen (default +y for model files).
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees.
    pub fov_degrees: Option<f32>,
}

/// Why a view cannot be made.
#[derive(Clone, Debug, PartialEq)]
pub enum ViewError {
    /// `--camera-index` past the file's cameras.
    NoSuchCamera {
        /// The index asked for.
        index: usize,
        /// How many the file has.
        count: usize,
    },
    /// The eye is at the point looked at, or up is zero or along the view.
    Degenerate,
    /// The field of view is outside [`FOV_RANGE_DEGREES`].
    Fov(f32),
}

impl std::fmt::Display for ViewError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ViewError::NoSuchCamera { index, count } => write!(
                f,
                "--camera-index {index}: the file has {count} camera(s){}",
                if *count == 0 {
                    String::new()
                } else {
                    format!(", 0 to {}", count - 1)
                }
            ),
            ViewError::Degenerate => f.write_str(
                "--look-from and --look-at are the same point, or --up is zero: give two different points and a non-zero up",
            ),
            ViewError::Fov(d) => write!(
                f,
                "--fov {d}: expected a vertical field of view from {} to {} degrees",
                FOV_RANGE_DEGREES.0, FOV_RANGE_DEGREES.1
            ),
        }
    }
}

impl std::error::Error for ViewError {}

impl View {
    /// Whether any value is set.
    pub fn is_set(&self) -> bool {
        *self != View::default()
    }

    /// The camera for a model of `cameras` within `bounds` (min, max): the chosen file
    /// camera, else one framed on the bounds; then the user's values over it.
    pub fn camera(
        &self,
        cameras: &[ModelCamera],
        bounds: (Vec3, Vec3),
    ) -> Result<Camera, ViewError> {
        let fov = self.fov()?;
        let (from, at, up, file_fov) = match (self.camera_index, cameras.first()) {
            (Some(index), _) if index >= cameras.len() => {
                return Err(ViewError::NoSuchCamera {
                    index,
                    count: cameras.len(),
                });
            }
            (Some(i), _) => {
                let c = &cameras[i];
                (c.position, c.position + c.forward, c.up, c.fov)
            }
            (None, Some(c)) if self.look_from.is_none() && self.look_at.is_none() => {
                (c.position, c.position + c.forward, c.up, c.fov)
            }
            _ => {
                let (lo, hi) = bounds;
                let centre = (lo + hi) * 0.5;
                let radius = ((hi - lo).length() * 0.5).max(1e-6);
                let fov = fov.unwrap_or(DEFAULT_FOV_DEGREES.to_radians());
                // The bounding sphere fits the field of view, with a margin of a tenth.
                let distance = radius / (fov * 0.5).sin() * 1.1;
                let from = centre + THREE_QUARTER.normalize() * distance;
                (from, centre, Vec3::Y, Some(fov))
            }
        };
        // A file camera's own up keeps its roll unless the user gives one; keys turn about it.
        let up = self.up.unwrap_or(up);
        let from = self.look_from.unwrap_or(from);
        let at = self.look_at.unwrap_or(at);
        let fov = fov.or(file_fov).or(Some(DEFAULT_FOV_DEGREES.to_radians()));
        Camera::look_at(from, at, up, fov).ok_or(ViewError::Degenerate)
    }

    /// The user's values over `camera` (a scene file's or a built-in scene's, in its own
    /// axes: its up is the camera's −down unless `--up` is given).
    pub fn apply(&self, camera: Camera) -> Result<Camera, ViewError> {
        if let Some(index) = self.camera_index {
            return Err(ViewError::NoSuchCamera { index, count: 0 });
        }
        let fov = self.fov()?;
        if self.look_from.is_none() && self.look_at.is_none() && self.up.is_none() {
            return Ok(Camera {
                fov: fov.or(camera.fov),
                ..camera
            });
        }
        let from = self.look_from.unwrap_or(camera.position);
        let at = self.look_at.unwrap_or(camera.position + camera.forward());
        let up = self.up.unwrap_or(-camera.frame.y_axis);
        Camera::look_at(from, at, up, fov.or(camera.fov)).ok_or(ViewError::Degenerate)
    }

    fn fov(&self) -> Result<Option<f32>, ViewError> {
        match self.fov_degrees {
            Some(d) if !(d >= FOV_RANGE_DEGREES.0 && d <= FOV_RANGE_DEGREES.1) => {
                Err(ViewError::Fov(d))
            }
            d => Ok(d.map(f32::to_radians)),
        }
    }
}

/// The default rig for a model whose file has no light: a key light above the camera and to
/// its right (over its shoulder), twice as far from the model's centre as the model's radius,
/// bright enough that a surface at the centre facing it gets an irradiance of 1 (as the
/// Cornell box's light gives its floor, about). The dim uniform fill is the scene's constant
/// indirect term; an environment light comes with the physically based materials.
pub fn default_rig(camera: &Camera, bounds: (Vec3, Vec3)) -> Vec<PointLight> {
    let (lo, hi) = bounds;
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-6);
    let toward_camera = (camera.position - centre).normalize_or(Vec3::Z);
    let dir = (toward_camera - camera.down() * 0.8 + camera.right() * 0.5).normalize_or(Vec3::Y);
    let distance = 2.5 * radius;
    // Irradiance P / (4π r²) = 1 at the centre.
    let power = 4.0 * std::f32::consts::PI * distance * distance;
    vec![PointLight {
        position: centre + dir * distance,
        power: Vec3::splat(power),
    }]
}
