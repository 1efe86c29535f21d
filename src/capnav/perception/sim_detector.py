"""The simulator detector: ground-truth instance images degraded into Detic-like detections.

It reads only ``frame.gt_instance`` / ``frame.gt_category`` (and the observed depth), never the
scene manifest. Noise model, per instance and frame, all draws from ``rng(seed, frame.index)`` so
a frame's detections do not depend on the order frames are processed in:

* quality ``q = size * occlusion * distance`` where ``size = 1 / (1 + (a50 / a)^2)`` for the mask
  area fraction ``a``; ``occlusion = 1 - w_occ * o`` with ``o`` the fraction of the mask outline
  that borders a nearer surface (occluders; pixels on the image border count half: truncation); ``distance =
  exp(-max(0, d - d_free) / d_scale)`` for the mean depth ``d``;
* a miss with probability ``1 - p_max * q`` (misses grow with occlusion, small size, distance);
* a label swap inside ``core.categories.CONFUSION_GROUPS`` with probability
  ``confusion_rate * (2 - q)`` (poor views are confused twice as often);
* mask boundary noise: each outline pixel is dropped and each pixel of the outer ring is added
  with probability ``boundary_flip``;
* a confidence ``0.25 + 0.7 q + N(0, score_sigma)`` (x0.85 when the label was swapped), dropped
  below ``score_threshold`` like Detic's default output threshold;
* ``Poisson(fp_rate)`` false positives per frame: a depth-coherent blob with a random label and
  a low score.

Measured per frame on apartment seed 0 (231 frames, ``benchmarks/bench_mapping.py``): the default
level detects 69% of the instances showing >= 100 pixels (79% of those >= 2000 px), swaps 6.4% of
labels, adds 0.035 false positives per frame (mean score 0.82); "hard" gives 62% / 74% / 13.4% /
0.17. The intent is the failure profile of an open-vocabulary detector such as Detic (small, far
and occluded objects missed, lookalikes confused, few confident false positives); the exact
rates of a real detector depend on the model and the scenes and were not measured here.
``noise="oracle"`` turns every noise source off.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.categories import BY_ID, NAMES, category, confusable
from capnav.core.errors import FrameError, InputError
from capnav.core.frame import Frame
from capnav.perception.base import DETECTORS, Detection, Detector, box_from_mask


@dataclass(frozen=True)
class SimNoise:
    """Parameters of the simulator detector's noise model (see the module docstring)."""

    p_max: float = 0.93
    area_half: float = 0.002  # mask area fraction at which the size factor is 0.5
    min_area_frac: float = 4e-4  # smaller masks are never reported (~30 px at 320x240)
    occlusion_weight: float = 0.7
    occluder_gap: float = 0.05  # m: a neighbour this much nearer counts as an occluder
    dist_free: float = 3.5  # m
    dist_scale: float = 4.0  # m
    confusion_rate: float = 0.08
    boundary_flip: float = 0.25
    fp_rate: float = 0.05  # expected false positives per frame
    score_sigma: float = 0.08
    score_threshold: float = 0.3
    oracle: bool = False


NOISE_PRESETS: dict[str, SimNoise] = {
    "default": SimNoise(),
    "hard": SimNoise(p_max=0.85, confusion_rate=0.15, boundary_flip=0.4, fp_rate=0.2, dist_free=2.5),
    "oracle": SimNoise(p_max=1.0, confusion_rate=0.0, boundary_flip=0.0, fp_rate=0.0, score_sigma=0.0,
                       score_threshold=0.0, oracle=True),
}


def resolve_noise(noise: str | SimNoise) -> tuple[str, SimNoise]:
    if isinstance(noise, SimNoise):
        return "custom", noise
    if noise not in NOISE_PRESETS:
        raise InputError(f"unknown noise level {noise!r}; available: {', '.join(NOISE_PRESETS)}")
    return noise, NOISE_PRESETS[noise]


