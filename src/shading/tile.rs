//! The shading kernel: the hits of a tile of primary rays shaded together, as structure of
//! arrays, [`Lanes::WIDTH`] pixels at a time (eight with AVX2 or AVX-512, one elsewhere). The
//! hit points ([`surface`]), each light's term and shadow ray ([`super::light`]), the shadow
//! rays of the whole tile toward one light traced together, the sums over the lights and the
//! colours. One ray at a time ([`Tracer::direct`]) is this kernel at width 1 with one pixel.
//!
//! Surfaces the lanes do not finish (a mirror, a black surface, flat colour: see
//! [`Tracer::in_lanes`]) are shaded ray by ray first.

use glam::Vec3;

use super::lane::{Lanes, Scalar, each3};
use super::light::{directional_light, point_light, spot_light};
use super::surface::{Surface, surface, with_shading};
use super::{Mode, RayCounts, SHADOW_EPSILON, Tracer};
use crate::accel::TILE_RAYS;
use crate::accel::tri4::Best8;
use crate::geometry::{Ray, RayTile};
use crate::scene::{DirectionalLight, Indirect, PointLight, SpotLight};

/// Most pixels in a tile.
const N: usize = TILE_RAYS;

/// Up to eight lanes of `f32`: one vector on the widest lanes (width 1 uses the first).
pub(crate) type Block = [f32; 8];

/// `a[o..o + 8]`.
#[inline(always)]
fn block(a: &[f32], o: usize) -> &Block {
    a[o..o + 8].try_into().expect("eight lanes")
}

/// `0, 1, 2, …`: the indices of a tile's pixels in place.
static PIXEL_ORDER: [u32; N] = {
    let mut order = [0; N];
    let mut j = 0;
    while j < N {
        order[j] = j as u32;
        j += 1;
    }
    order
};

/// The pixels of a tile gathered for the kernel, packed in order, from the first that is not
/// in place (see `shade_lanes`).
#[derive(Clone, Debug)]
pub(crate) struct Gathered {
    /// Each pixel's index in the tile.
    idx: [u32; N],
    /// Each pixel's hit: pixel `j` in lane `j % 8` of block `j / 8`.
    hits: [Best8; N / 8],
}

impl Default for Gathered {
    fn default() -> Self {
        Gathered {
            idx: [0; N],
            hits: [Best8::NONE; N / 8],
        }
    }
}

/// Points being shaded, in `B` blocks of eight (pixel `i` in lane `i % 8` of block `i / 8`),
/// each vector `[x, y, z]`.
#[derive(Clone, Debug)]
pub(crate) struct Points<const B: usize> {
    /// The hit point, its error bound and the normal facing the ray ([`Surface`]), and the
    /// shading normal (only where the scene has vertex normals).
    p: [[Block; 3]; B],
    err: [[Block; 3]; B],
    normal: [[Block; 3]; B],
    shading: [[Block; 3]; B],
    /// The base colour (colour frames only).
    rho: [[Block; 3]; B],
    /// The sum over the lights so far.
    sum: [[Block; 3]; B],
    /// One light's term, and its shadow ray's origin and direction.
    term: [[Block; 3]; B],
    pub(super) origin: [[Block; 3]; B],
    pub(super) dir: [[Block; 3]; B],
}

impl<const B: usize> Default for Points<B> {
    fn default() -> Self {
        let zero = [[[0.0; 8]; 3]; B];
        Points {
            p: zero,
            err: zero,
            normal: zero,
            shading: zero,
            rho: zero,
            sum: zero,
            term: zero,
            origin: zero,
            dir: zero,
        }
    }
}

impl<const B: usize> Points<B> {
    /// One point, for one ray at a time.
    fn one(at: &Surface<f32>) -> Points<B> {
        let mut p = Points::default();
        for k in 0..3 {
            p.p[0][k][0] = at.p[k];
            p.err[0][k][0] = at.err[k];
            p.normal[0][k][0] = at.normal[k];
            p.shading[0][k][0] = at.shading[k];
        }
        p
    }

