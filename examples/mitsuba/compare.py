#!/usr/bin/env python3
"""Renders a raytty scene with Mitsuba 3 and compares it with raytty's raw frame.

An independent check of raytty's path tracer: the same triangles (exported by
`cargo run --release --example mitsuba -- SCENE DIR`), the same camera, Mitsuba's `diffuse`
BSDF (two-sided, as raytty shades both sides), point, directional, spot and constant
emitters, a `box` pixel filter and the `path` integrator. Prints both renderers' times and the RMSE and 10x10-block RMSE between
their images (block means: noise averages away in them, a systematic difference does not).

Units. raytty's pixel is rho*E with the diffuse 1/pi dropped (the seed's lab: a point light of
power P gives D = P*max(cos, 0)/(4*pi*r^2)), so raytty's values are pi times radiance. Mitsuba
is given point emitters of intensity P/(4*pi) (W/sr) and its image is multiplied by pi.

Depth. raytty's stage 6 follows a path for up to 16 bounces after the primary hit, each with
next-event estimation at its vertex: the longest path it counts has 18 segments (camera,
primary hit, 16 bounces, light), Mitsuba's `max_depth = 18`.

Timing. Both renderers' CPU time is user + sys over all their threads. Mitsuba's is
mi.render's after a warm-up render (its kernels compiled, or loaded from Dr.Jit's cache: two
1024-spp renders in a row cost the same), without mi.load_dict (scene and BVH, ~0.01 s for
these scenes); raytty's is its whole process (start-up, scene, BVH and the PFM: ~15 ms of CPU
for a 1-spp area frame, 0.1 % of a 1024-spp one). Judged against a reference of Mitsuba's,
each renderer's squared error carries the reference's noise too; the ratio is printed as
measured and with that noise (estimated from Mitsuba's own error) taken out.

Usage (Mitsuba 3 from pip; the llvm variant wants libLLVM, e.g. Debian's libllvm19 with
DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1; scalar_rgb needs nothing):

    cargo build --release --example mitsuba
    target/release/examples/mitsuba cornell /tmp/cornell-mi
    python3 examples/mitsuba/compare.py /tmp/cornell-mi --raytty target/release/raytty \\
        --pixels 160x100 --spp 1024 --variant llvm_ad_rgb
"""

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np


def read_pfm(path):
    """A PFM as an (h, w, 3) array, top row first."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            sys.exit(f"{path}: not a colour PFM")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3)[::-1].astype(np.float64)


def write_pfm(path, img):
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1\n" % (w, h))
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


CLAMP = False


def shown(a):
    """The image as compared: clamped to 0..1 (as a screen shows it) with --clamp."""
    return np.clip(a, 0.0, 1.0) if CLAMP else a


def rmse(a, b):
    a, b = shown(a), shown(b)
    return float(np.sqrt(np.mean((a - b) ** 2)))


def block_rmse(a, b, block=10):
    """RMSE of block x block means (edge blocks smaller), as raytty's bench::metrics."""
    h, w, _ = a.shape
    d = shown(a) - shown(b)
    sq, n = 0.0, 0
    for y in range(0, h, block):
        for x in range(0, w, block):
            m = d[y : y + block, x : x + block].reshape(-1, 3).mean(axis=0)
            sq += float(np.dot(m, m))
            n += 3
    return math.sqrt(sq / n)


