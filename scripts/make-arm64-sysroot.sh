#!/usr/bin/env bash
# Builds (once) an arm64 Debian 12 sysroot from Debian packages with mmdebstrap, for the
# aarch64 cross build and for running its tests under qemu-aarch64.
#
#   scripts/make-arm64-sysroot.sh [DIR]
#
# DIR defaults to $MSGRAPHS_ARM64_SYSROOT, else /opt/msgraphs/sysroot-arm64 (the same default as
# toolchains/aarch64-linux-gnu.cmake). A stamp file records the package list and this script's
# checksum; when both match, the script returns at once.
#
# The extract variant resolves dependencies and unpacks without running maintainer scripts, so
# it needs no qemu; three fix-ups below stand in for what postinst would have done.
set -euo pipefail

sysroot=$(realpath -m "${1:-${MSGRAPHS_ARM64_SYSROOT:-/opt/msgraphs/sysroot-arm64}}")
packages=libc6-dev,libstdc++-12-dev,libeigen3-dev,libceres-dev,libfastrtps-dev,libgpiod-dev,libgtest-dev,libgmock-dev,libbenchmark-dev
stamp_value="$packages $(sha256sum "${BASH_SOURCE[0]}" | cut -c1-16)"
stamp="$sysroot/.msgraphs-sysroot-stamp"

if [[ -f "$stamp" && "$(cat "$stamp")" == "$stamp_value" ]]; then
  echo "sysroot: up to date at $sysroot"
  exit 0
fi

# The machine's own apt sources are the mirror argument (deb822 .sources or a classic .list).
mirror=
for f in /etc/apt/sources.list.d/debian.sources /etc/apt/sources.list; do
  if [[ -s "$f" ]]; then mirror=$f; break; fi
done
[[ -n "$mirror" ]] || { echo "sysroot: no apt sources file found" >&2; exit 1; }

echo "sysroot: building arm64 sysroot at $sysroot (mirror list $mirror)"
rm -rf "$sysroot"
mkdir -p "$(dirname "$sysroot")"
mmdebstrap --quiet --mode=root --variant=extract --architectures=arm64 --include="$packages" \
  bookworm "$sysroot" "$mirror"

# Fix-up 1: absolute symlinks (libm.so -> /lib/aarch64-linux-gnu/libm.so.6) would resolve on the
# host; make them relative to the sysroot.
find "$sysroot/usr" -type l -lname '/*' -print0 | while IFS= read -r -d '' link; do
  target=$(readlink "$link")
  ln -sfn "$(realpath -m --relative-to="$(dirname "$link")" "$sysroot$target")" "$link"
done

# Fix-up 2: the BLAS/LAPACK alternatives links that postinst normally creates (without them
# libceres.so fails to link: undefined dgeqrf_ and friends).
libdir=$sysroot/usr/lib/aarch64-linux-gnu
for impl in openblas-pthread blas lapack atlas; do
  for lib in libblas.so.3 libblas.so liblapack.so.3 liblapack.so; do
    if [[ -e "$libdir/$impl/$lib" && ! -e "$libdir/$lib" ]]; then ln -s "$impl/$lib" "$libdir/$lib"; fi
  done
done

# Fix-up 3: CMake package files hard-code /usr/lib/aarch64-linux-gnu/... (Ceres's LAPACK,
# fastrtps/fastcdr IMPORTED_LOCATION); re-root them, or ninja looks for the host's files.
cmake_dirs=()
for d in "$libdir/cmake" "$sysroot/usr/share/cmake" "$sysroot"/usr/share/*/cmake "$sysroot/usr/lib/cmake"; do
  if [[ -d "$d" ]]; then cmake_dirs+=("$d"); fi
done
grep -rlE '"/usr/|;/usr/' "${cmake_dirs[@]}" | sort -u \
  | xargs -r sed -i -E "s#([\";])/usr/#\1$sysroot/usr/#g"

echo "$stamp_value" > "$stamp"
echo "sysroot: done ($(du -sh "$sysroot" | cut -f1))"
