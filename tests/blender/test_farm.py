"""A render split into sample ranges (parts, a Dask LocalCluster of 2 workers) is the single render.

The merge adds float64 sums in another grouping than the single render's waves, so images
are compared within 1e-6 relative (docs/render-farms.md). Every run is bounded by a
timeout, and every process a run started must be gone when it ends.
"""
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import bpy
import numpy as np
import psutil
import pytest

from tests.support.render_helpers import read_channels

ROOT = Path(__file__).resolve().parents[2]
SAMPLES, SEED, SIZE = 8, 5, 32
OPTIONS = ["--samples", SAMPLES, "--seed", SEED, "--resolution", f"{SIZE}x{SIZE}", "--engine-threads", 1]
RELATIVE = 1e-6


def cli(*args):
    return [sys.executable, "-m", "drt_engine", *map(str, args)]


def run(*args, timeout=120):
    return subprocess.run(cli(*args), cwd=ROOT, capture_output=True, text=True, timeout=timeout)


def one_error_line(result, *words):
    assert result.returncode != 0
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("drt: error:")
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


@pytest.fixture(scope="module")
def cornell_box(sample_scene):
    """The Cornell box this Blender can open (under 4.x, built by its script: the worker CLIs run this Python)."""
    return sample_scene("cornell_box")


@pytest.fixture(scope="module")
def single(cornell_box, tmp_path_factory):
    out = tmp_path_factory.mktemp("single") / "single.exr"
    result = run("render", cornell_box, "-o", out, *OPTIONS)
    assert result.returncode == 0, result.stderr
    return out


def assert_same_image(path, reference):
    a, b = read_channels(path), read_channels(reference)
    assert sorted(a) == sorted(b)
    for name in b:
        scale = np.maximum(np.abs(a[name]), np.abs(b[name]))
        assert np.all(np.abs(a[name] - b[name]) <= RELATIVE * scale), name
    report, expected = (json.loads(p.with_name(p.stem + ".drt.json").read_text()) for p in (path, reference))
    assert report["settings"] | {"threads": 0} == expected["settings"] | {"threads": 0}
    for key in ("samples", "rays", "stopped_by"):
        assert report["stats"][key] == expected["stats"][key], key
    for key in ("rmse", "relmse"):  # the same error estimate
        assert report["stats"][key] == pytest.approx(expected["stats"][key], rel=RELATIVE)
    assert report["log"][-1]["relmse"] == report["stats"]["relmse"]
    assert path.with_name(path.stem + ".error.png").stat().st_size > 0


class Tree:
    """Every process below ``root`` seen while watching (so orphans can be checked afterwards)."""

    def __init__(self, root: int):
        self.root = psutil.Process(root)
        self.seen: dict[int, psutil.Process] = {}

    def watch(self) -> list[psutil.Process]:
        try:
            children = self.root.children(recursive=True)
        except psutil.NoSuchProcess:
            return []
        for child in children:
            self.seen.setdefault(child.pid, child)
        return children

    def renders(self) -> list[psutil.Process]:
        """Running task renders (the workers' child processes)."""
        out = []
        for child in self.watch():
            try:
                if "--sample-range" in child.cmdline():
                    out.append(child)
            except psutil.Error:
                pass
        return out

    def assert_all_gone(self, timeout=15.0):
        deadline = time.monotonic() + timeout
        alive = list(self.seen.values())
        while alive and time.monotonic() < deadline:
            alive = [p for p in alive if p.is_running() and p.status() != psutil.STATUS_ZOMBIE]
            time.sleep(0.2)
        assert not alive, [p.cmdline() for p in alive]


def _default_sigint():  # pragma: no cover (runs in the child, before exec)
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start(*args):
    """The CLI as a terminal's foreground job: a process group of its own (Ctrl-C signals the whole group), and
    SIGINT's default action even when pytest itself ignores SIGINT, as a background job of a script does
    (`make test > log &`): an ignored SIGINT is inherited through exec by the CLI, its workers and their
    renders, so a Ctrl-C would reach no one and the render would run on."""
    return subprocess.Popen(cli(*args), cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=_default_sigint)


