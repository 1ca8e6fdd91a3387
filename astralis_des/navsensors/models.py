"""Sensors that read only the pose: GNSS, barometer and magnetometer, in both fidelities.

- **GNSS** (:class:`Gnss`): a fix in latitude, longitude and altitude (WGS 84, by pymap3d from
  the site's east-north-up frame about its geodetic origin), with horizontal and vertical
  noise, a status and the satellites seen. How much of the sky the receiver sees decides it:
  rays to the sky above an elevation mask, tested against the world's solids (walls, slabs,
  roofs, obstacles), give the open share; the satellites seen are that share of those an open
  sky shows; below ``degraded_below`` open the noise grows (multipath, few satellites), and
  with fewer than 4 satellites there is no fix. Indoors the fix degrades at the door and drops
  out under a slab, from the geometry, not from a room flag. The open share is sampled on a
  grid of ``SKY_CELL`` metres and kept on the world.
- **Barometer** (:class:`Barometer`): the standard atmosphere's pressure at the site's
  elevation plus the height, with white noise and a slowly drifting bias (a first-order
  Gauss-Markov process, as AirSim's barometer drifts), and the altitude it implies.
- **Magnetometer** (:class:`Magnetometer`): the Earth's field at the site (north, east, down,
  in microtesla) turned into the body frame, with noise and a constant bias, and the
  heading it implies (from magnetic north, corrected by the declination the field gives).

Each draws from its own generator (``astralis_des.streams``), the same number of draws per
reading whatever it reads, so a run is byte-identical from its seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pymap3d

from astralis_des.world.geometry import FloatArray, segments_hit_boxes
from astralis_des.world.model import World

if TYPE_CHECKING:
    pass

SKY_CELL = 1.0  # m: the open share of the sky is sampled on this grid
SKY_REACH = 60.0  # m: a ray to the sky clear this far is clear (over any building here)
ELEVATIONS = (25.0, 45.0, 65.0)  # degrees of the rays to the sky (mask: 15)
AZIMUTHS = 8  # rays per elevation, and one straight up
MEMO_CELLS = 1 << 18  # open shares a world keeps
DRIFT_BLOCK = 512  # readings of a barometer's drift worked out at once
# the International Standard Atmosphere below 11 km
P0, T0, LAPSE, G0, R_AIR = 101325.0, 288.15, 0.0065, 9.80665, 287.05287
EXPONENT = G0 / (R_AIR * LAPSE)


def _sky_rays() -> FloatArray:
    """Unit vectors to the sky: ``AZIMUTHS`` at each of ``ELEVATIONS``, and the zenith."""
    rays = [(0.0, 0.0, 1.0)]
    for elevation in ELEVATIONS:
        e = math.radians(elevation)
        for k in range(AZIMUTHS):
            a = 2 * math.pi * (k + 0.5 * (len(rays) % 2)) / AZIMUTHS
            rays.append((math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)))
    return np.array(rays)


SKY_RAYS = _sky_rays()


def sky_openness(world: World, positions: FloatArray) -> FloatArray:
    """The share of the rays to the sky from each position that no solid blocks, sampled at
    the centre of its ``SKY_CELL`` grid cell (kept on the world: a study's next mission
    finds it there)."""
    cells = np.floor(np.atleast_2d(np.asarray(positions, dtype=float)) / SKY_CELL)
    keys = [tuple(c) for c in cells.astype(np.int64).tolist()]
    memo = world.memo("sky", MEMO_CELLS)
    new = sorted({k for k in keys if k not in memo})
    if new:
        centres = (np.array(new, dtype=float) + 0.5) * SKY_CELL
        starts = np.repeat(centres, len(SKY_RAYS), axis=0)
        ends = starts + SKY_REACH * np.tile(SKY_RAYS, (len(new), 1))
        blocked = segments_hit_boxes(starts, ends, world.solid_array).reshape(len(new), -1)
        for key, share in zip(new, 1.0 - blocked.mean(axis=1), strict=True):
            memo[key] = float(share)
    return np.array([memo[k] for k in keys])


def pressure_at(altitude: float | FloatArray) -> float | FloatArray:
    """Pa at ``altitude`` metres above sea level (ISA troposphere)."""
    return P0 * (1.0 - LAPSE * np.asarray(altitude) / T0) ** EXPONENT


def altitude_of(pressure: float | FloatArray) -> float | FloatArray:
    """Metres above sea level where the ISA pressure is ``pressure`` Pa."""
    return T0 / LAPSE * (1.0 - (np.asarray(pressure) / P0) ** (1.0 / EXPONENT))


@dataclass(frozen=True)
class Origin:
    """The site's geodetic origin: where its (0, 0, 0) lies (WGS 84)."""

    latitude: float  # degrees
    longitude: float  # degrees
    altitude: float  # m above the ellipsoid (the ground of the site)

    def geodetic(self, position: FloatArray) -> tuple[float, float, float]:
        """Latitude, longitude (degrees) and altitude (m) of a site point (x east, y north,
        z up)."""
        x, y, z = (float(v) for v in position)
        lat, lon, alt = pymap3d.enu2geodetic(x, y, z, self.latitude, self.longitude,
                                             self.altitude)
        return float(lat), float(lon), float(alt)


