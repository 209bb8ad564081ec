# grainflow_find_python(<var> <modules> <what is skipped without it>)
# Sets <var> to the Python that scripts/python.sh picks for <modules> (comma-separated, e.g.
# "h5py,numpy"): the first of $GRAINFLOW_PYTHON, /usr/bin/python3 and the python3 on PATH
# that imports them all, the same lookup the tutorials and benchmarks use. Without one, <var>
# is empty and the script's message (the modules, the interpreters tried, the apt line) is
# printed with what is skipped.
function(grainflow_find_python var modules skipped)
  execute_process(COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/python.sh --which --needs ${modules}
                  RESULT_VARIABLE _status OUTPUT_VARIABLE _python ERROR_VARIABLE _message
                  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_STRIP_TRAILING_WHITESPACE)
  if(_status EQUAL 0)
    set(${var} "${_python}" PARENT_SCOPE)
  else()
    set(${var} "" PARENT_SCOPE)
    message(STATUS "${_message}\n  ${skipped} skipped")
  endif()
endfunction()
