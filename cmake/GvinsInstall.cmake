# Installation: libraries (static by default), public headers, the command-line tools, the
# simulator's data and scenarios, a CMake package (find_package(SriGvins CONFIG) gives
# SriGvins::base ... SriGvins::fusion) and pkg-config files (sri-gvins-<module>.pc and the
# umbrella sri-gvins.pc). Included by the top-level CMakeLists.txt after the modules and apps.
include(CMakePackageConfigHelpers)

set(GVINS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/SriGvins)
set(GVINS_DATA_SUBDIR sri_gvins)
get_property(gvins_libraries GLOBAL PROPERTY GVINS_LIBRARIES)

# ---- run-time data: the simulator's navigation file and the scenarios ----------------------------
# Installed to <prefix>/share/sri_gvins/{data,config}. The library finds the data relative to the
# running executable (<bindir>/<GVINS_DATA_FROM_BIN>/data, see sim/src/scenario.cpp) or through
# GVINS_DATA_DIR, never through a path of this build tree. The build tree holds the same layout
# under build/share/sri_gvins, so the tools, tests and benchmarks (bin/, tests/, bench/, fuzz/,
# all one level below the build folder) find it the same way; there the data files are symbolic
# links to tests/data (the same files as the source tree's scenarios name), the installed ones
# copies.
file(RELATIVE_PATH GVINS_DATA_FROM_BIN ${CMAKE_INSTALL_FULL_BINDIR}
     ${CMAKE_INSTALL_FULL_DATADIR}/${GVINS_DATA_SUBDIR})
get_filename_component(gvins_stage "${PROJECT_BINARY_DIR}/bin/${GVINS_DATA_FROM_BIN}" ABSOLUTE)
set(gvins_nav_dir gnss/nagoya_static_2024)
set(gvins_nav_files ${PROJECT_SOURCE_DIR}/tests/data/${gvins_nav_dir}/base.nav.gz
                    ${PROJECT_SOURCE_DIR}/tests/data/${gvins_nav_dir}/LICENSE.MatRTKLIB)
file(MAKE_DIRECTORY ${gvins_stage}/data/${gvins_nav_dir})
foreach(f IN LISTS gvins_nav_files)
  get_filename_component(name ${f} NAME)
  file(CREATE_LINK ${f} ${gvins_stage}/data/${gvins_nav_dir}/${name} SYMBOLIC COPY_ON_ERROR)