def occluded_outline(inst: NDArray[np.integer], depth: NDArray[np.floating], gap: float
                     ) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Per pixel: (on an instance outline or the image border, outline pixel next to a nearer surface)."""
    h, w = inst.shape
    d = np.where(np.isfinite(depth) & (depth > 0), depth, np.inf).astype(np.float32)
    outline = np.zeros((h, w), dtype=bool)
    occl = np.zeros((h, w), dtype=bool)
    outline[0, :] = outline[-1, :] = outline[:, 0] = outline[:, -1] = True
    for sl_a, sl_b in (((slice(1, None), slice(None)), (slice(None, -1), slice(None))),
                       ((slice(None), slice(1, None)), (slice(None), slice(None, -1)))):
        diff = inst[sl_a] != inst[sl_b]
        outline[sl_a] |= diff
        outline[sl_b] |= diff
        occl[sl_a] |= diff & (d[sl_b] < d[sl_a] - gap)
        occl[sl_b] |= diff & (d[sl_a] < d[sl_b] - gap)
    return outline, occl


class SimDetector(Detector):
    """Detections from the simulator's per-pixel truth, degraded by ``SimNoise``."""

    needs_truth = True

    def __init__(self, noise: str | SimNoise = "default", seed: int = 0, **overrides: float) -> None:
        name, cfg = resolve_noise(noise)
        if overrides:
            try:
                cfg = replace(cfg, **overrides)  # type: ignore[arg-type]
            except TypeError as e:
                raise InputError(f"bad SimNoise override: {e}") from None
            name = f"{name}+custom"
        self.noise = cfg
        self.seed = int(seed)
        self.id = f"sim:{name}:seed={self.seed}"

    def detect(self, frame: Frame) -> list[Detection]:
        if frame.gt_instance is None or frame.gt_category is None:
            raise FrameError(frame.index, "the sim detector needs gt_instance/gt_category images "
                                          "(use a simulator dataset or another detector)")
        inst = np.asarray(frame.gt_instance)
        cat = np.asarray(frame.gt_category)
        h, w = inst.shape
        if cat.shape != (h, w) or frame.depth.shape != (h, w):
            raise FrameError(frame.index, f"gt images {inst.shape}/{cat.shape} do not match depth {frame.depth.shape}")
        cfg = self.noise
        rng = np.random.default_rng([self.seed, frame.index & 0x7FFFFFFF, 0x5D])
        n_px = float(h * w)
        ids = np.where(cat > 0, inst, 0).astype(np.int64)
        if ids.max(initial=0) <= 0:
            return self._false_positives(frame, rng)
        nbin = int(ids.max()) + 1
        area = np.bincount(ids.ravel(), minlength=nbin)
        depth = np.asarray(frame.depth, dtype=np.float32)
        valid = np.isfinite(depth) & (depth > 0)
        dsum = np.bincount(ids.ravel(), weights=np.where(valid, depth, 0).ravel(), minlength=nbin)
        dcnt = np.bincount(ids.ravel(), weights=valid.ravel().astype(np.float64), minlength=nbin)
        outline, occl = occluded_outline(ids, depth, cfg.occluder_gap)
        n_out = np.bincount(ids.ravel(), weights=outline.ravel().astype(np.float64), minlength=nbin)
        border = np.zeros((h, w), dtype=np.float64)
        border[0, :] = border[-1, :] = border[:, 0] = border[:, -1] = 0.5  # truncation: half an occlusion
        n_occ = np.bincount(ids.ravel(), weights=np.maximum(occl, border).ravel(), minlength=nbin)
        slices = ndimage.find_objects(ids)
        dets: list[Detection] = []
        for iid in range(1, nbin):
            sl = slices[iid - 1] if iid - 1 < len(slices) else None
            if sl is None or area[iid] < cfg.min_area_frac * n_px:
                continue
            a = area[iid] / n_px
            size_f = 1.0 / (1.0 + (cfg.area_half / a) ** 2)
            occ = n_occ[iid] / max(n_out[iid], 1.0)
            occ_f = max(0.0, 1.0 - cfg.occlusion_weight * occ)
            dist = dsum[iid] / dcnt[iid] if dcnt[iid] > 0 else np.inf
            dist_f = float(np.exp(-max(0.0, dist - cfg.dist_free) / cfg.dist_scale))
            q = size_f * occ_f * dist_f
            # Draw every random number even in oracle mode so streams stay aligned across settings.
            u_miss, u_conf, u_pick = rng.random(3)
            s_noise = rng.normal(0.0, 1.0)
            sub = ids[sl] == iid
            cat_id = int(np.bincount(cat[sl][sub]).argmax())
            if cat_id not in BY_ID:
                continue
            label = BY_ID[cat_id].name
            if cfg.oracle:
                mask = np.zeros((h, w), dtype=bool)
                mask[sl] = sub
                dets.append(Detection(box_from_mask(mask), cat_id, label, 1.0, mask))
                continue
            if u_miss >= cfg.p_max * q:
                continue
            swapped = False
            others = confusable(label)
            if others and u_conf < cfg.confusion_rate * (2.0 - q):
                label = others[int(u_pick * len(others)) % len(others)]
                cat_id = category(label).id
                swapped = True
            score = 0.25 + 0.7 * q + cfg.score_sigma * s_noise
            if swapped:
                score *= 0.85
            score = float(np.clip(score, 0.01, 0.99))
            if score < cfg.score_threshold:
                continue
            mask = self._noisy_mask(sub, sl, (h, w), rng)
            if mask.sum() < cfg.min_area_frac * n_px:
                continue
            dets.append(Detection(box_from_mask(mask), cat_id, label, score, mask))
        dets.extend(self._false_positives(frame, rng))
        return dets

    def _noisy_mask(self, sub: NDArray[np.bool_], sl: tuple[slice, ...], shape: tuple[int, int],
                    rng: np.random.Generator) -> NDArray[np.bool_]:
        h, w = shape
        y0, y1 = max(sl[0].start - 1, 0), min(sl[0].stop + 1, h)
        x0, x1 = max(sl[1].start - 1, 0), min(sl[1].stop + 1, w)
        crop = np.zeros((y1 - y0, x1 - x0), dtype=bool)
        crop[sl[0].start - y0: sl[0].stop - y0, sl[1].start - x0: sl[1].stop - x0] = sub
        p = self.noise.boundary_flip
        if p > 0:
            inner = crop & ~ndimage.binary_erosion(crop)
            outer = ndimage.binary_dilation(crop) & ~crop
            flip = rng.random(crop.shape) < p
            crop = (crop & ~(inner & flip)) | (outer & flip)
        mask = np.zeros((h, w), dtype=bool)
        mask[y0:y1, x0:x1] = crop
        return mask

    def _false_positives(self, frame: Frame, rng: np.random.Generator) -> list[Detection]:
        cfg = self.noise
        n = int(rng.poisson(cfg.fp_rate)) if cfg.fp_rate > 0 else 0
        h, w = frame.shape
        out: list[Detection] = []
        depth = np.asarray(frame.depth, dtype=np.float32)
        for _ in range(n):
            cu, cv = int(rng.integers(0, w)), int(rng.integers(0, h))
            ru = max(2, int(w * rng.uniform(0.04, 0.12)))
            rv = max(2, int(h * rng.uniform(0.04, 0.12)))
            label = NAMES[int(rng.integers(0, len(NAMES)))]
            score = float(rng.uniform(cfg.score_threshold, cfg.score_threshold + 0.25))
            z0 = depth[cv, cu]
            if not (np.isfinite(z0) and z0 > 0):
                continue
            vv, uu = np.ogrid[:h, :w]
            blob = ((uu - cu) / ru) ** 2 + ((vv - cv) / rv) ** 2 <= 1.0
            with np.errstate(invalid="ignore"):
                blob &= np.abs(depth - z0) < 0.3
            if blob.sum() < cfg.min_area_frac * h * w:
                continue
            out.append(Detection(box_from_mask(blob), category(label).id, label, score, blob))
        return out


@DETECTORS.register("sim")
def _make_sim(noise: str | SimNoise = "default", seed: int = 0, **overrides: float) -> SimDetector:
    return SimDetector(noise=noise, seed=seed, **overrides)
