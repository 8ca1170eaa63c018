# What `cmake --install` lays out and how CPack packs it: two components, each a Debian package.
#   stripemux   the host tool, its scenes and example boards (share/stripemux)
#   stripemuxd  the firmware, its boards (share/stripemuxd/boards) and a systemd unit
# Included last by the top CMakeLists.txt: CPack takes the components of every install() before.
# docs/install.md describes the layout and the commands.

if(SMX_BUILD_HOST_TOOLS)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/hal/sim/scenes/ DESTINATION ${SMX_DATA_INSTALL_DIR}/scenes
          COMPONENT stripemux)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/boards/ DESTINATION ${SMX_DATA_INSTALL_DIR}/boards
          COMPONENT stripemux)
endif()

# The unit starts the firmware of the Linux devices: stripemuxd on a board build,
# stripemuxd-linux beside the simulated board's stripemuxd on a host build.
set(SMX_UNIT_FIRMWARE "")
if(TARGET stripemuxd-linux)
  set(SMX_UNIT_FIRMWARE stripemuxd-linux)
elseif(TARGET stripemuxd AND NOT SMX_BUILD_HOST_TOOLS)
  set(SMX_UNIT_FIRMWARE stripemuxd)
endif()
if(TARGET stripemuxd)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/boards/ DESTINATION ${SMX_BOARDS_INSTALL_DIR}
          COMPONENT stripemuxd)
endif()
if(SMX_UNIT_FIRMWARE)
  # Written at install time: the unit names absolute paths under the prefix of that install
  # (cmake --install --prefix, or /usr in a package), not the one configured.
  install(CODE "
    set(SMX_UNIT_EXE \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}/${SMX_UNIT_FIRMWARE}\")
    set(SMX_UNIT_BOARD \"\${CMAKE_INSTALL_PREFIX}/${SMX_BOARDS_INSTALL_DIR}/rpi4\")
    set(unit \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${SMX_UNIT_INSTALL_DIR}/stripemuxd.service\")
    message(STATUS \"Installing: \${unit}\")
    configure_file(\"${PROJECT_SOURCE_DIR}/packaging/stripemuxd.service.in\" \"\${unit}\" @ONLY)
    list(APPEND CMAKE_INSTALL_MANIFEST_FILES \"\${unit}\")
  " COMPONENT stripemuxd)
endif()

# Debian packages: cpack --config build/<preset>/CPackConfig.cmake (or the `package` target)
# writes build/<preset>/packages/<name>_<version>_<arch>.deb.
# Packing installs what is built and builds nothing: the `package` and `install` targets skip the
# build of `all` (cmake --build first), so the tests can pack a built tree in seconds.
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY ON)
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME stripemux)
set(CPACK_PACKAGE_VENDOR stripemux)
set(CPACK_PACKAGE_CONTACT "stripemux maintainers <stripemux@localhost>")
set(CPACK_PACKAGE_DIRECTORY ${PROJECT_BINARY_DIR}/packages)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)  # the packages carry no debug info (nor the build's paths in it)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# Depends from the libraries the binaries link (dpkg-shlibdeps). For the cross build it reads
# the arm64 libraries that tools/install-deps installs (multiarch) and their dpkg records.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# Seconds, not minutes: the tests build the packages (tests/install).
set(CPACK_DEBIAN_COMPRESSION_TYPE gzip)
if(CMAKE_CROSSCOMPILING)
  if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
    set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE arm64)
  else()
    message(WARNING "packaging: no Debian architecture known for ${CMAKE_SYSTEM_PROCESSOR}")
  endif()
endif()

set(CPACK_DEBIAN_STRIPEMUX_PACKAGE_NAME stripemux)
set(CPACK_DEBIAN_STRIPEMUX_DESCRIPTION "stripemux host tool: patterns, simulation, decoding, \
evaluation, device client
The stripemux command with the simulator's named scenes and the example boards and rigs
(/usr/share/stripemux).")
# The live view's 3D point cloud (three.js, served from this machine); the page works without.
set(CPACK_DEBIAN_STRIPEMUX_PACKAGE_RECOMMENDS libjs-three)
set(CPACK_DEBIAN_STRIPEMUXD_PACKAGE_NAME stripemuxd)
set(CPACK_DEBIAN_STRIPEMUXD_DESCRIPTION "stripemux scanner firmware with a systemd unit
stripemuxd serves range images of the board's cameras and projectors to a host. Boards are in
/usr/share/stripemuxd/boards; the unit stripemuxd.service runs the board named by
STRIPEMUXD_BOARD (/etc/default/stripemuxd).")

set(CPACK_COMPONENTS_ALL "")
if(SMX_BUILD_HOST_TOOLS)
  list(APPEND CPACK_COMPONENTS_ALL stripemux)
  # The simulated board's stripemuxd renders the scenes of the host tool's package.
  set(CPACK_DEBIAN_STRIPEMUXD_PACKAGE_SUGGESTS stripemux)
endif()
if(TARGET stripemuxd)
  list(APPEND CPACK_COMPONENTS_ALL stripemuxd)
endif()
include(CPack)
