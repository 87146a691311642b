# Installation layout and Debian packages (CPack DEB) for amd64, arm64 and armhf.
#   cmake --preset release && cmake --build --preset release && (cd build/release && cpack)
#   -> build/release/diffodom_<version>_<arch>.deb; cross presets give the arm64 / armhf package.
# The package is what a robot controller runs: /usr/bin/odometryd, /usr/bin/odomctl, the default
# config /etc/odometryd/odometryd.toml (a conffile), the calibration store's directory
# /var/lib/odometryd/, the DBC file /usr/share/odometryd/odometry.dbc and the systemd unit
# /lib/systemd/system/odometryd.service. Package paths are absolute Debian paths, so install()
# uses absolute destinations for everything outside /usr.

# Binaries: firmware/ and odomctl/ install odometryd and odomctl to bin (prefix /usr here).
set(ODO_PKG_SOURCE ${CMAKE_CURRENT_SOURCE_DIR})
install(FILES ${ODO_PKG_SOURCE}/firmware/config/odometryd.toml DESTINATION /etc/odometryd)
# The calibration store's default location (/var/lib/odometryd/calibration.bin); postinst also
# creates it, so a purge followed by a reinstall works.
install(DIRECTORY DESTINATION /var/lib/odometryd)
install(FILES ${ODO_PKG_SOURCE}/protocol/odometry.dbc DESTINATION /usr/share/odometryd)
install(FILES ${ODO_PKG_SOURCE}/firmware/systemd/odometryd.service
  DESTINATION /lib/systemd/system)

# Debian architecture of the target: the cross toolchains set CMAKE_SYSTEM_PROCESSOR, while CPack
# would otherwise ask `dpkg --print-architecture`, which names the build machine.
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(ODO_DEB_ARCH arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^arm")
  set(ODO_DEB_ARCH armhf)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(ODO_DEB_ARCH amd64)
else()
  message(STATUS "packaging: no Debian architecture known for ${CMAKE_SYSTEM_PROCESSOR}")
  set(ODO_DEB_ARCH "")
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME diffodom)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "diffodom project")
set(CPACK_PACKAGE_CONTACT "diffodom maintainers <diffodom@example.org>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
  "odometry firmware for differential-drive robots (odometryd, odomctl)")
set(CPACK_PACKAGE_DESCRIPTION
  "odometryd reads the two wheel encoders (HCTL-1100 counter chip, GPIO quadrature or CAN counts)
in a fixed-rate real-time loop, integrates the pose with UMBmark-calibrated factors and broadcasts
pose, velocity and uncertainty on the CAN bus. odomctl replays encoder logs, runs the UMBmark
calibration and manages the calibration store.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
if(ODO_DEB_ARCH)
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${ODO_DEB_ARCH})
endif()
# Depends from the binaries' DT_NEEDED entries through dpkg-shlibdeps. For a cross build it must
# look up the target's libraries (libc6:arm64 ...), not the host's: CPack runs it with the
# binaries' own ELF class/machine, and dpkg-shlibdeps only accepts libraries of that format from
# the multiarch directories, so the :arm64/:armhf packages of tools/setup.sh --cross must be
# installed. tests/package/check_deb.sh verifies the result against readelf for every package.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS OFF)
# Binaries are stripped in the package (the build tree keeps the unstripped ones).
set(CPACK_STRIP_FILES ON)
# /etc files of a package must be conffiles (dpkg keeps local edits on upgrade and asks).
set(ODO_DEB_CONTROL ${CMAKE_CURRENT_BINARY_DIR}/debian-control)
file(WRITE ${ODO_DEB_CONTROL}/conffiles "/etc/odometryd/odometryd.toml\n")
configure_file(${ODO_PKG_SOURCE}/packaging/debian/postinst ${ODO_DEB_CONTROL}/postinst COPYONLY
  FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ
  WORLD_EXECUTE)
configure_file(${ODO_PKG_SOURCE}/packaging/debian/prerm ${ODO_DEB_CONTROL}/prerm COPYONLY
  FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ
  WORLD_EXECUTE)
configure_file(${ODO_PKG_SOURCE}/packaging/debian/postrm ${ODO_DEB_CONTROL}/postrm COPYONLY
  FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ
  WORLD_EXECUTE)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
  ${ODO_DEB_CONTROL}/conffiles ${ODO_DEB_CONTROL}/postinst ${ODO_DEB_CONTROL}/prerm
  ${ODO_DEB_CONTROL}/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)

# ctest -L package: build this tree's package and check it (tests/package/check_deb.sh). For the
# machine's own architecture it also installs, runs, verifies the unit, removes and purges (root
# only; tools/test.sh runs it on the throw-away CI machine). Not part of the unit|sim|cli tiers.
if(ODO_BUILD_TESTS AND ODO_DEB_ARCH)
  add_test(NAME package_deb
    COMMAND bash ${ODO_PKG_SOURCE}/tests/package/check_deb.sh ${CMAKE_BINARY_DIR} ${ODO_PKG_SOURCE}
            ${ODO_DEB_ARCH} $<$<NOT:$<BOOL:${CMAKE_CROSSCOMPILING}>>:--install>)
  set_tests_properties(package_deb PROPERTIES LABELS package SKIP_RETURN_CODE 77 RUN_SERIAL ON
    TIMEOUT 300)
endif()
