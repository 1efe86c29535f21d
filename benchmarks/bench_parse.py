"""What the dependency parser costs a one-process query: ``CapNav.open(map, voxels=False).ask(text)``
in a fresh interpreter, for a short noun phrase (read by patterns, the parser is not loaded) and
for a sentence (the parser is loaded), least CPU and wall time of ``--repeat`` processes each.

    python benchmarks/bench_parse.py MAP [--repeat 3]

Run it with the ``capnav`` to compare on ``PYTHONPATH`` (before / after a change); the last column
says whether spaCy was imported. CPU time (user + system of the child) is the figure to compare
on a loaded machine; wall time is printed beside it with the load average."""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time

QUERIES = ("the red chair next to the table",
           "when I get back from work I would like to sit in the armchair next to the lamp")

CHILD = ("import sys, json; from capnav.api import CapNav; "
         "a = CapNav.open(sys.argv[1], voxels=False).ask(sys.argv[2]); "
         "print(json.dumps({'answer': f'{a.object.category} {a.object.id}' if a.found else 'not found', "
         "'spacy': 'spacy' in sys.modules}))")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("map")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"load average {' / '.join(f'{v:.1f}' for v in os.getloadavg())} on {os.cpu_count()} cores; "
          f"min of {args.repeat} processes")
    print("| instruction | answer | wall | CPU | spaCy imported |")
    print("|---|---|---:|---:|---|")
    for text in QUERIES:
        walls, cpus, out = [], [], {}
        for _ in range(args.repeat):
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            p = subprocess.run([sys.executable, "-c", CHILD, args.map, text], capture_output=True, text=True,
                               check=True)
            walls.append(time.perf_counter() - t0)
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpus.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
            out = json.loads(p.stdout.strip().splitlines()[-1])
        print(f"| {text} | {out['answer']} | {min(walls):.2f} s | {min(cpus):.2f} s | {out['spacy']} |")


if __name__ == "__main__":
    main()
