# `cmake --install`: the header and its parts (include/microshadow/), the static and shared libraries, the CLI, a relocatable CMake package
# (find_package(microshadow): microshadow::microshadow is the shared library, microshadow::microshadow_static
# the static one with its dependencies, microshadow::cli the program) and pkg-config files
# (microshadow: shared; microshadow-static: the archive and everything it needs).
include(CMakePackageConfigHelpers)

install(FILES include/microshadow.h ${PROJECT_BINARY_DIR}/include/microshadow_version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY include/microshadow/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/microshadow FILES_MATCHING PATTERN "*.h")
install(TARGETS microshadow microshadow_shared microshadow_cli EXPORT microshadowTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
set(MS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/microshadow)
install(EXPORT microshadowTargets NAMESPACE microshadow:: DESTINATION ${MS_CMAKE_DIR})
configure_package_config_file(cmake/microshadowConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/microshadowConfig.cmake INSTALL_DESTINATION ${MS_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/microshadowConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/microshadowConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/microshadowConfigVersion.cmake DESTINATION ${MS_CMAKE_DIR})

# pkg-config: prefix relative to the .pc file's own folder, so an install under any --prefix works.
file(RELATIVE_PATH MS_PC_TO_PREFIX "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
string(REGEX REPLACE "/$" "" MS_PC_TO_PREFIX "${MS_PC_TO_PREFIX}")
set(MS_PC_REQUIRES "libcjson libpng libturbojpeg libzstd libwebp OpenEXR")
get_filename_component(MS_EXRCORE_NAME ${OPENEXRCORE_LIB} NAME_WE)
string(REGEX REPLACE "^lib" "-l" MS_PC_LIBS_PRIVATE "${MS_EXRCORE_NAME}")
string(APPEND MS_PC_LIBS_PRIVATE " -lmeshoptimizer -ldraco")   # meshoptimizer has no .pc of its own
if(MS_HAVE_EMBREE)
  string(APPEND MS_PC_LIBS_PRIVATE " -lembree3")
endif()
string(APPEND MS_PC_LIBS_PRIVATE " ${OpenMP_C_FLAGS} -lm -lstdc++")
configure_file(cmake/microshadow.pc.in ${CMAKE_CURRENT_BINARY_DIR}/microshadow.pc @ONLY)
configure_file(cmake/microshadow-static.pc.in ${CMAKE_CURRENT_BINARY_DIR}/microshadow-static.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/microshadow.pc ${CMAKE_CURRENT_BINARY_DIR}/microshadow-static.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# The Python module, beside the library it loads (python/microshadow finds ../../../libmicroshadow.so).
install(DIRECTORY python/microshadow DESTINATION ${CMAKE_INSTALL_LIBDIR}/python3/dist-packages
  PATTERN __pycache__ EXCLUDE)

# The licence and the vendored parts' notices, with the installed library that contains their code.
install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/microshadow)
install(FILES third_party/cgltf/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/microshadow RENAME LICENSE.cgltf)
install(FILES third_party/xatlas/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/microshadow RENAME LICENSE.xatlas)
install(FILES third_party/ltc/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/microshadow RENAME LICENSE.ltc)
install(FILES third_party/mikktspace/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/microshadow RENAME LICENSE.mikktspace)
