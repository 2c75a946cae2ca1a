"""The executables' jobs from Python: igi.synth.synthesize, igi.solve, igi.diagnose, igi.export and
igi.run take the executables' flags as keyword options, write what the executables write, and
return summaries whose to_dict() is the executables' JSON report; a progress callback sees the
work advance and Ctrl-C stops it with nothing written."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import igi

# A small room: 3 photos of 96x72, the glossy regions' values unknown.
SYNTH = dict(cameras=3, width=96, height=72, spp=4, seed=5, validation_lightings="none")
# A quick solve of it: the paper's method only.
SOLVE = dict(pixel_stride=2, refine_iterations=0, max_iterations=3, seed=1)


@pytest.fixture(scope="module")
def capture(tmp_path_factory):
    out = tmp_path_factory.mktemp("synth") / "room"
    calls = []
    scene, summary = igi.synth.synthesize(out, threads=2,
                                          progress=lambda *a: calls.append(a), **SYNTH)
    return out, scene, summary, calls


@pytest.fixture(scope="module")
def solved(capture, tmp_path_factory):
    out = tmp_path_factory.mktemp("solve") / "solved"
    calls = []
    scene, summary = igi.solve(capture[1], out, threads=2, progress=lambda *a: calls.append(a),
                               **SOLVE)
    return out, scene, summary, calls


def test_synthesize_writes_what_igi_synth_writes(capture, bin_dir, tmp_path):
    out, scene, summary, _ = capture
    assert len(summary.photos) == 3 and len(scene.photos) == 3
    theirs = tmp_path / "room"
    subprocess.run([bin_dir / "igi-synth", "--out", theirs, "--cameras", "3", "--width", "96",
                    "--height", "72", "--spp", "4", "--seed", "5", "--validation-lightings",
                    "none", "--threads", "2", "--quiet"], check=True, capture_output=True)
    assert json.loads((theirs / "truth.json").read_text()) == summary.truth
    for photo in summary.photos:
        np.testing.assert_array_equal(np.asarray(igi.read_image(out / photo)),
                                      np.asarray(igi.read_image(theirs / photo)))


def test_solve_summary_is_report_json_with_igi_solves_keys(solved, capture, bin_dir, tmp_path):
    out, scene, summary, _ = solved
    report = json.loads((out / "report.json").read_text())
    assert summary.to_dict() == report
    assert summary.regions == report["regions"]
    theirs = tmp_path / "theirs"
    # Exit 3: the capture's ceiling is seen by no photo (igi.solve reports it in the summary).
    result = subprocess.run([bin_dir / "igi-solve", capture[1].file, "--out", theirs,
                             "--pixel-stride", "2", "--refine-iterations", "0", "--max-iterations",
                             "3", "--seed", "1", "--threads", "2", "--quiet"], capture_output=True)
    assert result.returncode == 3, result.stderr
    assert "unobserved" in {r["status"] for r in summary.regions}
    their_report = json.loads((theirs / "report.json").read_text())
    assert sorted(report.keys()) == sorted(their_report.keys())
    # The same solve: the same materials written.
    their_scene = json.loads((theirs / "scene.json").read_text())
    assert scene.materials == their_scene["materials"]
    # The returned scene is OUT/scene.json, every material value filled in.
    assert scene.file == os.fspath(out / "scene.json")
    assert all("rho_d" in m for m in scene.materials.values())


def test_progress_callback_sees_each_stage_to_its_end(solved, capture):
    calls = solved[3]
    labels = {label for label, _, _ in calls}
    assert any(label.startswith("igi-solve") for label in labels), labels
    for label in labels:
        done, total = [(d, t) for lab, d, t in calls if lab == label][-1]
        assert done == total, (label, done, total)
    assert capture[3], "igi-synth's renders report progress too"


def test_options_are_the_flags_and_bad_ones_raise_input_error(capture, tmp_path):
    with pytest.raises(igi.InputError) as error:
        igi.solve(capture[1], tmp_path / "a", pixel_strid=2)
    assert error.value.problems == ["--pixel-strid: 2: not an option of igi-solve"]
    with pytest.raises(igi.InputError, match="--pixel-stride"):
        igi.solve(capture[1], tmp_path / "b", pixel_stride=0)
    with pytest.raises(igi.InputError, match="--albedo-maps"):
        igi.solve(capture[1], tmp_path / "c", albedo_maps="sometimes")
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()
    assert "pixel_stride (default 2)" in igi.solve.__doc__
    assert "effect" in igi.synth.synthesize.__doc__


def test_export_summary_is_export_report_json(solved, tmp_path):
    out = tmp_path / "mitsuba"
    summary = igi.export(solved[1], out, "mitsuba", mitsuba_spp=16)
    assert summary.to_dict() == json.loads((out / "export_report.json").read_text())
    assert summary.target == "mitsuba"
    assert (out / summary.files[0]).exists()
    with pytest.raises(igi.InputError, match="--format"):
        igi.export(solved[1], tmp_path / "x", "povray")


def test_diagnose_summary_is_diagnosis_json(solved, tmp_path):
    out = tmp_path / "diagnosis"
    scene, summary = igi.diagnose(solved[1], out, threads=2, spp=4, spp_max=0, max_steps=1,
                                  refine_iterations=0, solve_iterations=2)
    assert summary.to_dict() == json.loads((out / "diagnosis.json").read_text())
    assert "steps" in summary.keys()
    assert scene.file == os.fspath(out / "scene.json")


def test_run_with_hdr_photos_goes_from_scene_to_report(capture, tmp_path):
    out = tmp_path / "run"
    summary = igi.run(out, scene=capture[1], hdr_photos=True, skip_diagnose=True,
                      solve_arg=["--refine-iterations=0", "--max-iterations=2"], report_spp=4,
                      report_photos=1, threads=2)
    stages = {s["stage"]: s["status"] for s in summary.stages}
    # "partial": igi-solve's exit 3 for the ceiling no photo sees, as igi-run reports it.
    assert stages["04-solve"] == "partial" and summary.partial, stages
    assert any("ceiling" in line for line in summary.partial_lines), summary.partial_lines
    assert os.path.exists(summary.report) and os.path.exists(summary.solved_scene)
    # A rerun keeps the finished stages.
    again = igi.run(out, scene=capture[1], hdr_photos=True, skip_diagnose=True,
                    solve_arg=["--refine-iterations=0", "--max-iterations=2"], report_spp=4,
                    report_photos=1, threads=2)
    assert {s["stage"]: s["status"] for s in again.stages}["04-solve"] == "kept"


def test_ctrl_c_stops_a_solve_with_nothing_written(capture, tmp_path):
    out = tmp_path / "interrupted"
    script = textwrap.dedent(f"""
        import sys, time, igi
        scene = igi.Scene.load({os.fspath(capture[1].file)!r})
        started = []
        def progress(label, done, total):
            if not started:
                started.append(time.monotonic())
                print("started", flush=True)
        try:
            igi.solve(scene, {os.fspath(out)!r}, threads=2, progress=progress, pixel_stride=1,
                      refine_iterations=4, refine_rays=256)
        except KeyboardInterrupt:
            print("interrupted after %.1f s" % (time.monotonic() - started[0]), flush=True)
            sys.exit(0)
        print("finished", flush=True)
    """)
    process = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                               env=dict(os.environ))
    assert process.stdout.readline().strip() == "started"
    time.sleep(1.0)
    process.send_signal(signal.SIGINT)
    output, _ = process.communicate(timeout=60)
    assert process.returncode == 0, output
    assert output.startswith("interrupted after"), output
    assert not (out / "scene.json").exists() and not (out / "report.json").exists()


def test_a_failing_progress_callback_stops_the_job_with_its_error(solved):
    scene = solved[1]
    camera = scene.photos[0]["camera"]

    def progress(label, done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        igi.Renderer(scene, "L0").render(camera, spp=64, progress=progress)
    # The next job runs normally.
    image = igi.Renderer(scene, "L0").render(camera, spp=1)
    assert np.isfinite(np.asarray(image)).all()
