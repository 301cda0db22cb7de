#!/usr/bin/env bash
# Installs gonio's C library into PREFIX the way C and C++ projects expect (docs/C_API.md,
# "Installing"):
#
#   PREFIX/lib/libgonio.so.VERSION          the shared library, SONAME libgonio.so.0.MINOR (0.x)
#   PREFIX/lib/libgonio.so.0.MINOR, libgonio.so   links to it
#   PREFIX/lib/libgonio.a                   the static library (link also -lpthread -ldl -lm)
#   PREFIX/include/gonio/gonio.h, gonio.hpp, gonio_device.h
#   PREFIX/lib/pkgconfig/gonio.pc           pkg-config: the shared library
#   PREFIX/lib/pkgconfig/gonio-static.pc    pkg-config: the static library
#   PREFIX/lib/cmake/gonio/gonioConfig.cmake, gonioConfigVersion.cmake
#                                           find_package(gonio CONFIG): gonio::gonio, gonio::gonio_static
#
# The .pc and CMake files locate the prefix from their own place, so the tree can be moved.
#
# Usage: scripts/install-c.sh PREFIX [--profile PROFILE]
#   PROFILE: the cargo profile to build and install (default `dist`: release without debug info;
#   the test command installs the `test` build it already has).
#
# Why not cargo-c: it does the same (SONAME, .pc, headers), but it is built from source on every
# machine that runs the test command (a few minutes on 2 cores, on top of the project's own build),
# it writes no CMake package, and this project's header is generated and tested by its own tests
# (cbindgen in crates/gonio-capi/tests/header.rs); the ~40 lines below are the whole of the job.
set -euo pipefail
cd "$(dirname "$0")/.."

prefix=""
profile="dist"
while [ $# -gt 0 ]; do
  case "$1" in
    --profile) profile="$2"; shift 2 ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    *) if [ -z "$prefix" ]; then prefix="$1"; shift; else echo "install-c: unexpected argument $1" >&2; exit 2; fi ;;
  esac
done
if [ -z "$prefix" ]; then
  echo "usage: scripts/install-c.sh PREFIX [--profile PROFILE]" >&2
  exit 2
fi
mkdir -p "$prefix"
prefix="$(cd "$prefix" && pwd)"

cargo build --locked --profile "$profile" -p gonio-capi
case "$profile" in
  dev|test) dir="target/debug" ;;
  bench) dir="target/release" ;;
  *) dir="target/$profile" ;;
esac
version="$(sed -n 's/^version *= *"\(.*\)"/\1/p' Cargo.toml | head -n 1)"
major="${version%%.*}"
rest="${version#*.}"
minor="${rest%%.*}"
if [ "$major" = "0" ]; then soname="libgonio.so.0.$minor"; else soname="libgonio.so.$major"; fi

install -d "$prefix/lib/pkgconfig" "$prefix/lib/cmake/gonio" "$prefix/include/gonio"
install -m 644 "$dir/libgonio_capi.a" "$prefix/lib/libgonio.a"
install -m 755 "$dir/libgonio_capi.so" "$prefix/lib/libgonio.so.$version"
ln -sfn "libgonio.so.$version" "$prefix/lib/$soname"
ln -sfn "$soname" "$prefix/lib/libgonio.so"
install -m 644 crates/gonio-capi/include/gonio.h crates/gonio-capi/include/gonio.hpp \
  crates/gonio-capi/include/gonio_device.h "$prefix/include/gonio/"

for kind in shared static; do
  if [ "$kind" = shared ]; then
    name="gonio"; libs='-L${libdir} -lgonio'; private='Libs.private: -lpthread -ldl -lm'
  else
    name="gonio-static"; libs='${libdir}/libgonio.a -lpthread -ldl -lm'; private=""
  fi
  cat > "$prefix/lib/pkgconfig/$name.pc" <<PC
prefix=\${pcfiledir}/../..
libdir=\${prefix}/lib
includedir=\${prefix}/include

Name: $name
Description: gonio: importance sampling of tabulated directional distributions (IES, EULUMDAT, BRDFs, environment maps) by the Havran-Dmitriev-Seidel map ($kind library)
Version: $version
Libs: $libs
$private
Cflags: -I\${includedir} -I\${includedir}/gonio
PC
done

cat > "$prefix/lib/cmake/gonio/gonioConfig.cmake" <<CMAKE
# find_package(gonio CONFIG): the imported targets gonio::gonio (shared) and gonio::gonio_static.
# Written by scripts/install-c.sh; relocatable (the prefix is found from this file's place).
include(CMakeFindDependencyMacro)
find_dependency(Threads)
get_filename_component(_gonio_prefix "\${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)
if(NOT TARGET gonio::gonio)
  add_library(gonio::gonio SHARED IMPORTED)
  set_target_properties(gonio::gonio PROPERTIES
    IMPORTED_LOCATION "\${_gonio_prefix}/lib/libgonio.so.$version"
    IMPORTED_SONAME "$soname"
    INTERFACE_INCLUDE_DIRECTORIES "\${_gonio_prefix}/include;\${_gonio_prefix}/include/gonio")
endif()
if(NOT TARGET gonio::gonio_static)
  add_library(gonio::gonio_static STATIC IMPORTED)
  set_target_properties(gonio::gonio_static PROPERTIES
    IMPORTED_LOCATION "\${_gonio_prefix}/lib/libgonio.a"
    IMPORTED_LINK_INTERFACE_LANGUAGES "C"
    INTERFACE_INCLUDE_DIRECTORIES "\${_gonio_prefix}/include;\${_gonio_prefix}/include/gonio"
    INTERFACE_LINK_LIBRARIES "Threads::Threads;\${CMAKE_DL_LIBS};m")
endif()
unset(_gonio_prefix)
set(gonio_VERSION "$version")
CMAKE
cat > "$prefix/lib/cmake/gonio/gonioConfigVersion.cmake" <<CMAKE
# 0.x: a request is met by the same minor version at the same or a later patch (a 0.x minor
# release may change the ABI); from 1.0 on, by the same major version.
set(PACKAGE_VERSION "$version")
if(PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
elseif(NOT PACKAGE_FIND_VERSION_MAJOR EQUAL $major)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
elseif($major EQUAL 0 AND DEFINED PACKAGE_FIND_VERSION_MINOR AND NOT PACKAGE_FIND_VERSION_MINOR EQUAL $minor
       AND NOT "\${PACKAGE_FIND_VERSION}" STREQUAL "0")
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
else()
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
  if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)
    set(PACKAGE_VERSION_EXACT TRUE)
  endif()
endif()
CMAKE
echo "install-c: gonio $version ($profile build) installed into $prefix (SONAME $soname)"
