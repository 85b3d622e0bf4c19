#!/usr/bin/env bash
# Installs every Debian 12 package kinograph builds, tests or benchmarks with.
# Idempotent: packages already present are skipped; apt runs only when something is missing.
set -euo pipefail

PACKAGES=(
  # toolchain
  cmake ninja-build pkg-config g++ git
  # messaging
  liblcm-dev liblcm-bin libglib2.0-dev
  # lcm-spy with kinograph's types: the jar is built, and its test run, when a JDK is present
  # (the build skips both without one)
  liblcm-java libjchart2d-java openjdk-17-jdk-headless
  # numerics, collision, models, meshes
  libeigen3-dev libsuitesparse-dev libbullet-dev liburdfdom-dev libassimp-dev
  # rendering and plots
  libosmesa6-dev libpng-dev fonts-dejavu-core libcairo2-dev
  # tools, config, logging
  nlohmann-json3-dev libyaml-cpp-dev libexpat1-dev libcli11-dev libspdlog-dev
  # tests and benchmarks (KDL and Ceres are test/bench-only oracles)
  libgtest-dev libgmock-dev libbenchmark-dev liborocos-kdl-dev libceres-dev
  # the side-by-side benchmark against OMPL's control planners (bench/peers)
  libompl-dev
  # third-party URDFs with real meshes for renderer tests
  dart-doc
  # the Python client's tests (the client needs only python3 and liblcm1)
  python3
  # the API reference (target docs, test docs.doxygen); the build skips both without it
  doxygen
  # network namespaces for LCM multicast tests
  iproute2 util-linux
  # fuzz targets (fuzz/, ctest fuzz.short_runs): clang with libFuzzer, ASan and UBSan
  clang-14 libfuzzer-14-dev
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
