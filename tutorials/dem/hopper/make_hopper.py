#!/usr/bin/env python3
"""Writes hopper.stl: a conical hopper (ASCII STL, metres).

A vertical cylinder of radius R = 25 mm from z = H_c = 30 mm up to z = 150 mm sits on
a cone that narrows to a circular orifice of diameter D0 = 12 mm at z = 0. The cone's
half-angle from the vertical is atan((R - D0/2) / H_c) = 32 deg. The orifice is open
(no triangles across it). 64 segments around; the cone is cut into 6 rings, the
cylinder into 8, so triangles are 2.5-15 mm across.
"""
import math
import sys

R, D0, HC, TOP, SEG = 0.025, 0.012, 0.030, 0.150, 64
rings = [(D0 / 2 + (R - D0 / 2) * k / 6, HC * k / 6) for k in range(7)]
rings += [(R, HC + (TOP - HC) * k / 8) for k in range(1, 9)]


def point(radius, z, k):
    a = 2 * math.pi * (k % SEG) / SEG  # k = SEG is k = 0, bit for bit (welding)
    return (radius * math.cos(a), radius * math.sin(a), z)


tris = []
for (r0, z0), (r1, z1) in zip(rings[:-1], rings[1:]):
    for k in range(SEG):
        a, b = point(r0, z0, k), point(r0, z0, k + 1)
        c, d = point(r1, z1, k + 1), point(r1, z1, k)
        tris += [(a, b, c), (a, c, d)]

out = sys.argv[1] if len(sys.argv) > 1 else "hopper.stl"
with open(out, "w") as f:
    f.write("solid hopper\n")
    for t in tris:
        f.write("  facet normal 0 0 0\n    outer loop\n")
        for v in t:
            f.write("      vertex %.17g %.17g %.17g\n" % v)
        f.write("    endloop\n  endfacet\n")
    f.write("endsolid hopper\n")
print(f"{out}: {len(tris)} triangles")
