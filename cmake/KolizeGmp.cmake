# Finds GMP (Debian: libgmp-dev), used by the narrowphase's exact CCD decision, and exposes
# it as the imported target kolize_gmp::gmp. GMP ships no CMake package; this is installed
# with kolize so that consumers of the static narrowphase library find it too.
include_guard(GLOBAL)

find_path(KOLIZE_GMP_INCLUDE_DIR gmp.h REQUIRED)
find_library(KOLIZE_GMP_LIBRARY NAMES gmp REQUIRED)
if(NOT TARGET kolize_gmp::gmp)
    add_library(kolize_gmp::gmp UNKNOWN IMPORTED)
    set_target_properties(kolize_gmp::gmp PROPERTIES
        IMPORTED_LOCATION "${KOLIZE_GMP_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${KOLIZE_GMP_INCLUDE_DIR}")
endif()