@dataclass(frozen=True)
class Readings:
    """A sensor's readings in time order: ``t`` and named columns of one row per reading."""

    t: FloatArray
    columns: dict[str, np.ndarray]

    def __len__(self) -> int:
        return len(self.t)

    @staticmethod
    def joined(parts: list[Readings]) -> Readings:
        """The readings of ``parts`` one after the other."""
        if not parts:
            return Readings(np.zeros(0), {})
        return Readings(np.concatenate([p.t for p in parts]),
                        {k: np.concatenate([p.columns[k] for p in parts])
                         for k in parts[0].columns})

    def row(self, i: int) -> dict[str, Any]:
        """Reading ``i`` as plain numbers (the API's answer)."""
        out: dict[str, Any] = {"t": float(self.t[i])}
        for name, column in self.columns.items():
            value = column[i]
            plain = value.tolist() if isinstance(value, np.ndarray) else value.item()
            out[name] = None if isinstance(plain, float) and not math.isfinite(plain) else plain
        return out


@dataclass
class Gnss:
    world: World
    origin: Origin
    rng: np.random.Generator
    horizontal_std: float = 1.5  # m, under an open sky
    vertical_std: float = 3.0
    satellites: int = 12  # seen under an open sky
    degraded_below: float = 0.6  # open share under which the fix degrades

    def read(self, t: FloatArray, positions: FloatArray, rotations: FloatArray) -> Readings:
        noise = self.rng.normal(0.0, 1.0, (len(t), 3))  # drawn whatever the fix
        open_sky = sky_openness(self.world, positions)
        seen = np.floor(self.satellites * open_sky + 0.5).astype(np.int64)
        fixed = seen >= 4
        worse = np.maximum(1.0, self.degraded_below / np.maximum(open_sky, 1e-9)) ** 2
        h, v = self.horizontal_std * worse, self.vertical_std * worse
        p = positions + noise * np.column_stack([h, h, v])
        lat, lon, alt = pymap3d.enu2geodetic(p[:, 0], p[:, 1], p[:, 2], self.origin.latitude,
                                             self.origin.longitude, self.origin.altitude)
        nan = np.full(len(t), np.nan)
        status = np.where(~fixed, "none", np.where(open_sky >= self.degraded_below, "fix",
                                                   "degraded"))
        return Readings(t, {
            "position": np.where(fixed[:, None], p, np.nan),  # the fix in the site's frame
            "latitude": np.where(fixed, np.asarray(lat, dtype=float), nan),
            "longitude": np.where(fixed, np.asarray(lon, dtype=float), nan),
            "altitude": np.where(fixed, np.asarray(alt, dtype=float), nan),
            "status": status, "satellites": seen, "open_sky": open_sky,
            "horizontal_std": np.where(fixed, h, np.inf),
            "vertical_std": np.where(fixed, v, np.inf)})


