# `cpack -G DEB` in the build directory: skyfarm_<version>_<arch>.deb holding
# what cmake/Install.cmake installs, under /usr.  Its Depends: line is computed
# by dpkg-shlibdeps from the libraries the binaries link (libzmq5,
# libopenexr-3-1-30, libcpp-httplib0.11, ...), so it follows the build.
# ffmpeg is recommended: the server runs it for timelapse videos only.
set(CPACK_GENERATOR "DEB" CACHE STRING "CPack generators")
set(CPACK_PACKAGE_NAME "skyfarm")
set(CPACK_PACKAGE_VENDOR "skyfarm")
set(CPACK_PACKAGE_CONTACT "skyfarm maintainers <skyfarm@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "physically based sky renderer served as a render farm")
set(CPACK_PACKAGE_DESCRIPTION
    "skyfarm-server takes JSON render requests over HTTP and hands their units to\n skyfarm-worker processes over ZeroMQ; skyfarm-worker also renders on its own.")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX "/usr")
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION "graphics")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "ffmpeg")
include(CPack)
