#!/usr/bin/env python3
"""accuracy_cost.bed_height_measure: the bed-height measures of
benchmarks/coarse_grain/bed_height.py against closed forms (numpy only, well under a second).

1. The fraction of a sphere's volume below s radii from its centre, F(s) = (2 + 3s - s^3)/4,
   against the cap volume pi h^2 (3R - h)/3 (h = R(1 + s)) over 4 pi R^3/3, and its inverse
   s = 2 sin(asin(2q - 1)/3) against F.
2. One sphere: the height below which the fraction q of its mass lies is z + R s(q).
3. A stack of 10 equal touching spheres (centres (2i + 1)R): 95 % of the mass lies below the
   middle of the top sphere (9.5 spheres' mass), h = 19 R, while the 95th percentile of the
   centres is 18.1 R (numpy's linear interpolation at position 9 x 0.95 = 8.55 of 0..9).
4. A cubic lattice of spheres of two radii and masses, 20 layers: each layer's mass is
   symmetric about its centre plane, so 95 % (19 layers) lies below the top of layer 19, the
   plane between layers 19 and 20 (H 19/20 for a lattice of height H).
5. The pressure height: a linear profile from p_in at z = 0 to p_out at z = H0 and constant
   above reaches p_out + 5 % of the drop at 0.95 H0.
6. An ascii and a binary OpenFOAM volScalarField read back to the values written.
"""
import math
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "benchmarks", "coarse_grain"))
import bed_height as bh  # noqa: E402

failures = []


def check(name, got, want, tol):
    ok = abs(got - want) <= tol
    print(f"{'ok  ' if ok else 'FAIL'} {name}: {got:.12g} (expected {want:.12g}, tolerance {tol:g})")
    if not ok:
        failures.append(name)


# 1. Cap volume and the inverse.
R = 0.7
for s in (-1.0, -0.6, -0.1, 0.0, 0.35, 0.9, 1.0):
    h = R * (1 + s)
    cap = math.pi * h * h * (3 * R - h) / 3
    check(f"F({s})", float(bh.sphere_fraction_below(s)), cap / (4 * math.pi * R**3 / 3), 1e-14)
check("F(-2) = 0", float(bh.sphere_fraction_below(-2.0)), 0.0, 0.0)
check("F(3) = 1", float(bh.sphere_fraction_below(3.0)), 1.0, 0.0)
for q in (0.05, 0.5, 0.8, 0.95):
    check(f"F(s({q}))", float(bh.sphere_fraction_below(bh.sphere_quantile(q))), q, 1e-14)

# 2. One sphere.
for q in (0.5, 0.95):
    check(f"one sphere, q = {q}", bh.real_height([0.3], [R], [2.0], q, tol=1e-13),
          0.3 + R * bh.sphere_quantile(q), 1e-12)

# 3. A stack of ten touching spheres.
r = 1e-3
z = (2 * np.arange(10) + 1) * r
check("stack: real height / R", bh.real_height(z, np.full(10, r), np.ones(10)) / r, 19.0, 1e-5)
check("stack: centre height / R", bh.centre_height(z) / r, 18.1, 1e-9)

# 4. A two-size cubic lattice, 20 layers of 6 x 6 sites (spacing a, radii 0.4 a and 0.5 a).
a = 2e-3
ix, iy, iz = np.meshgrid(np.arange(6), np.arange(6), np.arange(20), indexing="ij")
zc = ((iz + 0.5) * a).ravel()
big = ((ix + iy) % 2 == 0).ravel()
rad = np.where(big, 0.5 * a, 0.4 * a)
mass = 2500 * 4 / 3 * math.pi * rad**3
check("lattice: real height / H", bh.real_height(zc, rad, mass) / (20 * a), 0.95, 1e-6)

# 5. Pressure profile.
zp = np.linspace(0, 0.24, 81)
p = np.where(zp < 0.05, 100.0 * (1 - zp / 0.05), 0.0) + 3.0
check("pressure height / H0", bh.pressure_height(zp, p) / 0.05, 0.95, 1e-12)

# 6. OpenFOAM field files.
values = np.array([1.5, -2.25, 3e-7, 4.0])
header = ("FoamFile\n{{\n    version     2.0;\n    format      {fmt};\n    class       volScalarField;\n"
          "    object      p;\n}}\ndimensions [0 2 -2 0 0 0 0];\n\ninternalField   nonuniform List<scalar> \n4\n(")
with tempfile.TemporaryDirectory() as tmp:
    for fmt in ("ascii", "binary"):
        body = (" ".join(repr(v) for v in values) + "\n").encode() if fmt == "ascii" else values.astype("<f8").tobytes()
        path = os.path.join(tmp, f"p_{fmt}")
        with open(path, "wb") as f:
            f.write(header.format(fmt=fmt).encode() + body + b")\n;\n\nboundaryField\n{\n}\n")
        got = bh.foam_scalar_field(path)
        check(f"{fmt} field", float(np.abs(got - values).max()) if len(got) == 4 else 1.0, 0.0, 0.0)

vectors = np.array([[1.5, -2.25, 3e-7], [4.0, 0.0, -1e3]])
vheader = header.replace("volScalarField", "volVectorField").replace("List<scalar> \n4", "List<vector> \n2")
with tempfile.TemporaryDirectory() as tmp:
    for fmt in ("ascii", "binary"):
        body = ("\n".join("(" + " ".join(repr(v) for v in row) + ")" for row in vectors) + "\n").encode() \
            if fmt == "ascii" else vectors.astype("<f8").tobytes()
        path = os.path.join(tmp, f"U_{fmt}")
        with open(path, "wb") as f:
            f.write(vheader.format(fmt=fmt).encode() + body + b")\n;\n\nboundaryField\n{\n}\n")
        got = bh.foam_vector_field(path)
        check(f"{fmt} vector field", float(np.abs(got - vectors).max()) if got.shape == (2, 3) else 1.0, 0.0, 0.0)

print("bed_height_test:", "FAILED " + ", ".join(failures) if failures else "all passed")
sys.exit(1 if failures else 0)
