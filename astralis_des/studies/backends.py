"""Where a study's chunks run, by registry: ``local`` (a process pool) and ``ray``.

A backend takes the study once per worker and yields chunk results as they finish; the runner
puts the rows back in order.
"""

from __future__ import annotations

import logging
import multiprocessing
from collections.abc import Callable, Generator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from astralis_des.errors import InputError
from astralis_des.exits import default_termination
from astralis_des.registry import Registry, UnknownEntry
from astralis_des.studies.scenarios import ChunkResult, run_chunk

if TYPE_CHECKING:
    from astralis_des.studies.spec import Study

log = logging.getLogger(__name__)


class Backend(Protocol):
    workers: int

    def run(self, study: Study, chunks: Sequence[list[int]],
            recordings: Path | None) -> Generator[ChunkResult, None, None]: ...


BACKENDS: Registry[str, Callable[[int, str | None], Backend]] = Registry("study backend")


def make_backend(name: str, workers: int, address: str | None = None) -> Backend:
    try:
        return BACKENDS.get(name)(workers, address)
    except UnknownEntry as exc:
        raise InputError(str(exc), key="backend") from None


# -- local: one process, or a process pool ---------------------------------------------------
_STUDY: Study | None = None  # the study a pool worker runs, set once by its initializer


def _take_study(study: Study) -> None:
    global _STUDY
    _STUDY = study
    default_termination()  # the pool ends its workers with SIGTERM: no interrupt there


def _chunk_in_worker(job: tuple[list[int], Path | None]) -> ChunkResult:
    assert _STUDY is not None
    return run_chunk(_STUDY, *job)


class LocalBackend:
    """This process for one worker, else a pool of processes that each get the study once."""

    def __init__(self, workers: int, address: str | None = None) -> None:
        if address is not None:
            raise InputError("the local backend takes no address (it is for ray)",
                             key="address")
        self.workers = max(1, workers)

    def run(self, study: Study, chunks: Sequence[list[int]],
            recordings: Path | None) -> Generator[ChunkResult, None, None]:
        if self.workers == 1 or len(chunks) == 1:
            for chunk in chunks:
                yield run_chunk(study, chunk, recordings)
            return
        # Leaving the pool's block terminates its workers, also on Ctrl-C or an error.
        with multiprocessing.get_context("fork").Pool(
                min(self.workers, len(chunks)), initializer=_take_study,
                initargs=(study,)) as pool:
            yield from pool.imap_unordered(_chunk_in_worker, [(c, recordings) for c in chunks])


BACKENDS.register("local")(LocalBackend)


# -- ray: a local instance, or an existing cluster ----------------------------------------
class _RayWorker:
    """A Ray actor holding the study, so each chunk sends only its indices."""

    def __init__(self, study: Study) -> None:
        self.study = study

    def run(self, indices: list[int], recordings: Path | None) -> ChunkResult:
        return run_chunk(self.study, indices, recordings)


class RayBackend:
    """``ray.init(address=...)`` for an existing cluster, else a local instance of ``workers``
    CPUs; one actor per CPU (as many as the cluster has, with an address)."""

    def __init__(self, workers: int, address: str | None = None) -> None:
        try:
            import ray  # noqa: F401
        except ImportError:
            raise InputError("the ray backend needs the optional extra: "
                             "pip install 'astralis-des[ray]'", key="backend") from None
        self.workers = max(1, workers)
        self.address = address

    def run(self, study: Study, chunks: Sequence[list[int]],
            recordings: Path | None) -> Generator[ChunkResult, None, None]:
        import ray
        from ray.util import ActorPool

        started = not ray.is_initialized()
        if started:
            options: dict[str, Any] = {"include_dashboard": False, "logging_level": "ERROR",
                                       "log_to_driver": False}
            if self.address is None:
                options["num_cpus"] = self.workers
            ray.init(address=self.address, **options)
        actors: list[Any] = []
        try:
            if self.address is not None:
                self.workers = max(1, int(ray.cluster_resources().get("CPU", self.workers)))
            ref = ray.put(study)
            actor: Any = ray.remote(num_cpus=1)(_RayWorker)
            actors += [actor.remote(ref) for _ in range(min(self.workers, len(chunks)))]
            pool = ActorPool(actors)
            yield from pool.map_unordered(
                lambda a, chunk: a.run.remote(chunk, recordings), list(chunks))
        finally:
            for a in actors:
                ray.kill(a)
            if started:
                ray.shutdown()


BACKENDS.register("ray")(RayBackend)
