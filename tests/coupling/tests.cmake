# Command-level tests of grainFoam's two-way coupling (included by tests/CMakeLists.txt).
# Each runs tests/coupling/grainfoam_cases.py on a fresh copy of a case from
# tests/coupling/cases/ in the build tree; the references, tolerances and edits to the case
# are stated in that script, one function per test. Run time on 2 cores: each under 15 s.
#
#   coupling.void_fraction_volume  cases/periodic_box (307 beads of 3 radii in a 20 mm box of
#       8^3 cells, periodic along x and y, 7 of them placed across the periodic faces and the
#       processor plane): for voidFraction centre, divided and smoothed, on 1 rank and on
#       2 (simple (2 1 1)), sum (1 - eps) V = sum 4/3 pi r^3 to 1e-12 (printed by grainFoam
#       and recomputed from the written field and snapshot), and eps(2 ranks) = eps(1 rank)
#       to 1e-12 (reconstructPar).
#   coupling.exchange_balance      the same bed in a flow of 0.05 m/s, sampling cell: the
#       fluid's exchange source is minus the sum of the fluid forces on the particles
#       (Newton's third law) to 1e-12 relative, 1 and 2 ranks.
#   coupling.neutrally_buoyant     cases/neutral_particle: one bead as dense as water at rest
#       in water at rest, models A and B: after 0.1 s it has moved < 1e-9 m, speed < 1e-8 m/s;
#       its snapshot's fluid_force (output.fields) is the buoyancy and its force zero; with
#       output.start between the two write times only the second has a snapshot.
#   coupling.refuses_bad_setup     processor meshes that are not boxes (2 ranks), deltaT not
#       a whole number of DEM steps, fluid.density != rho, undisturbedVelocity unknown or with
#       cellPoint, meanPressureGradient unknown or with walls across gravity, a couplingProperties
#       key given twice (also on 2 ranks; the advice, one removed, runs): each stops with
#       its message.
#   coupling.restart               cases/periodic_box under 10 g in a flow: 400 fluid steps vs
#       200 + restart (startFrom latestTime) + 200, on 1 and on 2 ranks: every particle and
#       U, p, phi, voidfraction bit-identical; a 1-rank checkpoint restarted on 2 ranks
#       continues the same flow (centre of mass within 2 % of its fall); a missing DEM
#       checkpoint is refused naming the file. About 45 s.
#   coupling.restart_files         the files of a restart time against the checksums grainFoam
#       recorded when it wrote them (grainflowChecksums): intact (matched, runs on); a flipped
#       mantissa bit of U refused naming the file, then the advice (delete U's line) runs and
#       ends with another U than the intact restart; phi deleted, a damaged checksum and a
#       garbled line of the record refused; on 2 ranks, processor1's p with a flipped bit.
#       About 20 s.
#   coupling.restart_bed_surface   the same restarts with dragVoidFraction sharpInterface and
#       facePressure dragSeries (the beads pile on the floor): bit-identical on 1 and 2 ranks
#       (Ksl taken as written at the restart, as the void fraction is). About 25 s.
#   coupling.stop_signal           the same case, SIGTERM mid-run (on 2 ranks to one rank only):
#       exit 0 with the message, the time written with its checkpoint; restarted, it ends
#       bit-identical to a run stopped at that time by endTime and restarted. About 25 s.
#   coupling.scene_output          cases/neutral_particle: output.directory and
#       output.snapshot_interval honoured (26 snapshots at 0.004 k s in out/beads), time.end
#       before endTime ends the run there, output.log_interval and a snapshot interval
#       under deltaT refused naming the scene's line.
#   coupling.nan_guard             a NaN velocity put into the checkpoint: the restarted run
#       stops at the first DEM step naming that particle, with a diagnostic snapshot.
#   coupling.heat_equilibrium      cases/heated_box: eight beads at 400 K held still in closed
#       air at 300 K (heat on): the mixture's thermal energy conserved to 1e-12, the mean
#       temperatures against the two-body closed form (T_eq, tau with Nu = 2) within 0.5 %,
#       the exchange balanced to round-off at every write time; a restart at half time ends
#       with the same T; missing kappa, Cp unlike the scene, heat without convection keys
#       refused with their messages. About 10 s.
#   coupling.heat_parcels          cases/heated_box with the eight beads as one parcel of
#       k = 2 at the centre of one 4 mm cell: the same closed form (T_eq, tau) within 0.5 %, energy conserved
#       to 1e-12, exchange balanced, the snapshot's real_count 8. About 5 s.
#   coupling.heat_balance          cases/periodic_box with heat (Gunn), beads at 350 K raining
#       through water at 300 K, on 1 and 2 ranks: heat taken by the particles = heat lost by
#       the fluid to 1e-12 relative at every write time, mixture energy conserved to 1e-12,
#       the two rank counts agree within 1 %; then on 2 ranks with the fill's beads as 38
#       parcels of k = 2 among the real ones: the same balance and conservation. About 40 s.
#   coupling.heat_front            cases/heated_bed: 384 beads (d = 3 mm) on a simple cubic
#       lattice resting on a distributor, air at 400 K entering the bed at 300 K at 0.8 m/s
#       (contact conduction off, cells d high): the fluid's and the beads' thermal fronts (theta = 1/2)
#       at 0.1 ... 0.4 s against Schumann (1929) with Gunn's h (tests/coupling/schumann.py,
#       numpy only) within 5 %; the bed stays put (< 0.1 d); exchange balanced. About 6 s.
#   coupling.balanced_decomposition  scripts/balanced_decomposition.py on cases/heated_bed in a
#       column twice as tall (the bed in its lowest 24 of 56 cell layers), cut along z for 2
#       ranks: every cell on rank 0 or 1, two slabs, the cut best for the objective (every cut
#       tried in the test): `sum` (larger slab's cells + w particles least) at w = 4, `phases`
#       (busier DEM slab + busier fluid slab least) at w = 0.25 (28 layers: equal slabs) and 4
#       (12); grainFoam on the last on 2 ranks: each rank owns its slab's beads, the DEM's cut
#       plane is the mesh's, exchange balanced. About 40 s on the loaded 2-core machine.
#   coupling.diffusion_smoothing   diffusionBandwidth: one bead's solid fraction in
#       cases/neutral_particle (voidFraction centre, b = 1.6 mm, 2 steps) has variance b^2/2
#       per axis (the Gaussian exp(-r^2/b^2)) to 1e-9, its centre and volume the bead's;
#       cases/periodic_box in a flow with b = 5 mm on 1 and 2 ranks: exchange balanced and
#       volume conserved to 1e-12, eps(2 ranks) = eps(1 rank) to 1e-12; a negative b and b
#       with cellPoint refused. About 10 s.
#   coupling.restart_unwritten_time  cases/neutral_particle: a time folder grainFoam did not
#       write (0 copied to 0.002; 0.002 with uniform/ or uniform/grainflowCheckpoint lost) is
#       refused with startFrom latestTime (the DEM had restarted at t = 0 under the fluid's
#       0.002), without the advice "delete its line", whose following is refused too; the
#       advice given (an intact earlier time) runs with the DEM's time the fluid's.
#   coupling.run_time_edits        runTimeModifiable true, files edited during the run at a set
#       time (timeActivatedFileUpdate): a changed deltaT is not taken (said once; the DEM's
#       time stays the fluid's), the scene's time.end still ends the run after a controlDict
#       edit and the last line is true, an earlier endTime is taken, couplingProperties and
#       transportProperties edits are said once not to be taken. About 10 s.
#   coupling.restart_time_step     a DEM step dividing deltaT only to 1e-7 refused at start-up
#       with the exact divisor, which runs and restarts; a restart with another deltaT refused
#       naming the deltaT that restarts (which then runs) and a new run for the new one; a
#       changed voidFraction at a restart named as the cause of the differing fields.
#   coupling.checkpoint_keeping    purgeWrite 2 and a restart: every time folder OpenFOAM keeps
#       keeps its DEM checkpoint, and restarts; a fresh run into that case notes the earlier
#       run's snapshots and checkpoints and the folders naming them.
#   coupling.setup_messages        diffusionBandwidth 60 m and 5 m refused with the allowed
#       range, whose end runs; mpirun -np 2 without -parallel says to add it; a
#       fluid.viscosity unlike rho*nu printed to 12 digits, which typed back run.
#   coupling.restart_lost_snapshots  snapshots 1 and 2 (the one at the checkpoint) deleted
#       before a restart: named as gaps, the restart's snapshots keep the uninterrupted run's
#       numbers 3 and 4 (t = n * 0.005 s).
#   coupling.coupled_inputs        inputs taken without a word before: the scene's
#       parallel.balance: true (2 ranks) and parallel.grid refused at their line naming
#       system/decomposeParDict, the advice (removed) running with every particle's volume
#       deposited (1e-12); transportModel BirdCarreau and its coefficients refused at their
#       lines, Newtonian running; an end 5.6 fluid steps from the start said to end at the
#       6th step (0.006 s: the last Time line and snapshot) at start-up and in the last line,
#       whose advice ends exactly there, and likewise an endTime of 5.4 steps; out-of-range
#       couplingProperties values refused at the key's line; the scene path expanded as
#       OpenFOAM expands file names ($FOAM_CASE, <case>; also on 2 ranks), an unset variable,
#       a '$' left and a directory each refused saying so. About 40 s.
if(NOT TARGET grainFoam)
  return()
