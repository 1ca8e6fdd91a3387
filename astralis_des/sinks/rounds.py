"""Each assignment round in the recording, at its time: the matrix of Eq. 1's costs (agents
down, rooms across, each cell coloured from the round's cheapest to its dearest and labelled
with its cost, the chosen pairs outlined in green), readable with 16 agents and 18 rooms; and
for a small team, the round's bipartite graph as well."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pyarrow as pa

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.sinks import paths
from astralis_des.sinks.columns import (
    colors,
    descriptor,
    flags,
    floats,
    offsets,
    rows,
    send,
    texts,
    times,
    vectors,
)

GRAPH_AGENTS = 6  # up to this many agents in the team, the rounds are drawn as graphs too
NARROW = 6  # rooms: up to this many in a round, every cell of its matrix shows its cost
CHEAP, DEAR = np.array((40.0, 110.0, 190.0)), np.array((190.0, 70.0, 40.0))  # cost -> colour
NO_COST = (70, 70, 70)  # a pair the strategy could not price
CHOSEN = (60, 230, 90)
NAME_COLOR = (220, 220, 220)
CHAR = 0.3  # a label's character, in rows' heights (a row is about 24 px on screen)


def log_rounds(rec: Any, rounds: Sequence[Mapping[str, Any]],
               kinds: Mapping[str, str], graph: bool) -> None:
    """Every round's matrix at ``mission/assignment/matrix``, and with ``graph`` its graph at
    ``mission/assignment/graph``."""
    log_matrices(rec, [Matrix.of(record, kinds) for record in rounds
                       if record["agents"] and record["rooms"]])
    if graph and rounds:
        log_graphs(rec, [record["t"] for record in rounds],
                   [Graph.of(record, kinds) for record in rounds])


@dataclass(frozen=True)
class Grid:
    """Where a round's matrix is drawn in its 2-D view (y down): a row one unit high per
    agent, a column ``cell`` wide per room, the agents' names on the left, the rooms' above
    (on two lines, staggered, when the columns are narrow) under the round's title."""

    agents: int
    rooms: int
    widest: int = 4  # characters of the longest agent's name

    @property
    def narrow(self) -> bool:
        return self.rooms <= NARROW

    @property
    def cell(self) -> float:
        return 2.0 if self.narrow else 1.4

    @property
    def lines(self) -> int:
        return 1 if self.narrow else 2

    def cell_top(self, i: int, j: int) -> tuple[float, float]:
        """Where a cell's label goes: the viewer hangs a point's label from the point, so at
        the cell's top the label fills the cell."""
        return ((j + 0.5) * self.cell, float(i))

    def bounds(self) -> tuple[float, float, float, float]:
        """x from, x to, y from, y to: what the view shows."""
        return (-CHAR * self.widest - 0.6, self.rooms * self.cell + 0.1, -self.lines - 1.1,
                self.agents + 0.1)

    @staticmethod
    def largest(rounds: Sequence[Mapping[str, Any]]) -> Grid:
        """The grid that holds every round's matrix."""
        return Grid(max((len(r["agents"]) for r in rounds), default=1),
                    max((len(r["rooms"]) for r in rounds), default=1),
                    max((len(a) for r in rounds for a in r["agents"]), default=4))


def cost_text(cost: float | None) -> str:
    """A cost in at most four characters where it can: ``0.72``, ``3.80``, ``10.3``, ``124``
    (``-`` for none)."""
    if cost is None:
        return "-"
    return f"{cost:.2f}" if abs(cost) < 10 else f"{cost:.1f}" if abs(cost) < 100 \
        else f"{cost:.0f}"


def shades(costs: np.ndarray) -> np.ndarray:
    """RGB of each cost, blue for the round's cheapest to red for its dearest; grey where a
    cost is missing (NaN)."""
    known = np.isfinite(costs)
    lo, hi = (costs[known].min(), costs[known].max()) if known.any() else (0.0, 1.0)
    share = np.where(known, (np.nan_to_num(costs, nan=lo) - lo) / max(hi - lo, 1e-9), 0.0)
    rgb = CHEAP + share[..., None] * (DEAR - CHEAP)
    rgb[~known] = NO_COST
    return rgb.astype(np.uint8)


