#[=======================================================================[.rst:
FindSuiteSparse
---------------

Finds SuiteSparse installs that ship no CMake package (e.g. Debian 12's libsuitesparse-dev:
headers in ``<prefix>/include/suitesparse``, one shared library per package).

Components: ``KLU``, ``CHOLMOD``, ``UMFPACK`` (default: all three), and the helper packages
``AMD``, ``CAMD``, ``COLAMD``, ``CCOLAMD``, ``BTF``, ``Config`` that are pulled in as needed.

Imported targets (each carries its dependencies):
  ``SuiteSparse::KLU``, ``SuiteSparse::CHOLMOD``, ``SuiteSparse::UMFPACK``,
  ``SuiteSparse::AMD``, ``SuiteSparse::CAMD``, ``SuiteSparse::COLAMD``, ``SuiteSparse::CCOLAMD``,
  ``SuiteSparse::BTF``, ``SuiteSparse::Config``

Result variables:
  ``SuiteSparse_FOUND``, ``SuiteSparse_<C>_FOUND``, ``SuiteSparse_VERSION``,
  ``SuiteSparse_INCLUDE_DIR``, ``SuiteSparse_LIBRARIES``

Headers are used as ``#include <klu.h>``, ``<cholmod.h>``, ``<umfpack.h>``.
Hint: set ``SuiteSparse_ROOT`` to an install prefix.
#]=======================================================================]

include(FindPackageHandleStandardArgs)

if(NOT SuiteSparse_FIND_COMPONENTS)
  set(SuiteSparse_FIND_COMPONENTS KLU CHOLMOD UMFPACK)
endif()

find_path(SuiteSparse_INCLUDE_DIR NAMES SuiteSparse_config.h PATH_SUFFIXES suitesparse)
mark_as_advanced(SuiteSparse_INCLUDE_DIR)

if(SuiteSparse_INCLUDE_DIR AND EXISTS "${SuiteSparse_INCLUDE_DIR}/SuiteSparse_config.h")
  file(STRINGS "${SuiteSparse_INCLUDE_DIR}/SuiteSparse_config.h" _ss_version_lines
       REGEX "^#define SUITESPARSE_(MAIN|SUB|SUBSUB)_VERSION +[0-9]+")
  foreach(_part MAIN SUB SUBSUB)
    string(REGEX REPLACE ".*#define SUITESPARSE_${_part}_VERSION +([0-9]+).*" "\\1"
           _ss_${_part} "${_ss_version_lines}")
  endforeach()
  set(SuiteSparse_VERSION "${_ss_MAIN}.${_ss_SUB}.${_ss_SUBSUB}")
  unset(_ss_version_lines)
endif()

# _ss_<component>: <library name> <header> <dependencies...>. Optional dependencies are
# prefixed with '?' (linked when found, e.g. CHOLMOD's CAMD/CCOLAMD).
set(_ss_Config  suitesparseconfig SuiteSparse_config.h)
set(_ss_AMD     amd     amd.h     Config)
set(_ss_CAMD    camd    camd.h    Config)
set(_ss_COLAMD  colamd  colamd.h  Config)
set(_ss_CCOLAMD ccolamd ccolamd.h Config)
set(_ss_BTF     btf     btf.h)
set(_ss_KLU     klu     klu.h     AMD COLAMD BTF Config)
set(_ss_CHOLMOD cholmod cholmod.h AMD COLAMD ?CAMD ?CCOLAMD Config)
set(_ss_UMFPACK umfpack umfpack.h AMD ?CHOLMOD Config)

# Find one package, create SuiteSparse::<C> and set SuiteSparse_<C>_FOUND. Its dependencies must
# have been looked for already (the loop below goes from the leaves up).
macro(_suitesparse_find comp)
  list(GET _ss_${comp} 0 _ss_lib)
  list(GET _ss_${comp} 1 _ss_hdr)
  set(_ss_deps ${_ss_${comp}})
  list(REMOVE_AT _ss_deps 0 1)

  find_library(SuiteSparse_${comp}_LIBRARY NAMES ${_ss_lib})
  mark_as_advanced(SuiteSparse_${comp}_LIBRARY)
  set(SuiteSparse_${comp}_FOUND FALSE)
  if(SuiteSparse_${comp}_LIBRARY AND SuiteSparse_INCLUDE_DIR
     AND EXISTS "${SuiteSparse_INCLUDE_DIR}/${_ss_hdr}")
    set(SuiteSparse_${comp}_FOUND TRUE)
  endif()

  set(_ss_links "")
  foreach(_ss_dep IN LISTS _ss_deps)
    string(REGEX REPLACE "^[?]" "" _ss_name "${_ss_dep}")
    if(SuiteSparse_${_ss_name}_FOUND)
      list(APPEND _ss_links SuiteSparse::${_ss_name})
    elseif(NOT _ss_dep MATCHES "^[?]")
      set(SuiteSparse_${comp}_FOUND FALSE)  # a required dependency is missing
    endif()
  endforeach()

  if(SuiteSparse_${comp}_FOUND AND NOT TARGET SuiteSparse::${comp})
    add_library(SuiteSparse::${comp} UNKNOWN IMPORTED)
    set_target_properties(SuiteSparse::${comp} PROPERTIES
      IMPORTED_LOCATION "${SuiteSparse_${comp}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${SuiteSparse_INCLUDE_DIR}"
      INTERFACE_LINK_LIBRARIES "${_ss_links}")
  endif()
endmacro()

foreach(_ss_comp Config AMD CAMD COLAMD CCOLAMD BTF KLU CHOLMOD UMFPACK)
  _suitesparse_find(${_ss_comp})
endforeach()

# The libraries also need BLAS/LAPACK (CHOLMOD, UMFPACK) for static linking; shared libraries
# carry those dependencies themselves, so nothing is added for them here.
set(SuiteSparse_LIBRARIES "")
foreach(_ss_comp IN LISTS SuiteSparse_FIND_COMPONENTS)
  if(SuiteSparse_${_ss_comp}_FOUND)
    list(APPEND SuiteSparse_LIBRARIES SuiteSparse::${_ss_comp})
  endif()
endforeach()

find_package_handle_standard_args(SuiteSparse
  REQUIRED_VARS SuiteSparse_INCLUDE_DIR
  VERSION_VAR SuiteSparse_VERSION
  HANDLE_COMPONENTS)
