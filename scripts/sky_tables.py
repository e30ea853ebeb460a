#!/usr/bin/env python3
"""Writes src/scene/sky/hosek_wilkie.bin: the spectral Hosek-Wilkie (2012) sky coefficients and
the sun's spectral irradiance, as little-endian f32, from the copy in Mitsuba 3's wheel.

Source: the `mitsuba` package on PyPI (3.9.1), `mitsuba/data/sunsky/sunsky_datasets.bin` and
`sampling_data.bin`, which carry the Hosek-Wilkie datasets under the 3-clause BSD licence
reproduced in src/scene/sky/LICENSE-hosek-wilkie.txt. Usage:
    pip install mitsuba==3.9.1
    scripts/sky_tables.py [SITE-PACKAGES/mitsuba/data/sunsky]

Layout of the output (all f32, C order):
    b"PRISMSKY", u32 version = 1, then
    params   [turbidity 10][albedo 2][control point 6][band 11][coefficient 9]  (A B C D E F G I H)
    radiance [turbidity 10][albedo 2][control point 6][band 11]
    sun      [turbidity 10][elevation 30: 2°, 5°, ..., 89°][band 11]  irradiance, W m^-2 nm^-1
Bands are 320, 360, ..., 720 nm.
"""
import struct
import sys
from pathlib import Path

import numpy as np


def read_tensor_file(path):
    """Mitsuba's tensor_file: magic, version, field count, then per field its name, rank,
    dtype, absolute byte offset and shape."""
    b = Path(path).read_bytes()
    if b[:12] != b"tensor_file\0":
        sys.exit(f"{path}: not a Mitsuba tensor_file")
    (count,) = struct.unpack_from("<I", b, 14)
    p, out = 18, {}
    for _ in range(count):
        (n,) = struct.unpack_from("<H", b, p)
        p += 2
        name = b[p : p + n].decode()
        p += n
        rank, dtype = struct.unpack_from("<HB", b, p)
        p += 3
        (offset,) = struct.unpack_from("<Q", b, p)
        p += 8
        shape = struct.unpack_from(f"<{rank}Q", b, p)
        p += 8 * rank
        dt = {0x0A: "<f4", 0x0B: "<f8"}[dtype]
        out[name] = np.frombuffer(b, dtype=dt, count=int(np.prod(shape)), offset=offset).reshape(shape)
    return out


def default_dir():
    import importlib.util

    spec = importlib.util.find_spec("mitsuba")
    if spec is None:
        sys.exit("give the mitsuba/data/sunsky directory, or pip install mitsuba==3.9.1")
    return Path(spec.origin).parent / "data" / "sunsky"


def main():
    src = Path(sys.argv[1]) if len(sys.argv) > 1 else default_dir()
    sky = read_tensor_file(src / "sunsky_datasets.bin")
    sampling = read_tensor_file(src / "sampling_data.bin")
    params, radiance, sun = sky["sky_params_spec"], sky["sky_rad_spec"], sampling["sun_irradiance"]
    assert params.shape == (10, 2, 6, 11, 9), params.shape
    assert radiance.shape == (10, 2, 6, 11), radiance.shape
    assert sun.shape == (10, 30, 11), sun.shape
    out = Path(__file__).resolve().parent.parent / "src" / "scene" / "sky" / "hosek_wilkie.bin"
    with open(out, "wb") as f:
        f.write(b"PRISMSKY" + struct.pack("<I", 1))
        for a in (params, radiance, sun):
            f.write(np.ascontiguousarray(a, dtype="<f4").tobytes())
    print(f"wrote {out} ({out.stat().st_size} bytes)")


if __name__ == "__main__":
    main()
