#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The README's commands, on a fresh Debian 12 machine:
#   ./run.sh report   set up, then run every paper case on every engine -> report/report.md
#   ./run.sh test     set up, then run the test suite
#   ./run.sh wheel-check  set up, then build the wheel and run it installed outside the repository
# Setup: Debian packages (when root; otherwise it says what to install), a Python
# virtual environment in .venv with the project installed, the LIGGGHTS plugin, and the LAMMPS
# plugin (with the LAMMPS headers it needs, taken from Debian's source package).
# STICKSLIP_SOURCE_BUILDS (a comma-separated list; .ci/run sets it) also builds engines from
# Debian's source packages, once, cached in build/ (a second set-up costs seconds):
#   lammps-2025      LAMMPS 4 Feb 2025 (Debian 13's source) with the tangential sub-model
#                    stick_slip compiled in: build/lammps_2025/build/lmp (~8 min on 2 cores)
#   lammps-2026      LAMMPS 4 Jul 2026 (Debian sid's source) with tools/lammps_patch.py's patch
#                    applied, LAMMPS' own granular and pair-style test programs, and LAMMPS'
#                    documentation packages (PyPI) for tools/lammps_docs.py:
#                    build/lammps_2026/build/lmp (~10 min on 2 cores)
#   lammps-2026-bigbig  the same tree built again with 64-bit atom and image ids
#                    (LAMMPS_SIZES=BIGBIG): build/lammps_2026/bigbig/lmp (~9 min)
#   liggghts-public  LIGGGHTS-PUBLIC 3.8.0 (Debian 12's source) with tangential stick_slip
#                    built in by `make auto`: build/liggghts_public/source/src/lmp_auto (~10 min)
set -euo pipefail
cd "$(dirname "$0")"

APT_PACKAGES="python3-venv python3-pip liggghts libliggghts-dev liggghts-doc libopenmpi-dev openmpi-bin g++ cmake yade python3-numpy lammps liblammps-dev lammps-examples"

setup_system() {
    local missing=()
    for p in $APT_PACKAGES; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    if [ "$(id -u)" -eq 0 ]; then
        echo "setup: installing Debian packages: ${missing[*]}"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
    else
        echo "setup: not root; please run: sudo apt-get install ${missing[*]}" >&2
        echo "setup: continuing; engines whose packages are missing will be skipped" >&2
    fi
}

setup_python() {
    # Install only when the environment is new or the project's dependencies changed
    # (pyproject.toml's hash is kept in .venv): a set-up that has nothing to do costs nothing.
    local stamp=.venv/.stickslip-pyproject.sha256
    local want
    want="$(sha256sum pyproject.toml | cut -d' ' -f1)"
    if [ ! -x .venv/bin/python ]; then
        python3 -m venv .venv
    fi
    if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ] || ! .venv/bin/python -c "import stickslip" 2>/dev/null; then
        .venv/bin/python -m pip install -q --upgrade pip >/dev/null
        .venv/bin/python -m pip install -q -e '.[test]'
        echo "$want" > "$stamp"
    fi
}

setup_plugin() {
    # The LIGGGHTS plugin builds in seconds against the installed headers; cmake rebuilds
    # only what changed, so a second set-up is a second or so.
    if [ -f liggghts_plugin/CMakeLists.txt ] && command -v liggghts >/dev/null 2>&1; then
        [ -f build/liggghts_plugin/CMakeCache.txt ] || \
            cmake -S liggghts_plugin -B build/liggghts_plugin -DCMAKE_BUILD_TYPE=Release >/dev/null
        cmake --build build/liggghts_plugin -j 2 >/dev/null
    fi
}

