#[=======================================================================[.rst:
FindOpenFOAM
------------

Finds Debian 12's OpenFOAM v1912 (libraries in ``/usr/lib``, environment file in
``/usr/share/openfoam/etc``) together with the matching headers that ``scripts/bootstrap.sh``
prepares from the Debian source package (Debian ships no OpenFOAM headers and no wmake; see
DESIGN.md section 8).

Input variables (cache or environment):

``GRAINFLOW_CACHE``
  Folder that holds ``openfoam-src/`` (default ``/var/cache/grainflow``, as in bootstrap.sh).
``OpenFOAM_SOURCE_DIR``
  Overrides ``${GRAINFLOW_CACHE}/openfoam-src`` directly.

Imported target:

``OpenFOAM::finiteVolume``
  INTERFACE target: lnInclude folders as SYSTEM includes, the compile definitions and options
  that wmake would use for this build of OpenFOAM, and finiteVolume + meshTools + OpenFOAM
  linked with ``--add-needed --no-as-needed`` (OpenFOAM registers its run-time selectable
  models from static constructors, so a library must stay linked even when no symbol of it is
  referenced directly). Consumers must compile as C++17 (``CXX_STANDARD 17``).

Result variables:

``OpenFOAM_FOUND``, ``OpenFOAM_VERSION`` (API level, e.g. ``1912``), ``OpenFOAM_BASHRC``
(the environment file every OpenFOAM program needs; ``scripts/foam_env.sh`` sources it),
``OpenFOAM_SOURCE_DIR``, ``OpenFOAM_INCLUDE_DIRS``, ``OpenFOAM_LIBRARIES``.
#]=======================================================================]

include(FindPackageHandleStandardArgs)

# --- 1. Header cache from scripts/bootstrap.sh --------------------------------
if(NOT GRAINFLOW_CACHE)
  if(NOT "$ENV{GRAINFLOW_CACHE}" STREQUAL "")
    set(_of_cache "$ENV{GRAINFLOW_CACHE}")
  else()
    set(_of_cache "/var/cache/grainflow")
  endif()
  set(GRAINFLOW_CACHE "${_of_cache}"
      CACHE PATH "Folder where scripts/bootstrap.sh keeps the OpenFOAM source (openfoam-src/)")
  unset(_of_cache)
endif()
if(NOT OpenFOAM_SOURCE_DIR)
  set(OpenFOAM_SOURCE_DIR "${GRAINFLOW_CACHE}/openfoam-src")
endif()

# The lnInclude folders wmake would put on the include path, and one header each that must be
# there (wmakeLnInclude fills a folder with symlinks; an interrupted run leaves it partial).
set(_of_lninclude_checks
    "src/OpenFOAM/lnInclude/argList.H"
    "src/OSspecific/POSIX/lnInclude/POSIX.H"
    "src/finiteVolume/lnInclude/fvMesh.H"
    "src/meshTools/lnInclude/meshTools.H")
set(OpenFOAM_INCLUDE_DIRS "")
set(_of_missing_headers "")
foreach(_of_check IN LISTS _of_lninclude_checks)
  get_filename_component(_of_dir "${OpenFOAM_SOURCE_DIR}/${_of_check}" DIRECTORY)
  list(APPEND OpenFOAM_INCLUDE_DIRS "${_of_dir}")
  if(NOT EXISTS "${OpenFOAM_SOURCE_DIR}/${_of_check}")
    list(APPEND _of_missing_headers "${_of_check}")
  endif()
endforeach()

set(_of_reason "")
if(_of_missing_headers)
  string(JOIN ", " _of_missing_list ${_of_missing_headers})
  string(CONCAT _of_reason
         "the OpenFOAM headers are not prepared in ${OpenFOAM_SOURCE_DIR} (missing: "
         "${_of_missing_list}). Debian ships OpenFOAM without headers: run scripts/bootstrap.sh "
         "(as root, same GRAINFLOW_CACHE) to fetch the matching source and generate the "
         "lnInclude folders, or point -DGRAINFLOW_CACHE=... at a cache it has filled.")
  if(OpenFOAM_FIND_REQUIRED)
    message(FATAL_ERROR "FindOpenFOAM: ${_of_reason}")
  endif()
endif()

# API level of the headers, e.g. "api=1912" in META-INFO/api-info.
set(OpenFOAM_VERSION "")
if(EXISTS "${OpenFOAM_SOURCE_DIR}/META-INFO/api-info")
  file(STRINGS "${OpenFOAM_SOURCE_DIR}/META-INFO/api-info" _of_api REGEX "^api=[0-9]+")
  string(REGEX REPLACE "^api=([0-9]+).*" "\\1" OpenFOAM_VERSION "${_of_api}")
endif()

