"""The container image: the Dockerfile builds with podman on a local Debian bookworm base, and
the default mission run inside it writes, on a mounted folder, the same event log as outside.

Skipped where podman is not installed or the base image ``localhost/debian-bookworm`` is not
there (this test never makes it; the README says how: a debootstrap tree, imported). Podman
runs here only with the runc runtime and the host network. The first build takes a few
minutes (pip installs the dependencies); later ones reuse podman's cached layers and take
seconds.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BASE = "localhost/debian-bookworm"
IMAGE = "localhost/astralis-des:test"
PODMAN = ["podman", "--runtime", "runc"]
HOST_CERTS = Path("/etc/ssl/certs")  # pip inside a build step needs the host's CA bundle here
BUILD_TIMEOUT = 20 * 60
RUN_TIMEOUT = 5 * 60

pytestmark = pytest.mark.container


def podman(*args: str, timeout: float, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    try:
        return subprocess.run([*PODMAN, *args], capture_output=True, text=True, timeout=timeout,
                              cwd=cwd, check=False)
    except subprocess.TimeoutExpired:
        pytest.fail(f"podman {args[0]} took longer than {timeout:.0f} s")


def tail(proc: subprocess.CompletedProcess[str], lines: int = 40) -> str:
    return "\n".join((proc.stdout + proc.stderr).splitlines()[-lines:])


@pytest.fixture(scope="module")
def image() -> str:
    """The image, built from the working tree (cached layers are reused)."""
    if shutil.which("podman") is None:
        pytest.skip("podman is not installed")
    if podman("image", "exists", BASE, timeout=60).returncode != 0:
        pytest.skip(f"no base image {BASE} (the README's Container section makes it)")
    certs = (["-v", f"{HOST_CERTS}:/hostcerts:ro"]
             if (HOST_CERTS / "ca-certificates.crt").is_file() else [])
    build = podman("build", "--network", "host", *certs, "--build-arg", f"BASE={BASE}",
                   "-t", IMAGE, ".", timeout=BUILD_TIMEOUT, cwd=ROOT)
    assert build.returncode == 0, f"podman build failed:\n{tail(build)}"
    return IMAGE


def outside_command() -> list[str]:
    """``astralis`` of the environment running the tests."""
    exe = Path(sys.executable).with_name("astralis")
    if exe.is_file():
        return [str(exe)]
    return [sys.executable, "-c", "import sys; from astralis_des.cli import main; "
            "sys.exit(main())"]


@pytest.fixture(scope="module")
def inside(image: str, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """The default mission run in the image, its outputs in a mounted folder."""
    mount = tmp_path_factory.mktemp("container")
    name = f"astralis-test-{uuid.uuid4().hex[:12]}"
    try:
        proc = podman("run", "--rm", "--name", name, "--network", "host",
                      "-v", f"{mount}:/out", image,
                      "run", "missions/urban_search.yaml", "--out", "/out/run", "--quiet",
                      "--mcap",
                      timeout=RUN_TIMEOUT)
    finally:
        subprocess.run([*PODMAN, "rm", "-f", "--ignore", name], capture_output=True,
                       timeout=60, check=False)
    assert proc.returncode == 0, f"the mission failed in the container:\n{tail(proc)}"
    yield mount / "run"


def test_image_runs_astralis_by_default(image: str) -> None:
    proc = podman("image", "inspect", "--format",
                  "{{json .Config.Entrypoint}} {{json .Config.Cmd}} {{.Config.WorkingDir}}",
                  image, timeout=60)
    assert proc.returncode == 0, tail(proc)
    entrypoint, cmd, workdir = proc.stdout.split()
    assert json.loads(entrypoint) == ["astralis"]
    assert json.loads(cmd) == ["run", "missions/urban_search.yaml"]
    assert workdir == "/work"


def test_default_mission_in_container(inside: Path) -> None:
    events = inside / "events.jsonl"
    assert events.is_file(), sorted(p.name for p in inside.iterdir())
    last = json.loads(events.read_text().splitlines()[-1])
    assert last["kind"] == "mission_end"
    assert last["outcome"] == "found"
    summary = json.loads((inside / "summary.json").read_text())
    assert summary["outcome"] == "found"
    assert summary["mission"] == "urban_search"
    assert (inside / "run.mcap").read_bytes()[:8] == b"\x89MCAP0\r\n"  # the image exports MCAP


def test_container_run_is_identical_to_host_run(inside: Path, tmp_path: Path) -> None:
    out = tmp_path / "run"
    proc = subprocess.run([*outside_command(), "run", "missions/urban_search.yaml",
                           "--out", str(out), "--quiet"],
                          cwd=ROOT, capture_output=True, text=True, timeout=RUN_TIMEOUT,
                          check=False)
    assert proc.returncode == 0, tail(proc)
    host, container = (out / "events.jsonl").read_bytes(), (inside / "events.jsonl").read_bytes()
    assert host == container, "the event log differs between the host and the container"
