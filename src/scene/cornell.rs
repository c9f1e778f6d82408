//! The built-in Cornell box, exactly as the course's `TestModel.h` defines it.

use glam::Vec3;

use crate::camera::Camera;
use crate::scene::{Effects, Material, PointLight, Scene, SceneBuilder};

/// The room's side in Cornell units.
const L: f32 = 555.0;

/// The seed's colours, linear RGB.
pub mod colours {
    use glam::Vec3;
    /// Red.
    pub const RED: Vec3 = Vec3::new(0.75, 0.15, 0.15);
    /// Yellow.
    pub const YELLOW: Vec3 = Vec3::new(0.75, 0.75, 0.15);
    /// Green.
    pub const GREEN: Vec3 = Vec3::new(0.15, 0.75, 0.15);
    /// Cyan.
    pub const CYAN: Vec3 = Vec3::new(0.15, 0.75, 0.75);
    /// Blue.
    pub const BLUE: Vec3 = Vec3::new(0.15, 0.15, 0.75);
    /// Purple.
    pub const PURPLE: Vec3 = Vec3::new(0.75, 0.15, 0.75);
    /// White.
    pub const WHITE: Vec3 = Vec3::new(0.75, 0.75, 0.75);
}

/// The seed's light: at (0, −0.5, −0.7), power 14 per channel.
pub const LIGHT: PointLight = PointLight {
    position: Vec3::new(0.0, -0.5, -0.7),
    power: Vec3::new(14.0, 14.0, 14.0),
};

/// Maps a Cornell-unit vertex into the box [−1, 1]³ with y down: v·(2/L) − 1, then x, y negated.
fn to_unit(v: Vec3) -> Vec3 {
    let u = v * (2.0 / L) - Vec3::ONE;
    Vec3::new(-u.x, -u.y, u.z)
}

/// The 10 triangles of a block with corners A..H (no bottom face), in the seed's order.
fn block(c: [Vec3; 8]) -> Vec<[Vec3; 3]> {
    let [a, b, cc, d, e, f, g, h] = c.map(to_unit);
    vec![
        [e, b, a],
        [e, f, b],
        [f, d, b],
        [f, h, d],
        [h, cc, d],
        [h, g, cc],
        [g, e, cc],
        [e, a, cc],
        [g, f, e],
        [g, h, f],
    ]
}

/// The box's eight corners from the four floor corners and a height.
fn corners(floor: [(f32, f32); 4], height: f32) -> [Vec3; 8] {
    let f = floor.map(|(x, z)| Vec3::new(x, 0.0, z));
    let r = floor.map(|(x, z)| Vec3::new(x, height, z));
    [f[0], f[1], f[2], f[3], r[0], r[1], r[2], r[3]]
}

/// The Cornell box scene: 30 triangles (room 10, short block 10, tall block 10) in the seed's
/// order, the seed's camera and light, and the seed's effects.
pub fn cornell_box() -> Scene {
    let mut b = SceneBuilder::new();
    let [a, bb, c, d, e, f, g, h] =
        corners([(L, 0.0), (0.0, 0.0), (L, L), (0.0, L)], L).map(to_unit);
    let green = b.material(Material::diffuse(colours::GREEN));
    let purple = b.material(Material::diffuse(colours::PURPLE));
    let yellow = b.material(Material::diffuse(colours::YELLOW));
    let cyan = b.material(Material::diffuse(colours::CYAN));
    let white = b.material(Material::diffuse(colours::WHITE));
    let red = b.material(Material::diffuse(colours::RED));
    let blue = b.material(Material::diffuse(colours::BLUE));
    // The room is one object for culling, but keeps one material per wall: add wall by wall.
    b.object([[c, bb, a], [c, d, bb]], green);
    b.object([[a, e, c], [c, e, g]], purple);
    b.object([[f, bb, d], [h, f, d]], yellow);
    b.object([[e, f, g], [f, h, g]], cyan);
    b.object([[g, d, c], [g, h, d]], white);
    b.object(
        block(corners(
            [(290.0, 114.0), (130.0, 65.0), (240.0, 272.0), (82.0, 225.0)],
            165.0,
        )),
        red,
    );
    b.object(
        block(corners(
            [
                (423.0, 247.0),
                (265.0, 296.0),
                (472.0, 406.0),
                (314.0, 456.0),
            ],
            330.0,
        )),
        blue,
    );
    b.light(LIGHT);
    b.build("cornell", Camera::default(), Effects::SEED)
        .expect("the built-in Cornell box is valid")
}
