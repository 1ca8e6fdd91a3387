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
    name: str  # as registered
    workers: int

    def run(self, study: Study, chunks: Sequence[list[int]],
            recordings: Path | None) -> Generator[ChunkResult, None, None]: ...

    def hold(self, base: Study) -> None:
        """Keep the workers for the runs that follow, of studies made from ``base`` by
        ``with_changes`` (a tune's trials), until :meth:`close`."""

    def close(self) -> None: ...


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


_MADE: list[tuple[dict[str, Any], Study]] = []  # a held pool's worker: the last study it made


def _changed_chunk_in_worker(job: tuple[dict[str, Any], list[int], Path | None]) -> ChunkResult:
    """A chunk of ``_STUDY.with_changes(**changes)``, the study made once per worker and run."""
    assert _STUDY is not None
    changes, indices, recordings = job
    if not _MADE or _MADE[0][0] != changes:
        _MADE[:] = [(changes, _STUDY.with_changes(**changes))]
    return run_chunk(_MADE[0][1], indices, recordings)


class LocalBackend:
    """This process for one worker, else a pool of processes that each get the study once."""

    name = "local"

    def __init__(self, workers: int, address: str | None = None) -> None:
        if address is not None:
            raise InputError("the local backend takes no address (it is for ray)",
                             key="address")
        self.workers = max(1, workers)
        self._held: tuple[Study, Any] | None = None  # the base study and its pool

    def hold(self, base: Study) -> None:
        """One pool for the runs that follow, its workers holding ``base``: a study made from
        it by ``with_changes`` is sent as its changes, and what the workers keep on the world
        (free floor, furnished rooms) lasts from one run to the next."""
        self.close()
        if self.workers > 1:
            pool = multiprocessing.get_context("fork").Pool(
                self.workers, initializer=_take_study, initargs=(base,))
            self._held = (base, pool)

    def close(self) -> None:
        if self._held is not None:
            self._held[1].terminate()
            self._held[1].join()
            self._held = None

    def run(self, study: Study, chunks: Sequence[list[int]],
            recordings: Path | None) -> Generator[ChunkResult, None, None]:
        if self.workers == 1 or len(chunks) == 1:
            for chunk in chunks:
                yield run_chunk(study, chunk, recordings)
            return
        held = self._held
        if held is not None and study.origin is not None and study.origin[0] is held[0]:
            changes = study.origin[1]
            yield from held[1].imap_unordered(_changed_chunk_in_worker,
                                              [(changes, c, recordings) for c in chunks])
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

    name = "ray"

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

    def hold(self, base: Study) -> None:
        """Nothing kept: each run starts its actors (a cluster's are shared)."""

    def close(self) -> None:
        pass


BACKENDS.register("ray")(RayBackend)