    /// The [`Surface`] of the pixels from `o`; their shading normals stored only if `smooth`
    /// (else the normals are).
    #[inline(always)]
    fn surface<S: Lanes>(&self, s: S, o: usize, smooth: bool) -> Surface<S::F> {
        let (c, at) = (o / 8, o % 8);
        let (p, err, normal) = (&self.p[c], &self.err[c], &self.normal[c]);
        let normal = each3!(|k| s.load_at(&normal[k], at));
        Surface {
            p: each3!(|k| s.load_at(&p[k], at)),
            err: each3!(|k| s.load_at(&err[k], at)),
            normal,
            shading: match smooth {
                true => each3!(|k| s.load_at(&self.shading[c][k], at)),
                false => normal,
            },
        }
    }

    /// Pixel `i` of `v`.
    #[inline(always)]
    pub(super) fn at(v: &[[Block; 3]; B], i: usize) -> Vec3 {
        let b = &v[i / 8];
        Vec3::new(b[0][i % 8], b[1][i % 8], b[2][i % 8])
    }
}

/// How a tile's shadow rays toward one light are traced.
#[derive(Clone, Copy)]
enum Shadows {
    /// Through the scene's structure: one ray alone ([`crate::Scene::occluded`]), several
    /// together ([`crate::Scene::occluded_each`]).
    Scene,
    /// In packets of eight against the light's cull ([`Tracer::culls`]: small scenes).
    #[cfg(target_arch = "x86_64")]
    Packets(super::lane::Avx2),
}

