#!/usr/bin/python3
"""Writes api/examples/assets/cumulus.vdb, the small cloud volume the examples
place (api/examples/cloud_volume.json): a cumulus-like heap of soft balls,
eroded by a fixed value noise, as an OpenVDB float grid "density" of
48 x 48 x 32 voxels of 25 m (1.2 km wide, 0.8 km tall), values 0..1, its
base at z = 0 and centred on the grid frame's origin in x and y.

Needs Debian's python3-openvdb (and python3-numpy); run with the system
Python:  /usr/bin/python3 scripts/make-example-cloud.py
The grid's values are a pure function of this script; the .vdb bytes are not
(OpenVDB writes a random file UUID), so the asset id, the SHA-256 of the
imported SKYVOL1 file, is what stays the same.
"""
import os
import sys

import numpy as np
import pyopenvdb as vdb

NX, NY, NZ = 48, 48, 32
VOXEL_M = 25.0


def value_noise(x, y, z, cell, seed):
    """Trilinear value noise on a lattice of `cell` voxels (hashed corners)."""
    def corner(i, j, k):
        h = (i * 73856093) ^ (j * 19349663) ^ (k * 83492791) ^ (seed * 2654435761)
        h = (h ^ (h >> 13)) * 1274126177
        return ((h ^ (h >> 16)) & 0xFFFF) / 65535.0
    fx, fy, fz = x / cell, y / cell, z / cell
    i, j, k = np.floor(fx).astype(np.int64), np.floor(fy).astype(np.int64), np.floor(fz).astype(np.int64)
    tx, ty, tz = fx - i, fy - j, fz - k
    tx, ty, tz = tx * tx * (3 - 2 * tx), ty * ty * (3 - 2 * ty), tz * tz * (3 - 2 * tz)
    out = np.zeros_like(fx)
    for di in (0, 1):
        for dj in (0, 1):
            for dk in (0, 1):
                w = (tx if di else 1 - tx) * (ty if dj else 1 - ty) * (tz if dk else 1 - tz)
                out += w * corner(i + di, j + dj, k + dk)
    return out


def density():
    x, y, z = np.meshgrid(np.arange(NX, dtype=np.float64), np.arange(NY, dtype=np.float64),
                          np.arange(NZ, dtype=np.float64), indexing="ij")
    # Soft balls (centre x, y, z in voxels, radius): a cumulus heap, flat-ish base.
    balls = [(24, 24, 10, 12), (16, 22, 9, 9), (31, 27, 9, 9), (24, 17, 8, 8),
             (22, 28, 17, 9), (27, 22, 20, 7), (20, 24, 22, 6)]
    shape = np.zeros_like(x)
    for cx, cy, cz, r in balls:
        d = np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + ((z - cz) * 1.1) ** 2) / r
        shape = np.maximum(shape, np.clip(1.0 - d, 0.0, 1.0))
    base = np.clip((z - 2.0) / 3.0, 0.0, 1.0)  # a base 50-125 m above the grid's floor
    noise = 0.6 * value_noise(x, y, z, 6.0, 1) + 0.4 * value_noise(x, y, z, 2.5, 2)
    d = np.clip(shape * 2.5 - 0.6 * noise, 0.0, 1.0) * base
    d[d < 1e-3] = 0.0
    return d.astype(np.float32)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "api", "examples", "assets", "cumulus.vdb")
    grid = vdb.FloatGrid(0.0)
    grid.copyFromArray(density(), ijk=(0, 0, 0), tolerance=0.0)
    grid.name = "density"
    grid.gridClass = vdb.GridClass.FOG_VOLUME
    # Row vectors (OpenVDB): world = [i j k 1] M; voxel centres at index * 25 m - half the width.
    grid.transform = vdb.createLinearTransform([[VOXEL_M, 0, 0, 0], [0, VOXEL_M, 0, 0], [0, 0, VOXEL_M, 0],
                                                [-0.5 * (NX - 1) * VOXEL_M, -0.5 * (NY - 1) * VOXEL_M, 0, 1]])
    vdb.write(out, grids=[grid])
    print(f"wrote {out}: {grid.activeVoxelCount()} active voxels, {os.path.getsize(out)} bytes")


if __name__ == "__main__":
    main()