setup_lammps_headers() {
    # liblammps-dev ships only 36 core headers (and not the fmt/ headers they include), none of
    # GRANULAR's: the plugin takes the matching ones from Debian's own source package of the
    # installed version (80 MB, downloaded once into build/lammps_source/), extracting only
    # src/*.h, src/GRANULAR/*.h and src/fmt/* (~7 s). Nothing is built from it.
    local dir=build/lammps_headers cache=build/lammps_source version
    [ -f "$dir/.complete" ] && return 0
    command -v lmp >/dev/null 2>&1 || return 0
    version="$(dpkg-query -W -f='${source:Version}' liblammps-dev 2>/dev/null)" || return 0
    mkdir -p "$cache"
    if ! ls "$cache"/lammps_*.orig.tar.* >/dev/null 2>&1; then
        if ! apt-get source --print-uris "lammps=$version" >/dev/null 2>&1; then
            if [ "$(id -u)" -ne 0 ]; then
                echo "setup: no deb-src entry for lammps $version; as root add one (a copy of" \
                     "/etc/apt/sources.list.d/debian.sources with 'Types: deb-src'), apt-get update," \
                     "and run ./run.sh setup again; the LAMMPS plugin is skipped" >&2
                return 0
            fi
            echo "setup: adding a deb-src entry for Debian's sources (LAMMPS headers)"
            sed 's/^Types: deb$/Types: deb-src/' /etc/apt/sources.list.d/debian.sources \
                > /etc/apt/sources.list.d/stickslip-deb-src.sources
            apt-get update -qq
        fi
        # (as root apt would hand the download to its _apt user, which cannot write here)
        (cd "$cache" && apt-get source --download-only -qq -o APT::Sandbox::User=root "lammps=$version" >/dev/null)
    fi
    rm -rf "$dir" && mkdir -p "$dir"
    tar -xJf "$cache"/lammps_*.orig.tar.xz -C "$dir" --strip-components=1 --wildcards \
        --no-wildcards-match-slash '*/src/*.h' '*/src/GRANULAR/*.h' '*/src/fmt/*'
    echo "$version" > "$dir/.complete"
}

setup_lammps_plugin() {
    # The LAMMPS plugin: styles derived from Debian's GRANULAR classes, built against
    # /usr/lib's liblammps.so.0 (~25 s the first time on 2 cores; cmake rebuilds only what changed)
    [ -f lammps_plugin/CMakeLists.txt ] && command -v lmp >/dev/null 2>&1 || return 0
    setup_lammps_headers
    [ -f build/lammps_headers/.complete ] || return 0
    [ -f build/lammps_plugin/CMakeCache.txt ] || \
        cmake -S lammps_plugin -B build/lammps_plugin -DCMAKE_BUILD_TYPE=Release \
              -DLAMMPS_HEADERS="$PWD/build/lammps_headers/src" >/dev/null
    cmake --build build/lammps_plugin -j 2 >/dev/null
}

# The compiled YADE law's headers: YADE's own, from the oldest YADE source Debian serves (Debian
# 12's 2023.02a source does not download): suite, source version.
YADE_HEADERS_SOURCE="trixie:2025.2.0-1"

