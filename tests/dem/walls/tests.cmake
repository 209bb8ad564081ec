# The walls' travel guard and the start-up report through the command line.
# fast_rod.yaml: a rod (r 0.5 mm) at 150 m/s with dt = 2.5e-5 s against a bead of r = 1 mm,
# 150 x 2.5e-5 / 1e-3 = 3.75 radii per step: refused by check and by run, with the steps
# that fit (1e-3 / (2 x 150) = 3.33e-6 s, rounded down, lowered to the 1.81e-7 s that the
# start-up contact-time check of the same dt accepts) and that resolve the impact.
set(_fast_rod_refusal
    "fast_rod.yaml: error: wall 'rod' moves 3.75 x the smallest particle radius per step \\(sweep speed 150 m/s x dt = 2.5e-05 s = 0.00375 m; smallest radius 0.001 m\\); the limit is 1 \\(key time.max_step_travel;A step of at most 1.81e-07 s fits;twice the wall's speed \\(3.33e-06 s\\); the start-up checks of dt \\(the Rayleigh and contact times\\) need at most 1.81e-07 s;on the wall at 150 m/s needs at most 8.28e-08 s")
grain_cli_test(walls_fast_rod_check_refused 1 "${_fast_rod_refusal}"
               CMD ${_grain} check ${_scenes}/walls/fast_rod.yaml)
grain_cli_test(walls_fast_rod_run_refused 1 "${_fast_rod_refusal}"
               CMD ${_grain} run ${_scenes}/walls/fast_rod.yaml --output out
               WORKDIR ${_work}/walls_fast_rod FORBID "done:")
# The first proposed step is accepted by every start-up check and runs to the end.
grain_cli_test(walls_fast_rod_first_proposal_run 0 "done: 552 steps, 1 particles \\(0 removed\\)"
               CMD ${_grain} run ${_scenes}/walls/fast_rod_first_proposal.yaml --output out
               WORKDIR ${_work}/walls_fast_rod_first_proposal FORBID "error:")
# At the proposed impact step the check reports the rod's travel and the run strikes the
# bead (the physics of the rebound, (1 + e) U, is checked in wall_travel_test).
grain_cli_test(walls_fast_rod_proposed_step 0
               "wall 'rod' moves 1.242e-05 m per step \\(sweep speed 150 m/s x dt = 8.28e-08 s\\) = 0.01242 x the smallest radius 0.001 m; limit 1 \\(key time.max_step_travel\\)"
               CMD ${_grain} check ${_scenes}/walls/fast_rod_fitting_step.yaml)
grain_cli_test(walls_fast_rod_proposed_step_run 0 "done: 1208 steps, 1 particles \\(0 removed\\)"
               CMD ${_grain} run ${_scenes}/walls/fast_rod_fitting_step.yaml --output out
               WORKDIR ${_work}/walls_fast_rod_proposed)
# A scene without particles says so (it printed "radius inf .. 0 m").
grain_cli_test(check_empty_scene 0
               "particles: 0 \\(the scene has no particles: no insertion entry placed any\\)"
               CMD ${_grain} check ${_scenes}/walls/empty.yaml FORBID "inf")
# A void-fraction grid of 1000^3 cells is refused before allocation (it died with
# std::bad_alloc after grain check had accepted it).
set(_huge_grid
    "huge_void_fraction_grid.yaml:23: error: fluid.void_fraction: cell_size 0.002 m over the domain's 2 x 2 x 2 m gives 1000 x 1000 x 1000 = 1e.09 cells, 16 GB on every rank; the limit is 67108864 cells \\(1.074 GB\\). Use cell_size >= 0.00493 m")
grain_cli_test(huge_void_fraction_grid_check 1 "${_huge_grid}"
               CMD ${_grain} check ${_scenes}/fluid/huge_void_fraction_grid.yaml FORBID "bad_alloc")
grain_cli_test(huge_void_fraction_grid_run 1 "${_huge_grid}"
               CMD ${_grain} run ${_scenes}/fluid/huge_void_fraction_grid.yaml --output out
               WORKDIR ${_work}/huge_void_fraction_grid FORBID "bad_alloc")
