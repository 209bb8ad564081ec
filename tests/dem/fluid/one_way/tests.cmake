# One-way fluid through the command line: 20 beads settling in water reach the
# Schiller–Naumann terminal velocity (checked in one_way_fluid_test; here: the scene
# runs and the fluid block is accepted).
grain_cli_test(fluid_settling 0 "done: [0-9]+ steps, 20 particles \\(0 removed\\)"
               CMD ${_grain} run ${_scenes}/fluid/settling.yaml --output out --no-progress
               WORKDIR ${_work}/fluid_settling)
