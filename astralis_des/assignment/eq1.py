"""Eq. 1: E(i, j) = d(i, j) / mean_k d(i, k) + risk(j) W1(i) + messiness(j) W2(i)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from astralis_des.kinds import KIND_DEFAULTS


@dataclass(frozen=True)
class Agent:
    id: str
    kind: str
    position: tuple[float, float, float]


@dataclass(frozen=True)
class RoomInfo:
    id: str
    position: tuple[float, float, float]
    risk: float
    messiness: float
    area: float = 0.0  # m^2 of floor: what the queue planners' search times scale with


@dataclass(frozen=True)
class Weights:
    """W1 (on risk) and W2 (on messiness) per agent kind."""

    risk: Mapping[str, float]
    messiness: Mapping[str, float]

    @classmethod
    def zero(cls) -> Weights:
        return cls({}, {})

    def of(self, kind: str) -> tuple[float, float]:
        """``kind``'s W1 and W2: its own where set, else those of the kind its record reads
        (:attr:`astralis_des.kinds.KindDefaults.weights`), else 0."""
        like = KIND_DEFAULTS[kind].weights if kind in KIND_DEFAULTS else None

        def one(w: Mapping[str, float]) -> float:
            if kind in w:
                return float(w[kind])
            return float(w.get(like, 0.0)) if like is not None else 0.0

        return one(self.risk), one(self.messiness)


def distances(agents: Sequence[Agent], rooms: Sequence[RoomInfo]) -> NDArray[np.float64]:
    """``(A, R)``: l2 for UAVs, Manhattan for the UGV and the human (their paths bend)."""
    a = np.array([ag.position for ag in agents], dtype=float)
    r = np.array([rm.position for rm in rooms], dtype=float)
    delta = np.abs(a[:, None, :] - r[None, :, :])
    l2 = np.sqrt((delta**2).sum(axis=2))
    l1 = delta.sum(axis=2)
    manhattan = np.array([KIND_DEFAULTS[ag.kind].distance == "manhattan" for ag in agents])
    return np.where(manhattan[:, None], l1, l2)


def eq1_costs(agents: Sequence[Agent], rooms: Sequence[RoomInfo],
              weights: Weights) -> NDArray[np.float64]:
    """The ``(A, R)`` matrix of Eq. 1, each agent's distances normalised by their mean."""
    d = distances(agents, rooms)
    mean = d.mean(axis=1, keepdims=True)
    norm = np.divide(d, mean, out=np.zeros_like(d), where=mean > 0)
    risk = np.array([rm.risk for rm in rooms])
    mess = np.array([rm.messiness for rm in rooms])
    w = np.array([weights.of(ag.kind) for ag in agents], dtype=float).reshape(len(agents), 2)
    w1, w2 = w[:, 0], w[:, 1]
    return np.asarray(norm + w1[:, None] * risk[None, :] + w2[:, None] * mess[None, :])
