//! raytty: a raytracer that lives in the terminal.
//!
//! The library is the tracer and the frame encoder; it does no terminal I/O and never imports
//! crossterm. Data flows scene → camera rays → intersection → shading → [`Image`] →
//! [`CellGrid`] → bytes:
//!
//! ```
//! use raytty::{CellGrid, ColorMode, Options, cornell_box, encode_text};
//! let scene = cornell_box();
//! let frame = scene.render(&Options { width: 40, height: 24, ..Options::default() });
//! let text = encode_text(&CellGrid::from_image(&frame.image, ColorMode::Ascii));
//! assert_eq!(text.iter().filter(|&&b| b == b'\n').count(), 12);
//! ```
#![warn(missing_docs)]

pub mod accel;
pub mod bench;
pub mod camera;
pub mod denoise;
pub mod frame;
pub mod geometry;
pub mod image;
pub mod light;
pub mod material;
mod render;
pub mod rng;
pub mod sampler;
pub mod scene;
pub mod shading;
pub mod simd;
mod text;

pub use accel::{AccelKind, AccelStats, Hit};
pub use camera::Camera;
pub use frame::{CellGrid, ColorMode, encode_diff, encode_text};
pub use geometry::{Ray, Triangle};
pub use image::Image;
pub use render::{BandDone, Frame, FrameStats, HitCache, Options, Output};
pub use scene::cornell::cornell_box;
pub use scene::{
    DirectionalLight, Effects, Indirect, Material, PointLight, Scene, SceneBuilder, SpotLight,
};
pub use shading::{LightEffects, Mode, RayCounts, Settings, Stage, Tracer};
pub use text::printable;
