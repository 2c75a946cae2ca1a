#!/usr/bin/env bash
# Sustained capture rate of igi-capture against the peer arv-camera-test-0.8 (Aravis's own
# streaming test, which receives frames and throws them away), on the same fake GigE Vision
# camera (arv-fake-gv-camera-0.8) at its highest frame rate (1000 Hz requested), run side by
# side on this machine. igi-capture writes every frame (16-bit TIFF, --no-fsync) and its
# manifest line; a run counts only with zero lost frames (exit 0 and no frame_id gaps).
#
# Usage: bench/capture/run_capture_bench.sh [BUILD_DIR] [SECONDS]
# Prints a Markdown table with frames/s of both and the ratio igi-capture / peer.
set -euo pipefail

build_dir=${1:-build}
seconds=${2:-5}
capture="$(cd "$build_dir" && pwd)/bin/igi-capture"
work=$(mktemp -d /tmp/igi_capture_bench.XXXXXX)

# A private network namespace keeps this run's fake camera away from anyone else's.
if [[ -z "${IGI_BENCH_IN_NETNS:-}" ]] && unshare -rn true 2>/dev/null; then
  export IGI_BENCH_IN_NETNS=1
  exec unshare -rn "$0" "$@"
fi
[[ -n "${IGI_BENCH_IN_NETNS:-}" ]] && ip link set lo up

fake_pid=""
cleanup() {
  [[ -n "$fake_pid" ]] && kill "$fake_pid" 2>/dev/null && wait "$fake_pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

start_fake() {
  arv-fake-gv-camera-0.8 -i 127.0.0.1 -s BENCH >"$work/fake.log" 2>&1 &
  fake_pid=$!
  for _ in $(seq 50); do grep -q ':0F74 ' /proc/self/net/udp && return 0; sleep 0.1; done
  echo "fake camera did not start" >&2; exit 1
}
stop_fake() { kill "$fake_pid"; wait "$fake_pid" 2>/dev/null || true; fake_pid=""; }

echo "| frame | peer arv-camera-test-0.8 frames/s | peer lost | igi-capture frames/s | igi lost (skipped/failed) | igi exit | ratio igi/peer |"
echo "|---|---|---|---|---|---|---|"
for size in 512 256 128; do
  start_fake
  peer_log="$work/peer_$size.log"
  timeout $((seconds + 20)) arv-camera-test-0.8 -n 127.0.0.1 -f 1000 -w "$size" -h "$size" \
    --duration="$seconds" >"$peer_log" 2>&1 || true
  completed=$(grep -m1 'n_completed_buffers' "$peer_log" | awk '{print $NF}')
  peer_lost=$(awk '/n_missing_frames|n_failures|n_underruns/ {s += $NF} END {print s + 0}' "$peer_log")
  peer_fps=$(awk -v n="$completed" -v s="$seconds" 'BEGIN {printf "%.1f", n / s}')
  stop_fake

  start_fake
  frames=$(awk -v f="$peer_fps" -v s="$seconds" 'BEGIN {printf "%d", f * s}')
  rm -rf "$work/out"
  set +e
  "$capture" --camera 127.0.0.1 --out "$work/out" --exposures-us 10000 --frames "$frames" \
    --frame-rate 1000 --width "$size" --height "$size" --pixel-format Mono8 --format tiff \
    --no-fsync --settle-frames 0 --quiet >"$work/igi.log" 2>&1
  code=$?
  set -e
  stop_fake
  igi_fps=$(grep -o '[0-9.]* frames/s' "$work/igi.log" | awk '{print $1}')
  skipped=$(grep -o '[0-9]* frames skipped' "$work/igi.log" | awk '{print $1}')
  failed=$([[ $code == 0 ]] && echo 0 || echo 1)
  ratio=$(awk -v a="${igi_fps:-0}" -v b="$peer_fps" 'BEGIN {printf "%.2f", a / b}')
  echo "| ${size}x${size} Mono8 | $peer_fps | $peer_lost | ${igi_fps:-?} | ${skipped:-?}/$failed | $code | $ratio |"
  [[ $code == 0 ]] || sed 's/^/    /' "$work/igi.log" >&2
done
