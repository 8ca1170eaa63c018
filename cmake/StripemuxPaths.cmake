# Where the installed tools find their data, and the same data for runs from the build tree.
# Nothing absolute goes into a binary: the installed tool finds <prefix>/share/stripemux from its
# own executable (smx::sim::dataDir), so the tree may be installed anywhere (DESTDIR, a .deb,
# dpkg -x into a folder).
include(GNUInstallDirs)

set(SMX_DATA_INSTALL_DIR ${CMAKE_INSTALL_DATADIR}/stripemux)     # scenes/, boards/
set(SMX_BOARDS_INSTALL_DIR ${CMAKE_INSTALL_DATADIR}/stripemuxd/boards)
set(SMX_UNIT_INSTALL_DIR lib/systemd/system)

# The data folder relative to the bin folder ("../share/stripemux" by default): the path from one
# prefix-relative folder to another, so any prefix gives the same answer.
file(RELATIVE_PATH SMX_DATA_DIR_FROM_BIN /prefix/${CMAKE_INSTALL_BINDIR}
     /prefix/${SMX_DATA_INSTALL_DIR})

# A build tree's data folder at its top: links to the source tree's scenes and example boards.
# Executables anywhere below (the tool, the tests) find it by looking upwards.
set(SMX_BUILD_DATA_DIR stripemux-data)
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/${SMX_BUILD_DATA_DIR})
file(CREATE_LINK ${PROJECT_SOURCE_DIR}/hal/sim/scenes
     ${PROJECT_BINARY_DIR}/${SMX_BUILD_DATA_DIR}/scenes SYMBOLIC)
file(CREATE_LINK ${PROJECT_SOURCE_DIR}/boards ${PROJECT_BINARY_DIR}/${SMX_BUILD_DATA_DIR}/boards
     SYMBOLIC)
