"""Requests by purpose -> categories, on phrasings written for this check (not the development set).

Each line below is an activity request and the categories that can serve it, written without
looking at the glosses. The script reads every request the way ``capnav query`` does
(``parse_instruction`` with the MiniLM embedder) and counts how often the chosen category serves it
(top-1) and how often a serving category is among the chosen one and its alternatives (served).
It prints the default ``PurposeConfig`` beside the reference reading on the same glosses: the single
best gloss per category and the activity as written (no light-verb or pronoun rewriting).

    .venv/bin/python benchmarks/eval_purposes.py
"""

from __future__ import annotations

import argparse
from dataclasses import replace

from bench_common import table
from capnav.language import create_embedder
from capnav.language.embedder import TextEmbedder
from capnav.language.purpose import PurposeConfig, find_activity, match_purpose, purpose_categories

#: (request, categories that serve it).
CASES: list[tuple[str, set[str]]] = [
    ("somewhere to stretch out", {"bed", "sofa"}),
    ("where can I rest my legs", {"ottoman", "sofa", "chair", "armchair", "stool"}),
    ("somewhere to curl up with a book", {"armchair", "sofa"}),
    ("where can I take a nap", {"bed", "sofa"}),
    ("where can I sleep tonight", {"bed"}),
    ("somewhere to sit", {"chair", "armchair", "sofa", "stool"}),
    ("where can I wash my hands", {"sink"}),
    ("where can I have a shower", {"bathtub"}),
    ("where can I have a soak", {"bathtub"}),
    ("where can I keep my milk cold", {"refrigerator"}),
    ("where do I store the butter", {"refrigerator"}),
    ("where can I fry an egg", {"stove"}),
    ("where can I boil some water", {"stove"}),
    ("where can I bake a cake", {"stove"}),
    ("somewhere to put my coffee down", {"coffee table", "table", "nightstand"}),
    ("somewhere to eat breakfast", {"table", "counter"}),
    ("where can I do the dishes", {"sink"}),
    ("where can I chop vegetables", {"counter", "table"}),
    ("where can I write a letter", {"desk"}),
    ("where can I study", {"desk"}),
    ("where can I fold my jumpers away", {"wardrobe", "dresser"}),
    ("where can I put my socks away", {"dresser", "wardrobe"}),
    ("where can I hang my coat", {"wardrobe"}),
    ("where can I keep my novels", {"bookshelf"}),
    ("where can I watch a film", {"tv", "sofa"}),
    ("where can I catch the football on tv", {"tv"}),
    ("somewhere to rest my feet", {"ottoman"}),
    ("where can I prop my legs up", {"ottoman", "sofa"}),
    ("I need the toilet", {"toilet"}),
    ("where can I relieve myself", {"toilet"}),
    ("somewhere to do the laundry", {"washing machine"}),
    ("where can I clean my dirty socks", {"washing machine"}),
    ("where can I read at night", {"lamp", "armchair", "bed"}),
    ("I need more light", {"lamp"}),
    ("where can I put my alarm clock by the bed", {"nightstand"}),
    ("where can I lie flat", {"bed", "sofa"}),
    ("where can I recline", {"armchair", "sofa", "bed"}),
    ("where can I lounge", {"sofa", "armchair"}),
    ("I'm tired", {"bed", "sofa"}),
    ("somewhere to perch in the kitchen", {"stool", "chair"}),
    ("where can I water something green", {"plant"}),
    ("where can I keep the cups and plates", {"cabinet"}),
    ("somewhere to store the pans", {"cabinet"}),
    ("where can I brush my hair", {"dresser", "sink"}),
    ("where do I shave", {"sink"}),
    ("where can I bathe the baby", {"bathtub"}),
    ("where can I take a breather", {"sofa", "armchair", "bed", "chair"}),
    ("where can I doze off", {"bed", "sofa", "armchair"}),
    ("somewhere to kick back", {"sofa", "armchair", "ottoman"}),
    ("where could we get some sleep", {"bed", "sofa"}),
    ("where can I have a quick wash", {"sink", "bathtub"}),
    ("where can I grab a cold drink", {"refrigerator"}),
]


def score(emb: TextEmbedder, cfg: PurposeConfig) -> tuple[int, int, int, list[str]]:
    """(requests with an activity, top-1 serves, a serving category among the candidates, misses)."""
    n = top1 = served = 0
    misses: list[str] = []
    for text, ok in CASES:
        act = find_activity(text)
        if act is None:
            misses.append(f"{text!r}: no activity found")
            continue
        n += 1
        best, alts = purpose_categories(match_purpose(act, emb, cfg), cfg)
        top1 += best in ok
        served += bool(({best} | set(alts)) & ok)
        if best not in ok:
            misses.append(f"{text!r} -> {best} (alternatives {', '.join(alts) or 'none'})")
    return n, top1, served, misses


def shown(k: int, n: int) -> str:
    return f"{k}/{n} ({k / n:.1%})"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--misses", action="store_true", help="print the requests whose top-1 does not serve")
    args = ap.parse_args()
    emb = create_embedder("minilm")
    configs: list[tuple[str, PurposeConfig]] = [
        ("reference: best gloss, activity as written", replace(PurposeConfig(), top_k=1, normalise=False)),
        ("default PurposeConfig", PurposeConfig()),
    ]
    rows = []
    for name, cfg in configs:
        n, top1, served, misses = score(emb, cfg)
        rows.append([name, str(len(CASES)), str(n), shown(top1, len(CASES)), shown(served, len(CASES))])
        if args.misses:
            print(f"\n{name}: " + "\n  ".join(["", *misses]))
    table("requests by purpose -> category (MiniLM, WordNet glosses)",
          ["reading", "n", "with an activity", "top-1 serves", "a candidate serves"], rows)


if __name__ == "__main__":
    main()
