"""Generated fuzzing: every generated world, mission and study file ends in a result or a
one-line error (exit 2), never a traceback, a warning, a hang or a mixed output folder; every
generated API request gets a reply and the server keeps serving.

The ``ci`` profile (the default) runs a few hundred cases in seconds; ``tools/fuzz.py`` runs the
long one. Cases the fuzzer found are kept under ``tests/fuzzing/found/`` and run here too.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from pathlib import Path

import pytest
import zmq
from fuzzing.cases import Case, dealer_to, run_case
from fuzzing.strategies import mission_cases, requests, study_cases
from hypothesis import HealthCheck, given, settings

from astralis_des import Mission

FOUND = Path(__file__).parent / "fuzzing" / "found"
EXAMPLES = {"missions": 150, "studies": 12, "requests": 400}
SCALE = float(os.environ.get("ASTRALIS_FUZZ_SCALE", "1"))


def fuzz(kind: str) -> settings:
    # derandomize: the same cases on every run, so that the suite is as reproducible as a run
    return settings(max_examples=int(EXAMPLES[kind] * SCALE), deadline=None, database=None,
                    derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz") / "case"


@fuzz("missions")
@given(case=mission_cases())
def test_a_generated_mission_file_ends_in_a_result_or_a_one_line_error(
        case: Case, folder: Path) -> None:
    outcome = run_case(case, folder)
    assert outcome.ok, f"{outcome.kind}: {outcome.detail}"


@fuzz("studies")
@given(case=study_cases())
def test_a_generated_study_file_ends_in_a_result_or_a_one_line_error(
        case: Case, folder: Path) -> None:
    outcome = run_case(case, folder)
    assert outcome.ok, f"{outcome.kind}: {outcome.detail}"


@pytest.mark.parametrize("found", sorted(p.name for p in FOUND.iterdir()))
def test_a_case_the_fuzzer_found_stays_fixed(found: str, tmp_path: Path) -> None:
    where = FOUND / found
    study = where / "study.yaml"
    case = Case((where / "mission.yaml").read_bytes(), (where / "world.yaml").read_bytes(),
                study.read_bytes() if study.exists() else None)
    outcome = run_case(case, tmp_path / "case")
    assert outcome.ok, f"{outcome.kind}: {outcome.detail}"


@pytest.fixture(scope="module")
def dealer(urban_search: Mission) -> Iterator[zmq.Socket[bytes]]:
    with dealer_to(urban_search) as socket:
        yield socket


@fuzz("requests")
@given(frames=requests())
def test_a_generated_api_request_gets_one_reply(frames: list[bytes],
                                               dealer: zmq.Socket[bytes]) -> None:
    dealer.send_multipart([b"", *frames])
    assert dealer.poll(30_000), "no reply in 30 s"
    reply = json.loads(dealer.recv_multipart()[-1])
    assert isinstance(reply["ok"], bool)
    if not reply["ok"]:
        assert reply["error"]["code"] != "internal", reply["error"]["message"]
        assert "\n" not in reply["error"]["message"]
