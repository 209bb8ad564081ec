# Coupled cases of the hard-case stress suite (issue "Hard cases stay numerically stable";
# docs/stability.md), included by tests/CMakeLists.txt. Each runs
# tests/coupling_stress/stress_cases.py on fresh copies of cases from
# tests/coupling_stress/cases/ in the build tree; the invariants, references and tolerances
# are stated in that script, one function per test. Every run is checked for: no nan/inf
# in the log, snapshots or written voidfraction; particle count conserved, none removed;
# eps within [minVoidFraction, 1]; printed volume difference and exchange imbalance < 1e-12.
#
#   coupling_stress.dense_bed_10x_umf  cases/dense_bed: 300 beads d = 1 mm on a bcc lattice
#       (eps = 0.39), 5.4 m/s air (10 U_mf) switched on within one fluid step: finite, no
#       bead through the distributor or the lid by more than max_overlap r, none lost.
#   coupling_stress.particles_larger_than_cells  cases/large_particles: d / dx = 0.5, 1, 2, 3
#       with smoothed, and centre at 3: the volume recomputed from every written field
#       (clamped volume counted) to 1e-12; centre reports clamped cell-steps > 0.
#   coupling_stress.on_faces_and_corners_2ranks  cases/faces_corners: beads centred exactly
#       on cell faces, edges, corners, the processor plane and the periodic faces; centre,
#       divided, smoothed at rest and divided in a flow, on 1 and 2 ranks (simple (2 1 1)):
#       eps(2 ranks) = eps(1 rank) to 1e-12. It found that ParticleCoupling::locate put a
#       point exactly on an interior cell face in a cell that depended on the rank's grid
#       origin (fixed: global origin and spacing; see docs/stability.md).
#   coupling_stress.crowded_cell_2ranks  cases/crowded: 27 beads in one cell (0.905 of its
#       volume), centre and divided, 1 and 2 ranks: with centre eps = minVoidFraction exactly
#       there and 1 elsewhere, the clamped volume V_c (eps_min - eps_raw) to 1e-12; 2 ranks =
#       1 rank to 1e-12.
#   coupling_stress.emptied_and_refilled_cells  cases/convected: a slab of 60 beads launched
#       at 5 m/s round a periodic box of 8 x 2 x 2 cells, 5 laps: every cell is exactly 1 at
#       some writes and < 1 at others, >= 4 empty -> filled transitions per cell.
#   coupling_stress.fast_crossing_ranks  the same slab for 2 laps on 1, 2 and 4 ranks: every
#       rank empty at >= 2 writes; agreement with 1 rank to round-off until the first bead
#       changes rank, then within the bound set by samples taken on arrival.
# Run time on 2 cores: each under 60 s (measured figures in docs/stability.md).
if(NOT TARGET grainFoam OR NOT TARGET grainflowFoamBCs)
  return()
endif()

# h5py reads the particle snapshots (scripts/python.sh picks the Python).
grainflow_find_python(GRAINFLOW_STRESS_PYTHON "h5py,numpy,yaml" "the coupling_stress.* tests are")
if(NOT GRAINFLOW_STRESS_PYTHON)
  return()
endif()

