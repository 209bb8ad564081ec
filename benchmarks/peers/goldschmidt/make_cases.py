#!/usr/bin/python3
"""Writes the DPMFoam case and the equivalent grainFoam case of the Goldschmidt benchmark.

    make_cases.py DESCRIPTION OUTPUT_DIR [--positions SNAPSHOT.h5]

Every physical input is read from OpenFOAM's DPMFoam example named by DESCRIPTION's `source`
(Debian package openfoam-examples): mesh (system/blockMeshDict), fluid (rho.air, nu), fluid
time step, inflow (0/U.air bottom), gravity, particle positions, diameter and density
(kinematicCloudProperties), and the spring-slider-dashpot contact parameters. Writes

  OUTPUT_DIR/dpmfoam/    the example itself, endTime shortened, plus the bottom-pressure probe
  OUTPUT_DIR/grainfoam/  the same column as a grainFoam case (particles.yaml, particles.csv)
  OUTPUT_DIR/grainfoam_*/ the same with other couplingProperties (description: grainfoam_cases)
  OUTPUT_DIR/setup.json  the derived numbers (restitutions, DEM step, particle count)
  OUTPUT_DIR/settle/settle.yaml  the DEM-only scene that settles the example's particles
                         (description `start: settled`; run.sh runs it with `grain run`)

With --positions, both codes start from the particles of that grain snapshot (at rest)
instead of the example's lattice (kinematicCloudPositions is rewritten for DPMFoam).

What "the same" means here (docs/performance.md, "grainFoam against DPMFoam"):
- mesh: the example's blockMeshDict, its patches only renamed for grainFoam's boundary
  conditions where needed (none: the names are kept);
- fluid: rho, nu, the inflow (DPMFoam's interstitialInletVelocity with a superficial
  1.875 m/s is grainFoam's superficialVelocityInlet with the same superficial velocity),
  the top at p = 0, the walls no-slip, the x faces symmetry; PIMPLE settings and linear
  solvers as in the example;
- particles: the example's parcels carry nParticle = 1, so each parcel is one real sphere and
  grainFoam gets one DEM sphere per parcel at the same position (24 750 spheres of 2.5 mm,
  2526 kg/m3, Young's modulus and Poisson ratio as given); the contact law is Hertz with a
  Coulomb-limited tangential spring in both codes, with grainFoam's restitution set to the
  one DPMFoam's dashpot (alpha, b = 1.5) produces (integrated here) and the same friction;
- drag: DPMFoam's ErgunWenYuDrag is Gidaspow's switch (Ergun below a void fraction of 0.8,
  Wen-Yu above): grainFoam's `gidaspow`;
- time: the same fluid step; the DEM step follows grainFoam's rule (description), not
  DPMFoam's collision sub-cycling.
"""
import gzip
import json
import math
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import yaml


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def block(text, name):
    """The body of the first dictionary `name { ... }` in text (braces matched)."""
    m = re.search(r"(?<![\w.])" + re.escape(name) + r"\s*\{", text)
    if not m:
        raise KeyError(f"no dictionary '{name}'")
    depth, i = 1, m.end()
    while depth:
        depth += {"{": 1, "}": -1}.get(text[i], 0)
        i += 1
    return text[m.end():i - 1]


def entry(text, key):
    """The value of the first `key value;` entry at any depth of text."""
    m = re.search(r"(?<![\w.])" + re.escape(key) + r"\s+([^;{]+);", text)
    if not m:
        raise KeyError(f"no entry '{key}'")
    return m.group(1).strip()


def number(text, key):
    return float(entry(text, key))


def vector(text):
    return [float(v) for v in text.strip().strip("()").split()]


def read(path):
    return strip_comments(path.read_text())


def hertz_dashpot_restitution(alpha, e_star, r_eff, m_eff, speed=0.5):
    """Restitution of OpenFOAM's (Pair|Wall)SpringSliderDashpot with b = 1.5: m x'' =
    -k x^1.5 - alpha sqrt(m k) x^0.25 x', k = 4/3 sqrt(R) E*. The dashpot scales like the
    Hertz spring, so e does not depend on the impact speed. Integrated by RK4 over 4000 steps
    of the contact."""
    k = 4.0 / 3.0 * math.sqrt(r_eff) * e_star

    def accel(x, v):
        xp = max(x, 0.0)
        return (-k * xp**1.5 - alpha * math.sqrt(m_eff * k) * xp**0.25 * v) / m_eff

    # elastic Hertz contact time (Johnson 1985): 2.868 (m^2 / (R E*^2 v))^(1/5)
    t_c = 2.868 * (m_eff**2 / (r_eff * e_star**2 * speed))**0.2
    h = t_c / 4000
    x, v = 0.0, speed
    while True:
        k1x, k1v = v, accel(x, v)
        k2x, k2v = v + h / 2 * k1v, accel(x + h / 2 * k1x, v + h / 2 * k1v)
        k3x, k3v = v + h / 2 * k2v, accel(x + h / 2 * k2x, v + h / 2 * k2v)
        k4x, k4v = v + h * k3v, accel(x + h * k3x, v + h * k3v)
        x_new = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v_new = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if x_new < 0:  # separation: interpolate the velocity at x = 0
            return -(v + (v_new - v) * x / (x - x_new)) / speed
        x, v = x_new, v_new


