"""Table IV: the action an assigned agent takes in a room, by its risk and messiness.

The table is the actions' records' ``table4`` cells (risk comes first: a high-risk room gets an
inward spiral from a UAV and corridor observation from the UGV, whatever its messiness; Table
IV has no human row, so an assigned operator walks in and looks, our choice).
"""

from __future__ import annotations

from astralis_des.plugins import ACTIONS

_table: tuple[int, dict[tuple[str, bool, bool], str]] = (-1, {})


def table4() -> dict[tuple[str, bool, bool], str]:
    """``(kind, high risk, high messiness)`` -> action, from the registered records."""
    global _table
    if _table[0] != ACTIONS.version:
        cells: dict[tuple[str, bool, bool], str] = {}
        for spec in ACTIONS.specs():
            for kind in spec.kinds:
                for risky, messy in spec.table4:
                    cell = (kind, risky, messy)
                    if cell in cells:
                        raise ValueError(f"Table IV cell {cell} is both {cells[cell]} and "
                                         f"{spec.name}")
                    cells[cell] = spec.name
        _table = (ACTIONS.version, cells)
    return _table[1]


def table4_action(kind: str, risk: float, messiness: float, high_risk: float = 0.5,
                  high_messiness: float = 0.5) -> str:
    """High means >= the threshold (the paper: 0.5)."""
    return table4()[(kind, risk >= high_risk, messiness >= high_messiness)]
