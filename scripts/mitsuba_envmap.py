#!/usr/bin/env python3
"""prism's environment maps against Mitsuba 3's `envmap` on the same scenes, RGB mode, box
pixel filter, the same map file in both.

Mitsuba's `envmap` puts the map's centre column at +z, prism's at -z (both +y up, both turn
right-handed): the Mitsuba emitter is turned by prism's rotation times a further 180° about y.

1. Orientation: a black map with one bright texel (up and towards +x in prism's convention)
   lights a diffuse sphere; the lit region's centroid (in pixels) must agree within 1 pixel,
   under three rotations.
2. A diffuse sphere on a diffuse plane under `assets/env/studio.exr` and
   `assets/env/sunrise.exr`, each turned 30° about y: the image means must agree within 2 %
   per channel (each renderer's own noise is well below that at 256 spp).

Skips cleanly (exit 0 with a message) where Mitsuba 3 is not installed; `../shared/duel/setup.sh`
installs it into ~/.cache/prism-duel/venv. Usage:
    ~/.cache/prism-duel/venv/bin/python scripts/mitsuba_envmap.py [--prism target/release/prism]
"""
import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SIZE, SPP = 96, 256


def prism_render(prism, out, env, entities, spp=SPP):
    scene = out / "s.ron"
    scene.write_text(
        "#![enable(implicit_some)]\n"
        f"Scene(render: (width: {SIZE}, height: {SIZE}, spp: {spp}, max_depth: 8, seed: 3, filter: Box),\n"
        " camera: (position: (0.0, 1.0, 4.0), look_at: (0.0, 0.5, 0.0), fov_y: 35.0),\n"
        f" environment: {env},\n"
        f" entities: [{entities}])\n"
    )
    exr = out / "p.exr"
    subprocess.run(
        [prism, "render", str(scene), "-o", str(exr), "--quiet", "--allow-any-path"], check=True
    )
    import mitsuba as mi
    import numpy as np

    return np.array(mi.Bitmap(str(exr)))[..., :3]


def mitsuba_render(map_path, rotate_y, plane, spp=SPP):
    import mitsuba as mi
    import numpy as np

    T = mi.ScalarTransform4f
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 9},
        "sensor": {
            "type": "perspective",
            "fov": 35.0,
            "fov_axis": "y",
            "to_world": T().look_at(origin=[0, 1, 4], target=[0, 0.5, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "env": {
            "type": "envmap",
            "filename": str(map_path),
            "to_world": T().rotate([0, 1, 0], rotate_y + 180.0),
        },
        "ball": {
            "type": "sphere",
            "center": [0, 0.5, 0],
            "radius": 0.5,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5, 0.5, 0.5]}},
        },
    }
    if plane:
        d["floor"] = {
            "type": "rectangle",
            "to_world": T().rotate([1, 0, 0], -90).scale(3.0),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.4, 0.4, 0.4]}},
        }
    return np.array(mi.render(mi.load_dict(d), seed=3))[..., :3]


BALL = (
    '(name: "ball", shape: Sphere(center: (0.0, 0.5, 0.0), radius: 0.5), '
    "material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5)))"
)
FLOOR = (
    '(name: "floor", shape: Rect(center: (0.0, 0.0, 0.0), u: (3.0, 0.0, 0.0), v: (0.0, 0.0, -3.0)), '
    "material: Diffuse(albedo: Rgb(0.4, 0.4, 0.4)))"
)


def centroid(img):
    import numpy as np

    w = img.sum(axis=2)
    ys, xs = np.mgrid[0 : w.shape[0], 0 : w.shape[1]]
    return (float((w * xs).sum() / w.sum()), float((w * ys).sum() / w.sum()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--prism", default=str(ROOT / "target/release/prism"))
    ap.add_argument("--tolerance", type=float, default=0.02)
    args = ap.parse_args()
    try:
        import mitsuba as mi
        import numpy as np
    except ImportError:
        print("Mitsuba 3 is not installed (../shared/duel/setup.sh installs it): skipped")
        return 0
    mi.set_variant("scalar_rgb")
    failed = False
    with tempfile.TemporaryDirectory() as d:
        out = Path(d)
        # A 64×32 map: one texel at column 48 (u = 0.766, towards +x), row 8 (45° up).
        dot = np.zeros((32, 64, 3), dtype=np.float32)
        dot[8, 48] = 2000.0
        dot_path = out / "dot.exr"
        mi.Bitmap(dot).write(str(dot_path))
        print("| map | rotate y | prism centroid (x, y) px | Mitsuba centroid | distance |")
        print("|---|---|---|---|---|")
        for ry in [0.0, 90.0, 200.0]:
            p = prism_render(
                args.prism, out, f'Image(path: "{dot_path}", rotate: (0.0, {ry}, 0.0))', BALL, 64
            )
            m = mitsuba_render(dot_path, ry, False, 64)
            cp, cm = centroid(p), centroid(m)
            dist = ((cp[0] - cm[0]) ** 2 + (cp[1] - cm[1]) ** 2) ** 0.5
            failed |= dist > 1.0
            print(
                f"| one bright texel | {ry:.0f}° | ({cp[0]:.2f}, {cp[1]:.2f}) | "
                f"({cm[0]:.2f}, {cm[1]:.2f}) | {dist:.2f} |"
            )
        print()
        print(f"| map | prism mean (R, G, B) | Mitsuba {mi.__version__} mean | largest difference |")
        print("|---|---|---|---|")
        for name in ["studio.exr", "sunrise.exr"]:
            path = ROOT / "assets/env" / name
            p = prism_render(
                args.prism,
                out,
                f'Image(path: "{path}", rotate: (0.0, 30.0, 0.0))',
                BALL + ", " + FLOOR,
            )
            m = mitsuba_render(path, 30.0, True)
            pm, mm = p.reshape(-1, 3).mean(axis=0), m.reshape(-1, 3).mean(axis=0)
            diff = max(abs(a / b - 1.0) for a, b in zip(pm, mm))
            failed |= diff > args.tolerance
            fmt = lambda v: ", ".join(f"{x:.4f}" for x in v)
            print(f"| {name}, sphere on a plane | {fmt(pm)} | {fmt(mm)} | {100 * diff:.2f} % |")
    if failed:
        print("prism and Mitsuba disagree beyond the tolerances", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