# Headers and libraries must come from the same Debian source version: bootstrap.sh records the
# version it prepared; a later `apt-get upgrade` of libopenfoam silently breaks the ABI match.
set(_of_stamp "${GRAINFLOW_CACHE}/openfoam-headers.stamp")
find_program(OpenFOAM_DPKG_QUERY dpkg-query)
mark_as_advanced(OpenFOAM_DPKG_QUERY)
if(NOT _of_missing_headers AND EXISTS "${_of_stamp}" AND OpenFOAM_DPKG_QUERY)
  file(STRINGS "${_of_stamp}" _of_header_pkg LIMIT_COUNT 1)
  execute_process(COMMAND "${OpenFOAM_DPKG_QUERY}" -W "-f=\${source:Version}" libopenfoam
                  OUTPUT_VARIABLE _of_lib_pkg ERROR_QUIET RESULT_VARIABLE _of_rc
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(_of_rc EQUAL 0 AND NOT _of_lib_pkg STREQUAL _of_header_pkg)
    message(FATAL_ERROR
            "FindOpenFOAM: the headers in ${OpenFOAM_SOURCE_DIR} are from openfoam "
            "${_of_header_pkg} but the installed libopenfoam is ${_of_lib_pkg}. "
            "Run scripts/bootstrap.sh to refresh the headers.")
  endif()
endif()

# --- 2. Libraries and environment file ----------------------------------------
# Debian installs them straight into /usr/lib (not the multiarch folder).
foreach(_of_lib IN ITEMS OpenFOAM finiteVolume meshTools)
  find_library(OpenFOAM_${_of_lib}_LIBRARY NAMES ${_of_lib}
               HINTS /usr/lib /usr/lib/openfoam ENV FOAM_LIBBIN)
  mark_as_advanced(OpenFOAM_${_of_lib}_LIBRARY)
endforeach()
set(OpenFOAM_LIBRARIES ${OpenFOAM_finiteVolume_LIBRARY} ${OpenFOAM_meshTools_LIBRARY}
                       ${OpenFOAM_OpenFOAM_LIBRARY})

find_file(OpenFOAM_BASHRC NAMES bashrc
          HINTS /usr/share/openfoam/etc ENV WM_PROJECT_DIR
          PATH_SUFFIXES etc NO_DEFAULT_PATH
          DOC "OpenFOAM environment file sourced before running any OpenFOAM program")

if(NOT _of_reason)
  set(_of_reason "Debian packages: openfoam libopenfoam (scripts/bootstrap.sh installs them)")
endif()
find_package_handle_standard_args(OpenFOAM
  REQUIRED_VARS OpenFOAM_OpenFOAM_LIBRARY OpenFOAM_finiteVolume_LIBRARY
                OpenFOAM_meshTools_LIBRARY OpenFOAM_BASHRC OpenFOAM_SOURCE_DIR OpenFOAM_VERSION
  VERSION_VAR OpenFOAM_VERSION
  REASON_FAILURE_MESSAGE "${_of_reason}")

# --- 3. Imported target -------------------------------------------------------
if(OpenFOAM_FOUND AND NOT _of_missing_headers AND NOT TARGET OpenFOAM::finiteVolume)
  add_library(OpenFOAM::finiteVolume INTERFACE IMPORTED)
  set_target_properties(OpenFOAM::finiteVolume PROPERTIES
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${OpenFOAM_INCLUDE_DIRS}"
    INTERFACE_INCLUDE_DIRECTORIES "${OpenFOAM_INCLUDE_DIRS}")
  # As wmake's linux64Gcc rules for this build (WM_DP, 32-bit labels).
  target_compile_definitions(OpenFOAM::finiteVolume INTERFACE
    OPENFOAM=${OpenFOAM_VERSION} WM_DP WM_LABEL_SIZE=32 NoRepository)
  target_compile_options(OpenFOAM::finiteVolume INTERFACE
    $<$<COMPILE_LANGUAGE:CXX>:-m64 -ftemplate-depth-100>)
  target_compile_features(OpenFOAM::finiteVolume INTERFACE cxx_std_17)
  # LINKER: options come before the libraries on the link line, so --no-as-needed applies.
  target_link_options(OpenFOAM::finiteVolume INTERFACE
    "LINKER:--add-needed" "LINKER:--no-as-needed")
  target_link_libraries(OpenFOAM::finiteVolume INTERFACE ${OpenFOAM_LIBRARIES} dl)
endif()

unset(_of_api)
unset(_of_check)
unset(_of_dir)
unset(_of_header_pkg)
unset(_of_lib)
unset(_of_lib_pkg)
unset(_of_lninclude_checks)
unset(_of_missing_headers)
unset(_of_missing_list)
unset(_of_rc)
unset(_of_reason)
unset(_of_stamp)
