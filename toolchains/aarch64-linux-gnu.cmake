# Cross build for 64-bit ARM Linux boards (Raspberry Pi 4/5, i.MX8, RK3399 ...) with Debian's
# g++-aarch64-linux-gnu. Test executables run under qemu-user: binfmt_misc is often not mounted
# in containers, so the emulator is always named explicitly.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)

# The binaries run against Debian's multiarch arm64 runtime (libc6:arm64, libstdc++6:arm64, which
# tools/install-deps installs with libgpiod-dev:arm64), loader included. With the cross
# toolchain's own prefix (-L /usr/aarch64-linux-gnu) its loader would still find the multiarch
# libc in /lib/aarch64-linux-gnu once that is installed, and a loader and libc of two builds
# deadlock in thread start-up.
set(CMAKE_CROSSCOMPILING_EMULATOR /usr/bin/qemu-aarch64-static;-L;/)

# Used by the integer-only check of the per-frame objects (tests/static).
set(SMX_TARGET_OBJDUMP aarch64-linux-gnu-objdump)
set(SMX_TARGET_NM aarch64-linux-gnu-nm)

# pkg-config reads the arm64 .pc files of Debian's multiarch -dev packages (libcamera-dev:arm64)
# and never the host's. Their paths are real paths of this machine (/usr/include,
# /usr/lib/aarch64-linux-gnu), so no sysroot is prefixed.
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig)
set(ENV{PKG_CONFIG_SYSROOT_DIR} "")
set(ENV{PKG_CONFIG_PATH} "")
