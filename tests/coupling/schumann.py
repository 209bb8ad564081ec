"""Reference solutions for a packed bed heated by a gas entering at its inlet (issue 21,
point 3), independent of grainflow: numpy only.

The one-dimensional two-phase model of a fixed bed with plug flow (Schumann 1929): fluid
temperature T(z, t), solid temperature T_s(z, t), superficial velocity U, void fraction eps,

  eps rho_f c_f dT/dt + rho_f c_f U dT/dz = eps k_f d2T/dz2 + h a (T_s - T)
  (1 - eps) rho_s c_s dT_s/dt             = h a (T - T_s)

with a = 6 (1 - eps) / d the particle surface per bed volume, T = T_s = T_0 at t = 0 and
T = T_in at the inlet z = 0 for t > 0. Schumann's model has k_f = 0 (no axial conduction);
then, in the dimensionless distance and the dimensionless time counted from the gas's arrival,

  xi = h a z / (rho_f c_f U),   eta = h a (t - eps z / U) / ((1 - eps) rho_s c_s),

the fluid and solid excess temperatures theta = (T - T_0) / (T_in - T_0) are (eta > 0)

  theta_f = 1 - int_0^xi  exp(-eta - s) I0(2 sqrt(eta s)) ds
  theta_s =     int_0^eta exp(-xi - s)  I0(2 sqrt(xi s))  ds

(Schumann's J function: theta_f = J(xi, eta), theta_s = 1 - J(eta, xi)); theta = 0 ahead of
the gas (eta < 0). The integrals are evaluated by Gauss-Legendre quadrature.

With k_f > 0 (`theta_fluid_conducting`) the Laplace transform in t of the fluid equation,
with the solid eliminated, is a constant-coefficient ODE in z whose decaying solution for a
semi-infinite bed with T = T_in at z = 0 is

  theta_f^(z, p) = exp(lambda(p) z) / p,
  lambda = (rho_f c_f U - sqrt((rho_f c_f U)^2 + 4 eps k_f g(p))) / (2 eps k_f),
  g(p) = eps rho_f c_f p + h a C_s p / (C_s p + h a),  C_s = (1 - eps) rho_s c_s,

inverted numerically by Talbot's contour (fixed-Talbot method of Abate & Valko 2004). At
k_f -> 0 it reduces to the transform of Schumann's solution: the two are independent
evaluations of the same model (checked by `self_check`).

h from Gunn (1978, eq. 21):
  Nu = (7 - 10 eps + 5 eps^2)(1 + 0.7 Re^0.2 Pr^1/3) + (1.33 - 2.4 eps + 1.2 eps^2) Re^0.7 Pr^1/3,
  Re = rho_f d U / mu (superficial velocity), Pr = c_f mu / k_f, h = Nu k_f / d.
"""
import math

import numpy as np

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(400)


def gunn_nusselt(eps, re, pr):
    """Gunn (1978), eq. 21, for a fixed or fluidised bed of void fraction eps."""
    return ((7 - 10 * eps + 5 * eps ** 2) * (1 + 0.7 * re ** 0.2 * pr ** (1 / 3)) +
            (1.33 - 2.4 * eps + 1.2 * eps ** 2) * re ** 0.7 * pr ** (1 / 3))


def _integral(x, y):
    """int_0^x exp(-y - s) I0(2 sqrt(y s)) ds by Gauss-Legendre (the integrand is an entire
    function of s: no singularity at s = 0)."""
    if x <= 0:
        return 0.0
    s = 0.5 * x * (_NODES + 1)
    arg = 2 * np.sqrt(y * s)
    # I0(z) e^-z is bounded: write the product as (I0(z) e^-z) exp(-(sqrt(y) - sqrt(s))^2).
    scaled = np.where(arg < 700, np.i0(np.minimum(arg, 700)) * np.exp(-np.minimum(arg, 700)),
                      1 / np.sqrt(2 * math.pi * np.maximum(arg, 1e-300)))
    f = scaled * np.exp(-(math.sqrt(y) - np.sqrt(s)) ** 2)
    return float(0.5 * x * np.dot(_WEIGHTS, f))


def theta_fluid(xi, eta):
    """Schumann's fluid excess temperature at dimensionless distance xi and time eta."""
    if eta < 0:
        return 0.0
    return 1.0 - _integral(xi, eta)


