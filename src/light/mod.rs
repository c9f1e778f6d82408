//! Sampling light sources: the pieces next-event estimation with area lights is built from.
//! Picking one light of many in proportion to its power ([`AliasTable`]), a point uniformly
//! on an emitting triangle ([`sample_triangle`]), and the change of a density per area into
//! one per solid angle as seen from the shaded point ([`area_to_solid_angle`]).
//! [`AreaLights`] puts them together for a scene's emitting triangles.

mod alias;
mod area;
mod emitters;

pub use alias::AliasTable;
pub use area::{TrianglePoint, area_to_solid_angle, sample_triangle};
pub use emitters::{AreaLights, LightPoint, MAX_CANDIDATES};
