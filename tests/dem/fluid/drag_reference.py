#!/usr/bin/env python3
"""Reference drag coefficients for tests/dem/fluid/drag_laws_test.cpp.

Recomputes K (F = K (u_f - v), drag excluding the mean-pressure part) from each
paper's formula as published — drag coefficient C_D, interphase coefficient beta,
pressure drop, or total-force ratio F — with plain Python floats, independently of
the C++ algebra. Run:  python3 tests/dem/fluid/drag_reference.py
and paste the printed rows into kReference in drag_laws_test.cpp.

Conventions (docs/models/fluid-forces.md): Re = rho eps d U / mu (superficial slip);
Re0 = rho d U / mu (single sphere); laws written for the total force F_total (Koch-Hill,
Tenneti, Ergun's pressure drop) give the drag as eps * F_total; Beetstra's F is already
normalised as the drag (its Carman-Kozeny limit is 10 phi/eps^2, not 10 phi/eps^3).
"""
import math

D, RHO, MU = 1.0e-3, 1000.0, 1.0e-3          # glass-bead-in-water-like case [m, kg/m3, Pa s]
VOLUME = math.pi * D**3 / 6
VOID_FRACTIONS = [0.4, 0.6, 0.85, 0.95]
REYNOLDS = [0.1, 10.0, 500.0, 2000.0]        # superficial Re; U = Re mu / (rho eps d)


def cd_schiller_naumann(re):
    return 24.0 / re * (1.0 + 0.15 * re**0.687) if re < 1000.0 else 0.44


def schiller_naumann(eps, u):
    re0 = RHO * D * u / MU
    force = 0.5 * cd_schiller_naumann(re0) * RHO * (math.pi * D * D / 4.0) * u * u
    return force / u


def di_felice_like(eps, u, chi_of):
    re = RHO * eps * D * u / MU
    cd = (0.63 + 4.8 / math.sqrt(re))**2
    f0 = 0.5 * cd * RHO * (math.pi * D * D / 4.0) * (eps * u)**2
    return f0 * eps**(-chi_of(eps, re)) / u


def bell(re):
    return math.exp(-(1.5 - math.log10(re))**2 / 2.0)


def di_felice(eps, u):
    return di_felice_like(eps, u, lambda e, re: 3.7 - 0.65 * bell(re))


def rong(eps, u):
    return di_felice_like(eps, u, lambda e, re: 2.65 * (e + 1) - (5.3 - 3.5 * e) * e * e * bell(re))


def wen_yu(eps, u):
    re = RHO * eps * D * u / MU
    phi = 1.0 - eps
    beta = 0.75 * cd_schiller_naumann(re) * eps * phi * RHO * u * eps**-2.65 / D
    return beta * VOLUME / phi                                   # per particle: n = phi / V


def ergun(eps, u):
    phi, us = 1.0 - eps, eps * u
    dp_per_length = 150.0 * MU * phi**2 * us / (eps**3 * D * D) + 1.75 * RHO * phi * us * us / (eps**3 * D)
    total_force = dp_per_length * VOLUME / phi                  # dp/L = n F_total
    return eps * total_force / u


def gidaspow(eps, u):
    return ergun(eps, u) if eps < 0.8 else wen_yu(eps, u)


def from_total_ratio(eps, u, ratio):
    total_force = 3.0 * math.pi * MU * D * (eps * u) * ratio   # F normalised by Stokes at eps U
    return eps * total_force / u


def koch_hill(eps, u):
    phi = 1.0 - eps
    if phi < 0.4:
        f0 = (1 + 3 * math.sqrt(phi / 2) + 135.0 / 64.0 * phi * math.log(phi) + 16.14 * phi) / \
             (1 + 0.681 * phi - 8.48 * phi**2 + 8.16 * phi**3)
    else:
        f0 = 10 * phi / eps**3
    f3 = 0.0673 + 0.212 * phi + 0.0232 / eps**5
    re_radius = RHO * eps * (D / 2) * u / MU                    # Koch & Hill use the radius
    return from_total_ratio(eps, u, f0 + f3 * re_radius)


def beetstra(eps, u):
    phi = 1.0 - eps
    re = RHO * eps * D * u / MU
    f = 10 * phi / (1 - phi)**2 + (1 - phi)**2 * (1 + 1.5 * math.sqrt(phi)) + \
        0.413 * re / (24 * (1 - phi)**2) * (1 / (1 - phi) + 3 * phi * (1 - phi) + 8.4 * re**-0.343) / \
        (1 + 10**(3 * phi) * re**(-(1 + 4 * phi) / 2))
    # van der Hoef et al. (2005) normalisation: F = F_drag / (3 pi mu d eps U), Stokes limit
    # 10 phi/eps^2 (Carman-Kozeny with the factor eps of F_drag = eps F_total inside).
    return 3.0 * math.pi * MU * D * (eps * u) * f / u


def tenneti(eps, u):
    phi = 1.0 - eps
    re = RHO * eps * D * u / MU
    f_isol = 1 + 0.15 * re**0.687
    f_phi = 5.81 * phi / (1 - phi)**3 + 0.48 * phi**(1.0 / 3.0) / (1 - phi)**4
    f_phi_re = phi**3 * re * (0.95 + 0.61 * phi**3 / (1 - phi)**2)
    return from_total_ratio(eps, u, f_isol / (1 - phi)**3 + f_phi + f_phi_re)


LAWS = [("schiller_naumann", schiller_naumann), ("di_felice", di_felice), ("rong", rong),
        ("wen_yu", wen_yu), ("ergun", ergun), ("gidaspow", gidaspow), ("koch_hill", koch_hill),
        ("beetstra", beetstra), ("tenneti_garg_subramaniam", tenneti)]

if __name__ == "__main__":
    print(f"// d = {D}, rho_f = {RHO}, mu = {MU}; columns: law, eps, U [m/s], K [kg/s]")
    for name, law in LAWS:
        for eps in VOID_FRACTIONS:
            for re in REYNOLDS:
                u = re * MU / (RHO * eps * D)
                print(f'    {{"{name}", {eps!r}, {u!r}, {law(eps, u)!r}}},')
