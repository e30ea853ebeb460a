#!/usr/bin/env python3
"""Writes tests/data/sky_mitsuba.csv: Mitsuba 3's `sunsky` emitter evaluated at 20 directions
of the upper hemisphere under 3 sun settings and 8 wavelengths (sky alone), and at the sun's
centre (sun alone), for tests/sky.rs to compare prism's sky against.

Directions are in prism's frame (+y up, azimuth 0 towards -z, 90 towards +x) and mapped to
Mitsuba's (+z up) by (x, y, z) -> (x, -z, y), a rotation. Usage:
    pip install mitsuba==3.9.1
    scripts/sky_reference.py > tests/data/sky_mitsuba.csv
"""
import math
import sys

try:
    import mitsuba as mi
except ImportError:
    sys.exit("needs Mitsuba 3: pip install mitsuba==3.9.1")

mi.set_variant("scalar_spectral")

# (sun elevation °, sun azimuth °, turbidity, ground albedo)
SETTINGS = [(30.0, 120.0, 3.0, 0.3), (5.0, 250.0, 6.0, 0.5), (65.0, 10.0, 2.0, 0.1)]
WAVELENGTHS = [360.0, 400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0]


def direction(elevation, azimuth):
    e, a = math.radians(elevation), math.radians(azimuth)
    return (math.cos(e) * math.sin(a), math.sin(e), -math.cos(e) * math.cos(a))


def to_mitsuba(d):
    return [d[0], -d[2], d[1]]


def directions(sun_elevation, sun_azimuth):
    """20 directions: a golden-angle spiral over the upper hemisphere (elevations 1° to 89°)
    plus four near the sun (2°, 5°, 10° and 20° away) and one at the horizon's edge."""
    out = []
    for k in range(15):
        elevation = 1.0 + 88.0 * (k + 0.5) / 15.0
        out.append((elevation, (k * 137.50776) % 360.0))
    for off in (2.0, 5.0, 10.0, 20.0):
        e = sun_elevation + off if sun_elevation + off < 89.0 else sun_elevation - off
        out.append((e, sun_azimuth))
    out.append((0.5, sun_azimuth + 180.0))
    return out


def evaluate(emitter, d, lam):
    si = mi.SurfaceInteraction3f()
    si.wi = -mi.Vector3f(to_mitsuba(d))
    si.wavelengths = [lam] * 4
    return emitter.eval(si)[0]


print("kind,sun_elevation,sun_azimuth,turbidity,albedo,dx,dy,dz,lambda,radiance")
for elev, az, turb, alb in SETTINGS:
    sun = direction(elev, az)
    common = {"type": "sunsky", "sun_direction": to_mitsuba(sun), "turbidity": turb, "albedo": alb}
    sky = mi.load_dict({**common, "sun_scale": 0.0})
    sun_only = mi.load_dict({**common, "sky_scale": 0.0})
    for de, da in directions(elev, az):
        d = direction(de, da)
        for lam in WAVELENGTHS:
            print(f"sky,{elev},{az},{turb},{alb},{d[0]:.9f},{d[1]:.9f},{d[2]:.9f},{lam},{evaluate(sky, d, lam):.9g}")
    for lam in WAVELENGTHS:
        print(f"sun,{elev},{az},{turb},{alb},{sun[0]:.9f},{sun[1]:.9f},{sun[2]:.9f},{lam},{evaluate(sun_only, sun, lam):.9g}")