setup_yade_law() {
    # The compiled YADE law (yade_law/compiled/): a YADE plugin built against Debian's YADE
    # without rebuilding YADE. YADE's 2025.2.0 source (14 MB, downloaded once; only the headers
    # of core/, lib/ and pkg/ are kept, build/yade_source/), the plugin compiled with the
    # definitions read from the installed YADE (yade_flags.py), a private YADE prefix
    # (build/yade_law/prefix) and the launcher build/yade_law/yade-stickslip, which checks the
    # plugin against the installed YADE (layout_check.py) and starts YADE with it. ~2.5 min on 2
    # cores the first time; cmake rebuilds only what changed. Also a second plugin built for a
    # YADE without MPI (build/yade_law_wrong), which the layout check must refuse
    # (tests/test_yade_compiled.py), included in that time.
    command -v yade >/dev/null 2>&1 || return 0
    install_packages libeigen3-dev libboost-python-dev libboost-serialization-dev libboost-log-dev \
        libboost-thread-dev libcgal-dev python3-dev || return 0
    local top=build/yade_source suite version
    IFS=: read -r suite version <<< "$YADE_HEADERS_SOURCE"
    if [ ! -f "$top/src/.complete" ]; then
        echo "setup: YADE ${version%%-*}'s headers from Debian's source ($suite), for the compiled YADE law"
        fetch_debian_source "$suite" yade "$version" "$top/download"
        rm -rf "$top/src" && mkdir -p "$top/src"
        tar -xf "$top"/download/yade_*.orig.tar.* -C "$top/src" --strip-components=1 --wildcards \
            '*/RELEASE' '*/core/*.hpp' '*/lib/*.hpp' '*/lib/*.h' '*/lib/*.ipp' '*/pkg/*.hpp'
        echo "$version" > "$top/src/.complete"
    fi
    local build
    for build in yade_law yade_law_wrong; do
        local extra=()
        [ "$build" = yade_law_wrong ] && extra=(-D "YADE_FLAGS_ARGS=--without;MPI")
        [ -f "build/$build/CMakeCache.txt" ] || \
            cmake -S yade_law/compiled -B "build/$build" -DCMAKE_BUILD_TYPE=Release \
                  -DYADE_SOURCE="$PWD/$top/src" "${extra[@]}" >/dev/null
        cmake --build "build/$build" -j "$(nproc)" >/dev/null
    done
    # the verdict now (it is kept beside the plugin): one line if the plugin is refused
    python3 yade_law/compiled/layout_check.py build/yade_law/prefix || true
}

wants_source_build() {
    case ",${STICKSLIP_SOURCE_BUILDS:-}," in *",$1,"*) return 0 ;; *) return 1 ;; esac
}

fetch_debian_source() {
    # fetch_debian_source SUITE PACKAGE VERSION DIR: the source package's tarballs into DIR,
    # from Debian's registry, through a sources list of its own (the system's apt lists are
    # untouched). apt also asks for the .dsc, which the registry may not serve: the
    # tarballs are checked instead (apt verified their hashes against the suite's index).
    local suite=$1 package=$2 version=$3 dir=$4 apt="$4/apt"
    ls "$dir"/"${package}"_*.orig.tar.* >/dev/null 2>&1 && return 0
    mkdir -p "$apt/lists/partial" "$apt/cache/archives/partial"
    echo "deb-src [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] http://deb.debian.org/debian $suite main" \
        > "$apt/sources.list"
    local opts=(-o Dir::Etc::sourcelist="$PWD/$apt/sources.list" -o Dir::Etc::sourceparts=-
                -o Dir::State::Lists="$PWD/$apt/lists" -o Dir::Cache="$PWD/$apt/cache"
                -o APT::Sandbox::User="$(id -un)" -o Debug::NoLocking=1)
    apt-get "${opts[@]}" update -qq
    (cd "$dir" && apt-get "${opts[@]}" source --download-only -qq "$package=$version" >/dev/null 2>&1) || true
    if ! ls "$dir"/"${package}"_*.orig.tar.* >/dev/null 2>&1; then
        echo "setup: could not download Debian's $package $version source from $suite" >&2
        return 1
    fi
}

# The modern LAMMPS releases Debian carries, each built from its source package behind the
# switch (its word), the same minimal build: core + GRANULAR + PLUGIN, MPI (Debian 12's
# OpenMPI), shared library, with lammps_plugin/granular/ and the law's core copied into
# src/GRANULAR/ as a user would. word: Debian suite, source version, folder under build/.
LAMMPS_RELEASES="lammps-2025:trixie:20250204+dfsg.1-2:lammps_2025 lammps-2026:sid:20260704+dfsg-2:lammps_2026"

