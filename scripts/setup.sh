#!/usr/bin/env bash
# Installs what ademono needs on Debian 12, only what is missing, then configures and builds.
# Usage: scripts/setup.sh [--build-type Release|Debug|RelWithDebInfo] [--sanitize|--tsan|--fuzz]
#                         [--build-dir DIR] [--no-build] [--target T]
#   --sanitize: AddressSanitizer + UndefinedBehaviorSanitizer build (default dir build/asan)
#   --tsan:     ThreadSanitizer build of the threaded mapping tests only (default dir build/tsan),
#               instrumenting the modules that run on several threads (CI's list, below)
#   --tsan-all: the same with every module instrumented (default dir build/tsan-all)
#   --fuzz:     clang + libFuzzer targets of fuzz/ only (default dir build/fuzz; tools/fuzz.sh)
#   --target:   build only this target (repeatable)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_type=Release
build_dir=""
do_build=1
sanitize=OFF
tsan=OFF
# The modules whose code runs on more than one thread at once: the map and its users (slam),
# local BA (optimize), matching (feature), the keyframe database (place) and the pipeline's
# prefetch and detector threads (runner). docs/reliability.md says why the rest can stay plain.
tsan_modules="slam;runner;optimize;feature;place"
fuzz=OFF
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build-type) build_type="$2"; shift 2 ;;
    --build-dir) build_dir="$2"; shift 2 ;;
    --no-build) do_build=0; shift ;;
    --sanitize) sanitize=ON; shift ;;
    --tsan) tsan=ON; shift ;;
    --tsan-all) tsan=ON; tsan_modules=all; shift ;;
    --fuzz) fuzz=ON; shift ;;
    --target) targets+=(--target "$2"); shift 2 ;;
    *) echo "setup.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
if [ -z "$build_dir" ]; then
  if [ "$sanitize" = ON ]; then build_dir="$here/build/asan"
  elif [ "$tsan" = ON ] && [ "$tsan_modules" = all ]; then build_dir="$here/build/tsan-all"
  elif [ "$tsan" = ON ]; then build_dir="$here/build/tsan"
  elif [ "$fuzz" = ON ]; then build_dir="$here/build/fuzz"
  else build_dir="$here/build/$(echo "$build_type" | tr '[:upper:]' '[:lower:]')"; fi
fi

