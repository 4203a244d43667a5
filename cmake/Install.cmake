# What `cmake --install` puts under the prefix (GNUInstallDirs), and so what
# the .deb holds (cmake/Package.cmake):
#   bin/skyfarm-server, bin/skyfarm-worker     the programs; the server starts
#                                              the worker next to itself
#   lib/systemd/system/skyfarm-*.service       the units, ExecStart= pointing at
#                                              the installed bin/ (SKYFARM_SYSTEMD_UNITDIR)
#   share/doc/skyfarm/                         README.md, deploy/README.md as
#                                              DEPLOY.md, skyfarm.env.example
# The physical tables of data/, the web page and the OpenAPI document are
# embedded in the binaries at build time, so nothing else is needed at run time
# and the programs run from any directory, without the source tree.
include(GNUInstallDirs)

set(SKYFARM_SYSTEMD_UNITDIR "lib/systemd/system" CACHE STRING
    "systemd unit directory, relative to the install prefix")

install(TARGETS skyfarm-server skyfarm-worker RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/deploy/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} RENAME DEPLOY.md)
install(FILES ${PROJECT_SOURCE_DIR}/deploy/systemd/skyfarm.env.example DESTINATION ${CMAKE_INSTALL_DOCDIR})

# The units in deploy/systemd/ name /usr/bin/skyfarm-*, the .deb's paths.  They
# are rewritten at install time, not configure time, because the prefix is only
# known then (`cmake --install --prefix`, CPack's /usr).
set(_skyfarm_units skyfarm-server.service skyfarm-worker@.service)
install(CODE "
  set(_bindir \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
  if(IS_ABSOLUTE \"${CMAKE_INSTALL_BINDIR}\")
    set(_bindir \"${CMAKE_INSTALL_BINDIR}\")
  endif()
  set(_unitdir \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${SKYFARM_SYSTEMD_UNITDIR}\")
  foreach(_unit ${_skyfarm_units})
    file(READ \"${PROJECT_SOURCE_DIR}/deploy/systemd/\${_unit}\" _text)
    string(REPLACE \"/usr/bin/skyfarm-\" \"\${_bindir}/skyfarm-\" _text \"\${_text}\")
    file(MAKE_DIRECTORY \"\${_unitdir}\")
    message(STATUS \"Installing: \${_unitdir}/\${_unit}\")
    file(WRITE \"\${_unitdir}/\${_unit}\" \"\${_text}\")
    list(APPEND CMAKE_INSTALL_MANIFEST_FILES \"\${_unitdir}/\${_unit}\")
  endforeach()
")