setup_lammps_release() {
    # setup_lammps_release WORD: the release's source (downloaded once: 132 MB for 2025, 214 MB
    # for 2026), extracted without what no build here reads; then cmake. 4 Feb 2025 takes
    # lammps_plugin/granular/ and law_core/stick_slip_core.h copied into src/GRANULAR/ as a
    # user would: sources whose copy changed are copied again and rebuilt (cmake
    # reconfigures: the sub-model registry is
    # generated at configure time). 4 Jul 2026 takes the sub-model as a pull request would, by
    # tools/lammps_patch.py's patch (patch_lammps_tree: with its documentation, example and
    # unit-test cases), and also builds LAMMPS' own granular and pair-style tests (unittest/,
    # ENABLE_TESTING) with Debian's googletest and libyaml (LAMMPS' CMake would download
    # googletest). Times on 2 cores, first build with the download: 2025 8 min; 2026 with its tests 10 min.
    local word=$1 entry suite version top src testing=0
    entry=$(tr ' ' '\n' <<< "$LAMMPS_RELEASES" | grep "^$word:") || return 1
    IFS=: read -r _ suite version top <<< "$entry"
    top=build/$top
    src=$top/source
    [ "$word" = lammps-2026 ] && testing=1
    if [ ! -f "$src/.complete" ]; then
        echo "setup: LAMMPS ${version%%+*} from Debian's source ($suite; first time: minutes on 2 cores)"
        fetch_debian_source "$suite" lammps "$version" "$top/download"
        rm -rf "$src" && mkdir -p "$src"
        if [ "$testing" = 1 ]; then
            # LAMMPS' tests read examples/plugins, examples/COUPLE, fortran/ and python/
            tar -xf "$top"/download/lammps_*.orig.tar.* -C "$src" --exclude=doc/html
        else
            tar -xf "$top"/download/lammps_*.orig.tar.* -C "$src" --exclude=examples --exclude=doc \
                --exclude=potentials --exclude=bench --exclude=tools --exclude=python --exclude=lib \
                --exclude=fortran --exclude=unittest
        fi
        # (2025's tarball has its files in one folder, 2026's at the top)
        if [ ! -d "$src/src" ]; then
            local inner=("$src"/*/)
            mv "${inner[0]}"* "$src"/ && rmdir "${inner[0]}"
        fi
        echo "$version" > "$src/.complete"
    fi
    local changed=0 f
    if [ "$testing" = 0 ]; then
        for f in lammps_plugin/granular/* law_core/stick_slip_core.h; do
            cmp -s "$f" "$src/src/GRANULAR/${f##*/}" || { cp "$f" "$src/src/GRANULAR/"; changed=1; }
        done
    else
        patch_lammps_tree "$top" && changed=1
    fi
    local options=()
    if [ "$testing" = 1 ]; then
        # Debian's googletest sources (package googletest) as the archive LAMMPS' CMake would
        # download: it takes a file already in _deps/ whose SHA-256 matches the one it is given
        install_packages googletest libyaml-dev
        mkdir -p "$top/build/_deps"
        local gtest="$top/build/_deps/googletest-debian.tar.gz"
        [ -f "$gtest" ] || tar -czf "$gtest" -C /usr/src googletest
        options=(-D ENABLE_TESTING=on -D "GTEST_URL=file://$PWD/$gtest"
                 -D "GTEST_SHA256=$(sha256sum "$gtest" | cut -d' ' -f1)")
    fi
    if [ ! -f "$top/build/CMakeCache.txt" ] || [ "$changed" = 1 ]; then
        cmake -S "$src/cmake" -B "$top/build" -C "$src/cmake/presets/all_off.cmake" -D PKG_GRANULAR=on \
              -D PKG_PLUGIN=on -D BUILD_MPI=on -D BUILD_SHARED_LIBS=on -D LAMMPS_EXCEPTIONS=on \
              -D BUILD_OMP=off -D CMAKE_BUILD_TYPE=Release "${options[@]}" >/dev/null
    fi
    cmake --build "$top/build" -j "$(nproc)" --target lmp >/dev/null
    if [ "$testing" = 1 ]; then
        # only the test programs the sub-model needs (all of LAMMPS' would take far longer)
        cmake --build "$top/build" -j "$(nproc)" --target $(lammps_test_programs) >/dev/null
    fi
}

