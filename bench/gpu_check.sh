#!/usr/bin/env bash
# The rasterizer's GPU check: partsim's render, shadow and dataset benchmarks on a lent GPU
# machine, within one 10-minute command of a 15-minute device budget.
#
# The GPU machine has neither partsim's build nor its Debian libraries, and reaches no package
# registry. So the check runs in two steps:
#
#   bash bench/gpu_check.sh pack [DIR]     here, on the build machine (default DIR: .gpu/render)
#       builds partsim_render_bench and partsim_vision_dataset_bench, copies them to DIR/bin and
#       the shared libraries they load that are not the C library, the C++ runtime or OpenGL's
#       (MuJoCo, assimp, Embree, ...) into DIR/lib.tar.xz, and downloads Debian's GL dispatch
#       packages (libEGL, libOpenGL, libglvnd: the NVIDIA driver supplies the rest) to DIR/gl.
#       DIR must be a folder git ignores (`echo /.gpu/ >> .git/info/exclude`); it travels with
#       the device tool's `carry` (about 25 MB).
#
#   bash bench/gpu_check.sh run [DIR] [--quick]     on the GPU machine (or here, to try it)
#       installs the GL packages (as root; skipped where libEGL is already there), unpacks the
#       libraries into a temporary folder, then runs, each under its own time limit:
#         1. partsim_render_bench --reps 3                 (partsim against the bare program)
#         2. partsim_render_bench --shadows --reps 3       (the sun casting shadows)
#         3. partsim_render_bench --shadow-modes --reps 3  (maps redrawn, kept, sized, moving)
#         4. partsim_render_bench --batch --reps 3         (the context kept current, or not)
#         5. partsim_render_bench --camera-set --reps 3    (4 cameras: Render each, RenderMany)
#         6. partsim_vision_dataset_bench --reps 1 --seconds 1 --jobs 1,4,8,16 (and the phases)
#       Each writes its output to $OUT (the device tool's folder; ./gpu-check-out elsewhere), and
#       summary.md collects the tables with the machine's name. --quick runs each with the
#       smallest settings (a minute on the build VM's llvmpipe), to check the script.
#
# The device tool's call, from the repository root (timeout_s 600; about 6-8 minutes expected on
# an H100/H200, not yet run there):
#   run(command="bash bench/gpu_check.sh run .gpu/render", carry=[".gpu/render"], timeout_s=600)
set -euo pipefail
cd "$(dirname "$0")/.."

mode="${1:-}"
dir=.gpu/render
quick=0
for a in "${@:2}"; do
  if [ "$a" = "--quick" ]; then quick=1; else dir=$a; fi
done

BENCHES=(partsim_render_bench partsim_vision_dataset_bench)
# libraries the GPU machine has (its own C library and C++ runtime) or must not take from here
# (OpenGL's dispatch and EGL come from the NVIDIA driver and the gl/ packages)
SYSTEM_LIBS='^(linux-vdso|ld-linux|libc\.|libm\.|libdl\.|librt\.|libpthread\.|libgcc_s\.|libstdc\+\+\.|libEGL\.|libGL|libOpenGL\.|libGLdispatch\.|libGLX\.)'