def wait_for_render(proc, tree, timeout=90.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        found = tree.renders()
        if found:
            return found
        time.sleep(0.1)
    pytest.fail("no task render started")


def test_split_render_with_a_killed_worker_equals_the_single_render(cornell_box, single, tmp_path):
    """2 sample ranges on 2 local workers; the worker of the first task to start is killed mid-task."""
    out = tmp_path / "split.exr"
    proc = start("render", cornell_box, "-o", out, *OPTIONS, "--workers", 2)
    tree = Tree(proc.pid)
    try:
        victim = wait_for_render(proc, tree)[0]
        worker = victim.parent()
        assert "--sample-range" not in worker.cmdline()
        worker.kill()
        stdout, stderr = proc.communicate(timeout=150)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 0, stderr
    assert stderr == ""
    assert not victim.is_running() or victim.status() == psutil.STATUS_ZOMBIE  # died with its worker
    assert "2/2 tasks done" in stdout and "est. error" in stdout
    assert_same_image(out, single)
    tree.assert_all_gone()


def test_a_denoised_split_render_is_denoised_once_after_the_merge(cornell_box, tmp_path):
    """``--denoise --workers 2``: the parts carry the denoiser's features and halves, the merge denoises
    the merged image once, and it is the single denoised render (the same noisy sums into OIDN; the
    denoised image within 1e-3, what float64 sums added in another order change in OIDN's output)."""
    single, split = tmp_path / "single.exr", tmp_path / "split.exr"
    result = run("render", cornell_box, "-o", single, *OPTIONS, "--denoise")
    assert result.returncode == 0, result.stderr
    result = run("render", cornell_box, "-o", split, *OPTIONS, "--denoise", "--workers", 2, timeout=240)
    assert result.returncode == 0, result.stderr
    assert "2/2 tasks done" in result.stdout and "(denoised " in result.stdout.splitlines()[-1]
    a, b = read_channels(split), read_channels(single)
    assert sorted(a) == sorted(b) and "ViewLayer.Noisy Image.R" in a
    for name in b:
        tolerance = 1e-3 if ".Combined." in name and not name.endswith(".A") else RELATIVE
        assert np.allclose(a[name], b[name], rtol=tolerance, atol=tolerance * np.abs(b[name]).max()), name
    report, expected = (json.loads(p.with_name(p.stem + ".drt.json").read_text()) for p in (split, single))
    log = report["log"]  # an entry as the merged samples grow (one or two: parts may arrive out of order)
    assert ["relmse_denoised" in entry for entry in log] == [False] * (len(log) - 1) + [True]
    for key in ("relmse", "relmse_denoised"):
        assert report["stats"][key] == pytest.approx(expected["stats"][key], rel=1e-3), key


def test_merged_parts_from_blender_and_the_cli_equal_the_single_render(drt, cornell_box, single, tmp_path):
    """Samples 0:3 from a `blender -b`-style render (scene.drt.sample_offset / count), 3:8 from the CLI."""
    cli_part = tmp_path / "b.exr"
    job = subprocess.Popen(cli("render", cornell_box, "-o", cli_part, *OPTIONS, "--sample-range", "3:8"), cwd=ROOT,
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        bpy.ops.wm.open_mainfile(filepath=str(cornell_box), load_ui=False)
        scene = bpy.context.scene
        scene.render.engine = "DRT"
        scene.render.resolution_x = scene.render.resolution_y = SIZE
        scene.render.resolution_percentage = 100
        scene.drt.samples, scene.drt.seed, scene.drt.threads = SAMPLES, SEED, 1
        scene.drt.sample_offset, scene.drt.sample_count = 0, 3
        scene.render.filepath = str(tmp_path / "frame_####")
        bpy.ops.render.render(write_still=True, scene=scene.name)
        _, stderr = job.communicate(timeout=120)
    finally:
        job.kill()
    assert job.returncode == 0, stderr
    blender_part = tmp_path / "frame_0001.samples-0-3.exr"
    assert blender_part.is_file(), sorted(os.listdir(tmp_path))

    out = tmp_path / "merged.exr"
    result = run("merge", cli_part, blender_part, "-o", out)
    assert result.returncode == 0, result.stderr
    assert "2 parts, 8 samples" in result.stdout
    assert_same_image(out, single)

    # parts that do not make one image: one line each
    one_error_line(run("merge", cli_part, "-o", tmp_path / "x.exr"), "samples 0:3 are missing")
    one_error_line(run("merge", blender_part, blender_part, cli_part, "-o", tmp_path / "x.exr"), "overlaps")
    one_error_line(run("merge", single, "-o", tmp_path / "x.exr"), "not a DRT part")
    other_seed = tmp_path / "seed.exr"
    assert run("render", cornell_box, "-o", other_seed, *OPTIONS, "--seed", 6, "--sample-range", "3:8").returncode == 0
    one_error_line(run("merge", blender_part, other_seed, "-o", tmp_path / "x.exr"), "different seeds")


def test_missing_scheduler_is_one_line_within_a_minute(cornell_box, tmp_path):
    with socket.socket() as s:  # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    began = time.monotonic()
    result = run("render", cornell_box, "-o", tmp_path / "x.exr", *OPTIONS, "--cluster", f"tcp://127.0.0.1:{port}",
                 "--connect-timeout", 5, timeout=60)
    one_error_line(result, "no Dask scheduler answered", f"127.0.0.1:{port}")
    assert time.monotonic() - began < 60
    assert "Traceback" not in result.stdout


def test_worker_without_drt_is_named_in_one_line(cornell_box, tmp_path):
    """A `dask worker` started outside the repository, where drt_engine is not importable."""
    dask = Path(sys.executable).with_name("dask")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    address_file = tmp_path / "scheduler.json"
    scheduler = subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                  "--scheduler-file", address_file], cwd=tmp_path, env=env,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = None
    try:
        deadline = time.monotonic() + 30
        while not address_file.is_file() and time.monotonic() < deadline:
            time.sleep(0.2)
        address = json.loads(address_file.read_text())["address"]
        worker = subprocess.Popen([dask, "worker", address, "--nthreads", "1", "--no-nanny", "--host", "127.0.0.1",
                                   "--no-dashboard"], cwd=tmp_path, env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        result = run("render", cornell_box, "-o", tmp_path / "x.exr", *OPTIONS, "--cluster", address,
                     "--connect-timeout", 30, timeout=90)
        line = one_error_line(result, "worker tcp://127.0.0.1:", "cannot run DRT", "drt_engine")
        assert "No module named" in line
    finally:
        for proc in (worker, scheduler):
            if proc is not None:
                proc.terminate()
                try:
                    proc.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()


def test_ctrl_c_cancels_and_leaves_no_process(cornell_box, tmp_path):
    # samples enough that no task can end before Ctrl-C reaches it (the render is cancelled, not waited for)
    long = ["--samples", 1 << 20, *OPTIONS[2:]]
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # pytest as a script's `make test &` runs it
    try:
        proc = start("render", cornell_box, "-o", tmp_path / "x.exr", *long, "--workers", 2)
    finally:
        signal.signal(signal.SIGINT, previous)
    tree = Tree(proc.pid)
    try:
        wait_for_render(proc, tree)
        tree.watch()
        os.killpg(proc.pid, signal.SIGINT)  # what Ctrl-C in a terminal does: the whole foreground group
        _, stderr = proc.communicate(timeout=150)  # client and cluster close take up to 10 + 30 s, more under load
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, stderr
    assert len(stderr.splitlines()) == 1 and "cancelled" in stderr, stderr
    assert not (tmp_path / "x.exr").exists()
    tree.assert_all_gone()


def test_ranges_cover_every_sample_once():
    from drt_engine.headless.farm import split

    for samples, tasks in ((8, 2), (7, 3), (1024, 16), (3, 5)):
        ranges = split(samples, tasks)
        assert ranges[0][0] == 0 and ranges[-1][1] == samples
        assert all(a < b for a, b in ranges) and all(b == c for (_, b), (c, _) in zip(ranges, ranges[1:]))
        assert len(ranges) == min(tasks, samples)


def test_frame_outputs():
    from drt_engine.headless.farm import frame_output

    assert frame_output(Path("/o/shot_####.exr"), 12, True) == Path("/o/shot_0012.exr")
    assert frame_output(Path("/o/shot_##.exr"), 7, False) == Path("/o/shot_07.exr")
    assert frame_output(Path("/o/shot.exr"), 3, True) == Path("/o/shot0003.exr")
    assert frame_output(Path("/o/shot.exr"), 3, False) == Path("/o/shot.exr")


@pytest.mark.parametrize("extra, words", [
    (["--sample-range", "5:3"], ["START < END"]),
    (["--sample-range", "0:9"], ["goes past the 8 samples"]),
    (["--sample-range", "0:4", "--adaptive-threshold", "0.01"], ["fixed sample count"]),
    (["--frames", "1-3"], ["--frames needs --workers or --cluster"]),
    (["--workers", "2", "--cluster", "tcp://127.0.0.1:1"], ["not both"]),
])
def test_bad_farm_options_are_one_line(drt, cornell_box, tmp_path, extra, words):
    """In this process (the checks come before any render or cluster)."""
    from drt_engine.headless import cli, commands
    from drt_engine.headless.errors import CLIError

    with pytest.raises(CLIError) as caught:
        commands.render(cli.build_parser().parse_args(["render", str(cornell_box), "-o", str(tmp_path / "x.exr"),
                                                       *map(str, OPTIONS), *extra]))
    for word in words:
        assert word in str(caught.value)


def test_tls_options_make_an_encrypted_client(cornell_box, tmp_path):
    from drt_engine.headless import cli
    from drt_engine.headless.errors import CLIError
    from drt_engine.headless.farm import _security

    def args(*extra):
        return cli.build_parser().parse_args(["render", str(cornell_box), "-o", "x.exr", "--cluster", "tls://h:8786",
                                              *extra])

    assert not _security(args()).require_encryption  # Dask's own configuration then
    with pytest.raises(CLIError, match="no such file"):
        _security(args("--tls-ca-file", str(tmp_path / "missing.pem")))
    for name in ("ca.pem", "cert.pem", "key.pem"):
        (tmp_path / name).write_text("-")
    security = _security(args("--tls-ca-file", str(tmp_path / "ca.pem"), "--tls-cert", str(tmp_path / "cert.pem"),
                              "--tls-key", str(tmp_path / "key.pem")))
    assert security.require_encryption
    assert (security.tls_ca_file, security.tls_client_cert, security.tls_client_key) == tuple(
        str(tmp_path / n) for n in ("ca.pem", "cert.pem", "key.pem"))
