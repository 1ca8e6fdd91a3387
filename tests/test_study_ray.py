"""The Ray backend: a small study on a local 2-CPU instance gives the local backend's table."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from astralis_des.errors import InputError
from astralis_des.studies import load_study, run_study
from astralis_des.studies.backends import make_backend

ROOT = Path(__file__).parents[1]
OUTCOMES = ROOT / "studies" / "outcomes.yaml"


@pytest.fixture(scope="module")
def local_ray() -> Iterator[None]:
    """One local 2-CPU Ray instance for the module (a study uses a running instance)."""
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, logging_level="ERROR", log_to_driver=False)
    yield
    ray.shutdown()


def test_ray_backend_matches_local(local_ray: None) -> None:
    """Mission scenarios on Ray give the same rows as in one process."""
    study = load_study(OUTCOMES).with_changes(scenarios=3, vary={"strategy": ["naive", "mixed"]})
    on_ray = run_study(study, workers=2, backend="ray")
    assert (on_ray.backend, on_ray.workers) == ("ray", 2)
    assert on_ray.table.num_rows == 6
    assert on_ray.table.equals(run_study(study, workers=1).table)


def test_unknown_backend_suggests() -> None:
    """A misspelt backend is bad input naming the key, with a hint."""
    with pytest.raises(InputError) as info:
        make_backend("rey", 2)
    assert str(info.value) == "backend: unknown study backend 'rey'; did you mean 'ray'?"


def test_a_cluster_with_token_auth_is_refused_in_one_line_saying_what_to_set(
        tmp_path: Path) -> None:
    """A Ray cluster started with RAY_AUTH_MODE=token (Ray's coming default), reached
    without its token: exit 2 and one line naming RAY_AUTH_MODE and RAY_AUTH_TOKEN (before:
    a ConnectionError traceback, after Ray's own retry lines)."""
    import os
    import shutil
    import signal
    import socket
    import subprocess
    import sys
    import tempfile
    import time

    pytest.importorskip("ray")
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    secret = {"RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": "astralis-test-token-0123456789"}
    short = tempfile.mkdtemp(prefix="ray", dir="/tmp")  # Ray's socket paths must be short
    head = subprocess.Popen(
        [str(Path(sys.executable).parent / "ray"), "start", "--head", f"--port={port}",
         "--num-cpus=1", "--include-dashboard=false", "--disable-usage-stats", "--block",
         f"--temp-dir={short}"], env={**os.environ, **secret},
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            with socket.socket() as knock:
                if knock.connect_ex(("127.0.0.1", port)) == 0:
                    break
            time.sleep(0.2)
        plain = {k: v for k, v in os.environ.items() if not k.startswith("RAY_AUTH")}
        plain["RAY_gcs_server_port_wait_time_s"] = "2"  # Ray's tries to connect: 2, not 20
        done = subprocess.run(
            [sys.executable, "-m", "astralis_des.cli", "study", str(ROOT / "studies" /
             "table5.yaml"), "--scenarios", "2", "--backend", "ray", "--address",
             f"127.0.0.1:{port}", "--out", str(tmp_path / "study"), "--quiet"],
            capture_output=True, text=True, env=plain, timeout=120)
    finally:
        os.killpg(head.pid, signal.SIGTERM)  # ray start --block stops its processes
        try:
            head.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(head.pid, signal.SIGKILL)
            head.wait()
        shutil.rmtree(short, ignore_errors=True)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        f"error: address: cannot use the Ray cluster at 127.0.0.1:{port} (")
    assert lines[0].endswith("a cluster with token authentication needs RAY_AUTH_MODE=token "
                             "and its token in RAY_AUTH_TOKEN or RAY_AUTH_TOKEN_PATH "
                             "(docs/studies.md)")
    assert not (tmp_path / "study").exists()