pack() {
  mkdir -p "$dir/bin" "$dir/gl"
  cmake --build build -j"${PARTSIM_JOBS:-2}" --target "${BENCHES[@]}"
  libs=$(mktemp -d)
  for b in "${BENCHES[@]}"; do
    cp "build/bench/$b" "$dir/bin/"
    ldd "build/bench/$b" | awk '/=> \//{print $1, $3}' | while read -r name path; do
      if ! [[ "$name" =~ $SYSTEM_LIBS ]]; then cp -L "$path" "$libs/$name"; fi
    done
  done
  tar -C "$libs" -cJf "$dir/lib.tar.xz" .
  rm -rf "$libs"
  (cd "$dir/gl" && rm -f ./*.deb &&
    apt-get download libegl1 libopengl0 libglvnd0 libgl1 libglx0 libgles2 >/dev/null)
  git rev-parse --short HEAD > "$dir/commit" 2>/dev/null || true
  echo "packed $(du -sh "$dir" | cut -f1) into $dir: $(ls "$dir/bin" | tr '\n' ' ')"
  echo "libraries: $(tar -tJf "$dir/lib.tar.xz" | grep -c '\.so') in lib.tar.xz; GL packages: $(ls "$dir/gl" | wc -l)"
}

run() {
  [ -d "$dir/bin" ] || { echo "gpu_check: no $dir/bin (run 'bash bench/gpu_check.sh pack' first)" >&2; exit 2; }
  out="${OUT:-gpu-check-out}"
  mkdir -p "$out"
  # OpenGL's dispatch libraries, where the machine has none (the device's README recipe)
  if ! ldconfig -p | grep -q 'libEGL\.so\.1 '; then
    if [ "$(id -u)" -eq 0 ]; then
      for f in "$dir"/gl/*.deb; do dpkg -x "$f" /; done
      ldconfig
    else
      echo "gpu_check: libEGL is missing and this is not root: the rasterizer will not start" >&2
    fi
  fi
  if [ -d /usr/local/nvidia/share/glvnd/egl_vendor.d ]; then
    export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
  fi
  libs=$(mktemp -d)
  tar -C "$libs" -xJf "$dir/lib.tar.xz"
  export LD_LIBRARY_PATH="$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  for b in "${BENCHES[@]}"; do
    if ldd "$dir/bin/$b" | grep -q 'not found'; then
      echo "gpu_check: $b misses libraries:" >&2
      ldd "$dir/bin/$b" | grep 'not found' >&2
      exit 1
    fi
  done
  machine="$(nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>/dev/null || true)"
  [ -n "$machine" ] || machine="no NVIDIA GPU seen"
  {
    echo "# partsim GPU check, $(date -u +%Y-%m-%dT%H:%MZ)"
    echo
    echo "- machine: $machine; $(nproc) cores; $(uname -m)"
    echo "- partsim commit: $(cat "$dir/commit" 2>/dev/null || echo unknown)"
  } > "$out/summary.md"

  if [ "$quick" = 1 ]; then
    reps=(--reps 1 --seconds 0.05)
    dataset=(--objects 2 --views 2 --size 64 --reps 1 --seconds 0.1 --jobs 1,2)
  else
    reps=(--reps 3 --seconds 0.5)
    dataset=(--reps 1 --seconds 1 --jobs 1,4,8,16)
  fi
  status=0
  step() {  # name, limit in seconds, command...
    local name=$1 limit=$2
    shift 2
    echo "== $name: $*"
    local t0=$SECONDS rc=0
    timeout "$limit" "$@" > "$out/$name.txt" 2>&1 || rc=$?
    cat "$out/$name.txt"
    {
      echo
      echo "## $name ($((SECONDS - t0)) s, exit $rc)"
      echo
      echo '```'
      grep -v '^rep [0-9]' "$out/$name.txt" | tail -40
      echo '```'
    } >> "$out/summary.md"
    [ "$rc" -eq 0 ] || status=1
  }
  step render 120 "$dir/bin/partsim_render_bench" "${reps[@]}"
  step shadows 120 "$dir/bin/partsim_render_bench" --shadows "${reps[@]}"
  step shadow_modes 120 "$dir/bin/partsim_render_bench" --shadow-modes "${reps[@]}"
  step batch 75 "$dir/bin/partsim_render_bench" --batch "${reps[@]}"
  step camera_set 75 "$dir/bin/partsim_render_bench" --camera-set "${reps[@]}"
  step dataset 240 "$dir/bin/partsim_vision_dataset_bench" "${dataset[@]}"
  rm -rf "$libs"
  echo "wrote $out/summary.md"
  exit "$status"
}

case "$mode" in
  pack) pack ;;
  run) run ;;
  *)
    echo "usage: bash bench/gpu_check.sh pack [DIR] | run [DIR] [--quick]" >&2
    exit 2
    ;;
esac
