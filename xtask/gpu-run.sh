#!/usr/bin/env bash
# The real-GPU check, run from the repository root on a machine with a GPU and no Rust toolchain
# (the `device` tool's machine): the cross-check test binaries and the host's benchmarks that
# `cargo xtask gpu-bundle` packed into .gpu-bundle/. Writes to $OUT (default out/gpu-run):
# run.log (machine, adapter, every test's output, every benchmark's output) and reports.tar.gz
# (reports/: kernel rates, SSR per-pass times at 1920x1080, render, energy and storage benchmarks,
# each .md + .json). Exits non-zero if a test failed.
#
#   device run, carry [".gpu-bundle", ".gl"]:  bash .gpu-bundle/run.sh
#
# GPU_RUN_ADAPTER=<substring> picks the Vulkan adapter (default: the runner's choice, a discrete
# GPU first); GPU_RUN_QUICK=1 skips the benchmarks (tests only); GPU_RUN_TEST_TIMEOUT (seconds,
# default 120) bounds each test file's run; GPU_RUN_BUDGET (seconds, default none) is the time the
# whole script may take: every step's limit is cut to what is left of it (less 10 s to pack), and
# a step that would get under 15 s is skipped and reported as such, so a device call's limit ends
# the script cleanly with every report so far packed. GPU_RUN_FILES="a b ..." runs only these test
# files, in this order (default: every file, the diagnostic ones first).
set -u
here=$(cd "$(dirname "$0")" && pwd)
OUT=${OUT:-out/gpu-run}
mkdir -p "$OUT"
log="$OUT/run.log"
: >"$log"
say() { echo "$*" | tee -a "$log"; }
start=$(date +%s)
# room SECONDS LABEL: sets secs to SECONDS, or to what is left of GPU_RUN_BUDGET (less 10 s to
# pack) if that is less; under 15 s it logs LABEL as skipped and fails.
room() {
    secs=$1
    if [ -n "${GPU_RUN_BUDGET:-}" ]; then
        local left=$(( GPU_RUN_BUDGET - ($(date +%s) - start) - 10 ))
        [ "$left" -lt "$secs" ] && secs=$left
    fi
    [ "$secs" -ge 15 ] && return 0
    say "== $2: SKIPPED, GPU_RUN_BUDGET spent"
    return 1
}

# The Vulkan loader: the device machine starts bare (see the device tool's README for .gl/).
if [ -d .gl ]; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
if ! ldconfig -p | grep -q libvulkan.so.1; then
    say "no Vulkan loader (libvulkan.so.1): bring one (.gl/) or install libvulkan1"
    exit 2
fi
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$nv" ] && ! ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; then
    export VK_DRIVER_FILES=$nv
fi
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/xdg-runtime}
mkdir -p "$XDG_RUNTIME_DIR"
[ -n "${GPU_RUN_ADAPTER:-}" ] && export HOST_ADAPTER=$GPU_RUN_ADAPTER

# The tests read the repository's scenes through the path baked in at build time.
. "$here/baked.env"
mkdir -p "$BAKED_ROOT/tests" "$BAKED_ROOT/scenes"
[ -d "$BAKED_ROOT/scenes/cornell_box" ] || cp -r "$here/scenes/cornell_box" "$BAKED_ROOT/scenes/"