endforeach()
install(FILES ${gvins_nav_files} DESTINATION ${CMAKE_INSTALL_DATADIR}/${GVINS_DATA_SUBDIR}/data/${gvins_nav_dir})
# The scenarios name the navigation file relative to themselves (../tests/data/... in the source
# tree); the installed copies point at ../data/... instead.
file(GLOB gvins_scenarios CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/config/*.yaml)
foreach(f IN LISTS gvins_scenarios)
  get_filename_component(name ${f} NAME)
  file(READ ${f} text)
  string(REPLACE "../tests/data/" "../data/" text "${text}")
  file(CONFIGURE OUTPUT ${gvins_stage}/config/${name} CONTENT "${text}" @ONLY)
endforeach()
install(DIRECTORY ${gvins_stage}/config DESTINATION ${CMAKE_INSTALL_DATADIR}/${GVINS_DATA_SUBDIR})
if(TARGET gvins_sim)
  set_property(SOURCE ${PROJECT_SOURCE_DIR}/sim/src/scenario.cpp TARGET_DIRECTORY gvins_sim APPEND
               PROPERTY COMPILE_DEFINITIONS GVINS_SIM_DATA_FROM_BIN="${GVINS_DATA_FROM_BIN}")
endif()
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})

# ---- command-line tools: every executable defined under apps/ ------------------------------------
if(NOT GVINS_FUZZ)
  get_property(gvins_app_dirs DIRECTORY ${PROJECT_SOURCE_DIR}/apps PROPERTY SUBDIRECTORIES)
  foreach(d IN LISTS gvins_app_dirs)
    get_property(targets DIRECTORY ${d} PROPERTY BUILDSYSTEM_TARGETS)
    foreach(t IN LISTS targets)
      get_target_property(type ${t} TYPE)
      if(type STREQUAL "EXECUTABLE")
        install(TARGETS ${t} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
      endif()
    endforeach()
  endforeach()
endif()

# ---- CMake package --------------------------------------------------------------------------------
install(EXPORT SriGvinsTargets NAMESPACE SriGvins:: DESTINATION ${GVINS_CMAKE_DIR})
set(GVINS_OPENCV_COMPONENTS core imgproc imgcodecs video calib3d features2d)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/SriGvinsConfig.cmake.in
  ${PROJECT_BINARY_DIR}/SriGvinsConfig.cmake INSTALL_DESTINATION ${GVINS_CMAKE_DIR})
# 0.x: minor versions may break the interface.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/SriGvinsConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/SriGvinsConfig.cmake ${PROJECT_BINARY_DIR}/SriGvinsConfigVersion.cmake
        DESTINATION ${GVINS_CMAKE_DIR})

# ---- pkg-config -----------------------------------------------------------------------------------
# One file per library, sri-gvins-<module>.pc, whose Requires name the modules and the system
# packages it links (its private dependencies too: the libraries are static), and sri-gvins.pc for
# all of them. The prefix is found from the .pc file's own place (${pcfiledir}), so the installed
# tree can be moved.
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(GVINS_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  set(GVINS_PC_PREFIX "\${pcfiledir}/..")
  string(REPLACE "/" ";" parts "${CMAKE_INSTALL_LIBDIR}")
  foreach(p IN LISTS parts)
    string(APPEND GVINS_PC_PREFIX "/..")
  endforeach()
endif()

# gvins_pkgconfig_requirements(<target> <requires-var> <libs-var>): pkg-config modules and extra
# linker items of a library's link interface (imported targets mapped to their .pc names).
function(gvins_pkgconfig_requirements target requires_var libs_var)
  get_target_property(items ${target} INTERFACE_LINK_LIBRARIES)
  set(requires)
  set(libs)
  foreach(item IN LISTS items)
    string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" item "${item}")
    if(item MATCHES "^gvins_(.*)$")
      list(APPEND requires sri-gvins-${CMAKE_MATCH_1})
    elseif(item STREQUAL "Eigen3::Eigen")
      list(APPEND requires eigen3)
    elseif(item STREQUAL "yaml-cpp")
      list(APPEND requires yaml-cpp)
    elseif(item STREQUAL "ZLIB::ZLIB")
      list(APPEND requires zlib)
    elseif(item MATCHES "^opencv_")
      list(APPEND requires opencv4)
    elseif(item STREQUAL "Threads::Threads")
      list(APPEND libs -pthread)
    elseif(IS_ABSOLUTE "${item}")
      list(APPEND libs "${item}")
    elseif(item MATCHES "^-")
      list(APPEND libs "${item}")
    else()
      message(WARNING "the pkg-config file of ${target} lacks '${item}': no pkg-config name known for it "
                      "(add one to gvins_pkgconfig_requirements in cmake/GvinsInstall.cmake)")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES requires)
  list(REMOVE_DUPLICATES libs)
  set(${requires_var} ${requires} PARENT_SCOPE)
  set(${libs_var} ${libs} PARENT_SCOPE)
endfunction()

set(GVINS_PC_CFLAGS)
foreach(d IN LISTS GVINS_EIGEN_DEFINITIONS)
  list(APPEND GVINS_PC_CFLAGS -D${d})
endforeach()
if(GVINS_SRI_NATIVE)
  list(APPEND GVINS_PC_CFLAGS -march=native -ffp-contract=fast)
endif()
list(JOIN GVINS_PC_CFLAGS " " GVINS_PC_CFLAGS)
set(gvins_all_pc)
foreach(lib IN LISTS gvins_libraries)
  string(REGEX REPLACE "^gvins_" "" module ${lib})
  gvins_pkgconfig_requirements(${lib} requires libs)
  list(JOIN requires " " GVINS_PC_REQUIRES)
  list(JOIN libs " " GVINS_PC_EXTRA_LIBS)
  set(GVINS_PC_NAME "SRI-GVINS ${module}")
  set(GVINS_PC_DESCRIPTION "SRI-GVINS library gvins_${module}")
  set(GVINS_PC_LIBS "-L\${libdir} -l${lib} ${GVINS_PC_EXTRA_LIBS}")
  configure_file(${PROJECT_SOURCE_DIR}/cmake/sri-gvins.pc.in ${PROJECT_BINARY_DIR}/pkgconfig/sri-gvins-${module}.pc @ONLY)
  list(APPEND gvins_all_pc sri-gvins-${module})
endforeach()
list(JOIN gvins_all_pc " " GVINS_PC_REQUIRES)
set(GVINS_PC_NAME "SRI-GVINS")
set(GVINS_PC_DESCRIPTION "SRI-GVINS: GNSS, square-root inverse VIO and their fusion (all libraries)")
set(GVINS_PC_LIBS "")
configure_file(${PROJECT_SOURCE_DIR}/cmake/sri-gvins.pc.in ${PROJECT_BINARY_DIR}/pkgconfig/sri-gvins.pc @ONLY)
install(DIRECTORY ${PROJECT_BINARY_DIR}/pkgconfig/ DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
