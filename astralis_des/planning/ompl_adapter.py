"""OMPL behind one module, the only one that speaks its camelCase API.

``plan_3d`` plans for a point in a box of R^3 (RRTConnect, or informed RRT* for shorter paths);
``plan_se2`` for a car-like body on a floor, in Reeds-Shepp or Dubins space. Validity is a
vectorised callable, ``valid(states (N, 3)) -> (N,) bool``. A motion is checked in one call on
its states every ``resolution`` metres (of arc, in SE2), so a costly ``valid`` is paid per
motion rather than per state; the returned states are some of those very samples, so every one
of them was checked. Ordinary failures (a start in a wall, no path in time) are a :class:`Plan`
with a reason.

Determinism: the same inputs and seed give the same path in any process. OMPL draws the seed of
every random generator it makes (planner, samplers, simplifier) from one process-wide seed
generator; each plan reseeds it, then makes all of its OMPL objects afresh. What is left:

- the wall-clock budget. RRTConnect stops at its first solution, so its path is reproducible
  whenever it is found within the budget. Informed RRT* improves its path until it stops; it
  stops after ``iterations`` iterations or at the budget, whichever comes first, and only a path
  that the iteration count ended is reproducible.
- simplification is one round of OMPL's simplifier, bounded in work rather than time (so
  ``seconds`` may exceed the budget by it). Should its smoothing step a motion onto states that
  fail the checks, the vertex-reduced path is kept instead.
- the seed generator is process-wide: plans running at once in threads interleave their draws.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import ompl.base as ob
import ompl.geometric as og
import ompl.util as ou
from numpy.typing import ArrayLike, NDArray

from astralis_des.world.geometry import FloatArray

Validity = Callable[[FloatArray], NDArray[np.bool_]]

PLANNERS = ("rrtconnect", "informed_rrtstar")
SPACES = ("reedsshepp", "dubins")
WAYPOINT_SPACING = 1.0  # m, at most, between consecutive points of a 3-D path
CURVE_SPACING = 0.25  # m of arc, at most, between consecutive states of an SE2 path

ou.setLogLevel(ou.LOG_WARN)


@dataclass(frozen=True)
class Plan:
    """A planned path, or why there is none; ``seconds`` is the wall time spent planning."""

    ok: bool
    path: FloatArray | None  # (N, 3): x, y, z in 3-D; x, y, yaw in SE2
    reason: str = ""
    seconds: float = 0.0
    length: float = 0.0  # m along the path (for SE2, along its curves)


def plan_3d(valid: Validity, lo: ArrayLike, hi: ArrayLike, start: ArrayLike, goal: ArrayLike,
            *, budget: float, planner: str = "rrtconnect", seed: int = 0,
            resolution: float = 0.05, iterations: int = 2000,
            max_step: float | None = None) -> Plan:
    """A collision-free polyline from ``start`` to ``goal`` inside ``lo`` to ``hi``.

    Consecutive points are at most ``WAYPOINT_SPACING`` apart. ``iterations`` bounds informed
    RRT*. ``max_step`` is the longest motion the planner tries at once (OMPL's range; by
    default a fifth of the bounds' diagonal): about a room's size suits a building's rooms and
    doors. With ``valid`` read from a voxel map, a ``resolution`` of a quarter voxel keeps the
    segments between checked points from cutting the corner of a voxel.
    """
    t0 = time.perf_counter()
    _check_choice("planner", planner, PLANNERS)
    points = np.array([start, goal], dtype=float).reshape(2, 3)
    failure = _check_request(valid, points, points, lo, hi, budget)
    if failure:
        return Plan(False, None, failure, time.perf_counter() - t0)
    _seed(seed)
    space = ob.RealVectorStateSpace(3)
    space.setBounds(_bounds(lo, hi))
    motions = _Straight(valid, resolution)
    return _plan(space, motions, _real_states(space, points), planner, iterations, max_step,
                 WAYPOINT_SPACING, budget, t0)


def plan_se2(valid: Validity, lo2: ArrayLike, hi2: ArrayLike, start: ArrayLike,
             goal: ArrayLike, *, turning_radius: float, budget: float,
             space: str = "reedsshepp", seed: int = 0, resolution: float = 0.05) -> Plan:
    """Poses ``(x, y, yaw)`` from ``start`` to ``goal`` along curves of ``turning_radius``.

    Reeds-Shepp curves may reverse, Dubins curves only go forward. Consecutive states are at
    most ``CURVE_SPACING`` metres of arc apart; yaws are in ``[-pi, pi)``.
    """
    t0 = time.perf_counter()
    _check_choice("space", space, SPACES)
    poses = np.array([start, goal], dtype=float).reshape(2, 3)
    poses[:, 2] = (poses[:, 2] + math.pi) % (2 * math.pi) - math.pi
    failure = _check_request(valid, poses, poses[:, :2], lo2, hi2, budget)
    if failure:
        return Plan(False, None, failure, time.perf_counter() - t0)
    _seed(seed)
    se2 = ob.ReedsSheppStateSpace(turning_radius) if space == "reedsshepp" else \
        ob.DubinsStateSpace(turning_radius)
    se2.setBounds(_bounds(lo2, hi2))
    motions = _Curved(valid, resolution, se2)
    return _plan(se2, motions, _se2_states(se2, poses), "rrtconnect", 0, None, CURVE_SPACING,
                 budget, t0)


class _Straight:
    """Motions in R^3: straight segments, sampled every ``step`` metres."""

    def __init__(self, valid: Validity, step: float) -> None:
        self.valid, self.step = valid, step

    def samples(self, s1: Any, s2: Any, step: float = 0.0) -> FloatArray:
        """``(n, 3)`` states at ``k / n`` of the motion, ``k = 1 .. n``, ``step`` apart at most
        (by default the checking resolution)."""
        a = (s1[0], s1[1], s1[2])
        d = (s2[0] - a[0], s2[1] - a[1], s2[2] - a[2])
        n = max(math.ceil(math.hypot(*d) / (step or self.step)), 1)
        return np.multiply.outer(np.arange(1, n + 1) / n, d) + a

    def values(self, state: Any) -> tuple[float, float, float]:
        return (state[0], state[1], state[2])


class _Curved(_Straight):
    """Motions in SE2: the space's shortest curves, sampled every ``step`` metres of arc."""

    def __init__(self, valid: Validity, step: float, space: Any) -> None:
        super().__init__(valid, step)
        self.space = space
        self.scratch = space.allocState()

    def samples(self, s1: Any, s2: Any, step: float = 0.0) -> FloatArray:
        n = max(math.ceil(self.space.distance(s1, s2) / (step or self.step)), 1)
        out = np.empty((n, 3))
        s = self.scratch
        for k in range(n):
            self.space.interpolate(s1, s2, (k + 1) / n, s)
            out[k] = s.getX(), s.getY(), s.getYaw()
        return out

    def values(self, state: Any) -> tuple[float, float, float]:
        return (state.getX(), state.getY(), state.getYaw())


class _MotionValidator(ob.MotionValidator):
    """A motion is valid when all of its samples are: one call of ``valid`` per motion."""

    def __init__(self, si: Any, motions: _Straight) -> None:
        super().__init__(si)
        self.motions = motions

    def checkMotion(self, s1: Any, s2: Any, *_: Any) -> bool:
        return bool(self.motions.valid(self.motions.samples(s1, s2)).all())


def _plan(space: Any, motions: _Straight, states: tuple[Any, Any], planner: str,
          iterations: int, max_step: float | None, spacing: float, budget: float,
          t0: float) -> Plan:
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(
        lambda s: bool(motions.valid(np.array([motions.values(s)]))[0]))
    si.setStateValidityCheckingResolution(min(motions.step / space.getMaximumExtent(), 1.0))
    validator = _MotionValidator(si, motions)  # kept alive here while OMPL holds it
    si.setMotionValidator(validator)
    si.setup()
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(*states)
    solver, stop = _solver(si, pdef, planner, iterations, max_step,
                           budget - (time.perf_counter() - t0))
    status = solver.solve(stop) if stop is not None else None
    if status is None or not pdef.hasExactSolution():
        return Plan(False, None, _why_not(status, solver, planner, iterations, budget),
                    time.perf_counter() - t0)
    path = _simplified(si, pdef.getSolutionPath(), motions)
    return Plan(True, _states_along(path, motions, spacing), "", time.perf_counter() - t0,
                float(path.length()))


def _solver(si: Any, pdef: Any, planner: str, iterations: int, max_step: float | None,
            budget: float) -> tuple[Any, Any]:
    """The planner, set up, and when it must stop (None: no time is left)."""
    if planner == "informed_rrtstar":
        pdef.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
        solver = og.InformedRRTstar(si)
    else:
        solver = og.RRTConnect(si)
    if max_step is not None:
        solver.setRange(max_step)
    solver.setProblemDefinition(pdef)
    solver.setup()
    if budget <= 0:
        return solver, None
    stop = ob.timedPlannerTerminationCondition(budget)
    if planner == "informed_rrtstar":
        done = ob.PlannerTerminationCondition(lambda: solver.numIterations() >= iterations)
        stop = ob.plannerOrTerminationCondition(stop, done)
    return solver, stop


def _simplified(si: Any, path: Any, motions: _Straight) -> Any:
    """The path with shortcuts taken: one round of OMPL's simplifier, bounded in work."""
    simplifier = og.PathSimplifier(si)
    simplifier.reduceVertices(path)  # keeps only motions checked as they are
    smooth = og.PathGeometric(path)
    simplifier.simplify(smooth, ob.plannerAlwaysTerminatingCondition(), True)
    states = smooth.getStates()
    checked = [motions.samples(a, b) for a, b in itertools.pairwise(states)]
    return smooth if bool(motions.valid(np.vstack(checked)).all()) else path


def _states_along(path: Any, motions: _Straight, spacing: float) -> FloatArray:
    """States along the path at most ``spacing`` apart: checked samples when they are dense
    enough (every ``stride``-th of each motion, and its last), else samples that far apart."""
    states = path.getStates()
    out = [np.array([motions.values(states[0])])]
    stride = int(spacing / motions.step + 1e-9)
    for a, b in itertools.pairwise(states):
        if stride < 1:
            out.append(motions.samples(a, b, spacing))
            continue
        samples = motions.samples(a, b)
        k = np.arange(1, len(samples) + 1)
        out.append(samples[(k % stride == 0) | (k == len(samples))])
    return np.vstack(out)


def _why_not(status: Any, solver: Any, planner: str, iterations: int, budget: float) -> str:
    if status is not None and status.getStatus() not in (
            ob.PlannerStatus.TIMEOUT, ob.PlannerStatus.APPROXIMATE_SOLUTION):
        return f"the planner failed: {status.asString().lower()}"
    if planner == "informed_rrtstar" and solver.numIterations() >= iterations:
        return f"no path found within {iterations} iterations"
    return f"no path found within {budget:g} s"


def _check_request(valid: Validity, states: FloatArray, points: FloatArray, lo: ArrayLike,
                   hi: ArrayLike, budget: float) -> str:
    """Why the request fails before planning ("" if it does not)."""
    if not budget > 0:
        return f"time budget must be positive (got {budget:g} s)"
    inside = np.all((points >= np.asarray(lo, dtype=float)) &
                    (points <= np.asarray(hi, dtype=float)), axis=1)
    ok = np.asarray(valid(states), dtype=bool)
    for k, which in enumerate(("start", "goal")):
        if not inside[k]:
            return f"{which} outside the planning bounds"
        if not ok[k]:
            return f"{which} in collision"
    return ""


def _check_choice(what: str, name: str, choices: tuple[str, ...]) -> None:
    if name not in choices:
        raise ValueError(f"unknown {what} {name!r}; expected one of {', '.join(choices)}")


def _seed(seed: int) -> None:
    """Reseed OMPL's seed generator; every generator made afterwards draws from it."""
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_NONE)  # reseeding once generators exist is logged as an error
    try:
        ou.RNG.setSeed(seed % (2**32 - 1) + 1)  # OMPL refuses a seed of 0
    finally:
        ou.setLogLevel(level)


def _bounds(lo: ArrayLike, hi: ArrayLike) -> Any:
    lo_, hi_ = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    bounds = ob.RealVectorBounds(len(lo_))
    for i, (a, b) in enumerate(zip(lo_, hi_, strict=True)):
        bounds.setLow(i, float(a))
        bounds.setHigh(i, float(b))
    return bounds


def _real_states(space: Any, points: FloatArray) -> tuple[Any, Any]:
    states = space.allocState(), space.allocState()
    for state, point in zip(states, points, strict=True):
        for i in range(3):
            state[i] = float(point[i])
    return states


def _se2_states(space: Any, poses: FloatArray) -> tuple[Any, Any]:
    states = space.allocState(), space.allocState()
    for state, (x, y, yaw) in zip(states, poses, strict=True):
        state.setX(float(x))
        state.setY(float(y))
        state.setYaw(float(yaw))
    return states