def main():
    args = sys.argv[1:]
    snapshot = None
    if len(args) == 4 and args[2] == "--positions":
        snapshot = args[3]
    elif len(args) != 2:
        sys.exit("usage: make_cases.py DESCRIPTION OUTPUT_DIR [--positions SNAPSHOT.h5]")
    desc = yaml.safe_load(open(args[0]))
    out = Path(args[1])
    src = Path(desc["source"])
    if not (src / "constant/kinematicCloudProperties").exists():
        sys.exit(f"make_cases.py: {src} is not the DPMFoam Goldschmidt example "
                 "(install the Debian package openfoam-examples)")

    cloud = read(src / "constant/kinematicCloudProperties")
    transport = read(src / "constant/transportProperties")
    control = read(src / "system/controlDict")
    u_air = read(src / "0/U.air")
    g = vector(entry(read(src / "constant/g"), "value"))
    rho_f, nu = number(transport, "rho.air"), number(transport, "nu")
    dt_fluid = number(control, "deltaT")

    props = block(cloud, "constantProperties")
    rho_p, young, poisson = number(props, "rho0"), number(props, "youngsModulus"), \
        number(props, "poissonsRatio")
    inject = block(cloud, "injectionModels")
    if entry(inject, "type") != "manualInjection" or number(inject, "nParticle") != 1 \
            or entry(inject, "parcelBasisType") != "fixed":
        sys.exit("make_cases.py: expected manualInjection of fixed parcels of 1 particle")
    diameter = number(block(inject, "sizeDistribution"), "value")
    radius = diameter / 2
    if "ErgunWenYuDrag" not in block(cloud, "particleForces"):
        sys.exit("make_cases.py: expected ErgunWenYuDrag (grainFoam's gidaspow)")
    pair = block(cloud, "pairSpringSliderDashpotCoeffs")
    wall = block(cloud, "wallSpringSliderDashpotCoeffs")
    for coeffs in (pair, wall):
        if number(coeffs, "b") != 1.5 or entry(coeffs, "useEquivalentSize") != "no":
            sys.exit("make_cases.py: expected Hertzian springs (b 1.5, useEquivalentSize no)")
    wall_young, wall_poisson = number(wall, "youngsModulus"), number(wall, "poissonsRatio")

    mass = rho_p * math.pi / 6 * diameter**3
    e_star_pair = young / (2 * (1 - poisson**2))
    e_star_wall = 1 / ((1 - poisson**2) / young + (1 - wall_poisson**2) / wall_young)
    e_pair = hertz_dashpot_restitution(number(pair, "alpha"), e_star_pair, radius / 2, mass / 2)
    e_wall = hertz_dashpot_restitution(number(wall, "alpha"), e_star_wall, radius, mass)

    # grainFoam's DEM step: dem_rayleigh_fraction t_R, rounded down to dt_fluid / n.
    shear = young / (2 * (1 + poisson))
    t_rayleigh = math.pi * radius * math.sqrt(rho_p / shear) / (0.1631 * poisson + 0.8766)
    n_sub = math.ceil(dt_fluid / (desc["dem_rayleigh_fraction"] * t_rayleigh) - 1e-9)
    dt_dem = dt_fluid / n_sub

    bottom = block(u_air, "bottom")
    if entry(bottom, "type") != "interstitialInletVelocity":
        sys.exit("make_cases.py: expected interstitialInletVelocity at the bottom")
    u_superficial = vector(entry(bottom, "inletVelocity").replace("uniform", ""))

    mesh = read(src / "system/blockMeshDict")
    scale = number(mesh, "scale")
    verts = [[scale * c for c in vector(v)]
             for v in re.findall(r"\([^()]*\)", block_list(mesh, "vertices"))]
    lo = [min(v[i] for v in verts) for i in range(3)]
    hi = [max(v[i] for v in verts) for i in range(3)]

    pos_text = gzip.open(src / "constant/kinematicCloudPositions.gz", "rt").read()
    positions = [vector(v) for v in re.findall(r"\(([-\d.eE+ ]+)\)", strip_comments(pos_text))]
    if snapshot:
        import h5py
        with h5py.File(snapshot, "r") as f:
            if len(f["position"]) != len(positions):
                sys.exit(f"make_cases.py: {snapshot} holds {len(f['position'])} particles, "
                         f"the example {len(positions)}")
            speed = float(np.max(np.linalg.norm(f["velocity"][:], axis=1)))
            positions = [list(map(float, x)) for x in f["position"][:]]
        print(f"make_cases.py: starting from {snapshot} (largest speed there {speed:.3g} m/s; "
              "both codes start at rest)")

    if out.exists():
        shutil.rmtree(out)
    end, write = desc["end_time"], desc["write_interval"]

    # --- DPMFoam: the example, shortened -----------------------------------------------
    dpm = out / "dpmfoam"
    shutil.copytree(src, dpm)
    (dpm / "constant/kinematicCloudPositions.gz").unlink()
    (dpm / "constant/kinematicCloudPositions").write_text(
        "FoamFile\n{\n    version 2.0;\n    format ascii;\n    class vectorField;\n"
        "    object kinematicCloudPositions;\n}\n\n"
        + (f"// The settled bed of {snapshot}\n" if snapshot else "")
        + f"{len(positions)}\n(\n"
        + "".join(f"({p[0]:.9g} {p[1]:.9g} {p[2]:.9g})\n" for p in positions) + ")\n")
    text = (dpm / "system/controlDict").read_text()
    text = re.sub(r"\nendTime\s+[^;]+;", f"\nendTime         {end};", text)
    # One write, at the end: DPMFoam's lagrangian output is not part of the comparison.
    text = re.sub(r"\nwriteInterval\s+[^;]+;", f"\nwriteInterval   {end};", text)
    text = re.sub(r"\nstartFrom\s+[^;]+;", "\nstartFrom       startTime;", text)
    text += pressure_probe("p", "phi.air")
    (dpm / "system/controlDict").write_text(text)

    # --- grainFoam ---------------------------------------------------------------------
    gf = out / "grainfoam"
    for d in ("0", "constant", "system"):
        (gf / d).mkdir(parents=True)
    shutil.copy(src / "system/blockMeshDict", gf / "system/blockMeshDict")
    shutil.copy(src / "system/decomposeParDict", gf / "system/decomposeParDict")
    header = lambda cls, obj: ("FoamFile\n{\n    version 2.0;\n    format ascii;\n"
                               f"    class {cls};\n    object {obj};\n}}\n")
    us = " ".join(f"{c:g}" for c in u_superficial)
    (gf / "0/U").write_text(header("volVectorField", "U") + f"""
// Written by make_cases.py from {src}/0/U.air.
dimensions      [0 1 -1 0 0 0 0];
internalField   uniform (0 0 0);
boundaryField
{{
    walls        {{ type noSlip; }}
    top          {{ type pressureInletOutletVelocity; inletValue uniform (0 0 0); value uniform (0 0 0); }}
    // DPMFoam: interstitialInletVelocity, inletVelocity ({us}) = the superficial velocity
    bottom       {{ type superficialVelocityInlet; superficialVelocity constant ({us}); value uniform (0 0 0); }}
    frontAndBack {{ type symmetry; }}
}}
""")
    (gf / "0/p").write_text(header("volScalarField", "p") + """
// Kinematic pressure without its hydrostatic part (DPMFoam's p includes g.x).
dimensions      [0 2 -2 0 0 0 0];
internalField   uniform 0;
boundaryField
{
    walls        { type zeroGradient; }
    top          { type fixedValue; value uniform 0; }
    bottom       { type fixedFluxPressure; }
    frontAndBack { type symmetry; }
}
""")
    (gf / "constant/transportProperties").write_text(
        header("dictionary", "transportProperties") + f"\nrho {rho_f:g};\nnu  {nu:g};\n")
    coupling_properties = lambda case: header("dictionary", "couplingProperties") + f"""
scene            "particles.yaml";
voidFraction     {case['void_fraction']};
sampling         {case['sampling']};
minVoidFraction  {desc['min_void_fraction']};
ddtVoidFraction  on;
"""
    (gf / "system/controlDict").write_text(header("dictionary", "controlDict") + f"""
application     grainFoam;
libs            ("libgrainflowFoamBCs.so");
startFrom       startTime;
startTime       0;
stopAt          endTime;
endTime         {end};
deltaT          {dt_fluid:g};      // {n_sub} DEM steps of {dt_dem:.6g} s
adjustTimeStep  no;
writeControl    runTime;
writeInterval   {write};
purgeWrite      0;
writeFormat     binary;
writePrecision  8;
writeCompression off;
timeFormat      general;
timePrecision   6;
runTimeModifiable false;
""" + pressure_probe("p", "phi"))
    fv_solution = read(src / "system/fvSolution")
    p_solver = block(fv_solution, '"(p|kinematicCloud:theta)"')
    u_solver = block(fv_solution, '"(U.air|k|omega)"')
    pimple = block(fv_solution, "PIMPLE")
    (gf / "system/fvSolution").write_text(header("dictionary", "fvSolution") + f"""
// The solvers and PIMPLE settings of {src}/system/fvSolution.
solvers
{{
    p      {{ {' '.join(p_solver.split())} }}
    pFinal {{ $p; relTol 0; }}
    U      {{ {' '.join(u_solver.split())} }}
    UFinal {{ $U; relTol 0; }}
}}
PIMPLE
{{
    nOuterCorrectors {entry(pimple, 'nOuterCorrectors')};
    nCorrectors {entry(pimple, 'nCorrectors')};
    nNonOrthogonalCorrectors {entry(pimple, 'nNonOrthogonalCorrectors')};
    momentumPredictor {entry(pimple, 'momentumPredictor')};
}}
""")
    (gf / "system/fvSchemes").write_text(header("dictionary", "fvSchemes") + """
// As the example's: Euler, linear gradients, linearUpwindV convection.
ddtSchemes      { default Euler; }
gradSchemes     { default Gauss linear; }
divSchemes
{
    default         none;
    div(phi,U)      Gauss linearUpwindV unlimited;
    div(((c*nu)*dev2(T(grad(U))))) Gauss linear;
}
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes   { default corrected; }
""")
    if snapshot:
        shutil.copy(snapshot, gf / "settled.h5")
    with open(gf / "particles.csv", "w") as f:
        f.write("# The parcels of DPMFoam's constant/kinematicCloudPositions (nParticle 1 each).\n")
        f.write("x,y,z,radius\n")
        for p in positions:
            f.write(f"{p[0]:.9g},{p[1]:.9g},{p[2]:.9g},{radius:.9g}\n")
    names = ["left", "right", "front", "back", "bottom", "top"]
    walls = []
    for axis in range(3):
        for side, (point, sign) in enumerate(((lo, 1), (hi, -1))):
            normal = [0, 0, 0]
            normal[axis] = sign
            at = [0.0, 0.0, 0.0]
            at[axis] = point[axis]
            walls.append({"type": "plane", "name": names[2 * axis + side], "point": at,
                          "normal": normal, "material": "wall"})
    scene = {
        "domain": {"min": lo, "max": hi},
        "gravity": g,
        "time": {"step": dt_dem, "end": end, "expected_max_speed": 1.0},
        "materials": [
            {"name": "glass", "youngs_modulus": young, "poisson_ratio": poisson,
             "density": rho_p},
            {"name": "wall", "youngs_modulus": wall_young, "poisson_ratio": wall_poisson,
             "density": rho_p},
        ],
        "interactions": [
            {"materials": ["glass", "glass"], "restitution": round(e_pair, 4),
             "friction": number(pair, "mu")},
            {"materials": ["glass", "wall"], "restitution": round(e_wall, 4),
             "friction": number(wall, "mu")},
            {"materials": ["wall", "wall"], "restitution": round(e_wall, 4),
             "friction": number(wall, "mu")},
        ],
        "contact": {"normal": "hertz", "tangential": "history"},
        "walls": walls,
        # From the settled bed: grain's own snapshot (a settled sphere may touch a wall by a
        # little overlap, which a CSV insertion refuses and a snapshot allows), at rest.
        "insert": [{"type": "snapshot", "file": "settled.h5", "keep_velocity": False}
                   if snapshot else {"type": "csv", "file": "particles.csv", "material": "glass"}],
        "fluid": {"density": rho_f, "viscosity": rho_f * nu, "drag": "gidaspow", "model": "A",
                  "pressure": {"hydrostatic": False},
                  "forces": ["drag", "pressure_gradient", "viscous", "buoyancy"]},
    }
    with open(gf / "particles.yaml", "w") as f:
        f.write(f"# Written by benchmarks/peers/goldschmidt/make_cases.py from {src}.\n"
                f"# DEM step {dt_dem:.6g} s = {dt_dem / t_rayleigh:.3f} t_R "
                f"(t_R = {t_rayleigh:.4g} s), {n_sub} per fluid step of {dt_fluid:g} s.\n"
                f"# Restitution from DPMFoam's dashpots: pair alpha {number(pair, 'alpha')} "
                f"-> e = {e_pair:.4f}, wall alpha {number(wall, 'alpha')} -> e = {e_wall:.4f}.\n")
        yaml.safe_dump(scene, f, sort_keys=False, default_flow_style=None)

    # The other grainFoam cases differ in couplingProperties only.
    cases = desc["grainfoam_cases"]
    (gf / "constant/couplingProperties").write_text(coupling_properties(cases["grainfoam"]))
    for name, case in cases.items():
        if name != "grainfoam":
            shutil.copytree(gf, out / name)
            (out / name / "constant/couplingProperties").write_text(coupling_properties(case))

    # The DEM-only settling of the example's particles (an initial condition for both codes):
    # no fluid; restitution lowered to settle_restitution so that the bed comes to rest sooner;
    # the lattice jittered (below).
    settle = dict(scene, fluid=None)
    del settle["fluid"]
    settle["time"] = {"step": dt_dem, "end": desc["settle_time"], "expected_max_speed": 2.0}
    settle["insert"] = [{"type": "csv", "file": "particles_jittered.csv", "material": "glass"}]
    settle["interactions"] = [dict(i, restitution=desc["settle_restitution"])
                              for i in scene["interactions"]]
    settle["output"] = {"directory": str(out / "settle/output"),
                        "snapshot_interval": desc["settle_time"] / 3, "progress": False}
    (out / "settle").mkdir()
    # The lattice is simple cubic, each sphere straight above another: left alone it settles
    # into towers of touching spheres. Every coordinate is moved by a uniform random amount of
    # at most settle_jitter (< half the 0.5 mm gaps) so that it packs like a poured bed.
    rng = np.random.default_rng(desc["settle_seed"])
    jitter = desc["settle_jitter"]
    with open(out / "settle/particles_jittered.csv", "w") as f:
        f.write(f"# The example's lattice, each coordinate moved by up to {jitter} m.\n")
        f.write("x,y,z,radius\n")
        for p in positions:
            q = np.array(p) + rng.uniform(-jitter, jitter, 3)
            f.write(f"{q[0]:.9g},{q[1]:.9g},{q[2]:.9g},{radius:.6g}\n")
    with open(out / "settle/settle.yaml", "w") as f:
        f.write("# Written by make_cases.py: the example's particles settled without fluid.\n")
        yaml.safe_dump(settle, f, sort_keys=False, default_flow_style=None)

    setup = {"codes": ["dpmfoam", *cases], "particles": len(positions), "diameter": diameter, "rho_p": rho_p, "mass": mass,
             "rho_f": rho_f, "nu": nu, "g": g, "dt_fluid": dt_fluid, "dt_dem": dt_dem,
             "dem_steps_per_fluid_step": n_sub, "t_rayleigh": t_rayleigh,
             "restitution_pair": e_pair, "restitution_wall": e_wall,
             "superficial_velocity": u_superficial, "domain": [lo, hi],
             "end_time": end, "start": "settled" if snapshot else "lattice", "startup": desc["startup"], "write_interval": write}
    (out / "setup.json").write_text(json.dumps(setup, indent=1))
    print(f"make_cases.py: {len(positions)} spheres of d = {diameter} m; restitution pair "
          f"{e_pair:.4f}, wall {e_wall:.4f}; DEM step {dt_dem:.4g} s = "
          f"{dt_dem / t_rayleigh:.3f} t_R ({n_sub} per fluid step {dt_fluid:g} s)")


def block_list(text, name):
    """The body of `name ( ... );` (parentheses matched)."""
    m = re.search(r"(?<![\w.])" + re.escape(name) + r"\s*\(", text)
    depth, i = 1, m.end()
    while depth:
        depth += {"(": 1, ")": -1}.get(text[i], 0)
        i += 1
    return text[m.end():i - 1]


def pressure_probe(p_name, phi_name):
    """Area-averaged pressure on the bottom patch every step (the top is p = 0)."""
    return f"""
functions
{{
    pBottom
    {{
        type            surfaceFieldValue;
        libs            ("libfieldFunctionObjects.so");
        writeControl    timeStep;
        writeInterval   1;
        log             false;
        writeFields     false;
        regionType      patch;
        name            bottom;
        operation       areaAverage;
        fields          ({p_name});
    }}
}}
"""


if __name__ == "__main__":
    main()