apt_packages=(
  build-essential cmake ninja-build pkg-config ccache
  libopencv-dev libeigen3-dev libceres-dev libyaml-cpp-dev libcli11-dev
  libspdlog-dev libfmt-dev nlohmann-json3-dev libcereal-dev zlib1g-dev libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-numpy python3-opencv python3-onnx python3-torch python3-pytest python3-open3d
  python3-dev pybind11-dev python3-matplotlib
  chromium
  libboost-dev
  clang libclang-rt-14-dev
)
missing=()
for p in "${apt_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm fetches ONNX Runtime; a machine may already have Node.js from elsewhere.
command -v npm >/dev/null || missing+=(npm)
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""; [ "$(id -u)" = 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# `ademono batch --engine slurm` (its CI test and scripts/slurm_local.sh): a one-node Slurm from
# Debian's packages. slurm_local.sh starts the daemons (and uses a munged that already runs).
slurm_missing=()
for p in slurm-wlm munge; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || slurm_missing+=("$p")
done
if [ ${#slurm_missing[@]} -gt 0 ]; then
  echo "setup: installing ${slurm_missing[*]}"
  sudo_cmd=""; [ "$(id -u)" = 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${slurm_missing[@]}"
fi

# ONNX Runtime 1.29 (CPU) from the npm registry into a project-local prefix.
ort_root="$here/.deps/onnxruntime"
if [ ! -f "$ort_root/lib/libonnxruntime.so.1" ] || [ ! -f "$ort_root/include/onnxruntime_cxx_api.h" ]; then
  echo "setup: fetching ONNX Runtime (npm com.github.asus4.onnxruntime@0.4.9)"
  tmp="$(mktemp -d)"
  trap 'rm -rf "$tmp"' EXIT
  (cd "$tmp" && npm pack --silent com.github.asus4.onnxruntime@0.4.9 >/dev/null)
  tar -xzf "$tmp"/com.github.asus4.onnxruntime-0.4.9.tgz -C "$tmp"
  hdr="$tmp/package/Plugins/iOS~/onnxruntime.xcframework/ios-arm64/onnxruntime.framework/Headers"
  rm -rf "$ort_root.partial" && mkdir -p "$ort_root.partial/include" "$ort_root.partial/lib"
  cp "$hdr"/*.h "$ort_root.partial/include/"
  cp "$tmp/package/Plugins/Linux/x64/libonnxruntime.so" "$ort_root.partial/lib/libonnxruntime.so.1"
  ln -sf libonnxruntime.so.1 "$ort_root.partial/lib/libonnxruntime.so"
  rm -rf "$ort_root" && mv "$ort_root.partial" "$ort_root"
fi

# The run report's JavaScript (uPlot for the 2D plots, regl for the WebGL map view), pinned, from
# the npm registry into .deps/web; CMake inlines the minified files into the binary.
web_root="$here/.deps/web"
web_missing=0
for f in uPlot.iife.min.js uPlot.min.css uPlot.LICENSE regl.min.js regl.LICENSE; do
  [ -f "$web_root/$f" ] || web_missing=1
done
if [ "$web_missing" = 1 ]; then
  echo "setup: fetching the report's JavaScript (npm uplot@1.6.32, regl@2.1.1)"
  web_tmp="$(mktemp -d)"
  (cd "$web_tmp" && npm pack --silent uplot@1.6.32 regl@2.1.1 >/dev/null)
  mkdir -p "$web_tmp/uplot" "$web_tmp/regl"
  tar -xzf "$web_tmp/uplot-1.6.32.tgz" -C "$web_tmp/uplot"
  tar -xzf "$web_tmp/regl-2.1.1.tgz" -C "$web_tmp/regl"
  rm -rf "$web_root.partial" && mkdir -p "$web_root.partial"
  cp "$web_tmp/uplot/package/dist/uPlot.iife.min.js" "$web_tmp/uplot/package/dist/uPlot.min.css" \
    "$web_tmp/uplot/package/LICENSE" "$web_root.partial/"
  mv "$web_root.partial/LICENSE" "$web_root.partial/uPlot.LICENSE"
  cp "$web_tmp/regl/package/dist/regl.min.js" "$web_root.partial/"
  cp "$web_tmp/regl/package/LICENSE" "$web_root.partial/regl.LICENSE"
  rm -rf "$web_tmp" "$web_root" && mv "$web_root.partial" "$web_root"
fi

# The live view (src/ademono/live): npm @foxglove/schemas, whose JSON schemas CMake compiles into
# the server, and the Node clients of its tests (@foxglove/ws-protocol, ws, ajv), pinned by
# tests/live/package-lock.json, into .deps/foxglove; the schemas are written out as
# .deps/foxglove/schemas/foxglove.NAME.json.
fg_root="$here/.deps/foxglove"
if ! cmp -s "$here/tests/live/package-lock.json" "$fg_root/package-lock.json" ||
   [ ! -f "$fg_root/schemas/foxglove.SceneUpdate.json" ]; then
  echo "setup: fetching the live view's npm packages (tests/live/package-lock.json)"
  rm -rf "$fg_root.partial" && mkdir -p "$fg_root.partial/schemas"
  cp "$here/tests/live/package.json" "$here/tests/live/package-lock.json" "$fg_root.partial/"
  (cd "$fg_root.partial" && npm ci --silent --no-audit --no-fund >/dev/null)
  (cd "$fg_root.partial" && node -e '
    const s = require("./node_modules/@foxglove/schemas/dist/jsonschema/index.js");
    for (const [name, schema] of Object.entries(s))
      require("fs").writeFileSync("schemas/foxglove." + name + ".json", JSON.stringify(schema));')
  rm -rf "$fg_root" && mv "$fg_root.partial" "$fg_root"
fi

if [ "$do_build" = 1 ]; then
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  extra=()
  # Timing a sanitized build means nothing: no benchmarks there.
  [ "$sanitize" = ON ] && extra=(-DADEMONO_BUILD_BENCHMARKS=OFF)
  if [ "$tsan" = ON ]; then
    extra=(-DADEMONO_TSAN=ON "-DADEMONO_TSAN_MODULES=$tsan_modules" -DADEMONO_BUILD_BENCHMARKS=OFF)
    [ ${#targets[@]} -gt 0 ] || targets=(--target test_threaded_mapping)
  fi
  if [ "$fuzz" = ON ]; then
    # libFuzzer comes with clang (libclang-rt-14-dev); -O2 -g for readable crash stacks.
    [ "$build_type" = Release ] && build_type=RelWithDebInfo
    extra=(-DCMAKE_CXX_COMPILER=clang++ -DADEMONO_FUZZ=ON
           -DADEMONO_BUILD_BENCHMARKS=OFF)
    [ ${#targets[@]} -gt 0 ] || targets=(--target fuzz_all)
  fi
  cmake -S "$here" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="$build_type" -DADEMONO_SANITIZE="$sanitize" \
    -DONNXRUNTIME_ROOT="$ort_root" "${launcher[@]}" "${extra[@]}" >/dev/null
  cmake --build "$build_dir" -j "$(nproc)" "${targets[@]}"
fi
