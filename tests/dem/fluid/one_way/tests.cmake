# One-way fluid through the command line: 20 beads settling in water reach the
# Schiller–Naumann terminal velocity (checked in one_way_fluid_test; here: the scene
# runs and the fluid block is accepted).
grain_cli_test(fluid_settling 0 "done: [0-9]+ steps, 20 particles \\(0 removed\\)"
               CMD ${_grain} run ${_scenes}/fluid/settling.yaml --output out --no-progress
               WORKDIR ${_work}/fluid_settling)

# Every fluid force prints its stability time scale at `grain check`. The 10 um bead in
# shear with rotational drag at dt = 65 spin relaxation times: the torque is implicit, so the
# run ends; with an explicit torque the spin diverged to 9e111 rad/s. A lone bead without
# walls has no contact to resolve, so the Rayleigh and contact-time checks do not apply and
# both commands exit 0.
grain_cli_test(fluid_limits_check 0
               "fluid force rotational_drag: time scale I/K_r \\(Stokes: rho_p d\\^2/\\(60 mu\\)\\) = 4.167e-06 s \\(particle 1\\), dt/tau = 64.8[0-9]*; implicit in the spin"
               CMD ${_grain} check ${_scenes}/fluid/spin_shear.yaml)
grain_cli_test(fluid_spin_runs 0 "done: 1000 steps, 1 particles"
               CMD ${_grain} run ${_scenes}/fluid/spin_shear.yaml --output out --no-progress
               WORKDIR ${_work}/fluid_spin_runs)
# An explicit lift beyond its limit: refused at start-up, naming the force and a step.
grain_cli_test(fluid_lift_refused 1
               "dt = 0.02 s is beyond the stability limit of the fluid force 'saffman_mei' \\(dt <= 0.009794 s;.*use dt <= 0.00881[0-9] s"
               CMD ${_grain} check ${_scenes}/fluid/saffman_too_coarse.yaml)

# Coarse-grained parcels (docs/models/coarse-graining.md): `grain check` reports the real
# particles the parcels stand for (20 parcels of k = 2: 160 beads of 0.6 mm, 4.524e-5 kg),
# names the parcel class in the Rayleigh line, and warns (dem/engine/parcel_limits.hpp) that
# the 10 mm domain is narrower than 10 parcel diameters and that the 2.5 mm void-fraction cell
# is smaller than 3 parcel diameters (2.08), but not that it is smaller than a parcel.
grain_cli_test(coarse_grain_check 0
               "Rayleigh time t_R = [0-9.e-]+ s \\(smallest 'glass\\[k=2\\]' particle\\);'glass\\[k=2\\]': 20 parcels of k = 2 stand for 160 real particles, 4.5238[0-9]*e-05 kg in all;warning: the domain's narrowest side \\(0.01 m\\) is less than 10 diameters of parcels 'glass\\[k=2\\]' \\(0.0012 m\\);warning: parcels 'glass\\[k=2\\]' \\(diameter up to 0.0012 m\\) are wider than a third of the void-fraction cell \\(smallest 0.0025 m, typical 0.0025 m\\): cells of 2.08 parcel diameters"
               FORBID "are wider than the void-fraction cell"
               CMD ${_grain} check ${_scenes}/fluid/parcels.yaml)
# The same parcels from a stream: none exists at the start, and the class, its sizes and both
# warnings are there all the same (they were not: the limits saw only the particles present).
grain_cli_test(coarse_grain_check_stream 0
               "'glass\\[k=2\\]': 0 parcels of k = 2 stand for 0 real particles, 0 kg in all \\(real radius up to 0.0003 m, parcel radius up to 0.0006 m\\); none yet: a stream inserts them;warning: the domain's narrowest side \\(0.01 m\\) is less than 10 diameters of parcels 'glass\\[k=2\\]' \\(0.0012 m\\);warning: parcels 'glass\\[k=2\\]' \\(diameter up to 0.0012 m\\) are wider than a third of the void-fraction cell"
               CMD ${_grain} check ${_scenes}/fluid/parcel_stream.yaml)
# Run to its end (0.02 s at 1000 parcels/s: 20 parcels of k = 2), the stream's line and the
# closing line give the parcels and the 8 x 20 = 160 real particles they stand for; the counts
# of particles and removed ones count each parcel as one, and say so.
grain_cli_test(coarse_grain_run_stream 0
               "done: [0-9]+ steps, 20 particles \\(0 removed\\);coarse graining: the 20 particles stand for 160 real particles \\(4.5238[0-9]*e-05 kg\\); each parcel counts as one particle;stream .*parcel_stream.yaml:18: 20 particles \\(parcels of k = 2: 160 real particles\\)"
               CMD ${_grain} run ${_scenes}/fluid/parcel_stream.yaml --output out --no-progress
               WORKDIR ${_work}/coarse_grain_run_stream)
# A mesh wall's opening under 10 parcel diameters: the hopper tutorial's 12 mm orifice under
# parcels of k = 2 (4.4 mm) is 2.7 of them (docs/models/coarse-graining.md, "Limits").
grain_cli_test(coarse_grain_check_orifice 0
               "warning: wall 'hopper' has an opening 0.01199 m wide around \\(0, 0, 0\\) m: 2.72 diameters of parcels 'glass\\[k=2\\]' \\(0.004399 m\\), fewer than 10"
               CMD ${_grain} check ${_scenes}/coarse_grain_hopper.yaml)
