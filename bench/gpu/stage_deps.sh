#!/bin/bash
# Stage .twin-deps/ for bench/gpu/run.sh on a GPU machine without Debian's
# packages (run here, on Debian 12): the twin's host libraries and headers
# (TBB, fmt, glm, toml++, nlohmann-json, CLI11, pcg) from the installed
# packages, the OptiX SDK headers (never committed: .twin-deps is ignored),
# and the commit the results belong to.
#   bash bench/gpu/stage_deps.sh <OptiX SDK include folder's parent> [OLD_COMMIT]
# With OLD_COMMIT, also that commit's source tree in .twin-deps/old (run.sh's
# identity step compares its GPU frames with this tree's).
set -euo pipefail
optix=${1:?usage: stage_deps.sh OPTIX_SDK_DIR (the folder holding include/optix.h)}
D=.twin-deps
rm -rf "$D" && mkdir -p "$D/sysroot"
for p in libtbb-dev libtbb12 libtbbmalloc2 libtbbbind-2-5 libfmt-dev libfmt9 libglm-dev libtomlplusplus-dev \
         libtomlplusplus3 nlohmann-json3-dev libcli11-dev libpcg-cpp-dev; do
    dpkg -L "$p" | while read -r f; do if [ -f "$f" ] || [ -L "$f" ]; then echo "$f"; fi; done
done | grep -v '/usr/share/doc\|/usr/share/lintian\|/usr/share/man' | tar cf - -T - 2>/dev/null | tar xf - -C "$D/sysroot"
mkdir -p "$D/optix" && cp -r "$optix/include" "$D/optix/"
git rev-parse --short=10 HEAD > "$D/commit"
if [ -n "${2:-}" ]; then
    mkdir -p "$D/old" && git archive "$2" CMakeLists.txt cmake include src scenes | tar xf - -C "$D/old"
    git rev-parse --short=10 "$2" > "$D/old.commit"
fi
du -sh "$D"
