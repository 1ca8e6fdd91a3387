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
