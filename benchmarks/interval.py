"""The 95% Wilson score interval of a success proportion, as the results tables give it.

    python benchmarks/interval.py 348 360        # successes, trials -> 96.7% [94.3, 98.1]

Subgoals of one episode share an apartment and a start, so they are not independent draws; the
interval is the binomial one and reads as optimistic for that reason.
"""

from __future__ import annotations

import argparse
import math


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """(low, high) of the Wilson score interval for ``k`` successes in ``n`` trials."""
    if n <= 0 or not 0 <= k <= n:
        raise SystemExit(f"need 0 <= successes <= trials and trials > 0, got {k} of {n}")
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("successes", type=int)
    ap.add_argument("trials", type=int)
    a = ap.parse_args()
    lo, hi = wilson(a.successes, a.trials)
    print(f"{100 * a.successes / a.trials:.1f}% [{100 * lo:.1f}, {100 * hi:.1f}]")


if __name__ == "__main__":
    main()
