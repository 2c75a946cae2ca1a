#!/usr/bin/python3
"""Rendering from Python against igi-render: the same scene, camera, lighting, spp and seed,
alternately, in one run on one machine. Both sides do the same work — read scene.json and its
mesh, build the ray scene, path-trace, and write the image as EXR — and are timed from outside
the work: igi-render as a process (its wall time, less the start of an empty process measured the same
way: igi-render --version), Python as the calls igi.Scene.load, igi.Renderer and render in a warm
interpreter, then igi.write_image. The images are checked equal bit for bit on every pair.

Usage: bench/python/render_bench.py [--build build] [--scene S] [--camera C] [--lighting L]
                                    [--spp N] [--width W] [--height H] [--pairs P] [--threads T]
Prints a Markdown table: both sides' median seconds, the ratio Python / igi-render of the medians
and the median (quartiles) of the per-pair ratios.
"""

import argparse
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time


def quartiles(values):
    q = statistics.quantiles(values, n=4)
    return q[0], statistics.median(values), q[2]


def main() -> int:
    root = pathlib.Path(__file__).resolve().parents[2]
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=str(root / "build"))
    parser.add_argument("--scene", default=str(root / "tests/data/scenes/render/complete.json"))
    parser.add_argument("--camera", default="cam0")
    parser.add_argument("--lighting", default="L0")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--pairs", type=int, default=7)
    parser.add_argument("--threads", type=int, default=2)
    a = parser.parse_args()
    build = pathlib.Path(a.build).resolve()
    sys.path.insert(0, str(build / "python"))
    import numpy as np

    import igi

    igi_render = build / "bin" / "igi-render"
    env = dict(os.environ, IGI_NO_PROGRESS="1")

    def process_seconds(args):
        start = time.perf_counter()
        subprocess.run(args, check=True, capture_output=True, env=env)
        return time.perf_counter() - start

    igi_times, python_times = [], []
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "render.exr"
        ours = pathlib.Path(tmp) / "python.exr"
        for pair in range(a.pairs):
            start_cost = process_seconds([igi_render, "--version"])
            exe = process_seconds([igi_render, a.scene, "--camera", a.camera, "--lighting",
                                   a.lighting, "--spp", str(a.spp), "--width", str(a.width),
                                   "--height", str(a.height), "--threads", str(a.threads),
                                   "--seed", "3", "--quiet", "--out", out]) - start_cost
            start = time.perf_counter()
            scene = igi.Scene.load(a.scene)
            image = igi.Renderer(scene, a.lighting).render(a.camera, spp=a.spp, seed=3,
                                                           width=a.width, height=a.height,
                                                           threads=a.threads)
            igi.write_image(ours, image)
            py = time.perf_counter() - start
            if not np.array_equal(np.asarray(igi.read_image(ours)),
                                  np.asarray(igi.read_image(out))):
                print("images differ", file=sys.stderr)
                return 1
            igi_times.append(exe)
            python_times.append(py)
            print(f"pair {pair}: igi-render {exe:.3f} s, Python {py:.3f} s", file=sys.stderr)
    ratios = [p / e for p, e in zip(python_times, igi_times)]
    low, mid, high = quartiles(ratios)
    load = os.getloadavg()[0]
    print(f"| scene | size, spp | pairs | load | igi-render s (median) | Python s (median) "
          f"| Python / igi-render (medians) | paired: median (quartiles) |")
    print("|---|---|---|---|---|---|---|---|")
    print(f"| {pathlib.Path(a.scene).name} {a.camera} {a.lighting} | {a.width}×{a.height}, "
          f"{a.spp} | {a.pairs} | {load:.1f} | {statistics.median(igi_times):.3f} | "
          f"{statistics.median(python_times):.3f} | "
          f"**{statistics.median(python_times) / statistics.median(igi_times):.3f}** | "
          f"{mid:.3f} ({low:.3f}–{high:.3f}) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
