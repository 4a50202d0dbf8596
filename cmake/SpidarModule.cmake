# Shared build settings for every spidar target.
add_library(spidar_build_flags INTERFACE)
target_compile_options(spidar_build_flags INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  # GCC 12 false positives: inside Eigen for fixed-capacity dynamic matrices, and -Wrestrict on
  # `"literal" + std::string` (GCC bug 105651).
  $<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized -Wno-restrict>
  $<$<BOOL:${SPIDAR_WERROR}>:-Werror>)
if(SPIDAR_SANITIZE)
  target_compile_options(spidar_build_flags INTERFACE
    -fsanitize=${SPIDAR_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  if(SPIDAR_NO_SANITIZE)
    target_compile_options(spidar_build_flags INTERFACE -fno-sanitize=${SPIDAR_NO_SANITIZE})
  endif()
  target_link_options(spidar_build_flags INTERFACE -fsanitize=${SPIDAR_SANITIZE})
endif()

# spidar_add_module(<name> SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# Creates library target spidar_<name>, alias and export name spidar::<name>.
# Public headers live in include/spidar/<name>/.
function(spidar_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(spidar_${name} ${ARG_SOURCES})
  add_library(spidar::${name} ALIAS spidar_${name})
  set_target_properties(spidar_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME spidar_${name})
  target_include_directories(spidar_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(spidar_${name} PUBLIC cxx_std_20)
  target_link_libraries(spidar_${name}
    PUBLIC ${ARG_PUBLIC_DEPS}
    PRIVATE ${ARG_PRIVATE_DEPS} $<BUILD_INTERFACE:spidar_build_flags>)
  install(TARGETS spidar_${name} EXPORT spidarTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()