def mitsuba_scene(mi, spec, export_dir, width, height, spp, max_depth):
    cam = spec["camera"]
    origin = cam["origin"]
    target = [o + f for o, f in zip(origin, cam["forward"])]
    up = [-d for d in cam["down"]]
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth},
        "sensor": {
            "type": "perspective",
            "fov": cam["fov_degrees"],
            "fov_axis": cam["fov_axis"],
            "to_world": mi.ScalarTransform4f().look_at(origin=origin, target=target, up=up),
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "pixel_format": "rgb",
                "rfilter": {"type": "box"},
            },
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    for i, m in enumerate(spec["materials"]):
        colour = {"type": "rgb", "value": m["colour"]}
        # raytty's layers, bottom up: a diffuse base, glass over it (transmission), metal over
        # that, the seed's mirror on top; each takes its fraction of what is above it leaves.
        bsdf = {"type": "diffuse", "reflectance": colour}
        # Below GGX alpha 1e-3 raytty treats a surface as smooth (material::ggx::SMOOTH_ALPHA).
        alpha = m.get("roughness", 0.0) ** 2
        smooth = alpha < 1e-3
        if m.get("transmission", 0.0) > 0:
            glass = {"type": "dielectric" if smooth else "roughdielectric", "int_ior": m["ior"],
                     "ext_ior": 1.0, "specular_transmittance": colour}
            if not smooth:
                glass.update({"distribution": "ggx", "alpha": alpha})
            bsdf = glass if m["transmission"] >= 1 else {
                "type": "blendbsdf", "weight": m["transmission"], "a": bsdf, "b": glass}
        if m.get("metal", 0.0) > 0:
            # F = the colour at every angle ('none' is F = 1, times specular_reflectance);
            # raytty's Schlick term rises toward 1 at grazing angles only.
            metal = {"type": "conductor" if smooth else "roughconductor", "material": "none",
                     "specular_reflectance": colour}
            if not smooth:
                metal.update({"distribution": "ggx", "alpha": alpha})
            bsdf = metal if m["metal"] >= 1 else {
                "type": "blendbsdf", "weight": m["metal"], "a": bsdf, "b": metal}
        if m["mirror"] > 0:
            # raytty: (1 - mirror)*the rest + mirror*perfect reflection.
            bsdf = {
                "type": "blendbsdf",
                "weight": m["mirror"],
                "a": bsdf,
                "b": {"type": "conductor", "material": "none"},
            }
        shape = {
            "type": "obj",
            "filename": os.path.join(export_dir, m["obj"]),
            "face_normals": True,
            # Glass has two sides of its own; the rest shade both sides alike.
            "bsdf": bsdf if m.get("transmission", 0.0) > 0 else {"type": "twosided", "bsdf": bsdf},
        }
        if max(m.get("emission", [0, 0, 0])) > 0:
            # raytty's emission is what the camera sees, pi times radiance.
            shape["emitter"] = {"type": "area", "radiance": {
                "type": "rgb", "value": [e / math.pi for e in m["emission"]]}}
        scene[f"shape{i}"] = shape
    for i, light in enumerate(spec["lights"]):
        scene[f"light{i}"] = {
            "type": "point",
            "position": light["position"],
            "intensity": {"type": "rgb", "value": [p / (4 * math.pi) for p in light["power"]]},
        }
    # A directional light's irradiance is the same number in both (raytty's pixel is rho*E;
    # Mitsuba's radiance rho*E/pi, times pi); both take the direction the light travels.
    for i, light in enumerate(spec.get("directional", [])):
        scene[f"sun{i}"] = {
            "type": "directional",
            "direction": light["direction"],
            "irradiance": {"type": "rgb", "value": light["irradiance"]},
        }
    # A spot: the intensity on its axis is the power over 4 pi, as a point light's. Mitsuba's
    # own falloff is linear in the angle; raytty's is glTF's (t^2, t linear in the cosine), so
    # Mitsuba gets a hard cone at the outer angle times a texture of raytty's falloff
    # (projected along the spot: u, v span tan(outer) either side of the axis).
    for i, light in enumerate(spec.get("spots", [])):
        pos, d = light["position"], light["direction"]
        up = [0, 0, 1] if abs(d[2]) < 0.9 else [1, 0, 0]
        spot = {
            "type": "spot",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=pos, target=[p + q for p, q in zip(pos, d)], up=up),
            "intensity": {"type": "rgb", "value": [p / (4 * math.pi) for p in light["power"]]},
            "cutoff_angle": math.degrees(light["outer"]),
            "beam_width": math.degrees(light["outer"]),
        }
        if light["inner"] < light["outer"]:
            spot["texture"] = {
                "type": "bitmap",
                "bitmap": mi.Bitmap(spot_falloff(light["inner"], light["outer"])),
                "raw": True,
                "filter_type": "bilinear",
                "wrap_mode": "clamp",
            }
        scene[f"spot{i}"] = spot
    # The environment: raytty's value is what the camera sees, pi times radiance.
    env = spec.get("environment", [0, 0, 0])
    if max(env) > 0:
        scene["environment"] = {
            "type": "constant",
            "radiance": {"type": "rgb", "value": [e / math.pi for e in env]},
        }
    return scene


