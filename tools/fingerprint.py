"""Fingerprints of what a refactor must keep byte for byte: every mission's event log (in
both fidelities) and the tables of the Table V studies.

    python tools/fingerprint.py OUT.json            # write the fingerprints
    python tools/fingerprint.py OUT.json --check    # compare with OUT.json; exit 1 on a change

Each mission of ``missions/`` runs through the command line (``astralis run --no-recording
--quiet``) in kinematic and in physics fidelity; each study of ``studies/table5*.yaml`` runs
through ``astralis study --quiet`` (assignment only: fast). The SHA-256 of each
``events.jsonl`` and of each study's ``table.csv`` are compared; a change names the file.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIDELITIES = ("kinematic", "physics")


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _astralis(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "astralis_des.cli", *args], cwd=ROOT, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def fingerprints(work: Path) -> dict[str, str]:
    out: dict[str, str] = {}
    for mission in sorted((ROOT / "missions").glob("*.yaml")):
        for fidelity in FIDELITIES:
            folder = work / f"{mission.stem}-{fidelity}"
            _astralis("run", str(mission), "--fidelity", fidelity, "--out", str(folder),
                      "--no-recording", "--quiet")
            out[f"missions/{mission.name} {fidelity} events.jsonl"] = \
                _sha(folder / "events.jsonl")
    for study in sorted((ROOT / "studies").glob("table5*.yaml")):
        folder = work / study.stem
        _astralis("study", str(study), "--out", str(folder), "--quiet")
        for table in sorted(folder.glob("*.csv")):
            out[f"studies/{study.name} {table.name}"] = _sha(table)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", type=Path)
    parser.add_argument("--check", action="store_true", help="compare with FILE")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        now = fingerprints(Path(tmp))
    if not args.check:
        args.file.write_text(json.dumps(now, indent=1) + "\n")
        print(f"{len(now)} fingerprints written to {args.file}")
        return
    before = json.loads(args.file.read_text())
    changed = sorted(k for k in before.keys() | now.keys() if before.get(k) != now.get(k))
    for key in changed:
        print(f"changed: {key}")
    print(f"{len(now) - len(changed)} of {len(now)} unchanged")
    sys.exit(1 if changed else 0)


if __name__ == "__main__":
    main()