def theta_solid(xi, eta):
    """Schumann's solid excess temperature."""
    if eta <= 0:
        return 0.0
    return _integral(eta, xi)


class Bed:
    """A bed's numbers: d [m], eps, U [m/s] superficial, rho_f [kg/m3], mu [Pa s],
    c_f [J/(kg K)], k_f [W/(m K)], rho_s [kg/m3], c_s [J/(kg K)]; h from Gunn unless given."""

    def __init__(self, d, eps, u, rho_f, mu, c_f, k_f, rho_s, c_s, h=None):
        self.d, self.eps, self.u = d, eps, u
        self.rho_f, self.mu, self.c_f, self.k_f = rho_f, mu, c_f, k_f
        self.rho_s, self.c_s = rho_s, c_s
        self.re = rho_f * d * u / mu
        self.pr = c_f * mu / k_f
        self.nu = gunn_nusselt(eps, self.re, self.pr)
        self.h = self.nu * k_f / d if h is None else h
        self.a = 6 * (1 - eps) / d
        self.cap_s = (1 - eps) * rho_s * c_s       # J/(m3 K) of bed
        self.flow = rho_f * c_f * u                # W/(m2 K)

    def xi(self, z):
        return self.h * self.a * z / self.flow

    def eta(self, z, t):
        return self.h * self.a * (t - self.eps * z / self.u) / self.cap_s

    def fluid(self, z, t):
        return theta_fluid(self.xi(z), self.eta(z, t))

    def solid(self, z, t):
        return theta_solid(self.xi(z), self.eta(z, t))

    def energy_front(self, t):
        """Where a sharp front would be by the energy balance alone (h infinite)."""
        return self.flow * t / (self.cap_s + self.eps * self.rho_f * self.c_f)

    def fluid_conducting(self, z, t, k_axial=None, m=32):
        """theta_f with axial conduction eps k_axial d2T/dz2 in the fluid (default k_f),
        by fixed-Talbot inversion of the Laplace transform (M = m terms)."""
        k = self.k_f if k_axial is None else k_axial
        r = 2 * m / (5 * t)
        theta = np.arange(1, m) * math.pi / m
        cot = 1 / np.tan(theta)
        p = np.concatenate(([r], r * theta * (cot + 1j)))
        sigma = theta + (theta * cot - 1) * cot
        g = (self.eps * self.rho_f * self.c_f * p +
             self.h * self.a * self.cap_s * p / (self.cap_s * p + self.h * self.a))
        if k > 0:
            lam = (self.flow - np.sqrt(self.flow ** 2 + 4 * self.eps * k * g)) / (2 * self.eps * k)
        else:
            lam = -g / self.flow
        f = np.exp(lam * z) / p
        total = 0.5 * np.exp(r * t) * f[0].real + np.sum(
            (np.exp(t * p[1:]) * f[1:] * (1 + 1j * sigma)).real)
        return float(r / m * total)


def crossing(zs, values, level=0.5):
    """First z where the sampled profile (decreasing along z) falls to `level`, linearly
    interpolated between samples; nan if it does not."""
    zs, values = np.asarray(zs, float), np.asarray(values, float)
    for k in range(len(zs) - 1):
        if values[k] >= level > values[k + 1]:
            w = (values[k] - level) / (values[k] - values[k + 1])
            return float(zs[k] + w * (zs[k + 1] - zs[k]))
    return float("nan")


def front(profile, t, z_max, level=0.5, tol=1e-10):
    """z in (0, z_max) where profile(z, t) = level (profile decreasing in z), by bisection."""
    lo, hi = 0.0, z_max
    if profile(hi, t) > level:
        return float("nan")
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if profile(mid, t) > level:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def self_check(bed, times, z_max):
    """Largest |Schumann (Bessel) - Talbot at k = 0| of theta_f over a grid: the two
    evaluations of the same model agree (printed by the tests)."""
    worst = 0.0
    for t in times:
        for z in np.linspace(0.02, 0.98, 25) * min(z_max, bed.u * t / bed.eps):
            worst = max(worst, abs(bed.fluid(z, t) - bed.fluid_conducting(z, t, k_axial=0.0)))
    return worst
