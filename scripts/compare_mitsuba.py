#!/usr/bin/env python3
"""irpol's polarized path integrator against Mitsuba 3's polarized path tracer.

Run by hand (not in CI); it needs Mitsuba 3 (see scripts/mitsuba_requirements.txt) and a release
build of irpol:

    python3 -m venv /tmp/mitsuba-venv
    /tmp/mitsuba-venv/bin/pip install -r scripts/mitsuba_requirements.txt
    nice -n 10 /tmp/mitsuba-venv/bin/python scripts/compare_mitsuba.py [--irpol target/release/irpol]

The scene: a glossy metal sphere (Gaussian σ = 0.15, N = 3 + 20i) just above a glossy square ground
(σ = 0.2, N = 1.5 + 0.1i), both reflection only (ρ_d = 0, Smith shadowing, temperature 1 K so that
L_bb(1 K) = 0 in the 8–14 µm band: hc/(λkT) ≈ 1439 at 10 µm), lit by an unpolarized environment that
depends on elevation only: a sky table in radiance, and below the horizon irpol's ground radiance
ε_g L_bb(T_g) + (1 − ε_g) E_sky/π (src/scene/environment.rs), here with T_g = 1 K, ε_g = 0.2.

How the two are made to describe the same thing:
- Environment. irpol samples the sky table at u = sin(elevation) = i/1024 (linear in elevation between
  the table's knots) and interpolates linearly in u; E_sky/π = 2∫ L u du by the trapezoid rule on that
  grid. The script reproduces both exactly and writes Mitsuba's `envmap` as a latitude–longitude
  bitmap of that radiance (constant along each row). Mitsuba places row j at polar angle π j/(H − 1)
  (rows on the poles, bilinear in between; see envmap.cpp eval_spectrum), so the value of row j is
  irpol's radiance at u = cos(π j/(H − 1)); with H even no row falls on the horizon and the sky/ground
  jump becomes a ramp one row (180°/(H − 1)) wide. The map's +Y (its zenith) is turned onto world +z.
- Materials. Mitsuba `roughconductor`, distribution "beckmann", alpha = √2 σ, eta = n, k = k. Its
  Smith G1 is Walter's rational approximation (< 0.35 %); irpol's is exact.
- Geometry. The same icosphere (irpol's construction is repeated here and written as a PLY with the
  exact radial vertex normals) and a `rectangle` for the plane.
- Camera. `perspective`, fov_axis = 'y', to_world = look_at(position, look_at, up), a box pixel
  filter. Mitsuba averages each pixel's area; irpol shades the pixel centre, so region masks keep only
  pixels that lie wholly inside one region.
- Transport depth. irpol `bounces` = B follows B inter-reflections and takes the open-world value at
  the next vertex; Mitsuba `path` gets max_depth = B + 2 (Russian roulette from depth 5, unbiased).
- Stokes frames. Mitsuba's `stokes` integrator rotates each sample's Stokes vector to the basis
  x_m = d × v (d: camera ray, v: the camera's up axis), propagation −d, and its convention has the
  +45° axis at f × x for propagation f (mueller::rotator and rotate_stokes_basis). irpol's pixel frame
  is x_pix = image right made perpendicular to the ray, y_pix = ω × x_pix with ω = −d: the same
  handedness, so S_irpol = L(ψ) S_mitsuba with ψ the signed angle from x_m to x_pix about −d
  (S1' = cos2ψ S1 + sin2ψ S2, S2' = −sin2ψ S1 + cos2ψ S2), S0 unchanged.
- S3. Mitsuba's fresnel_polarized conjugates N = n + ik to n − ik (the exp(+iωt) convention), so its
  r_s, r_p are the complex conjugates of irpol's (docs/design.md §1.3, exp(−iωt)): every Mueller matrix has the
  signs of its S3 row and column flipped, M_mitsuba = D M_irpol D with D = diag(1, 1, 1, −1), and
  S3_irpol = −S3_mitsuba. The script checks this at the BRDF level before it compares images: it
  evaluates both BRDFs (`irpol eval` and Mitsuba's bsdf.eval, rotated into the psps frames) at a few
  geometries, including +45° linear light specularly reflected off the metal.

Regions: sphere upper and lower half, ground within 1.8 R of the sphere's axis ("near": its shadow,
its reflection and the inter-reflection), ground beyond 3.5 R ("far"), and, as a check of the
environment map, the sky and the environment's ground seen directly. Only pixels wholly inside a
region count. A mirror (the scene is symmetric about the vertical plane through the camera and the
sphere's axis, which projects onto the image's centre column) flips S2 and S3, so their region
means vanish by symmetry; the rows "S2 odd" and "S3 odd" compare ⟨S · sgn(column − centre)⟩ instead.

Noise and timing: each renderer runs `--passes` independent passes (irpol: one process per seed;
Mitsuba: one mi.render per seed). Per-pixel standard errors come from the spread between passes, and a
region mean's standard error from their sum (pixels are independent). irpol is timed as whole
processes; Mitsuba as its mi.render calls (scene loading reported apart; the first pass includes JIT
compilation in the llvm variants), both in wall-clock and CPU seconds (on a shared machine the CPU
time is the steadier). The time ratio is given raw and at equal noise (T σ² per renderer, σ² the
mean per-pixel S0 variance over the four surface regions).

Diagnostics (not needed for the comparison itself):
- `--irpol-supersample N` renders irpol at N× the resolution and averages N×N blocks, a box-filtered
  pixel like Mitsuba's. irpol shades each pixel's centre; where a Stokes component varies quickly
  (S3 and S2 near the sphere's silhouette) region means then differ by more than the noise.
- `--sphere-only` leaves out the ground: irpol is then its open-world tables alone (noise-free).
- `--quadrature K` integrates the exact open-world value (scripts/pbrdf_numpy.py's BRDF, exact
  Smith) at K pixels of each region where no irpol correction ray hit geometry, and prints irpol
  (its tables) and Mitsuba against it, with the effect of Mitsuba's approximate Smith G1.

Output: a table on stdout, /tmp/mitsuba_compare.png (S0, DoLP and S3 of both and their difference)
and the images under --work. Exit 0 when S0 region means agree within --tolerance (relative, default
1 %) and S1, S2, S3 region means and the odd parts within 4 combined standard errors (or 0.2 % of
S0), 1 otherwise (or when the irpol binary changed during the run).
"""

import argparse
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

# ----------------------------------------------------------------------------------------------
# The scene, once, for both renderers.

