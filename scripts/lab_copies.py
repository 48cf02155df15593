"""Working copies of the notebooks for ``make lab``: ``python scripts/lab_copies.py SOURCE LAB``.

For every ``SOURCE/NN_name.ipynb``:

- no copy in ``LAB`` yet: copied;
- the copy holds cells tagged ``solution`` and the source holds none (the copy came from ``notebooks/`` and
  the class now works from the student copies, ``make lab LAB_FROM=build/student``): the copy is moved to
  ``LAB/backup/NN_name.<time>.ipynb`` (never deleted: it may hold the instructor's own edits) and replaced by the
  source's, with one line saying so;
- otherwise the copy is kept as it is (a student's work is never overwritten).

Exit code 0; one line per notebook copied or replaced.
"""

from __future__ import annotations

import json
import shutil
import sys
import time
from pathlib import Path


def has_solutions(path: Path) -> bool:
    """Whether the notebook at ``path`` has a cell tagged ``solution``."""
    cells = json.loads(path.read_text(encoding="utf-8")).get("cells", [])
    return any("solution" in c.get("metadata", {}).get("tags", []) for c in cells)


def refresh(source: Path, lab: Path, *, stamp: str | None = None) -> list[str]:
    """Bring ``lab``'s copies up to date with ``source`` (see the module docstring); returns what was done."""
    stamp = stamp or time.strftime("%Y%m%d-%H%M%S")
    lab.mkdir(parents=True, exist_ok=True)
    done = []
    for nb in sorted(source.glob("[0-9][0-9]_*.ipynb")):
        copy = lab / nb.name
        if not copy.exists():
            shutil.copyfile(nb, copy)
            done.append(f"copied {nb.name}")
        elif has_solutions(copy) and not has_solutions(nb):
            backup = lab / "backup" / f"{nb.stem}.{stamp}.ipynb"
            backup.parent.mkdir(exist_ok=True)
            shutil.move(copy, backup)
            shutil.copyfile(nb, copy)
            done.append(
                f"replaced {nb.name} (it held the solutions; the old copy is {backup.relative_to(lab)})"
            )
    return done


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 2:
        print("usage: python scripts/lab_copies.py SOURCE LAB", file=sys.stderr)
        return 2
    source, lab = Path(args[0]), Path(args[1])
    if not any(source.glob("[0-9][0-9]_*.ipynb")):
        print(f"lab_copies: no notebooks in {source} (student copies: run `make run` first)", file=sys.stderr)
        return 2
    for line in refresh(source, lab):
        print(f"[lab] {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