patch_lammps_tree() {
    # patch_lammps_tree TOP: the sub-model enters 4 Jul 2026's tree as a pull request would:
    # tools/lammps_patch.py's patch (sources, documentation, example, unit-test cases), written
    # against pristine copies of the files it reads (TOP/pristine, kept from the source: those
    # it changes and those that show the tree's layout) and applied with patch(1); a changed
    # patch first takes the previous one out (the files it added removed, those it changed
    # restored), whatever was done to them since.
    # Returns 0 when the tree changed.
    local top=$1 src=$1/source f applied=$1/source/.stick_slip.patch
    [ -f "$applied" ] || rm -rf "$top/pristine"
    for f in $(.venv/bin/python tools/lammps_patch.py "$src" --reads); do
        [ -f "$top/pristine/$f" ] && continue
        if [ -f "$applied" ] && grep -q "^diff --git a/$f " "$applied"; then
            echo "setup: $top/pristine lacks $f, which the applied patch changed: remove $top/source and set up again" >&2
            exit 1
        fi
        mkdir -p "$top/pristine/$(dirname "$f")" && cp "$src/$f" "$top/pristine/$f"
    done
    .venv/bin/python tools/lammps_patch.py "$top/pristine" -o "$top/stick_slip.patch"
    cmp -s "$top/stick_slip.patch" "$applied" && return 1
    if [ -f "$applied" ]; then
        # the previous patch out: the files it added removed, those it changed from the pristine copies
        for f in $(sed -n '/^diff --git /{s/.* b\///;h};/^new file mode/{x;p}' "$applied"); do rm -f "$src/$f"; done
        (cd "$top/pristine" && find . -type f) | while read -r f; do cp "$top/pristine/$f" "$src/$f"; done
    fi
    patch -d "$src" -p1 -s --dry-run < "$top/stick_slip.patch" >/dev/null
    patch -d "$src" -p1 -s < "$top/stick_slip.patch" >/dev/null
    cp "$top/stick_slip.patch" "$applied"
    return 0
}

setup_lammps_docs() {
    # LAMMPS' documentation packages (its doc/utils/requirements.txt, from PyPI; the GitHub fork
    # of sphinx-fortran as PyPI's: tools/lammps_docs.py) and the spelling builder's enchant
    # library and dictionary, for tools/lammps_docs.py (~40 s the first time)
    local venv=build/lammps_docs/venv want
    install_packages libenchant-2-2 hunspell-en-us clang-format
    want=$(.venv/bin/python tools/lammps_docs.py build/lammps_2026/source --requirements | sha256sum | cut -d' ' -f1)
    [ -f "$venv/.requirements" ] && [ "$(cat "$venv/.requirements")" = "$want" ] && return 0
    [ -x "$venv/bin/python" ] || python3 -m venv "$venv"
    .venv/bin/python tools/lammps_docs.py build/lammps_2026/source --requirements > build/lammps_docs/requirements.txt
    "$venv/bin/python" -m pip install -q --retries 10 -r build/lammps_docs/requirements.txt
    echo "$want" > "$venv/.requirements"
}

lammps_test_programs() {
    # LAMMPS' granular tests (test_dem_01 ... test_dem_11) and the pair-style tester
    local n
    for n in 01 02 03 04 05 06 07 08 09 10 11; do printf 'test_dem_%s ' "$n"; done
    echo test_pair_style
}

install_packages() {
    # install_packages PACKAGE...: Debian packages a source build needs (as root), or say which
    local p missing=()
    for p in "$@"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    if [ "$(id -u)" -ne 0 ]; then
        echo "setup: please run: sudo apt-get install ${missing[*]}" >&2
        return 1
    fi
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
}

setup_lammps_bigbig() {
    # the patched 4 Jul 2026 tree again, built with LAMMPS' 64-bit sizes (lmp only)
    [ -f build/lammps_2026/bigbig/CMakeCache.txt ] || \
        cmake -S build/lammps_2026/source/cmake -B build/lammps_2026/bigbig \
              -C build/lammps_2026/source/cmake/presets/all_off.cmake -D PKG_GRANULAR=on -D BUILD_MPI=on \
              -D LAMMPS_SIZES=BIGBIG -D BUILD_OMP=off -D CMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build build/lammps_2026/bigbig -j "$(nproc)" --target lmp >/dev/null
}

