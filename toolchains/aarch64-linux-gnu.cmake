# Cross-compilation for the robot's aarch64 payload computer (Debian 12 arm64).
#
# Libraries come from an arm64 sysroot built by scripts/make-arm64-sysroot.sh (Debian's arm64
# multiarch cannot co-install Ceres with the host's). Tests run under qemu-aarch64 through
# CMAKE_CROSSCOMPILING_EMULATOR, so plain `ctest` executes the aarch64 binaries.
#
# MSGRAPHS_ARM64_SYSROOT: cache variable, else the environment variable of the same name, else
# /opt/msgraphs/sysroot-arm64 (the script's default).

set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

if(NOT MSGRAPHS_ARM64_SYSROOT)
  if(DEFINED ENV{MSGRAPHS_ARM64_SYSROOT})
    set(MSGRAPHS_ARM64_SYSROOT "$ENV{MSGRAPHS_ARM64_SYSROOT}")
  else()
    set(MSGRAPHS_ARM64_SYSROOT /opt/msgraphs/sysroot-arm64)
  endif()
endif()
set(MSGRAPHS_ARM64_SYSROOT "${MSGRAPHS_ARM64_SYSROOT}" CACHE PATH "arm64 sysroot")
# try_compile projects re-read this file; pass the sysroot on to them.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES MSGRAPHS_ARM64_SYSROOT)

if(NOT EXISTS "${MSGRAPHS_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu")
  message(FATAL_ERROR "arm64 sysroot not found at '${MSGRAPHS_ARM64_SYSROOT}'. "
                      "Run scripts/bootstrap.sh --cross (or set MSGRAPHS_ARM64_SYSROOT).")
endif()

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_SYSROOT "${MSGRAPHS_ARM64_SYSROOT}")
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH "${MSGRAPHS_ARM64_SYSROOT}")
# Programs (fastddsgen, qemu) run on the build machine; libraries and headers come from the sysroot.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${MSGRAPHS_ARM64_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${MSGRAPHS_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${MSGRAPHS_ARM64_SYSROOT}/usr/share/pkgconfig")

# -L: the sysroot's dynamic loader and libraries. Never combine with QEMU_LD_PREFIX pointing at
# /usr/aarch64-linux-gnu: mixing that ld.so with the sysroot's libc hangs (build-environment.md 2a).
find_program(MSGRAPHS_QEMU_AARCH64 NAMES qemu-aarch64-static qemu-aarch64 REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR "${MSGRAPHS_QEMU_AARCH64};-L;${MSGRAPHS_ARM64_SYSROOT}")
