# kolize_add_layer(<target> <export-name> SOURCES <files...> LINK <public deps...>)
# One library per layer folder: alias kolize::<export-name>, headers from the folder's
# include/, C++17 for consumers, the warnings target privately, installed and exported.
include_guard(GLOBAL)

function(kolize_add_layer target export_name)
    cmake_parse_arguments(ARG "" "" "SOURCES;LINK" ${ARGN})
    add_library(${target} ${ARG_SOURCES})
    add_library(kolize::${export_name} ALIAS ${target})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
    target_include_directories(${target} PUBLIC
        $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
        $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_compile_features(${target} PUBLIC cxx_std_17)
    target_link_libraries(${target} PUBLIC ${ARG_LINK} PRIVATE $<BUILD_INTERFACE:kolize_warnings>)
    if(KOLIZE_SANITIZE)
        # Static libraries built with the sanitizers need them at the consumer's link too;
        # the installed package carries the flag.
        target_link_options(${target} INTERFACE -fsanitize=address,undefined)
    endif()
    install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
    set_property(GLOBAL APPEND PROPERTY KOLIZE_INSTALL_TARGETS ${target})
endfunction()
