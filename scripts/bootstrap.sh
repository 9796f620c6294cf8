#!/usr/bin/env bash
# Installs every Debian 12 package msgraphs needs. Idempotent: when everything is present it
# only runs dpkg-query (well under a second) and touches neither apt nor the network.
#
#   scripts/bootstrap.sh            host build: compilers, Eigen, Ceres, Fast DDS, libgpiod, PCL, tests
#   scripts/bootstrap.sh --cross    also the aarch64 cross toolchain, qemu-user and the arm64 sysroot
#   scripts/bootstrap.sh --fuzz     also clang and its libFuzzer runtime (scripts/fuzz.sh)
#   scripts/bootstrap.sh --vm       also the kernel-in-the-loop VM (qemu-system, a Debian kernel
#                                   with vcan and gpio-sim; scripts/vm/prepare.sh)
#
# Why a sysroot and not `dpkg --add-architecture arm64`: libceres-dev:arm64 cannot be co-installed
# with the amd64 one (glog/gflags are not Multi-Arch: same), see docs/cross-build.md.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cross=0
fuzz=0
vm=0
for arg in "$@"; do
  case "$arg" in
    --cross) cross=1 ;;
    --fuzz) fuzz=1 ;;
    --vm) vm=1 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "bootstrap: unknown argument '$arg' (expected --cross, --fuzz or --vm)" >&2; exit 2 ;;
  esac
done

host_packages=(
  build-essential cmake ninja-build ccache pkg-config git
  libeigen3-dev libceres-dev
  libfastrtps-dev fastddsgen fastdds-tools
  libgpiod-dev gpiod can-utils
  libpcl-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  iproute2 nftables
  python3 librsvg2-bin  # tools/eval: results tables; the demo picture as PNG
)
cross_packages=(g++-aarch64-linux-gnu qemu-user-static mmdebstrap file)  # file: CI shows the binaries' architecture
fuzz_packages=(clang libclang-rt-14-dev)

missing_packages() {
  local p status
  for p in "$@"; do
    status=$(dpkg-query -W -f='${db:Status-Abbrev}' "$p" 2>/dev/null || true)
    [[ "$status" == ii* ]] || echo "$p"
  done
}

if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); else sudo_cmd=(); fi

wanted=("${host_packages[@]}")
(( cross )) && wanted+=("${cross_packages[@]}")
(( fuzz )) && wanted+=("${fuzz_packages[@]}")
mapfile -t todo < <(missing_packages "${wanted[@]}")
if (( ${#todo[@]} )); then
  echo "bootstrap: installing ${#todo[@]} missing package(s): ${todo[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "${todo[@]}" >/dev/null
  mapfile -t still < <(missing_packages "${wanted[@]}")
  if (( ${#still[@]} )); then
    echo "bootstrap: failed to install: ${still[*]}" >&2; exit 1
  fi
else
  echo "bootstrap: all ${#wanted[@]} host packages present"
fi

if (( cross )); then
  "${sudo_cmd[@]}" "$here/make-arm64-sysroot.sh"
fi

if (( vm )); then
  "$here/vm/prepare.sh"
fi
