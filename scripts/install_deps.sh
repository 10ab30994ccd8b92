#!/usr/bin/env bash
# Installs exactly the Debian 12 packages mrpt_yesslam needs to build and test, and nothing when
# they are all present already. Uses sudo only when not running as root.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config          # compiler and build system
  lld                                       # LLVM's linker: links the test executables 3-4x faster
  ccache                                    # compiler cache: rebuilds (and CI's three builds) reuse objects
  clang-format-14                           # the code's format (.clang-format), checked by a test
  libmrpt-dev                               # MRPT 2.5: observations, rawlogs, poses, opengl scenes
  libopencv-dev                             # OpenCV 4.6: images, ORB, DNN
  libjpeg62-turbo-dev                       # jpeglib.h: we guard MRPT's JPEG decoding (already an OpenCV dependency)
  libceres-dev libeigen3-dev                # optimisation, linear algebra
  liboctomap-dev                            # semantic OctoMap
  libopenni2-dev                            # live RGB-D cameras
  libdeflate-dev                            # fast inflate for dataset PNGs
  libgtest-dev googletest                   # unit tests
  mrpt-apps                                 # rawlog-edit: tests check that MRPT's own tools read our rawlogs
  libegl1 libegl-mesa0 libgl1-mesa-dri      # headless OpenGL (EGL + Mesa software renderer) for rendering
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install_deps: error: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install_deps: done"
