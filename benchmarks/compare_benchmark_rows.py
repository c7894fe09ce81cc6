"""Two benchmark rows flown on the same trials, compared trial by trial (paired).

Reads the cells (``cells/ROW/TASK-SENSORS.parquet``) of two ``quadimpact
benchmark`` output folders, typically the default law and a policy, each run
with ``--no-references``::

    quadimpact benchmark --no-references --sensors ideal,onboard --out DIR/law
    quadimpact benchmark --no-references --policy FILE --name mine --sensors ideal,onboard \\
        --out DIR/policy
    python benchmarks/compare_benchmark_rows.py DIR/law DIR/policy

For every task and sensor set present in both it prints the two success
shares (held hovers of the valid trials, docs/BENCHMARK.md 1.2), their
difference in points with Newcombe's paired 95 % interval (the trials valid
in both), and how many trials each wins alone; then, over the successes, the
median (p90) time to the hover and distance to it, and over the valid trials
the height lost. A folder holding one row is read as that row; give
``--first-row`` / ``--second-row`` otherwise.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from quadimpact.studies.benchmark.paired import paired_difference
from quadimpact.studies.statistics import rate


def _row_dir(folder: Path, row: str | None) -> Path:
    rows = sorted(p for p in (folder / "cells").iterdir() if p.is_dir())
    if row is not None:
        return folder / "cells" / row
    if len(rows) != 1:
        raise SystemExit(f"{folder}: {len(rows)} rows ({', '.join(p.name for p in rows)}): "
                         "name one with --first-row / --second-row")  # fmt: skip
    return rows[0]


def _quantiles(t: pd.DataFrame, column: str, mask: np.ndarray) -> str:
    v = pd.to_numeric(t.loc[mask, column], errors="coerce").dropna()
    return f"{v.median():.2f} ({v.quantile(0.9):.2f})" if len(v) else "-"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("first", type=Path, help="the reference's benchmark folder (the law)")
    ap.add_argument("second", type=Path, help="the compared benchmark folder (the policy)")
    ap.add_argument("--first-row", default=None)
    ap.add_argument("--second-row", default=None)
    args = ap.parse_args()
    a_dir, b_dir = _row_dir(args.first, args.first_row), _row_dir(args.second, args.second_row)
    print(f"{b_dir.name} ({args.second}) against {a_dir.name} ({args.first}), paired")
    print("| task | sensors | valid in both | first | second | difference, points [95 %] | "
          "won by the second alone / by the first alone |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    extra = []
    for cell in sorted(a_dir.glob("*.parquet")):
        other = b_dir / cell.name
        if not other.is_file():
            continue
        a = pd.read_parquet(cell).sort_values("run_id").reset_index(drop=True)
        b = pd.read_parquet(other).sort_values("run_id").reset_index(drop=True)
        if not np.array_equal(a["run_id"].to_numpy(), b["run_id"].to_numpy()):
            raise SystemExit(f"{cell.name}: the two rows flew other trials")
        both = (a["valid"].astype(bool) & b["valid"].astype(bool)).to_numpy()
        sa = a["success"].astype(bool).to_numpy()[both]
        sb = b["success"].astype(bool).to_numpy()[both]
        d = paired_difference(sb, sa)
        ra, rb = rate(int(sa.sum()), sa.size), rate(int(sb.sum()), sb.size)
        task, sensors = cell.stem.split("-", 1)
        wins = f"{int((sb & ~sa).sum())} / {int((sa & ~sb).sum())}"
        print(f"| {task} | `{sensors}` | {sa.size:,} | {100 * ra.value:.1f} % | "
              f"{100 * rb.value:.1f} % | {100 * d.difference:+.1f} [{100 * d.low:+.1f}, "
              f"{100 * d.high:+.1f}] | {wins} |")  # fmt: skip
        ma = a["success"].astype(bool).to_numpy() & both
        mb = b["success"].astype(bool).to_numpy() & both
        extra.append(
            f"| {task} | `{sensors}` | {_quantiles(a, 'time_to_held_hover_s', ma)} | "
            f"{_quantiles(b, 'time_to_held_hover_s', mb)} | "
            f"{_quantiles(a, 'held_hover_distance_m', ma)} | "
            f"{_quantiles(b, 'held_hover_distance_m', mb)} | "
            f"{_quantiles(a, 'height_lost_m', both)} | {_quantiles(b, 'height_lost_m', both)} |"
        )
    print()
    print("| task | sensors | time to the hover, first | second (s) | distance to it, first | "
          "second (m) | height lost, first | second (m) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(extra))


if __name__ == "__main__":
    main()
