# Finds Debian's Bullet libraries and exposes them as imported targets:
#   kolize_bullet::LinearMath, kolize_bullet::Collision, kolize_bullet::Dynamics
# Debian ships a float build and a "-float64" build (BT_USE_DOUBLE_PRECISION); the
# variable KOLIZE_DOUBLE_PRECISION picks which. Bullet's own BulletConfig.cmake only sets
# relative-path variables, so we locate the libraries ourselves.
include_guard(GLOBAL)

if(KOLIZE_DOUBLE_PRECISION)
    set(_kolize_bullet_suffix "-float64")
else()
    set(_kolize_bullet_suffix "")
endif()

find_path(KOLIZE_BULLET_INCLUDE_DIR btBulletCollisionCommon.h PATH_SUFFIXES bullet REQUIRED)

foreach(_part LinearMath BulletCollision BulletDynamics)
    string(REPLACE "Bullet" "" _short "${_part}")
    find_library(KOLIZE_BULLET_${_short}_LIBRARY NAMES ${_part}${_kolize_bullet_suffix} REQUIRED)
    if(NOT TARGET kolize_bullet::${_short})
        add_library(kolize_bullet::${_short} UNKNOWN IMPORTED)
        set_target_properties(kolize_bullet::${_short} PROPERTIES
            IMPORTED_LOCATION "${KOLIZE_BULLET_${_short}_LIBRARY}"
            INTERFACE_INCLUDE_DIRECTORIES "${KOLIZE_BULLET_INCLUDE_DIR}")
        if(KOLIZE_DOUBLE_PRECISION)
            set_property(TARGET kolize_bullet::${_short} APPEND PROPERTY
                INTERFACE_COMPILE_DEFINITIONS BT_USE_DOUBLE_PRECISION)
        endif()
    endif()
endforeach()
set_property(TARGET kolize_bullet::Collision APPEND PROPERTY
    INTERFACE_LINK_LIBRARIES kolize_bullet::LinearMath)
set_property(TARGET kolize_bullet::Dynamics APPEND PROPERTY
    INTERFACE_LINK_LIBRARIES kolize_bullet::Collision)
