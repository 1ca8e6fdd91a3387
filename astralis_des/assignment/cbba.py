"""``cbba``: the consensus-based bundle algorithm (Choi, Brunet and How, "Consensus-Based
Decentralized Auctions for Robust Task Allocation", IEEE T-RO 25(4), 2009; a plug-in of SPACE).

Each agent builds a bundle of up to ``options.bundle`` rooms (default 3), adding the room whose
best insertion into its path raises its score most, while that beats the highest bid it knows
for the room; its score is a time-discounted reward, ``sum discount ** finish_time`` over its
path (finish times from :mod:`.durations`), which has the diminishing marginal gain CBBA needs
to converge. The agents then tell their neighbours their winning bids, winners and the times
of their news, and each applies the paper's decision table (Table 1: update, reset or leave)
room by room; an agent outbid for a room drops it and every room it added after it. The two
phases repeat until nothing changes. Neighbours: every agent (``options.comm_range`` unset), or
those within ``comm_range`` metres of each other at the round's start. The round reports its
iterations and the messages sent; a room two parts of a split graph both won goes to the higher
bid (a ``conflicts`` count).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from astralis_des.assignment.plans import Plan, Problem
from astralis_des.assignment.strategies import register_planner

NONE = -1  # no winner known
MAX_ITERATIONS = 500


@dataclass
class Agent:
    """One agent's view: its bundle (in the order added), its path (in the order searched),
    the winning bid ``y`` and winner ``z`` it believes for each room, and ``s``, the time of
    its latest news from each agent."""

    index: int
    bundle: list[int] = field(default_factory=list)
    path: list[int] = field(default_factory=list)
    y: np.ndarray = field(default_factory=lambda: np.zeros(0))
    z: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    s: np.ndarray = field(default_factory=lambda: np.zeros(0))


class CBBA:
    """The algorithm's state, one phase at a time (a test can check each step)."""

    def __init__(self, problem: Problem) -> None:
        self.problem = problem
        self.n_a, self.n_r = problem.allowed.shape
        self.bundle_size = int(problem.options.get("bundle", 3))
        self.discount = float(problem.options.get("discount", 0.99))
        comm = problem.options.get("comm_range")
        starts = np.array([a.position for a in problem.agents], dtype=float).reshape(-1, 3)
        gap = np.linalg.norm(starts[:, None, :] - starts[None, :, :], axis=2)
        self.links = (gap <= float(comm)) if comm is not None else \
            np.ones((self.n_a, self.n_a), dtype=bool)
        np.fill_diagonal(self.links, False)
        self.agents = [Agent(i, y=np.zeros(self.n_r), z=np.full(self.n_r, NONE),
                             s=np.zeros(self.n_a)) for i in range(self.n_a)]
        self.search = problem.search_times
        self.travel = problem.room_legs  # [i][from room, to room]
        self.first = problem.first_legs
        self.iteration = 0
        self.messages = 0

    # -- scores ----------------------------------------------------------------------------
    def score(self, i: int, path: list[int]) -> float:
        """The time-discounted reward of ``path`` for agent ``i``."""
        t, total, last = 0.0, 0.0, None
        for j in path:
            t += (self.first[i][j] if last is None else self.travel[i][last, j]) + \
                self.search[i, j]
            total += self.discount ** t
            last = j
        return total

    def best_insertion(self, i: int, j: int) -> tuple[float, int]:
        """The most room ``j`` adds to agent ``i``'s path, and where it goes."""
        path = self.agents[i].path
        base = self.score(i, path)
        best, where = -np.inf, 0
        for n in range(len(path) + 1):
            gain = self.score(i, path[:n] + [j] + path[n:]) - base
            if gain > best + 1e-12:
                best, where = gain, n
        return best, where

    @staticmethod
    def outbids(y1: float, a1: int, y2: float, a2: int) -> bool:
        """A bid ``y1`` of agent ``a1`` beats ``y2`` of ``a2`` (ties: the lower index)."""
        if a2 == NONE:
            return y1 > 0
        return y1 > y2 or (y1 == y2 and a1 < a2)

    # -- phase 1 ---------------------------------------------------------------------------
    def build_bundle(self, i: int) -> None:
        me = self.agents[i]
        while len(me.bundle) < self.bundle_size:
            best, pick, where = 0.0, NONE, 0
            for j in range(self.n_r):
                if j in me.bundle or not self.problem.allowed[i, j]:
                    continue
                gain, n = self.best_insertion(i, j)
                if self.outbids(gain, i, me.y[j], int(me.z[j])) and gain > best:
                    best, pick, where = gain, j, n
            if pick == NONE:
                return
            me.bundle.append(pick)
            me.path.insert(where, pick)
            me.y[pick], me.z[pick] = best, i

    # -- phase 2 ---------------------------------------------------------------------------
    def consensus(self) -> None:
        """Every agent hears its neighbours (what they believed before this exchange)."""
        self.iteration += 1
        sent = [(a.y.copy(), a.z.copy(), a.s.copy()) for a in self.agents]
        for i, me in enumerate(self.agents):
            for k in np.flatnonzero(self.links[i]):
                self.messages += 1
                yk, zk, sk = sent[k]
                sk = sk.copy()
                sk[k] = self.iteration  # the news is fresh from k itself
                for j in range(self.n_r):
                    self.resolve(me, int(k), j, float(yk[j]), int(zk[j]), sk)
                me.s = np.maximum(me.s, sk)
                me.s[k] = self.iteration
            self.release_outbid(me)

    def resolve(self, me: Agent, k: int, j: int, yk: float, zk: int, sk: np.ndarray) -> None:
        """Table 1 of the paper for room ``j``: what agent ``me`` does with ``k``'s news."""
        i, zi, yi = me.index, int(me.z[j]), float(me.y[j])
        sender = _sender(zk, k, i)
        receiver = _receiver(zi, i, k, zk if sender == "m" else None)
        news = Bids(yk, zk, yi, zi, k, i, sk, me.s, self.outbids)
        action = TABLE_1.get((sender, receiver), _leave)(news)
        if action == "update":
            me.y[j], me.z[j] = yk, zk
        elif action == "reset":
            me.y[j], me.z[j] = 0.0, NONE

    @staticmethod
    def release_outbid(me: Agent) -> None:
        """Drop the first room of the bundle the agent lost, and every room added after it
        (their scores assumed it)."""
        lost = next((n for n, j in enumerate(me.bundle) if me.z[j] != me.index), None)
        if lost is None:
            return
        for j in me.bundle[lost + 1:]:
            if me.z[j] == me.index:
                me.y[j], me.z[j] = 0.0, NONE
        for j in me.bundle[lost:]:
            me.path.remove(j)
        del me.bundle[lost:]

    def run(self) -> bool:
        """Both phases until nothing changes; False if ``MAX_ITERATIONS`` ran out first."""
        for _ in range(MAX_ITERATIONS):
            before = self.state()
            for i in range(self.n_a):
                self.build_bundle(i)
            self.consensus()
            if self.state() == before:
                return True
        return False

    def state(self) -> tuple[object, ...]:
        return tuple((tuple(a.bundle), tuple(a.z.tolist()), tuple(a.y.tolist()))
                     for a in self.agents)


