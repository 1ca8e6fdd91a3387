"""Write ``docs/world.md``, every key of a world file, from the schema (a test checks that it is
up to date, as ``astralis schema --markdown`` does for ``docs/missions.md``).

    python tools/world_reference.py [-o docs/world.md]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from astralis_des.mission.reference import WORLD_EXAMPLE, world_reference

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, default=ROOT / "docs" / "world.md")
    args = parser.parse_args()
    args.out.write_text(world_reference(ROOT / WORLD_EXAMPLE), encoding="utf-8")


if __name__ == "__main__":
    main()
