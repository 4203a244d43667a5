#!/usr/bin/env python3
"""Writes the example mesh of api/examples/assets/: a small open pavilion.

    python3 scripts/make-example-meshes.py [OUT_DIR]   (default api/examples/assets)

pavilion.obj: a 4 m x 4 m floor slab, four octagonal columns 2.4 m tall and a
hipped roof with a 0.3 m overhang, 138 triangles, in metres.  The file is in
the object's own frame as skyfarm reads it (x right, y forward, z up; no axis
conversion), its origin at the centre of the floor's underside, so that a
placement's translate_m [x, y, 0] stands it on the ground.  Every part is a
closed solid with its faces wound counter-clockwise seen from outside.
Deterministic: running it again writes the same bytes.
"""
import math
import os
import sys


class Mesh:
    def __init__(self):
        self.vertices = []
        self.faces = []  # 1-based vertex indices, counter-clockwise from outside

    def vertex(self, x, y, z):
        self.vertices.append((x, y, z))
        return len(self.vertices)

    def quad(self, a, b, c, d):
        self.faces.append((a, b, c))
        self.faces.append((a, c, d))

    def box(self, x0, y0, z0, x1, y1, z1):
        v = [self.vertex(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
        # v[i]: bit 0 x, bit 1 y, bit 2 z.
        self.quad(v[0], v[2], v[3], v[1])  # bottom (-z)
        self.quad(v[4], v[5], v[7], v[6])  # top (+z)
        self.quad(v[0], v[1], v[5], v[4])  # south (-y)
        self.quad(v[2], v[6], v[7], v[3])  # north (+y)
        self.quad(v[0], v[4], v[6], v[2])  # west (-x)
        self.quad(v[1], v[3], v[7], v[5])  # east (+x)

    def prism(self, cx, cy, radius, z0, z1, sides):
        ring = []
        for i in range(sides):
            a = 2.0 * math.pi * (i + 0.5) / sides
            x, y = cx + radius * math.cos(a), cy + radius * math.sin(a)
            ring.append((self.vertex(x, y, z0), self.vertex(x, y, z1)))
        for i in range(sides):
            (b0, t0), (b1, t1) = ring[i], ring[(i + 1) % sides]
            self.quad(b0, b1, t1, t0)
        for i in range(1, sides - 1):  # caps as fans
            self.faces.append((ring[0][1], ring[i][1], ring[i + 1][1]))
            self.faces.append((ring[0][0], ring[i + 1][0], ring[i][0]))

    def hipped_roof(self, half, z0, z_eave, z_apex):
        """A square slab from z0 to z_eave under a pyramid to z_apex."""
        corners = [(-half, -half), (half, -half), (half, half), (-half, half)]  # counter-clockwise from above
        low = [self.vertex(x, y, z0) for x, y in corners]
        high = [self.vertex(x, y, z_eave) for x, y in corners]
        apex = self.vertex(0.0, 0.0, z_apex)
        self.quad(low[0], low[3], low[2], low[1])  # underside (-z)
        for i in range(4):
            j = (i + 1) % 4
            self.quad(low[i], low[j], high[j], high[i])
            self.faces.append((high[i], high[j], apex))

    def obj_text(self, header):
        lines = [f"# {line}" for line in header]
        lines += [f"v {x:.4f} {y:.4f} {z:.4f}" for x, y, z in self.vertices]
        lines += [f"f {a} {b} {c}" for a, b, c in self.faces]
        return "\n".join(lines) + "\n"


def pavilion():
    m = Mesh()
    m.box(-2.0, -2.0, 0.0, 2.0, 2.0, 0.2)  # floor slab
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            m.prism(1.6 * sx, 1.6 * sy, 0.15, 0.2, 2.6, 8)  # columns
    m.hipped_roof(2.3, 2.6, 2.72, 3.8)
    return m


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "api", "examples", "assets")
    m = pavilion()
    header = [
        "skyfarm example mesh: an open pavilion, metres, z up, origin at the floor's centre",
        "(written by scripts/make-example-meshes.py)",
        f"{len(m.vertices)} vertices, {len(m.faces)} triangles",
    ]
    path = os.path.join(out_dir, "pavilion.obj")
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write(m.obj_text(header))
    print(f"{path}: {len(m.faces)} triangles")


if __name__ == "__main__":
    main()