@dataclass(frozen=True)
class Matrix:
    """What a round's matrix draws, at time ``t``: the heat map (a pixel per cell, stretched
    ``grid.cell`` wide), the labelled points (costs: all, or the chosen pairs' when the columns
    are narrow), the chosen cells, the names (agents, rooms, the round's title) and their
    colours."""

    t: float
    grid: Grid
    heat: np.ndarray
    costs: list[tuple[tuple[float, float], str]]
    chosen: list[tuple[float, float]]
    names: list[tuple[tuple[float, float], str, tuple[int, int, int]]]

    @staticmethod
    def of(record: Mapping[str, Any], kinds: Mapping[str, str]) -> Matrix:
        agents, rooms = list(record["agents"]), list(record["rooms"])
        grid = Grid(len(agents), len(rooms), max((len(a) for a in agents), default=4))
        cell = record["costs"]
        heat = shades(np.array([[np.nan if c is None else c for c in row] for row in cell],
                               dtype=float).reshape(len(agents), len(rooms)))
        row = {agent: i for i, agent in enumerate(agents)}
        column = {room: j for j, room in enumerate(rooms)}
        picked = [(row[m["agent"]], column[m["room"]]) for m in record["matching"]]
        shown = [(i, j) for i in range(len(agents)) for j in range(len(rooms))] \
            if grid.narrow else picked
        title = f"round {record['round']}, {record['segment']} ({len(agents)} x {len(rooms)})"
        names = [((-0.3 - CHAR * grid.widest / 2, float(i)), a, _color(kinds.get(a)))
                 for i, a in enumerate(agents)]
        names += [(((j + 0.5) * grid.cell, -1.0 - j % grid.lines), r, NAME_COLOR)
                  for j, r in enumerate(rooms)]
        names.append(((len(rooms) * grid.cell / 2, -1.0 - grid.lines), title, NAME_COLOR))
        return Matrix(record["t"], grid, heat,
                      [(grid.cell_top(i, j), cost_text(cell[i][j])) for i, j in shown],
                      [((j + 0.5) * grid.cell, i + 0.5) for i, j in picked], names)


IMAGE_FORMAT = pa.struct([pa.field("width", pa.uint32(), nullable=False),
                          pa.field("height", pa.uint32(), nullable=False),
                          pa.field("pixel_format", pa.uint8()),
                          pa.field("color_model", pa.uint8()),
                          pa.field("channel_datatype", pa.uint8())])
RGB, U8 = 2, 6  # rr.ColorModel.RGB, rr.ChannelDatatype.U8
BYTES = pa.list_(pa.field("item", pa.uint8(), nullable=False))


def log_matrices(rec: Any, matrices: Sequence[Matrix]) -> None:
    """The rounds' matrices in one column per entity (a chunk each, the looks in every row
    rather than a static chunk more): ``heat`` (the image and its stretch), ``costs`` (labels
    hung from the cells' tops, so that each fills its cell), ``chosen`` (a green box round
    each chosen cell) and ``names``."""
    if not matrices:
        return
    entity, n = paths.MISSION_MATRIX, len(matrices)
    index = times([m.t for m in matrices])
    heat = [m.heat.ravel() for m in matrices]
    nothing = pa.nulls(n, pa.uint8())
    send(rec, f"{entity}/heat", index, {
        descriptor("Image", "buffer"): rows(pa.ListArray.from_arrays(
            offsets([len(h) for h in heat]), pa.array(np.concatenate(heat), pa.uint8()),
            type=BYTES)),
        descriptor("Image", "format"): rows(pa.StructArray.from_arrays([
            pa.array([m.grid.rooms for m in matrices], pa.uint32()),
            pa.array([m.grid.agents for m in matrices], pa.uint32()), nothing,
            pa.array([RGB] * n, pa.uint8()), pa.array([U8] * n, pa.uint8())],
            fields=list(IMAGE_FORMAT))),
        descriptor("Transform3D", "scale"): rows(vectors(
            [(m.grid.cell, 1.0, 1.0) for m in matrices], 3))})
    each = [len(m.costs) for m in matrices]
    costs = [c for m in matrices for c in m.costs]
    send(rec, f"{entity}/costs", index, {
        descriptor("Points2D", "positions"): rows(vectors(
            np.array([p for p, _ in costs]).reshape(-1, 2), 2), each),
        descriptor("Points2D", "labels"): rows(texts([text for _, text in costs]), each),
        descriptor("Points2D", "radii"): rows(floats([0.0] * n)),
        descriptor("Points2D", "colors"): rows(colors([(255, 255, 255)] * n)),
        descriptor("Points2D", "show_labels"): rows(flags([True] * n)),
        descriptor("Points2D", "draw_order"): rows(floats([20.0] * n))})
    each = [len(m.chosen) for m in matrices]
    send(rec, f"{entity}/chosen", index, {
        descriptor("Boxes2D", "centers"): rows(vectors(
            np.array([c for m in matrices for c in m.chosen]).reshape(-1, 2), 2), each),
        descriptor("Boxes2D", "half_sizes"): rows(vectors(
            np.array([(m.grid.cell / 2 - 0.08, 0.42) for m in matrices
                      for _ in m.chosen]).reshape(-1, 2), 2), each),
        descriptor("Boxes2D", "colors"): rows(colors([CHOSEN] * n)),
        descriptor("Boxes2D", "radii"): rows(floats([0.09] * n)),
        descriptor("Boxes2D", "draw_order"): rows(floats([30.0] * n))})
    each = [len(m.names) for m in matrices]
    names = [name for m in matrices for name in m.names]
    send(rec, f"{entity}/names", index, {
        descriptor("Points2D", "positions"): rows(vectors(
            np.array([p for p, _, _ in names]).reshape(-1, 2), 2), each),
        descriptor("Points2D", "labels"): rows(texts([text for _, text, _ in names]), each),
        descriptor("Points2D", "colors"): rows(colors([color for _, _, color in names]), each),
        descriptor("Points2D", "radii"): rows(floats([0.0] * n)),
        descriptor("Points2D", "show_labels"): rows(flags([True] * n))})