/// A light that [`Tracer::add_light`] adds exactly, with one shadow ray per point.
#[derive(Clone, Copy)]
enum Delta<'a> {
    Point(&'a PointLight),
    Directional(&'a DirectionalLight),
    Spot(&'a SpotLight),
}

/// Scratch space of [`Shadows::Scene`] for a tile.
#[derive(Clone, Debug, Default)]
pub(super) struct ShadowScratch {
    rays: Vec<Ray>,
    blocked: Vec<bool>,
}

impl Tracer<'_> {
    /// The tile kernel of [`Tracer::shade_tile_best`]: on the widest lanes the scene's path
    /// has, the entry compiled for that path.
    pub(super) fn shade_tile_in(
        &self,
        rays: &RayTile,
        best: &[Best8; N / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        scratch: &mut super::TileScratch,
    ) {
        assert!(rays.len() <= N && out.len() == rays.len());
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = super::lane::Avx2::of(self.scene.isa()) {
            // SAFETY: the token says the CPU has AVX2; the scene's path is AVX-512 only where
            // the CPU has it.
            unsafe {
                if self.scene.isa() == crate::simd::Isa::Avx512 {
                    self.shade_tile_avx512(avx2, rays, best, out, n, scratch)
                } else {
                    self.shade_tile_avx2(avx2, rays, best, out, n, scratch)
                }
            }
            return;
        }
        self.shade_lanes(Scalar, rays, best, out, n, scratch)
    }

    /// [`Tracer::shade_lanes`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn shade_tile_avx2(
        &self,
        s: super::lane::Avx2,
        rays: &RayTile,
        best: &[Best8; N / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        scratch: &mut super::TileScratch,
    ) {
        self.shade_lanes(s, rays, best, out, n, scratch)
    }

    /// [`Tracer::shade_lanes`] compiled for AVX-512: the same operations on eight lanes, with
    /// 32 registers instead of 16 and comparisons into mask registers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl,avx512bw")]
    fn shade_tile_avx512(
        &self,
        s: super::lane::Avx2,
        rays: &RayTile,
        best: &[Best8; N / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        scratch: &mut super::TileScratch,
    ) {
        self.shade_lanes(s, rays, best, out, n, scratch)
    }

    /// The kernel (see the module's doc), inlined into each entry.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // lanes, blocks and axes, in step across arrays
    fn shade_lanes<S: Lanes>(
        &self,
        s: S,
        rays: &RayTile,
        best: &[Best8; N / 8],
        out: &mut [Vec3],
        n: &mut RayCounts,
        scratch: &mut super::TileScratch,
    ) {
        let w = S::WIDTH;
        let (g, pts) = (&mut *scratch.gathered, &mut *scratch.points);
        let k = rays.len();
        debug_assert!(k <= N);
        // The pixels shaded here, packed in order; the others one at a time. The first
        // `placed` are the tile's first packets, all shaded here: read where they are, in
        // `best`; the rest are gathered into `g`.
        let mut m = 0;
        let mut placed = 0;
        let mut others = 0u64;
        // `in_lanes` of the last triangle asked (neighbours mostly hit the same one).
        let mut last = (u32::MAX, false);
        for c in 0..k.div_ceil(8) {
            let ids = best[c].ids();
            let lanes = (k - 8 * c).min(8);
            let own = if lanes == 8 && *ids == [ids[0]; 8] && ids[0] != u32::MAX {
                // Eight hits on one triangle.
                if ids[0] != last.0 {
                    last = (ids[0], self.in_lanes(ids[0]));
                }
                if last.1 { 0xff } else { 0 }
            } else {
                let mut own = 0u32;
                for (l, &id) in ids[..lanes].iter().enumerate() {
                    if id != u32::MAX {
                        if id != last.0 {
                            last = (id, self.in_lanes(id));
                        }
                        own |= (last.1 as u32) << l;
                    }
                }
                own
            };
            // Eight pixels all shaded here (most packets): left in place while every pixel
            // before them is, else copied as they are.
            if own == 0xff && m % 8 == 0 {
                if m == 8 * c {
                    placed = m + 8;
                } else {
                    g.idx[m..m + 8].copy_from_slice(&PIXEL_ORDER[8 * c..8 * c + 8]);
                    g.hits[m / 8] = best[c];
                }
                m += 8;
                continue;
            }
            for l in 0..lanes {
                let i = 8 * c + l;
                if ids[l] == u32::MAX {
                    out[i] = self.background;
                } else if own >> l & 1 == 0 {
                    others |= 1 << i;
                } else {
                    // (`m < N`: the mask only tells the compiler so.)
                    let j = m & (N - 1);
                    g.idx[j] = i as u32;
                    g.hits[j / 8].set(j % 8, best[c].hit(l));
                    m += 1;
                }
            }
        }
        while others != 0 {
            let i = others.trailing_zeros() as usize;
            others &= others - 1;
            let mut rng = crate::rng::Rng::seeded(0);
            out[i] = self.shade_primary(&rays.ray(i), best[i / 8].hit(i % 8), &mut rng, n);
        }
        if m == 0 {
            return;
        }
        let dirs = rays.dir_lanes();
        let chunks = m.div_ceil(w);
        // Lanes past the last pixel repeat it (its triangle, index and barycentrics), so that
        // every block reads whole lanes. (A last block in place is whole.)
        let end = chunks * w;
        let last = m - 1;
        for j in m..end {
            g.idx[j] = g.idx[last];
            let hit = g.hits[last / 8].hit(last % 8);
            g.hits[j / 8].set(j % 8, hit);
        }
        // A big model keeps no list of triangles (`Scene::triangle`): the tile's are rebuilt
        // here, once each, pixel `j`'s at `j`. (Scenes with a list are read in place: copying
        // triangles out of it cost the seed's frame 8 % more instructions.)
        let rebuilt = &mut scratch.triangles;
        let (tris, by_pixel) = match self.scene.triangles() {
            [] => {
                rebuilt.clear();
                rebuilt.extend((0..end).map(|j| {
                    let hits = if j < placed {
                        &best[j / 8]
                    } else {
                        &g.hits[j / 8]
                    };
                    self.scene.triangle(hits.ids()[j % 8])
                }));
                (rebuilt.as_slice(), true)
            }
            list => (list, false),
        };
        // Colour frames look each pixel's base colour up here, where its triangle is at hand:
        // its material's where colours do not vary across triangles, else at the pixel
        // (vertex colours, textures).
        let colour = self.settings.mode == Mode::Colour;
        let varies = self.scene.colour_varies();
        let materials = self.scene.materials();
        for c in 0..chunks {
            let o = c * w;
            // Pixel `o + l` is lane `at + l` of `hit` (`at` is 0 on eight lanes): a packet of
            // `best` in place, else of `g`.
            let (bi, at) = (o / 8, o % 8);
            let hit = if o < placed { &best[bi] } else { &g.hits[bi] };
            let (ids, bary) = (hit.ids(), hit.barycentrics());
            // (Closures that copy what they use: none is left in memory for the others.)
            let tri = move |l: usize| match by_pixel {
                true => &tris[o + l],
                false => &tris[ids[at + l] as usize],
            };
            let first = tri(0);
            // The pixels are all on one triangle (the common case): its values are splatted,
            // else gathered lane by lane.
            let same = w == 1 || *ids == [ids[0]; 8];
            let v = each3!(|j| each3!(|a| match same {
                true => s.splat(first.v[j][a]),
                false => s.gather(move |l| tri(l).v[j][a]),
            }));
            let normal = each3!(|a| match same {
                true => s.splat(first.normal[a]),
                false => s.gather(move |l| tri(l).normal[a]),
            });
            // The rays' directions: the tile's own lanes in place, else gathered.
            let dir = each3!(|a| match o < placed {
                true => s.load_at(block(&dirs[a], o - at), at),
                false => s.gather(|l| dirs[a][g.idx[o + l] as usize]),
            });
            let b = each3!(|a| s.load_at(&bary[a], at));
            let mut surf = surface(s, v, normal, b, dir);
            if self.smooth {
                // Each pixel's interpolated vertex normal (the triangle's where it has none).
                let ns: [Vec3; 8] = std::array::from_fn(move |l| {
                    let l = l.min(w - 1);
                    let b = [bary[0][at + l], bary[1][at + l], bary[2][at + l]];
                    self.scene
                        .shading_normal(ids[at + l], b)
                        .unwrap_or_else(|| tri(l).normal)
                });
                with_shading(s, &mut surf, each3!(|a| s.gather(|l| ns[l][a])));
                let sh = &mut pts.shading[bi];
                each3!(|a| s.store_at(&mut sh[a], at, surf.shading[a]));
            }
            let (p, err, nn) = (&mut pts.p[bi], &mut pts.err[bi], &mut pts.normal[bi]);
            each3!(|a| {
                s.store_at(&mut p[a], at, surf.p[a]);
                s.store_at(&mut err[a], at, surf.err[a]);
                s.store_at(&mut nn[a], at, surf.normal[a]);
            });
            if colour {
                let rho = if varies {
                    let mut rho = [Vec3::ZERO; 8];
                    for (l, rho) in rho[..w].iter_mut().enumerate() {
                        let b = [bary[0][at + l], bary[1][at + l], bary[2][at + l]];
                        *rho = self.scene.base_colour(ids[at + l], b);
                    }
                    each3!(|a| s.gather(|l| rho[l][a]))
                } else if same {
                    let rho = materials[first.material as usize].colour;
                    each3!(|a| s.splat(rho[a]))
                } else {
                    let mut rho = [Vec3::ZERO; 8];
                    for (l, rho) in rho[..w].iter_mut().enumerate() {
                        *rho = materials[tri(l).material as usize].colour;
                    }
                    each3!(|a| s.gather(|l| rho[l][a]))
                };
                let r = &mut pts.rho[bi];
                each3!(|a| s.store_at(&mut r[a], at, rho[a]));
            }
        }
        let shadows = self.tile_shadows(s);
        self.add_lights(s, pts, m, shadows, &mut scratch.shadows, n);
        let indirect = match self.settings.effects.indirect {
            Indirect::Constant(k) => k,
            _ => 0.0,
        };
        debug_assert!(m <= k);
        let indirect = s.splat(indirect);
        for c in 0..chunks {
            let o = c * w;
            let count = (m - o).min(w);
            let (bi, ai) = (o / 8, o % 8);
            let sum = &pts.sum[bi];
            let sum = each3!(|a| s.load_at(&sum[a], ai));
            let colour = match colour {
                true => {
                    let rho = &pts.rho[bi];
                    let rho = each3!(|a| s.load_at(&rho[a], ai));
                    super::diffuse(s, rho, sum, [indirect; 3])
                }
                false => sum,
            };
            let mut rgb = [[0f32; 8]; 3];
            each3!(|a| s.store(&mut rgb[a], colour[a]));
            let colour = |l: usize| Vec3::new(rgb[0][l], rgb[1][l], rgb[2][l]);
            if count == 8 && o < placed {
                // Eight pixels in place: written in a row.
                for (l, out) in out[o..o + 8].iter_mut().enumerate() {
                    *out = colour(l);
                }
            } else {
                for l in 0..count {
                    let i = match o < placed {
                        true => o + l,
                        false => g.idx[o + l] as usize,
                    };
                    out[i] = colour(l);
                }
            }
        }
        debug_assert!(out.iter().all(|c| c.is_finite()), "non-finite colour");
    }

    /// How this tile's shadow rays are traced on lanes `s`.
    #[inline(always)]
    fn tile_shadows<S: Lanes>(&self, s: S) -> Shadows {
        #[cfg(target_arch = "x86_64")]
        if let (Some(avx2), Some(_)) = (s.avx2(), self.culls()) {
            return Shadows::Packets(avx2);
        }
        let _ = s;
        Shadows::Scene
    }

    /// Direct irradiance at one point, the kernel at width 1 (see [`Tracer::direct`]).
    pub(super) fn direct_at(&self, at: &Surface<f32>, n: &mut RayCounts) -> Vec3 {
        let mut pts = Points::<1>::one(at);
        self.add_lights(
            Scalar,
            &mut pts,
            1,
            Shadows::Scene,
            &mut ShadowScratch::default(),
            n,
        );
        Points::at(&pts.sum, 0)
    }

    /// The sums over the lights at the first `m` points of `pts` (their surfaces computed):
    /// light by light, each point's term where the light
    /// reaches it and no shadow ray is blocked (the tile's shadow rays toward a light traced
    /// together, as `shadows` says).
    #[inline(always)]
    fn add_lights<S: Lanes, const B: usize>(
        &self,
        s: S,
        pts: &mut Points<B>,
        m: usize,
        shadows: Shadows,
        scratch: &mut ShadowScratch,
        n: &mut RayCounts,
    ) {
        let w = S::WIDTH;
        let chunks = m.div_ceil(w);
        for sum in &mut pts.sum[..m.div_ceil(8)] {
            *sum = [[0.0; 8]; 3];
        }
        for (li, light) in self.lights.iter().enumerate() {
            // A dark light adds nothing and traces nothing.
            if light.power == Vec3::ZERO {
                continue;
            }
            let light = Delta::Point(light);
            self.add_light(s, pts, m, light, shadows, li, scratch, n);
        }
        // The other delta lights: no shadow cull of their own, so their rays go through the
        // scene's structure.
        for light in self.scene.directional_lights() {
            if light.irradiance == Vec3::ZERO {
                continue;
            }
            let light = Delta::Directional(light);
            self.add_light(s, pts, m, light, Shadows::Scene, 0, scratch, n);
        }
        for light in self.scene.spot_lights() {
            if light.power == Vec3::ZERO {
                continue;
            }
            let light = Delta::Spot(light);
            self.add_light(s, pts, m, light, Shadows::Scene, 0, scratch, n);
        }
        // Frames that trace no random ray take the environment unshadowed, as the seed's
        // constant N (path-traced ones find it where their rays leave the scene).
        if self.ambient != Vec3::ZERO {
            let e = self.ambient.to_array();
            for c in 0..chunks {
                let (bi, ai) = (c * w / 8, c * w % 8);
                let sum = &mut pts.sum[bi];
                each3!(|a| {
                    let v = s.load_at(&sum[a], ai);
                    s.store_at(&mut sum[a], ai, s.add(v, s.splat(e[a])));
                });
            }
        }
    }

    /// Adds one delta light to the sums of [`Tracer::add_lights`]: its [`Incident`] at each
    /// block of points, the shadow rays of the points it reaches traced together (as `shadows`
    /// says; light `li`'s cull for packets), and its term where nothing blocks.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn add_light<S: Lanes, const B: usize>(
        &self,
        s: S,
        pts: &mut Points<B>,
        m: usize,
        light: Delta,
        shadows: Shadows,
        li: usize,
        scratch: &mut ShadowScratch,
        n: &mut RayCounts,
    ) {
        let w = S::WIDTH;
        let chunks = m.div_ceil(w);
        // The lanes of block `c` that hold a pixel.
        let valid = |c: usize| (1u32 << (m - c * w).min(w)) - 1;
        let (mut lit, mut traced) = (0u64, 0u64);
        for c in 0..chunks {
            let o = c * w;
            let at = pts.surface(s, o, self.smooth);
            // (A match, not a closure: a closure would not be compiled with the kernel's
            // target features, and the lane functions would not inline into it.)
            let (shadows_on, smooth) = (self.settings.effects.shadows, self.smooth);
            let inc = match light {
                Delta::Point(l) => point_light(s, l, self.min_r2, &at, shadows_on, smooth),
                Delta::Directional(l) => {
                    directional_light(s, l, self.reach, &at, shadows_on, smooth)
                }
                Delta::Spot(l) => spot_light(s, l, self.min_r2, &at, shadows_on, smooth),
            };
            let (bi, ai) = (o / 8, o % 8);
            let (term, origin, dir) = (&mut pts.term[bi], &mut pts.origin[bi], &mut pts.dir[bi]);
            each3!(|a| {
                s.store_at(&mut term[a], ai, inc.term[a]);
                s.store_at(&mut origin[a], ai, inc.origin[a]);
                s.store_at(&mut dir[a], ai, inc.dir[a]);
            });
            let on = inc.lit & valid(c);
            lit |= (on as u64) << (c * w);
            traced |= ((inc.traced & on) as u64) << (c * w);
        }
        let mut blocked = 0;
        if self.settings.effects.shadows && traced != 0 {
            n.shadow += traced.count_ones() as u64;
            let t_max = 1.0 - SHADOW_EPSILON;
            blocked = match shadows {
                Shadows::Scene => self.blocked(pts, traced, t_max, scratch),
                #[cfg(target_arch = "x86_64")]
                Shadows::Packets(avx2) => {
                    let cull = &self.culls().expect("a small scene's culls")[li];
                    super::packets::blocked(avx2, cull, pts, m, traced, t_max)
                }
            };
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = li;
        let add = lit & !blocked;
        for c in 0..chunks {
            let on = (add >> (c * w)) as u32 & valid(c);
            if on == 0 {
                continue;
            }
            let on = s.lanes(on);
            let (bi, ai) = (c * w / 8, c * w % 8);
            let (sum, term) = (&mut pts.sum[bi], &pts.term[bi]);
            // The term added where `on`, +0 elsewhere: the same bits as keeping the sum there
            // (a sum starts at +0 and adds terms of +0 or more, so it is never −0, the one
            // value +0 changes). Not `select(on, v + t, v)`: stored back, that blend of the
            // sum's own lanes becomes a masked store (see `F8::store_whole`).
            let zero = s.splat(0.0);
            each3!(|a| {
                let v = s.load_at(&sum[a], ai);
                let t = s.load_at(&term[a], ai);
                s.store_at(&mut sum[a], ai, s.add(v, s.select(on, t, zero)));
            });
        }
    }

    /// Which of the `traced` points' shadow rays (bit per point) are blocked before `t_max`,
    /// through the scene's structure. (Inlined: one ray at a time, [`Tracer::direct_at`] then
    /// needs no zeroed copy of its point's blocks in memory: a GI frame's instructions −4 %.)
    #[inline(always)]
    fn blocked<const B: usize>(
        &self,
        pts: &Points<B>,
        traced: u64,
        t_max: f32,
        scratch: &mut ShadowScratch,
    ) -> u64 {
        let ray = |i: usize| Ray::new(Points::at(&pts.origin, i), Points::at(&pts.dir, i));
        if traced.count_ones() == 1 {
            let i = traced.trailing_zeros() as usize;
            return (self.scene.occluded(&ray(i), t_max) as u64) << i;
        }
        let ShadowScratch { rays, blocked } = scratch;
        rays.clear();
        let mut left = traced;
        while left != 0 {
            rays.push(ray(left.trailing_zeros() as usize));
            left &= left - 1;
        }
        blocked.clear();
        blocked.resize(rays.len(), false);
        self.scene.occluded_each(rays, t_max, blocked);
        let (mut out, mut left) = (0, traced);
        for &b in blocked.iter() {
            let i = left.trailing_zeros();
            left &= left - 1;
            out |= (b as u64) << i;
        }
        out
    }
}
