"""Furniture made of boxes, cylinders and spheres: every category, several shape variants each.

Local frame of a model: origin at the footprint centre on the floor, x = width, y = depth,
z up, the front faces +y (the side a person uses; placement turns it away from walls).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from capnav.sim.shapes import Part, box, cyl, sphere


@dataclass(frozen=True)
class Model:
    """A built piece of furniture: its parts and its full extent (w, d, h) in the local frame."""

    variant: str
    size: tuple[float, float, float]
    parts: tuple[Part, ...]


Builder = Callable[[np.random.Generator, float, float, float, str], list[Part]]


def _legs(w: float, d: float, h: float, t: float, inset: float, role: str = "legs",
          round_legs: bool = False) -> list[Part]:
    out = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            x, y = sx * (w / 2 - inset - t / 2), sy * (d / 2 - inset - t / 2)
            out.append(cyl(x, y, h / 2, t, h, role) if round_legs else box(x, y, h / 2, t, t, h, role))
    return out


def sofa(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    seat_h, arm_w = 0.42, 0.18 if v != "armless" else 0.0
    parts = [box(0, 0.05, 0.06 + (seat_h - 0.06) / 2, w - 2 * arm_w, d - 0.1, seat_h - 0.06),
             box(0, -d / 2 + 0.1, h / 2 + 0.03, w - 2 * arm_w, 0.2, h - 0.06)]
    parts += [box(x, 0, 0.03, 0.06, 0.06, 0.06, "legs") for x in (-w / 2 + 0.08, w / 2 - 0.08)]
    n_cush = 3 if w > 1.9 else 2
    cw = (w - 2 * arm_w - 0.04) / n_cush
    for k in range(n_cush):
        x = -w / 2 + arm_w + 0.02 + cw * (k + 0.5)
        parts.append(box(x, 0.08, seat_h + 0.06, cw - 0.03, d - 0.3, 0.12, "accent"))
    if v == "curved":
        for x in (-w / 2 + arm_w / 2, w / 2 - arm_w / 2):
            parts.append(box(x, 0.0, 0.3, arm_w, d, 0.48))
            parts.append(cyl(x, 0.0, 0.56, arm_w, d, "main", axis="y"))
    elif v in ("straight", "l-shaped"):
        for x in (-w / 2 + arm_w / 2, w / 2 - arm_w / 2):
            parts.append(box(x, 0.0, 0.32, arm_w, d, 0.64))
    if v == "l-shaped":  # chaise on the right, reaching forward
        parts.append(box(w / 2 - arm_w - 0.35, d / 2 + 0.35, 0.22, 0.7, 0.7, 0.44))
        parts.append(box(w / 2 - arm_w - 0.35, d / 2 + 0.35, 0.5, 0.66, 0.66, 0.12, "accent"))
    return parts


def armchair(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    arm = 0.15
    parts = [box(0, 0.05, 0.28, w - 2 * arm, d - 0.1, 0.3),
             box(0, 0.08, 0.47, w - 2 * arm - 0.02, d - 0.3, 0.1, "accent"),
             box(0, -d / 2 + 0.09, (h + 0.13) / 2, w - 2 * arm, 0.18, h - 0.13)]
    parts += _legs(w, d, 0.13, 0.05, 0.04, "legs", round_legs=True)
    if v == "round-armed":
        for x in (-w / 2 + arm / 2, w / 2 - arm / 2):
            parts.append(box(x, 0, 0.36, arm, d, 0.46))
            parts.append(cyl(x, 0, 0.59, arm, d, "main", axis="y"))
    else:
        for x in (-w / 2 + arm / 2, w / 2 - arm / 2):
            parts.append(box(x, 0, 0.4, arm, d, 0.54))
    if v == "wingback":
        for x in (-w / 2 + arm / 2, w / 2 - arm / 2):
            parts.append(box(x, -d / 2 + 0.2, (h + 0.67) / 2, arm, 0.3, h - 0.67))
    return parts


def chair(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    seat = 0.46
    if v == "tulip":
        return [cyl(0, 0, 0.01, 0.42, 0.02, "legs"), cyl(0, 0, seat / 2, 0.06, seat, "legs"),
                cyl(0, 0.02, seat, w, 0.05), box(0, -d / 2 + 0.03, (seat + h) / 2, w * 0.8, 0.04, h - seat)]
    parts = [box(0, 0.02, seat - 0.02, w, d - 0.04, 0.04)]
    parts += _legs(w, d, seat - 0.04, 0.04, 0.01)
    if v == "slat-back":
        for x in (-w / 2 + 0.02, w / 2 - 0.02):
            parts.append(box(x, -d / 2 + 0.02, (seat + h) / 2, 0.04, 0.04, h - seat))
        for k in range(3):
            parts.append(box(0, -d / 2 + 0.02, seat + 0.12 + k * (h - seat - 0.12) / 3 + 0.05, w - 0.04, 0.025, 0.05))
    else:  # solid back, upholstered seat pad
        parts.append(box(0, -d / 2 + 0.025, (seat + h) / 2, w, 0.05, h - seat))
        parts.append(box(0, 0.03, seat + 0.02, w - 0.04, d - 0.1, 0.04, "accent"))
    return parts


def stool(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    if v == "round":
        parts = [cyl(0, 0, h - 0.025, w, 0.05)]
        for a in np.deg2rad([90, 210, 330]):
            parts.append(cyl(0.3 * w * np.cos(a), 0.3 * w * np.sin(a), (h - 0.05) / 2, 0.035, h - 0.05, "legs"))
        return parts
    parts = [box(0, 0, h - 0.025, w, d, 0.05), *_legs(w, d, h - 0.05, 0.035, 0.02)]
    if v == "bar":  # foot rest ring as four rails
        parts += [box(0, y, 0.3, w - 0.04, 0.02, 0.02, "metal") for y in (-d / 2 + 0.03, d / 2 - 0.03)]
    return parts


def table(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    if v == "round":
        return [cyl(0, 0, h - 0.02, w, 0.04), cyl(0, 0, (h - 0.04) / 2, 0.1, h - 0.04, "legs"),
                cyl(0, 0, 0.015, 0.5, 0.03, "legs")]
    parts = [box(0, 0, h - 0.02, w, d, 0.04)]
    if v == "trestle":
        for x in (-w / 2 + 0.15, w / 2 - 0.15):
            parts.append(box(x, 0, (h - 0.04) / 2, 0.06, d * 0.7, h - 0.04, "legs"))
        parts.append(box(0, 0, 0.25, w - 0.3, 0.05, 0.05, "legs"))
    else:
        parts += _legs(w, d, h - 0.04, 0.06, 0.04)
    return parts


def coffee_table(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    if v == "round":
        return [cyl(0, 0, h - 0.02, w, 0.04), cyl(0, 0, (h - 0.04) / 2, 0.3 * w, h - 0.04, "legs")]
    parts = [box(0, 0, h - 0.02, w, d, 0.04), *_legs(w, d, h - 0.04, 0.04, 0.02)]
    if v == "two-tier":
        parts.append(box(0, 0, 0.12, w - 0.08, d - 0.08, 0.03, "accent"))
    return parts


def desk(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    parts = [box(0, 0, h - 0.02, w, d, 0.04)]
    if v == "drawer-unit":
        parts.append(box(w / 2 - 0.22, 0, (h - 0.04) / 2, 0.42, d - 0.04, h - 0.04))
        parts += [box(w / 2 - 0.22, d / 2 - 0.01, 0.15 + k * 0.22, 0.1, 0.02, 0.02, "metal") for k in range(3)]
        parts += [box(-w / 2 + 0.03, y, (h - 0.04) / 2, 0.04, 0.04, h - 0.04, "legs")
                  for y in (-d / 2 + 0.03, d / 2 - 0.03)]
    else:
        parts += _legs(w, d, h - 0.04, 0.05, 0.02, "legs" if v == "simple" else "metal")
        if v == "writing":
            parts.append(box(0, -d / 2 + 0.02, h + 0.1, w, 0.04, 0.2))
    return parts


def bed(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    parts = [box(0, 0, 0.17, w, d, 0.24, "accent"),
             box(0, 0.02, 0.38, w - 0.06, d - 0.08, 0.18, "mattress"),
             box(0, 0.25, 0.48, w - 0.02, d * 0.65, 0.04),
             box(0, -d / 2 + 0.04, h / 2, w, 0.08, h, "accent")]
    parts += [box(x, -d / 2 + 0.3, 0.54, 0.45 if w > 1.2 else 0.6, 0.3, 0.12, "pillow")
              for x in ((-w / 4, w / 4) if w > 1.2 else (0.0,))]
    parts += _legs(w, d, 0.05, 0.06, 0.02, "legs")
    if v == "footboard":
        parts.append(box(0, d / 2 - 0.03, 0.3, w, 0.06, 0.6, "accent"))
    return parts


def _drawers(w: float, d: float, h: float, n: int, z0: float, role: str = "metal") -> list[Part]:
    step = (h - z0) / n
    return [box(0, d / 2 + 0.005, z0 + step * (k + 0.5), min(0.25, w * 0.4), 0.02, 0.025, role) for k in range(n)]


def nightstand(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    if v == "open-shelf":
        return [box(0, 0, h - 0.015, w, d, 0.03), box(0, 0, 0.2, w - 0.04, d - 0.04, 0.02),
                *_legs(w, d, h - 0.03, 0.035, 0)]
    return [box(0, 0, (h - 0.06) / 2 + 0.06, w, d, h - 0.06), *_legs(w, d, 0.06, 0.04, 0.02),
            *_drawers(w, d, h, 2, 0.06)]


def wardrobe(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    n = 3 if v == "three-door" else 2
    parts = [box(0, 0, h / 2, w, d, h), box(0, 0, h - 0.03, w + 0.04, d + 0.02, 0.06, "accent")]
    for k in range(1, n):
        parts.append(box(-w / 2 + k * w / n, d / 2 + 0.004, h / 2, 0.012, 0.01, h - 0.12, "dark"))
    for k in range(n):
        x = -w / 2 + (k + 0.5) * w / n + (0.2 * w / n if k % 2 == 0 else -0.2 * w / n)
        parts.append(box(x, d / 2 + 0.015, h * 0.5, 0.02, 0.03, 0.25, "metal"))
    return parts


def dresser(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    n = 4 if v == "tall" else 3
    parts = [box(0, 0, (h - 0.08) / 2 + 0.08, w, d, h - 0.08), box(0, 0, h - 0.01, w + 0.02, d + 0.02, 0.02, "accent")]
    parts += _legs(w, d, 0.08, 0.05, 0.02)
    parts += _drawers(w, d, h, n, 0.08)
    if v == "double":
        parts.append(box(0, d / 2 + 0.004, (h + 0.08) / 2, 0.012, 0.01, h - 0.1, "dark"))
    return parts


def cabinet(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    base = 0.12 if v == "sideboard" else 0.04
    parts = [box(0, 0, (h - base) / 2 + base, w, d, h - base)]
    parts += _legs(w, d, base, 0.04, 0.03, "legs" if v == "sideboard" else "dark")
    doors = max(2, round(w / 0.45))
    for k in range(1, doors):
        parts.append(box(-w / 2 + k * w / doors, d / 2 + 0.004, (h + base) / 2, 0.012, 0.01, h - base - 0.05, "dark"))
    for k in range(doors):
        parts.append(box(-w / 2 + (k + 0.5) * w / doors, d / 2 + 0.012, h - 0.12, 0.08, 0.02, 0.02, "metal"))
    if v == "glass-top":
        parts.append(box(0, 0, h + 0.01, w, d, 0.02, "glass"))
    return parts


def bookshelf(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    t = 0.03
    parts = [box(x, 0, h / 2, t, d, h) for x in (-w / 2 + t / 2, w / 2 - t / 2)]
    parts.append(box(0, -d / 2 + 0.005, h / 2, w, 0.01, h, "accent"))
    n = max(3, int(h / 0.38))
    for k in range(n + 1):
        parts.append(box(0, 0, 0.02 + k * (h - 0.04) / n, w - 2 * t, d, t))
    fill = 0.8 if v == "full" else 0.45
    inner = w - 2 * t
    for k in range(n):  # books: a few textured blocks per shelf (one box per book would cost ~10x more)
        z0 = 0.02 + k * (h - 0.04) / n + t / 2
        x = -w / 2 + t
        while x < w / 2 - t - 0.1:
            bw = min(float(rng.uniform(0.15, 0.45)) * inner, w / 2 - t - x)
            if rng.random() < fill:
                bh = float(rng.uniform(0.2, 0.3))
                parts.append(box(x + bw / 2, 0.02, z0 + bh / 2, bw, d * 0.7, bh, f"books:{int(rng.integers(8))}"))
            x += bw + 0.02
    return parts


def tv(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    sh = w * 9 / 16
    z = h - sh / 2
    parts = [box(0, 0, z, w, 0.05, sh), box(0, 0.026, z, w - 0.03, 0.004, sh - 0.03, "screen")]
    if v == "pedestal":
        parts += [box(0, 0, (h - sh) / 2 + 0.01, 0.06, 0.04, h - sh), box(0, 0, 0.01, w * 0.35, d, 0.02)]
    else:  # media stand under the screen
        parts += [box(0, -0.02, 0.02 + (h - sh - 0.1) / 2, w * 1.05, d, h - sh - 0.1, "dark"),
                  box(0, 0, h - sh - 0.05, 0.15, 0.04, 0.1)]
    return parts


def lamp(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    parts = [cyl(0, 0, 0.015, w * 0.7, 0.03, "metal")]
    if v == "tripod":
        parts = [box(x, y, (h - 0.35) / 2, 0.025, 0.025, h - 0.35, "legs")
                 for x, y in ((0.0, w * 0.3), (w * 0.26, -w * 0.15), (-w * 0.26, -w * 0.15))]
    parts.append(cyl(0, 0, (h - 0.3) / 2, 0.03, h - 0.3, "metal"))
    if v == "globe":
        parts.append(sphere(0, 0, h - w / 2, w))
    else:
        parts.append(cyl(0, 0, h - 0.18, w, 0.36))
    return parts


def plant(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    pot_h = 0.25 + 0.1 * (h > 1.0)
    parts = [cyl(0, 0, pot_h / 2, w * 0.6, pot_h), cyl(0, 0, pot_h, w * 0.55, 0.01, "soil")]
    if v == "cactus":
        parts.append(cyl(0, 0, (pot_h + h) / 2, w * 0.3, h - pot_h, "leaf"))
        parts.append(cyl(w * 0.2, 0, pot_h + (h - pot_h) * 0.55, w * 0.15, (h - pot_h) * 0.4, "leaf"))
    elif v == "tall":
        parts.append(cyl(0, 0, (pot_h + h * 0.6) / 2, 0.04, h * 0.6 - pot_h, "soil"))
        for k in range(3):
            z = h * 0.55 + k * (h * 0.45 - w * 0.35) / 2
            parts.append(sphere(0.06 * np.cos(2.1 * k), 0.06 * np.sin(2.1 * k), z, w * (0.95 - 0.15 * k),
                                "leaf" if k % 2 == 0 else "leaf2"))
    else:  # bushy
        for k in range(5):
            a = 2 * np.pi * k / 5
            parts.append(sphere(0.18 * w * np.cos(a), 0.18 * w * np.sin(a), pot_h + (h - pot_h) * 0.45,
                                w * 0.6, "leaf" if k % 2 == 0 else "leaf2"))
        parts.append(sphere(0, 0, h - w * 0.3, w * 0.6, "leaf"))
    return parts


def toilet(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    bowl_y = d / 2 - 0.26
    parts = [cyl(0, bowl_y, 0.2, 0.34, 0.4), cyl(0, bowl_y, 0.41, 0.38, 0.03, "accent"),
             box(0, bowl_y - 0.15, 0.2, 0.22, 0.3, 0.4)]
    if v == "wall-hung":
        parts = [box(0, bowl_y - 0.05, 0.33, 0.36, 0.45, 0.2), cyl(0, bowl_y + 0.02, 0.42, 0.38, 0.03, "accent"),
                 box(0, -d / 2 + 0.06, h / 2, w, 0.12, h, "white")]
    else:
        parts.append(box(0, -d / 2 + 0.09, (0.42 + h) / 2, w, 0.18, h - 0.42))
    return parts


def sink(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    if v == "vanity":
        return [box(0, 0, (h - 0.06) / 2, w, d, h - 0.06, "accent"), box(0, 0, h - 0.03, w, d, 0.06),
                cyl(0, 0.03, h + 0.002, w * 0.5, 0.004, "dark"), cyl(0, -d / 2 + 0.06, h + 0.1, 0.03, 0.2, "metal")]
    return [cyl(0, -0.05, (h - 0.15) / 2, 0.16, h - 0.15), box(0, 0, h - 0.075, w, d, 0.15),
            cyl(0, 0.03, h + 0.002, w * 0.55, 0.004, "dark"), cyl(0, -d / 2 + 0.05, h + 0.1, 0.03, 0.2, "metal")]


def bathtub(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    t = 0.08
    parts = [box(0, 0, 0.05, w, d, 0.1),
             box(-w / 2 + t / 2, 0, h / 2, t, d, h), box(w / 2 - t / 2, 0, h / 2, t, d, h),
             box(0, -d / 2 + t / 2, h / 2, w - 2 * t, t, h), box(0, d / 2 - t / 2, h / 2, w - 2 * t, t, h)]
    if v == "clawfoot":
        parts[0] = box(0, 0, 0.12, w, d, 0.1)
        parts += _legs(w, d, 0.08, 0.06, 0.1, "metal", round_legs=True)
    parts.append(cyl(-w / 2 + 0.04, 0, h + 0.08, 0.03, 0.16, "metal"))
    return parts


def refrigerator(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    parts = [box(0, 0, h / 2, w, d, h)]
    if v == "french-door":
        parts.append(box(0, d / 2 + 0.004, h * 0.65, 0.01, 0.01, h * 0.68, "dark"))
        parts.append(box(0, d / 2 + 0.004, h * 0.3, w - 0.02, 0.01, 0.01, "dark"))
        parts += [box(x, d / 2 + 0.02, h * 0.65, 0.02, 0.03, 0.4, "metal") for x in (-0.05, 0.05)]
    else:
        split = h * (0.35 if v == "bottom-freezer" else 0.7)
        parts.append(box(0, d / 2 + 0.004, split, w - 0.02, 0.01, 0.012, "dark"))
        parts += [box(w / 2 - 0.06, d / 2 + 0.02, z, 0.02, 0.03, 0.3, "metal") for z in (split - 0.2, split + 0.25)]
    return parts


def counter(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    parts = [box(0, -0.02, (h - 0.04) / 2 + 0.05, w, d - 0.04, h - 0.09),
             box(0, 0, h - 0.02, w + 0.02, d, 0.04, "accent"),
             box(0, -0.06, 0.025, w, d - 0.12, 0.05, "dark")]
    doors = max(2, round(w / 0.5))
    for k in range(1, doors):
        parts.append(box(-w / 2 + k * w / doors, d / 2 - 0.035, h / 2, 0.012, 0.01, h - 0.2, "dark"))
    parts += [box(-w / 2 + (k + 0.5) * w / doors, d / 2 - 0.025, h - 0.15, 0.12, 0.02, 0.015, "metal")
              for k in range(doors)]
    if v == "with-sink":
        parts.append(box(-w / 4, 0, h + 0.002, 0.45, 0.35, 0.004, "metal"))
        parts.append(cyl(-w / 4, -d / 2 + 0.08, h + 0.15, 0.03, 0.3, "metal"))
    return parts


def stove(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    parts = [box(0, 0, h / 2, w, d, h), box(0, 0, h + 0.005, w - 0.02, d - 0.02, 0.01, "dark"),
             box(0, d / 2 + 0.005, h * 0.45, w - 0.1, 0.01, h * 0.45, "glass"),
             box(0, d / 2 + 0.02, h * 0.72, w - 0.15, 0.03, 0.02, "metal")]
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(cyl(sx * w * 0.22, sy * d * 0.2, h + 0.015, 0.16 if v == "gas" else 0.2, 0.02,
                             "metal" if v == "gas" else "screen"))
    if v == "range-hood":  # a back splash panel with controls
        parts.append(box(0, -d / 2 + 0.03, h + 0.1, w, 0.06, 0.2))
    return parts


def washing_machine(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    parts = [box(0, 0, h / 2, w, d, h), box(0, d / 2 + 0.005, h - 0.08, w - 0.04, 0.01, 0.1, "dark")]
    if v == "top-loader":
        parts.append(box(0, 0, h + 0.005, w - 0.08, d - 0.16, 0.01, "dark"))
    else:
        parts.append(cyl(0, d / 2 + 0.02, h * 0.45, 0.34, 0.04, "metal", axis="y"))
        parts.append(cyl(0, d / 2 + 0.04, h * 0.45, 0.26, 0.02, "glass", axis="y"))
    return parts


def ottoman(rng: np.random.Generator, w: float, d: float, h: float, v: str) -> list[Part]:
    if v == "round":
        return [cyl(0, 0, h / 2, w, h), cyl(0, 0, h - 0.01, w * 0.9, 0.03, "accent")]
    parts = [box(0, 0, (h + 0.06) / 2, w, d, h - 0.06), *_legs(w, d, 0.06, 0.04, 0.03)]
    if v == "tufted":
        parts += [sphere(x, y, h, 0.04, "accent") for x in (-w / 4, w / 4) for y in (-d / 4, d / 4)]
    return parts


@dataclass(frozen=True)
class CategorySpec:
    """Base size (w, d, h) and its random scale range, shape variants, and the builder."""

    size: tuple[float, float, float]
    scale: tuple[float, float]
    variants: tuple[str, ...]
    build: Builder
    keep_height: bool = False  # appliances: height fixed, width varies


SPECS: dict[str, CategorySpec] = {
    "sofa": CategorySpec((2.0, 0.9, 0.85), (0.8, 1.25), ("straight", "curved", "l-shaped", "armless"), sofa),
    "armchair": CategorySpec((0.85, 0.85, 0.9), (0.85, 1.15), ("boxy", "round-armed", "wingback"), armchair),
    "chair": CategorySpec((0.45, 0.5, 0.9), (0.9, 1.1), ("four-leg", "slat-back", "tulip"), chair),
    "stool": CategorySpec((0.4, 0.4, 0.6), (0.8, 1.25), ("round", "square", "bar"), stool),
    "table": CategorySpec((1.5, 0.9, 0.75), (0.8, 1.3), ("rectangular", "round", "trestle"), table, True),
    "coffee table": CategorySpec((1.0, 0.6, 0.42), (0.8, 1.3), ("rectangular", "round", "two-tier"), coffee_table,
                                 True),
    "desk": CategorySpec((1.3, 0.65, 0.75), (0.85, 1.25), ("simple", "drawer-unit", "writing"), desk, True),
    "bed": CategorySpec((1.6, 2.05, 1.0), (0.6, 1.15), ("platform", "footboard"), bed, True),
    "nightstand": CategorySpec((0.48, 0.4, 0.55), (0.85, 1.2), ("drawers", "open-shelf"), nightstand),
    "wardrobe": CategorySpec((1.4, 0.6, 2.0), (0.8, 1.3), ("two-door", "three-door"), wardrobe, True),
    "dresser": CategorySpec((1.1, 0.5, 0.85), (0.8, 1.25), ("low", "tall", "double"), dresser),
    "cabinet": CategorySpec((1.2, 0.45, 0.85), (0.7, 1.3), ("sideboard", "cupboard", "glass-top"), cabinet),
    "bookshelf": CategorySpec((0.9, 0.35, 1.8), (0.75, 1.25), ("full", "sparse"), bookshelf),
    "tv": CategorySpec((1.2, 0.4, 1.15), (0.8, 1.3), ("media-stand", "pedestal"), tv, True),
    "lamp": CategorySpec((0.4, 0.4, 1.6), (0.8, 1.15), ("drum", "globe", "tripod"), lamp),
    "plant": CategorySpec((0.5, 0.5, 1.0), (0.6, 1.6), ("bushy", "tall", "cactus"), plant),
    "toilet": CategorySpec((0.42, 0.7, 0.8), (0.95, 1.1), ("close-coupled", "wall-hung"), toilet, True),
    "sink": CategorySpec((0.6, 0.46, 0.85), (0.85, 1.4), ("pedestal", "vanity"), sink, True),
    "bathtub": CategorySpec((1.7, 0.75, 0.55), (0.9, 1.1), ("built-in", "clawfoot"), bathtub, True),
    "refrigerator": CategorySpec((0.7, 0.68, 1.8), (0.85, 1.3), ("top-freezer", "bottom-freezer", "french-door"),
                                 refrigerator, True),
    "counter": CategorySpec((1.8, 0.62, 0.9), (0.7, 1.4), ("plain", "with-sink"), counter, True),
    "stove": CategorySpec((0.6, 0.62, 0.9), (0.95, 1.2), ("electric", "gas", "range-hood"), stove, True),
    "washing machine": CategorySpec((0.6, 0.6, 0.85), (1.0, 1.05), ("front-loader", "top-loader"), washing_machine,
                                    True),
    "ottoman": CategorySpec((0.6, 0.6, 0.42), (0.8, 1.3), ("round", "square", "tufted"), ottoman),
}


def build_model(category: str, rng: np.random.Generator, variant: str | None = None,
                scale: float | None = None) -> Model:
    """A random instance of ``category``: variant and scale drawn from ``rng`` unless given."""
    spec = SPECS[category]
    v = variant if variant is not None else spec.variants[int(rng.integers(len(spec.variants)))]
    s = scale if scale is not None else float(rng.uniform(*spec.scale))
    w, d, h = spec.size
    if spec.keep_height:
        w, d = w * s, d * (1.0 + (s - 1.0) * 0.3)
        if category == "bed":  # single to king size; length fixed
            w, d = spec.size[0] * s, spec.size[1]
        if category == "tv":
            h = h - spec.size[0] * 9 / 16 + w * 9 / 16
    else:
        w, d, h = w * s, d * s, h * (1.0 + (s - 1.0) * 0.6)
    if v == "round" and category in ("table", "coffee table", "ottoman", "stool"):
        d = w
    parts = spec.build(rng, round(w, 3), round(d, 3), round(h, 3), v)
    # The true extent covers every part (handles, chaises, table tops); re-centre the footprint on it.
    lo = np.min([np.subtract(p.center, np.divide(p.size, 2)) for p in parts], axis=0)
    hi = np.max([np.add(p.center, np.divide(p.size, 2)) for p in parts], axis=0)
    cx, cy = float(lo[0] + hi[0]) / 2, float(lo[1] + hi[1]) / 2
    parts = [Part(p.kind, (p.center[0] - cx, p.center[1] - cy, p.center[2]), p.size, p.role, p.axis) for p in parts]
    size = (round(float(hi[0] - lo[0]), 4), round(float(hi[1] - lo[1]), 4), round(float(hi[2]), 4))
    return Model(v, size, tuple(parts))
