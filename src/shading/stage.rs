//! What a frame computes: the seed's stages, the settings they resolve to, and the rays a
//! frame traced, by kind.

use super::GI_MAX_BOUNCES;
use super::path::Estimator;
use crate::scene::{Effects, Indirect};

/// The seed's stages, selectable by name and by the keys 1-6.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// The triangle's colour (the seed's Fig. 2).
    Flat,
    /// Direct irradiance D as grey, no shadows (Figs. 7-9).
    Light,
    /// ρ·D, no shadows (Figs. 10-12).
    Direct,
    /// ρ·D with shadow rays (Fig. 13).
    Shadows,
    /// ρ·(D + N): the effects the scene calls for (Fig. 14 for the Cornell box; the default).
    Indirect,
    /// Path-traced global illumination.
    Gi,
}

impl Stage {
    /// All stages in key order (1-6).
    pub const ALL: [Stage; 6] = [
        Stage::Flat,
        Stage::Light,
        Stage::Direct,
        Stage::Shadows,
        Stage::Indirect,
        Stage::Gi,
    ];

    /// The stage's name as the CLI takes it.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Flat => "flat",
            Stage::Light => "light",
            Stage::Direct => "direct",
            Stage::Shadows => "shadows",
            Stage::Indirect => "indirect",
            Stage::Gi => "gi",
        }
    }

    /// Parses a stage name.
    pub fn from_name(name: &str) -> Option<Stage> {
        Stage::ALL.into_iter().find(|s| s.name() == name)
    }

    /// What this stage computes, given the effects the scene calls for.
    pub fn settings(self, scene: Effects) -> Settings {
        let none = Effects {
            shadows: false,
            indirect: Indirect::None,
            samples: 1,
            sampler: scene.sampler,
        };
        let (mode, effects) = match self {
            Stage::Flat => (Mode::Flat, none),
            Stage::Light => (Mode::Irradiance, none),
            Stage::Direct => (Mode::Colour, none),
            Stage::Shadows => (
                Mode::Colour,
                Effects {
                    shadows: true,
                    ..none
                },
            ),
            Stage::Indirect => (Mode::Colour, scene),
            Stage::Gi => (
                Mode::Colour,
                Effects {
                    shadows: true,
                    indirect: Indirect::PathTraced {
                        bounces: GI_MAX_BOUNCES,
                    },
                    samples: 1,
                    sampler: scene.sampler,
                },
            ),
        };
        Settings {
            mode,
            effects,
            frame: 0,
            estimator: Estimator::Auto,
        }
    }
}

/// What a hit's colour is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// The material colour ρ.
    Flat,
    /// The direct irradiance D itself.
    Irradiance,
    /// ρ·(direct + indirect), with mirrors.
    Colour,
}

/// Everything that decides a frame's pixels besides the scene, camera, lights and size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// What a hit's colour is made of.
    pub mode: Mode,
    /// Which effects run.
    pub effects: Effects,
    /// Frame number: seeds the random numbers (progressive refinement uses a new one per pass).
    pub frame: u32,
    /// How the physically based path gathers light at vertices that are not specular (the
    /// seed's shading ignores it).
    pub estimator: Estimator,
}

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Camera rays.
    pub primary: u64,
    /// Rays towards a light (any-hit queries).
    pub shadow: u64,
    /// Diffuse bounce rays of path-traced indirect light.
    pub bounce: u64,
    /// Mirror reflection rays.
    pub reflection: u64,
}

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.bounce + self.reflection
    }

    /// The counts by kind, named: primary, shadow, bounce, reflection.
    pub fn by_kind(&self) -> [(&'static str, u64); 4] {
        [
            ("primary", self.primary),
            ("shadow", self.shadow),
            ("bounce", self.bounce),
            ("reflection", self.reflection),
        ]
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.bounce += o.bounce;
        self.reflection += o.reflection;
    }
}