SCENE = {
    "camera": {
        "position": [4.4, -5.2, 2.3],
        "look_at": [0.0, 0.0, 0.75],
        "up": [0.0, 0.0, 1.0],
        "fov_deg": 30.0,
    },
    # Sky radiance (W m-2 sr-1, band-integrated) against elevation; ground below the horizon.
    "sky_elevation_deg": [0.0, 5.0, 15.0, 30.0, 60.0, 90.0],
    "sky_radiance": [31.0, 27.0, 21.0, 16.5, 12.5, 11.0],
    "ground_temperature_k": 1.0,
    "ground_emissivity": 0.2,
    "object_temperature_k": 1.0,
    "sphere": {"radius": 1.0, "subdivisions": 5, "center": [0.0, 0.0, 1.02],
               "material": {"sigma": 0.15, "n": 3.0, "k": 20.0}},
    "plane": {"size": [12.0, 12.0],
              "material": {"sigma": 0.2, "n": 1.5, "k": 0.1}},
    # irpol's lobe samples per path at the visible point (`[render] first_bounce_samples`).
    "first_bounce_samples": 4,
}

SKY_SAMPLES = 1025  # irpol's u grid (src/scene/environment.rs)


def sky_table(elevation_deg):
    """The sky table, linear in elevation between the knots (irpol's `interpolate`)."""
    knots_e = np.asarray(SCENE["sky_elevation_deg"], float)
    knots_l = np.asarray(SCENE["sky_radiance"], float)
    return np.interp(elevation_deg, knots_e, knots_l)


def irpol_sky_samples():
    u = np.arange(SKY_SAMPLES) / (SKY_SAMPLES - 1)
    return sky_table(np.degrees(np.arcsin(np.clip(u, 0.0, 1.0))))


def irpol_ground_radiance():
    """ε L_bb(T_g) + (1 − ε) E_sky/π with irpol's trapezoid rule; L_bb(1 K) = 0."""
    sky = irpol_sky_samples()
    h = 1.0 / (SKY_SAMPLES - 1)
    u = np.arange(SKY_SAMPLES) * h
    e_over_pi = float(np.sum((sky[:-1] * u[:-1] + sky[1:] * u[1:]) * h))
    assert SCENE["ground_temperature_k"] <= 2.0, "L_bb(T_g) is taken as 0"
    return (1.0 - SCENE["ground_emissivity"]) * e_over_pi


def irpol_env_radiance(u):
    """irpol's Environment::radiance_at_sine, vectorized over u = sin(elevation)."""
    u = np.asarray(u, float)
    sky = irpol_sky_samples()
    x = np.minimum(u, 1.0) * (SKY_SAMPLES - 1)
    i = np.clip(np.floor(np.maximum(x, 0.0)).astype(int), 0, SKY_SAMPLES - 2)
    f = x - i
    value = sky[i] + f * (sky[i + 1] - sky[i])
    return np.where(u < 0.0, irpol_ground_radiance(), value)


def scene_toml(width, height, bounces, samples, seed):
    s, p = SCENE["sphere"], SCENE["plane"]
    c = SCENE["camera"]
    f = lambda v: "[" + ", ".join(repr(float(x)) for x in v) + "]"
    return f"""# Written by scripts/compare_mitsuba.py: the Mitsuba comparison scene.
[camera]
position = {f(c["position"])}
look_at = {f(c["look_at"])}
up = {f(c["up"])}
fov_deg = {c["fov_deg"]!r}
resolution = [{width}, {height}]

[environment]
air_temperature_k = 1.0
sky = {{ model = "table", elevation_deg = {f(SCENE["sky_elevation_deg"])}, radiance = {f(SCENE["sky_radiance"])} }}
ground = {{ temperature_k = {SCENE["ground_temperature_k"]!r}, emissivity = {SCENE["ground_emissivity"]!r} }}

[render]
shading = "pixel"
bounces = {bounces}
samples = {samples}
first_bounce_samples = {SCENE["first_bounce_samples"]}
seed = {seed}

[materials.metal]
distribution = "gaussian"
sigma = {s["material"]["sigma"]!r}
n = {s["material"]["n"]!r}
k = {s["material"]["k"]!r}
rho_d = 0.0
shadowing = "smith"

[materials.ground]
distribution = "gaussian"
sigma = {p["material"]["sigma"]!r}
n = {p["material"]["n"]!r}
k = {p["material"]["k"]!r}
rho_d = 0.0
shadowing = "smith"

[[objects]]
name = "sphere"
shape = {{ kind = "sphere", radius = {s["radius"]!r}, subdivisions = {s["subdivisions"]} }}
material = "metal"
temperature_k = {SCENE["object_temperature_k"]!r}
translate = {f(s["center"])}

""" + ("" if not plane_enabled() else f"""
[[objects]]
name = "ground"
shape = {{ kind = "plane", size = {f(p["size"])}, divisions = [1, 1] }}
material = "ground"
temperature_k = {SCENE["object_temperature_k"]!r}
""")


def plane_enabled():
    return min(SCENE["plane"]["size"]) > 0.0


def icosphere(radius, subdivisions):
    """irpol's procedural icosphere (src/scene/procedural.rs): vertices, radial normals, faces."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    pos = [np.array(p, float) / np.linalg.norm(p) for p in [
        [-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
        [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]]
    faces = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
             [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
             [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    for _ in range(subdivisions):
        cache = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = pos[a] + pos[b]
                pos.append(m / np.linalg.norm(m))
                cache[key] = len(pos) - 1
            return cache[key]

        nxt = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            nxt += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        faces = nxt
    normals = np.array(pos)
    return normals * radius, normals, np.array(faces, np.int32)


def write_ply(path, vertices, normals, faces):
    vert = np.empty(len(vertices), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                                          ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")])
    for i, name in enumerate("xyz"):
        vert[name] = vertices[:, i]
        vert["n" + name] = normals[:, i]
    face = np.empty(len(faces), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    face["n"] = 3
    face["i"] = faces
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as out:
        out.write(header.encode("ascii"))
        out.write(vert.tobytes())
        out.write(face.tobytes())


# ----------------------------------------------------------------------------------------------
# Camera rays and region masks (analytic sphere and plane, in numpy).

def camera_frame():
    c = SCENE["camera"]
    pos = np.array(c["position"], float)
    forward = np.array(c["look_at"], float) - pos
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.array(c["up"], float))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    return pos, forward, right, up


def ray_directions(width, height, px, py):
    """irpol's Camera::ray_direction at continuous pixel coordinates (x right, y down)."""
    _, forward, right, up = camera_frame()
    ty = math.tan(math.radians(SCENE["camera"]["fov_deg"]) / 2.0)
    tx = ty * width / height
    ndc_x = 2.0 * px / width - 1.0
    ndc_y = 1.0 - 2.0 * py / height
    d = forward + right * (ndc_x * tx)[..., None] + up * (ndc_y * ty)[..., None]
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


REGIONS = ["sphere upper", "sphere lower", "ground near", "ground far", "sky (env)",
           "env ground"]


