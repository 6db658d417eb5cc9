#!/usr/bin/env python3
"""Rebuild the default terrain cost shipped in python/roughwalk/planning/data/.

The preferences come from the scripted expert (rules on raw geometry after
Zucker 2011, §4.2, with 10 % label noise) on roughwalk's own generated
terrains: no data files are needed, and the same seeds give the same
judgements and weights on any machine.

    python scripts/build_default_cost.py                 # rewrite the shipped files
    python scripts/build_default_cost.py --out-dir /tmp/x # write elsewhere, e.g. to compare
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from roughwalk.planning.default_cost import (
    DefaultCostRecipe,
    build_default_cost,
    build_default_preferences,
    data_dir,
)


def main() -> int:
    """Rebuild the shipped preferences and cost; print the agreement."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=data_dir(), help="where to write")
    args = parser.parse_args()
    recipe = DefaultCostRecipe()
    args.out_dir.mkdir(parents=True, exist_ok=True)
    store = args.out_dir / "default_preferences.sqlite"
    cost_file = args.out_dir / "default_cost.json"
    start = time.perf_counter()
    # Build beside, then replace, so that a failed run leaves the old files whole.
    with tempfile.TemporaryDirectory(dir=args.out_dir) as tmp:
        new_store = Path(tmp) / store.name
        n = build_default_preferences(new_store, recipe)
        cost, report = build_default_cost(new_store, Path(tmp) / cost_file.name)
        new_store.replace(store)
        (Path(tmp) / cost_file.name).replace(cost_file)
    print(f"wrote {n} scripted judgements to {store}")
    print(
        f"wrote {cost_file}: train agreement {report.train_agreement:.3f}, "
        f"{report.cv_folds}-fold held-out agreement {report.cv_agreement:.3f} "
        f"({time.perf_counter() - start:.1f} s)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