@dataclass
class Barometer:
    origin: Origin
    rng: np.random.Generator
    noise_std: float = 2.7  # Pa, white (AirSim's default: 0.027 hPa)
    drift_std: float = 10.0  # Pa, the bias's steady-state spread
    drift_tau: float = 3600.0  # s, the bias's correlation time
    bias: float = field(default=0.0, init=False)
    _last: float | None = field(default=None, init=False, repr=False)

    def read(self, t: FloatArray, positions: FloatArray, rotations: FloatArray) -> Readings:
        draws = self.rng.normal(0.0, 1.0, (len(t), 2))
        bias = self._drift(t, draws[:, 0])
        true = np.asarray(pressure_at(self.origin.altitude + positions[:, 2]), dtype=float)
        pressure = true + bias + self.noise_std * draws[:, 1]
        return Readings(t, {"pressure": pressure,
                            "altitude": np.asarray(altitude_of(pressure), dtype=float)})


    def _drift(self, t: FloatArray, w: FloatArray) -> FloatArray:
        """The bias at each time: ``b_k = a b_(k-1) + s sqrt(1 - a^2) w_k`` with
        ``a = exp(-dt / tau)`` for the readings' (even) spacing ``dt``, in closed form over
        blocks of readings (no loop a reading)."""
        out = np.empty(len(t))
        dt = float(t[1] - t[0]) if len(t) > 1 else (
            float(t[0]) - self._last if self._last is not None else 0.0)
        a = math.exp(-max(dt, 0.0) / self.drift_tau)
        gain = self.drift_std * math.sqrt(1.0 - a * a)
        start = 0 if self._last is not None else 1  # the first reading of all: no step yet
        out[:start] = self.bias
        for lo in range(start, len(t), DRIFT_BLOCK):
            step = w[lo:lo + DRIFT_BLOCK]
            k = np.arange(1, len(step) + 1)
            out[lo:lo + len(step)] = a**k * (self.bias + gain * np.cumsum(step * a**-k))
            self.bias = float(out[lo + len(step) - 1])
        if len(t):
            self._last = float(t[-1])
        return out


@dataclass
class Magnetometer:
    rng: np.random.Generator
    field_ned: tuple[float, float, float]  # microtesla: north, east, down at the site
    noise_std: float = 0.3  # microtesla
    bias: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def read(self, t: FloatArray, positions: FloatArray, rotations: FloatArray) -> Readings:
        """``rotations``: world (east, north, up) from body (forward, left, up). The heading
        is a level compass's: from the field's components along the body's forward and left
        axes, turned from magnetic to true north by the field's declination."""
        n, e, d = self.field_ned
        world = np.array([e, n, -d])  # east, north, up
        body = np.einsum("nji,j->ni", rotations, world) + np.asarray(self.bias) \
            + self.noise_std * self.rng.normal(0.0, 1.0, (len(t), 3))
        declination = math.degrees(math.atan2(e, n))
        heading = np.remainder(np.degrees(np.arctan2(body[:, 1], body[:, 0])) + declination,
                               360.0)
        return Readings(t, {"field": body, "heading": heading})


def yaw_rotation(yaw: float | FloatArray) -> FloatArray:
    """World from body for a level body heading ``yaw`` (radians, counter-clockwise from
    east): ``(3, 3)``, or ``(N, 3, 3)`` for an array of headings."""
    y = np.asarray(yaw, dtype=float)
    c, s = np.cos(y), np.sin(y)
    out = np.zeros((*y.shape, 3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 2, 2] = 1.0
    return out