endif()

# coupling.cellpoint_interpolation: the cellPoint weights of the coupling against OpenFOAM's
# interpolationCellPoint on a uniform, a graded and a skewed mesh (cellpoint/cellpoint.cmake,
# cellpoint/cellPointCheck.C), and on the same meshes the coupling's cell search
# (coupling/foam/cellSearch.H) against OpenFOAM's findCell: 1.0e6 searches, hints right and
# wrong, none given a cell that does not hold its point (a search that trusts its hint's
# neighbour untested gives 5.0e5). Under 10 s.
add_executable(cellPointCheck ${CMAKE_CURRENT_LIST_DIR}/cellpoint/cellPointCheck.C
                              ${PROJECT_SOURCE_DIR}/coupling/foam/cellPointWeights.C)
target_include_directories(cellPointCheck PRIVATE ${PROJECT_SOURCE_DIR})
target_link_libraries(cellPointCheck PRIVATE OpenFOAM::finiteVolume grainflow_warnings)
set_target_properties(cellPointCheck PROPERTIES
  CXX_STANDARD 17
  CXX_STANDARD_REQUIRED ON
  CXX_EXTENSIONS OFF
  RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
add_test(NAME coupling.cellpoint_interpolation
         COMMAND ${CMAKE_COMMAND}
                 -DFOAM_ENV=${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                 -DCHECK=$<TARGET_FILE:cellPointCheck>
                 -DCASES=${CMAKE_CURRENT_LIST_DIR}/cellpoint
                 -DWORK=${CMAKE_CURRENT_BINARY_DIR}/coupling/cellpoint_interpolation
                 -P ${CMAKE_CURRENT_LIST_DIR}/cellpoint/cellpoint.cmake)
set_tests_properties(coupling.cellpoint_interpolation PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC}"
  LABELS "foam;coupling"
  TIMEOUT 300)

# coupling.point_interpolation: the coupling's point values (coupling/foam/pointInterpolation)
# against OpenFOAM's volPointInterpolation, and its grad p (coupling/foam/gaussLinearGrad.H)
# against fvc::grad, bit for bit, on 1 and 2 ranks (pointinterp/pointinterp.cmake,
# pointinterp/pointInterpolationCheck.C). Under 20 s.
add_executable(pointInterpolationCheck ${CMAKE_CURRENT_LIST_DIR}/pointinterp/pointInterpolationCheck.C
                                       ${PROJECT_SOURCE_DIR}/coupling/foam/pointInterpolation.C)
target_include_directories(pointInterpolationCheck PRIVATE ${PROJECT_SOURCE_DIR})
target_link_libraries(pointInterpolationCheck PRIVATE OpenFOAM::finiteVolume grainflow_warnings)
set_target_properties(pointInterpolationCheck PROPERTIES
  CXX_STANDARD 17
  CXX_STANDARD_REQUIRED ON
  CXX_EXTENSIONS OFF
  RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
add_test(NAME coupling.point_interpolation
         COMMAND ${CMAKE_COMMAND}
                 -DFOAM_ENV=${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                 -DCHECK=$<TARGET_FILE:pointInterpolationCheck>
                 -DMPIEXEC=${MPIEXEC_EXECUTABLE}
                 -DCASES=${CMAKE_CURRENT_LIST_DIR}/pointinterp
                 -DCOMMON=${CMAKE_CURRENT_LIST_DIR}/cellpoint/uniform/system
                 -DWORK=${CMAKE_CURRENT_BINARY_DIR}/coupling/point_interpolation
                 -P ${CMAKE_CURRENT_LIST_DIR}/pointinterp/pointinterp.cmake)
set_tests_properties(coupling.point_interpolation PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
  LABELS "foam;coupling;mpi"
  PROCESSORS 2
  TIMEOUT 300)

# coupling.flux_reconstruction: the cell velocity grainFoam reconstructs from face fluxes
# (coupling/foam/fluxReconstruction.H, in place of OpenFOAM v1912's fvc::reconstruct, which is
# compiled wrong) against its closed form: the flux of a uniform velocity gives that velocity
# to 1e-12 on a uniform, a graded, a skewed and a 2-D mesh, also scaled by 2^-20 and 2^10
# (reconstruct/reconstruct.cmake, reconstruct/fluxReconstructionCheck.C). Under 10 s.
add_executable(fluxReconstructionCheck ${CMAKE_CURRENT_LIST_DIR}/reconstruct/fluxReconstructionCheck.C)
target_include_directories(fluxReconstructionCheck PRIVATE ${PROJECT_SOURCE_DIR})
target_link_libraries(fluxReconstructionCheck PRIVATE OpenFOAM::finiteVolume grainflow_warnings)
set_target_properties(fluxReconstructionCheck PROPERTIES
  CXX_STANDARD 17
  CXX_STANDARD_REQUIRED ON
  CXX_EXTENSIONS OFF
  RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
add_test(NAME coupling.flux_reconstruction
         COMMAND ${CMAKE_COMMAND}
                 -DFOAM_ENV=${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                 -DCHECK=$<TARGET_FILE:fluxReconstructionCheck>
                 -DCASES=${CMAKE_CURRENT_LIST_DIR}
                 -DWORK=${CMAKE_CURRENT_BINARY_DIR}/coupling/flux_reconstruction
                 -P ${CMAKE_CURRENT_LIST_DIR}/reconstruct/reconstruct.cmake)
set_tests_properties(coupling.flux_reconstruction PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC}"
  LABELS "foam;coupling"
  TIMEOUT 300)

# h5py reads the particle snapshots (scripts/python.sh picks the Python).
grainflow_find_python(GRAINFLOW_COUPLING_PYTHON "h5py,numpy" "the coupling.* command tests are")
if(NOT GRAINFLOW_COUPLING_PYTHON)
  return()
endif()

# superficialVelocityInlet (cases/heated_bed) is loaded by the cases' controlDict `libs`.
set(_grainflow_coupling_lib_dir "")
if(TARGET grainflowFoamBCs)
  set(_grainflow_coupling_lib_dir --lib-dir $<TARGET_FILE_DIR:grainflowFoamBCs>)
endif()

function(grainflow_coupling_test name ranks)
  add_test(NAME coupling.${name}
           COMMAND ${GRAINFLOW_COUPLING_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/grainfoam_cases.py ${name}
                   --foam-env ${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                   --solver $<TARGET_FILE:grainFoam>
                   --mpiexec ${MPIEXEC_EXECUTABLE}
                   ${_grainflow_coupling_lib_dir}
                   --cases ${CMAKE_CURRENT_LIST_DIR}/cases
                   --work ${CMAKE_CURRENT_BINARY_DIR}/coupling/${name})
  set_tests_properties(coupling.${name} PROPERTIES
    ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
    TIMEOUT 300)  # a hang guard: each takes seconds to ~40 s alone, several times that under load
  if(ranks GREATER 1)
    set_tests_properties(coupling.${name} PROPERTIES LABELS "foam;coupling;mpi"
                         PROCESSORS ${ranks})
  else()
    set_tests_properties(coupling.${name} PROPERTIES LABELS "foam;coupling")
  endif()
endfunction()

grainflow_coupling_test(void_fraction_volume 2)
grainflow_coupling_test(exchange_balance 2)
grainflow_coupling_test(neutrally_buoyant 1)
grainflow_coupling_test(cellpoint_ranks 2)
grainflow_coupling_test(refuses_bad_setup 2)
grainflow_coupling_test(hostile_fields 1)
grainflow_coupling_test(restart 2)
grainflow_coupling_test(restart_files 2)
set_tests_properties(coupling.restart PROPERTIES TIMEOUT 600)  # ~45 s on a quiet machine
grainflow_coupling_test(restart_bed_surface 2)
set_tests_properties(coupling.restart_bed_surface PROPERTIES TIMEOUT 600)
grainflow_coupling_test(stop_signal 2)
grainflow_coupling_test(nan_guard 2)
grainflow_coupling_test(scene_output 1)
grainflow_coupling_test(heat_equilibrium 1)
grainflow_coupling_test(heat_parcels 1)
grainflow_coupling_test(heat_balance 2)
grainflow_coupling_test(heat_front 1)
grainflow_coupling_test(balanced_decomposition 2)
grainflow_coupling_test(diffusion_smoothing 2)
grainflow_coupling_test(restart_unwritten_time 1)
grainflow_coupling_test(run_time_edits 1)
grainflow_coupling_test(restart_time_step 1)
grainflow_coupling_test(checkpoint_keeping 1)
grainflow_coupling_test(setup_messages 2)
grainflow_coupling_test(restart_lost_snapshots 1)
grainflow_coupling_test(coupled_inputs 2)
set_tests_properties(coupling.balanced_decomposition PROPERTIES TIMEOUT 300)  # ~40 s loaded
set_tests_properties(coupling.stop_signal PROPERTIES TIMEOUT 600)  # ~25 s on a quiet machine

# coupling.parcel_bed_ergun (tests/coupling/parcel_bed.py, cases/parcel_bed): coarse-grained
# parcels in grainFoam. A bed of 1 mm glass beads poured in a periodic 24 mm column with air at
# 0.2 m/s, as k = 1, 2, 3 parcels: each k's pressure drop against Ergun with that bed's own eps
# and height, within 7 % for every k, the beads' worst of fourteen pours (one pour is one
# sample: over fourteen pours k = 3 scatters from -4.8 to +2.7 %; parcel_bed.py,
# benchmarks/coarse_grain/packed_bed.py); snapshots carry k and k^3; the deposited volume is
# the real beads'; the momentum exchange balanced to 1e-12 on 1 and 2 ranks; undisturbedVelocity
# refused with parcels. About 70 s on a quiet 2-core machine, most of it the beads (k = 1).
if(TARGET grainflowFoamBCs)
  add_test(NAME coupling.parcel_bed_ergun
           COMMAND ${GRAINFLOW_COUPLING_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/parcel_bed.py
                   parcel_bed_ergun
                   --foam-env ${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                   --solver $<TARGET_FILE:grainFoam>
                   --mpiexec ${MPIEXEC_EXECUTABLE}
                   --lib-dir $<TARGET_FILE_DIR:grainflowFoamBCs>
                   --cases ${CMAKE_CURRENT_LIST_DIR}/cases
                   --work ${CMAKE_CURRENT_BINARY_DIR}/coupling/parcel_bed_ergun)
  set_tests_properties(coupling.parcel_bed_ergun PROPERTIES
    ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
    LABELS "foam;coupling;mpi"
    PROCESSORS 2
    TIMEOUT 300)
endif()

# coupling.documented_defaults (tests/coupling/documented_defaults.py): every default that the
# couplingProperties table of docs/coupling.md ("A coupled case") states is what grainFoam does.
# The table is read from the page; for each key with a stated default one tiny case (128 cells,
# 68 beads about a cell wide, a bed whose surface lies inside a cell, a horizontal flow; 5 fluid
# steps) runs with the key left out, written as the page's default, and written otherwise: the
# first two bit-identical (exit status, log without clock/host/PID lines, every field, uniform/
# and grainflowChecksums, every HDF5 dataset and attribute of the snapshot and checkpoint), the
# third with other fields or particles. A row without a check, or checked as another value than
# the page's, fails. 25 runs of ~1 s on 2 worker threads: 20-35 s on 2 cores.
add_test(NAME coupling.documented_defaults
         COMMAND ${GRAINFLOW_COUPLING_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/documented_defaults.py
                 --foam-env ${PROJECT_SOURCE_DIR}/scripts/foam_env.sh
                 --solver $<TARGET_FILE:grainFoam>
                 ${_grainflow_coupling_lib_dir}
                 --page ${PROJECT_SOURCE_DIR}/docs/coupling.md
                 --work ${CMAKE_CURRENT_BINARY_DIR}/coupling/documented_defaults)
set_tests_properties(coupling.documented_defaults PROPERTIES
  ENVIRONMENT "GRAINFLOW_FOAM_BASHRC=${OpenFOAM_BASHRC};${GRAINFLOW_MPIEXEC_ENV}"
  LABELS "foam;coupling"
  PROCESSORS 2
  TIMEOUT 300)