setup_lammps_modern() {
    local entry word
    for entry in $LAMMPS_RELEASES; do
        word=${entry%%:*}
        if wants_source_build "$word"; then timed "$word" setup_lammps_release "$word"; fi
    done
    if wants_source_build lammps-2026-bigbig; then
        if ! wants_source_build lammps-2026; then timed lammps-2026 setup_lammps_release lammps-2026; fi
        timed lammps-2026-bigbig setup_lammps_bigbig
    fi
    if wants_source_build lammps-2026; then timed "LAMMPS' documentation packages" setup_lammps_docs; fi
    wants_source_build lammps-2025 || return 0
    # the legacy pair style gran/hooke/stickslip as a plugin of LAMMPS 2025 (`plugin load`;
    # lammps_plugin/lammps2025.cmake; ~10 s the first time on 2 cores, relinked when liblammps
    # changes)
    [ -f build/lammps_2025_plugin/CMakeCache.txt ] || \
        cmake -S lammps_plugin -B build/lammps_2025_plugin -DCMAKE_BUILD_TYPE=Release \
              -DLAMMPS_2025_DIR="$PWD/build/lammps_2025" >/dev/null
    cmake --build build/lammps_2025_plugin -j "$(nproc)" >/dev/null
}

wheel_check() {
    # Install without a clone: the sdist and wheel of `python -m build`, the wheel installed into
    # a new virtual environment outside the repository, and pyref, calibrate and the YADE law
    # run from it (tests/test_wheel.py: ~1 min on 2 cores, so ./run.sh test leaves it out)
    .venv/bin/python -m pytest -q --runslow tests/test_wheel.py "$@"
}

