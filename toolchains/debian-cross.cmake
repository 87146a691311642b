# Shared part of the Debian 12 (bookworm) cross toolchains, included by the per-target files
# (aarch64-linux-gnu.cmake, arm-linux-gnueabihf.cmake), which set before including it:
#   CMAKE_SYSTEM_PROCESSOR, XC_TRIPLE (compiler prefix and multiarch directory),
#   XC_QEMU_ARCH (qemu-<arch> user-mode emulator), XC_LOADER (the target's dynamic loader).
# Uses Debian's cross compiler and the Debian multiarch :<arch> -dev packages (headers in
# /usr/include, libs in /usr/lib/<triple>, arch-indep files in /usr/share).

set(CMAKE_SYSTEM_NAME Linux)

# GCC's -Wpsabi notes (armhf: "parameter passing for argument of type std::span<...> changed in
# GCC 7.1", 239 of them; aarch64: one for std::pair "changed to match C++14 in GCC 10.1"): an ABI
# break only against objects built by an older GCC; every object and library here comes from
# Debian 12's GCC 12. On armhf they were about 1000 lines of a CI log whose tail is all that is
# kept.
set(CMAKE_CXX_FLAGS_INIT "-Wno-psabi")

set(CMAKE_C_COMPILER   /usr/bin/${XC_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER /usr/bin/${XC_TRIPLE}-g++)
set(CMAKE_AR           /usr/bin/${XC_TRIPLE}-ar     CACHE FILEPATH "")
set(CMAKE_RANLIB       /usr/bin/${XC_TRIPLE}-ranlib CACHE FILEPATH "")
set(CMAKE_STRIP        /usr/bin/${XC_TRIPLE}-strip  CACHE FILEPATH "")

# Debian multiarch: target libs live in /usr/lib/<triple>; CMake searches <prefix>/lib/<arch> with this.
set(CMAKE_LIBRARY_ARCHITECTURE ${XC_TRIPLE})

# Find roots: the cross toolchain's own tree (/usr/<triple>) AND "/" -- the multiarch :<arch>
# packages install into /usr/lib/<triple>, and Eigen (arch:all) into /usr/include + /usr/share.
# Without "/" here (ONLY mode): Eigen3 and GTest are not found, and libgpiod.so is not found by
# find_library (pkg_check_modules falls back to a bare "-lgpiod").
set(CMAKE_FIND_ROOT_PATH /usr/${XC_TRIPLE} /)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)   # host tools (pkg-config, qemu, python)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config: only look at the target's .pc files (never the host's /usr/lib/x86_64-linux-gnu/pkgconfig).
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/${XC_TRIPLE}/pkgconfig:/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "")

# Run target binaries (ctest, gtest_discover_tests, try_run) under user-mode qemu.
# binfmt_misc is usually not registered in containers, so the emulator is named explicitly
# (running ./test_bin directly gives "Exec format error").
# Any <arch> library (libgpiod2:<arch> ...) pulls in libc6:<arch>, which provides the target loader
# ${XC_LOADER}; then NO -L is wanted: loader and libc both come from libc6:<arch>.
# With "-L /usr/${XC_TRIPLE}" qemu would take the loader from libc6-<arch>-cross (2.36-8cross1)
# but still fall back to libc.so.6 from libc6:<arch> (2.36-9+deb12uN) -- a mixed glibc that
# happened to work but is fragile. -L is used only if libc6:<arch> is absent.
if(NOT DEFINED XC_QEMU)
  if(EXISTS /usr/bin/qemu-${XC_QEMU_ARCH}-static)
    set(XC_QEMU /usr/bin/qemu-${XC_QEMU_ARCH}-static)  # Debian package qemu-user-static
  else()
    set(XC_QEMU /usr/bin/qemu-${XC_QEMU_ARCH})         # Debian package qemu-user
  endif()
endif()
if(EXISTS ${XC_LOADER})
  set(CMAKE_CROSSCOMPILING_EMULATOR "${XC_QEMU}" CACHE STRING "Emulator for target binaries")
else()
  set(CMAKE_CROSSCOMPILING_EMULATOR "${XC_QEMU};-L;/usr/${XC_TRIPLE}" CACHE STRING "Emulator for target binaries")
endif()