def classify(width, height, px, py):
    """Region index (REGIONS; −1 = none) of the closest hit along the rays through (px, py)."""
    origin = camera_frame()[0]
    d = ray_directions(width, height, px, py)
    s = SCENE["sphere"]
    center, radius = np.array(s["center"]), s["radius"]
    oc = origin - center
    b = d @ oc
    disc = b * b - (oc @ oc - radius * radius)
    t_sphere = np.where(disc > 0.0, -b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
    t_sphere = np.where(t_sphere > 0.0, t_sphere, np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_plane = np.where(d[..., 2] < 0.0, -origin[2] / d[..., 2], np.inf)
    hit_p = origin + d * np.where(np.isfinite(t_plane), t_plane, 0.0)[..., None]
    half = np.array(SCENE["plane"]["size"]) / 2.0
    on_plane = (np.abs(hit_p[..., 0]) < half[0]) & (np.abs(hit_p[..., 1]) < half[1])
    t_plane = np.where(on_plane, t_plane, np.inf)
    region = np.full(d.shape[:-1], -1, int)
    sphere_first = t_sphere < t_plane
    hit_s = origin + d * np.where(np.isfinite(t_sphere), t_sphere, 0.0)[..., None]
    upper = hit_s[..., 2] > center[2]
    region[sphere_first & np.isfinite(t_sphere) & upper] = 0
    region[sphere_first & np.isfinite(t_sphere) & ~upper] = 1
    ground = ~sphere_first & np.isfinite(t_plane)
    rho = np.hypot(hit_p[..., 0] - center[0], hit_p[..., 1] - center[1])
    margin = 0.5
    inner = (np.abs(hit_p[..., 0]) < half[0] - margin) & (np.abs(hit_p[..., 1]) < half[1] - margin)
    region[ground & (rho < 1.8 * radius)] = 2
    region[ground & (rho > 3.5 * radius) & inner] = 3
    nohit = ~np.isfinite(t_sphere) & ~np.isfinite(t_plane)
    # Keep the background half a degree away from the horizon (the envmap's ramp, and irpol's jump).
    elevation = np.degrees(np.arcsin(np.clip(d[..., 2], -1, 1)))
    region[nohit & (elevation > 0.5)] = 4
    region[nohit & (elevation < -0.5)] = 5
    return region


def region_masks(width, height, sub=5):
    """Pixels wholly inside one region: every point of a sub×sub grid (edges included) agrees."""
    ys, xs = np.mgrid[0:height, 0:width]
    offsets = np.linspace(0.0, 1.0, sub)
    first = None
    agree = np.ones((height, width), bool)
    for oy in offsets:
        for ox in offsets:
            r = classify(width, height, xs + ox, ys + oy)
            if first is None:
                first = r
            else:
                agree &= r == first
    centre = classify(width, height, xs + 0.5, ys + 0.5)
    return {name: agree & (centre == i) & (first == i) for i, name in enumerate(REGIONS)}


def mitsuba_to_pixel_frame_angle(width, height):
    """ψ: signed angle from Mitsuba's Stokes x axis (d × v) to irpol's x_pix about −d, per pixel."""
    _, _, right, up = camera_frame()
    ys, xs = np.mgrid[0:height, 0:width]
    d = ray_directions(width, height, xs + 0.5, ys + 0.5)
    x_m = np.cross(d, up)
    x_m /= np.linalg.norm(x_m, axis=-1, keepdims=True)
    x_pix = right - d * (d @ right)[..., None]
    x_pix /= np.linalg.norm(x_pix, axis=-1, keepdims=True)
    f = -d
    sin = np.einsum("...i,...i", np.cross(x_m, x_pix), f)
    cos = np.einsum("...i,...i", x_m, x_pix)
    return np.arctan2(sin, cos)


def rotate_stokes(stokes, psi):
    """L(ψ) on (..., 4, H, W): S1' = c S1 + s S2, S2' = −s S1 + c S2 (irpol's rotate_stokes)."""
    c, s = np.cos(2 * psi), np.sin(2 * psi)
    out = stokes.copy()
    out[..., 1, :, :] = c * stokes[..., 1, :, :] + s * stokes[..., 2, :, :]
    out[..., 2, :, :] = -s * stokes[..., 1, :, :] + c * stokes[..., 2, :, :]
    return out


# ----------------------------------------------------------------------------------------------
# Mitsuba.

def choose_variant(mi, requested):
    if requested:
        mi.set_variant(requested)
        return requested
    # Dr.Jit falls back on any libLLVM it finds; one older than 16 aborts the process while
    # compiling (LLVM ERROR: Cannot select ... fmaximum), which no exception catches.
    llvm_ok = "DRJIT_LIBLLVM_PATH" in os.environ
    for v in ["scalar_mono_polarized", "llvm_ad_mono_polarized", "scalar_rgb_polarized",
              "scalar_spectral_polarized"]:
        if v.startswith("llvm") and not llvm_ok:
            print(f"  (variant {v} skipped: no libLLVM 16-19 found; see mitsuba_requirements.txt)")
            continue
        if v in mi.variants():
            try:
                mi.set_variant(v)
                return v
            except Exception as e:  # llvm without a usable libLLVM
                print(f"  (variant {v} unusable: {str(e).splitlines()[0]})")
    raise SystemExit("no polarized Mitsuba variant is usable")


def find_libllvm():
    for version in (19, 18, 17, 16):
        for path in (f"/usr/lib/x86_64-linux-gnu/libLLVM-{version}.so",
                     f"/usr/lib/llvm-{version}/lib/libLLVM.so",
                     f"/usr/lib/llvm-{version}/lib/libLLVM-{version}.so"):
            if os.path.exists(path):
                return path
    return None


def envmap_bitmap(mi, height=4096, width=16):
    theta = math.pi * np.arange(height) / (height - 1)
    row = irpol_env_radiance(np.cos(theta)).astype(np.float32)
    data = np.repeat(np.repeat(row[:, None, None], width, axis=1), 3, axis=2)
    return mi.Bitmap(np.ascontiguousarray(data), mi.Bitmap.PixelFormat.RGB)


def rough_conductor(material):
    return {"type": "roughconductor", "distribution": "beckmann",
            "alpha": math.sqrt(2.0) * material["sigma"],
            "eta": material["n"], "k": material["k"]}


def mitsuba_scene_base(mi, work, width, height, bounces, spp, sampler):
    """What every comparison scene shares: the stokes(path) integrator, the camera and the
    icosphere's PLY (written into `work`). Returns the scene dict without emitters or shapes, and
    the PLY's path."""
    T = mi.ScalarTransform4f
    s, c = SCENE["sphere"], SCENE["camera"]
    ply = Path(work) / "icosphere.ply"
    v, n, f = icosphere(s["radius"], s["subdivisions"])
    write_ply(ply, v + np.array(s["center"]), n, f)
    return {
        "type": "scene",
        "integrator": {"type": "stokes",
                       "inner": {"type": "path", "max_depth": bounces + 2, "rr_depth": 5}},
        "sensor": {
            "type": "perspective",
            "fov": c["fov_deg"],
            "fov_axis": "y",
            "to_world": T().look_at(origin=c["position"], target=c["look_at"], up=c["up"]),
            "film": {"type": "hdrfilm", "width": width, "height": height,
                     "rfilter": {"type": "box"}, "pixel_format": "luminance"},
            "sampler": {"type": sampler, "sample_count": spp},
        },
    }, ply


def mitsuba_scene(mi, work, width, height, bounces, spp, sampler="independent"):
    T = mi.ScalarTransform4f
    s, p = SCENE["sphere"], SCENE["plane"]
    scene, ply = mitsuba_scene_base(mi, work, width, height, bounces, spp, sampler)
    return mi.load_dict({
        **scene,
        "sky": {"type": "envmap", "bitmap": envmap_bitmap(mi),
                "to_world": T().rotate([1.0, 0.0, 0.0], 90.0)},
        "sphere": {"type": "ply", "filename": str(ply), "face_normals": False,
                   "bsdf": rough_conductor(s["material"])},
        **({"ground": {"type": "rectangle",
                       "to_world": T().scale([p["size"][0] / 2.0, p["size"][1] / 2.0, 1.0]),
                       "bsdf": rough_conductor(p["material"])}} if plane_enabled() else {}),
    })


def mitsuba_stokes(mi, scene, spp, seed):
    """One pass: (4, H, W) float64 Stokes in Mitsuba's sensor basis, and its (wall, CPU) time."""
    start, cpu = time.perf_counter(), time.process_time()
    mi.render(scene, spp=spp, seed=seed)
    film = scene.sensors()[0].film()
    bitmap = film.bitmap(raw=False)
    elapsed = (time.perf_counter() - start, time.process_time() - cpu)
    channels = dict(bitmap.split())
    out = []
    for j in range(4):
        arr = np.array(channels[f"S{j}"], copy=False)
        out.append(arr @ LUMINANCE if arr.ndim == 3 else arr)
    return np.array(out, np.float64), elapsed


# The stokes integrator's channels are sRGB (S0.R, S0.G, S0.B). A spectral variant converts each
# sample's spectrum to sRGB, and a flat spectrum v becomes (1.206, 0.949, 0.910) v on average (the
# equal-energy white in sRGB), not v; its luminance (Mitsuba's own weights, which sum to 1) is
# 1.0010 v (Mitsuba 3.9.1, scalar_spectral_polarized, a constant emitter seen directly).
# In mono and RGB variants with a grey scene the three channels are equal and this is R.
LUMINANCE = np.array([0.212671, 0.715160, 0.072169])


def mueller_brdf_mitsuba(mi, material, w_i, w_r):
    """Mitsuba's roughconductor as a Mueller BRDF (sr⁻¹) in irpol's psps frames (docs/design.md §1.3)."""
    vec = lambda v: mi.Vector3f(*[float(x) for x in v])
    w_i, w_r = np.asarray(w_i, float), np.asarray(w_r, float)
    bsdf = mi.load_dict(rough_conductor(material))
    si = mi.SurfaceInteraction3f()
    si.sh_frame = mi.Frame3f(vec([0.0, 0.0, 1.0]))
    si.n = mi.Normal3f(0.0, 0.0, 1.0)
    si.wi = vec(w_r)  # toward the camera (irpol's ω_r)
    # Toward the light (irpol's ω_i); the light travels along −ω_i.
    m = bsdf.eval(mi.BSDFContext(), si, vec(w_i))
    z = np.array([0.0, 0.0, 1.0])
    s_in = np.cross(z, -w_i)   # psps: s = unit(ẑ × k), k_in = −ω_i, k_out = ω_r
    s_out = np.cross(z, w_r)
    m = mi.mueller.rotate_mueller_basis(
        m, vec(-w_i), mi.mueller.stokes_basis(vec(-w_i)), vec(s_in / np.linalg.norm(s_in)),
        vec(w_r), mi.mueller.stokes_basis(vec(w_r)), vec(s_out / np.linalg.norm(s_out)))
    arr = np.array([[np.asarray(m[r, c]).ravel()[0] for c in range(4)] for r in range(4)],
                   np.float64)
    return arr / w_i[2]  # bsdf.eval includes cos θ of the light direction


def direction(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


def brdf_check(mi, irpol, work):
    """irpol eval against Mitsuba's bsdf.eval; returns (S3 sign, max relative deviation)."""
    geometries = [(45, 0, 45, 180), (45, 0, 50, 160), (30, 0, 35, 200), (60, 10, 55, 170),
                  (20, 0, 40, 150)]
    csv = work / "geometry.csv"
    csv.write_text("theta_i_deg,theta_r_deg,phi_i_deg,phi_r_deg\n"
                   + "".join(f"{a},{b},{c},{d}\n" for a, c, b, d in
                             [(g[0], g[1], g[2], g[3]) for g in geometries]))
    D = np.diag([1.0, 1.0, 1.0, -1.0])
    worst = 0.0
    signs = []
    print("BRDF check: irpol eval vs Mitsuba roughconductor (Beckmann α = √2σ), psps frames")
    print(f"  {'material':8} {'θi φi θr φr':>16} {'m00 irpol':>11} {'m00 mi/irpol':>12} "
          f"{'max|ΔM|/m00 (D M D)':>20} {'S3/S0 of +45° in: irpol':>24} {'mitsuba':>8}")
    for name, material in (("metal", SCENE["sphere"]["material"]),
                           ("ground", SCENE["plane"]["material"])):
        out = subprocess.run(
            [irpol, "eval", "--distribution", "gaussian", "--sigma", str(material["sigma"]),
             "--n", str(material["n"]), "--k", str(material["k"]), "--shadowing", "smith",
             "--geometry", str(csv)], check=True, capture_output=True, text=True).stdout
        # `irpol eval` starts with `#` lines naming the model (CSV comments).
        lines = [l for l in out.strip().splitlines() if not l.startswith("#")]
        header = lines[0].split(",")
        for line, (ti, pi, tr, pr) in zip(lines[1:], geometries):
            row = dict(zip(header, map(float, line.split(","))))
            m_ir = np.array([[row[f"m{r}{c}"] for c in range(4)] for r in range(4)])
            m_mi = mueller_brdf_mitsuba(mi, material, direction(ti, pi), direction(tr, pr))
            dev = np.max(np.abs(m_mi - D @ m_ir @ D)) / m_ir[0, 0]
            dev_plain = np.max(np.abs(m_mi - m_ir)) / m_ir[0, 0]
            worst = max(worst, dev)
            s_in = np.array([1.0, 0.0, 1.0, 0.0])
            so_ir, so_mi = m_ir @ s_in, m_mi @ s_in
            if abs(so_ir[3]) > 1e-3 * so_ir[0]:
                signs.append(np.sign(so_ir[3]) * np.sign(so_mi[3]))
            print(f"  {name:8} {ti:3} {pi:3} {tr:3} {pr:3}   {m_ir[0, 0]:11.5g} "
                  f"{m_mi[0, 0] / m_ir[0, 0]:12.5f} {dev:20.2e} {so_ir[3] / so_ir[0]:24.5f} "
                  f"{so_mi[3] / so_mi[0]:8.5f}   (without the S3 flip: {dev_plain:.2e})")
    sign = 1.0 if all(s > 0 for s in signs) else -1.0 if all(s < 0 for s in signs) else 0.0
    print(f"  S3 sign relation: S3_irpol = {sign:+.0f} × S3_mitsuba "
          "(expected −1: Mitsuba conjugates N, exp(+iωt))")
    print(f"  worst |M_mitsuba − D M_irpol D| / m00 = {worst:.2e} (Mitsuba's Smith G1 is a rational "
          "approximation, < 0.35 %, and float32)")
    return sign, worst


# ----------------------------------------------------------------------------------------------
# irpol.

def irpol_pass(irpol, work, width, height, bounces, samples, seed, toml=None):
    """One irpol render of this script's scene, or of `toml(width, height, bounces, samples, seed)`
    (a function giving a scene's text; scripts/check_mitsuba_scene.py passes its own)."""
    import tifffile
    scene = work / f"irpol_scene_seed{seed}.toml"
    scene.write_text((toml or scene_toml)(width, height, bounces, samples, seed))
    out = work / f"irpol_seed{seed}"
    import resource
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([irpol, "render", str(scene), "--out", str(out)], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    elapsed = (time.perf_counter() - start, cpu)
    stokes = np.array([tifffile.imread(out / f"S{j}.tif") for j in range(4)], np.float64)
    stderr_s0 = tifffile.imread(out / "stderr_S0.tif").astype(np.float64)
    summary = json.loads((out / "summary.json").read_text())
    return stokes, stderr_s0, elapsed, summary


# ----------------------------------------------------------------------------------------------
# Diagnostic: the exact open-world value by quadrature (--quadrature).

def hit_sphere_mesh(origin, d, mesh):
    """Closest hit of one ray with the icosphere: point and irpol's interpolated normal."""
    verts, norms, faces = mesh
    v0, v1, v2 = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    e1, e2 = v1 - v0, v2 - v0
    pv = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, pv)
    tv = origin - v0
    u = np.einsum("ij,ij->i", tv, pv) / det
    qv = np.cross(tv, e1)
    v = (qv @ d) / det
    t = np.einsum("ij,ij->i", e2, qv) / det
    ok = (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    i = int(np.argmin(np.where(ok, t, np.inf)))
    n = norms[faces[i, 0]] * (1 - u[i] - v[i]) + norms[faces[i, 1]] * u[i] + norms[faces[i, 2]] * v[i]
    return origin + t[i] * d, n / np.linalg.norm(n)


def walter_g1(cos_theta, alpha):
    """Mitsuba's Beckmann Smith G1 (microfacet.h): Walter et al.'s rational approximation."""
    tan = np.sqrt(np.maximum(1.0 - cos_theta ** 2, 0.0)) / cos_theta
    with np.errstate(divide="ignore"):
        a = 1.0 / (alpha * tan)
    g = np.where(a >= 1.6, 1.0, (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a))
    return np.where(tan == 0.0, 1.0, g)


def open_world_quadrature(width, height, pixels, material, sphere, n_theta=250, n_phi=500):
    """S_j = ∫ F_j0(ω_i→ω_r) L_env(ω_i) cosθ_i dΩ_i (j = 0, 1, 2; irpol's pixel frame) at the pixel
    centres, with the exact BRDF of scripts/pbrdf_numpy.py (checked against SCATMECH) on a
    Gauss–Legendre × uniform grid over the local hemisphere (250 × 500 nodes: per pixel within
    ~0.03 % of 800 × 1600); also S0 with Mitsuba's approximate Smith G1 in place of the exact one."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import pbrdf_numpy as pb
    origin, _, right, _ = camera_frame()
    x, w = np.polynomial.legendre.leggauss(n_theta)
    theta = (x + 1.0) * math.pi / 4.0
    phi = (np.arange(n_phi) + 0.5) * 2.0 * math.pi / n_phi
    th, ph = (a.ravel() for a in np.meshgrid(theta, phi, indexing="ij"))
    weight = np.repeat(w * math.pi / 4.0, n_phi) * (2.0 * math.pi / n_phi) * np.sin(th) * np.cos(th)
    w_i = pb.direction(th, ph)
    sigma, alpha = material["sigma"], math.sqrt(2.0) * material["sigma"]
    g1_ratio_i = walter_g1(np.cos(th), alpha) / pb.smith_g1(th, "gaussian", sigma, 0.0)
    mesh = None
    if sphere:
        s = SCENE["sphere"]
        v, n, f = icosphere(s["radius"], s["subdivisions"])
        mesh = (v + np.array(s["center"]), n, f)
    out = []
    for y, x_ in pixels:
        d = ray_directions(width, height, np.array(x_ + 0.5), np.array(y + 0.5))
        if sphere:
            _, n = hit_sphere_mesh(origin, d, mesh)
        else:
            n = np.array([0.0, 0.0, 1.0])
        w_r = -d
        e_x = np.array([0.0, 0.0, 1.0]) - n * n[2]
        e_x = e_x / np.linalg.norm(e_x) if np.linalg.norm(e_x) > 1e-9 else \
            (w_r - n * (w_r @ n)) / np.linalg.norm(w_r - n * (w_r @ n))
        e_y = np.cross(n, e_x)
        local = np.array([w_r @ e_x, w_r @ e_y, w_r @ n])
        t_r, p_r = math.degrees(math.acos(local[2])), math.degrees(math.atan2(local[1], local[0]))
        m = pb.mueller_brdf(np.degrees(th), np.degrees(ph), t_r, p_r, distribution="gaussian",
                            sigma=sigma, n=material["n"], k=material["k"], shadowing="smith")
        radiance = irpol_env_radiance(w_i @ np.array([e_x[2], e_y[2], n[2]])) * weight
        s0, s1, s2 = (m[:, j, 0] @ radiance for j in range(3))
        g1_ratio_r = (walter_g1(np.array([local[2]]), alpha)
                      / pb.smith_g1(np.radians([t_r]), "gaussian", sigma, 0.0))[0]
        s0_walter = (m[:, 0, 0] * g1_ratio_i) @ radiance * g1_ratio_r
        # psps s axis unit(n × ω_r) into the pixel frame: rotate_stokes(S, −ψ).
        s_axis = np.cross(n, w_r)
        s_axis /= np.linalg.norm(s_axis)
        x_pix = right - w_r * (right @ w_r)
        x_pix /= np.linalg.norm(x_pix)
        psi = math.atan2(s_axis @ np.cross(w_r, x_pix), s_axis @ x_pix)
        c, s_ = math.cos(-2 * psi), math.sin(-2 * psi)
        out.append((s0, c * s1 + s_ * s2, -s_ * s1 + c * s2, s0_walter))
    return np.array(out)


def quadrature_report(width, height, ir_passes, ir_stderr, mi_passes, masks, count, seed=5):
    """irpol and Mitsuba against the exact open-world value, on pixels where irpol's correction never
    hit geometry (stderr_S0 = 0 in every pass: the value is its open-world tables alone)."""
    print()
    print("Quadrature check (exact open-world value at pixel centres; pixels where no irpol correction "
          "ray hit geometry)")
    rng = np.random.default_rng(seed)
    unhit = np.all(np.array(ir_stderr) == 0.0, axis=0)
    ir_mean, mi_mean = ir_passes.mean(axis=0), mi_passes.mean(axis=0)
    mi_var = combine(mi_passes)[1]
    for region in REGIONS[:4]:
        mask = masks[region] & unhit
        if mask.sum() < 10:
            continue
        ys, xs = np.nonzero(mask)
        pick = np.arange(len(ys)) if count < 0 or count >= len(ys) else \
            np.sort(rng.choice(len(ys), count, replace=False))
        material = SCENE["sphere" if region.startswith("sphere") else "plane"]["material"]
        t0 = time.perf_counter()
        q = open_world_quadrature(width, height, list(zip(ys[pick], xs[pick])), material,
                                  region.startswith("sphere"))
        ir = ir_mean[:3, ys[pick], xs[pick]].T
        mi = mi_mean[:3, ys[pick], xs[pick]].T
        mi_se = np.sqrt(mi_var[:3, ys[pick], xs[pick]].sum(axis=1)) / len(pick)
        rel = ir[:, 0] / q[:, 0] - 1.0
        print(f"  {region} ({len(pick)} of {mask.sum()} px, {time.perf_counter() - t0:.0f} s): "
              f"S0 exact {q[:, 0].mean():.5f}, irpol {ir[:, 0].mean():.5f} "
              f"({100 * (ir[:, 0].mean() / q[:, 0].mean() - 1):+.3f} %; per pixel "
              f"{100 * rel.min():+.2f} … {100 * rel.max():+.2f} %, RMS {100 * np.sqrt(np.mean(rel ** 2)):.2f} %), "
              f"Mitsuba {mi[:, 0].mean():.5f} ± {mi_se[0]:.5f} "
              f"({100 * (mi[:, 0].mean() / q[:, 0].mean() - 1):+.3f} %; its Smith G1 alone: "
              f"{100 * (q[:, 3].mean() / q[:, 0].mean() - 1):+.3f} %)")
        for j in (1, 2):
            print(f"      S{j}: exact {q[:, j].mean():+.5f}, irpol {ir[:, j].mean():+.5f}, Mitsuba "
                  f"{mi[:, j].mean():+.5f} ± {mi_se[j]:.5f}")


# ----------------------------------------------------------------------------------------------
# Statistics.

def combine(passes):
    """Mean over passes and the per-pixel variance of that mean (from the spread of the passes)."""
    passes = np.asarray(passes)
    k = len(passes)
    mean = passes.mean(axis=0)
    var_of_mean = passes.var(axis=0, ddof=1) / k
    return mean, var_of_mean


def dolp(stokes):
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sqrt(stokes[1] ** 2 + stokes[2] ** 2) / stokes[0]


CHANNELS = ["S0", "S1", "S2", "S3", "S2 odd", "S3 odd", "DoLP"]


def region_stats(passes, mask):
    """Region means of S0..S3, of the mirror-odd parts of S2 and S3, and of DoLP, with standard
    errors (DoLP: jackknife over the passes).

    The scene is mirror-symmetric about the vertical plane through the camera and the sphere's axis
    (up to the square ground's far edges), which projects onto the image's centre column; a mirror
    flips S2 and S3, so their region means vanish by symmetry and only their odd parts
    ⟨S · sgn(column − centre)⟩, over pixels whose mirror image is in the region too, test them."""
    mean, var = combine(passes)
    n = mask.sum()
    means = [mean[j][mask].mean() for j in range(4)]
    errors = [math.sqrt(var[j][mask].sum()) / n for j in range(4)]
    width = mask.shape[1]
    side = np.sign(np.arange(width) - (width - 1) / 2.0)[None, :] * np.ones_like(mean[0])
    sym = mask & mask[:, ::-1]
    n_sym = max(sym.sum(), 1)
    for j in (2, 3):
        means.append((mean[j] * side)[sym].mean() if sym.any() else 0.0)
        errors.append(math.sqrt(var[j][sym].sum()) / n_sym)
    means.append(dolp(mean)[mask].mean())
    k = len(passes)
    jack = [dolp(np.delete(passes, i, axis=0).mean(axis=0))[mask].mean() for i in range(k)]
    errors.append(math.sqrt((k - 1) / k * np.sum((np.array(jack) - np.mean(jack)) ** 2)))
    return means, errors, var[0][mask]


def block_mean(image, n):
    h, w = image.shape[-2] // n, image.shape[-1] // n
    return image.reshape(image.shape[:-2] + (h, n, w, n)).mean(axis=(-3, -1))


# ----------------------------------------------------------------------------------------------


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--irpol", default=str(Path(__file__).resolve().parent.parent
                                                / "target" / "release" / "irpol"))
    parser.add_argument("--work", default="/tmp/mitsuba_compare")
    parser.add_argument("--png", default="/tmp/mitsuba_compare.png")
    parser.add_argument("--width", type=int, default=128)
    parser.add_argument("--height", type=int, default=96)
    parser.add_argument("--bounces", type=int, default=16)
    parser.add_argument("--passes", type=int, default=8, help="independent passes per renderer")
    parser.add_argument("--irpol-samples", type=int, default=1024, help="irpol samples per pass")
    parser.add_argument("--mitsuba-spp", type=int, default=2048, help="Mitsuba spp per pass")
    parser.add_argument("--irpol-first-bounce-samples", type=int,
                        default=SCENE["first_bounce_samples"],
                        help="irpol's lobe samples per path at the visible point (1: no split)")
    parser.add_argument("--mitsuba-sampler", default="independent",
                        help="Mitsuba sampler plugin: independent (its default), stratified, "
                             "multijitter, orthogonal or ldsampler")
    parser.add_argument("--irpol-supersample", type=int, default=1, metavar="N",
                        help="diagnostic: render irpol at N× the resolution (samples/N² each) and "
                             "average N×N blocks, i.e. a box-filtered pixel like Mitsuba's")
    parser.add_argument("--sphere-only", action="store_true",
                        help="diagnostic: leave out the ground plane (irpol is then its exact "
                             "open-world tables, noise-free)")
    parser.add_argument("--quadrature", type=int, default=0, metavar="K",
                        help="diagnostic: exact open-world values by quadrature at K pixels of each "
                             "region where irpol is its tables alone (−1: all; ~0.2 s a pixel)")
    parser.add_argument("--variant", default=None, help="Mitsuba variant (default: best available)")
    parser.add_argument("--tolerance", type=float, default=0.01, help="S0 relative tolerance")
    args = parser.parse_args()

    if args.sphere_only:
        SCENE["plane"]["size"] = [0.0, 0.0]
    SCENE["first_bounce_samples"] = args.irpol_first_bounce_samples
    irpol = args.irpol
    if not os.access(irpol, os.X_OK):
        print(f"irpol binary not found at {irpol}", file=sys.stderr)
        return 2
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    width, height = args.width, args.height

    if "DRJIT_LIBLLVM_PATH" not in os.environ and find_libllvm():
        os.environ["DRJIT_LIBLLVM_PATH"] = find_libllvm()
    import mitsuba as mi
    variant = choose_variant(mi, args.variant)
    binary_mtime = os.stat(irpol).st_mtime
    version = subprocess.run([irpol, "--version"], capture_output=True, text=True).stdout.strip()
    print(f"Mitsuba {mi.__version__}, variant {variant}; {version} at {irpol} (built "
          f"{time.strftime('%Y-%m-%d %H:%M:%S', time.localtime(binary_mtime))})")
    if "spectral" in variant:
        print("  note: spectral variant: the envmap is RGB-upsampled and D65-weighted; compare the "
              "background rows to see the scale")
    ground = irpol_ground_radiance()
    print(f"Environment: sky table {SCENE['sky_radiance']} at {SCENE['sky_elevation_deg']}°, "
          f"ground below the horizon {ground:.6f} W m-2 sr-1 "
          f"(= (1 − {SCENE['ground_emissivity']}) E_sky/π, L_bb(1 K) = 0)")

    sign, brdf_dev = brdf_check(mi, irpol, work)
    if sign == 0:
        print("S3 sign relation inconsistent between geometries: S3 not compared", file=sys.stderr)

    # irpol passes.
    n_sup = args.irpol_supersample
    samples = max(1, args.irpol_samples // (n_sup * n_sup))
    ir_passes, ir_stderr, ir_times = [], [], []
    for seed in range(1, args.passes + 1):
        s, e, t, summary = irpol_pass(irpol, work, width * n_sup, height * n_sup, args.bounces,
                                      samples, seed)
        ir_passes.append(block_mean(s, n_sup))
        ir_stderr.append(np.sqrt(block_mean(e ** 2, n_sup) / (n_sup * n_sup)))
        ir_times.append(t)
    sup = f" at {n_sup}×{n_sup} subpixels" if n_sup > 1 else ""
    print(f"irpol: {args.passes} passes × {samples} samples{sup}, bounces {args.bounces}: "
          f"{sum(t for t, _ in ir_times):.2f} s wall, {sum(c for _, c in ir_times):.2f} s CPU "
          f"(whole processes; per pass {min(t for t, _ in ir_times):.2f}–"
          f"{max(t for t, _ in ir_times):.2f} s; irpol's own timings in the last: "
          + ", ".join(f"{k} {v:.2f}" for k, v in summary["timings_s"].items()) + ")")

    # Mitsuba passes.
    t0 = time.perf_counter()
    scene = mitsuba_scene(mi, work, width, height, args.bounces, args.mitsuba_spp,
                          args.mitsuba_sampler)
    t_load = time.perf_counter() - t0
    mi_passes, mi_times = [], []
    for seed in range(1, args.passes + 1):
        s, t = mitsuba_stokes(mi, scene, args.mitsuba_spp, seed)
        mi_passes.append(s)
        mi_times.append(t)
    print(f"Mitsuba: {args.passes} passes × {args.mitsuba_spp} spp ({args.mitsuba_sampler} sampler), path max_depth "
          f"{args.bounces + 2}: {sum(t for t, _ in mi_times):.2f} s wall, "
          f"{sum(c for _, c in mi_times):.2f} s CPU (mi.render; first pass {mi_times[0][0]:.2f} s "
          f"incl. JIT, others {np.mean([t for t, _ in mi_times[1:]]) if len(mi_times) > 1 else float('nan'):.2f} s;"
          f" scene load {t_load:.2f} s)")

    # Into irpol's pixel frame.
    psi = mitsuba_to_pixel_frame_angle(width, height)
    mi_passes = rotate_stokes(np.array(mi_passes), psi)
    mi_passes[:, 3] *= sign if sign != 0 else 0.0
    ir_passes = np.array(ir_passes)
    print(f"Frame rotation Mitsuba → irpol: |ψ| up to {np.degrees(np.abs(psi)).max():.3f}° "
          f"(0 on the image's centre row and column); S3 multiplied by {sign:+.0f}")

    masks = region_masks(width, height)
    # A cross-check of the noise estimate: irpol's own stderr_S0 (per pass) against the spread.
    own = np.sqrt(np.mean(np.array(ir_stderr) ** 2, axis=0) / args.passes)

    print()
    print("Region means in irpol's pixel frame (W m-2 sr-1), ± standard error of the mean; "
          "Δ = irpol − Mitsuba")
    checks, failures = 0, 0
    var_ir_all, var_mi_all = [], []
    summary_rows = []
    for region in REGIONS:
        mask = masks[region]
        if mask.sum() == 0:
            print(f"  {region}: no pixel")
            continue
        m_ir, e_ir, v_ir = region_stats(ir_passes, mask)
        m_mi, e_mi, v_mi = region_stats(mi_passes, mask)
        if region not in ("sky (env)", "env ground"):
            var_ir_all.append(v_ir)
            var_mi_all.append(v_mi)
        print(f"  {region} ({mask.sum()} px)")
        for j, name in enumerate(CHANNELS):
            diff = m_ir[j] - m_mi[j]
            # Floor: float32 images (and Mitsuba's float32 envmap) agree to ~1e-5 at best.
            sig = math.hypot(e_ir[j], e_mi[j], 1e-5 * abs(m_mi[0]))
            z = diff / sig if sig > 0 else (math.inf if diff else 0.0)
            if name == "DoLP":
                ok, note = True, f"{diff:+9.5f} abs."
            elif name == "S0":
                ok = abs(diff / m_mi[0]) <= args.tolerance
                note = f"{100 * diff / m_mi[0]:+7.3f} %     "
            else:
                if name.startswith("S3") and sign == 0:
                    continue
                ok = abs(z) <= 4.0 or abs(diff / m_mi[0]) <= 0.002
                note = f"{100 * diff / m_mi[0]:+7.3f} % S0  "
            if name != "DoLP":
                checks += 1
                failures += not ok
            print(f"    {name:6} irpol {m_ir[j]:10.5f} ± {e_ir[j]:.5f}   Mitsuba {m_mi[j]:10.5f} ± "
                  f"{e_mi[j]:.5f}   Δ {diff:+9.5f}  {note} {z:+7.1f} σ"
                  f"{'' if ok else '   <-- outside tolerance'}")
            summary_rows.append(dict(region=region, channel=name, irpol=m_ir[j], irpol_se=e_ir[j],
                                     mitsuba=m_mi[j], mitsuba_se=e_mi[j], diff=diff, z=z))
        if region in ("sphere upper", "sphere lower", "ground near"):
            print(f"           irpol's own stderr_S0 for this mean: "
                  f"{math.sqrt((own[mask] ** 2).sum()) / mask.sum():.5f} "
                  f"(from the pass spread: {e_ir[0]:.5f})")

    # Noise and time.
    var_ir = np.concatenate(var_ir_all).mean()
    var_mi = np.concatenate(var_mi_all).mean()
    t_ir, t_mi = sum(t for t, _ in ir_times), sum(t for t, _ in mi_times)
    c_ir, c_mi = sum(c for _, c in ir_times), sum(c for _, c in mi_times)
    print()
    print("Noise: RMS per-pixel standard error of S0 over the four surface regions: "
          f"irpol {math.sqrt(var_ir):.4f}, Mitsuba {math.sqrt(var_mi):.4f} W m-2 sr-1")
    for region in REGIONS[:4]:
        mask = masks[region]
        if mask.any():
            print(f"  {region:13}: irpol {math.sqrt(combine(ir_passes)[1][0][mask].mean()):.4f}, "
                  f"Mitsuba {math.sqrt(combine(mi_passes)[1][0][mask].mean()):.4f}")
    print(f"Time: irpol {t_ir:.2f} s, Mitsuba {t_mi:.2f} s wall: Mitsuba/irpol = {t_mi / t_ir:.2f}"
          f" (CPU {c_ir:.2f} s and {c_mi:.2f} s: {c_mi / c_ir:.2f})")
    print(f"At equal noise (T σ² over the surface regions): Mitsuba/irpol = "
          f"{(t_mi * var_mi) / (t_ir * var_ir):.2f} wall, {(c_mi * var_mi) / (c_ir * var_ir):.2f} CPU")

    if args.quadrature:
        quadrature_report(width, height, ir_passes, ir_stderr, mi_passes, masks, args.quadrature)

    figure(ir_passes.mean(axis=0), mi_passes.mean(axis=0), combine(ir_passes)[1],
           combine(mi_passes)[1], masks, args.png, variant)
    print(f"Figure: {args.png}")
    np.savez_compressed(work / "compare.npz", irpol=ir_passes, mitsuba=mi_passes, psi=psi,
                        **{k.replace(" ", "_").replace("(", "").replace(")", ""): v
                           for k, v in masks.items()})
    (work / "compare.json").write_text(json.dumps(dict(
        rows=summary_rows, irpol_seconds=t_ir, mitsuba_seconds=t_mi, mitsuba_load_seconds=t_load,
        irpol_cpu_seconds=c_ir, mitsuba_cpu_seconds=c_mi,
        irpol_rms_se_s0=math.sqrt(var_ir), mitsuba_rms_se_s0=math.sqrt(var_mi), s3_sign=sign,
        brdf_max_deviation=brdf_dev, variant=variant), indent=1, default=float))
    if os.stat(irpol).st_mtime != binary_mtime:
        print("warning: the irpol binary changed during the run; run again", file=sys.stderr)
        failures += 1
    checks += 1
    failures += brdf_dev > 0.02
    print(f"{checks - failures} passed, {failures} failed")
    return 1 if failures else 0


def figure(ir, mit, var_ir, var_mi, masks, path, variant):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 3, figsize=(13, 9.2), constrained_layout=True)
    # A floor keeps noise-free pixels (the environment, unoccluded ground in irpol) readable.
    sigma = np.sqrt(var_ir + var_mi + (1e-4 * np.abs(mit[0]) + 1e-6) ** 2)
    outline = np.zeros(ir.shape[1:], float)
    for i, name in enumerate(REGIONS[:4]):
        outline[masks[name]] = i + 1
    rows = [("S0 (W m-2 sr-1)", ir[0], mit[0], sigma[0]),
            ("DoLP", dolp(ir), dolp(mit), None),
            ("S3 (W m-2 sr-1)", ir[3], mit[3], sigma[3])]
    for r, (label, a, b, s) in enumerate(rows):
        lo, hi = np.nanpercentile(np.concatenate([a.ravel(), b.ravel()]), [1, 99])
        if label.startswith("S3"):
            hi = max(abs(lo), abs(hi))
            lo, cmap = -hi, "RdBu_r"
        elif label == "DoLP":
            lo, hi, cmap = 0.0, min(1.0, hi), "viridis"
        else:
            cmap = "inferno"
        for c, (img, title) in enumerate(((a, "irpol"), (b, "Mitsuba 3"))):
            im = axes[r, c].imshow(img, cmap=cmap, vmin=lo, vmax=hi, interpolation="nearest")
            axes[r, c].set_title(f"{label}: {title}")
            fig.colorbar(im, ax=axes[r, c], shrink=0.8)
        if s is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                z = np.where(s > 0, (a - b) / s, 0.0)
            im = axes[r, 2].imshow(z, cmap="RdBu_r", vmin=-4, vmax=4, interpolation="nearest")
            axes[r, 2].set_title(f"{label.split()[0]}: (irpol − Mitsuba) / σ")
        else:
            im = axes[r, 2].imshow(a - b, cmap="RdBu_r", vmin=-0.1, vmax=0.1,
                                   interpolation="nearest")
            axes[r, 2].set_title("DoLP: irpol − Mitsuba")
        axes[r, 2].contour(outline, levels=[0.5, 1.5, 2.5, 3.5], colors="k", linewidths=0.4)
        fig.colorbar(im, ax=axes[r, 2], shrink=0.8)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(f"irpol vs Mitsuba 3 ({variant}, path): sphere N = 3+20i σ = 0.15, "
                 "ground N = 1.5+0.1i σ = 0.2; contours: compared regions")
    fig.savefig(path, dpi=90)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
