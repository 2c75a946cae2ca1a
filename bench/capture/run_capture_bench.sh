#!/usr/bin/env bash
# Sustained capture rate of igi-capture against the peer arv-camera-test-0.8 (Aravis's own
# streaming test, which receives frames and throws them away), on the same fake GigE Vision
# camera (arv-fake-gv-camera-0.8) at its highest frame rate (1000 Hz requested), run side by
# side on this machine. igi-capture writes every frame (16-bit TIFF, --no-fsync) and its
# manifest line (2 writer threads). A run counts only with zero lost frames: exit 0, no frame_id
# gaps, no Aravis underruns or failed frames, every frame listed in the manifest and on disk.
# The peer runs before and after igi-capture (the load of a shared machine drifts); its rate is
# the mean of the two, and igi-capture takes as many frames as the first peer run received.
#
# Usage: bench/capture/run_capture_bench.sh [BUILD_DIR] [SECONDS] [SIZES]   (SIZES: "512 256 128")
# Prints a Markdown table with frames/s of both and the ratio igi-capture / peer.
set -euo pipefail

build_dir=${1:-build}
seconds=${2:-5}
sizes=${3:-512 256 128}
capture="$(cd "$build_dir" && pwd)/bin/igi-capture"

# A private network namespace keeps this run's fake camera away from anyone else's.
if [[ -z "${IGI_BENCH_IN_NETNS:-}" ]] && unshare -rn true 2>/dev/null; then
  export IGI_BENCH_IN_NETNS=1
  exec unshare -rn "$0" "$@"
fi
[[ -n "${IGI_BENCH_IN_NETNS:-}" ]] && ip link set lo up

# Where the frames go: IGI_BENCH_DIR (default /tmp). Choose the disk a capture would use; on
# ext4 a folder where thousands of files were just deleted creates files about half as fast
# (the allocator skips recently freed inodes for a few minutes).
work=$(mktemp -d "${IGI_BENCH_DIR:-/tmp}/igi_capture_bench.XXXXXX")

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

# One peer run; prints "FRAMES_PER_S LOST".
run_peer() {
  local size=$1 log="$work/peer_$1.log"
  start_fake
  timeout $((seconds + 20)) arv-camera-test-0.8 -n 127.0.0.1 -f 1000 -w "$size" -h "$size" \
    --duration="$seconds" >"$log" 2>&1 || true
  stop_fake
  local completed lost
  completed=$(grep -m1 'n_completed_buffers' "$log" | awk '{print $NF}')
  lost=$(awk '/n_missing_frames|n_failures|n_underruns/ {s += $NF} END {print s + 0}' "$log")
  awk -v n="${completed:-0}" -v s="$seconds" -v l="$lost" 'BEGIN {printf "%.1f %d\n", n / s, l}'
}

echo "frames written under $work; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "| frame | peer frames/s (before, after) | peer lost | igi-capture frames/s | igi lost (gaps/underruns/failed) | igi exit | frames listed and on disk | ratio igi/peer |"
echo "|---|---|---|---|---|---|---|---|"
for size in $sizes; do
  # The peer runs before and after igi-capture and the two are averaged: on a
  # shared machine the load drifts during a run.
  read -r peer_a lost_a < <(run_peer "$size")
  frames=$(awk -v f="$peer_a" -v s="$seconds" 'BEGIN {printf "%d", f * s}')
  start_fake
  # A folder per size, all removed at the end: deleting thousands of files between runs would
  # slow the next run's file creation (ext4 skips recently freed inodes).
  out="$work/out_$size"
  set +e
  "$capture" --camera 127.0.0.1 --out "$out" --exposures-us 10000 --frames "$frames" \
    --frame-rate 1000 --width "$size" --height "$size" --pixel-format Mono8 --format tiff \
    --no-fsync --settle-frames 0 --quiet >"$work/igi.log" 2>&1
  code=$?
  set -e
  stop_fake
  read -r peer_b lost_b < <(run_peer "$size")
  peer_fps=$(awk -v a="$peer_a" -v b="$peer_b" 'BEGIN {printf "%.1f", (a + b) / 2}')
  igi_fps=$(grep -o '[0-9.]* frames/s' "$work/igi.log" | awk '{print $1}')
  gaps=$(grep -o '[0-9]* frames skipped' "$work/igi.log" | awk '{print $1}')
  underruns=$(grep -o '[0-9]* underruns' "$work/igi.log" | awk '{print $1}')
  failed=$(grep -o '[0-9]* failed,' "$work/igi.log" | awk '{print $1}')
  # Every manifest line names a file that is there, and there is one line per frame.
  listed=$(wc -l <"$out/manifest.jsonl" 2>/dev/null || echo 0)
  on_disk=0
  if [[ -f "$out/manifest.jsonl" ]]; then
    on_disk=$(grep -o '"file":"[^"]*"' "$out/manifest.jsonl" | cut -d'"' -f4 |
      while read -r f; do [[ -f "$out/$f" ]] && echo; done | wc -l)
  fi
  ratio=$(awk -v a="${igi_fps:-0}" -v b="$peer_fps" 'BEGIN {printf "%.2f", a / b}')
  echo "| ${size}x${size} Mono8 | $peer_fps ($peer_a, $peer_b) | $((lost_a + lost_b)) | ${igi_fps:-?} | ${gaps:-?}/${underruns:-?}/${failed:-?} | $code | $listed/$on_disk of $frames | $ratio |"
  [[ $code == 0 ]] || sed 's/^/    /' "$work/igi.log" >&2
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
