# SPDX-License-Identifier: MIT
# `cmake --install build --prefix DIR`: the folder libraries, their headers under
# include/mlcontact/<folder>/, the driver, and the CMake package (lib/cmake/mlcontact) with the
# targets mlcontact::mlcontact (every folder library) and mlcontact::mlc_<folder>.
#
# Headers: in the source tree they include each other as "core/...", "levels/..." (the source
# root is the include path). A consumer's include path must hold no generic core/ or mesh/, so
# the install interface is <prefix>/include alone and consumers write
# <mlcontact/levels/solve.hpp>. With GCC and Clang a quoted include is looked up next to the
# including file and then on the include path, never relative to an ancestor folder, so
# "core/timer.hpp" inside include/mlcontact/levels/ would not be found from include/ alone: the
# installed copies get their own-folder includes prefixed ("core/x.hpp" -> "mlcontact/core/x.hpp",
# cmake/rewrite_includes.cmake), a mechanical rewrite of the #include lines only.
include(CMakePackageConfigHelpers)
include(GNUInstallDirs)
set(_mlc_folders core comm mesh fem contact transfer smoothers solvers levels scene run studies bench)
set(_mlc_targets)
foreach(f ${_mlc_folders})
  list(APPEND _mlc_targets mlc_${f})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${f}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mlcontact/${f}
    FILES_MATCHING PATTERN "*.hpp")
endforeach()
# mlcontact::mlcontact: everything (the executable target is called mlcontact in this tree, so
# the interface library has another name here and is exported as "mlcontact").
add_library(mlc_all INTERFACE)
set_target_properties(mlc_all PROPERTIES EXPORT_NAME mlcontact)
target_link_libraries(mlc_all INTERFACE ${_mlc_targets})
install(TARGETS ${_mlc_targets} mlc_all EXPORT mlcontactTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS mlcontact RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The plotting scripts, found by the driver and the Python module in share/mlcontact/plots
# above them (run/plot_script.hpp).
install(FILES ${MLC_PLOT_SCRIPTS} DESTINATION ${CMAKE_INSTALL_DATADIR}/mlcontact/plots)
install(CODE "set(MLC_HEADER_ROOT \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_INCLUDEDIR}/mlcontact\")
set(MLC_FOLDERS \"${_mlc_folders}\")
include(\"${PROJECT_SOURCE_DIR}/cmake/rewrite_includes.cmake\")")

set(_cfg ${CMAKE_INSTALL_LIBDIR}/cmake/mlcontact)
install(EXPORT mlcontactTargets NAMESPACE mlcontact:: DESTINATION ${_cfg})
set(MLC_CONFIG_OPENMP ${OpenMP_CXX_FOUND})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/mlcontactConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/mlcontactConfig.cmake INSTALL_DESTINATION ${_cfg})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/mlcontactConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/mlcontactConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/mlcontactConfigVersion.cmake ${PROJECT_SOURCE_DIR}/cmake/FindHYPRE.cmake
  DESTINATION ${_cfg})
