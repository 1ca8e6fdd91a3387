"""Mutation fuzzing of real point clouds: small files of PDAL's corpus (data/scans: LAS 1.2 and
1.4, LAS with extra bytes, LAZ, PCD, PLY) with bytes flipped or overwritten in the header and
in the data, cut short, or with a run of bytes copied elsewhere. ``import_world`` either
makes a world or refuses the file with an :class:`InputError` of one line: never another
exception, a hang (a case takes well under a few seconds) or a Rust panic on stderr.

The ``ci`` profile (the default) runs about 30 s on two cores; ``ASTRALIS_FUZZ_SCALE``
multiplies the cases for a long run. Cases the fuzzer found stay as ``@example``.
"""

from __future__ import annotations

import os
import struct
import time
from pathlib import Path

import pytest
from fuzzing.cases import alarm
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from astralis_des.errors import InputError
from astralis_des.importers import ImportOptions, import_world

SCANS = Path(__file__).resolve().parents[1] / "data" / "scans"
SCALE = float(os.environ.get("ASTRALIS_FUZZ_SCALE", "1"))
EXAMPLES = 120  # a file, in the ci profile
LIMIT = 5.0  # seconds a case may take, at most (they take a tenth of that)
HEAD = 400  # bytes of header most mutations aim at
# Values that break headers: all ones, all zeros, the largest int32, -1 as int64, NaN.
WORDS = [b"\xff" * 4, b"\x00" * 4, b"\xff" * 8, struct.pack("<i", 2**31 - 1),
         struct.pack("<q", -1), struct.pack("<d", float("nan")), struct.pack("<d", 1e300)]

Mutation = tuple[str, int, int, bytes]  # kind, where, how much (bit, length, to), what


def offsets() -> st.SearchStrategy[int]:
    """Where a mutation goes: in the header half of the time, anywhere otherwise (taken
    modulo the file's size)."""
    return st.one_of(st.integers(0, HEAD), st.integers(0, 2**31))


def mutation() -> st.SearchStrategy[Mutation]:
    return st.one_of(
        st.tuples(st.just("flip"), offsets(), st.integers(0, 7), st.just(b"")),
        st.tuples(st.just("write"), offsets(), st.just(0),
                  st.one_of(st.sampled_from(WORDS), st.binary(min_size=1, max_size=16))),
        st.tuples(st.just("cut"), offsets(), st.just(0), st.just(b"")),
        st.tuples(st.just("copy"), offsets(), st.integers(1, 4096), st.binary(min_size=2,
                                                                               max_size=2)))


def mutate(data: bytes, mutations: list[Mutation]) -> bytes:
    """``data`` with each mutation done in turn: a bit flipped, bytes overwritten, the rest
    cut off, or a run of bytes copied in at another place (``what`` picks the place)."""
    out = bytearray(data)
    for kind, where, much, what in mutations:
        if not out:
            break
        at = where % len(out)
        if kind == "flip":
            out[at] ^= 1 << much
        elif kind == "write":
            out[at:at + len(what)] = what
        elif kind == "cut":
            del out[at:]
        else:
            to = int.from_bytes(what, "little") * len(out) // 65536
            out[to:to] = out[at:at + much]
    return bytes(out)


def fuzz(examples: int = EXAMPLES) -> settings:
    # derandomize: the same cases on every run, so that the suite is as reproducible as a run
    return settings(max_examples=int(examples * SCALE), deadline=None, database=None,
                    derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.function_scoped_fixture])


def imports_or_refuses(source: str, mutations: list[Mutation], partial: bool,
                       folder: Path, capfd: pytest.CaptureFixture[str]) -> None:
    """The property: a world, or one line that refuses the file; in time; stderr clean."""
    original = SCANS / source
    path = folder / f"case{original.suffix}"
    path.write_bytes(mutate(original.read_bytes(), mutations))
    capfd.readouterr()
    began = time.perf_counter()
    try:
        with alarm(LIMIT * 2):
            report = import_world(path, folder / "out" / "twin.yaml",
                                  ImportOptions(partial=partial))
    except InputError as refused:
        assert "\n" not in str(refused), str(refused)
    else:
        assert report.points > 0 and report.world.is_file()
    assert time.perf_counter() - began < LIMIT
    err = capfd.readouterr().err
    assert "panicked" not in err and "Traceback" not in err and "Warning" not in err, err


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