@dataclass(frozen=True)
class Graph:
    """A round's bipartite graph: agents on the left, rooms on the right, and between them
    one small node per edge labelled with Eq. 1's cost; the chosen pairs' cost nodes are large
    and green, the others small and grey."""

    ids: list[str]
    positions: list[tuple[float, float]]
    labels: list[str]
    colors: list[tuple[int, int, int]]
    radii: list[float]
    edges: list[tuple[str, str]]

    @staticmethod
    def of(record: Mapping[str, Any], kinds: Mapping[str, str]) -> Graph:
        agents, rooms = list(record["agents"]), list(record["rooms"])
        graph = Graph([], [], [], [], [], [])
        ids, positions, labels, colors, radii = (graph.ids, graph.positions, graph.labels,
                                                 graph.colors, graph.radii)
        for i, agent in enumerate(agents):
            ids.append(agent)
            positions.append((0.0, 100.0 * i))
            labels.append(f"{agent} ({kinds.get(agent, '?')})")
            colors.append(_color(kinds.get(agent)))
            radii.append(12.0)
        for j, room in enumerate(rooms):
            ids.append(room)
            positions.append((600.0, 100.0 * j + 50.0 * (len(agents) - len(rooms))))
            labels.append(f"{room} risk {record['risk'][j]:.2f} mess "
                          f"{record['messiness'][j]:.2f}")
            colors.append((int(255 * record["risk"][j]), 60, int(255 * record["messiness"][j])))
            radii.append(12.0)
        chosen = {(m["agent"], m["room"]) for m in record["matching"]}
        for i, agent in enumerate(agents):
            for j, room in enumerate(rooms):
                cost = record["costs"][i][j]
                if cost is None:
                    continue
                node = f"{agent}->{room}"
                share = 0.3 + 0.4 * (j + 1) / (len(rooms) + 1)
                (ax, ay), (bx, by) = positions[i], positions[len(agents) + j]
                ids.append(node)
                positions.append((ax + share * (bx - ax), ay + share * (by - ay)))
                picked = (agent, room) in chosen
                labels.append(f"{cost:.2f}" + (" chosen" if picked else ""))
                colors.append(CHOSEN if picked else (110, 110, 110))
                radii.append(8.0 if picked else 3.0)
                graph.edges.extend([(agent, node), (node, room)])
        return graph


EDGE = pa.struct([pa.field("first", pa.utf8(), nullable=False),
                  pa.field("second", pa.utf8(), nullable=False)])
DIRECTED = 2  # rr.components.GraphType.Directed


def log_graphs(rec: Any, at: Sequence[float], graphs: Sequence[Graph]) -> None:
    """The rounds' graphs (at their times ``at``) at ``mission/assignment/graph``, a row each."""
    nodes = [len(g.ids) for g in graphs]
    edges = [e for g in graphs for e in g.edges]
    send(rec, paths.MISSION_GRAPH, times(list(at)), {
        descriptor("GraphNodes", "node_ids"): rows(texts([i for g in graphs for i in g.ids]),
                                                   nodes),
        descriptor("GraphNodes", "positions"): rows(vectors(
            np.array([p for g in graphs for p in g.positions]).reshape(-1, 2), 2), nodes),
        descriptor("GraphNodes", "labels"): rows(texts([x for g in graphs for x in g.labels]),
                                                 nodes),
        descriptor("GraphNodes", "colors"): rows(colors(
            np.array([c for g in graphs for c in g.colors]).reshape(-1, 3)), nodes),
        descriptor("GraphNodes", "radii"): rows(floats([r for g in graphs for r in g.radii]),
                                                nodes),
        descriptor("GraphEdges", "edges"): rows(pa.StructArray.from_arrays(
            [texts([a for a, _ in edges]), texts([b for _, b in edges])], fields=list(EDGE)),
            [len(g.edges) for g in graphs]),
        descriptor("GraphEdges", "graph_type"): rows(pa.array([DIRECTED] * len(graphs),
                                                              pa.uint8()))})


def _color(kind: str | None) -> tuple[int, int, int]:
    """The colour of ``kind``'s agents (grey for a kind the run did not name)."""
    record = KIND_DEFAULTS.get(kind or "")
    return record.color if record is not None else (200, 200, 200)
