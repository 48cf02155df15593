#!/usr/bin/env bash
# Download, here, the wheels that bench/gpu_session.sh installs on the GPU machine (its python3 3.12 has torch,
# numpy, scipy, scikit-learn, numba and msgpack, but not librosa and these): into .whl/, which git ignores.
set -eu
grep -qx '/.whl/' .git/info/exclude 2>/dev/null || echo '/.whl/' >> .git/info/exclude
platforms=""
for p in manylinux_2_28_x86_64 manylinux_2_27_x86_64 manylinux_2_17_x86_64 manylinux2014_x86_64 manylinux1_x86_64; do
    platforms="$platforms --platform $p"
done
for w in librosa==0.11.0 soundfile==0.14.0 soxr==1.1.0 audioread==3.1.0 pooch==1.9.0 cffi==2.1.1 pycparser==3.12 \
         platformdirs==4.14.8 decorator==5.3.1; do
    python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
        $platforms -d .whl "$w"
done
ls -l .whl