@fuzz()
@given(mutations=st.lists(mutation(), min_size=1, max_size=3), partial=st.booleans())
# simple.laz's chunk table claiming 4,294,967,295 chunks: lazrs asked for 64 GB and aborted.
@example(mutations=[("write", 18207, 0, b"\xff\xff\xff\xff")], partial=False)
# simple.laz's chunks said to hold 268,485,456 points (a bit of its LASzip VLR flipped):
# lazrs's parallel reader zeroed 9 GB for the last chunk, 18 s.
@example(mutations=[("flip", 296, 4, b"")], partial=False)
@pytest.mark.parametrize("source", ["las/simple.las", "las/test1_4.las", "las/extrabytes.las",
                                    "laz/simple.laz"])
def test_a_damaged_las_or_laz_makes_a_world_or_one_line(
        source: str, mutations: list[Mutation], partial: bool, folder: Path,
        capfd: pytest.CaptureFixture[str]) -> None:
    """LAS and LAZ files with their bytes damaged: a world, or a one-line refusal."""
    imports_or_refuses(source, mutations, partial, folder, capfd)


@fuzz()
@given(mutations=st.lists(mutation(), min_size=1, max_size=3), partial=st.booleans())
@pytest.mark.parametrize("source", ["pcd/autzen-utm.pcd", "ply/simple_binary.ply"])
def test_a_damaged_pcd_or_ply_makes_a_world_or_one_line(
        source: str, mutations: list[Mutation], partial: bool, folder: Path,
        capfd: pytest.CaptureFixture[str]) -> None:
    """PCD and PLY files with their bytes damaged: a world, or a one-line refusal."""
    imports_or_refuses(source, mutations, partial, folder, capfd)


def _put(data: bytes, at: int, value: bytes) -> bytes:
    return data[:at] + value + data[at + len(value):]


FOUND = {  # cases the fuzzer found outside the LAS readers, as the bytes it made
    "scales of 1e150 (las)": ("las/simple.las", lambda d: _put(d, 131, struct.pack(
        "<dd", 1e150, 1e150))),
    "the header twice (pcd)": ("pcd/autzen-utm.pcd", lambda d: d[:368] + d),
    "a coordinate of COUNT 9 (pcd)": ("pcd/autzen-utm.pcd", lambda d: _put(d, 258, b"9")),
    "bytes copied in (las)": ("las/simple.las", lambda d: d[:10568] + d[36049:36053] +
                              d[10568:]),
    "a float of 3e38 (ply)": ("ply/simple_binary.ply", lambda d: _put(d, 208, struct.pack(
        "<f", 3e38))),
    "a float of 1e300 (pcd)": ("pcd/autzen-utm.pcd", lambda d: _put(d, 368, struct.pack(
        "<d", 1e300))),
    "a scale's bytes overwritten (las)": ("las/extrabytes.las", lambda d: _put(
        d, 168, b"\x00\x00E")),
}


@pytest.mark.parametrize("case", sorted(FOUND))
def test_a_case_the_fuzzer_found_stays_fixed(case: str, folder: Path,
                                            capfd: pytest.CaptureFixture[str]) -> None:
    """Each: a world, or a one-line refusal of a line's length, and nothing else on stderr
    (overflows, numpy's warnings, a traceback from the writer)."""
    source, damage = FOUND[case]
    path = folder / f"found{Path(source).suffix}"
    path.write_bytes(damage((SCANS / source).read_bytes()))
    capfd.readouterr()
    for partial in (False, True):
        try:
            import_world(path, folder / "found" / "twin.yaml", ImportOptions(partial=partial))
        except InputError as refused:
            assert "\n" not in str(refused) and len(str(refused)) < 400, str(refused)
    assert capfd.readouterr().err == ""
