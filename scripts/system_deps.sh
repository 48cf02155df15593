#!/bin/sh
# Install the Debian/Ubuntu packages beatlite needs at test/run time, when they are missing.
#
#   espeak-ng                       text-to-speech used by the data_samples/ corpus generator (beatlite.synth)
#   libegl1 libgl1-mesa-dri         headless OpenGL (EGL + Mesa llvmpipe) for pyvista off-screen rendering;
#                                   beatlite.viz.probe tries VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow first
#   libosmesa6                      second choice for pyvista off-screen rendering (vtkOSOpenGLRenderWindow)
#   chromium                        headless browser of tests/test_pages.py: opens the exported notebook pages
#                                   offline and checks that formulas and the animation player render
#   ffmpeg            (optional)    MP4 export of animations (GIF export needs nothing)
#
# Idempotent: installs only what `dpkg -s` reports missing. Installs only when run as root with apt-get
# available; otherwise prints the command to run and exits 0 (nothing here is fatal: without the
# rendering libraries beatlite.viz warns once and draws with matplotlib; without ffmpeg, save as .gif;
# without chromium the browser test of the exported pages is skipped with that reason).
#
# Usage: scripts/system_deps.sh [--no-optional]      (or: sudo scripts/system_deps.sh)
set -u

REQUIRED="espeak-ng libegl1 libgl1-mesa-dri libosmesa6 chromium"
OPTIONAL="ffmpeg"
[ "${1:-}" = "--no-optional" ] && OPTIONAL=""

missing=""
for pkg in $REQUIRED $OPTIONAL; do
    if command -v dpkg >/dev/null 2>&1; then
        status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
        case "$status" in
            *"install ok installed"*) continue ;;
        esac
    elif [ "$pkg" = espeak-ng ] && command -v espeak-ng >/dev/null 2>&1; then
        continue
    elif [ "$pkg" = ffmpeg ] && command -v ffmpeg >/dev/null 2>&1; then
        continue
    elif [ "$pkg" = chromium ] && command -v chromium >/dev/null 2>&1; then
        continue
    fi
    missing="$missing $pkg"
done

if [ -z "$missing" ]; then
    echo "system_deps: all system packages present ($REQUIRED $OPTIONAL)"
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1 || ! command -v dpkg >/dev/null 2>&1; then
    echo "system_deps: not a Debian/Ubuntu system; please install the equivalents of:$missing"
    echo "system_deps: (macOS: 'brew install espeak-ng ffmpeg'; VTK renders natively there)"
    exit 0
fi

if [ "$(id -u)" != "0" ]; then
    echo "system_deps: missing packages:$missing"
    echo "system_deps: run: sudo apt-get install -y --no-install-recommends$missing"
    exit 0
fi

echo "system_deps: installing:$missing"
export DEBIAN_FRONTEND=noninteractive
if ! apt-get install -y --no-install-recommends $missing; then
    apt-get update && apt-get install -y --no-install-recommends $missing || {
        echo "system_deps: apt-get failed; install by hand:$missing"
        exit 0
    }
fi
exit 0