def spot_falloff(inner, outer, n=1024):
    """raytty's spot falloff as an n x n RGB image over the plane one unit along the axis."""
    x = ((np.arange(n) + 0.5) / n * 2 - 1) * math.tan(outer)
    xx, yy = np.meshgrid(x, x)
    cos = 1 / np.sqrt(1 + xx * xx + yy * yy)
    ci, co = math.cos(inner), math.cos(outer)
    t = np.clip((cos - co) / (ci - co), 0, 1)
    return np.repeat((t * t)[:, :, None], 3, axis=2).astype(np.float32)


def render_raytty(binary, scene, width, height, spp, out):
    cmd = [
        binary, "render", "--scene", scene, "--stage", "gi", "--pixels", f"{width}x{height}",
        "--samples", str(spp), "--denoise", "off", "--format", "pfm", "-o", out,
        "--stats=json",
    ]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    stats = json.loads(done.stderr.strip().splitlines()[-1])
    return read_pfm(out), wall, stats["ms"] / 1e3, cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("export_dir", help="the directory the mitsuba example wrote")
    ap.add_argument("--raytty", default="target/release/raytty", help="the raytty binary")
    ap.add_argument("--pixels", default="160x100")
    ap.add_argument("--spp", type=int, default=256, help="samples per pixel, both renderers")
    ap.add_argument("--mitsuba-ref-spp", type=int, default=0,
                    help="also render a Mitsuba reference with this many samples and judge "
                         "both equal-sample frames against it (with --mitsuba-ref: that "
                         "file's samples)")
    ap.add_argument("--mitsuba-ref",
                    help="judge both equal-sample frames against this Mitsuba PFM (one an "
                         "earlier --mitsuba-ref-spp run wrote) instead of rendering one")
    ap.add_argument("--raytty-ref", help="a high-sample raytty PFM to compare Mitsuba's with")
    ap.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (llvm_ad_rgb, ...)")
    ap.add_argument("--max-depth", type=int, default=18)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--clamp", action="store_true",
                    help="compare images clamped to 0..1, as shown (scenes whose lights are "
                         "in view)")
    args = ap.parse_args()
    global CLAMP
    CLAMP = args.clamp

    import drjit as dr
    import mitsuba as mi

    mi.set_variant(args.variant)
    width, height = map(int, args.pixels.split("x"))
    with open(os.path.join(args.export_dir, "scene.json")) as f:
        spec = json.load(f)
    name = spec["scene"]

    def render_mitsuba(spp, seed):
        scene = mi.load_dict(mitsuba_scene(mi, spec, args.export_dir, width, height, spp,
                                           args.max_depth))
        start, cpu = time.perf_counter(), time.process_time()
        img = mi.render(scene, spp=spp, seed=seed)
        dr.eval(img)
        img = np.array(img, dtype=np.float64)[:, :, :3] * math.pi
        return img, time.perf_counter() - start, time.process_time() - cpu

    # The first llvm render compiles its kernels: time a second one.
    render_mitsuba(4, args.seed + 1000)
    mi_img, mi_time, mi_cpu = render_mitsuba(args.spp, args.seed)
    write_pfm(os.path.join(args.export_dir, f"mitsuba-{args.spp}.pfm"), mi_img)
    rt_img, rt_wall, rt_ms, rt_cpu = render_raytty(
        args.raytty, name, width, height, args.spp,
        os.path.join(args.export_dir, f"raytty-{args.spp}.pfm"))
    print(f"scene {name}, {width}x{height}, {args.spp} spp, Mitsuba {mi.__version__} "
          f"{args.variant}, max_depth {args.max_depth}")
    print(f"  raytty:  {rt_ms:.3f} s rendering ({rt_wall:.3f} s whole process, "
          f"{rt_cpu:.3f} s CPU)")
    print(f"  Mitsuba: {mi_time:.3f} s (mi.render, kernels already compiled; {mi_cpu:.3f} s "
          f"CPU)")
    print(f"  raytty vs Mitsuba, same spp: RMSE {rmse(rt_img, mi_img):.5f}, "
          f"block RMSE {block_rmse(rt_img, mi_img):.5f}; means {rt_img.mean(axis=(0, 1))} "
          f"vs {mi_img.mean(axis=(0, 1))}")
    if args.raytty_ref:
        ref = read_pfm(args.raytty_ref)
        print(f"  Mitsuba {args.spp} spp vs raytty reference: RMSE {rmse(mi_img, ref):.5f}, "
              f"block RMSE {block_rmse(mi_img, ref):.5f}")
        print(f"  raytty {args.spp} spp vs raytty reference: RMSE {rmse(rt_img, ref):.5f}, "
              f"block RMSE {block_rmse(rt_img, ref):.5f}")
    if args.mitsuba_ref_spp or args.mitsuba_ref:
        if args.mitsuba_ref:
            ref = read_pfm(args.mitsuba_ref)
            print(f"  Mitsuba reference {args.mitsuba_ref}:")
        else:
            ref, ref_time, _ = render_mitsuba(args.mitsuba_ref_spp, args.seed + 1)
            write_pfm(os.path.join(args.export_dir, f"mitsuba-{args.mitsuba_ref_spp}.pfm"), ref)
            print(f"  Mitsuba reference, {args.mitsuba_ref_spp} spp ({ref_time:.1f} s):")
        cost = {}
        for who, img, t in [("raytty", rt_img, rt_cpu), ("Mitsuba", mi_img, mi_cpu)]:
            e = rmse(img, ref)
            cost[who] = (t, e * e)
            print(f"    {who:8} {args.spp} spp: RMSE {e:.5f}, block RMSE "
                  f"{block_rmse(img, ref):.5f}, CPU time x RMSE^2 {t * e * e:.3e}")
        (rt_t, rt_e2), (mi_t, mi_e2) = cost["raytty"], cost["Mitsuba"]
        print(f"    CPU time x RMSE^2, raytty / Mitsuba: {rt_t * rt_e2 / (mi_t * mi_e2):.3f}")
        if args.mitsuba_ref_spp:
            # The reference's own noise is in both squared errors: Mitsuba's at spp is
            # v(1 + spp/ref_spp) with v its variance at spp, the reference's v·spp/ref_spp.
            # Subtracted (values clamped, so only nearly exact), the ratio of the renderers.
            r = args.spp / args.mitsuba_ref_spp
            noise = mi_e2 * r / (1 + r)
            print(f"    the same, the reference's noise ({math.sqrt(noise):.5f} RMSE) taken out: "
                  f"{rt_t * (rt_e2 - noise) / (mi_t * (mi_e2 - noise)):.3f}")
        if args.raytty_ref:
            rref = read_pfm(args.raytty_ref)
            print(f"    the two references: RMSE {rmse(rref, ref):.5f}, block RMSE "
                  f"{block_rmse(rref, ref):.5f}")


if __name__ == "__main__":
    main()