def _sender(zk: int, k: int, i: int) -> str:
    """Whom the sender ``k`` names as the winner: itself, the receiver, a third agent, none."""
    return "none" if zk == NONE else {k: "k", i: "i"}.get(zk, "m")


def _receiver(zi: int, i: int, k: int, m: int | None) -> str:
    """Whom the receiver ``i`` names: itself, the sender, the sender's third agent ``m`` (or,
    when the sender names none, any other agent), a fourth agent ``n``, or none."""
    if zi == NONE:
        return "none"
    if zi in (i, k):
        return "i" if zi == i else "k"
    return "m" if m is None or zi == m else "n"


@dataclass(frozen=True)
class Bids:
    """What a rule of Table 1 reads: the sender's bid and winner, the receiver's, and their
    news times."""

    yk: float
    zk: int
    yi: float
    zi: int
    k: int
    i: int
    sk: np.ndarray
    si: np.ndarray
    outbids: Callable[[float, int, float, int], bool]

    def newer(self, agent: int) -> bool:
        """The sender has later news of ``agent`` than the receiver."""
        return bool(self.sk[agent] > self.si[agent])


def _leave(b: Bids) -> str:
    return "leave"


def _update(b: Bids) -> str:
    return "update"


def _reset(b: Bids) -> str:
    return "reset"


def _if(test: Callable[[Bids], bool], then: str, otherwise: str = "leave") -> Rule:
    return lambda b: then if test(b) else otherwise


Rule = Callable[[Bids], str]
# (whom the sender k names as winner, whom the receiver i names) -> the receiver's action
TABLE_1: dict[tuple[str, str], Rule] = {
    ("k", "i"): _if(lambda b: b.outbids(b.yk, b.k, b.yi, b.i), "update"),
    ("k", "k"): _update,
    ("k", "m"): _if(lambda b: b.newer(b.zi) or b.outbids(b.yk, b.k, b.yi, b.zi), "update"),
    ("k", "none"): _update,
    ("i", "i"): _leave,
    ("i", "k"): _reset,
    ("i", "m"): _if(lambda b: b.newer(b.zi), "reset"),
    ("i", "none"): _leave,
    ("m", "i"): _if(lambda b: b.newer(b.zk) and b.outbids(b.yk, b.zk, b.yi, b.i), "update"),
    ("m", "k"): _if(lambda b: b.newer(b.zk), "update", "reset"),
    ("m", "m"): _if(lambda b: b.newer(b.zk), "update"),
    ("m", "n"): lambda b: (
        "update" if b.newer(b.zk) and (b.newer(b.zi) or b.outbids(b.yk, b.zk, b.yi, b.zi))
        else "reset" if b.newer(b.zi) and b.si[b.zk] > b.sk[b.zk] else "leave"),
    ("m", "none"): _if(lambda b: b.newer(b.zk), "update"),
    ("none", "i"): _leave,
    ("none", "k"): _update,
    ("none", "m"): _if(lambda b: b.newer(b.zi), "update"),
    ("none", "none"): _leave,
}


@register_planner("cbba", whole_mission=True, options=("bundle", "comm_range", "discount"))
def cbba(problem: Problem) -> Plan:
    """The consensus-based bundle algorithm over every pending room of the mission: bundles of
    up to ``bundle`` rooms, a time-discounted reward, agents within ``comm_range`` talking."""
    run = CBBA(problem)
    converged = run.run()
    owner: dict[int, int] = {}
    conflicts = 0
    for a in run.agents:  # a split graph may leave a room with two winners: the higher bid
        for j in a.path:
            other = owner.get(j)
            if other is not None:
                conflicts += 1
                if not run.outbids(float(a.y[j]), a.index, float(run.agents[other].y[j]),
                                   other):
                    continue
            owner[j] = a.index
    queues = [[j for j in a.path if owner.get(j) == a.index] for a in run.agents]
    info = {"iterations": run.iteration, "messages": run.messages, "converged": converged}
    if conflicts:
        info["conflicts"] = conflicts
    return Plan(queues, info)
