# coupling.cellpoint_interpolation: grainflow's cellPoint weights (coupling/foam/
# cellPointWeights) against OpenFOAM's interpolationCellPoint, by cellPointCheck, on three
# meshes made by blockMesh in fresh copies of the cases here:
#   uniform  10 x 6 x 8 equal box cells, walls and symmetry planes (the closed form only);
#   graded   12 x 7 x 9 box cells graded 6x, 5x and 3x, cyclic along x (the closed form on
#            cells of every size and aspect ratio);
#   skewed   9 x 6 x 7 skewed, twisted, graded cells (OpenFOAM's tetrahedra, table path).
# Each must print status=ok (its bound, 1e-12 of the field's magnitude, is explained in
# cellPointCheck.C; the same line holds the coupling's cell search, coupling/foam/
# cellSearch.H, against findCell: wrongCell=0); here also: uniform and graded have every cell
# a box, skewed none.
#
#   cmake -DFOAM_ENV=scripts/foam_env.sh -DCHECK=bin/cellPointCheck
#         -DCASES=tests/coupling/cellpoint -DWORK=<scratch> -P cellpoint.cmake
foreach(var FOAM_ENV CHECK CASES WORK)
  if(NOT ${var})
    message(FATAL_ERROR "cellpoint.cmake: -D${var}=... is required")
  endif()
endforeach()

include(${CMAKE_CURRENT_LIST_DIR}/../mesh_check.cmake)
set(failures "")
foreach(name uniform graded skewed)
  grainflow_mesh_check(${name} "${CASES}/${name}" cellPointCheck failures line)
  if(NOT line)
    continue()
  endif()
  string(REGEX MATCH "cells=([0-9]+) boxCells=([0-9]+)" counts "${line}")
  if(name STREQUAL "skewed")
    if(NOT CMAKE_MATCH_2 EQUAL 0)
      string(APPEND failures "\n  skewed: ${CMAKE_MATCH_2} box cells, expected none")
    endif()
  elseif(NOT CMAKE_MATCH_1 EQUAL CMAKE_MATCH_2)
    string(APPEND failures "\n  ${name}: ${CMAKE_MATCH_2} of ${CMAKE_MATCH_1} cells are boxes, expected all")
  endif()
endforeach()
if(failures)
  message(FATAL_ERROR "coupling.cellpoint_interpolation:${failures}")
endif()