bin=/tmp/gpu-bundle-bin
mkdir -p "$bin"
for f in "$here"/bin/*.xz; do
    xz -dc "$f" >"$bin/$(basename "$f" .xz)" && chmod +x "$bin/$(basename "$f" .xz)"
done

say "== machine: $(uname -m), $(nproc) cores, $(uptime)"
command -v nvidia-smi >/dev/null && nvidia-smi -L 2>&1 | tee -a "$log"
say "== bundle: $(cat "$here/commit")"
"$bin/host" info 2>&1 | tee -a "$log"

failed=0
# The reports are written outside $OUT and packed into $OUT/reports.tar.gz after each step, so
# what a step that ran out of time left behind still comes back (the device tool returns at most
# 8 files from $OUT).
work=/tmp/gpu-run
rep="$work/reports"
rm -rf "$rep"
mkdir -p "$rep"
pack() { tar -czf "$OUT/reports.tar.gz.tmp" -C "$work" reports && mv "$OUT/reports.tar.gz.tmp" "$OUT/reports.tar.gz"; }
# One run per test file (the combined binary's tests are named `file::test`), each under its own
# timeout, so a slow file cannot hide the others' failure details (libtest prints them at the
# end of a run). The files that diagnose a driver come first.
first="foundation math_crosscheck div_sqrt_probe eval_registry"
for t in "$bin"/test-*; do
    name=$(basename "$t")
    files=$("$t" --list 2>/dev/null | sed -n 's/^\([a-z0-9_]*\)::.*: test$/\1/p' | sort -u)
    [ -n "${GPU_RUN_FILES:-}" ] && first=$GPU_RUN_FILES && files=$(tr ' ' '\n' <<<"$GPU_RUN_FILES")
    ordered=$(for f in $first; do echo "$files" | grep -qx "$f" && echo "$f"; done; echo "$files" | grep -vxF -f <(tr ' ' '\n' <<<"$first"))
    for f in ${ordered:-"-"}; do
        filter=()
        [ "$f" != "-" ] && filter=("$f::")
        room "${GPU_RUN_TEST_TIMEOUT:-120}" "$name ${filter[*]:-(all)}" || { failed=1; continue; }
        say "== $name ${filter[*]:-(all)} (CI=true: a comparison that cannot run fails; limit $secs s)"
        t0=$(date +%s)
        CI=true timeout "$secs" "$t" "${filter[@]}" 2>&1 | tee -a "$log"
        rc=${PIPESTATUS[0]}
        say "== $name ${filter[*]:-(all)}: exit $rc in $(( $(date +%s) - t0 )) s"
        [ "$rc" -eq 0 ] || failed=1
    done
done

# The native build (driver OpFDiv/Sqrt) on this GPU, reported, not counted: HOST_DIV_SQRT=auto
# loads it only on drivers known to round them correctly, so the tests above ran the exact build
# here unless the driver is one of those; `host info` above printed the native build's probe.
for t in "$bin"/test-*; do
    say "== $(basename "$t") foundation + math_crosscheck with HOST_DIV_SQRT=native (informational: does the driver's division match the CPU's bits?)"
    for filter in foundation:: math_crosscheck::; do
        room 120 "$filter native" || continue
        HOST_DIV_SQRT=native CI=true timeout "$secs" "$t" "$filter" 2>&1 | tee -a "$log"
        say "== $filter native: exit ${PIPESTATUS[0]} (not counted)"
    done
done

step() { # step NAME SECONDS host-arguments...: one benchmark, its time, its exit status
    local name=$1 secs
    room "$2" "$name" || return 0
    shift 2
    say "== $name (limit $secs s): host $*"
    local t0
    t0=$(date +%s)
    timeout "$secs" "$bin/host" "$@" 2>&1 | tee -a "$log"
    say "== $name: exit ${PIPESTATUS[0]} in $(( $(date +%s) - t0 )) s"
    pack
}
if [ "${GPU_RUN_QUICK:-0}" != 1 ]; then
    # The kernel rates and the path tracer first: on a real GPU their pipelines take longest to
    # create (the exact build's), so a short budget should not leave them last.
    step "bench kernels" 200 bench kernels --device gpu --rows 1048576 --repeats 3 --output "$rep/kernel-rates.md"
    step "bench render" 120 bench render --device gpu --report "$rep/render-bench.md"
    step "bench ssr-passes 1920x1080" 150 bench ssr-passes --devices gpu,cpu --rounds 3 \
        --config "--scene floor --pipeline sssr" --config "--scene floor --pipeline hdrp" \
        --config "--scene floor --pipeline hdrp --resolve 3x3" --config "--scene floor --pipeline sssr --no-fis" \
        --report "$rep/ssr-passes-1080p.md"
    step "bench energy" 90 bench energy --device gpu --report "$rep/energy-bench.md"
    step "bench storage" 60 bench storage --repeats 5 --output "$rep/storage-bench.md"
fi
pack
say "== done in $(( $(date +%s) - start )) s: tests $([ $failed -eq 0 ] && echo passed || echo FAILED)"
exit $failed