setup_liggghts_public() {
    # LIGGGHTS-PUBLIC 3.8.0 from Debian 12's source (6.5 MB, downloaded once), built as its users
    # build it: liggghts_plugin/tangential_model_stick_slip.h and the law's core
    # (law_core/stick_slip_core.h) copied into src/ and LIGGGHTS' own
    # `make auto` (MPI with Debian 12's OpenMPI; VTK, JPG and superquadrics off, as none is needed
    # and Debian's library has no superquadrics), with stick_slip compiled in for the 40
    # combinations LIGGGHTS compiles for tangential history (src/style_contact_model_user.whitelist).
    # Executable: build/liggghts_public/source/src/lmp_auto; 9.5 min on 2 cores with the
    # download, once. A changed header is copied again and make rebuilds what includes them (1.5 min);
    # unchanged, a set-up costs nothing here. The source predates GNU make 4.3 and GCC 11: the
    # four fixes below and MPI_LIB_USR in Makefile.user let Debian 12 build it.
    wants_source_build liggghts-public || return 0
    local top=build/liggghts_public version=3.8.0+repack1-9 src header=tangential_model_stick_slip.h
    local core=law_core/stick_slip_core.h
    src=$top/source/src
    if [ ! -f "$top/source/.complete" ]; then
        echo "setup: LIGGGHTS-PUBLIC 3.8.0 from Debian 12's source (first time: ~5 min on 2 cores)"
        fetch_debian_source bookworm liggghts "$version" "$top/download"
        rm -rf "$top/source" && mkdir -p "$top/source"
        tar -xJf "$top"/download/liggghts_*.orig.tar.xz -C "$top/source" --strip-components=1 \
            --exclude='*/doc' --exclude='*/examples'
        # GNU make >= 4.3 keeps the backslash of \# inside $(shell ...): Makefile.auto's probe
        # programs would start with \#include (and OpenMPI be taken for MPICH)
        sed -i 's/\\#/#/g' "$src/MAKE/Makefile.auto"
        # GCC >= 11: a temporary stream cast to a reference; a pointer compared with 0 by >
        sed -i 's/return static_cast< std::ostringstream & >(( std::ostringstream() << std::dec << a ) ).str();/std::ostringstream s; s << a; return s.str();/' "$src/utils.h"
        sed -i 's/numneigh > 0) {/numneigh != NULL) {/' "$src/finish.cpp"
        # the one VTK source without the LAMMPS_VTK guard of its siblings (else VTK is required)
        for f in dump_mesh_vtk.h dump_mesh_vtk.cpp; do
            { echo '#ifdef LAMMPS_VTK'; cat "$src/$f"; echo '#endif'; } > "$src/$f.new" && mv "$src/$f.new" "$src/$f"
        done
        # Makefile.user as `make auto` would write it, with the options above; OpenMPI's library
        # folder given (without any -L, Makefile.auto links with an empty -Wl, that ld refuses)
        tail -n +11 "$src/MAKE/Makefile.user_default" | sed -e 's/^USE_VTK = "ON"/USE_VTK = "OFF"/' \
            -e 's/^USE_SUPERQUADRICS = "ON"/USE_SUPERQUADRICS = "OFF"/' \
            -e "s|^#MPI_LIB_USR=.*|MPI_LIB_USR=$(mpicxx --showme:libdirs)|" > "$src/MAKE/Makefile.user"
        cp "liggghts_plugin/$header" "$core" "$src/"
        (cd "$src" && bash Make.sh models >/dev/null)
        sed -n 's/TANGENTIAL_HISTORY/TANGENTIAL_STICK_SLIP/p' "$src/style_contact_model.whitelist" \
            > "$src/style_contact_model_user.whitelist"
        echo "$version" > "$top/source/.complete"
    fi
    local f
    for f in "liggghts_plugin/$header" "$core"; do
        cmp -s "$f" "$src/${f##*/}" || { cp "$f" "$src/"; rm -f "$src/lmp_auto"; }
    done
    [ -x "$src/lmp_auto" ] && return 0
    (cd "$src" && make auto -j "$(nproc)" >../../make.log 2>&1) || {
        echo "setup: LIGGGHTS' make auto failed (build/liggghts_public/make.log):" >&2
        grep -m 5 -E 'error:|\*\*\*' "$top/make.log" >&2
        return 1
    }
}

timed() {
    # timed NAME COMMAND...: run the command; a set-up step that took 20 s or more says how long
    local t0=$SECONDS name=$1
    shift
    "$@"  # (called as a plain command, so that set -e stops the set-up at the step's first failure)
    local dt=$((SECONDS - t0))
    [ "$dt" -lt 20 ] || echo "setup: $name took $((dt / 60)) min $((dt % 60)) s"
}

setup() {
    setup_system
    setup_python
    setup_plugin
    setup_lammps_plugin
    timed "the compiled YADE law" setup_yade_law
    setup_lammps_modern
    timed liggghts-public setup_liggghts_public
}

case "${1:-}" in
    report)
        setup
        shift
        .venv/bin/stickslip report "$@"
        ;;
    test)
        setup
        shift
        # pytest-xdist workers, two per core and at most 16 (STICKSLIP_TEST_JOBS=N: N workers, 0:
        # this process): many tests wait on engine processes (MPI start-up, YADE's import, a
        # shared run another worker is making), and a second worker per core fills those waits
        # (docs/testing.md, History: 2 workers 340-376 s, 3 312 s, 4 292-308 s on 2 cores); past
        # 16 the longest test (~45 s) sets the time, and each worker costs memory. Tests are
        # independent, and the runs several tests read are made once (tests/conftest.py).
        workers=$((2 * $(nproc)))
        [ "$workers" -gt 16 ] && workers=16
        .venv/bin/python -m pytest -q -n "${STICKSLIP_TEST_JOBS:-$workers}" --dist worksteal "$@"
        ;;
    wheel-check)
        setup
        shift
        wheel_check "$@"
        ;;
    setup)
        setup
        ;;
    *)
        echo "usage: ./run.sh report|test|wheel-check|setup [extra arguments]" >&2
        exit 2
        ;;
esac
