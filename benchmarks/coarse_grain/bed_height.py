"""Bed heights of a particle snapshot and of a pressure profile (issue 23: real-particle
quantities from coarse-grained parcels).

centre_height     the q-quantile of the particle (parcel) centres' heights.
real_height       the height below which the fraction q of the real particles' mass lies, each
                  particle's (parcel's) mass spread over its sphere: a parcel of k^3 real
                  particles fills its volume with them, so its mass below a height h is
                  m F((h - z)/R), F(s) = (2 + 3 s - s^3)/4 for |s| <= 1 (the volume of a unit
                  sphere's cap below s over 4 pi/3; 0 below, 1 above).
pressure_height   the height at which a pressure profile p(z) (inlet to outlet) has fallen to
                  p_out + (1 - q)(p_in - p_out): in a fluidised bed the fluid carries the bed's
                  weight, so p(z) - p_out measures the weight above z.

Tested by tests/coupling/bed_height_test.py against closed forms.
"""
import math
import re

import numpy as np


def sphere_fraction_below(s):
    """Fraction of a sphere's volume below s radii from its centre (s clipped to [-1, 1])."""
    s = np.clip(s, -1.0, 1.0)
    return (2.0 + 3.0 * s - s**3) / 4.0


def sphere_quantile(q):
    """s in [-1, 1] with sphere_fraction_below(s) = q: s^3 - 3 s + 4 q - 2 = 0, s = 2 sin(phi)
    gives sin(3 phi) = 2 q - 1."""
    return 2.0 * math.sin(math.asin(2.0 * q - 1.0) / 3.0)


def centre_height(z, q=0.95):
    """The q-quantile of the centres' heights z (numpy's linear interpolation)."""
    return float(np.percentile(z, 100.0 * q))


def real_height(z, radius, mass, q=0.95, tol=1e-9):
    """Height below which the fraction q of the mass lies, each sphere's mass spread over its
    volume (centre z, radius, mass: arrays). Bisection on the monotone mass below h, to tol [m]."""
    z, radius, mass = (np.asarray(a, dtype=float) for a in (z, radius, mass))
    target = q * mass.sum()
    lo, hi = float((z - radius).min()), float((z + radius).max())
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if np.dot(mass, sphere_fraction_below((mid - z) / radius)) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def pressure_height(z, p, q=0.95):
    """Height at which p(z) (z increasing, p[0] the inlet's, p[-1] the outlet's) first falls to
    p[-1] + (1 - q)(p[0] - p[-1]), interpolated linearly between the samples."""
    z, p = np.asarray(z, dtype=float), np.asarray(p, dtype=float)
    level = p[-1] + (1.0 - q) * (p[0] - p[-1])
    i = int(np.argmax(p <= level))  # first sample at or below the level (i >= 1)
    return float(z[i - 1] + (z[i] - z[i - 1]) * (p[i - 1] - level) / (p[i - 1] - p[i]))


def foam_scalar_field(path):
    """The internalField of an OpenFOAM volScalarField file, ascii or binary (double)."""
    return foam_field(path, "scalar")


def foam_vector_field(path):
    """The internalField of an OpenFOAM volVectorField file as an (n, 3) array, ascii or binary."""
    return foam_field(path, "vector")


def foam_field(path, kind):
    """The nonuniform internalField of an OpenFOAM field file of `kind` scalar or vector."""
    raw = open(path, "rb").read()
    start = raw.index(b"internalField")
    head = raw[start:start + 200]
    if b"nonuniform" not in head.split(b";")[0]:
        raise ValueError(f"{path}: internalField is not a nonuniform list")
    tag = f"List<{kind}>".encode()
    i = raw.index(tag, start) + len(tag)
    j = raw.index(b"(", i)
    n = int(raw[i:j].split()[0])
    width = 1 if kind == "scalar" else 3
    if re.search(rb"format\s+binary", raw[:start]):
        values = np.frombuffer(raw[j + 1:j + 1 + 8 * width * n], dtype="<f8").copy()
    elif kind == "scalar":
        values = np.array(raw[j + 1:raw.index(b")", j)].split(), dtype=float)
    else:  # ascii vectors: n lines "(x y z)" between the list's brackets
        vectors = re.findall(rb"\(([^()]*)\)", raw[j + 1:])[:n]
        values = np.array(b" ".join(vectors).split(), dtype=float)
    return values if width == 1 else values.reshape(n, 3)
