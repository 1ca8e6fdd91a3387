"""The study table (pyarrow) and its summary: rates with Wilson intervals, means with t
intervals, 95% by default."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from astralis_des.studies.evaluation import Metric

Z95 = 1.959963984540054


def to_table(rows: Sequence[dict[str, Any]]) -> pa.Table:
    """Rows as a table; columns in order of first appearance (a failed row has fewer)."""
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    data = {c: [row.get(c) for row in rows] for c in columns}
    return pa.table({c: pa.array(v) for c, v in data.items()})


def write_table(table: pa.Table, folder: Path, stem: str = "table") -> None:
    import pyarrow.csv as csv
    import pyarrow.parquet as pq

    csv.write_csv(table, folder / f"{stem}.csv")
    pq.write_table(table, folder / f"{stem}.parquet")


def two_proportion_z(share: float, n: int, other: float, other_n: int) -> float:
    """Two-proportion z-test (pooled): ``share`` of ``n`` against ``other`` of ``other_n``;
    0 when both are exact and equal."""
    pooled = (share * n + other * other_n) / (n + other_n)
    se = math.sqrt(pooled * (1 - pooled) * (1 / n + 1 / other_n))
    diff = share - other
    if se == 0:
        return 0.0 if diff == 0 else math.copysign(math.inf, diff)
    return diff / se


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float, float]:
    """A proportion ``k / n`` and its Wilson score interval (sound at 0 and 1)."""
    if n == 0:
        return (math.nan, math.nan, math.nan)
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return (p, max(0.0, centre - half), min(1.0, centre + half))


def mean_ci(values: Sequence[float], level: float = 0.95) -> tuple[float, float, float]:
    """A mean and its Student-t interval (NaN bounds with fewer than two values)."""
    x = np.asarray(values, dtype=float)
    if len(x) == 0:
        return (math.nan, math.nan, math.nan)
    mean = float(x.mean())
    if len(x) < 2:
        return (mean, math.nan, math.nan)
    from scipy.stats import t

    half = float(t.ppf(0.5 + level / 2, len(x) - 1)) * float(x.std(ddof=1)) / math.sqrt(len(x))
    return (mean, mean - half, mean + half)


def quartiles(values: Sequence[float]) -> tuple[float, float, float]:
    """The first quartile, the median and the third quartile (NaN without values)."""
    if not len(values):
        return (math.nan, math.nan, math.nan)
    q1, median, q3 = np.percentile(np.asarray(values, dtype=float), [25, 50, 75])
    return (float(q1), float(median), float(q3))


def metric_values(data: dict[str, list[Any]], column: str, variant: str) -> list[Any]:
    """A metric's values over a variant's runs that ended ``ok`` and have it (time to find:
    the runs that found the target), in row order; ``data``: the table as columns."""
    if column not in data:
        return []
    return [data[column][i] for i, v in enumerate(data.get("variant", []))
            if v == variant and data["status"][i] == "ok" and data[column][i] is not None]


def summarize(table: pa.Table, metrics: Sequence[Metric],
              variants: Sequence[str]) -> list[dict[str, Any]]:
    """Per variant and metric (tidy): ``n`` scenarios that ran, the estimate, its 95% bounds.

    A mean is over the rows where the column has a value (time to find: found runs only).
    """
    data = table.to_pydict()
    out = []
    for variant in variants:
        mine = [i for i, v in enumerate(data.get("variant", [])) if v == variant]
        ok = [i for i in mine if data["status"][i] == "ok"]
        for metric in metrics:
            values = [data[metric.column][i] for i in ok] if metric.column in data else []
            values = [v for v in values if v is not None]
            if metric.kind == "rate":
                est, lo, hi = wilson(sum(bool(v) for v in values), len(values))
            else:
                est, lo, hi = mean_ci(values)
            out.append({"variant": variant, "metric": metric.column, "label": metric.label,
                        "kind": metric.kind, "unit": metric.unit, "n": len(values),
                        "failed": len(mine) - len(ok), "estimate": est, "low": lo, "high": hi})
    return out


def format_quartiles(values: Sequence[float], unit: str = "") -> str:
    """``170.2 s [121.0, 240.2]``: the median and the interquartile range."""
    q1, median, q3 = quartiles(values)
    if math.isnan(median):
        return "-"
    return f"{median:.1f}{f' {unit}' if unit else ''} [{q1:.1f}, {q3:.1f}]"


def format_estimate(entry: dict[str, Any]) -> str:
    """``39.3% [36.3, 42.4]`` for a rate, ``812.4 s [790.1, 834.6]`` for a mean."""
    est, lo, hi = entry["estimate"], entry["low"], entry["high"]
    if math.isnan(est):
        return "-"
    if entry["kind"] == "rate":
        return f"{est:.1%} [{lo * 100:.1f}, {hi * 100:.1f}]"
    unit = f" {entry['unit']}" if entry["unit"] else ""
    if math.isnan(lo):
        return f"{est:.1f}{unit}"
    return f"{est:.1f}{unit} [{lo:.1f}, {hi:.1f}]"