function(grainflow_coupling_stress_test name ranks)
  add_test(NAME coupling_stress.${name}
           COMMAND ${GRAINFLOW_STRESS_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/stress_cases.py ${name}
                   --foam-env ${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                   --solver $<TARGET_FILE:grainFoam>
                   --mpiexec ${MPIEXEC_EXECUTABLE}
                   --lib-dir $<TARGET_FILE_DIR:grainflowFoamBCs>
                   --cases ${CMAKE_CURRENT_LIST_DIR}/cases
                   --work ${CMAKE_CURRENT_BINARY_DIR}/coupling_stress/${name})
  set_tests_properties(coupling_stress.${name} PROPERTIES
    ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
    LABELS "foam;coupling;stress"
    PROCESSORS ${ranks}
    TIMEOUT 60)
endfunction()

grainflow_coupling_stress_test(dense_bed_10x_umf 1)
grainflow_coupling_stress_test(particles_larger_than_cells 1)
grainflow_coupling_stress_test(on_faces_and_corners_2ranks 2)
grainflow_coupling_stress_test(crowded_cell_2ranks 2)
grainflow_coupling_stress_test(emptied_and_refilled_cells 1)
grainflow_coupling_stress_test(fast_crossing_ranks 2)
# Five grainFoam runs, two of them on 4 ranks oversubscribed on 2 cores: 15-20 s alone, but
# slow when the machine is shared.
set_tests_properties(coupling_stress.fast_crossing_ranks PROPERTIES TIMEOUT 180)

# coupling_stress.random_cases (tests/coupling_stress/random_coupled.py): random coupled
# cases drawn per seed (columns of 2-5 x 2-5 x 6-14 cells, periodic or walled sides, gas or
# liquid, beads of 0.15-1.2 cells, parcels, every drag law, centre or divided, cell or
# cellPoint, 1 or 2 ranks), each checked for the invariants above, particles clear of the
# walls, or a refusal that names what to change; when grainFoam's message names void-fraction
# settings that smooth a jumping eps, each is rerun and must carry the run further; each case
# that ends is restarted from a middle write and must end bit for bit alike. Seeds 3, 17 and
# 23 are the cases that found the divergence in the fluid solve (a crash in OpenFOAM's
# floating-point trap), the fluid-driven DEM stop and the restart's time (docs/stability.md).
add_test(NAME coupling_stress.random_cases
         COMMAND ${GRAINFLOW_STRESS_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/random_coupled.py
                 --foam-env ${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                 --solver $<TARGET_FILE:grainFoam>
                 --mpiexec ${MPIEXEC_EXECUTABLE}
                 --lib-dir $<TARGET_FILE_DIR:grainflowFoamBCs>
                 --cases ${CMAKE_CURRENT_LIST_DIR}/cases
                 --work ${CMAKE_CURRENT_BINARY_DIR}/coupling_stress/random_cases
                 --seeds 0:8,17,23 --timeout 60)
set_tests_properties(coupling_stress.random_cases PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
  LABELS "foam;coupling;stress"
  PROCESSORS 2
  TIMEOUT 300)

# coupling_stress.twin_cases (tests/coupling_stress/twin_cases.py): random coupled cases 0 (2
# ranks, parcels, a periodic side) and 8 run as drawn, turned (gravity along -x: mesh,
# inlet, decomposition and scene turned together) and moved 0.01-10 m from the origin, the
# fluid solved to 1e-15: every particle of a twin ends within 1e-6 of a diameter of the
# drawn case's.
add_test(NAME coupling_stress.twin_cases
         COMMAND ${GRAINFLOW_STRESS_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/twin_cases.py
                 --foam-env ${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                 --solver $<TARGET_FILE:grainFoam>
                 --grain $<TARGET_FILE:grain>
                 --mpiexec ${MPIEXEC_EXECUTABLE}
                 --lib-dir $<TARGET_FILE_DIR:grainflowFoamBCs>
                 --cases ${CMAKE_CURRENT_LIST_DIR}/cases
                 --work ${CMAKE_CURRENT_BINARY_DIR}/coupling_stress/twin_cases
                 --seeds 0,8 --twins turn1,shift --timeout 120)
set_tests_properties(coupling_stress.twin_cases PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
  LABELS "foam;coupling;stress"
  PROCESSORS 2
  TIMEOUT 240)
# coupling_stress.scale_twin_case: random coupled case 9 in other units (twin_cases.py
# --twins scale: lengths times 2^-12, so sub-micrometre cells; every number of the scene and
# the OpenFOAM files converted by its dimension): every particle within 1e-6 d of the drawn
# case's (measured: bit for bit). With OpenFOAM v1912's fvc::reconstruct correcting the
# velocity a particle was 2e-5 d off after 1.7 ms, against 9e-16 d for a one-ulp nudge
# (docs/coupling.md, "Non-orthogonal meshes").
add_test(NAME coupling_stress.scale_twin_case
         COMMAND ${GRAINFLOW_STRESS_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/twin_cases.py
                 --foam-env ${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                 --solver $<TARGET_FILE:grainFoam>
                 --grain $<TARGET_FILE:grain>
                 --mpiexec ${MPIEXEC_EXECUTABLE}
                 --lib-dir $<TARGET_FILE_DIR:grainflowFoamBCs>
                 --cases ${CMAKE_CURRENT_LIST_DIR}/cases
                 --work ${CMAKE_CURRENT_BINARY_DIR}/coupling_stress/scale_twin_case
                 --seeds 9 --twins scale --timeout 120)
set_tests_properties(coupling_stress.scale_twin_case PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
  LABELS "foam;coupling;stress"
  PROCESSORS 2
  TIMEOUT 240)
