"""Measure the offline verifier's refusal thresholds on generated apartments.

Each threshold says when an observation disagrees with a spoken attribute. It is measured here,
from how the map's observations of every instance compare with that instance's truth (the
manifest: colour name, room, model size), never from instructions:

* colour: the plausibility (``OfflineVerifier.color_fit``: every shade the word covers counts) of
  an object's observed colours for its true colour word, against the plausibility of colour words
  a person would not use for it (CIEDE2000 to the true word above ``--far``, and the true colour
  none of the shades the word covers, ``colors.family``). ``color_reject`` keeps all but
  ``--miss`` of the true words; ``color_match`` (negation: "not the white one") is the ranking
  agreement (``OfflineVerifier.color``) reached by no more than ``--miss`` of the wrong words.
* size: mapped volume ratio of two objects of one truth model and size (should be 1); the ratio
  below which size words cannot rank two instances is its 95th percentile.
* room: the inferred room against the room that holds the object's centre (inferred, unknown,
  wrong), which bounds how often a room refusal ("the X in the kitchen") may be wrong.
* surface (``capnav.language.surface``): the woven / smooth word and the grain (woven / grainy /
  plain) the pixels gave against the true material; how often a spoken material would be refused
  for the object's own material, and for a material of another family (fabric, leather or wood,
  velvet or plastic), and how often the object's own material agrees (is confirmed, not only
  not contradicted).
* shape (``capnav.language.form``): the shape words the points gave against the true shape
  variant, on the categories whose variants carry the word (round / rectangular tables, stools and
  ottomans; cactus or leafy plants); how often a spoken shape word would be refused for the
  object's own shape, and the opposite word.

    .venv/bin/python benchmarks/measure_evidence.py --seeds 1 2 3 --work /tmp/capnav-eval

Maps are built and cached exactly as ``benchmarks/eval_retrieval.py`` builds them (same work folder).
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from capnav.language import SceneContext, create_embedder
from capnav.language.colors import LEX_LAB, NAMES, canonical_color, ciede2000, family
from capnav.language.context import label_of
from capnav.language.form import shape_conflict
from capnav.language.surface import (
    GRAINED_MATERIALS,
    PLAIN_MATERIALS,
    WOVEN_MATERIALS,
    Surface,
    grain_agrees,
    material_conflict,
)
from capnav.retrieval.query import ParsedQuery
from capnav.retrieval.verifier import OfflineVerifier, OfflineVerifierConfig
from eval_retrieval import build, instance_of

#: Shape words each (category, truth variant) deserves and the word that would be wrong for it.
_ROUNDABLE = ("table", "coffee table", "stool", "ottoman")


def true_shape(category: str, variant: str) -> tuple[str, str] | None:
    """(right word, wrong word) for an instance, or None when its variant says nothing measurable."""
    if category in _ROUNDABLE:
        return ("round", "rectangular") if variant == "round" else ("rectangular", "round")
    if category == "plant":
        return ("slender", "leafy") if variant == "cactus" else ("leafy", "slender")
    return None


def material_word(material: str) -> str:
    return material.split()[-1]  # "stainless steel" is spoken "steel"


#: A material of each family a person would not use for an object of another (own family -> word).
_OTHER_FAMILY = {"woven": ("leather", "velvet"), "grained": ("fabric", "velvet"), "plain": ("fabric", "wood")}


def material_family(material: str) -> str | None:
    w = material_word(material)
    return ("woven" if w in WOVEN_MATERIALS else "grained" if w in GRAINED_MATERIALS
            else "plain" if w in PLAIN_MATERIALS else None)


def report_surface(rows: list[tuple[str, Surface]]) -> None:
    """rows: (true material, observed surface). The grain table, and for each family how often its
    own word is refused, confirmed, and another family's word refused."""
    print(f"\nsurface grain against the true material ({len(rows)} mapped objects)")
    print("| true material | n | woven | grainy | plain | nothing | own word confirmed | own word refused |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    by_mat: dict[str, list[Surface]] = {}
    for mat, s in rows:
        by_mat.setdefault(mat, []).append(s)
    for mat in sorted(by_mat):
        ss = by_mat[mat]
        c = Counter(s.grain for s in ss)
        w = material_word(mat)
        ok = sum(grain_agrees(w, s.grain) for s in ss)
        bad = sum(bool(material_conflict(w, s.word, s.grain)) for s in ss)
        print(f"| {mat} | {len(ss)} | {c['woven']} | {c['grainy']} | {c['plain']} | {c[None]} | {ok} | {bad} |")
    print("| family | objects | own word refused | own word confirmed | other families' words refused |")
    print("|---|---:|---:|---:|---:|")
    for fam, others in _OTHER_FAMILY.items():
        ss = [(material_word(m), s) for m, s in rows if material_family(m) == fam]
        if not ss:
            continue
        own = np.mean([bool(material_conflict(w, s.word, s.grain)) for w, s in ss])
        conf = np.mean([grain_agrees(w, s.grain) for w, s in ss])
        other = np.mean([bool(material_conflict(o, s.word, s.grain)) for _, s in ss for o in others])
        print(f"| {fam} ({'/'.join(sorted({w for w, _ in ss}))}) | {len(ss)} | {own:.1%} | {conf:.1%} | "
              f"{other:.1%} ({'/'.join(others)}) |")


def report_form(rows: list[tuple[str, str, str, list[str], str | None]]) -> None:
    """rows: (category, variant, material, observed shape words, observed surface word)."""
    print(f"\nsurface words against the true material ({len(rows)} mapped objects)")
    print("| true material | n | woven | smooth | nothing |")
    print("|---|---:|---:|---:|---:|")
    by_mat: dict[str, Counter[str | None]] = {}
    for _, _, mat, _, surf in rows:
        by_mat.setdefault(mat, Counter())[surf] += 1
    for mat in sorted(by_mat):
        c = by_mat[mat]
        print(f"| {mat} | {sum(c.values())} | {c['woven']} | {c['smooth']} | {c[None]} |")
    woven = [material_word(m) in WOVEN_MATERIALS for _, _, m, _, s in rows if s == "woven"]
    smooth = [material_word(m) not in WOVEN_MATERIALS for _, _, m, _, s in rows if s == "smooth"]
    fabric = [s == "woven" for _, _, m, _, s in rows if material_word(m) in WOVEN_MATERIALS]
    print(f"| 'woven' right | {len(woven)} | {np.mean(woven):.1%} | | |" if woven else "| 'woven' never said | | | | |")
    print(f"| 'smooth' right | {len(smooth)} | {np.mean(smooth):.1%} | | |" if smooth else "| 'smooth' never said |")
    if fabric:
        print(f"| fabric / cotton called woven | {len(fabric)} | {np.mean(fabric):.1%} | | |")
    own = [bool(material_conflict(material_word(m), s)) for _, _, m, _, s in rows]
    other = [bool(material_conflict("leather" if material_word(m) in WOVEN_MATERIALS else "fabric", s))
             for _, _, m, _, s in rows if m not in ("mesh",)]
    print(f"own material refused: {np.mean(own):.1%} of {len(own)}; the other kind's word (fabric <-> leather) "
          f"refused: {np.mean(other):.1%} of {len(other)}")
    print("\nshape words against the true variant (categories whose variants carry a word)")
    print("| word | said | right | precision |")
    print("|---|---:|---:|---:|")
    said: Counter[str] = Counter()
    right: Counter[str] = Counter()
    own_ref, wrong_ref = [], []
    for cat, var, _, words, _ in rows:
        t = true_shape(cat, var)
        if t is None:
            continue
        for w in words:
            if w in t:  # a word of this category's pair: right or wrong for this instance
                said[w] += 1
                right[w] += w == t[0]
        own_ref.append(shape_conflict(t[0], words) is not None)
        wrong_ref.append(shape_conflict(t[1], words) is not None)
    for w in sorted(said):
        print(f"| {w} | {said[w]} | {right[w]} | {right[w] / said[w]:.1%} |")
    print(f"own shape word refused: {np.mean(own_ref):.1%} of {len(own_ref)}; the opposite word refused: "
          f"{np.mean(wrong_ref):.1%} of {len(wrong_ref)}")
    print("\nobserved shape words by true variant:")
    table: dict[tuple[str, str], Counter[str]] = {}
    for cat, var, _, words, _ in rows:
        if true_shape(cat, var) is not None:
            table.setdefault((cat, var), Counter())[" ".join(words) or "-"] += 1
    for (cat, var), c in sorted(table.items()):
        print(f"  {cat} / {var}: " + ", ".join(f"{k} {n}" for k, n in c.most_common()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--work", type=Path, default=Path("/tmp/capnav-eval"))
    ap.add_argument("--far", type=float, default=20.0, help="ΔE00 (kL=2) between words that name other colours")
    ap.add_argument("--miss", type=float, default=0.02, help="share of true (wrong) words a threshold may misjudge")
    ap.add_argument("--color-floor", type=float, default=None,
                    help="weight of a small colour cluster (OfflineVerifierConfig.color_floor) to measure with")
    args = ap.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    true_agree: list[float] = []
    wrong_agree: list[float] = []
    wrong_rank: list[float] = []
    true_rank: list[float] = []
    ratios: list[float] = []
    rooms: Counter[str] = Counter()
    room_rows = []
    form_rows: list[tuple[str, str, str, list[str], str | None]] = []
    surface_rows: list[tuple[str, Surface]] = []
    for seed in args.seeds:
        cmap, manifest = build(seed, args.work)
        scene = SceneContext(cmap.objects, cmap.occupancy)
        cfg = OfflineVerifierConfig(**({} if args.color_floor is None else {"color_floor": args.color_floor}))
        judge = OfflineVerifier(create_embedder("minilm"), scene, cfg)
        judge.use_attributes(cmap.caches.get("attributes", {}))
        room_name = {r.id: r.name for r in manifest.rooms}
        inst = {o.id: instance_of(o, manifest) for o in cmap.objects}
        for o in cmap.objects:
            if inst[o.id] is None:
                continue
            truth = manifest.object(inst[o.id])
            word = canonical_color(truth.color_name)
            if word is not None:
                text = "the plant in the pot" if truth.category == "plant" else "the object"
                rank, fit, _ = judge.color_fit(ParsedQuery(text=text, colors=[word]), o)
                true_agree.append(fit)
                true_rank.append(rank)
                d = ciede2000(LEX_LAB[NAMES.index(word)][None], LEX_LAB, kL=2.0)
                # A word is wrong when far from the true colour and the true colour is none of the
                # shades it covers (grey for a dark grey object, yellow for a mustard one: people
                # say that).
                for w in (NAMES[k] for k in np.flatnonzero(d > args.far) if word not in family(NAMES[k])):
                    rank, fit, _ = judge.color_fit(ParsedQuery(text=text, colors=[w]), o)
                    wrong_agree.append(fit)
                    wrong_rank.append(rank)
            form_rows.append((truth.category, truth.shape, truth.material, judge.shapes(o), judge.surface(o).word))
            surface_rows.append((truth.material, judge.surface(o)))
            said = scene.room_of(o)
            real = room_name[truth.room]
            verdict = "unknown" if said is None else ("right" if said == real else "wrong")
            rooms[verdict] += 1
            if verdict == "wrong":
                room_rows.append(f"s{seed} object {o.id} {label_of(o)}: inferred {said}, truth {real}")
        by_model: dict[tuple[str, tuple[float, ...]], list[float]] = {}
        for o in cmap.objects:
            if inst[o.id] is not None:
                t = manifest.object(inst[o.id])
                key = (t.model, tuple(round(v, 3) for v in t.size))
                by_model.setdefault(key, []).append(float(scene.volume[scene.index[o.id]]))
        for vols in by_model.values():
            for i in range(len(vols)):
                for j in range(i + 1, len(vols)):
                    ratios.append(max(vols[i], vols[j]) / max(min(vols[i], vols[j]), 1e-9))
    ta, wa = np.array(true_agree), np.array(wrong_agree)
    reject = float(np.quantile(ta, args.miss))
    match = float(np.quantile(np.array(wrong_rank), 1.0 - args.miss))
    print(f"\nseeds {args.seeds}: {len(ta)} objects with a true colour word, {len(wa)} (object, wrong word) pairs")
    print("| measure | value |")
    print("|---|---:|")
    print(f"| colour plausibility, true word: p1 / p2 / p5 / median | {np.quantile(ta, 0.01):.3f} / "
          f"{np.quantile(ta, 0.02):.3f} / {np.quantile(ta, 0.05):.3f} / {np.median(ta):.3f} |")
    print(f"| colour plausibility, wrong word: median / p95 / p98 / max | {np.median(wa):.3f} / "
          f"{np.quantile(wa, 0.95):.3f} / {np.quantile(wa, 0.98):.3f} / {wa.max():.3f} |")
    print(f"| color_reject (true words kept: {1 - args.miss:.0%}) | {reject:.3f} |")
    print(f"|   wrong words refused at color_reject | {np.mean(wa < reject):.1%} |")
    print(f"| color_match (wrong words reaching it: {args.miss:.0%}) | {match:.3f} |")
    print(f"|   true words reaching color_match | {np.mean(np.array(true_rank) >= match):.1%} |")
    if ratios:
        r = np.array(ratios)
        print(f"| volume ratio of same-size instances: median / p95 / max ({len(r)} pairs) | "
              f"{np.median(r):.2f} / {np.quantile(r, 0.95):.2f} / {r.max():.2f} |")
    total = sum(rooms.values())
    print(f"| rooms inferred right / unknown / wrong ({total} objects) | {rooms['right'] / total:.1%} / "
          f"{rooms['unknown'] / total:.1%} / {rooms['wrong'] / total:.1%} |")
    for row in room_rows:
        print(f"  wrong room: {row}")
    report_form(form_rows)
    report_surface(surface_rows)


if __name__ == "__main__":
    main()
