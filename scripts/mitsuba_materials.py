#!/usr/bin/env python3
"""prism's materials against Mitsuba 3's on the same scene: a unit sphere seen from far away
(the view rays parallel to 1/400, so the sphere's points are seen at cosines distributed as
2μ dμ) in a white constant environment, RGB mode, box pixel filter. Each material's mean
radiance over the sphere's disc is printed for both renderers with their ratio; the script
exits 1 if a channel of a gated case differs by more than the tolerance (2 %).

Mitsuba's rough conductor uses the separable Smith term G1(wo)·G1(wi), prism the
height-correlated G2, which is larger: by quadrature of the white-furnace albedo, 0.5 % more
energy at α = 0.3 and 5.0 % more at α = 0.8. The α = 0.8 case is printed to show that, not
gated.

Glass in a white furnace is nearly invisible whatever its BSDF, so the rough dielectric is
also compared with paths cut short: one scattering event (the sphere's rough reflectance
alone) and two (light refracted in and out once more). prism's `max_depth` counts
scattering events, Mitsuba's path vertices: prism's n is Mitsuba's n + 1.

The disc's mean comes from the image mean (the pixel filter is a partition of unity, so the
image mean is the area mean of the radiance) and the disc's analytic share of the image.

Skips cleanly (exit 0 with a message) where Mitsuba 3 is not installed; `../shared/duel/setup.sh`
installs it into ~/.cache/prism-duel/venv. Usage:
    ~/.cache/prism-duel/venv/bin/python scripts/mitsuba_materials.py [--prism target/release/prism]
"""
import argparse
import math
import subprocess
import sys
import tempfile
from pathlib import Path

DIST, FOV, SIZE, SPP = 400.0, 0.35, 64, 256

ROUGH_GLASS = {
    "type": "roughdielectric",
    "distribution": "ggx",
    "alpha": 0.3,
    "sample_visible": True,
    "int_ior": 1.5,
    "ext_ior": 1.0,
}

# (name, prism material, Mitsuba BSDF dict, gated[, prism max_depth])
CASES = [
    (
        "rough conductor, complex IOR, α 0.3",
        "Conductor(eta: Rgb(0.2, 0.92, 1.1), k: Rgb(3.9, 2.45, 2.14), alpha: 0.3, multiscatter: false)",
        {
            "type": "roughconductor",
            "distribution": "ggx",
            "alpha": 0.3,
            "sample_visible": True,
            "eta": {"type": "rgb", "value": [0.2, 0.92, 1.1]},
            "k": {"type": "rgb", "value": [3.9, 2.45, 2.14]},
        },
        True,
    ),
    (
        "rough conductor, complex IOR, α 0.8 (separable G in Mitsuba)",
        "Conductor(eta: Rgb(1.6, 1.2, 0.9), k: Rgb(2.1, 2.6, 3.3), alpha: 0.8, multiscatter: false)",
        {
            "type": "roughconductor",
            "distribution": "ggx",
            "alpha": 0.8,
            "sample_visible": True,
            "eta": {"type": "rgb", "value": [1.6, 1.2, 0.9]},
            "k": {"type": "rgb", "value": [2.1, 2.6, 3.3]},
        },
        False,
    ),
    (
        "smooth conductor, complex IOR",
        "Conductor(eta: Rgb(0.2, 0.92, 1.1), k: Rgb(3.9, 2.45, 2.14))",
        {
            "type": "conductor",
            "eta": {"type": "rgb", "value": [0.2, 0.92, 1.1]},
            "k": {"type": "rgb", "value": [3.9, 2.45, 2.14]},
        },
        True,
    ),
    (
        "rough dielectric, η 1.5, α 0.3, one event",
        "Dielectric(ior: Constant(1.5), alpha: 0.3, multiscatter: false)",
        ROUGH_GLASS,
        True,
        1,
    ),
    (
        "rough dielectric, η 1.5, α 0.3, two events",
        "Dielectric(ior: Constant(1.5), alpha: 0.3, multiscatter: false)",
        ROUGH_GLASS,
        True,
        2,
    ),
    (
        "rough dielectric, η 1.5, α 0.3, furnace",
        "Dielectric(ior: Constant(1.5), alpha: 0.3, multiscatter: false)",
        ROUGH_GLASS,
        True,
        64,
    ),
]


def disc_fraction():
    half = math.tan(math.radians(FOV) / 2.0)
    r = math.tan(math.asin(1.0 / DIST)) / half * SIZE / 2.0
    return math.pi * r * r / (SIZE * SIZE)


def disc_mean(image_mean):
    return [1.0 - (1.0 - m) / disc_fraction() for m in image_mean]


def prism_mean(prism, material, out, depth):
    scene = out / "s.ron"
    scene.write_text(
        "#![enable(implicit_some)]\n"
        f"Scene(render: (width: {SIZE}, height: {SIZE}, spp: {SPP}, max_depth: {depth}, seed: 3, filter: Box),\n"
        f" camera: (position: (0.0, 0.0, {DIST}), look_at: (0.0, 0.0, 0.0), fov_y: {FOV}),\n"
        " environment: Constant(Rgb(1.0, 1.0, 1.0)),\n"
        f" entities: [(name: \"ball\", shape: Sphere(center: (0.0, 0.0, 0.0), radius: 1.0), material: {material})])\n"
    )
    exr = out / "p.exr"
    subprocess.run([prism, "render", str(scene), "-o", str(exr), "--quiet"], check=True)
    import mitsuba as mi
    import numpy as np

    img = np.array(mi.Bitmap(str(exr)))[..., :3]
    return disc_mean(img.reshape(-1, 3).mean(axis=0).tolist())


def mitsuba_mean(bsdf, depth):
    import mitsuba as mi
    import numpy as np

    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": depth + 1, "rr_depth": 1000},
            "sensor": {
                "type": "perspective",
                "fov": FOV,
                "fov_axis": "y",
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=[0, 0, DIST], target=[0, 0, 0], up=[0, 1, 0]
                ),
                "film": {
                    "type": "hdrfilm",
                    "width": SIZE,
                    "height": SIZE,
                    "rfilter": {"type": "box"},
                },
                "sampler": {"type": "multijitter", "sample_count": SPP},
            },
            "env": {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}},
            "ball": {"type": "sphere", "center": [0, 0, 0], "radius": 1.0, "bsdf": bsdf},
        }
    )
    img = np.array(mi.render(scene, seed=3))[..., :3]
    return disc_mean(img.reshape(-1, 3).mean(axis=0).tolist())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--prism", default="target/release/prism")
    ap.add_argument("--tolerance", type=float, default=0.02)
    args = ap.parse_args()
    try:
        import mitsuba as mi
    except ImportError:
        print("Mitsuba 3 is not installed (../shared/duel/setup.sh installs it): skipped")
        return 0
    mi.set_variant("scalar_rgb")
    worst = 0.0
    print(f"| material | prism (R, G, B) | Mitsuba {mi.__version__} (R, G, B) | largest difference |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        for name, prism_material, bsdf, gated, *depth in CASES:
            depth = depth[0] if depth else 16
            p = prism_mean(args.prism, prism_material, Path(d), depth)
            m = mitsuba_mean(bsdf, depth)
            diff = max(abs(a / b - 1.0) for a, b in zip(p, m))
            if gated:
                worst = max(worst, diff)
            fmt = lambda v: ", ".join(f"{x:.4f}" for x in v)
            print(f"| {name} | {fmt(p)} | {fmt(m)} | {100 * diff:.2f} % |")
    if worst > args.tolerance:
        print(f"differences above {100 * args.tolerance:.0f} %", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
